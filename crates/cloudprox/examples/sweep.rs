//! Collision probability against separation for two noisy spheres and two plates.
//!
//! `cargo run --release --example sweep -- [n_points] [linear|quadric]`
//!
//! Environment overrides for experiments: `SLACK_WEIGHT`, `ETA` (robust
//! confidence), `RMAX` (largest patch), `CTX` (near context in spacings), `DISC=1`
//! (add the discretization error), `MODEL` (`elements` or `points`).

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, box_surface, sphere};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let surface = args
        .get(2)
        .and_then(|s| Surface::from_name(s))
        .unwrap_or_default();
    let sigma = 0.002;
    let r = 0.1;
    let env = |k: &str, d: f64| {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(d)
    };
    let defaults = CollisionRequest::default();
    let request = CollisionRequest {
        classify: ClassifySettings {
            surface,
            slack_weight: env("SLACK_WEIGHT", defaults.classify.slack_weight),
            robust_eta: env("ETA", defaults.classify.robust_eta),
            ..defaults.classify
        },
        region_max_points: env("RMAX", defaults.region_max_points as f64) as usize,
        near_context: env("CTX", defaults.near_context),
        model: std::env::var("MODEL")
            .ok()
            .and_then(|m| QueryModel::from_name(&m))
            .unwrap_or_default(),
        ..defaults
    };
    request.validate().unwrap();
    let disc = env("DISC", 0.0) > 0.0;
    let make = |p: Vec<Point3>| {
        let c = PointCloud::from_sigma(p, sigma).unwrap();
        if disc {
            c.with_discretization(&DiscretizationSettings::default())
                .unwrap()
        } else {
            c
        }
    };
    let a = make(add_noise(&sphere(&Point3::origin(), r, n), sigma, 1));
    let b = make(add_noise(&sphere(&Point3::origin(), r, n), sigma, 2));
    println!(
        "spheres: n = {n}, radius {r}, sigma {sigma}, surface {}",
        surface.name()
    );
    println!(
        "{:>6} {:>10} {:>10} {:>8} {:>8} {:>9}",
        "d/sig", "P", "state", "patches", "points", "ms"
    );
    for k in [
        -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 15.0,
    ] {
        let d = k * sigma;
        let pb = Pose::translation(2.0 * r + d, 0.0, 0.0);
        let res = collide(&Pose::identity(), &a, &pb, &b, &request).unwrap();
        println!(
            "{k:>6.1} {:>10.4} {:>10} {:>8} {:>8} {:>9.2}   sep {:+.4} it {}",
            res.probability,
            res.state.name(),
            res.stats.counters.patches,
            res.stats.counters.points_classified,
            res.stats.time_seconds * 1e3,
            res.patches
                .iter()
                .map(|r| r.separation)
                .fold(f64::INFINITY, f64::min)
                / sigma,
            res.stats.counters.solver_iterations
        );
    }
    // Plates: a 20 cm x 20 cm x 2 cm slab under a 10 cm x 10 cm x 2 cm slab.
    let spacing = 0.01;
    let pa = add_noise(
        &box_surface(&Point3::origin(), &Vector3::new(0.1, 0.1, 0.01), spacing),
        sigma,
        3,
    );
    let pb = add_noise(
        &box_surface(&Point3::origin(), &Vector3::new(0.05, 0.05, 0.01), spacing),
        sigma,
        4,
    );
    let a = make(pa);
    let b = make(pb);
    println!("plates: {} and {} points", a.len(), b.len());
    for k in [
        -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 15.0,
    ] {
        let d = k * sigma;
        let pose_b = Pose::translation(0.0, 0.0, 0.02 + d);
        let res = collide(&Pose::identity(), &a, &pose_b, &b, &request).unwrap();
        println!(
            "{k:>6.1} {:>10.4} {:>10} {:>8} {:>8} {:>9.2}",
            res.probability,
            res.state.name(),
            res.stats.counters.patches,
            res.stats.counters.points_classified,
            res.stats.time_seconds * 1e3
        );
    }
}
