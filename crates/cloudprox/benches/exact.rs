#![allow(missing_docs)]
//! The exact distance between two triangle meshes: `exact_proximity` (both
//! meshes' triangle hierarchies traversed together) against parry's own
//! mesh-vs-mesh `distance` on the same two meshes, in the same run. A small
//! object inside a scene whose box holds it (a floor, a ceiling and a sphere),
//! apart from every surface by centimetres, and beside the scene's box.
//!
//! `cargo bench -p cloudprox --bench exact`

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Translation3, UnitQuaternion};
use std::hint::black_box;

use cloudprox::prelude::*;
use cloudprox::query::exact::ExactPart;
use cloudprox::robot::{capsule_mesh, sphere_mesh};

/// A mesh of `n` x `n` x 2 triangles over a square of side `side` at height
/// `z` (a floor or a ceiling).
fn grid(n: usize, side: f64, z: f64) -> Mesh {
    let step = side / n as f64;
    let vertices: Vec<Point3> = (0..=n)
        .flat_map(|i| {
            (0..=n).map(move |j| {
                Point3::new(
                    i as f64 * step - side / 2.0,
                    j as f64 * step - side / 2.0,
                    z,
                )
            })
        })
        .collect();
    let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let faces: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| {
            (0..n).flat_map(move |j| {
                [
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ]
            })
        })
        .collect();
    Mesh::new(vertices, faces).unwrap()
}

fn bench_mesh_distance(c: &mut Criterion) {
    let object = Mesh::merged(&[
        sphere_mesh(0.1).unwrap(),
        capsule_mesh(0.03, 0.3)
            .unwrap()
            .transformed(&Pose::translation(0.15, 0.0, 0.0)),
    ])
    .unwrap();
    let room = Mesh::merged(&[
        grid(70, 2.0, 0.0),
        grid(70, 2.0, 1.0),
        sphere_mesh(0.3)
            .unwrap()
            .transformed(&Pose::translation(0.5, 0.4, 0.5)),
    ])
    .unwrap();
    let (a, b) = (
        ExactShape::surfaces(&[object]).unwrap(),
        ExactShape::surfaces(&[room]).unwrap(),
    );
    let (ExactPart::Mesh { mesh: ma, .. }, ExactPart::Mesh { mesh: mb, .. }) =
        (&a.parts()[0], &b.parts()[0])
    else {
        unreachable!("bare surfaces are meshes")
    };
    let tilt = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
    let cases = [
        // Between the floor and the ceiling, at least 6 cm from the sphere.
        ("inside_the_scene_box", Translation3::new(0.5, -0.2, 0.5)),
        // Beside the scene's box.
        ("beside_the_scene_box", Translation3::new(1.3, 0.0, 0.5)),
    ];
    let mut group = c.benchmark_group("mesh_distance");
    group.sample_size(10);
    for (name, t) in cases {
        let pose = Pose::from_parts(t, tilt);
        let id = Pose::identity();
        group.bench_function(format!("{name}/cloudprox"), |bch| {
            bch.iter(|| black_box(exact_proximity(&pose, &a, &id, &b).unwrap()));
        });
        group.bench_function(format!("{name}/parry"), |bch| {
            bch.iter(|| black_box(parry3d_f64::query::distance(&pose, ma, &id, mb).unwrap()));
        });
    }
    group.finish();
}

criterion_group!(benches, bench_mesh_distance);
criterion_main!(benches);
