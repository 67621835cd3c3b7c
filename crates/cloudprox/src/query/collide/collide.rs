//! The generic entry of the collision query.

use std::time::Instant;

use crate::bvh::BvhWorkspace;
use crate::classify::{train, SolveStatus};
use crate::cloud::PointCloud;
use crate::error::Result;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::point_probability;
use crate::query::collide::region::{near_regions, split_patches, Patch};
use crate::query::collide::{CollisionRequest, CollisionResult, ContactRegion, QueryStats};
use crate::Real;

/// The probabilistic collision query between cloud `a` at world pose `pose_a` and
/// cloud `b` at `pose_b`.
///
/// # Arguments
/// * `pose_a`, `pose_b` - the clouds' poses (own frame to world).
/// * `a`, `b` - the clouds; their hierarchies are built on first use and reused.
/// * `request` - options (validated here).
///
/// # Returns
/// A [`CollisionResult`]: `P`, the state, per-point probabilities, the classified
/// patches of the near regions (world frame) and statistics. Errors only on an
/// invalid request; a solver that does not converge falls back (see
/// [`crate::classify::SolveStatus::Fallback`]) and is counted in the stats.
///
/// # Example
/// ```
/// use cloudprox::prelude::*;
/// let line = |x0: f64| -> Vec<Point3> { (0..50).map(|i| Point3::new(x0, i as f64 * 0.01, 0.0)).collect() };
/// let a = PointCloud::from_sigma(line(0.0), 0.001).unwrap();
/// let b = PointCloud::from_sigma(line(0.0), 0.001).unwrap();
/// // b shifted 2 cm along x: 20 sigma apart.
/// let r = collide(&Pose::identity(), &a, &Pose::translation(0.02, 0.0, 0.0), &b,
///                 &CollisionRequest::default()).unwrap();
/// assert_eq!(r.state, CollisionState::Free);
/// ```
///
/// # See Also
/// [`crate::query::collide_many`] for many poses of one cloud in parallel.
pub fn collide(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<CollisionResult> {
    let mut workspace = BvhWorkspace::default();
    collide_with_workspace(pose_a, a, pose_b, b, request, &mut workspace)
}

pub(crate) fn collide_with_workspace(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
    workspace: &mut BvhWorkspace,
) -> Result<CollisionResult> {
    request.validate()?;
    let start = Instant::now();
    let mut stats = QueryStats::default();
    let components: Vec<Patch> = if request.use_hierarchy {
        let rel = pose_b.inverse() * pose_a;
        let t = a
            .bvh()
            .traverse_pairs(b.bvh(), &rel, request.prune_epsilon, workspace);
        stats.node_pairs_visited = t.node_pairs_visited;
        stats.leaf_pairs = t.leaf_pairs.len();
        stats.pruned_bound = t.pruned_bound;
        near_regions(&t.leaf_pairs, a.bvh(), b.bvh())
    } else {
        vec![Patch {
            component: 0,
            a: (0..a.len() as u32).collect(),
            b: (0..b.len() as u32).collect(),
        }]
    };
    stats.near_regions = components.len();

    let world = |pose: &Pose, cloud: &PointCloud, idx: &[u32]| -> (Vec<Point3>, Vec<Matrix3>) {
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        idx.iter()
            .map(|&i| {
                let i = i as usize;
                (pose * cloud.points()[i], r * cloud.covariances()[i] * r.transpose())
            })
            .unzip()
    };

    let mut probabilities_a = vec![0.0; a.len()];
    let mut probabilities_b = vec![0.0; b.len()];
    let mut regions = Vec::new();
    for component in components {
        // Patches are cut in the world frame, so the cut does not depend on which
        // cloud's frame the traversal ran in.
        let comp_a = world(pose_a, a, &component.a).0;
        let comp_b = world(pose_b, b, &component.b).0;
        let local = Patch {
            component: component.component,
            a: (0..component.a.len() as u32).collect(),
            b: (0..component.b.len() as u32).collect(),
        };
        for patch in split_patches(local, &comp_a, &comp_b, request.region_max_points) {
            let ia: Vec<u32> = patch.a.iter().map(|&k| component.a[k as usize]).collect();
            let ib: Vec<u32> = patch.b.iter().map(|&k| component.b[k as usize]).collect();
            let region = classify_patch(patch.component, pose_a, a, &ia, pose_b, b, &ib, request, &world)?;
            for (&i, &p) in ia.iter().zip(&region.1) {
                probabilities_a[i as usize] = p;
            }
            for (&i, &p) in ib.iter().zip(&region.2) {
                probabilities_b[i as usize] = p;
            }
            stats.points_classified += ia.len() + ib.len();
            stats.solver_iterations += u64::from(region.0.iterations);
            stats.solver_fallbacks += usize::from(region.0.status == SolveStatus::Fallback);
            regions.push(region.0);
        }
    }
    stats.patches = regions.len();
    let probability = request
        .aggregation
        .aggregate(probabilities_a.iter().chain(&probabilities_b).copied());
    stats.time_seconds = start.elapsed().as_secs_f64();
    Ok(CollisionResult {
        probability,
        state: request.thresholds.state(probability),
        probabilities_a,
        probabilities_b,
        regions,
        stats,
    })
}

type WorldFn<'w> = dyn Fn(&Pose, &PointCloud, &[u32]) -> (Vec<Point3>, Vec<Matrix3>) + 'w;

#[allow(clippy::type_complexity)]
fn classify_patch(
    component: u32,
    pose_a: &Pose,
    a: &PointCloud,
    ia: &[u32],
    pose_b: &Pose,
    b: &PointCloud,
    ib: &[u32],
    request: &CollisionRequest,
    world: &WorldFn<'_>,
) -> Result<(ContactRegion, Vec<Real>, Vec<Real>)> {
    let (mut pts, mut covs) = world(pose_a, a, ia);
    let (pts_b, covs_b) = world(pose_b, b, ib);
    pts.extend_from_slice(&pts_b);
    covs.extend_from_slice(&covs_b);
    let labels: Vec<Real> = std::iter::repeat_n(1.0, ia.len())
        .chain(std::iter::repeat_n(-1.0, ib.len()))
        .collect();
    let fit = train(&pts, &covs, &labels, &request.classify)?;
    let sep = &fit.separator;
    let mut probs = Vec::with_capacity(pts.len());
    let mut dists = Vec::with_capacity(pts.len());
    for ((x, cov), &c) in pts.iter().zip(&covs).zip(&labels) {
        let (f, g) = sep.value_and_gradient(x);
        probs.push(point_probability(f, &g, cov, c));
        let gn = g.norm();
        dists.push(if gn > 0.0 { c * f / gn } else if c * f > 0.0 { Real::INFINITY } else { Real::NEG_INFINITY });
    }
    let na = ia.len();
    let (da, db) = dists.split_at(na);
    let separation = quantile(da, 0.25) + quantile(db, 0.25);
    let closest = |d: &[Real], off: usize| -> Point3 {
        let k = d
            .iter()
            .enumerate()
            .min_by(|x, y| x.1.total_cmp(y.1))
            .map_or(0, |(k, _)| k);
        pts[off + k]
    };
    let mid = nalgebra::center(&closest(da, 0), &closest(db, na));
    let point = sep.project(&mid);
    let (_, g) = sep.value_and_gradient(&point);
    let normal = if g.norm() > 0.0 { -g.normalize() } else { (pts_b_mean(&pts[na..]) - pts_b_mean(&pts[..na])).normalize() };
    let probability = request.aggregation.aggregate(probs.iter().copied());
    let probs_b = probs.split_off(na);
    Ok((
        ContactRegion {
            component,
            indices_a: ia.to_vec(),
            indices_b: ib.to_vec(),
            point,
            normal,
            separation,
            probability,
            separator: fit.separator.clone(),
            surface: fit.separator.surface,
            status: fit.status,
            iterations: fit.iterations,
        },
        probs,
        probs_b,
    ))
}

fn pts_b_mean(p: &[Point3]) -> Point3 {
    Point3::from(p.iter().map(|x| x.coords).sum::<crate::math::Vector3>() / p.len() as Real)
}

/// The `q`-quantile of `v` (nearest rank), `NaN` for an empty slice.
fn quantile(v: &[Real], q: Real) -> Real {
    if v.is_empty() {
        return Real::NAN;
    }
    let mut s = v.to_vec();
    let k = ((q * (s.len() - 1) as Real).round() as usize).min(s.len() - 1);
    let (_, x, _) = s.select_nth_unstable_by(k, Real::total_cmp);
    *x
}
