//! Exact shapes: triangle meshes, their primitives and their surface sampling.
//!
//! A [`Mesh`] is the exact geometry of an object (a robot link, a piece of
//! furniture, a reconstructed surface). It is the ground truth of the evaluation
//! ([`crate::query::exact`]) and the source of synthetic point clouds
//! ([`Mesh::sample_surface`]).
//!
//! [`MeshDistance`] answers exact signed-distance queries against a mesh (sign by
//! pseudo-normals or by the generalized winding number), and [`DistanceField`]
//! is its grid, built once, with a bound on its interpolation error.

mod distance_field;
mod mesh;
mod primitives;
mod sampling;
mod signed_bvh;
mod signed_distance;
mod signed_topology;

pub use distance_field::{DistanceField, FieldSample, FieldStats, FieldValue};
pub use mesh::Mesh;
pub use sampling::SurfaceSample;
pub use signed_distance::{ClosestPoint, MeshDistance, SignMethod};
pub use signed_topology::MeshTopology;
