//! Many poses of one cloud against another, in parallel.

use rayon::prelude::*;

use crate::bvh::BvhWorkspace;
use crate::cloud::PointCloud;
use crate::error::Result;
use crate::math::Pose;
use crate::query::collide::collide::collide_with_workspace;
use crate::query::collide::{CollisionRequest, CollisionResult};

/// [`crate::query::collide()`] for cloud `a` at each of `poses_a` against cloud `b`
/// at `pose_b`, on rayon's thread pool. Both hierarchies are built once, before
/// the parallel part. Results are in the order of `poses_a`.
pub fn collide_many(
    poses_a: &[Pose],
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<Vec<CollisionResult>> {
    request.validate()?;
    if request.use_hierarchy {
        let _ = (a.bvh(), b.bvh());
    }
    poses_a
        .par_iter()
        .map_init(BvhWorkspace::default, |ws, pose_a| {
            collide_with_workspace(pose_a, a, pose_b, b, request, ws)
        })
        .collect()
}
