//! Exact shapes: triangle meshes, their primitives and their surface sampling.
//!
//! A [`Mesh`] is the exact geometry of an object (a robot link, a piece of
//! furniture, a reconstructed surface). It is the ground truth of the evaluation
//! ([`crate::query::exact`]) and the source of synthetic point clouds
//! ([`Mesh::sample_surface`]).

mod mesh;
mod primitives;
mod sampling;

pub use mesh::Mesh;
pub use sampling::SurfaceSample;
