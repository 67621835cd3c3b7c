#![allow(missing_docs)]
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};
fn main() {
    let sigma: f64 = std::env::args()
        .nth(1)
        .map_or(0.001, |s| s.parse().unwrap());
    let gap: f64 = std::env::args().nth(2).map_or(-3.0, |s| s.parse().unwrap());
    let mk = |s| {
        PointCloud::from_sigma(
            add_noise(&sphere(&Point3::origin(), 0.1, 10_000), sigma, s),
            sigma,
        )
        .unwrap()
    };
    let (a, b) = (mk(1), mk(2));
    let _ = (a.elements().samples().bvh(), b.elements().samples().bvh());
    let pose = Pose::translation(0.2 + gap * sigma, 0.0, 0.0);
    let req = CollisionRequest {
        model: QueryModel::Elements,
        ..CollisionRequest::default()
    };
    let t = std::time::Instant::now();
    let mut n = 0;
    while t.elapsed().as_secs_f64() < 8.0 {
        let _ = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
        n += 1;
    }
    println!(
        "{n} queries, {:.3} ms each",
        t.elapsed().as_secs_f64() * 1e3 / n as f64
    );
}
