//! `Mesh`, `ExactShape` and the exact mesh-vs-mesh queries.

use std::sync::{Arc, Mutex, OnceLock};

use cloudprox::cloud::PointCloud;

use cloudprox::query::exact::{
    exact_intersects_many, exact_proximity as core_exact, exact_proximity_many, ExactProximity,
    ExactShape,
};
use cloudprox::shape::{Mesh, MeshDistance};
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyIterator, PyTuple};

use crate::convert::{
    points_from, points_to_py, pose_from, poses_from, rows3_to_py, shape_str, vec_to_py,
};
use crate::error::{invalid_input, run_detached};

tuple_class! {
    /// What ``Mesh.sample`` returns: the samples, their surface normals and the
    /// face each lies on. Unpacks as ``points, normals, faces = mesh.sample(...)``.
    "MeshSample": PyMeshSample {
        /// The sampled points, shape ``(k, 3)``.
        points: Py<PyArray2<f64>>,
        /// The unit normal of the face under each point, shape ``(k, 3)``.
        normals: Py<PyArray2<f64>>,
        /// The index of the face each point lies on, shape ``(k,)``, int64.
        faces: Py<PyArray1<i64>>,
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!("MeshSample(points={})", self.points.bind(py).shape()[0])
    }
}

/// The pickled form of a `Proximity`: intersecting, distance, penetration depth.
type ProximityState = (bool, f64, Option<f64>);

/// The answer of ``exact_proximity``: whether two exact shapes intersect and
/// how far apart (or how deep) they are.
#[pyclass(name = "Proximity", frozen, module = "cloudprox._native")]
pub struct PyProximity {
    inner: ExactProximity,
}

#[pymethods]
impl PyProximity {
    /// Whether the two solids (or surfaces, for open parts) intersect.
    #[getter]
    fn intersecting(&self) -> bool {
        self.inner.intersecting
    }

    /// The distance between the shapes in metres; 0 when they intersect.
    #[getter]
    fn distance(&self) -> f64 {
        self.inner.distance
    }

    /// When intersecting: the largest penetration depth over the intersecting
    /// pairs of parts, if every such pair is convex; ``None`` otherwise.
    #[getter]
    fn penetration_depth(&self) -> Option<f64> {
        self.inner.penetration_depth
    }

    /// ``distance`` when apart, ``-penetration_depth`` when intersecting (NaN
    /// when the depth is unknown).
    #[getter]
    fn signed_distance(&self) -> f64 {
        self.inner.signed_distance()
    }

    /// The four attributes as a dict (``penetration_depth`` may be ``None``,
    /// ``signed_distance`` NaN).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("intersecting", self.inner.intersecting)?;
        d.set_item("distance", self.inner.distance)?;
        d.set_item("penetration_depth", self.inner.penetration_depth)?;
        d.set_item("signed_distance", self.inner.signed_distance())?;
        Ok(d)
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    /// Pickle support: `intersecting`, `distance` and `penetration_depth`.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, ProximityState)> {
        let r = &slf.get().inner;
        Ok((
            slf.getattr("_from_state")?,
            (r.intersecting, r.distance, r.penetration_depth),
        ))
    }

    /// Rebuilds a pickled proximity (see `__reduce__`).
    #[staticmethod]
    fn _from_state(intersecting: bool, distance: f64, penetration_depth: Option<f64>) -> Self {
        Self {
            inner: ExactProximity {
                intersecting,
                distance,
                penetration_depth,
            },
        }
    }

    fn __repr__(&self) -> String {
        let depth = self
            .inner
            .penetration_depth
            .map_or("None".to_string(), |d| format!("{d}"));
        format!(
            "Proximity(intersecting={}, distance={}, penetration_depth={})",
            if self.inner.intersecting {
                "True"
            } else {
                "False"
            },
            self.inner.distance,
            depth
        )
    }
}

/// An `(m, 3)` integer array-like as triangle indices.
pub(crate) fn faces_from(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (obj,)).map_err(|e| {
        invalid_input(
            py,
            format!("faces must be an integer array-like: {}", e.value(py)),
        )
    })?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "i" | "u") {
        return Err(invalid_input(
            py,
            format!(
                "faces must be integers, got an array of dtype {}",
                arr.getattr("dtype")?.str()?
            ),
        ));
    }
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(invalid_input(
            py,
            format!(
                "faces must have shape (m, 3), got shape {}",
                shape_str(&shape)
            ),
        ));
    }
    let flat: Vec<i64> = np
        .call_method1("ravel", (arr.call_method1("astype", ("int64",))?,))?
        .call_method0("tolist")?
        .extract()?;
    flat.chunks_exact(3)
        .enumerate()
        .map(|(f, c)| {
            let idx = |v: i64| {
                u32::try_from(v).map_err(|_| {
                    invalid_input(py, format!("mesh face {f} has an invalid vertex index {v}"))
                })
            };
            Ok([idx(c[0])?, idx(c[1])?, idx(c[2])?])
        })
        .collect()
}

