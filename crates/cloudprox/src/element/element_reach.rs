//! Whether any element surface of one cloud can come within the noise's reach
//! of the other cloud's at all: a hierarchy over each cloud's elements, built
//! once in the cloud's own frame, whose node boxes enclose their elements'
//! fitted surfaces.
//!
//! The points model finds its near set from single points, and so does the
//! elements model from its elements' samples; but the samples of a large flat
//! element are a spacing of several millimetres apart, and the half spacing by
//! which sampled surfaces may come closer than their samples then keeps two
//! clouds "near" far beyond their noise (two 10 000-point spheres at 1 mm of
//! noise, 6 sigma apart: every query built near regions and patches only to find
//! that no element faces the other within reach). The element surfaces are
//! known, so this test bounds them directly: when no pair of elements passes
//! it, every patch of the query would be pruned, and the clouds are free.

use crate::bvh::{Aabb, BoxMotion, Bvh, BvhSettings, BvhWorkspace};
use crate::element::SurfaceElement;
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::Real;

/// The margin, in sampling spacings, by which two sampled surfaces may come
/// closer than their samples: half a spacing (as the near rule and the facing
/// rule of the crossing probabilities use).
pub(crate) const HALF_SPACING: Real = 0.5;

/// The hierarchy over element hulls keeps few hulls per leaf: hulls differ
/// far more than points do (a table top's plane half a metre across beside
/// single points seen at grazing angles with centimetres of noise), and a
/// node's box, sigma and margin are its widest hull's.
const HULL_TREE: BvhSettings = BvhSettings { leaf_max_points: 1 };

/// An element's fitted surface as the reach tests read it, in its cloud's own
/// frame.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Hull {
    /// The element's mean.
    pub mean: Point3,
    /// The element's normal.
    pub normal: Vector3,
    /// The fitted surface at the corners of the extent (all four the mean for a
    /// single point): the surface is a plane over the extent's rectangle, so
    /// every point of it lies in their convex hull.
    pub corners: [Point3; 4],
    /// The largest variance of the fitted height over the extent (at a corner:
    /// the variance is a convex quadratic of the tangential coordinates).
    pub var_max: Real,
    /// The largest distance of a corner from the mean, plus `sag`: every
    /// point of the surface lies within it of the mean.
    pub radius: Real,
    /// How far, along the normal, the fitted surface may lie from the corners'
    /// convex hull ([`SurfaceElement::sag_bound`]; 0 for a single point).
    pub sag: Real,
    /// A bound on the standard deviation, along any direction, of any point
    /// of the surface or of the element's samples.
    pub sigma: Real,
    /// Half the largest sampling spacing of the element and (for a single
    /// point) of its sample.
    pub margin: Real,
    /// Whether the element is a single point.
    pub point: bool,
}

