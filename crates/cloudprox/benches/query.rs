#![allow(missing_docs)]
//! `collide` on two 10K-point noisy spheres: apart, near, interpenetrating.
//!
//! `cargo bench -p cloudprox --bench query`

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

use cloudprox::prelude::*;

#[path = "common.rs"]
mod common;

fn bench_collide(c: &mut Criterion) {
    let (a, b) = common::spheres(10_000);
    let _ = (a.bvh(), b.bvh());
    let mut group = c.benchmark_group("collide_10k");
    group.sample_size(20);
    for (name, gap) in [
        ("apart_6sigma", 6.0),
        ("apart_20sigma", 20.0),
        ("near_1sigma", 1.0),
        ("interpenetrating_3sigma", -3.0),
    ] {
        for surface in [Surface::Quadric, Surface::Linear] {
            let req = CollisionRequest::builder()
                .classify(
                    ClassifySettings::builder()
                        .surface(surface)
                        .build()
                        .unwrap(),
                )
                .build()
                .unwrap();
            let pose = common::pose_at(gap);
            group.bench_function(format!("{name}/{}", surface.name()), |bch| {
                bch.iter(|| black_box(collide(&Pose::identity(), &a, &pose, &b, &req).unwrap()));
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_collide);
criterion_main!(benches);