/// A triangle mesh (vertices `(n, 3)` in metres, faces `(m, 3)` vertex indices,
/// counter-clockwise seen from outside), validated on construction.
#[pyclass(name = "Mesh", frozen, module = "cloudprox._native")]
pub struct PyMesh {
    pub(crate) inner: Arc<Mesh>,
    /// The clouds this mesh was sampled into for queries, by spacing (bits):
    /// a mesh queried again at the same spacing is not sampled again.
    samples: Mutex<Vec<(u64, Arc<PointCloud>)>>,
    /// Its signed distance for exact-side queries, built on first use.
    distance: OnceLock<Arc<MeshDistance>>,
}

/// How many sampled clouds a mesh keeps.
const SAMPLE_CACHE: usize = 4;

impl PyMesh {
    pub(crate) fn wrap(mesh: Mesh) -> Self {
        Self {
            inner: Arc::new(mesh),
            samples: Mutex::new(Vec::new()),
            distance: OnceLock::new(),
        }
    }

    /// The mesh's signed distance for an exact-side query (built once, without
    /// the GIL).
    pub(crate) fn distance(&self, py: Python<'_>) -> PyResult<Arc<MeshDistance>> {
        if let Some(d) = self.distance.get() {
            return Ok(Arc::clone(d));
        }
        let mesh = Arc::clone(&self.inner);
        let built = Arc::new(run_detached(py, move || MeshDistance::new(&mesh))?);
        Ok(Arc::clone(self.distance.get_or_init(|| built)))
    }

    /// The mesh sampled at `spacing` for a query (cached; see
    /// [`PointCloud::from_mesh`]). Runs without the GIL.
    pub(crate) fn sampled(&self, py: Python<'_>, spacing: f64) -> PyResult<Arc<PointCloud>> {
        let key = spacing.to_bits();
        if let Ok(cache) = self.samples.lock() {
            if let Some((_, c)) = cache.iter().find(|(k, _)| *k == key) {
                return Ok(Arc::clone(c));
            }
        }
        let mesh = Arc::clone(&self.inner);
        let cloud = Arc::new(run_detached(py, move || {
            PointCloud::from_mesh(&mesh, spacing, 0)
        })?);
        if let Ok(mut cache) = self.samples.lock() {
            if cache.len() >= SAMPLE_CACHE {
                cache.remove(0);
            }
            cache.push((key, Arc::clone(&cloud)));
        }
        Ok(cloud)
    }
}

