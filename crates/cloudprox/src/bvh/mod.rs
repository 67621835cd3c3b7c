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
//!
//! Spatial search has its home here: besides the tree, a hashed uniform grid
//! (`grid_knn.rs`) answers exact k-nearest-neighbour queries for every point of
//! a large cloud at once, much cheaper to build on millions of points than a
//! tree; the filters and the sampling spacing of large clouds use it
//! (`knn_map`).

mod aabb;
mod bvh_build;
mod bvh_nearest;
mod bvh_refit;
mod bvh_traverse_bvtt;
mod bvh_tree;
mod bvh_validation;
mod grid_knn;

#[cfg(test)]
mod bvh_tests;

pub use aabb::{Aabb, BoxMotion};
pub use bvh_traverse_bvtt::{prune_bound, PairTraversal};
pub use bvh_tree::{Bvh, BvhNode, BvhSettings, BvhWorkspace};

pub(crate) use grid_knn::for_each_knn;

/// Above this many points, the k-nearest-neighbour passes over a whole cloud
/// (its sampling spacing, its discretization covariances) use the hashed grid
/// (`grid_knn.rs`) instead of the tree.
pub const GRID_KNN_MIN_POINTS: usize = 4096;

/// For every point of a non-empty, finite cloud (fewer than 2^32 points),
/// `f(i, neighbours)` with its `k` nearest *other* points as `(squared
/// distance, index)` in no particular order; in parallel, results in point
/// order: the exact k-NN of the hashed grid.
pub(crate) fn knn_map<T, F>(points: &[crate::math::Point3], k: usize, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &[(f64, u32)]) -> T + Sync,
{
    for_each_knn(points, k, f)
}
