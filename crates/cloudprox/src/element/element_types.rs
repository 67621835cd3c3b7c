//! The types of the surface-element stage.

use std::sync::OnceLock;

use crate::bvh::Aabb;
use crate::cloud::PointCloud;
use crate::element::element_reach::ElementHulls;
use crate::error::{Error, Result};
use nalgebra::{SMatrix, SVector};

use crate::math::{Matrix3, Point3, Vector3};
use crate::Real;

/// How a cloud's points are grouped into surface elements.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementSettings {
    /// Significance level of the residual tests (default 0.01): the
    /// probability of splitting a group that does sample one smooth surface
    /// with the stated noise. (Curvature splits by Mallows' Cp, without a
    /// level, except in groups of fewer than twice `min_points`, which use
    /// this level: see the [module docs](crate::element).)
    pub significance: Real,
    /// The fewest points of an element (default 10; at least 7, the quadric fit
    /// needs 6 and its residual test a degree of freedom); smaller groups that
    /// fail the tests stay single points.
    pub min_points: usize,
    /// Correlation `rho` in `[0, 1]` of the sensor noise between the points of an
    /// element (default 0, independent). The mean of `m` points then has the
    /// covariance `(1 - rho) sum(Sigma_i) / m^2 + rho sum(Sigma_i) / m`: with
    /// `rho = 1` averaging gains nothing (a depth camera's calibration error moves
    /// a whole patch together).
    pub noise_correlation: Real,
    /// Which segmentation of the points (default 0, below
    /// [`MAX_SEGMENTATIONS`](crate::cloud::MAX_SEGMENTATIONS)): 0 halves every group
    /// that fails the element tests at the median along its widest axis;
    /// `k > 0` at a quantile between 40% and 60% drawn from `k` and the
    /// group (deterministic), so that each `k` groups the same points into
    /// differently placed elements. Where a contact falls relative to the
    /// element boundaries changes which planes read it; averaging a query
    /// over several segmentations
    /// ([`CollisionRequest::segmentations`](crate::query::CollisionRequest::segmentations))
    /// averages that out.
    pub segmentation: u32,
}

impl Default for ElementSettings {
    fn default() -> Self {
        Self {
            significance: 0.01,
            min_points: 10,
            noise_correlation: 0.0,
            segmentation: 0,
        }
    }
}

impl ElementSettings {
    /// Checks every field's domain.
    pub fn validate(&self) -> Result<()> {
        if !(self.significance > 0.0 && self.significance < 0.5) {
            return Err(Error::invalid(format!(
                "element significance must be in (0, 0.5), got {}",
                self.significance
            )));
        }
        if self.min_points < 7 {
            return Err(Error::invalid(format!(
                "element min_points must be >= 7, got {}",
                self.min_points
            )));
        }
        if !(0.0..=1.0).contains(&self.noise_correlation) {
            return Err(Error::invalid(format!(
                "noise_correlation must be in [0, 1], got {}",
                self.noise_correlation
            )));
        }
        if self.segmentation >= crate::cloud::MAX_SEGMENTATIONS {
            return Err(Error::invalid(format!(
                "element segmentation must be below {}, got {}",
                crate::cloud::MAX_SEGMENTATIONS,
                self.segmentation
            )));
        }
        Ok(())
    }
}