#[pymethods]
impl PyMesh {
    #[new]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let vertices = points_from(vertices, "vertices")?;
        let faces = faces_from(faces)?;
        Ok(Self::wrap(run_detached(py, move || {
            Mesh::new(vertices, faces)
        })?))
    }

    /// A box centred at the origin with half extents `(hx, hy, hz)`.
    #[staticmethod]
    fn cuboid(py: Python<'_>, hx: f64, hy: f64, hz: f64) -> PyResult<Self> {
        Ok(Self::wrap(run_detached(py, move || {
            Mesh::cuboid(hx, hy, hz)
        })?))
    }

    /// A cylinder along z centred at the origin (a prism of `segments` sides).
    #[staticmethod]
    #[pyo3(signature = (radius, half_height, segments=32))]
    fn cylinder(py: Python<'_>, radius: f64, half_height: f64, segments: i64) -> PyResult<Self> {
        let segments = usize::try_from(segments)
            .map_err(|_| invalid_input(py, format!("segments must be >= 3, got {segments}")))?;
        Ok(Self::wrap(run_detached(py, move || {
            Mesh::cylinder(radius, half_height, segments)
        })?))
    }

    /// Several meshes as one.
    #[staticmethod]
    #[allow(clippy::needless_pass_by_value)] // pyo3 extracts a Vec
    fn merged(py: Python<'_>, meshes: Vec<PyRef<'_, PyMesh>>) -> PyResult<Self> {
        let meshes: Vec<Mesh> = meshes.iter().map(|m| (*m.inner).clone()).collect();
        Ok(Self::wrap(run_detached(py, move || Mesh::merged(&meshes))?))
    }

    /// Vertices, shape `(n, 3)`.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_to_py(py, self.inner.vertices())
    }

    /// Faces, shape `(m, 3)`, int64.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let flat: Vec<i64> = self
            .inner
            .faces()
            .iter()
            .flatten()
            .map(|&i| i64::from(i))
            .collect();
        PyArray1::from_vec(py, flat).reshape([self.inner.faces().len(), 3])
    }

    /// Surface area (square metres).
    #[getter]
    fn area(&self) -> f64 {
        self.inner.area()
    }

    /// Enclosed volume (cubic metres; meaningful when closed).
    #[getter]
    fn volume(&self) -> f64 {
        self.inner.volume()
    }

    /// Whether every edge is shared by two faces of opposite directions.
    #[getter]
    fn is_closed(&self) -> bool {
        self.inner.is_closed()
    }

    /// Whether the mesh is closed and convex (within `tolerance` metres).
    #[pyo3(signature = (tolerance=1e-9))]
    fn is_convex(&self, tolerance: f64) -> bool {
        self.inner.is_convex(tolerance)
    }

    /// `(lower, upper)` corners of the bounding box, each shape `(3,)`.
    fn bounds<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let b = self.inner.aabb();
        (
            vec_to_py(py, b.mins.coords.as_slice()),
            vec_to_py(py, b.maxs.coords.as_slice()),
        )
    }

    /// A copy moved by the `(4, 4)` rigid transform `transform`.
    fn transformed(&self, py: Python<'_>, transform: &Bound<'_, PyAny>) -> PyResult<Self> {
        let pose = pose_from(py, Some(transform), "transform")?;
        Ok(Self::wrap(self.inner.transformed(&pose)))
    }

    /// Area-weighted uniform samples of the surface: `n` points, or
    /// `round(density * area)` with `density` (points per square metre), as a
    /// `MeshSample` (`points` `(k, 3)`, `normals` `(k, 3)`, `faces` `(k,)`).
    #[pyo3(signature = (n=None, *, density=None, seed=0))]
    fn sample(
        &self,
        py: Python<'_>,
        n: Option<i64>,
        density: Option<f64>,
        seed: u64,
    ) -> PyResult<PyMeshSample> {
        let mesh = Arc::clone(&self.inner);
        let sample = match (n, density) {
            (Some(n), None) => {
                if !(0..=100_000_000).contains(&n) {
                    return Err(invalid_input(py, format!("n must be in [0, 1e8], got {n}")));
                }
                run_detached(py, move || mesh.sample_surface(n as usize, seed))?
            }
            (None, Some(d)) => run_detached(py, move || mesh.sample_surface_density(d, seed))?,
            _ => return Err(invalid_input(py, "give exactly one of n and density")),
        };
        let faces: Vec<i64> = sample.faces.iter().map(|&f| i64::from(f)).collect();
        Ok(PyMeshSample {
            points: points_to_py(py, &sample.points)?.unbind(),
            normals: rows3_to_py(py, sample.normals.iter().copied())?.unbind(),
            faces: PyArray1::from_vec(py, faces).unbind(),
        })
    }

    /// Pickle support: `Mesh(vertices, faces)` (the samples cache is not kept).
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>),
    )> {
        let py = slf.py();
        let me = slf.get();
        Ok((slf.get_type().into_any(), (me.vertices(py)?, me.faces(py)?)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Mesh with {} vertices and {} faces.",
            self.inner.vertices().len(),
            self.inner.faces().len()
        )
    }
}

/// An object made of mesh parts, prepared for exact queries (closed convex parts
/// as convex polyhedra, the others as triangle meshes).
#[pyclass(name = "ExactShape", frozen, module = "cloudprox._native")]
pub struct PyExactShape {
    inner: Arc<ExactShape>,
    n_parts: usize,
}

#[pymethods]
impl PyExactShape {
    #[new]
    #[pyo3(signature = (parts, *, solid = true))]
    #[allow(clippy::needless_pass_by_value)] // pyo3 extracts a Vec
    fn new(py: Python<'_>, parts: Vec<PyRef<'_, PyMesh>>, solid: bool) -> PyResult<Self> {
        let meshes: Vec<Mesh> = parts.iter().map(|m| (*m.inner).clone()).collect();
        let n_parts = meshes.len();
        let inner = run_detached(py, move || {
            if solid {
                ExactShape::new(&meshes)
            } else {
                ExactShape::surfaces(&meshes)
            }
        })?;
        Ok(Self {
            inner: Arc::new(inner),
            n_parts,
        })
    }

