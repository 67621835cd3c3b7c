//! The generic entry of the collision query.

use std::time::Instant;

use crate::bvh::BvhWorkspace;
use crate::classify::{Separator, SocpSolver, SolveStatus};
use crate::cloud::PointCloud;
use crate::element::SurfaceElements;
use crate::error::Result;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::{
    crossing_probabilities, element_crossing_probabilities, elements_within_reach, normal_quantile,
    point_probability, surface_probability, Aggregation, ElementSide,
};
use crate::query::collide::contact::{fit_patch, least_spread_axis, mean};
use crate::query::collide::near::near_set;
use crate::query::collide::region::{cut, split_patches, Patch};
use crate::query::collide::{
    CollisionRequest, CollisionResult, ContactRegion, QueryModel, QueryStats,
};
use crate::uncertainty::directional_std_of;
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
/// All the work happens in `b`'s own frame (only `a`'s near points are moved), so
/// moving both clouds by the same rigid motion changes nothing but the world
/// coordinates of the reported points, normals and surfaces.
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
    // Pose of A in B's frame: all the work happens in B's frame.
    let rel = pose_b.inverse() * pose_a;
    // The samples: the points, or the samples of the surface elements.
    let elements = match request.model {
        QueryModel::Points => None,
        QueryModel::Elements => Some((a.elements(), b.elements())),
    };
    let (sa, sb) = match elements {
        None => (a, b),
        Some((ea, eb)) => (ea.samples(), eb.samples()),
    };
    let near = near_set(&rel, sa, sb, request, workspace, &mut stats);
    let core = &near.core;
    stats.near_regions = near.regions.len();

    let mut probabilities_a = vec![0.0; a.len()];
    let mut probabilities_b = vec![0.0; b.len()];
    // What the aggregation reads per sample: p_i, the surface probability q_i,
    // or the pair crossing probability.
    let mut inputs_a = vec![0.0; sa.len()];
    let mut inputs_b = vec![0.0; sb.len()];
    let mut regions = Vec::new();
    let stop_early = request.decide_only
        && matches!(request.aggregation, Aggregation::Max | Aggregation::Surface);
    'regions: for component in near.regions {
        let (pa, ca) = in_frame(&rel, sa, &component.a);
        let (pb, cb) = in_frame(&Pose::identity(), sb, &component.b);
        let local = Patch {
            component: component.component,
            a: (0..component.a.len() as u32).collect(),
            b: (0..component.b.len() as u32).collect(),
        };
        // The direction of least spread of the whole near region, oriented from A
        // to B: the axis along which every patch measures its separation.
        let axis = least_spread_axis(&[&pa[..], &pb[..]].concat(), &(mean(&pb) - mean(&pa)));
        let mut todo = split_patches(local, &pa, &pb, request.region_max_points);
        while let Some(patch) = todo.pop() {
            let na = patch.a.len();
            let pick = |idx: &[u32], p: &[Point3], c: &[Matrix3]| -> (Vec<Point3>, Vec<Matrix3>) {
                idx.iter().map(|&k| (p[k as usize], c[k as usize])).unzip()
            };
            let (mut pts, mut covs) = pick(&patch.a, &pa, &ca);
            let (ptsb, covsb) = pick(&patch.b, &pb, &cb);
            pts.extend(ptsb);
            covs.extend(covsb);
            let ia: Vec<u32> = patch.a.iter().map(|&k| component.a[k as usize]).collect();
            let ib: Vec<u32> = patch.b.iter().map(|&k| component.b[k as usize]).collect();
            // Where no element of either side faces the other within the
            // noise's reach, the surfaces cannot cross (every pair would count
            // 0 in [`element_crossings`]): the patch is pruned like a node
            // pair, without a separating surface, and its points keep
            // `p_i = 0`.
            // A patch where neither side has a surface element (lone points:
            // outliers, sparse corners, single-point clouds) has no surfaces to
            // compare: its points are judged as in the points model (Eq. 3).
            let surfaces = elements
                .filter(|&(ea, eb)| has_surface_element(ea, &ia) || has_surface_element(eb, &ib));
            if let Some((ea, eb)) = surfaces {
                let reach = -normal_quantile(0.5 * request.prune_epsilon);
                if !element_sides_within_reach(ea, &ia, &rel, eb, &ib, reach) {
                    stats.patches_beyond_reach += 1;
                    continue;
                }
            }
            let spacing = patch_median(&ia, sa.spacing(), &ib, sb.spacing());
            let sigma = patch_median(&ia, sa.sigma_max(), &ib, sb.sigma_max());
            let fit = fit_patch(
                &pts,
                &covs,
                na,
                &axis,
                spacing,
                sigma,
                request,
                !request.decide_only,
            )?;
            // A context sample (beyond the noise's reach of the other cloud) that
            // the surface puts on the wrong side shows a surface too rigid for the
            // patch (a wrapped or saddle-shaped contact): cut it and fit the halves.
            let misfit = ia
                .iter()
                .map(|&i| !core.0[i as usize])
                .chain(ib.iter().map(|&i| !core.1[i as usize]))
                .zip(&fit.probabilities)
                .any(|(context, &p)| context && p >= 0.5);
            let big_enough = na >= MIN_CUT_POINTS && pts.len() - na >= MIN_CUT_POINTS;
            if misfit && big_enough {
                if let Some((l, r)) = cut(&patch, &pa, &pb) {
                    stats.misfit_cuts += 1;
                    todo.push(r);
                    todo.push(l);
                    continue;
                }
            }
            let sep = &fit.classification.separator;
            let (own_a, own_b) = (&pts[..na], &pts[na..]);
            let (cov_a, cov_b) = (&covs[..na], &covs[na..]);
            let (qa, qb) = match (surfaces, request.aggregation) {
                (Some((ea, eb)), _) => {
                    let id = Pose::identity();
                    let reach = -normal_quantile(0.5 * request.prune_epsilon);
                    element_crossings(ea, &ia, &rel, eb, &ib, &id, sep, reach)
                }
                (None, Aggregation::Surface) if elements.is_none() => {
                    let either = |q: Vec<Real>, c: Vec<Real>| -> Vec<Real> {
                        q.into_iter().zip(c).map(|(q, c)| q.max(c)).collect()
                    };
                    (
                        either(
                            surface_probabilities(sep, own_a, cov_a, 1.0),
                            crossing_probabilities(own_a, cov_a, own_b, cov_b),
                        ),
                        either(
                            surface_probabilities(sep, own_b, cov_b, -1.0),
                            crossing_probabilities(own_b, cov_b, own_a, cov_a),
                        ),
                    )
                }
                (None, _) => (
                    fit.probabilities[..na].to_vec(),
                    fit.probabilities[na..].to_vec(),
                ),
            };
            for (&i, &q) in ia.iter().zip(&qa) {
                inputs_a[i as usize] = q;
            }
            for (&i, &q) in ib.iter().zip(&qb) {
                inputs_b[i as usize] = q;
            }
            let patch_probability = request.aggregation.aggregate(
                core_values(indexed(&ia, &qa), &core.0)
                    .chain(core_values(indexed(&ib, &qb), &core.1)),
            );
            stats.points_classified += pts.len();
            stats.solver_iterations += u64::from(fit.classification.iterations);
            stats.barrier_fallbacks += usize::from(
                request.classify.solver == SocpSolver::Barrier
                    && fit.classification.solver != SocpSolver::Barrier,
            );
            stats.solver_fallbacks +=
                usize::from(fit.classification.status == SolveStatus::Fallback);
            // The patch's points: the samples themselves, or the points of the
            // elements they stand for; each with its Eq. 3 probability against
            // the patch's surface.
            let (indices_a, indices_b) = match elements {
                None => {
                    if !request.decide_only {
                        for (&i, &p) in ia.iter().zip(&fit.probabilities[..na]) {
                            probabilities_a[i as usize] = p;
                        }
                        for (&i, &p) in ib.iter().zip(&fit.probabilities[na..]) {
                            probabilities_b[i as usize] = p;
                        }
                    }
                    (ia, ib)
                }
                Some((ea, eb)) => {
                    let (ia, ib) = (element_points(ea, &ia), element_points(eb, &ib));
                    if !request.decide_only {
                        point_probabilities(sep, &rel, a, &ia, 1.0, &mut probabilities_a);
                        let id = Pose::identity();
                        point_probabilities(sep, &id, b, &ib, -1.0, &mut probabilities_b);
                    }
                    (ia, ib)
                }
            };
            let mut separator = fit.classification.separator;
            separator.frame = *pose_b;
            regions.push(ContactRegion {
                component: patch.component,
                indices_a,
                indices_b,
                point: pose_b * fit.point,
                normal: pose_b.rotation * fit.normal,
                separation: fit.separation,
                probability: patch_probability,
                surface: separator.surface,
                separator,
                status: fit.classification.status,
                iterations: fit.classification.iterations,
            });
            if stop_early && patch_probability >= request.thresholds.collision {
                break 'regions;
            }
        }
    }
    stats.patches = regions.len();
    let probability = request.aggregation.aggregate(
        core_values(inputs_a.iter().copied().enumerate(), &core.0)
            .chain(core_values(inputs_b.iter().copied().enumerate(), &core.1)),
    );
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

