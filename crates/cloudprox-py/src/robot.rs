//! `Robot` (a URDF robot), `collide_robot`, `collide_robot_many`, `check_motion`.

use std::path::PathBuf;
use std::sync::Arc;

use cloudprox::cloud::PointCloud;
use cloudprox::math::Pose;
use cloudprox::robot::{
    check_motion as core_check_motion, collide_robot as core_collide_robot,
    collide_robot_many as core_collide_robot_many, AttachedShape, LinkCollision, Robot,
    RobotCollisionResult, RobotCounters, RobotStats, TargetCollision,
};
use cloudprox::Real;
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyMapping, PyTuple};

use crate::cloud::PyPointCloud;
use crate::convert::{check_shape, pose_from, pose_to_py, to_f64_array, vec_to_py};
use crate::error::{invalid_input, run_detached, CoreResultExt};
use crate::filter::PySelfFilter;
use crate::mesh::PyMesh;
use crate::result::{PyCollisionResult, PyContactPatch};
use crate::robot_request::{motion_request_from, robot_request_from};

/// A configuration of `robot`: a float64 array of shape `(dof,)` (its length
/// is checked by the core), or a mapping from joint name to value, the joints
/// it does not name at their reference value
/// ([`Robot::reference_configuration`]).
fn config_from(robot: &Robot, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    if let Ok(map) = obj.cast::<PyMapping>() {
        return config_from_mapping(robot, map, what);
    }
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[None], what, "(dof,)")?;
    array_data(&arr, what)
}

/// The configuration of a mapping from joint name to value (see [`config_from`]).
fn config_from_mapping(
    robot: &Robot,
    map: &Bound<'_, PyMapping>,
    what: &str,
) -> PyResult<Vec<f64>> {
    let py = map.py();
    let mut values = Vec::new();
    for item in map.items()?.iter() {
        let (key, value): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item.extract()?;
        let Ok(joint) = key.extract::<String>() else {
            let ty = key.get_type().name()?;
            return Err(invalid_input(
                py,
                format!("{what}: joint names must be str, got {ty}"),
            ));
        };
        let value = value.extract::<f64>().map_err(|_| {
            invalid_input(
                py,
                format!("{what}: the value of joint '{joint}' must be a float"),
            )
        })?;
        values.push((joint, value));
    }
    robot
        .configuration_from_names(values.iter().map(|(n, v)| (n.as_str(), *v)))
        .map_err(|e| match e {
            cloudprox::Error::InvalidInput(m) => invalid_input(py, format!("{what}: {m}")),
            other => invalid_input(py, format!("{what}: {other}")),
        })
}

/// The configurations of `collide_robot_many`: an `(m, dof)` array, or a
/// sequence whose rows are arrays or joint-name mappings.
fn configs_from(robot: &Robot, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vec<f64>>> {
    let rows_are_mappings = (obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>())
        && obj
            .try_iter()?
            .any(|row| row.is_ok_and(|r| r.cast::<PyMapping>().is_ok()));
    if rows_are_mappings {
        return obj
            .try_iter()?
            .enumerate()
            .map(|(i, row)| config_from(robot, &row?, &format!("{what}[{i}]")))
            .collect();
    }
    let dof = robot.dof();
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[None, Some(dof)], what, &format!("(m, {dof})"))?;
    let flat = array_data(&arr, what)?;
    Ok(if dof == 0 {
        vec![Vec::new(); arr.shape()[0]]
    } else {
        flat.chunks_exact(dof).map(<[f64]>::to_vec).collect()
    })
}

fn array_data(arr: &Bound<'_, PyArrayDyn<f64>>, what: &str) -> PyResult<Vec<f64>> {
    let ro = arr.readonly();
    ro.as_slice()
        .map(<[f64]>::to_vec)
        .map_err(|_| invalid_input(arr.py(), format!("{what} is not contiguous")))
}

fn cloud_from(obj: &Bound<'_, PyAny>) -> PyResult<Arc<PointCloud>> {
    if let Ok(c) = obj.cast::<PyPointCloud>() {
        return Ok(Arc::clone(&c.get().inner));
    }
    let ty = obj.get_type().name()?;
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "cloud must be a PointCloud, got {ty}; wrap arrays in PointCloud(points, sigma=...)"
    )))
}

/// A robot loaded from a URDF file: links, joints, limits and collision
/// geometry, prepared once for many queries.
#[pyclass(name = "Robot", frozen, module = "cloudprox._native")]
pub struct PyRobot {
    inner: Arc<Robot>,
    source: RobotSource,
}

/// What a robot was loaded from, to load it again after pickling: the URDF's
/// text and name, the folder relative mesh paths are resolved against, the
/// `package://` folders, and the SRDF's text and name if one was applied. Mesh
/// files are read again on unpickling.
#[derive(Clone)]
struct RobotSource {
    xml: String,
    name: String,
    base_dir: Option<PathBuf>,
    package_dirs: Vec<PathBuf>,
    srdf: Option<(String, String)>,
    /// Link pairs allowed to collide (`with_allowed_collisions`), after the SRDF's.
    allowed: Vec<(String, String)>,
    /// Objects attached (`attach`), in order, after the allowed pairs.
    attached: Vec<AttachedSource>,
}

