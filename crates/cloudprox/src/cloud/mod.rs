//! Point clouds with per-point uncertainty and rigid poses (a scan file's
//! points become a cloud through [`crate::scan::ScanPipeline`]).

mod from_mesh;
mod point_cloud;
mod pose;

pub use point_cloud::{PointCloud, MAX_COORDINATE, MAX_SEGMENTATIONS};
pub(crate) use pose::validate_pose;
pub use pose::{
    pose_from_matrix, pose_from_quaternion, pose_from_rotation_vector, pose_from_rpy,
    pose_from_translation, pose_look_at, pose_to_matrix, random_rotations, unit_quaternion,
};
