//! The robot model: links, joints, limits; checks of configurations.

use super::attached::AttachedObject;
use super::cache::SpacingCache;
use super::geometry::{LinkGeometry, LinkSamples};
use crate::error::{Error, Result};
use crate::math::{Point3, Pose, Vector3};
use crate::Real;

/// Tolerance (radians or metres) by which a configuration may leave a joint's
/// limits before [`Robot::check_configuration`] rejects it (rounding of limits
/// written with few digits).
pub const LIMIT_TOLERANCE: Real = 1e-9;

/// How a joint moves its child link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis, within limits (radians).
    Revolute,
    /// Rotation about the axis, unlimited (radians).
    Continuous,
    /// Translation along the axis, within limits (metres).
    Prismatic,
    /// No motion.
    Fixed,
}

impl JointKind {
    /// The URDF name of the kind.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
        }
    }
}

/// A joint that copies another: `value = multiplier * q[dof] + offset`, with
/// chains of mimic joints composed down to the configuration entry they follow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mimic {
    /// The joint named in the URDF's `<mimic joint=...>`.
    pub joint: usize,
    /// The configuration entry the value follows (after composing chains).
    pub dof: usize,
    /// The composed multiplier.
    pub multiplier: Real,
    /// The composed offset.
    pub offset: Real,
}

/// One joint of the kinematic tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The URDF name.
    pub name: String,
    /// How it moves.
    pub kind: JointKind,
    /// Index of the parent link.
    pub parent: usize,
    /// Index of the child link.
    pub child: usize,
    /// The child link's frame in the parent link's frame at value 0 (`<origin>`).
    pub origin: Pose,
    /// Unit axis of motion in the joint frame (zero for fixed joints).
    pub axis: Vector3,
    /// `[lower, upper]` (radians or metres); infinite for continuous joints,
    /// `[0, 0]` for fixed ones.
    pub limits: [Real; 2],
    /// The joint it copies, if it is a mimic joint.
    pub mimic: Option<Mimic>,
    /// Its entry in a configuration `q`, if it is an independent moving joint.
    pub dof: Option<usize>,
}

impl Joint {
    /// The transform of the joint's motion by `value` (in the joint frame).
    pub fn motion(&self, value: Real) -> Pose {
        match self.kind {
            JointKind::Revolute | JointKind::Continuous => Pose::rotation(self.axis * value),
            JointKind::Prismatic => Pose::translation(
                self.axis.x * value,
                self.axis.y * value,
                self.axis.z * value,
            ),
            JointKind::Fixed => Pose::identity(),
        }
    }

    /// The joint's value in configuration `q` (0 for fixed joints).
    pub fn value(&self, q: &[Real]) -> Real {
        if let Some(d) = self.dof {
            q[d]
        } else if let Some(m) = self.mimic {
            m.multiplier * q[m.dof] + m.offset
        } else {
            0.0
        }
    }
}

/// One link: a frame, and its collision geometry if it has any.
#[derive(Debug, Clone)]
pub struct Link {
    /// The URDF name.
    pub name: String,
    /// The joint whose child it is (`None` for the root).
    pub parent_joint: Option<usize>,
    /// The collision geometry, in the link frame (`None`: no `<collision>`).
    pub geometry: Option<LinkGeometry>,
}

/// A robot: a tree of links joined by joints, each link with its collision
/// geometry, prepared once for many queries.
///
/// A configuration `q` holds one value per independent moving joint (revolute,
/// continuous, prismatic, not mimic), in the order the joints appear in the
/// URDF ([`Robot::joint_names`]). A configuration outside the limits is
/// rejected, not clamped ([`Robot::check_configuration`]; [`Robot::clamp`]
/// clamps on request): a planner that asks about a state the robot cannot
/// reach has a bug worth hearing about.
#[derive(Debug)]
pub struct Robot {
    pub(crate) name: String,
    pub(crate) links: Vec<Link>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) root: usize,
    /// Joints in an order where every parent link is placed before its child.
    pub(crate) order: Vec<usize>,
    /// The joint of each configuration entry.
    pub(crate) dof_joints: Vec<usize>,
    /// Link pairs (both with geometry, `i < j`) checked for self-collision.
    pub(crate) self_pairs: Vec<(usize, usize)>,
    /// Link pairs left out of self-collision: adjacent, or touching at the
    /// reference configuration.
    pub(crate) ignored_pairs: Vec<(usize, usize)>,
    /// Per link: `(dof, weight)` such that a link point moves at most
    /// `sum weight * |dq[dof]|` for a joint-space step `dq`.
    pub(crate) motion_weights: Vec<Vec<(usize, Real)>>,
    /// Objects held by links ([`Robot::attach`]), in the order attached.
    pub(crate) attached: Vec<AttachedObject>,
    /// Link samples per sampling spacing.
    pub(crate) samples: SpacingCache<LinkSamples>,
    /// Every entry's surface samples for the shadow, per footprint spacing.
    pub(crate) shadow_samples: SpacingCache<Vec<Vec<Point3>>>,
}

