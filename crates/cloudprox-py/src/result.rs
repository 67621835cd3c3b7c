//! `CollisionResult`, `ContactPatch` and `QueryStats`: the answer of a query,
//! as plain data.

use std::sync::Arc;

use cloudprox::classify::{Separator, SolveStatus, Surface};
use cloudprox::cloud::PointCloud;
use cloudprox::math::Pose;
use cloudprox::math::{Point3, Vector3};
use cloudprox::query::{
    CollisionResult, ContactPatch, PointProbabilities, QueryCounters, QueryStats,
};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::convert::{
    indices_to_py, points_from, points_to_py, rows3_to_py, vec_to_py, vector3_to_py,
};
use crate::error::{guard, CoreResultExt};

/// The values `(m,)` and gradients `(m, 3)` of a separating surface.
type Evaluation<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);

/// `x` with about 6 significant digits, like Python's `%.6g`.
/// A statistics counter as an exact 64-bit word of its pickled form, and back.
pub(crate) trait StateWord: Sized {
    /// The word.
    fn to_word(&self) -> u64;
    /// The counter from its word.
    fn from_word(word: u64) -> Self;
}

impl StateWord for usize {
    fn to_word(&self) -> u64 {
        *self as u64
    }
    fn from_word(word: u64) -> Self {
        word as usize
    }
}

impl StateWord for u64 {
    fn to_word(&self) -> u64 {
        *self
    }
    fn from_word(word: u64) -> Self {
        word
    }
}

impl StateWord for f64 {
    fn to_word(&self) -> u64 {
        self.to_bits()
    }
    fn from_word(word: u64) -> Self {
        f64::from_bits(word)
    }
}

pub(crate) fn fmt_g(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if !(1e-4..1e6).contains(&a) {
        format!("{x:.5e}")
    } else {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }
}

/// The `&'static str` of a state name (`"free"`, `"contact"`, `"collision"`).
pub(crate) fn state_name(py: Python<'_>, s: &str) -> PyResult<&'static str> {
    match s {
        "free" => Ok("free"),
        "contact" => Ok("contact"),
        "collision" => Ok("collision"),
        other => Err(crate::error::invalid_input(
            py,
            format!("unknown collision state '{other}'"),
        )),
    }
}

/// The pickled form of a separator: surface name, weights, offset, centre,
/// scale and frame (see [`crate::cloud::pose_to_7`]).
type SeparatorState = (String, Vec<f64>, f64, [f64; 3], f64, [f64; 7]);

/// The pickled form of a `ContactPatch`.
type PatchState = (
    u32,
    Vec<u32>,
    Vec<u32>,
    [f64; 3],
    [f64; 3],
    f64,
    f64,
    SeparatorState,
    String,
    u32,
);

/// The pickled form of per-point probabilities: the points, the stored
/// indices and their values.
type SparseState = (usize, Vec<u32>, Vec<f64>);

fn sparse_to_state(p: &PointProbabilities) -> SparseState {
    (p.len(), p.indices().to_vec(), p.values().to_vec())
}

fn sparse_from_state(
    py: Python<'_>,
    (len, indices, values): SparseState,
) -> PyResult<PointProbabilities> {
    PointProbabilities::from_sparse(len, indices, values).or_py(py)
}

/// The stored points of per-point probabilities: `(indices, probabilities)`.
type Nonzero<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>);

fn nonzero_to_py<'py>(py: Python<'py>, p: &PointProbabilities) -> Nonzero<'py> {
    (indices_to_py(py, p.indices()), vec_to_py(py, p.values()))
}

/// The pickled form of a `CollisionResult` (without the clouds it was computed on).
type ResultState = (
    f64,
    String,
    SparseState,
    SparseState,
    Vec<PatchState>,
    StatsState,
    Option<[f64; 3]>,
);

fn patch_to_state(r: &ContactPatch) -> PatchState {
    let sep = &r.separator;
    (
        r.component,
        r.indices_a.clone(),
        r.indices_b.clone(),
        [r.point.x, r.point.y, r.point.z],
        [r.normal.x, r.normal.y, r.normal.z],
        r.separation,
        r.probability,
        (
            sep.surface.name().to_string(),
            sep.w.clone(),
            sep.b,
            [sep.center.x, sep.center.y, sep.center.z],
            sep.scale,
            crate::cloud::pose_to_7(&sep.frame),
        ),
        r.status.name().to_string(),
        r.iterations,
    )
}

fn surface_from(py: Python<'_>, name: &str) -> PyResult<Surface> {
    Surface::from_name(name).ok_or_else(|| {
        crate::error::invalid_input(py, format!("unknown surface '{name}' in a pickled patch"))
    })
}

