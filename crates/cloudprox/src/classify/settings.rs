//! Settings of the robust classifier: public fields, [`Default`] and
//! [`ClassifySettings::validate`].

use crate::classify::Surface;
use crate::error::{Error, Result};
use crate::uncertainty::RobustModel;
use crate::Real;

/// Which solver trains the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SocpSolver {
    /// The specialized primal-dual interior-point method: Newton systems of
    /// `dim + 1` unknowns, `O(n)` per iteration, on a working set of the
    /// constraints. Falls back to Clarabel if it does not converge. The default.
    #[default]
    PrimalDual,
    /// Clarabel, a general conic interior-point solver: the exact reference.
    Clarabel,
}

crate::names::named_options!(SocpSolver, "solver", {
    PrimalDual => "primal_dual",
    Clarabel => "clarabel",
});

/// How separating surfaces are trained: set the fields over
/// [`ClassifySettings::default`]; every entry point that takes the settings
/// checks them with [`ClassifySettings::validate`].
///
/// ```
/// use cloudprox::classify::{ClassifySettings, SocpSolver, Surface};
///
/// let settings = ClassifySettings {
///     surface: Surface::Linear,
///     solver: SocpSolver::Clarabel,
///     ..ClassifySettings::default()
/// };
/// assert!(settings.validate().is_ok());
/// let bad = ClassifySettings { robust_eta: 1.0, ..settings };
/// assert!(bad.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClassifySettings {
    /// Surface family (default [`Surface::Quadric`]).
    pub surface: Surface,
    /// The slack weight: the weight (`lambda` in the formulas) of the slacks
    /// against `1/2 |w|^2`, in normalized coordinates (default 100: close to a
    /// hard margin, so the surface sits mid-gap).
    pub slack_weight: Real,
    /// Confidence `eta` of each point's chance constraint, in `[0.5, 1)` (default 0.9).
    pub robust_eta: Real,
    /// Distribution assumption behind `r = r(eta)` (default Gaussian).
    pub robust_model: RobustModel,
    /// Which solver (default [`SocpSolver::PrimalDual`]).
    pub solver: SocpSolver,
    /// Clarabel's interior-point iteration limit (default 100).
    pub solver_max_iter: u32,
    /// Relative and absolute gap / feasibility tolerance (default 1e-7).
    pub solver_tol: Real,
}

impl Default for ClassifySettings {
    fn default() -> Self {
        Self {
            surface: Surface::Quadric,
            slack_weight: 100.0,
            robust_eta: 0.9,
            robust_model: RobustModel::Gaussian,
            solver: SocpSolver::PrimalDual,
            solver_max_iter: 100,
            solver_tol: 1e-7,
        }
    }
}

impl ClassifySettings {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the first field out of its domain: a
    /// `slack_weight` that is not finite and positive, a `robust_eta` outside
    /// `[0.5, 1)`, `solver_max_iter` 0, or a `solver_tol` outside `(0, 1)`.
    pub fn validate(&self) -> Result<()> {
        if !(self.slack_weight.is_finite() && self.slack_weight > 0.0) {
            return Err(Error::invalid(format!(
                "slack_weight must be finite and > 0, got {}",
                self.slack_weight
            )));
        }
        self.robust_model.radius(self.robust_eta)?;
        if self.solver_max_iter == 0 {
            return Err(Error::invalid("solver_max_iter must be >= 1"));
        }
        if !(self.solver_tol.is_finite() && self.solver_tol > 0.0 && self.solver_tol < 1.0) {
            return Err(Error::invalid(format!(
                "solver_tol must be in (0, 1), got {}",
                self.solver_tol
            )));
        }
        Ok(())
    }

    /// The robustness radius `r` for these settings.
    ///
    /// # Errors
    /// As [`RobustModel::radius`] for a `robust_eta` out of its domain.
    pub fn robust_radius(&self) -> Result<Real> {
        self.robust_model.radius(self.robust_eta)
    }
}
