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
}

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
        }
    }

    /// Checks every parameter, naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_param("axial_offset", self.axial_offset, true)?;
        check_param("axial_quadratic", self.axial_quadratic, true)?;
        check_param("axial_depth0", self.axial_depth0, true)?;
        check_param("focal_px", self.focal_px, false)?;
        check_param("sigma_px", self.sigma_px, true)
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