impl Hull {
    /// A lower bound on the distance between the hull's surface (the convex
    /// hull of its corners, `sag` either side along its normal) and the box
    /// `local` of another frame, `to_local` taking the hull's frame there: the
    /// largest gap along the box's three axes and along the hull's normal
    /// (each a separating axis of two convex sets; 0 or less when they may
    /// meet).
    pub(crate) fn box_gap(&self, to_local: &Pose, local: &Aabb) -> Real {
        let corners = self.corners_moved(to_local);
        let n = to_local.rotation * self.normal;
        let mut gap = Real::NEG_INFINITY;
        for k in 0..3 {
            let (lo, hi) = corners
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), c| {
                    (lo.min(c[k]), hi.max(c[k]))
                });
            let widen = self.sag * n[k].abs();
            gap = gap.max((lo - widen - local.maxs[k]).max(local.mins[k] - hi - widen));
        }
        let (lo, hi) = corners
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), c| {
                let t = c.coords.dot(&n);
                (lo.min(t), hi.max(t))
            });
        let centre = local.center().coords.dot(&n);
        let half = local.half_extents().dot(&n.abs());
        gap.max((lo - self.sag - centre - half).max(centre - half - hi - self.sag))
    }

    /// The corners moved by `pose`. A plain loop: an array `map`'s closure
    /// is left out of line by some builds (four of criterion's microsecond
    /// cases 12-23% slower when it was, with no change to this code).
    #[inline]
    pub(crate) fn corners_moved(&self, pose: &Pose) -> [Point3; 4] {
        let mut out = self.corners;
        for c in &mut out {
            *c = pose * *c;
        }
        out
    }

    fn new(e: &SurfaceElement, sample_sigma: Real, sample_spacing: Real) -> Self {
        let across = across_normal(e);
        let mut corners = [e.mean; 4];
        let mut var_max: Real = 0.0;
        let mut radius: Real = 0.0;
        if !e.is_point() {
            let [[u0, u1], [v0, v1]] = e.extent;
            for (k, (u, v)) in [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
                .into_iter()
                .enumerate()
            {
                let (x, var) = e.surface_point(u, v);
                corners[k] = x;
                var_max = var_max.max(var);
                radius = radius.max((x - e.mean).norm());
            }
            var_max = var_max.max(e.height_var_bound());
        }
        let sag = e.sag_bound();
        let spacing = if e.is_point() {
            e.spacing.max(sample_spacing)
        } else {
            e.spacing
        };
        Self {
            mean: e.mean,
            normal: e.normal,
            corners,
            var_max,
            radius: radius + sag,
            sag,
            sigma: (var_max + across.trace()).max(0.0).sqrt().max(sample_sigma),
            margin: HALF_SPACING * spacing,
            point: e.is_point(),
        }
    }
}

/// The covariance of an element's surface across its normal (the whole
/// covariance of a single point).
pub(crate) fn across_normal(e: &SurfaceElement) -> Matrix3 {
    if e.is_point() {
        e.cov_mean
    } else {
        let p = Matrix3::identity() - e.normal * e.normal.transpose();
        p * e.cov_mean * p
    }
}

/// A lower bound on the distance between any point of the convex hull of
/// `corners_a` and any of `corners_b`: the largest gap between their
/// projections on the two normals and on the line between the means.
pub(crate) fn hull_gap(
    (mean_a, normal_a, corners_a): (&Point3, &Vector3, &[Point3; 4]),
    (mean_b, normal_b, corners_b): (&Point3, &Vector3, &[Point3; 4]),
) -> Real {
    let offset = mean_b - mean_a;
    let apart = offset.norm();
    let between = if apart > 0.0 {
        offset / apart
    } else {
        *normal_a
    };
    let span = |corners: &[Point3; 4], d: &Vector3| {
        corners
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), c| {
                let t = c.coords.dot(d);
                (lo.min(t), hi.max(t))
            })
    };
    [normal_a, normal_b, &between]
        .iter()
        .map(|d| {
            let (lo_a, hi_a) = span(corners_a, d);
            let (lo_b, hi_b) = span(corners_b, d);
            (lo_b - hi_a).max(lo_a - hi_b)
        })
        .fold(0.0, Real::max)
}

/// The hulls of a cloud's elements and a hierarchy over them (own frame).
#[derive(Debug, Clone)]
pub(crate) struct ElementHulls {
    hulls: Vec<Hull>,
    tree: Bvh,
    /// Per node, over all its elements.
    all: NodeBounds,
    /// Per node, over its surface elements only (single points left out):
    /// a scan's stray points carry centimetres of noise from their sparse
    /// sampling, and would otherwise widen every node above them.
    surfaces: NodeBounds,
}

/// Per node of an [`ElementHulls`] hierarchy: the box of some of its elements'
/// corners, the largest `sigma`, `margin` and `radius` among them, and
/// whether it has any.
#[derive(Debug, Clone)]
struct NodeBounds {
    boxes: Vec<Aabb>,
    sigma: Vec<Real>,
    margin: Vec<Real>,
    radius: Vec<Real>,
    any: Vec<bool>,
}

