//! The surface-element stage of a query: which elements a patch's samples
//! stand for, whether their fitted surfaces can reach each other at all, and
//! the probability that they cross ([`crate::probability::element`]).

use std::cell::Cell;

use crate::bvh::BvhWorkspace;
use crate::classify::Separator;
use crate::element::{surfaces_may_reach, Hull, SurfaceElement, SurfaceElements};
use crate::math::Pose;
use crate::probability::{
    element_crossing_probabilities, element_pair_crosses, element_pair_within_reach,
    elements_within_reach, ElementReading, ElementSide,
};
use crate::query::collide::near::SampleLink;
use crate::Real;

/// The probability, per sample of a patch (`ia` of A's elements `ea`, at `pose_a`
/// in the separator's frame; `ib` of B's), that the fitted surface of the
/// element it stands for crosses the other side's
/// ([`element_crossing_probabilities`]), whether some pair that the
/// separating surface does not describe would raise the patch's value above
/// what the described pairs give (the patch is then cut like a misfit; see
/// [`crate::probability::element::ElementCrossings`]), and every facing
/// pair's reading within reach (with A's elements as `own`, B's as `other`),
/// for [`crate::probability::contact_probability`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn element_crossings(
    ea: &SurfaceElements,
    ia: &[u32],
    pose_a: &Pose,
    eb: &SurfaceElements,
    ib: &[u32],
    pose_b: &Pose,
    sep: &Separator,
    reach_sds: Real,
) -> (Vec<Real>, Vec<Real>, bool, Vec<ElementReading>) {
    let (ua, ub) = (unique_owners(ea, ia), unique_owners(eb, ib));
    let (sa, sb) = (
        element_side(ea, &ua, pose_a, 1.0),
        element_side(eb, &ub, pose_b, -1.0),
    );
    let ca = element_crossing_probabilities(&sa, &sb, sep, reach_sds);
    let cb = element_crossing_probabilities(&sb, &sa, sep, reach_sds);
    let undescribed =
        ca.undescribed_max.max(cb.undescribed_max) > ca.described_max.max(cb.described_max);
    let per_sample = |els: &SurfaceElements, idx: &[u32], unique: &[u32], q: &[Real]| {
        let owner = els.sample_owner();
        idx.iter()
            // `unique` lists every owner of `idx` (it was made from them).
            .map(|&s| {
                unique
                    .binary_search(&owner[s as usize])
                    .map_or(0.0, |k| q[k])
            })
            .collect::<Vec<Real>>()
    };
    // Both sides' readings as pairs of (A's element, B's element), by their
    // indices in the clouds' elements.
    let readings: Vec<ElementReading> = ca
        .readings
        .iter()
        .map(|r| ElementReading {
            own: ua[r.own as usize],
            other: ub[r.other as usize],
            ..*r
        })
        .chain(cb.readings.iter().map(|r| ElementReading {
            own: ua[r.other as usize],
            other: ub[r.own as usize],
            ..*r
        }))
        .collect();
    (
        per_sample(ea, ia, &ua, &ca.values),
        per_sample(eb, ib, &ub, &cb.values),
        undescribed,
        readings,
    )
}

/// Whether some element surface (or single point) of `ea`, at `rel` in `eb`'s
/// frame, may come within `reach_sds` noise standard deviations, beyond half a
/// sampling spacing, of one of `eb` (the hierarchies over both clouds'
/// element hulls, see [`crate::element`]). When none may, every patch the
/// query would build is pruned: the clouds are free, and neither the near set
/// nor a classifier is needed to say so. Returns the answer and the number of
/// node pairs tested.
pub(crate) fn element_surfaces_may_reach(
    ea: &SurfaceElements,
    rel: &Pose,
    eb: &SurfaceElements,
    reach_sds: Real,
    workspace: &mut BvhWorkspace,
) -> (bool, usize) {
    if !reach_sds.is_finite() {
        return (true, 0);
    }
    // Two single points whose hulls pass the hull test (a superset of the
    // near rule) may reach each other; a pair with a surface must face.
    let faces = |a: ElementRef<'_>, b: ElementRef<'_>| {
        (a.1.point && b.1.point) || element_pair_within_reach(a, rel, b, reach_sds)
    };
    first_hull_pair(ea, rel, eb, reach_sds, workspace, false, faces)
}

