//! The nearest pair of points of two elements' fitted surfaces, read with the
//! one gap formula of the crossing probabilities ([`read_oriented`]): the
//! distance query beyond the near region ([`mod@crate::query::distance`]).

use super::{read_oriented, Facing, Posed, HALF_SPACING};
use crate::element::{Hull, SurfaceElement};
use crate::math::{Point3, Pose, Vector3};
use crate::Real;

/// Alternating projections from the best probe towards the two surfaces'
/// closest points ([`nearest_surface_pair`]).
const REFINE_STEPS: usize = 4;

/// The gap between two elements' fitted surfaces where they come closest,
/// in the frame of the second element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ElementGap {
    /// The gap along `direction` (the pair's reading, see [`read_oriented`]).
    pub gap: Real,
    /// Its standard deviation (the same formula as a crossing's).
    pub std: Real,
    /// The part of `std` from the two fitted surfaces alone.
    pub fit_std: Real,
    /// The point of A's fitted surface.
    pub point_a: Point3,
    /// The point of B's fitted surface.
    pub point_b: Point3,
    /// The unit direction the gap is measured along, from A towards B.
    pub direction: Vector3,
}

/// A lower bound on the distance between any point of the fitted surface of
/// `a` (its cloud at `pose_a` in `b`'s frame) and any of `b`'s, and a bound
/// on the standard deviation of the gap of any pair of their points along any
/// direction.
pub(crate) fn surface_pair_bound(
    a: (&SurfaceElement, &Hull),
    pose_a: &Pose,
    b: (&SurfaceElement, &Hull),
) -> (Real, Real) {
    let (pa, pb) = (Posed::new(a, pose_a), Posed::new(b, &Pose::identity()));
    (pa.distance_bound(&pb), a.1.sigma.hypot(b.1.sigma))
}

/// The nearest pair of points of the fitted surfaces of elements `a` (its
/// cloud at `pose_a` in `b`'s frame) and `b`, read as a facing pair: from
/// every probe of each element, the other's surface point straight across
/// (clamped to its extent), then a few alternating projections from the
/// closest of them. The gap is measured as the crossing probabilities measure
/// a pair's, the two surfaces ordered by the line between the two points
/// (from A towards B): over the facing element along its normal, beside it
/// along that line. So the gap is never negative: this reads surfaces apart,
/// beyond the noise's reach (a crossing needs the near region's separating
/// surface to tell which side each is on).
pub(crate) fn nearest_surface_pair(
    a: (&SurfaceElement, &Hull),
    pose_a: &Pose,
    b: (&SurfaceElement, &Hull),
) -> ElementGap {
    let (pa, pb) = (Posed::new(a, pose_a), Posed::new(b, &Pose::identity()));
    let from_a = closest_from(&pa, &pb, 1.0);
    let from_b = closest_from(&pb, &pa, -1.0);
    if from_b.gap < from_a.gap {
        from_b
    } else {
        from_a
    }
}

/// Every probe's facing pair of elements `a` (its cloud at `pose_a` in `b`'s
/// frame) and `b`, from both elements' probes, read as
/// [`nearest_surface_pair`] reads its pair, each with whether the probe lies
/// beside the facing element rather than over it: the readings a gap field
/// pools.
pub(crate) fn surface_pair_readings(
    a: (&SurfaceElement, &Hull),
    pose_a: &Pose,
    b: (&SurfaceElement, &Hull),
) -> Vec<(ElementGap, bool)> {
    let (pa, pb) = (Posed::new(a, pose_a), Posed::new(b, &Pose::identity()));
    let from = |own: &Posed<'_>, other: &Posed<'_>, label: Real| {
        own.e
            .probes
            .iter()
            .map(|&[u, v]| own.probe(u, v))
            .map(|(x, var_x)| {
                let (f, g) = facing(own, other, x, var_x);
                (labelled(g, &f, label), f.key.0)
            })
            .collect::<Vec<_>>()
    };
    let mut out = from(&pa, &pb, 1.0);
    out.extend(from(&pb, &pa, -1.0));
    out
}

/// A reading made from a probe of side `label` (+1: A, -1: B) with the
/// points named by side and the direction from A towards B.
fn labelled(g: ElementGap, f: &Facing, label: Real) -> ElementGap {
    if label > 0.0 {
        g
    } else {
        ElementGap {
            point_a: f.y,
            point_b: f.x,
            direction: -g.direction,
            ..g
        }
    }
}

/// The surface point of element `e` (its cloud at `pose`) nearest `at`
/// across its surface: the fitted surface at `at`'s tangential coordinates,
/// clamped to the extent (the mean for a single point).
pub(crate) fn surface_point_near(e: (&SurfaceElement, &Hull), pose: &Pose, at: &Point3) -> Point3 {
    let p = Posed::new(e, pose);
    let (u, v) = p.coordinates(at);
    p.at(u, v).0
}

/// The closest facing pair from `own`'s probes to `other` (`label` +1 for A's
/// probes, -1 for B's), refined by alternating projections.
fn closest_from(own: &Posed<'_>, other: &Posed<'_>, label: Real) -> ElementGap {
    let first = own
        .e
        .probes
        .iter()
        .map(|&[u, v]| own.probe(u, v))
        .chain(own.e.probes.is_empty().then_some((own.mean, 0.0)))
        .map(|(x, var_x)| facing(own, other, x, var_x))
        .min_by(|p, q| p.1.gap.total_cmp(&q.1.gap));
    let Some(mut best) = first else {
        return facing(own, other, own.mean, 0.0).1;
    };
    for _ in 0..REFINE_STEPS {
        let (f, _) = &best;
        let back = own.across(&f.y, other);
        let next = facing(own, other, back.y, back.var_y);
        if next.1.gap >= best.1.gap {
            break;
        }
        best = next;
    }
    let (f, g) = best;
    labelled(g, &f, label)
}

/// The facing pair of `own`'s surface point `x` (height variance `var_x`)
/// and `other`'s point straight across, and its reading.
fn facing(own: &Posed<'_>, other: &Posed<'_>, x: Point3, var_x: Real) -> (Facing, ElementGap) {
    let c = other.across(&x, own);
    let over = other.e.is_point() || other.is_over(c.u, c.v);
    let d = c.y - x;
    let f = Facing {
        own: 0,
        x,
        var_x,
        other: 0,
        y: c.y,
        var_y: c.var_y,
        allowed: HALF_SPACING * own.e.spacing.max(other.e.spacing),
        key: (!over, d.norm_squared()),
    };
    // The line between the two points orders the surfaces (from the probe's
    // side towards the other's); `read_oriented` takes it from A towards B.
    let u_line = d.try_normalize(0.0).unwrap_or(other.normal);
    let r = read_oriented(&f, (own, other), &u_line, 1.0, 0.0);
    let gap = ElementGap {
        gap: r.gap,
        std: r.std,
        fit_std: r.fit_std,
        point_a: f.x,
        point_b: f.y,
        direction: r.direction,
    };
    (f, gap)
}