impl NodeBounds {
    /// The bounds over the hulls for which `counts` holds.
    fn new(tree: &Bvh, hulls: &[Hull], counts: impl Fn(&Hull) -> bool) -> Self {
        let n = tree.nodes().len();
        let mut out = Self {
            boxes: vec![Aabb::empty(); n],
            sigma: vec![0.0; n],
            margin: vec![0.0; n],
            radius: vec![0.0; n],
            any: vec![false; n],
        };
        for id in (0..n).rev() {
            if let Some([l, r]) = tree.nodes()[id].children {
                let (l, r) = (l as usize, r as usize);
                out.boxes[id] = out.boxes[l].merged(&out.boxes[r]);
                out.sigma[id] = out.sigma[l].max(out.sigma[r]);
                out.margin[id] = out.margin[l].max(out.margin[r]);
                out.radius[id] = out.radius[l].max(out.radius[r]);
                out.any[id] = out.any[l] || out.any[r];
                continue;
            }
            for &e in tree.node_points(id as u32) {
                let h = &hulls[e as usize];
                if !counts(h) {
                    continue;
                }
                for c in &h.corners {
                    out.boxes[id].take_point(&(c + h.normal * h.sag));
                    out.boxes[id].take_point(&(c - h.normal * h.sag));
                }
                out.sigma[id] = out.sigma[id].max(h.sigma);
                out.margin[id] = out.margin[id].max(h.margin);
                out.radius[id] = out.radius[id].max(h.radius);
                out.any[id] = true;
            }
        }
        out
    }

    /// The reach of node pair `(ia, ib)` at `k` standard deviations.
    fn limit(a: &Self, ia: usize, b: &Self, ib: usize, k: Real) -> Real {
        a.margin[ia].max(b.margin[ib]) + k * (a.sigma[ia] + b.sigma[ib])
    }
}

impl ElementHulls {
    /// The hulls of `elements`, with the largest standard deviation and
    /// sampling spacing of each element's samples (`sample_sigma`,
    /// `sample_spacing`, one per element).
    #[allow(clippy::expect_used)] // a cloud has at least one element, every mean finite
    pub(crate) fn new(
        elements: &[SurfaceElement],
        sample_sigma: &[Real],
        sample_spacing: &[Real],
    ) -> Self {
        let hulls: Vec<Hull> = elements
            .iter()
            .zip(sample_sigma.iter().zip(sample_spacing))
            .map(|(e, (&s, &h))| Hull::new(e, s, h))
            .collect();
        let means: Vec<Point3> = hulls.iter().map(|h| h.mean).collect();
        let sigmas: Vec<Real> = hulls.iter().map(|h| h.sigma).collect();
        let tree = Bvh::build(&means, &sigmas, &HULL_TREE)
            .expect("element means are finite and the default settings valid");
        let all = NodeBounds::new(&tree, &hulls, |_| true);
        let surfaces = NodeBounds::new(&tree, &hulls, |h| !h.point);
        Self {
            hulls,
            tree,
            all,
            surfaces,
        }
    }

    /// The node bounds over all elements, or over the surface elements alone.
    fn bounds(&self, surfaces_only: bool) -> &NodeBounds {
        if surfaces_only {
            &self.surfaces
        } else {
            &self.all
        }
    }

    /// The hull of element `e`.
    pub(crate) fn hull(&self, e: u32) -> &Hull {
        &self.hulls[e as usize]
    }

    /// Every element whose mean may lie within `radius + margin + reach sigma`
    /// of `bounds` (same frame; each element's own hull values), in
    /// increasing order, into `out` (cleared first): the hierarchy over the
    /// means, each node at its largest `radius`, `margin` and `sigma`. A
    /// superset of the elements that pass that test one by one. Returns the
    /// number of nodes tested.
    pub(crate) fn means_near_box(
        &self,
        bounds: &Aabb,
        reach: Real,
        out: &mut Vec<u32>,
        stack: &mut Vec<u32>,
    ) -> usize {
        let b = &self.all;
        let mut visited = 0;
        out.clear();
        stack.clear();
        stack.push(0);
        while let Some(id) = stack.pop() {
            visited += 1;
            let i = id as usize;
            let node = &self.tree.nodes()[i];
            let l = b.radius[i] + b.margin[i] + reach * b.sigma[i];
            if node.aabb.distance_squared(bounds) > l * l {
                continue;
            }
            match node.children {
                None => out.extend_from_slice(self.tree.node_points(id)),
                Some([l, r]) => {
                    stack.push(r);
                    stack.push(l);
                }
            }
        }
        out.sort_unstable();
        visited
    }