/// One attached object of a `RobotSource`: the Python object given (pickled
/// with the robot) and its core shape (attached again on loading).
#[derive(Clone)]
struct AttachedSource {
    link: String,
    object: Arc<Py<PyAny>>,
    shape: AttachedShape,
    pose: Pose,
    name: String,
    touch_links: Vec<String>,
}

impl AttachedSource {
    /// The source of `obj` (a `Mesh` or a `PointCloud`) attached to `link`.
    fn new(
        link: String,
        obj: &Bound<'_, PyAny>,
        pose: Pose,
        name: String,
        touch_links: Vec<String>,
    ) -> PyResult<Self> {
        let shape = if let Ok(m) = obj.cast::<PyMesh>() {
            AttachedShape::Mesh((*m.get().inner).clone())
        } else if let Ok(c) = obj.cast::<PyPointCloud>() {
            AttachedShape::Cloud(Arc::clone(&c.get().inner))
        } else {
            let ty = obj.get_type().name()?;
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "an attached object must be a cloudprox.Mesh or a cloudprox.PointCloud, got {ty}"
            )));
        };
        Ok(Self {
            link,
            object: Arc::new(obj.clone().unbind()),
            shape,
            pose,
            name,
            touch_links,
        })
    }

    /// Attaches the object to `robot`.
    fn attach(&self, robot: &mut Robot) -> cloudprox::Result<()> {
        let touch: Vec<&str> = self.touch_links.iter().map(String::as_str).collect();
        robot.attach(
            &self.link,
            self.shape.clone(),
            &self.pose,
            &self.name,
            &touch,
        )
    }
}

/// The pickled form of an attached object: the link, the `Mesh` or
/// `PointCloud`, the `(4, 4)` pose, the name and the touch links.
type AttachedState<'py> = (
    String,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    String,
    Vec<String>,
);

impl RobotSource {
    /// The source of a robot loaded from `xml` (named `name` in errors), no
    /// pairs allowed beyond the SRDF's.
    fn new(
        xml: String,
        name: String,
        base_dir: Option<PathBuf>,
        package_dirs: Option<Vec<PathBuf>>,
        srdf: Option<(String, String)>,
    ) -> Self {
        Self {
            xml,
            name,
            base_dir,
            package_dirs: package_dirs.unwrap_or_default(),
            srdf,
            allowed: Vec::new(),
            attached: Vec::new(),
        }
    }
}

/// The name that stands for URDF text given as a string, in errors.
const URDF_STRING_NAME: &str = "<URDF string>";
/// The name that stands for SRDF text given as a string, in errors.
const SRDF_STRING_NAME: &str = "<SRDF string>";

/// The pickled form of a `Robot`: the arguments of `_from_urdf_text`.
type RobotState<'py> = (
    String,
    String,
    Option<PathBuf>,
    Vec<PathBuf>,
    Option<String>,
    Option<String>,
    Vec<(String, String)>,
    Vec<AttachedState<'py>>,
);

impl PyRobot {
    /// Name pairs of entry pairs (links, then attached objects).
    fn entry_names(&self, pairs: &[(usize, usize)]) -> Vec<(String, String)> {
        pairs
            .iter()
            .map(|&(a, b)| (entry_name(&self.inner, a), entry_name(&self.inner, b)))
            .collect()
    }

    fn names(&self, pairs: &[(usize, usize)]) -> Vec<(String, String)> {
        let names = self.inner.link_names();
        pairs
            .iter()
            .map(|&(a, b)| (names[a].to_string(), names[b].to_string()))
            .collect()
    }

    /// Loads the robot of `source` (the URDF, then the SRDF's pairs), with the
    /// GIL released.
    fn load(py: Python<'_>, source: RobotSource) -> PyResult<Self> {
        let (robot, source) = run_detached(py, move || {
            let s = &source;
            let mut robot =
                Robot::from_urdf_str(&s.xml, &s.name, s.base_dir.as_deref(), &s.package_dirs)?;
            if let Some((text, name)) = &s.srdf {
                robot.apply_srdf_str(text, name)?;
            }
            for (a, b) in &s.allowed {
                robot.allow_collision(a, b)?;
            }
            for object in &s.attached {
                object.attach(&mut robot)?;
            }
            Ok((robot, source))
        })?;
        Ok(Self {
            inner: Arc::new(robot),
            source,
        })
    }
}

/// The name of a query entry: a link's, or an attached object's.
fn entry_name(robot: &Robot, i: usize) -> String {
    robot.entry_name(i).unwrap_or("?").to_string()
}

/// The text of a file, read with the GIL released.
fn read_text(py: Python<'_>, path: PathBuf) -> PyResult<String> {
    run_detached(py, move || {
        std::fs::read_to_string(&path).map_err(|e| cloudprox::Error::io(&path, &e))
    })
}

