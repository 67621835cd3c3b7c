//! The hierarchy over a mesh's triangles behind [`super::MeshDistance`]: closest
//! points (nearest first, optionally bounded), the triangles near a box, the
//! pairs of overlapping triangles, and the generalized winding number
//! evaluated hierarchically (Jacobson, Kavan & Sorkine-Hornung 2013, section
//! 3.3: a subtree whose box does not hold the query point is replaced by a fan
//! over its boundary edges, which has the same winding number there).
//!
//! The point-triangle routine is the Voronoi-region walk of Ericson, *Real-Time
//! Collision Detection* (2005), section 5.1.5, which also names the feature
//! (corner, edge or interior) the closest point lies on: the angle-weighted
//! pseudo-normal sign needs it.

use crate::math::{Point3, Vector3};
use crate::Real;

/// Triangles per leaf.
const LEAF_TRIANGLES: usize = 4;

/// Traversal stack size: the tree splits at the median, so its depth is at
/// most `log2(n / LEAF_TRIANGLES) + 2` (34 for `2^32` triangles) and a
/// depth-first walk never holds more than depth + 1 pending nodes.
const STACK: usize = 96;

/// A closest point this close (in barycentric or edge parameter) to an edge or
/// a corner is labelled as lying on it, so that the sign reads that feature's
/// pseudo-normal rather than a neighbouring face's.
const SNAP: Real = 1e-12;

/// The part of a triangle a closest point lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Feature {
    /// Corner `k` (0, 1, 2 for a, b, c).
    Vertex(u8),
    /// The edge from corner `k` to corner `(k + 1) % 3`.
    Edge(u8),
    /// The interior.
    Face,
}

/// The closest point to `p` on the segment from `a` to `a + d`, labelled as
/// edge `k` (corners `k` and `(k + 1) % 3` at its ends).
fn on_edge(p: &Point3, a: &Point3, d: &Vector3, k: u8) -> (Point3, Feature) {
    let dd = d.norm_squared();
    let t = if dd > 0.0 {
        ((p - a).dot(d) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    edge_point(a, d, t, k)
}

/// `a + t d` on edge `k`, snapped to a corner label near the ends.
fn edge_point(a: &Point3, d: &Vector3, t: Real, k: u8) -> (Point3, Feature) {
    let feature = if t <= SNAP {
        Feature::Vertex(k)
    } else if t >= 1.0 - SNAP {
        Feature::Vertex((k + 1) % 3)
    } else {
        Feature::Edge(k)
    };
    (a + d * t, feature)
}

/// The closest point to `p` on triangle `(a, b, c)` and the feature it lies
/// on. A degenerate (zero-area) triangle is treated as its three edges.
pub(crate) fn closest_on_triangle(
    p: &Point3,
    a: &Point3,
    b: &Point3,
    c: &Point3,
) -> (Point3, Feature) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, Feature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        // d1 - d3 = |ab|^2.
        let den = d1 - d3;
        let t = if den > 0.0 { d1 / den } else { 0.0 };
        return edge_point(a, &ab, t, 0);
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        // d2 - d6 = |ac|^2; the edge runs from c to a (edge 2).
        let den = d2 - d6;
        let t = if den > 0.0 { d2 / den } else { 0.0 };
        return edge_point(c, &(a - c), 1.0 - t, 2);
    }
    let va = d3 * d6 - d5 * d4;
    let e4 = d4 - d3;
    let e5 = d5 - d6;
    if va <= 0.0 && e4 >= 0.0 && e5 >= 0.0 {
        // e4 + e5 = |bc|^2.
        let den = e4 + e5;
        let t = if den > 0.0 { e4 / den } else { 0.0 };
        return edge_point(b, &(c - b), t, 1);
    }
    // va + vb + vc = |ab x ac|^2.
    let den = va + vb + vc;
    if den <= Real::MIN_POSITIVE || !den.is_finite() {
        return degenerate_closest(p, a, b, c);
    }
    let v = vb / den;
    let w = vc / den;
    let u = 1.0 - v - w;
    let q = a + ab * v + ac * w;
    let feature = match (u <= SNAP, v <= SNAP, w <= SNAP) {
        (false, false, false) => Feature::Face,
        // One small weight: the edge opposite that corner.
        (true, false, false) => Feature::Edge(1),
        (false, true, false) => Feature::Edge(2),
        (false, false, true) => Feature::Edge(0),
        // Two small: the third corner.
        (false, true, true) => Feature::Vertex(0),
        (true, false, true) => Feature::Vertex(1),
        (true, true, _) => Feature::Vertex(2),
    };
    (q, feature)
}

