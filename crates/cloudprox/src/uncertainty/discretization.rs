//! Discretization error: how sparsely the surface around each point was sampled.

use rayon::prelude::*;

use crate::bvh::{Bvh, BvhWorkspace};
use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Vector3};
use crate::Real;

/// Settings of the k-nearest-neighbour discretization estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscretizationSettings {
    /// Number of neighbours `k` (FCL used 10).
    pub k: usize,
    /// The Gaussian weight is `exp(-d^2 / s^2)` with `s = weight_scale * d_k`, `d_k`
    /// the distance to the k-th neighbour (FCL: 2).
    pub weight_scale: Real,
}

impl Default for DiscretizationSettings {
    fn default() -> Self {
        Self {
            k: 10,
            weight_scale: 2.0,
        }
    }
}

impl DiscretizationSettings {
    /// Checks `k >= 2` and a finite positive `weight_scale`.
    pub fn validate(&self) -> Result<()> {
        if self.k < 2 {
            return Err(Error::invalid(format!(
                "discretization k must be >= 2, got {}",
                self.k
            )));
        }
        if !(self.weight_scale.is_finite() && self.weight_scale > 0.0) {
            return Err(Error::invalid(format!(
                "discretization weight_scale must be finite and > 0, got {}",
                self.weight_scale
            )));
        }
        Ok(())
    }
}

/// The discretization covariance of every point, from its `k` nearest neighbours.
///
/// For point `i` with neighbours `j` at distances `d_j` (itself included), weights
/// `w_j = exp(-d_j^2 / s^2)` with `s = weight_scale * d_k` (distances, not squared
/// distances as FCL's code had), the weighted scatter of the neighbourhood about its
/// weighted mean is
/// `S_i = sum_j w_j (x_j - m)(x_j - m)^T / sum_j w_j`.
/// Part of that scatter is the sensor noise of the neighbours themselves: in the
/// normal direction of a flat, densely sampled surface `S_i` is exactly the sensor
/// covariance. Counting it again would inflate the noise, so the sensor covariance
/// is subtracted and the result projected back onto the PSD cone:
/// `Sigma_disc,i = psd(S_i - Sigma_sensor,i)`. What remains is the spread of the
/// surface patch a sample stands for (tangential) plus any curvature it spans.
///
/// `sensor` holds the sensor covariances (same length as `points`); clouds with
/// fewer than `k + 1` points use all points.
pub fn discretization_covariances(
    points: &[Point3],
    sensor: &[Matrix3],
    bvh: &Bvh,
    settings: &DiscretizationSettings,
) -> Result<Vec<Matrix3>> {
    settings.validate()?;
    if sensor.len() != points.len() {
        return Err(Error::Shape {
            what: "sensor covariances".into(),
            expected: points.len(),
            got: sensor.len(),
        });
    }
    if points.len() < 2 {
        return Ok(vec![Matrix3::zeros(); points.len()]);
    }
    let k = settings.k.min(points.len() - 1);
    let out = points
        .par_iter()
        .zip(sensor)
        .map_init(
            || (BvhWorkspace::default(), Vec::with_capacity(k + 1)),
            |(workspace, neighbours), (x, sensor_i)| {
                bvh.nearest_k(points, x, k + 1, workspace, neighbours);
                let d_k = neighbours.last().map_or(0.0, |&(d2, _)| d2.sqrt());
                if d_k <= 0.0 {
                    return Matrix3::zeros();
                }
                let s = settings.weight_scale * d_k;
                let mut wsum = 0.0;
                let mut mean = Vector3::zeros();
                for &(d2, j) in neighbours.iter() {
                    let w = (-d2 / (s * s)).exp();
                    wsum += w;
                    mean += w * points[j as usize].coords;
                }
                mean /= wsum;
                let mut scatter = Matrix3::zeros();
                for &(d2, j) in neighbours.iter() {
                    let w = (-d2 / (s * s)).exp();
                    let o = points[j as usize].coords - mean;
                    scatter += w * o * o.transpose();
                }
                scatter /= wsum;
                project_psd(&(scatter - sensor_i))
            },
        )
        .collect();
    Ok(out)
}

/// The nearest positive semi-definite matrix (negative eigenvalues set to zero).
fn project_psd(m: &Matrix3) -> Matrix3 {
    let sym = 0.5 * (m + m.transpose());
    let eig = sym.symmetric_eigen();
    let vals = eig.eigenvalues.map(|l| l.max(0.0));
    let v = eig.eigenvectors;
    let c = v * Matrix3::from_diagonal(&vals) * v.transpose();
    0.5 * (c + c.transpose())
}
