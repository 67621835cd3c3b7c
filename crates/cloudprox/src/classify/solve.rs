//! Solving the robust SOCP (the specialized primal-dual method, or Clarabel as
//! reference and fallback), and the outcome as data.

use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus};

use crate::classify::problem::{assemble, Normalized};
use crate::classify::working_set::solve_reduced;
use crate::classify::{ClassifySettings, Separator, SocpSolver};
use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::Real;

/// How a classification ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveStatus {
    /// The solver (the specialized method or Clarabel) converged to the requested
    /// tolerance.
    Solved,
    /// Clarabel converged to its reduced tolerance.
    AlmostSolved,
    /// Neither solver converged (iteration limit, numerical trouble); the separator
    /// is the fallback plane: normal along the difference of the two class means
    /// (in normalized coordinates), through their midpoint.
    Fallback,
}

impl SolveStatus {
    /// `"solved"`, `"almost_solved"` or `"fallback"`.
    pub fn name(self) -> &'static str {
        match self {
            SolveStatus::Solved => "solved",
            SolveStatus::AlmostSolved => "almost_solved",
            SolveStatus::Fallback => "fallback",
        }
    }
}

/// A trained separator and how the solve went.
#[derive(Debug, Clone, PartialEq)]
pub struct Classification {
    /// The surface, positive on label +1's side.
    pub separator: Separator,
    /// Outcome of the solve.
    pub status: SolveStatus,
    /// The solver that produced the separator (Clarabel for the fallback too).
    pub solver: SocpSolver,
    /// Interior-point iterations.
    pub iterations: u32,
    /// Optimal slacks `xi_i` in the input order (empty on fallback).
    pub slacks: Vec<Real>,
}

/// Trains the robust separating surface for `points` with covariances `covs` and
/// labels `+1.0` / `-1.0` (see the [module docs](crate::classify) for the problem).
///
/// Errors on mismatched lengths, labels other than +-1, or a set missing one of
/// the two labels. A solver that does not converge is not an error: see
/// [`SolveStatus::Fallback`].
pub fn train(
    points: &[Point3],
    covs: &[Matrix3],
    labels: &[Real],
    settings: &ClassifySettings,
) -> Result<Classification> {
    train_hinted(points, covs, labels, settings, None).map(|(c, _)| c)
}

/// [`train`] for one of a sequence of nearby problems when `warm` is given:
/// the specialized method's first working set starts from it (empty, or
/// one flag per point: the constraints that supported the previous problem's
/// surface; alone when it is large enough, else with the nearest points), and the result comes with, per point, whether its constraint
/// supports this surface (empty when `warm` is `None` or the specialized
/// method did not solve it).
pub(crate) fn train_hinted(
    points: &[Point3],
    covs: &[Matrix3],
    labels: &[Real],
    settings: &ClassifySettings,
    warm: Option<&[bool]>,
) -> Result<(Classification, Vec<bool>)> {
    settings.validate()?;
    let n = points.len();
    for (what, len) in [("covariances", covs.len()), ("labels", labels.len())] {
        if len != n {
            return Err(Error::Shape {
                what: what.into(),
                expected: n,
                got: len,
            });
        }
    }
    if let Some(i) = labels.iter().position(|&c| c != 1.0 && c != -1.0) {
        return Err(Error::invalid(format!(
            "label {i} is {}, expected +1 or -1",
            labels[i]
        )));
    }
    if !labels.contains(&1.0) || !labels.contains(&-1.0) {
        return Err(Error::invalid(
            "training a separator needs points of both clouds",
        ));
    }
    let r = settings.robust_radius()?;
    let norm = Normalized::new(points, covs);
    if settings.solver == SocpSolver::PrimalDual {
        if let Some((sol, support)) = solve_reduced(
            &norm,
            labels,
            settings.surface,
            settings.slack_weight,
            r,
            settings.solver_tol,
            warm,
        ) {
            let classification = Classification {
                separator: Separator {
                    surface: settings.surface,
                    w: sol.w,
                    b: sol.b,
                    center: norm.center,
                    scale: norm.scale,
                    frame: Pose::identity(),
                },
                status: SolveStatus::Solved,
                solver: SocpSolver::PrimalDual,
                iterations: sol.iterations,
                slacks: sol.xi,
            };
            return Ok((classification, support));
        }
    }
    let problem = assemble(&norm, labels, settings.surface, settings.slack_weight, r);
    let solver_settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(settings.solver_max_iter)
        .tol_gap_abs(settings.solver_tol)
        .tol_gap_rel(settings.solver_tol)
        .tol_feas(settings.solver_tol)
        .build()
        .map_err(|e| Error::invalid(format!("solver settings: {e}")))?;
    let solved = DefaultSolver::new(
        &problem.P,
        &problem.q,
        &problem.A,
        &problem.b,
        &problem.cones,
        solver_settings,
    )
    .ok()
    .map(|mut solver| {
        solver.solve();
        solver.solution
    });
    let d = problem.dim;
    if let Some(sol) = solved {
        let status = match sol.status {
            SolverStatus::Solved => Some(SolveStatus::Solved),
            SolverStatus::AlmostSolved => Some(SolveStatus::AlmostSolved),
            _ => None,
        };
        if let Some(status) = status {
            if sol.x[..=d].iter().all(|v| v.is_finite()) {
                return Ok((
                    Classification {
                        separator: Separator {
                            surface: settings.surface,
                            w: sol.x[..d].to_vec(),
                            b: sol.x[d],
                            center: norm.center,
                            scale: norm.scale,
                            frame: Pose::identity(),
                        },
                        status,
                        solver: SocpSolver::Clarabel,
                        iterations: sol.iterations,
                        slacks: sol.x[d + 1..d + 1 + n].to_vec(),
                    },
                    Vec::new(),
                ));
            }
        }
        return Ok((
            fallback(&norm, labels, settings, sol.iterations),
            Vec::new(),
        ));
    }
    Ok((fallback(&norm, labels, settings, 0), Vec::new()))
}

fn fallback(
    norm: &Normalized,
    labels: &[Real],
    settings: &ClassifySettings,
    iterations: u32,
) -> Classification {
    let mean_of = |label: Real| {
        let (sum, cnt) = norm
            .u
            .iter()
            .zip(labels)
            .filter(|(_, &c)| c == label)
            .fold((Vector3::zeros(), 0.0), |(s, k), (u, _)| (s + u, k + 1.0));
        sum / cnt
    };
    let (ma, mb) = (mean_of(1.0), mean_of(-1.0));
    let normal = ma - mb;
    let mid = (ma + mb) * 0.5;
    let mut w = vec![0.0; settings.surface.dim()];
    w[..3].copy_from_slice(normal.as_slice());
    Classification {
        separator: Separator {
            surface: settings.surface,
            w,
            b: -normal.dot(&mid),
            center: norm.center,
            scale: norm.scale,
            frame: Pose::identity(),
        },
        status: SolveStatus::Fallback,
        solver: SocpSolver::Clarabel,
        iterations,
        slacks: Vec::new(),
    }
}
