#![allow(missing_docs)]
//! Hierarchy build, refit and discretization estimate on a 10K-point cloud.
//!
//! `cargo bench -p cloudprox --bench bvh`

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

use cloudprox::bvh::{Bvh, BvhSettings};
use cloudprox::prelude::*;

#[path = "common.rs"]
mod common;

fn bench_bvh(c: &mut Criterion) {
    let (a, _) = common::spheres(10_000);
    let mut group = c.benchmark_group("bvh_10k");
    group.sample_size(20);
    group.bench_function("build", |bch| {
        bch.iter(|| {
            black_box(Bvh::build(a.points(), a.sigma_max(), &BvhSettings::default()).unwrap())
        });
    });
    let mut tree = Bvh::build(a.points(), a.sigma_max(), &BvhSettings::default()).unwrap();
    group.bench_function("refit", |bch| {
        bch.iter(|| tree.refit(a.points(), a.sigma_max()).unwrap());
    });
    group.bench_function("discretization_k10", |bch| {
        bch.iter(|| {
            black_box(
                a.clone()
                    .with_discretization(&DiscretizationSettings::default())
                    .unwrap(),
            )
        });
    });
    group.finish();
}

criterion_group!(benches, bench_bvh);
criterion_main!(benches);
