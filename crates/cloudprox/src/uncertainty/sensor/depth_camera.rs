//! Structured-light depth camera (Kinect v1-like).

use crate::error::Result;
use crate::uncertainty::sensor::{check_param, Ray};
use crate::Real;

/// Structured-light depth camera: the axial (depth) error grows with the square
/// of depth, the lateral error linearly.
///
/// - axial: `sigma_z(z) = axial_offset + axial_quadratic * (z - axial_depth0)^2`;
/// - along the ray: `sigma_z(z) * r / z` (a depth error moves the point along its ray);
/// - lateral: `sigma_px * z / focal_px` (a pixel error at depth `z`).
///
/// The default is the fit of Khoshelham & Elberink, "Accuracy and resolution of
/// Kinect depth data for indoor mapping applications", Sensors 12(2), 2012:
/// `sigma_z = 1.425e-3 z^2` (metres): 1.4 mm at 1 m, 3.6 cm at 5 m,
/// with the Kinect v1's focal length of 580 px and a lateral error of 0.8 px
/// (Nguyen, Izadi & Lovell, "Modeling Kinect sensor noise for improved 3D
/// reconstruction and tracking", 3DIMPVT 2012, Fig. 7: `sigma_L` about 0.8 px).
/// [`DepthCamera::nguyen_2012`] is the fit of that paper
/// (`sigma_z = 0.0012 + 0.0019 (z - 0.4)^2`, for surfaces facing the camera).
///
/// **What averaging gains.** The camera measures disparity in steps of
/// `disparity_step_px` (1/8 px for the Kinect v1, baseline 7.5 cm): depth comes
/// in steps of `dz(z) = z^2 disparity_step_px / (focal_px baseline_m)`, 2.9 mm at
/// 1 m and 11.5 mm at 2 m. Neighbouring points of one surface round the same
/// way, so that share of the error (variance `dz^2 / 12`) is common to the points
/// of a surface element and does not average away:
/// [`DepthCamera::noise_correlation`] is its share of the axial variance (about
/// 0.3 for both presets over 1-3 m), and a cloud seen by this camera builds its
/// surface elements with it ([`crate::element::ElementSettings::noise_correlation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthCamera {
    /// Constant part of the axial standard deviation (metres).
    pub axial_offset: Real,
    /// Quadratic coefficient of the axial standard deviation (1/metre).
    pub axial_quadratic: Real,
    /// Depth at which the quadratic term vanishes (metres).
    pub axial_depth0: Real,
    /// Focal length (pixels).
    pub focal_px: Real,
    /// Lateral standard deviation in the image (pixels).
    pub sigma_px: Real,
    /// Baseline between projector and camera (metres).
    pub baseline_m: Real,
    /// Resolution of the measured disparity (pixels; 0: continuous).
    pub disparity_step_px: Real,
}

/// The Kinect v1's projector-camera baseline (metres).
pub const KINECT_BASELINE_M: Real = 0.075;
/// The Kinect v1's disparity resolution: 1/8 pixel (its disparity is an
/// integer in eighths of a pixel).
pub const KINECT_DISPARITY_STEP_PX: Real = 0.125;

impl Default for DepthCamera {
    fn default() -> Self {
        Self::khoshelham_2012()
    }
}

impl DepthCamera {
    /// Khoshelham & Elberink (2012): `sigma_z = 1.425e-3 z^2`, focal 580 px,
    /// lateral 0.8 px. The default.
    pub fn khoshelham_2012() -> Self {
        Self {
            axial_offset: 0.0,
            axial_quadratic: 1.425e-3,
            axial_depth0: 0.0,
            focal_px: 580.0,
            sigma_px: 0.8,
            baseline_m: KINECT_BASELINE_M,
            disparity_step_px: KINECT_DISPARITY_STEP_PX,
        }
    }

    /// Nguyen, Izadi & Lovell (2012): `sigma_z = 0.0012 + 0.0019 (z - 0.4)^2`,
    /// lateral 0.8 px, focal 580 px.
    pub fn nguyen_2012() -> Self {
        Self {
            axial_offset: 0.0012,
            axial_quadratic: 0.0019,
            axial_depth0: 0.4,
            focal_px: 580.0,
            sigma_px: 0.8,
            baseline_m: KINECT_BASELINE_M,
            disparity_step_px: KINECT_DISPARITY_STEP_PX,
        }
    }

    /// Checks every parameter, naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_param("axial_offset", self.axial_offset, true)?;
        check_param("axial_quadratic", self.axial_quadratic, true)?;
        check_param("axial_depth0", self.axial_depth0, true)?;
        check_param("focal_px", self.focal_px, false)?;
        check_param("sigma_px", self.sigma_px, true)?;
        check_param("baseline_m", self.baseline_m, false)?;
        check_param("disparity_step_px", self.disparity_step_px, true)
    }

    /// The depth step at depth `z` (metres): one disparity step,
    /// `z^2 disparity_step_px / (focal_px baseline_m)`.
    pub fn depth_step(&self, z: Real) -> Real {
        z * z * self.disparity_step_px / (self.focal_px * self.baseline_m)
    }

    /// The share of the axial variance at depth `z` that the points of one
    /// surface share: the depth quantization's `depth_step(z)^2 / 12` over
    /// `sigma_axial(z)^2`, at most 1.
    pub fn noise_correlation(&self, z: Real) -> Real {
        let q = self.depth_step(z).powi(2) / 12.0;
        let s = self.sigma_axial(z).powi(2);
        if q <= 0.0 {
            0.0
        } else if s <= q {
            1.0
        } else {
            q / s
        }
    }

    /// The axial (depth) standard deviation at depth `z` (metres).
    pub fn sigma_axial(&self, z: Real) -> Real {
        let dz = z - self.axial_depth0;
        self.axial_offset + self.axial_quadratic * dz * dz
    }

    /// The lateral standard deviation at depth `z` (metres).
    pub fn sigma_lateral(&self, z: Real) -> Real {
        self.sigma_px * z / self.focal_px
    }

    pub(crate) fn sigmas(&self, ray: &Ray) -> (Real, Real) {
        (
            self.sigma_axial(ray.depth) * ray.range / ray.depth,
            self.sigma_lateral(ray.depth),
        )
    }
}
