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
/// frame) for a [`RobotShadow`], cached on the robot per footprint.
#[derive(Debug)]
pub(crate) struct ShadowSamples {
    shadow: RobotShadow,
    samples: Arc<Vec<Vec<Point3>>>,
}

impl ShadowSamples {
    /// The samples of `robot`'s links and objects at `shadow`'s footprint
    /// (sampled on first use of that footprint).
    ///
    /// # Errors
    /// An invalid `shadow`; a link that cannot be sampled.
    pub(crate) fn new(robot: &Robot, shadow: &RobotShadow) -> Result<Self> {
        shadow.validate()?;
        let spacing = shadow.occlusion.footprint();
        let samples = robot
            .shadow_samples
            .get_or_build(spacing, || sample_entries(robot, spacing))?;
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

/// Every entry's surface samples at `spacing` (a sample per `spacing^2`).
fn sample_entries(robot: &Robot, spacing: Real) -> Result<Vec<Vec<Point3>>> {
    let density = 1.0 / (spacing * spacing);
    let geometries = robot
        .links
        .iter()
        .map(|l| l.geometry.as_ref())
        .chain(robot.attached.iter().map(|o| Some(&o.geometry)));
    geometries
        .map(|g| match g {
            Some(g) => g
                .mesh
                .sample_surface_density(density, LINK_SAMPLING_SEED)
                .map(|s| s.points),
            None => Ok(Vec::new()),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::AttachedShape;
    use crate::shape::Mesh;

    const URDF: &str = r#"<robot name="bar">
      <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
      <link name="arm"><collision><origin xyz="0.2 0 0.05"/><geometry><box size="0.4 0.04 0.04"/></geometry></collision></link>
      <joint name="turn" type="revolute"><parent link="base"/><child link="arm"/>
        <origin xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"#;

    /// A shadow over a 1 cm grid of points on the plane x = 1 seen from the
    /// origin (footprint about 1 cm).
    fn shadow() -> RobotShadow {
        let pts: Vec<Point3> = (0..41 * 41)
            .map(|i| {
                Point3::new(
                    1.0,
                    0.01 * Real::from(i % 41) - 0.2,
                    0.01 * Real::from(i / 41) - 0.2,
                )
            })
            .collect();
        let spacing = vec![0.01; pts.len()];
        let occ = Occlusion::new(&pts, None, &spacing, Point3::origin(), None).unwrap();
        RobotShadow::new(Arc::new(occ))
    }

    #[test]
    fn the_samples_are_drawn_once_per_footprint_and_again_after_an_attach() {
        let mut robot = Robot::from_urdf_str(URDF, "bar.urdf", None, &[]).unwrap();
        let shadow = shadow();
        let first = ShadowSamples::new(&robot, &shadow).unwrap();
        let again = ShadowSamples::new(&robot, &shadow).unwrap();
        assert!(Arc::ptr_eq(&first.samples, &again.samples));
        assert_eq!(first.samples.len(), robot.links().len());
        assert!(first.samples.iter().all(|s| !s.is_empty()));
        // The samples are the links' surfaces at the footprint: a box of
        // area A holds about A / footprint^2 of them.
        let area = 2.0 * (0.4 * 0.04 * 2.0 + 0.04 * 0.04);
        let expected = area / shadow.occlusion.footprint().powi(2);
        let n = first.samples[1].len() as Real;
        assert!((n - expected).abs() < 0.2 * expected, "{n} vs {expected}");
        let cube = Mesh::cuboid(0.02, 0.02, 0.02).unwrap();
        robot
            .attach(
                "arm",
                AttachedShape::Mesh(cube),
                &Pose::identity(),
                "cube",
                &[],
            )
            .unwrap();
        let held = ShadowSamples::new(&robot, &shadow).unwrap();
        assert!(!Arc::ptr_eq(&first.samples, &held.samples));
        assert_eq!(held.samples.len(), robot.links().len() + 1);
    }
}
