//! Separating surface families and their feature maps.

use crate::math::Vector3;
use crate::Real;
use std::f64::consts::SQRT_2;

/// The family of the separating surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Surface {
    /// A plane `w . x + b = 0` (the paper's Eq. 2).
    Linear,
    /// A quadric `x^T Q x + g . x + b = 0` through the degree-2 feature map
    /// `phi(x) = (x, y, z, x^2, y^2, z^2, sqrt2 xy, sqrt2 xz, sqrt2 yz)`. The `sqrt2`
    /// makes `|w|^2 = |g|^2 + |Q|_F^2`, so the regularizer (and the solution) is
    /// invariant under rotations. Follows curved and wrapped contacts that one
    /// plane per region cannot (see `docs/architecture.md`); the default.
    #[default]
    Quadric,
}

crate::names::named_options!(Surface, "surface", {
    Linear => "linear",
    Quadric => "quadric",
});

impl Surface {
    /// Dimension of the feature map.
    pub fn dim(self) -> usize {
        match self {
            Surface::Linear => 3,
            Surface::Quadric => 9,
        }
    }

    /// Writes `phi(u)` into `phi` and the Jacobian `d phi / d u` (one row of 3 per
    /// feature) into `jac`; both have length [`Surface::dim`].
    pub fn features(self, u: &Vector3, phi: &mut [Real], jac: &mut [Vector3]) {
        let (x, y, z) = (u.x, u.y, u.z);
        phi[0] = x;
        phi[1] = y;
        phi[2] = z;
        jac[0] = Vector3::x();
        jac[1] = Vector3::y();
        jac[2] = Vector3::z();
        if self == Surface::Quadric {
            phi[3] = x * x;
            phi[4] = y * y;
            phi[5] = z * z;
            phi[6] = SQRT_2 * x * y;
            phi[7] = SQRT_2 * x * z;
            phi[8] = SQRT_2 * y * z;
            jac[3] = Vector3::new(2.0 * x, 0.0, 0.0);
            jac[4] = Vector3::new(0.0, 2.0 * y, 0.0);
            jac[5] = Vector3::new(0.0, 0.0, 2.0 * z);
            jac[6] = SQRT_2 * Vector3::new(y, x, 0.0);
            jac[7] = SQRT_2 * Vector3::new(z, 0.0, x);
            jac[8] = SQRT_2 * Vector3::new(0.0, z, y);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobian_matches_finite_differences() {
        let u = Vector3::new(0.3, -0.7, 1.1);
        for s in [Surface::Linear, Surface::Quadric] {
            let d = s.dim();
            let (mut phi, mut jac) = (vec![0.0; d], vec![Vector3::zeros(); d]);
            s.features(&u, &mut phi, &mut jac);
            for k in 0..3 {
                let h = 1e-6;
                let mut e = Vector3::zeros();
                e[k] = h;
                let (mut pp, mut pm) = (vec![0.0; d], vec![0.0; d]);
                let mut j2 = vec![Vector3::zeros(); d];
                s.features(&(u + e), &mut pp, &mut j2);
                s.features(&(u - e), &mut pm, &mut j2);
                for f in 0..d {
                    let fd = (pp[f] - pm[f]) / (2.0 * h);
                    assert!((fd - jac[f][k]).abs() < 1e-8, "{s:?} feature {f} axis {k}");
                }
            }
        }
    }
}
