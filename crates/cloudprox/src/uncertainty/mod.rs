//! Uncertainty of a point: `Sigma_i = Sigma_sensor,i + Sigma_disc,i`.
//!
//! - [`NoiseModel`]: the sensor part (position error): isotropic, per point, full,
//!   or from a range sensor's model ([`sensor`]: depth camera, stereo, lidar);
//! - [`discretization_covariances`]: the discretization part, how sparsely the
//!   surface was sampled, from the k nearest neighbours;
//! - [`RobustModel`]: the robustness radius `r_i` of the chance constraint;
//! - [`validate_covariance`] and [`covariance_factor`]: checks and square roots.

mod covariance;
mod discretization;
mod noise;
mod robust;
pub mod sensor;

pub(crate) use covariance::directional_std_of;
pub use covariance::{covariance_factor, max_std, min_std, validate_covariance};
pub use discretization::{discretization_covariances, DiscretizationSettings};
pub use noise::NoiseModel;
pub use robust::RobustModel;
pub use sensor::{ray_covariances, DepthCamera, Lidar, SensorModel, StereoCamera, Viewpoint};