/// The probability, per sample of a patch (`ia` of A's elements `ea`, at `pose_a`
/// in the separator's frame; `ib` of B's), that the fitted surface of the
/// element it stands for crosses the other side's
/// ([`element_crossing_probabilities`]).
#[allow(clippy::too_many_arguments)]
fn element_crossings(
    ea: &SurfaceElements,
    ia: &[u32],
    pose_a: &Pose,
    eb: &SurfaceElements,
    ib: &[u32],
    pose_b: &Pose,
    sep: &Separator,
    reach_sds: Real,
) -> (Vec<Real>, Vec<Real>) {
    let (ua, ub) = (unique_owners(ea, ia), unique_owners(eb, ib));
    let (sa, sb) = (
        element_side(ea, &ua, pose_a, 1.0),
        element_side(eb, &ub, pose_b, -1.0),
    );
    let qa = element_crossing_probabilities(&sa, &sb, sep, reach_sds);
    let qb = element_crossing_probabilities(&sb, &sa, sep, reach_sds);
    let per_sample = |els: &SurfaceElements, idx: &[u32], unique: &[u32], q: &[Real]| {
        let owner = els.sample_owner();
        idx.iter()
            .map(|&s| {
                q[unique
                    .binary_search(&owner[s as usize])
                    .expect("owner listed")]
            })
            .collect::<Vec<Real>>()
    };
    (per_sample(ea, ia, &ua, &qa), per_sample(eb, ib, &ub, &qb))
}

