//! |P(poses moved) - P(data moved)| and monotonicity over gaps, by near_context.
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};
fn main() {
    let sigma = 0.002;
    let t = Pose::new(Vector3::new(0.3, -0.4, 1.0), Vector3::new(1.0, 2.0, -0.5));
    for n in [1500usize, 2000, 4000] {
        let a = PointCloud::from_sigma(
            add_noise(&sphere(&Point3::origin(), 0.1, n), sigma, 11),
            sigma,
        )
        .unwrap();
        let b = PointCloud::from_sigma(
            add_noise(&sphere(&Point3::origin(), 0.1, n), sigma, 12),
            sigma,
        )
        .unwrap();
        for ctx in [0.0, 1.0, 2.0, 3.0] {
            let req = CollisionRequest::builder()
                .near_context(ctx)
                .build()
                .unwrap();
            let mut worst: f64 = 0.0;
            let mut bumps: f64 = 0.0;
            let mut prev = 1.0;
            for k in [
                -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0,
            ] {
                let pb = Pose::translation(0.2 + k * sigma, 0.0, 0.0);
                let r0 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
                let r1 = collide(
                    &Pose::identity(),
                    &a.transformed(&t),
                    &Pose::identity(),
                    &b.transformed(&(t * pb)),
                    &req,
                )
                .unwrap();
                worst = worst.max((r0.probability - r1.probability).abs());
                bumps = bumps.max(r0.probability - prev);
                prev = r0.probability;
            }
            println!("n {n} ctx {ctx}: worst frame dP {worst:.4}, worst increase {bumps:.4}");
        }
    }
}
