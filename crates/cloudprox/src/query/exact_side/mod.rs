//! The collision query with one exact side: a mesh's surface is the
//! separating surface, and nothing is trained.
//!
//! When one side of a query is an exact mesh, its surface is known, so the
//! paper's Eq. 3 needs no classifier: a cloud point `x` with covariance
//! `Sigma` lies on the wrong side of the mesh's surface with probability
//! `p = Phi(-sd(x) / sqrt(n^T Sigma n))`, `sd` the signed distance to the mesh
//! (negative inside, [`MeshDistance`](crate::shape::MeshDistance)) and `n` its
//! unit gradient. The pair's `P` is the elements model's
//! ([`contact_probability`](crate::probability::contact_probability)), read
//! against the exact surface: each of the cloud's surface elements near the
//! mesh gives, at each of its probes, the signed distance of its fitted
//! surface to the mesh and that distance's standard deviation (the fit's,
//! along `n`, with the position of the element's sampled edges; the mesh side
//! adds none), and single points give their own signed distance with their
//! covariance along `n` (Eq. 3). One definition of `P`, two evaluations: two
//! clouds read element against element, a mesh and a cloud element against
//! the surface.
//!
//! - `frame.rs`: the cloud seen from the mesh (poses, the reach, the broad
//!   phase: which elements can come within the noise's reach of the surface);
//! - `readings.rs`: the elements' readings against the surface;
//! - `points.rs`: the per-point probabilities (Eq. 3);
//! - `reach.rs`: whether a box around the mesh can reach the cloud at all
//!   (a robot's broad phase, before any signed distance);
//! - `nearest.rs`: the cloud's surface estimate nearest the surface, for
//!   the distance query ([`mod@crate::query::distance`]);
//! - `query.rs`: the entry points.

mod frame;
mod nearest;
mod points;
mod query;
mod reach;
mod readings;
#[cfg(test)]
mod tests;

pub(crate) use nearest::nearest_to_mesh;
pub(crate) use query::collide_exact_cloud_padded;
pub use query::{
    collide_cloud_exact, collide_cloud_exact_many, collide_exact_cloud, collide_exact_cloud_many,
};
pub(crate) use reach::exact_side_may_reach;
