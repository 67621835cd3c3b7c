//! The [`PointCloud`] type.

use std::sync::OnceLock;

use rayon::prelude::*;

use crate::bvh::{knn_of_every_point, Bvh, BvhSettings};
use crate::element::{ElementSettings, SurfaceElements};
use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Pose};
use crate::uncertainty::{max_std, DiscretizationSettings, NoiseModel};
use crate::Real;

/// Points with a 3x3 covariance each, in the cloud's own frame.
///
/// The covariance of point `i` is `Sigma_i = Sigma_sensor,i + Sigma_disc,i`: the
/// sensor part comes from a [`NoiseModel`], the discretization part is added by
/// [`PointCloud::with_discretization`]. The bounding volume hierarchy over the
/// points is built on first use and shared by all queries (and threads) after.
///
/// The sensor part is kept on its own: it is how far noise can carry a point
/// towards the other cloud, which decides pruning and the near region. The
/// discretization part spreads along the surface and stands for where between
/// the samples the surface is; there the near rule counts half a sampling
/// spacing instead (see `query::collide`).
#[derive(Debug)]
pub struct PointCloud {
    points: Vec<Point3>,
    covariances: Vec<Matrix3>,
    sigma_max: Vec<Real>,
    /// Sensor covariances when a discretization part was added (else `covariances`).
    sensor: Option<Vec<Matrix3>>,
    sensor_sigma_max: Vec<Real>,
    sensor_sigma_min: Vec<Real>,
    bvh_settings: BvhSettings,
    bvh: OnceLock<Bvh>,
    spacing: OnceLock<Spacing>,
    element_settings: ElementSettings,
    elements: ElementSets,
}

/// The most segmentations a query may average over
/// ([`crate::query::CollisionRequest::segmentations`]).
pub const MAX_SEGMENTATIONS: u32 = 16;

/// A cloud's surface elements, one set per segmentation, each built on first
/// use.
#[derive(Debug, Clone, Default)]
struct ElementSets([OnceLock<Box<SurfaceElements>>; MAX_SEGMENTATIONS as usize]);

/// Sampling spacing per point and its maximum per hierarchy node.
#[derive(Debug, Clone)]
struct Spacing {
    per_point: Vec<Real>,
    per_node: Vec<Real>,
    /// The two middle values of `per_point` in sorted order (equal for an odd
    /// count): its median, read by every query that samples a mesh or a
    /// robot's links against the cloud, without a pass over the cloud each.
    middle: (Real, Real),
}

impl Spacing {
    /// The spacing of every point, its maximum per node of `bvh` and its
    /// two middle values.
    fn new(per_point: Vec<Real>, bvh: &Bvh) -> Self {
        let per_node = bvh.node_max(&per_point);
        let mut sorted = per_point.clone();
        let mid = sorted.len() / 2;
        sorted.select_nth_unstable_by(mid, Real::total_cmp);
        let upper = sorted[mid];
        let lower = if sorted.len() % 2 == 1 {
            upper
        } else {
            sorted[..mid]
                .iter()
                .copied()
                .fold(Real::NEG_INFINITY, Real::max)
        };
        Spacing {
            per_point,
            per_node,
            middle: (lower, upper),
        }
    }
}

/// Neighbours behind the spacing estimate: the distance to the 6th nearest.
const SPACING_NEIGHBOURS: usize = 6;

impl Clone for PointCloud {
    fn clone(&self) -> Self {
        let bvh = OnceLock::new();
        if let Some(b) = self.bvh.get() {
            let _ = bvh.set(b.clone());
        }
        let spacing = OnceLock::new();
        if let Some(sp) = self.spacing.get() {
            let _ = spacing.set(sp.clone());
        }
        let elements = self.elements.clone();
        Self {
            points: self.points.clone(),
            covariances: self.covariances.clone(),
            sigma_max: self.sigma_max.clone(),
            sensor: self.sensor.clone(),
            sensor_sigma_max: self.sensor_sigma_max.clone(),
            sensor_sigma_min: self.sensor_sigma_min.clone(),
            bvh_settings: self.bvh_settings,
            bvh,
            spacing,
            element_settings: self.element_settings,
            elements,
        }
    }
}

