//! Forward kinematics and joint-space motion bounds.

use super::model::{JointKind, Robot};
use crate::error::Result;
use crate::math::Pose;
use crate::Real;

impl Robot {
    /// Every link's pose (link frame to world) at configuration `q`, with the
    /// root link at `base` (in link order, [`Robot::link_names`]).
    ///
    /// A joint places its child at `parent * origin * motion(value)`, with
    /// `motion` the rotation about (revolute, continuous) or translation along
    /// (prismatic) the joint's unit axis; a mimic joint's value is
    /// `multiplier * q[master] + offset`.
    ///
    /// # Errors
    /// As [`Robot::check_configuration`].
    pub fn link_poses(&self, q: &[Real], base: &Pose) -> Result<Vec<Pose>> {
        self.check_configuration(q)?;
        Ok(self.link_poses_unchecked(q, base))
    }

    /// [`Robot::link_poses`] without the checks (`q` must have [`Robot::dof`] entries).
    pub(crate) fn link_poses_unchecked(&self, q: &[Real], base: &Pose) -> Vec<Pose> {
        let mut poses = vec![Pose::identity(); self.links.len()];
        poses[self.root] = *base;
        for &j in &self.order {
            let joint = &self.joints[j];
            poses[joint.child] = poses[joint.parent] * joint.origin * joint.motion(joint.value(q));
        }
        poses
    }

    /// An upper bound on how far any point of any link's geometry (or of an
    /// object it holds, [`Robot::attach`]) moves
    /// between configurations `q0` and `q0 + dq`, and between any two
    /// configurations on the straight segment joining them: for each link, the
    /// sum over the joints above it of `|d value| * r` (`r` the largest distance
    /// from the joint's origin of any geometry below it, for a rotation; 1 for a
    /// translation). Independent of `q0`.
    pub fn displacement_bound(&self, dq: &[Real]) -> Real {
        self.motion_weights
            .iter()
            .map(|w| w.iter().map(|&(d, r)| r * dq[d].abs()).sum::<Real>())
            .fold(0.0, Real::max)
    }

    /// The per-link weights of [`Robot::displacement_bound`].
    pub(crate) fn compute_motion_weights(&mut self) {
        // reach[l]: the largest distance from link l's origin of any geometry in
        // the subtree of l (its own, and its descendants' through their joints,
        // prismatic joints at their farthest travel).
        let mut reach = vec![0.0; self.links.len()];
        for (l, link) in self.links.iter().enumerate() {
            reach[l] = link.geometry.as_ref().map_or(0.0, |g| g.radius);
        }
        // A held object is part of its link's geometry here.
        for object in &self.attached {
            reach[object.link] = reach[object.link].max(object.reach());
        }
        for &j in self.order.iter().rev() {
            let joint = &self.joints[j];
            // A mimic joint's values are its master's limits mapped through
            // the mimic (its own limits do not bound them).
            let range = match joint.mimic {
                Some(m) => {
                    let [lo, hi] = self.joints[self.dof_joints[m.dof]].limits;
                    [m.multiplier * lo + m.offset, m.multiplier * hi + m.offset]
                }
                None => joint.limits,
            };
            let travel = match joint.kind {
                JointKind::Prismatic => range[0].abs().max(range[1].abs()),
                _ => 0.0,
            };
            let r = joint.origin.translation.vector.norm() + travel + reach[joint.child];
            if r > reach[joint.parent] {
                reach[joint.parent] = r;
            }
        }
        let mut weights = vec![Vec::new(); self.links.len()];
        for &j in &self.order {
            let joint = &self.joints[j];
            let mut w = weights[joint.parent].clone();
            let per_unit = match joint.kind {
                JointKind::Revolute | JointKind::Continuous => reach[joint.child],
                JointKind::Prismatic => 1.0,
                JointKind::Fixed => 0.0,
            };
            let source = joint
                .dof
                .map(|d| (d, 1.0))
                .or_else(|| joint.mimic.map(|m| (m.dof, m.multiplier.abs())));
            if let Some((d, scale)) = source {
                if per_unit > 0.0 {
                    w.push((d, per_unit * scale));
                }
            }
            weights[joint.child] = w;
        }
        // Links without geometry (or a held object) do not move anything.
        for (l, link) in self.links.iter().enumerate() {
            if link.geometry.is_none() && !self.attached.iter().any(|o| o.link == l) {
                weights[l].clear();
            }
        }
        self.motion_weights = weights;
    }
}