/// The SRDF of a load: the file `path` or the text `text` (not both), as
/// `(text, name)`.
fn srdf_source(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<String>,
) -> PyResult<Option<(String, String)>> {
    match (path, text) {
        (Some(_), Some(_)) => Err(invalid_input(
            py,
            "give the SRDF as srdf (a path) or as srdf_string (its text), not both",
        )),
        (Some(path), None) => {
            let name = path.display().to_string();
            Ok(Some((read_text(py, path)?, name)))
        }
        (None, Some(text)) => Ok(Some((text, SRDF_STRING_NAME.to_string()))),
        (None, None) => Ok(None),
    }
}

#[pymethods]
impl PyRobot {
    /// Loads a URDF file; `package_dirs` are searched for `package://` URIs;
    /// the `<disable_collisions>` pairs of the SRDF file `srdf` (or of the SRDF
    /// text `srdf_string`) are not checked for self-collision.
    #[staticmethod]
    #[pyo3(signature = (path, package_dirs=None, srdf=None, *, srdf_string=None))]
    fn from_urdf(
        py: Python<'_>,
        path: PathBuf,
        package_dirs: Option<Vec<PathBuf>>,
        srdf: Option<PathBuf>,
        srdf_string: Option<String>,
    ) -> PyResult<Self> {
        let name = path.display().to_string();
        let base_dir = path.parent().map(std::path::Path::to_path_buf);
        // Read once: the text is parsed and kept for pickling.
        let xml = read_text(py, path)?;
        let srdf = srdf_source(py, srdf, srdf_string)?;
        Self::load(
            py,
            RobotSource::new(xml, name, base_dir, package_dirs, srdf),
        )
    }

    /// Loads a robot from URDF text; relative mesh paths are resolved against
    /// `base_dir`, `package_dirs` searched for `package://` URIs; `srdf` (a
    /// path) or `srdf_string` (SRDF text) as in `from_urdf`.
    #[staticmethod]
    #[pyo3(signature = (text, package_dirs=None, base_dir=None, srdf=None, *, srdf_string=None))]
    fn from_urdf_string(
        py: Python<'_>,
        text: String,
        package_dirs: Option<Vec<PathBuf>>,
        base_dir: Option<PathBuf>,
        srdf: Option<PathBuf>,
        srdf_string: Option<String>,
    ) -> PyResult<Self> {
        let srdf = srdf_source(py, srdf, srdf_string)?;
        let name = URDF_STRING_NAME.to_string();
        Self::load(
            py,
            RobotSource::new(text, name, base_dir, package_dirs, srdf),
        )
    }

    /// Pickle support: the URDF text, its name, the folder relative mesh paths
    /// are resolved against, the package folders, the SRDF text and name, the
    /// allowed pairs and the attached objects (each with its `Mesh` or
    /// `PointCloud`); the robot is loaded again on unpickling (its mesh files
    /// must be readable at the same paths).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, RobotState<'py>)> {
        let py = slf.py();
        let s = &slf.get().source;
        let (srdf_text, srdf_name) = s.srdf.clone().unzip();
        let attached = s
            .attached
            .iter()
            .map(|a| {
                Ok((
                    a.link.clone(),
                    a.object.clone_ref(py).into_bound(py),
                    pose_to_py(py, &a.pose)?.into_any(),
                    a.name.clone(),
                    a.touch_links.clone(),
                ))
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok((
            slf.getattr("_from_urdf_text")?,
            (
                s.xml.clone(),
                s.name.clone(),
                s.base_dir.clone(),
                s.package_dirs.clone(),
                srdf_text,
                srdf_name,
                s.allowed.clone(),
                attached,
            ),
        ))
    }

    /// Loads a robot from URDF text (see `__reduce__`); `name` stands for the
    /// file in errors, relative mesh paths are resolved against `base_dir`;
    /// the SRDF text `srdf_text` (named `srdf_name` in errors) is applied,
    /// then the `allowed` pairs, then the `attached` objects.
    #[staticmethod]
    #[pyo3(signature = (xml, name, base_dir=None, package_dirs=None, srdf_text=None, srdf_name=None, allowed=None, attached=None))]
    #[allow(clippy::too_many_arguments)]
    fn _from_urdf_text(
        py: Python<'_>,
        xml: String,
        name: String,
        base_dir: Option<PathBuf>,
        package_dirs: Option<Vec<PathBuf>>,
        srdf_text: Option<String>,
        srdf_name: Option<String>,
        allowed: Option<Vec<(String, String)>>,
        attached: Option<Vec<AttachedState<'_>>>,
    ) -> PyResult<Self> {
        let srdf = srdf_text.map(|t| (t, srdf_name.unwrap_or_else(|| SRDF_STRING_NAME.into())));
        let attached = attached
            .unwrap_or_default()
            .into_iter()
            .map(|(link, obj, pose, name, touch)| {
                let pose = pose_from(py, Some(&pose), "pose")?;
                AttachedSource::new(link, &obj, pose, name, touch)
            })
            .collect::<PyResult<Vec<_>>>()?;
        let source = RobotSource {
            allowed: allowed.unwrap_or_default(),
            attached,
            ..RobotSource::new(xml, name, base_dir, package_dirs, srdf)
        };
        Self::load(py, source)
    }

    /// The robot's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }

    /// Number of configuration entries.
    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    /// Names of the joints of the configuration entries, in order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner
            .joint_names()
            .into_iter()
            .map(str::to_string)
            .collect()
    }

