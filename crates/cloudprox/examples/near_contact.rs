//! The elements model's query near contact, repeated: two noisy 10 000-point
//! spheres (radius 0.1 m) at a gap given in sigma, as the criterion bench
//! `collide_10k_elements` sets them, for profilers and instruction counts.
//!
//! `cargo build --profile profiling -p cloudprox --example near_contact`, then
//! `target/profiling/examples/near_contact [QUERIES] [GAP_SIGMAS] [SIGMA]
//! [NEAR_CONTEXT] [SEGMENTATIONS]` (defaults 100, 1, 0.001, 2, 1). Under
//! `valgrind --tool=callgrind` with `RAYON_NUM_THREADS=1`, a query's
//! instructions are the difference between runs of `N` and 0 queries over `N`
//! (the clouds and their elements are built before the first query).

use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};

fn main() -> Result<()> {
    let arg = |k: usize, default: f64| -> f64 {
        std::env::args()
            .nth(k)
            .map_or(default, |s| s.parse().expect("a number"))
    };
    let queries = arg(1, 100.0) as usize;
    let (gap, sigma) = (arg(2, 1.0), arg(3, 0.001));
    let request = CollisionRequest {
        model: QueryModel::Elements,
        near_context: arg(4, 2.0),
        segmentations: arg(5, 1.0) as u32,
        ..CollisionRequest::default()
    };
    let cloud = |seed| -> Result<PointCloud> {
        let points = add_noise(&sphere(&Point3::origin(), 0.1, 10_000), sigma, seed);
        PointCloud::from_sigma(points, sigma)
    };
    let (a, b) = (cloud(1)?, cloud(2)?);
    cloudprox::query::prepare(&a, &request);
    cloudprox::query::prepare(&b, &request);
    let pose_b = Pose::translation(0.2 + gap * sigma, 0.0, 0.0);
    let start = std::time::Instant::now();
    let mut last = None;
    for _ in 0..queries {
        last = Some(collide(&Pose::identity(), &a, &pose_b, &b, &request)?);
    }
    if let Some(r) = last {
        let per_query = start.elapsed().as_secs_f64() / queries as f64;
        println!(
            "{queries} queries, {:.3} ms each: P = {:.6}, {} samples classified",
            per_query * 1e3,
            r.probability,
            r.stats.counters.points_classified
        );
    }
    Ok(())
}
