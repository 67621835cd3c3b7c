#![allow(missing_docs)]
//! Signed distance to a robot link's mesh: building `MeshDistance` (welding,
//! re-orientation, hierarchy, sign method), building its `DistanceField` on
//! one core (2.5 and 3 mm, band 2 cm), and the cost per point of the exact
//! query against the field's, on points within 2 cm of the surface.
//!
//! Meshes: the Panda hand (collision STL, 200 faces, closed; visual OBJ, 7078
//! faces, open and non-manifold) when the Python tests have fetched them into
//! the cache (`$CLOUDPROX_CACHE` or `~/.cache/cloudprox`, `realfiles/pypi/`),
//! and a synthetic closed link of 4800 faces (0.2 m long, bumpy) always.
//!
//! `cargo bench -p cloudprox --bench signed_distance`

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use cloudprox::prelude::*;
use cloudprox::sample::NormalRng;
use cloudprox::shape::{DistanceField, MeshDistance};

/// A closed, non-convex link: a bumpy capsule-like solid of revolution
/// 0.2 m long, 60 x 40 quads (4800 faces).
fn bumpy_link() -> Mesh {
    let (rings, segments) = (40usize, 60usize);
    let mut vertices = Vec::new();
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for k in 0..segments {
            let f = 2.0 * std::f64::consts::PI * k as f64 / segments as f64;
            let r = 0.03 * (1.0 + 0.25 * (5.0 * f).sin() * (3.0 * t).sin()) * t.sin();
            vertices.push(Point3::new(r * f.cos(), r * f.sin(), -0.1 * t.cos()));
        }
    }
    let bottom = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, -0.1));
    vertices.push(Point3::new(0.0, 0.0, 0.1));
    let top = bottom + 1;
    let at = |i: usize, k: usize| (i * segments + k % segments) as u32;
    let mut faces = Vec::new();
    for k in 0..segments {
        faces.push([bottom, at(0, k + 1), at(0, k)]);
        faces.push([top, at(rings - 2, k), at(rings - 2, k + 1)]);
    }
    for i in 0..rings - 2 {
        for k in 0..segments {
            faces.push([at(i, k), at(i, k + 1), at(i + 1, k + 1)]);
            faces.push([at(i, k), at(i + 1, k + 1), at(i + 1, k)]);
        }
    }
    Mesh::new(vertices, faces).unwrap()
}

/// A real mesh from the Python tests' cache, if it is there.
fn cached(file: &str) -> Option<Mesh> {
    let cache = std::env::var_os("CLOUDPROX_CACHE")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache/cloudprox")))?;
    let path = cache.join("realfiles/pypi").join(file);
    cloudprox::io::read_mesh(&path, None).ok().map(|d| d.mesh)
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    let mut out = all_meshes();
    // `SIGNED_DISTANCE_MESHES=bumpy_link,panda_hand_visual` benches only those.
    if let Ok(only) = std::env::var("SIGNED_DISTANCE_MESHES") {
        out.retain(|(name, _)| only.split(',').any(|o| o == *name));
    }
    out
}

fn all_meshes() -> Vec<(&'static str, Mesh)> {
    let mut out = Vec::new();
    if let Some(m) =
        cached("gym-ignition-models-1.1.1/gym_ignition_models/panda/meshes/collision/hand.stl")
    {
        out.push(("panda_hand_collision", m));
    }
    if let Some(m) = cached("dm-robotics-panda-0.4.8/dm_robotics/panda/assets/panda/hand.obj") {
        out.push(("panda_hand_visual", m));
    }
    out.push(("bumpy_link", bumpy_link()));
    out
}

/// Points within `near` of the surface.
fn near_points(mesh: &Mesh, n: usize, near: f64) -> Vec<Point3> {
    let mut rng = NormalRng::new(3);
    mesh.sample_surface(n, 1)
        .unwrap()
        .points
        .into_iter()
        .map(|p| {
            let d = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            p + d * (near * (2.0 * rng.uniform() - 1.0))
        })
        .collect()
}

fn bench_signed_distance(c: &mut Criterion) {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for (name, mesh) in meshes() {
        let md = Arc::new(MeshDistance::new(&mesh).unwrap());
        eprintln!(
            "{name}: {} faces, sign method {:?}, {:?}",
            mesh.faces().len(),
            md.sign_method(),
            md.topology()
        );
        let mut group = c.benchmark_group(format!("signed_distance_{name}"));
        group.sample_size(10);
        group.measurement_time(std::time::Duration::from_secs(3));
        group.bench_function("mesh_distance_new", |b| {
            b.iter(|| black_box(MeshDistance::new(&mesh).unwrap()));
        });
        for (label, resolution) in [
            ("field_2.5mm_band_2cm_1core", 0.0025),
            ("field_3mm_band_2cm_1core", 0.003),
        ] {
            group.bench_function(label, |b| {
                b.iter(|| {
                    one.install(|| {
                        black_box(DistanceField::new(Arc::clone(&md), resolution, 0.02).unwrap())
                    })
                });
            });
        }
        let field = DistanceField::new(Arc::clone(&md), 0.0025, 0.02).unwrap();
        eprintln!(
            "{name}: field {:?} {:?}, {} bytes",
            field.dims(),
            field.stats(),
            field.memory_bytes()
        );
        let points = near_points(&mesh, 10_000, 0.02);
        group.throughput(Throughput::Elements(points.len() as u64));
        group.bench_function("exact_closest_per_point", |b| {
            b.iter(|| {
                for p in &points {
                    black_box(md.closest(p));
                }
            });
        });
        group.bench_function("field_evaluate_per_point", |b| {
            b.iter(|| {
                for p in &points {
                    black_box(field.evaluate(p));
                }
            });
        });
        group.bench_function("exact_closest_within_1cm_per_point", |b| {
            b.iter(|| {
                for p in &points {
                    black_box(md.closest_within(p, 0.01));
                }
            });
        });
        group.finish();
    }
}

criterion_group!(benches, bench_signed_distance);
criterion_main!(benches);