    /// Names of the links, in URDF order.
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.inner
            .link_names()
            .into_iter()
            .map(str::to_string)
            .collect()
    }

    /// `(dof, 2)` lower and upper limits (infinite for continuous joints).
    #[getter]
    fn joint_limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows: Vec<Vec<f64>> = self
            .inner
            .joint_limits()
            .iter()
            .map(|l| l.to_vec())
            .collect();
        if rows.is_empty() {
            return Ok(PyArray2::zeros(py, [0, 2], false));
        }
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    /// Link pairs checked for self-collision, as name pairs.
    #[getter]
    fn self_collision_pairs(&self) -> Vec<(String, String)> {
        self.names(self.inner.self_collision_pairs())
    }

    /// Link pairs never checked for self-collision (adjacent, or touching at the
    /// reference configuration), as name pairs.
    #[getter]
    fn ignored_pairs(&self) -> Vec<(String, String)> {
        self.names(self.inner.ignored_pairs())
    }

    /// A copy of the robot that does not check the link pairs `pairs` (name
    /// pairs, either order) for self-collision; they join `ignored_pairs`.
    fn with_allowed_collisions(
        &self,
        py: Python<'_>,
        pairs: Vec<(String, String)>,
    ) -> PyResult<Self> {
        let mut robot = (*self.inner).clone();
        for (a, b) in &pairs {
            robot.allow_collision(a, b).or_py(py)?;
        }
        let mut source = self.source.clone();
        source.allowed.extend(pairs);
        Ok(Self {
            inner: Arc::new(robot),
            source,
        })
    }

    /// A copy of the robot holding `obj` (a `Mesh` or a `PointCloud`, in its
    /// own frame) on `link` at `pose` (the object's frame in the link's
    /// frame; `None`: identity), named `name`; `touch_links` may touch it
    /// without self-collision, besides `link`.
    #[pyo3(signature = (link, obj, pose=None, *, name, touch_links=None))]
    fn attach(
        &self,
        py: Python<'_>,
        link: String,
        obj: &Bound<'_, PyAny>,
        pose: Option<&Bound<'_, PyAny>>,
        name: String,
        touch_links: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let pose = pose_from(py, pose, "pose")?;
        let object = AttachedSource::new(link, obj, pose, name, touch_links.unwrap_or_default())?;
        let robot = Arc::clone(&self.inner);
        let (robot, object) = run_detached(py, move || {
            let mut robot = (*robot).clone();
            object.attach(&mut robot)?;
            Ok((robot, object))
        })?;
        let mut source = self.source.clone();
        source.attached.push(object);
        Ok(Self {
            inner: Arc::new(robot),
            source,
        })
    }

    /// A copy of the robot without the attached object `name`.
    fn detach(&self, py: Python<'_>, name: &str) -> PyResult<Self> {
        let mut robot = (*self.inner).clone();
        robot.detach(name).or_py(py)?;
        let mut source = self.source.clone();
        source.attached.retain(|a| a.name != name);
        Ok(Self {
            inner: Arc::new(robot),
            source,
        })
    }

    /// Names of the attached objects, in the order attached.
    #[getter]
    fn attached_objects(&self) -> Vec<String> {
        self.inner
            .attached_objects()
            .iter()
            .map(|o| o.name().to_string())
            .collect()
    }

    /// Every attached object's pose (4x4, object frame to world) at `q`, the
    /// root at `base_pose`, by name.
    #[pyo3(signature = (q, base_pose=None))]
    fn attached_poses<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        base_pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = config_from(&self.inner, q, "q")?;
        let base = pose_from(py, base_pose, "base_pose")?;
        let poses = self.inner.attached_poses(&q, &base).or_py(py)?;
        let d = PyDict::new(py);
        for (object, pose) in self.inner.attached_objects().iter().zip(&poses) {
            d.set_item(object.name(), pose_to_py(py, pose)?)?;
        }
        Ok(d)
    }

    /// Every link's pose (4x4, link frame to world) at `q`, the root at `base_pose`.
    #[pyo3(signature = (q, base_pose=None))]
    fn link_poses<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        base_pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = config_from(&self.inner, q, "q")?;
        let base = pose_from(py, base_pose, "base_pose")?;
        let poses = self.inner.link_poses(&q, &base).or_py(py)?;
        let d = PyDict::new(py);
        for (name, pose) in self.inner.link_names().into_iter().zip(&poses) {
            d.set_item(name, pose_to_py(py, pose)?)?;
        }
        Ok(d)
    }

    /// `q` clamped into the joint limits.
    fn clamp<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = config_from(&self.inner, q, "q")?;
        if q.len() != self.inner.dof() {
            return Err(invalid_input(
                py,
                format!(
                    "q must have {} entries (one per joint), got {}",
                    self.inner.dof(),
                    q.len()
                ),
            ));
        }
        Ok(vec_to_py(py, &self.inner.clamp(&q)))
    }

    /// The collision mesh of a link in its own frame, or `None` without geometry.
    fn link_mesh(&self, py: Python<'_>, link: &str) -> PyResult<Option<PyMesh>> {
        let i = self
            .inner
            .link_index(link)
            .ok_or_else(|| invalid_input(py, format!("robot has no link named '{link}'")))?;
        Ok(self.inner.links()[i]
            .geometry
            .as_ref()
            .map(|g| PyMesh::wrap(g.mesh.clone())))
    }

    /// Pairs of non-adjacent links whose exact meshes intersect at `q`.
    fn self_collisions(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<(String, String)>> {
        let q = config_from(&self.inner, q, "q")?;
        let pairs = self.inner.self_collisions(&q).or_py(py)?;
        let pairs: Vec<(usize, usize)> = pairs.iter().map(|p| (p.link_a, p.link_b)).collect();
        Ok(self.entry_names(&pairs))
    }

    /// The self-filter of the robot at `q` (root at `base_pose`, in the cloud's
    /// frame): removes the points within `padding` of a link, or inside a closed link
    /// (`None`: the core's `SELF_FILTER_DEFAULT_PADDING`).
    #[pyo3(signature = (q, padding=None, base_pose=None))]
    fn self_filter(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
        padding: Option<f64>,
        base_pose: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PySelfFilter> {
        let padding = padding.unwrap_or(cloudprox::filter::SELF_FILTER_DEFAULT_PADDING);
        let q = config_from(&self.inner, q, "q")?;
        let base = pose_from(py, base_pose, "base_pose")?;
        let robot = Arc::clone(&self.inner);
        let f = run_detached(py, move || robot.self_filter(&q, &base, padding))?;
        Ok(PySelfFilter::wrap(f))
    }

    fn __repr__(&self) -> String {
        let with_geometry = self
            .inner
            .links()
            .iter()
            .filter(|l| l.geometry.is_some())
            .count();
        let attached = match self.inner.attached_objects().len() {
            0 => String::new(),
            n => format!(", attached={n}"),
        };
        format!(
            "Robot(name='{}', dof={}, links={}, with_geometry={}{attached})",
            self.inner.name(),
            self.inner.dof(),
            self.inner.links().len(),
            with_geometry
        )
    }
}

/// One link's part of a `RobotCollisionResult`.
#[pyclass(name = "LinkCollision", frozen, module = "cloudprox._native")]
pub struct PyLinkCollision {
    name: String,
    inner: LinkCollision,
}

#[pymethods]
impl PyLinkCollision {
    /// The link's name.
    #[getter]
    fn link(&self) -> &str {
        &self.name
    }

    /// The link's collision probability (0 when the broad phase skipped it).
    #[getter]
    fn probability(&self) -> f64 {
        self.inner.probability
    }

    /// With ``shadow=``, the link's shadow probability (the prior times the
    /// largest probability of a surface sample lying in the scan's shadow),
    /// already in ``probability``; 0 without.
    #[getter]
    fn shadow(&self) -> f64 {
        self.inner.shadow
    }

    /// `"free"`, `"contact"` or `"collision"`.
    #[getter]
    fn state(&self) -> &'static str {
        self.inner.state.name()
    }

    /// Whether the link was queried (it passed the broad phase).
    #[getter]
    fn queried(&self) -> bool {
        self.inner.queried
    }

    /// The full query result of the link (side A is the link: its exact
    /// surface, or its sample for sampled links), or `None` when the broad
    /// phase skipped it.
    #[getter]
    fn result(&self, py: Python<'_>) -> PyResult<Option<PyCollisionResult>> {
        self.inner
            .result
            .clone()
            .map(|r| PyCollisionResult::new(py, r))
            .transpose()
    }

    /// With a grasp target: the link's query against it, as a
    /// `LinkCollision` (its own `target` is `None`); `None` without a target.
    #[getter]
    fn target(&self) -> Option<PyLinkCollision> {
        self.inner.target.as_ref().map(|t| PyLinkCollision {
            name: self.name.clone(),
            inner: (**t).clone(),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "LinkCollision(link='{}', probability={:.6}, state='{}', queried={})",
            self.name,
            self.inner.probability,
            self.inner.state.name(),
            if self.inner.queried { "True" } else { "False" }
        )
    }
}

stats_class! {
    /// Counters and timings of one ``collide_robot`` query
    /// (``RobotCollisionResult.stats``).
    "RobotStats": PyRobotStats(RobotStats { counters: RobotCounters }),
    state: RobotStatsState,
    repr: [links_with_geometry, links_queried],
    counters: {
        /// Links with geometry, and attached objects.
        links_with_geometry: usize,
        /// Links queried against the cloud (the others were skipped by the broad
        /// phase, or left once the query was decided), plus, with a grasp
        /// target, those queried against it.
        links_queried: usize,
        /// Links left unqueried because an earlier link's probability had reached
        /// the collision threshold (``decide_only`` only).
        links_after_decision: usize,
        /// Hierarchy nodes of the cloud visited by the broad phase.
        broad_phase_nodes: usize,
        /// Link pairs tested for self-collision.
        self_pairs_checked: usize,
        /// Node pairs visited by the per-link queries, summed.
        node_pairs_visited: usize,
        /// Interior-point iterations of the per-link queries' classifiers,
        /// summed (0 for exact links).
        solver_iterations: u64,
    }
}

/// The answer of `collide_robot`.
#[pyclass(name = "RobotCollisionResult", frozen, module = "cloudprox._native")]
pub struct PyRobotCollisionResult {
    probability: f64,
    state: &'static str,
    links: Vec<Py<PyLinkCollision>>,
    self_collisions: Vec<(String, String)>,
    target: Option<TargetCollision>,
    stats: RobotStats,
}

impl PyRobotCollisionResult {
    fn new(py: Python<'_>, robot: &Robot, r: RobotCollisionResult) -> PyResult<Self> {
        let links = r
            .links
            .into_iter()
            .map(|l| {
                Py::new(
                    py,
                    PyLinkCollision {
                        name: entry_name(robot, l.link),
                        inner: l,
                    },
                )
            })
            .collect::<PyResult<Vec<_>>>()?;
        let self_collisions = r
            .self_collisions
            .iter()
            .map(|p| (entry_name(robot, p.link_a), entry_name(robot, p.link_b)))
            .collect();
        Ok(Self {
            probability: r.probability,
            state: r.state.name(),
            links,
            self_collisions,
            target: r.target,
            stats: r.stats,
        })
    }
}

#[pymethods]
impl PyRobotCollisionResult {
    /// The robot's collision probability with the environment.
    #[getter]
    fn probability(&self) -> f64 {
        self.probability
    }

    /// `"free"`, `"contact"` or `"collision"`.
    #[getter]
    fn state(&self) -> &'static str {
        self.state
    }

    /// Per link with geometry: its `LinkCollision`, by link name (URDF order).
    #[getter]
    fn links<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for l in &self.links {
            d.set_item(l.get().name.as_str(), l.clone_ref(py))?;
        }
        Ok(d)
    }

    /// The contact patches of every queried link, as `(link name, ContactPatch)`.
    #[getter]
    fn patches<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let mut out = Vec::new();
        for l in &self.links {
            let l = l.get();
            if let Some(r) = &l.inner.result {
                for g in &r.patches {
                    let patch = Py::new(py, PyContactPatch::wrap(g.clone()))?;
                    out.push(PyTuple::new(
                        py,
                        [
                            l.name.clone().into_pyobject(py)?.into_any(),
                            patch.into_bound(py).into_any(),
                        ],
                    )?);
                }
            }
        }
        PyList::new(py, out)
    }

    /// Pairs of non-adjacent links that intersect (exact meshes), as name pairs;
    /// reported apart from `probability`.
    #[getter]
    fn self_collisions(&self) -> Vec<(String, String)> {
        self.self_collisions.clone()
    }

    /// With a grasp target (`target=`): the allowed links' contact with it,
    /// reported apart from `probability`, and the other links' collision with
    /// it (counted in `probability`); `None` without a target.
    #[getter]
    fn target(&self) -> Option<PyTargetCollision> {
        self.target.map(|inner| PyTargetCollision { inner })
    }

    /// Counters and timings (a new `RobotStats` each time).
    #[getter]
    fn stats(&self) -> PyRobotStats {
        PyRobotStats::wrap(self.stats.clone())
    }

    fn __repr__(&self) -> String {
        format!(
            "RobotCollisionResult(probability={:.6}, state='{}', links={}, self_collisions={})",
            self.probability,
            self.state,
            self.links.len(),
            self.self_collisions.len()
        )
    }
}