/// Whether some sample of `samples` stands for an element of more than one point.
fn has_surface_element(elements: &SurfaceElements, samples: &[u32]) -> bool {
    let owner = elements.sample_owner();
    samples
        .iter()
        .any(|&s| !elements.elements()[owner[s as usize] as usize].is_point())
}

/// Whether the elements of a patch's samples (`ia` of `ea` at `pose_a` in B's
/// frame, `ib` of `eb`) face each other within `reach_sds` noise standard
/// deviations ([`elements_within_reach`]).
fn element_sides_within_reach(
    ea: &SurfaceElements,
    ia: &[u32],
    pose_a: &Pose,
    eb: &SurfaceElements,
    ib: &[u32],
    reach_sds: Real,
) -> bool {
    let sa = element_side(ea, &unique_owners(ea, ia), pose_a, 1.0);
    let sb = element_side(eb, &unique_owners(eb, ib), &Pose::identity(), -1.0);
    elements_within_reach(&sa, &sb, reach_sds)
}

/// The elements `unique` of `els` as one side of a patch.
fn element_side<'a>(
    els: &'a SurfaceElements,
    unique: &[u32],
    pose: &Pose,
    label: Real,
) -> ElementSide<'a> {
    ElementSide {
        elements: unique
            .iter()
            .map(|&e| &els.elements()[e as usize])
            .collect(),
        pose: *pose,
        label,
    }
}

/// The elements (sorted, each once) that the samples `samples` stand for.
fn unique_owners(elements: &SurfaceElements, samples: &[u32]) -> Vec<u32> {
    let owner = elements.sample_owner();
    let mut unique: Vec<u32> = samples.iter().map(|&s| owner[s as usize]).collect();
    unique.sort_unstable();
    unique.dedup();
    unique
}

/// The point indices of the elements that the samples `samples` stand for, each
/// element once, in the order of first appearance.
fn element_points(elements: &SurfaceElements, samples: &[u32]) -> Vec<u32> {
    unique_owners(elements, samples)
        .iter()
        .flat_map(|&e| elements.element_points(e).iter().copied())
        .collect()
}