impl Clone for Robot {
    /// A copy of the robot, its cached link samples shared with the original
    /// (none if a thread panicked while holding the cache: it is only a cache).
    fn clone(&self) -> Self {
        Robot {
            name: self.name.clone(),
            links: self.links.clone(),
            joints: self.joints.clone(),
            root: self.root,
            order: self.order.clone(),
            dof_joints: self.dof_joints.clone(),
            self_pairs: self.self_pairs.clone(),
            ignored_pairs: self.ignored_pairs.clone(),
            motion_weights: self.motion_weights.clone(),
            attached: self.attached.clone(),
            samples: self.samples.clone(),
            shadow_samples: self.shadow_samples.clone(),
        }
    }
}

impl Robot {
    /// The robot's name (`<robot name=...>`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of configuration entries.
    pub fn dof(&self) -> usize {
        self.dof_joints.len()
    }

    /// The links, in URDF order.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The joints, in URDF order.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The root link's index.
    pub fn root(&self) -> usize {
        self.root
    }

    /// Names of the links, in URDF order.
    pub fn link_names(&self) -> Vec<&str> {
        self.links.iter().map(|l| l.name.as_str()).collect()
    }

    /// Names of the joints of the configuration entries, in order.
    pub fn joint_names(&self) -> Vec<&str> {
        self.dof_joints
            .iter()
            .map(|&j| self.joints[j].name.as_str())
            .collect()
    }

    /// `[lower, upper]` of each configuration entry (infinite for continuous joints).
    pub fn joint_limits(&self) -> Vec<[Real; 2]> {
        self.dof_joints
            .iter()
            .map(|&j| self.joints[j].limits)
            .collect()
    }

    /// The index of the link named `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Link pairs checked for self-collision (indices, `i < j`).
    pub fn self_collision_pairs(&self) -> &[(usize, usize)] {
        &self.self_pairs
    }

    /// Link pairs (both with geometry) never checked for self-collision:
    /// adjacent links (joined by a joint, looking through links without
    /// geometry) and pairs whose exact shapes touch at the reference
    /// configuration (every joint at 0, or at the limit nearest 0).
    pub fn ignored_pairs(&self) -> &[(usize, usize)] {
        &self.ignored_pairs
    }

    /// Checks that `q` has one finite value per configuration entry, within the
    /// joint limits (up to `LIMIT_TOLERANCE`, 1e-9).
    ///
    /// # Errors
    /// [`Error::Shape`] for a wrong length; [`Error::InvalidInput`] naming the
    /// joint for a non-finite value or one outside its limits.
    pub fn check_configuration(&self, q: &[Real]) -> Result<()> {
        if q.len() != self.dof() {
            return Err(Error::Shape {
                what: format!(
                    "configuration of robot '{}' (one value per joint: {})",
                    self.name,
                    self.joint_names().join(", ")
                ),
                expected: self.dof(),
                got: q.len(),
            });
        }
        for (i, (&v, &j)) in q.iter().zip(&self.dof_joints).enumerate() {
            let joint = &self.joints[j];
            if !v.is_finite() {
                return Err(Error::invalid(format!(
                    "configuration entry {i} (joint '{}') is not finite: {v}",
                    joint.name
                )));
            }
            let [lo, hi] = joint.limits;
            if v < lo - LIMIT_TOLERANCE || v > hi + LIMIT_TOLERANCE {
                return Err(Error::invalid(format!(
                    "configuration entry {i} (joint '{}') is {v}, outside its limits [{lo}, {hi}]",
                    joint.name
                )));
            }
        }
        Ok(())
    }

