//! Bounding volume hierarchy over the points of one cloud, with noise-aware bounds.
//!
//! The tree is built once in the cloud's own frame over point indices (the cloud
//! owns the points). Every node stores the axis-aligned box of its points and the
//! largest standard deviation `sigma_max` of any point inside it. Two trees are
//! traversed together under a relative rigid pose ([`Bvh::traverse_pairs`]); a
//! node pair is pruned when the probability bound [`prune_bound`] of any of its
//! points crossing a plane between the two boxes is below `epsilon`, which is the
//! same as inflating each box by `k = Phi^-1(1 - epsilon / n)` of its
//! `sigma_max` and finding the inflated boxes disjoint.
//!
//! The `impl Bvh` blocks are split by concern: build, refit, pair traversal,
//! k-nearest neighbours, validation.

mod aabb;
mod bvh_build;
mod bvh_nearest;
mod bvh_refit;
mod bvh_traverse_bvtt;
mod bvh_tree;
mod bvh_validation;

#[cfg(test)]
mod bvh_tests;

pub use aabb::Aabb;
pub use bvh_traverse_bvtt::{prune_bound, PairTraversal};
pub use bvh_tree::{Bvh, BvhNode, BvhSettings, BvhWorkspace};