/// A group of points that samples one smooth piece of surface within their
/// noise, or a single point. In the cloud's own frame.
///
/// The surface is a quadric height field over the points' principal plane: a
/// point at tangential coordinates `(u, v)` from the mean lies at height
/// `h(u, v) = height . x` along the normal, `x = (1, u, v, u^2, u v, v^2)`,
/// fitted by weighted least squares; the variance of the fitted height there
/// is `x^T height_cov x + common_var`. (A plane fitted to a curved patch lies
/// outside a convex surface near the patch's edges, where two surfaces first
/// meet: the quadric reads the gap there without that bias, with the
/// variance its curvature terms add.)
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceElement {
    /// Index of the element's first point in [`SurfaceElements::indices`].
    pub first: u32,
    /// Number of points.
    pub count: u32,
    /// The points' mean.
    pub mean: Point3,
    /// Unit normal of the points' principal plane (its sign is arbitrary).
    pub normal: Vector3,
    /// Unit tangents: the sides of the smallest rectangle holding the points
    /// in the tangent plane, the longer first (a square face gets its sides,
    /// not its diagonals, which principal axes may give).
    pub tangents: [Vector3; 2],
    /// The surface's range along each tangent, `[min, max]` from the mean:
    /// where its sampled edges are, read from the points with their noise
    /// taken out (a noisy sampling up to an edge puts `rho s / sqrt(2 pi)` of
    /// its points beyond it, `rho` the density there and `s` the noise along
    /// the tangent, so about a quarter of the points within `2 s` inside the
    /// edge lie beyond it). It follows the density near each edge, so a floor
    /// seen at a grazing angle (points bunched towards the camera, noise along
    /// the rays nearly in the floor's plane) is covered to its far edge, and it
    /// is not pushed out by the outermost noisy points.
    pub extent: [[Real; 2]; 2],
    /// Tangential coordinates where the fitted surface is probed in a query: up
    /// to 25 of the points' own (the extremes along each tangent and a stride
    /// over the rest), inside `extent`.
    pub probes: Vec<[Real; 2]>,
    /// The points' mean sampling spacing (distance to the 6th nearest
    /// neighbour, see [`PointCloud::spacing`]).
    pub spacing: Real,
    /// Covariance of the mean (metres squared): `sum(Sigma_i) / m^2` for
    /// independent noise.
    pub cov_mean: Matrix3,
    /// Coefficients of the fitted quadric's height over `(1, u, v, u^2, u v, v^2)`.
    pub height: [Real; 6],
    /// Covariance of `height` (the share of independent noise).
    pub height_cov: SMatrix<Real, 6, 6>,
    /// Variance added to every fitted height by noise correlated between the
    /// points (see [`ElementSettings::noise_correlation`]).
    pub common_var: Real,
    /// Where the surface was sampled: the points' tangential coordinates,
    /// sorted by cells of side [`SurfaceElement::spacing`] (see
    /// [`SurfaceElement::covers`]). Empty for a single point.
    pub footprint: Vec<FootprintPoint>,
}

/// The quadric height field's row `(1, u, v, u^2, u v, v^2)`.
pub(crate) fn height_row(u: Real, v: Real) -> SVector<Real, 6> {
    SVector::<Real, 6>::new(1.0, u, v, u * u, u * v, v * v)
}

/// One point of an element's footprint: its cell `(i, j)` of side `spacing`
/// and its tangential coordinates `(u, v)`.
pub type FootprintPoint = (i32, i32, f32, f32);

/// The cell of side `cell` holding tangential coordinates `(u, v)`.
pub(crate) fn footprint_cell(u: Real, v: Real, cell: Real) -> (i32, i32) {
    ((u / cell).floor() as i32, (v / cell).floor() as i32)
}

impl SurfaceElement {
    /// The fitted height at `(u, v)` (without its variance).
    pub fn height_at(&self, u: Real, v: Real) -> Real {
        height_row(u, v).dot(&SVector::<Real, 6>::from(self.height))
    }

    /// A bound on how far the fitted surface over the extent lies, along the
    /// normal, from the convex hull of its four extent corners: the surface's
    /// bilinear interpolation between the corners lies in their hull, and the
    /// quadric differs from it by `c_uu (u - u0)(u - u1) + c_vv (v - v0)(v - v1)`
    /// (the `u v` term is bilinear itself), at most `(|c_uu| du^2 + |c_vv|
    /// dv^2) / 4` over the extent. 0 for a single point.
    pub(crate) fn sag_bound(&self) -> Real {
        if self.is_point() {
            return 0.0;
        }
        let [[u0, u1], [v0, v1]] = self.extent;
        let h = &self.height;
        0.25 * (h[3].abs() * (u1 - u0).powi(2) + h[5].abs() * (v1 - v0).powi(2))
    }

