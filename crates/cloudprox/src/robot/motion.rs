//! Checking a straight joint-space motion against an environment cloud.

use super::model::Robot;
use super::query::{check_base, collide_robot_prepared, LinkSides, RobotRequest, RobotWorkspace};
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Pose;
use crate::probability::CollisionState;
use crate::Real;

/// Most states [`check_motion`] checks on one motion.
pub const MAX_MOTION_STATES: usize = 1_000_000;

/// Options of [`check_motion`].
#[derive(Debug, Clone, PartialEq)]
pub struct MotionRequest {
    /// The query at each state (default [`RobotRequest::default`]).
    pub robot: RobotRequest,
    /// The largest distance (metres) any point of any link may move between two
    /// checked states; `None`: the cloud's median sensor standard deviation
    /// (its largest direction), or half its median spacing where the cloud has
    /// no noise. A collision between two checked states then leaves the robot
    /// within half of it of the obstacle at one of them, where the noise model
    /// sees it.
    pub resolution: Option<Real>,
    /// A state is unsafe when its collision probability exceeds this (a chance
    /// constraint), or when links collide with each other (if self-collision is
    /// checked). `None`: the request's free threshold.
    pub max_probability: Option<Real>,
    /// Whether each state's classifier starts from the samples that supported
    /// the previous state's separating surfaces, link by link (default
    /// `true`). Consecutive states lie within the resolution of each other, so
    /// the working set's first round is more often already the optimum. Each
    /// state's classifier still adds every violated constraint, so its
    /// surface is the cold query's to the solver's tolerance and `P` moves by
    /// about 1e-5 at most (a state whose `P` lies that close to
    /// `max_probability` can be judged otherwise); `false` makes every
    /// state's answer bit for bit that of [`collide_robot`](super::collide_robot).
    pub warm_start: bool,
}

impl Default for MotionRequest {
    fn default() -> Self {
        MotionRequest {
            robot: RobotRequest::default(),
            resolution: None,
            max_probability: None,
            warm_start: true,
        }
    }
}

impl MotionRequest {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// As [`RobotRequest::validate`]; a `resolution` given that is not finite
    /// and positive; a `max_probability` given outside `[0, 1]`.
    pub fn validate(&self) -> Result<()> {
        self.robot.validate()?;
        if let Some(r) = self.resolution {
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::invalid(format!(
                    "motion resolution must be finite and > 0, got {r}"
                )));
            }
        }
        if let Some(p) = self.max_probability {
            if !(0.0..=1.0).contains(&p) {
                return Err(Error::invalid(format!(
                    "max_probability must be in [0, 1], got {p}"
                )));
            }
        }
        Ok(())
    }
}

/// The answer of [`check_motion`].
#[derive(Debug, Clone, PartialEq)]
pub struct MotionResult {
    /// Whether every checked state is safe.
    pub safe: bool,
    /// The largest collision probability of the states checked (up to the
    /// first unsafe one: the check stops there).
    pub probability: Real,
    /// The fraction along the motion (0 at `q0`, 1 at `q1`) of the first unsafe state.
    pub first_unsafe: Option<Real>,
    /// The state at the first unsafe state, or the worst state's when safe.
    pub state: CollisionState,
    /// States checked.
    pub states_checked: usize,
    /// States the motion was divided into (`steps + 1` with both ends).
    pub states_total: usize,
    /// The largest displacement (metres) of a link point between two states.
    pub resolution: Real,
    /// Interior-point iterations of the classifiers of every state checked,
    /// summed (what [`MotionRequest::warm_start`] saves).
    pub solver_iterations: u64,
}

/// The default [`MotionRequest::resolution`] for `cloud`.
fn default_resolution(cloud: &PointCloud) -> Real {
    let median = |v: &[Real]| -> Real {
        let mut s = v.to_vec();
        let mid = s.len() / 2;
        let (_, m, _) = s.select_nth_unstable_by(mid, Real::total_cmp);
        *m
    };
    let sigma = median(cloud.sensor_sigma_max());
    if sigma > 0.0 {
        sigma
    } else {
        0.5 * median(cloud.spacing())
    }
}

/// Checks the straight joint-space motion from `q0` to `q1` (root at `base`)
/// against `cloud`: states `q0 + t (q1 - q0)` at `t = i / n`, with `n` the
/// smallest count for which no link point moves more than the resolution
/// between two states ([`Robot::displacement_bound`]); checked in order from
/// `q0`, stopping at the first unsafe state. Each state's classifier starts
/// from the previous state's supporting samples ([`MotionRequest::warm_start`]).
///
/// # Errors
/// As [`MotionRequest::validate`]; as [`Robot::check_configuration`] for `q0`
/// and `q1`; a cloud whose default resolution is 0 (coinciding points without
/// noise); a motion needing more than `MAX_MOTION_STATES` (one million) states.
pub fn check_motion(
    robot: &Robot,
    q0: &[Real],
    q1: &[Real],
    base: &Pose,
    cloud: &PointCloud,
    request: &MotionRequest,
) -> Result<MotionResult> {
    request.validate()?;
    check_base(base)?;
    robot
        .check_configuration(q0)
        .map_err(|e| Error::invalid(format!("q0: {e}")))?;
    robot
        .check_configuration(q1)
        .map_err(|e| Error::invalid(format!("q1: {e}")))?;
    let resolution = request
        .resolution
        .unwrap_or_else(|| default_resolution(cloud));
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(Error::invalid(format!(
            "the cloud gives a motion resolution of {resolution} (no noise and coinciding \
             points): give the resolution"
        )));
    }
    let threshold = request
        .max_probability
        .unwrap_or(request.robot.collide.thresholds.free);
    let dq: Vec<Real> = q0.iter().zip(q1).map(|(a, b)| b - a).collect();
    let travel = robot.displacement_bound(&dq);
    let steps_f = (travel / resolution).ceil().max(1.0);
    if steps_f >= MAX_MOTION_STATES as Real {
        return Err(Error::invalid(format!(
            "the motion moves a link point up to {travel} m: {steps_f} states at resolution \
             {resolution} m exceed {MAX_MOTION_STATES}; raise the resolution"
        )));
    }
    let steps = steps_f as usize;
    let sides = LinkSides::new(robot, &request.robot, cloud)?;
    let mut ws = if request.warm_start {
        RobotWorkspace::warm_started()
    } else {
        RobotWorkspace::default()
    };
    let mut q = vec![0.0; q0.len()];
    let mut worst = 0.0;
    let mut worst_state = CollisionState::Free;
    let mut solver_iterations = 0;
    for i in 0..=steps {
        let t = i as Real / steps as Real;
        for (k, v) in q.iter_mut().enumerate() {
            *v = q0[k] + t * dq[k];
        }
        let r = collide_robot_prepared(robot, &sides, &q, base, cloud, &request.robot, &mut ws);
        solver_iterations += r.stats.counters.solver_iterations;
        if r.probability >= worst {
            worst = r.probability;
            worst_state = r.state;
        }
        if r.probability > threshold || r.self_colliding() {
            return Ok(MotionResult {
                safe: false,
                probability: worst,
                first_unsafe: Some(t),
                state: r.state,
                states_checked: i + 1,
                states_total: steps + 1,
                resolution,
                solver_iterations,
            });
        }
    }
    Ok(MotionResult {
        safe: true,
        probability: worst,
        first_unsafe: None,
        state: worst_state,
        states_checked: steps + 1,
        states_total: steps + 1,
        resolution,
        solver_iterations,
    })
}