/// The closest point to `p` on the three edges of a degenerate triangle.
fn degenerate_closest(p: &Point3, a: &Point3, b: &Point3, c: &Point3) -> (Point3, Feature) {
    let cands = [
        on_edge(p, a, &(b - a), 0),
        on_edge(p, b, &(c - b), 1),
        on_edge(p, c, &(a - c), 2),
    ];
    let mut best = cands[0];
    let mut best_d = (p - best.0).norm_squared();
    for cand in &cands[1..] {
        let d = (p - cand.0).norm_squared();
        if d < best_d {
            best = *cand;
            best_d = d;
        }
    }
    best
}

/// A triangle prepared for squared distances: a corner, the two edges from
/// it and their dot products.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriData {
    a: Vector3,
    ab: Vector3,
    ac: Vector3,
    ab2: Real,
    ac2: Real,
    abac: Real,
    /// Zero area: measured as its edges.
    degenerate: bool,
}

impl TriData {
    /// The data of triangle `(a, b, c)`.
    pub(crate) fn new(a: &Point3, b: &Point3, c: &Point3) -> Self {
        let ab = b - a;
        let ac = c - a;
        let (ab2, ac2, abac) = (ab.norm_squared(), ac.norm_squared(), ab.dot(&ac));
        Self {
            a: a.coords,
            ab,
            ac,
            ab2,
            ac2,
            abac,
            // (Also when NaN.)
            degenerate: (ab2 * ac2 - abac * abac).partial_cmp(&Real::MIN_POSITIVE)
                != Some(std::cmp::Ordering::Greater),
        }
    }

    /// The squared distance from `p`: the same Voronoi-region walk as
    /// [`closest_on_triangle`], with the dot products of the edges
    /// precomputed (`ab . bp = ab . ap - |ab|^2`, and so on).
    #[inline]
    pub(crate) fn distance2(&self, p: &Point3) -> Real {
        let ap = p.coords - self.a;
        if self.degenerate {
            let a = Point3::from(self.a);
            let (q, _) = closest_on_triangle(p, &a, &(a + self.ab), &(a + self.ac));
            return (p - q).norm_squared();
        }
        let d1 = self.ab.dot(&ap);
        let d2 = self.ac.dot(&ap);
        if d1 <= 0.0 && d2 <= 0.0 {
            return ap.norm_squared();
        }
        let d3 = d1 - self.ab2;
        let d4 = d2 - self.abac;
        if d3 >= 0.0 && d4 <= d3 {
            return (ap - self.ab).norm_squared();
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            return (ap - self.ab * (d1 / self.ab2)).norm_squared();
        }
        let d5 = d1 - self.abac;
        let d6 = d2 - self.ac2;
        if d6 >= 0.0 && d5 <= d6 {
            return (ap - self.ac).norm_squared();
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            return (ap - self.ac * (d2 / self.ac2)).norm_squared();
        }
        let va = d3 * d6 - d5 * d4;
        let e4 = d4 - d3;
        let e5 = d5 - d6;
        if va <= 0.0 && e4 >= 0.0 && e5 >= 0.0 {
            let w = e4 / (e4 + e5);
            return (ap - self.ab - (self.ac - self.ab) * w).norm_squared();
        }
        let den = va + vb + vc;
        let v = vb / den;
        let w = vc / den;
        (ap - self.ab * v - self.ac * w).norm_squared()
    }
}

