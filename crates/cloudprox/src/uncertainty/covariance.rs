//! Validation and square roots of 3x3 covariance matrices.

use crate::error::{Error, Result};
use crate::math::{Matrix3, Vector3};
use crate::Real;

/// Checks that `cov` is a covariance: finite, symmetric and positive semi-definite.
///
/// Symmetry and the smallest eigenvalue are judged relative to the matrix's own
/// scale (`1e-9 * max |c_jk|`), so millimetre-level covariances (1e-6 m^2) pass
/// while a real sign error fails. `what` names the offending item in the message.
pub fn validate_covariance(cov: &Matrix3, what: &str) -> Result<()> {
    if cov.iter().any(|c| !c.is_finite()) {
        return Err(Error::invalid(format!(
            "{what}: covariance has a NaN or infinite entry"
        )));
    }
    let scale = cov.amax();
    let tol = 1e-9 * scale.max(Real::MIN_POSITIVE);
    if (cov - cov.transpose()).amax() > tol {
        return Err(Error::invalid(format!(
            "{what}: covariance is not symmetric"
        )));
    }
    let min_eig = cov.symmetric_eigenvalues().min();
    if min_eig < -tol {
        return Err(Error::invalid(format!(
            "{what}: covariance is not positive semi-definite (smallest eigenvalue {min_eig:e})"
        )));
    }
    Ok(())
}

/// A factor `L` with `L L^T = cov`, so that `||L^T v|| = sqrt(v^T cov v)`.
///
/// The Cholesky factor when `cov` is positive definite (closed form, a few
/// square roots; backward stable, so `L L^T` reproduces `cov` to rounding as
/// the eigen-decomposition does); otherwise from the eigen-decomposition
/// (`L = V sqrt(Lambda)`), which exists for singular (rank-deficient)
/// covariances too, with eigenvalues that round below zero clamped to zero.
/// Any factor gives the same `||L^T v||`.
pub fn covariance_factor(cov: &Matrix3) -> Matrix3 {
    if let Some(chol) = cov.cholesky() {
        return chol.l();
    }
    let eig = cov.symmetric_eigen();
    let sqrt_vals = eig.eigenvalues.map(|l| l.max(0.0).sqrt());
    eig.eigenvectors * Matrix3::from_diagonal(&sqrt_vals)
}

/// The largest standard deviation along any direction: `sqrt(lambda_max(cov))`.
pub fn max_std(cov: &Matrix3) -> Real {
    cov.symmetric_eigenvalues().max().max(0.0).sqrt()
}

/// The smallest standard deviation along any direction: `sqrt(lambda_min(cov))`.
pub fn min_std(cov: &Matrix3) -> Real {
    cov.symmetric_eigenvalues().min().max(0.0).sqrt()
}

/// `sqrt(v^T cov v)`, the standard deviation of the projection on `v` (times `|v|`).
pub(crate) fn directional_std_of(cov: &Matrix3, v: &Vector3) -> Real {
    v.dot(&(cov * v)).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_psd_and_rejects_others() {
        let ok = Matrix3::new(4e-6, 1e-6, 0.0, 1e-6, 2e-6, 0.0, 0.0, 0.0, 0.0);
        validate_covariance(&ok, "x").unwrap();
        let asym = Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let e = validate_covariance(&asym, "point 3").unwrap_err();
        assert!(e.to_string().contains("point 3") && e.to_string().contains("symmetric"));
        let neg = Matrix3::from_diagonal(&Vector3::new(1.0, -0.1, 1.0));
        assert!(validate_covariance(&neg, "p")
            .unwrap_err()
            .to_string()
            .contains("positive semi-definite"));
        let nan = Matrix3::from_diagonal(&Vector3::new(1.0, f64::NAN, 1.0));
        assert!(validate_covariance(&nan, "p").is_err());
    }

    #[test]
    fn factor_reproduces_covariance_even_when_singular() {
        let c = Matrix3::new(2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0);
        let l = covariance_factor(&c);
        assert!((l * l.transpose() - c).amax() < 1e-12);
        let v = Vector3::new(0.3, -1.0, 2.0);
        assert!(((l.transpose() * v).norm() - directional_std_of(&c, &v)).abs() < 1e-12);
        assert!((max_std(&c) - 3f64.sqrt()).abs() < 1e-12);
    }
}