fn patch_from_state(py: Python<'_>, s: PatchState) -> PyResult<ContactPatch> {
    let (
        component,
        indices_a,
        indices_b,
        point,
        normal,
        separation,
        probability,
        sep,
        status,
        iterations,
    ) = s;
    let (surface, w, b, center, scale, frame) = sep;
    let surface = surface_from(py, &surface)?;
    let status = match status.as_str() {
        "solved" => SolveStatus::Solved,
        "almost_solved" => SolveStatus::AlmostSolved,
        "fallback" => SolveStatus::Fallback,
        other => {
            return Err(crate::error::invalid_input(
                py,
                format!("unknown solve status '{other}' in a pickled patch"),
            ))
        }
    };
    Ok(ContactPatch {
        component,
        indices_a,
        indices_b,
        point: Point3::new(point[0], point[1], point[2]),
        normal: Vector3::new(normal[0], normal[1], normal[2]),
        separation,
        probability,
        separator: Separator {
            surface,
            w,
            b,
            center: Point3::new(center[0], center[1], center[2]),
            scale,
            frame: crate::cloud::pose_from_7(&frame),
        },
        surface,
        status,
        iterations,
    })
}

stats_class! {
    /// Counters and timings of one ``collide`` query (``CollisionResult.stats``).
    "QueryStats": PyQueryStats(QueryStats { counters: QueryCounters }),
    state: StatsState,
    repr: [near_regions, patches, points_classified, solver_iterations],
    counters: {
        /// Node pairs of the two hierarchies tested during the traversal.
        node_pairs_visited: usize,
        /// Leaf pairs kept (not pruned).
        leaf_pairs: usize,
        /// Connected near regions.
        near_regions: usize,
        /// Patches classified (``len(result.patches)``).
        patches: usize,
        /// Patches cut in two because their surface put a point beyond the noise's
        /// reach of the other cloud on the wrong side.
        misfit_cuts: usize,
        /// Patches of the elements model pruned without a classifier (no element
        /// faces the other side within the noise's reach).
        patches_beyond_reach: usize,
        /// Element surface pairs found crossing (0 or 1 per segmentation): with the elements
        /// model, ``decide_only`` looks for one before any patch (a collision
        /// decided without a classifier), the full query where its patches
        /// found no collision.
        surface_crossings: usize,
        /// Element pairs whose surfaces face within the noise's reach although
        /// no sample of one of them was near the other (a metre-wide element
        /// that a thin part passes through): each brought both elements into
        /// the near set.
        surface_links: usize,
        /// Points of both clouds that went into a classifier.
        points_classified: usize,
        /// Interior-point iterations over all patches.
        solver_iterations: u64,
        /// Patches where the specialized solver did not converge and Clarabel
        /// was used.
        clarabel_fallbacks: usize,
        /// Patches whose solve fell back to the mean-difference plane
        /// (``ContactPatch.status == "fallback"``).
        solver_fallbacks: usize,
        /// Upper bound on the probability that any pruned point is on the wrong
        /// side (pruned points get ``p_i = 0``); below ``prune_epsilon`` per pair.
        pruned_bound: f64,
    }
}

/// One patch of a near region with its own separating surface (world frame).
#[pyclass(name = "ContactPatch", frozen, module = "cloudprox._native")]
pub struct PyContactPatch {
    inner: ContactPatch,
}

impl PyContactPatch {
    /// Wraps a core patch (the robot queries' patches).
    pub(crate) fn wrap(inner: ContactPatch) -> Self {
        Self { inner }
    }
}

#[pymethods]
impl PyContactPatch {
    /// Index of the connected near region this patch belongs to.
    #[getter]
    fn component(&self) -> u32 {
        self.inner.component
    }