    /// Whether some element passes `leaf` among those whose node comes within
    /// `limit(sigma, margin)` of `bounds` (same frame), `sigma` and `margin`
    /// the node's largest over its elements: a one-sided descent, whose
    /// `false` proves that every element either lies in a node farther than
    /// its own limit from the box (the limit must grow with both arguments)
    /// or fails `leaf`. Returns the answer and the number of nodes tested.
    pub(crate) fn near_box(
        &self,
        bounds: &Aabb,
        limit: impl Fn(Real, Real) -> Real,
        mut leaf: impl FnMut(&Hull) -> bool,
        stack: &mut Vec<u32>,
    ) -> (bool, usize) {
        let b = &self.all;
        let mut visited = 0;
        stack.clear();
        stack.push(0);
        while let Some(id) = stack.pop() {
            visited += 1;
            let i = id as usize;
            let l = limit(b.sigma[i], b.margin[i]);
            if !b.any[i] || b.boxes[i].distance_squared(bounds) > l * l {
                continue;
            }
            match self.tree.nodes()[i].children {
                None => {
                    let points = self.tree.node_points(id);
                    if points.iter().any(|&e| leaf(&self.hulls[e as usize])) {
                        return (true, visited);
                    }
                }
                Some([l, r]) => {
                    stack.push(r);
                    stack.push(l);
                }
            }
        }
        (false, visited)
    }
}

/// Whether two elements' surfaces (A's hull `a`, posed as `corners`, `mean`,
/// `normal` in B's frame; B's hull `b`) may lie within `k` standard deviations
/// (each side's `sigma`) beyond the larger half spacing of each other. `false`
/// proves that no point of one surface, nor any sample, lies that close to the
/// other.
fn pair_may_reach(a: &Hull, posed: &PosedHull, b: &Hull, k: Real) -> bool {
    let limit = a.margin.max(b.margin) + k * (a.sigma + b.sigma);
    (b.mean - posed.mean).norm() - a.radius - b.radius <= limit
        && hull_gap(
            (&posed.mean, &posed.normal, &posed.corners),
            (&b.mean, &b.normal, &b.corners),
        ) - a.sag
            - b.sag
            <= limit
}

/// A hull's mean, normal and corners moved into the other cloud's frame.
struct PosedHull {
    mean: Point3,
    normal: Vector3,
    corners: [Point3; 4],
}

impl PosedHull {
    /// Hull `h` moved by `rel`.
    fn new(h: &Hull, rel: &Pose) -> Self {
        Self {
            mean: rel * h.mean,
            normal: rel.rotation * h.normal,
            corners: h.corners_moved(rel),
        }
    }
}

