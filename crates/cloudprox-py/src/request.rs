//! `CollisionRequest`: the options of a collision query as one frozen object.
//!
//! Each option is defined once, by the keyword constructor of
//! [`PyCollisionRequest`]: an option left out takes the Rust default
//! (`CollisionRequest::default()`), enum names are parsed by the core's
//! `FromStr` (whose error names the valid names) and the whole request is
//! checked by the core's `validate()`. `replace(**changes)` and the keyword
//! shortcut of the queries ([`request_from`]) go through that constructor.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::str::FromStr;

use cloudprox::classify::{SocpSolver, Surface};
use cloudprox::probability::Aggregation;
use cloudprox::query::{CollisionRequest, QueryModel};
use cloudprox::uncertainty::RobustModel;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyFloat, PyTuple};

use crate::error::{invalid_input, CoreResultExt};

/// An enum option parsed by the core (`"quadric"` -> `Surface::Quadric`).
fn parse<T: FromStr<Err = cloudprox::Error>>(py: Python<'_>, name: &str) -> PyResult<T> {
    name.parse::<T>().or_py(py)
}

/// The options of a collision query (``collide``, ``collide_many`` and the robot
/// queries), as one immutable value.
///
/// Every option is keyword-only; one left out (or ``None``) takes the Rust
/// core's default, so ``CollisionRequest()`` shows the defaults. Names of the
/// enum options are checked here: an unknown name, a value out of its domain
/// or thresholds out of order raise ``InvalidInputError`` naming the option.
/// ``replace(**changes)`` gives a modified copy; ``to_dict()`` the options as
/// a JSON-ready dict; requests compare equal when every option is equal, hash,
/// and pickle.
#[pyclass(name = "CollisionRequest", frozen, module = "cloudprox._native")]
#[derive(Clone)]
pub struct PyCollisionRequest {
    /// The validated core request.
    pub inner: CollisionRequest,
}

impl PyCollisionRequest {
    /// Every option by name, in the order of the constructor, as Python values.
    fn dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.inner;
        let d = PyDict::new(py);
        d.set_item("surface", r.classify.surface.name())?;
        d.set_item("aggregation", r.aggregation.name())?;
        d.set_item("threshold_collision", r.thresholds.collision)?;
        d.set_item("threshold_free", r.thresholds.free)?;
        d.set_item("prune_epsilon", r.prune_epsilon)?;
        d.set_item("region_max_points", r.region_max_points)?;
        d.set_item("near_context", r.near_context)?;
        d.set_item("slack_weight", r.classify.slack_weight)?;
        d.set_item("robust_eta", r.classify.robust_eta)?;
        d.set_item("robust_model", r.classify.robust_model.name())?;
        d.set_item("solver", r.classify.solver.name())?;
        d.set_item("use_hierarchy", r.use_hierarchy)?;
        d.set_item("model", r.model.name())?;
        d.set_item("decide_only", r.decide_only)?;
        d.set_item("segmentations", r.segmentations)?;
        Ok(d)
    }
}