/// The largest magnitude of a coordinate (metres) a [`PointCloud`] accepts, and
/// of a pose's translation in a query: a million kilometres. Beyond it squared
/// distances, quadric features and variances can overflow to infinity, and the
/// probabilities would be NaN.
pub const MAX_COORDINATE: Real = 1e9;

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
    if let Some(i) = points.iter().position(|p| p.coords.amax() > MAX_COORDINATE) {
        return Err(Error::invalid(format!(
            "point {i} has a coordinate beyond +-{MAX_COORDINATE:e} m: {:?}",
            points[i].coords.as_slice()
        )));
    }
    Ok(())
}

/// Covariances whose entries reach beyond `MAX_COORDINATE^2` (a standard
/// deviation beyond [`MAX_COORDINATE`]) overflow in the same way.
fn validate_covariance_scale(covariances: &[Matrix3]) -> Result<()> {
    let limit = MAX_COORDINATE * MAX_COORDINATE;
    if let Some(i) = covariances
        .iter()
        .position(|c| c.iter().any(|x| !x.is_finite()) || c.amax() > limit)
    {
        return Err(Error::invalid(format!(
            "point {i}: covariance entry {:e} is beyond ({MAX_COORDINATE:e} m)^2",
            covariances[i].amax()
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
        validate_covariance_scale(&covariances)?;
        let rho = match noise {
            NoiseModel::Sensor(model, viewpoint) => model.noise_correlation(&points, viewpoint)?,
            _ => 0.0,
        };
        let mut cloud = Self::from_parts(points, covariances);
        cloud.element_settings.noise_correlation = rho;
        Ok(cloud)
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

    /// A cloud seen by a range sensor: covariances anisotropic along each
    /// point's viewing ray from `viewpoint` (see [`crate::uncertainty::sensor`]),
    /// and its surface elements built with the sensor's noise correlation
    /// ([`crate::uncertainty::SensorModel::noise_correlation`]).
    pub fn from_sensor(
        points: Vec<Point3>,
        model: &crate::uncertainty::SensorModel,
        viewpoint: &crate::uncertainty::Viewpoint,
    ) -> Result<Self> {
        Self::new(points, &NoiseModel::Sensor(*model, *viewpoint))
    }

    fn from_parts(points: Vec<Point3>, covariances: Vec<Matrix3>) -> Self {
        // `max_std` and `min_std` from one eigen decomposition each.
        let (sigma_max, sensor_sigma_min): (Vec<Real>, Vec<Real>) = covariances
            .par_iter()
            .map(|c| {
                let ev = c.symmetric_eigenvalues();
                (ev.max().max(0.0).sqrt(), ev.min().max(0.0).sqrt())
            })
            .unzip();
        Self {
            points,
            covariances,
            sensor_sigma_max: sigma_max.clone(),
            sensor_sigma_min,
            sigma_max,
            sensor: None,
            bvh_settings: BvhSettings::default(),
            bvh: OnceLock::new(),
            spacing: OnceLock::new(),
            element_settings: ElementSettings::default(),
            elements: ElementSets::default(),
        }
    }

    /// A cloud from total and sensor covariances that are already valid (the
    /// samples of surface elements).
    pub(crate) fn from_total_and_sensor(
        points: Vec<Point3>,
        total: Vec<Matrix3>,
        sensor: Vec<Matrix3>,
    ) -> Self {
        let mut c = Self::from_parts(points, sensor);
        c.sensor = Some(std::mem::replace(&mut c.covariances, total));
        c.sigma_max = c.covariances.par_iter().map(max_std).collect();
        c
    }

    /// The cloud's surface elements (see [`crate::element`]), built on first
    /// call in the cloud's own frame and kept until the points move (the
    /// settings' segmentation, see [`PointCloud::segmentation`]).
    pub fn elements(&self) -> &SurfaceElements {
        self.segmentation(self.element_settings.segmentation)
    }

    /// The element set `offset` segmentations past the settings' own: the
    /// `offset`-th of the sets a query averages over
    /// ([`crate::query::CollisionRequest::segmentations`]).
    pub(crate) fn segmentation_after(&self, offset: u32) -> &SurfaceElements {
        self.segmentation(self.element_settings.segmentation.wrapping_add(offset))
    }

    /// The cloud's surface elements of segmentation `k`
    /// ([`ElementSettings::segmentation`], the other settings the cloud's),
    /// built on first call and kept until the points move (each set about as
    /// large as the cloud's points; a query over `K` segmentations keeps `K`).
    /// [`PointCloud::elements`] is the settings' own segmentation. `k` is
    /// taken modulo [`MAX_SEGMENTATIONS`].
    #[allow(clippy::expect_used)] // settings validated when set, cloud non-empty and finite
    pub fn segmentation(&self, k: u32) -> &SurfaceElements {
        let k = k % MAX_SEGMENTATIONS;
        self.elements.0[k as usize].get_or_init(|| {
            let settings = ElementSettings {
                segmentation: k,
                ..self.element_settings
            };
            Box::new(
                SurfaceElements::build(self, &settings)
                    .expect("element settings are validated when set"),
            )
        })
    }

    /// How the surface elements are built; existing ones are dropped and
    /// rebuilt lazily.
    pub fn set_element_settings(&mut self, settings: ElementSettings) -> Result<()> {
        settings.validate()?;
        self.element_settings = settings;
        self.elements = ElementSets::default();
        Ok(())
    }

    /// Sets the correlation of the sensor noise between the points of an
    /// element ([`ElementSettings::noise_correlation`], in `[0, 1]`), the
    /// other element settings kept; existing elements are dropped.
    pub fn set_noise_correlation(&mut self, rho: Real) -> Result<()> {
        self.set_element_settings(ElementSettings {
            noise_correlation: rho,
            ..self.element_settings
        })
    }

    /// The settings the surface elements are built with.
    pub fn element_settings(&self) -> &ElementSettings {
        &self.element_settings
    }

    /// Adds the k-nearest-neighbour discretization covariance to every point's
    /// covariance (see [`crate::uncertainty::discretization_covariances`]).
    pub fn with_discretization(mut self, settings: &DiscretizationSettings) -> Result<Self> {
        // The spacing's neighbours are among the discretization's: both
        // from one k-NN pass.
        let (disc, spacing) = settings.covariances_and_nth_distance(
            &self.points,
            self.sensor_covariances(),
            self.bvh(),
            SPACING_NEIGHBOURS,
        )?;
        if let Some(per_point) = spacing {
            if self.spacing.get().is_none() {
                let _ = self.spacing.set(Spacing::new(per_point, self.bvh()));
            }
        }
        if self.sensor.is_none() {
            self.sensor = Some(self.covariances.clone());
        }
        for (c, d) in self.covariances.iter_mut().zip(disc) {
            *c += d;
        }
        self.sigma_max = self.covariances.par_iter().map(max_std).collect();
        self.elements = ElementSets::default();
        Ok(self)
    }

    /// Adds a known discretization covariance to every point's covariance (as
    /// [`PointCloud::with_discretization`] does with its estimate); for samples of
    /// an exact surface whose patch per sample is known.
    pub fn with_discretization_covariances(mut self, disc: Vec<Matrix3>) -> Result<Self> {
        if disc.len() != self.points.len() {
            return Err(Error::Shape {
                what: "discretization covariances".into(),
                expected: self.points.len(),
                got: disc.len(),
            });
        }
        for (i, d) in disc.iter().enumerate() {
            crate::uncertainty::validate_covariance(d, &format!("discretization of point {i}"))?;
        }
        if self.sensor.is_none() {
            self.sensor = Some(self.covariances.clone());
        }
        for (c, d) in self.covariances.iter_mut().zip(disc) {
            *c += d;
        }
        self.sigma_max = self.covariances.par_iter().map(max_std).collect();
        self.elements = ElementSets::default();
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

    /// Per-point sensor covariances (the total without the discretization part).
    pub fn sensor_covariances(&self) -> &[Matrix3] {
        self.sensor.as_deref().unwrap_or(&self.covariances)
    }

    /// Per-point largest sensor standard deviation: what the hierarchy's pruning
    /// and the near rule use.
    pub fn sensor_sigma_max(&self) -> &[Real] {
        &self.sensor_sigma_max
    }

    /// Per-point smallest sensor standard deviation (the near rule's quick accept).
    pub fn sensor_sigma_min(&self) -> &[Real] {
        &self.sensor_sigma_min
    }

    /// The hierarchy over the points, built on first call.
    #[allow(clippy::expect_used)] // a validated cloud is non-empty and finite
    pub fn bvh(&self) -> &Bvh {
        self.bvh.get_or_init(|| {
            Bvh::build(&self.points, &self.sensor_sigma_max, &self.bvh_settings)
                .expect("a validated non-empty cloud always has a hierarchy")
        })
    }

    /// Local sampling spacing of every point: the distance to its 6th nearest
    /// neighbour in the cloud (0 for clouds of fewer than 7 points, which use
    /// their farthest point). Computed on first call.
    pub fn spacing(&self) -> &[Real] {
        &self.spacing_data().per_point
    }

    /// The side of the square of surface each point stands for: the median of
    /// [`PointCloud::spacing`] (`d_6`) times `sqrt(pi / 6)` (a surface density
    /// of 6 points in a disc of radius `d_6`, `6 / (pi d_6^2)` points per square
    /// metre). A regular grid of pitch `h` gives `h sqrt(2 pi / 6)`.
    pub fn cell_side(&self) -> Real {
        // The mean of the two middle values, as numpy's median (the one
        // middle value, exactly, for an odd count: both are it).
        let (lower, upper) = self.spacing_data().middle;
        0.5 * (lower + upper) * (std::f64::consts::PI / SPACING_NEIGHBOURS as Real).sqrt()
    }

    /// The upper of the two middle values of [`PointCloud::spacing`] in sorted
    /// order (the median for an odd count), computed once with the spacings.
    pub(crate) fn spacing_upper_median(&self) -> Real {
        self.spacing_data().middle.1
    }

    /// The largest [`PointCloud::spacing`] below every node of [`PointCloud::bvh`].
    pub fn node_spacing(&self) -> &[Real] {
        &self.spacing_data().per_node
    }

    fn spacing_data(&self) -> &Spacing {
        self.spacing.get_or_init(|| {
            let k = SPACING_NEIGHBOURS.min(self.points.len() - 1);
            // The distance to the k-th neighbour does not depend on how
            // ties are broken.
            let per_point: Vec<Real> = knn_of_every_point(&self.points, self.bvh(), k, |_, nb| {
                nb.last().map_or(0.0, |&(d2, _)| d2.sqrt())
            });
            Spacing::new(per_point, self.bvh())
        })
    }

    /// Sets how the hierarchy is built; an existing one is dropped and rebuilt lazily.
    pub fn set_bvh_settings(&mut self, settings: BvhSettings) -> Result<()> {
        settings.validate()?;
        self.bvh_settings = settings;
        self.bvh = OnceLock::new();
        self.spacing = OnceLock::new();
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
            bvh.refit(&self.points, &self.sensor_sigma_max)?;
        }
        self.spacing = OnceLock::new();
        self.elements = ElementSets::default();
        Ok(())
    }

    /// Applies `pose` to the points and rotates the covariances (`R Sigma R^T`);
    /// the hierarchy is rebuilt lazily.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] when a moved point would have a non-finite
    /// coordinate or one beyond the range every cloud is held to (a pose with
    /// a huge or non-finite translation); the cloud is then left unchanged.
    pub fn transform(&mut self, pose: &Pose) -> Result<()> {
        let moved: Vec<Point3> = self.points.iter().map(|p| pose * p).collect();
        validate_points(&moved).map_err(|e| match e {
            Error::InvalidInput(m) => {
                Error::invalid(format!("the pose moves the cloud out of range: {m}"))
            }
            e => e,
        })?;
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        self.points = moved;
        for c in self
            .covariances
            .iter_mut()
            .chain(self.sensor.iter_mut().flatten())
        {
            *c = r * *c * r.transpose();
        }
        self.bvh = OnceLock::new();
        self.spacing = OnceLock::new();
        self.elements = ElementSets::default();
        Ok(())
    }

    /// A copy moved by `pose` (see [`PointCloud::transform`]).
    ///
    /// # Errors
    /// As [`PointCloud::transform`].
    pub fn transformed(&self, pose: &Pose) -> Result<Self> {
        let mut c = self.clone();
        c.transform(pose)?;
        Ok(c)
    }
}

#[cfg(test)]
mod spacing_tests {
    use super::*;
    use crate::bvh::GRID_KNN_MIN_POINTS;
    use crate::sample::{add_noise, box_surface};

    /// A pose that moves the points out of range is refused by name and leaves
    /// the cloud as it was.
    #[test]
    fn a_pose_out_of_range_is_refused() {
        let pts = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(0.1, 0.0, 0.0)];
        let mut cloud = PointCloud::from_sigma(pts.clone(), 0.001).unwrap();
        for t in [1e300, Real::INFINITY, Real::NAN] {
            let pose = Pose::translation(t, 0.0, 0.0);
            let err = cloud.transformed(&pose).unwrap_err().to_string();
            assert!(
                err.contains("the pose moves the cloud out of range"),
                "{err}"
            );
            assert!(cloud.transform(&pose).is_err());
            assert_eq!(cloud.points(), &pts[..]);
        }
        let moved = cloud
            .transformed(&Pose::translation(1.0, 0.0, 0.0))
            .unwrap();
        assert_eq!(moved.points()[1], Point3::new(1.1, 0.0, 0.0));
    }

    /// The spacing that the discretization's k-NN pass leaves behind is the
    /// one the spacing's own pass finds, bit for bit, on the grid (large
    /// clouds) and on the tree (small ones), and on clouds smaller than the
    /// neighbourhoods.
    #[test]
    fn spacing_from_the_discretization_is_the_spacing() {
        let big = add_noise(
            &box_surface(
                &Point3::origin(),
                &crate::math::Vector3::new(0.3, 0.2, 0.1),
                0.004,
            ),
            0.001,
            3,
        );
        assert!(big.len() > GRID_KNN_MIN_POINTS);
        for n in [big.len(), 3000, 8, 5, 2] {
            let pts = big[..n].to_vec();
            let own = PointCloud::from_sigma(pts.clone(), 0.001).unwrap();
            let disc = PointCloud::from_sigma(pts, 0.001)
                .unwrap()
                .with_discretization(&DiscretizationSettings::default())
                .unwrap();
            assert!(disc.spacing.get().is_some(), "{n} points: not left behind");
            assert_eq!(own.spacing(), disc.spacing(), "{n} points");
            assert_eq!(own.node_spacing(), disc.node_spacing(), "{n} points");
            assert_eq!(own.cell_side().to_bits(), disc.cell_side().to_bits());
        }
        // Neighbourhoods smaller than the spacing's: its own pass.
        let few = DiscretizationSettings {
            k: 3,
            ..DiscretizationSettings::default()
        };
        let pts = big[..3000].to_vec();
        let own = PointCloud::from_sigma(pts.clone(), 0.001).unwrap();
        let disc = PointCloud::from_sigma(pts, 0.001)
            .unwrap()
            .with_discretization(&few)
            .unwrap();
        assert!(disc.spacing.get().is_none());
        assert_eq!(own.spacing(), disc.spacing());
    }

    /// The grid path (large clouds) and the tree path give the same spacing.
    #[test]
    fn grid_and_tree_spacing_agree() {
        let pts = add_noise(
            &box_surface(
                &Point3::origin(),
                &crate::math::Vector3::new(0.3, 0.2, 0.1),
                0.004,
            ),
            0.001,
            3,
        );
        assert!(pts.len() > GRID_KNN_MIN_POINTS);
        let cloud = PointCloud::from_sigma(pts.clone(), 0.001).unwrap();
        let grid = cloud.spacing().to_vec();
        let bvh = cloud.bvh();
        let mut ws = crate::bvh::BvhWorkspace::default();
        let mut nn = Vec::new();
        for (i, p) in pts.iter().enumerate() {
            bvh.nearest_k(&pts, p, SPACING_NEIGHBOURS + 1, &mut ws, &mut nn);
            let tree = nn.last().unwrap().0.sqrt();
            assert_eq!(grid[i], tree, "point {i}");
        }
    }
}
