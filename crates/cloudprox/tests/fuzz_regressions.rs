//! The bugs the fuzzers found (`scripts/fuzz.sh`, `docs/robustness.md`), each
//! with its minimized input.

use cloudprox::cloud::MAX_COORDINATE;
use cloudprox::prelude::*;
use cloudprox::query::collide::QueryModel;

fn problem<T: std::fmt::Debug>(r: Result<T>) -> String {
    match r {
        Err(Error::InvalidInput(m)) => m,
        other => panic!("expected an invalid-input error, got {other:?}"),
    }
}

/// fuzz target `collide`: one coordinate of 1.4e155 (finite, so accepted)
/// made squared distances overflow, and with the `independent` aggregation
/// `P` came out NaN. Coordinates beyond `MAX_COORDINATE` are now rejected.
#[test]
fn huge_coordinate_is_rejected_not_nan() {
    let points = vec![
        Point3::new(6.935, 13.103, 0.019271),
        Point3::new(0.024435, 0.032635, 1.4175470658480749e155),
        Point3::new(0.009509, 9.765, 11.307),
        Point3::new(13.106, 14.648, 8.51),
    ];
    let m = problem(PointCloud::from_sigma(points.clone(), 0.017));
    assert!(m.contains("point 1") && m.contains("beyond"), "{m}");

    // The same query with the coordinate at the limit: a probability.
    let mut ok = points;
    ok[1].z = MAX_COORDINATE;
    let a = PointCloud::from_sigma(ok, 0.017).unwrap();
    let b =
        PointCloud::from_sigma(vec![Point3::new(0.01876, -0.000178, 0.020816)], 0.0239).unwrap();
    let pose_a = Pose::from_parts(
        nalgebra::Translation3::new(0.026727, 0.028269, 0.029811),
        nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
            0.0021148581629540277,
            6.037055643300019e-5,
            0.46778749593615226,
            0.8838384368062586,
        )),
    );
    for model in [QueryModel::Points, QueryModel::Elements] {
        let request = CollisionRequest {
            model,
            aggregation: Aggregation::Independent,
            decide_only: true,
            ..CollisionRequest::default()
        };
        let r = collide(&pose_a, &a, &Pose::identity(), &b, &request).unwrap();
        assert!(
            (0.0..=1.0).contains(&r.probability),
            "{model:?}: P = {}",
            r.probability
        );
    }
}

/// A standard deviation beyond `MAX_COORDINATE` squares to an infinite (or
/// overflowing) covariance: rejected like a coordinate.
#[test]
fn huge_sigma_is_rejected() {
    let points = vec![Point3::origin(), Point3::new(0.01, 0.0, 0.0)];
    for sigma in [1e200, 1e155, 2e9] {
        let m = problem(PointCloud::from_sigma(points.clone(), sigma));
        assert!(m.contains("covariance entry"), "{sigma}: {m}");
    }
    assert!(PointCloud::from_sigma(points, 1e9).is_ok());
}

/// A `Pose` built from parts can hold NaN or a translation that overflows the
/// points it moves: `collide` rejects it instead of returning NaN.
#[test]
fn non_finite_or_huge_pose_is_rejected() {
    let pts: Vec<Point3> = (0..20)
        .map(|i| Point3::new(f64::from(i) * 0.01, 0.0, 0.0))
        .collect();
    let a = PointCloud::from_sigma(pts.clone(), 0.001).unwrap();
    let b = PointCloud::from_sigma(pts, 0.001).unwrap();
    let nan_rotation = Pose::from_parts(
        nalgebra::Translation3::identity(),
        nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0)),
    );
    let far = Pose::translation(1e300, 0.0, 0.0);
    let nan_t = Pose::translation(0.0, f64::NAN, 0.0);
    let request = CollisionRequest::default();
    let id = Pose::identity();
    let m = problem(collide(&nan_rotation, &a, &id, &b, &request));
    assert!(m.contains("pose_a") && m.contains("rotation"), "{m}");
    let m = problem(collide(&id, &a, &far, &b, &request));
    assert!(m.contains("pose_b") && m.contains("translation"), "{m}");
    let m = problem(collide(&nan_t, &a, &id, &b, &request));
    assert!(m.contains("pose_a"), "{m}");
    assert!(collide(&Pose::translation(5.0, 0.0, 0.0), &a, &id, &b, &request).is_ok());
}

/// fuzz target `exact`: meshes with vertices near 1e153 and 1e300 made
/// parry's point-tetrahedron projection fail its `assert!(denom != 0.0)`
/// (a panic in release builds too) inside `exact_proximity`. Parts with a
/// vertex beyond `MAX_COORDINATE` are now rejected when the shape is built,
/// and `pose_from_matrix` rejects translations beyond it.
#[test]
fn exact_shapes_and_poses_reject_huge_coordinates() {
    let tetra = |far: f64| {
        Mesh::new(
            vec![
                Point3::new(14.127, 0.002, -4.2159820896619384e37),
                Point3::new(f64::MAX, 10.015, 0.022351),
                Point3::new(0.032631, -4.988467470189946e153, far),
                Point3::new(16.18, 0.028519, -2.1483862124025464e76),
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
        .unwrap()
    };
    for solid in [true, false] {
        let parts = [tetra(1.0)];
        let r = if solid {
            ExactShape::new(&parts)
        } else {
            ExactShape::surfaces(&parts)
        };
        let m = problem(r.map(|_| ()));
        assert!(m.contains("part 0: vertex 0 is beyond"), "{m}");
    }
    let mut m = cloudprox::math::Matrix4::identity();
    m[(0, 3)] = 1e300;
    let e = problem(cloudprox::cloud::pose_from_matrix(&m));
    assert!(e.contains("translation"), "{e}");
    m[(0, 3)] = MAX_COORDINATE;
    assert!(cloudprox::cloud::pose_from_matrix(&m).is_ok());
}