/// The element pairs of `ea` (at `rel` in `eb`'s frame) and `eb` whose hulls
/// may come within the noise's reach of each other: read on the elements'
/// surfaces over their extent, not on their samples.
pub(crate) struct PairsWithinReach<'a> {
    ea: &'a SurfaceElements,
    rel: Pose,
    eb: &'a SurfaceElements,
    reach_sds: Real,
    /// Whether any pair (of surfaces or single points) may reach: when none
    /// may, the clouds are free.
    pub any: bool,
    /// The pairs of two surface elements whose hulls pass the hull test;
    /// whether they face within reach is asked only of those the near rule
    /// missed ([`PairsWithinReach::links`]). A pair with a single point is
    /// left to the near rule: the point is its own sample, and its hull's
    /// reach is a bound, widest for a scan's stray points (centimetres of
    /// noise from their sparse sampling), which as links made regions of
    /// points 8 sigma from the other cloud (a Kinect frame).
    candidates: Vec<(u32, u32)>,
    /// Whether the candidates are every pair of surface elements (found
    /// without the hierarchy, so not limited to the reach).
    all_pairs: bool,
    /// The `z` at which every candidate met so far was tested for a crossing
    /// during the descent (deciding only), and whether one crossed (the
    /// descent then stopped there).
    crossing: Option<(Real, bool)>,
    /// Node pairs tested.
    pub visited: usize,
}

impl PairsWithinReach<'_> {
    /// The pairs whose surfaces face within reach
    /// ([`element_pair_within_reach`]) although one of the two elements has
    /// no sample in `core` (the near rule's core samples of A and of B), as
    /// runs of samples for the near set.
    pub(crate) fn links(&self, core: &(Vec<bool>, Vec<bool>)) -> Vec<SampleLink> {
        let (ea, eb) = (self.ea, self.eb);
        let (ha, hb) = (ea.hulls(), eb.hulls());
        // Which elements have a core sample.
        let found = |els: &SurfaceElements, core: &[bool]| {
            let mut found = vec![false; els.elements().len()];
            for (&o, _) in els.sample_owner().iter().zip(core).filter(|(_, &c)| c) {
                found[o as usize] = true;
            }
            found
        };
        let (found_a, found_b) = (found(ea, &core.0), found(eb, &core.1));
        self.candidates
            .iter()
            .filter(|&&(e, f)| !found_a[e as usize] || !found_b[f as usize])
            .filter(|&&(e, f)| {
                let (a, b) = (&ea.elements()[e as usize], &eb.elements()[f as usize]);
                element_pair_within_reach(
                    (a, ha.hull(e)),
                    &self.rel,
                    (b, hb.hull(f)),
                    self.reach_sds,
                )
            })
            .map(|&(e, f)| SampleLink {
                a: element_sample_range(ea, e),
                b: element_sample_range(eb, f),
            })
            .collect()
    }

    /// Whether the surfaces of some candidate pair cross, each beyond `z_sds`
    /// standard deviations on both sides of the other
    /// ([`element_pair_crosses`]), as [`element_surfaces_cross`] finds it;
    /// `None` when `z_sds` is beyond the reach the candidates were found at
    /// (the hull test passes more pairs at more standard deviations, so the
    /// candidates hold every pair that can cross only up to their own),
    /// unless they are every pair.
    pub(crate) fn cross(&self, z_sds: Real) -> Option<bool> {
        if !z_sds.is_finite() {
            return Some(false);
        }
        if let Some((z, crossed)) = self.crossing {
            if z == z_sds {
                return Some(crossed);
            }
        }
        if z_sds > self.reach_sds && !self.all_pairs {
            return None;
        }
        let (ea, eb) = (self.ea, self.eb);
        let (ha, hb) = (ea.hulls(), eb.hulls());
        Some(self.candidates.iter().any(|&(e, f)| {
            let (a, b) = (&ea.elements()[e as usize], &eb.elements()[f as usize]);
            element_pair_crosses((a, ha.hull(e)), &self.rel, (b, hb.hull(f)), z_sds)
        }))
    }
}

