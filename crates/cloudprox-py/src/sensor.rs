//! Sensor noise models: `DepthCamera`, `StereoCamera`, `Lidar`.

use cloudprox::math::Point3;
use cloudprox::uncertainty::{DepthCamera, Lidar, SensorModel, StereoCamera, Viewpoint};
use numpy::prelude::*;
use numpy::{PyArray1, PyArray3};
use pyo3::prelude::*;

use crate::convert::{matrices3_to_py, points_from, pose_from, to_f64_array, vector3_from};
use crate::error::{invalid_input, run_detached, CoreResultExt};

/// The viewpoint from `origin` (`(3,)`) or `sensor_pose` (`(4, 4)`, optical axis
/// `+z`); exactly one must be given.
pub fn viewpoint_from(
    py: Python<'_>,
    origin: Option<&Bound<'_, PyAny>>,
    sensor_pose: Option<&Bound<'_, PyAny>>,
) -> PyResult<Viewpoint> {
    match (origin, sensor_pose) {
        (Some(_), Some(_)) => Err(invalid_input(
            py,
            "give either origin or sensor_pose, not both (sensor_pose holds the origin)",
        )),
        (None, None) => Err(invalid_input(
            py,
            "a sensor model needs the sensor's origin (3,) or sensor_pose (4, 4)",
        )),
        (Some(o), None) => Ok(Viewpoint::at(Point3::from(vector3_from(o, "origin")?))),
        (None, Some(p)) => Ok(Viewpoint::from_pose(&pose_from(
            py,
            Some(p),
            "sensor_pose",
        )?)),
    }
}

/// A sensor model object's core model, if `obj` is one.
pub fn sensor_model_from(obj: &Bound<'_, PyAny>) -> PyResult<SensorModel> {
    if let Ok(c) = obj.cast::<PyDepthCamera>() {
        return Ok(SensorModel::DepthCamera(c.get().inner));
    }
    if let Ok(c) = obj.cast::<PyStereoCamera>() {
        return Ok(SensorModel::Stereo(c.get().inner));
    }
    if let Ok(c) = obj.cast::<PyLidar>() {
        return Ok(SensorModel::Lidar(c.get().inner));
    }
    Err(invalid_input(
        obj.py(),
        format!(
            "sensor must be a DepthCamera, StereoCamera or Lidar, got {}",
            obj.get_type().name()?
        ),
    ))
}

fn covariances_py<'py>(
    py: Python<'py>,
    model: SensorModel,
    points: &Bound<'py, PyAny>,
    origin: Option<&Bound<'py, PyAny>>,
    sensor_pose: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let points = points_from(points, "points")?;
    let vp = viewpoint_from(py, origin, sensor_pose)?;
    let covs = run_detached(py, move || model.covariances(&points, &vp))?;
    matrices3_to_py(py, &covs)
}

fn map_depth<'py>(
    py: Python<'py>,
    depth: &Bound<'py, PyAny>,
    f: impl Fn(f64) -> f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let arr = to_f64_array(depth, "depth")?;
    let out: Vec<f64> = arr.readonly().as_array().iter().map(|&z| f(z)).collect();
    Ok(PyArray1::from_vec(py, out))
}

/// Structured-light depth camera (Kinect v1-like): axial standard deviation
/// `axial_offset + axial_quadratic (z - axial_depth0)^2`, stretched along the ray
/// by `range / depth`; lateral `sigma_px z / focal_px`. Defaults: Khoshelham &
/// Elberink (2012), `sigma_z = 1.425e-3 z^2`, focal 580 px, 0.8 px.
#[pyclass(name = "DepthCamera", frozen, module = "cloudprox._native")]
pub struct PyDepthCamera {
    inner: DepthCamera,
}

