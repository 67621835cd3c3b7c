//! From a scan to a [`PointCloud`]: sensor noise, filter steps, discretization.
//!
//! A [`ScanPipeline`] turns the [`CloudData`] a reader returns into the cloud
//! the queries take, in three stages:
//!
//! 1. the sensor covariance of every point ([`ScanNoise`]): an isotropic sigma,
//!    the covariances stored in the file, or a range sensor's model
//!    ([`SensorModel`]) seen from where the sensor sat ([`SensorPlacement`]: a
//!    given origin or pose, else the file's own viewpoint, a PCD `VIEWPOINT`);
//! 2. the filter steps, in order ([`ScanStep`]: crop box, voxel downsampling,
//!    statistical outliers, shadow (veil) points, the robot's own points). Each
//!    step subsets the points with [`CloudData::select_indices`], keeping their
//!    covariances, normals and pixels aligned; voxel downsampling merges the
//!    covariances and drops the per-pixel layout. What each step removed is
//!    reported in a [`StepReport`];
//! 3. the [`PointCloud`], with the k-nearest-neighbour discretization part
//!    added ([`PointCloud::with_discretization`]) and, for a sensor model, the
//!    model's noise correlation for the surface elements.
//!
//! The covariances are computed once on the scan as read, before the filters:
//! the sensor model is a property of each measured point, and the voxel step
//! merges the members' covariances into its centroid's.
//!
//! ```
//! use cloudprox::scan::{ScanNoise, ScanPipeline, ScanStep, SensorPlacement};
//! use cloudprox::io::CloudData;
//! use cloudprox::math::Point3;
//! use cloudprox::uncertainty::{DepthCamera, SensorModel};
//!
//! // A 20 x 20 patch 1 m in front of a camera at the origin looking along +z.
//! let points: Vec<Point3> = (0..400)
//!     .map(|i| Point3::new((i % 20) as f64 * 0.005, (i / 20) as f64 * 0.005, 1.0))
//!     .collect();
//! let scan = CloudData::from_points(points);
//! let pipeline = ScanPipeline::new(ScanNoise::Sensor(SensorModel::DepthCamera(
//!     DepthCamera::default(),
//! )))
//! .placement(SensorPlacement::Origin(Point3::origin()))
//! .step(ScanStep::voxel(0.01))
//! .step(ScanStep::outliers());
//! let out = pipeline.run(&scan).unwrap();
//! assert_eq!(out.steps[0].before, 400);
//! assert_eq!(out.steps[0].after, 100);
//! assert_eq!(out.cloud.len(), out.steps[1].after);
//! ```

use rayon::prelude::*;

use crate::cloud::{validate_pose, PointCloud};
use crate::error::{Error, Result};
use crate::filter::{
    self, CovarianceMerge, SelfFilter, ShadowSettings, SOR_DEFAULT_K, SOR_DEFAULT_STD_RATIO,
};
use crate::io::CloudData;
use crate::math::{Matrix3, Point3, Pose};
use crate::uncertainty::{DiscretizationSettings, SensorModel, Viewpoint};
use crate::Real;

/// Where the sensor covariances of a scan's points come from.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ScanNoise {
    /// The same isotropic standard deviation (metres) for every point.
    Isotropic(Real),
    /// The covariances stored in the scan ([`CloudData::covariances`]).
    Stored,
    /// A range sensor's model, seen from the pipeline's [`SensorPlacement`].
    Sensor(SensorModel),
}

/// Where the sensor sat when it took the scan, in the scan's frame: what the
/// sensor model ([`ScanNoise::Sensor`]) and the shadow step need.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub enum SensorPlacement {
    /// The scan's own viewpoint ([`CloudData::sensor`], a PCD `VIEWPOINT`):
    /// its translation is the origin, its `+z` axis the optical axis. A scan
    /// that records none leaves the sensor unknown.
    #[default]
    FromScan,
    /// The sensor's optical centre; its axis unknown (depth taken as range).
    Origin(Point3),
    /// The sensor's pose (sensor to scan frame), looking along its `+z` axis.
    Pose(Pose),
}