/// The signed solid angle of triangle `(a, b, c)` seen from `p` (Van Oosterom
/// & Strackee 1983): positive when `p` is on the side its counter-clockwise
/// normal points away from, so that a closed, outward-oriented surface sums to
/// `4 pi` inside and 0 outside. Zero for a point on the triangle's plane outside
/// it, and for a point at a corner.
pub(crate) fn solid_angle(p: &Point3, a: &Point3, b: &Point3, c: &Point3) -> Real {
    let va = a - p;
    let vb = b - p;
    let vc = c - p;
    let la = va.norm();
    let lb = vb.norm();
    let lc = vc.norm();
    let num = va.dot(&vb.cross(&vc));
    let den = la * lb * lc + va.dot(&vb) * lc + va.dot(&vc) * lb + vb.dot(&vc) * la;
    2.0 * num.atan2(den)
}

/// Whether the ray `origin + t dir` (`t >= 0`, `inv` the reciprocal of
/// `dir`) meets box `b` (slab test, a little generous).
fn ray_hits_box(origin: &Point3, inv: &Vector3, b: &Box3) -> bool {
    let mut near: Real = 0.0;
    let mut far = Real::INFINITY;
    for k in 0..3 {
        let margin = 1e-9
            * (b.maxs[k] - b.mins[k])
                .abs()
                .max(origin[k].abs())
                .max(1e-300);
        let t0 = (b.mins[k] - margin - origin[k]) * inv[k];
        let t1 = (b.maxs[k] + margin - origin[k]) * inv[k];
        let (lo, hi) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        near = near.max(lo);
        far = far.min(hi);
        if near > far {
            return false;
        }
    }
    true
}

/// Whether (and how) the ray from `o` along `d` crosses triangle `(a, b, c)`:
/// `Some(1)` leaving through its front (the side its counter-clockwise normal
/// points to), `Some(-1)` entering, `Some(0)` missing it, `None` grazing its
/// boundary or running in its plane within rounding (Moller & Trumbore 1997,
/// with tolerances).
pub(crate) fn ray_crossing(
    o: &Point3,
    d: &Vector3,
    a: &Point3,
    b: &Point3,
    c: &Point3,
) -> Option<i32> {
    const TOL: Real = 1e-10;
    let e1 = b - a;
    let e2 = c - a;
    let pvec = d.cross(&e2);
    let det = e1.dot(&pvec);
    let scale = e1.norm() * e2.norm() * d.norm();
    let tvec = o - a;
    if det.abs() <= TOL * scale {
        // Parallel to the plane: a miss unless the ray runs in it.
        let n = e1.cross(&e2);
        let off = n.dot(&tvec);
        return if scale == 0.0 || off.abs() > TOL * n.norm() * tvec.norm().max(e1.norm()) {
            Some(0)
        } else {
            None
        };
    }
    let inv = 1.0 / det;
    let u = tvec.dot(&pvec) * inv;
    if !(-TOL..=1.0 + TOL).contains(&u) {
        return Some(0);
    }
    let qvec = tvec.cross(&e1);
    let v = d.dot(&qvec) * inv;
    if v < -TOL || u + v > 1.0 + TOL {
        return Some(0);
    }
    let t = e2.dot(&qvec) * inv;
    // A point in the triangle (within rounding) is neither side of it.
    let t_tol = TOL * (e1.norm() + e2.norm() + tvec.norm()) / d.norm();
    if t < -t_tol {
        return Some(0);
    }
    if t <= t_tol {
        return None;
    }
    if u <= TOL || v <= TOL || u + v >= 1.0 - TOL {
        return None;
    }
    // det = -d . (e1 x e2): negative when leaving through the front.
    Some(if det < 0.0 { 1 } else { -1 })
}

/// An axis-aligned box as two corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Box3 {
    /// The lower corner.
    pub(crate) mins: [Real; 3],
    /// The upper corner.
    pub(crate) maxs: [Real; 3],
}

