//! Scale: a cloud of millions of points, its hierarchy, and one query against it.
//!
//! `cargo run --release --example scale -- [n_points]` (default 10^7). Under
//! `/usr/bin/time -v` for the peak resident set; the example also prints the
//! process's own high-water mark (`VmHWM`) after each stage, so the memory of
//! the points, their covariances and the hierarchy can be told apart.
//! `RAYON_NUM_THREADS=1` runs every stage on one thread.
//!
//! The cloud: a 10 m x 10 m floor with gentle waves (amplitude 5 cm), sampled on
//! a regular grid, 2 mm isotropic noise. The query: a 10 000-point noisy sphere
//! of radius 0.1 m whose lowest point is about 1 cm above the floor (5 sigma;
//! the floor is not flat under it), then about 1 cm into it. The cloud's
//! sampling spacing, which the query needs, is computed before it and timed on
//! its own.

use std::time::Instant;

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};

/// The floor's height at `(x, y)`.
fn floor(x: f64, y: f64) -> f64 {
    0.05 * (0.7 * x).sin() * (0.5 * y).cos()
}

/// The process's peak resident set so far (MiB), from `/proc/self/status`.
fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() -> Result<()> {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse::<f64>().ok())
        .map_or(10_000_000, |x| x as usize);
    let sigma = 0.002;
    let side = (n as f64).sqrt().ceil() as usize;
    let pitch = 10.0 / side as f64;
    let t = Instant::now();
    let grid: Vec<Point3> = (0..n)
        .map(|k| {
            let (x, y) = (
                (k % side) as f64 * pitch - 5.0,
                (k / side) as f64 * pitch - 5.0,
            );
            Point3::new(x, y, floor(x, y))
        })
        .collect();
    let points = add_noise(&grid, sigma, 1);
    drop(grid);
    println!(
        "points: {n} ({side} x {side} grid, pitch {:.2} mm), made in {:.2} s, peak {:.0} MiB",
        pitch * 1e3,
        t.elapsed().as_secs_f64(),
        peak_mib()
    );

    let t = Instant::now();
    let cloud = PointCloud::from_sigma(points, sigma)?;
    println!(
        "cloud (validation, covariances, sigmas): {:.2} s, peak {:.0} MiB",
        t.elapsed().as_secs_f64(),
        peak_mib()
    );

    let t = Instant::now();
    let nodes = cloud.bvh().nodes().len();
    println!(
        "hierarchy ({nodes} nodes): {:.2} s, peak {:.0} MiB",
        t.elapsed().as_secs_f64(),
        peak_mib()
    );

    let t = Instant::now();
    let median = {
        let mut s = cloud.spacing().to_vec();
        let mid = s.len() / 2;
        *s.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    println!(
        "sampling spacing (6th neighbour of every point, the hashed grid; median {:.2} mm): \
         {:.2} s, peak {:.0} MiB",
        median * 1e3,
        t.elapsed().as_secs_f64(),
        peak_mib()
    );

    let ball = PointCloud::from_sigma(
        add_noise(&sphere(&Point3::origin(), 0.1, 10_000), sigma, 2),
        sigma,
    )?;
    let request = CollisionRequest::default();
    for gap in [0.01, -0.01] {
        let z = floor(0.3, -0.2) + 0.1 + gap;
        let pose = Pose::translation(0.3, -0.2, z);
        let t = Instant::now();
        let r = collide(&pose, &ball, &Pose::identity(), &cloud, &request)?;
        println!(
            "query, 10 000-point sphere {:+.0} mm from the floor: P = {:.4} ({}), {:.1} ms",
            gap * 1e3,
            r.probability,
            r.state.name(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    println!(
        "peak {:.0} MiB in all, {:.0} bytes a point",
        peak_mib(),
        peak_mib() * 1024.0 * 1024.0 / n as f64
    );
    Ok(())
}
