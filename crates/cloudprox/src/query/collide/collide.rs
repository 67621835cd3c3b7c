//! The generic entry of the collision query.

use std::time::Instant;

use rayon::prelude::*;

use crate::bvh::{BvhWorkspace, PointSearch};
use crate::classify::{SocpSolver, SolveStatus};
use crate::cloud::{validate_pose, PointCloud};
use crate::error::Result;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::{
    contact_probability, normal_cdf, normal_quantile, Aggregation, ElementReading,
};
use crate::query::collide::collide_many::prepare;
use crate::query::collide::contact::{fit_patch, least_spread_axis, mean};
use crate::query::collide::elements::{
    element_crossings, element_pairs_within_reach, element_points, element_sides_within_reach,
    element_surfaces_cross, has_surface_element, unique_owners,
};
use crate::query::collide::near::{near_set, NearSet};
use crate::query::collide::probabilities::{
    core_values, indexed, point_probabilities, surface_side,
};
use crate::query::collide::region::{cut, split_patches, Patch};
use crate::query::collide::warm_start::WarmStart;
use crate::query::collide::{
    CollisionRequest, CollisionResult, ContactPatch, PointAggregates, PointProbabilities,
    QueryCounters, QueryModel, QueryStats,
};
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
/// [`crate::query::collide_many`] for many poses of one cloud in parallel;
/// [`crate::query::collide_along`] for the poses of a motion.
pub fn collide(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<CollisionResult> {
    let mut workspace = BvhWorkspace::default();
    collide_with_workspace(pose_a, a, pose_b, b, request, &mut workspace, None)
}

pub(crate) fn collide_with_workspace(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
    workspace: &mut BvhWorkspace,
    warm: Option<&mut WarmStart>,
) -> Result<CollisionResult> {
    request.validate()?;
    let k = request.segmentations;
    let per_point = !request.decide_only;
    if request.model != QueryModel::Elements || k <= 1 {
        return collide_segmentation(
            pose_a, a, pose_b, b, request, workspace, warm, 0, per_point, None,
        );
    }
    // The mean over segmentations (see `CollisionRequest::segmentations`):
    // each run's whole `P`, so deciding only, no early stop (and no per-point
    // work, which only the full query reports). Called from outside rayon's
    // pool (a query on its own), the runs after the first go to the pool,
    // each with its own workspace, while the first, which a motion's warm
    // start follows, runs here; every set a run reads is built first (built
    // inside the pool, a thread waiting for its `OnceLock`'s helpers could
    // take up another run that needs the same set). Inside the pool (one of
    // `collide_many`'s queries) the runs go one after another: the pool's
    // threads are busy with the other queries, and a thread waiting for its
    // helpers could take up another query, whose work the time of this one
    // would then count.
    validate_pose(pose_a, "pose_a")?;
    validate_pose(pose_b, "pose_b")?;
    let start = Instant::now();
    let each = CollisionRequest {
        decide_only: false,
        ..*request
    };
    let mut runs = Vec::with_capacity(k as usize);
    if rayon::current_thread_index().is_some() {
        let mut warm = warm;
        for s in 0..k {
            let w = if s == 0 { warm.as_deref_mut() } else { None };
            runs.push(collide_segmentation(
                pose_a, a, pose_b, b, &each, workspace, w, s, per_point, None,
            )?);
        }
    } else {
        prepare(a, request);
        prepare(b, request);
        let (first, rest) = rayon::join(
            || {
                collide_segmentation(
                    pose_a, a, pose_b, b, &each, workspace, warm, 0, per_point, None,
                )
            },
            || {
                (1..k)
                    .into_par_iter()
                    .map(|s| {
                        let mut own = BvhWorkspace::default();
                        collide_segmentation(
                            pose_a, a, pose_b, b, &each, &mut own, None, s, per_point, None,
                        )
                    })
                    .collect::<Result<Vec<_>>>()
            },
        );
        runs.push(first?);
        runs.extend(rest?);
    }
    let probability = runs.iter().map(|r| r.probability).sum::<Real>() / Real::from(k);
    let (probabilities_a, probabilities_b) = if request.decide_only {
        (
            PointProbabilities::zeros(a.len()),
            PointProbabilities::zeros(b.len()),
        )
    } else {
        (
            PointProbabilities::mean(&runs.iter().map(|r| &r.probabilities_a).collect::<Vec<_>>()),
            PointProbabilities::mean(&runs.iter().map(|r| &r.probabilities_b).collect::<Vec<_>>()),
        )
    };
    let counters =
        QueryCounters::combined(&runs.iter().map(|r| &r.stats.counters).collect::<Vec<_>>());
    Ok(CollisionResult {
        probability,
        state: request.thresholds.state(probability),
        probabilities_a,
        probabilities_b,
        patches: runs.into_iter().flat_map(|r| r.patches).collect(),
        point_aggregates: None,
        stats: QueryStats {
            counters,
            time_seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// The full query of one segmentation (the clouds' own, `request`'s
/// `segmentations` and `decide_only` not read) and every facing pair's
/// reading within reach that its `P` read, in `b`'s frame, with A's
/// elements as `own` ([`mod@crate::query::distance`]).
pub(crate) fn collide_readings(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
) -> Result<(CollisionResult, Vec<ElementReading>)> {
    request.validate()?;
    let request = CollisionRequest {
        decide_only: false,
        segmentations: 1,
        ..*request
    };
    let mut workspace = BvhWorkspace::default();
    let mut readings = Vec::new();
    let result = collide_segmentation(
        pose_a,
        a,
        pose_b,
        b,
        &request,
        &mut workspace,
        None,
        0,
        false,
        Some(&mut readings),
    )?;
    Ok((result, readings))
}

/// One run of the query: with the elements model, on the clouds' element
/// sets of segmentation `offset` past each cloud's own
/// ([`ElementSettings::segmentation`](crate::element::ElementSettings::segmentation)).
/// `per_point` false leaves out what only the full query reports (per-point
/// probabilities and separation estimates): `!decide_only` for a query on
/// its own; false for a run of a mean over segmentations deciding only,
/// which needs its whole `P` (`request.decide_only` false) and nothing else.
#[allow(clippy::too_many_arguments)]
fn collide_segmentation(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &CollisionRequest,
    workspace: &mut BvhWorkspace,
    mut warm: Option<&mut WarmStart>,
    offset: u32,
    per_point: bool,
    sink: Option<&mut Vec<ElementReading>>,
) -> Result<CollisionResult> {
    validate_pose(pose_a, "pose_a")?;
    validate_pose(pose_b, "pose_b")?;
    let start = Instant::now();
    let mut stats = QueryStats::default();
    // Pose of A in B's frame: all the work happens in B's frame.
    let rel = pose_b.inverse() * pose_a;
    // The samples: the points, or the samples of the surface elements.
    let elements = match request.model {
        QueryModel::Points => None,
        QueryModel::Elements => Some((a.segmentation_after(offset), b.segmentation_after(offset))),
    };
    let (sa, sb) = match elements {
        None => (a, b),
        Some((ea, eb)) => (ea.samples(), eb.samples()),
    };
    // The noise's reach in standard deviations: beyond it no surface crosses.
    let reach = -normal_quantile(0.5 * request.prune_epsilon);
    // The elements model first reads the element surfaces themselves: when no
    // two can reach each other, the clouds are free; the pairs that can are
    // linked in the near set, whether or not their samples are near.
    // Deciding only, the descent also looks for crossing surfaces (below) and
    // stops at the first.
    let z = crossing_sds(reach, request.thresholds.collision);
    let stop_at_crossing = request.decide_only.then_some(z);
    let within_reach = elements.map(|(ea, eb)| {
        let pairs = element_pairs_within_reach(
            ea,
            &rel,
            eb,
            reach,
            request.use_hierarchy,
            stop_at_crossing,
            workspace,
        );
        stats.counters.node_pairs_visited += pairs.visited;
        pairs
    });
    let beyond_reach = request.use_hierarchy && within_reach.as_ref().is_some_and(|p| !p.any);
    // Two element surfaces that cross (probes of one on both sides of the
    // other, each beyond the noise) are a collision, whichever side of either
    // is inside: no near set or classifier is needed to say so. Its
    // probability, when they cross (the bound's confidence, at least the
    // collision threshold).
    let crossing = |stats: &mut QueryStats, workspace: &mut BvhWorkspace| -> Option<Real> {
        // Surfaces that cross are within reach of each other: none crosses
        // where no pair is within reach (with or without the hierarchy).
        let (ea, eb) = elements.filter(|_| within_reach.as_ref().is_some_and(|p| p.any))?;
        // The pairs within reach found above hold every pair that can cross
        // when `z` is the reach (the usual case), and without the hierarchy
        // every pair at any `z`: no second descent (and deciding only, the
        // descent has tested them already).
        let known = within_reach.as_ref().and_then(|p| p.cross(z));
        let crossed = known.unwrap_or_else(|| {
            let (crossed, visited) = element_surfaces_cross(ea, &rel, eb, z, workspace);
            stats.counters.node_pairs_visited += visited;
            crossed
        });
        crossed.then(|| {
            stats.counters.surface_crossings += 1;
            (1.0 - 2.0 * normal_cdf(-z)).max(request.thresholds.collision)
        })
    };
    // Deciding only, a crossing decides before anything else.
    if request.decide_only {
        if let Some(probability) = crossing(&mut stats, workspace) {
            stats.time_seconds = start.elapsed().as_secs_f64();
            return Ok(CollisionResult {
                probability,
                state: request.thresholds.state(probability),
                probabilities_a: PointProbabilities::zeros(a.len()),
                probabilities_b: PointProbabilities::zeros(b.len()),
                patches: Vec::new(),
                point_aggregates: None,
                stats,
            });
        }
    }
    let near = if beyond_reach {
        NearSet::empty(sa.len(), sb.len())
    } else {
        let links = |core: &(Vec<bool>, Vec<bool>)| {
            within_reach
                .as_ref()
                .map_or_else(Vec::new, |pairs| pairs.links(core))
        };
        let own = elements.map_or((None, None), |(ea, eb)| {
            (Some(ea.sample_is_point()), Some(eb.sample_is_point()))
        });
        near_set(&rel, sa, sb, own, links, request, workspace, &mut stats)
    };
    let core = &near.core;
    stats.counters.near_regions = near.regions.len();

    // Every point's probability while the patches are read; the result keeps
    // the patches' points.
    let mut probabilities_a: Vec<Real> = Vec::new();
    let mut probabilities_b: Vec<Real> = Vec::new();
    // What the aggregation reads per sample: p_i, the surface probability q_i,
    // or the pair crossing probability.
    let mut inputs_a: Vec<Real> = Vec::new();
    let mut inputs_b: Vec<Real> = Vec::new();
    let mut patches = Vec::new();
    // With elements: every facing pair's reading within reach, over all
    // patches, and the largest value of a patch without surface elements.
    let mut readings: Vec<ElementReading> = Vec::new();
    let mut lone: Real = 0.0;
    // The samples given an input: every other input is 0, which changes no
    // aggregate, so `P` reads these alone (a query against a cloud of 10^7
    // points then does not pass over all of them).
    let mut touched: (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    // (With elements the pair's `P` combines the readings of every patch
    // (`contact_probability`): a patch alone does not decide it.)
    let stop_early = request.decide_only
        && elements.is_none()
        && matches!(request.aggregation, Aggregation::Max | Aggregation::Surface);
    if let Some(w) = warm.as_deref_mut() {
        w.begin(sa.len(), sb.len());
    }
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
                if !element_sides_within_reach(ea, &ia, &rel, eb, &ib, reach) {
                    stats.counters.patches_beyond_reach += 1;
                    continue;
                }
            }
            let spacing = patch_median(&ia, sa.spacing(), &ib, sb.spacing());
            let sigma = patch_median(&ia, sa.sigma_max(), &ib, sb.sigma_max());
            let hint = warm.as_deref().map(|w| w.hint(&ia, &ib));
            let fit = fit_patch(
                &pts,
                &covs,
                na,
                &axis,
                spacing,
                sigma,
                request,
                per_point,
                hint.as_deref(),
            )?;
            // A context sample (beyond the noise's reach of the other cloud) that
            // the surface puts on the wrong side shows a surface too rigid for the
            // patch (a wrapped or saddle-shaped contact): cut it and fit the
            // halves. So does a crossing element pair the surface does not
            // describe (known once the crossings are computed, which a patch cut
            // for its context does not need).
            let big_enough = na >= MIN_CUT_POINTS && pts.len() - na >= MIN_CUT_POINTS;
            let mut cut_misfit = |misfit: bool, stats: &mut QueryStats| {
                let halves = (misfit && big_enough)
                    .then(|| cut(&patch, &pa, &pb))
                    .flatten();
                if let Some((l, r)) = halves {
                    stats.counters.misfit_cuts += 1;
                    todo.push(r);
                    todo.push(l);
                    return true;
                }
                false
            };
            let context_misfit = ia
                .iter()
                .map(|&i| !core.0[i as usize])
                .chain(ib.iter().map(|&i| !core.1[i as usize]))
                .zip(&fit.probabilities)
                .any(|(context, &p)| context && p >= 0.5);
            if cut_misfit(context_misfit, &mut stats) {
                continue;
            }
            // The element surfaces' crossings, and whether some crossing pair
            // lies where the separating surface does not describe it.
            let crossings = surfaces.map(|(ea, eb)| {
                let id = Pose::identity();
                let sep = &fit.classification.separator;
                element_crossings(ea, &ia, &rel, eb, &ib, &id, sep, reach)
            });
            if cut_misfit(crossings.as_ref().is_some_and(|c| c.2), &mut stats) {
                continue;
            }
            // The surface is kept (a cut one's halves record their own).
            if let Some(w) = warm.as_deref_mut() {
                w.record(&ia, &ib, &fit.support);
            }
            let sep = &fit.classification.separator;
            let (own_a, own_b) = (&pts[..na], &pts[na..]);
            let (cov_a, cov_b) = (&covs[..na], &covs[na..]);
            let contact = crossings.as_ref().map(|c| {
                let of_region = |r: &ElementReading| ElementReading {
                    contact: component.component,
                    ..*r
                };
                readings.extend(c.3.iter().map(of_region));
                contact_probability(&c.3)
            });
            let (qa, qb) = match (crossings, request.aggregation) {
                (Some((qa, qb, _, _)), _) => (qa, qb),
                (None, Aggregation::Surface) if elements.is_none() => {
                    let (search_a, search_b) = (PointSearch::new(own_a), PointSearch::new(own_b));
                    // Each point's largest deviation, kept by its cloud (a
                    // rotation does not change it).
                    let std = |idx: &[u32], cloud: &PointCloud| -> Vec<Real> {
                        idx.iter().map(|&i| cloud.sigma_max()[i as usize]).collect()
                    };
                    let (std_a, std_b) = (std(&ia, sa), std(&ib, sb));
                    let side_a = (&search_a, cov_a, &std_a[..]);
                    let side_b = (&search_b, cov_b, &std_b[..]);
                    (
                        surface_side(sep, side_a, side_b, 1.0),
                        surface_side(sep, side_b, side_a, -1.0),
                    )
                }
                (None, _) => (
                    fit.probabilities[..na].to_vec(),
                    fit.probabilities[na..].to_vec(),
                ),
            };
            // The arrays are made for the first patch read: a query that reads
            // none (decided by its bounds) allocates none, and one without
            // per-point work no per-point array.
            if inputs_a.is_empty() {
                inputs_a = vec![0.0; sa.len()];
                inputs_b = vec![0.0; sb.len()];
                if per_point {
                    probabilities_a = vec![0.0; a.len()];
                    probabilities_b = vec![0.0; b.len()];
                }
            }
            // A sample of a sparse cloud can be in several patches
            // ([`split_patches`]): it keeps its largest value.
            for (&i, &q) in ia.iter().zip(&qa) {
                inputs_a[i as usize] = inputs_a[i as usize].max(q);
            }
            for (&i, &q) in ib.iter().zip(&qb) {
                inputs_b[i as usize] = inputs_b[i as usize].max(q);
            }
            touched.0.extend_from_slice(&ia);
            touched.1.extend_from_slice(&ib);
            let patch_probability = contact.unwrap_or_else(|| {
                let p = request.aggregation.aggregate(
                    core_values(indexed(&ia, &qa), &core.0)
                        .chain(core_values(indexed(&ib, &qb), &core.1)),
                );
                lone = lone.max(p);
                p
            });
            stats.counters.points_classified += pts.len();
            stats.counters.solver_iterations += u64::from(fit.classification.iterations);
            stats.counters.clarabel_fallbacks += usize::from(
                request.classify.solver == SocpSolver::PrimalDual
                    && fit.classification.solver != SocpSolver::PrimalDual,
            );
            stats.counters.solver_fallbacks +=
                usize::from(fit.classification.status == SolveStatus::Fallback);
            // The patch's points: the samples themselves, or the points of the
            // elements they stand for; each with its Eq. 3 probability against
            // the patch's surface.
            let (indices_a, indices_b) = match elements {
                None => {
                    if per_point {
                        for (&i, &p) in ia.iter().zip(&fit.probabilities[..na]) {
                            probabilities_a[i as usize] = probabilities_a[i as usize].max(p);
                        }
                        for (&i, &p) in ib.iter().zip(&fit.probabilities[na..]) {
                            probabilities_b[i as usize] = probabilities_b[i as usize].max(p);
                        }
                    }
                    (ia, ib)
                }
                Some((ea, eb)) => {
                    let (oa, ob) = (unique_owners(ea, &ia), unique_owners(eb, &ib));
                    if per_point {
                        let id = Pose::identity();
                        let (side_a, side_b) = ((ea, &oa[..], &rel), (eb, &ob[..], &id));
                        let (pa, pb) = (&mut probabilities_a, &mut probabilities_b);
                        point_probabilities(sep, side_a, side_b, (1.0, reach), pa);
                        point_probabilities(sep, side_b, side_a, (-1.0, reach), pb);
                    }
                    (element_points(ea, &oa), element_points(eb, &ob))
                }
            };
            let mut separator = fit.classification.separator;
            separator.frame = *pose_b;
            patches.push(ContactPatch {
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
    if let Some(w) = warm {
        w.finish();
    }
    stats.counters.patches = patches.len();
    // In index order, as over every sample: a sum's order is kept, and the
    // zeros left out add exactly nothing.
    for t in [&mut touched.0, &mut touched.1] {
        t.sort_unstable();
        t.dedup();
    }
    // The points model's samples are its points: the same points, read for
    // their Eq. 3 probabilities (the inputs themselves unless `surface`).
    let point_aggregates = (elements.is_none() && per_point).then(|| {
        let values: Vec<Real> = core_values(indexed_inputs(&touched.0, &probabilities_a), &core.0)
            .chain(core_values(
                indexed_inputs(&touched.1, &probabilities_b),
                &core.1,
            ))
            .collect();
        PointAggregates::of(&values)
    });
    // A paper aggregation of the points model is one of those (the same
    // values in the same order); otherwise the inputs are aggregated.
    // With elements, each patch is one contact and its probability the
    // contact's (`contact_probability`): `P` is the most probable contact's.
    // The readings of all patches together: a contact cut into several
    // patches is still one contact (the largest of the patches' values
    // would read the minimum of their noisy estimates again). Patches of lone
    // points (no element readings) keep their own values.
    let by_patch = elements
        .is_some()
        .then(|| contact_probability(&readings).max(lone));
    if let Some(sink) = sink {
        *sink = std::mem::take(&mut readings);
    }
    let probability = by_patch
        .or_else(|| point_aggregates.and_then(|g| g.get(request.aggregation)))
        .unwrap_or_else(|| {
            request.aggregation.aggregate(
                core_values(indexed_inputs(&touched.0, &inputs_a), &core.0)
                    .chain(core_values(indexed_inputs(&touched.1, &inputs_b), &core.1)),
            )
        });
    // The full query reads the crossings too where its patches did not find a
    // collision: a thin part passing through a thin solid (a leg through a
    // floor) gives the patch's separating surface no side to put it on, and
    // the crossing is what says the surfaces meet. Deciding only, the
    // crossings were read first.
    let probability = if request.decide_only || probability >= request.thresholds.collision {
        probability
    } else {
        crossing(&mut stats, workspace).map_or(probability, |c| c.max(probability))
    };
    // The points given a probability are the patches' points (none without
    // per-point work).
    let gathered = |len: usize, dense: &[Real], side: fn(&ContactPatch) -> &[u32]| {
        if !per_point {
            return PointProbabilities::zeros(len);
        }
        PointProbabilities::gather(len, dense, patches.iter().flat_map(side).copied().collect())
    };
    let probabilities_a = gathered(a.len(), &probabilities_a, |p| &p.indices_a);
    let probabilities_b = gathered(b.len(), &probabilities_b, |p| &p.indices_b);
    stats.time_seconds = start.elapsed().as_secs_f64();
    Ok(CollisionResult {
        probability,
        state: request.thresholds.state(probability),
        probabilities_a,
        probabilities_b,
        patches,
        point_aggregates,
        stats,
    })
}

/// The standard deviations beyond which both probes of a crossing must read
/// ([`element_surfaces_cross`]): the noise's reach (`reach`), or more when the
/// collision threshold asks for more confidence than the reach gives (the
/// crossing's probability is at least `1 - 2 Phi(-z)`).
fn crossing_sds(reach: Real, collision: Real) -> Real {
    reach.max(-normal_quantile(0.5 * (1.0 - collision)))
}

/// Patches are cut on a misfit only while both halves keep this many points of
/// each cloud.
const MIN_CUT_POINTS: usize = 16;

/// `(sample index, input)` of the samples `idx`.
fn indexed_inputs<'a>(
    idx: &'a [u32],
    inputs: &'a [Real],
) -> impl Iterator<Item = (usize, Real)> + 'a {
    idx.iter().map(|&i| (i as usize, inputs[i as usize]))
}

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
