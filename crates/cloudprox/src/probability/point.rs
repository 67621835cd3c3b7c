//! Per-point probability of lying on the wrong side (paper, Eq. 3).

use crate::math::{Matrix3, Vector3};
use crate::probability::gaussian::wrong_side;
#[cfg(test)]
use crate::probability::normal_cdf;
use crate::uncertainty::directional_std_of;
use crate::Real;

/// `P(c f(x') <= 0)` for `x' ~ N(x, Sigma)`, to first order in `f`:
/// `Phi(-c f(x) / sqrt(grad^T Sigma grad))` (paper, Eq. 3), with `value = f(x)`,
/// `gradient = grad f(x)` (the complete gradient), `label = c` (+1 for cloud A,
/// -1 for cloud B).
///
/// With no spread along the gradient the answer is exact: 1 when the point is on
/// the wrong side or on the surface, 0 otherwise.
pub fn point_probability(value: Real, gradient: &Vector3, cov: &Matrix3, label: Real) -> Real {
    wrong_side(label * value, directional_std_of(cov, gradient))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_closed_form_for_a_plane() {
        // f(x) = n . x - d with |n| = 1: the signed distance; Sigma = s^2 I.
        let n = Vector3::new(0.0, 0.6, 0.8);
        let s = 0.01;
        let cov = Matrix3::identity() * s * s;
        for &dist in &[-0.03, -0.01, 0.0, 0.005, 0.02, 0.05] {
            let p_a = point_probability(dist, &n, &cov, 1.0);
            assert!((p_a - normal_cdf(-dist / s)).abs() < 1e-15);
            let p_b = point_probability(dist, &n, &cov, -1.0);
            assert!((p_a + p_b - 1.0).abs() < 1e-12);
        }
        // Scaling f does not change the probability.
        let p1 = point_probability(0.02, &n, &cov, 1.0);
        let p2 = point_probability(0.2, &(n * 10.0), &cov, 1.0);
        assert!((p1 - p2).abs() < 1e-15);
    }

    #[test]
    fn anisotropic_covariance_uses_the_normal_direction() {
        let cov = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1e-4));
        let p = point_probability(0.02, &Vector3::z(), &cov, 1.0);
        assert!((p - normal_cdf(-2.0)).abs() < 1e-15);
        assert_eq!(
            point_probability(0.02, &Vector3::z(), &Matrix3::zeros(), 1.0),
            0.0
        );
        assert_eq!(
            point_probability(-0.02, &Vector3::z(), &Matrix3::zeros(), 1.0),
            1.0
        );
    }
}
