#![allow(missing_docs)]
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};
fn main() {
    for sigma in [0.001, 0.005] {
        let mk = |s| {
            PointCloud::from_sigma(
                add_noise(&sphere(&Point3::origin(), 0.1, 10_000), sigma, s),
                sigma,
            )
            .unwrap()
        };
        let (a, b) = (mk(1), mk(2));
        let _ = (a.elements().samples().bvh(), b.elements().samples().bvh());
        for gap in [1.0, -3.0] {
            let pose = Pose::translation(0.2 + gap * sigma, 0.0, 0.0);
            let req = CollisionRequest {
                model: QueryModel::Elements,
                ..CollisionRequest::default()
            };
            let mut best = f64::MAX;
            let mut r = None;
            for _ in 0..50 {
                let x = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
                best = best.min(x.stats.time_seconds);
                r = Some(x);
            }
            let r = r.unwrap();
            println!(
                "sigma {sigma} gap {gap}: P {:.4} best {:.3} ms {:?}",
                r.probability,
                best * 1e3,
                r.stats.counters
            );
            for p in &r.patches {
                println!(
                    "   patch: {} + {} pts, iters {}",
                    p.indices_a.len(),
                    p.indices_b.len(),
                    p.iterations
                );
            }
        }
    }
}
