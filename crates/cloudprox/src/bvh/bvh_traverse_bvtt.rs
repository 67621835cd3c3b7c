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
    /// Sum over every pruned node pair of [`prune_bound`] (or, where Mills'
    /// ratio `phi(x) / x` already puts it below `epsilon`, of that larger
    /// bound: by a relative `1 / x^2` or so, 9% at `x = 3.3`, up to 1.5x
    /// near `x = 1`): an upper bound on the probability that any pruned point
    /// lies on the wrong side of a plane that separates its node's box from
    /// the other node's box (capped at 1; once the sum reaches the cap, pairs
    /// beyond every pair's pruning distance add nothing more).
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

/// Whether [`prune_bound`] prunes a pair (is below `epsilon`), and if so an
/// upper bound on it that is also below `epsilon`: exactly the pairs
/// [`prune_bound`] would prune, mostly without its `erfc`.
///
/// Mills' ratio brackets the tail with one exponential: `phi(x) x / (1 + x^2)
/// < Phi(-x) < phi(x) / x` for `x > 0`. The bracket is a relative `1 / x^2`
/// or so wide (9% at the closest pairs the default `epsilon`, 1e-3, prunes,
/// `x` about 3.3; less beyond), far wider than rounding while its ends are
/// normal numbers (`x` below about 37; beyond, subnormal rounding could
/// exceed it, and the exact bound decides): where `n` times its upper end is
/// below `epsilon` the pair is pruned and that end returned (above
/// [`prune_bound`]); where `n` times its lower end reaches `epsilon` the
/// pair is kept; only between them is [`prune_bound`] computed.
pub(crate) fn pruned_within(
    gap: Real,
    sigma_a: Real,
    sigma_b: Real,
    n: usize,
    epsilon: Real,
) -> Option<Real> {
    let s = sigma_a + sigma_b;
    let x = gap / s;
    if s > 0.0 && x > 1.0 {
        let tail = n as Real * (-0.5 * x * x).exp() / SQRT_2PI;
        let (lower, upper) = (tail * x / (1.0 + x * x), tail / x);
        if lower >= Real::MIN_POSITIVE {
            if upper < epsilon {
                return Some(upper);
            }
            if lower >= epsilon {
                return None;
            }
        }
    }
    let bound = prune_bound(gap, sigma_a, sigma_b, n);
    (bound < epsilon).then_some(bound)
}

