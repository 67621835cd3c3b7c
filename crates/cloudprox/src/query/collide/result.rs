//! What a collision query returns: plain data with documented conventions.

use crate::classify::{Separator, SolveStatus, Surface};
use crate::error::{Error, Result};
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

/// Per-point probabilities of one cloud's `len` points: 0 but at the points of
/// the near regions, which alone are stored (a query near a few hundred points
/// of a cloud of millions keeps a few hundred values, so a batch of results
/// holds memory in proportion to the contacts, not to the clouds). Zeros are
/// never stored, so equal probabilities compare equal.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointProbabilities {
    len: usize,
    indices: Vec<u32>,
    values: Vec<Real>,
}

/// Up to this many dense entries per index, [`PointProbabilities::gather`]
/// reads the dense array instead of sorting the indices (a sort costs about
/// `log2 m` comparisons and moves per index, a pass one read per entry).
const GATHER_SCAN_RATIO: usize = 16;

impl PointProbabilities {
    /// `len` zeros.
    pub fn zeros(len: usize) -> Self {
        Self {
            len,
            indices: Vec::new(),
            values: Vec::new(),
        }
    }

    /// The probabilities at `indices` (strictly increasing, each below `len`)
    /// and 0 elsewhere.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if `indices` and `values` differ in length, the
    /// indices are not strictly increasing or not below `len`, or a value is
    /// not a probability (in `[0, 1]`).
    pub fn from_sparse(len: usize, indices: Vec<u32>, values: Vec<Real>) -> Result<Self> {
        if indices.len() != values.len() {
            return Err(Error::invalid(format!(
                "{} indices but {} values",
                indices.len(),
                values.len()
            )));
        }
        if indices.windows(2).any(|w| w[0] >= w[1]) {
            return Err(Error::invalid("indices are not strictly increasing"));
        }
        if let Some(&last) = indices.last() {
            if last as usize >= len {
                return Err(Error::invalid(format!(
                    "index {last} is not below the {len} points"
                )));
            }
        }
        if let Some(v) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
            return Err(Error::invalid(format!("{v} is not a probability")));
        }
        Ok(Self::nonzero(len, indices.into_iter().zip(values)))
    }

    /// The non-zero `(index, probability)` pairs of `pairs` (by index) among
    /// `len` points.
    fn nonzero(len: usize, pairs: impl Iterator<Item = (u32, Real)>) -> Self {
        let (indices, values) = pairs.filter(|&(_, v)| v != 0.0).unzip();
        Self {
            len,
            indices,
            values,
        }
    }

    /// The non-zero entries of `dense` at `indices` (any order, repeats
    /// allowed; every other entry of `dense` must be 0) among `len` points
    /// (`dense` may be empty when `indices` is).
    ///
    /// Both ways below give the same entries in index order: a pass over
    /// `dense` (every non-zero entry is at one of `indices`) where it is at
    /// most [`GATHER_SCAN_RATIO`] times as long as `indices`, else `indices`
    /// sorted (a query against a large cloud then does not read all of it).
    pub(crate) fn gather(len: usize, dense: &[Real], mut indices: Vec<u32>) -> Self {
        if !indices.is_empty() && dense.len() <= GATHER_SCAN_RATIO * indices.len() {
            debug_assert!(
                {
                    let mut at = vec![false; dense.len()];
                    for &i in &indices {
                        at[i as usize] = true;
                    }
                    dense.iter().zip(&at).all(|(&v, &i)| i || v == 0.0)
                },
                "a non-zero entry of the dense array outside the indices"
            );
            return Self::nonzero(len, (0u32..).zip(dense.iter().copied()));
        }
        indices.sort_unstable();
        indices.dedup();
        Self::nonzero(len, indices.into_iter().map(|i| (i, dense[i as usize])))
    }

    /// Number of points (stored or not).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Point `i`'s probability (0 for a point outside every near region).
    ///
    /// # Panics
    /// If `i >= len`.
    pub fn get(&self, i: usize) -> Real {
        assert!(i < self.len, "point {i} of {}", self.len);
        self.indices
            .binary_search(&(i as u32))
            .map_or(0.0, |k| self.values[k])
    }

    /// The stored points' indices, increasing.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The stored points' probabilities, in the order of [`Self::indices`].
    pub fn values(&self) -> &[Real] {
        &self.values
    }

    /// `(index, probability)` of the stored points, by index.
    pub fn iter(&self) -> impl Iterator<Item = (u32, Real)> + '_ {
        self.indices
            .iter()
            .copied()
            .zip(self.values.iter().copied())
    }

    /// The mean of several runs' probabilities of the same `len` points (0
    /// where a run stores none), stored where any run stores one.
    pub(crate) fn mean(runs: &[&PointProbabilities]) -> Self {
        let len = runs.first().map_or(0, |r| r.len);
        let mut all: Vec<(u32, Real)> = runs.iter().flat_map(|r| r.iter()).collect();
        // Stable: each point's values are summed in the runs' order, as a sum
        // over the runs' dense arrays would.
        all.sort_by_key(|&(i, _)| i);
        let k = runs.len().max(1) as Real;
        let mut summed: Vec<(u32, Real)> = Vec::with_capacity(all.len());
        for (i, p) in all {
            match summed.last_mut() {
                Some(last) if last.0 == i => last.1 += p,
                _ => summed.push((i, p)),
            }
        }
        Self::nonzero(len, summed.into_iter().map(|(i, p)| (i, (p / k).min(1.0))))
    }

    /// Every point's probability, `len` values.
    pub fn to_dense(&self) -> Vec<Real> {
        let mut out = vec![0.0; self.len];
        for (i, p) in self.iter() {
            out[i as usize] = p;
        }
        out
    }
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
    /// Element surface pairs found crossing by the hierarchies (0 or 1 per
    /// segmentation): with
    /// the elements model, `decide_only` looks for one before any patch (a
    /// collision decided without a classifier; on one segmentation: the runs
    /// of a mean over several compute their whole `P`), and the full query
    /// where its patches found no collision (a part through a thin solid).
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

