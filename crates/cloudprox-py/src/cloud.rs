//! `PointCloud`: points with a covariance each.

use std::sync::Arc;

use cloudprox::cloud::PointCloud;
use cloudprox::math::{Matrix3, Point3};
use cloudprox::uncertainty::DiscretizationSettings;
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{
    matrices3_from, matrices3_to_py, points_from, points_to_py, pose_from, shape_str, to_f64_array,
    vec_to_py,
};
use crate::error::{invalid_input, run_detached};
use crate::request::{request_from, PyCollisionRequest};
use crate::sensor::{sensor_model_from, viewpoint_from};

/// The noise given to the constructor.
pub(crate) enum Noise {
    Sensor(
        cloudprox::uncertainty::SensorModel,
        cloudprox::uncertainty::Viewpoint,
    ),
    Sigma(f64),
    Sigmas(Vec<f64>),
    Covariances(Vec<Matrix3>),
}

pub(crate) fn noise_from(
    py: Python<'_>,
    sigma: Option<&Bound<'_, PyAny>>,
    cov: Option<&Bound<'_, PyAny>>,
    sensor: Option<&Bound<'_, PyAny>>,
    origin: Option<&Bound<'_, PyAny>>,
    sensor_pose: Option<&Bound<'_, PyAny>>,
) -> PyResult<Noise> {
    if let Some(sensor) = sensor {
        if sigma.is_some() || cov.is_some() {
            return Err(invalid_input(
                py,
                "give one of sigma, cov or sensor (the sensor model gives the covariances)",
            ));
        }
        let model = sensor_model_from(sensor)?;
        return Ok(Noise::Sensor(
            model,
            viewpoint_from(py, origin, sensor_pose)?,
        ));
    }
    if origin.is_some() || sensor_pose.is_some() {
        return Err(invalid_input(
            py,
            "origin and sensor_pose are only used with a sensor model (sensor=...)",
        ));
    }
    match (sigma, cov) {
        (Some(_), Some(_)) => Err(invalid_input(
            py,
            "give either sigma or cov, not both (cov already holds the full sensor noise)",
        )),
        (None, None) => Ok(Noise::Sigma(0.0)),
        (None, Some(cov)) => Ok(Noise::Covariances(matrices3_from(cov, "cov")?)),
        (Some(sigma), None) => {
            let arr = to_f64_array(sigma, "sigma")?;
            let values: Vec<f64> = arr.readonly().as_array().iter().copied().collect();
            match (arr.ndim(), values.as_slice()) {
                (0, &[s]) => Ok(Noise::Sigma(s)),
                (1, _) => Ok(Noise::Sigmas(values)),
                _ => Err(invalid_input(
                    py,
                    format!(
                        "sigma must be a scalar or an array of shape (n,), got shape {}",
                        shape_str(arr.shape())
                    ),
                )),
            }
        }
    }
}

/// The discretization settings asked for: `None` without discretization, the
/// core's defaults with `k` (checked) replaced when given; `k` without
/// discretization is refused.
pub(crate) fn discretization_settings(
    py: Python<'_>,
    discretization: bool,
    k: Option<i64>,
) -> PyResult<Option<DiscretizationSettings>> {
    match (discretization, k) {
        (true, k) => {
            let mut settings = DiscretizationSettings::default();
            if let Some(k) = k {
                settings.k = usize::try_from(k).map_err(|_| {
                    invalid_input(py, format!("discretization k must be >= 2, got {k}"))
                })?;
            }
            Ok(Some(settings))
        }
        (false, None) => Ok(None),
        (false, Some(k)) => Err(invalid_input(
            py,
            format!("k = {k} is only used with discretization=True"),
        )),
    }
}

/// A point cloud with a 3x3 covariance per point (the sensor noise, plus the
/// discretization error if requested), in its own frame.
///
/// The Rust cloud sits behind an `Arc`: queries share it (and its hierarchy,
/// built on first use) without copying.
#[pyclass(name = "PointCloud", frozen, module = "cloudprox._native")]
pub struct PyPointCloud {
    pub(crate) inner: Arc<PointCloud>,
    recipe: Recipe,
}

