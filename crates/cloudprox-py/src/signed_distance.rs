//! `MeshDistance` and `DistanceField`: the signed distance to a mesh, exact and
//! on a grid with an error bound.

use std::sync::Arc;

use cloudprox::math::Point3;
use cloudprox::shape::{DistanceField, MeshDistance, SignMethod};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{points_from, points_to_py, rows3_to_py, vec_to_py};
use crate::error::{invalid_input, run_detached};
use crate::mesh::PyMesh;

/// `(n, 3)` finite query points.
fn query_points(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Point3>> {
    let points = points_from(obj, "points")?;
    if let Some(i) = points
        .iter()
        .position(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(invalid_input(
            obj.py(),
            format!(
                "points[{i}] has a non-finite coordinate: {:?}",
                points[i].coords.as_slice()
            ),
        ));
    }
    Ok(points)
}

/// A sign method from its name.
fn sign_method(py: Python<'_>, name: &str) -> PyResult<SignMethod> {
    match name {
        "pseudo_normal" => Ok(SignMethod::PseudoNormal),
        "winding_number" => Ok(SignMethod::WindingNumber),
        other => Err(invalid_input(
            py,
            format!(
                "sign_method must be \"auto\", \"pseudo_normal\" or \"winding_number\", got {other:?}"
            ),
        )),
    }
}

/// The three arrays of `closest`: distances `(n,)`, points `(n, 3)`, normals `(n, 3)`.
type Closest<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// The three arrays of `evaluate`: distances `(n,)`, gradients `(n, 3)`, bounds `(n,)`.
type Evaluated<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// A triangle mesh prepared for signed-distance queries in its own frame.
#[pyclass(name = "MeshDistance", frozen, module = "cloudprox._native")]
pub struct PyMeshDistance {
    inner: Arc<MeshDistance>,
}

#[pymethods]
impl PyMeshDistance {
    #[new]
    #[pyo3(signature = (mesh, *, sign_method = "auto"))]
    fn new(py: Python<'_>, mesh: &Bound<'_, PyMesh>, sign_method: &str) -> PyResult<Self> {
        let forced = match sign_method {
            "auto" => None,
            name => Some(self::sign_method(py, name)?),
        };
        let mesh = Arc::clone(&mesh.get().inner);
        let inner = run_detached(py, move || match forced {
            None => MeshDistance::new(&mesh),
            Some(m) => MeshDistance::with_sign_method(&mesh, m),
        })?;
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// `"pseudo_normal"` or `"winding_number"`: how the sign is read.
    #[getter]
    fn sign_method(&self) -> &'static str {
        self.inner.sign_method().name()
    }

    /// What welding and re-orientation found, as a dict.
    #[getter]
    fn topology<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = self.inner.topology();
        let d = PyDict::new(py);
        d.set_item("vertices", t.vertices)?;
        d.set_item("shells", t.shells)?;
        d.set_item("boundary_edges", t.boundary_edges)?;
        d.set_item("non_manifold_edges", t.non_manifold_edges)?;
        d.set_item("degenerate_faces", t.degenerate_faces)?;
        d.set_item("reoriented_faces", t.reoriented_faces)?;
        d.set_item("closed", t.closed)?;
        d.set_item("self_intersecting", t.self_intersecting)?;
        Ok(d)
    }

    /// The number of faces of the mesh.
    #[getter]
    fn num_faces(&self) -> usize {
        self.inner.num_faces()
    }

    /// The signed distance of each point (negative inside), `(n,)`.
    fn signed_distance<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let points = query_points(points)?;
        let md = Arc::clone(&self.inner);
        let d = run_detached(py, move || Ok(md.signed_distance_many(&points)))?;
        Ok(PyArray1::from_vec(py, d))
    }

    /// The unsigned distance of each point, `(n,)`.
    fn distance<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let points = query_points(points)?;
        let md = Arc::clone(&self.inner);
        let d = run_detached(py, move || {
            Ok(md
                .closest_many(&points)
                .iter()
                .map(cloudprox::shape::ClosestPoint::distance)
                .collect::<Vec<_>>())
        })?;
        Ok(PyArray1::from_vec(py, d))
    }

    /// Signed distances `(n,)`, closest points `(n, 3)` and unit normals (the
    /// gradient of the signed distance) `(n, 3)`.
    fn closest<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>) -> PyResult<Closest<'py>> {
        let points = query_points(points)?;
        let md = Arc::clone(&self.inner);
        let c = run_detached(py, move || Ok(md.closest_many(&points)))?;
        let d: Vec<f64> = c.iter().map(|c| c.signed_distance).collect();
        let q: Vec<Point3> = c.iter().map(|c| c.point).collect();
        Ok((
            PyArray1::from_vec(py, d),
            points_to_py(py, &q)?,
            rows3_to_py(py, c.iter().map(|c| c.normal))?,
        ))
    }

    /// `closest` for the points within `max_distance` of the surface; NaN rows
    /// for the others (found without searching farther).
    fn closest_within<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        max_distance: f64,
    ) -> PyResult<Closest<'py>> {
        if max_distance.is_nan() || max_distance < 0.0 {
            return Err(invalid_input(
                py,
                format!("max_distance must be >= 0, got {max_distance}"),
            ));
        }
        let points = query_points(points)?;
        let md = Arc::clone(&self.inner);
        let c = run_detached(
            py,
            move || Ok(md.closest_within_many(&points, max_distance)),
        )?;
        let nan = f64::NAN;
        let d: Vec<f64> = c
            .iter()
            .map(|c| c.map_or(nan, |c| c.signed_distance))
            .collect();
        let q: Vec<Point3> = c
            .iter()
            .map(|c| c.map_or(Point3::new(nan, nan, nan), |c| c.point))
            .collect();
        let n = c
            .iter()
            .map(|c| c.map_or(cloudprox::math::Vector3::new(nan, nan, nan), |c| c.normal));
        Ok((
            PyArray1::from_vec(py, d),
            points_to_py(py, &q)?,
            rows3_to_py(py, n)?,
        ))
    }

    /// The generalized winding number of each point, `(n,)`.
    fn winding_number<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let points = query_points(points)?;
        let md = Arc::clone(&self.inner);
        let w = run_detached(py, move || {
            Ok(points
                .iter()
                .map(|p| md.winding_number(p))
                .collect::<Vec<_>>())
        })?;
        Ok(PyArray1::from_vec(py, w))
    }

    /// Whether each point is inside, bool `(n,)`.
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let points = query_points(points)?;
        let md = Arc::clone(&self.inner);
        let c = run_detached(py, move || {
            Ok(points.iter().map(|p| md.contains(p)).collect::<Vec<_>>())
        })?;
        Ok(PyArray1::from_vec(py, c))
    }

    /// The signed-distance grid of this mesh (see ``DistanceField``).
    fn field(&self, py: Python<'_>, resolution: f64, band: f64) -> PyResult<PyDistanceField> {
        PyDistanceField::build(py, &self.inner, resolution, band)
    }

    fn __repr__(&self) -> String {
        format!(
            "MeshDistance with {} faces, sign method {}.",
            self.inner.num_faces(),
            self.inner.sign_method().name()
        )
    }
}

