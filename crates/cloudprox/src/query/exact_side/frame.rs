//! The cloud seen from the mesh: the relative pose, the noise's reach and the
//! broad phase.

use crate::bvh::Aabb;
use crate::element::{Hull, SurfaceElements};
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::probability::normal_quantile;
use crate::shape::{ClosestPoint, DistanceField, FieldValue, MeshDistance};
use crate::Real;

/// One query's view of the cloud from the mesh's own frame, where every
/// signed distance is read (so a rigid motion of both sides changes nothing).
pub(crate) struct Frame<'a> {
    /// The mesh's signed distance.
    mesh: &'a MeshDistance,
    /// A distance field of the mesh (its own frame), when it has one: bounds
    /// on the signed distance without a search ([`Frame::bounds`]).
    field: Option<&'a DistanceField>,
    /// The padding (metres, `>= 0`): the surface read is the mesh's grown by
    /// it, its signed distance `sd - padding` (see [`Frame::padded`]).
    padding: Real,
    /// The cloud's frame in the mesh's frame.
    pub rel: Pose,
    /// The rotation of `rel` as a matrix (cloud to mesh).
    rotation: Matrix3,
    /// The noise's reach in standard deviations: `-Phi^-1(epsilon / 2)` for
    /// the request's `prune_epsilon`, as the two-cloud query's near rule.
    pub reach: Real,
    /// The mesh's bounding box in its frame.
    bounds: Aabb,
}

/// Where an element stands against the surface after the broad phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Standing {
    /// Farther outside than the noise can reach: it reads nothing.
    Beyond,
    /// Within reach of the surface: the element's mean and the surface's
    /// point closest to it (mesh frame).
    Near(Point3, ClosestPoint),
    /// Inside the mesh, farther from its surface than the reach.
    Deep,
}

impl<'a> Frame<'a> {
    /// The frame of a cloud at `rel` in the mesh's frame, for a request's
    /// `prune_epsilon`.
    pub fn new(mesh: &'a MeshDistance, rel: Pose, prune_epsilon: Real) -> Self {
        Self::padded(mesh, rel, prune_epsilon, 0.0)
    }

    /// [`Frame::new`] for the mesh's surface grown by `padding` (metres,
    /// `>= 0`): every signed distance read is the mesh's less `padding`, every
    /// closest point moved `padding` along its outward normal, the support
    /// points and the bounding box grown alike. Padding 0 reads the mesh
    /// itself, bit for bit.
    pub fn padded(mesh: &'a MeshDistance, rel: Pose, prune_epsilon: Real, padding: Real) -> Self {
        let (mins, maxs) = mesh.bounds();
        let d = Vector3::repeat(padding);
        Self {
            mesh,
            field: None,
            padding,
            rel,
            rotation: *rel.rotation.to_rotation_matrix().matrix(),
            reach: -normal_quantile(0.5 * prune_epsilon),
            bounds: Aabb {
                mins: mins - d,
                maxs: maxs + d,
            },
        }
    }

    /// The frame with `field` (a distance field of the same mesh) bounding
    /// the signed distances before any search ([`Frame::bounds`]).
    pub fn with_field(mut self, field: Option<&'a DistanceField>) -> Self {
        self.field = field;
        self
    }

    /// Bounds `[lo, hi]` on the (padded) surface's signed distance at `x`
    /// (mesh frame) from the distance field, without a search (an
    /// interpolation and its error bound, or the band's lower bound and the
    /// side); `None` without a field.
    pub fn bounds(&self, x: &Point3) -> Option<(Real, Real)> {
        let (lo, hi) = match self.field?.evaluate_in_band(x) {
            FieldValue::Near(s) if s.distance.is_nan() => return None,
            FieldValue::Near(s) => (s.distance - s.bound, s.distance + s.bound),
            FieldValue::Beyond {
                lower_bound,
                inside: true,
            } => (Real::NEG_INFINITY, -lower_bound),
            FieldValue::Beyond { lower_bound, .. } => (lower_bound, Real::INFINITY),
        };
        Some((lo - self.padding, hi - self.padding))
    }

    /// The padding (metres).
    pub fn padding(&self) -> Real {
        self.padding
    }

    /// A bound on the mesh's own (unpadded) unsigned distance from bounds
    /// `[lo, hi]` on the padded signed distance ([`Frame::bounds`]).
    pub fn reach_of(&self, (lo, hi): (Real, Real)) -> Real {
        (lo + self.padding).abs().max((hi + self.padding).abs())
    }

    /// The (padded) surface's closest point to `x` (mesh frame) if the
    /// mesh's own (unpadded) surface lies within `limit` of it.
    pub fn mesh_within(&self, x: &Point3, limit: Real) -> Option<ClosestPoint> {
        self.mesh.closest_within(x, limit).map(|c| self.pad(c))
    }

    /// The mesh's closest point `c` read on the padded surface.
    fn pad(&self, mut c: ClosestPoint) -> ClosestPoint {
        if self.padding != 0.0 {
            c.signed_distance -= self.padding;
            c.point += c.normal * self.padding;
        }
        c
    }

    /// The (padded) surface's closest point to `x` (mesh frame).
    pub fn closest(&self, x: &Point3) -> ClosestPoint {
        self.pad(self.mesh.closest(x))
    }

