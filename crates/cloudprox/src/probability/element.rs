//! The probability that the fitted surfaces of two clouds' elements cross.

use crate::bvh::PointSearch;
use crate::classify::Separator;
use crate::element::{across_normal, height_row, hull_gap, Hull, SurfaceElement, HALF_SPACING};
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::probability::gaussian::wrong_side;
use crate::probability::ElementReading;
use crate::Real;

/// Elements of the other side tried as the facing one (the nearest by mean).
const FACING_CANDIDATES: usize = 6;

mod nearest;
pub(crate) use nearest::{
    nearest_surface_pair, surface_pair_bound, surface_pair_readings, surface_point_near, ElementGap,
};

/// One side's elements of a patch, posed in the separator's frame.
pub(crate) struct ElementSide<'a> {
    /// The elements and their hulls.
    pub elements: Vec<(&'a SurfaceElement, &'a Hull)>,
    /// Pose of their cloud's frame in the separator's frame.
    pub pose: Pose,
    /// +1 for cloud A, -1 for cloud B.
    pub label: Real,
}

impl ElementSide<'_> {
    /// The elements placed in the separator's frame.
    fn posed(&self) -> Vec<Posed<'_>> {
        self.elements
            .iter()
            .map(|&e| Posed::new(e, &self.pose))
            .collect()
    }
}

/// An element moved into the separator's frame.
struct Posed<'a> {
    e: &'a SurfaceElement,
    hull: &'a Hull,
    mean: Point3,
    tangents: [Vector3; 2],
    normal: Vector3,
    /// The covariance across the normal (the whole covariance for a point).
    across: Matrix3,
    /// The hull's corners, moved: every surface point [`Posed::at`] returns
    /// lies in their convex hull.
    corners: [Point3; 4],
}

impl<'a> Posed<'a> {
    fn new((e, hull): (&'a SurfaceElement, &'a Hull), pose: &Pose) -> Self {
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        Self {
            e,
            hull,
            mean: pose * e.mean,
            tangents: [r * e.tangents[0], r * e.tangents[1]],
            normal: r * e.normal,
            across: r * across_normal(e) * r.transpose(),
            corners: hull.corners_moved(pose),
        }
    }

    /// A lower bound on the distance between any surface point of `self` and
    /// any of `other` ([`hull_gap`]).
    fn distance_bound(&self, other: &Posed<'_>) -> Real {
        hull_gap(
            (&self.mean, &self.normal, &self.corners),
            (&other.mean, &other.normal, &other.corners),
        ) - self.hull.sag
            - other.hull.sag
    }

    /// Whether some facing pair of `self` and `other` could lie within the
    /// noise's reach (`reach_sds` standard deviations, bounded over every
    /// direction, beyond half a spacing); `false` proves that none does.
    fn may_reach(&self, other: &Posed<'_>, reach_sds: Real) -> bool {
        let allowed = HALF_SPACING * self.e.spacing.max(other.e.spacing);
        let s = (self.var_bound(self.hull.var_max) + other.var_bound(other.hull.var_max)).sqrt();
        let limit = allowed + reach_sds * s;
        // The bounding spheres first (most pairs of a patch are far apart),
        // then the tighter bound.
        (other.mean - self.mean).norm() - self.hull.radius - other.hull.radius <= limit
            && self.distance_bound(other) <= limit
    }

    /// The probe of `self` at tangential coordinates `(u, v)` and the variance
    /// of its height (the mean, without one, for a single point).
    fn probe(&self, u: Real, v: Real) -> (Point3, Real) {
        if self.e.is_point() {
            (self.mean, 0.0)
        } else {
            self.at(u, v)
        }
    }

    /// The surface point of `self` straight across from `x`, a probe of
    /// `from` (at `x`'s tangential coordinates, clamped to the extent). The
    /// offset across is measured in `self`'s tangent plane; a single point has
    /// none, so in the probe's own (the point lies over the probe's surface),
    /// and in every direction when both are points.
    fn across(&self, x: &Point3, from: &Posed<'_>) -> Across {
        let (u, v) = self.coordinates(x);
        let (y, var_y) = self.at(u, v);
        let d = y - x;
        let lateral = match (self.e.is_point(), from.e.is_point()) {
            (false, _) => (d - self.normal * self.normal.dot(&d)).norm(),
            (true, false) => (d - from.normal * from.normal.dot(&d)).norm(),
            (true, true) => d.norm(),
        };
        Across {
            u,
            v,
            y,
            var_y,
            lateral,
        }
    }

    /// Whether some probe of `self` faces `other` (within half a spacing
    /// across its surface, where it was sampled) within the noise's reach:
    /// every facing pair, not only each probe's best, so `false` proves that
    /// no facing pair of the two elements is within reach.
    fn probes_reach(&self, other: &Posed<'_>, reach_sds: Real) -> bool {
        let allowed = HALF_SPACING * self.e.spacing.max(other.e.spacing);
        self.e.probes.iter().any(|&[u, v]| {
            let (x, var_x) = self.probe(u, v);
            let c = other.across(&x, self);
            let s = (self.var_bound(var_x) + other.var_bound(c.var_y)).sqrt();
            c.lateral <= allowed
                && (c.y - x).norm() <= allowed + reach_sds * s
                && other.e.covers(c.u, c.v)
        })
    }

