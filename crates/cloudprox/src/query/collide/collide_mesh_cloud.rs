//! The collision query between an exact mesh and a noisy point cloud.

use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Pose;
use crate::query::collide::{collide, CollisionRequest, CollisionResult};
use crate::query::exact_side::collide_exact_cloud;
use crate::shape::{Mesh, MeshDistance};
use crate::Real;

/// How [`collide_mesh_cloud`] reads the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MeshSide {
    /// The mesh's surface is the separating surface (the default):
    /// [`collide_exact_cloud`], nothing sampled, nothing trained.
    #[default]
    Exact,
    /// The mesh is sampled into a cloud ([`MeshSampling::spacing`],
    /// [`MeshSampling::seed`]) and the two clouds are collided ([`collide`]).
    Sampled,
}

crate::names::named_options!(MeshSide, "mesh_side", {
    Exact => "exact",
    Sampled => "sampled",
});

/// How a mesh stands in [`collide_mesh_cloud`]: exact (the default), or
/// sampled into a cloud.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeshSampling {
    /// Exact or sampled (default [`MeshSide::Exact`]); the spacing and the
    /// seed are those of [`MeshSide::Sampled`].
    pub side: MeshSide,
    /// Sampling spacing (metres); `None` (the default) picks it from the other
    /// cloud ([`mesh_sampling_spacing`]).
    pub spacing: Option<Real>,
    /// Seed of the area-uniform sampling (default 0).
    pub seed: u64,
}

impl MeshSampling {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if `spacing` is given and is not finite and positive.
    pub fn validate(&self) -> Result<()> {
        if let Some(s) = self.spacing {
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::invalid(format!(
                    "mesh sampling spacing must be finite and > 0, got {s}"
                )));
            }
        }
        Ok(())
    }
}

/// The mesh's share of the cloud's sampling spacing: the mesh is sampled
/// [`MESH_SPACING_FACTOR`] times as densely as the cloud (chosen by measurement,
/// see `docs/architecture.md`).
pub const MESH_SPACING_FACTOR: Real = 0.5;

/// The spacing a mesh is sampled at against `cloud`: [`MESH_SPACING_FACTOR`]
/// times the median of the cloud's own sampling spacing (distance to the 6th
/// nearest neighbour), so that the mesh side never is the coarser one and its
/// discretization error stays below the cloud's.
pub fn mesh_sampling_spacing(cloud: &PointCloud) -> Real {
    MESH_SPACING_FACTOR * cloud.spacing_upper_median()
}

/// The probabilistic collision query between an exact mesh at `pose_mesh` and a
/// noisy cloud at `pose_cloud`.
///
/// By default ([`MeshSide::Exact`]) the mesh's surface is the separating
/// surface ([`collide_exact_cloud`]; its signed distance is built here, so to
/// query one mesh many times build a [`MeshDistance`] once and call that
/// directly). With [`MeshSide::Sampled`], the mesh is sampled into a cloud without sensor noise whose covariance is its
/// own discretization error ([`PointCloud::from_mesh`]), at the spacing
/// `sampling` gives, and the two clouds are collided ([`collide`]); the result's
/// side A is the mesh's sample. To query the same mesh many times, sample it once
/// with [`PointCloud::from_mesh`] and call [`collide`] directly.
///
/// # Errors
/// As [`CollisionRequest::validate`] and [`MeshSampling::validate`] (before
/// any work), [`collide`] and [`PointCloud::from_mesh`]; a spacing that would sample the
/// mesh into more than 1e9 points.
pub fn collide_mesh_cloud(
    pose_mesh: &Pose,
    mesh: &Mesh,
    pose_cloud: &Pose,
    cloud: &PointCloud,
    request: &CollisionRequest,
    sampling: &MeshSampling,
) -> Result<CollisionResult> {
    request.validate()?;
    sampling.validate()?;
    if sampling.side == MeshSide::Exact {
        let distance = MeshDistance::new(mesh)?;
        return collide_exact_cloud(pose_mesh, &distance, pose_cloud, cloud, request);
    }
    let spacing = match sampling.spacing {
        Some(s) => s,
        None => mesh_sampling_spacing(cloud),
    };
    if spacing <= 0.0 {
        return Err(Error::invalid(
            "the cloud's points coincide (sampling spacing 0): give the mesh sampling spacing",
        ));
    }
    let sample = PointCloud::from_mesh(mesh, spacing, sampling.seed)?;
    collide(pose_mesh, &sample, pose_cloud, cloud, request)
}