    /// The largest variance of the fitted height over the extent, read on a
    /// 5 x 5 grid over it (the variance is a smooth quartic of `(u, v)`
    /// there, largest towards the corners), with a tenth more for what lies
    /// between the grid's nodes.
    pub(crate) fn height_var_bound(&self) -> Real {
        if self.is_point() {
            return 0.0;
        }
        let [[u0, u1], [v0, v1]] = self.extent;
        let mut largest: Real = 0.0;
        for i in 0..5 {
            for j in 0..5 {
                let (u, v) = (
                    u0 + (u1 - u0) * Real::from(i) / 4.0,
                    v0 + (v1 - v0) * Real::from(j) / 4.0,
                );
                let x = height_row(u, v);
                largest = largest.max(x.dot(&(self.height_cov * x)));
            }
        }
        1.1 * largest.max(0.0) + self.common_var
    }

    /// Whether the element is a single point kept as it is.
    pub fn is_point(&self) -> bool {
        self.count == 1
    }

    /// Standard deviation of the mean along the normal.
    pub fn normal_std(&self) -> Real {
        crate::uncertainty::directional_std_of(&self.cov_mean, &self.normal)
    }

    /// The point of the fitted surface over tangential coordinates `(u, v)`
    /// and the variance of its height along the normal.
    pub fn surface_point(&self, u: Real, v: Real) -> (Point3, Real) {
        let x = height_row(u, v);
        let h = x.dot(&SVector::<Real, 6>::from(self.height));
        let var = x.dot(&(self.height_cov * x)) + self.common_var;
        (
            self.mean + self.tangents[0] * u + self.tangents[1] * v + self.normal * h,
            var.max(0.0),
        )
    }

    /// The sampled point's tangential coordinates nearest `(u, v)` (`None`
    /// for a single point).
    pub fn nearest_sampled(&self, u: Real, v: Real) -> Option<(Real, Real)> {
        self.footprint
            .iter()
            .map(|p| (Real::from(p.2), Real::from(p.3)))
            .min_by(|a, b| {
                let d = |p: &(Real, Real)| (p.0 - u).powi(2) + (p.1 - v).powi(2);
                d(a).total_cmp(&d(b))
            })
    }

    /// Whether `(u, v)` lies within the element's extent and where it was
    /// sampled ([`SurfaceElement::covers`]).
    pub fn sampled_over(&self, u: Real, v: Real) -> bool {
        let [[u0, u1], [v0, v1]] = self.extent;
        (u0..=u1).contains(&u) && (v0..=v1).contains(&v) && self.covers(u, v)
    }

    /// Whether the surface was sampled at tangential coordinates `(u, v)`: some
    /// point of the element lies within one sampling spacing of it in the
    /// tangent plane. The extent's rectangle is only a summary (a square face
    /// whose principal axes run along its diagonals gets a rectangle turned by
    /// 45 degrees, whose corners stick out of the face); the footprint is where
    /// the points are. Always true for a single point.
    pub fn covers(&self, u: Real, v: Real) -> bool {
        let h = self.spacing;
        if self.footprint.is_empty() || h.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return true;
        }
        let (ci, cj) = footprint_cell(u, v, h);
        // The cells are sorted by row: rows beyond the first or last cannot hit.
        let (first, last) = (
            self.footprint[0].0,
            self.footprint[self.footprint.len() - 1].0,
        );
        if ci.saturating_add(1) < first || ci.saturating_sub(1) > last {
            return false;
        }
        let h2 = h * h;
        // The three cells of a row around `cj` are one run of the sorted cells.
        let (j0, j1) = (cj.saturating_sub(1), cj.saturating_add(1));
        (-1..=1).any(|di| {
            let row = ci.saturating_add(di);
            let start = self.footprint.partition_point(|p| (p.0, p.1) < (row, j0));
            self.footprint[start..]
                .iter()
                .take_while(|p| p.0 == row && p.1 <= j1)
                .any(|p| (Real::from(p.2) - u).powi(2) + (Real::from(p.3) - v).powi(2) <= h2)
        })
    }

    /// The covariance of a point of the fitted surface whose height variance is
    /// `var`: `var` along the normal, the mean's covariance across it.
    pub fn surface_covariance(&self, var: Real) -> Matrix3 {
        let nn = self.normal * self.normal.transpose();
        let across = Matrix3::identity() - nn;
        across * self.cov_mean * across + nn * var
    }

    /// The tangential coordinates of the five standard samples that stand for
    /// the element in a classifier: over the mean, and at the ends of its range
    /// along each tangent (a large element's grid samples follow them in
    /// [`SurfaceElements::samples`]).
    pub fn sample_coordinates(&self) -> [(Real, Real); 5] {
        let [[u0, u1], [v0, v1]] = self.extent;
        [(0.0, 0.0), (u1, 0.0), (u0, 0.0), (0.0, v1), (0.0, v0)]
    }
}