#[pymethods]
impl PyCollisionRequest {
    #[new]
    #[pyo3(signature = (
        *, surface=None, aggregation=None, threshold_collision=None, threshold_free=None,
        prune_epsilon=None, region_max_points=None, near_context=None, slack_weight=None,
        robust_eta=None, robust_model=None, solver=None, use_hierarchy=None, model=None,
        decide_only=None, segmentations=None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        surface: Option<&str>,
        aggregation: Option<&str>,
        threshold_collision: Option<f64>,
        threshold_free: Option<f64>,
        prune_epsilon: Option<f64>,
        region_max_points: Option<i64>,
        near_context: Option<f64>,
        slack_weight: Option<f64>,
        robust_eta: Option<f64>,
        robust_model: Option<&str>,
        solver: Option<&str>,
        use_hierarchy: Option<bool>,
        model: Option<&str>,
        decide_only: Option<bool>,
        segmentations: Option<i64>,
    ) -> PyResult<Self> {
        let mut r = CollisionRequest::default();
        if let Some(s) = surface {
            r.classify.surface = parse::<Surface>(py, s)?;
        }
        if let Some(s) = aggregation {
            r.aggregation = parse::<Aggregation>(py, s)?;
        }
        if let Some(v) = threshold_collision {
            r.thresholds.collision = v;
        }
        if let Some(v) = threshold_free {
            r.thresholds.free = v;
        }
        if let Some(v) = prune_epsilon {
            r.prune_epsilon = v;
        }
        if let Some(v) = region_max_points {
            r.region_max_points = usize::try_from(v).map_err(|_| {
                invalid_input(
                    py,
                    format!("region_max_points must be a non-negative integer, got {v}"),
                )
            })?;
        }
        if let Some(v) = near_context {
            r.near_context = v;
        }
        if let Some(v) = slack_weight {
            r.classify.slack_weight = v;
        }
        if let Some(v) = robust_eta {
            r.classify.robust_eta = v;
        }
        if let Some(s) = robust_model {
            r.classify.robust_model = parse::<RobustModel>(py, s)?;
        }
        if let Some(s) = solver {
            r.classify.solver = parse::<SocpSolver>(py, s)?;
        }
        if let Some(v) = use_hierarchy {
            r.use_hierarchy = v;
        }
        if let Some(s) = model {
            r.model = parse::<QueryModel>(py, s)?;
        }
        if let Some(v) = decide_only {
            r.decide_only = v;
        }
        if let Some(v) = segmentations {
            r.segmentations = u32::try_from(v).map_err(|_| {
                invalid_input(
                    py,
                    format!(
                        "segmentations must be in 1..={}, got {v}",
                        cloudprox::cloud::MAX_SEGMENTATIONS
                    ),
                )
            })?;
        }
        r.validate().or_py(py)?;
        Ok(Self { inner: r })
    }

    /// Family of the separating surface: ``"linear"`` (a plane) or
    /// ``"quadric"``.
    #[getter]
    fn surface(&self) -> &'static str {
        self.inner.classify.surface.name()
    }

    /// How per-point probabilities become ``P``: ``"max"``, ``"surface"``
    /// (model ``"points"`` only), ``"union"`` or ``"independent"``.
    #[getter]
    fn aggregation(&self) -> &'static str {
        self.inner.aggregation.name()
    }

    /// ``P`` at or above this reads ``"collision"``, in ``[0.5, 1]``.
    #[getter]
    fn threshold_collision(&self) -> f64 {
        self.inner.thresholds.collision
    }

    /// ``P`` at or below this reads ``"free"``, in ``[0, 0.5]``.
    #[getter]
    fn threshold_free(&self) -> f64 {
        self.inner.thresholds.free
    }

    /// A pair of hierarchy nodes is pruned when its crossing bound is below
    /// this, in ``[0, 1)``; the sum of what was pruned is
    /// ``QueryStats.pruned_bound``.
    #[getter]
    fn prune_epsilon(&self) -> f64 {
        self.inner.prune_epsilon
    }

    /// Near regions with more points are split into patches, each with its own
    /// surface (at least 8): a bound on the cost of one solve.
    #[getter]
    fn region_max_points(&self) -> usize {
        self.inner.region_max_points
    }

    /// Context kept around a near region, in sampling spacings (at least 0.5).
    #[getter]
    fn near_context(&self) -> f64 {
        self.inner.near_context
    }

    /// Weight of the classifier's slack term against ``|w|^2 / 2`` (``lambda``
    /// in the formulas), finite and > 0; large values approach a hard margin.
    #[getter]
    fn slack_weight(&self) -> f64 {
        self.inner.classify.slack_weight
    }

    /// Confidence ``eta`` of each point's chance constraint, in ``[0.5, 1)``.
    #[getter]
    fn robust_eta(&self) -> f64 {
        self.inner.classify.robust_eta
    }

    /// Noise assumption of the chance constraints: ``"gaussian"`` or
    /// ``"chebyshev"`` (any distribution; far more conservative).
    #[getter]
    fn robust_model(&self) -> &'static str {
        self.inner.classify.robust_model.name()
    }

    /// Solver of the classifier: ``"primal_dual"`` (specialised, falls back to
    /// Clarabel) or ``"clarabel"`` (the general conic reference).
    #[getter]
    fn solver(&self) -> &'static str {
        self.inner.classify.solver.name()
    }

    /// ``False`` tests every point pair instead of using the hierarchy (the
    /// brute-force reference).
    #[getter]
    fn use_hierarchy(&self) -> bool {
        self.inner.use_hierarchy
    }

    /// What is classified: ``"points"`` (the paper's method) or ``"elements"``
    /// (surface elements fitted to the points).
    #[getter]
    fn model(&self) -> &'static str {
        self.inner.model.name()
    }

    /// Return as soon as the state is decided: no per-point probabilities or
    /// separations; the state is that of the full query.
    #[getter]
    fn decide_only(&self) -> bool {
        self.inner.decide_only
    }

    /// With ``model="elements"``: how many segmentations of the clouds the
    /// query averages ``P`` and the per-point probabilities over (1 to 16).
    #[getter]
    fn segmentations(&self) -> u32 {
        self.inner.segmentations
    }

    /// A copy with the given options changed (``None`` leaves an option as
    /// it is), validated like the constructor.
    #[pyo3(signature = (**changes))]
    fn replace(&self, py: Python<'_>, changes: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        with_changes(py, self, changes, &[])
    }

    /// The options as a dict (names to ``str``, ``float``, ``int`` or ``bool``),
    /// ready for JSON; ``CollisionRequest(**d)`` rebuilds the request.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.dict(py)
    }

    /// The valid names of the enum options, by option, from the Rust enums.
    #[staticmethod]
    fn choices(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        fn names<T: Copy>(all: &[T], name: fn(T) -> &'static str) -> Vec<&'static str> {
            all.iter().map(|&v| name(v)).collect()
        }
        let d = PyDict::new(py);
        let lists = [
            (Surface::OPTION, names(Surface::ALL, Surface::name)),
            (
                Aggregation::OPTION,
                names(Aggregation::ALL, Aggregation::name),
            ),
            (
                RobustModel::OPTION,
                names(RobustModel::ALL, RobustModel::name),
            ),
            (SocpSolver::OPTION, names(SocpSolver::ALL, SocpSolver::name)),
            (QueryModel::OPTION, names(QueryModel::ALL, QueryModel::name)),
        ];
        for (option, list) in lists {
            d.set_item(option, PyTuple::new(py, list)?)?;
        }
        Ok(d)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let parts = self
            .dict(py)?
            .iter()
            .map(|(k, v)| Ok(format!("{}={}", k, v.repr()?)))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(format!("CollisionRequest({})", parts.join(", ")))
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    fn __hash__(&self, py: Python<'_>) -> PyResult<u64> {
        // Equal requests hash equal: floats by value (`-0.0 + 0.0` is `0.0`).
        let mut h = DefaultHasher::new();
        for (k, v) in self.dict(py)?.iter() {
            k.to_string().hash(&mut h);
            match v.extract::<f64>() {
                Ok(x) if v.is_instance_of::<PyFloat>() => (x + 0.0).to_bits().hash(&mut h),
                _ => v.to_string().hash(&mut h),
            }
        }
        Ok(h.finish())
    }

    /// Pickle support: the options, given back to the constructor.
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok((PyTuple::empty(py), self.dict(py)?))
    }
}