/// A signed-distance grid in a mesh's own frame with an error bound.
#[pyclass(name = "DistanceField", frozen, module = "cloudprox._native")]
pub struct PyDistanceField {
    inner: Arc<DistanceField>,
}

impl PyDistanceField {
    fn build(py: Python<'_>, md: &Arc<MeshDistance>, resolution: f64, band: f64) -> PyResult<Self> {
        let md = Arc::clone(md);
        let inner = run_detached(py, move || DistanceField::new(md, resolution, band))?;
        Ok(Self {
            inner: Arc::new(inner),
        })
    }
}

#[pymethods]
impl PyDistanceField {
    #[new]
    fn new(
        py: Python<'_>,
        mesh_distance: &Bound<'_, PyMeshDistance>,
        resolution: f64,
        band: f64,
    ) -> PyResult<Self> {
        Self::build(py, &mesh_distance.get().inner, resolution, band)
    }

    /// Signed distances `(n,)`, their gradients `(n, 3)` and error bounds
    /// `(n,)`: ``|exact - distance| <= bound``.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Evaluated<'py>> {
        let points = query_points(points)?;
        let field = Arc::clone(&self.inner);
        let s = run_detached(py, move || Ok(field.evaluate_many(&points)))?;
        let d: Vec<f64> = s.iter().map(|s| s.distance).collect();
        let b: Vec<f64> = s.iter().map(|s| s.bound).collect();
        Ok((
            PyArray1::from_vec(py, d),
            rows3_to_py(py, s.iter().map(|s| s.gradient))?,
            PyArray1::from_vec(py, b),
        ))
    }

    /// The node spacing (metres).
    #[getter]
    fn resolution(&self) -> f64 {
        self.inner.resolution()
    }

    /// The band within which nodes hold exact values (metres).
    #[getter]
    fn band(&self) -> f64 {
        self.inner.band()
    }

    /// Nodes per axis.
    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        let [a, b, c] = self.inner.dims();
        (a, b, c)
    }

    /// The position of node ``(0, 0, 0)``, ``(3,)``.
    #[getter]
    fn origin<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_to_py(py, self.inner.origin().coords.as_slice())
    }

    /// The bytes the grid holds.
    #[getter]
    fn nbytes(&self) -> usize {
        self.inner.memory_bytes()
    }

    /// What the build found, as a dict of counts.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.stats();
        let d = PyDict::new(py);
        d.set_item("nodes", s.nodes)?;
        d.set_item("nodes_in_band", s.nodes_in_band)?;
        d.set_item("cells_interpolated", s.cells_interpolated)?;
        d.set_item("cells_sign_agnostic", s.cells_sign_agnostic)?;
        d.set_item("cells_exact", s.cells_exact)?;
        d.set_item("cells_beyond", s.cells_beyond)?;
        d.set_item("exact_sign_nodes", s.exact_sign_nodes)?;
        Ok(d)
    }

    /// The exact queries the field falls back to.
    #[getter]
    fn mesh_distance(&self) -> PyMeshDistance {
        PyMeshDistance {
            inner: Arc::clone(self.inner.source()),
        }
    }

    fn __repr__(&self) -> String {
        let [a, b, c] = self.inner.dims();
        format!(
            "DistanceField of {a} x {b} x {c} nodes every {} m, band {} m.",
            self.inner.resolution(),
            self.inner.band()
        )
    }
}
