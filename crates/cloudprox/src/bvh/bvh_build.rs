//! Top-down construction: split along the largest principal axis at the median.

use crate::bvh::{Aabb, Bvh, BvhNode, BvhSettings};
use crate::error::{Error, Result};
use crate::math::{Point3, PrincipalAxes, Vector3};
use crate::Real;

impl Bvh {
    /// Builds the hierarchy over `points` with per-point largest standard deviations
    /// `sigmas` (see [`crate::uncertainty::max_std`]).
    ///
    /// Each node is split at the median of the points' projections on the largest
    /// principal axis of their scatter (the thesis version of the method), which
    /// keeps the tree balanced and follows thin surfaces. Build time is
    /// `O(n log n)`; the two halves of every node of at least 4096 points are
    /// built in parallel (rayon), into the same tree a single thread builds.
    pub fn build(points: &[Point3], sigmas: &[Real], settings: &BvhSettings) -> Result<Bvh> {
        settings.validate()?;
        if points.is_empty() {
            return Err(Error::invalid(
                "cannot build a hierarchy over an empty cloud",
            ));
        }
        if sigmas.len() != points.len() {
            return Err(Error::Shape {
                what: "per-point sigmas".into(),
                expected: points.len(),
                got: sigmas.len(),
            });
        }
        let n = u32::try_from(points.len())
            .map_err(|_| Error::invalid("clouds are limited to 2^32 - 1 points"))?;
        let leaf_max = settings.leaf_max_points;
        // Every node's place in the pre-order array follows from its point
        // count alone, so the two halves of a node are built into disjoint
        // parts of one array at once: the same tree as one thread builds.
        let placeholder = BvhNode {
            aabb: Aabb::empty(),
            sigma_max: 0.0,
            first: 0,
            count: 0,
            children: None,
        };
        let mut nodes = vec![placeholder; subtree_nodes(points.len(), leaf_max)];
        let mut indices: Vec<u32> = (0..n).collect();
        let input = Input {
            points,
            sigmas,
            leaf_max,
        };
        build_node(&input, &mut nodes, 0, &mut indices, 0);
        Ok(Bvh { nodes, indices })
    }
}

/// Below this many points a subtree is built on the current thread.
const PARALLEL_MIN_POINTS: usize = 4096;

/// What every node of one build reads.
struct Input<'a> {
    points: &'a [Point3],
    sigmas: &'a [Real],
    leaf_max: usize,
}

/// Number of nodes of the subtree over `count` points: halving gives at most
/// two distinct counts per depth (consecutive integers), so this walks the
/// depths with their multiplicities.
fn subtree_nodes(count: usize, leaf_max: usize) -> usize {
    let mut level: Vec<(usize, usize)> = vec![(count, 1)];
    let mut total = 0;
    while !level.is_empty() {
        let mut next: Vec<(usize, usize)> = Vec::with_capacity(2);
        for (c, m) in level {
            total += m;
            if c > leaf_max {
                for half in [c / 2, c - c / 2] {
                    match next.iter_mut().find(|(k, _)| *k == half) {
                        Some((_, mult)) => *mult += m,
                        None => next.push((half, m)),
                    }
                }
            }
        }
        level = next;
    }
    total
}

/// Builds the subtree over `indices` (the points of `first..first + len`) into
/// `nodes`, its pre-order block, whose first node has index `id`.
fn build_node(input: &Input<'_>, nodes: &mut [BvhNode], id: u32, indices: &mut [u32], first: u32) {
    let count = indices.len() as u32;
    let mut aabb = Aabb::empty();
    let mut sigma_max: Real = 0.0;
    for &i in indices.iter() {
        aabb.take_point(&input.points[i as usize]);
        sigma_max = sigma_max.max(input.sigmas[i as usize]);
    }
    // A subtree has at least one node (its root); `subtree_nodes` sized it.
    let Some((node, below)) = nodes.split_first_mut() else {
        return;
    };
    *node = BvhNode {
        aabb,
        sigma_max,
        first,
        count,
        children: None,
    };
    if indices.len() <= input.leaf_max {
        return;
    }
    let axis = principal_axis(input.points, indices);
    let mid = indices.len() / 2;
    let key = |i: &u32| input.points[*i as usize].coords.dot(&axis);
    indices.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
    let left_nodes = subtree_nodes(mid, input.leaf_max);
    let (left_ids, right_ids) = (id + 1, id + 1 + left_nodes as u32);
    node.children = Some([left_ids, right_ids]);
    let (left, right) = below.split_at_mut(left_nodes);
    let (left_idx, right_idx) = indices.split_at_mut(mid);
    let right_first = first + mid as u32;
    if count as usize >= PARALLEL_MIN_POINTS {
        rayon::join(
            || build_node(input, left, left_ids, left_idx, first),
            || build_node(input, right, right_ids, right_idx, right_first),
        );
    } else {
        build_node(input, left, left_ids, left_idx, first);
        build_node(input, right, right_ids, right_idx, right_first);
    }
}

/// Unit eigenvector of the largest eigenvalue of the points' scatter matrix.
fn principal_axis(points: &[Point3], idx: &[u32]) -> Vector3 {
    PrincipalAxes::of(idx.iter().map(|&i| points[i as usize])).largest()
}