/// The grasp target's part of a `RobotCollisionResult`.
#[pyclass(name = "TargetCollision", frozen, module = "cloudprox._native")]
pub struct PyTargetCollision {
    inner: TargetCollision,
}

#[pymethods]
impl PyTargetCollision {
    /// The allowed links' contact probability with the target (not counted in
    /// the robot's probability).
    #[getter]
    fn probability(&self) -> f64 {
        self.inner.probability
    }

    /// `"free"`, `"contact"` or `"collision"`, from `probability`.
    #[getter]
    fn state(&self) -> &'static str {
        self.inner.state.name()
    }

    /// The other links' collision probability with the target (counted in
    /// the robot's probability).
    #[getter]
    fn other_probability(&self) -> f64 {
        self.inner.other_probability
    }

    fn __repr__(&self) -> String {
        format!(
            "TargetCollision(probability={:.6}, state='{}', other_probability={:.6})",
            self.inner.probability,
            self.inner.state.name(),
            self.inner.other_probability
        )
    }
}

fn robot_arg(robot: &Bound<'_, PyAny>) -> PyResult<Arc<Robot>> {
    let r = robot
        .cast::<PyRobot>()
        .map_err(|_| pyo3::exceptions::PyTypeError::new_err("robot must be a cloudprox.Robot"))?;
    Ok(Arc::clone(&r.get().inner))
}