impl Box3 {
    /// The box holding nothing.
    pub(crate) const EMPTY: Box3 = Box3 {
        mins: [Real::INFINITY; 3],
        maxs: [Real::NEG_INFINITY; 3],
    };

    /// The box of a triangle's corners.
    pub(crate) fn of_triangle(t: &[Point3; 3]) -> Self {
        let mut b = Self::EMPTY;
        for p in t {
            b.take(p);
        }
        b
    }

    /// Grows the box to hold `p`.
    pub(crate) fn take(&mut self, p: &Point3) {
        for k in 0..3 {
            self.mins[k] = self.mins[k].min(p[k]);
            self.maxs[k] = self.maxs[k].max(p[k]);
        }
    }

    /// The smallest box holding both.
    pub(crate) fn merged(&self, o: &Box3) -> Self {
        let mut b = *self;
        for k in 0..3 {
            b.mins[k] = b.mins[k].min(o.mins[k]);
            b.maxs[k] = b.maxs[k].max(o.maxs[k]);
        }
        b
    }

    /// The squared distance from `p` to the box (0 inside).
    #[inline]
    pub(crate) fn distance2_to_point(&self, p: &Point3) -> Real {
        let mut d2 = 0.0;
        for k in 0..3 {
            let d = (self.mins[k] - p[k]).max(p[k] - self.maxs[k]).max(0.0);
            d2 += d * d;
        }
        d2
    }

    /// The squared distance between two boxes (0 when they overlap).
    #[inline]
    pub(crate) fn distance2_to_box(&self, o: &Box3) -> Real {
        let mut d2 = 0.0;
        for k in 0..3 {
            let d = (self.mins[k] - o.maxs[k])
                .max(o.mins[k] - self.maxs[k])
                .max(0.0);
            d2 += d * d;
        }
        d2
    }

    /// Whether `p` is in the box grown by `margin` on every side.
    pub(crate) fn contains_with_margin(&self, p: &Point3, margin: Real) -> bool {
        (0..3).all(|k| p[k] >= self.mins[k] - margin && p[k] <= self.maxs[k] + margin)
    }

    /// The centre.
    pub(crate) fn center(&self) -> Point3 {
        Point3::new(
            0.5 * (self.mins[0] + self.maxs[0]),
            0.5 * (self.mins[1] + self.maxs[1]),
            0.5 * (self.mins[2] + self.maxs[2]),
        )
    }

    /// The length of the diagonal.
    pub(crate) fn diagonal(&self) -> Real {
        (0..3)
            .map(|k| (self.maxs[k] - self.mins[k]).powi(2))
            .sum::<Real>()
            .sqrt()
    }
}

/// A node: a box and either two children (`count == 0`: `first` and
/// `first + 1`) or a leaf's triangles (`first .. first + count`).
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Box3,
    first: u32,
    count: u32,
}

/// One triangle of the hierarchy, in leaf order.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tri {
    /// The corners (as oriented for the sign).
    pub(crate) corners: [Point3; 3],
    /// The corners' vertex ids after welding.
    pub(crate) ids: [u32; 3],
    /// The index of the face in the mesh it came from.
    pub(crate) face: u32,
}

/// A triangle hierarchy (median split on the widest axis of the centroids).
#[derive(Debug, Clone)]
pub(crate) struct TriangleBvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    boxes: Vec<Box3>,
    data: Vec<TriData>,
}

