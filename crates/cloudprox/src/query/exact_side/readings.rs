//! The cloud's surface elements read against the exact surface.

use crate::element::{across_normal, SurfaceElement, SurfaceElements, HALF_SPACING};
use crate::math::{Point3, Vector3};
use crate::probability::{contact_probability, ElementReading};
use crate::query::exact_side::frame::{Frame, Standing};
use crate::shape::ClosestPoint;
use crate::Real;

/// What the elements of one segmentation read against the surface.
pub(crate) struct ElementScan {
    /// Every reading within the noise's reach, with the element as `own`
    /// and as `other` alike (the exact side has no element: its surface adds
    /// no error, so no two readings share one of its errors).
    pub readings: Vec<ElementReading>,
    /// The elements within reach of the surface or deep inside it, each with
    /// whether some reading of it is at or inside the surface.
    pub near: Vec<(u32, bool)>,
    /// Elements whose hull was tested against the surface.
    pub tested: usize,
}

/// The readings of every element of `els` within reach of the surface
/// (see the [module docs](crate::query::exact_side)), in the order of the
/// elements: those the hierarchy finds near the mesh's box
/// ([`Frame::candidates`]), each then as [`Frame::standing`] places it;
/// with `decisive`, stopped at the first element whose own readings
/// reach that probability ([`contact_probability`] of them): the
/// exact side's `P` is the largest of its elements' (one contact, each
/// element its own pair), so the full scan's `P` is at least that. Elements
/// deep inside the surface are then looked for first (no probes): a link
/// pressed into a scan is decided by the first of them, whatever the size
/// of the overlap.
pub(crate) fn element_readings(
    frame: &Frame<'_>,
    els: &SurfaceElements,
    decisive: Option<Real>,
) -> ElementScan {
    let mut scan = ElementScan {
        readings: Vec::new(),
        near: Vec::new(),
        tested: 0,
    };
    let mut candidates = Vec::new();
    frame.candidates(els, &mut candidates);
    let mut standings = Vec::with_capacity(candidates.len());
    for k in candidates {
        scan.tested += 1;
        let standing = frame.standing(els, k);
        if let (Standing::Deep, Some(p)) = (standing, decisive) {
            let r = deep_reading(frame, els, k);
            if contact_probability(&[r]) >= p {
                scan.readings.push(r);
                scan.near.push((k, r.gap <= 0.0));
                return scan;
            }
        }
        standings.push((k, standing));
    }
    for (k, standing) in standings {
        let e = &els.elements()[k as usize];
        let before = scan.readings.len();
        match standing {
            Standing::Beyond => continue,
            Standing::Deep => scan.readings.push(deep_reading(frame, els, k)),
            Standing::Near(..) if e.is_point() => scan.readings.push(point_reading(frame, e, k)),
            Standing::Near(centre, start) => {
                let radius = probe_radius(frame, els, k);
                probe_readings(frame, e, k, (radius, centre, start), &mut scan.readings);
            }
        }
        let own = &scan.readings[before..];
        scan.near.push((k, own.iter().any(|r| r.gap <= 0.0)));
        if decisive.is_some_and(|p| contact_probability(own) >= p) {
            break;
        }
    }
    scan
}

/// A single point's reading: its signed distance and its covariance along
/// the distance's gradient (Eq. 3). Always within reach (the broad phase
/// found the surface within reach of it).
pub(super) fn point_reading(frame: &Frame<'_>, e: &SurfaceElement, k: u32) -> ElementReading {
    let c = frame.closest(&frame.to_mesh(&e.mean));
    let n = frame.to_cloud(&c.normal);
    let var = n.dot(&(e.cov_mean * n));
    reading(k, c.signed_distance, var, var)
}

/// An element found deep inside: its least deep point lies at most its
/// hull's radius above its mean, still beyond the reach inside.
fn deep_reading(frame: &Frame<'_>, els: &SurfaceElements, k: u32) -> ElementReading {
    let hull = els.hulls().hull(k);
    let sd = frame.signed_distance(&frame.to_mesh(&hull.mean));
    let var = hull.sigma * hull.sigma;
    reading(k, sd + hull.radius, var, var)
}

