//! The [`PointCloud`] type.

use std::sync::OnceLock;

use crate::bvh::{Bvh, BvhSettings};
use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Pose};
use crate::uncertainty::{discretization_covariances, max_std, DiscretizationSettings, NoiseModel};
use crate::Real;

/// Points with a 3x3 covariance each, in the cloud's own frame.
///
/// The covariance of point `i` is `Sigma_i = Sigma_sensor,i + Sigma_disc,i`: the
/// sensor part comes from a [`NoiseModel`], the discretization part is added by
/// [`PointCloud::with_discretization`]. The bounding volume hierarchy over the
/// points is built on first use and shared by all queries (and threads) after.
#[derive(Debug)]
pub struct PointCloud {
    points: Vec<Point3>,
    covariances: Vec<Matrix3>,
    sigma_max: Vec<Real>,
    bvh_settings: BvhSettings,
    bvh: OnceLock<Bvh>,
}

impl Clone for PointCloud {
    fn clone(&self) -> Self {
        let bvh = OnceLock::new();
        if let Some(b) = self.bvh.get() {
            let _ = bvh.set(b.clone());
        }
        Self {
            points: self.points.clone(),
            covariances: self.covariances.clone(),
            sigma_max: self.sigma_max.clone(),
            bvh_settings: self.bvh_settings,
            bvh,
        }
    }
}

fn validate_points(points: &[Point3]) -> Result<()> {
    if points.is_empty() {
        return Err(Error::invalid("point cloud is empty"));
    }
    if let Some(i) = points
        .iter()
        .position(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(Error::invalid(format!(
            "point {i} has a NaN or infinite coordinate: {:?}",
            points[i].coords.as_slice()
        )));
    }
    Ok(())
}

impl PointCloud {
    /// A cloud whose sensor covariances come from `noise`. Errors on an empty cloud,
    /// non-finite coordinates, or an invalid noise model (see [`NoiseModel::covariances`]).
    pub fn new(points: Vec<Point3>, noise: &NoiseModel) -> Result<Self> {
        validate_points(&points)?;
        let covariances = noise.covariances(&points)?;
        Ok(Self::from_parts(points, covariances))
    }

    /// A cloud with the same isotropic standard deviation `sigma` (metres) everywhere.
    pub fn from_sigma(points: Vec<Point3>, sigma: Real) -> Result<Self> {
        Self::new(points, &NoiseModel::Isotropic(sigma))
    }

    /// A cloud with one isotropic standard deviation per point.
    pub fn from_sigmas(points: Vec<Point3>, sigmas: Vec<Real>) -> Result<Self> {
        Self::new(points, &NoiseModel::PerPointSigma(sigmas))
    }

    /// A cloud with a full covariance per point (validated symmetric PSD).
    pub fn from_covariances(points: Vec<Point3>, covariances: Vec<Matrix3>) -> Result<Self> {
        Self::new(points, &NoiseModel::Full(covariances))
    }

    fn from_parts(points: Vec<Point3>, covariances: Vec<Matrix3>) -> Self {
        let sigma_max = covariances.iter().map(max_std).collect();
        Self {
            points,
            covariances,
            sigma_max,
            bvh_settings: BvhSettings::default(),
            bvh: OnceLock::new(),
        }
    }

    /// Adds the k-nearest-neighbour discretization covariance to every point's
    /// covariance (see [`discretization_covariances`]).
    pub fn with_discretization(mut self, settings: &DiscretizationSettings) -> Result<Self> {
        let disc =
            discretization_covariances(&self.points, &self.covariances, self.bvh(), settings)?;
        for (c, d) in self.covariances.iter_mut().zip(disc) {
            *c += d;
        }
        self.sigma_max = self.covariances.iter().map(max_std).collect();
        if let Some(bvh) = self.bvh.get_mut() {
            bvh.refit(&self.points, &self.sigma_max)?;
        }
        Ok(self)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud has no points (never true for a constructed cloud).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Point positions in the cloud's own frame (metres).
    pub fn points(&self) -> &[Point3] {
        &self.points
    }

    /// Per-point total covariances (metres squared).
    pub fn covariances(&self) -> &[Matrix3] {
        &self.covariances
    }

    /// Per-point largest standard deviation over all directions.
    pub fn sigma_max(&self) -> &[Real] {
        &self.sigma_max
    }

    /// The hierarchy over the points, built on first call.
    pub fn bvh(&self) -> &Bvh {
        self.bvh.get_or_init(|| {
            Bvh::build(&self.points, &self.sigma_max, &self.bvh_settings)
                .expect("a validated non-empty cloud always has a hierarchy")
        })
    }

    /// Sets how the hierarchy is built; an existing one is dropped and rebuilt lazily.
    pub fn set_bvh_settings(&mut self, settings: BvhSettings) -> Result<()> {
        settings.validate()?;
        self.bvh_settings = settings;
        self.bvh = OnceLock::new();
        Ok(())
    }

    /// Moves the points (same number, same order, covariances kept) and refits the
    /// hierarchy's boxes in `O(n)` if it was built (see [`Bvh::refit`]).
    pub fn set_points(&mut self, points: Vec<Point3>) -> Result<()> {
        if points.len() != self.points.len() {
            return Err(Error::Shape {
                what: "moved points".into(),
                expected: self.points.len(),
                got: points.len(),
            });
        }
        validate_points(&points)?;
        self.points = points;
        if let Some(bvh) = self.bvh.get_mut() {
            bvh.refit(&self.points, &self.sigma_max)?;
        }
        Ok(())
    }

    /// Applies `pose` to the points and rotates the covariances (`R Sigma R^T`);
    /// the hierarchy is rebuilt lazily.
    pub fn transform(&mut self, pose: &Pose) {
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        for p in &mut self.points {
            *p = pose * *p;
        }
        for c in &mut self.covariances {
            *c = r * *c * r.transpose();
        }
        self.bvh = OnceLock::new();
    }

    /// A copy moved by `pose` (see [`PointCloud::transform`]).
    pub fn transformed(&self, pose: &Pose) -> Self {
        let mut c = self.clone();
        c.transform(pose);
        c
    }

    /// A new cloud holding the points at `indices` (in that order) with their covariances.
    pub fn select(&self, indices: &[usize]) -> Result<Self> {
        if let Some(&i) = indices.iter().find(|&&i| i >= self.len()) {
            return Err(Error::invalid(format!(
                "index {i} out of range for a cloud of {} points",
                self.len()
            )));
        }
        let points: Vec<Point3> = indices.iter().map(|&i| self.points[i]).collect();
        validate_points(&points)?;
        let covs = indices.iter().map(|&i| self.covariances[i]).collect();
        Ok(Self::from_parts(points, covs))
    }
}
