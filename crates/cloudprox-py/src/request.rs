//! Query options: keyword arguments to a validated `CollisionRequest`.
//!
//! Every option is `None` by default, meaning "the Rust default"
//! (`CollisionRequest::default()` and `ClassifySettings::default()`), so the
//! defaults live in one place. [`default_options`] shows them to Python.

use cloudprox::classify::{SocpSolver, Surface};
use cloudprox::probability::Aggregation;
use cloudprox::query::{CollisionRequest, QueryModel};
use cloudprox::uncertainty::RobustModel;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::error::{invalid_input, CoreResultExt};

const SURFACES: [Surface; 2] = [Surface::Linear, Surface::Quadric];
const AGGREGATIONS: [Aggregation; 4] = [
    Aggregation::Surface,
    Aggregation::Max,
    Aggregation::Union,
    Aggregation::Independent,
];
const MODELS: [QueryModel; 2] = [QueryModel::Elements, QueryModel::Points];
const ROBUST_MODELS: [RobustModel; 2] = [RobustModel::Gaussian, RobustModel::Chebyshev];
const SOLVERS: [SocpSolver; 2] = [SocpSolver::Barrier, SocpSolver::Clarabel];

fn parse_name<T: Copy>(
    py: Python<'_>,
    option: &str,
    given: &str,
    all: &[T],
    name: impl Fn(T) -> &'static str,
) -> PyResult<T> {
    all.iter()
        .copied()
        .find(|&v| name(v) == given)
        .ok_or_else(|| {
            let valid: Vec<String> = all.iter().map(|&v| format!("'{}'", name(v))).collect();
            invalid_input(
                py,
                format!(
                    "unknown {option} '{given}'; valid names: {}",
                    valid.join(", ")
                ),
            )
        })
}

fn usize_option(py: Python<'_>, option: &str, v: i64) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| {
        invalid_input(
            py,
            format!("{option} must be a non-negative integer, got {v}"),
        )
    })
}

/// The keyword options shared by `collide` and `collide_many`.
#[derive(Debug, Default)]
pub struct RequestOptions {
    pub surface: Option<String>,
    pub aggregation: Option<String>,
    pub threshold_collision: Option<f64>,
    pub threshold_free: Option<f64>,
    pub prune_epsilon: Option<f64>,
    pub region_max_points: Option<i64>,
    pub near_context: Option<f64>,
    pub lambda: Option<f64>,
    pub robust_eta: Option<f64>,
    pub robust_model: Option<String>,
    pub solver: Option<String>,
    pub use_hierarchy: Option<bool>,
    pub model: Option<String>,
    pub decide_only: Option<bool>,
}

impl RequestOptions {
    /// The validated request: the Rust defaults with the given options applied.
    pub fn build(&self, py: Python<'_>) -> PyResult<CollisionRequest> {
        let mut r = CollisionRequest::default();
        if let Some(s) = &self.surface {
            r.classify.surface = parse_name(py, "surface", s, &SURFACES, Surface::name)?;
        }
        if let Some(s) = &self.aggregation {
            r.aggregation = parse_name(py, "aggregation", s, &AGGREGATIONS, Aggregation::name)?;
        }
        if let Some(s) = &self.robust_model {
            r.classify.robust_model =
                parse_name(py, "robust_model", s, &ROBUST_MODELS, RobustModel::name)?;
        }
        if let Some(s) = &self.solver {
            r.classify.solver = parse_name(py, "solver", s, &SOLVERS, SocpSolver::name)?;
        }
        if let Some(v) = self.threshold_collision {
            r.thresholds.collision = v;
        }
        if let Some(v) = self.threshold_free {
            r.thresholds.free = v;
        }
        if let Some(v) = self.prune_epsilon {
            r.prune_epsilon = v;
        }
        if let Some(v) = self.region_max_points {
            r.region_max_points = usize_option(py, "region_max_points", v)?;
        }
        if let Some(v) = self.near_context {
            r.near_context = v;
        }
        if let Some(v) = self.lambda {
            r.classify.lambda = v;
        }
        if let Some(v) = self.robust_eta {
            r.classify.robust_eta = v;
        }
        if let Some(v) = self.use_hierarchy {
            r.use_hierarchy = v;
        }
        if let Some(s) = &self.model {
            r.model = parse_name(py, "model", s, &MODELS, QueryModel::name)?;
        }
        if let Some(v) = self.decide_only {
            r.decide_only = v;
        }
        r.validate().or_py(py)?;
        Ok(r)
    }
}

/// The default value of every option of `collide` and `collide_many`, as a dict
/// keyed by the keyword names (`lambda_` for the slack weight), read from the Rust
/// `Default` implementations.
#[pyfunction]
pub fn default_options(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let r = CollisionRequest::default();
    let d = PyDict::new(py);
    d.set_item("surface", r.classify.surface.name())?;
    d.set_item("aggregation", r.aggregation.name())?;
    d.set_item("threshold_collision", r.thresholds.collision)?;
    d.set_item("threshold_free", r.thresholds.free)?;
    d.set_item("prune_epsilon", r.prune_epsilon)?;
    d.set_item("region_max_points", r.region_max_points)?;
    d.set_item("near_context", r.near_context)?;
    d.set_item("lambda_", r.classify.lambda)?;
    d.set_item("robust_eta", r.classify.robust_eta)?;
    d.set_item("robust_model", RobustModel::name(r.classify.robust_model))?;
    d.set_item("solver", r.classify.solver.name())?;
    d.set_item("use_hierarchy", r.use_hierarchy)?;
    d.set_item("model", r.model.name())?;
    d.set_item("decide_only", r.decide_only)?;
    Ok(d)
}

/// The valid names of the string options, as a dict of tuples.
#[pyfunction]
pub fn option_names(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("surface", PyTuple::new(py, SURFACES.map(Surface::name))?)?;
    d.set_item(
        "aggregation",
        PyTuple::new(py, AGGREGATIONS.map(Aggregation::name))?,
    )?;
    d.set_item(
        "robust_model",
        PyTuple::new(py, ROBUST_MODELS.map(RobustModel::name))?,
    )?;
    d.set_item("solver", PyTuple::new(py, SOLVERS.map(SocpSolver::name))?)?;
    d.set_item("model", PyTuple::new(py, MODELS.map(QueryModel::name))?)?;
    Ok(d)
}