/// Whether some pair of elements, `ea` of `a` (at `rel` in `b`'s frame) and
/// `eb` of `b`, passes [`pair_may_reach`] (its surfaces may lie within reach
/// of each other) and then `test(ea, eb)`, the caller's exact test of the pair
/// (whether it faces the other within reach, or whether the two surfaces
/// cross). The traversal stops at the first such pair; `false` proves that no
/// pair passes both. From the first node pair for which `surfaces_only()`
/// holds on, single points are left out (the caller has learnt what it needed
/// of them): node pairs are bounded by their surface elements alone. Returns
/// the answer and the number of node pairs tested.
pub(crate) fn surfaces_may_reach(
    a: &ElementHulls,
    rel: &Pose,
    b: &ElementHulls,
    reach_sds: Real,
    workspace: &mut BvhWorkspace,
    surfaces_only: impl Fn() -> bool,
    mut test: impl FnMut(u32, u32) -> bool,
) -> (bool, usize) {
    // All of A as one box first: a node pair of the traversal below can only
    // pass where A's root passes with B's node (the root's box, sigma and
    // margin bound its descendants'), and this one-sided descent prunes
    // moderately distant pairs in a few nodes where the pair traversal would
    // split A's nodes first.
    let boxes = BoxGap::new(rel);
    let (near, visited_root) = root_may_reach(a, &boxes, b, reach_sds, &mut workspace.pair_stack);
    if !near {
        return (false, visited_root);
    }
    let mut found = false;
    let mut posed: Vec<PosedHull> = Vec::new();
    let visited = a.tree.descend_pairs(
        &b.tree,
        &mut workspace.pair_stack,
        (0, 0),
        |ia, ib| {
            let (ia, ib) = (ia as usize, ib as usize);
            let only = surfaces_only();
            let (na, nb) = (a.bounds(only), b.bounds(only));
            na.any[ia]
                && nb.any[ib]
                && !boxes.apart(
                    &na.boxes[ia],
                    &nb.boxes[ib],
                    NodeBounds::limit(na, ia, nb, ib, reach_sds),
                )
        },
        // The node whose box, grown by its reach, is the larger first: hulls
        // differ in size and noise far more than points do.
        |ia, ib| {
            let size = |h: &NodeBounds, i: u32| {
                let i = i as usize;
                h.boxes[i].half_extents().norm() + h.margin[i] + reach_sds * h.sigma[i]
            };
            let only = surfaces_only();
            size(a.bounds(only), ia) >= size(b.bounds(only), ib)
        },
        |la, lb| {
            let own = a.tree.node_points(la);
            posed.clear();
            posed.extend(
                own.iter()
                    .map(|&e| PosedHull::new(&a.hulls[e as usize], rel)),
            );
            for (&e, p) in own.iter().zip(&posed) {
                let h = &a.hulls[e as usize];
                for &f in b.tree.node_points(lb) {
                    let g = &b.hulls[f as usize];
                    if surfaces_only() && (h.point || g.point) {
                        continue;
                    }
                    if pair_may_reach(h, p, g, reach_sds) && test(e, f) {
                        found = true;
                        return false;
                    }
                }
            }
            true
        },
    );
    (found, visited_root + visited)
}

/// The gap test between a box of A (own frame, A at `rel` in B's frame) and
/// a box of B, prepared once per query.
struct BoxGap {
    /// A's frame into B's, and back.
    motion: BoxMotion,
    back: BoxMotion,
    /// Whether the motion keeps the axes (then the gap along B's axes is the
    /// boxes' distance, and A's axes add nothing).
    same_axes: bool,
}

impl BoxGap {
    fn new(rel: &Pose) -> Self {
        let motion = BoxMotion::new(rel);
        Self {
            motion,
            back: BoxMotion::new(&rel.inverse()),
            same_axes: motion.keeps_axes(),
        }
    }

    /// Whether boxes `of_a` and `of_b` are farther apart than `limit`: along
    /// B's axes (A's box moved into B's frame), then, when the motion turns
    /// the axes, along A's (B's box moved into A's). Each gap is a lower bound
    /// on the boxes' distance (on the real-mesh bench's turned poses at 0.5%,
    /// A's axes spare 12% of the node pairs over all poses, 32% over those
    /// the hulls decide).
    fn apart(&self, of_a: &Aabb, of_b: &Aabb, limit: Real) -> bool {
        self.apart_moved(of_a, &of_a.moved(&self.motion), of_b, limit)
    }

    /// [`BoxGap::apart`] with A's box already moved into B's frame
    /// (`moved_a`), for a box tested against many.
    fn apart_moved(&self, of_a: &Aabb, moved_a: &Aabb, of_b: &Aabb, limit: Real) -> bool {
        let beyond = |x: &Aabb, y: &Aabb| x.distance_squared(y) > limit * limit;
        beyond(moved_a, of_b) || (!self.same_axes && beyond(&of_b.moved(&self.back), of_a))
    }
}

