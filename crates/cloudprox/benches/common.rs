//! Scenes shared by the benches.
#![allow(dead_code)]

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};

/// Noise of every point (1 mm, a structured-light camera at about 0.8 m).
pub const SIGMA: f64 = 0.001;
/// Radius of both spheres.
pub const RADIUS: f64 = 0.1;

/// Two noisy spheres of `n` points each, noise [`SIGMA`].
pub fn spheres(n: usize) -> (PointCloud, PointCloud) {
    spheres_with_noise(n, SIGMA)
}

/// Two noisy spheres of `n` points each, isotropic noise `sigma`.
pub fn spheres_with_noise(n: usize, sigma: f64) -> (PointCloud, PointCloud) {
    let a = PointCloud::from_sigma(
        add_noise(&sphere(&Point3::origin(), RADIUS, n), sigma, 1),
        sigma,
    )
    .unwrap();
    let b = PointCloud::from_sigma(
        add_noise(&sphere(&Point3::origin(), RADIUS, n), sigma, 2),
        sigma,
    )
    .unwrap();
    (a, b)
}

/// Pose of B whose exact surface is `gap_sigmas` sigma ([`SIGMA`]) from A's.
pub fn pose_at(gap_sigmas: f64) -> Pose {
    pose_at_noise(gap_sigmas, SIGMA)
}

/// Pose of B whose exact surface is `gap_sigmas` times `sigma` from A's.
pub fn pose_at_noise(gap_sigmas: f64, sigma: f64) -> Pose {
    Pose::translation(2.0 * RADIUS + gap_sigmas * sigma, 0.0, 0.0)
}
