//! Simultaneous traversal of two hierarchies (the bounding volume test tree) with
//! probabilistic pruning.

use crate::bvh::{BoxMotion, Bvh, BvhWorkspace};
use crate::math::Pose;
use crate::probability::{normal_cdf, normal_quantile};
use crate::Real;

/// What a pair traversal found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PairTraversal {
    /// The leaf pairs `(leaf of self, leaf of other)` that were not pruned.
    pub leaf_pairs: Vec<(u32, u32)>,
    /// Number of node pairs tested.
    pub node_pairs_visited: usize,
    /// Sum of [`prune_bound`] over every pruned node pair: an upper bound on the
    /// probability that any pruned point lies on the wrong side of a plane that
    /// separates its node's box from the other node's box (capped at 1).
    pub pruned_bound: Real,
}

/// Upper bound on the probability that any of `n` points of two boxes a distance
/// `gap` apart crosses the plane between them, when no point's standard deviation
/// exceeds `sigma_a` (first box) or `sigma_b` (second box) in any direction.
///
/// Two convex sets `gap` apart are separated by a slab of that width. Place the
/// plane inside it at `gap * sigma_a / (sigma_a + sigma_b)` from the first box: a
/// point of either box must then move at least `gap / (sigma_a + sigma_b)` of its
/// own standard deviations along the normal to cross, and a union bound over the
/// `n` points gives `n * Phi(-gap / (sigma_a + sigma_b))`. With no noise the
/// bound is 0 for `gap > 0`, and it is `n / 2` for touching boxes.
pub fn prune_bound(gap: Real, sigma_a: Real, sigma_b: Real, n: usize) -> Real {
    let s = sigma_a + sigma_b;
    let n = n as Real;
    if s <= 0.0 {
        return if gap > 0.0 { 0.0 } else { n };
    }
    n * normal_cdf(-gap / s)
}

/// A gap of at most this many times `sigma_a + sigma_b` gives a
/// [`prune_bound`] of at least `epsilon` for any pair of nodes (at least two
/// points): `-Phi^-1(epsilon / 2)`, lowered until the computed bound at it
/// reaches `epsilon` (so that rounding cannot keep a pair the bound would
/// prune); infinite for `epsilon = 0` (nothing is pruned), `-inf` where no
/// gap is (`epsilon > 1`, NaN, negative) or where `epsilon / 2` is not
/// representable (the smallest subnormal).
pub(crate) fn kept_without_bound(epsilon: Real) -> Real {
    let z = -normal_quantile(0.5 * epsilon);
    if z.is_nan() || z < 0.0 {
        return Real::NEG_INFINITY;
    }
    if z.is_infinite() {
        // `epsilon / 2` rounded to 0: only a zero epsilon prunes nothing.
        return if epsilon <= 0.0 {
            Real::INFINITY
        } else {
            Real::NEG_INFINITY
        };
    }
    // A margin far above rounding, then checked.
    let mut z = z * (1.0 - 1e-7);
    while z > 0.0 && 2.0 * normal_cdf(-z) < epsilon {
        z *= 1.0 - 1e-7;
    }
    z
}

impl Bvh {
    /// The largest of a per-point quantity below every node (one value per node).
    pub fn node_max(&self, per_point: &[Real]) -> Vec<Real> {
        let mut out: Vec<Real> = vec![0.0; self.nodes.len()];
        for id in (0..self.nodes.len()).rev() {
            out[id] = match self.nodes[id].children {
                Some([l, r]) => out[l as usize].max(out[r as usize]),
                None => self
                    .node_points(id as u32)
                    .iter()
                    .map(|&i| per_point[i as usize])
                    .fold(0.0, Real::max),
            };
        }
        out
    }

    /// Traverses `self` (posed by `pose`, which maps `self`'s frame into `other`'s)
    /// and `other` together, returning the leaf pairs that could not be pruned.
    ///
    /// A node pair is pruned when [`prune_bound`] of the distance between their
    /// boxes (less the margin) (the first one's box moved by `pose`, enclosed in an axis-aligned box,
    /// which only makes the distance smaller and the bound safer) is below
    /// `epsilon`. With `epsilon = 0` nothing is pruned. The larger node of a pair
    /// is the one descended.
    ///
    /// `margin_self` and `margin_other` are optional per-node distances (one per
    /// node, or empty for none) subtracted from a pair's gap, the larger of the
    /// two: a margin of context kept around the noise-based near region.
    pub fn traverse_pairs(
        &self,
        other: &Bvh,
        pose: &Pose,
        epsilon: Real,
        margin_self: &[Real],
        margin_other: &[Real],
        workspace: &mut BvhWorkspace,
    ) -> PairTraversal {
        let keep_within = kept_without_bound(epsilon);
        self.traverse_pairs_keeping(
            other,
            pose,
            epsilon,
            (margin_self, margin_other),
            keep_within,
            workspace,
        )
    }

