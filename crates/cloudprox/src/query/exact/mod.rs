//! Exact mesh-vs-mesh proximity (collision, distance, penetration depth) through
//! parry: the ground truth the noisy-cloud queries are measured against.
//!
//! An [`ExactShape`] is an object made of parts, each a [`Mesh`](crate::shape::Mesh):
//! a closed convex part becomes a convex polyhedron (exact GJK distance, EPA
//! penetration depth), any other part a triangle mesh (exact distance and
//! intersection; point containment through pseudo-normals when it is closed).

#[allow(clippy::module_inception)]
mod exact;
mod exact_shape;

pub use exact::{
    exact_intersects, exact_intersects_many, exact_proximity, exact_proximity_many, ExactProximity,
};
pub use exact_shape::{ExactPart, ExactShape};
