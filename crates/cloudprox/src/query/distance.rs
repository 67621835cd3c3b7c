//! The clearance between two sampled surfaces, with its standard deviation.
//!
//! [`distance`] (two clouds), [`distance_exact_cloud`] and
//! [`distance_cloud_exact`] (an exact mesh and a cloud) estimate the signed
//! separation of the two *surface estimates* (each cloud's surface elements,
//! [`crate::element`]), not of raw points: negative where they
//! interpenetrate. The gap and its standard deviation are the very readings
//! the collision query's probability is made of:
//!
//! - near a contact (within the noise's reach) the distance is read from
//!   the collision query's own facing-pair readings as its `P` reads them
//!   (each contact turned to one orientation by its separating surface, one
//!   reading per element pair, pooled into a gap field where there are
//!   three or more): the smallest gap among the terms whose largest
//!   `Phi(-gap / std)` is the contact's crossing probability. So
//!   `Phi(-distance / std)` is at most the collision query's `P` (of one
//!   segmentation), and equals it when the contact is one facing element
//!   pair; where several pairs read a contact, `P` is its most critical
//!   term (the smallest `gap / std`), which need not be the nearest;
//! - beyond the near region the collision query reads nothing: the nearest
//!   pair of element surfaces is found from the hulls' lower bounds, and the
//!   facing pairs within the noise's reach of its gap are read with the same
//!   gap formula and as one contact in the same way (one reading per element
//!   pair, pooled into a gap field whose lowest term is the distance);
//! - with [`DistanceRequest::max_distance`], when every element pair's lower
//!   bound, less the noise's reach, exceeds it, the query stops there and
//!   returns that bound ([`DistanceResult::beyond_max_distance`]).

use crate::bvh::PointSearch;
use crate::cloud::{validate_pose, PointCloud};
use crate::element::{SurfaceElements, HALF_SPACING};
use crate::error::{Error, Result};
use crate::math::{Point3, Pose, Vector3};
use crate::probability::{
    nearest_reading, nearest_surface_pair, normal_quantile, surface_pair_bound,
    surface_pair_readings, surface_point_near, ElementGap, ElementReading,
};
use crate::query::collide::{collide_readings, CollisionRequest, QueryModel};
use crate::query::exact_side::nearest_to_mesh;
use crate::shape::MeshDistance;
use crate::Real;

/// The options of a distance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceRequest {
    /// Stop early when the surfaces are surely farther apart than this, in
    /// metres (default infinity: never). "Surely": every element pair's
    /// lower bound on its surfaces' distance, less the noise's reach
    /// (`collision.prune_epsilon`) times a bound on the pair's standard
    /// deviation, exceeds it. Must be `>= 0` (or infinite).
    pub max_distance: Real,
    /// The collision query's options, for the near region: its
    /// `prune_epsilon` (the noise's reach), classifier and near-set options.
    /// The model is always the elements model and one segmentation (the
    /// clouds' own) is read.
    pub collision: CollisionRequest,
}

impl Default for DistanceRequest {
    fn default() -> Self {
        Self {
            max_distance: Real::INFINITY,
            collision: CollisionRequest::default(),
        }
    }
}

impl DistanceRequest {
    /// Checks the options: `max_distance` not NaN and not negative, and the
    /// collision options ([`CollisionRequest::validate`]).
    pub fn validate(&self) -> Result<()> {
        if self.max_distance.is_nan() || self.max_distance < 0.0 {
            return Err(Error::invalid(format!(
                "max_distance must be >= 0 (or infinite), got {}",
                self.max_distance
            )));
        }
        self.collision.validate()
    }

    /// The noise's reach in standard deviations.
    fn reach(&self) -> Real {
        -normal_quantile(0.5 * self.collision.prune_epsilon)
    }
}

/// The answer of a distance query, in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceResult {
    /// The estimated signed separation of the two surface estimates
    /// (negative where they interpenetrate); with `beyond_max_distance`, a
    /// lower bound on it instead.
    pub distance: Real,
    /// The standard deviation of `distance` (0 for a bound).
    pub std: Real,
    /// The point of A's surface estimate where the distance is read (NaN
    /// for a bound).
    pub point_a: Point3,
    /// The point of B's surface estimate (NaN for a bound).
    pub point_b: Point3,
    /// The unit direction the distance is measured along, from A towards B
    /// (NaN for a bound).
    pub normal: Vector3,
    /// Whether the query stopped at `max_distance`: the surfaces are farther
    /// apart than it by more than the noise's reach, and `distance` is a
    /// lower bound.
    pub beyond_max_distance: bool,
    /// Whether the reading is one of the collision query's (the surfaces
    /// within the noise's reach of each other), else the nearest pair of
    /// surfaces beyond it.
    pub near_contact: bool,
}