/// The robot at configuration `q` (root at `base_pose`) against the cloud.
#[pyfunction]
#[pyo3(signature = (robot, q, cloud, base_pose=None, *, request=None, **options))]
pub fn collide_robot(
    py: Python<'_>,
    robot: &Bound<'_, PyAny>,
    q: &Bound<'_, PyAny>,
    cloud: &Bound<'_, PyAny>,
    base_pose: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyRobotCollisionResult> {
    let robot = robot_arg(robot)?;
    let request = robot_request_from(py, request, options)?;
    let q = config_from(&robot, q, "q")?;
    let base = pose_from(py, base_pose, "base_pose")?;
    let cloud = cloud_from(cloud)?;
    let r2 = Arc::clone(&robot);
    let result = run_detached(py, move || {
        core_collide_robot(&r2, &q, &base, &cloud, &request)
    })?;
    PyRobotCollisionResult::new(py, &robot, result)
}

/// The answer of `collide_robot_many`: arrays over the configurations.
#[pyclass(name = "RobotBatchResult", frozen, module = "cloudprox._native")]
pub struct PyRobotBatchResult {
    probabilities: Vec<f64>,
    states: Vec<&'static str>,
    self_colliding: Vec<bool>,
    /// With a grasp target: per configuration, the allowed links' contact
    /// probability with it.
    target_probabilities: Option<Vec<f64>>,
    link_probabilities: Vec<f64>,
    n_links: usize,
}

/// The pickled form of a `RobotBatchResult`.
type BatchState = (
    Vec<f64>,
    Vec<String>,
    Vec<bool>,
    Vec<f64>,
    usize,
    Option<Vec<f64>>,
);
/// The state of a batch result pickled before grasp targets.
type BatchStateV1 = (Vec<f64>, Vec<String>, Vec<bool>, Vec<f64>, usize);

#[pymethods]
impl PyRobotBatchResult {
    /// Pickle support: the arrays.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (BatchState,))> {
        let me = slf.get();
        let state = (
            me.probabilities.clone(),
            me.states.iter().map(|s| (*s).to_string()).collect(),
            me.self_colliding.clone(),
            me.link_probabilities.clone(),
            me.n_links,
            me.target_probabilities.clone(),
        );
        Ok((slf.getattr("_from_state")?, (state,)))
    }

    /// Rebuilds a pickled batch result (see `__reduce__`).
    #[staticmethod]
    fn _from_state(py: Python<'_>, state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let state: BatchState = match state.extract::<BatchStateV1>() {
            Ok((p, s, c, l, n)) => (p, s, c, l, n, None),
            Err(_) => state.extract()?,
        };
        let (probabilities, states, self_colliding, link_probabilities, n_links, target) = state;
        let states = states
            .iter()
            .map(|s| crate::result::state_name(py, s))
            .collect::<PyResult<Vec<_>>>()?;
        if states.len() != probabilities.len()
            || self_colliding.len() != probabilities.len()
            || link_probabilities.len() != probabilities.len() * n_links
            || target
                .as_ref()
                .is_some_and(|t| t.len() != probabilities.len())
        {
            return Err(invalid_input(
                py,
                "a pickled RobotBatchResult of inconsistent lengths",
            ));
        }
        Ok(Self {
            probabilities,
            states,
            self_colliding,
            target_probabilities: target,
            link_probabilities,
            n_links,
        })
    }

    /// `(m,)` with a grasp target (`target=`): the allowed links' contact
    /// probability with it per configuration (not in `probabilities`); `None`
    /// without a target.
    #[getter]
    fn target_probabilities<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.target_probabilities.as_ref().map(|t| vec_to_py(py, t))
    }

    /// `(m,)` collision probabilities.
    #[getter]
    fn probabilities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_to_py(py, &self.probabilities)
    }

    /// `(m,)` states (`"free"`, `"contact"`, `"collision"`), a numpy string array.
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("numpy")?
            .call_method1("array", (self.states.clone(),))
    }

    /// `(m,)` whether non-adjacent links intersect.
    #[getter]
    fn self_colliding<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_slice(py, &self.self_colliding)
    }

    /// `(m, n_links)` per-link probabilities, links in `Robot.link_names` order
    /// (0 for links without geometry and links the broad phase skipped).
    #[getter]
    fn link_probabilities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let m = self.probabilities.len();
        PyArray1::from_slice(py, &self.link_probabilities).reshape([m, self.n_links])
    }

    fn __len__(&self) -> usize {
        self.probabilities.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "RobotBatchResult(configurations={}, links={})",
            self.probabilities.len(),
            self.n_links
        )
    }
}