    /// Indices of cloud A's points in the patch, shape `(k,)`, int64.
    #[getter]
    fn indices_a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        indices_to_py(py, &self.inner.indices_a)
    }

    /// Indices of cloud B's points in the patch, shape `(l,)`, int64.
    #[getter]
    fn indices_b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        indices_to_py(py, &self.inner.indices_b)
    }

    /// A point on the separating surface where the clouds come closest, shape `(3,)`.
    #[getter]
    fn point<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector3_to_py(py, &self.inner.point.coords)
    }

    /// Unit normal of the surface at `point`, from A towards B, shape `(3,)`.
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector3_to_py(py, &self.inner.normal)
    }

    /// Estimated signed separation of the two surfaces at this patch (metres),
    /// negative when they interpenetrate: measured along the near region's
    /// direction of least spread (oriented from A to B), not along ``normal``.
    #[getter]
    fn separation(&self) -> f64 {
        self.inner.separation
    }

    /// The patch's aggregated collision probability.
    #[getter]
    fn probability(&self) -> f64 {
        self.inner.probability
    }

    /// The surface family: `"linear"` or `"quadric"`.
    #[getter]
    fn surface(&self) -> &'static str {
        self.inner.surface.name()
    }

    /// How the solve ended: `"solved"`, `"almost_solved"` or `"fallback"`.
    #[getter]
    fn status(&self) -> &'static str {
        self.inner.status.name()
    }

    /// Interior-point iterations of the solve.
    #[getter]
    fn iterations(&self) -> u32 {
        self.inner.iterations
    }

    /// The separating surface `f` (positive on A's side) and its gradient at the
    /// `(m, 3)` points `x`: a tuple of shapes `(m,)` and `(m, 3)`.
    fn evaluate<'py>(&self, py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Evaluation<'py>> {
        let points = points_from(x, "x")?;
        let sep = &self.inner.separator;
        let (f, g): (Vec<f64>, Vec<_>) =
            guard(|| points.iter().map(|p| sep.value_and_gradient(p)).unzip())
                .map_err(crate::error::Panicked::into_py_err)?;
        Ok((vec_to_py(py, &f), rows3_to_py(py, g.into_iter())?))
    }

    /// Pickle support: every field, the separating surface included.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (PatchState,))> {
        Ok((
            slf.getattr("_from_state")?,
            (patch_to_state(&slf.get().inner),),
        ))
    }

    /// Rebuilds a pickled patch (see `__reduce__`).
    #[staticmethod]
    fn _from_state(py: Python<'_>, state: PatchState) -> PyResult<Self> {
        Ok(Self {
            inner: patch_from_state(py, state)?,
        })
    }

    fn __repr__(&self) -> String {
        let r = &self.inner;
        format!(
            "ContactPatch(component={}, points=({}, {}), probability={}, separation={}, \
             surface='{}', status='{}')",
            r.component,
            r.indices_a.len(),
            r.indices_b.len(),
            fmt_g(r.probability),
            fmt_g(r.separation),
            r.surface.name(),
            r.status.name()
        )
    }
}

/// The answer of `collide`: `P`, the state, per-point probabilities, the contact
/// patches and statistics.
#[pyclass(name = "CollisionResult", frozen, module = "cloudprox._native")]
pub struct PyCollisionResult {
    probability: f64,
    state: &'static str,
    probabilities_a: PointProbabilities,
    probabilities_b: PointProbabilities,
    patches: Vec<Py<PyContactPatch>>,
    stats: QueryStats,
    /// The points model's `max`, `union` and `independent` aggregates.
    point_aggregates: Option<[f64; 3]>,
    sides: Option<QueriedSides>,
}

/// The two sides of a query as queried (a sampled mesh side: its samples; an
/// exact mesh side: none) with their poses, kept (shared, not copied) so a
/// result can give its points.
pub struct QueriedSides {
    /// Side A's cloud in its own frame (`None` for an exact mesh).
    pub a: Option<Arc<PointCloud>>,
    /// Side B's cloud in its own frame (`None` for an exact mesh).
    pub b: Option<Arc<PointCloud>>,
    /// Side A's pose.
    pub pose_a: Pose,
    /// Side B's pose.
    pub pose_b: Pose,
}

impl PyCollisionResult {
    /// Wraps a core result (creates the patch objects once).
    pub fn new(py: Python<'_>, r: CollisionResult) -> PyResult<Self> {
        let patches = r
            .patches
            .into_iter()
            .map(|inner| Py::new(py, PyContactPatch { inner }))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(Self {
            probability: r.probability,
            state: r.state.name(),
            probabilities_a: r.probabilities_a,
            probabilities_b: r.probabilities_b,
            patches,
            stats: r.stats,
            point_aggregates: r.point_aggregates.map(|g| [g.max, g.union, g.independent]),
            sides: None,
        })
    }

    /// Wraps a core result and the sides it was computed on.
    pub fn with_sides(py: Python<'_>, r: CollisionResult, sides: QueriedSides) -> PyResult<Self> {
        let mut out = Self::new(py, r)?;
        out.sides = Some(sides);
        Ok(out)
    }

    fn world_points<'py>(
        &self,
        py: Python<'py>,
        side_a: bool,
    ) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let Some(s) = &self.sides else {
            return Ok(None);
        };
        let (cloud, pose) = if side_a {
            (&s.a, &s.pose_a)
        } else {
            (&s.b, &s.pose_b)
        };
        let Some(cloud) = cloud else {
            return Ok(None);
        };
        let moved: Vec<_> = cloud.points().iter().map(|p| pose * p).collect();
        points_to_py(py, &moved).map(Some)
    }
}

#[pymethods]
impl PyCollisionResult {
    /// The pair's collision probability `P` in `[0, 1]`.
    #[getter]
    fn probability(&self) -> f64 {
        self.probability
    }

