//! What a collision query returns: plain data with documented conventions.

use crate::classify::{Separator, SolveStatus, Surface};
use crate::math::{Point3, Vector3};
use crate::probability::{Aggregation, CollisionState};
use crate::Real;

/// One classified patch of a near region (a connected group of near points,
/// cut into patches along the contact when large or misfit), with its own
/// separating surface. World frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPatch {
    /// Index of the connected near region this patch belongs to.
    pub component: u32,
    /// Indices of cloud A's points in the patch.
    pub indices_a: Vec<u32>,
    /// Indices of cloud B's points in the patch.
    pub indices_b: Vec<u32>,
    /// A point on the separating surface where the two clouds come closest.
    pub point: Point3,
    /// Unit normal of the surface at `point`, pointing from A towards B.
    pub normal: Vector3,
    /// Estimated signed separation of the two clouds' surfaces (metres), negative
    /// when they interpenetrate, at this patch. Measured along the near region's
    /// direction of least spread (oriented from A to B), as the smallest over lines
    /// through up to 64 of the patch's points of: the median
    /// offset of B's points nearest that line minus that of A's (those within two
    /// sampling spacings of it, at most 12, at least 3 of each). Medians keep it unbiased by the noise on a
    /// flat contact; curvature within the sampled neighbourhood biases it upwards.
    pub separation: Real,
    /// The patch's aggregated collision probability.
    pub probability: Real,
    /// The trained surface (world frame; positive on A's side).
    pub separator: Separator,
    /// The surface family.
    pub surface: Surface,
    /// How the solve ended.
    pub status: SolveStatus,
    /// Interior-point iterations of the solve.
    pub iterations: u32,
}

/// The counters of one query: everything in [`QueryStats`] but the wall
/// time, so that two runs of one query compare equal.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QueryCounters {
    /// Node pairs tested during the traversal.
    pub node_pairs_visited: usize,
    /// Leaf pairs kept (not pruned).
    pub leaf_pairs: usize,
    /// Connected near regions.
    pub near_regions: usize,
    /// Patches (= [`CollisionResult::patches`]) classified.
    pub patches: usize,
    /// Patches cut in two because their surface put a point beyond the noise's
    /// reach of the other cloud on the wrong side.
    pub misfit_cuts: usize,
    /// Patches of the elements model pruned without a classifier: no element
    /// of either side faces the other within the noise's reach (their points
    /// keep `p_i = 0`).
    pub patches_beyond_reach: usize,
    /// Element surface pairs found crossing by the hierarchies (0 or 1): with
    /// the elements model, `decide_only` looks for one before any patch (a
    /// collision decided without a classifier), and the full query where its
    /// patches found no collision (a part through a thin solid).
    pub surface_crossings: usize,
    /// Element pairs whose surfaces face within the noise's reach although
    /// none of the samples that stand for one of them was near the other (a
    /// metre-wide element that a thin part passes through): each brought
    /// both elements into the near set.
    pub surface_links: usize,
    /// Points of both clouds that went into a classifier.
    pub points_classified: usize,
    /// Interior-point iterations over all patches.
    pub solver_iterations: u64,
    /// Patches where the specialized solver did not converge and Clarabel was
    /// used.
    pub clarabel_fallbacks: usize,
    /// Patches whose solve fell back to the mean-difference plane (see
    /// [`SolveStatus::Fallback`]).
    pub solver_fallbacks: usize,
    /// Upper bound on the probability that any pruned point is on the wrong side
    /// of a plane separating its node from the other cloud's (see
    /// [`crate::bvh::prune_bound`]); pruned points get `p_i = 0`.
    pub pruned_bound: Real,
}

/// Counters and timings of one query. Equality compares the counters, not
/// the wall time (two runs of one query differ in it).
#[derive(Debug, Clone, Default)]
pub struct QueryStats {
    /// The counters.
    pub counters: QueryCounters,
    /// Wall time of the query (seconds).
    pub time_seconds: Real,
}

impl PartialEq for QueryStats {
    fn eq(&self, o: &Self) -> bool {
        self.counters == o.counters
    }
}

/// The answer of [`crate::query::collide()`].
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionResult {
    /// The pair's collision probability `P`, aggregated as requested.
    pub probability: Real,
    /// The decided state from `P` and the thresholds.
    pub state: CollisionState,
    /// Per-point probability of cloud A's points lying on the wrong side (0 for
    /// points outside every near region).
    pub probabilities_a: Vec<Real>,
    /// The same for cloud B.
    pub probabilities_b: Vec<Real>,
    /// The classified patches of the near regions.
    pub patches: Vec<ContactPatch>,
    /// With the points model (not `decide_only`): `P` under each of the
    /// paper's aggregations, from this query's per-point probabilities over
    /// the points `P` aggregates. A points-model query asking for one of them
    /// returns it as its `probability`, bit for bit, so one query gives all
    /// three. `None` with the elements model (its `P` aggregates surface
    /// crossings, not points) and with `decide_only` (no per-point
    /// probabilities).
    pub point_aggregates: Option<PointAggregates>,
    /// Counters and timings.
    pub stats: QueryStats,
}

/// The paper's three aggregates of one points-model query's per-point
/// probabilities (see [`CollisionResult::point_aggregates`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointAggregates {
    /// [`Aggregation::Max`].
    pub max: Real,
    /// [`Aggregation::Union`].
    pub union: Real,
    /// [`Aggregation::Independent`].
    pub independent: Real,
}

impl PointAggregates {
    /// The three aggregates of `probabilities`.
    pub fn of(probabilities: &[Real]) -> Self {
        let p = || probabilities.iter().copied();
        Self {
            max: Aggregation::Max.aggregate(p()),
            union: Aggregation::Union.aggregate(p()),
            independent: Aggregation::Independent.aggregate(p()),
        }
    }

    /// The aggregate under `aggregation` (`None` for [`Aggregation::Surface`],
    /// which reads the surfaces around the points, not their probabilities).
    pub fn get(&self, aggregation: Aggregation) -> Option<Real> {
        match aggregation {
            Aggregation::Max => Some(self.max),
            Aggregation::Union => Some(self.union),
            Aggregation::Independent => Some(self.independent),
            Aggregation::Surface => None,
        }
    }
}
