//! Scratch profiling driver (not committed).
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let gap: f64 = args[1].parse().unwrap();
    let decide = args.get(2).is_some();
    let sigma = 0.001;
    let mk = |seed| {
        PointCloud::from_sigma(
            add_noise(&sphere(&Point3::origin(), 0.1, 10_000), sigma, seed),
            sigma,
        )
        .unwrap()
    };
    let (a, b) = (mk(1), mk(2));
    let req = CollisionRequest::builder()
        .model(QueryModel::Elements)
        .decide_only(decide)
        .build()
        .unwrap();
    let pose = Pose::translation(0.2 + gap * sigma, 0.0, 0.0);
    let r = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
    println!("{:?}", r.stats);
    let t = std::time::Instant::now();
    for _ in 0..2000 {
        std::hint::black_box(collide(&Pose::identity(), &a, &pose, &b, &req).unwrap());
    }
    println!("{:.3} ms", t.elapsed().as_secs_f64() / 2.0);
}