/// `sqrt(2 pi)`.
const SQRT_2PI: Real = 2.506_628_274_631_000_5;

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
            NodeMargins {
                a: margin_self,
                b: margin_other,
                scale: 1.0,
            },
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
        margins: NodeMargins<'_>,
        keep_within: Real,
        workspace: &mut BvhWorkspace,
    ) -> PairTraversal {
        let test = PairTest::new(self, other, pose, epsilon, keep_within);
        let mut out = PairTraversal::default();
        let mut pruned_bound = 0.0;
        let mut leaf_pairs = Vec::new();
        out.node_pairs_visited = self.descend_pairs(
            other,
            &mut workspace.pair_stack,
            (0, 0),
            |ia, ib| test.keeps(ia, ib, margins, &mut pruned_bound),
            |ia, ib| test.split_first(ia, ib),
            |ia, ib| {
                leaf_pairs.push((ia, ib));
                true
            },
        );
        out.leaf_pairs = leaf_pairs;
        out.pruned_bound = pruned_bound.min(1.0);
        out
    }

    /// The traversal with the `inner` margins, and what the one with the
    /// `outer` margins (each at least as large, per node, as the inner one)
    /// adds to it, to be finished only if needed ([`WiderTraversal::finish`]).
    ///
    /// A larger margin only shrinks a pair's gap, and the bound only grows as
    /// the gap shrinks, so every pair the inner traversal keeps the outer one
    /// keeps too (not tested again: that monotony holds for the normal numbers
    /// [`pruned_within`] computes, and is checked in debug builds). Where the
    /// inner traversal prunes a pair, the outer test runs on the same
    /// distance: a pair it prunes too is recorded with its bound, one it
    /// keeps is recorded to be descended later, each at its place in the
    /// descent, so that the finished outer traversal has the leaf pairs in
    /// the order, the visits and the pruned sum of its own descent. The inner
    /// traversal costs about what it did alone (a near miss the inner margins
    /// prune stays cheap); a query that needs both descends each node pair
    /// once.
    pub(crate) fn traverse_pairs_nested<'t>(
        &'t self,
        other: &'t Bvh,
        pose: &Pose,
        epsilon: Real,
        inner: NodeMargins<'_>,
        outer: NodeMargins<'t>,
        workspace: &mut BvhWorkspace,
    ) -> (PairTraversal, WiderTraversal<'t>) {
        let test = PairTest::new(self, other, pose, epsilon, kept_without_bound(epsilon));
        let mut t_in = PairTraversal::default();
        let (mut pruned_in, mut pruned_out) = (0.0, 0.0);
        let mut steps = Vec::new();
        t_in.node_pairs_visited = self.descend_pairs(
            other,
            &mut workspace.pair_stack,
            (0, 0),
            |ia, ib| {
                let gap = test.distance(ia, ib);
                let Some(bound) = test.pruned(ia, ib, gap, inner, pruned_in >= 1.0) else {
                    debug_assert!(test.pruned(ia, ib, gap, outer, false).is_none());
                    // A kept pair of leaves (the descent's `leaf` below).
                    if self.nodes[ia as usize].is_leaf() && other.nodes[ib as usize].is_leaf() {
                        steps.push(Step::Leaf(ia, ib));
                    }
                    return true;
                };
                pruned_in += bound;
                // (The outer sum so far leaves out the pairs still to be
                // descended: a lower bound, so its cap is reached no sooner.)
                match test.pruned(ia, ib, gap, outer, pruned_out >= 1.0) {
                    Some(outer_bound) => {
                        pruned_out += outer_bound;
                        steps.push(Step::Pruned(outer_bound));
                    }
                    None => steps.push(Step::Descend(ia, ib)),
                }
                false
            },
            |ia, ib| test.split_first(ia, ib),
            |_, _| true,
        );
        // The inner leaf pairs are the recorded ones, in order.
        t_in.leaf_pairs = steps
            .iter()
            .filter_map(|step| match *step {
                Step::Leaf(ia, ib) => Some((ia, ib)),
                _ => None,
            })
            .collect();
        t_in.pruned_bound = pruned_in.min(1.0);
        let wider = WiderTraversal {
            test,
            margins: outer,
            steps,
            visited: t_in.node_pairs_visited,
        };
        (t_in, wider)
    }

    /// The bounding volume test tree of `self` and `other`: from the pair of
    /// nodes `(root_a, root_b)` (the roots: `(0, 0)`), every node pair for
    /// which `keep` holds is descended (where both nodes have children,
    /// `self`'s node is split when `split_self` says so; both nodes leaves:
    /// `leaf` is called), until `leaf` returns `false`. Returns the number of
    /// node pairs tested. The traversals differ in `keep` (what bounds a node
    /// pair), in which node they split first and in what a leaf pair does.
    pub(crate) fn descend_pairs(
        &self,
        other: &Bvh,
        stack: &mut Vec<(u32, u32)>,
        (root_a, root_b): (u32, u32),
        mut keep: impl FnMut(u32, u32) -> bool,
        split_self: impl Fn(u32, u32) -> bool,
        mut leaf: impl FnMut(u32, u32) -> bool,
    ) -> usize {
        let mut visited = 0;
        stack.clear();
        stack.push((root_a, root_b));
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

/// Per-node margins of a pair traversal: `scale` times each node's value in
/// `a` (the first hierarchy's nodes) and `b` (the second's); an empty slice:
/// none. A pair's margin is the larger of its two nodes'.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeMargins<'m> {
    /// Per node of the first hierarchy.
    pub a: &'m [Real],
    /// Per node of the second hierarchy.
    pub b: &'m [Real],
    /// Factor on every value (the near set's: spacings of context).
    pub scale: Real,
}

impl NodeMargins<'_> {
    /// The margin of the pair `(ia, ib)`.
    fn of(&self, ia: u32, ib: u32) -> Real {
        let one = |m: &[Real], i: u32| m.get(i as usize).map_or(0.0, |x| x * self.scale);
        one(self.a, ia).max(one(self.b, ib))
    }
}

/// The bound test of one node pair of two hierarchies (see
/// [`Bvh::traverse_pairs`]): the distance between the nodes' boxes (the first
/// moved by the pose), less a margin, against the Gaussian bound.
struct PairTest<'t> {
    a: &'t Bvh,
    b: &'t Bvh,
    motion: BoxMotion,
    epsilon: Real,
    keep_within: Real,
    /// Beyond this many deviations every pair is pruned, whatever its
    /// points: `-Phi^-1(epsilon / n)` with `n` all the points of both
    /// hierarchies (widened far beyond rounding; infinite, pruning nothing
    /// this way, where `epsilon` is 0).
    prune_beyond: Real,
}

impl<'t> PairTest<'t> {
    fn new(a: &'t Bvh, b: &'t Bvh, pose: &Pose, epsilon: Real, keep_within: Real) -> Self {
        let all = a.nodes.first().map_or(0, |n| n.count) + b.nodes.first().map_or(0, |n| n.count);
        let z = -normal_quantile(epsilon / all.max(1) as Real);
        Self {
            a,
            b,
            motion: BoxMotion::new(pose),
            epsilon,
            keep_within,
            // (NaN where `epsilon` is outside [0, 1]: nothing pruned this way.)
            prune_beyond: if z.is_nan() {
                Real::INFINITY
            } else {
                z.max(0.0) * (1.0 + 1e-6)
            },
        }
    }

