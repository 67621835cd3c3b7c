//! Grasp targets and link padding: the parts of a robot query that name links,
//! resolved against the robot before the query runs.

use std::sync::Arc;

use super::geometry::LINK_SAMPLING_SEED;
use super::model::Robot;
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Pose;
use crate::probability::CollisionState;
use crate::shape::Mesh;
use crate::Real;

/// The object a grasp target stands for.
#[derive(Debug, Clone)]
pub enum TargetObject {
    /// A cloud in the environment cloud's frame (segmented from the scan, its
    /// points keeping their covariances).
    Cloud(Arc<PointCloud>),
    /// A mesh at a pose in the environment cloud's frame (a known object at
    /// its estimated pose). It is sampled into a cloud at the links' sampling
    /// spacing (no sensor noise, its sampling's covariance; see
    /// [`PointCloud::from_mesh`]), as a sampled link is.
    Mesh {
        /// The mesh, in its own frame.
        mesh: Arc<Mesh>,
        /// Its pose in the environment cloud's frame.
        pose: Pose,
    },
}

/// An object the robot is about to grasp, still in the scene: the links of
/// `allowed_links` may touch it, every other link is checked against it as
/// against the environment (see [`RobotRequest::target`](super::RobotRequest::target)).
///
/// # Example
/// ```
/// use std::sync::Arc;
/// use cloudprox::prelude::*;
/// use cloudprox::robot::{collide_robot, GraspTarget, Robot, RobotRequest};
/// let urdf = r#"<robot name="hand"><link name="finger"><collision>
///     <geometry><box size="0.02 0.02 0.02"/></geometry></collision></link></robot>"#;
/// let robot = Robot::from_urdf_str(urdf, "hand.urdf", None, &[]).unwrap();
/// // A patch of the plane x = x0 (2 mm grid, 1 mm noise).
/// let patch = |x0: f64| {
///     let points = (0..49)
///         .map(|i| Point3::new(x0, (i % 7) as f64 * 0.002 - 0.006, (i / 7) as f64 * 0.002 - 0.006))
///         .collect();
///     PointCloud::from_sigma(points, 0.001).unwrap()
/// };
/// // The object on the finger's face x = 0.01; the rest of the scene far away.
/// let object = Arc::new(patch(0.009));
/// let scene = patch(1.0);
/// let allowed = RobotRequest {
///     target: Some(GraspTarget::cloud(Arc::clone(&object), vec!["finger".into()])),
///     ..RobotRequest::default()
/// };
/// let r = collide_robot(&robot, &[], &Pose::identity(), &scene, &allowed).unwrap();
/// assert_eq!(r.state, CollisionState::Free);
/// assert_eq!(r.target.unwrap().state, CollisionState::Collision);
/// // Not allowed: the object counts as the scene does.
/// let denied = RobotRequest {
///     target: Some(GraspTarget::cloud(object, Vec::new())),
///     ..RobotRequest::default()
/// };
/// let r = collide_robot(&robot, &[], &Pose::identity(), &scene, &denied).unwrap();
/// assert_eq!(r.state, CollisionState::Collision);
/// ```
#[derive(Debug, Clone)]
pub struct GraspTarget {
    /// The object.
    pub object: TargetObject,
    /// The links (or attached objects) allowed to touch it, by name (the
    /// fingers, the hand): their contacts with it are reported apart
    /// ([`RobotCollisionResult::target`](super::RobotCollisionResult::target))
    /// and do not enter the robot's probability.
    pub allowed_links: Vec<String>,
}

impl GraspTarget {
    /// A target given as its own cloud (environment frame).
    pub fn cloud(cloud: Arc<PointCloud>, allowed_links: Vec<String>) -> Self {
        Self {
            object: TargetObject::Cloud(cloud),
            allowed_links,
        }
    }

    /// A target given as a mesh at `pose` (environment frame).
    pub fn mesh(mesh: Arc<Mesh>, pose: Pose, allowed_links: Vec<String>) -> Self {
        Self {
            object: TargetObject::Mesh { mesh, pose },
            allowed_links,
        }
    }
}

