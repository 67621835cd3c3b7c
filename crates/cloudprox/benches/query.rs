#![allow(missing_docs)]
//! `collide` on two 10K-point noisy spheres: apart, near, interpenetrating;
//! the paper's per-point model and the surface-element model, at two noise
//! levels. And a motion of one sphere into the other, queried pose by pose
//! (`collide_many`) and warm-started along the motion (`collide_along`). The
//! element model averaged over three segmentations near contact
//! (`/segmentations_3`).
//!
//! `cargo bench -p cloudprox --bench query`
//! (`-- collide_10k_elements` for the element model alone, `-- motion_10k`
//! for the motion)

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

use cloudprox::prelude::*;

#[path = "common.rs"]
mod common;

const GAPS: [(&str, f64); 4] = [
    ("apart_6sigma", 6.0),
    ("apart_20sigma", 20.0),
    ("near_1sigma", 1.0),
    ("interpenetrating_3sigma", -3.0),
];

fn bench_points(c: &mut Criterion) {
    let (a, b) = common::spheres(10_000);
    let _ = (a.bvh(), b.bvh());
    let mut group = c.benchmark_group("collide_10k");
    group.sample_size(20);
    for (name, gap) in GAPS {
        for surface in [Surface::Quadric, Surface::Linear] {
            let req = CollisionRequest {
                model: QueryModel::Points,
                classify: ClassifySettings {
                    surface,
                    ..ClassifySettings::default()
                },
                ..CollisionRequest::default()
            };
            let pose = common::pose_at(gap);
            group.bench_function(format!("{name}/{}", surface.name()), |bch| {
                bch.iter(|| black_box(collide(&Pose::identity(), &a, &pose, &b, &req).unwrap()));
            });
        }
    }
    group.finish();
}

fn bench_elements(c: &mut Criterion) {
    let mut group = c.benchmark_group("collide_10k_elements");
    group.sample_size(20);
    for sigma in [0.001, 0.005] {
        let (a, b) = common::spheres_with_noise(10_000, sigma);
        // Built once per cloud (not part of a query).
        let _ = (a.elements().samples().bvh(), b.elements().samples().bvh());
        for decide_only in [false, true] {
            let req = CollisionRequest {
                model: QueryModel::Elements,
                decide_only,
                ..CollisionRequest::default()
            };
            for (name, gap) in GAPS {
                let pose = common::pose_at_noise(gap, sigma);
                let tag = if decide_only { "/decide_only" } else { "" };
                group.bench_function(format!("sigma_{}mm/{name}{tag}", sigma * 1e3), |bch| {
                    bch.iter(|| {
                        black_box(collide(&Pose::identity(), &a, &pose, &b, &req).unwrap())
                    });
                });
            }
        }
        // The mean over three segmentations, near contact (each segmentation's
        // elements built once, not part of a query).
        let req = CollisionRequest {
            model: QueryModel::Elements,
            segmentations: 3,
            ..CollisionRequest::default()
        };
        cloudprox::query::prepare(&a, &req);
        cloudprox::query::prepare(&b, &req);
        for (name, gap) in [GAPS[2], GAPS[3]] {
            let pose = common::pose_at_noise(gap, sigma);
            group.bench_function(
                format!("sigma_{}mm/{name}/segmentations_3", sigma * 1e3),
                |bch| {
                    bch.iter(|| {
                        black_box(collide(&Pose::identity(), &a, &pose, &b, &req).unwrap())
                    });
                },
            );
        }
    }
    group.finish();
}

fn bench_element_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("elements_build_10k");
    group.sample_size(10);
    for sigma in [0.001, 0.005] {
        let (a, _) = common::spheres_with_noise(10_000, sigma);
        let _ = a.spacing();
        let settings = cloudprox::element::ElementSettings::default();
        group.bench_function(format!("sigma_{}mm", sigma * 1e3), |bch| {
            bch.iter(|| {
                black_box(cloudprox::element::SurfaceElements::build(&a, &settings).unwrap())
            });
        });
    }
    group.finish();
}

/// A approaching B from 6 sigma apart to 3 sigma into it in quarter-sigma
/// steps (37 poses, sigma 1 mm): every pose queried.
fn bench_motion(c: &mut Criterion) {
    let mut group = c.benchmark_group("motion_10k");
    group.sample_size(10);
    let (a, b) = common::spheres(10_000);
    let poses: Vec<Pose> = (0..=36)
        .map(|k| {
            let gap = (6.0 - 0.25 * f64::from(k)) * common::SIGMA;
            Pose::translation(-2.0 * common::RADIUS - gap, 0.0, 0.0)
        })
        .collect();
    let id = Pose::identity();
    for model in [QueryModel::Points, QueryModel::Elements] {
        let req = CollisionRequest {
            model,
            ..CollisionRequest::default()
        };
        cloudprox::query::prepare(&a, &req);
        cloudprox::query::prepare(&b, &req);
        let name = format!("{model:?}").to_lowercase();
        group.bench_function(format!("{name}/collide_many"), |bch| {
            bch.iter(|| black_box(collide_many(&poses, &a, &id, &b, &req).unwrap()));
        });
        group.bench_function(format!("{name}/collide_along"), |bch| {
            bch.iter(|| black_box(collide_along(&poses, &a, &id, &b, &req).unwrap()));
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    bench_points,
    bench_elements,
    bench_element_build,
    bench_motion
);
criterion_main!(benches);
