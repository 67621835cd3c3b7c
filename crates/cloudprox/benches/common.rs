//! Scenes shared by the benches.
#![allow(dead_code)]

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};

/// Noise of every point (1 mm, a structured-light camera at about 0.8 m).
pub const SIGMA: f64 = 0.001;
/// Radius of both spheres.
pub const RADIUS: f64 = 0.1;

/// Two noisy spheres of `n` points each.
pub fn spheres(n: usize) -> (PointCloud, PointCloud) {
    let a = PointCloud::from_sigma(
        add_noise(&sphere(&Point3::origin(), RADIUS, n), SIGMA, 1),
        SIGMA,
    )
    .unwrap();
    let b = PointCloud::from_sigma(
        add_noise(&sphere(&Point3::origin(), RADIUS, n), SIGMA, 2),
        SIGMA,
    )
    .unwrap();
    (a, b)
}

/// Pose of B whose exact surface is `gap_sigmas` sigma from A's.
pub fn pose_at(gap_sigmas: f64) -> Pose {
    Pose::translation(2.0 * RADIUS + gap_sigmas * SIGMA, 0.0, 0.0)
}