/// Whether any element pair of `ea` (at `rel` in `eb`'s frame) and `eb` may
/// come within `reach_sds` noise standard deviations, beyond half a sampling
/// spacing, of each other, and every such pair of two surface elements (the
/// candidates): by the hierarchies over both clouds' element hulls, or
/// (`use_hierarchy = false`) over every pair. A wide element stands in the
/// near set for its samples, which a thin part passing between them may be
/// far from: these pairs are what bring such an element into the near set
/// ([`crate::query::collide::near`]).
///
/// With `stop_at_crossing = Some(z)` (deciding only, `z` at most the reach)
/// each candidate is also tested for a crossing at `z` as it is met, and the
/// descent stops at the first one: the query is then decided, and needs
/// neither the other candidates nor the links.
pub(crate) fn element_pairs_within_reach<'a>(
    ea: &'a SurfaceElements,
    rel: &Pose,
    eb: &'a SurfaceElements,
    reach_sds: Real,
    use_hierarchy: bool,
    stop_at_crossing: Option<Real>,
    workspace: &mut BvhWorkspace,
) -> PairsWithinReach<'a> {
    let mut out = PairsWithinReach {
        ea,
        rel: *rel,
        eb,
        reach_sds,
        any: !reach_sds.is_finite(),
        candidates: Vec::new(),
        all_pairs: !use_hierarchy,
        crossing: None,
        visited: 0,
    };
    if !reach_sds.is_finite() {
        return out;
    }
    // A crossing test at more standard deviations than the reach needs pairs
    // the hull test at the reach may not pass: not here.
    let stop_at = stop_at_crossing.filter(|&z| z.is_finite() && z <= reach_sds);
    let (ha, hb) = (ea.hulls(), eb.hulls());
    let any = Cell::new(false);
    let (mut candidates, mut crossed) = (Vec::new(), false);
    let mut test = |i: u32, j: u32| {
        let (a, b) = (&ea.elements()[i as usize], &eb.elements()[j as usize]);
        // The exact test until one pair passes: enough to say the clouds are
        // not beyond reach. Two single points are left to the near rule.
        let within = || {
            (a.is_point() && b.is_point())
                || element_pair_within_reach((a, ha.hull(i)), rel, (b, hb.hull(j)), reach_sds)
        };
        if !any.get() && within() {
            any.set(true);
        }
        if a.is_point() || b.is_point() {
            return false;
        }
        candidates.push((i, j));
        if let Some(z) = stop_at {
            if element_pair_crosses((a, ha.hull(i)), rel, (b, hb.hull(j)), z) {
                // Crossing surfaces are within reach of each other.
                any.set(true);
                crossed = true;
                return true;
            }
        }
        false
    };
    if use_hierarchy {
        // Once some pair is within reach, single points matter no more (see
        // [`PairsWithinReach::candidates`]): the descent then bounds its
        // nodes by their surface elements alone.
        let found = || any.get();
        out.visited = surfaces_may_reach(ha, rel, hb, reach_sds, workspace, found, &mut test).1;
    } else {
        'all: for i in 0..ea.elements().len() as u32 {
            for j in 0..eb.elements().len() as u32 {
                if test(i, j) {
                    break 'all;
                }
            }
        }
    }
    out.any = any.get();
    out.candidates = candidates;
    out.crossing = stop_at.map(|z| (z, crossed));
    out
}

/// The samples (a contiguous run of [`SurfaceElements::samples`], the
/// element's centre first) that stand for element `e`.
fn element_sample_range(elements: &SurfaceElements, e: u32) -> std::ops::Range<u32> {
    let owner = elements.sample_owner();
    let start = owner.partition_point(|&o| o < e);
    let end = owner.partition_point(|&o| o <= e);
    start as u32..end as u32
}