impl TriangleBvh {
    /// The hierarchy over `tris` (at least one).
    pub(crate) fn new(tris: &[Tri]) -> Self {
        let n = tris.len();
        let centroids: Vec<Point3> = tris
            .iter()
            .map(|t| {
                Point3::from(
                    (t.corners[0].coords + t.corners[1].coords + t.corners[2].coords) / 3.0,
                )
            })
            .collect();
        let boxes_in: Vec<Box3> = tris.iter().map(|t| Box3::of_triangle(&t.corners)).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = vec![Node {
            bounds: Box3::EMPTY,
            first: 0,
            count: 0,
        }];
        let mut pending = vec![(0usize, 0usize, n)];
        while let Some((id, start, end)) = pending.pop() {
            let slice = &mut order[start..end];
            let bounds = slice
                .iter()
                .fold(Box3::EMPTY, |b, &t| b.merged(&boxes_in[t as usize]));
            if end - start <= LEAF_TRIANGLES {
                nodes[id] = Node {
                    bounds,
                    first: start as u32,
                    count: (end - start) as u32,
                };
                continue;
            }
            let mut cb = Box3::EMPTY;
            for &t in slice.iter() {
                cb.take(&centroids[t as usize]);
            }
            let axis = (0..3)
                .max_by(|&i, &j| (cb.maxs[i] - cb.mins[i]).total_cmp(&(cb.maxs[j] - cb.mins[j])))
                .unwrap_or(0);
            let mid = (end - start) / 2;
            slice.select_nth_unstable_by(mid, |&s, &t| {
                centroids[s as usize][axis].total_cmp(&centroids[t as usize][axis])
            });
            let left = nodes.len();
            nodes.push(nodes[id]);
            nodes.push(nodes[id]);
            nodes[id] = Node {
                bounds,
                first: left as u32,
                count: 0,
            };
            pending.push((left + 1, start + mid, end));
            pending.push((left, start, start + mid));
        }
        let tris: Vec<Tri> = order.iter().map(|&t| tris[t as usize]).collect();
        let boxes = order.iter().map(|&t| boxes_in[t as usize]).collect();
        let data = tris
            .iter()
            .map(|t| TriData::new(&t.corners[0], &t.corners[1], &t.corners[2]))
            .collect();
        Self {
            nodes,
            tris,
            boxes,
            data,
        }
    }

    /// The triangles, in leaf order (the indices the queries return).
    pub(crate) fn tris(&self) -> &[Tri] {
        &self.tris
    }

    /// The box of triangle `t` (leaf order).
    pub(crate) fn tri_box(&self, t: u32) -> &Box3 {
        &self.boxes[t as usize]
    }

    /// The box of every triangle.
    pub(crate) fn bounds(&self) -> Box3 {
        self.nodes[0].bounds
    }

    /// The squared distance from `p` to triangle `t` (leaf order).
    #[inline]
    pub(crate) fn distance2(&self, p: &Point3, t: u32) -> Real {
        self.data[t as usize].distance2(p)
    }

    /// The nearest triangle to `p` no farther than `sqrt(max_distance2)`, and
    /// the squared distance: `None` if every triangle is farther. With
    /// `hint`, that triangle is tried first (a neighbour's nearest, usually
    /// nearest here too, makes the bound tight from the start).
    pub(crate) fn nearest(
        &self,
        p: &Point3,
        max_distance2: Real,
        hint: Option<u32>,
    ) -> Option<(u32, Real)> {
        let mut best = max_distance2;
        let mut found: Option<u32> = None;
        if let Some(h) = hint {
            let d2 = self.distance2(p, h);
            if d2 <= best {
                best = d2;
                found = Some(h);
            }
        }
        let mut stack = [(0u32, 0.0 as Real); STACK];
        let mut len = 1;
        stack[0] = (0, self.nodes[0].bounds.distance2_to_point(p));
        while len > 0 {
            len -= 1;
            let (id, d2) = stack[len];
            if d2 > best || (found.is_some() && d2 == best) {
                continue;
            }
            let node = &self.nodes[id as usize];
            if node.count > 0 {
                for t in node.first..node.first + node.count {
                    if Some(t) == hint {
                        continue;
                    }
                    if self.boxes[t as usize].distance2_to_point(p) > best {
                        continue;
                    }
                    let d2 = self.distance2(p, t);
                    if d2 < best || (found.is_none() && d2 <= best) {
                        best = d2;
                        found = Some(t);
                    }
                }
                continue;
            }
            let (l, r) = (node.first, node.first + 1);
            let dl = self.nodes[l as usize].bounds.distance2_to_point(p);
            let dr = self.nodes[r as usize].bounds.distance2_to_point(p);
            // The nearer child is popped first.
            let (near, far) = if dl <= dr {
                ((l, dl), (r, dr))
            } else {
                ((r, dr), (l, dl))
            };
            if far.1 <= best && len < STACK {
                stack[len] = far;
                len += 1;
            }
            if near.1 <= best && len < STACK {
                stack[len] = near;
                len += 1;
            }
        }
        found.map(|t| (t, best))
    }