/// A cloud's surface elements and the samples that stand for them in queries.
#[derive(Debug, Clone)]
pub struct SurfaceElements {
    pub(crate) elements: Vec<SurfaceElement>,
    pub(crate) indices: Vec<u32>,
    /// The cloud's points and covariances in the order of `indices`: an
    /// element's points lie together in memory, so a query reading a region's
    /// points streams through them instead of gathering them from the cloud.
    pub(crate) points: Vec<Point3>,
    pub(crate) covariances: Vec<Matrix3>,
    pub(crate) samples: PointCloud,
    pub(crate) sample_owner: Vec<u32>,
    /// Per sample: whether it stands for a single-point element (a point that
    /// fits no surface with its neighbours; see the near rule's context).
    pub(crate) sample_is_point: Vec<bool>,
    /// The elements' hulls and a hierarchy over them, built on first use.
    pub(crate) hulls: OnceLock<ElementHulls>,
    /// Boxes over runs of [`MEMBER_CHUNK`] consecutive points of `points`,
    /// built on first use ([`SurfaceElements::members_near`]).
    pub(crate) member_chunks: OnceLock<Vec<MemberChunk>>,
}

/// How many consecutive points of an element set one [`MemberChunk`] boxes.
const MEMBER_CHUNK: usize = 32;

/// A run of consecutive points of an element set (an element's points lie
/// together, so a run lies on a small part of its surface): their box and a
/// bound on their largest standard deviation (`sqrt(trace)` of their
/// covariances).
#[derive(Debug, Clone, Copy)]
pub(crate) struct MemberChunk {
    /// The box around the run's points (the cloud's frame).
    pub aabb: Aabb,
    /// A bound on any of the run's points' largest standard deviation.
    pub sigma: Real,
}

impl SurfaceElements {
    /// The elements.
    pub fn elements(&self) -> &[SurfaceElement] {
        &self.elements
    }

    /// The permutation of point indices that the elements' `first`/`count` refer to.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The point indices of element `e`.
    pub fn element_points(&self, e: u32) -> &[u32] {
        &self.indices[self.range(e)]
    }

    /// The positions of element `e`'s points in [`indices`](Self::indices).
    pub(crate) fn range(&self, e: u32) -> std::ops::Range<usize> {
        let el = &self.elements[e as usize];
        el.first as usize..(el.first + el.count) as usize
    }

    /// Element `e`'s points: `(index, point, covariance)` each, the point and
    /// covariance read from the element's own contiguous copy.
    pub(crate) fn members(&self, e: u32) -> impl Iterator<Item = (u32, &Point3, &Matrix3)> {
        self.run(self.range(e))
    }

    /// The points at positions `r` of [`indices`](Self::indices), as
    /// [`SurfaceElements::members`].
    fn run(&self, r: std::ops::Range<usize>) -> impl Iterator<Item = (u32, &Point3, &Matrix3)> {
        self.indices[r.clone()]
            .iter()
            .copied()
            .zip(&self.points[r.clone()])
            .zip(&self.covariances[r])
            .map(|((i, p), c)| (i, p, c))
    }

