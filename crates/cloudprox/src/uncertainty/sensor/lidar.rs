//! Laser range finder.

use crate::error::Result;
use crate::uncertainty::sensor::{check_param, Ray};
use crate::Real;

/// Laser range finder (time of flight): a range error roughly constant over the
/// working range, and an angular spread across the beam.
///
/// - along the ray: `sigma_range`;
/// - across it: `r * sigma_angle` at range `r`.
///
/// Defaults from the Hokuyo UTM-30LX datasheet: accuracy ±30 mm over 0.1–10 m
/// and repeatability `sigma < 10 mm`, so `sigma_range = 0.01` m (±30 mm as the
/// 3-sigma bound); angular resolution 0.25°, whose uniform quantization error has
/// standard deviation `0.25° / sqrt(12)`, about 1.26 mrad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lidar {
    /// Range standard deviation (metres).
    pub sigma_range: Real,
    /// Angular standard deviation across the beam (radians).
    pub sigma_angle: Real,
}

impl Default for Lidar {
    fn default() -> Self {
        Self {
            sigma_range: 0.01,
            sigma_angle: 0.25_f64.to_radians() / 12f64.sqrt(),
        }
    }
}

impl Lidar {
    /// Checks every parameter, naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_param("sigma_range", self.sigma_range, true)?;
        check_param("sigma_angle", self.sigma_angle, true)
    }

    pub(crate) fn sigmas(&self, ray: &Ray) -> (Real, Real) {
        (self.sigma_range, ray.range * self.sigma_angle)
    }
}