    /// The signed number of times the ray from `origin` along `dir` crosses
    /// the triangles (+1 leaving through a face's front, -1 entering), or
    /// `None` if it grazes an edge, a corner or a face's plane within
    /// rounding (then another direction must be tried).
    pub(crate) fn ray_crossings(&self, origin: &Point3, dir: &Vector3) -> Option<i32> {
        let inv = dir.map(|d| 1.0 / d);
        let mut count = 0;
        let mut stack = [0u32; STACK];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len] as usize];
            if !ray_hits_box(origin, &inv, &node.bounds) {
                continue;
            }
            if node.count > 0 {
                for t in node.first..node.first + node.count {
                    let c = &self.tris[t as usize].corners;
                    count += ray_crossing(origin, dir, &c[0], &c[1], &c[2])?;
                }
            } else if len + 2 <= STACK {
                stack[len] = node.first;
                stack[len + 1] = node.first + 1;
                len += 2;
            }
        }
        Some(count)
    }

    /// Pushes onto `out` every triangle whose box is within
    /// `sqrt(max_distance2)` of `query` (a superset of the triangles within
    /// that distance of it).
    pub(crate) fn near_box(&self, query: &Box3, max_distance2: Real, out: &mut Vec<u32>) {
        let mut stack = [0u32; STACK];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len] as usize];
            if node.bounds.distance2_to_box(query) > max_distance2 {
                continue;
            }
            if node.count > 0 {
                for t in node.first..node.first + node.count {
                    if self.boxes[t as usize].distance2_to_box(query) <= max_distance2 {
                        out.push(t);
                    }
                }
            } else if len + 2 <= STACK {
                stack[len] = node.first;
                stack[len + 1] = node.first + 1;
                len += 2;
            }
        }
    }

    /// Whether `test` holds for some pair of distinct triangles (leaf order,
    /// `s < t`) whose boxes, grown by `margin`, overlap. Stops at the first.
    pub(crate) fn any_overlapping_pair(
        &self,
        margin: Real,
        test: &mut impl FnMut(u32, u32) -> bool,
    ) -> bool {
        let overlap = |a: &Box3, b: &Box3| {
            (0..3).all(|k| a.mins[k] <= b.maxs[k] + margin && b.mins[k] <= a.maxs[k] + margin)
        };
        let mut pending = vec![(0u32, 0u32)];
        while let Some((i, j)) = pending.pop() {
            let (a, b) = (&self.nodes[i as usize], &self.nodes[j as usize]);
            if !overlap(&a.bounds, &b.bounds) {
                continue;
            }
            match (a.count > 0, b.count > 0) {
                (true, true) => {
                    for s in a.first..a.first + a.count {
                        for t in b.first..b.first + b.count {
                            let pair = if i == j { s < t } else { true };
                            if pair
                                && overlap(&self.boxes[s as usize], &self.boxes[t as usize])
                                && test(s.min(t), s.max(t))
                            {
                                return true;
                            }
                        }
                    }
                }
                _ if i == j => {
                    let (l, r) = (a.first, a.first + 1);
                    pending.extend([(l, l), (r, r), (l, r)]);
                }
                (false, _) if b.count > 0 || a.bounds.diagonal() >= b.bounds.diagonal() => {
                    pending.extend([(a.first, j), (a.first + 1, j)]);
                }
                _ => pending.extend([(i, b.first), (i, b.first + 1)]),
            }
        }
        false
    }
}

