//! `RobotRequest` and `MotionRequest`: the options of the robot queries as
//! frozen objects, like `CollisionRequest`.
//!
//! Each layer keeps the options given to it as Python values (its *source*)
//! and the validated core request built from them. One parser per layer
//! ([`robot_from_source`], [`motion_from_source`]) reads a source: the
//! constructors, `replace(**changes)` and the keyword options of
//! `collide_robot`, `collide_robot_many` and `check_motion` all go through it
//! ([`robot_request_from`], [`motion_request_from`]), so an option is parsed
//! and checked in one place. The collision options go to `CollisionRequest`'s
//! own path (`request::with_changes`).

use std::sync::Arc;

use cloudprox::query::{CollisionRequest, MeshSide};
use cloudprox::robot::{GraspTarget, MotionRequest, RobotRequest, RobotShadow};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyMapping, PyTuple};

use crate::cloud::PyPointCloud;
use crate::convert::pose_from;
use crate::error::{invalid_input, CoreResultExt};
use crate::mesh::PyMesh;
use crate::occlusion::PyOcclusion;
use crate::request::{with_changes, PyCollisionRequest};

/// The options of the robot queries that are not `CollisionRequest` options,
/// in the order of `RobotRequest`'s constructor.
pub const ROBOT_OPTIONS: [&str; 11] = [
    "mesh_side",
    "mesh_spacing",
    "broad_phase",
    "self_collision",
    "padding",
    "target",
    "target_pose",
    "allowed_links",
    "shadow",
    "shadow_depth",
    "shadow_prior",
];
/// The options of `check_motion` beyond those of `collide_robot`.
pub const MOTION_OPTIONS: [&str; 3] = ["resolution", "max_probability", "warm_start"];

fn extract<'py, T: FromPyObjectOwned<'py>>(
    py: Python<'py>,
    v: &Bound<'py, PyAny>,
    key: &str,
    kind: &str,
) -> PyResult<T> {
    v.extract::<T>()
        .map_err(|_| invalid_input(py, format!("option {key} must be {kind}")))
}

