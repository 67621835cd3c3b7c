//! Per-point probabilities against the exact surface (the paper's Eq. 3).

use crate::cloud::PointCloud;
use crate::element::SurfaceElements;
use crate::error::Result;
use crate::math::{Matrix3, Point3};
use crate::probability::point_probability;
use crate::query::collide::PointProbabilities;
use crate::query::exact_side::frame::Frame;
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
/// for noise beyond the reach).
pub(crate) fn point_probabilities(
    frame: &Frame<'_>,
    cloud: &PointCloud,
    els: &SurfaceElements,
    near: &[(u32, bool)],
) -> Result<PointProbabilities> {
    let sigma = cloud.sigma_max();
    let mut pairs: Vec<(u32, Real)> = Vec::new();
    for &(e, touching) in near {
        for (i, p, cov) in els.members(e) {
            let radius = frame.reach * sigma[i as usize];
            let value = point_value(frame, p, cov, radius, touching);
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

/// Eq. 3 for the point `p` (cloud frame) with covariance `cov`, its surface
/// searched within `radius` (see [`point_probabilities`]).
fn point_value(frame: &Frame<'_>, p: &Point3, cov: &Matrix3, radius: Real, touching: bool) -> Real {
    let x = frame.to_mesh(p);
    let c = match frame.mesh.closest_within(&x, radius) {
        Some(c) => c,
        None if touching && frame.mesh.contains(&x) => frame.mesh.closest(&x),
        None => return 0.0,
    };
    let n = frame.to_cloud(&c.normal);
    point_probability(c.signed_distance, &n, cov, 1.0).clamp(0.0, 1.0)
}