#[pymethods]
impl PyDepthCamera {
    #[new]
    // Every parameter left `None` is the core's `DepthCamera::default()`'s.
    #[pyo3(signature = (
        *, axial_offset=None, axial_quadratic=None, axial_depth0=None, focal_px=None,
        sigma_px=None, baseline_m=None, disparity_step_px=None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        axial_offset: Option<f64>,
        axial_quadratic: Option<f64>,
        axial_depth0: Option<f64>,
        focal_px: Option<f64>,
        sigma_px: Option<f64>,
        baseline_m: Option<f64>,
        disparity_step_px: Option<f64>,
    ) -> PyResult<Self> {
        let d = DepthCamera::default();
        let inner = DepthCamera {
            axial_offset: axial_offset.unwrap_or(d.axial_offset),
            axial_quadratic: axial_quadratic.unwrap_or(d.axial_quadratic),
            axial_depth0: axial_depth0.unwrap_or(d.axial_depth0),
            focal_px: focal_px.unwrap_or(d.focal_px),
            sigma_px: sigma_px.unwrap_or(d.sigma_px),
            baseline_m: baseline_m.unwrap_or(d.baseline_m),
            disparity_step_px: disparity_step_px.unwrap_or(d.disparity_step_px),
        };
        inner.validate().or_py(py)?;
        Ok(Self { inner })
    }

    /// Nguyen, Izadi & Lovell (2012): `sigma_z = 0.0012 + 0.0019 (z - 0.4)^2`.
    #[staticmethod]
    fn nguyen_2012() -> Self {
        Self {
            inner: DepthCamera::nguyen_2012(),
        }
    }

    /// Khoshelham & Elberink (2012): `sigma_z = 1.425e-3 z^2` (the default).
    #[staticmethod]
    fn khoshelham_2012() -> Self {
        Self {
            inner: DepthCamera::khoshelham_2012(),
        }
    }

    #[getter]
    fn axial_offset(&self) -> f64 {
        self.inner.axial_offset
    }
    #[getter]
    fn axial_quadratic(&self) -> f64 {
        self.inner.axial_quadratic
    }
    #[getter]
    fn axial_depth0(&self) -> f64 {
        self.inner.axial_depth0
    }
    #[getter]
    fn focal_px(&self) -> f64 {
        self.inner.focal_px
    }
    #[getter]
    fn sigma_px(&self) -> f64 {
        self.inner.sigma_px
    }
    #[getter]
    fn baseline_m(&self) -> f64 {
        self.inner.baseline_m
    }
    #[getter]
    fn disparity_step_px(&self) -> f64 {
        self.inner.disparity_step_px
    }

    /// Depth step (one disparity step) at each depth, metres.
    fn depth_step<'py>(
        &self,
        py: Python<'py>,
        depth: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_depth(py, depth, |z| self.inner.depth_step(z))
    }

    /// Share of the axial variance common to one surface's points at each depth.
    fn noise_correlation<'py>(
        &self,
        py: Python<'py>,
        depth: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_depth(py, depth, |z| self.inner.noise_correlation(z))
    }

    /// Axial (depth) standard deviation at each depth, metres.
    fn sigma_axial<'py>(
        &self,
        py: Python<'py>,
        depth: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_depth(py, depth, |z| self.inner.sigma_axial(z))
    }

    /// Lateral standard deviation at each depth, metres.
    fn sigma_lateral<'py>(
        &self,
        py: Python<'py>,
        depth: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_depth(py, depth, |z| self.inner.sigma_lateral(z))
    }

    /// Sensor covariances `(n, 3, 3)` of `points` seen from `origin` or `sensor_pose`.
    #[pyo3(signature = (points, origin=None, sensor_pose=None))]
    fn covariances<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        origin: Option<&Bound<'py, PyAny>>,
        sensor_pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        covariances_py(
            py,
            SensorModel::DepthCamera(self.inner),
            points,
            origin,
            sensor_pose,
        )
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "DepthCamera(axial_offset={}, axial_quadratic={}, axial_depth0={}, focal_px={}, sigma_px={})",
            c.axial_offset, c.axial_quadratic, c.axial_depth0, c.focal_px, c.sigma_px
        )
    }
}

/// Stereo camera: depth standard deviation `z^2 sigma_disparity_px / (focal_px
/// baseline)`, stretched along the ray; lateral `sigma_px z / focal_px`.
#[pyclass(name = "StereoCamera", frozen, module = "cloudprox._native")]
pub struct PyStereoCamera {
    inner: StereoCamera,
}

#[pymethods]
impl PyStereoCamera {
    #[new]
    // Every parameter left `None` is the core's `StereoCamera::default()`'s.
    #[pyo3(signature = (*, focal_px=None, baseline=None, sigma_disparity_px=None, sigma_px=None))]
    fn new(
        py: Python<'_>,
        focal_px: Option<f64>,
        baseline: Option<f64>,
        sigma_disparity_px: Option<f64>,
        sigma_px: Option<f64>,
    ) -> PyResult<Self> {
        let d = StereoCamera::default();
        let inner = StereoCamera {
            focal_px: focal_px.unwrap_or(d.focal_px),
            baseline: baseline.unwrap_or(d.baseline),
            sigma_disparity_px: sigma_disparity_px.unwrap_or(d.sigma_disparity_px),
            sigma_px: sigma_px.unwrap_or(d.sigma_px),
        };
        inner.validate().or_py(py)?;
        Ok(Self { inner })
    }

