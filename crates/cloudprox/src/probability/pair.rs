//! The probability that two sampled surfaces cross, from the samples of both.

use crate::math::Point3;
use crate::probability::normal_cdf;
use crate::Real;

/// Per sample of one side, the probability that the surface it samples and the
/// surface the nearest sample of the other side samples lie on the wrong sides
/// of each other.
///
/// Sample `i` lies at signed distance `m_i` from the separating surface on its
/// own side (its *margin*), with standard deviation `s_i` along the surface's
/// normal; so does its nearest other sample `j`. Their surfaces are
/// `g = m_i + m_j` apart across the separating surface, and with independent
/// errors `g` has the standard deviation `sqrt(s_i^2 + s_j^2)`: the surfaces
/// cross with probability `Phi(-g / sqrt(s_i^2 + s_j^2))`. Unlike the paper's
/// per-point Eq. 3, this does not depend on where between the two sides the
/// separating surface was placed: on two parallel plates it is the probability
/// that the fitted gap is negative. Exact (0 or 1) without noise.
pub fn pair_crossing_probabilities(
    own: &[Point3],
    own_margins: &[Real],
    own_stds: &[Real],
    other: &[Point3],
    other_margins: &[Real],
    other_stds: &[Real],
) -> Vec<Real> {
    own.iter()
        .enumerate()
        .map(|(i, x)| {
            let Some(j) = (0..other.len()).min_by(|&j, &k| {
                (other[j] - x)
                    .norm_squared()
                    .total_cmp(&(other[k] - x).norm_squared())
            }) else {
                return 0.0;
            };
            crossing(
                own_margins[i] + other_margins[j],
                own_stds[i].hypot(other_stds[j]),
            )
        })
        .collect()
}

/// `Phi(-gap / sd)`, exact (0 or 1) when `sd` is 0.
pub(crate) fn crossing(gap: Real, sd: Real) -> Real {
    if sd > 0.0 && sd.is_finite() {
        normal_cdf(-gap / sd)
    } else if gap > 0.0 {
        0.0
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gap_and_its_standard_deviation() {
        let a = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0)];
        let b = [Point3::new(1.0, 0.0, 0.3), Point3::new(0.0, 0.0, 0.3)];
        // Margins 0.1 and 0.2 (the surface nearer A): the gap is 0.3 either way.
        let p =
            pair_crossing_probabilities(&a, &[0.1, 0.1], &[0.3, 0.3], &b, &[0.2, 0.2], &[0.4, 0.4]);
        for q in p {
            assert!((q - normal_cdf(-0.3 / 0.5)).abs() < 1e-15);
        }
        // Nearest partner: a[0]'s is b[1] (margin -0.5 there).
        let p = pair_crossing_probabilities(
            &a,
            &[0.1, 0.1],
            &[0.0, 0.0],
            &b,
            &[0.2, -0.5],
            &[0.0, 0.0],
        );
        assert_eq!(p, vec![1.0, 0.0]);
        assert!(
            pair_crossing_probabilities(&a, &[0.1, 0.1], &[0.0, 0.0], &[], &[], &[])
                .iter()
                .all(|&q| q == 0.0)
        );
    }
}