/// The readings at the probes of a surface element: at each, the signed
/// distance of the fitted surface's point there to the mesh, and its
/// variance along the distance's gradient `n`: the fitted height's along the
/// element's normal, the mean's across it, and the position of the sampled
/// edge where the probe lies within half a spacing of it. Readings beyond
/// reach (`sd > h/2 + reach s`, `h` the spacing) are left out; every reading
/// inside the surface is kept (the element's surface is inside the solid).
/// Each probe's surface is searched within `radius` ([`probe_radius`]: every
/// reading within reach lies within it), and a probe is passed over without
/// a search when the distance of the last point read outside (first the
/// element's mean, `centre` with its closest point `start`), less the step
/// to it, exceeds `radius` (the ball of that distance about the point holds
/// no surface). Then from the mesh's point closest to the probe nearest the
/// surface, or from `start` when no probe is within `radius`, towards the
/// element's point nearest the surface ([`refine`]).
fn probe_readings(
    frame: &Frame<'_>,
    e: &SurfaceElement,
    k: u32,
    (radius, centre, start): (Real, Point3, ClosestPoint),
    out: &mut Vec<ElementReading>,
) {
    let allowed = HALF_SPACING * e.spacing;
    let mut best = Nearest {
        gap: Real::INFINITY,
        at: None,
        closest: start,
    };
    let mut reference = (centre, start);
    for &[u, v] in &e.probes {
        let x = frame.to_mesh(&e.surface_point(u, v).0);
        let (xr, cr) = &reference;
        if !cr.is_inside() && cr.distance() - (x - xr).norm() > radius {
            continue;
        }
        let Some((r, closest)) = read_at(frame, e, k, (u, v), radius) else {
            continue;
        };
        reference = (x, closest);
        if r.gap < best.gap {
            best = Nearest {
                gap: r.gap,
                at: Some((u, v)),
                closest,
            };
        }
        if r.gap <= allowed + frame.reach * r.std {
            out.push(r);
        }
    }
    // Two searches: from the probe nearest the surface, and from across the
    // mesh's deepest vertex.
    let seeds = [Some(best), support_reading(frame, e, k, start, out)];
    for seed in seeds.into_iter().flatten() {
        let nearest = refine(frame, e, k, seed, out);
        descend(frame, e, k, &nearest, out);
    }
}

/// The element's surface read across from the mesh's support point towards
/// it (the vertex deepest on the element's side, from the side of the
/// element's plane that `start`, the mesh's point closest to the element's
/// mean, lies on), where it lies over the element's extent: where the
/// element was sampled, else at the nearest sampled point (a hole in the
/// sampling, a shadow); the reading is kept within reach, and the search
/// goes on from it (`None` where the vertex lies beside the extent). A mesh
/// pressed into a wide element between its probes, farther than the search
/// radius from each (a robot link on a scanned floor, tens of centimetres
/// across), is found there: the closest points from the element's mean lead
/// to the mesh's side, not to where it goes through.
fn support_reading(
    frame: &Frame<'_>,
    e: &SurfaceElement,
    k: u32,
    start: ClosestPoint,
    out: &mut Vec<ElementReading>,
) -> Option<Nearest> {
    let normal = frame.to_mesh_direction(&e.normal);
    let above = (start.point - frame.to_mesh(&e.mean)).dot(&normal) >= 0.0;
    let deepest = frame.support(&(if above { -normal } else { normal }));
    let q = frame.to_cloud_point(&deepest) - e.mean;
    let (mut u, mut v) = (q.dot(&e.tangents[0]), q.dot(&e.tangents[1]));
    let [[u0, u1], [v0, v1]] = e.extent;
    if !((u0..=u1).contains(&u) && (v0..=v1).contains(&v)) {
        return None;
    }
    if !e.covers(u, v) {
        // A hole in the sampling (a shadow): the nearest sampled point.
        (u, v) = e.nearest_sampled(u, v)?;
    }
    let (r, closest) = read_at(frame, e, k, (u, v), Real::INFINITY)?;
    if r.gap <= HALF_SPACING * e.spacing + frame.reach * r.std {
        out.push(r);
    }
    Some(Nearest {
        gap: r.gap,
        at: Some((u, v)),
        closest,
    })
}

/// The element's surface point read nearest the surface so far: its gap, its
/// tangential coordinates (`None` before any) and the mesh's closest point.
pub(super) struct Nearest {
    pub gap: Real,
    pub at: Option<(Real, Real)>,
    pub closest: ClosestPoint,
}

/// A search radius for an element's probes that holds every reading within
/// reach: half a spacing plus the reach times a bound on the reading's
/// standard deviation (the hull's bound along any direction, with the
/// sampled edges' half spacing along two tangents).
fn probe_radius(frame: &Frame<'_>, els: &SurfaceElements, k: u32) -> Real {
    let hull = els.hulls().hull(k);
    let e = &els.elements()[k as usize];
    let half = HALF_SPACING * e.spacing;
    half + frame.reach * (hull.sigma * hull.sigma + 2.0 * half * half).sqrt()
}

