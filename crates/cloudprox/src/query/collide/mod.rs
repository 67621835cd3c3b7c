//! The probabilistic collision query between two noisy point clouds.
//!
//! 1. traverse the two hierarchies under the relative pose, pruning node pairs
//!    whose crossing bound is below `prune_epsilon` ([`crate::bvh`]);
//! 2. merge the kept leaf pairs into connected near regions, and split large
//!    regions into patches along the contact ([`region`]);
//! 3. train a robust separating surface per patch ([`crate::classify`]);
//! 4. per-point probabilities by Eq. 3, aggregated into `P` and a state
//!    ([`crate::probability`]).

#[allow(clippy::module_inception)]
mod collide;
mod collide_many;
mod collide_mesh_cloud;
pub mod region;
mod request;
mod result;

pub use collide::collide;
pub use collide_many::collide_many;
pub use collide_mesh_cloud::{
    collide_mesh_cloud, mesh_sampling_spacing, MeshSampling, MESH_SPACING_FACTOR,
};
pub use request::{CollisionRequest, CollisionRequestBuilder};
pub use result::{CollisionResult, ContactRegion, QueryStats};
