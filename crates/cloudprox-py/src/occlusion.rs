//! `Occlusion`: what a scan did not see.

use std::sync::Arc;

use cloudprox::filter::{Occlusion, Visibility};
use cloudprox::math::Point3;
use numpy::PyArray1;
use pyo3::prelude::*;

use crate::cloud::PyPointCloud;
use crate::convert::{points_from, vector3_from};
use crate::error::{invalid_input, CoreResultExt};

/// The space a scan did not see: the nearest return per viewing direction
/// from the sensor's origin, in cells of the scan's own angular spacing
/// ([`cloudprox::filter::Occlusion`]).
#[pyclass(name = "Occlusion", frozen, module = "cloudprox._native")]
pub struct PyOcclusion {
    pub(crate) inner: Arc<Occlusion>,
}

#[pymethods]
impl PyOcclusion {
    #[new]
    #[pyo3(signature = (scan, origin, *, cell=None))]
    fn new(
        py: Python<'_>,
        scan: &Bound<'_, PyAny>,
        origin: &Bound<'_, PyAny>,
        cell: Option<f64>,
    ) -> PyResult<Self> {
        let cloud = scan.cast::<PyPointCloud>().map_err(|_| {
            let ty = scan
                .get_type()
                .name()
                .map_or_else(|_| "?".to_owned(), |n| n.to_string());
            invalid_input(py, format!("scan must be a PointCloud, got {ty}"))
        })?;
        let cloud = &cloud.get().inner;
        let origin = Point3::from(vector3_from(origin, "origin")?);
        let inner = Occlusion::new(
            cloud.points(),
            Some(cloud.sensor_covariances()),
            cloud.spacing(),
            origin,
            cell,
        )
        .or_py(py)?;
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// The angular cell in radians.
    #[getter]
    fn cell(&self) -> f64 {
        self.inner.cell()
    }

    /// The probability that each of `points` (`(n, 3)`, the scan's frame)
    /// lies behind the observed surface along its viewing ray (by at most
    /// `depth` metres, when given).
    #[pyo3(signature = (points, depth=None))]
    fn hidden_probability<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'_, PyAny>,
        depth: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let depth = depth.unwrap_or(f64::INFINITY);
        if depth.is_nan() || depth <= 0.0 {
            return Err(invalid_input(
                py,
                format!("depth must be positive, got {depth}"),
            ));
        }
        let pts = finite_points(py, points)?;
        let p: Vec<f64> = pts
            .iter()
            .map(|x| self.inner.hidden_within(x, depth))
            .collect();
        Ok(PyArray1::from_vec(py, p))
    }

    /// Each of `points` as the scan saw it: ``"seen"`` (in front of the
    /// observed surface), ``"hidden"`` (behind it) or ``"unobserved"`` (no
    /// return along its direction).
    fn visibility(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<Vec<&'static str>> {
        let pts = finite_points(py, points)?;
        Ok(pts
            .iter()
            .map(|x| match self.inner.visibility(x) {
                Visibility::Seen => "seen",
                Visibility::Hidden => "hidden",
                Visibility::Unobserved => "unobserved",
            })
            .collect())
    }

    fn __repr__(&self) -> String {
        format!("Occlusion(cell={:.4} rad)", self.inner.cell())
    }
}

/// `points` as `(n, 3)` points, each finite (else an error naming the first
/// that is not).
fn finite_points(py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<Vec<Point3>> {
    let pts = points_from(points, "points")?;
    if let Some(i) = pts
        .iter()
        .position(|p| !p.coords.iter().all(|v| v.is_finite()))
    {
        return Err(invalid_input(
            py,
            format!("points: point {i} is not finite"),
        ));
    }
    Ok(pts)
}
