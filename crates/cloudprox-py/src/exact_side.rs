//! Which query a pair of sides takes: two clouds (a mesh sampled into one),
//! or an exact mesh against a cloud
//! ([`cloudprox::query::exact_side`], the default for a mesh side).

use std::sync::Arc;

use cloudprox::cloud::PointCloud;
use cloudprox::math::Pose;
use cloudprox::query::collide::MeshSide;
use cloudprox::query::exact_side::{
    collide_cloud_exact, collide_cloud_exact_many, collide_exact_cloud, collide_exact_cloud_many,
};
use cloudprox::query::{CollisionRequest, CollisionResult};
use cloudprox::shape::MeshDistance;
use pyo3::prelude::*;

use crate::error::{invalid_input, run_detached};
use crate::result::QueriedSides;
use crate::side::{resolve_pair, Side};

/// A query's two sides, resolved.
pub enum Pair {
    /// Two clouds (a mesh side sampled into one).
    Clouds(Arc<PointCloud>, Arc<PointCloud>),
    /// An exact mesh and a cloud; `mesh_is_a` says which side the mesh is.
    Exact {
        /// The mesh's signed distance.
        mesh: Arc<MeshDistance>,
        /// The cloud.
        cloud: Arc<PointCloud>,
        /// Whether the mesh is side A.
        mesh_is_a: bool,
    },
}

/// The sides `a` and `b`: a mesh side is exact unless `mesh_side` is
/// `"sampled"` or a `mesh_spacing` is given (which samples it).
pub fn resolve(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    mesh_side: Option<&str>,
    mesh_spacing: Option<f64>,
) -> PyResult<Pair> {
    let side = match mesh_side {
        None if mesh_spacing.is_some() => MeshSide::Sampled,
        None => MeshSide::Exact,
        Some(name) => name
            .parse::<MeshSide>()
            .map_err(|e| invalid_input(py, e.to_string()))?,
    };
    if side == MeshSide::Exact && mesh_spacing.is_some() {
        return Err(invalid_input(
            py,
            "mesh_spacing samples the mesh: it needs mesh_side='sampled'",
        ));
    }
    let (sa, sb) = (Side::from_py(a, "a")?, Side::from_py(b, "b")?);
    let exact = match (&sa, &sb) {
        (Side::Cloud(_), Side::Cloud(_)) => None,
        (Side::Cloud(cloud), mesh) => Some((mesh, Arc::clone(cloud), false)),
        (mesh, Side::Cloud(cloud)) => Some((mesh, Arc::clone(cloud), true)),
        _ => None,
    };
    match exact {
        Some((mesh, cloud, mesh_is_a)) if side == MeshSide::Exact => Ok(Pair::Exact {
            mesh: distance_of(py, mesh)?,
            cloud,
            mesh_is_a,
        }),
        _ => {
            let (ca, cb) = resolve_pair(py, a, b, mesh_spacing)?;
            Ok(Pair::Clouds(ca, cb))
        }
    }
}

/// A mesh side's signed distance (a `Mesh` keeps its own).
fn distance_of(py: Python<'_>, side: &Side) -> PyResult<Arc<MeshDistance>> {
    match side {
        Side::Mesh(m) => m.get().distance(py),
        Side::Foreign(mesh) => {
            let mesh = Arc::clone(mesh);
            Ok(Arc::new(run_detached(py, move || {
                MeshDistance::new(&mesh)
            })?))
        }
        Side::Cloud(_) => Err(invalid_input(py, "a cloud has no signed distance")),
    }
}

impl Pair {
    /// The sides as a result records them (a mesh side: no points).
    pub fn sides(&self, pose_a: Pose, pose_b: Pose) -> QueriedSides {
        let (a, b) = match self {
            Pair::Clouds(a, b) => (Some(Arc::clone(a)), Some(Arc::clone(b))),
            Pair::Exact {
                cloud, mesh_is_a, ..
            } => {
                let c = Some(Arc::clone(cloud));
                if *mesh_is_a {
                    (None, c)
                } else {
                    (c, None)
                }
            }
        };
        QueriedSides {
            a,
            b,
            pose_a,
            pose_b,
        }
    }
}

/// The exact-side query of `mesh` and `cloud` at `pose_a` and `pose_b`.
pub fn exact_one(
    mesh: &MeshDistance,
    cloud: &PointCloud,
    mesh_is_a: bool,
    (pose_a, pose_b): (&Pose, &Pose),
    request: &CollisionRequest,
) -> cloudprox::Result<CollisionResult> {
    if mesh_is_a {
        collide_exact_cloud(pose_a, mesh, pose_b, cloud, request)
    } else {
        collide_cloud_exact(pose_a, cloud, pose_b, mesh, request)
    }
}

/// The exact-side query of side A at each of `poses_a` against side B.
pub fn exact_many(
    mesh: &MeshDistance,
    cloud: &PointCloud,
    mesh_is_a: bool,
    (poses_a, pose_b): (&[Pose], &Pose),
    request: &CollisionRequest,
) -> cloudprox::Result<Vec<CollisionResult>> {
    if mesh_is_a {
        collide_exact_cloud_many(poses_a, mesh, pose_b, cloud, request)
    } else {
        collide_cloud_exact_many(poses_a, cloud, pose_b, mesh, request)
    }
}
