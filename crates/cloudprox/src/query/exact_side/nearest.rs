//! The cloud's surface estimate nearest the exact surface, read with the
//! exact-side query's formula ([`read_at`]): the distance query's mesh side.

use crate::cloud::PointCloud;
use crate::math::{Point3, Pose, Vector3};
use crate::query::exact_side::frame::Frame;
use crate::query::exact_side::readings::{point_reading, read_at, refine, Nearest};
use crate::shape::MeshDistance;
use crate::Real;

/// Where the cloud's surface estimate comes closest to the exact surface, in
/// the mesh's frame; or a lower bound, when it is farther than asked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MeshGap {
    /// The signed distance of the cloud's surface estimate to the mesh there
    /// (negative inside), or the lower bound (`bound`).
    pub gap: Real,
    /// Its standard deviation (the exact-side reading's; 0 for a bound).
    pub std: Real,
    /// The point of the cloud's fitted surface (NaN for a bound).
    pub point_cloud: Point3,
    /// The mesh's closest point to it (NaN for a bound).
    pub point_mesh: Point3,
    /// The mesh's outward normal there (towards the cloud's point outside).
    pub normal: Vector3,
    /// Whether `gap` is only a lower bound: every element is farther than the
    /// noise's reach beyond `max_distance`.
    pub bound: bool,
}

/// The element surface (or single point) of `cloud` (at `rel` in the mesh's
/// frame) nearest the surface of `mesh`: each element is bounded below by
/// the signed distance of its mean less its hull's radius (a signed distance
/// changes no faster than the point), and read from the nearest bound up,
/// at every probe (then refined as the exact-side query refines its nearest
/// probe), until the next bound exceeds the best gap. When every bound, less
/// `reach` standard deviations of its element's noise, exceeds
/// `max_distance`, only that smallest bound is returned.
pub(crate) fn nearest_to_mesh(
    mesh: &MeshDistance,
    rel: Pose,
    cloud: &PointCloud,
    prune_epsilon: Real,
    max_distance: Real,
) -> MeshGap {
    let frame = Frame::new(mesh, rel, prune_epsilon);
    let els = cloud.elements();
    let hulls = els.hulls();
    let mut order: Vec<(Real, Real, u32)> = (0..els.elements().len() as u32)
        .map(|k| {
            let h = hulls.hull(k);
            let lb = mesh.signed_distance(&frame.to_mesh(&h.mean)) - h.radius;
            (lb, lb - frame.reach * h.sigma, k)
        })
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0));
    let lowest = order.iter().map(|o| o.1).fold(Real::INFINITY, Real::min);
    if lowest > max_distance {
        return MeshGap {
            gap: lowest,
            std: 0.0,
            point_cloud: Point3::new(Real::NAN, Real::NAN, Real::NAN),
            point_mesh: Point3::new(Real::NAN, Real::NAN, Real::NAN),
            normal: Vector3::new(Real::NAN, Real::NAN, Real::NAN),
            bound: true,
        };
    }
    let mut best: Option<MeshGap> = None;
    for &(lb, _, k) in &order {
        if best.is_some_and(|b| lb > b.gap) {
            break;
        }
        let read = element_nearest(&frame, cloud, k);
        if best.is_none_or(|b| read.is_some_and(|r| r.gap < b.gap)) {
            best = read.or(best);
        }
    }
    best.unwrap_or(MeshGap {
        gap: Real::NAN,
        std: Real::NAN,
        point_cloud: Point3::new(Real::NAN, Real::NAN, Real::NAN),
        point_mesh: Point3::new(Real::NAN, Real::NAN, Real::NAN),
        normal: Vector3::new(Real::NAN, Real::NAN, Real::NAN),
        bound: false,
    })
}

/// Element `k`'s reading nearest the surface: a single point's own
/// ([`point_reading`]); a surface's at the probe nearest the surface, refined
/// towards the element's point nearest it ([`refine`]).
fn element_nearest(frame: &Frame<'_>, cloud: &PointCloud, k: u32) -> Option<MeshGap> {
    let els = cloud.elements();
    let e = &els.elements()[k as usize];
    if e.is_point() || e.probes.is_empty() {
        let r = point_reading(frame, e, k);
        let c = frame.closest(&frame.to_mesh(&e.mean));
        return Some(gap_of(frame, r.gap, r.std, &e.mean, c));
    }
    let first = e
        .probes
        .iter()
        .filter_map(|&[u, v]| {
            read_at(frame, e, k, (u, v), Real::INFINITY).map(|(r, c)| (r.gap, (u, v), c))
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))?;
    let (gap, at, closest) = first;
    let mut scratch = Vec::new();
    let nearest = refine(
        frame,
        e,
        k,
        Nearest {
            gap,
            at: Some(at),
            closest,
        },
        &mut scratch,
    );
    let (u, v) = nearest.at?;
    let (r, c) = read_at(frame, e, k, (u, v), Real::INFINITY)?;
    Some(gap_of(frame, r.gap, r.std, &e.surface_point(u, v).0, c))
}

/// A reading as a [`MeshGap`]: the cloud's point `x` (cloud frame) and the
/// mesh's closest point `c` to it.
fn gap_of(
    frame: &Frame<'_>,
    gap: Real,
    std: Real,
    x: &Point3,
    c: crate::shape::ClosestPoint,
) -> MeshGap {
    MeshGap {
        gap,
        std,
        point_cloud: frame.to_mesh(x),
        point_mesh: c.point,
        normal: c.normal,
        bound: false,
    }
}