/// `base` with the options in `changes` applied (`None` values skipped); a name
/// that is neither an option nor in `also_valid` is an `InvalidInputError`
/// listing the valid names.
pub fn with_changes(
    py: Python<'_>,
    base: &PyCollisionRequest,
    changes: Option<&Bound<'_, PyDict>>,
    also_valid: &[&str],
) -> PyResult<PyCollisionRequest> {
    let Some(changes) = changes.filter(|c| !c.is_empty()) else {
        return Ok(base.clone());
    };
    let merged = base.dict(py)?;
    for (k, v) in changes.iter() {
        let key: String = k.extract()?;
        if !merged.contains(&key)? {
            let mut valid: Vec<String> = merged.keys().iter().map(|k| k.to_string()).collect();
            valid.extend(also_valid.iter().map(ToString::to_string));
            return Err(invalid_input(
                py,
                format!(
                    "unknown option '{key}'; valid options: {}",
                    valid.join(", ")
                ),
            ));
        }
        if !v.is_none() {
            merged.set_item(key, v)?;
        }
    }
    let made = py
        .get_type::<PyCollisionRequest>()
        .call((), Some(&merged))?;
    Ok(made.cast_into::<PyCollisionRequest>()?.get().clone())
}

/// The request of a query: `request` (default: the Rust defaults) with the
/// keyword options `options` applied on top (keywords override the request's
/// fields). `also_valid` names the query's other keywords, for the message of
/// an unknown name.
pub fn request_from(
    py: Python<'_>,
    request: Option<&Bound<'_, PyCollisionRequest>>,
    options: Option<&Bound<'_, PyDict>>,
    also_valid: &[&str],
) -> PyResult<CollisionRequest> {
    let base = match request {
        Some(r) => r.get().clone(),
        None => PyCollisionRequest {
            inner: CollisionRequest::default(),
        },
    };
    Ok(with_changes(py, &base, options, also_valid)?.inner)
}