/// One filter step of a [`ScanPipeline`] (see [`crate::filter`] for the rules).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum ScanStep {
    /// [`filter::crop_box`]: keep the points inside the box `[min, max]` given
    /// in the box's frame placed by `pose` (outside it with `invert`).
    Crop {
        /// The box's minimum corner, in its own frame.
        min: Point3,
        /// The box's maximum corner, in its own frame.
        max: Point3,
        /// The box's pose in the scan's frame.
        pose: Pose,
        /// Keep the points outside the box instead.
        invert: bool,
    },
    /// [`filter::voxel_downsample_with`]: one point per occupied voxel of side
    /// `size` (metres), the covariances merged by `merge`. The output has no
    /// normals and no per-pixel layout.
    Voxel {
        /// The voxel side (metres).
        size: Real,
        /// How the members' covariances are merged.
        merge: CovarianceMerge,
    },
    /// [`filter::statistical_outlier_removal`] with `k` neighbours and a
    /// threshold of `std_ratio` standard deviations.
    Outliers {
        /// The number of neighbours.
        k: usize,
        /// The threshold, in global standard deviations.
        std_ratio: Real,
    },
    /// [`filter::shadow_filter`] seen from the sensor origin of the
    /// pipeline's [`SensorPlacement`], on the image pixels of an organized scan
    /// (until a voxel step drops them).
    Shadow(ShadowSettings),
    /// [`SelfFilter::apply`]: remove the points on the robot's links.
    SelfFilter(SelfFilter),
}

impl ScanStep {
    /// A crop step: the axis-aligned box `[min, max]` in the scan's frame.
    pub fn crop(min: Point3, max: Point3) -> Self {
        Self::Crop {
            min,
            max,
            pose: Pose::identity(),
            invert: false,
        }
    }

    /// A voxel step of side `size` (metres), covariances merged by their mean
    /// ([`CovarianceMerge::Mean`]).
    pub fn voxel(size: Real) -> Self {
        Self::Voxel {
            size,
            merge: CovarianceMerge::Mean,
        }
    }

    /// An outlier step with the defaults [`SOR_DEFAULT_K`] and
    /// [`SOR_DEFAULT_STD_RATIO`].
    pub fn outliers() -> Self {
        Self::Outliers {
            k: SOR_DEFAULT_K,
            std_ratio: SOR_DEFAULT_STD_RATIO,
        }
    }

    /// A shadow step with the default [`ShadowSettings`].
    pub fn shadow() -> Self {
        Self::Shadow(ShadowSettings::default())
    }

    /// The step's name: `crop`, `voxel`, `outliers`, `shadow` or `self`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Crop { .. } => "crop",
            Self::Voxel { .. } => "voxel",
            Self::Outliers { .. } => "outliers",
            Self::Shadow(_) => "shadow",
            Self::SelfFilter(_) => "self",
        }
    }
}

/// What one filter step did: how many points went in and came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepReport {
    /// The step's name ([`ScanStep::name`]).
    pub step: &'static str,
    /// Points before the step.
    pub before: usize,
    /// Points after it.
    pub after: usize,
}

impl StepReport {
    /// How many points the step removed (or, for a voxel step, merged away).
    pub fn removed(&self) -> usize {
        self.before - self.after
    }
}

/// A scan-to-cloud pipeline: a noise source, where the sensor sat, ordered
/// filter steps and the discretization settings (see the [module docs](self)).
///
/// Built once, run on any number of scans ([`ScanPipeline::run`]).
#[derive(Debug, Clone)]
pub struct ScanPipeline {
    noise: ScanNoise,
    placement: SensorPlacement,
    steps: Vec<ScanStep>,
    discretization: Option<DiscretizationSettings>,
}

/// A scan after its noise and filter steps, before it becomes a
/// [`PointCloud`] ([`ScanPipeline::filter`]).
#[derive(Debug, Clone)]
pub struct FilteredScan {
    /// The points that are left, with their sensor covariances in
    /// [`CloudData::covariances`] (`None` for an isotropic sigma), normals and
    /// pixels kept aligned.
    pub data: CloudData,
    /// What each step did, in order; it stops at a step that left no point.
    pub steps: Vec<StepReport>,
    noise: ScanNoise,
    viewpoint: Option<Viewpoint>,
    discretization: Option<DiscretizationSettings>,
}

/// The result of [`ScanPipeline::run`].
#[derive(Debug, Clone)]
pub struct Scan {
    /// The cloud the queries take.
    pub cloud: PointCloud,
    /// What each filter step did, in order.
    pub steps: Vec<StepReport>,
}

impl ScanPipeline {
    /// A pipeline with this noise, the sensor placed by the scan's own viewpoint
    /// ([`SensorPlacement::FromScan`]), no filter step, and the default
    /// discretization settings.
    pub fn new(noise: ScanNoise) -> Self {
        Self {
            noise,
            placement: SensorPlacement::FromScan,
            steps: Vec::new(),
            discretization: Some(DiscretizationSettings::default()),
        }
    }

    /// Sets where the sensor sat.
    #[must_use]
    pub fn placement(mut self, placement: SensorPlacement) -> Self {
        self.placement = placement;
        self
    }

    /// Appends a filter step (steps run in the order they are added).
    #[must_use]
    pub fn step(mut self, step: ScanStep) -> Self {
        self.steps.push(step);
        self
    }