    /// `"free"`, `"contact"` or `"collision"`.
    #[getter]
    fn state(&self) -> &'static str {
        self.state
    }

    /// Per-point probability of A's points being on the wrong side, shape `(n_a,)`
    /// (a new array each time: the result stores the near regions' points only).
    #[getter]
    fn probabilities_a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.probabilities_a.to_dense())
    }

    /// Per-point probability of B's points being on the wrong side, shape `(n_b,)`.
    #[getter]
    fn probabilities_b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.probabilities_b.to_dense())
    }

    /// The points of A with a non-zero probability and their probabilities:
    /// `(indices (m,) int64, probabilities (m,))`, by index; what
    /// `probabilities_a` holds without its zeros.
    #[getter]
    fn nonzero_a<'py>(&self, py: Python<'py>) -> Nonzero<'py> {
        nonzero_to_py(py, &self.probabilities_a)
    }

    /// The same for B.
    #[getter]
    fn nonzero_b<'py>(&self, py: Python<'py>) -> Nonzero<'py> {
        nonzero_to_py(py, &self.probabilities_b)
    }

    /// Side A's points as queried (a sampled mesh side: its samples), world
    /// frame, shape `(n_a, 3)`; `None` when the result does not record them
    /// (robot links, an exact mesh side).
    #[getter]
    fn points_a<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.world_points(py, true)
    }

    /// Side B's points as queried, world frame, shape `(n_b, 3)`, or `None`.
    #[getter]
    fn points_b<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.world_points(py, false)
    }

    /// Writes the interactive HTML view of the result and opens it in the web
    /// browser (`cloudprox.view.show`; needs `cloudprox[view]`). Returns the path.
    #[pyo3(signature = (path=None, **options))]
    fn show<'py>(
        slf: &Bound<'py, Self>,
        path: Option<&Bound<'py, PyAny>>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let show = py.import("cloudprox.view")?.getattr("show")?;
        let path = match path {
            Some(p) => p.clone(),
            None => py.None().into_bound(py),
        };
        show.call(PyTuple::new(py, [slf.clone().into_any(), path])?, options)
    }

    /// Pickle support: `P`, the state, the per-point probabilities, the patches
    /// and the statistics; not the clouds (`points_a` and `points_b` are `None`
    /// once unpickled).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (ResultState,))> {
        let me = slf.get();
        let patches = me
            .patches
            .iter()
            .map(|r| patch_to_state(&r.get().inner))
            .collect();
        let state = (
            me.probability,
            me.state.to_string(),
            sparse_to_state(&me.probabilities_a),
            sparse_to_state(&me.probabilities_b),
            patches,
            PyQueryStats::state_of(&me.stats),
            me.point_aggregates,
        );
        Ok((slf.getattr("_from_state")?, (state,)))
    }

    /// Rebuilds a pickled result (see `__reduce__`).
    #[staticmethod]
    fn _from_state(py: Python<'_>, state: ResultState) -> PyResult<Self> {
        let (probability, state_text, probabilities_a, probabilities_b, patches, stats, aggregates) =
            state;
        let patches = patches
            .into_iter()
            .map(|r| Py::new(py, PyContactPatch::wrap(patch_from_state(py, r)?)))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(Self {
            probability,
            state: state_name(py, &state_text)?,
            probabilities_a: sparse_from_state(py, probabilities_a)?,
            probabilities_b: sparse_from_state(py, probabilities_b)?,
            patches,
            stats: PyQueryStats::from_state(py, stats)?,
            point_aggregates: aggregates,
            sides: None,
        })
    }

    /// With the points model: `P` under each of the paper's aggregations
    /// (`{"max": ..., "union": ..., "independent": ...}`), from this query's
    /// per-point probabilities over the points `P` aggregates. A points-model
    /// query asking for one of them returns it as its `probability`, exactly,
    /// so one query gives all three. `None` with the elements model (its `P`
    /// aggregates surface crossings) and with `decide_only`.
    #[getter]
    fn point_aggregates<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some([max, union, independent]) = self.point_aggregates else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("max", max)?;
        d.set_item("union", union)?;
        d.set_item("independent", independent)?;
        Ok(Some(d))
    }

    /// The classified patches (a new list of the same patch objects each time).
    #[getter]
    fn patches<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.patches.iter().map(|r| r.clone_ref(py)))
    }

    /// Counters and timings of the query (a new `QueryStats` each time).
    #[getter]
    fn stats(&self) -> PyQueryStats {
        PyQueryStats::wrap(self.stats.clone())
    }

    fn __repr__(&self) -> String {
        format!(
            "CollisionResult(probability={}, state='{}', patches={}, points=({}, {}))",
            fmt_g(self.probability),
            self.state,
            self.patches.len(),
            self.probabilities_a.len(),
            self.probabilities_b.len()
        )
    }
}