    /// A cheap necessary condition for `self` to give `x` a facing point
    /// (see [`for_each_facing`]): its surface point across from `x` (clamped
    /// to the extent) lies within `allowed` of `x` across its normal, and,
    /// when the best so far lies over its element (`over_found`), `x` lies
    /// over `self` too. Read on the tangential coordinates alone, before the
    /// surface point and its variance are evaluated; `false` rules the
    /// element out (the lateral offset `Posed::across` measures is the
    /// clamped coordinates' offset, compared here with a margin over the
    /// rounding). Always true for a single point.
    fn could_face(&self, x: &Point3, allowed: Real, over_found: bool) -> bool {
        if self.e.is_point() {
            return true;
        }
        let (u, v) = self.coordinates(x);
        if over_found && !self.is_over(u, v) {
            return false;
        }
        let [[u0, u1], [v0, v1]] = self.e.extent;
        let (du, dv) = (u.clamp(u0, u1) - u, v.clamp(v0, v1) - v);
        du * du + dv * dv <= allowed * allowed * (1.0 + 1e-6)
    }

    /// Tangential coordinates of `x`.
    fn coordinates(&self, x: &Point3) -> (Real, Real) {
        let d = x - self.mean;
        (d.dot(&self.tangents[0]), d.dot(&self.tangents[1]))
    }

    /// The fitted surface over `(u, v)` (clamped to the element's range) and
    /// the variance of its height.
    fn at(&self, u: Real, v: Real) -> (Point3, Real) {
        if self.e.is_point() {
            return (self.mean, 0.0);
        }
        let [[u0, u1], [v0, v1]] = self.e.extent;
        let (u, v) = (u.clamp(u0, u1), v.clamp(v0, v1));
        let x = height_row(u, v);
        let var = x.dot(&(self.e.height_cov * x)) + self.e.common_var;
        let height = x.dot(&nalgebra::SVector::<Real, 6>::from(self.e.height));
        (
            self.mean + self.tangents[0] * u + self.tangents[1] * v + self.normal * height,
            var.max(0.0),
        )
    }

    /// The variance along the unit vector `dir` of a surface point whose height
    /// variance is `var`.
    fn var_along(&self, var: Real, dir: &Vector3) -> Real {
        let n = self.normal.dot(dir);
        var * n * n + dir.dot(&(self.across * dir))
    }

    /// Whether tangential coordinates `(u, v)` lie within the extent (the
    /// fitted surface is then evaluated there, not at the extent's edge).
    fn is_over(&self, u: Real, v: Real) -> bool {
        let [[u0, u1], [v0, v1]] = self.e.extent;
        (u0..=u1).contains(&u) && (v0..=v1).contains(&v)
    }

    /// The variance that the position of the element's sampled edges adds
    /// along `dir` to its surface point `x`, when `x` lies within half a
    /// spacing of an edge: a sampled surface ends somewhere between its last
    /// samples and the next sample that would have been (the edge is known
    /// to about half a spacing, the scale of the near rule's margin), and
    /// moving the edge by that much along the tangent `t` across it moves the
    /// surface's end by `t . dir` of it along `dir`. Zero for a single point
    /// and for `dir` along the normal (two parallel faces: the edge does not
    /// change their gap); it is what makes a face's end meeting another
    /// surface at an angle uncertain by the sampling.
    fn edge_var_along(&self, x: &Point3, dir: &Vector3) -> Real {
        if self.e.is_point() {
            return 0.0;
        }
        let half = HALF_SPACING * self.e.spacing;
        let (u, v) = self.coordinates(x);
        let [[u0, u1], [v0, v1]] = self.e.extent;
        [(u - u0).min(u1 - u), (v - v0).min(v1 - v)]
            .iter()
            .zip(&self.tangents)
            .filter(|(to_edge, _)| **to_edge <= half)
            .map(|(_, t)| (t.dot(dir) * half).powi(2))
            .sum()
    }

    /// The distance of `x` (tangential coordinates) to the nearest edge of the
    /// extent, in sampling spacings (0 for a single point).
    fn edge_distance(&self, x: &Point3) -> Real {
        if self.e.is_point() || self.e.spacing <= 0.0 {
            return 0.0;
        }
        let (u, v) = self.coordinates(x);
        let [[u0, u1], [v0, v1]] = self.e.extent;
        (u - u0).min(u1 - u).min(v - v0).min(v1 - v) / self.e.spacing
    }

    /// The larger side of the extent in sampling spacings (0 for a point).
    fn size(&self) -> Real {
        if self.e.is_point() || self.e.spacing <= 0.0 {
            return 0.0;
        }
        let [[u0, u1], [v0, v1]] = self.e.extent;
        (u1 - u0).max(v1 - v0) / self.e.spacing
    }

    /// Whether a clearance `gap` along `dir` is read across the element's own
    /// end rather than across its surface: `gap > 0` and `dir` closer to the
    /// tangent plane than to the normal (never for a single point). Such a
    /// reading says where the sampled surface ends, which is known only to
    /// half a spacing, and the surface it ends at says more (a table's side
    /// face under a piano, where the table's top reads the gap); read across
    /// an end, a crossing (the surface has passed through the other) counts
    /// as any other (see [`crate::probability::contact_probability`]).
    fn clearance_across_its_end(&self, gap: Real, dir: &Vector3) -> bool {
        gap > 0.0
            && !self.e.is_point()
            && self.normal.dot(dir).abs() < std::f64::consts::FRAC_1_SQRT_2
    }

