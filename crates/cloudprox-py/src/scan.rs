//! The scan pipeline: `ScanStep`, `scan_to_cloud` and its `ScanResult` (the
//! core's `scan::ScanPipeline`).

use cloudprox::filter::SOR_DEFAULT_STD_RATIO;
use cloudprox::math::Point3;
use cloudprox::scan::{ScanNoise, ScanPipeline, ScanStep, SensorPlacement};
use pyo3::prelude::*;

use crate::cloud::{discretization_settings, PyPointCloud};
use crate::convert::{pose_from, vector3_from};
use crate::error::{invalid_input, run_detached};
use crate::filter::{covariance_merge, outlier_k, shadow_settings, PySelfFilter};
use crate::io::PyCloudFile;
use crate::sensor::sensor_model_from;

/// One filter step of `scan_to_cloud`, made by its static methods.
#[pyclass(name = "ScanStep", frozen, module = "cloudprox._native")]
pub struct PyScanStep {
    inner: ScanStep,
}

#[pymethods]
impl PyScanStep {
    /// Keep the points inside the box `[min, max]` (outside with `invert=True`);
    /// `pose` places the box in the scan's frame.
    #[staticmethod]
    #[pyo3(signature = (min, max, pose=None, invert=false))]
    fn crop(
        py: Python<'_>,
        min: &Bound<'_, PyAny>,
        max: &Bound<'_, PyAny>,
        pose: Option<&Bound<'_, PyAny>>,
        invert: bool,
    ) -> PyResult<Self> {
        Ok(Self {
            inner: ScanStep::Crop {
                min: Point3::from(vector3_from(min, "min")?),
                max: Point3::from(vector3_from(max, "max")?),
                pose: pose_from(py, pose, "pose")?,
                invert,
            },
        })
    }

    /// One point per occupied voxel of side `size`, covariances merged by
    /// `merge` (`"mean"` or `"independent"`).
    #[staticmethod]
    #[pyo3(signature = (size, merge="mean"))]
    fn voxel(py: Python<'_>, size: f64, merge: &str) -> PyResult<Self> {
        let merge = covariance_merge(py, merge)?;
        Ok(Self {
            inner: ScanStep::Voxel { size, merge },
        })
    }

    /// Statistical outlier removal; `k` and `std_ratio` left `None` are the
    /// core's defaults.
    #[staticmethod]
    #[pyo3(signature = (k=None, std_ratio=None))]
    fn outliers(py: Python<'_>, k: Option<i64>, std_ratio: Option<f64>) -> PyResult<Self> {
        Ok(Self {
            inner: ScanStep::Outliers {
                k: outlier_k(py, k)?,
                std_ratio: std_ratio.unwrap_or(SOR_DEFAULT_STD_RATIO),
            },
        })
    }

    /// The shadow (veil) filter seen from the sensor origin; settings left
    /// `None` are the core's defaults.
    #[staticmethod]
    #[pyo3(signature = (min_angle_deg=None, window=None, k=None))]
    fn shadow(
        py: Python<'_>,
        min_angle_deg: Option<f64>,
        window: Option<i64>,
        k: Option<i64>,
    ) -> PyResult<Self> {
        Ok(Self {
            inner: ScanStep::Shadow(shadow_settings(py, min_angle_deg, window, k)?),
        })
    }

    /// Remove the points on the robot, as `filter.apply` does.
    #[staticmethod]
    fn self_filter(py: Python<'_>, filter: &Bound<'_, PySelfFilter>) -> PyResult<Self> {
        Ok(Self {
            inner: ScanStep::SelfFilter(filter.get().snapshot(py)?),
        })
    }

    /// The step's name: `crop`, `voxel`, `outliers`, `shadow` or `self`.
    #[getter]
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn __repr__(&self) -> String {
        format!("ScanStep.{}", self.inner.name())
    }
}