impl DistanceResult {
    /// `P(distance < 0) = Phi(-distance / std)`: the probability that the
    /// two surfaces cross at the reading (see the [module docs](self) for how
    /// it relates to the collision query's `P`).
    pub fn crossing_probability(&self) -> Real {
        crate::probability::wrong_side(self.distance, self.std)
    }

    /// A bound result (`beyond_max_distance`).
    fn bound(lower: Real) -> Self {
        let nan = Real::NAN;
        Self {
            distance: lower,
            std: 0.0,
            point_a: Point3::new(nan, nan, nan),
            point_b: Point3::new(nan, nan, nan),
            normal: Vector3::new(nan, nan, nan),
            beyond_max_distance: true,
            near_contact: false,
        }
    }

    /// The result with sides A and B swapped.
    fn swapped(self) -> Self {
        Self {
            point_a: self.point_b,
            point_b: self.point_a,
            normal: -self.normal,
            ..self
        }
    }
}

/// The signed distance between the surface estimates of cloud `a` at world
/// pose `pose_a` and cloud `b` at `pose_b`, with its standard deviation and
/// witness points (see the [module docs](self)).
///
/// All the work happens in `b`'s frame: a rigid motion of both clouds moves
/// the witness points and normal and changes nothing else.
///
/// # Errors
/// An invalid request ([`DistanceRequest::validate`]) or a pose that is not
/// a finite rigid transform.
///
/// # Example
/// ```
/// use cloudprox::prelude::*;
/// use cloudprox::query::distance::{distance, DistanceRequest};
/// let plate = |z: f64| -> Vec<Point3> {
///     (0..400).map(|i| Point3::new((i % 20) as f64 * 0.005, (i / 20) as f64 * 0.005, z)).collect()
/// };
/// let a = PointCloud::from_sigma(plate(0.0), 0.0005).unwrap();
/// let b = PointCloud::from_sigma(plate(0.03), 0.0005).unwrap();
/// let d = distance(&Pose::identity(), &a, &Pose::identity(), &b, &DistanceRequest::default()).unwrap();
/// assert!((d.distance - 0.03).abs() < 1e-3);
/// ```
pub fn distance(
    pose_a: &Pose,
    a: &PointCloud,
    pose_b: &Pose,
    b: &PointCloud,
    request: &DistanceRequest,
) -> Result<DistanceResult> {
    request.validate()?;
    validate_pose(pose_a, "pose_a")?;
    validate_pose(pose_b, "pose_b")?;
    let rel = pose_b.inverse() * pose_a;
    let (ea, eb) = (a.elements(), b.elements());
    let pairs = candidate_pairs(ea, &rel, eb, request.reach());
    let lower = pairs
        .iter()
        .map(|p| p.noisy)
        .fold(Real::INFINITY, Real::min);
    if lower > request.max_distance {
        return Ok(DistanceResult::bound(lower));
    }
    let collision = CollisionRequest {
        model: QueryModel::Elements,
        ..request.collision
    };
    let (far, within_reach) = nearest_pair(ea, &rel, eb, &pairs, request.reach());
    let near = if within_reach || far.gap.is_nan() {
        let (_, readings) = collide_readings(pose_a, a, pose_b, b, &collision)?;
        nearest_reading(&readings, true).map(|r| read_at_reading(ea, &rel, eb, &r))
    } else {
        None
    };
    let in_b = near.map_or((far, false), |g| (g, true));
    Ok(to_world(pose_b, in_b))
}

/// The gap of reading `r` (A's element `r.own` at `rel` in `eb`'s frame,
/// B's `r.other`) with its witness points: each element's surface point
/// nearest the reading's place.
fn read_at_reading(
    ea: &SurfaceElements,
    rel: &Pose,
    eb: &SurfaceElements,
    r: &ElementReading,
) -> ElementGap {
    let at = r.at.unwrap_or_else(Point3::origin);
    let on_a = (&ea.elements()[r.own as usize], ea.hulls().hull(r.own));
    let on_b = (&eb.elements()[r.other as usize], eb.hulls().hull(r.other));
    ElementGap {
        gap: r.gap,
        std: r.std,
        fit_std: r.fit_std,
        point_a: surface_point_near(on_a, rel, &at),
        point_b: surface_point_near(on_b, &Pose::identity(), &at),
        direction: r.direction,
    }
}

