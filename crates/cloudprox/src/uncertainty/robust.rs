//! The robustness radius `r_i` of the robust classifier's chance constraints.

use crate::error::{Error, Result};
use crate::probability::normal_quantile;
use crate::Real;

/// Which noise distribution the chance constraint `P(c_i f(x_i') >= 0) >= eta`
/// is made to hold for (Shivaswamy, Bhattacharyya & Smola, JMLR 2006).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RobustModel {
    /// Gaussian noise with the point's covariance: `r = Phi^-1(eta)`.
    #[default]
    Gaussian,
    /// Any distribution with that mean and covariance (multivariate Chebyshev):
    /// `r = sqrt(eta / (1 - eta))`. Far more conservative.
    Chebyshev,
}

crate::names::named_options!(RobustModel, "robust_model", {
    Gaussian => "gaussian",
    Chebyshev => "chebyshev",
});

impl RobustModel {
    /// The radius `r` for confidence `eta` in `[0.5, 1)`.
    pub fn radius(self, eta: Real) -> Result<Real> {
        if !(0.5..1.0).contains(&eta) {
            return Err(Error::invalid(format!(
                "robust_eta must be in [0.5, 1), got {eta}"
            )));
        }
        Ok(match self {
            RobustModel::Gaussian => normal_quantile(eta),
            RobustModel::Chebyshev => (eta / (1.0 - eta)).sqrt(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radii_follow_their_formulas() {
        assert!(RobustModel::Gaussian.radius(0.5).unwrap().abs() < 1e-12);
        assert!(
            (RobustModel::Gaussian.radius(0.975).unwrap() - 1.959_963_984_540_054).abs() < 1e-9
        );
        assert!((RobustModel::Chebyshev.radius(0.9).unwrap() - 3.0).abs() < 1e-12);
        assert!(RobustModel::Gaussian.radius(1.0).is_err());
        assert!(RobustModel::Chebyshev.radius(0.2).is_err());
        for m in [RobustModel::Gaussian, RobustModel::Chebyshev] {
            assert_eq!(RobustModel::from_name(m.name()), Some(m));
        }
        assert_eq!(RobustModel::from_name("student"), None);
    }
}
