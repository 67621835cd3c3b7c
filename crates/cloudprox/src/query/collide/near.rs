//! The near set: which points of the two clouds can touch, grouped into
//! connected near regions.

use crate::bvh::BvhWorkspace;
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::query::collide::region::{
    near_points, near_points_brute_force, near_regions, Patch, SAMPLING_MARGIN,
};
use crate::query::collide::{CollisionRequest, QueryStats};
use crate::Real;

/// The near regions of a query and which of their points are *core* points.
pub(crate) struct NearSet {
    /// Connected near regions (point indices of each cloud).
    pub regions: Vec<Patch>,
    /// Core points of A and of B: within the noise's reach of the other cloud
    /// (the others in a region are context). Only core points count towards `P`.
    pub core: (Vec<bool>, Vec<bool>),
}

impl NearSet {
    /// No near region: the clouds are free.
    pub(crate) fn empty(na: usize, nb: usize) -> Self {
        Self {
            regions: Vec::new(),
            core: (vec![false; na], vec![false; nb]),
        }
    }
}

/// Finds the near set of `a` (at `rel` in `b`'s frame) and `b`, in two stages.
///
/// First the noise and the sampling alone: two surfaces sampled at spacing `h`
/// can meet with no two samples closer than about `h/2`, so a pair is near when
/// the noise reaches across its distance less half a spacing (the core points).
/// If no pair is, the clouds are free and the set is empty. Otherwise again with
/// the context margin of [`CollisionRequest::near_context`] spacings, so the
/// classifier sees the surface around the core. With `use_hierarchy = false` the
/// same rule runs on every point pair and all near points form one region.
pub(crate) fn near_set(
    rel: &Pose,
    a: &PointCloud,
    b: &PointCloud,
    request: &CollisionRequest,
    workspace: &mut BvhWorkspace,
    stats: &mut QueryStats,
) -> NearSet {
    let ctx = request.near_context.max(SAMPLING_MARGIN);
    let eps = request.prune_epsilon;
    if request.use_hierarchy {
        let (ma, mb) = (margins(a, SAMPLING_MARGIN), margins(b, SAMPLING_MARGIN));
        let mut t = a
            .bvh()
            .traverse_pairs(b.bvh(), rel, eps, &ma, &mb, workspace);
        let core = near_points(&t.leaf_pairs, rel, a, b, eps, SAMPLING_MARGIN);
        let any_near = core.0.iter().any(|&k| k);
        let mut keep = core.clone();
        if any_near && ctx > SAMPLING_MARGIN {
            let (ma, mb) = (margins(a, ctx), margins(b, ctx));
            t = a
                .bvh()
                .traverse_pairs(b.bvh(), rel, eps, &ma, &mb, workspace);
            keep = near_points(&t.leaf_pairs, rel, a, b, eps, ctx);
        }
        stats.counters.node_pairs_visited += t.node_pairs_visited;
        stats.counters.leaf_pairs = t.leaf_pairs.len();
        stats.counters.pruned_bound = t.pruned_bound;
        if !any_near {
            t.leaf_pairs.clear();
        }
        let regions = near_regions(&t.leaf_pairs, a.bvh(), b.bvh(), &keep.0, &keep.1);
        NearSet { regions, core }
    } else {
        let core = near_points_brute_force(rel, a, b, eps, SAMPLING_MARGIN);
        let mut keep = core.clone();
        if keep.0.iter().any(|&k| k) && ctx > SAMPLING_MARGIN {
            keep = near_points_brute_force(rel, a, b, eps, ctx);
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
        NearSet { regions, core }
    }
}

/// Per-node margins of `spacings` sampling spacings.
fn margins(cloud: &PointCloud, spacings: Real) -> Vec<Real> {
    cloud.node_spacing().iter().map(|s| s * spacings).collect()
}