/// The core robot request of the robot options in `source` (names of
/// [`ROBOT_OPTIONS`] to Python values, `None` values skipped) over the link
/// queries' request `collide`, validated: the one parser of the robot options.
fn robot_from_source(
    py: Python<'_>,
    collide: &CollisionRequest,
    source: &Bound<'_, PyDict>,
) -> PyResult<RobotRequest> {
    let mut out = RobotRequest {
        collide: *collide,
        ..RobotRequest::default()
    };
    let mut mesh_side: Option<String> = None;
    let mut target: Option<Bound<'_, PyAny>> = None;
    let mut target_pose: Option<Bound<'_, PyAny>> = None;
    let mut allowed: Option<Vec<String>> = None;
    let mut shadow: (Option<Bound<'_, PyAny>>, Option<f64>, Option<f64>) = (None, None, None);
    for (k, v) in source.iter() {
        let key: String = k.extract()?;
        if v.is_none() {
            continue;
        }
        match key.as_str() {
            "mesh_side" => mesh_side = Some(extract(py, &v, &key, "a str")?),
            "mesh_spacing" => out.mesh_spacing = Some(extract(py, &v, &key, "a float")?),
            "broad_phase" => out.broad_phase = extract(py, &v, &key, "a bool")?,
            "self_collision" => out.self_collision = extract(py, &v, &key, "a bool")?,
            "padding" => padding_from(py, &v, &mut out)?,
            "target" => target = Some(v),
            "target_pose" => target_pose = Some(v),
            "allowed_links" => allowed = Some(names_from(py, &v, "allowed_links")?),
            "shadow" => shadow.0 = Some(v),
            "shadow_depth" => shadow.1 = Some(extract(py, &v, &key, "a float (metres)")?),
            "shadow_prior" => shadow.2 = Some(extract(py, &v, &key, "a float in [0, 1]")?),
            _ => {
                return Err(invalid_input(
                    py,
                    format!(
                        "unknown robot option '{key}'; valid options: {}",
                        ROBOT_OPTIONS.join(", ")
                    ),
                ))
            }
        }
    }
    out.target = target_from(py, target.as_ref(), target_pose.as_ref(), allowed)?;
    out.shadow = shadow_from(py, shadow)?;
    out.mesh_side = link_side(py, mesh_side.as_deref(), out.mesh_spacing)?;
    out.validate().or_py(py)?;
    Ok(out)
}

/// `shadow=` (an `Occlusion`) with `shadow_depth=` and `shadow_prior=`.
fn shadow_from(
    py: Python<'_>,
    (occlusion, depth, prior): (Option<Bound<'_, PyAny>>, Option<f64>, Option<f64>),
) -> PyResult<Option<RobotShadow>> {
    let Some(occlusion) = occlusion else {
        if depth.is_some() || prior.is_some() {
            return Err(invalid_input(
                py,
                "shadow_depth and shadow_prior need a shadow (a filters.Occlusion)".to_string(),
            ));
        }
        return Ok(None);
    };
    let occ = occlusion.cast::<PyOcclusion>().map_err(|_| {
        invalid_input(
            py,
            "option shadow must be a filters.Occlusion of the scan".to_string(),
        )
    })?;
    let mut s = RobotShadow::new(Arc::clone(&occ.get().inner));
    s.depth = depth.unwrap_or(s.depth);
    s.prior = prior.unwrap_or(s.prior);
    Ok(Some(s))
}

/// `padding=`: a float for every link, or a mapping from link name to metres.
fn padding_from(py: Python<'_>, v: &Bound<'_, PyAny>, robot: &mut RobotRequest) -> PyResult<()> {
    if let Ok(map) = v.cast::<PyMapping>() {
        for item in map.items()?.iter() {
            let (name, d): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item.extract()?;
            let name: String = name.extract().map_err(|_| {
                invalid_input(py, "padding's keys must be link names (str)".to_string())
            })?;
            let d: f64 = d.extract().map_err(|_| {
                invalid_input(
                    py,
                    format!("padding of link '{name}' must be a float (metres)"),
                )
            })?;
            robot.link_padding.push((name, d));
        }
        return Ok(());
    }
    robot.padding = v.extract().map_err(|_| {
        invalid_input(
            py,
            "option padding must be a float (metres) or a dict from link name to metres"
                .to_string(),
        )
    })?;
    Ok(())
}

/// A list of names (`what` names the option in errors); a lone str is refused.
fn names_from(py: Python<'_>, v: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<String>> {
    if v.extract::<String>().is_ok() {
        return Err(invalid_input(
            py,
            format!("option {what} must be a list of link names, got a str"),
        ));
    }
    v.extract()
        .map_err(|_| invalid_input(py, format!("option {what} must be a list of link names")))
}

/// `target=` (a `PointCloud`, or a `Mesh` at `target_pose`) with
/// `allowed_links=`.
fn target_from(
    py: Python<'_>,
    target: Option<&Bound<'_, PyAny>>,
    pose: Option<&Bound<'_, PyAny>>,
    allowed: Option<Vec<String>>,
) -> PyResult<Option<GraspTarget>> {
    let Some(target) = target else {
        if allowed.is_some() || pose.is_some() {
            return Err(invalid_input(
                py,
                "allowed_links and target_pose need a target (a PointCloud or a Mesh)".to_string(),
            ));
        }
        return Ok(None);
    };
    let allowed = allowed.unwrap_or_default();
    if let Ok(c) = target.cast::<PyPointCloud>() {
        if pose.is_some() {
            return Err(invalid_input(
                py,
                "target_pose places a Mesh target: a PointCloud target is in the cloud's frame \
                 already (move it with PointCloud.transformed)"
                    .to_string(),
            ));
        }
        return Ok(Some(GraspTarget::cloud(
            Arc::clone(&c.get().inner),
            allowed,
        )));
    }
    if let Ok(m) = target.cast::<PyMesh>() {
        let pose = pose_from(py, pose, "target_pose")?;
        return Ok(Some(GraspTarget::mesh(
            Arc::clone(&m.get().inner),
            pose,
            allowed,
        )));
    }
    let ty = target.get_type().name()?;
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "target must be a PointCloud or a Mesh, got {ty}"
    )))
}

/// How the links stand: `mesh_side` by name, or (not given) exact unless a
/// `mesh_spacing` is given, which samples them, as `collide` reads a mesh.
fn link_side(py: Python<'_>, name: Option<&str>, spacing: Option<f64>) -> PyResult<MeshSide> {
    match name {
        None if spacing.is_some() => Ok(MeshSide::Sampled),
        None => Ok(MeshSide::Exact),
        Some(name) => name
            .parse::<MeshSide>()
            .map_err(|e| invalid_input(py, e.to_string())),
    }
}