/// Whether the box of all of `a`'s element corners (moved by `boxes`),
/// with `a`'s largest sigma and margin, comes within reach of some leaf of
/// `b`'s hierarchy (by the node rule of [`surfaces_may_reach`]). `false`
/// proves that no node pair of that traversal passes. Returns the answer and
/// the number of nodes of `b` tested.
fn root_may_reach(
    a: &ElementHulls,
    boxes: &BoxGap,
    b: &ElementHulls,
    reach_sds: Real,
    stack: &mut Vec<(u32, u32)>,
) -> (bool, usize) {
    let tree_b = &b.tree;
    let (a, b) = (&a.all, &b.all);
    let root = &a.boxes[0];
    let moved_root = root.moved(&boxes.motion);
    let (sigma, margin) = (a.sigma[0], a.margin[0]);
    let mut visited = 0;
    stack.clear();
    stack.push((0, 0));
    while let Some((_, id)) = stack.pop() {
        visited += 1;
        let id = id as usize;
        let limit = margin.max(b.margin[id]) + reach_sds * (sigma + b.sigma[id]);
        if boxes.apart_moved(root, &moved_root, &b.boxes[id], limit) {
            continue;
        }
        match tree_b.nodes()[id].children {
            None => return (true, visited),
            Some([l, r]) => {
                stack.push((0, r));
                stack.push((0, l));
            }
        }
    }
    (false, visited)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::cloud::PointCloud;
    use crate::sample::{add_noise, sphere};
    use nalgebra::{Translation3, UnitQuaternion};

    /// A noisy sphere with a few outliers (single-point elements) off its surface.
    fn cloud(radius: Real, n: usize, sigma: Real, seed: u64) -> PointCloud {
        let mut points = add_noise(&sphere(&Point3::origin(), radius, n), sigma, seed);
        for k in 0..8 {
            let t = k as Real * 0.8;
            let dir = Vector3::new(t.cos(), t.sin(), (t * 0.7).cos()).normalize();
            points.push(Point3::from(dir * (radius + (k % 3) as Real * 4.0 * sigma)));
        }
        PointCloud::from_sigma(points, sigma).unwrap()
    }

    /// Every pair of hulls, without the hierarchy (the tests of
    /// [`all_pairs`]).
    fn brute_force(a: &ElementHulls, rel: &Pose, b: &ElementHulls, k: Real) -> bool {
        !all_pairs(a, rel, b, k).is_empty()
    }

    /// Every pair of hulls that reach each other, without the hierarchy: by
    /// [`pair_may_reach`] and by the boxes of their corners (the test of the
    /// hierarchy's one-hull leaves; the two are lower bounds on their
    /// distance, neither tighter than the other everywhere).
    fn all_pairs(a: &ElementHulls, rel: &Pose, b: &ElementHulls, k: Real) -> Vec<(u32, u32)> {
        let boxes = BoxGap::new(rel);
        let corners_box = |h: &Hull| {
            let mut x = Aabb::empty();
            for c in &h.corners {
                x.take_point(&(c + h.normal * h.sag));
                x.take_point(&(c - h.normal * h.sag));
            }
            x
        };
        let mut out = Vec::new();
        for (e, h) in a.hulls.iter().enumerate() {
            let p = PosedHull::new(h, rel);
            for (f, g) in b.hulls.iter().enumerate() {
                let limit = h.margin.max(g.margin) + k * (h.sigma + g.sigma);
                let apart = boxes.apart(&corners_box(h), &corners_box(g), limit);
                if !apart && pair_may_reach(h, &p, g, k) {
                    out.push((e as u32, f as u32));
                }
            }
        }
        out
    }

    /// Once told to leave single points out (here: after the first pair
    /// met), the descent still meets every pair of surface elements within
    /// reach, and no more pairs with a single point.
    #[test]
    fn the_descent_by_surfaces_alone_meets_every_surface_pair() {
        let (sigma, k) = (0.001, 4.9);
        let a = cloud(0.05, 3000, sigma, 5);
        // B with stray points off its surface towards A (single-point
        // elements in the contact zone).
        let mut pts = cloud(0.04, 2000, sigma, 6).points().to_vec();
        for j in 0..12 {
            let t = 0.15 * (j as Real - 5.5);
            let dir = Vector3::new(1.0, 0.6 * t, 0.4 * t.sin()).normalize();
            pts.push(Point3::from(dir * (0.04 + (3 + j % 4) as Real * sigma)));
        }
        let b = PointCloud::from_sigma(pts, sigma).unwrap();
        let (ha, hb) = (a.elements().hulls(), b.elements().hulls());
        let mut ws = BvhWorkspace::default();
        let (mut checked, mut with_points) = (0, 0);
        for step in 0..24 {
            let gap = -3.0 * sigma + step as Real * sigma;
            let turn = UnitQuaternion::from_euler_angles(0.3, 0.1 * step as Real, 0.2);
            let pose = Pose::from_parts(Translation3::new(0.09 + gap, 0.01, 0.0), turn);
            let is_surface = |(e, f): &(u32, u32)| !ha.hull(*e).point && !hb.hull(*f).point;
            let every = all_pairs(ha, &pose, hb, k);
            // Pairs with a single point the switch must leave out.
            with_points += usize::from(every.iter().filter(|p| !is_surface(p)).count() >= 2);
            let mut expected: Vec<(u32, u32)> = every.into_iter().filter(is_surface).collect();
            let met = std::cell::RefCell::new(Vec::new());
            let switched = || !met.borrow().is_empty();
            surfaces_may_reach(ha, &pose, hb, k, &mut ws, switched, |e, f| {
                met.borrow_mut().push((e, f));
                false
            });
            let met = met.into_inner();
            let points_met = met.iter().filter(|p| !is_surface(p)).count();
            assert!(
                points_met <= 1,
                "gap {gap}: {points_met} pairs with a point"
            );
            let mut surfaces: Vec<(u32, u32)> = met.into_iter().filter(is_surface).collect();
            surfaces.sort_unstable();
            expected.sort_unstable();
            assert_eq!(surfaces, expected, "gap {gap}");
            checked += usize::from(!expected.is_empty());
        }
        assert!(
            checked >= 6,
            "only {checked} poses with surface pairs within reach"
        );
        assert!(
            with_points >= 3,
            "only {with_points} poses with pairs of a single point"
        );
    }

    #[test]
    fn the_hierarchy_finds_a_reaching_pair_exactly_when_one_exists() {
        let (sigma, k) = (0.001, 4.9);
        let a = cloud(0.05, 3000, sigma, 3);
        let b = cloud(0.04, 2000, sigma, 4);
        let (ha, hb) = (a.elements().hulls(), b.elements().hulls());
        assert!(a.elements().multi_point_count() > 20);
        let mut ws = BvhWorkspace::default();
        let (mut reached, mut not) = (0, 0);
        // (Curved element surfaces reach by their sag too: the sweep runs
        // far enough for some poses to be beyond every reach.)
        for step in 0..60 {
            let gap = -3.0 * sigma + step as Real * 1.5 * sigma;
            let turn = UnitQuaternion::from_euler_angles(0.1 * step as Real, 0.4, -0.3);
            let dir = Vector3::new(1.0, 0.3 * (step % 5) as Real, -0.2).normalize();
            let pose = Pose::from_parts(Translation3::from(dir * (0.09 + gap)), turn);
            let (fast, _) = surfaces_may_reach(ha, &pose, hb, k, &mut ws, || false, |_, _| true);
            assert_eq!(fast, brute_force(ha, &pose, hb, k), "gap {gap}");
            if fast {
                reached += 1;
            } else {
                not += 1;
            }
        }
        // Both answers occur over the sweep.
        assert!(reached > 5 && not > 5, "{reached} reached, {not} not");
    }

    #[test]
    fn hulls_enclose_the_samples_and_bound_their_noise() {
        let c = cloud(0.05, 3000, 0.001, 5);
        let els = c.elements();
        let hulls = els.hulls();
        for (k, &e) in els.sample_owner().iter().enumerate() {
            let h = hulls.hull(e);
            let x = els.samples().points()[k];
            // A sample lies on its element's surface: no farther from the mean
            // than the farthest corner, and inside the corners' box.
            assert!((x - h.mean).norm() <= h.radius + 1e-12 || h.radius == 0.0);
            // (The surface is curved: within `sag` of the corners' hull.)
            let mut b = Aabb::empty();
            for c in &h.corners {
                b.take_point(&(c + h.normal * h.sag));
                b.take_point(&(c - h.normal * h.sag));
            }
            assert!(b.distance_squared_to_point(&x) <= 1e-20, "sample {k}");
            assert!(els.samples().sigma_max()[k] <= h.sigma * (1.0 + 1e-12));
            assert!(0.5 * els.elements()[e as usize].spacing <= h.margin);
        }
    }
}
