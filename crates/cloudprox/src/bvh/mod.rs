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
//! tree; the filters use it, and the k-NN pass over a whole cloud (its
//! sampling spacing, its discretization covariances) above
//! [`GRID_KNN_MIN_POINTS`] points (`knn_of_every_point`); `PointSearch`
//! (`point_search.rs`) answers the neighbourhood and radius queries over a
//! patch's points during a query.

mod aabb;
mod bvh_build;
mod bvh_nearest;
mod bvh_refit;
mod bvh_traverse_bvtt;
mod bvh_tree;
mod bvh_validation;
mod grid_knn;
mod point_search;

#[cfg(test)]
mod bvh_tests;

pub use aabb::{Aabb, BoxMotion};
pub(crate) use bvh_traverse_bvtt::{kept_without_bound, NodeMargins};
pub use bvh_traverse_bvtt::{prune_bound, PairTraversal};
pub use bvh_tree::{Bvh, BvhNode, BvhSettings, BvhWorkspace};

pub(crate) use grid_knn::for_each_knn;
pub(crate) use point_search::{Neighbourhoods, PointSearch};

/// Above this many points, the k-nearest-neighbour passes over a whole cloud
/// (its sampling spacing, its discretization covariances) use the hashed grid
/// (`grid_knn.rs`) instead of the tree.
pub const GRID_KNN_MIN_POINTS: usize = 4096;

/// For every point of a non-empty, finite cloud (fewer than 2^32 points),
/// `f(i, neighbours)` with the point itself and its `k` nearest *other* points
/// (fewer in a cloud of at most `k` points) as `(squared distance, index)`,
/// nearest first (ties by index, from the grid and the tree alike); in
/// parallel, results in point order. The
/// neighbours come from `bvh` (built over `points`) up to
/// [`GRID_KNN_MIN_POINTS`] points and from the hashed grid above (exact as
/// well, and much cheaper to build on large clouds): the same neighbours (but
/// where more than `k + 1` points share a position). The
/// k-NN pass over a whole cloud, for its sampling spacing and its
/// discretization covariances (a query's searches over a patch are
/// `PointSearch`'s).
pub(crate) fn knn_of_every_point<T, F>(
    points: &[crate::math::Point3],
    bvh: &Bvh,
    k: usize,
    f: F,
) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &[(f64, u32)]) -> T + Sync,
{
    use rayon::prelude::*;
    if points.len() > GRID_KNN_MIN_POINTS {
        thread_local! {
            /// The neighbourhood handed to `f`, reused by the thread's points.
            static NEIGHBOURS: std::cell::RefCell<Vec<(f64, u32)>> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        return for_each_knn(points, k, |i, others| {
            NEIGHBOURS.with_borrow_mut(|neighbours| {
                neighbours.clear();
                neighbours.push((0.0, i as u32));
                neighbours.extend_from_slice(others);
                neighbours.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                f(i, neighbours)
            })
        });
    }
    points
        .par_iter()
        .enumerate()
        .map_init(
            || (BvhWorkspace::default(), Vec::with_capacity(k + 1)),
            |(workspace, neighbours), (i, x)| {
                bvh.nearest_k(points, x, k + 1, workspace, neighbours);
                f(i, neighbours)
            },
        )
        .collect()
}
