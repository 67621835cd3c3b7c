//! Python bindings of the cloudprox core crate, imported as `cloudprox._native`.
//!
//! One file per concern:
//!
//! | file | what |
//! |---|---|
//! | `macros.rs` | `stats_class!` (a statistics class from one list of its counters), `tuple_class!` (a class that unpacks as the tuple of its fields) |
//! | `error.rs` | exception hierarchy, core error and panic mapping |
//! | `convert.rs` | numpy <-> nalgebra conversion and shape checks |
//! | `cloud.rs` | `PointCloud` |
//! | `request.rs` | `CollisionRequest`: the query options |
//! | `collide.rs` | `collide`, `collide_many`, `collide_along` |
//! | `result.rs` | `CollisionResult`, `ContactPatch`, `QueryStats` |
//! | `filter.rs` | sensor-cloud filters: crop box, voxel, outliers, shadow, self |
//! | `io.rs` | `CloudFile`, reading and writing point-cloud and mesh files |
//! | `mesh.rs` | `Mesh`, `ExactShape`, exact mesh-vs-mesh queries |
//! | `pose.rs` | pose constructors (translation, quaternion, rpy, rotation vector, look-at, random) |
//! | `sample.rs` | seeded synthetic shapes |
//! | `scan.rs` | `scan_to_cloud`: the core's scan pipeline (noise, filter steps, cloud) |
//! | `sensor.rs` | sensor noise models `DepthCamera`, `StereoCamera`, `Lidar` |
//! | `side.rs` | a query side: a cloud, or a mesh sampled into one |
//! | `exact_side.rs` | which query a pair of sides takes: two clouds, or an exact mesh against a cloud |
//! | `robot.rs` | `Robot`, `collide_robot`, `collide_robot_many`, `check_motion` |
//! | `robot_request.rs` | `RobotRequest`, `MotionRequest`: the robot queries' options |
//!
//! The Python package `cloudprox` re-exports everything (the filters, pose
//! constructors and synthetic samplers through its `filters`, `pose` and
//! `synthetic` modules); `_native.pyi` is the stub.
#![deny(unused_qualifications)]
#![deny(clippy::unwrap_used, clippy::expect_used)]

use pyo3::prelude::*;

#[macro_use]
mod macros;
mod cloud;
mod collide;
mod convert;
mod distance;
mod error;
mod exact_side;
mod filter;
mod io;
mod mesh;
mod occlusion;
mod pose;
mod request;
mod result;
mod robot;
mod robot_request;
mod sample;
mod scan;
mod sensor;
mod side;
mod signed_distance;

/// The compiled part of cloudprox.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    error::register(m)?;
    m.add_class::<cloud::PyPointCloud>()?;
    m.add_class::<result::PyCollisionResult>()?;
    m.add_class::<result::PyContactPatch>()?;
    m.add_function(wrap_pyfunction!(collide::collide, m)?)?;
    m.add_function(wrap_pyfunction!(collide::collide_many, m)?)?;
    m.add_function(wrap_pyfunction!(collide::collide_along, m)?)?;
    m.add_function(wrap_pyfunction!(collide::facing_pairs, m)?)?;
    m.add_function(wrap_pyfunction!(distance::distance, m)?)?;
    m.add_class::<distance::PyDistanceResult>()?;
    m.add_class::<request::PyCollisionRequest>()?;
    m.add_class::<result::PyQueryStats>()?;
    m.add_class::<mesh::PyMesh>()?;
    m.add_class::<mesh::PyMeshSample>()?;
    m.add_class::<mesh::PyProximity>()?;
    m.add_class::<mesh::PyProximityBatch>()?;
    m.add_class::<filter::PyVoxels>()?;
    m.add_class::<filter::PySelfFilter>()?;
    m.add_class::<occlusion::PyOcclusion>()?;
    m.add_function(wrap_pyfunction!(filter::crop_box, m)?)?;
    m.add_function(wrap_pyfunction!(filter::voxel_downsample, m)?)?;
    m.add_function(wrap_pyfunction!(filter::statistical_outlier_removal, m)?)?;
    m.add("SOR_DEFAULT_K", cloudprox::filter::SOR_DEFAULT_K)?;
    m.add(
        "SOR_DEFAULT_STD_RATIO",
        cloudprox::filter::SOR_DEFAULT_STD_RATIO,
    )?;
    m.add_function(wrap_pyfunction!(filter::shadow_filter, m)?)?;
    m.add_class::<io::PyCloudFile>()?;
    m.add_function(wrap_pyfunction!(io::read_point_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(io::write_point_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_mesh_counted, m)?)?;
    m.add_function(wrap_pyfunction!(io::write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(io::parse_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_pointcloud2, m)?)?;
    m.add_function(wrap_pyfunction!(io::write_pointcloud2, m)?)?;
    m.add_class::<scan::PyScanStep>()?;
    m.add_class::<scan::PyScanResult>()?;
    m.add_function(wrap_pyfunction!(scan::scan_to_cloud, m)?)?;
    m.add_class::<sensor::PyDepthCamera>()?;
    m.add_class::<sensor::PyStereoCamera>()?;
    m.add_class::<sensor::PyLidar>()?;
    m.add_class::<mesh::PyExactShape>()?;
    m.add_function(wrap_pyfunction!(mesh::exact_proximity, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::exact_proximity_many_py, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::exact_intersects_many_py, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::exact_time_of_impact_many_py, m)?)?;
    m.add_function(wrap_pyfunction!(sensor::ray_covariances, m)?)?;
    m.add_function(wrap_pyfunction!(pose::pose_from_translation, m)?)?;
    m.add_function(wrap_pyfunction!(pose::pose_from_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(pose::pose_from_rpy, m)?)?;
    m.add_function(wrap_pyfunction!(pose::pose_from_rotation_vector, m)?)?;
    m.add_function(wrap_pyfunction!(pose::pose_look_at, m)?)?;
    m.add_function(wrap_pyfunction!(pose::random_rotations, m)?)?;
    m.add_function(wrap_pyfunction!(sample::sample_sphere, m)?)?;
    m.add_function(wrap_pyfunction!(sample::sample_box_surface, m)?)?;
    m.add_function(wrap_pyfunction!(sample::add_noise, m)?)?;
    m.add_class::<robot::PyRobot>()?;
    m.add_class::<robot::PyLinkCollision>()?;
    m.add_class::<robot::PyRobotCollisionResult>()?;
    m.add_class::<robot::PyTargetCollision>()?;
    m.add_class::<robot::PyRobotStats>()?;
    m.add_class::<robot::PyRobotBatchResult>()?;
    m.add_class::<robot::PyMotionResult>()?;
    m.add_class::<robot_request::PyRobotRequest>()?;
    m.add_class::<robot_request::PyMotionRequest>()?;
    m.add_function(wrap_pyfunction!(robot::collide_robot, m)?)?;
    m.add_function(wrap_pyfunction!(robot::collide_robot_many, m)?)?;
    m.add_function(wrap_pyfunction!(robot::check_motion, m)?)?;
    m.add_class::<signed_distance::PyMeshDistance>()?;
    m.add_class::<signed_distance::PyDistanceField>()?;
    Ok(())
}