    /// Element `e`'s points as [`SurfaceElements::members`], passing over
    /// the runs of them ([`MemberChunk`]) that `keep` refuses: a wide
    /// element's points far from a small mesh are left without reading
    /// each one.
    pub(crate) fn members_near(
        &self,
        e: u32,
        keep: impl Fn(&MemberChunk) -> bool,
    ) -> impl Iterator<Item = (u32, &Point3, &Matrix3)> {
        let r = self.range(e);
        let chunks = self.member_chunks();
        let first = r.start / MEMBER_CHUNK;
        let last = r.end.div_ceil(MEMBER_CHUNK);
        (first..last)
            .filter(move |&k| keep(&chunks[k]))
            .flat_map(move |k| {
                self.run(r.start.max(k * MEMBER_CHUNK)..r.end.min((k + 1) * MEMBER_CHUNK))
            })
    }

    /// The boxes over runs of [`MEMBER_CHUNK`] points, built on first use.
    fn member_chunks(&self) -> &[MemberChunk] {
        self.member_chunks.get_or_init(|| {
            self.points
                .chunks(MEMBER_CHUNK)
                .zip(self.covariances.chunks(MEMBER_CHUNK))
                .map(|(pts, covs)| {
                    let mut aabb = Aabb::empty();
                    for p in pts {
                        aabb.take_point(p);
                    }
                    let sigma = covs
                        .iter()
                        .map(|c| c.trace().max(0.0).sqrt())
                        .fold(0.0, Real::max);
                    MemberChunk { aabb, sigma }
                })
                .collect()
        })
    }

    /// The cloud of samples standing for the elements (five per multi-point
    /// element: its mean and the four edges of its extent on the fitted plane,
    /// then, for an element more than two grid pitches across, the centres of
    /// a grid of six sampling spacings over where it was sampled; each with
    /// the covariance of the plane's height there; the point itself for a
    /// single-point element, with its own covariances). An element's samples
    /// are contiguous, its mean first.
    pub fn samples(&self) -> &PointCloud {
        &self.samples
    }

    /// The element each sample stands for.
    pub fn sample_owner(&self) -> &[u32] {
        &self.sample_owner
    }

    /// Per sample: whether it stands for a single-point element.
    pub(crate) fn sample_is_point(&self) -> &[bool] {
        &self.sample_is_point
    }

    /// The elements' hulls and the hierarchy over them ([`ElementHulls`]),
    /// built on first use.
    pub(crate) fn hulls(&self) -> &ElementHulls {
        self.hulls.get_or_init(|| {
            let n = self.elements.len();
            let (mut sigma, mut spacing) = (vec![0.0; n], vec![0.0; n]);
            let s = &self.samples;
            for (k, &e) in self.sample_owner.iter().enumerate() {
                let e = e as usize;
                sigma[e] = Real::max(sigma[e], s.sigma_max()[k].max(s.sensor_sigma_max()[k]));
                spacing[e] = Real::max(spacing[e], s.spacing()[k]);
            }
            ElementHulls::new(&self.elements, &sigma, &spacing)
        })
    }