    /// A bound on the variance along any direction.
    fn var_bound(&self, var: Real) -> Real {
        var + self.across.trace()
    }
}

/// A probe of one side and the other side's facing surface point.
struct Facing {
    /// Index of the probe's element.
    own: usize,
    x: Point3,
    var_x: Real,
    other: usize,
    y: Point3,
    var_y: Real,
    /// Half a sampling spacing: how far apart samples of touching surfaces can be.
    allowed: Real,
    /// Whether `x` lies beside the other element rather than over it, then the
    /// squared distance: the best facing pair has the smallest.
    key: (bool, Real),
}

/// A point `x` seen from an element: its tangential coordinates, the surface
/// point `y` straight across (clamped to the extent) with the variance of its
/// height, and the offset of `y - x` across the element's normal.
struct Across {
    u: Real,
    v: Real,
    y: Point3,
    var_y: Real,
    lateral: Real,
}

/// Calls `visit` on the facing pair of each of `own`'s probes that has one (see
/// [`element_crossing_probabilities`]), for the elements marked `active`, until
/// `visit` returns `false`; returns whether every pair was visited.
fn for_each_facing(
    own: &[Posed<'_>],
    other: &[Posed<'_>],
    active: &[bool],
    mut visit: impl FnMut(&Facing) -> bool,
) -> bool {
    // The other side's elements nearest to a probe by mean (a patch holds
    // hundreds of elements, each with 25 probes).
    let candidates = PointSearch::new(other.iter().map(|o| o.mean).collect::<Vec<_>>());
    let mut nearest: Vec<(Real, u32)> = Vec::with_capacity(FACING_CANDIDATES);
    let mut probes: Vec<(Point3, Real)> = Vec::new();
    let mut near_element: Vec<u32> = Vec::new();
    for (k, p) in own.iter().enumerate() {
        if !active[k] {
            continue;
        }
        // One search per element for the candidates of all its probes.
        probes.clear();
        probes.extend(p.e.probes.iter().map(|&[u, v]| p.probe(u, v)));
        let r = probes
            .iter()
            .fold(0.0, |r: Real, (x, _)| r.max((x - p.mean).norm()));
        candidates.candidates_near(
            &p.mean,
            r,
            FACING_CANDIDATES,
            &mut nearest,
            &mut near_element,
        );
        for &(x, var_x) in &probes {
            candidates.nearest_among(&x, FACING_CANDIDATES, &near_element, &mut nearest);
            let mut best: Option<Facing> = None;
            for &(_, j) in &nearest {
                let j = j as usize;
                let o = &other[j];
                let allowed = HALF_SPACING * p.e.spacing.max(o.e.spacing);
                if !o.could_face(&x, allowed, best.as_ref().is_some_and(|b| !b.key.0)) {
                    continue;
                }
                let Across {
                    u: ou,
                    v: ov,
                    y,
                    var_y,
                    lateral,
                } = o.across(&x, p);
                let d = y - x;
                // An element that `x` lies over (within its extent, so `y`
                // is straight across) beats one it lies beside (`y` clamped
                // to the extent's edge, offset sideways): the gap of a pair
                // beside says little about a crossing, and the closest
                // element is often the one beside.
                let over = o.e.is_point() || o.is_over(ou, ov);
                let key = (!over, d.norm_squared());
                let better = best.as_ref().is_none_or(|b| key < b.key);
                // Over the other element's surface only where it was sampled
                // (the costliest test, so the last).
                if lateral <= allowed && better && o.e.covers(ou, ov) {
                    best = Some(Facing {
                        key,
                        own: k,
                        x,
                        var_x,
                        other: j,
                        y,
                        var_y,
                        allowed,
                    });
                }
            }
            if let Some(f) = best {
                if !visit(&f) {
                    return false;
                }
            }
        }
    }
    true
}

/// Per element of `own`, whether some element of `other` may lie within the
/// noise's reach of it ([`Posed::may_reach`]). An element without one has no
/// facing pair within reach: it is skipped, which changes no result and spares
/// its probes' facing searches (two spheres 6 sigma apart at 1 mm: every
/// element of the near region).
fn within_reach_of(own: &[Posed<'_>], other: &[Posed<'_>], reach_sds: Real) -> Vec<bool> {
    own.iter()
        .map(|p| other.iter().any(|o| p.may_reach(o, reach_sds)))
        .collect()
}

/// Whether element `a` (with its hull, its cloud at `pose_a` in `b`'s frame)
/// and element `b` have a facing pair within `reach_sds` standard deviations
/// (as [`elements_within_reach`] tests it, over every facing pair of the two).
/// `false` proves that no patch holding both finds the pair within reach.
pub(crate) fn element_pair_within_reach(
    a: (&SurfaceElement, &Hull),
    pose_a: &Pose,
    b: (&SurfaceElement, &Hull),
    reach_sds: Real,
) -> bool {
    let (pa, pb) = (Posed::new(a, pose_a), Posed::new(b, &Pose::identity()));
    pa.may_reach(&pb, reach_sds)
        && (pa.probes_reach(&pb, reach_sds) || pb.probes_reach(&pa, reach_sds))
}

/// Whether the fitted surfaces of elements `a` (its cloud at `pose_a` in `b`'s
/// frame) and `b` cross: probes of one lie over the other's sampled surface
/// (within its extent, where its footprint has points) on both sides of it,
/// each farther from it than `z_sds` standard deviations of the pair's heights
/// and no farther than half a spacing plus `z_sds` of them (near the crossing,
/// where a facing pair of [`element_crossing_probabilities`] counts).
///
/// Two sampled surfaces of different objects cross only where the objects
/// overlap, whichever side of either is inside, so a crossing decides a
/// collision without a separating surface. The probability that the two
/// surfaces do not cross although both probes read beyond `z_sds` is at most
/// `2 Phi(-z_sds)` (a union bound over the two probes). Single points never
/// cross anything: they have no side.
pub(crate) fn element_pair_crosses(
    a: (&SurfaceElement, &Hull),
    pose_a: &Pose,
    b: (&SurfaceElement, &Hull),
    z_sds: Real,
) -> bool {
    if a.0.is_point() || b.0.is_point() {
        return false;
    }
    let (pa, pb) = (Posed::new(a, pose_a), Posed::new(b, &Pose::identity()));
    pa.may_reach(&pb, z_sds) && (pa.straddles(&pb, z_sds) || pb.straddles(&pa, z_sds))
}

impl Posed<'_> {
    /// Whether probes of `self` lie over `other`'s sampled surface on both
    /// sides of it, each between `z_sds` standard deviations of the pair's
    /// heights and half a spacing plus that (see [`element_pair_crosses`]).
    fn straddles(&self, other: &Posed<'_>, z_sds: Real) -> bool {
        let n = other.normal;
        // The height over `other`'s surface is, up to the two surfaces' sags,
        // affine along `self`'s, so its probes lie on both sides only if its
        // hull's corners come within the sags of both sides.
        let height = |x: &Point3| {
            let (u, v) = other.coordinates(x);
            n.dot(&(x - other.mean)) - other.e.height_at(u, v)
        };
        let sag = self.hull.sag + other.hull.sag;
        let (lo, hi) = self
            .corners
            .iter()
            .map(height)
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(l, h), c| {
                (l.min(c), h.max(c))
            });
        if lo >= sag || hi <= -sag {
            return false;
        }
        let allowed = HALF_SPACING * self.e.spacing.max(other.e.spacing);
        let (mut above, mut below) = (false, false);
        for &[u, v] in &self.e.probes {
            let (x, var_x) = self.at(u, v);
            let (ou, ov) = other.coordinates(&x);
            if !other.is_over(ou, ov) || !other.e.covers(ou, ov) {
                continue;
            }
            let (y, var_y) = other.at(ou, ov);
            let h = n.dot(&(x - y));
            let sd = (self.var_along(var_x, &n) + other.var_along(var_y, &n))
                .max(0.0)
                .sqrt();
            if h.abs() > z_sds * sd && h.abs() <= allowed + z_sds * sd {
                above |= h > 0.0;
                below |= h < 0.0;
                if above && below {
                    return true;
                }
            }
        }
        false
    }
}

