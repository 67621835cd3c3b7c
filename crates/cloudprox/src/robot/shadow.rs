//! The scan's shadow in a robot query ([`RobotShadow`]): a link whose surface
//! reaches into space the sensor did not see reads at least the stated
//! prior's probability, not `free`.

use std::sync::Arc;

use crate::error::{Error, Result};
use crate::filter::Occlusion;
use crate::math::{Point3, Pose};
use crate::robot::geometry::LINK_SAMPLING_SEED;
use crate::robot::Robot;
use crate::Real;

/// How a robot query reads the scan's shadow ([`super::RobotRequest::shadow`]).
///
/// Each link (and attached object) is sampled over its surface at the
/// occlusion's footprint (a cell at the scan's median range); its shadow
/// probability is `prior` times the largest probability among its samples of
/// lying behind the observed surface by at most `depth`
/// ([`Occlusion::hidden_within`]). The link's probability is the request's
/// aggregation of its query's and that. On the robot bench (one Kinect
/// view), a 5 cm depth put every missed collision deeper than 3 sigma in the
/// shadow and a tenth of the free configurations near the scene.
#[derive(Debug, Clone)]
pub struct RobotShadow {
    /// The scan's occlusion, in the cloud's (world) frame.
    pub occlusion: Arc<Occlusion>,
    /// How far behind an observed surface space counts as possibly occupied
    /// (metres, `> 0`; infinite: anywhere behind it): the thickness of the
    /// objects seen from the front. Default 5 cm.
    pub depth: Real,
    /// The probability that space in the shadow is occupied, in `[0, 1]`
    /// (default 1/2: a link there reads `contact` with the default
    /// thresholds).
    pub prior: Real,
}

/// The default [`RobotShadow::depth`] (metres).
pub const SHADOW_DEFAULT_DEPTH: Real = 0.05;

/// The default [`RobotShadow::prior`].
pub const SHADOW_DEFAULT_PRIOR: Real = 0.5;

impl PartialEq for RobotShadow {
    /// The same occlusion (the same shared object), depth and prior.
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.occlusion, &other.occlusion)
            && self.depth == other.depth
            && self.prior == other.prior
    }
}

impl RobotShadow {
    /// The shadow of `occlusion` with the default depth and prior.
    pub fn new(occlusion: Arc<Occlusion>) -> Self {
        Self {
            occlusion,
            depth: SHADOW_DEFAULT_DEPTH,
            prior: SHADOW_DEFAULT_PRIOR,
        }
    }

    /// # Errors
    /// A depth that is not positive (or is NaN), a prior outside `[0, 1]`.
    pub fn validate(&self) -> Result<()> {
        if self.depth.is_nan() || self.depth <= 0.0 {
            return Err(Error::invalid(format!(
                "shadow depth must be positive (metres), got {}",
                self.depth
            )));
        }
        if !(0.0..=1.0).contains(&self.prior) {
            return Err(Error::invalid(format!(
                "shadow prior must lie in [0, 1], got {}",
                self.prior
            )));
        }
        Ok(())
    }
}

/// Each entry's surface samples (links, then attached objects; in its own
/// frame) for a [`RobotShadow`].
#[derive(Debug)]
pub(crate) struct ShadowSamples {
    shadow: RobotShadow,
    samples: Vec<Vec<Point3>>,
}

impl ShadowSamples {
    /// The samples of `robot`'s links and objects at `shadow`'s footprint.
    ///
    /// # Errors
    /// An invalid `shadow`; a link that cannot be sampled.
    pub(crate) fn new(robot: &Robot, shadow: &RobotShadow) -> Result<Self> {
        shadow.validate()?;
        let spacing = shadow.occlusion.footprint();
        let density = 1.0 / (spacing * spacing);
        let geometries = robot
            .links
            .iter()
            .map(|l| l.geometry.as_ref())
            .chain(robot.attached.iter().map(|o| Some(&o.geometry)));
        let samples = geometries
            .map(|g| match g {
                Some(g) => g
                    .mesh
                    .sample_surface_density(density, LINK_SAMPLING_SEED)
                    .map(|s| s.points),
                None => Ok(Vec::new()),
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            shadow: shadow.clone(),
            samples,
        })
    }

    /// Entry `entry`'s shadow probability at world pose `pose`.
    pub(crate) fn probability(&self, entry: usize, pose: &Pose) -> Real {
        let occ = &self.shadow.occlusion;
        let hidden = self.samples[entry]
            .iter()
            .map(|x| occ.hidden_within(&(pose * x), self.shadow.depth))
            .fold(0.0, Real::max);
        self.shadow.prior * hidden
    }
}
