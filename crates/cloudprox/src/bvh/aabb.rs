//! Axis-aligned bounding boxes.

use crate::math::{Point3, Pose, Vector3};
use crate::Real;

/// An axis-aligned box `[mins, maxs]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub mins: Point3,
    /// Largest corner.
    pub maxs: Point3,
}

impl Aabb {
    /// The empty box (merging anything into it gives that thing).
    pub fn empty() -> Self {
        Self {
            mins: Point3::new(Real::INFINITY, Real::INFINITY, Real::INFINITY),
            maxs: Point3::new(Real::NEG_INFINITY, Real::NEG_INFINITY, Real::NEG_INFINITY),
        }
    }

    /// Grows `self` to contain `p`.
    pub fn take_point(&mut self, p: &Point3) {
        self.mins = self.mins.inf(p);
        self.maxs = self.maxs.sup(p);
    }

    /// Grows `self` to contain `other`.
    pub fn merge(&mut self, other: &Aabb) {
        self.mins = self.mins.inf(&other.mins);
        self.maxs = self.maxs.sup(&other.maxs);
    }

    /// `self` grown to contain `other`.
    pub fn merged(&self, other: &Aabb) -> Aabb {
        let mut m = *self;
        m.merge(other);
        m
    }

    /// Centre of the box.
    pub fn center(&self) -> Point3 {
        nalgebra::center(&self.mins, &self.maxs)
    }

    /// Half of the box's extents.
    pub fn half_extents(&self) -> Vector3 {
        (self.maxs - self.mins) * 0.5
    }

    /// The axis-aligned box (in the target frame) enclosing this box moved by `pose`.
    pub fn transformed(&self, pose: &Pose) -> Aabb {
        let c = pose * self.center();
        let r = pose.rotation.to_rotation_matrix();
        let h = r.matrix().abs() * self.half_extents();
        Aabb {
            mins: c - h,
            maxs: c + h,
        }
    }

    /// Euclidean distance between the two boxes (0 when they overlap): a lower
    /// bound on the distance between any point of one and any point of the other.
    pub fn distance(&self, other: &Aabb) -> Real {
        let gap = (self.mins - other.maxs)
            .sup(&(other.mins - self.maxs))
            .sup(&Vector3::zeros());
        gap.norm()
    }

    /// Squared distance from a point to the box (0 inside).
    pub fn distance_squared_to_point(&self, p: &Point3) -> Real {
        let gap = (self.mins - p).sup(&(p - self.maxs)).sup(&Vector3::zeros());
        gap.norm_squared()
    }
}
