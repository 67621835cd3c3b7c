//! The `distance` function and its result.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{pose_from, vector3_to_py};
use crate::error::run_detached;
use crate::exact_side::{resolve, Pair};
use crate::request::{request_from, PyCollisionRequest};
use cloudprox::query::{DistanceRequest, DistanceResult};

/// The keywords of `distance` that are not request options.
const DISTANCE_KEYWORDS: [&str; 2] = ["request", "max_distance"];

/// The estimated signed separation between the surfaces two clouds (or a mesh
/// and a cloud) sample, with its standard deviation and witness points
/// ([`cloudprox::query::distance`]). `max_distance` (metres, default: none)
/// stops early when the surfaces are surely farther apart; the result is
/// then a lower bound (`beyond_max_distance`). The GIL is released.
#[pyfunction]
#[pyo3(signature = (a, b, pose_a=None, pose_b=None, *, max_distance=None, request=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn distance(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
    max_distance: Option<f64>,
    request: Option<&Bound<'_, PyCollisionRequest>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyDistanceResult> {
    let collision = request_from(py, request, options, &DISTANCE_KEYWORDS)?;
    let request = DistanceRequest {
        max_distance: max_distance.unwrap_or(f64::INFINITY),
        collision,
    };
    let pose_a = pose_from(py, pose_a, "pose_a")?;
    let pose_b = pose_from(py, pose_b, "pose_b")?;
    let pair = resolve(py, a, b, None, None)?;
    let inner = run_detached(py, move || match &pair {
        Pair::Clouds(ca, cb) => cloudprox::query::distance(&pose_a, ca, &pose_b, cb, &request),
        Pair::Exact {
            mesh,
            cloud,
            mesh_is_a,
        } => {
            if *mesh_is_a {
                cloudprox::query::distance_exact_cloud(&pose_a, mesh, &pose_b, cloud, &request)
            } else {
                cloudprox::query::distance_cloud_exact(&pose_a, cloud, &pose_b, mesh, &request)
            }
        }
    })?;
    Ok(PyDistanceResult { inner })
}

/// What ``distance`` returns: the estimated signed separation of the two
/// sampled surfaces, its standard deviation and the witness points.
#[pyclass(name = "DistanceResult", frozen, module = "cloudprox._native")]
pub struct PyDistanceResult {
    inner: DistanceResult,
}

#[pymethods]
impl PyDistanceResult {
    /// The estimated signed separation in metres (negative where the
    /// surfaces interpenetrate); with ``beyond_max_distance``, a lower bound.
    #[getter]
    fn distance(&self) -> f64 {
        self.inner.distance
    }

    /// The standard deviation of ``distance`` in metres (0 for a bound).
    #[getter]
    fn std(&self) -> f64 {
        self.inner.std
    }

    /// The witness point on A's surface estimate, world frame, ``(3,)`` (NaN for a bound).
    #[getter]
    fn point_a<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vector3_to_py(py, &self.inner.point_a.coords)
    }

    /// The witness point on B's surface estimate, world frame, ``(3,)`` (NaN for a bound).
    #[getter]
    fn point_b<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vector3_to_py(py, &self.inner.point_b.coords)
    }

    /// The unit direction the distance is measured along, from A towards B, ``(3,)``.
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vector3_to_py(py, &self.inner.normal)
    }

    /// Whether the query stopped at ``max_distance`` (``distance`` is a lower bound).
    #[getter]
    fn beyond_max_distance(&self) -> bool {
        self.inner.beyond_max_distance
    }

    /// Whether the reading is one of ``collide``'s: two clouds within the
    /// noise's reach of each other (always false with an exact mesh side).
    #[getter]
    fn near_contact(&self) -> bool {
        self.inner.near_contact
    }

    /// ``Phi(-distance / std)``: the probability that the surfaces cross at
    /// the reading; at most ``collide``'s ``P``, equal to it when the contact
    /// is one pair of surface elements.
    #[getter]
    fn crossing_probability(&self) -> f64 {
        self.inner.crossing_probability()
    }

    fn __repr__(&self) -> String {
        format!(
            "DistanceResult(distance={:.6}, std={:.3e}, beyond_max_distance={})",
            self.inner.distance,
            self.inner.std,
            if self.inner.beyond_max_distance {
                "True"
            } else {
                "False"
            }
        )
    }
}
