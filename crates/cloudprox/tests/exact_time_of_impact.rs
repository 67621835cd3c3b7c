//! `exact_time_of_impact`: travel along a direction until a target signed
//! distance, on cases with closed-form answers, and its refusals of bad input.

use crate::common;

use cloudprox::prelude::*;
use cloudprox::query::exact::{exact_time_of_impact, exact_time_of_impact_many};
use common::{at, cube, shape};
use nalgebra::{Translation3, UnitQuaternion};

/// A 0.1 m half-side cube at the origin and a wall (0.1 m half-thick, 10 m
/// wide) centred at x = 1: faces 0.8 apart along x.
fn cube_and_wall() -> (ExactShape, ExactShape, Pose) {
    let wall = Mesh::cuboid(0.1, 5.0, 5.0).unwrap();
    (shape(&[cube(0.1)]), shape(&[wall]), at(1.0, 0.0, 0.0))
}

fn toi(
    pa: &Pose,
    a: &ExactShape,
    d: Vector3,
    pb: &Pose,
    b: &ExactShape,
    target: f64,
) -> Option<f64> {
    exact_time_of_impact(pa, a, &d, pb, b, target, 10.0).unwrap()
}

#[test]
fn a_cube_meets_a_wall_at_the_gap_over_the_approach_cosine() {
    let (a, b, pb) = cube_and_wall();
    let o = Pose::identity();
    // Head-on: contact after 0.8, a 0.1 gap after 0.7; the length of the
    // direction does not matter.
    let t = toi(&o, &a, Vector3::new(3.0, 0.0, 0.0), &pb, &b, 0.0).unwrap();
    assert!((t - 0.8).abs() < 1e-9, "{t}");
    // A gap target is cast with a rounded shape, which GJK resolves to a
    // relative 1e-7 or so.
    let t = toi(&o, &a, Vector3::x(), &pb, &b, 0.1).unwrap();
    assert!((t - 0.7).abs() < 1e-7, "{t}");
    // At 53 degrees (cosine 0.6 with the wall's normal): 0.8 / 0.6.
    let d = Vector3::new(0.6, 0.8, 0.0);
    let t = toi(&o, &a, d, &pb, &b, 0.0).unwrap();
    assert!((t - 0.8 / 0.6).abs() < 1e-9, "{t}");
    let t = toi(&o, &a, d, &pb, &b, 0.25).unwrap();
    assert!((t - 0.55 / 0.6).abs() < 1e-7, "{t}");
    // The pose reached is at the target, as exact_proximity measures it.
    let p = Pose::translation(0.6 * t, 0.8 * t, 0.0);
    assert!((exact_proximity(&p, &a, &pb, &b).unwrap().distance - 0.25).abs() < 1e-7);
    // A rotated start: the cube turned 45 degrees about z reaches 0.1 * sqrt(2)
    // further along x.
    let turned = Pose::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_4),
    );
    let t = toi(&turned, &a, Vector3::x(), &pb, &b, 0.0).unwrap();
    assert!((t - (0.9 - 0.1 * 2f64.sqrt())).abs() < 1e-9, "{t}");
}

#[test]
fn a_negative_target_is_a_penetration_depth() {
    let (a, b, pb) = cube_and_wall();
    let o = Pose::identity();
    // Head-on, the EPA depth is the travel past contact.
    let t = toi(&o, &a, Vector3::x(), &pb, &b, -0.05).unwrap();
    assert!((t - 0.85).abs() < 1e-8, "{t}");
    // At cosine 0.6 the depth grows at 0.6 per metre: the search past contact
    // (safe steps and secant brackets) pins it down.
    let d = Vector3::new(0.6, 0.8, 0.0);
    let t = toi(&o, &a, d, &pb, &b, -0.05).unwrap();
    assert!((t - 0.85 / 0.6).abs() < 1e-8, "{t}");
    let p = Pose::translation(0.6 * t, 0.8 * t, 0.0);
    let s = exact_proximity(&p, &a, &pb, &b).unwrap().signed_distance();
    assert!((s + 0.05).abs() < 1e-8, "{s}");
    // Already 0.02 deep, a 0.05 target is 0.03 further.
    let t = toi(&at(0.82, 0.0, 0.0), &a, Vector3::x(), &pb, &b, -0.05).unwrap();
    assert!((t - 0.03).abs() < 1e-8, "{t}");
}

