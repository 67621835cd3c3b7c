//! Settings of the robust classifier, with a validating builder.

use crate::classify::Surface;
use crate::error::{Error, Result};
use crate::uncertainty::RobustModel;
use crate::Real;

/// Which solver trains the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SocpSolver {
    /// The specialized log-barrier interior-point method: Newton systems of
    /// `dim + 1` unknowns, `O(n)` per step. Falls back to Clarabel if it does not
    /// converge. The default.
    #[default]
    Barrier,
    /// Clarabel, a general conic interior-point solver: the exact reference.
    Clarabel,
}

crate::names::named_options!(SocpSolver, "solver", {
    Barrier => "barrier",
    Clarabel => "clarabel",
});

/// How separating surfaces are trained. Build with [`ClassifySettingsBuilder`] or
/// take [`ClassifySettings::default`].
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
    /// Which solver (default [`SocpSolver::Barrier`]).
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
            solver: SocpSolver::Barrier,
            solver_max_iter: 100,
            solver_tol: 1e-7,
        }
    }
}

impl ClassifySettings {
    /// A builder starting from the defaults.
    pub fn builder() -> ClassifySettingsBuilder {
        ClassifySettingsBuilder::default()
    }

    /// Checks every field's domain.
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
    pub fn robust_radius(&self) -> Result<Real> {
        self.robust_model.radius(self.robust_eta)
    }
}

/// Builder of [`ClassifySettings`]; [`ClassifySettingsBuilder::build`] validates.
#[derive(Debug, Clone, Default)]
pub struct ClassifySettingsBuilder {
    inner: ClassifySettings,
}

impl ClassifySettingsBuilder {
    /// Surface family.
    pub fn surface(mut self, surface: Surface) -> Self {
        self.inner.surface = surface;
        self
    }
    /// Slack weight (`lambda` in the formulas).
    pub fn slack_weight(mut self, weight: Real) -> Self {
        self.inner.slack_weight = weight;
        self
    }
    /// Chance-constraint confidence `eta`.
    pub fn robust_eta(mut self, eta: Real) -> Self {
        self.inner.robust_eta = eta;
        self
    }
    /// Distribution assumption for `r(eta)`.
    pub fn robust_model(mut self, model: RobustModel) -> Self {
        self.inner.robust_model = model;
        self
    }
    /// Which solver.
    pub fn solver(mut self, solver: SocpSolver) -> Self {
        self.inner.solver = solver;
        self
    }
    /// Clarabel's iteration limit.
    pub fn solver_max_iter(mut self, n: u32) -> Self {
        self.inner.solver_max_iter = n;
        self
    }
    /// Solver tolerance.
    pub fn solver_tol(mut self, tol: Real) -> Self {
        self.inner.solver_tol = tol;
        self
    }
    /// The validated settings.
    pub fn build(self) -> Result<ClassifySettings> {
        self.inner.validate()?;
        Ok(self.inner)
    }
}