    /// Whether the pair `(ia, ib)` is kept with `margins`; if not, its bound
    /// is added to `sum` (a running sum of pruned bounds, capped at 1 where
    /// it is read: see [`PairTest::pruned`]'s `saturated`).
    fn keeps(&self, ia: u32, ib: u32, margins: NodeMargins<'_>, sum: &mut Real) -> bool {
        let gap = self.distance(ia, ib);
        match self.pruned(ia, ib, gap, margins, *sum >= 1.0) {
            Some(bound) => {
                *sum += bound;
                false
            }
            None => true,
        }
    }

    /// Whether the first hierarchy's node of a pair is split first: the one
    /// with more points.
    fn split_first(&self, ia: u32, ib: u32) -> bool {
        self.a.nodes[ia as usize].count >= self.b.nodes[ib as usize].count
    }

    /// The distance between the boxes of node `ia` (moved) and node `ib`.
    fn distance(&self, ia: u32, ib: u32) -> Real {
        let (na, nb) = (&self.a.nodes[ia as usize], &self.b.nodes[ib as usize]);
        na.aabb.moved(&self.motion).distance(&nb.aabb)
    }

    /// The pair's bound if it prunes the pair, given the boxes' `distance`
    /// and per-node `margins` (the larger of the two nodes' is subtracted). With `saturated` (the caller's sum of bounds
    /// has reached its cap of 1, so only the decision matters), a pair
    /// beyond [`PairTest::prune_beyond`] deviations is pruned with a bound
    /// of 0, without computing it.
    fn pruned(
        &self,
        ia: u32,
        ib: u32,
        distance: Real,
        margins: NodeMargins<'_>,
        saturated: bool,
    ) -> Option<Real> {
        let (na, nb) = (&self.a.nodes[ia as usize], &self.b.nodes[ib as usize]);
        let gap = (distance - margins.of(ia, ib)).max(0.0);
        // Close pairs are kept without the Gaussian tail (most pairs of an
        // overlap); the bound decides the others.
        let sigma = na.sigma_max + nb.sigma_max;
        if gap <= self.keep_within * sigma {
            return None;
        }
        if saturated && gap > self.prune_beyond * sigma {
            return Some(0.0);
        }
        pruned_within(
            gap,
            na.sigma_max,
            nb.sigma_max,
            (na.count + nb.count) as usize,
            self.epsilon,
        )
    }
}

/// One step of the outer descent that [`Bvh::traverse_pairs_nested`]'s inner
/// one took or left, in the descent's order.
enum Step {
    /// A leaf pair both keep.
    Leaf(u32, u32),
    /// A pair both prune, with its outer bound.
    Pruned(Real),
    /// A pair the inner traversal pruned and the outer keeps: its
    /// descendants are the outer descent's alone.
    Descend(u32, u32),
}

/// The rest of an outer traversal after [`Bvh::traverse_pairs_nested`].
pub(crate) struct WiderTraversal<'t> {
    test: PairTest<'t>,
    margins: NodeMargins<'t>,
    steps: Vec<Step>,
    visited: usize,
}

impl WiderTraversal<'_> {
    /// The outer traversal, as [`Bvh::traverse_pairs`] with the outer margins
    /// gives it: the recorded steps in order, each pair left to descend
    /// descended where it was met.
    pub(crate) fn finish(self, workspace: &mut BvhWorkspace) -> PairTraversal {
        let test = &self.test;
        let (a, b) = (test.a, test.b);
        let margins = self.margins;
        let mut out = PairTraversal {
            node_pairs_visited: self.visited,
            ..PairTraversal::default()
        };
        let mut pruned = 0.0;
        for step in &self.steps {
            match *step {
                Step::Leaf(ia, ib) => out.leaf_pairs.push((ia, ib)),
                Step::Pruned(bound) => pruned += bound,
                Step::Descend(ia, ib) => {
                    // The pair itself was visited (and kept) already.
                    let mut first = true;
                    let visited = a.descend_pairs(
                        b,
                        &mut workspace.pair_stack,
                        (ia, ib),
                        |ja, jb| {
                            std::mem::take(&mut first) || test.keeps(ja, jb, margins, &mut pruned)
                        },
                        |ja, jb| test.split_first(ja, jb),
                        |ja, jb| {
                            out.leaf_pairs.push((ja, jb));
                            true
                        },
                    );
                    out.node_pairs_visited += visited - 1;
                }
            }
        }
        out.pruned_bound = pruned.min(1.0);
        out
    }
}
