//! What a collision query should compute: public fields, [`Default`] and
//! [`CollisionRequest::validate`].

use crate::classify::ClassifySettings;
use crate::error::{Error, Result};
use crate::probability::{Aggregation, Thresholds};
use crate::Real;

/// What a query classifies and aggregates: the surface elements the points
/// sample ([`crate::element`], the default) or the points themselves (the
/// paper's method).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum QueryModel {
    /// Surface elements (the default): each cloud's points grouped, once per
    /// cloud, into pieces of surface that fit a quadric height field within
    /// their noise; the classifier trains on the elements' samples, and `P` is
    /// the probability that the two sampled surfaces cross, read at every
    /// facing pair of element surfaces (gap and its standard deviation) and
    /// combined over the contact ([`crate::probability::contact_probability`]).
    /// Per-point probabilities (Eq. 3 with each point's own covariance against
    /// the trained surface) are still reported.
    #[default]
    Elements,
    /// Every point is a sample of the classifier and a candidate for `P` (the
    /// paper's method, with the aggregations [`Aggregation`]).
    Points,
}

crate::names::named_options!(QueryModel, "model", {
    Elements => "elements",
    Points => "points",
});

/// Options of [`crate::query::collide()`]: set the fields over
/// [`CollisionRequest::default`]; every query that takes a request checks it
/// with [`CollisionRequest::validate`] before any work.
///
/// ```
/// use cloudprox::classify::{ClassifySettings, Surface};
/// use cloudprox::probability::{Aggregation, Thresholds};
/// use cloudprox::query::CollisionRequest;
///
/// let request = CollisionRequest {
///     aggregation: Aggregation::Independent,
///     thresholds: Thresholds { collision: 0.95, free: 0.05 },
///     classify: ClassifySettings {
///         surface: Surface::Linear,
///         ..ClassifySettings::default()
///     },
///     ..CollisionRequest::default()
/// };
/// assert!(request.validate().is_ok());
/// let bad = CollisionRequest { prune_epsilon: -1.0, ..request };
/// assert!(bad.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionRequest {
    /// What is classified: surface elements or points (see [`QueryModel`];
    /// default [`QueryModel::Elements`]).
    pub model: QueryModel,
    /// How separating surfaces are trained (default
    /// [`ClassifySettings::default`]).
    pub classify: ClassifySettings,
    /// How per-point probabilities become `P` (default [`Aggregation::Max`]).
    pub aggregation: Aggregation,
    /// The decision thresholds (default `collision = 0.9`, `free = 0.1`).
    pub thresholds: Thresholds,
    /// A node pair is pruned when its crossing bound is below this (default 1e-3).
    /// The sum of the bounds of what was pruned is reported in
    /// [`crate::query::QueryCounters::pruned_bound`].
    pub prune_epsilon: Real,
    /// Context kept around the near region, in sampling spacings (each point's
    /// distance to its 6th nearest neighbour) (default 2, at least 0.5). A pair
    /// of points is near when the noise reaches across its distance less half a
    /// spacing (sampled surfaces can meet between samples); once some pair is,
    /// pairs closer than `near_context` spacings join too, so that sparse clouds
    /// still give the classifier a surface to fit (the larger spacing of the
    /// pair; with the elements model, a single-point element's sample counts
    /// in its own spacing).
    pub near_context: Real,
    /// Near regions with more points than this are split into patches along the
    /// contact, each with its own surface (default 2000): a bound on the cost of
    /// one solve. Smaller patches are also cut where one surface misfits (see
    /// [`QueryCounters::misfit_cuts`](crate::query::QueryCounters::misfit_cuts)).
    /// A cloud too sparse for a cut to leave points of it in both halves (a
    /// handful of points against thousands) is shared by the halves when it
    /// holds at most half this many; its points keep their largest value.
    pub region_max_points: usize,
    /// `false` skips the hierarchy: the near points are found by testing every
    /// point pair (`O(n_a n_b)`) and all go into one region (still split into
    /// patches); with the elements model, the element pairs within reach and
    /// the crossings of element surfaces are found by testing every element
    /// pair. The brute-force reference. Default `true`.
    pub use_hierarchy: bool,
    /// Return as soon as the state is decided (default `false`): no per-point
    /// probabilities, no separation estimates, and with the `max` aggregation the
    /// query stops at the first patch whose probability reaches the collision
    /// threshold (against an exact mesh side with the elements model and one
    /// segmentation: at the first element whose readings reach it, elements
    /// deep inside the mesh looked at first). The state (and, when nothing is
    /// skipped, `P`) is that of the full query; `P` is otherwise at most the
    /// full query's.
    pub decide_only: bool,
    /// With the elements model, how many segmentations of the two clouds the
    /// query averages over (default 1, at most
    /// [`MAX_SEGMENTATIONS`](crate::cloud::MAX_SEGMENTATIONS)): the query runs
    /// once on each pair of element sets, each cloud's own segmentation and
    /// the next `segmentations - 1`
    /// ([`PointCloud::segmentation`](crate::cloud::PointCloud::segmentation):
    /// the same points grouped into differently placed elements), and `P`
    /// and the per-point probabilities are their means; the state is `P`'s,
    /// the patches are every run's, the counters their sums (the pruned
    /// bound their mean) and the time the whole query's. Which element planes read a contact depends on where
    /// the element boundaries fall, and from one noise draw to the next
    /// that changes more than the noise of the planes themselves: the mean
    /// over a few segmentations ranks poses near contact better, for as many
    /// times the work (in a query on its own the runs after the first go to
    /// rayon's pool, so on several cores it waits for less; inside the pool,
    /// as `collide_many`'s queries are, they run one after another).
    /// Deciding only, each
    /// segmentation's query still computes its whole `P` (a mean of early
    /// stops would not be the full query's), without the per-point
    /// probabilities and separation estimates. Must be 1 with the points
    /// model.
    pub segmentations: u32,
}

