//! Many poses of one cloud against another, in parallel: any poses
//! ([`collide_many`]), or the poses of a motion ([`collide_along`]).

use rayon::prelude::*;

use crate::bvh::BvhWorkspace;
use crate::cloud::{validate_pose, PointCloud};
use crate::error::Result;
use crate::math::Pose;
use crate::query::collide::collide::collide_with_workspace;
use crate::query::collide::{CollisionRequest, CollisionResult, QueryModel, WarmStart};

/// [`crate::query::collide()`] for cloud `a` at each of `poses_a` against cloud `b`
/// at `pose_b`, on rayon's thread pool. What a query of both clouds builds on
/// first use (hierarchy, spacing; with the elements model, the elements with
/// their hulls and samples) is built once, before the parallel part: built
/// inside a query, rayon inside its `OnceLock` could have a thread wait for
/// itself. Results are in the order of `poses_a`.
pub fn collide_many(
    poses_a: &[Pose],
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<Vec<CollisionResult>> {
    ready(a, b, request)?;
    poses_a
        .par_iter()
        .map_init(BvhWorkspace::default, |ws, pose_a| {
            collide_with_workspace(pose_a, a, pose_b, b, request, ws, None)
        })
        .collect()
}

/// Checks `request` and builds what a query of `a` and `b` under it builds on
/// first use ([`prepare`]), before a parallel part.
fn ready(a: &PointCloud, b: &PointCloud, request: &CollisionRequest) -> Result<()> {
    request.validate()?;
    prepare(a, request);
    prepare(b, request);
    Ok(())
}

/// Poses of a motion that [`collide_along`] queries in a row, each from the
/// last one's classifier support; each run of this many starts cold.
pub const ALONG_RUN: usize = 16;

/// [`crate::query::collide()`] for cloud `a` at the poses `poses_a` of a
/// motion (consecutive poses near each other) against cloud `b` at `pose_b`.
///
/// The poses are taken in runs of [`ALONG_RUN`], the runs in parallel on
/// rayon's thread pool (so `ceil(m / ALONG_RUN)` parallel tasks for `m`
/// poses). A run's first pose is queried cold; each later pose's classifier
/// starts from the samples that supported the previous pose's separating
/// surfaces (as `check_motion` does per link). Each round of its working set
/// still adds every violated constraint, so the surfaces are
/// [`collide_many`]'s to the solver's tolerance and `P` moves by about 1e-5
/// at most (a state can differ only where `P` lies that close to a
/// threshold), with fewer solver iterations where consecutive poses see the
/// same contact. The runs are fixed by the poses' order alone, so the answers
/// do not depend on the number of threads. Results are in the order of
/// `poses_a`.
///
/// # Errors
/// An invalid request; a pose of `poses_a` that is not finite (the first, by
/// its index), found before any query runs.
pub fn collide_along(
    poses_a: &[Pose],
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<Vec<CollisionResult>> {
    ready(a, b, request)?;
    for (i, pose) in poses_a.iter().enumerate() {
        validate_pose(pose, &format!("poses_a[{i}]"))?;
    }
    let runs: Vec<Result<Vec<CollisionResult>>> = poses_a
        .par_chunks(ALONG_RUN)
        .map(|run| {
            let mut ws = BvhWorkspace::default();
            let mut warm = WarmStart::default();
            run.iter()
                .map(|pose_a| {
                    collide_with_workspace(pose_a, a, pose_b, b, request, &mut ws, Some(&mut warm))
                })
                .collect()
        })
        .collect();
    let mut out = Vec::with_capacity(poses_a.len());
    for run in runs {
        out.extend(run?);
    }
    Ok(out)
}

/// Builds every part of `cloud` that is built on first use and that a query
/// under `request` reads: its hierarchy and sampling spacing (the spacing is
/// computed on the hierarchy, so both are built whatever `use_hierarchy`
/// says) and, for the elements model, its surface elements with their hulls
/// and their samples' hierarchy and spacing (of every segmentation the
/// request averages over). Calling it again costs nothing.
///
/// Call it on a new cloud before querying it from several threads of a rayon
/// pool (your own `par_iter` over [`collide`](crate::query::collide())):
/// these parts are built with rayon inside a `OnceLock`, and a rayon thread
/// building one, while it waits for its helpers, may take up another query of
/// the same loop that needs the same part and wait for itself. It also keeps
/// the build out of the first query's time. [`collide_many`], [`collide_along`] and the robot's
/// batch queries call it themselves.
pub fn prepare(cloud: &PointCloud, request: &CollisionRequest) {
    let _ = (cloud.bvh(), cloud.spacing());
    if request.model == QueryModel::Elements {
        for k in 0..request.segmentations {
            let elements = cloud.segmentation_after(k);
            let samples = elements.samples();
            let _ = (elements.hulls(), samples.bvh(), samples.spacing());
        }
    }
}
