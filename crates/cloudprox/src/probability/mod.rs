//! From a separating surface to probabilities and a state.
//!
//! - [`point_probability`]: the paper's Eq. 3 for one point;
//! - [`Aggregation`]: how per-point probabilities become the pair's `P`;
//! - [`surface_probability`]: the same for the surface around a point;
//! - [`crossing_probabilities`]: where two sampled surfaces cross;
//! - `element_crossing_probabilities` (crate-internal): the probability that
//!   the fitted surfaces of two clouds' surface elements cross (the elements
//!   model's `P`), and `elements_within_reach`: whether they can at all;
//! - [`Thresholds`] and [`CollisionState`]: the decision `free` / `contact` / `collision`.

mod aggregation;
mod contact;
mod crossing;
mod element;
mod gap_field;
mod gaussian;
mod point;
mod state;

pub(crate) use aggregation::NEIGHBOURHOOD;
pub use aggregation::{surface_probability, Aggregation};
pub(crate) use contact::nearest_reading;
pub use contact::{contact_probability, ElementReading};
pub use crossing::crossing_probabilities;
pub(crate) use crossing::{crossing_probabilities_in, CrossingSide};
pub use element::FacingPair;
pub(crate) use element::{
    element_crossing_probabilities, element_facing_pairs, element_pair_crosses,
    element_pair_within_reach, elements_within_reach, nearest_surface_pair, surface_pair_bound,
    surface_pair_readings, surface_point_near, ElementGap, ElementSide,
};
pub(crate) use gaussian::wrong_side;
pub use gaussian::{normal_cdf, normal_quantile};
pub use point::point_probability;
pub use state::{CollisionState, Thresholds};
