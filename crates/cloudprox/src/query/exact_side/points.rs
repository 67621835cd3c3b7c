//! Per-point probabilities against the exact surface (the paper's Eq. 3).

use crate::cloud::PointCloud;
use crate::element::SurfaceElements;
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
/// point's largest standard deviation) or inside are read exactly; the
/// others have `p < epsilon / 2`, stored as 0. A point farther than its
/// reach from the mesh's bounding box is passed over first (a wide floor's
/// element near a small link holds thousands of such points). An element's points lie
/// together: each search is bounded by the previous point's closest point
/// (the surface lies at most that far), and a point is passed over without
/// one when the previous point's distance `d`, less the step between them,
/// exceeds its reach while the previous point was outside (the ball of
/// radius `d` about it holds no surface, so the point lies outside too,
/// beyond its reach).
pub(crate) fn point_probabilities(
    frame: &Frame<'_>,
    cloud: &PointCloud,
    els: &SurfaceElements,
    near: &[(u32, bool)],
) -> Result<PointProbabilities> {
    let sigma = cloud.sigma_max();
    let mut pairs: Vec<(u32, Real)> = Vec::new();
    for &(e, _) in near {
        let mut last: Option<(Point3, ClosestPoint)> = None;
        for (i, p, cov) in els.members(e) {
            let x = frame.to_mesh(p);
            let radius = frame.reach * sigma[i as usize];
            if frame.beyond_box(&x, radius) {
                continue;
            }
            if let Some((xr, cr)) = &last {
                if !cr.is_inside() && cr.distance() - (x - xr).norm() > radius {
                    continue;
                }
            }
            let c = closest_from(frame, &x, last.as_ref().map(|(_, c)| &c.point));
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
/// than `hint` (a point of the surface) when given.
fn closest_from(frame: &Frame<'_>, x: &Point3, hint: Option<&Point3>) -> ClosestPoint {
    let Some(q) = hint else {
        return frame.closest(x);
    };
    // A margin over the rounding.
    let bound = (x - q).norm() * (1.0 + 1e-9) + 1e-12;
    frame
        .closest_within(x, bound)
        .unwrap_or_else(|| frame.closest(x))
}