/// Steps from the probe nearest the surface towards the element's point
/// nearest it: the surface point straight across from the mesh's closest
/// point, where the element was sampled (a mesh's corner pressed into the
/// surface between the probes is read there), at most [`REFINE_STEPS`]
/// times while the gap shrinks; each step's reading within reach is kept.
pub(super) fn refine(
    frame: &Frame<'_>,
    e: &SurfaceElement,
    k: u32,
    mut best: Nearest,
    out: &mut Vec<ElementReading>,
) -> Nearest {
    for _ in 0..REFINE_STEPS {
        let q = frame.to_cloud_point(&best.closest.point) - e.mean;
        let (u, v) = (q.dot(&e.tangents[0]), q.dot(&e.tangents[1]));
        if !e.sampled_over(u, v) {
            break;
        }
        let Some((r, next)) = read_at(frame, e, k, (u, v), Real::INFINITY) else {
            break;
        };
        if r.gap >= best.gap - 1e-12 * e.spacing {
            break;
        }
        best = Nearest {
            gap: r.gap,
            at: Some((u, v)),
            closest: next,
        };
        if r.gap <= HALF_SPACING * e.spacing + frame.reach * r.std {
            out.push(r);
        }
    }
    best
}

/// From the element's surface point nearest the surface (where [`refine`]
/// stopped), steps along the element's surface into the solid: along the
/// part of the closest point's inward normal within the element's tangent
/// plane, half a spacing and then twice as far each step, at most
/// [`DESCEND_STEPS`] times while the gap falls, where the element was
/// sampled; each step's reading within reach is kept. Where the element's
/// surface passes through a thin part of the solid (a bar through a floor
/// tens of centimetres from the element's probes), the closest points lead
/// only to the part's wall, and the surface goes on inside it.
fn descend(
    frame: &Frame<'_>,
    e: &SurfaceElement,
    k: u32,
    best: &Nearest,
    out: &mut Vec<ElementReading>,
) {
    let Some((mut u, mut v)) = best.at else {
        return;
    };
    let inward = -frame.to_cloud(&best.closest.normal);
    let (du, dv) = (inward.dot(&e.tangents[0]), inward.dot(&e.tangents[1]));
    let along = du.hypot(dv);
    if along <= 1e-6 || !along.is_finite() {
        return;
    }
    let (du, dv) = (du / along, dv / along);
    let (mut gap, mut step) = (best.gap, HALF_SPACING * e.spacing);
    for _ in 0..DESCEND_STEPS {
        let (nu, nv) = (u + du * step, v + dv * step);
        if !e.sampled_over(nu, nv) {
            return;
        }
        let Some((r, _)) = read_at(frame, e, k, (nu, nv), Real::INFINITY) else {
            return;
        };
        if r.gap >= gap - 1e-12 * e.spacing {
            return;
        }
        if r.gap <= HALF_SPACING * e.spacing + frame.reach * r.std {
            out.push(r);
        }
        (u, v, gap, step) = (nu, nv, r.gap, 2.0 * step);
    }
}

/// Steps of [`descend`].
const DESCEND_STEPS: usize = 6;

/// Steps of [`refine`].
const REFINE_STEPS: usize = 3;

/// The reading of element `k`'s fitted surface at tangential coordinates
/// `(u, v)` (see [`probe_readings`]) and the mesh's closest point to it;
/// `None` if the surface point lies outside, farther than `radius`.
pub(super) fn read_at(
    frame: &Frame<'_>,
    e: &SurfaceElement,
    k: u32,
    (u, v): (Real, Real),
    radius: Real,
) -> Option<(ElementReading, ClosestPoint)> {
    let (x, var_h) = e.surface_point(u, v);
    let c = frame.closest_near(&frame.to_mesh(&x), radius)?;
    let n = frame.to_cloud(&c.normal);
    let along = e.normal.dot(&n);
    let fit = var_h * along * along + n.dot(&(across_normal(e) * n));
    let edge = edge_var_along(e, u, v, &n);
    Some((reading(k, c.signed_distance, fit + edge, fit), c))
}

/// The reading of element `k` with gap `gap` and variance `var`, `fit` of it
/// from the element's fitted surface.
fn reading(k: u32, gap: Real, var: Real, fit: Real) -> ElementReading {
    ElementReading {
        own: k,
        other: k,
        gap,
        std: var.max(0.0).sqrt(),
        fit_std: fit.max(0.0).sqrt(),
        beside: false,
        // One contact: the exact side has no near regions to read apart.
        contact: 0,
        // Read at the most critical element: its signed distances are
        // measured against the exact surface, which needs no pooling.
        at: None,
        direction: Vector3::zeros(),
    }
}

/// The variance that the position of the element's sampled edges adds along
/// `dir` at tangential coordinates `(u, v)`: within half a spacing of an
/// edge, the edge is known to half a spacing along the tangent across it,
/// which moves the surface's end by `t . dir` of that (as the two-cloud
/// readings count it for a probe's own element).
fn edge_var_along(e: &SurfaceElement, u: Real, v: Real, dir: &Vector3) -> Real {
    let half = HALF_SPACING * e.spacing;
    let [[u0, u1], [v0, v1]] = e.extent;
    [(u - u0).min(u1 - u), (v - v0).min(v1 - v)]
        .iter()
        .zip(&e.tangents)
        .filter(|(to_edge, _)| **to_edge <= half)
        .map(|(_, t)| (t.dot(dir) * half).powi(2))
        .sum()
}