    /// Number of elements of more than one point.
    pub fn multi_point_count(&self) -> usize {
        self.elements.iter().filter(|e| !e.is_point()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat element whose footprint holds `points` (tangential coordinates).
    fn element_with_footprint(points: &[(Real, Real)], spacing: Real) -> SurfaceElement {
        let mut footprint: Vec<FootprintPoint> = points
            .iter()
            .map(|&(u, v)| {
                let (i, j) = footprint_cell(u, v, spacing);
                (i, j, u as f32, v as f32)
            })
            .collect();
        footprint.sort_unstable_by_key(|a| (a.0, a.1));
        SurfaceElement {
            first: 0,
            count: points.len() as u32,
            mean: Point3::origin(),
            normal: Vector3::z(),
            tangents: [Vector3::x(), Vector3::y()],
            extent: [[-1.0, 1.0], [-1.0, 1.0]],
            probes: Vec::new(),
            spacing,
            cov_mean: Matrix3::zeros(),
            height: [0.0; 6],
            height_cov: SMatrix::zeros(),
            common_var: 0.0,
            footprint,
        }
    }

    /// The definition: some footprint point within one spacing.
    fn brute(e: &SurfaceElement, u: Real, v: Real) -> bool {
        e.footprint.iter().any(|p| {
            (Real::from(p.2) - u).powi(2) + (Real::from(p.3) - v).powi(2) <= e.spacing * e.spacing
        })
    }

    #[test]
    fn members_near_are_the_members_whose_run_is_kept() {
        // A noisy box's elements; the runs kept are those whose box meets a
        // corner region: every member inside it is among those returned,
        // and those returned are members, in order, each of a kept run.
        let pts = crate::sample::box_surface(&Point3::origin(), &Vector3::new(0.3, 0.2, 0.1), 0.01);
        let cloud = PointCloud::from_sigma(crate::sample::add_noise(&pts, 1e-3, 3), 1e-3).unwrap();
        let els = cloud.elements();
        let region = Aabb {
            mins: Point3::new(0.1, 0.05, -0.2),
            maxs: Point3::new(0.4, 0.3, 0.2),
        };
        let keep = |c: &MemberChunk| c.aabb.distance_squared(&region) == 0.0;
        let (mut inside, mut skipped) = (0, 0);
        for e in 0..els.elements().len() as u32 {
            let all: Vec<u32> = els.members(e).map(|(i, _, _)| i).collect();
            let near: Vec<u32> = els.members_near(e, keep).map(|(i, _, _)| i).collect();
            let mut at = all.iter();
            assert!(near.iter().all(|i| at.any(|j| j == i)), "element {e}");
            for (i, p, _) in els.members(e) {
                if region.distance_squared_to_point(p) == 0.0 {
                    inside += 1;
                    assert!(near.contains(&i), "element {e}: point {i} inside");
                }
            }
            skipped += all.len() - near.len();
            // Keeping every run gives every member.
            assert_eq!(els.members_near(e, |_| true).count(), all.len());
        }
        assert!(
            inside > 0 && skipped > 0,
            "{inside} inside, {skipped} passed over"
        );
    }

    #[test]
    fn covers_is_some_footprint_point_within_a_spacing() {
        // A square sampled with a ring left out: holes, edges and sparse spots.
        let mut uniform = crate::sample::lcg_uniform(11);
        let pts: Vec<(Real, Real)> = (0..400)
            .map(|_| (2.0 * uniform() - 1.0, 2.0 * uniform() - 1.0))
            .filter(|(u, v)| !(0.4..0.6).contains(&u.hypot(*v)))
            .collect();
        let e = element_with_footprint(&pts, 0.05);
        let mut hits = 0;
        for _ in 0..5000 {
            let (u, v) = (2.4 * uniform() - 1.2, 2.4 * uniform() - 1.2);
            let covered = brute(&e, u, v);
            assert_eq!(e.covers(u, v), covered, "({u}, {v})");
            hits += usize::from(covered);
        }
        assert!((500..4500).contains(&hits), "{hits} of 5000 covered");
        // Cells saturated at both ends of i32 (coordinates 1e12 spacings out).
        let far = element_with_footprint(&[(-1e3, 0.0), (1e3, 0.0), (1e3, 1e-10)], 1e-9);
        for (u, v) in [
            (1e3, 0.0),
            (1e3 + 5e-10, 0.0),
            (-1e3, 5e-10),
            (-1e3, 2e-9),
            (0.0, 0.0),
            (1e3, -2e-9),
        ] {
            assert_eq!(far.covers(u, v), brute(&far, u, v), "({u}, {v})");
        }
        assert!(far.covers(1e3 + 5e-10, 0.0) && !far.covers(-1e3, 2e-9));
    }
}