/// The options of a robot query (``collide_robot``, ``collide_robot_many``,
/// the states of ``check_motion``), as one immutable value.
///
/// ``collide`` is the ``CollisionRequest`` of the link queries (default:
/// ``CollisionRequest()``); the other keywords are the robot's own options,
/// parsed and checked as the keyword options of ``collide_robot`` are: one
/// left out (or ``None``) takes the core's default. ``replace(**changes)``
/// takes both the robot's options and ``CollisionRequest``'s (applied to
/// ``collide``); ``to_dict()`` gives every option (``RobotRequest(**d)``
/// rebuilds it); requests pickle.
#[pyclass(name = "RobotRequest", frozen, module = "cloudprox._native")]
pub struct PyRobotRequest {
    /// The validated core request.
    pub inner: RobotRequest,
    /// The link queries' request.
    collide: Py<PyCollisionRequest>,
    /// The robot options given (names of [`ROBOT_OPTIONS`], no `None` values).
    source: Py<PyDict>,
}

impl PyRobotRequest {
    /// The request of the robot options `source` over `collide`.
    fn build(
        py: Python<'_>,
        collide: PyCollisionRequest,
        source: Bound<'_, PyDict>,
    ) -> PyResult<Self> {
        let inner = robot_from_source(py, &collide.inner, &source)?;
        Ok(Self {
            inner,
            collide: Py::new(py, collide)?,
            source: source.unbind(),
        })
    }

    /// The request of a plain `CollisionRequest` (every robot option at its default).
    fn of_collision(py: Python<'_>, collide: PyCollisionRequest) -> PyResult<Self> {
        Self::build(py, collide, PyDict::new(py))
    }

    /// A copy (the Python values shared).
    fn clone_ref(&self, py: Python<'_>) -> Self {
        Self {
            inner: self.inner.clone(),
            collide: self.collide.clone_ref(py),
            source: self.source.clone_ref(py),
        }
    }

    /// A given option's Python value, or `None`.
    fn given<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.source.bind(py).get_item(name)
    }

    /// Every option by name, in the order of the constructor.
    fn dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.inner;
        let d = PyDict::new(py);
        d.set_item("collide", self.collide.clone_ref(py))?;
        d.set_item("mesh_side", r.mesh_side.name())?;
        d.set_item("mesh_spacing", r.mesh_spacing)?;
        d.set_item("broad_phase", r.broad_phase)?;
        d.set_item("self_collision", r.self_collision)?;
        d.set_item("padding", self.padding(py)?)?;
        for name in ["target", "target_pose", "allowed_links", "shadow"] {
            d.set_item(name, self.given(py, name)?)?;
        }
        d.set_item("shadow_depth", r.shadow.as_ref().map(|s| s.depth))?;
        d.set_item("shadow_prior", r.shadow.as_ref().map(|s| s.prior))?;
        Ok(d)
    }
}

/// `base` with the options in `changes` applied (`None` values skipped): the
/// robot options to its source, the others to its `CollisionRequest`; a name
/// of neither (nor in `also_valid`) is an `InvalidInputError` listing the
/// valid names.
fn robot_with_changes(
    py: Python<'_>,
    base: &PyRobotRequest,
    changes: Option<&Bound<'_, PyDict>>,
    also_valid: &[&str],
) -> PyResult<PyRobotRequest> {
    let Some(changes) = changes.filter(|c| !c.is_empty()) else {
        return Ok(base.clone_ref(py));
    };
    let source = base.source.bind(py).copy()?;
    let collide_changes = PyDict::new(py);
    for (k, v) in changes.iter() {
        let key: String = k.extract()?;
        if v.is_none() {
            continue;
        }
        if ROBOT_OPTIONS.contains(&key.as_str()) {
            source.set_item(key, v)?;
        } else {
            collide_changes.set_item(key, v)?;
        }
    }
    let collide = with_changes(py, base.collide.get(), Some(&collide_changes), also_valid)?;
    PyRobotRequest::build(py, collide, source)
}

/// The robot request a query's `request=` stands for: a `RobotRequest`, a
/// `CollisionRequest` (the link queries' options, the robot's at their
/// defaults) or `None` (every default).
fn robot_base(py: Python<'_>, request: Option<&Bound<'_, PyAny>>) -> PyResult<PyRobotRequest> {
    match request {
        None => PyRobotRequest::of_collision(
            py,
            PyCollisionRequest {
                inner: CollisionRequest::default(),
            },
        ),
        Some(r) => {
            if let Ok(r) = r.cast::<PyRobotRequest>() {
                return Ok(r.get().clone_ref(py));
            }
            if let Ok(c) = r.cast::<PyCollisionRequest>() {
                return PyRobotRequest::of_collision(py, c.get().clone());
            }
            let ty = r.get_type().name()?;
            Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "request must be a CollisionRequest or a RobotRequest, got {ty}"
            )))
        }
    }
}

