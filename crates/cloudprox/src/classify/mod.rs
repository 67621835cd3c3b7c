//! The robust classifier: the surface that best separates two noisy point sets.
//!
//! For points `x_i` with labels `c_i` (+1 for cloud A, -1 for cloud B) and
//! covariances `Sigma_i`, the paper's Eq. 2, generalized to a feature map `phi`:
//!
//! ```text
//! minimize    1/2 |w|^2 + lambda * sum_i xi_i
//! subject to  c_i (w . phi(x_i) + b) >= 1 - xi_i + r_i |Sigma_i^(1/2) J_i^T w|,  xi_i >= 0
//! ```
//!
//! where `J_i` is the Jacobian of `phi` at `x_i`, so `J_i^T w` is the gradient of
//! the surface `f(x) = w . phi(x) + b` and `|Sigma_i^(1/2) grad f|` its standard
//! deviation at the point (the covariance pushed through the feature map). It is
//! a second-order cone program, solved by a specialized primal-dual
//! interior-point method whose Newton systems have only `dim + 1` unknowns
//! ([`SocpSolver::PrimalDual`], the default), with Clarabel ([`SocpSolver::Clarabel`]) as the exact reference and
//! the fallback. Coordinates are normalized per
//! problem (centred, divided by their RMS radius) and the covariances scaled by
//! the same factor squared.
//!
//! - [`ClassifySettings`]: surface type, `slack_weight` (`lambda`), `robust_eta`, solver limits;
//! - [`Surface`] and [`Separator`]: the feature maps and the trained `f`, `grad f`;
//! - [`train`]: assembles and solves the problem; [`Classification`] and
//!   [`SolveStatus`] report the outcome as data (a failed solve is not an error:
//!   it falls back to a documented plane).

mod primal_dual;
mod problem;
mod separator;
mod settings;
mod solve;
mod surface;
mod working_set;

pub use separator::{QuadraticForm, Separator};
pub use settings::{ClassifySettings, SocpSolver};
pub(crate) use solve::train_hinted;
pub use solve::{train, Classification, SolveStatus};
pub use surface::Surface;
