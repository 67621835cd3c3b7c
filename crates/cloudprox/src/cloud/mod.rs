//! Point clouds with per-point uncertainty, and rigid poses.

mod from_mesh;
mod point_cloud;
mod pose;

pub use point_cloud::{PointCloud, MAX_COORDINATE};
pub(crate) use pose::validate_pose;
pub use pose::{pose_from_matrix, pose_to_matrix};