/// The request of `collide_robot` and `collide_robot_many`: `request` (see
/// [`robot_base`]) with the keyword options `options` applied on top.
pub fn robot_request_from(
    py: Python<'_>,
    request: Option<&Bound<'_, PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<RobotRequest> {
    let base = robot_base(py, request)?;
    let mut valid = vec!["request"];
    valid.extend(ROBOT_OPTIONS);
    Ok(robot_with_changes(py, &base, options, &valid)?.inner)
}

#[pymethods]
impl PyRobotRequest {
    #[new]
    #[pyo3(signature = (
        *, collide=None, mesh_side=None, mesh_spacing=None, broad_phase=None,
        self_collision=None, padding=None, target=None, target_pose=None, allowed_links=None,
        shadow=None, shadow_depth=None, shadow_prior=None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        py: Python<'py>,
        collide: Option<&Bound<'py, PyCollisionRequest>>,
        mesh_side: Option<Bound<'py, PyAny>>,
        mesh_spacing: Option<Bound<'py, PyAny>>,
        broad_phase: Option<Bound<'py, PyAny>>,
        self_collision: Option<Bound<'py, PyAny>>,
        padding: Option<Bound<'py, PyAny>>,
        target: Option<Bound<'py, PyAny>>,
        target_pose: Option<Bound<'py, PyAny>>,
        allowed_links: Option<Bound<'py, PyAny>>,
        shadow: Option<Bound<'py, PyAny>>,
        shadow_depth: Option<Bound<'py, PyAny>>,
        shadow_prior: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let values = [
            mesh_side,
            mesh_spacing,
            broad_phase,
            self_collision,
            padding,
            target,
            target_pose,
            allowed_links,
            shadow,
            shadow_depth,
            shadow_prior,
        ];
        let source = PyDict::new(py);
        for (name, value) in ROBOT_OPTIONS.iter().zip(values) {
            if let Some(v) = value.filter(|v| !v.is_none()) {
                source.set_item(name, v)?;
            }
        }
        let collide = collide.map_or_else(
            || PyCollisionRequest {
                inner: CollisionRequest::default(),
            },
            |c| c.get().clone(),
        );
        Self::build(py, collide, source)
    }

    /// The ``CollisionRequest`` of the link queries.
    #[getter]
    fn collide(&self, py: Python<'_>) -> Py<PyCollisionRequest> {
        self.collide.clone_ref(py)
    }

    /// How each link stands: ``"exact"`` (its exact surface) or ``"sampled"``.
    #[getter]
    fn mesh_side(&self) -> &'static str {
        self.inner.mesh_side.name()
    }

    /// Sampling spacing of sampled links (metres), or ``None``: half the
    /// cloud's median spacing.
    #[getter]
    fn mesh_spacing(&self) -> Option<f64> {
        self.inner.mesh_spacing
    }

    /// Whether links that cannot reach the cloud are skipped (``P = 0``).
    #[getter]
    fn broad_phase(&self) -> bool {
        self.inner.broad_phase
    }

    /// Whether self-collision between non-adjacent links is checked.
    #[getter]
    fn self_collision(&self) -> bool {
        self.inner.self_collision
    }

    /// The links' safety margin (metres): a float for every link, or a dict
    /// from link name to metres.
    #[getter]
    fn padding<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        if self.inner.link_padding.is_empty() {
            return Ok(self.inner.padding.into_pyobject(py)?.into_any());
        }
        let d = PyDict::new(py);
        for (name, v) in &self.inner.link_padding {
            d.set_item(name, v)?;
        }
        Ok(d.into_any())
    }

    /// The object about to be grasped (a ``PointCloud`` or a ``Mesh``), or ``None``.
    #[getter]
    fn target<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.given(py, "target")
    }

    /// The pose of a ``Mesh`` target, as given, or ``None``.
    #[getter]
    fn target_pose<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.given(py, "target_pose")
    }

    /// The links that may touch the target, as given, or ``None``.
    #[getter]
    fn allowed_links<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.given(py, "allowed_links")
    }

    /// The scan's ``filters.Occlusion`` whose shadow the links read, or ``None``.
    #[getter]
    fn shadow<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.given(py, "shadow")
    }

    /// With a shadow: the depth (metres) behind the observed surface a link
    /// sample may lie and count; ``None`` without.
    #[getter]
    fn shadow_depth(&self) -> Option<f64> {
        self.inner.shadow.as_ref().map(|s| s.depth)
    }

    /// With a shadow: the prior probability of a shadowed sample; ``None`` without.
    #[getter]
    fn shadow_prior(&self) -> Option<f64> {
        self.inner.shadow.as_ref().map(|s| s.prior)
    }

    /// A copy with the given options changed (``None`` leaves an option as it
    /// is): the robot's options and those of ``CollisionRequest`` (applied to
    /// ``collide``), validated like the constructor.
    #[pyo3(signature = (**changes))]
    fn replace(&self, py: Python<'_>, changes: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        robot_with_changes(py, self, changes, &ROBOT_OPTIONS)
    }

    /// Every option as a dict (``collide`` a ``CollisionRequest``);
    /// ``RobotRequest(**d)`` rebuilds the request.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.dict(py)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("RobotRequest({})", kwargs_repr(&self.dict(py)?)?))
    }

    /// Pickle support: the options, given back to the constructor.
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        let d = self.source.bind(py).copy()?;
        d.set_item("collide", self.collide.clone_ref(py))?;
        Ok((PyTuple::empty(py), d))
    }
}

