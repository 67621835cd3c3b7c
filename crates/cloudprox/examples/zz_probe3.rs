#![allow(missing_docs)]
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};
fn main() {
    for sigma in [0.001, 0.005] {
        for gap in [1.0, -3.0] {
            let mk = |s| {
                PointCloud::from_sigma(
                    add_noise(&sphere(&Point3::origin(), 0.1, 10_000), sigma, s),
                    sigma,
                )
                .unwrap()
            };
            let (a, b) = (mk(1), mk(2));
            let pose = Pose::translation(0.2 + gap * sigma, 0.0, 0.0);
            let req = CollisionRequest {
                model: QueryModel::Elements,
                ..CollisionRequest::default()
            };
            eprintln!("sigma {sigma} gap {gap}");
            let _ = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
        }
    }
}
