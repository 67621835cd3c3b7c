//! Deterministic synthetic shapes and seeded Gaussian noise, for tests,
//! benchmarks, examples and demos (no external random-number crate needed).

use crate::math::{Point3, Vector3};
use crate::Real;

/// `n` points spread evenly over a sphere (Fibonacci lattice).
pub fn sphere(center: &Point3, radius: Real, n: usize) -> Vec<Point3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as Real + 0.5) / n as Real;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let t = golden * i as Real;
            center + radius * Vector3::new(r * t.cos(), r * t.sin(), z)
        })
        .collect()
}

/// The surface of an axis-aligned box (centre, half extents) sampled on a grid of
/// about `spacing` on each face (edges shared between faces appear once per face).
///
/// # Panics
/// If `spacing` is not finite and positive.
pub fn box_surface(center: &Point3, half: &Vector3, spacing: Real) -> Vec<Point3> {
    assert!(
        spacing.is_finite() && spacing > 0.0,
        "box_surface: spacing must be finite and > 0, got {spacing}"
    );
    let mut out = Vec::new();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let nu = ((2.0 * half[u] / spacing).round() as usize).max(1);
        let nv = ((2.0 * half[v] / spacing).round() as usize).max(1);
        for sign in [-1.0, 1.0] {
            for i in 0..=nu {
                for j in 0..=nv {
                    let mut p = Vector3::zeros();
                    p[axis] = sign * half[axis];
                    p[u] = -half[u] + 2.0 * half[u] * i as Real / nu as Real;
                    p[v] = -half[v] + 2.0 * half[v] * j as Real / nv as Real;
                    // Skip the face borders of the u/v-faces already emitted.
                    let on_earlier_face = (0..axis).any(|a| (p[a].abs() - half[a]).abs() < 1e-12);
                    if !on_earlier_face {
                        out.push(center + p);
                    }
                }
            }
        }
    }
    out
}

/// SplitMix64's output function: a bijection of `u64` that spreads every input
/// bit over the output (Steele, Lea and Flood, *Fast splittable pseudorandom
/// number generators*, 2014). [`NormalRng`] applies it to its counter; the
/// element split to a hash of a group.
pub(crate) fn splitmix64_mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform numbers in `[0, 1)` from a 64-bit linear congruential generator
/// seeded by `seed` (Knuth's MMIX constants): the tests' fixed streams.
#[cfg(test)]
pub(crate) fn lcg_uniform(seed: u64) -> impl FnMut() -> Real {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as Real) / ((1u64 << 53) as Real)
    }
}

/// A small seeded generator of standard normal numbers (SplitMix64 + Box-Muller).
#[derive(Debug, Clone)]
pub struct NormalRng {
    state: u64,
    spare: Option<Real>,
}

impl NormalRng {
    /// A generator from `seed`.
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed,
            spare: None,
        }
    }

    /// A uniform number in `(0, 1)`.
    pub fn uniform(&mut self) -> Real {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let z = splitmix64_mix(self.state);
        ((z >> 11) as Real + 0.5) / (1u64 << 53) as Real
    }

    /// A standard normal number.
    pub fn normal(&mut self) -> Real {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let t = 2.0 * std::f64::consts::PI * u2;
        self.spare = Some(r * t.sin());
        r * t.cos()
    }
}

/// `points` with isotropic Gaussian noise of standard deviation `sigma` added.
pub fn add_noise(points: &[Point3], sigma: Real, seed: u64) -> Vec<Point3> {
    let mut rng = NormalRng::new(seed);
    points
        .iter()
        .map(|p| p + sigma * Vector3::new(rng.normal(), rng.normal(), rng.normal()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_lie_on_their_surfaces_and_noise_has_the_right_spread() {
        let c = Point3::new(1.0, 2.0, 3.0);
        for p in sphere(&c, 0.5, 500) {
            assert!(((p - c).norm() - 0.5).abs() < 1e-12);
        }
        let half = Vector3::new(0.1, 0.2, 0.3);
        let pts = box_surface(&c, &half, 0.05);
        for p in &pts {
            let d = p - c;
            let on = (0..3).any(|a| (d[a].abs() - half[a]).abs() < 1e-12);
            let inside = (0..3).all(|a| d[a].abs() <= half[a] + 1e-12);
            assert!(on && inside);
        }
        let mut rng = NormalRng::new(3);
        let xs: Vec<Real> = (0..20000).map(|_| rng.normal()).collect();
        let mean = xs.iter().sum::<Real>() / xs.len() as Real;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<Real>() / xs.len() as Real;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
    }
}