/// `k=repr(v), ...` of a dict's items.
fn kwargs_repr(d: &Bound<'_, PyDict>) -> PyResult<String> {
    let parts = d
        .iter()
        .map(|(k, v)| Ok(format!("{}={}", k, v.repr()?)))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(parts.join(", "))
}

/// The core motion request of the motion options in `source` (names of
/// [`MOTION_OPTIONS`] to Python values) over the states' request `robot`,
/// validated: the one parser of the motion options.
fn motion_from_source(
    py: Python<'_>,
    robot: &RobotRequest,
    source: &Bound<'_, PyDict>,
) -> PyResult<MotionRequest> {
    let mut out = MotionRequest {
        robot: robot.clone(),
        ..MotionRequest::default()
    };
    for (k, v) in source.iter() {
        let key: String = k.extract()?;
        if v.is_none() {
            continue;
        }
        match key.as_str() {
            "resolution" => out.resolution = Some(extract(py, &v, &key, "a float")?),
            "max_probability" => out.max_probability = Some(extract(py, &v, &key, "a float")?),
            "warm_start" => out.warm_start = extract(py, &v, &key, "a bool")?,
            _ => {
                return Err(invalid_input(
                    py,
                    format!(
                        "unknown motion option '{key}'; valid options: {}",
                        MOTION_OPTIONS.join(", ")
                    ),
                ))
            }
        }
    }
    out.validate().or_py(py)?;
    Ok(out)
}

/// The options of ``check_motion``, as one immutable value.
///
/// ``robot`` is the ``RobotRequest`` of every state's query (default:
/// ``RobotRequest()``); ``resolution``, ``max_probability`` and
/// ``warm_start`` are the motion's own, parsed and checked as the keyword
/// options of ``check_motion`` are. ``replace(**changes)`` takes the options
/// of all three layers; requests pickle.
#[pyclass(name = "MotionRequest", frozen, module = "cloudprox._native")]
pub struct PyMotionRequest {
    /// The validated core request.
    pub inner: MotionRequest,
    /// Every state's request.
    robot: Py<PyRobotRequest>,
    /// The motion options given (names of [`MOTION_OPTIONS`], no `None` values).
    source: Py<PyDict>,
}

impl PyMotionRequest {
    /// The request of the motion options `source` over `robot`.
    fn build(py: Python<'_>, robot: PyRobotRequest, source: Bound<'_, PyDict>) -> PyResult<Self> {
        let inner = motion_from_source(py, &robot.inner, &source)?;
        Ok(Self {
            inner,
            robot: Py::new(py, robot)?,
            source: source.unbind(),
        })
    }

    /// Every option by name, in the order of the constructor.
    fn dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("robot", self.robot.clone_ref(py))?;
        d.set_item("resolution", self.inner.resolution)?;
        d.set_item("max_probability", self.inner.max_probability)?;
        d.set_item("warm_start", self.inner.warm_start)?;
        Ok(d)
    }
}