/// The fans that close every node's patch of a [`TriangleBvh`], for the
/// hierarchical winding number.
#[derive(Debug, Clone)]
pub(crate) struct BoundaryFans {
    /// Per node, its net boundary edges as corner points:
    /// `boundary[ranges[n].0 .. ranges[n].1]` (the apex is the node box's centre).
    boundary: Vec<[Point3; 2]>,
    ranges: Vec<(u32, u32)>,
}

impl BoundaryFans {
    /// Prepares the hierarchical winding number: every node's net boundary
    /// (its triangles' directed edges, each cancelled by a reverse), from the
    /// leaves up. `positions` are the welded vertices the triangles' ids index.
    pub(crate) fn new(bvh: &TriangleBvh, positions: &[Point3]) -> Self {
        let n = bvh.nodes.len();
        let mut flat: Vec<[u32; 2]> = Vec::new();
        let mut ranges = vec![(0u32, 0u32); n];
        // Children come after their parent: from the last node back, every
        // child's boundary is known before its parent's.
        for id in (0..n).rev() {
            let node = bvh.nodes[id];
            let mut edges: Vec<[u32; 2]> = if node.count > 0 {
                (node.first..node.first + node.count)
                    .flat_map(|t| {
                        let [a, b, c] = bvh.tris[t as usize].ids;
                        [[a, b], [b, c], [c, a]]
                    })
                    .collect()
            } else {
                let (ls, le) = ranges[node.first as usize];
                let (rs, re) = ranges[node.first as usize + 1];
                flat[ls as usize..le as usize]
                    .iter()
                    .chain(&flat[rs as usize..re as usize])
                    .copied()
                    .collect()
            };
            cancel_reverse_pairs(&mut edges);
            let start = flat.len() as u32;
            flat.extend(edges);
            ranges[id] = (start, flat.len() as u32);
        }
        let boundary = flat
            .iter()
            .map(|&[a, b]| [positions[a as usize], positions[b as usize]])
            .collect();
        Self { boundary, ranges }
    }

    /// The generalized winding number at `p` (sum of solid angles over `4 pi`),
    /// hierarchically: exact, no approximation. `bvh` is the hierarchy these fans were made for.
    pub(crate) fn winding_number(&self, bvh: &TriangleBvh, p: &Point3) -> Real {
        let margin = 1e-9 * bvh.nodes[0].bounds.diagonal();
        let mut sum = 0.0;
        let mut stack = [0u32; STACK];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let id = stack[len] as usize;
            let node = &bvh.nodes[id];
            if !node.bounds.contains_with_margin(p, margin) {
                // The patch and the fan over its boundary (apex inside the box)
                // bound a closed chain inside the box: equal winding outside.
                let (s, e) = self.ranges[id];
                if s < e {
                    let apex = node.bounds.center();
                    for [a, b] in &self.boundary[s as usize..e as usize] {
                        sum += solid_angle(p, a, b, &apex);
                    }
                }
            } else if node.count > 0 {
                for t in node.first..node.first + node.count {
                    let c = &bvh.tris[t as usize].corners;
                    sum += solid_angle(p, &c[0], &c[1], &c[2]);
                }
            } else if len + 2 <= STACK {
                stack[len] = node.first;
                stack[len + 1] = node.first + 1;
                len += 2;
            }
        }
        sum / (4.0 * std::f64::consts::PI)
    }
}