/// `collide_robot` for each row of the `(m, dof)` array `qs`, in parallel
/// (rayon) with the GIL released.
#[pyfunction]
#[pyo3(signature = (robot, qs, cloud, base_pose=None, *, request=None, **options))]
pub fn collide_robot_many(
    py: Python<'_>,
    robot: &Bound<'_, PyAny>,
    qs: &Bound<'_, PyAny>,
    cloud: &Bound<'_, PyAny>,
    base_pose: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyRobotBatchResult> {
    let robot = robot_arg(robot)?;
    let request = robot_request_from(py, request, options)?;
    let has_target = request.target.is_some();
    let qs = configs_from(&robot, qs, "qs")?;
    let base = pose_from(py, base_pose, "base_pose")?;
    let cloud = cloud_from(cloud)?;
    let r2 = Arc::clone(&robot);
    let results = run_detached(py, move || {
        core_collide_robot_many(&r2, &qs, &base, &cloud, &request)
    })?;
    let n_links = robot.links().len();
    let mut link_probabilities = vec![0.0; results.len() * n_links];
    for (i, r) in results.iter().enumerate() {
        // Attached objects (entries beyond the links) enter the probabilities only.
        for l in r.links.iter().filter(|l| l.link < n_links) {
            link_probabilities[i * n_links + l.link] = l.probability;
        }
    }
    Ok(PyRobotBatchResult {
        probabilities: results.iter().map(|r| r.probability).collect(),
        states: results.iter().map(|r| r.state.name()).collect(),
        self_colliding: results
            .iter()
            .map(RobotCollisionResult::self_colliding)
            .collect(),
        target_probabilities: has_target.then(|| {
            results
                .iter()
                .map(|r| r.target.map_or(Real::NAN, |t| t.probability))
                .collect()
        }),
        link_probabilities,
        n_links,
    })
}

/// The answer of `check_motion`.
#[pyclass(name = "MotionResult", frozen, module = "cloudprox._native")]
pub struct PyMotionResult {
    inner: cloudprox::robot::MotionResult,
}

#[pymethods]
impl PyMotionResult {
    /// Whether every checked state is safe.
    #[getter]
    fn safe(&self) -> bool {
        self.inner.safe
    }

    /// The largest collision probability of the states checked.
    #[getter]
    fn probability(&self) -> f64 {
        self.inner.probability
    }

    /// Fraction along the motion of the first unsafe state, or `None`.
    #[getter]
    fn first_unsafe(&self) -> Option<f64> {
        self.inner.first_unsafe
    }

    /// The state at the first unsafe state, or the worst state's when safe.
    #[getter]
    fn state(&self) -> &'static str {
        self.inner.state.name()
    }

    /// States checked.
    #[getter]
    fn states_checked(&self) -> usize {
        self.inner.states_checked
    }

    /// States the motion was divided into (both ends included).
    #[getter]
    fn states_total(&self) -> usize {
        self.inner.states_total
    }

    /// The largest displacement (metres) of a link point between two states.
    #[getter]
    fn resolution(&self) -> f64 {
        self.inner.resolution
    }

    /// Interior-point iterations of the classifiers of every state checked, summed.
    #[getter]
    fn solver_iterations(&self) -> u64 {
        self.inner.solver_iterations
    }

    fn __repr__(&self) -> String {
        format!(
            "MotionResult(safe={}, probability={:.6}, first_unsafe={}, states={}/{})",
            if self.inner.safe { "True" } else { "False" },
            self.inner.probability,
            self.inner
                .first_unsafe
                .map_or("None".to_string(), |t| format!("{t:.6}")),
            self.inner.states_checked,
            self.inner.states_total
        )
    }
}

/// The straight joint-space motion from `q0` to `q1` against the cloud.
#[pyfunction]
#[pyo3(signature = (robot, q0, q1, cloud, base_pose=None, *, request=None, **options))]
pub fn check_motion(
    py: Python<'_>,
    robot: &Bound<'_, PyAny>,
    q0: &Bound<'_, PyAny>,
    q1: &Bound<'_, PyAny>,
    cloud: &Bound<'_, PyAny>,
    base_pose: Option<&Bound<'_, PyAny>>,
    request: Option<&Bound<'_, PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyMotionResult> {
    let robot = robot_arg(robot)?;
    let request = motion_request_from(py, request, options)?;
    let q0 = config_from(&robot, q0, "q0")?;
    let q1 = config_from(&robot, q1, "q1")?;
    let base = pose_from(py, base_pose, "base_pose")?;
    let cloud = cloud_from(cloud)?;
    let inner = run_detached(py, move || {
        core_check_motion(&robot, &q0, &q1, &base, &cloud, &request)
    })?;
    Ok(PyMotionResult { inner })
}
