//! The `collide`, `collide_many` and `collide_along` functions.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{pose_from, poses_from};
use crate::error::run_detached;
use crate::exact_side::{exact_many, exact_one, resolve, Pair};
use crate::request::{request_from, PyCollisionRequest};
use crate::result::PyCollisionResult;
use cloudprox::cloud::PointCloud;
use cloudprox::math::Pose;
use cloudprox::query::{CollisionRequest, CollisionResult};

/// The keywords of `collide`, `collide_many` and `collide_along` that are not
/// request options.
const QUERY_KEYWORDS: [&str; 3] = ["request", "mesh_side", "mesh_spacing"];

/// The probabilistic collision query between cloud `a` at `pose_a` and cloud `b`
/// at `pose_b` (`(4, 4)` transforms, `None` = identity). Either side may be a
/// mesh instead (cloudprox `Mesh`, trimesh `Trimesh`, Open3D `TriangleMesh`):
/// by default (`mesh_side="exact"`) its surface is the separating surface
/// ([`cloudprox::query::exact_side`]); with `mesh_side="sampled"` (or a
/// `mesh_spacing`) it is sampled at `mesh_spacing` (default: half the cloud's
/// median spacing) into a cloud without sensor noise. The options are `request` (a `CollisionRequest`,
/// default: the Rust defaults); keyword options (the names of
/// `CollisionRequest`'s constructor) are a shortcut that overrides the
/// request's fields. The GIL is released during the query.
#[pyfunction]
#[pyo3(signature = (a, b, pose_a=None, pose_b=None, *, request=None, mesh_side=None, mesh_spacing=None, **options))]
pub fn collide(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyCollisionRequest>>,
    mesh_side: Option<&str>,
    mesh_spacing: Option<f64>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyCollisionResult> {
    let request = request_from(py, request, options, &QUERY_KEYWORDS)?;
    let pose_a = pose_from(py, pose_a, "pose_a")?;
    let pose_b = pose_from(py, pose_b, "pose_b")?;
    let pair = resolve(py, a, b, mesh_side, mesh_spacing)?;
    let sides = pair.sides(pose_a, pose_b);
    let result = run_detached(py, move || match &pair {
        Pair::Clouds(ca, cb) => cloudprox::query::collide(&pose_a, ca, &pose_b, cb, &request),
        Pair::Exact {
            mesh,
            cloud,
            mesh_is_a,
        } => exact_one(mesh, cloud, *mesh_is_a, (&pose_a, &pose_b), &request),
    })?;
    PyCollisionResult::with_sides(py, result, sides)
}

/// The core's answer for many poses of one cloud ([`cloudprox::query::collide_many`],
/// [`cloudprox::query::collide_along`]).
type ManyPoses = fn(
    &[Pose],
    &PointCloud,
    &Pose,
    &PointCloud,
    &CollisionRequest,
) -> cloudprox::Result<Vec<CollisionResult>>;

/// A query of many poses of `a`: the arguments read and checked, `run` with the
/// GIL released, each result with the sides it was queried on.
#[allow(clippy::too_many_arguments)]
fn query_poses(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    poses_a: &Bound<'_, PyAny>,
    pose_b: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyCollisionRequest>>,
    (mesh_side, mesh_spacing): (Option<&str>, Option<f64>),
    options: Option<&Bound<'_, PyDict>>,
    run: ManyPoses,
) -> PyResult<Vec<PyCollisionResult>> {
    let request = request_from(py, request, options, &QUERY_KEYWORDS)?;
    let poses_a = poses_from(poses_a, "poses_a")?;
    let pose_b = pose_from(py, pose_b, "pose_b")?;
    let pair = Arc::new(resolve(py, a, b, mesh_side, mesh_spacing)?);
    let shared = Arc::clone(&pair);
    let (results, poses_a) = run_detached(py, move || {
        match &*shared {
            Pair::Clouds(ca, cb) => run(&poses_a, ca, &pose_b, cb, &request),
            Pair::Exact {
                mesh,
                cloud,
                mesh_is_a,
            } => exact_many(mesh, cloud, *mesh_is_a, (&poses_a, &pose_b), &request),
        }
        .map(|r| (r, poses_a))
    })?;
    results
        .into_iter()
        .zip(poses_a)
        .map(|(r, pose_a)| PyCollisionResult::with_sides(py, r, pair.sides(pose_a, pose_b)))
        .collect()
}

/// `collide` for cloud `a` at each of the `(m, 4, 4)` poses `poses_a` against cloud
/// `b` at `pose_b`, in parallel (rayon) with the GIL released. Results are in the
/// order of `poses_a`.
#[pyfunction]
#[pyo3(signature = (a, b, poses_a, pose_b=None, *, request=None, mesh_side=None, mesh_spacing=None, **options))]
pub fn collide_many(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    poses_a: &Bound<'_, PyAny>,
    pose_b: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyCollisionRequest>>,
    mesh_side: Option<&str>,
    mesh_spacing: Option<f64>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<PyCollisionResult>> {
    let run: ManyPoses = cloudprox::query::collide_many;
    query_poses(
        py,
        a,
        b,
        poses_a,
        pose_b,
        request,
        (mesh_side, mesh_spacing),
        options,
        run,
    )
}

/// `collide` for cloud `a` at the `(m, 4, 4)` poses `poses_a` of a motion against
/// cloud `b` at `pose_b`: runs of 16 consecutive poses in parallel (rayon) with
/// the GIL released, within a run each query's classifier starting from the
/// previous pose's support. Results are in the order of `poses_a`.
#[pyfunction]
#[pyo3(signature = (a, b, poses_a, pose_b=None, *, request=None, mesh_side=None, mesh_spacing=None, **options))]
pub fn collide_along(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    poses_a: &Bound<'_, PyAny>,
    pose_b: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyCollisionRequest>>,
    mesh_side: Option<&str>,
    mesh_spacing: Option<f64>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<PyCollisionResult>> {
    let run: ManyPoses = cloudprox::query::collide_along;
    query_poses(
        py,
        a,
        b,
        poses_a,
        pose_b,
        request,
        (mesh_side, mesh_spacing),
        options,
        run,
    )
}

/// The elements model's facing pairs in the patches of `collide(a, b, pose_a,
/// pose_b)` ([`cloudprox::query::facing_pairs`]), for diagnostics: a dict of
/// arrays, one row per pair (`from_a`, `element`, `other_element`, `probe`,
/// `facing`, `direction`, `gap`, `std`, `probability`, `within_reach`,
/// `beside`).
#[pyfunction]
#[pyo3(signature = (a, b, pose_a=None, pose_b=None, *, request=None, **options))]
pub fn facing_pairs<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    pose_a: Option<&Bound<'py, PyAny>>,
    pose_b: Option<&Bound<'py, PyAny>>,
    request: Option<&Bound<'py, PyCollisionRequest>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    use crate::convert::{points_to_py, vec_to_py};
    use numpy::IntoPyArray;
    let request = request_from(py, request, options, &QUERY_KEYWORDS)?;
    let pose_a = pose_from(py, pose_a, "pose_a")?;
    let pose_b = pose_from(py, pose_b, "pose_b")?;
    let (ca, cb) = crate::side::resolve_pair(py, a, b, None)?;
    let pairs = run_detached(py, move || {
        cloudprox::query::facing_pairs(&pose_a, &ca, &pose_b, &cb, &request)
    })?;
    let out = PyDict::new(py);
    let bools = |f: fn(&cloudprox::probability::FacingPair) -> bool| {
        pairs.iter().map(f).collect::<Vec<bool>>().into_pyarray(py)
    };
    let ints = |f: fn(&cloudprox::probability::FacingPair) -> u32| {
        pairs
            .iter()
            .map(|p| i64::from(f(p)))
            .collect::<Vec<i64>>()
            .into_pyarray(py)
    };
    let reals = |f: fn(&cloudprox::probability::FacingPair) -> f64| {
        vec_to_py(py, &pairs.iter().map(f).collect::<Vec<f64>>())
    };
    out.set_item("from_a", bools(|p| p.from_a))?;
    out.set_item("element", ints(|p| p.element))?;
    out.set_item("other_element", ints(|p| p.other_element))?;
    out.set_item(
        "probe",
        points_to_py(py, &pairs.iter().map(|p| p.probe).collect::<Vec<_>>())?,
    )?;
    out.set_item(
        "facing",
        points_to_py(py, &pairs.iter().map(|p| p.facing).collect::<Vec<_>>())?,
    )?;
    let dirs: Vec<cloudprox::math::Point3> = pairs
        .iter()
        .map(|p| cloudprox::math::Point3::from(p.direction))
        .collect();
    out.set_item("direction", points_to_py(py, &dirs)?)?;
    out.set_item("gap", reals(|p| p.gap))?;
    out.set_item("std", reals(|p| p.std))?;
    out.set_item("probability", reals(|p| p.probability))?;
    out.set_item("within_reach", bools(|p| p.within_reach))?;
    out.set_item("beside", bools(|p| p.beside))?;
    out.set_item("probe_edge", reals(|p| p.probe_edge))?;
    out.set_item("count", ints(|p| p.counts[0]))?;
    out.set_item("other_count", ints(|p| p.counts[1]))?;
    out.set_item("size", reals(|p| p.sizes[0]))?;
    out.set_item("other_size", reals(|p| p.sizes[1]))?;
    out.set_item("own_std", reals(|p| p.own_std))?;
    Ok(out)
}