/// The result in world coordinates from a gap read in `b`'s frame.
fn to_world(pose_b: &Pose, (g, near): (ElementGap, bool)) -> DistanceResult {
    DistanceResult {
        distance: g.gap,
        std: g.std,
        point_a: pose_b * g.point_a,
        point_b: pose_b * g.point_b,
        normal: pose_b.rotation * g.direction,
        beyond_max_distance: false,
        near_contact: near,
    }
}

/// The signed distance between an exact mesh (its signed distance `mesh`)
/// at `pose_mesh`, side A, and the surface estimate of `cloud` at
/// `pose_cloud`, side B: the signed distance of the cloud's element surfaces
/// to the mesh where it is smallest (negative inside the mesh), with the
/// exact-side query's standard deviation (the fit's along the mesh's normal;
/// the mesh adds none). `point_a` is the mesh's closest point, `normal` the
/// mesh's outward normal there.
///
/// # Errors
/// As [`distance`].
pub fn distance_exact_cloud(
    pose_mesh: &Pose,
    mesh: &MeshDistance,
    pose_cloud: &Pose,
    cloud: &PointCloud,
    request: &DistanceRequest,
) -> Result<DistanceResult> {
    request.validate()?;
    validate_pose(pose_mesh, "pose_mesh")?;
    validate_pose(pose_cloud, "pose_cloud")?;
    let rel = pose_mesh.inverse() * pose_cloud;
    let g = nearest_to_mesh(
        mesh,
        rel,
        cloud,
        request.collision.prune_epsilon,
        request.max_distance,
    );
    if g.bound {
        return Ok(DistanceResult::bound(g.gap));
    }
    Ok(DistanceResult {
        distance: g.gap,
        std: g.std,
        point_a: pose_mesh * g.point_mesh,
        point_b: pose_mesh * g.point_cloud,
        normal: pose_mesh.rotation * g.normal,
        beyond_max_distance: false,
        near_contact: false,
    })
}

/// [`distance_exact_cloud`] with the sides in the other order: the cloud is
/// side A, the mesh side B (the same distance, the witness points swapped,
/// the normal turned).
///
/// # Errors
/// As [`distance`].
pub fn distance_cloud_exact(
    pose_cloud: &Pose,
    cloud: &PointCloud,
    pose_mesh: &Pose,
    mesh: &MeshDistance,
    request: &DistanceRequest,
) -> Result<DistanceResult> {
    distance_exact_cloud(pose_mesh, mesh, pose_cloud, cloud, request).map(DistanceResult::swapped)
}

/// An element pair that may hold the nearest surfaces.
struct Candidate {
    /// A's element and B's.
    a: u32,
    b: u32,
    /// A lower bound on the distance between their surfaces.
    bound: Real,
    /// `bound` less the noise's reach times a bound on the pair's standard
    /// deviation.
    noisy: Real,
    /// How far beyond the nearest gap the pair's readings count as one
    /// contact with it: half the larger spacing plus the reach times the
    /// bound on its standard deviation.
    window: Real,
}