/// Removes from `edges` every directed edge together with one reverse of it:
/// what remains is the net boundary of the triangles the edges came from.
fn cancel_reverse_pairs(edges: &mut Vec<[u32; 2]>) {
    // Key each edge by its sorted ends and its direction, then cancel within
    // each key.
    edges.sort_unstable_by_key(|&[a, b]| (a.min(b), a.max(b), a > b));
    let mut out = Vec::with_capacity(edges.len());
    let mut k = 0;
    while k < edges.len() {
        let key = (edges[k][0].min(edges[k][1]), edges[k][0].max(edges[k][1]));
        let mut forward = 0i64;
        let mut end = k;
        while end < edges.len()
            && (
                edges[end][0].min(edges[end][1]),
                edges[end][0].max(edges[end][1]),
            ) == key
        {
            forward += if edges[end][0] < edges[end][1] { 1 } else { -1 };
            end += 1;
        }
        let edge = if forward > 0 {
            [key.0, key.1]
        } else {
            [key.1, key.0]
        };
        for _ in 0..forward.unsigned_abs() {
            out.push(edge);
        }
        k = end;
    }
    *edges = out;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(p: &Point3, t: &[Point3; 3]) -> Real {
        // Dense sampling of the triangle, as a loose reference.
        let mut best = Real::INFINITY;
        let n = 200;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (u, v) = (i as Real / n as Real, j as Real / n as Real);
                let q = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
                best = best.min((p - q).norm());
            }
        }
        best
    }

    #[test]
    fn closest_point_matches_sampling_and_names_the_feature() {
        let t = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let cases = [
            (Point3::new(0.2, 0.2, 0.5), Feature::Face),
            (Point3::new(-1.0, -1.0, 0.3), Feature::Vertex(0)),
            (Point3::new(2.0, -0.1, 0.0), Feature::Vertex(1)),
            (Point3::new(-0.1, 2.0, 0.0), Feature::Vertex(2)),
            (Point3::new(0.5, -1.0, 0.0), Feature::Edge(0)),
            (Point3::new(1.0, 1.0, 0.2), Feature::Edge(1)),
            (Point3::new(-1.0, 0.5, -0.2), Feature::Edge(2)),
        ];
        for (p, f) in cases {
            let (q, feat) = closest_on_triangle(&p, &t[0], &t[1], &t[2]);
            assert_eq!(feat, f, "{p:?}");
            assert!(((p - q).norm() - brute(&p, &t)).abs() < 1e-2, "{p:?}");
        }
        // A degenerate triangle is its edges.
        let d = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
        ];
        let (q, _) = closest_on_triangle(&Point3::new(1.5, 1.0, 0.0), &d[0], &d[1], &d[2]);
        assert!((q - Point3::new(1.5, 0.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn the_fast_distance_is_the_closest_points() {
        let t = [
            Point3::new(0.1, -0.2, 0.05),
            Point3::new(1.0, 0.3, -0.2),
            Point3::new(-0.3, 0.9, 0.4),
        ];
        let data = TriData::new(&t[0], &t[1], &t[2]);
        let mut x: u64 = 7;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as Real / (1u64 << 53) as Real * 4.0 - 2.0
        };
        for _ in 0..10_000 {
            let p = Point3::new(next(), next(), next());
            let (q, _) = closest_on_triangle(&p, &t[0], &t[1], &t[2]);
            let d = (p - q).norm_squared();
            assert!((data.distance2(&p) - d).abs() <= 1e-12 * (1.0 + d), "{p:?}");
        }
    }

    #[test]
    fn solid_angles_of_a_closed_tetrahedron_sum_to_the_winding_number() {
        let v = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ];
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let w = |p: Point3| {
            faces
                .iter()
                .map(|f| solid_angle(&p, &v[f[0]], &v[f[1]], &v[f[2]]))
                .sum::<Real>()
                / (4.0 * std::f64::consts::PI)
        };
        assert!((w(Point3::new(0.1, 0.1, 0.1)) - 1.0).abs() < 1e-12);
        assert!(w(Point3::new(1.0, 1.0, 1.0)).abs() < 1e-12);
    }

    #[test]
    fn cancelling_leaves_the_net_boundary() {
        let mut e = vec![[0, 1], [1, 2], [2, 0], [1, 0], [0, 1], [3, 4]];
        cancel_reverse_pairs(&mut e);
        e.sort_unstable();
        assert_eq!(e, vec![[0, 1], [1, 2], [2, 0], [3, 4]]);
    }
}