/// Eq. 3 of each point `idx` of `cloud` (moved by `pose` into the separator's
/// frame) against `sep`, with label `label`; the larger of it and what `out`
/// already holds (a point can be in several patches).
fn point_probabilities(
    sep: &Separator,
    pose: &Pose,
    cloud: &PointCloud,
    idx: &[u32],
    label: Real,
    out: &mut [Real],
) {
    let r = pose.rotation.to_rotation_matrix();
    let r = r.matrix();
    for &i in idx {
        let i = i as usize;
        let x = pose * cloud.points()[i];
        let cov = r * cloud.covariances()[i] * r.transpose();
        let (f, g) = sep.value_and_gradient_local(&x);
        out[i] = out[i].max(point_probability(f, &g, &cov, label));
    }
}

/// The values of the `(point index, value)` pairs whose point is a core point.
/// Only they count towards `P`: a context point is beyond the noise's reach of
/// the other cloud, so a surface that puts it on the wrong side misfits; that is
/// no evidence of a collision.
fn core_values<'a>(
    points: impl Iterator<Item = (usize, Real)> + 'a,
    core: &'a [bool],
) -> impl Iterator<Item = Real> + 'a {
    points.filter(|&(i, _)| core[i]).map(|(_, v)| v)
}

/// `(point index, value)` pairs of a patch's points `idx` and their `values`.
fn indexed<'a>(idx: &'a [u32], values: &'a [Real]) -> impl Iterator<Item = (usize, Real)> + 'a {
    idx.iter().map(|&i| i as usize).zip(values.iter().copied())
}

/// Neighbours behind a surface probability: the point and its 6 nearest.
const SURFACE_NEIGHBOURS: usize = 7;

/// The surface probability `q_i` ([`surface_probability`]) of each of one side's
/// points of a patch (`pts`, `covs` in the separator's frame, label `label`),
/// from the point and its nearest neighbours among that side's patch points
/// (neighbours beyond the patch belong to surfaces the separator was not
/// fitted to, e.g. the far face of a thin plate).
fn surface_probabilities(
    sep: &Separator,
    pts: &[Point3],
    covs: &[Matrix3],
    label: Real,
) -> Vec<Real> {
    let (margins, stds): (Vec<Real>, Vec<Real>) = pts
        .iter()
        .zip(covs)
        .map(|(x, c)| {
            let (f, g) = sep.value_and_gradient_local(x);
            (label * f, directional_std_of(c, &g))
        })
        .unzip();
    let k = SURFACE_NEIGHBOURS.min(pts.len());
    let mut by_distance: Vec<(Real, usize)> = Vec::with_capacity(pts.len());
    let (mut m, mut s) = (Vec::with_capacity(k), Vec::with_capacity(k));
    pts.iter()
        .map(|x| {
            by_distance.clear();
            by_distance.extend(
                pts.iter()
                    .enumerate()
                    .map(|(j, y)| ((x - y).norm_squared(), j)),
            );
            by_distance.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
            m.clear();
            s.clear();
            for &(_, j) in &by_distance[..k] {
                m.push(margins[j]);
                s.push(stds[j]);
            }
            surface_probability(&m, &s)
        })
        .collect()
}

/// Patches are cut on a misfit only while both halves keep this many points of
/// each cloud.
const MIN_CUT_POINTS: usize = 16;

/// Median over a patch's points (`ia` of A, `ib` of B) of a per-point quantity.
fn patch_median(ia: &[u32], of_a: &[Real], ib: &[u32], of_b: &[Real]) -> Real {
    let mut v: Vec<Real> = ia
        .iter()
        .map(|&i| of_a[i as usize])
        .chain(ib.iter().map(|&i| of_b[i as usize]))
        .collect();
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, Real::total_cmp).1
}

/// Points `idx` of `cloud` and their covariances, moved by `pose`.
fn in_frame(pose: &Pose, cloud: &PointCloud, idx: &[u32]) -> (Vec<Point3>, Vec<Matrix3>) {
    let r = pose.rotation.to_rotation_matrix();
    let r = r.matrix();
    idx.iter()
        .map(|&i| {
            let i = i as usize;
            (
                pose * cloud.points()[i],
                r * cloud.covariances()[i] * r.transpose(),
            )
        })
        .unzip()
}
