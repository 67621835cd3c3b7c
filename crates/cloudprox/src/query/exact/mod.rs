//! Exact mesh-vs-mesh proximity (collision, distance, penetration depth) through
//! parry: the ground truth the noisy-cloud queries are measured against.
//!
//! An [`ExactShape`] is an object made of parts, each a [`Mesh`](crate::shape::Mesh):
//! a closed convex part becomes a convex polyhedron (exact GJK distance, EPA
//! penetration depth), any other part a triangle mesh (exact distance and
//! intersection; point containment through pseudo-normals when it is closed).
//! [`exact_time_of_impact`] moves one object along a straight line until its
//! signed distance to the other reaches a target (shape casting, then a search
//! on the penetration depth for a negative target); a convex part of many vertices
//! is cast with a support function that walks its edges instead of scanning its
//! vertices (the same support points).

mod climbing_hull;
#[allow(clippy::module_inception)]
mod exact;
mod exact_shape;
mod mesh_distance;
mod time_of_impact;

pub(crate) use exact::intersects;
pub use exact::{
    exact_intersects, exact_intersects_many, exact_proximity, exact_proximity_many, ExactProximity,
};
pub use exact_shape::{ExactPart, ExactShape};
pub use time_of_impact::{exact_time_of_impact, exact_time_of_impact_many, IMPACT_TOLERANCE};
