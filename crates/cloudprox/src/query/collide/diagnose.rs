//! The elements model's facing pairs, for diagnostics: what each patch's
//! element surfaces read across the contact, so that the estimated gaps can be
//! compared with exact geometry (the standardized residual
//! `(g_true - g_hat) / s` should be standard normal).

use crate::cloud::PointCloud;
use crate::element::SurfaceElements;
use crate::error::Result;
use crate::math::Pose;
use crate::probability::{element_facing_pairs, normal_quantile, FacingPair};
use crate::query::collide::elements::element_side;
use crate::query::collide::{collide, CollisionRequest, QueryModel};

/// Every facing pair of element surfaces that the elements model reads in the
/// patches of the query `collide(pose_a, a, pose_b, b, request)` (run with
/// `model = elements` and one segmentation whatever `request` says), in world
/// coordinates: each probe of one side's elements, the other side's facing
/// surface point, the direction across them (from A towards B), the gap, its
/// standard deviation and the crossing probability `Phi(-gap / std)`.
///
/// The pair's `P` is the largest probability over the pairs within reach
/// (and the crossing rule, which reads no facing pair).
pub fn facing_pairs(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<Vec<FacingPair>> {
    let mut request = *request;
    request.model = QueryModel::Elements;
    request.segmentations = 1;
    request.decide_only = false;
    let result = collide(pose_a, a, pose_b, b, &request)?;
    let (ea, eb) = (a.elements(), b.elements());
    let (owner_a, owner_b) = (point_owners(ea, a.len()), point_owners(eb, b.len()));
    let rel = pose_b.inverse() * pose_a;
    let reach = -normal_quantile(0.5 * request.prune_epsilon);
    let mut out = Vec::new();
    for patch in &result.patches {
        let ia = owners(&owner_a, &patch.indices_a);
        let ib = owners(&owner_b, &patch.indices_b);
        let side_a = element_side(ea, &ia, &rel, 1.0);
        let side_b = element_side(eb, &ib, &Pose::identity(), -1.0);
        let mut sep = patch.separator.clone();
        sep.frame = Pose::identity();
        out.extend(element_facing_pairs(
            &side_a, &ia, &side_b, &ib, &sep, reach,
        ));
        out.extend(element_facing_pairs(
            &side_b, &ib, &side_a, &ia, &sep, reach,
        ));
    }
    for p in &mut out {
        p.probe = pose_b * p.probe;
        p.facing = pose_b * p.facing;
        p.direction = pose_b.rotation * p.direction;
    }
    Ok(out)
}

/// The element each point of a cloud of `n` points belongs to.
fn point_owners(elements: &SurfaceElements, n: usize) -> Vec<u32> {
    let mut owner = vec![0; n];
    for e in 0..elements.elements().len() as u32 {
        for &i in elements.element_points(e) {
            owner[i as usize] = e;
        }
    }
    owner
}

/// The elements (sorted, each once) of the points `points`.
fn owners(owner: &[u32], points: &[u32]) -> Vec<u32> {
    let mut out: Vec<u32> = points.iter().map(|&i| owner[i as usize]).collect();
    out.sort_unstable();
    out.dedup();
    out
}