/// Whether some probe of either side faces the other side within the noise's
/// reach (`|y - x| <= h/2 + reach_sds s` with `s` bounded over all directions):
/// when none does, the surfaces cannot cross and no separating surface is
/// needed to say so.
pub(crate) fn elements_within_reach(
    a: &ElementSide<'_>,
    b: &ElementSide<'_>,
    reach_sds: Real,
) -> bool {
    let (pa, pb) = (a.posed(), b.posed());
    // Stops at the first pair within reach.
    let reaches = |own: &[Posed<'_>], other: &[Posed<'_>]| {
        let active = within_reach_of(own, other, reach_sds);
        active.iter().any(|&a| a)
            && !for_each_facing(own, other, &active, |f| {
                let s = (own[f.own].var_bound(f.var_x) + other[f.other].var_bound(f.var_y)).sqrt();
                (f.y - f.x).norm() > f.allowed + reach_sds * s
            })
    };
    reaches(&pa, &pb) || reaches(&pb, &pa)
}

/// Per element of `own`, the probability that its fitted surface and the
/// other side's cross.
///
/// At each of its probes `x` (see [`SurfaceElement::probes`]), the other side's
/// facing surface point `y` is the point of one of its nearest elements at
/// `x`'s tangential coordinates (clamped to that element's range; an element
/// `x` lies over is preferred to one it lies beside) that lies
/// within half a sampling spacing of `x` across its surface. The two surfaces
/// there are `g = (y - x) . u` apart along the direction `u` across them (the
/// facing element's normal, turned from A towards B by the separating
/// surface's normal at the pair's midpoint; see [`pair_direction`]), with the
/// standard deviation
/// `s = sqrt(u^T (Sigma_x + Sigma_y) u + e_x)` of the two fitted surfaces
/// and of where the probe's sampled edge is (`e_x`, for a probe over the
/// other element within half a spacing of its own element's edge: see
/// `Posed::edge_var_along`), and cross with probability `Phi(-g / s)`. A pair farther apart than the noise can
/// reach (`|y - x| > h/2 + reach_sds s`, `h` the spacing) cannot cross there
/// and counts 0: a deep crossing shows where the surfaces cross, not far from
/// it. The element's value is the largest over its probes.
///
/// Also returned: the largest crossing probability of a pair that lies where
/// the separating surface does not describe it, and the largest of the others
/// (see [`ElementCrossings`]).
pub(crate) fn element_crossing_probabilities(
    own: &ElementSide<'_>,
    other: &ElementSide<'_>,
    sep: &Separator,
    reach_sds: Real,
) -> ElementCrossings {
    let (po, pt) = (own.posed(), other.posed());
    let mut out = ElementCrossings {
        values: vec![0.0; po.len()],
        described_max: 0.0,
        undescribed_max: 0.0,
        readings: Vec::new(),
    };
    let active = within_reach_of(&po, &pt, reach_sds);
    let form = sep.quadratic_form(&Pose::identity());
    for_each_facing(&po, &pt, &active, |f| {
        let Some(r) = read_pair(f, &po, &pt, &form, own.label, reach_sds) else {
            return true;
        };
        if r.within_reach {
            let p = r.probability;
            if p < 0.5 {
                out.described_max = out.described_max.max(p);
            } else if p > out.undescribed_max.min(out.described_max) {
                // Only a pair that would cross and could raise one of the two
                // maxima needs the test.
                if r.undescribed(&form, f) {
                    out.undescribed_max = out.undescribed_max.max(p);
                } else {
                    out.described_max = out.described_max.max(p);
                }
            }
            out.values[f.own] = Real::max(out.values[f.own], p);
            out.readings.push(ElementReading {
                own: f.own as u32,
                other: f.other as u32,
                gap: r.gap,
                std: r.std,
                fit_std: r.fit_std,
                beside: f.key.0 || po[f.own].clearance_across_its_end(r.gap, &r.direction),
                contact: 0,
                at: Some(nalgebra::center(&f.x, &f.y)),
                direction: r.direction,
            });
        }
        true
    });
    out
}

