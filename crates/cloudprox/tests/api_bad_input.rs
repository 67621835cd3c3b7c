//! Every kind of bad input gets an error that names the problem; nothing panics.

use cloudprox::cloud::pose_from_matrix;
use cloudprox::math::Matrix4;
use cloudprox::prelude::*;
use cloudprox::uncertainty::NoiseModel;

fn pts(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| Point3::new(i as f64 * 0.01, 0.0, 0.0))
        .collect()
}

fn msg<T: std::fmt::Debug>(r: Result<T>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn bad_points() {
    assert!(msg(PointCloud::from_sigma(vec![], 0.01)).contains("empty"));
    let mut p = pts(5);
    p[3].y = f64::NAN;
    assert!(msg(PointCloud::from_sigma(p.clone(), 0.01)).contains("point 3"));
    p[3].y = f64::INFINITY;
    assert!(msg(PointCloud::from_sigma(p, 0.01)).contains("NaN or infinite"));
}

#[test]
fn bad_noise() {
    assert!(msg(PointCloud::from_sigma(pts(5), -0.1)).contains("sigma"));
    assert!(msg(PointCloud::from_sigma(pts(5), f64::NAN)).contains("sigma"));
    assert!(msg(PointCloud::from_sigmas(pts(5), vec![0.1; 4])).contains("expected 5, got 4"));
    assert!(msg(PointCloud::from_sigmas(pts(3), vec![0.1, -1.0, 0.1])).contains("point 1"));
    let mut covs = vec![Matrix3::identity() * 1e-4; 4];
    covs[2] = Matrix3::from_diagonal(&Vector3::new(1e-4, -1e-4, 1e-4));
    assert!(
        msg(PointCloud::from_covariances(pts(4), covs.clone())).contains("positive semi-definite")
    );
    covs[2] = Matrix3::new(1e-4, 5e-5, 0.0, 0.0, 1e-4, 0.0, 0.0, 0.0, 1e-4);
    assert!(msg(PointCloud::from_covariances(pts(4), covs.clone())).contains("symmetric"));
    covs[2][(1, 1)] = f64::INFINITY;
    assert!(msg(PointCloud::new(pts(4), &NoiseModel::Full(covs))).contains("point 2"));
}

#[test]
fn bad_requests() {
    let request = |change: fn(&mut CollisionRequest)| {
        let mut r = CollisionRequest::default();
        change(&mut r);
        msg(r.validate())
    };
    let e = request(|r| {
        r.thresholds = Thresholds {
            collision: 0.3,
            free: 0.6,
        }
    });
    assert!(
        e.contains("threshold_free") && e.contains("threshold_collision"),
        "{e}"
    );
    assert!(request(|r| r.thresholds.free = 0.6).contains("threshold"));
    assert!(request(|r| r.prune_epsilon = -1.0).contains("prune_epsilon"));
    assert!(request(|r| r.prune_epsilon = f64::NAN).contains("prune_epsilon"));
    assert!(request(|r| r.region_max_points = 2).contains("region_max_points"));
    assert!(request(|r| r.near_context = 0.1).contains("near_context"));
    let settings = |change: fn(&mut ClassifySettings)| {
        let mut s = ClassifySettings::default();
        change(&mut s);
        msg(s.validate())
    };
    assert!(settings(|s| s.slack_weight = 0.0).contains("slack_weight"));
    assert!(settings(|s| s.robust_eta = 1.0).contains("robust_eta"));
    assert!(settings(|s| s.solver_tol = 0.0).contains("solver_tol"));
    assert!(settings(|s| s.solver_max_iter = 0).contains("solver_max_iter"));
    // A request assembled by hand is validated by the query too.
    let mut req = CollisionRequest::default();
    req.thresholds.free = 0.7;
    let a = PointCloud::from_sigma(pts(5), 0.01).unwrap();
    assert!(msg(collide(&Pose::identity(), &a, &Pose::identity(), &a, &req)).contains("threshold"));
    let id = Pose::identity();
    for many in [collide_many, collide_along] {
        assert!(msg(many(&[id], &a, &id, &a, &req)).contains("threshold"));
    }
    // A motion's pose that is not finite is named by its index, before any
    // query runs.
    let mut far = Pose::translation(1.0, 0.0, 0.0);
    far.translation.vector.x = f64::NAN;
    let motion = [Pose::identity(), Pose::identity(), far];
    let e = msg(collide_along(
        &motion,
        &a,
        &id,
        &a,
        &CollisionRequest::default(),
    ));
    assert!(e.contains("poses_a[2]") && e.contains("not finite"), "{e}");
    // So is every other entry point that takes a request or settings.
    let cube = Mesh::cuboid(0.1, 0.1, 0.1).unwrap();
    let sampling = MeshSampling::default();
    let e = msg(collide_mesh_cloud(&id, &cube, &id, &a, &req, &sampling));
    assert!(e.contains("threshold"), "{e}");
    for spacing in [0.0, -1.0, f64::NAN] {
        let bad = MeshSampling {
            spacing: Some(spacing),
            ..sampling
        };
        let e = msg(collide_mesh_cloud(
            &id,
            &cube,
            &id,
            &a,
            &CollisionRequest::default(),
            &bad,
        ));
        assert!(e.contains("spacing"), "{e}");
    }
    let bad = ClassifySettings {
        robust_eta: 0.2,
        ..ClassifySettings::default()
    };
    let labels = [1.0, 1.0, -1.0, -1.0, -1.0];
    let e = msg(cloudprox::classify::train(
        a.points(),
        a.covariances(),
        &labels,
        &bad,
    ));
    assert!(e.contains("robust_eta"), "{e}");
}

#[test]
fn bad_poses() {
    let mut m = Matrix4::identity();
    m[(0, 0)] = 2.0;
    assert!(msg(pose_from_matrix(&m)).contains("rotation"));
    let mut m = Matrix4::identity();
    m[(1, 3)] = f64::NAN;
    assert!(msg(pose_from_matrix(&m)).contains("NaN"));
}

#[test]
fn degenerate_but_valid_inputs_do_not_panic() {
    // Identical points in both clouds, no noise at all: a collision, not a crash.
    let same = vec![Point3::new(0.1, 0.2, 0.3); 40];
    let a = PointCloud::from_sigma(same.clone(), 0.0).unwrap();
    let b = PointCloud::from_sigma(same, 0.0).unwrap();
    let r = collide(
        &Pose::identity(),
        &a,
        &Pose::identity(),
        &b,
        &CollisionRequest::default(),
    )
    .unwrap();
    assert_eq!(r.state, CollisionState::Collision);
    // One point each, far apart.
    let a = PointCloud::from_sigma(vec![Point3::origin()], 0.001).unwrap();
    let b = PointCloud::from_sigma(vec![Point3::new(1.0, 0.0, 0.0)], 0.001).unwrap();
    let r = collide(
        &Pose::identity(),
        &a,
        &Pose::identity(),
        &b,
        &CollisionRequest::default(),
    )
    .unwrap();
    assert_eq!(r.state, CollisionState::Free);
    // One point each, touching: one point per class still trains.
    let b = PointCloud::from_sigma(vec![Point3::new(0.001, 0.0, 0.0)], 0.001).unwrap();
    let r = collide(
        &Pose::identity(),
        &a,
        &Pose::identity(),
        &b,
        &CollisionRequest::default(),
    )
    .unwrap();
    assert!(r.probability > 0.1);
    // Coplanar, collinear and huge-coordinate clouds.
    let far: Vec<Point3> = pts(30)
        .iter()
        .map(|p| p + Vector3::new(1e6, 1e6, 0.0))
        .collect();
    let a = PointCloud::from_sigma(far.clone(), 0.01).unwrap();
    let b = PointCloud::from_sigma(far, 0.01).unwrap();
    let r = collide(
        &Pose::identity(),
        &a,
        &Pose::translation(0.0, 0.0, 0.005),
        &b,
        &CollisionRequest::default(),
    )
    .unwrap();
    assert!(r.probability.is_finite() && (0.0..=1.0).contains(&r.probability));
}
