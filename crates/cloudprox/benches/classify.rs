#![allow(missing_docs)]
//! One robust SOCP on two noisy facing patches, by size, surface and solver
//! (the specialized primal-dual method and Clarabel).
//!
//! `cargo bench -p cloudprox --bench classify`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

use cloudprox::classify::{train, ClassifySettings, SocpSolver, Surface};
use cloudprox::math::{Matrix3, Point3};
use cloudprox::sample::NormalRng;

fn patches(n: usize) -> (Vec<Point3>, Vec<Matrix3>, Vec<f64>) {
    let mut rng = NormalRng::new(n as u64);
    let sigma = 0.001;
    let (mut p, mut c, mut l) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        let label = if i % 2 == 0 { 1.0 } else { -1.0 };
        let (x, y) = (0.05 * (rng.uniform() - 0.5), 0.05 * (rng.uniform() - 0.5));
        let z = 3.0 * (x * x + y * y) + label * -0.002 + sigma * rng.normal();
        p.push(Point3::new(x, y, z));
        c.push(Matrix3::identity() * sigma * sigma);
        l.push(label);
    }
    (p, c, l)
}

fn bench_classify(c: &mut Criterion) {
    let mut group = c.benchmark_group("train");
    group.sample_size(20);
    for surface in [Surface::Linear, Surface::Quadric] {
        for solver in [SocpSolver::PrimalDual, SocpSolver::Clarabel] {
            let s = ClassifySettings {
                surface,
                solver,
                ..ClassifySettings::default()
            };
            for n in [100, 200, 400, 800, 1600] {
                let (p, cv, l) = patches(n);
                let id = format!("{}_{}", surface.name(), solver.name());
                group.bench_with_input(BenchmarkId::new(id, n), &n, |b, _| {
                    b.iter(|| black_box(train(&p, &cv, &l, &s).unwrap()));
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, bench_classify);
criterion_main!(benches);