    /// Per part: `"convex"`, `"solid"` (closed mesh, with containment) or
    /// `"surface"` (triangles only), how it is queried.
    #[getter]
    fn part_kinds(&self) -> Vec<&'static str> {
        self.inner
            .parts()
            .iter()
            .map(|p| match p {
                cloudprox::query::exact::ExactPart::Convex(_) => "convex",
                cloudprox::query::exact::ExactPart::Mesh { closed: true, .. } => "solid",
                cloudprox::query::exact::ExactPart::Mesh { closed: false, .. } => "surface",
            })
            .collect()
    }

    fn __len__(&self) -> usize {
        self.n_parts
    }

    fn __repr__(&self) -> String {
        format!("ExactShape with {} parts.", self.n_parts)
    }
}

/// Exact proximity of `a` at `pose_a` and `b` at `pose_b`, as a `Proximity`.
#[pyfunction]
#[pyo3(signature = (a, b, pose_a=None, pose_b=None))]
pub fn exact_proximity<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyExactShape>,
    b: &Bound<'py, PyExactShape>,
    pose_a: Option<&Bound<'py, PyAny>>,
    pose_b: Option<&Bound<'py, PyAny>>,
) -> PyResult<PyProximity> {
    let pa = pose_from(py, pose_a, "pose_a")?;
    let pb = pose_from(py, pose_b, "pose_b")?;
    let (sa, sb) = (Arc::clone(&a.get().inner), Arc::clone(&b.get().inner));
    let inner = run_detached(py, move || core_exact(&pa, &sa, &pb, &sb))?;
    Ok(PyProximity { inner })
}

/// What ``exact_proximity_many`` returns: one ``Proximity`` per pose, read as
/// arrays of shape ``(m,)`` (``batch.distance``) or one pose at a time
/// (``batch[i]``).
#[pyclass(name = "ProximityBatch", frozen, module = "cloudprox._native")]
pub struct PyProximityBatch {
    inner: Vec<ExactProximity>,
}

impl PyProximityBatch {
    fn column<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&ExactProximity) -> f64,
    ) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.iter().map(f).collect())
    }
}

#[pymethods]
impl PyProximityBatch {
    /// Whether the shapes intersect at each pose, bool ``(m,)``.
    #[getter]
    fn intersecting<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_vec(py, self.inner.iter().map(|r| r.intersecting).collect())
    }

    /// Distance between the shapes (0 where they intersect), ``(m,)``.
    #[getter]
    fn distance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |r| r.distance)
    }

    /// The penetration depth where the shapes intersect (NaN where unknown or
    /// apart), ``(m,)``.
    #[getter]
    fn penetration_depth<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |r| r.penetration_depth.unwrap_or(f64::NAN))
    }

    /// ``distance``, or minus the depth where intersecting, ``(m,)``.
    #[getter]
    fn signed_distance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, ExactProximity::signed_distance)
    }

    /// The four arrays as a dict (``tolist()`` them for JSON).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("intersecting", self.intersecting(py))?;
        d.set_item("distance", self.distance(py))?;
        d.set_item("penetration_depth", self.penetration_depth(py))?;
        d.set_item("signed_distance", self.signed_distance(py))?;
        Ok(d)
    }

    /// The number of poses.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// The ``Proximity`` at pose ``index`` (negative counts from the end).
    fn __getitem__(&self, index: isize) -> PyResult<PyProximity> {
        let n = self.inner.len();
        let i = if index < 0 {
            n.checked_sub(index.unsigned_abs())
        } else {
            Some(index.unsigned_abs())
        };
        match i.and_then(|i| self.inner.get(i)) {
            Some(&inner) => Ok(PyProximity { inner }),
            None => Err(pyo3::exceptions::PyIndexError::new_err(format!(
                "pose index {index} out of range for {n} poses"
            ))),
        }
    }

    fn __repr__(&self) -> String {
        let hits = self.inner.iter().filter(|r| r.intersecting).count();
        format!(
            "ProximityBatch(poses={}, intersecting={hits})",
            self.inner.len()
        )
    }
}

