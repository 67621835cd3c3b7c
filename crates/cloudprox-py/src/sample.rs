//! Seeded synthetic shapes (wrapping `cloudprox::sample`), for tests and demos.

use cloudprox::math::Point3;
use cloudprox::sample;
use numpy::PyArray2;
use pyo3::prelude::*;

use crate::convert::{points_from, points_to_py, vector3_from};
use crate::error::{guard, invalid_input, Panicked};

/// The most points a sampler may return (guards against runaway allocations).
const MAX_POINTS: f64 = 1e8;

fn positive(py: Python<'_>, what: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(invalid_input(
            py,
            format!("{what} must be finite and > 0, got {v}"),
        ))
    }
}

/// `n` points spread evenly over a sphere (Fibonacci lattice), shape `(n, 3)`.
#[pyfunction]
#[pyo3(signature = (n, radius=1.0, center=None))]
pub fn sample_sphere<'py>(
    py: Python<'py>,
    n: i64,
    radius: f64,
    center: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let radius = positive(py, "radius", radius)?;
    if !(0..=MAX_POINTS as i64).contains(&n) {
        return Err(invalid_input(py, format!("n must be in [0, 1e8], got {n}")));
    }
    let center = match center {
        Some(c) => Point3::from(vector3_from(c, "center")?),
        None => Point3::origin(),
    };
    let pts = py.detach(|| guard(|| sample::sphere(&center, radius, n as usize)));
    points_to_py(py, &pts.map_err(Panicked::into_py_err)?)
}

/// The surface of an axis-aligned box (`half_extents` `(3,)`) sampled on a grid of
/// about `spacing` per face, shape `(m, 3)`.
#[pyfunction]
#[pyo3(signature = (half_extents, spacing, center=None))]
pub fn sample_box_surface<'py>(
    py: Python<'py>,
    half_extents: &Bound<'py, PyAny>,
    spacing: f64,
    center: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let half = vector3_from(half_extents, "half_extents")?;
    for k in 0..3 {
        positive(py, "every half extent", half[k])?;
    }
    let spacing = positive(py, "spacing", spacing)?;
    let per_face = |u: f64, v: f64| (2.0 * u / spacing + 1.0) * (2.0 * v / spacing + 1.0);
    let estimate =
        2.0 * (per_face(half.y, half.z) + per_face(half.x, half.z) + per_face(half.x, half.y));
    if estimate > MAX_POINTS {
        return Err(invalid_input(
            py,
            format!("spacing {spacing} gives about {estimate:.3e} points, more than 1e8"),
        ));
    }
    let center = match center {
        Some(c) => Point3::from(vector3_from(c, "center")?),
        None => Point3::origin(),
    };
    let pts = py.detach(|| guard(|| sample::box_surface(&center, &half, spacing)));
    points_to_py(py, &pts.map_err(Panicked::into_py_err)?)
}

/// `points` `(n, 3)` with seeded isotropic Gaussian noise of standard deviation
/// `sigma` added (the core's generator: the same seed gives the same noise).
#[pyfunction]
#[pyo3(signature = (points, sigma, seed=0))]
pub fn add_noise<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    sigma: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let points = points_from(points, "points")?;
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(invalid_input(
            py,
            format!("sigma must be finite and >= 0, got {sigma}"),
        ));
    }
    let noisy = py.detach(|| guard(|| sample::add_noise(&points, sigma, seed)));
    points_to_py(py, &noisy.map_err(Panicked::into_py_err)?)
}
