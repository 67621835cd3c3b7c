//! The sensor-cloud filters: `crop_box`, `voxel_downsample`,
//! `statistical_outlier_removal`, `shadow_filter`, `SelfFilter`.

use std::sync::RwLock;

use cloudprox::filter::{
    self, CovarianceMerge, SelfFilter, ShadowSettings, SELF_FILTER_DEFAULT_PADDING, SOR_DEFAULT_K,
    SOR_DEFAULT_STD_RATIO,
};
use cloudprox::io::Grid;
use cloudprox::math::{Point3, Pose};
use numpy::{PyArray1, PyArray2, PyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyIterator, PyTuple};

use crate::convert::{
    indices_to_py, matrices3_from, matrices3_to_py, points_from, points_to_py, pose_from,
    poses_from, vector3_from,
};
use crate::error::{invalid_input, run_detached, CoreResultExt};
use crate::mesh::PyMesh;

fn point3_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Point3> {
    Ok(Point3::from(vector3_from(obj, what)?))
}

/// `v` as a `usize`, refused by name below `min`.
pub(crate) fn usize_arg(py: Python<'_>, v: i64, what: &str, min: i64) -> PyResult<usize> {
    if v < min {
        return Err(invalid_input(
            py,
            format!("{what} must be >= {min}, got {v}"),
        ));
    }
    usize::try_from(v).map_err(|_| invalid_input(py, format!("{what} is too large: {v}")))
}

/// The voxel filter's covariance rule by name: `"mean"` or `"independent"`.
pub(crate) fn covariance_merge(py: Python<'_>, merge: &str) -> PyResult<CovarianceMerge> {
    match merge {
        "mean" => Ok(CovarianceMerge::Mean),
        "independent" => Ok(CovarianceMerge::MeanOfIndependent),
        other => Err(invalid_input(
            py,
            format!("merge must be \"mean\" or \"independent\", got {other:?}"),
        )),
    }
}

/// The outlier filter's neighbour count: `k` checked, or the core's default.
pub(crate) fn outlier_k(py: Python<'_>, k: Option<i64>) -> PyResult<usize> {
    match k {
        Some(k) => usize_arg(py, k, "k", 1),
        None => Ok(SOR_DEFAULT_K),
    }
}

/// The shadow filter's settings: those given, checked, the core's defaults
/// for the others.
pub(crate) fn shadow_settings(
    py: Python<'_>,
    min_angle_deg: Option<f64>,
    window: Option<i64>,
    k: Option<i64>,
) -> PyResult<ShadowSettings> {
    let default = ShadowSettings::default();
    Ok(ShadowSettings {
        min_angle: min_angle_deg.map_or(default.min_angle, f64::to_radians),
        window: window.map_or(Ok(default.window), |w| usize_arg(py, w, "window", 1))?,
        k: k.map_or(Ok(default.k), |k| usize_arg(py, k, "k", 1))?,
    })
}

/// Indices (ascending, int64) of the points inside the box `[min, max]` (outside
/// with `invert=True`); `pose` places the box in the cloud's frame.
#[pyfunction]
#[pyo3(signature = (points, min, max, pose=None, invert=false))]
pub fn crop_box<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    min: &Bound<'py, PyAny>,
    max: &Bound<'py, PyAny>,
    pose: Option<&Bound<'py, PyAny>>,
    invert: bool,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let points = points_from(points, "points")?;
    let (lo, hi) = (point3_from(min, "min")?, point3_from(max, "max")?);
    let pose = pose_from(py, pose, "pose")?;
    let keep = run_detached(py, move || {
        filter::crop_box(&points, &lo, &hi, &pose, invert)
    })?;
    Ok(indices_to_py(py, &keep))
}