    /// [`Bvh::traverse_pairs`] with node pairs closer than `keep_within`
    /// times their deviations kept without the bound ([`kept_without_bound`];
    /// `-inf`: every pair by the bound, the tests' reference).
    pub(crate) fn traverse_pairs_keeping(
        &self,
        other: &Bvh,
        pose: &Pose,
        epsilon: Real,
        (margin_self, margin_other): (&[Real], &[Real]),
        keep_within: Real,
        workspace: &mut BvhWorkspace,
    ) -> PairTraversal {
        let margin = |m: &[Real], i: u32| m.get(i as usize).copied().unwrap_or(0.0);
        let mut out = PairTraversal::default();
        let mut pruned_bound = 0.0;
        let mut leaf_pairs = Vec::new();
        let motion = BoxMotion::new(pose);
        out.node_pairs_visited = self.descend_pairs(
            other,
            &mut workspace.pair_stack,
            |ia, ib| {
                let (na, nb) = (&self.nodes[ia as usize], &other.nodes[ib as usize]);
                let gap = (na.aabb.moved(&motion).distance(&nb.aabb)
                    - margin(margin_self, ia).max(margin(margin_other, ib)))
                .max(0.0);
                // Close pairs are kept without the Gaussian tail (most pairs of
                // an overlap); the bound decides the others.
                if gap <= keep_within * (na.sigma_max + nb.sigma_max) {
                    return true;
                }
                let bound = prune_bound(
                    gap,
                    na.sigma_max,
                    nb.sigma_max,
                    (na.count + nb.count) as usize,
                );
                if bound < epsilon {
                    pruned_bound += bound;
                    return false;
                }
                true
            },
            |ia, ib| self.nodes[ia as usize].count >= other.nodes[ib as usize].count,
            |ia, ib| {
                leaf_pairs.push((ia, ib));
                true
            },
        );
        out.leaf_pairs = leaf_pairs;
        out.pruned_bound = pruned_bound.min(1.0);
        out
    }

    /// The bounding volume test tree of `self` and `other`: from the root pair,
    /// every node pair for which `keep` holds is descended (where both nodes
    /// have children, `self`'s node is split when `split_self` says so; both
    /// nodes leaves: `leaf` is called), until `leaf` returns `false`. Returns
    /// the number of node pairs tested. The traversals differ in `keep` (what
    /// bounds a node pair), in which node they split first and in what a leaf
    /// pair does.
    pub(crate) fn descend_pairs(
        &self,
        other: &Bvh,
        stack: &mut Vec<(u32, u32)>,
        mut keep: impl FnMut(u32, u32) -> bool,
        split_self: impl Fn(u32, u32) -> bool,
        mut leaf: impl FnMut(u32, u32) -> bool,
    ) -> usize {
        let mut visited = 0;
        stack.clear();
        stack.push((0, 0));
        while let Some((ia, ib)) = stack.pop() {
            visited += 1;
            if !keep(ia, ib) {
                continue;
            }
            let (na, nb) = (&self.nodes[ia as usize], &other.nodes[ib as usize]);
            match (na.children, nb.children) {
                (None, None) => {
                    if !leaf(ia, ib) {
                        break;
                    }
                }
                (Some([l, r]), None) => {
                    stack.push((l, ib));
                    stack.push((r, ib));
                }
                (None, Some([l, r])) => {
                    stack.push((ia, l));
                    stack.push((ia, r));
                }
                (Some([al, ar]), Some([bl, br])) => {
                    if split_self(ia, ib) {
                        stack.push((al, ib));
                        stack.push((ar, ib));
                    } else {
                        stack.push((ia, bl));
                        stack.push((ia, br));
                    }
                }
            }
        }
        visited
    }
}
