//! From a separating surface to probabilities and a state.
//!
//! - [`point_probability`]: the paper's Eq. 3 for one point;
//! - [`Aggregation`]: how per-point probabilities become the pair's `P`;
//! - [`surface_probability`]: the same for the surface around a point;
//! - [`crossing_probabilities`]: where two sampled surfaces cross;
//! - [`pair_crossing_probabilities`]: the probability that the surfaces two
//!   samples stand for lie on the wrong sides of each other;
//! - [`element_crossing_probabilities`]: the same for the fitted surfaces of
//!   two clouds' surface elements (the elements model's `P`);
//! - [`Thresholds`] and [`CollisionState`]: the decision `free` / `contact` / `collision`.

mod aggregation;
mod crossing;
mod element;
mod gaussian;
mod pair;
mod point;
mod state;

pub use aggregation::{surface_probability, Aggregation};
pub use crossing::crossing_probabilities;
pub use element::{element_crossing_probabilities, ElementSide};
pub use gaussian::{normal_cdf, normal_quantile};
pub use pair::pair_crossing_probabilities;
pub use point::point_probability;
pub use state::{CollisionState, Thresholds};