tuple_class! {
    /// What ``voxel_downsample`` returns: one point per occupied voxel, with the
    /// merged covariances and the member counts. Unpacks as
    /// ``points, covariances, counts = voxel_downsample(...)``.
    "Voxels": PyVoxels {
        /// The centroid of each voxel's members, shape ``(m, 3)``.
        points: Py<PyArray2<f64>>,
        /// The merged covariance of each voxel, shape ``(m, 3, 3)``; ``None`` when
        /// no covariances were given.
        covariances: Option<Py<PyArray3<f64>>>,
        /// The number of input points in each voxel, shape ``(m,)``, int64.
        counts: Py<PyArray1<i64>>,
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Voxels(points={}, covariances={})",
            self.points.bind(py).shape()[0],
            if self.covariances.is_some() {
                "yes"
            } else {
                "None"
            }
        )
    }
}

/// Voxel downsampling: one point per occupied voxel of side `voxel_size` (the
/// centroid of its members), with merged covariances (`merge="mean"`: the mean
/// of the members'; `"independent"`: their sum over n^2) and member counts, as a
/// `Voxels`.
#[pyfunction]
#[pyo3(signature = (points, voxel_size, covariances=None, merge="mean"))]
pub fn voxel_downsample<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    voxel_size: f64,
    covariances: Option<&Bound<'py, PyAny>>,
    merge: &str,
) -> PyResult<PyVoxels> {
    let points = points_from(points, "points")?;
    let covs = covariances
        .map(|c| matrices3_from(c, "covariances"))
        .transpose()?;
    let merge = covariance_merge(py, merge)?;
    let v = run_detached(py, move || {
        filter::voxel_downsample_with(&points, covs.as_deref(), voxel_size, merge)
    })?;
    let counts: Vec<i64> = v.counts.iter().map(|&c| i64::from(c)).collect();
    Ok(PyVoxels {
        points: points_to_py(py, &v.points)?.unbind(),
        covariances: v
            .covariances
            .as_ref()
            .map(|c| matrices3_to_py(py, c).map(Bound::unbind))
            .transpose()?,
        counts: PyArray1::from_vec(py, counts).unbind(),
    })
}

/// Indices (ascending) of the points kept by statistical outlier removal (PCL's
/// rule: mean distance to the `k` nearest neighbours above the global mean plus
/// `std_ratio` standard deviations removes a point).
/// `k` and `std_ratio` left `None` are the core's `SOR_DEFAULT_K` and
/// `SOR_DEFAULT_STD_RATIO`.
#[pyfunction]
#[pyo3(signature = (points, k=None, std_ratio=None))]
pub fn statistical_outlier_removal<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    k: Option<i64>,
    std_ratio: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let std_ratio = std_ratio.unwrap_or(SOR_DEFAULT_STD_RATIO);
    let points = points_from(points, "points")?;
    let k = outlier_k(py, k)?;
    let keep = run_detached(py, move || {
        filter::statistical_outlier_removal(&points, k, std_ratio)
    })?;
    Ok(indices_to_py(py, &keep))
}

/// Indices (ascending) of the points kept by the shadow (veil) filter;
/// `min_angle_deg`, `window` and `k` left `None` are the core's
/// `ShadowSettings::default()`.
#[pyfunction]
#[pyo3(signature = (points, origin, *, pixels=None, grid_shape=None, min_angle_deg=None, window=None, k=None))]
pub fn shadow_filter<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    origin: &Bound<'py, PyAny>,
    pixels: Option<&Bound<'py, PyAny>>,
    grid_shape: Option<(i64, i64)>,
    min_angle_deg: Option<f64>,
    window: Option<i64>,
    k: Option<i64>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let points = points_from(points, "points")?;
    let origin = point3_from(origin, "origin")?;
    let grid = match (pixels, grid_shape) {
        (None, None) => None,
        (Some(px), Some((h, w))) => {
            let (h, w) = (
                usize_arg(py, h, "grid height", 1)?,
                usize_arg(py, w, "grid width", 1)?,
            );
            let px: Vec<i64> = px.extract().or_else(|_| {
                py.import("numpy")?
                    .call_method1("asarray", (px,))?
                    .call_method1("astype", ("int64",))?
                    .call_method0("tolist")?
                    .extract()
            })?;
            let n_pix = (h as u64) * (w as u64);
            let pixels = px
                .iter()
                .enumerate()
                .map(|(i, &p)| {
                    u32::try_from(p)
                        .ok()
                        .filter(|&p| u64::from(p) < n_pix)
                        .ok_or_else(|| {
                            invalid_input(
                                py,
                                format!("pixels[{i}] = {p} is outside the {h}x{w} grid"),
                            )
                        })
                })
                .collect::<PyResult<Vec<u32>>>()?;
            Some(Grid {
                width: w,
                height: h,
                pixels,
            })
        }
        _ => {
            return Err(invalid_input(
                py,
                "give both pixels and grid_shape (an organized cloud), or neither",
            ))
        }
    };
    let settings = shadow_settings(py, min_angle_deg, window, k)?;
    let keep = run_detached(py, move || {
        filter::shadow_filter(&points, &origin, grid.as_ref(), &settings)
    })?;
    Ok(indices_to_py(py, &keep))
}

