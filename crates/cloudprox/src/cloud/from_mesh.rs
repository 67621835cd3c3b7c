//! A point cloud standing for an exact triangle mesh.

use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Matrix3;
use crate::shape::Mesh;
use crate::Real;

impl PointCloud {
    /// The cloud that stands for an exact mesh (a robot link, a gripper) in a
    /// query: its surface sampled area-uniformly at one point per `spacing^2`
    /// (seeded), with **no sensor noise** (the mesh is exact) and the
    /// discretization covariance of that sampling, known exactly here: a sample
    /// stands for a patch of about `spacing^2` of its own face, so its covariance
    /// is `spacing^2 / 12 (I - n n^T)` (the variance of a uniform spread over a
    /// square of side `spacing`, in the face's plane; `n` the face normal) and none
    /// across the face. (The k-nearest-neighbour estimate used for sensor clouds
    /// would put spurious spread across the surface at the mesh's edges.)
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for a non-finite or non-positive `spacing`, a mesh of
    /// zero area, or a sampling of more than 1e9 points.
    pub fn from_mesh(mesh: &Mesh, spacing: Real, seed: u64) -> Result<Self> {
        Self::from_mesh_offset(mesh, spacing, seed, 0.0)
    }

    /// [`PointCloud::from_mesh`] with every sample moved `offset` metres along
    /// its face's outward normal (a padded robot link: the faces' offsets,
    /// without the rounded edges and corners of the exact offset surface).
    /// Offset 0 is [`PointCloud::from_mesh`] bit for bit.
    pub(crate) fn from_mesh_offset(
        mesh: &Mesh,
        spacing: Real,
        seed: u64,
        offset: Real,
    ) -> Result<Self> {
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(Error::invalid(format!(
                "mesh sampling spacing must be finite and > 0, got {spacing}"
            )));
        }
        let sample = mesh.sample_surface_density(1.0 / (spacing * spacing), seed)?;
        let var = spacing * spacing / 12.0;
        let disc = sample
            .normals
            .iter()
            .map(|n| (Matrix3::identity() - n * n.transpose()) * var)
            .collect();
        let sensor = vec![Matrix3::zeros(); sample.points.len()];
        let mut points = sample.points;
        if offset != 0.0 {
            for (p, n) in points.iter_mut().zip(&sample.normals) {
                *p += n * offset;
            }
        }
        PointCloud::from_covariances(points, sensor)?.with_discretization_covariances(disc)
    }
}
