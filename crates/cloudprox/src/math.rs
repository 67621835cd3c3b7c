//! Point, vector, matrix and pose aliases used throughout the crate.

use crate::Real;

/// A point in 3D space (metres).
pub type Point3 = nalgebra::Point3<Real>;
/// A vector in 3D space.
pub type Vector3 = nalgebra::Vector3<Real>;
/// A 3x3 matrix (covariances are in metres squared).
pub type Matrix3 = nalgebra::Matrix3<Real>;
/// A 4x4 homogeneous matrix.
pub type Matrix4 = nalgebra::Matrix4<Real>;
/// A rigid pose (rotation then translation), mapping an object's own frame to the world.
pub type Pose = nalgebra::Isometry3<Real>;