/// Whether the fitted surfaces of some element of `ea` (at `rel` in `eb`'s
/// frame) and some element of `eb` cross, each beyond `z_sds` standard
/// deviations on both sides of the other ([`element_pair_crosses`]), found by
/// the hierarchies over both clouds' element hulls. Returns the answer and
/// the number of node pairs tested.
///
/// Two sampled surfaces of different objects cross only where the objects
/// overlap, whichever side of each is inside: a crossing decides a collision
/// without a separating surface (the `decide_only` query's first test).
pub(crate) fn element_surfaces_cross(
    ea: &SurfaceElements,
    rel: &Pose,
    eb: &SurfaceElements,
    z_sds: Real,
    workspace: &mut BvhWorkspace,
) -> (bool, usize) {
    if !z_sds.is_finite() {
        return (false, 0);
    }
    let crosses = |a: ElementRef<'_>, b: ElementRef<'_>| element_pair_crosses(a, rel, b, z_sds);
    // Single points never cross anything: the descent reads surfaces alone.
    first_hull_pair(ea, rel, eb, z_sds, workspace, true, crosses)
}

/// An element and its hull.
type ElementRef<'a> = (&'a SurfaceElement, &'a Hull);

/// Whether some pair of elements of `ea` (at `rel` in `eb`'s frame) and `eb`
/// passes the hull test at `sds` standard deviations and then `test`
/// ([`surfaces_may_reach`]); with `surfaces_only`, a pair of surface elements.
fn first_hull_pair(
    ea: &SurfaceElements,
    rel: &Pose,
    eb: &SurfaceElements,
    sds: Real,
    workspace: &mut BvhWorkspace,
    surfaces_only: bool,
    test: impl Fn(ElementRef<'_>, ElementRef<'_>) -> bool,
) -> (bool, usize) {
    let (ha, hb) = (ea.hulls(), eb.hulls());
    let pair = |i: u32, j: u32| {
        test(
            (&ea.elements()[i as usize], ha.hull(i)),
            (&eb.elements()[j as usize], hb.hull(j)),
        )
    };
    surfaces_may_reach(ha, rel, hb, sds, workspace, || surfaces_only, pair)
}

/// Whether some sample of `samples` stands for an element of more than one point.
pub(crate) fn has_surface_element(elements: &SurfaceElements, samples: &[u32]) -> bool {
    let owner = elements.sample_owner();
    samples
        .iter()
        .any(|&s| !elements.elements()[owner[s as usize] as usize].is_point())
}

/// Whether the elements of a patch's samples (`ia` of `ea` at `pose_a` in B's
/// frame, `ib` of `eb`) face each other within `reach_sds` noise standard
/// deviations ([`elements_within_reach`]).
pub(crate) fn element_sides_within_reach(
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
pub(crate) fn element_side<'a>(
    els: &'a SurfaceElements,
    unique: &[u32],
    pose: &Pose,
    label: Real,
) -> ElementSide<'a> {
    ElementSide {
        elements: unique
            .iter()
            .map(|&e| (&els.elements()[e as usize], els.hulls().hull(e)))
            .collect(),
        pose: *pose,
        label,
    }
}

/// The elements (sorted, each once) that the samples `samples` stand for.
pub(crate) fn unique_owners(elements: &SurfaceElements, samples: &[u32]) -> Vec<u32> {
    let owner = elements.sample_owner();
    let mut unique: Vec<u32> = samples.iter().map(|&s| owner[s as usize]).collect();
    unique.sort_unstable();
    unique.dedup();
    unique
}

/// The point indices of the elements `owners`, element by element.
pub(crate) fn element_points(elements: &SurfaceElements, owners: &[u32]) -> Vec<u32> {
    owners
        .iter()
        .flat_map(|&e| elements.element_points(e).iter().copied())
        .collect()
}