    /// Appends filter steps, in order.
    #[must_use]
    pub fn steps(mut self, steps: impl IntoIterator<Item = ScanStep>) -> Self {
        self.steps.extend(steps);
        self
    }

    /// Sets the discretization part's settings; `None` leaves it out (the
    /// cloud's covariances are then the sensor's alone).
    #[must_use]
    pub fn discretization(mut self, settings: Option<DiscretizationSettings>) -> Self {
        self.discretization = settings;
        self
    }

    /// The filter steps, in order.
    pub fn filter_steps(&self) -> &[ScanStep] {
        &self.steps
    }

    /// The noise source.
    pub fn noise(&self) -> &ScanNoise {
        &self.noise
    }

    /// The sensor placement.
    pub fn sensor_placement(&self) -> &SensorPlacement {
        &self.placement
    }

    /// Runs the pipeline on `scan`: noise, filter steps, then the cloud.
    ///
    /// # Errors
    /// As [`ScanPipeline::filter`], then [`FilteredScan::into_cloud`] (which
    /// fails when a step left no point, naming it).
    pub fn run(&self, scan: &CloudData) -> Result<Scan> {
        self.filter(scan)?.into_cloud()
    }

    /// The first two stages only: the sensor covariances of `scan`'s points and
    /// the filter steps. A step that leaves no point stops the pipeline without
    /// an error: the result's [`FilteredScan::emptied_by`] names it.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if the scan has no point or a non-finite one, if
    /// a placement's origin or pose is not finite, if the noise is
    /// [`ScanNoise::Stored`] and the scan stores no covariances, if a sensor
    /// model or a shadow step needs the sensor's position and it is unknown
    /// ([`SensorPlacement::FromScan`] on a scan without a viewpoint), or if a
    /// sigma, sensor model or step parameter is out of its domain (the core
    /// function's message); [`Error::Shape`] if the scan's covariances, normals
    /// or pixels are not one per point.
    pub fn filter(&self, scan: &CloudData) -> Result<FilteredScan> {
        check_scan(scan)?;
        let viewpoint = self.viewpoint(scan)?;
        let mut data = scan.clone();
        data.covariances = self.sensor_covariances(scan, viewpoint.as_ref())?;
        let mut steps = Vec::with_capacity(self.steps.len());
        for (i, step) in self.steps.iter().enumerate() {
            let before = data.points.len();
            data = apply_step(i, step, data, viewpoint.as_ref())?;
            let after = data.points.len();
            steps.push(StepReport {
                step: step.name(),
                before,
                after,
            });
            if after == 0 {
                break;
            }
        }
        Ok(FilteredScan {
            data,
            steps,
            noise: self.noise,
            viewpoint,
            discretization: self.discretization,
        })
    }

    /// The sensor's viewpoint, when known.
    fn viewpoint(&self, scan: &CloudData) -> Result<Option<Viewpoint>> {
        match &self.placement {
            SensorPlacement::Origin(o) => {
                if !o.coords.iter().all(|c| c.is_finite()) {
                    return Err(Error::invalid(format!(
                        "scan pipeline: sensor origin must be finite, got {:?}",
                        o.coords.as_slice()
                    )));
                }
                Ok(Some(Viewpoint::at(*o)))
            }
            SensorPlacement::Pose(p) => {
                validate_pose(p, "scan pipeline: sensor pose")?;
                Ok(Some(Viewpoint::from_pose(p)))
            }
            SensorPlacement::FromScan => match &scan.sensor {
                Some(p) => {
                    validate_pose(p, "scan pipeline: the scan's sensor pose")?;
                    Ok(Some(Viewpoint::from_pose(p)))
                }
                None => Ok(None),
            },
        }
    }

    /// The sensor covariance of every point (`None` for an isotropic sigma).
    fn sensor_covariances(
        &self,
        scan: &CloudData,
        viewpoint: Option<&Viewpoint>,
    ) -> Result<Option<Vec<Matrix3>>> {
        match &self.noise {
            ScanNoise::Isotropic(s) => {
                if !(s.is_finite() && *s >= 0.0) {
                    return Err(Error::invalid(format!(
                        "scan pipeline: sigma must be finite and >= 0, got {s}"
                    )));
                }
                Ok(None)
            }
            ScanNoise::Stored => match &scan.covariances {
                Some(c) => Ok(Some(c.clone())),
                None => Err(Error::invalid(
                    "scan pipeline: the scan stores no covariances: give an isotropic sigma \
                     or a sensor model",
                )),
            },
            ScanNoise::Sensor(model) => {
                let vp = viewpoint.ok_or_else(|| {
                    Error::invalid(
                        "scan pipeline: the scan records no sensor viewpoint: give the \
                         sensor's origin or pose for the sensor model",
                    )
                })?;
                // A laser scanner has no optical axis (a spinning lidar sees all
                // around): its model needs the origin only, and a pose's +z
                // must not make the points behind it "not in front".
                let vp = match model {
                    SensorModel::Lidar(_) => Viewpoint::at(vp.origin),
                    _ => *vp,
                };
                model.covariances(&scan.points, &vp).map(Some)
            }
        }
    }
}

