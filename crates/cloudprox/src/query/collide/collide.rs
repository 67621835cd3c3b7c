//! The generic entry of the collision query.

use std::time::Instant;

use crate::bvh::BvhWorkspace;
use crate::classify::{train, Classification, Separator, SocpSolver, SolveStatus};
use crate::cloud::PointCloud;
use crate::error::Result;
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::probability::{
    crossing_probabilities, point_probability, surface_probability, Aggregation,
};
use crate::query::collide::region::{
    cut, near_points, near_points_brute_force, near_regions, split_patches, Patch, SAMPLING_MARGIN,
};
use crate::query::collide::{CollisionRequest, CollisionResult, ContactRegion, QueryStats};
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
    // Pose of A in B's frame.
    let rel = pose_b.inverse() * pose_a;
    // Near points, in two stages. First the noise and the sampling alone: two
    // surfaces sampled at spacing h can meet with no two samples closer than
    // about h/2, so a pair is near when the noise reaches across its distance
    // less half a spacing (the "core" points). If no pair is, the clouds are free
    // and the query ends here. Otherwise again with the context margin, so the
    // classifier sees the surface around the core.
    let ctx = request.near_context.max(SAMPLING_MARGIN);
    let eps = request.prune_epsilon;
    let (components, core): (Vec<Patch>, (Vec<bool>, Vec<bool>)) = if request.use_hierarchy {
        let (ma, mb) = (margins(a, SAMPLING_MARGIN), margins(b, SAMPLING_MARGIN));
        let mut t = a
            .bvh()
            .traverse_pairs(b.bvh(), &rel, eps, &ma, &mb, workspace);
        let core = near_points(&t.leaf_pairs, &rel, a, b, eps, SAMPLING_MARGIN);
        let any_near = core.0.iter().any(|&k| k);
        let mut keep = core.clone();
        if any_near && ctx > SAMPLING_MARGIN {
            let (ma, mb) = (margins(a, ctx), margins(b, ctx));
            t = a
                .bvh()
                .traverse_pairs(b.bvh(), &rel, eps, &ma, &mb, workspace);
            keep = near_points(&t.leaf_pairs, &rel, a, b, eps, ctx);
        }
        stats.node_pairs_visited = t.node_pairs_visited;
        stats.leaf_pairs = t.leaf_pairs.len();
        stats.pruned_bound = t.pruned_bound;
        if !any_near {
            t.leaf_pairs.clear();
        }
        let regions = near_regions(&t.leaf_pairs, a.bvh(), b.bvh(), &keep.0, &keep.1);
        (regions, core)
    } else {
        // The brute-force reference: the same near-point rule on every point pair,
        // all near points in one region.
        let core = near_points_brute_force(&rel, a, b, eps, SAMPLING_MARGIN);
        let mut keep = core.clone();
        if keep.0.iter().any(|&k| k) && ctx > SAMPLING_MARGIN {
            keep = near_points_brute_force(&rel, a, b, eps, ctx);
        }
        let pick =
            |k: &[bool]| -> Vec<u32> { (0..k.len() as u32).filter(|&i| k[i as usize]).collect() };
        let region = Patch {
            component: 0,
            a: pick(&keep.0),
            b: pick(&keep.1),
        };
        let regions = if region.a.is_empty() || region.b.is_empty() {
            Vec::new()
        } else {
            vec![region]
        };
        (regions, core)
    };
    stats.near_regions = components.len();

    let mut probabilities_a = vec![0.0; a.len()];
    let mut probabilities_b = vec![0.0; b.len()];
    // What the aggregation reads per point: p_i, or the surface probability q_i.
    let mut inputs_a = vec![0.0; a.len()];
    let mut inputs_b = vec![0.0; b.len()];
    let mut regions = Vec::new();
    for component in components {
        let (pa, ca) = in_frame(&rel, a, &component.a);
        let (pb, cb) = in_frame(&Pose::identity(), b, &component.b);
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
            let spacing = patch_median(&ia, a.spacing(), &ib, b.spacing());
            let sigma = patch_median(&ia, a.sigma_max(), &ib, b.sigma_max());
            let fit = fit_patch(&pts, &covs, na, &axis, spacing, sigma, request)?;
            // A context point (beyond the noise's reach of the other cloud) that
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
            for (&i, &p) in ia.iter().zip(&fit.probabilities[..na]) {
                probabilities_a[i as usize] = p;
            }
            for (&i, &p) in ib.iter().zip(&fit.probabilities[na..]) {
                probabilities_b[i as usize] = p;
            }
            let sep = &fit.classification.separator;
            let (qa, qb) = if request.aggregation == Aggregation::Surface {
                let (own_a, own_b) = (&pts[..na], &pts[na..]);
                let (cov_a, cov_b) = (&covs[..na], &covs[na..]);
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
            } else {
                (
                    fit.probabilities[..na].to_vec(),
                    fit.probabilities[na..].to_vec(),
                )
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
            let mut separator = fit.classification.separator;
            separator.frame = *pose_b;
            regions.push(ContactRegion {
                component: patch.component,
                indices_a: ia,
                indices_b: ib,
                point: pose_b * fit.point,
                normal: pose_b.rotation * fit.normal,
                separation: fit.separation,
                probability: patch_probability,
                surface: separator.surface,
                separator,
                status: fit.classification.status,
                iterations: fit.classification.iterations,
            });
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

/// Per-node margins of `spacings` sampling spacings.
fn margins(cloud: &PointCloud, spacings: Real) -> Vec<Real> {
    cloud.node_spacing().iter().map(|s| s * spacings).collect()
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

/// A classified patch, in the frame its points were given in.
struct PatchFit {
    classification: Classification,
    /// Per-point probabilities, A's points first.
    probabilities: Vec<Real>,
    point: Point3,
    normal: Vector3,
    separation: Real,
}

/// Trains the surface for `pts` (the first `na` from A) and derives the per-point
/// probabilities (Eq. 3), the contact point, normal and separation estimate.
fn fit_patch(
    pts: &[Point3],
    covs: &[Matrix3],
    na: usize,
    axis: &Vector3,
    spacing: Real,
    sigma: Real,
    request: &CollisionRequest,
) -> Result<PatchFit> {
    let labels: Vec<Real> = (0..pts.len())
        .map(|i| if i < na { 1.0 } else { -1.0 })
        .collect();
    let classification = train(pts, covs, &labels, &request.classify)?;
    let sep = &classification.separator;
    let mut probabilities = Vec::with_capacity(pts.len());
    let mut margins = Vec::with_capacity(pts.len());
    for ((x, cov), &c) in pts.iter().zip(covs).zip(&labels) {
        let (f, g) = sep.value_and_gradient_local(x);
        probabilities.push(point_probability(f, &g, cov, c));
        let gn = g.norm();
        margins.push(if gn > 0.0 { c * f / gn } else { c * f });
    }
    // The contact point: between the point of each side closest to (or deepest
    // across) the surface, projected onto it.
    let deepest = |range: std::ops::Range<usize>| -> Point3 {
        let k = range
            .clone()
            .min_by(|&i, &j| margins[i].total_cmp(&margins[j]))
            .unwrap_or(range.start);
        pts[k]
    };
    let mid = nalgebra::center(&deepest(0..na), &deepest(na..pts.len()));
    let point = sep.project(&mid);
    let (_, g) = sep.value_and_gradient_local(&point);
    let normal = if g.norm() > 0.0 {
        -g.normalize()
    } else {
        (mean(&pts[na..]) - mean(&pts[..na])).normalize()
    };
    // The separation is measured along the near region's axis (unlike the trained
    // surface's normal, it stays meaningful when the clouds interpenetrate and the
    // surface cannot separate them), on lines through up to 64 of the patch's
    // points; the smallest is where the surfaces come closest or cross deepest.
    // Only points within two sampling spacings (the patch's median) of a line
    // count for it, and a line needs 3 of each side.
    let radius = 2.0 * spacing;
    // Along a line, one cloud may show several surfaces (both faces of a thin
    // plate): offsets further apart than this belong to different surfaces.
    let split = (4.0 * sigma).max(0.5 * spacing);
    let stride = pts.len().div_ceil(64).max(1);
    let separation = pts
        .iter()
        .step_by(stride)
        .filter_map(|x| {
            let sb = axial_offset(&pts[na..], x, axis, radius, -1.0, split)?;
            let sa = axial_offset(&pts[..na], x, axis, radius, 1.0, split)?;
            Some(sb - sa)
        })
        .reduce(Real::min)
        .unwrap_or_else(|| {
            let inf = Real::INFINITY;
            axial_offset(&pts[na..], &mid, axis, inf, -1.0, split).unwrap_or(0.0)
                - axial_offset(&pts[..na], &mid, axis, inf, 1.0, split).unwrap_or(0.0)
        });
    Ok(PatchFit {
        classification,
        probabilities,
        point,
        normal,
        separation,
    })
}

/// Unit eigenvector of the smallest eigenvalue of the points' scatter, oriented
/// along `towards`.
fn least_spread_axis(pts: &[Point3], towards: &Vector3) -> Vector3 {
    let c = mean(pts);
    let mut scatter = Matrix3::zeros();
    for p in pts {
        let d = p.coords - c;
        scatter += d * d.transpose();
    }
    let eig = scatter.symmetric_eigen();
    let axis = eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned();
    if axis.dot(towards) < 0.0 {
        -axis
    } else {
        axis
    }
}

fn mean(p: &[Point3]) -> Vector3 {
    p.iter().map(|x| x.coords).sum::<Vector3>() / p.len() as Real
}

/// Where one side's surface crosses the line through `point` along `axis`: among
/// the side's 12 points nearest that line (within `radius` of it), sorted by
/// their offset along `axis` starting from the end that faces the other cloud
/// (`facing = +1`: the largest offsets first), the median of the leading run of
/// offsets less than `split` apart, i.e. of the surface nearest the other cloud;
/// `None` with fewer than 3 points near the line or 2 in that run. Medians keep
/// the estimate unbiased by the noise on a flat contact.
fn axial_offset(
    pts: &[Point3],
    point: &Point3,
    axis: &Vector3,
    radius: Real,
    facing: Real,
    split: Real,
) -> Option<Real> {
    let r2 = radius * radius;
    let mut by_lateral: Vec<(Real, Real)> = pts
        .iter()
        .filter_map(|x| {
            let d = x - point;
            let along = d.dot(axis);
            let lat = (d - axis * along).norm_squared();
            (lat <= r2).then_some((lat, along))
        })
        .collect();
    if by_lateral.len() < 3 {
        return None;
    }
    let k = 12.min(by_lateral.len());
    by_lateral.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
    let mut along: Vec<Real> = by_lateral[..k].iter().map(|x| facing * x.1).collect();
    along.sort_by(|a, b| b.total_cmp(a));
    let run = 1 + along.windows(2).take_while(|w| w[0] - w[1] < split).count();
    if run < 2 {
        return None;
    }
    Some(facing * along[run / 2])
}