impl Default for CollisionRequest {
    fn default() -> Self {
        Self {
            model: QueryModel::default(),
            classify: ClassifySettings::default(),
            aggregation: Aggregation::Max,
            thresholds: Thresholds::default(),
            prune_epsilon: 1e-3,
            near_context: 2.0,
            region_max_points: 2000,
            use_hierarchy: true,
            decide_only: false,
            segmentations: 1,
        }
    }
}

impl CollisionRequest {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the first field out of its domain: as
    /// [`ClassifySettings::validate`] and [`Thresholds::validate`]; a
    /// `prune_epsilon` outside `[0, 1)`, a `near_context` below 0.5 or not
    /// finite, `region_max_points` below 8, the `surface` aggregation with
    /// the elements model, or `segmentations` outside `1..=MAX_SEGMENTATIONS`
    /// or above 1 with the points model.
    pub fn validate(&self) -> Result<()> {
        self.classify.validate()?;
        self.thresholds.validate()?;
        if !(self.prune_epsilon.is_finite() && (0.0..1.0).contains(&self.prune_epsilon)) {
            return Err(Error::invalid(format!(
                "prune_epsilon must be in [0, 1), got {}",
                self.prune_epsilon
            )));
        }
        if !(self.near_context.is_finite() && self.near_context >= 0.5) {
            return Err(Error::invalid(format!(
                "near_context must be finite and >= 0.5, got {}",
                self.near_context
            )));
        }
        if self.model == QueryModel::Elements && self.aggregation == Aggregation::Surface {
            return Err(Error::invalid(
                "aggregation 'surface' belongs to model 'points' (the elements model aggregates surface crossings already)",
            ));
        }
        if !(1..=crate::cloud::MAX_SEGMENTATIONS).contains(&self.segmentations) {
            return Err(Error::invalid(format!(
                "segmentations must be in 1..={}, got {}",
                crate::cloud::MAX_SEGMENTATIONS,
                self.segmentations
            )));
        }
        if self.model == QueryModel::Points && self.segmentations > 1 {
            return Err(Error::invalid(format!(
                "segmentations = {} needs model 'elements' (the points model has no segmentation)",
                self.segmentations
            )));
        }
        if self.region_max_points < 8 {
            return Err(Error::invalid(format!(
                "region_max_points must be >= 8, got {}",
                self.region_max_points
            )));
        }
        Ok(())
    }
}