/// What one facing pair reads (see [`element_crossing_probabilities`]).
struct PairReading {
    /// Unit direction across the pair, from A towards B.
    direction: Vector3,
    /// The gap along `direction` (negative where the surfaces have crossed).
    gap: Real,
    /// Its standard deviation.
    std: Real,
    /// The part of `std` from the two fitted surfaces alone.
    fit_std: Real,
    /// `Phi(-gap / std)`.
    probability: Real,
    /// Whether the pair lies within the noise's reach (else it counts 0).
    within_reach: bool,
    /// Whether the separating surface runs across the two surfaces here.
    steep: bool,
    /// The separator's gradient norm at the pair's midpoint.
    gradient_norm: Real,
    /// `h/2 + reach_sds s` plus the pair's length.
    span_limit: Real,
}

impl PairReading {
    /// Whether the separating surface does not describe this pair (see
    /// [`ElementCrossings`]).
    fn undescribed(&self, form: &crate::classify::QuadraticForm, f: &Facing) -> bool {
        let (fx, fy) = (
            form.value_and_gradient(&f.x).0,
            form.value_and_gradient(&f.y).0,
        );
        let near_end = fx.abs().min(fy.abs()) / self.gradient_norm;
        // A separating surface running across the two surfaces here,
        // not between them, says nothing of their order either.
        self.steep || (fx * fy > 0.0 && near_end > self.span_limit)
    }
}

