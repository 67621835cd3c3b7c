//! Per-point probabilities against the exact surface (the paper's Eq. 3).

use crate::cloud::PointCloud;
use crate::element::{MemberChunk, SurfaceElements};
use crate::error::Result;
use crate::math::Point3;
use crate::probability::point_probability;
use crate::query::collide::PointProbabilities;
use crate::query::exact_side::frame::Frame;
use crate::shape::ClosestPoint;
use crate::Real;

/// `p_i = Phi(-sd(x_i) / sqrt(n^T Sigma_i n))` for the points of the
/// elements `near` (see [`super::readings::ElementScan::near`]), 0 for every
/// other point of `cloud`.
///
/// Only points within the noise's reach of the surface (`reach` times the
/// point's largest standard deviation) are read exactly; the others outside
/// have `p < epsilon / 2`, stored as 0, and those inside deeper than their
/// reach `p > 1 - epsilon / 2`, stored as 1 where they are passed over (below). A point farther than its
/// reach from the mesh's bounding box is passed over first, a run of an
/// element's points at a time where the run's box lies beyond the reach of
/// all of them (a wide floor's element near a small link holds thousands of
/// such points). An element's points lie
/// together: each search is bounded by the previous point's closest point
/// (the surface lies at most that far), and a point is passed over without
/// one when the previous point's distance `d`, less the step between them,
/// exceeds its reach (the ball of radius `d` about the previous point holds
/// no surface, so the point lies on its side, beyond its reach): a link
/// pressed into a scan reads the thousands of points deep inside it from a
/// few searches. With a distance field of the mesh, its bounds place a point
/// beyond its reach, outside or inside, before any search.
pub(crate) fn point_probabilities(
    frame: &Frame<'_>,
    cloud: &PointCloud,
    els: &SurfaceElements,
    near: &[(u32, bool)],
) -> Result<PointProbabilities> {
    let sigma = cloud.sigma_max();
    let mut pairs: Vec<(u32, Real)> = Vec::new();
    // A run of an element's points farther from the mesh's box than the
    // noise of any of them reaches is passed over whole.
    let mesh_box = frame.box_in_cloud();
    let within = |c: &MemberChunk| {
        let r = frame.reach * c.sigma;
        c.aabb.distance_squared(&mesh_box) <= r * r
    };
    for &(e, _) in near {
        let mut last: Option<(Point3, ClosestPoint)> = None;
        for (i, p, cov) in els.members_near(e, within) {
            let x = frame.to_mesh(p);
            let radius = frame.reach * sigma[i as usize];
            if frame.beyond_box(&x, radius) {
                continue;
            }
            let bounds = frame.bounds(&x);
            match bounds {
                Some((lo, _)) if lo > radius => continue,
                Some((_, hi)) if hi < -radius => {
                    pairs.push((i, 1.0));
                    continue;
                }
                _ => {}
            }
            if let Some((xr, cr)) = &last {
                if cr.distance() - (x - xr).norm() > radius {
                    if cr.is_inside() {
                        pairs.push((i, 1.0));
                    }
                    continue;
                }
            }
            // The padded surface's point `c` lies `padding` off the mesh's.
            let hint = last
                .as_ref()
                .map(|(_, c)| (x - c.point).norm() + frame.padding());
            let c = closest_from(frame, &x, [hint, bounds.map(|b| frame.reach_of(b))]);
            last = Some((x, c));
            if !c.is_inside() && c.distance() > radius {
                continue;
            }
            let n = frame.to_cloud(&c.normal);
            let value = point_probability(c.signed_distance, &n, cov, 1.0).clamp(0.0, 1.0);
            if value > 0.0 {
                pairs.push((i, value));
            }
        }
    }
    pairs.sort_unstable_by_key(|&(i, _)| i);
    pairs.dedup_by_key(|&mut (i, _)| i);
    let (indices, values) = pairs.into_iter().unzip();
    PointProbabilities::from_sparse(cloud.len(), indices, values)
}

/// The surface's closest point to `x` (mesh frame), searched no farther
/// than the smaller of `limits` (bounds on the mesh's unsigned distance at
/// `x`: the previous point's closest point's distance, the distance
/// field's) when there are any.
fn closest_from(frame: &Frame<'_>, x: &Point3, limits: [Option<Real>; 2]) -> ClosestPoint {
    let Some(limit) = limits.into_iter().flatten().reduce(Real::min) else {
        return frame.closest(x);
    };
    // A margin over the rounding.
    frame
        .mesh_within(x, limit * (1.0 + 1e-9) + 1e-12)
        .unwrap_or_else(|| frame.closest(x))
}