#[test]
fn starts_at_or_within_the_target_travel_zero() {
    let (a, b, pb) = cube_and_wall();
    // Intersecting, any direction (even away).
    for d in [Vector3::x(), -Vector3::x(), Vector3::y()] {
        assert_eq!(toi(&at(0.85, 0.0, 0.0), &a, d, &pb, &b, 0.0), Some(0.0));
    }
    // 0.05 apart with a 0.1 target; 0.05 deep with a 0.02 depth target.
    assert_eq!(
        toi(&at(0.75, 0.0, 0.0), &a, -Vector3::x(), &pb, &b, 0.1),
        Some(0.0)
    );
    assert_eq!(
        toi(&at(0.85, 0.0, 0.0), &a, -Vector3::x(), &pb, &b, -0.02),
        Some(0.0)
    );
    // Containment without touching surfaces: a small cube inside one of two
    // cubes merged into one closed, non-convex solid.
    let dumbbell = Mesh::merged(&[cube(0.2), cube(0.2).transformed(&at(1.0, 0.0, 0.0))]).unwrap();
    let solid = shape(&[dumbbell]);
    let small = shape(&[cube(0.05)]);
    let o = Pose::identity();
    assert_eq!(toi(&o, &small, Vector3::z(), &o, &solid, 0.0), Some(0.0));
}

#[test]
fn shapes_that_never_meet_give_none() {
    let (a, b, pb) = cube_and_wall();
    let o = Pose::identity();
    // Moving away, or parallel to the wall.
    assert_eq!(toi(&o, &a, -Vector3::x(), &pb, &b, 0.0), None);
    assert_eq!(toi(&o, &a, Vector3::z(), &pb, &b, 0.0), None);
    assert_eq!(toi(&o, &a, Vector3::z(), &pb, &b, -0.01), None);
    // The wall is beyond reach.
    let short = exact_time_of_impact(&o, &a, &Vector3::x(), &pb, &b, 0.0, 0.5).unwrap();
    assert_eq!(short, None);
    // A penetration deeper than the wall's thickness never comes: the depth
    // peaks at 0.2 (the cube's side) as it passes through.
    assert_eq!(toi(&o, &a, Vector3::x(), &pb, &b, -0.5), None);
}