/// A scan's points are non-empty and finite, and everything per point aligned.
fn check_scan(scan: &CloudData) -> Result<()> {
    if scan.points.is_empty() {
        return Err(Error::invalid(format!(
            "scan pipeline: the scan has no point with finite coordinates ({} skipped)",
            scan.skipped
        )));
    }
    if let Some(i) = scan
        .points
        .par_iter()
        .position_first(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(Error::invalid(format!(
            "scan pipeline: point {i} has a non-finite coordinate {:?}",
            scan.points[i].coords.as_slice()
        )));
    }
    scan.check_aligned("scan pipeline: the scan")
}

/// Step `i` on `data` (non-empty); the sensor covariances are in
/// `data.covariances`.
fn apply_step(
    i: usize,
    step: &ScanStep,
    data: CloudData,
    viewpoint: Option<&Viewpoint>,
) -> Result<CloudData> {
    let keep = match step {
        ScanStep::Crop {
            min,
            max,
            pose,
            invert,
        } => filter::crop_box(&data.points, min, max, pose, *invert)?,
        ScanStep::Voxel { size, merge } => {
            let v = filter::voxel_downsample_with(
                &data.points,
                data.covariances.as_deref(),
                *size,
                *merge,
            )?;
            return Ok(CloudData {
                points: v.points,
                covariances: v.covariances,
                normals: None,
                grid: None,
                ..data
            });
        }
        ScanStep::Outliers { k, std_ratio } => {
            filter::statistical_outlier_removal(&data.points, *k, *std_ratio)?
        }
        ScanStep::Shadow(settings) => {
            let vp = viewpoint.ok_or_else(|| {
                Error::invalid(format!(
                    "scan pipeline: step {i} (shadow) needs the sensor origin, which is unknown \
                     (the scan records no viewpoint): give the sensor's origin or pose"
                ))
            })?;
            filter::shadow_filter(&data.points, &vp.origin, data.grid.as_ref(), settings)?
        }
        ScanStep::SelfFilter(f) => f.apply(&data.points),
    };
    if keep.len() == data.points.len() {
        return Ok(data);
    }
    data.select_indices(&keep)
}

impl FilteredScan {
    /// The index of the step that left no point, if one did (the last one in
    /// [`FilteredScan::steps`]; the steps after it did not run).
    pub fn emptied_by(&self) -> Option<usize> {
        self.data.points.is_empty().then(|| self.steps.len() - 1)
    }

    /// The sensor's viewpoint used by the noise and the shadow step, if known.
    pub fn viewpoint(&self) -> Option<&Viewpoint> {
        self.viewpoint.as_ref()
    }

    /// The last stage: the [`PointCloud`] of the points that are left, with
    /// their sensor covariances (an isotropic sigma, or the covariances
    /// carried through the steps), the discretization part if set, and for a
    /// sensor model its noise correlation at these points
    /// ([`SensorModel::noise_correlation`]).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if a step left no point (naming it), or as
    /// [`PointCloud::from_covariances`] and
    /// [`PointCloud::with_discretization`] (e.g. a stored covariance that is
    /// not symmetric positive semi-definite, naming the point).
    pub fn into_cloud(self) -> Result<Scan> {
        if let Some(i) = self.emptied_by() {
            return Err(Error::invalid(format!(
                "scan pipeline: step {i} ({}) removed every point",
                self.steps[i].step
            )));
        }
        let CloudData {
            points,
            covariances,
            ..
        } = self.data;
        let rho = match (&self.noise, &self.viewpoint) {
            (ScanNoise::Sensor(model), Some(vp)) => Some(model.noise_correlation(&points, vp)?),
            _ => None,
        };
        let cloud = match (covariances, &self.noise) {
            (Some(c), _) => PointCloud::from_covariances(points, c)?,
            (None, ScanNoise::Isotropic(s)) => PointCloud::from_sigma(points, *s)?,
            (None, _) => {
                return Err(Error::invalid(
                    "scan pipeline: the scan has no sensor covariances",
                ))
            }
        };
        let mut cloud = match &self.discretization {
            Some(settings) => cloud.with_discretization(settings)?,
            None => cloud,
        };
        if let Some(rho) = rho {
            cloud.set_noise_correlation(rho)?;
        }
        Ok(Scan {
            cloud,
            steps: self.steps,
        })
    }
}
