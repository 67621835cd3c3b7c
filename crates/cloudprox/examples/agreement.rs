//! Distribution of |P(hierarchy) - P(brute force)| on random small scenes.
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere, NormalRng};

fn main() {
    let sigma = 0.003;
    let mut rng = NormalRng::new(5);
    for surface in [Surface::Linear, Surface::Quadric] {
        let req = |h: bool| {
            CollisionRequest::builder()
                .classify(
                    ClassifySettings::builder()
                        .surface(surface)
                        .build()
                        .unwrap(),
                )
                .use_hierarchy(h)
                .region_max_points(100_000)
                .build()
                .unwrap()
        };
        let mut diffs = Vec::new();
        let mut state_mismatch = 0;
        for k in 0..200 {
            let na = 40 + (rng.uniform() * 120.0) as usize;
            let nb = 40 + (rng.uniform() * 120.0) as usize;
            let ra = 0.03 + 0.05 * rng.uniform();
            let rb = 0.03 + 0.05 * rng.uniform();
            let gap = -3.0 + 17.0 * rng.uniform();
            let a = PointCloud::from_sigma(
                add_noise(&sphere(&Point3::origin(), ra, na), sigma, k),
                sigma,
            )
            .unwrap();
            let b = PointCloud::from_sigma(
                add_noise(&sphere(&Point3::origin(), rb, nb), sigma, k + 999),
                sigma,
            )
            .unwrap();
            let dir = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            let pb = Pose::new(
                dir * (ra + rb + gap * sigma),
                Vector3::new(rng.normal(), rng.normal(), rng.normal()),
            );
            let h = collide(&Pose::identity(), &a, &pb, &b, &req(true)).unwrap();
            let bf = collide(&Pose::identity(), &a, &pb, &b, &req(false)).unwrap();
            diffs.push((
                (h.probability - bf.probability).abs(),
                gap,
                h.probability,
                bf.probability,
            ));
            if h.state != bf.state {
                state_mismatch += 1;
            }
        }
        diffs.sort_by(|x, y| x.0.total_cmp(&y.0));
        let q = |f: f64| diffs[((diffs.len() - 1) as f64 * f) as usize].0;
        println!(
            "{:?}: median {:.4} p90 {:.4} p99 {:.4} max {:.4} state mismatches {}/200; worst {:?}",
            surface,
            q(0.5),
            q(0.9),
            q(0.99),
            q(1.0),
            state_mismatch,
            diffs.last().unwrap()
        );
    }
}
