//! The entry points of the exact-side query.

use std::time::Instant;

use rayon::prelude::*;

use crate::cloud::{validate_pose, PointCloud};
use crate::error::{Error, Result};
use crate::math::Pose;
use crate::probability::{contact_probability, Aggregation};
use crate::query::collide::{
    CollisionRequest, CollisionResult, PointAggregates, PointProbabilities, QueryCounters,
    QueryModel, QueryStats,
};
use crate::query::exact_side::frame::Frame;
use crate::query::exact_side::points::point_probabilities;
use crate::query::exact_side::readings::{element_readings, ElementScan};
use crate::shape::{DistanceField, MeshDistance};
use crate::Real;

/// The probabilistic collision query between an exact mesh (its signed
/// distance `mesh`) at `pose_mesh` and a noisy cloud at `pose_cloud`, the
/// mesh's surface standing as the separating surface (see the
/// [module docs](crate::query::exact_side)).
///
/// # Returns
/// A [`CollisionResult`] whose side A is the mesh (no points:
/// `probabilities_a` is empty) and side B the cloud: `P` (with
/// [`QueryModel::Elements`], the default, the elements' readings against the
/// surface through [`contact_probability`], averaged over
/// `request.segmentations`; with [`QueryModel::Points`], the request's
/// aggregation of the per-point probabilities), the state from `P` and the
/// request's thresholds, with the points model its three aggregates
/// ([`CollisionResult::point_aggregates`]), the per-point probabilities of the cloud's points
/// near the surface (Eq. 3; left out with `decide_only` under the elements
/// model), no patches (nothing is trained) and counters: `node_pairs_visited`
/// the elements tested against the surface, `leaf_pairs` the readings within
/// reach, `near_regions` the elements within reach.
///
/// With `decide_only` (elements model, one segmentation) the elements are
/// read until the first whose own readings reach the collision threshold
/// (the elements deep inside the mesh first, one closest-point search each):
/// `P` is then that element's, at most the full query's, with the same state.
///
/// A cloud whose every element is beyond the noise's reach of the surface
/// (each element's hull against the mesh's box, then against the surface
/// within its reach) is free without a reading.
///
/// # Errors
/// As [`CollisionRequest::validate`]; a pose that is not finite; the
/// `surface` aggregation (it reads a trained surface around each point).
///
/// # Example
/// ```
/// use cloudprox::prelude::*;
/// use cloudprox::query::exact_side::collide_exact_cloud;
/// use cloudprox::shape::MeshDistance;
/// let cube = MeshDistance::new(&Mesh::cuboid(0.05, 0.05, 0.05).unwrap()).unwrap();
/// let plane: Vec<Point3> = (0..400)
///     .map(|i| Point3::new((i % 20) as f64 * 0.005 - 0.05, (i / 20) as f64 * 0.005 - 0.05, 0.0))
///     .collect();
/// let cloud = PointCloud::from_sigma(plane, 0.001).unwrap();
/// let req = CollisionRequest::default();
/// // The plane 2 cm below the cube's bottom face: 20 sigma.
/// let r = collide_exact_cloud(&Pose::translation(0.0, 0.0, 0.07), &cube,
///                             &Pose::identity(), &cloud, &req).unwrap();
/// assert_eq!(r.state, CollisionState::Free);
/// let r = collide_exact_cloud(&Pose::identity(), &cube, &Pose::identity(), &cloud, &req).unwrap();
/// assert_eq!(r.state, CollisionState::Collision);
/// ```
pub fn collide_exact_cloud(
    pose_mesh: &Pose,
    mesh: &MeshDistance,
    pose_cloud: &Pose,
    cloud: &PointCloud,
    request: &CollisionRequest,
) -> Result<CollisionResult> {
    validate(request)?;
    validate_pose(pose_mesh, "pose_mesh")?;
    validate_pose(pose_cloud, "pose_cloud")?;
    collide_exact_cloud_padded(pose_mesh, (mesh, 0.0, None), pose_cloud, cloud, request)
}

/// [`collide_exact_cloud`] with the sides in the other order: the cloud is
/// side A, the mesh side B (`probabilities_b` is empty). The same `P`,
/// state and per-point probabilities.
///
/// # Errors
/// As [`collide_exact_cloud`].
pub fn collide_cloud_exact(
    pose_cloud: &Pose,
    cloud: &PointCloud,
    pose_mesh: &Pose,
    mesh: &MeshDistance,
    request: &CollisionRequest,
) -> Result<CollisionResult> {
    let mut r = collide_exact_cloud(pose_mesh, mesh, pose_cloud, cloud, request)?;
    std::mem::swap(&mut r.probabilities_a, &mut r.probabilities_b);
    Ok(r)
}

/// [`collide_exact_cloud`] for the mesh at each of `poses_mesh` against the
/// cloud at `pose_cloud`, in parallel (rayon); results in the order of the
/// poses. The cloud's elements and their hulls are built once, before.
///
/// # Errors
/// As [`collide_exact_cloud`] (before any work), naming the first bad pose.
pub fn collide_exact_cloud_many(
    poses_mesh: &[Pose],
    mesh: &MeshDistance,
    pose_cloud: &Pose,
    cloud: &PointCloud,
    request: &CollisionRequest,
) -> Result<Vec<CollisionResult>> {
    validate(request)?;
    validate_pose(pose_cloud, "pose_cloud")?;
    for (i, p) in poses_mesh.iter().enumerate() {
        validate_pose(p, &format!("poses_mesh[{i}]"))?;
    }
    for s in 0..segmentations(request) {
        cloud.segmentation_after(s).hulls();
    }
    poses_mesh
        .par_iter()
        .map(|p| collide_exact_cloud_padded(p, (mesh, 0.0, None), pose_cloud, cloud, request))
        .collect()
}

