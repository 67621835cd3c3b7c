//! Sensor noise models: per-point covariances anisotropic along the viewing ray.
//!
//! A range sensor measures each point along the ray from its origin; its error
//! along that ray (axial, from the range or depth measurement) differs from its
//! error across it (lateral, from the pixel or beam direction). Every model here
//! gives, for a point `p` seen from origin `o` with unit ray `u = (p - o) / |p - o|`,
//!
//! ```text
//! Sigma = sigma_ray^2 u u^T + sigma_lat^2 (I - u u^T)
//! ```
//!
//! | model | axial | lateral | source |
//! |---|---|---|---|
//! | [`DepthCamera`] (structured light) | `a + b (z - z0)^2` | `sigma_px z / f` | Khoshelham & Elberink 2012; Nguyen, Izadi & Lovell 2012 |
//! | [`StereoCamera`] | `z^2 sigma_d / (f B)` | `sigma_px z / f` | triangulation, `z = f B / d` |
//! | [`Lidar`] (laser range finder) | `sigma_range` | `r sigma_angle` | Hokuyo UTM-30LX datasheet |
//!
//! Cameras measure depth `z` along their optical axis, not range `r = |p - o|`.
//! A depth error `dz` moves the point along its ray by `dz r / z`, so the ray
//! standard deviation is `sigma_z(z) r / z`. The optical axis is the sensor
//! frame's `+z` ([`Viewpoint::from_pose`], the PCL/ROS optical-frame convention);
//! when only an origin is known, `z = r` (exact on the axis, and within 6% at
//! 20° off axis for the axial law `z^2`).
//!
//! The discretization part (how sparsely the surface was sampled) is added on top
//! by [`crate::cloud::PointCloud::with_discretization`].

mod depth_camera;
mod lidar;
mod stereo;

pub use depth_camera::{DepthCamera, KINECT_BASELINE_M, KINECT_DISPARITY_STEP_PX};
pub use lidar::Lidar;
pub use stereo::StereoCamera;

use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::Real;

/// Where a sensor sits: its origin and, when known, its optical axis (unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewpoint {
    /// The sensor's optical centre, in the cloud's frame (metres).
    pub origin: Point3,
    /// The direction the sensor looks along (unit vector), if known. Without it
    /// the depth of a point is taken to be its range.
    pub axis: Option<Vector3>,
}

impl Viewpoint {
    /// A viewpoint at `origin` with an unknown axis.
    pub fn at(origin: Point3) -> Self {
        Self { origin, axis: None }
    }

    /// The viewpoint of a sensor whose frame is `pose` (sensor to cloud frame),
    /// looking along the frame's `+z` axis (as a PCD `VIEWPOINT` or a ROS optical
    /// frame gives it).
    pub fn from_pose(pose: &Pose) -> Self {
        Self {
            origin: Point3::from(pose.translation.vector),
            axis: Some(pose.rotation * Vector3::z()),
        }
    }

    /// Checks a finite origin and a finite, non-zero axis (normalized here).
    pub fn validated(&self) -> Result<Self> {
        if !self.origin.coords.iter().all(|c| c.is_finite()) {
            return Err(Error::invalid(format!(
                "sensor origin must be finite, got {:?}",
                self.origin.coords.as_slice()
            )));
        }
        let axis = match self.axis {
            None => None,
            Some(a) => {
                let n = a.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(Error::invalid(format!(
                        "sensor axis must be a finite non-zero vector, got {:?}",
                        a.as_slice()
                    )));
                }
                Some(a / n)
            }
        };
        Ok(Self {
            origin: self.origin,
            axis,
        })
    }
}

/// A range sensor's noise model (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SensorModel {
    /// Structured-light depth camera (Kinect v1-like).
    DepthCamera(DepthCamera),
    /// Stereo camera.
    Stereo(StereoCamera),
    /// Laser range finder.
    Lidar(Lidar),
}

/// The geometry of one measured point as the noise laws need it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ray {
    /// Unit direction from the origin to the point.
    pub dir: Vector3,
    /// Range `|p - o|` (metres).
    pub range: Real,
    /// Depth along the optical axis (metres); the range when the axis is unknown.
    pub depth: Real,
}

impl SensorModel {
    /// Checks every parameter (finite, in range), naming the first bad one.
    pub fn validate(&self) -> Result<()> {
        match self {
            SensorModel::DepthCamera(m) => m.validate(),
            SensorModel::Stereo(m) => m.validate(),
            SensorModel::Lidar(m) => m.validate(),
        }
    }

    /// Standard deviations `(along the ray, across it)` for one ray.
    fn sigmas(&self, ray: &Ray) -> (Real, Real) {
        match self {
            SensorModel::DepthCamera(m) => m.sigmas(ray),
            SensorModel::Stereo(m) => m.sigmas(ray),
            SensorModel::Lidar(m) => m.sigmas(ray),
        }
    }