/// How a cloud was made, to rebuild it bit for bit after pickling: the root
/// cloud's points and sensor covariances (read from `root`), the discretization
/// neighbours (`None`: none added), then the rigid transforms applied in order.
/// The points' order, the covariances and the noise correlation are kept; the
/// hierarchy, spacing and surface elements are rebuilt lazily, deterministically.
#[derive(Clone)]
struct Recipe {
    root: Arc<PointCloud>,
    disc_k: Option<usize>,
    poses: Vec<cloudprox::math::Pose>,
}

/// A pose as 7 numbers: the unit quaternion's `(i, j, k, w)` and the translation.
pub(crate) fn pose_to_7(p: &cloudprox::math::Pose) -> [f64; 7] {
    let q = p.rotation.coords;
    let t = p.translation.vector;
    [q[0], q[1], q[2], q[3], t[0], t[1], t[2]]
}

/// The pose of [`pose_to_7`]'s numbers, exactly.
pub(crate) fn pose_from_7(v: &[f64; 7]) -> cloudprox::math::Pose {
    let q = nalgebra::Quaternion::new(v[3], v[0], v[1], v[2]);
    nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(v[4], v[5], v[6]),
        nalgebra::UnitQuaternion::new_unchecked(q),
    )
}

/// The pickled form of a `PointCloud` (see [`Recipe`]).
type CloudState<'py> = (
    u32,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    Option<usize>,
    f64,
    Vec<[f64; 7]>,
);

/// [`CloudState`] as read back (arrays as any array-like).
type CloudStateIn<'py> = (
    u32,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Option<usize>,
    f64,
    Vec<[f64; 7]>,
);

/// Version of [`CloudState`].
const CLOUD_STATE_VERSION: u32 = 1;

impl PyPointCloud {
    /// Wraps a cloud made in the core whose covariances are its sensor part
    /// plus, with `disc_k`, the discretization part of `disc_k` neighbours
    /// (what pickling rebuilds).
    pub(crate) fn from_core(cloud: PointCloud, disc_k: Option<usize>) -> Self {
        let inner = Arc::new(cloud);
        Self {
            recipe: Recipe {
                root: Arc::clone(&inner),
                disc_k,
                poses: Vec::new(),
            },
            inner,
        }
    }

    /// A cloud from points and noise, with the discretization part if asked for
    /// (`k` neighbours), built without the GIL.
    pub(crate) fn build(
        py: Python<'_>,
        points: Vec<Point3>,
        noise: Noise,
        discretization: bool,
        k: Option<i64>,
        noise_correlation: Option<f64>,
    ) -> PyResult<Self> {
        let disc = discretization_settings(py, discretization, k)?;
        let disc_k = disc.map(|d| d.k);
        let cloud = run_detached(py, move || {
            let cloud = match noise {
                Noise::Sensor(model, vp) => PointCloud::from_sensor(points, &model, &vp),
                Noise::Sigma(s) => PointCloud::from_sigma(points, s),
                Noise::Sigmas(s) => PointCloud::from_sigmas(points, s),
                Noise::Covariances(c) => PointCloud::from_covariances(points, c),
            }?;
            let mut cloud = match disc {
                Some(settings) => cloud.with_discretization(&settings)?,
                None => cloud,
            };
            if let Some(rho) = noise_correlation {
                cloud.set_noise_correlation(rho)?;
            }
            Ok(cloud)
        })?;
        let inner = Arc::new(cloud);
        Ok(Self {
            recipe: Recipe {
                root: Arc::clone(&inner),
                disc_k,
                poses: Vec::new(),
            },
            inner,
        })
    }
}