/// What `scan_to_cloud` returns: the cloud and what each step did.
#[pyclass(name = "ScanResult", frozen, module = "cloudprox._native")]
pub struct PyScanResult {
    cloud: Option<Py<PyPointCloud>>,
    steps: Vec<(&'static str, usize, usize)>,
    emptied_by: Option<usize>,
}

#[pymethods]
impl PyScanResult {
    /// The `PointCloud`; raises `InvalidInputError` when a step removed every
    /// point (see `emptied_by`).
    #[getter]
    fn cloud(&self, py: Python<'_>) -> PyResult<Py<PyPointCloud>> {
        match (&self.cloud, self.emptied_by) {
            (Some(c), _) => Ok(c.clone_ref(py)),
            (None, Some(i)) => Err(invalid_input(
                py,
                format!(
                    "scan pipeline: step {i} ({}) removed every point",
                    self.steps[i].0
                ),
            )),
            (None, None) => Err(invalid_input(py, "scan pipeline: no cloud")),
        }
    }

    /// `(name, before, after)` for each step that ran, in order.
    #[getter]
    fn steps(&self) -> Vec<(&'static str, usize, usize)> {
        self.steps.clone()
    }

    /// The index of the step that left no point (the last one run), or `None`.
    #[getter]
    fn emptied_by(&self) -> Option<usize> {
        self.emptied_by
    }

    fn __repr__(&self) -> String {
        let steps: Vec<String> = self
            .steps
            .iter()
            .map(|(n, b, a)| format!("{n} {b} -> {a}"))
            .collect();
        format!("ScanResult(steps=[{}])", steps.join(", "))
    }
}

/// Runs the scan pipeline of the Rust core on a `CloudFile`: the sensor
/// covariances (`sigma`; `sensor` seen from `origin`, `sensor_pose` or the
/// file's viewpoint; else the covariances stored in the file), the `steps` in
/// order, then the `PointCloud` (discretization part added with `k` neighbours
/// unless `discretization=False`). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    scan, steps=Vec::new(), *, sigma=None, sensor=None, origin=None, sensor_pose=None,
    discretization=true, k=None
))]
#[allow(clippy::too_many_arguments)]
pub fn scan_to_cloud(
    py: Python<'_>,
    scan: &Bound<'_, PyCloudFile>,
    steps: Vec<Bound<'_, PyScanStep>>,
    sigma: Option<f64>,
    sensor: Option<&Bound<'_, PyAny>>,
    origin: Option<&Bound<'_, PyAny>>,
    sensor_pose: Option<&Bound<'_, PyAny>>,
    discretization: bool,
    k: Option<i64>,
) -> PyResult<PyScanResult> {
    let noise = match (sigma, sensor) {
        (Some(_), Some(_)) => {
            return Err(invalid_input(
                py,
                "give either sigma or sensor, not both (or neither: the covariances stored in \
                 the file)",
            ))
        }
        (Some(s), None) => ScanNoise::Isotropic(s),
        (None, Some(m)) => ScanNoise::Sensor(sensor_model_from(m)?),
        (None, None) => ScanNoise::Stored,
    };
    let placement = match (origin, sensor_pose) {
        (Some(_), Some(_)) => {
            return Err(invalid_input(
                py,
                "give either origin or sensor_pose, not both (sensor_pose holds the origin)",
            ))
        }
        (Some(o), None) => SensorPlacement::Origin(Point3::from(vector3_from(o, "origin")?)),
        (None, Some(p)) => SensorPlacement::Pose(pose_from(py, Some(p), "sensor_pose")?),
        (None, None) => SensorPlacement::FromScan,
    };
    let disc = discretization_settings(py, discretization, k)?;
    let pipeline = ScanPipeline::new(noise)
        .placement(placement)
        .steps(steps.into_iter().map(|s| s.get().inner.clone()))
        .discretization(disc);
    let data = std::sync::Arc::clone(&scan.get().data);
    let (cloud, reports, emptied_by) = run_detached(py, move || {
        let filtered = pipeline.filter(&data)?;
        let emptied_by = filtered.emptied_by();
        let reports = filtered.steps.clone();
        let cloud = match emptied_by {
            Some(_) => None,
            None => Some(filtered.into_cloud()?.cloud),
        };
        Ok((cloud, reports, emptied_by))
    })?;
    let cloud = cloud
        .map(|c| Py::new(py, PyPointCloud::from_core(c, disc.map(|d| d.k))))
        .transpose()?;
    Ok(PyScanResult {
        cloud,
        steps: reports
            .iter()
            .map(|r| (r.step, r.before, r.after))
            .collect(),
        emptied_by,
    })
}
