//! Axis-aligned bounding boxes.

use crate::math::{Matrix3, Point3, Pose, Vector3};
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
        self.moved(&BoxMotion::new(pose))
    }

    /// [`Aabb::transformed`] by a motion prepared once for many boxes (the
    /// same box, without turning the rotation into a matrix per box).
    pub fn moved(&self, motion: &BoxMotion) -> Aabb {
        let c = motion.pose * self.center();
        let h = motion.abs_rotation * self.half_extents();
        Aabb {
            mins: c - h,
            maxs: c + h,
        }
    }

    /// Euclidean distance between the two boxes (0 when they overlap): a lower
    /// bound on the distance between any point of one and any point of the other.
    pub fn distance(&self, other: &Aabb) -> Real {
        self.distance_squared(other).sqrt()
    }

    /// The square of [`Aabb::distance`] (no square root, for comparisons).
    pub fn distance_squared(&self, other: &Aabb) -> Real {
        let gap = (self.mins - other.maxs)
            .sup(&(other.mins - self.maxs))
            .sup(&Vector3::zeros());
        gap.norm_squared()
    }

    /// Squared distance from a point to the box (0 inside).
    pub fn distance_squared_to_point(&self, p: &Point3) -> Real {
        let gap = (self.mins - p).sup(&(p - self.maxs)).sup(&Vector3::zeros());
        gap.norm_squared()
    }
}

/// A rigid motion prepared for moving many boxes ([`Aabb::moved`]): the
/// pose and the absolute values of its rotation matrix.
#[derive(Debug, Clone, Copy)]
pub struct BoxMotion {
    pose: Pose,
    abs_rotation: Matrix3,
}

impl BoxMotion {
    /// The motion `pose`.
    pub fn new(pose: &Pose) -> Self {
        Self {
            pose: *pose,
            abs_rotation: pose.rotation.to_rotation_matrix().matrix().abs(),
        }
    }

    /// Whether the rotation maps the axes onto the axes (a matrix of 0s and
    /// ±1s, to rounding): a moved box's axis-aligned box is then the moved box
    /// itself, and the gap between two boxes along one frame's axes is their
    /// distance.
    pub fn keeps_axes(&self) -> bool {
        self.abs_rotation
            .iter()
            .all(|&x| x <= 1e-12 || x >= 1.0 - 1e-12)
    }
}