    /// The correlation of the noise between the points of one surface element
    /// ([`crate::element::ElementSettings::noise_correlation`]): for a depth
    /// camera the median over `points` of [`DepthCamera::noise_correlation`] at
    /// each point's depth; 0 (independent) for the stereo camera and the laser.
    ///
    /// # Errors
    /// As [`SensorModel::covariances`].
    pub fn noise_correlation(&self, points: &[Point3], viewpoint: &Viewpoint) -> Result<Real> {
        let SensorModel::DepthCamera(cam) = self else {
            return Ok(0.0);
        };
        self.validate()?;
        let vp = viewpoint.validated()?;
        let mut rho = points
            .iter()
            .enumerate()
            .map(|(i, p)| Ok(cam.noise_correlation(ray_of(i, p, &vp)?.depth)))
            .collect::<Result<Vec<Real>>>()?;
        if rho.is_empty() {
            return Ok(0.0);
        }
        let mid = rho.len() / 2;
        Ok(*rho.select_nth_unstable_by(mid, Real::total_cmp).1)
    }

    /// The sensor covariance of every point seen from `viewpoint`.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for a bad parameter or viewpoint, a non-finite
    /// point, a point at the origin, or (axis known) a point not in front of the
    /// sensor; the message names the point.
    pub fn covariances(&self, points: &[Point3], viewpoint: &Viewpoint) -> Result<Vec<Matrix3>> {
        self.validate()?;
        let vp = viewpoint.validated()?;
        points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let ray = ray_of(i, p, &vp)?;
                let (s_ray, s_lat) = self.sigmas(&ray);
                Ok(ray_covariance(&ray.dir, s_ray, s_lat))
            })
            .collect()
    }
}

/// The ray of point `i` from `vp` (validated).
pub(crate) fn ray_of(i: usize, p: &Point3, vp: &Viewpoint) -> Result<Ray> {
    let d = p - vp.origin;
    let range = d.norm();
    if !range.is_finite() {
        return Err(Error::invalid(format!(
            "point {i} has a NaN or infinite coordinate: {:?}",
            p.coords.as_slice()
        )));
    }
    if range == 0.0 {
        return Err(Error::invalid(format!(
            "point {i} lies at the sensor origin: it has no viewing ray"
        )));
    }
    let dir = d / range;
    let depth = match vp.axis {
        None => range,
        Some(axis) => {
            let z = d.dot(&axis);
            if z <= 0.0 {
                return Err(Error::invalid(format!(
                    "point {i} is not in front of the sensor (depth {z} m along its axis): \
                     check the sensor pose"
                )));
            }
            z
        }
    };
    Ok(Ray { dir, range, depth })
}

/// `s_ray^2 u u^T + s_lat^2 (I - u u^T)` for a unit `u`.
pub(crate) fn ray_covariance(u: &Vector3, s_ray: Real, s_lat: Real) -> Matrix3 {
    let uu = u * u.transpose();
    uu * (s_ray * s_ray) + (Matrix3::identity() - uu) * (s_lat * s_lat)
}

/// Checks that `value` is finite and `> 0` (or `>= 0` when `zero_ok`).
pub(crate) fn check_param(name: &str, value: Real, zero_ok: bool) -> Result<()> {
    let ok = value.is_finite() && (value > 0.0 || (zero_ok && value == 0.0));
    if ok {
        Ok(())
    } else {
        let bound = if zero_ok { ">= 0" } else { "> 0" };
        Err(Error::invalid(format!(
            "sensor parameter {name} must be finite and {bound}, got {value}"
        )))
    }
}

/// Covariances with fixed standard deviations along and across each point's
/// viewing ray from `viewpoint`: `sigma_ray^2 u u^T + sigma_lat^2 (I - u u^T)`,
/// the form every model of this module gives, with its laws left out (for a
/// noise level set by hand, such as an experiment's anisotropic noise).
///
/// # Errors
/// [`Error::InvalidInput`] for a negative or non-finite standard deviation, a
/// bad viewpoint, a non-finite point, a point at the origin, or (axis known) a
/// point not in front of the sensor; the message names the point.
pub fn ray_covariances(
    points: &[Point3],
    viewpoint: &Viewpoint,
    sigma_ray: Real,
    sigma_lat: Real,
) -> Result<Vec<Matrix3>> {
    check_param("sigma_ray", sigma_ray, true)?;
    check_param("sigma_lat", sigma_lat, true)?;
    let vp = viewpoint.validated()?;
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            Ok(ray_covariance(
                &ray_of(i, p, &vp)?.dir,
                sigma_ray,
                sigma_lat,
            ))
        })
        .collect()
}