#[pymethods]
impl PyPointCloud {
    #[new]
    #[pyo3(signature = (
        points, sigma=None, cov=None, *, sensor=None, origin=None, sensor_pose=None,
        discretization=false, k=None, noise_correlation=None
    ))]
    fn new(
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        sigma: Option<&Bound<'_, PyAny>>,
        cov: Option<&Bound<'_, PyAny>>,
        sensor: Option<&Bound<'_, PyAny>>,
        origin: Option<&Bound<'_, PyAny>>,
        sensor_pose: Option<&Bound<'_, PyAny>>,
        discretization: bool,
        k: Option<i64>,
        noise_correlation: Option<f64>,
    ) -> PyResult<Self> {
        let points = points_from(points, "points")?;
        let noise = noise_from(py, sigma, cov, sensor, origin, sensor_pose)?;
        Self::build(py, points, noise, discretization, k, noise_correlation)
    }

    /// Point positions, shape `(n, 3)`, float64 (metres).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_to_py(py, self.inner.points())
    }

    /// Per-point total covariances, shape `(n, 3, 3)`, float64 (metres squared).
    #[getter]
    fn covariances<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        matrices3_to_py(py, self.inner.covariances())
    }

    /// Per-point largest standard deviation over all directions, shape `(n,)`.
    #[getter]
    fn sigma_max<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_to_py(py, self.inner.sigma_max())
    }

    /// Per-point sampling spacing, shape `(n,)`: the distance to the 6th nearest
    /// neighbour (computed on first use, without the GIL).
    #[getter]
    fn spacing<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let inner = Arc::clone(&self.inner);
        let s = run_detached(py, move || Ok(inner.spacing().to_vec()))?;
        Ok(PyArray1::from_vec(py, s))
    }

    /// The side of the square of surface each point stands for (metres): the
    /// median `spacing` times `sqrt(pi / 6)` (computed without the GIL).
    #[getter]
    fn cell_side(&self, py: Python<'_>) -> PyResult<f64> {
        let inner = Arc::clone(&self.inner);
        run_detached(py, move || Ok(inner.cell_side()))
    }

    /// Build now, without the GIL, every part of this cloud that a query under
    /// `request` (with the keyword `options` on top, as in ``collide``) builds on
    /// its first use: the hierarchy and sampling spacing and, for
    /// ``model="elements"``, the surface elements (every set of the
    /// ``segmentations`` the request averages over). Later queries then do not
    /// pay for it (the first query's ``time_seconds`` included); calling it
    /// again costs nothing. ``collide_many`` and the robot queries do it
    /// themselves.
    #[pyo3(signature = (request=None, **options))]
    fn prepare(
        &self,
        py: Python<'_>,
        request: Option<&Bound<'_, PyCollisionRequest>>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let request = request_from(py, request, options, &["request"])?;
        let inner = Arc::clone(&self.inner);
        run_detached(py, move || {
            cloudprox::query::prepare(&inner, &request);
            Ok(())
        })
    }

    /// Correlation of the sensor noise between the points of one surface element
    /// (set by `noise_correlation=`, else the sensor model's; 0 for `sigma`/`cov`).
    #[getter]
    fn noise_correlation(&self) -> f64 {
        self.inner.element_settings().noise_correlation
    }

    /// Per-point sensor covariances (without the discretization part), shape
    /// `(n, 3, 3)`.
    #[getter]
    fn sensor_covariances<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        matrices3_to_py(py, self.inner.sensor_covariances())
    }

    /// A new cloud of the points at `indices` (or, with `invert`, of every
    /// other point), in the order given: each keeps its sensor covariance and
    /// the cloud its noise correlation; a discretization covariance is
    /// estimated again from the kept points' neighbours (same `k`).
    #[pyo3(signature = (indices, invert=false))]
    fn select_by_index(
        &self,
        py: Python<'_>,
        indices: &Bound<'_, PyAny>,
        invert: bool,
    ) -> PyResult<Self> {
        if indices.cast::<PyArray1<bool>>().is_ok() {
            return Err(invalid_input(
                py,
                "indices must be integers, got a boolean mask: pass numpy.flatnonzero(mask)",
            ));
        }
        let raw: Vec<i64> = indices
            .extract()
            .map_err(|_| invalid_input(py, "indices must be a sequence of integers"))?;
        let n = self.inner.len();
        let mut chosen = Vec::with_capacity(raw.len());
        for &i in &raw {
            match usize::try_from(i) {
                Ok(u) if u < n => chosen.push(u),
                _ => {
                    return Err(invalid_input(
                        py,
                        format!("index {i} is out of range for a cloud of {n} points"),
                    ))
                }
            }
        }
        if invert {
            let mut keep = vec![true; n];
            for &i in &chosen {
                keep[i] = false;
            }
            chosen = (0..n).filter(|&i| keep[i]).collect();
        }
        if chosen.is_empty() {
            return Err(invalid_input(
                py,
                "the selection holds no point: a cloud needs at least one",
            ));
        }
        let points: Vec<_> = chosen.iter().map(|&i| self.inner.points()[i]).collect();
        let sensor: Vec<_> = chosen
            .iter()
            .map(|&i| self.inner.sensor_covariances()[i])
            .collect();
        let rho = self.inner.element_settings().noise_correlation;
        let disc_k = self.recipe.disc_k;
        let root = run_detached(py, move || root_cloud(points, sensor, disc_k, rho))?;
        let root = Arc::new(root);
        Ok(Self {
            inner: Arc::clone(&root),
            recipe: Recipe {
                root,
                disc_k,
                poses: Vec::new(),
            },
        })
    }

    /// A new cloud moved by the `(4, 4)` rigid transform `transform`.
    fn transformed(&self, py: Python<'_>, transform: &Bound<'_, PyAny>) -> PyResult<Self> {
        let pose = pose_from(py, Some(transform), "transform")?;
        let inner = Arc::clone(&self.inner);
        let moved = run_detached(py, move || inner.transformed(&pose))?;
        let mut recipe = self.recipe.clone();
        recipe.poses.push(pose);
        Ok(Self {
            inner: Arc::new(moved),
            recipe,
        })
    }

    /// Pickle support: the cloud is rebuilt from its root's points and sensor
    /// covariances, its discretization neighbours, noise correlation and moves.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (CloudState<'py>,))> {
        let py = slf.py();
        let me = slf.get();
        let root = &me.recipe.root;
        let state = (
            CLOUD_STATE_VERSION,
            points_to_py(py, root.points())?,
            matrices3_to_py(py, root.sensor_covariances())?,
            me.recipe.disc_k,
            root.element_settings().noise_correlation,
            me.recipe.poses.iter().map(pose_to_7).collect(),
        );
        Ok((slf.getattr("_from_state")?, (state,)))
    }

    /// Rebuilds a pickled cloud (see `__reduce__`).
    #[staticmethod]
    fn _from_state(py: Python<'_>, state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (version, points, sensor, disc_k, rho, poses): CloudStateIn<'_> = state.extract()?;
        if version != CLOUD_STATE_VERSION {
            return Err(invalid_input(
                py,
                format!("cannot unpickle a PointCloud of state version {version}"),
            ));
        }
        let points = points_from(&points, "pickled points")?;
        let sensor = matrices3_from(&sensor, "pickled covariances")?;
        let poses: Vec<_> = poses.iter().map(pose_from_7).collect();
        let moves = poses.clone();
        let (root, cloud) = run_detached(py, move || {
            let root = Arc::new(root_cloud(points, sensor, disc_k, rho)?);
            let mut cloud = Arc::clone(&root);
            for pose in &moves {
                cloud = Arc::new(cloud.transformed(pose)?);
            }
            Ok((root, cloud))
        })?;
        Ok(Self {
            inner: cloud,
            recipe: Recipe {
                root,
                disc_k,
                poses,
            },
        })
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        format!("PointCloud with {} points.", self.inner.len())
    }
}

/// A root cloud (no moves) from its points and sensor covariances, with the
/// discretization of `disc_k` neighbours (when given) and noise correlation
/// `rho`: what `select_by_index` and unpickling rebuild.
fn root_cloud(
    points: Vec<Point3>,
    sensor: Vec<Matrix3>,
    disc_k: Option<usize>,
    rho: f64,
) -> cloudprox::Result<PointCloud> {
    let mut root = PointCloud::from_covariances(points, sensor)?;
    if let Some(k) = disc_k {
        let settings = DiscretizationSettings {
            k,
            ..DiscretizationSettings::default()
        };
        root = root.with_discretization(&settings)?;
    }
    root.set_noise_correlation(rho)?;
    Ok(root)
}