/// [`collide_exact_cloud_many`] for the cloud at each of `poses_cloud`
/// against the mesh at `pose_mesh`, with the sides as
/// [`collide_cloud_exact`] gives them (the cloud is side A).
///
/// # Errors
/// As [`collide_exact_cloud_many`], naming the first bad pose of `poses_cloud`.
pub fn collide_cloud_exact_many(
    poses_cloud: &[Pose],
    cloud: &PointCloud,
    pose_mesh: &Pose,
    mesh: &MeshDistance,
    request: &CollisionRequest,
) -> Result<Vec<CollisionResult>> {
    validate_pose(pose_mesh, "pose_mesh")?;
    for (i, p) in poses_cloud.iter().enumerate() {
        validate_pose(p, &format!("poses_cloud[{i}]"))?;
    }
    // Only the relative pose matters (nothing of the result is in the world
    // frame): the mesh at `p^-1 pose_mesh` against the cloud at the identity.
    let poses_mesh: Vec<Pose> = poses_cloud
        .iter()
        .map(|p| p.inverse() * pose_mesh)
        .collect();
    let mut out = collide_exact_cloud_many(&poses_mesh, mesh, &Pose::identity(), cloud, request)?;
    for r in &mut out {
        std::mem::swap(&mut r.probabilities_a, &mut r.probabilities_b);
    }
    Ok(out)
}

/// The request checks and what the exact side cannot answer.
fn validate(request: &CollisionRequest) -> Result<()> {
    request.validate()?;
    if request.model == QueryModel::Points && request.aggregation == Aggregation::Surface {
        return Err(Error::invalid(
            "aggregation 'surface' reads a trained surface around each point: \
             not available with an exact mesh side (use 'max', 'union' or 'independent')",
        ));
    }
    Ok(())
}

/// The segmentations a query averages over (one with the points model).
fn segmentations(request: &CollisionRequest) -> u32 {
    match request.model {
        QueryModel::Elements => request.segmentations,
        QueryModel::Points => 1,
    }
}

/// [`collide_exact_cloud`] of the mesh's surface grown by `padding` (metres,
/// finite and `>= 0`, checked by the caller): every signed distance read is
/// the mesh's less `padding` (a robot link's safety margin). Padding 0 is
/// [`collide_exact_cloud`] bit for bit. With `field`, a distance field of
/// the same mesh, its bounds place elements and points beyond reach or deep
/// inside before any search (the same result: a bound only decides what
/// the search would). The request and poses are not validated.
pub(crate) fn collide_exact_cloud_padded(
    pose_mesh: &Pose,
    (mesh, padding, field): (&MeshDistance, Real, Option<&DistanceField>),
    pose_cloud: &Pose,
    cloud: &PointCloud,
    request: &CollisionRequest,
) -> Result<CollisionResult> {
    let start = Instant::now();
    let frame = Frame::padded(
        mesh,
        pose_mesh.inverse() * pose_cloud,
        request.prune_epsilon,
        padding,
    )
    .with_field(field);
    let k = segmentations(request);
    let points_model = request.model == QueryModel::Points;
    // One segmentation's P is the largest of its elements': decide_only stops
    // at the first element that reaches the collision threshold.
    let decisive =
        (request.decide_only && !points_model && k == 1).then_some(request.thresholds.collision);
    let scans: Vec<ElementScan> = (0..k)
        .map(|s| element_readings(&frame, cloud.segmentation_after(s), decisive))
        .collect();
    let probabilities_b = if request.decide_only && !points_model {
        PointProbabilities::zeros(cloud.len())
    } else {
        point_probabilities(&frame, cloud, cloud.segmentation_after(0), &scans[0].near)?
    };
    let probability = if points_model {
        request
            .aggregation
            .aggregate(probabilities_b.values().iter().copied())
    } else {
        scans
            .iter()
            .map(|s| contact_probability(&s.readings))
            .sum::<Real>()
            / Real::from(k)
    };
    let point_aggregates = points_model.then(|| PointAggregates::of(probabilities_b.values()));
    Ok(CollisionResult {
        probability,
        state: request.thresholds.state(probability),
        probabilities_a: PointProbabilities::zeros(0),
        probabilities_b,
        patches: Vec::new(),
        point_aggregates,
        stats: QueryStats {
            counters: counters(&scans),
            time_seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// The counters of the scans (see [`collide_exact_cloud`]).
fn counters(scans: &[ElementScan]) -> QueryCounters {
    QueryCounters {
        node_pairs_visited: scans.iter().map(|s| s.tested).sum(),
        leaf_pairs: scans.iter().map(|s| s.readings.len()).sum(),
        near_regions: scans.iter().map(|s| s.near.len()).sum(),
        ..QueryCounters::default()
    }
}