#[test]
fn non_convex_and_open_parts_are_cast_as_triangle_meshes() {
    // Two cubes, one lower (one closed, non-convex part), moving down onto an open square.
    let l_shape = Mesh::merged(&[cube(0.1), cube(0.1).transformed(&at(0.3, 0.0, -0.2))]).unwrap();
    let floor = Mesh::new(
        vec![
            Point3::new(-1.0, -1.0, 0.0),
            Point3::new(1.0, -1.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(-1.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let a = shape(&[l_shape]);
    assert!(matches!(
        a.parts()[0],
        cloudprox::query::exact::ExactPart::Mesh { .. }
    ));
    let floor = ExactShape::surfaces(&[floor]).unwrap();
    // The L's lowest face is at z = -0.3: 0.7 above the floor from z = 1.
    let start = at(0.0, 0.0, 1.0);
    let o = Pose::identity();
    let t = toi(&start, &a, -Vector3::z(), &o, &floor, 0.0).unwrap();
    assert!((t - 0.7).abs() < 1e-9, "{t}");
    let t = toi(&start, &a, -Vector3::z(), &o, &floor, 0.05).unwrap();
    assert!((t - 0.65).abs() < 1e-7, "{t}");
    // Depth is unknown for these parts: a negative target is refused once
    // they intersect.
    let err = exact_time_of_impact(&start, &a, &-Vector3::z(), &o, &floor, -0.01, 10.0)
        .unwrap_err()
        .to_string();
    assert!(err.contains("penetration depths"), "{err}");
}

#[test]
fn many_starts_equal_a_loop_and_bad_input_is_refused() {
    let (a, b, pb) = cube_and_wall();
    let poses: Vec<Pose> = (0..8).map(|i| at(0.0, 0.1 * i as f64, 0.0)).collect();
    let dirs: Vec<Vector3> = (0..8)
        .map(|i| Vector3::new(1.0, 0.2 * i as f64 - 0.7, 0.1))
        .collect();
    let targets: Vec<f64> = (0..8).map(|i| 0.05 * i as f64 - 0.1).collect();
    let many = exact_time_of_impact_many(&poses, &a, &dirs, &pb, &b, &targets, 10.0).unwrap();
    for i in 0..8 {
        let one = exact_time_of_impact(&poses[i], &a, &dirs[i], &pb, &b, targets[i], 10.0).unwrap();
        assert_eq!(many[i], one);
    }
    let bad = |p: &Pose, d: Vector3, target: f64, reach: f64| {
        exact_time_of_impact(p, &a, &d, &pb, &b, target, reach)
            .unwrap_err()
            .to_string()
    };
    let o = Pose::identity();
    assert!(bad(&o, Vector3::zeros(), 0.0, 1.0).contains("direction"));
    assert!(bad(&o, Vector3::new(f64::NAN, 0.0, 0.0), 0.0, 1.0).contains("direction"));
    assert!(bad(&o, Vector3::new(f64::INFINITY, 0.0, 0.0), 0.0, 1.0).contains("direction"));
    assert!(bad(&o, Vector3::x(), f64::NAN, 1.0).contains("target"));
    assert!(bad(&o, Vector3::x(), f64::INFINITY, 1.0).contains("target"));
    assert!(bad(&o, Vector3::x(), 0.0, -1.0).contains("max_travel"));
    assert!(bad(&o, Vector3::x(), 0.0, f64::NAN).contains("max_travel"));
    assert!(bad(&at(f64::NAN, 0.0, 0.0), Vector3::x(), 0.0, 1.0).contains("pose_a"));
    assert!(bad(&at(1e300, 0.0, 0.0), Vector3::x(), 0.0, 1.0).contains("pose_a"));
    let err =
        exact_time_of_impact_many(&poses, &a, &dirs[..3], &pb, &b, &targets, 1.0).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Shape {
                expected: 8,
                got: 3,
                ..
            }
        ),
        "{err}"
    );
    let err =
        exact_time_of_impact_many(&poses, &a, &dirs, &pb, &b, &targets[..1], 1.0).unwrap_err();
    assert!(err.to_string().contains("targets"), "{err}");
}

#[test]
fn a_large_face_meets_a_small_mesh_inside_it() {
    // A 2 m square (two triangles, an open surface) lowered onto a cube seen
    // as a surface: the first contact is deep inside one triangle, far from
    // every corner, and the cube is not the mesh with fewer triangles.
    let square = Mesh::new(
        vec![
            Point3::new(-1.0, -1.0, 0.0),
            Point3::new(1.0, -1.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(-1.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let plate = ExactShape::surfaces(&[square]).unwrap();
    let block = ExactShape::surfaces(&[cube(0.05)]).unwrap();
    let o = Pose::identity();
    let start = at(0.3, 0.2, 1.0);
    for (target, want) in [(0.0, 0.95), (0.02, 0.93), (0.3, 0.65)] {
        let t = toi(&start, &plate, -Vector3::z(), &o, &block, target).unwrap();
        assert!((t - want).abs() < 1e-7, "target {target}: {t}");
        // Swapped: the cube moves up into the square.
        let t = toi(&o, &block, Vector3::z(), &start, &plate, target).unwrap();
        assert!((t - want).abs() < 1e-7, "target {target}, swapped: {t}");
    }
    // Already within 1 m of it, with a corner 1.3 m away.
    assert_eq!(
        toi(&start, &plate, -Vector3::z(), &o, &block, 1.0),
        Some(0.0)
    );
}