impl PartialEq for GraspTarget {
    /// The same object (the same shared cloud or mesh, at the same pose) and
    /// the same allowed links.
    fn eq(&self, o: &Self) -> bool {
        let same = match (&self.object, &o.object) {
            (TargetObject::Cloud(a), TargetObject::Cloud(b)) => Arc::ptr_eq(a, b),
            (TargetObject::Mesh { mesh: a, pose: p }, TargetObject::Mesh { mesh: b, pose: q }) => {
                Arc::ptr_eq(a, b) && p == q
            }
            _ => false,
        };
        same && self.allowed_links == o.allowed_links
    }
}

/// The grasp target's part of a
/// [`RobotCollisionResult`](super::RobotCollisionResult).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetCollision {
    /// The allowed links' contact probability with the target, aggregated as
    /// the robot's probability is (reported apart: it does not enter it).
    pub probability: Real,
    /// The state from `probability` and the thresholds (`collision`: the
    /// fingers are on the object).
    pub state: CollisionState,
    /// The other links' collision probability with the target, aggregated
    /// alike: it enters the robot's probability, as the environment does.
    pub other_probability: Real,
}

/// A request's padding and target resolved against a robot.
#[derive(Debug)]
pub(crate) struct Resolved {
    /// Per entry (links, then attached objects, as
    /// [`LinkCollision::link`](super::LinkCollision::link) numbers them): its
    /// padding (metres; 0 for attached objects).
    pub padding: Vec<Real>,
    /// The target's cloud (environment frame) and, per entry, whether it may
    /// touch it.
    pub target: Option<(Arc<PointCloud>, Vec<bool>)>,
}

/// The padding of every entry of `robot`: `padding` for each link, then the
/// named links' own. `link_padding` is checked here (names, values);
/// `padding` by the request's validation.
fn resolve_padding(
    robot: &Robot,
    padding: Real,
    link_padding: &[(String, Real)],
) -> Result<Vec<Real>> {
    let links = robot.links.len();
    let mut out = vec![padding; links];
    out.resize(links + robot.attached.len(), 0.0);
    for (name, d) in link_padding {
        let Some(i) = robot.link_index(name) else {
            if robot.attached_index(name).is_some() {
                return Err(Error::invalid(format!(
                    "padding names attached object '{name}': attached objects are not padded"
                )));
            }
            return Err(Error::invalid(format!(
                "padding names link '{name}', which robot '{}' does not have",
                robot.name
            )));
        };
        check_padding(*d, &format!("padding of link '{name}'"))?;
        out[i] = *d;
    }
    Ok(out)
}

/// A padding must be finite and `>= 0` (`what` names it).
pub(crate) fn check_padding(d: Real, what: &str) -> Result<()> {
    if d.is_finite() && d >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{what} must be finite and >= 0 (metres), got {d}"
        )))
    }
}

/// The request's padding and target against `robot`; a mesh target is
/// sampled at `spacing()` and moved to its pose.
///
/// # Errors
/// A padding or allowed link naming no link (or, for the allowed links, no
/// attached object) of the robot; a negative or non-finite padding; a mesh
/// target that cannot be sampled.
pub(crate) fn resolve(
    robot: &Robot,
    (padding, link_padding): (Real, &[(String, Real)]),
    target: Option<&GraspTarget>,
    spacing: impl FnOnce() -> Result<Real>,
) -> Result<Resolved> {
    let padding = resolve_padding(robot, padding, link_padding)?;
    let Some(target) = target else {
        return Ok(Resolved {
            padding,
            target: None,
        });
    };
    let entries = robot.links.len() + robot.attached.len();
    let mut allowed = vec![false; entries];
    for name in &target.allowed_links {
        let i = robot
            .link_index(name)
            .or_else(|| robot.attached_index(name).map(|k| robot.links.len() + k));
        let Some(i) = i else {
            return Err(Error::invalid(format!(
                "allowed_links names '{name}', which is neither a link nor an attached \
                 object of robot '{}'",
                robot.name
            )));
        };
        allowed[i] = true;
    }
    let cloud = match &target.object {
        TargetObject::Cloud(c) => Arc::clone(c),
        TargetObject::Mesh { mesh, pose } => {
            let s = spacing()?;
            let sampled = PointCloud::from_mesh(mesh, s, LINK_SAMPLING_SEED)
                .and_then(|c| c.transformed(pose))
                .map_err(|e| Error::invalid(format!("grasp target mesh: {e}")))?;
            Arc::new(sampled)
        }
    };
    Ok(Resolved {
        padding,
        target: Some((cloud, allowed)),
    })
}