    /// `q` clamped into the joint limits (non-finite values are left as they are).
    pub fn clamp(&self, q: &[Real]) -> Vec<Real> {
        q.iter()
            .zip(&self.dof_joints)
            .map(|(&v, &j)| {
                let [lo, hi] = self.joints[j].limits;
                if v.is_finite() {
                    v.clamp(lo, hi)
                } else {
                    v
                }
            })
            .collect()
    }

    /// The configuration that gives the named joints their values and every
    /// other entry its reference value ([`Robot::reference_configuration`]).
    /// Values are not checked here ([`Robot::check_configuration`] is, by every
    /// query); a joint named twice takes its last value.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the joint for a name that is not a
    /// configuration entry (an unknown joint, a fixed joint, a mimic joint).
    pub fn configuration_from_names<'a>(
        &self,
        values: impl IntoIterator<Item = (&'a str, Real)>,
    ) -> Result<Vec<Real>> {
        let mut q = self.reference_configuration();
        for (name, value) in values {
            let entry = self
                .dof_joints
                .iter()
                .position(|&j| self.joints[j].name == name)
                .ok_or_else(|| self.not_an_entry(name))?;
            q[entry] = value;
        }
        Ok(q)
    }

    /// The error of a joint name that is not a configuration entry.
    fn not_an_entry(&self, name: &str) -> Error {
        let why = match self.joints.iter().find(|j| j.name == name) {
            Some(j) if j.mimic.is_some() => "is a mimic joint (give the joint it follows)",
            Some(_) => "is a fixed joint",
            None => "is not a joint",
        };
        Error::invalid(format!(
            "'{name}' {why} of robot '{}'; its configuration joints: {}",
            self.name,
            self.joint_names().join(", ")
        ))
    }

    /// The reference configuration: every entry at 0, or at the limit nearest 0.
    pub fn reference_configuration(&self) -> Vec<Real> {
        self.clamp(&vec![0.0; self.dof()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A slider limited to `[0.2, 1]`, a turn about z, a fixed tool and a
    /// mimic joint following the turn.
    const URDF: &str = r#"<robot name="slider">
      <link name="base"/><link name="carriage"/><link name="arm"/><link name="tool"/><link name="twin"/>
      <joint name="slide" type="prismatic"><parent link="base"/><child link="carriage"/>
        <axis xyz="1 0 0"/><limit lower="0.2" upper="1.0" effort="1" velocity="1"/></joint>
      <joint name="turn" type="continuous"><parent link="carriage"/><child link="arm"/>
        <axis xyz="0 0 1"/></joint>
      <joint name="weld" type="fixed"><parent link="arm"/><child link="tool"/></joint>
      <joint name="copy" type="continuous"><parent link="carriage"/><child link="twin"/>
        <axis xyz="0 0 1"/><mimic joint="turn" multiplier="2"/></joint>
    </robot>"#;

    fn slider() -> Robot {
        Robot::from_urdf_str(URDF, "slider.urdf", None, &[]).unwrap()
    }

    #[test]
    fn configuration_from_names_fills_in_the_reference() {
        let r = slider();
        assert_eq!(r.joint_names(), ["slide", "turn"]);
        assert_eq!(r.configuration_from_names([]).unwrap(), [0.2, 0.0]);
        assert_eq!(
            r.configuration_from_names([("turn", 1.5)]).unwrap(),
            [0.2, 1.5]
        );
        assert_eq!(
            r.configuration_from_names([("turn", 1.5), ("slide", 0.5), ("turn", -1.0)])
                .unwrap(),
            [0.5, -1.0]
        );
        // Values are checked by the queries, not here.
        let q = r.configuration_from_names([("slide", 7.0)]).unwrap();
        assert!(r.check_configuration(&q).is_err());
    }

    #[test]
    fn configuration_from_names_rejects_other_names() {
        let r = slider();
        for (name, why) in [
            ("elbow", "is not a joint"),
            ("weld", "is a fixed joint"),
            ("copy", "is a mimic joint"),
        ] {
            let err = r.configuration_from_names([(name, 0.0)]).unwrap_err();
            let Error::InvalidInput(msg) = &err else {
                panic!("{err:?}")
            };
            assert!(msg.contains(&format!("'{name}' {why}")), "{msg}");
            assert!(msg.contains("slide, turn"), "{msg}");
        }
    }
}