impl QueryCounters {
    /// The counters of several runs of one query (its segmentations, see
    /// [`crate::query::CollisionRequest::segmentations`]): sums, but the
    /// pruned bound, whose mean bounds what pruning changes of a mean of the
    /// runs' probabilities.
    pub(crate) fn combined(runs: &[&QueryCounters]) -> Self {
        let mut out = QueryCounters::default();
        for c in runs {
            // Every field named, so that a new counter cannot be left out.
            let QueryCounters {
                node_pairs_visited: _,
                leaf_pairs: _,
                near_regions: _,
                patches: _,
                misfit_cuts: _,
                patches_beyond_reach: _,
                surface_crossings: _,
                surface_links: _,
                points_classified: _,
                solver_iterations: _,
                clarabel_fallbacks: _,
                solver_fallbacks: _,
                pruned_bound: _,
            } = c;
            out.node_pairs_visited += c.node_pairs_visited;
            out.leaf_pairs += c.leaf_pairs;
            out.near_regions += c.near_regions;
            out.patches += c.patches;
            out.misfit_cuts += c.misfit_cuts;
            out.patches_beyond_reach += c.patches_beyond_reach;
            out.surface_crossings += c.surface_crossings;
            out.surface_links += c.surface_links;
            out.points_classified += c.points_classified;
            out.solver_iterations += c.solver_iterations;
            out.clarabel_fallbacks += c.clarabel_fallbacks;
            out.solver_fallbacks += c.solver_fallbacks;
            out.pruned_bound += c.pruned_bound / runs.len() as Real;
        }
        out
    }
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
    /// points outside every near region), stored for the near regions' points
    /// only.
    pub probabilities_a: PointProbabilities,
    /// The same for cloud B.
    pub probabilities_b: PointProbabilities,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sparse_probabilities_read_as_their_dense_values() {
        let dense = [0.0, 0.25, 0.0, 0.0, 1.0, 0.0];
        // Indices out of order, repeated, and one at a zero: only the non-zero
        // values are kept, in index order.
        let p = PointProbabilities::gather(dense.len(), &dense, vec![4, 1, 4, 2]);
        assert_eq!(p.len(), 6);
        assert_eq!(p.indices(), &[1, 4]);
        assert_eq!(p.values(), &[0.25, 1.0]);
        assert_eq!(p.to_dense(), dense.to_vec());
        assert_eq!((0..6).map(|i| p.get(i)).collect::<Vec<_>>(), dense.to_vec());
        // The same probabilities given with a stored zero compare equal.
        let q = PointProbabilities::from_sparse(6, vec![1, 3, 4], vec![0.25, 0.0, 1.0]).unwrap();
        assert_eq!(p, q);
        assert!(PointProbabilities::zeros(0).is_empty());
        assert_eq!(PointProbabilities::zeros(3).to_dense(), vec![0.0; 3]);
        // Nothing written: no dense array was made, the points are still counted.
        assert_eq!(
            PointProbabilities::gather(7, &[], Vec::new()),
            PointProbabilities::zeros(7)
        );
    }

    #[test]
    fn gathering_reads_the_same_entries_by_a_pass_or_by_sorting() {
        // Non-zero values at every third index below 60, one index written
        // as 0 (a point on its own side far from the surface).
        let indices: Vec<u32> = (0..20).rev().map(|k| 3 * k).chain([9, 30]).collect();
        let value = |i: u32| {
            if i == 27 {
                0.0
            } else {
                0.01 * Real::from(i + 1)
            }
        };
        for len in [64, 10_000] {
            let mut dense = vec![0.0; len];
            for &i in &indices {
                dense[i as usize] = value(i);
            }
            // 64 entries for 22 indices: a pass; 10 000: a sort.
            assert_eq!(len <= GATHER_SCAN_RATIO * indices.len(), len == 64);
            let p = PointProbabilities::gather(len, &dense, indices.clone());
            let want: Vec<u32> = (0..20).map(|k| 3 * k).filter(|&i| i != 27).collect();
            assert_eq!(p.indices(), &want[..], "len {len}");
            assert_eq!(
                p.values(),
                &want.iter().map(|&i| value(i)).collect::<Vec<_>>()[..]
            );
            assert_eq!(p.to_dense(), dense);
        }
    }

    #[test]
    fn malformed_sparse_probabilities_are_refused() {
        let bad = [
            (vec![1, 2], vec![0.5]),
            (vec![2, 1], vec![0.5, 0.5]),
            (vec![1, 1], vec![0.5, 0.5]),
            (vec![5], vec![0.5]),
            (vec![1], vec![1.5]),
            (vec![1], vec![Real::NAN]),
        ];
        for (indices, values) in bad {
            let e = PointProbabilities::from_sparse(5, indices.clone(), values.clone());
            assert!(
                matches!(e, Err(Error::InvalidInput(_))),
                "{indices:?} {values:?}"
            );
        }
    }

    #[test]
    #[should_panic(expected = "point 3 of 3")]
    fn reading_past_the_cloud_panics() {
        PointProbabilities::zeros(3).get(3);
    }
}
