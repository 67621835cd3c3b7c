#![allow(missing_docs)]
//! The sensor-cloud filters on synthetic depth images of 1000 x 1000 (1M) and
//! 1920 x 1080 (2M) pixels: a wall 2 m away, a box and a sphere in front of it,
//! 1 mm depth noise and veil points at the silhouettes.
//!
//! `cargo bench -p cloudprox --bench filter -- --sample-size 10`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

use cloudprox::filter::{
    crop_box, shadow_filter, statistical_outlier_removal, voxel_downsample, SelfFilter,
    ShadowSettings, SOR_DEFAULT_K, SOR_DEFAULT_STD_RATIO,
};
use cloudprox::io::Grid;
use cloudprox::prelude::*;
use cloudprox::sample::NormalRng;

/// Depth along the ray `(u, v, 1)` of the scene (wall, box front, sphere).
fn depth(u: f64, v: f64) -> f64 {
    let mut t: f64 = 2.0; // wall z = 2
    if (-0.3..=0.3).contains(&u) && (-0.2..=0.2).contains(&v) {
        t = t.min(1.0); // box front face z = 1 (its sides are hidden)
    }
    // Sphere centre (0.5, 0.3, 1.5), radius 0.2.
    let (d, c) = (Vector3::new(u, v, 1.0), Vector3::new(0.5, 0.3, 1.5));
    let (a, b, cc) = (d.dot(&d), -2.0 * d.dot(&c), c.dot(&c) - 0.04);
    let disc = b * b - 4.0 * a * cc;
    if disc >= 0.0 {
        let s = (-b - disc.sqrt()) / (2.0 * a);
        if s > 0.0 {
            t = t.min(s);
        }
    }
    t
}

fn scene(width: usize, height: usize) -> (Vec<Point3>, Grid) {
    let f = width as f64 / 2.0 / (35f64.to_radians()).tan();
    let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
    let z: Vec<f64> = (0..width * height)
        .map(|px| {
            depth(
                ((px % width) as f64 - cx) / f,
                ((px / width) as f64 - cy) / f,
            )
        })
        .collect();
    let mut rng = NormalRng::new(7);
    let mut points = Vec::with_capacity(width * height);
    for px in 0..width * height {
        let (r, c) = (px / width, px % width);
        let mut d = z[px];
        // Veil: a pixel next to a nearer one reads a mixed depth half the time.
        if c + 1 < width && z[px + 1] < d - 0.1 && rng.uniform() < 0.5 {
            let t = 0.15 + 0.7 * rng.uniform();
            d = (1.0 - t) * z[px + 1] + t * d;
        }
        d += 0.001 * rng.normal();
        points.push(Point3::new(
            (c as f64 - cx) / f * d,
            (r as f64 - cy) / f * d,
            d,
        ));
    }
    let grid = Grid {
        width,
        height,
        pixels: (0..(width * height) as u32).collect(),
    };
    (points, grid)
}

fn bench_filter(c: &mut Criterion) {
    let mut group = c.benchmark_group("filter");
    for (w, h, name) in [(1000, 1000, "1M"), (1920, 1080, "2M")] {
        let (points, grid) = scene(w, h);
        let covs = vec![Matrix3::identity() * 1e-6; points.len()];
        let pose = Pose::new(Vector3::new(0.1, 0.0, 1.5), Vector3::new(0.0, 0.3, 0.2));
        group.bench_function(BenchmarkId::new("crop_box", name), |b| {
            b.iter(|| {
                black_box(
                    crop_box(
                        &points,
                        &Point3::new(-0.5, -0.5, -0.6),
                        &Point3::new(0.5, 0.5, 0.6),
                        &pose,
                        false,
                    )
                    .unwrap(),
                )
            });
        });
        group.bench_function(BenchmarkId::new("voxel_1cm_cov", name), |b| {
            b.iter(|| black_box(voxel_downsample(&points, Some(&covs), 0.01).unwrap()));
        });
        group.bench_function(BenchmarkId::new("sor_k20", name), |b| {
            b.iter(|| {
                black_box(
                    statistical_outlier_removal(&points, SOR_DEFAULT_K, SOR_DEFAULT_STD_RATIO)
                        .unwrap(),
                )
            });
        });
        let settings = ShadowSettings::default();
        group.bench_function(BenchmarkId::new("shadow_organized", name), |b| {
            b.iter(|| {
                black_box(
                    shadow_filter(&points, &Point3::origin(), Some(&grid), &settings).unwrap(),
                )
            });
        });
        group.bench_function(BenchmarkId::new("shadow_knn8", name), |b| {
            b.iter(|| {
                black_box(shadow_filter(&points, &Point3::origin(), None, &settings).unwrap())
            });
        });
        // A 7-link arm: the box and the sphere's place are links, the rest in front.
        let mut links = vec![
            (
                Mesh::cuboid(0.3, 0.2, 0.2).unwrap(),
                Pose::translation(0.0, 0.0, 1.2),
            ),
            (
                Mesh::cylinder(0.2, 0.2, 32).unwrap(),
                Pose::translation(0.5, 0.3, 1.5),
            ),
        ];
        for i in 0..5 {
            links.push((
                Mesh::cylinder(0.05, 0.15, 24).unwrap(),
                Pose::new(
                    Vector3::new(-0.6 + 0.1 * i as f64, -0.3, 1.2),
                    Vector3::new(0.3 * i as f64, 0.5, 0.0),
                ),
            ));
        }
        let filter = SelfFilter::new(links, 0.01).unwrap();
        group.bench_function(BenchmarkId::new("self_filter_7_links", name), |b| {
            b.iter(|| black_box(filter.apply(&points)));
        });
    }
    group.finish();
}

criterion_group!(benches, bench_filter);
criterion_main!(benches);
