//! Pose constructors (wrapping `cloudprox::cloud::pose_*`): every one returns a
//! `(4, 4)` float64 homogeneous matrix; bad input raises `InvalidInputError`
//! naming the argument. Python re-exports them as `cloudprox.pose`.

use cloudprox::cloud::{
    pose_from_quaternion as core_quaternion, pose_from_rotation_vector as core_rotation_vector,
    pose_from_rpy as core_rpy, pose_from_translation as core_translation,
    pose_look_at as core_look_at, random_rotations as core_random_rotations,
};
use cloudprox::math::{Point3, Pose, Vector3};
use nalgebra::Translation3;
use numpy::{PyArray2, PyArray3};
use pyo3::prelude::*;

use crate::convert::{array4_from, pose_to_py, poses_to_py, vector3_from};
use crate::error::{invalid_input, CoreResultExt};

/// The most rotations `random_rotations` returns at once.
const MAX_ROTATIONS: i64 = 100_000_000;

fn translation_or_zero(translation: Option<&Bound<'_, PyAny>>) -> PyResult<Vector3> {
    translation.map_or(Ok(Vector3::zeros()), |t| vector3_from(t, "translation"))
}

/// The pure translation by `translation` `(3,)` (metres).
#[pyfunction]
#[pyo3(signature = (translation))]
pub fn pose_from_translation<'py>(
    py: Python<'py>,
    translation: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let t = vector3_from(translation, "translation")?;
    pose_to_py(py, &core_translation(&t).or_py(py)?)
}

/// Rotation by the quaternion `(w, x, y, z)` (scalar first; normalised), then
/// translation by `translation` (default zero).
#[pyfunction]
#[pyo3(signature = (quaternion, translation=None))]
pub fn pose_from_quaternion<'py>(
    py: Python<'py>,
    quaternion: &Bound<'py, PyAny>,
    translation: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = array4_from(quaternion, "quaternion")?;
    let t = translation_or_zero(translation)?;
    pose_to_py(py, &core_quaternion(&t, q).or_py(py)?)
}

/// Rotation by roll-pitch-yaw `(3,)` radians (ROS/URDF: about the fixed x, then
/// y, then z axes, `R = Rz(yaw) Ry(pitch) Rx(roll)`), then translation.
#[pyfunction]
#[pyo3(signature = (rpy, translation=None))]
pub fn pose_from_rpy<'py>(
    py: Python<'py>,
    rpy: &Bound<'py, PyAny>,
    translation: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = vector3_from(rpy, "rpy")?;
    let t = translation_or_zero(translation)?;
    pose_to_py(py, &core_rpy(&t, &a).or_py(py)?)
}

/// Rotation by a rotation vector `(3,)` (axis times angle in radians), then
/// translation.
#[pyfunction]
#[pyo3(signature = (rotation_vector, translation=None))]
pub fn pose_from_rotation_vector<'py>(
    py: Python<'py>,
    rotation_vector: &Bound<'py, PyAny>,
    translation: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let v = vector3_from(rotation_vector, "rotation_vector")?;
    let t = translation_or_zero(translation)?;
    pose_to_py(py, &core_rotation_vector(&t, &v).or_py(py)?)
}

/// A camera at `eye` looking at `target`: its optical frame (x right, y down,
/// z forward) in the world; `up` (default `(0, 0, 1)`) is the world's up.
#[pyfunction]
#[pyo3(signature = (eye, target, up=None))]
pub fn pose_look_at<'py>(
    py: Python<'py>,
    eye: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    up: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = Point3::from(vector3_from(eye, "eye")?);
    let t = Point3::from(vector3_from(target, "target")?);
    let up = up.map_or(Ok(Vector3::z()), |u| vector3_from(u, "up"))?;
    pose_to_py(py, &core_look_at(&e, &t, &up).or_py(py)?)
}

/// `n` uniformly random rotations as `(n, 4, 4)` poses (zero translation),
/// seeded: the same `seed` gives the same rotations.
#[pyfunction]
#[pyo3(signature = (n, seed=0))]
pub fn random_rotations(py: Python<'_>, n: i64, seed: u64) -> PyResult<Bound<'_, PyArray3<f64>>> {
    if !(0..=MAX_ROTATIONS).contains(&n) {
        return Err(invalid_input(py, format!("n must be in [0, 1e8], got {n}")));
    }
    let poses: Vec<Pose> = py.detach(|| {
        core_random_rotations(n as usize, seed)
            .into_iter()
            .map(|q| Pose::from_parts(Translation3::identity(), q))
            .collect()
    });
    poses_to_py(py, &poses)
}
