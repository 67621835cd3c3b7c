//! The `collide` and `collide_many` functions.

use std::sync::Arc;

use pyo3::prelude::*;

use crate::convert::{pose_from, poses_from};
use crate::error::run_detached;
use crate::request::RequestOptions;
use crate::result::{PyCollisionResult, QueriedSides};
use crate::side::resolve_pair;

/// The probabilistic collision query between cloud `a` at `pose_a` and cloud `b`
/// at `pose_b` (`(4, 4)` transforms, `None` = identity). Either side may be a
/// mesh instead (cloudprox `Mesh`, trimesh `Trimesh`, Open3D `TriangleMesh`): it
/// is sampled at `mesh_spacing` (default: half the cloud's median spacing) into a
/// cloud without sensor noise. Options left at `None`
/// take the Rust defaults (see `default_options()`). The GIL is released during
/// the query.
#[pyfunction]
#[pyo3(signature = (
    a, b, pose_a=None, pose_b=None, *, surface=None, aggregation=None,
    threshold_collision=None, threshold_free=None, prune_epsilon=None,
    region_max_points=None, near_context=None, lambda_=None, robust_eta=None, robust_model=None,
    solver=None, use_hierarchy=None, mesh_spacing=None, model=None, decide_only=None
))]
pub fn collide(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
    surface: Option<String>,
    aggregation: Option<String>,
    threshold_collision: Option<f64>,
    threshold_free: Option<f64>,
    prune_epsilon: Option<f64>,
    region_max_points: Option<i64>,
    near_context: Option<f64>,
    lambda_: Option<f64>,
    robust_eta: Option<f64>,
    robust_model: Option<String>,
    solver: Option<String>,
    use_hierarchy: Option<bool>,
    mesh_spacing: Option<f64>,
    model: Option<String>,
    decide_only: Option<bool>,
) -> PyResult<PyCollisionResult> {
    let request = RequestOptions {
        surface,
        aggregation,
        threshold_collision,
        threshold_free,
        prune_epsilon,
        region_max_points,
        near_context,
        lambda: lambda_,
        robust_eta,
        robust_model,
        solver,
        use_hierarchy,
        model,
        decide_only,
    }
    .build(py)?;
    let pose_a = pose_from(py, pose_a, "pose_a")?;
    let pose_b = pose_from(py, pose_b, "pose_b")?;
    let (ca, cb) = resolve_pair(py, a, b, mesh_spacing)?;
    let sides = QueriedSides {
        a: Arc::clone(&ca),
        b: Arc::clone(&cb),
        pose_a,
        pose_b,
    };
    let result = run_detached(py, move || {
        cloudprox::query::collide(&pose_a, &ca, &pose_b, &cb, &request)
    })?;
    PyCollisionResult::with_sides(py, result, sides)
}

/// `collide` for cloud `a` at each of the `(m, 4, 4)` poses `poses_a` against cloud
/// `b` at `pose_b`, in parallel (rayon) with the GIL released. Results are in the
/// order of `poses_a`.
#[pyfunction]
#[pyo3(signature = (
    a, b, poses_a, pose_b=None, *, surface=None, aggregation=None,
    threshold_collision=None, threshold_free=None, prune_epsilon=None,
    region_max_points=None, near_context=None, lambda_=None, robust_eta=None, robust_model=None,
    solver=None, use_hierarchy=None, mesh_spacing=None, model=None, decide_only=None
))]
pub fn collide_many(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    poses_a: &Bound<'_, PyAny>,
    pose_b: Option<&Bound<'_, PyAny>>,
    surface: Option<String>,
    aggregation: Option<String>,
    threshold_collision: Option<f64>,
    threshold_free: Option<f64>,
    prune_epsilon: Option<f64>,
    region_max_points: Option<i64>,
    near_context: Option<f64>,
    lambda_: Option<f64>,
    robust_eta: Option<f64>,
    robust_model: Option<String>,
    solver: Option<String>,
    use_hierarchy: Option<bool>,
    mesh_spacing: Option<f64>,
    model: Option<String>,
    decide_only: Option<bool>,
) -> PyResult<Vec<PyCollisionResult>> {
    let request = RequestOptions {
        surface,
        aggregation,
        threshold_collision,
        threshold_free,
        prune_epsilon,
        region_max_points,
        near_context,
        lambda: lambda_,
        robust_eta,
        robust_model,
        solver,
        use_hierarchy,
        model,
        decide_only,
    }
    .build(py)?;
    let poses_a = poses_from(poses_a, "poses_a")?;
    let pose_b = pose_from(py, pose_b, "pose_b")?;
    let (ca, cb) = resolve_pair(py, a, b, mesh_spacing)?;
    let (sa, sb, poses) = (Arc::clone(&ca), Arc::clone(&cb), poses_a.clone());
    let results = run_detached(py, move || {
        cloudprox::query::collide_many(&poses_a, &ca, &pose_b, &cb, &request)
    })?;
    results
        .into_iter()
        .zip(poses)
        .map(|(r, pose_a)| {
            let sides = QueriedSides {
                a: Arc::clone(&sa),
                b: Arc::clone(&sb),
                pose_a,
                pose_b,
            };
            PyCollisionResult::with_sides(py, r, sides)
        })
        .collect()
}