/// `base` with the options in `changes` applied (`None` values skipped): the
/// motion options to its source, the others to its `RobotRequest`.
fn motion_with_changes(
    py: Python<'_>,
    base: &PyMotionRequest,
    changes: Option<&Bound<'_, PyDict>>,
    also_valid: &[&str],
) -> PyResult<PyMotionRequest> {
    let source = base.source.bind(py).copy()?;
    let robot_changes = PyDict::new(py);
    if let Some(changes) = changes {
        for (k, v) in changes.iter() {
            let key: String = k.extract()?;
            if v.is_none() {
                continue;
            }
            if MOTION_OPTIONS.contains(&key.as_str()) {
                source.set_item(key, v)?;
            } else {
                robot_changes.set_item(key, v)?;
            }
        }
    }
    let robot = robot_with_changes(py, base.robot.get(), Some(&robot_changes), also_valid)?;
    PyMotionRequest::build(py, robot, source)
}

/// The request of `check_motion`: `request` (a `MotionRequest`, a
/// `RobotRequest`, a `CollisionRequest` or `None`) with the keyword options
/// `options` applied on top.
pub fn motion_request_from(
    py: Python<'_>,
    request: Option<&Bound<'_, PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<MotionRequest> {
    let mut valid = vec!["request"];
    valid.extend(ROBOT_OPTIONS);
    valid.extend(MOTION_OPTIONS);
    if let Some(m) = request.and_then(|r| r.cast::<PyMotionRequest>().ok()) {
        if options.is_none_or(PyDictMethods::is_empty) {
            return Ok(m.get().inner.clone());
        }
        return Ok(motion_with_changes(py, m.get(), options, &valid)?.inner);
    }
    let robot = robot_base(py, request).map_err(|e| {
        if e.is_instance_of::<pyo3::exceptions::PyTypeError>(py) {
            let ty = request
                .and_then(|r| r.get_type().name().ok())
                .map_or_else(|| "?".to_string(), |n| n.to_string());
            pyo3::exceptions::PyTypeError::new_err(format!(
                "request must be a CollisionRequest, a RobotRequest or a MotionRequest, got {ty}"
            ))
        } else {
            e
        }
    })?;
    let base = PyMotionRequest::build(py, robot, PyDict::new(py))?;
    Ok(motion_with_changes(py, &base, options, &valid)?.inner)
}

#[pymethods]
impl PyMotionRequest {
    #[new]
    #[pyo3(signature = (*, robot=None, resolution=None, max_probability=None, warm_start=None))]
    fn new<'py>(
        py: Python<'py>,
        robot: Option<&Bound<'py, PyRobotRequest>>,
        resolution: Option<Bound<'py, PyAny>>,
        max_probability: Option<Bound<'py, PyAny>>,
        warm_start: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let source = PyDict::new(py);
        for (name, value) in MOTION_OPTIONS
            .iter()
            .zip([resolution, max_probability, warm_start])
        {
            if let Some(v) = value.filter(|v| !v.is_none()) {
                source.set_item(name, v)?;
            }
        }
        let robot = match robot {
            Some(r) => r.get().clone_ref(py),
            None => robot_base(py, None)?,
        };
        Self::build(py, robot, source)
    }

    /// The ``RobotRequest`` of every state's query.
    #[getter]
    fn robot(&self, py: Python<'_>) -> Py<PyRobotRequest> {
        self.robot.clone_ref(py)
    }

    /// The largest displacement (metres) of a link point between two checked
    /// states, or ``None``: from the cloud's noise.
    #[getter]
    fn resolution(&self) -> Option<f64> {
        self.inner.resolution
    }

    /// A state is unsafe above this probability, or ``None``: the free threshold.
    #[getter]
    fn max_probability(&self) -> Option<f64> {
        self.inner.max_probability
    }

    /// Whether each state's classifier starts from the previous state's samples.
    #[getter]
    fn warm_start(&self) -> bool {
        self.inner.warm_start
    }

    /// A copy with the given options changed (``None`` leaves an option as it
    /// is): those of the motion, of ``RobotRequest`` and of ``CollisionRequest``.
    #[pyo3(signature = (**changes))]
    fn replace(&self, py: Python<'_>, changes: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut valid = ROBOT_OPTIONS.to_vec();
        valid.extend(MOTION_OPTIONS);
        motion_with_changes(py, self, changes, &valid)
    }

    /// Every option as a dict (``robot`` a ``RobotRequest``);
    /// ``MotionRequest(**d)`` rebuilds the request.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.dict(py)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("MotionRequest({})", kwargs_repr(&self.dict(py)?)?))
    }

    /// Pickle support: the options, given back to the constructor.
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        let d = self.source.bind(py).copy()?;
        d.set_item("robot", self.robot.clone_ref(py))?;
        Ok((PyTuple::empty(py), d))
    }
}
