//! From a separating surface to probabilities and a state.
//!
//! - [`point_probability`]: the paper's Eq. 3 for one point;
//! - [`Aggregation`]: how per-point probabilities become the pair's `P`;
//! - [`Thresholds`] and [`CollisionState`]: the decision `free` / `contact` / `collision`.

mod aggregation;
mod gaussian;
mod point;
mod state;

pub use aggregation::Aggregation;
pub use gaussian::{normal_cdf, normal_quantile};
pub use point::point_probability;
pub use state::{CollisionState, Thresholds};
