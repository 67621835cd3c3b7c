//! Stereo camera.

use crate::error::Result;
use crate::uncertainty::sensor::{check_param, Ray};
use crate::Real;

/// Stereo camera: depth from disparity, `z = f B / d`.
///
/// First-order error propagation of a disparity error `sigma_d` gives
/// `sigma_z = |dz/dd| sigma_d = z^2 sigma_d / (f B)` (focal length `f` in pixels,
/// baseline `B` in metres); along the ray this is `sigma_z r / z`. The lateral
/// error of a pixel error `sigma_px` at depth `z` is `z sigma_px / f`.
/// See e.g. Gallup et al., "Variable baseline/resolution stereo", CVPR 2008, or
/// any stereo text (Hartley & Zisserman). Defaults: an Intel RealSense
/// D435-like camera at 848x480: focal about 430 px, baseline 50 mm, subpixel disparity
/// noise 0.08 px (Intel's tuning guide quotes a subpixel RMS of about 0.08 px
/// for a well-textured target), lateral 0.5 px.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoCamera {
    /// Focal length (pixels).
    pub focal_px: Real,
    /// Baseline between the two cameras (metres).
    pub baseline: Real,
    /// Standard deviation of the disparity (pixels).
    pub sigma_disparity_px: Real,
    /// Lateral standard deviation in the image (pixels).
    pub sigma_px: Real,
}

impl Default for StereoCamera {
    fn default() -> Self {
        Self {
            focal_px: 430.0,
            baseline: 0.05,
            sigma_disparity_px: 0.08,
            sigma_px: 0.5,
        }
    }
}

impl StereoCamera {
    /// Checks every parameter, naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_param("focal_px", self.focal_px, false)?;
        check_param("baseline", self.baseline, false)?;
        check_param("sigma_disparity_px", self.sigma_disparity_px, true)?;
        check_param("sigma_px", self.sigma_px, true)
    }

    /// The depth standard deviation at depth `z`: `z^2 sigma_d / (f B)`.
    pub fn sigma_axial(&self, z: Real) -> Real {
        z * z * self.sigma_disparity_px / (self.focal_px * self.baseline)
    }

    /// The lateral standard deviation at depth `z`: `z sigma_px / f`.
    pub fn sigma_lateral(&self, z: Real) -> Real {
        z * self.sigma_px / self.focal_px
    }

    pub(crate) fn sigmas(&self, ray: &Ray) -> (Real, Real) {
        (
            self.sigma_axial(ray.depth) * ray.range / ray.depth,
            self.sigma_lateral(ray.depth),
        )
    }
}
