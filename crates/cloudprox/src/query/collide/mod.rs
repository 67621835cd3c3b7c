//! The probabilistic collision query between two noisy point clouds.
//!
//! 0. the samples: each cloud's points (the paper's model, the default) or its
//!    surface elements ([`crate::element`]), see [`QueryModel`]; with
//!    elements, the hierarchies over both clouds' element hulls first decide
//!    whether any two surfaces can come within the noise's reach
//!    (`elements.rs`): if none can, the pair is free without a near set;
//! 1. the near set: traverse the two hierarchies under the relative pose,
//!    pruning node pairs whose crossing bound is below `prune_epsilon`
//!    ([`crate::bvh`]), and keep the samples within the noise's reach of the
//!    other cloud, with context around them (`near.rs`);
//! 2. merge them into connected near regions, and split large regions into
//!    patches along the contact (`region.rs`);
//! 3. train a robust separating surface per patch ([`crate::classify`]), and
//!    estimate the contact point, normal and separation (`contact.rs`); along
//!    a motion, the classifier starts from the samples that supported the
//!    previous state's surfaces (`warm_start.rs`);
//! 4. with surface elements, whether a patch's element surfaces can reach each
//!    other at all (if not, it is pruned without a classifier) and the
//!    probability that they cross (`elements.rs`);
//! 5. probabilities: per point by Eq. 3, and the pair's `P` from the core
//!    samples ([`crate::probability`], `probabilities.rs`), with a state.
//!
//! `collide.rs` runs these stages in order; each lives in its own file.

#[allow(clippy::module_inception)]
mod collide;
mod collide_many;
mod collide_mesh_cloud;
mod contact;
mod diagnose;
mod elements;
mod near;
mod probabilities;
pub(crate) mod region;
mod request;
mod result;
mod warm_start;

pub use collide::collide;
pub(crate) use collide::{collide_readings, collide_with_workspace};
pub use collide_many::{collide_along, collide_many, prepare, ALONG_RUN};
pub use collide_mesh_cloud::{
    collide_mesh_cloud, mesh_sampling_spacing, MeshSampling, MeshSide, MESH_SPACING_FACTOR,
};
pub use diagnose::facing_pairs;
pub(crate) use elements::element_surfaces_may_reach;
pub use request::{CollisionRequest, QueryModel};
pub use result::{
    CollisionResult, ContactPatch, PointAggregates, PointProbabilities, QueryCounters, QueryStats,
};
pub(crate) use warm_start::WarmStart;
