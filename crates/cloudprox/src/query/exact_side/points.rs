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
/// elements `near` (each with whether it touches the surface; see
/// [`super::readings::ElementScan::near`]), 0 for every other point of
/// `cloud`.
///
/// Each point's surface is searched within the noise's reach of it
/// (`reach` times its largest standard deviation): a point with no surface
/// there lies farther than the reach outside (`p < epsilon / 2`, stored as
/// 0) or inside, which is asked only of the points of touching elements
/// (an element whose readings all lie outside has its points outside but
/// for noise beyond the reach). The previous point's closest point bounds
/// the search (the surface is at most that far): an element's points lie
/// together, so most searches are short.
pub(crate) fn point_probabilities(
    frame: &Frame<'_>,
    cloud: &PointCloud,
    els: &SurfaceElements,
    near: &[(u32, bool)],
) -> Result<PointProbabilities> {
    let sigma = cloud.sigma_max();
    let mut pairs: Vec<(u32, Real)> = Vec::new();
    for &(e, touching) in near {
        let mut last: Option<Point3> = None;
        for (i, p, cov) in els.members(e) {
            let x = frame.to_mesh(p);
            let radius = frame.reach * sigma[i as usize];
            let Some(c) = closest_for_point(frame, &x, radius, last, touching) else {
                continue;
            };
            last = Some(c.point);
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

/// The surface's closest point to `x` (mesh frame) if it lies within
/// `radius` or `x` is inside (asked only when `touching`), searched no
/// farther than `last` (a point of the surface) when given.
fn closest_for_point(
    frame: &Frame<'_>,
    x: &Point3,
    radius: Real,
    last: Option<Point3>,
    touching: bool,
) -> Option<ClosestPoint> {
    let Some(q) = last else {
        return frame
            .mesh
            .closest_within(x, radius)
            .or_else(|| (touching && frame.mesh.contains(x)).then(|| frame.mesh.closest(x)));
    };
    // The surface is within `hint` of `x`; a margin over the rounding.
    let hint = (x - q).norm() * (1.0 + 1e-9) + 1e-12;
    if hint <= radius {
        return frame
            .mesh
            .closest_within(x, hint)
            .or_else(|| Some(frame.mesh.closest(x)));
    }
    if let Some(c) = frame.mesh.closest_within(x, radius) {
        return Some(c);
    }
    if !touching {
        return None;
    }
    // Farther than the reach: inside (certain wrong side) or outside (none).
    let c = frame
        .mesh
        .closest_within(x, hint)
        .unwrap_or_else(|| frame.mesh.closest(x));
    c.is_inside().then_some(c)
}
