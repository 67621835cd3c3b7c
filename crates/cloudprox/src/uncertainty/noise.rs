//! Sensor noise (position error) models.

use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3};
use crate::uncertainty::sensor::{SensorModel, Viewpoint};
use crate::uncertainty::validate_covariance;
use crate::Real;

/// How the sensor part of each point's covariance is obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum NoiseModel {
    /// The same isotropic standard deviation `sigma` (metres) for every point:
    /// `Sigma_i = sigma^2 I`.
    Isotropic(Real),
    /// One isotropic standard deviation per point.
    PerPointSigma(Vec<Real>),
    /// A full 3x3 covariance per point (metres squared).
    Full(Vec<Matrix3>),
    /// A range sensor's model seen from a viewpoint: anisotropic along each
    /// point's viewing ray (see [`crate::uncertainty::sensor`]).
    Sensor(SensorModel, Viewpoint),
}

impl NoiseModel {
    /// The per-point sensor covariances for `points`, validated.
    ///
    /// Errors name the first offending point: a negative or non-finite sigma, a
    /// covariance that is not symmetric PSD, or a count that differs from the points'.
    pub fn covariances(&self, points: &[Point3]) -> Result<Vec<Matrix3>> {
        let check_sigma = |s: Real, i: Option<usize>| -> Result<()> {
            if s.is_finite() && s >= 0.0 {
                Ok(())
            } else {
                let at = i.map_or(String::new(), |i| format!(" of point {i}"));
                Err(Error::invalid(format!(
                    "sigma{at} must be finite and >= 0, got {s}"
                )))
            }
        };
        match self {
            NoiseModel::Isotropic(s) => {
                check_sigma(*s, None)?;
                Ok(vec![Matrix3::identity() * (s * s); points.len()])
            }
            NoiseModel::PerPointSigma(sigmas) => {
                if sigmas.len() != points.len() {
                    return Err(Error::Shape {
                        what: "per-point sigmas".into(),
                        expected: points.len(),
                        got: sigmas.len(),
                    });
                }
                sigmas
                    .iter()
                    .enumerate()
                    .map(|(i, &s)| {
                        check_sigma(s, Some(i))?;
                        Ok(Matrix3::identity() * (s * s))
                    })
                    .collect()
            }
            NoiseModel::Full(covs) => {
                if covs.len() != points.len() {
                    return Err(Error::Shape {
                        what: "per-point covariances".into(),
                        expected: points.len(),
                        got: covs.len(),
                    });
                }
                for (i, c) in covs.iter().enumerate() {
                    validate_covariance(c, &format!("point {i}"))?;
                }
                Ok(covs.clone())
            }
            NoiseModel::Sensor(model, viewpoint) => model.covariances(points, viewpoint),
        }
    }
}
