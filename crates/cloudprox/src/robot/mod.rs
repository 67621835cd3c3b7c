//! Robots: a URDF model (links, joints, limits, collision geometry), its forward
//! kinematics, and the queries of a robot against a noisy environment cloud.
//!
//! | concern | file |
//! |---|---|
//! | the model: links, joints, mimic joints, limits | `model.rs` |
//! | URDF loading (`urdf-rs`), mesh URIs (`package://`, `file://`, relative) | `urdf.rs` |
//! | SRDF `<disable_collisions>` (`quick-xml`) | `srdf.rs` |
//! | forward kinematics, joint-space motion bounds | `kinematics.rs` |
//! | link collision geometry: meshes, URDF primitives, samples, exact shapes | `geometry.rs` |
//! | `collide_robot`, `collide_robot_many`, self-collision | `query.rs` |
//! | `check_motion` | `motion.rs` |
//! | reading the scan's shadow (`RobotRequest::shadow`) | `shadow.rs` |
//! | the caches per sampling spacing (link samples, shadow samples) | `cache.rs` |
//! | attached (held) objects: `Robot::attach`, `Robot::detach` | `attached.rs` |
//! | grasp targets, link padding: resolved against the robot | `target.rs` |
//!
//! A robot is prepared once ([`Robot::from_urdf_file`]): every link's collision
//! elements become one [`Mesh`](crate::shape::Mesh) in the link frame (for
//! sampling and the self-filter) and one [`ExactShape`](crate::query::exact::ExactShape)
//! (for self-collision); the point cloud that stands for a link in a query is
//! sampled once per sampling spacing and cached on the robot.

mod attached;
mod cache;
mod geometry;
mod kinematics;
mod model;
mod motion;
mod query;
mod shadow;
mod srdf;
mod target;
mod urdf;

pub use attached::{AttachedObject, AttachedShape};
pub use geometry::{capsule_mesh, sphere_mesh, LinkGeometry, CIRCLE_SEGMENTS, LINK_SAMPLING_SEED};
pub use model::{Joint, JointKind, Link, Mimic, Robot};
pub use motion::{check_motion, MotionRequest, MotionResult};
pub use query::{
    collide_robot, collide_robot_many, LinkCollision, RobotCollisionResult, RobotCounters,
    RobotRequest, RobotStats, SelfCollision,
};
pub use shadow::{RobotShadow, SHADOW_DEFAULT_DEPTH, SHADOW_DEFAULT_PRIOR};
pub use srdf::{parse_disabled_collisions, DisabledCollision};
pub use target::{GraspTarget, TargetCollision, TargetObject};