/// [`exact_proximity`] for poses `(m, 4, 4)` of `a`, in parallel, as a
/// `ProximityBatch`. The GIL is released during the queries.
#[pyfunction]
#[pyo3(name = "exact_proximity_many", signature = (a, b, poses_a, pose_b=None))]
pub fn exact_proximity_many_py(
    py: Python<'_>,
    a: &Bound<'_, PyExactShape>,
    b: &Bound<'_, PyExactShape>,
    poses_a: &Bound<'_, PyAny>,
    pose_b: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyProximityBatch> {
    let poses = poses_from(poses_a, "poses_a")?;
    let pb = pose_from(py, pose_b, "pose_b")?;
    let (sa, sb) = (Arc::clone(&a.get().inner), Arc::clone(&b.get().inner));
    let inner = run_detached(py, move || exact_proximity_many(&poses, &sa, &pb, &sb))?;
    Ok(PyProximityBatch { inner })
}

/// Whether `a` at each of the poses `(m, 4, 4)` intersects `b`, in parallel: a
/// bool array `(m,)`, the `intersecting` of [`exact_proximity_many`] without
/// the distances (much cheaper for large meshes that are apart).
#[pyfunction]
#[pyo3(name = "exact_intersects_many", signature = (a, b, poses_a, pose_b=None))]
pub fn exact_intersects_many_py<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyExactShape>,
    b: &Bound<'py, PyExactShape>,
    poses_a: &Bound<'py, PyAny>,
    pose_b: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let poses = poses_from(poses_a, "poses_a")?;
    let pb = pose_from(py, pose_b, "pose_b")?;
    let (sa, sb) = (Arc::clone(&a.get().inner), Arc::clone(&b.get().inner));
    let hits = run_detached(py, move || exact_intersects_many(&poses, &sa, &pb, &sb))?;
    Ok(PyArray1::from_vec(py, hits))
}

/// One value per pose from `obj`: a scalar (repeated) or an array `(m,)`.
fn per_pose_values(obj: &Bound<'_, PyAny>, m: usize, what: &str) -> PyResult<Vec<f64>> {
    let arr = crate::convert::to_f64_array(obj, what)?;
    let values: Vec<f64> = arr.readonly().as_array().iter().copied().collect();
    match (arr.ndim(), values.as_slice()) {
        (0, &[v]) => Ok(vec![v; m]),
        (1, _) if values.len() == m => Ok(values),
        _ => Err(invalid_input(
            obj.py(),
            format!(
                "{what} must be a scalar or an array of shape ({m},), got shape {}",
                shape_str(arr.shape())
            ),
        )),
    }
}

/// How far `a` at each start `(m, 4, 4)` moves along its direction before its
/// signed distance to `b` first reaches the target, in parallel: a float array
/// `(m,)` of travels (0 where the start is already at or within the target,
/// infinity where the target is not reached within `max_travel`). The GIL is
/// released during the queries.
#[pyfunction]
#[pyo3(
    name = "exact_time_of_impact_many",
    signature = (a, b, poses_a, directions, target=None, max_travel=f64::INFINITY, pose_b=None)
)]
#[allow(clippy::too_many_arguments)]
pub fn exact_time_of_impact_many_py<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyExactShape>,
    b: &Bound<'py, PyExactShape>,
    poses_a: &Bound<'py, PyAny>,
    directions: &Bound<'py, PyAny>,
    target: Option<&Bound<'py, PyAny>>,
    max_travel: f64,
    pose_b: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let poses = poses_from(poses_a, "poses_a")?;
    let m = poses.len();
    let dirs_arr = crate::convert::to_f64_array(directions, "directions")?;
    let dirs: Vec<cloudprox::math::Vector3> = if dirs_arr.ndim() == 1 {
        vec![crate::convert::vector3_from(directions, "directions")?; m]
    } else {
        crate::convert::check_shape(&dirs_arr, &[Some(m), Some(3)], "directions", "(m, 3)")?;
        points_from(directions, "directions")?
            .into_iter()
            .map(|p| p.coords)
            .collect()
    };
    let targets = match target {
        Some(t) => per_pose_values(t, m, "target")?,
        None => vec![0.0; m],
    };
    let pb = pose_from(py, pose_b, "pose_b")?;
    let (sa, sb) = (Arc::clone(&a.get().inner), Arc::clone(&b.get().inner));
    let travel = run_detached(py, move || {
        cloudprox::query::exact::exact_time_of_impact_many(
            &poses, &sa, &dirs, &pb, &sb, &targets, max_travel,
        )
    })?;
    let travel: Vec<f64> = travel
        .into_iter()
        .map(|t| t.unwrap_or(f64::INFINITY))
        .collect();
    Ok(PyArray1::from_vec(py, travel))
}