/// Removes the points that lie on the robot: within `padding` of a link's
/// surface, or inside a closed link. Links are `(Mesh, pose)` pairs; the
/// acceleration structures are built once, `set_poses` moves the links.
#[pyclass(name = "SelfFilter", frozen, module = "cloudprox._native")]
pub struct PySelfFilter {
    inner: RwLock<SelfFilter>,
}

impl PySelfFilter {
    /// Wraps a core filter (`Robot.self_filter`).
    pub(crate) fn wrap(inner: SelfFilter) -> Self {
        Self {
            inner: RwLock::new(inner),
        }
    }

    /// A copy of the core filter as it is now (links and poses).
    pub(crate) fn snapshot(&self, py: Python<'_>) -> PyResult<SelfFilter> {
        self.inner
            .read()
            .map(|f| f.clone())
            .map_err(|_| invalid_input(py, "SelfFilter is poisoned by an earlier panic"))
    }
}

#[pymethods]
impl PySelfFilter {
    #[new]
    #[pyo3(signature = (links, padding=None))]
    fn new(py: Python<'_>, links: &Bound<'_, PyAny>, padding: Option<f64>) -> PyResult<Self> {
        let padding = padding.unwrap_or(SELF_FILTER_DEFAULT_PADDING);
        let mut parsed: Vec<(cloudprox::shape::Mesh, Pose)> = Vec::new();
        for (i, item) in links.try_iter()?.enumerate() {
            let item = item?;
            let (mesh, pose): (Bound<'_, PyAny>, Option<Bound<'_, PyAny>>) =
                if let Ok(m) = item.cast::<PyMesh>() {
                    (m.clone().into_any(), None)
                } else {
                    item.extract().map_err(|_| {
                        invalid_input(
                            py,
                            format!("links[{i}] must be a Mesh or a (Mesh, (4, 4) pose) pair"),
                        )
                    })?
                };
            let mesh = mesh.cast::<PyMesh>().map_err(|_| {
                invalid_input(py, format!("links[{i}]: the first item must be a Mesh"))
            })?;
            let pose = pose_from(py, pose.as_ref(), &format!("links[{i}] pose"))?;
            parsed.push(((*mesh.get().inner).clone(), pose));
        }
        let inner = run_detached(py, move || SelfFilter::new(parsed, padding))?;
        Ok(Self {
            inner: RwLock::new(inner),
        })
    }

    /// Moves the links: `(m, 4, 4)`, one pose per link.
    fn set_poses(&self, py: Python<'_>, poses: &Bound<'_, PyAny>) -> PyResult<()> {
        let poses = poses_from(poses, "poses")?;
        let mut f = self
            .inner
            .write()
            .map_err(|_| invalid_input(py, "SelfFilter is poisoned by an earlier panic"))?;
        f.set_poses(&poses).or_py(py)
    }

    /// The padding (metres).
    #[getter]
    fn padding(&self) -> f64 {
        self.inner.read().map_or(f64::NAN, |f| f.padding())
    }

    /// Indices (ascending) of the points not on the robot.
    fn apply<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let points = points_from(points, "points")?;
        let f = self
            .inner
            .read()
            .map_err(|_| invalid_input(py, "SelfFilter is poisoned by an earlier panic"))?;
        let keep = py.detach(|| f.apply(&points));
        Ok(indices_to_py(py, &keep))
    }
}