/// The element pairs of `ea` (at `rel` in `eb`'s frame) and `eb` whose
/// noisy lower bound ([`Candidate::noisy`]) is at most an upper bound on
/// the surfaces' distance (from each of A's elements to B's nearest by mean:
/// the means' distance plus the two hulls' radii), sorted by their bound:
/// every pair that can hold the nearest surfaces, and the smallest noisy
/// bound of all pairs.
fn candidate_pairs(
    ea: &SurfaceElements,
    rel: &Pose,
    eb: &SurfaceElements,
    reach: Real,
) -> Vec<Candidate> {
    let (ha, hb) = (ea.hulls(), eb.hulls());
    let means_b: Vec<Point3> = (0..eb.elements().len() as u32)
        .map(|j| hb.hull(j).mean)
        .collect();
    let search = PointSearch::new(means_b);
    let (radius_b, sigma_b) = (0..eb.elements().len() as u32).fold((0.0, 0.0), |(r, s), j| {
        let h = hb.hull(j);
        (h.radius.max(r), h.sigma.max(s))
    });
    let count_a = ea.elements().len() as u32;
    let mut nearest = Vec::new();
    let upper = (0..count_a).fold(Real::INFINITY, |u, i| {
        let h = ha.hull(i);
        search.nearest(&(rel * h.mean), 1, &mut nearest);
        nearest.first().map_or(u, |&(d2, j)| {
            u.min(d2.sqrt() + h.radius + hb.hull(j).radius)
        })
    });
    let mut out = Vec::new();
    let mut within = Vec::new();
    for i in 0..count_a {
        let h = ha.hull(i);
        let r = upper + h.radius + radius_b + reach * (h.sigma + sigma_b);
        search.within(&(rel * h.mean), r, &mut within);
        for &j in &within {
            let a = (&ea.elements()[i as usize], h);
            let b = (&eb.elements()[j as usize], hb.hull(j));
            let sphere = (rel * h.mean - b.1.mean).norm() - h.radius - b.1.radius;
            let (tight, sigma) = surface_pair_bound(a, rel, b);
            let bound = sphere.max(tight);
            let noisy = bound - reach * sigma;
            if noisy <= upper {
                out.push(Candidate {
                    a: i,
                    b: j,
                    bound,
                    noisy,
                    window: HALF_SPACING * a.0.spacing.max(b.0.spacing) + reach * sigma,
                });
            }
        }
    }
    out.sort_by(|x, y| x.bound.total_cmp(&y.bound));
    out
}

/// The nearest pair of element surfaces among `pairs` (sorted by bound):
/// each read ([`nearest_surface_pair`]) until the next bound exceeds the
/// best gap; then the readings of every pair within its window of that gap
/// ([`Candidate::window`], each reading within half a spacing plus `reach`
/// of its standard deviations of it) read as the collision query reads a
/// contact's readings, one reading per element pair ([`nearest_reading`],
/// the pair's most precise unless its gap truly varies), the nearest of
/// those; and whether that gap lies within the noise's reach (half a
/// spacing plus `reach` standard deviations), where the surfaces may cross.
///
/// The readings are not pooled into a gap field here: beyond the noise's
/// reach the readings of a curved contact vary across it by more than
/// their noise, which a field of few terms reads as its mean.
fn nearest_pair(
    ea: &SurfaceElements,
    rel: &Pose,
    eb: &SurfaceElements,
    pairs: &[Candidate],
    reach: Real,
) -> (ElementGap, bool) {
    let elements = |p: &Candidate| {
        (
            (&ea.elements()[p.a as usize], ea.hulls().hull(p.a)),
            (&eb.elements()[p.b as usize], eb.hulls().hull(p.b)),
        )
    };
    let mut best: Option<(ElementGap, Real)> = None;
    for p in pairs {
        if best.is_some_and(|(b, _)| p.bound > b.gap) {
            break;
        }
        let (a, b) = elements(p);
        let g = nearest_surface_pair(a, rel, b);
        if best.is_none_or(|(b, _)| g.gap < b.gap) {
            best = Some((g, HALF_SPACING * a.0.spacing.max(b.0.spacing)));
        }
    }
    let Some((best, half)) = best else {
        let nan = Real::NAN;
        let none = ElementGap {
            gap: nan,
            std: nan,
            fit_std: nan,
            point_a: Point3::new(nan, nan, nan),
            point_b: Point3::new(nan, nan, nan),
            direction: Vector3::new(nan, nan, nan),
        };
        return (none, false);
    };
    let mut readings = Vec::new();
    for p in pairs.iter().filter(|p| p.bound <= best.gap + p.window) {
        let (a, b) = elements(p);
        let half = HALF_SPACING * a.0.spacing.max(b.0.spacing);
        for (g, beside) in surface_pair_readings(a, rel, b) {
            if g.gap <= best.gap + half + reach * g.std {
                readings.push(ElementReading {
                    own: p.a,
                    other: p.b,
                    gap: g.gap,
                    std: g.std,
                    fit_std: g.fit_std,
                    beside,
                    contact: 0,
                    at: Some(nalgebra::center(&g.point_a, &g.point_b)),
                    direction: g.direction,
                });
            }
        }
    }
    let read = nearest_reading(&readings, true)
        .map(|r| read_at_reading(ea, rel, eb, &r))
        .filter(|g| g.gap.is_finite())
        .unwrap_or(best);
    (read, read.gap <= half + reach * read.std)
}