/// The reading of the facing pair `f` of `po[f.own]` and `pt[f.other]`:
/// its direction, gap, standard deviation and crossing probability; `None`
/// where the separator has no gradient there.
fn read_pair(
    f: &Facing,
    po: &[Posed<'_>],
    pt: &[Posed<'_>],
    form: &crate::classify::QuadraticForm,
    label: Real,
    reach_sds: Real,
) -> Option<PairReading> {
    let (_, g) = form.value_and_gradient(&nalgebra::center(&f.x, &f.y));
    let gn = g.norm();
    if gn <= 0.0 || !gn.is_finite() {
        return None;
    }
    // From A towards B: f decreases from A's side to B's.
    let u_sep = g / (-gn);
    Some(PairReading {
        gradient_norm: gn,
        ..read_oriented(f, (&po[f.own], &pt[f.other]), &u_sep, label, reach_sds)
    })
}

/// The reading of the facing pair `f` of `own_e` (the probe's element) and
/// `other_e` with the order of the two surfaces given by `u_sep`, a unit
/// vector from A towards B (the separating surface's normal at the pair in a
/// query; see [`pair_direction`]): the one formula of a pair's gap and its
/// standard deviation, which the crossing probabilities and the distance
/// query ([`nearest`]) both read. `gradient_norm` is left at 1.
fn read_oriented(
    f: &Facing,
    (own_e, other_e): (&Posed<'_>, &Posed<'_>),
    u_sep: &Vector3,
    label: Real,
    reach_sds: Real,
) -> PairReading {
    let (u, steep) = pair_direction(own_e, other_e, f.key.0, u_sep);
    let gap = label * (f.y - f.x).dot(&u);
    // Where the probe lies over the other element, the gap is measured
    // across that element's surface (along its normal), and where the
    // probe's own sampled surface ends is uncertain along it; the other
    // element's end moves within its own plane, which does not change a
    // gap measured across it. A probe beside the other element is
    // measured between the two ends, each known to half a spacing: both
    // ends' uncertainty counts (without it, such pairs read gaps 0.6
    // standard deviations too small on real meshes, with 1.75 times the
    // stated spread).
    let other_edge = if f.key.0 {
        other_e.edge_var_along(&f.y, &u)
    } else {
        0.0
    };
    let fit = (own_e.var_along(f.var_x, &u) + other_e.var_along(f.var_y, &u)).max(0.0);
    let edges = own_e.edge_var_along(&f.x, &u) + other_edge;
    let sd = (fit + edges).max(0.0).sqrt();
    let span = (f.y - f.x).norm();
    let reach = f.allowed + reach_sds * sd;
    PairReading {
        direction: u,
        gap,
        std: sd,
        fit_std: fit.sqrt(),
        probability: wrong_side(gap, sd),
        within_reach: span <= reach,
        steep,
        gradient_norm: 1.0,
        span_limit: span + reach,
    }
}

/// One facing pair of a patch's element surfaces, as the elements model reads
/// it (the elements model's crossing readings), in the frame the patch was read in:
/// for diagnostics (the standardized residual of the gap against exact
/// geometry, see [`crate::query::facing_pairs`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FacingPair {
    /// Whether the probe is on cloud A's element (else on B's).
    pub from_a: bool,
    /// Index of the probe's element in its cloud's elements.
    pub element: u32,
    /// Index of the facing element in the other cloud's elements.
    pub other_element: u32,
    /// The probe: a point of the own element's fitted surface.
    pub probe: Point3,
    /// The other side's facing surface point.
    pub facing: Point3,
    /// Unit direction across the pair, from A towards B.
    pub direction: Vector3,
    /// The estimated gap along `direction`.
    pub gap: Real,
    /// Its standard deviation.
    pub std: Real,
    /// `Phi(-gap / std)`.
    pub probability: Real,
    /// Whether the pair counts (within the noise's reach).
    pub within_reach: bool,
    /// Whether the probe lies beside the facing element rather than over it.
    pub beside: bool,
    /// The probe's distance to the nearest edge of its element's extent, in
    /// the element's sampling spacings (0 for a single point).
    pub probe_edge: Real,
    /// The points of the probe's element and of the facing one.
    pub counts: [u32; 2],
    /// The larger side of each element's extent, in its sampling spacings.
    pub sizes: [Real; 2],
    /// The standard deviation of the probe's own surface along `direction`.
    pub own_std: Real,
}

/// Every facing pair of `own`'s elements against `other`'s under the patch's
/// separating surface `sep` ([`FacingPair`]); `element_ids` are the indices of
/// `own.elements` and `other_ids` of `other.elements` in their clouds.
pub(crate) fn element_facing_pairs(
    own: &ElementSide<'_>,
    own_ids: &[u32],
    other: &ElementSide<'_>,
    other_ids: &[u32],
    sep: &Separator,
    reach_sds: Real,
) -> Vec<FacingPair> {
    let (po, pt) = (own.posed(), other.posed());
    let active = within_reach_of(&po, &pt, reach_sds);
    let form = sep.quadratic_form(&Pose::identity());
    let mut out = Vec::new();
    for_each_facing(&po, &pt, &active, |f| {
        if let Some(r) = read_pair(f, &po, &pt, &form, own.label, reach_sds) {
            out.push(FacingPair {
                from_a: own.label > 0.0,
                element: own_ids[f.own],
                other_element: other_ids[f.other],
                probe: f.x,
                facing: f.y,
                direction: r.direction,
                gap: r.gap,
                std: r.std,
                probability: r.probability,
                within_reach: r.within_reach,
                beside: f.key.0,
                probe_edge: po[f.own].edge_distance(&f.x),
                counts: [po[f.own].e.count, pt[f.other].e.count],
                sizes: [po[f.own].size(), pt[f.other].size()],
                own_std: po[f.own].var_along(f.var_x, &r.direction).max(0.0).sqrt(),
            });
        }
        true
    });
    out
}

/// The direction across a facing pair, from A towards B, along which its gap
/// is measured, and whether the separating surface (unit normal `u_sep` at
/// the pair, from A towards B) runs *across* the two surfaces there rather
/// than between them.
///
/// A probe lying over the other element (`beside` false) is measured along
/// that element's normal (along the own element's when the other is a single
/// point), turned towards B by the separating surface: the surfaces' own
/// geometry gives the distance, the separator only the order. A probe beside
/// the other element is measured along `u_sep` (along the normal, a probe
/// beside a coplanar neighbour reads a gap near 0) and is never flagged. Two
/// single points are measured along `u_sep`. The separator runs across the
/// surfaces when its normal is closer to their tangent plane than to their
/// normal (more than 45 degrees from the facing element's normal): there the
/// side each surface is on is not the side the separator puts it, and the
/// order it gives is not known (a crossing read there is undescribed, see
/// [`ElementCrossings`]).
fn pair_direction(
    own: &Posed<'_>,
    other: &Posed<'_>,
    beside: bool,
    u_sep: &Vector3,
) -> (Vector3, bool) {
    let normal = if !other.e.is_point() {
        Some(other.normal)
    } else if !own.e.is_point() {
        Some(own.normal)
    } else {
        None
    };
    let Some(n) = normal else {
        return (*u_sep, false);
    };
    let c = n.dot(u_sep);
    let steep = c.abs() < std::f64::consts::FRAC_1_SQRT_2;
    if beside {
        (*u_sep, false)
    } else {
        (if c >= 0.0 { n } else { -n }, steep)
    }
}

/// The crossing probabilities of one side's elements
/// ([`element_crossing_probabilities`]), and the largest crossing probability
/// among the pairs the separating surface describes and among those it does
/// not.
///
/// A pair that would cross (`Phi(-g/s) >= 1/2`) is *undescribed* where the
/// separating surface runs across the two surfaces rather than between them
/// (its normal more than 45 degrees from the facing element's; see
/// [`pair_direction`]), or when `x` and
/// `y` lie on the same side of the separating surface, both farther from it
/// than the pair spans (the pair's length plus `h/2 + reach_sds s`; the
/// distance to the surface read as `|f| / |grad f|` at the nearer end). There
/// the surface's normal says nothing about which side either surface is on (a
/// patch's quadric wrapped around a contact elsewhere, running across two flat
/// faces 4 sigma apart). When such a pair would raise the patch's value above
/// what the described pairs give, the patch is cut like a misfit; when the
/// described pairs already give as much (a deep interpenetration, read as a
/// certain crossing where the surface runs between the two clouds), the
/// undescribed pairs change nothing and the patch is kept.
pub(crate) struct ElementCrossings {
    /// The crossing probability of each element of the side.
    pub values: Vec<Real>,
    /// The largest over the pairs the separating surface describes.
    pub described_max: Real,
    /// The largest over the pairs it does not describe (0 if none).
    pub undescribed_max: Real,
    /// Every facing pair within reach.
    pub readings: Vec<ElementReading>,
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::probability::normal_cdf;

    #[test]
    fn a_sampled_edge_is_uncertain_by_half_a_spacing_along_its_tangent() {
        // A flat, nearly noiseless 20 x 20 grid at 4 mm spacing: one element.
        use crate::cloud::PointCloud;
        use nalgebra::{Translation3, UnitQuaternion};
        let h = 0.004;
        let pts: Vec<Point3> = (0..400)
            .map(|i| Point3::new((i / 20) as Real * h, (i % 20) as Real * h, 0.0))
            .collect();
        let cloud = PointCloud::from_sigma(pts, 1e-5).unwrap();
        let els = cloud.elements();
        let (k, e) = els
            .elements()
            .iter()
            .enumerate()
            .max_by_key(|(_, e)| e.count)
            .unwrap();
        assert!(e.count > 300, "{} points", e.count);
        let half = HALF_SPACING * e.spacing;
        let turn = UnitQuaternion::from_euler_angles(0.3, -0.5, 1.1);
        for pose in [
            Pose::identity(),
            Pose::from_parts(Translation3::new(0.1, 0.2, -0.3), turn),
        ] {
            let p = Posed::new((e, els.hulls().hull(k as u32)), &pose);
            let [[u0, u1], [v0, v1]] = e.extent;
            let (centre, _) = p.at(0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let (side, _) = p.at(u1, 0.5 * (v0 + v1));
            let (corner, _) = p.at(u0, v1);
            let [t0, t1] = p.tangents;
            let n = p.normal;
            let close = |a: Real, b: Real| (a - b).abs() <= 1e-9 * half * half;
            // Inside, or across the surface: the edge does not move the point.
            assert_eq!(p.edge_var_along(&centre, &t0), 0.0);
            assert!(close(p.edge_var_along(&side, &n), 0.0));
            // At the side across t0: half a spacing along t0, none along t1.
            assert!(close(p.edge_var_along(&side, &t0), half * half));
            assert!(close(p.edge_var_along(&side, &t1), 0.0));
            let diagonal = (t0 + n).normalize();
            assert!(close(p.edge_var_along(&side, &diagonal), 0.5 * half * half));
            // At a corner both edges count.
            let both = (t0 + t1).normalize();
            assert!(close(p.edge_var_along(&corner, &both), half * half));
        }
    }

    #[test]
    fn candidates_from_the_tree_are_the_nearest_means() {
        // A deterministic scatter of 500 means; queries inside and outside it.
        let mean = |i: usize| {
            let t = i as Real;
            Point3::new(
                (t * 0.618).fract(),
                (t * 0.414).fract(),
                (t * 0.732).fract() * 0.1,
            )
        };
        let means: Vec<Point3> = (0..500).map(mean).collect();
        let tree = PointSearch::new(means.clone());
        let brute = PointSearch::scan(means);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for q in 0..50 {
            let x = Point3::new(q as Real * 0.031 - 0.2, 0.5, q as Real * 0.007);
            tree.nearest(&x, FACING_CANDIDATES, &mut a);
            brute.nearest(&x, FACING_CANDIDATES, &mut b);
            assert_eq!(a.len(), FACING_CANDIDATES);
            assert_eq!(a, b, "query {q}");
        }
    }

    #[test]
    fn the_pair_screen_bounds_every_surface_point_pair() {
        // Elements of a noisy sphere (radius 5 cm, 1 mm noise) against those
        // of a second one, posed at a few offsets and turns: the screen's
        // distance bound is at most the distance of any two surface points
        // (a grid over both extents), and its variance bound at least the
        // variance anywhere, so an element it skips has no facing pair
        // within reach.
        use crate::cloud::PointCloud;
        use crate::sample::{add_noise, sphere};
        use nalgebra::{Translation3, UnitQuaternion};
        let cloud = |seed| {
            PointCloud::from_sigma(
                add_noise(&sphere(&Point3::origin(), 0.05, 2000), 0.001, seed),
                0.001,
            )
            .unwrap()
        };
        let (ca, cb) = (cloud(1), cloud(2));
        let (ea, eb) = (ca.elements().elements(), cb.elements().elements());
        assert!(ea.iter().filter(|e| !e.is_point()).count() > 20);
        let grid = |p: &Posed<'_>| -> Vec<(Point3, Real)> {
            let [[u0, u1], [v0, v1]] = p.e.extent;
            let mut out = Vec::new();
            for i in 0..=4 {
                for j in 0..=4 {
                    let (u, v) = (
                        u0 + (u1 - u0) * i as Real / 4.0,
                        v0 + (v1 - v0) * j as Real / 4.0,
                    );
                    out.push(p.at(u, v));
                }
            }
            out
        };
        let mut checked = 0;
        for (k, offset) in [0.1, 0.102, 0.11, 0.13].into_iter().enumerate() {
            let turn = UnitQuaternion::from_euler_angles(0.3 * k as Real, 0.7, -0.2);
            let pose = Pose::from_parts(Translation3::new(offset, 0.0, 0.0), turn);
            let (ha, hb) = (ca.elements().hulls(), cb.elements().hulls());
            let pa: Vec<Posed<'_>> = ea
                .iter()
                .enumerate()
                .step_by(7)
                .map(|(k, e)| Posed::new((e, ha.hull(k as u32)), &pose))
                .collect();
            let pb: Vec<Posed<'_>> = eb
                .iter()
                .enumerate()
                .step_by(5)
                .map(|(k, e)| Posed::new((e, hb.hull(k as u32)), &Pose::identity()))
                .collect();
            for a in &pa {
                let ga = grid(a);
                for &(_, var) in &ga {
                    assert!(var <= a.hull.var_max * (1.0 + 1e-12) + 1e-18);
                }
                for b in &pb {
                    let gb = grid(b);
                    let nearest = ga
                        .iter()
                        .flat_map(|(x, _)| gb.iter().map(move |(y, _)| (y - x).norm()))
                        .fold(Real::INFINITY, Real::min);
                    assert!(
                        a.distance_bound(b) <= nearest + 1e-12,
                        "bound {} > distance {nearest}",
                        a.distance_bound(b)
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000);
    }

    #[test]
    fn a_pair_is_measured_along_the_facing_normal_and_steep_separators_are_flagged() {
        // Elements of a noisy flat square (normal along z); the separating
        // surface's normal at 30 and 60 degrees from it, either sign.
        use crate::cloud::PointCloud;
        use crate::sample::add_noise;
        let grid: Vec<Point3> = (0..40)
            .flat_map(|i| {
                (0..40).map(move |j| Point3::new(i as Real * 0.005, j as Real * 0.005, 0.0))
            })
            .collect();
        let mut points = add_noise(&grid, 0.0005, 3);
        // An outlier a metre away stays a single point.
        points.push(Point3::new(1.0, 1.0, 1.0));
        let cloud = PointCloud::from_sigma(points, 0.0005).unwrap();
        let els = cloud.elements();
        let k = els
            .elements()
            .iter()
            .position(|e| !e.is_point())
            .expect("a surface element");
        let plane = Posed::new(
            (&els.elements()[k], els.hulls().hull(k as u32)),
            &Pose::identity(),
        );
        let point_k = els
            .elements()
            .iter()
            .position(SurfaceElement::is_point)
            .expect("a single point");
        assert!(plane.normal.z.abs() > 0.99);
        for sign in [1.0, -1.0] {
            for (deg, steep) in [(30.0, false), (60.0, true)] {
                let a = (deg as Real).to_radians();
                let u_sep = Vector3::new(a.sin(), 0.0, sign * a.cos());
                let (u, s) = pair_direction(&plane, &plane, false, &u_sep);
                assert_eq!(s, steep, "{deg} degrees");
                // Along the normal, turned to the separator's side.
                assert!((u.dot(&plane.normal).abs() - 1.0).abs() < 1e-12);
                assert!(u.dot(&u_sep) > 0.0);
                // Beside the other element: along the separator's normal.
                let (u, s) = pair_direction(&plane, &plane, true, &u_sep);
                assert_eq!((u, s), (u_sep, false));
            }
        }
        // Two single points: the separator's normal, never steep.
        let j = point_k;
        {
            let pt = Posed::new(
                (&els.elements()[j], els.hulls().hull(j as u32)),
                &Pose::identity(),
            );
            let u_sep = Vector3::new(1.0, 0.0, 0.0);
            assert_eq!(pair_direction(&pt, &pt, false, &u_sep), (u_sep, false));
            // A point facing an element: the element's normal.
            let (u, s) = pair_direction(&plane, &pt, false, &u_sep);
            assert!(s && (u.dot(&plane.normal).abs() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn crossing_is_the_gaussian_tail_and_exact_without_noise() {
        assert!((wrong_side(0.3, 0.5) - normal_cdf(-0.6)).abs() < 1e-15);
        assert_eq!(wrong_side(0.1, 0.0), 0.0);
        assert_eq!(wrong_side(-0.1, 0.0), 1.0);
        assert_eq!(wrong_side(0.0, 0.0), 1.0);
    }
}
