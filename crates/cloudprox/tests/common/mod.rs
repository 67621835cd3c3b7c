//! Scenes shared by the integration tests.
#![allow(dead_code)]

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, box_surface, sphere};

pub const SIGMA: f64 = 0.002;
pub const RADIUS: f64 = 0.1;

/// Two noisy spheres of radius 0.1 m centred at the origin of their own frames.
pub fn spheres(n: usize) -> (PointCloud, PointCloud) {
    let a = add_noise(&sphere(&Point3::origin(), RADIUS, n), SIGMA, 11);
    let b = add_noise(&sphere(&Point3::origin(), RADIUS, n), SIGMA, 12);
    (
        PointCloud::from_sigma(a, SIGMA).unwrap(),
        PointCloud::from_sigma(b, SIGMA).unwrap(),
    )
}

/// Pose of sphere B so that the exact surfaces are `gap` apart along x.
pub fn sphere_pose(gap: f64) -> Pose {
    Pose::translation(2.0 * RADIUS + gap, 0.0, 0.0)
}

/// A 20 x 20 x 2 cm plate (A) and a 10 x 10 x 2 cm plate (B), both surfaces
/// sampled every 1 cm, in their own frames centred at the origin.
pub fn plates() -> (PointCloud, PointCloud) {
    let a = add_noise(
        &box_surface(&Point3::origin(), &Vector3::new(0.1, 0.1, 0.01), 0.01),
        SIGMA,
        21,
    );
    let b = add_noise(
        &box_surface(&Point3::origin(), &Vector3::new(0.05, 0.05, 0.01), 0.01),
        SIGMA,
        22,
    );
    (
        PointCloud::from_sigma(a, SIGMA).unwrap(),
        PointCloud::from_sigma(b, SIGMA).unwrap(),
    )
}

/// Pose of plate B resting `gap` above plate A's top face.
pub fn plate_pose(gap: f64) -> Pose {
    Pose::translation(0.0, 0.0, 0.02 + gap)
}

/// Feeds every prefix of `file`, and `file` with each of `bits` flipped in every
/// byte, to `read` (the readers' no-panic tests: `read` ignores the result).
pub fn for_each_corruption(file: &[u8], bits: &[u32], mut read: impl FnMut(&[u8])) {
    for cut in 0..file.len() {
        read(&file[..cut]);
    }
    let mut f = file.to_vec();
    for i in 0..file.len() {
        for &bit in bits {
            f[i] ^= 1 << bit;
            read(&f);
            f[i] ^= 1 << bit;
        }
    }
}

/// `len` pseudo-random bytes (a linear congruential generator from `seed`).
pub fn garbage(len: usize, seed: u32) -> Vec<u8> {
    let mut x = seed;
    (0..len)
        .map(|_| {
            x = x.wrapping_mul(1664525).wrapping_add(1013904223);
            (x >> 24) as u8
        })
        .collect()
}

/// A cube of half-side `h` at the origin.
pub fn cube(h: f64) -> Mesh {
    Mesh::cuboid(h, h, h).unwrap()
}

/// An exact shape of `parts`.
pub fn shape(parts: &[Mesh]) -> ExactShape {
    ExactShape::new(parts).unwrap()
}

/// A translation.
pub fn at(x: f64, y: f64, z: f64) -> Pose {
    Pose::translation(x, y, z)
}