    #[getter]
    fn focal_px(&self) -> f64 {
        self.inner.focal_px
    }
    #[getter]
    fn baseline(&self) -> f64 {
        self.inner.baseline
    }
    #[getter]
    fn sigma_disparity_px(&self) -> f64 {
        self.inner.sigma_disparity_px
    }
    #[getter]
    fn sigma_px(&self) -> f64 {
        self.inner.sigma_px
    }

    /// Depth standard deviation at each depth, metres.
    fn sigma_axial<'py>(
        &self,
        py: Python<'py>,
        depth: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_depth(py, depth, |z| self.inner.sigma_axial(z))
    }

    /// Lateral standard deviation at each depth, metres.
    fn sigma_lateral<'py>(
        &self,
        py: Python<'py>,
        depth: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        map_depth(py, depth, |z| self.inner.sigma_lateral(z))
    }

    /// Sensor covariances `(n, 3, 3)` of `points` seen from `origin` or `sensor_pose`.
    #[pyo3(signature = (points, origin=None, sensor_pose=None))]
    fn covariances<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        origin: Option<&Bound<'py, PyAny>>,
        sensor_pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        covariances_py(
            py,
            SensorModel::Stereo(self.inner),
            points,
            origin,
            sensor_pose,
        )
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "StereoCamera(focal_px={}, baseline={}, sigma_disparity_px={}, sigma_px={})",
            c.focal_px, c.baseline, c.sigma_disparity_px, c.sigma_px
        )
    }
}

/// Laser range finder: range standard deviation `sigma_range` along the ray,
/// `range * sigma_angle` across it. Defaults: Hokuyo UTM-30LX (10 mm, 0.25° /
/// sqrt(12)).
#[pyclass(name = "Lidar", frozen, module = "cloudprox._native")]
pub struct PyLidar {
    inner: Lidar,
}

#[pymethods]
impl PyLidar {
    #[new]
    // Every parameter left `None` is the core's `Lidar::default()`'s.
    #[pyo3(signature = (*, sigma_range=None, sigma_angle=None))]
    fn new(py: Python<'_>, sigma_range: Option<f64>, sigma_angle: Option<f64>) -> PyResult<Self> {
        let d = Lidar::default();
        let inner = Lidar {
            sigma_range: sigma_range.unwrap_or(d.sigma_range),
            sigma_angle: sigma_angle.unwrap_or(d.sigma_angle),
        };
        inner.validate().or_py(py)?;
        Ok(Self { inner })
    }

    #[getter]
    fn sigma_range(&self) -> f64 {
        self.inner.sigma_range
    }
    #[getter]
    fn sigma_angle(&self) -> f64 {
        self.inner.sigma_angle
    }

    /// Sensor covariances `(n, 3, 3)` of `points` seen from `origin` or `sensor_pose`.
    #[pyo3(signature = (points, origin=None, sensor_pose=None))]
    fn covariances<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        origin: Option<&Bound<'py, PyAny>>,
        sensor_pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        covariances_py(
            py,
            SensorModel::Lidar(self.inner),
            points,
            origin,
            sensor_pose,
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "Lidar(sigma_range={}, sigma_angle={})",
            self.inner.sigma_range, self.inner.sigma_angle
        )
    }
}

/// Covariances `(n, 3, 3)` with fixed standard deviations along (`sigma_ray`)
/// and across (`sigma_lateral`) each point's viewing ray from `origin` or
/// `sensor_pose`: the form of every sensor model, without its laws.
#[pyfunction]
#[pyo3(signature = (points, sigma_ray, sigma_lateral, *, origin=None, sensor_pose=None))]
pub fn ray_covariances<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    sigma_ray: f64,
    sigma_lateral: f64,
    origin: Option<&Bound<'py, PyAny>>,
    sensor_pose: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let points = points_from(points, "points")?;
    let vp = viewpoint_from(py, origin, sensor_pose)?;
    let covs = run_detached(py, move || {
        cloudprox::uncertainty::ray_covariances(&points, &vp, sigma_ray, sigma_lateral)
    })?;
    matrices3_to_py(py, &covs)
}
