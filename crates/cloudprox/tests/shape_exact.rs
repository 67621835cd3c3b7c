//! Meshes, their sampling and exact mesh-vs-mesh proximity, on cases with known
//! answers.

use crate::common;

use cloudprox::prelude::*;
use cloudprox::query::exact::{exact_proximity_many, ExactPart};
use common::{at, cube, shape};
use nalgebra::{Translation3, UnitQuaternion};

#[test]
fn primitives_have_their_analytic_area_and_volume() {
    let b = Mesh::cuboid(0.1, 0.2, 0.3).unwrap();
    assert!((b.area() - 8.0 * (0.02 + 0.03 + 0.06)).abs() < 1e-12);
    assert!((b.volume() - 8.0 * 0.006).abs() < 1e-12);
    assert!(b.is_closed() && b.is_convex(1e-12));
    let n = 64;
    let c = Mesh::cylinder(0.1, 0.5, n).unwrap();
    let side = 2.0 * 0.1 * (std::f64::consts::PI / n as f64).sin() * n as f64; // prism perimeter
    let cap = 0.5 * n as f64 * 0.01 * (2.0 * std::f64::consts::PI / n as f64).sin();
    assert!((c.area() - (side * 1.0 + 2.0 * cap)).abs() < 1e-12);
    assert!((c.volume() - cap * 1.0).abs() < 1e-12);
    assert!(c.is_closed() && c.is_convex(1e-12));
    // Two cubes side by side, merged: closed, not convex.
    let two = Mesh::merged(&[cube(0.1), cube(0.1).transformed(&at(0.3, 0.0, 0.0))]).unwrap();
    assert!(two.is_closed() && !two.is_convex(1e-9));
    // An open mesh (a cube without its last face).
    let open = Mesh::new(
        cube(0.1).vertices().to_vec(),
        cube(0.1).faces()[..11].to_vec(),
    )
    .unwrap();
    assert!(!open.is_closed());
}