    /// The (padded) surface's closest point to `x` (mesh frame) if its
    /// unsigned distance is within `radius` (see
    /// [`MeshDistance::closest_within`]; the mesh is searched within
    /// `radius + padding`, so a padded answer may lie farther than `radius`).
    pub fn closest_within(&self, x: &Point3, radius: Real) -> Option<ClosestPoint> {
        self.mesh
            .closest_within(x, radius + self.padding)
            .map(|c| self.pad(c))
    }

    /// The (padded) surface's signed distance at `x` (mesh frame).
    pub fn signed_distance(&self, x: &Point3) -> Real {
        self.closest(x).signed_distance
    }

    /// Whether `x` (mesh frame) lies inside the (padded) surface.
    pub fn contains(&self, x: &Point3) -> bool {
        self.mesh.contains(x)
            || (self.padding > 0.0
                && self
                    .mesh
                    .closest_within(x, self.padding)
                    .is_some_and(|c| c.signed_distance < self.padding))
    }

    /// The (padded) surface's support point along `dir` (mesh frame).
    pub fn support(&self, dir: &Vector3) -> Point3 {
        let s = self.mesh.support(dir);
        if self.padding == 0.0 {
            return s;
        }
        let n = dir.norm();
        if n > 0.0 {
            s + dir * (self.padding / n)
        } else {
            s
        }
    }

    /// A point of the cloud's frame in the mesh's.
    pub fn to_mesh(&self, p: &Point3) -> Point3 {
        self.rel * p
    }

    /// A point of the mesh's frame in the cloud's.
    pub fn to_cloud_point(&self, p: &Point3) -> Point3 {
        self.rel.inverse_transform_point(p)
    }

    /// A direction of the cloud's frame in the mesh's.
    pub fn to_mesh_direction(&self, v: &Vector3) -> Vector3 {
        self.rotation * v
    }

    /// A direction of the mesh's frame in the cloud's.
    pub fn to_cloud(&self, v: &Vector3) -> Vector3 {
        self.rotation.transpose() * v
    }

    /// The axis-aligned box, in the cloud's frame, around the (padded)
    /// mesh's bounding box: a point farther than `r` from it lies farther
    /// than `r` from the mesh's box ([`Frame::beyond_box`]).
    pub fn box_in_cloud(&self) -> Aabb {
        self.bounds.transformed(&self.rel.inverse())
    }

    /// Whether `x` (mesh frame) lies farther than `radius` from the mesh's
    /// bounding box, so farther than `radius` outside the mesh: a test of
    /// three coordinates before any search.
    pub fn beyond_box(&self, x: &Point3, radius: Real) -> bool {
        self.bounds.distance_squared_to_point(x) > radius * radius
    }

    /// The mesh's closest point to `x` (mesh frame) if the surface lies
    /// within `radius` of it or `x` is inside; `None` says `x` lies outside,
    /// farther than `radius` (a bounded search: a point far from the surface
    /// costs a few box tests).
    pub fn closest_near(&self, x: &Point3, radius: Real) -> Option<ClosestPoint> {
        if let Some(c) = self.closest_within(x, radius) {
            return Some(c);
        }
        let inside = self.bounds.distance_squared_to_point(x) == 0.0 && self.contains(x);
        inside.then(|| self.closest(x))
    }

    /// The elements of `els` whose mean may lie within `radius + margin +
    /// reach sigma` of the mesh's box (the first test of [`Frame::standing`]),
    /// in increasing order, into `out`: the mesh's box moved into the cloud's
    /// frame (a box holding it) descends the hierarchy over the elements'
    /// means, so a query costs what lies near the mesh, not the cloud's size.
    pub fn candidates(&self, els: &SurfaceElements, out: &mut Vec<u32>) {
        let in_cloud = self.bounds.transformed(&self.rel.inverse());
        els.hulls()
            .means_near_box(&in_cloud, self.reach, out, &mut Vec::new());
    }

    /// Where element `e` of `els` stands: its hull (every point of its
    /// surface within `radius` of its mean, every standard deviation below
    /// `sigma`) is first tested against the mesh's box, then against the
    /// surface within its reach, `radius + margin + reach sigma` (by the
    /// distance field's bounds first, where the mesh has one); an element
    /// whose mean is farther inside than that is deep.
    pub fn standing(&self, els: &SurfaceElements, e: u32) -> Standing {
        let hull: &Hull = els.hulls().hull(e);
        let centre = self.to_mesh(&hull.mean);
        let limit = hull.radius + hull.margin + self.reach * hull.sigma;
        let to_box = self.bounds.distance_squared_to_point(&centre);
        if to_box > limit * limit {
            return Standing::Beyond;
        }
        match self.bounds(&centre) {
            Some((lo, _)) if lo > limit => return Standing::Beyond,
            Some((_, hi)) if hi < -limit => return Standing::Deep,
            _ => {}
        }
        if let Some(c) = self.closest_within(&centre, limit) {
            Standing::Near(centre, c)
        } else if to_box == 0.0 && self.contains(&centre) {
            Standing::Deep
        } else {
            Standing::Beyond
        }
    }
}
