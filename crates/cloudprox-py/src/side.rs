//! One side of a query: a `PointCloud`, or a mesh (cloudprox `Mesh`, a trimesh
//! `Trimesh`, an Open3D `TriangleMesh`) sampled into a cloud.

use std::sync::Arc;

use cloudprox::cloud::PointCloud;
use cloudprox::query::collide::mesh_sampling_spacing;
use cloudprox::shape::Mesh;
use pyo3::prelude::*;

use crate::cloud::PyPointCloud;
use crate::convert::points_from;
use crate::error::{invalid_input, run_detached};
use crate::mesh::{faces_from, PyMesh};

/// A query side as given.
pub enum Side {
    /// A point cloud.
    Cloud(Arc<PointCloud>),
    /// A cloudprox `Mesh` (its samples are cached on it).
    Mesh(Py<PyMesh>),
    /// A mesh of another library, converted.
    Foreign(Arc<Mesh>),
}

fn foreign_mesh(obj: &Bound<'_, PyAny>) -> PyResult<Option<Mesh>> {
    let py = obj.py();
    // trimesh.Trimesh: vertices + faces; Open3D TriangleMesh: vertices + triangles.
    let faces_attr = if obj.hasattr("faces")? {
        "faces"
    } else if obj.hasattr("triangles")? {
        "triangles"
    } else {
        return Ok(None);
    };
    if !obj.hasattr("vertices")? {
        return Ok(None);
    }
    let np = py.import("numpy")?;
    let vertices = np.call_method1("asarray", (obj.getattr("vertices")?,))?;
    let faces = np.call_method1("asarray", (obj.getattr(faces_attr)?,))?;
    let vertices = points_from(&vertices, "mesh vertices")?;
    let faces = faces_from(&faces)?;
    Ok(Some(run_detached(py, move || Mesh::new(vertices, faces))?))
}

impl Side {
    /// Resolves `obj` (named `what` in errors).
    pub fn from_py(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Self> {
        if let Ok(c) = obj.cast::<PyPointCloud>() {
            return Ok(Side::Cloud(Arc::clone(&c.get().inner)));
        }
        if let Ok(m) = obj.cast::<PyMesh>() {
            return Ok(Side::Mesh(m.clone().unbind()));
        }
        if let Some(mesh) = foreign_mesh(obj)? {
            return Ok(Side::Foreign(Arc::new(mesh)));
        }
        let ty = obj.get_type().name()?;
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{what} must be a PointCloud or a mesh (cloudprox.Mesh, trimesh.Trimesh, \
                 open3d TriangleMesh), got {ty}; wrap arrays in PointCloud(points, sigma=...)"
        )))
    }

    fn is_cloud(&self) -> bool {
        matches!(self, Side::Cloud(_))
    }

    /// This side as a cloud; a mesh is sampled at `spacing`, or against `other`'s
    /// sampling when `spacing` is `None`.
    fn to_cloud(
        &self,
        py: Python<'_>,
        other: &Arc<PointCloud>,
        spacing: Option<f64>,
    ) -> PyResult<Arc<PointCloud>> {
        let spacing = if let Some(s) = spacing {
            s
        } else {
            let other = Arc::clone(other);
            run_detached(py, move || Ok(mesh_sampling_spacing(&other)))?
        };
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(invalid_input(
                py,
                format!(
                    "mesh_spacing must be finite and > 0, got {spacing} (the cloud's points \
                     coincide? give mesh_spacing)"
                ),
            ));
        }
        match self {
            Side::Cloud(c) => Ok(Arc::clone(c)),
            Side::Mesh(m) => m.get().sampled(py, spacing),
            Side::Foreign(mesh) => {
                let mesh = Arc::clone(mesh);
                Ok(Arc::new(run_detached(py, move || {
                    PointCloud::from_mesh(&mesh, spacing, 0)
                })?))
            }
        }
    }
}

/// The two sides of a query as clouds: meshes are sampled against the cloud on
/// the other side. Two meshes are refused (use the exact queries).
pub fn resolve_pair(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    mesh_spacing: Option<f64>,
) -> PyResult<(Arc<PointCloud>, Arc<PointCloud>)> {
    let (sa, sb) = (Side::from_py(a, "a")?, Side::from_py(b, "b")?);
    match (&sa, &sb) {
        (Side::Cloud(ca), Side::Cloud(cb)) => {
            if mesh_spacing.is_some() {
                return Err(invalid_input(
                    py,
                    "mesh_spacing is only used when one side is a mesh",
                ));
            }
            Ok((Arc::clone(ca), Arc::clone(cb)))
        }
        (Side::Cloud(ca), _) => Ok((Arc::clone(ca), sb.to_cloud(py, ca, mesh_spacing)?)),
        (_, Side::Cloud(cb)) => Ok((sa.to_cloud(py, cb, mesh_spacing)?, Arc::clone(cb))),
        _ => {
            debug_assert!(!sa.is_cloud() && !sb.is_cloud());
            Err(invalid_input(
                py,
                "both sides are meshes: collide needs at least one point cloud; \
                 use exact_proximity for two meshes",
            ))
        }
    }
}