#[test]
fn bad_meshes_are_rejected_with_the_problem_named() {
    let v = vec![
        Point3::origin(),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let msg = |r: Result<Mesh>| r.unwrap_err().to_string();
    assert!(msg(Mesh::new(vec![], vec![[0, 1, 2]])).contains("no vertices"));
    assert!(msg(Mesh::new(v.clone(), vec![])).contains("no faces"));
    assert!(msg(Mesh::new(v.clone(), vec![[0, 1, 3]])).contains("refers to vertex 3"));
    assert!(msg(Mesh::new(v.clone(), vec![[0, 1, 1]])).contains("repeats a vertex"));
    let mut bad = v.clone();
    bad[1].y = f64::NAN;
    assert!(msg(Mesh::new(bad, vec![[0, 1, 2]])).contains("vertex 1 has a non-finite"));
    assert!(msg(Mesh::cuboid(0.1, -1.0, 0.1)).contains("half extent y"));
    assert!(msg(Mesh::cylinder(0.1, 0.1, 2)).contains("at least 3 segments"));
    let flat = Mesh::new(
        vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert!(flat
        .sample_surface(10, 0)
        .unwrap_err()
        .to_string()
        .contains("area 0"));
    assert!(cube(0.1).sample_surface_density(-1.0, 0).is_err());
    assert!(ExactShape::new(&[]).is_err());
}

#[test]
fn sampling_is_on_the_surface_area_weighted_and_seeded() {
    let b = Mesh::cuboid(0.1, 0.2, 0.4).unwrap();
    let s = b.sample_surface(60_000, 7).unwrap();
    assert_eq!(s.points.len(), 60_000);
    let mut per_axis = [0usize; 3];
    for (p, n) in s.points.iter().zip(&s.normals) {
        let on_face = [
            (p.x.abs() - 0.1).abs(),
            (p.y.abs() - 0.2).abs(),
            (p.z.abs() - 0.4).abs(),
        ];
        let axis = (0..3)
            .min_by(|&i, &j| on_face[i].total_cmp(&on_face[j]))
            .unwrap();
        assert!(on_face[axis] < 1e-12, "{p:?} is not on the box");
        assert!(p.x.abs() <= 0.1 + 1e-12 && p.y.abs() <= 0.2 + 1e-12 && p.z.abs() <= 0.4 + 1e-12);
        // The face normal is the outward axis.
        assert!((n[axis].abs() - 1.0).abs() < 1e-12 && n[axis] * p[axis] > 0.0);
        per_axis[axis] += 1;
    }
    // Face pairs normal to x, y, z have areas 2*(0.4*0.8), 2*(0.2*0.8), 2*(0.2*0.4).
    let areas = [0.32, 0.16, 0.08];
    let total: f64 = areas.iter().sum();
    for k in 0..3 {
        let expected = areas[k] / total;
        let got = per_axis[k] as f64 / 60_000.0;
        let sd = (expected * (1.0 - expected) / 60_000.0).sqrt();
        assert!(
            (got - expected).abs() < 5.0 * sd,
            "axis {k}: {got} vs {expected}"
        );
    }
    assert_eq!(
        b.sample_surface(100, 7).unwrap().points,
        s.points[..100].to_vec()
    );
    assert_ne!(
        b.sample_surface(100, 8).unwrap().points,
        s.points[..100].to_vec()
    );
    let d = b.sample_surface_density(1000.0, 1).unwrap();
    assert_eq!(d.points.len(), (1000.0 * b.area()).round() as usize);
}

#[test]
fn box_pairs_have_their_closed_form_distance_and_depth() {
    let a = shape(&[cube(0.1)]);
    let b = shape(&[Mesh::cuboid(0.2, 0.05, 0.1).unwrap()]);
    // Face to face along x: gap = 0.5 - 0.1 - 0.2.
    let r = exact_proximity(&at(0.0, 0.0, 0.0), &a, &at(0.5, 0.0, 0.0), &b).unwrap();
    assert!(!r.intersecting && (r.distance - 0.2).abs() < 1e-9, "{r:?}");
    assert!((r.signed_distance() - 0.2).abs() < 1e-9);
    // Edge to edge: offsets beyond contact of 0.2 in x and 0.1 in y.
    let r = exact_proximity(&at(0.0, 0.0, 0.0), &a, &at(0.5, 0.25, 0.0), &b).unwrap();
    assert!(
        (r.distance - (0.2f64.powi(2) + 0.1f64.powi(2)).sqrt()).abs() < 1e-9,
        "{r:?}"
    );
    // Overlapping by 0.03 along x (the shallowest axis).
    let r = exact_proximity(&at(0.0, 0.0, 0.0), &a, &at(0.27, 0.0, 0.0), &b).unwrap();
    assert!(r.intersecting && r.distance == 0.0);
    assert!((r.signed_distance() + 0.03).abs() < 1e-7, "{r:?}");
}

#[test]
fn exact_answers_are_invariant_under_rigid_motion_and_swapping() {
    let a = shape(&[
        cube(0.1),
        Mesh::cylinder(0.05, 0.2, 24)
            .unwrap()
            .transformed(&at(0.0, 0.0, 0.3)),
    ]);
    let b = shape(&[
        Mesh::cuboid(0.3, 0.3, 0.02).unwrap(),
        cube(0.05).transformed(&at(0.2, 0.2, 0.1)),
    ]);
    let motion = Pose::from_parts(
        Translation3::new(0.3, -1.0, 2.0),
        UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
    );
    let tilt = UnitQuaternion::from_euler_angles(0.2, 0.1, 0.4);
    for z in [-0.3, -0.05, 0.0, 0.01, 0.05, 0.2] {
        let pa = Pose::from_parts(Translation3::new(0.05, -0.02, 0.15 + z), tilt);
        let pb = Pose::identity();
        let r = exact_proximity(&pa, &a, &pb, &b).unwrap();
        let moved = exact_proximity(&(motion * pa), &a, &(motion * pb), &b).unwrap();
        let swapped = exact_proximity(&pb, &b, &pa, &a).unwrap();
        for o in [moved, swapped] {
            assert_eq!(o.intersecting, r.intersecting, "z={z}");
            assert!(
                (o.signed_distance() - r.signed_distance()).abs() < 1e-6,
                "z={z}: {o:?} vs {r:?}"
            );
        }
    }
}

#[test]
fn non_convex_parts_use_the_triangle_mesh_and_detect_containment() {
    let two = Mesh::merged(&[cube(0.1), cube(0.1).transformed(&at(0.5, 0.0, 0.0))]).unwrap();
    let as_mesh = shape(&[two]);
    assert!(matches!(
        as_mesh.parts()[0],
        ExactPart::Mesh { closed: true, .. }
    ));
    let as_parts = shape(&[cube(0.1), cube(0.1).transformed(&at(0.5, 0.0, 0.0))]);
    let probe = shape(&[cube(0.02)]);
    for (x, y) in [(0.25, 0.0), (0.25, 0.3), (0.0, 0.2), (0.6, -0.2)] {
        let m = exact_proximity(&Pose::identity(), &as_mesh, &at(x, y, 0.0), &probe).unwrap();
        let p = exact_proximity(&Pose::identity(), &as_parts, &at(x, y, 0.0), &probe).unwrap();
        assert!(
            !m.intersecting && (m.distance - p.distance).abs() < 1e-9,
            "{m:?} {p:?}"
        );
    }
    // The probe entirely inside one cube: no surface crosses, yet it intersects.
    let inside = exact_proximity(&Pose::identity(), &as_mesh, &at(0.5, 0.0, 0.0), &probe).unwrap();
    assert!(inside.intersecting && inside.penetration_depth.is_none());
    assert!(inside.signed_distance().is_nan());
    let inside = exact_proximity(&Pose::identity(), &as_parts, &at(0.5, 0.0, 0.0), &probe).unwrap();
    assert!(
        inside.intersecting && (inside.signed_distance() + 0.12).abs() < 1e-6,
        "{inside:?}"
    );
}

#[test]
fn surfaces_intersect_only_where_triangles_cross() {
    let big = ExactShape::surfaces(&[cube(0.1)]).unwrap();
    let probe = ExactShape::surfaces(&[cube(0.02)]).unwrap();
    assert!(matches!(
        big.parts()[0],
        ExactPart::Mesh { closed: false, .. }
    ));
    // Inside the big cube: a solid would contain the probe; as surfaces the
    // probe's face at x = 0.04 is 0.06 from the cube's at x = 0.1.
    let inside = exact_proximity(&Pose::identity(), &big, &at(0.02, 0.0, 0.0), &probe).unwrap();
    assert!(!inside.intersecting, "{inside:?}");
    assert!((inside.distance - 0.06).abs() < 1e-9, "{inside:?}");
    // Across a face: the triangles cross.
    let across = exact_proximity(&Pose::identity(), &big, &at(0.1, 0.0, 0.0), &probe).unwrap();
    assert!(across.intersecting && across.penetration_depth.is_none());
    // The same cubes as solids: contained, so intersecting.
    let solid = exact_proximity(
        &Pose::identity(),
        &shape(&[cube(0.1)]),
        &at(0.02, 0.0, 0.0),
        &shape(&[cube(0.02)]),
    )
    .unwrap();
    assert!(solid.intersecting);
}

#[test]
fn many_poses_equal_a_loop() {
    let a = shape(&[cube(0.1)]);
    let b = shape(&[Mesh::cylinder(0.2, 0.1, 32).unwrap()]);
    let poses: Vec<Pose> = (0..40)
        .map(|i| at(0.0, 0.0, 0.1 + 0.01 * i as f64))
        .collect();
    let many = exact_proximity_many(&poses, &a, &Pose::identity(), &b).unwrap();
    for (p, r) in poses.iter().zip(&many) {
        assert_eq!(*r, exact_proximity(p, &a, &Pose::identity(), &b).unwrap());
    }
    // Cube bottom at z - 0.1 over the cylinder top at 0.1: gap z - 0.2.
    for (i, r) in many.iter().enumerate() {
        let z = 0.1 + 0.01 * i as f64;
        assert!(
            (r.signed_distance() - (z - 0.2)).abs() < 1e-7,
            "z={z}: {r:?}"
        );
    }
}

#[test]
fn the_intersection_only_query_agrees_with_the_full_one() {
    use cloudprox::query::exact::{exact_intersects, exact_intersects_many};
    let two = Mesh::merged(&[cube(0.1), cube(0.1).transformed(&at(0.5, 0.0, 0.0))]).unwrap();
    let solids = shape(&[two.clone(), Mesh::cylinder(0.05, 0.3, 16).unwrap()]);
    let surfaces = ExactShape::surfaces(&[two]).unwrap();
    let probe = shape(&[cube(0.02)]);
    // Probe along x through both cubes (inside, across faces, in the gap).
    let poses: Vec<Pose> = (0..=70)
        .map(|i| at(-0.1 + 0.01 * f64::from(i), 0.0, 0.0))
        .collect();
    for target in [&solids, &surfaces] {
        let fast = exact_intersects_many(&poses, &probe, &Pose::identity(), target).unwrap();
        for (p, hit) in poses.iter().zip(&fast) {
            let full = exact_proximity(p, &probe, &Pose::identity(), target).unwrap();
            assert_eq!(*hit, full.intersecting, "{p:?}");
            assert_eq!(
                *hit,
                exact_intersects(p, &probe, &Pose::identity(), target).unwrap()
            );
        }
    }
    // Inside the first cube: the solid holds the probe, the surface does not.
    assert!(exact_intersects(&at(0.0, 0.0, 0.0), &probe, &Pose::identity(), &solids).unwrap());
    assert!(!exact_intersects(&at(0.0, 0.0, 0.0), &probe, &Pose::identity(), &surfaces).unwrap());
    // Across the face at x = 0.1.
    assert!(exact_intersects(&at(0.1, 0.0, 0.0), &probe, &Pose::identity(), &surfaces).unwrap());
}

#[test]
fn bad_poses_are_refused_with_the_pose_named() {
    use cloudprox::query::exact::{exact_intersects, exact_intersects_many};
    let a = shape(&[cube(0.1)]);
    let b = shape(&[cube(0.1)]);
    let id = Pose::identity();
    let nan = Pose::translation(f64::NAN, 0.0, 0.0);
    let far = Pose::translation(0.0, 1e12, 0.0);
    let scaled = Pose::from_parts(
        Translation3::identity(),
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(2.0, 0.0, 0.0, 0.0)),
    );
    let message = |e: Error| match e {
        Error::InvalidInput(m) => m,
        other => panic!("not an invalid input: {other}"),
    };
    let m = message(exact_proximity(&nan, &a, &id, &b).unwrap_err());
    assert!(m.contains("pose_a") && m.contains("translation"), "{m}");
    let m = message(exact_proximity(&id, &a, &far, &b).unwrap_err());
    assert!(m.contains("pose_b") && m.contains("translation"), "{m}");
    let m = message(exact_intersects(&scaled, &a, &id, &b).unwrap_err());
    assert!(m.contains("pose_a") && m.contains("rotation"), "{m}");
    let m = message(exact_intersects(&id, &a, &nan, &b).unwrap_err());
    assert!(m.contains("pose_b"), "{m}");
    // The many forms name the first bad pose by its index.
    let poses = [id, at(0.5, 0.0, 0.0), nan, far];
    let m = message(exact_proximity_many(&poses, &a, &id, &b).unwrap_err());
    assert!(m.contains("poses_a[2]"), "{m}");
    let m = message(exact_intersects_many(&poses, &a, &id, &b).unwrap_err());
    assert!(m.contains("poses_a[2]"), "{m}");
    let m = message(exact_intersects_many(&poses[..2], &a, &scaled, &b).unwrap_err());
    assert!(m.contains("pose_b") && m.contains("rotation"), "{m}");
    // Good poses still answer.
    assert!(exact_intersects_many(&poses[..2], &a, &id, &b).unwrap() == [true, false]);
}

/// Two bare surfaces (meshes of thousands of triangles): the distance of
/// `exact_proximity` (both meshes' hierarchies traversed at once) equals
/// parry's own mesh-vs-mesh distance, for a small mesh inside a large one's
/// box (where parry prunes nothing) and beside it, under random rigid poses.
#[test]
fn mesh_mesh_distance_agrees_with_parry() {
    use cloudprox::robot::{capsule_mesh, sphere_mesh};
    let small = Mesh::merged(&[
        sphere_mesh(0.05).unwrap(),
        capsule_mesh(0.02, 0.1)
            .unwrap()
            .transformed(&at(0.06, 0.0, 0.0)),
    ])
    .unwrap();
    let room = Mesh::merged(&[
        Mesh::cuboid(1.0, 1.0, 1.0).unwrap(),
        sphere_mesh(0.2).unwrap().transformed(&at(0.4, 0.1, 0.0)),
        capsule_mesh(0.1, 0.5)
            .unwrap()
            .transformed(&at(-0.5, -0.3, 0.2)),
    ])
    .unwrap();
    let (a, b) = (
        ExactShape::surfaces(&[small]).unwrap(),
        ExactShape::surfaces(&[room]).unwrap(),
    );
    let (ExactPart::Mesh { mesh: ma, .. }, ExactPart::Mesh { mesh: mb, .. }) =
        (&a.parts()[0], &b.parts()[0])
    else {
        panic!("surfaces are meshes");
    };
    assert!(ma.num_triangles() > 1000 && mb.num_triangles() > 1000);
    let mut state = 3_u64;
    let mut unit = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let pose_b = Pose::from_parts(
        Translation3::new(0.3, -0.2, 0.1),
        UnitQuaternion::from_euler_angles(0.3, -0.2, 1.0),
    );
    let (mut free, mut hit) = (0, 0);
    for k in 0..60 {
        let mut v = Vector3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5);
        let t = if k % 2 == 0 {
            // Anywhere in the room's box.
            Translation3::from(1.8 * v)
        } else {
            // About the room's sphere's surface: crossing it or near.
            v = v.normalize() * (0.2 + 0.1 * (unit() - 0.5));
            Translation3::from(Vector3::new(0.4, 0.1, 0.0) + v)
        };
        let q = UnitQuaternion::from_euler_angles(6.0 * unit(), 6.0 * unit(), 6.0 * unit());
        let pose_a = pose_b * Pose::from_parts(t, q);
        let r = exact_proximity(&pose_a, &a, &pose_b, &b).unwrap();
        let want_hit = parry3d_f64::query::intersection_test(&pose_a, ma, &pose_b, mb).unwrap();
        assert_eq!(r.intersecting, want_hit);
        if want_hit {
            hit += 1;
            continue;
        }
        free += 1;
        let want = parry3d_f64::query::distance(&pose_a, ma, &pose_b, mb).unwrap();
        assert!(
            (r.distance - want).abs() <= 1e-9,
            "distance {} vs parry's {want}",
            r.distance
        );
    }
    assert!(free >= 20 && hit >= 5, "{free} free, {hit} intersecting");
}
