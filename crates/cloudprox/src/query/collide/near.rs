//! The near set: which points of the two clouds can touch, grouped into
//! connected near regions.

use std::ops::Range;

use crate::bvh::{kept_without_bound, Bvh, BvhWorkspace, NodeMargins};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::query::collide::region::{
    near_points, near_points_brute_force, near_regions, OwnContext, Patch, SAMPLING_MARGIN,
};
use crate::query::collide::{CollisionRequest, QueryStats};
use crate::Real;

/// The core stage's rule has no context beyond the sampling margin, which the
/// noise part covers for every sample alike.
const NONE: OwnContext<'static> = (None, None);

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
///
/// `links`, given the core samples the near rule found, returns runs of
/// samples known to be near each other by other means (the surface elements'
/// pairs within reach, whose samples may all be far from each other on a
/// metre-wide element): where a run has no core sample, its first becomes
/// one, each run's samples are kept, and the two runs are put in one region.
/// `own_context` marks the samples whose context is measured in their own
/// spacing (see `NearRule`).
pub(crate) fn near_set(
    rel: &Pose,
    a: &PointCloud,
    b: &PointCloud,
    own_context: OwnContext<'_>,
    links: impl FnOnce(&(Vec<bool>, Vec<bool>)) -> Vec<SampleLink>,
    request: &CollisionRequest,
    workspace: &mut BvhWorkspace,
    stats: &mut QueryStats,
) -> NearSet {
    let ctx = request.near_context.max(SAMPLING_MARGIN);
    let eps = request.prune_epsilon;
    if request.use_hierarchy {
        // Margins of so many spacings: each node's largest, scaled.
        let margins = |scale: Real| NodeMargins {
            a: a.node_spacing(),
            b: b.node_spacing(),
            scale,
        };
        // The core's leaf pairs and, where the context reaches farther, what
        // the context's traversal adds to them, finished only if a core point
        // is found: each node pair is descended once.
        let (mut t, wider) = if ctx > SAMPLING_MARGIN {
            let (t, wider) = a.bvh().traverse_pairs_nested(
                b.bvh(),
                rel,
                eps,
                margins(SAMPLING_MARGIN),
                margins(ctx),
                workspace,
            );
            (t, Some(wider))
        } else {
            let t = a.bvh().traverse_pairs_keeping(
                b.bvh(),
                rel,
                eps,
                margins(SAMPLING_MARGIN),
                kept_without_bound(eps),
                workspace,
            );
            (t, None)
        };
        let mut core = near_points(&t.leaf_pairs, rel, a, b, eps, SAMPLING_MARGIN, NONE, None);
        let links = add_links_to_core(&links(&core), &mut core);
        // Only the leaf pairs and the links set core flags: without either,
        // none is set, and a query the bounds decide does not scan its clouds.
        let any_near = (!t.leaf_pairs.is_empty() || !links.is_empty()) && core.0.iter().any(|&k| k);
        let mut keep = core.clone();
        if let Some(wider) = wider.filter(|_| any_near) {
            t = wider.finish(workspace);
            // Where the rule's reach in deviations, `-Phi^-1(epsilon / 2)`, is
            // finite, the context's rule finds every core point the core's
            // rule found (the links' run starts it may not find are kept with
            // their runs below): it need not look for them again. (Where it is
            // infinite, epsilon / 2 rounding to 0, a noise-free pair within
            // half a spacing is core but beyond a single-point element's own
            // context.)
            let found = (0.5 * eps > 0.0).then(|| std::mem::take(&mut keep));
            keep = near_points(&t.leaf_pairs, rel, a, b, eps, ctx, own_context, found);
        }
        stats.counters.node_pairs_visited += t.node_pairs_visited;
        stats.counters.leaf_pairs = t.leaf_pairs.len();
        stats.counters.pruned_bound = t.pruned_bound;
        if !any_near {
            t.leaf_pairs.clear();
        }
        if !links.is_empty() {
            stats.counters.surface_links += links.len();
            keep_links(&links, &mut keep);
            t.leaf_pairs
                .extend(linked_leaf_pairs(&links, a.bvh(), b.bvh()));
        }
        let regions = near_regions(&t.leaf_pairs, a.bvh(), b.bvh(), &keep.0, &keep.1);
        NearSet { regions, core }
    } else {
        let mut core = near_points_brute_force(rel, a, b, eps, SAMPLING_MARGIN, NONE);
        let links = add_links_to_core(&links(&core), &mut core);
        let mut keep = core.clone();
        if keep.0.iter().any(|&k| k) && ctx > SAMPLING_MARGIN {
            keep = near_points_brute_force(rel, a, b, eps, ctx, own_context);
        }
        stats.counters.surface_links += links.len();
        keep_links(&links, &mut keep);
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

/// Two runs of samples, one of each cloud, near each other by their surfaces
/// (see [`near_set`]); the first sample of each run stands for it.
#[derive(Debug, Clone)]
pub(crate) struct SampleLink {
    /// A's samples.
    pub a: Range<u32>,
    /// B's samples.
    pub b: Range<u32>,
}

/// Makes the first sample of each run of `links` a core sample where the run
/// has none, and returns the links that did so: a link whose runs both hold a
/// core sample already is the near rule's own finding.
fn add_links_to_core(links: &[SampleLink], core: &mut (Vec<bool>, Vec<bool>)) -> Vec<SampleLink> {
    let lacks = |k: &[bool], run: &Range<u32>| !run.clone().any(|i| k[i as usize]);
    let needed: Vec<SampleLink> = links
        .iter()
        .filter(|l| lacks(&core.0, &l.a) || lacks(&core.1, &l.b))
        .cloned()
        .collect();
    for l in &needed {
        for (k, run) in [(&mut core.0, &l.a), (&mut core.1, &l.b)] {
            if lacks(k, run) && !run.is_empty() {
                k[run.start as usize] = true;
            }
        }
    }
    needed
}

/// Keeps every sample of every run of `links`.
fn keep_links(links: &[SampleLink], keep: &mut (Vec<bool>, Vec<bool>)) {
    for link in links {
        for (k, run) in [(&mut keep.0, &link.a), (&mut keep.1, &link.b)] {
            for i in run.clone() {
                k[i as usize] = true;
            }
        }
    }
}

/// Leaf pairs that put each link's samples in one region: every leaf holding
/// a sample of one run paired with the leaf of the other run's first sample.
fn linked_leaf_pairs(links: &[SampleLink], bvh_a: &Bvh, bvh_b: &Bvh) -> Vec<(u32, u32)> {
    let (leaf_a, leaf_b) = (leaf_of(bvh_a), leaf_of(bvh_b));
    let mut pairs = Vec::new();
    for l in links {
        if l.a.is_empty() || l.b.is_empty() {
            continue;
        }
        let (first_a, first_b) = (leaf_a[l.a.start as usize], leaf_b[l.b.start as usize]);
        pairs.extend(l.a.clone().map(|i| (leaf_a[i as usize], first_b)));
        pairs.extend(l.b.clone().map(|j| (first_a, leaf_b[j as usize])));
    }
    pairs
}

/// The leaf holding each point of a hierarchy.
fn leaf_of(bvh: &Bvh) -> Vec<u32> {
    let mut leaf = vec![0; bvh.indices().len()];
    for (k, n) in bvh.nodes().iter().enumerate() {
        if n.is_leaf() {
            for &i in bvh.node_points(k as u32) {
                leaf[i as usize] = k as u32;
            }
        }
    }
    leaf
}
