//! Sensor noise models against their formulas.

use cloudprox::math::{Matrix3, Point3, Pose, Vector3};
use cloudprox::uncertainty::{DepthCamera, Lidar, SensorModel, StereoCamera, Viewpoint};
use cloudprox::Error;
use nalgebra::{Translation3, UnitQuaternion};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

/// Variance of `cov` along the unit vector `u`.
fn var_along(cov: &Matrix3, u: &Vector3) -> f64 {
    (u.transpose() * cov * u)[(0, 0)]
}

fn one(model: SensorModel, p: Point3, vp: Viewpoint) -> Matrix3 {
    model.covariances(&[p], &vp).unwrap()[0]
}

#[test]
fn depth_camera_default_is_khoshelham_on_the_axis() {
    let cam = DepthCamera::default();
    let vp = Viewpoint::from_pose(&Pose::identity());
    for z in [0.5, 1.0, 2.0, 5.0] {
        let c = one(SensorModel::DepthCamera(cam), Point3::new(0.0, 0.0, z), vp);
        let axial = 1.425e-3 * z * z;
        let lateral = 0.8 * z / 580.0;
        assert!(close(c[(2, 2)], axial * axial, 1e-12), "z = {z}");
        assert!(close(c[(0, 0)], lateral * lateral, 1e-12));
        assert!(close(c[(1, 1)], lateral * lateral, 1e-12));
        assert!(c[(0, 1)].abs() < 1e-18 && c[(0, 2)].abs() < 1e-18);
    }
    // 1.4 mm at 1 m, 3.6 cm at 5 m.
    assert!(close(cam.sigma_axial(1.0), 1.425e-3, 1e-12));
    assert!(close(cam.sigma_axial(5.0), 0.035625, 1e-12));
}

#[test]
fn nguyen_fit_values() {
    let cam = DepthCamera::nguyen_2012();
    assert!(close(cam.sigma_axial(0.4), 0.0012, 1e-12));
    assert!(close(cam.sigma_axial(2.4), 0.0012 + 0.0019 * 4.0, 1e-12));
}

#[test]
fn off_axis_depth_error_is_stretched_along_the_ray() {
    let cam = DepthCamera::default();
    let model = SensorModel::DepthCamera(cam);
    let p = Point3::new(1.0, 0.5, 2.0);
    let vp = Viewpoint::from_pose(&Pose::identity());
    let c = one(model, p, vp);
    let r = p.coords.norm();
    let u = p.coords / r;
    let z = 2.0;
    let s_ray = cam.sigma_axial(z) * r / z;
    let s_lat = cam.sigma_lateral(z);
    assert!(close(var_along(&c, &u), s_ray * s_ray, 1e-10));
    let perp = u.cross(&Vector3::x()).normalize();
    assert!(close(var_along(&c, &perp), s_lat * s_lat, 1e-10));
    // Without the axis the depth is the range.
    let c2 = one(model, p, Viewpoint::at(Point3::origin()));
    assert!(close(var_along(&c2, &u), cam.sigma_axial(r).powi(2), 1e-10));
    assert!(close(
        var_along(&c2, &perp),
        cam.sigma_lateral(r).powi(2),
        1e-10
    ));
}

#[test]
fn depth_noise_simulated_along_rays_matches_the_covariance() {
    // Simulate the sensor: the measured depth z' = z + N(0, sigma_z(z)) and the
    // point moves along its ray to depth z'. The sample variance along the ray must
    // match the model's.
    let cam = DepthCamera::nguyen_2012();
    let p = Point3::new(-0.8, 0.3, 3.0);
    let vp = Viewpoint::from_pose(&Pose::identity());
    let c = one(SensorModel::DepthCamera(cam), p, vp);
    let u = p.coords.normalize();
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let n = 200_000;
    let mut sum2 = 0.0;
    for _ in 0..n {
        let e: f64 = rng.sample(StandardNormal);
        let z2 = p.z + cam.sigma_axial(p.z) * e;
        let q = p.coords * (z2 / p.z);
        sum2 += (q - p.coords).dot(&u).powi(2);
    }
    let var = sum2 / f64::from(n);
    assert!(
        close(var, var_along(&c, &u), 0.02),
        "{var} vs {}",
        var_along(&c, &u)
    );
}

#[test]
fn stereo_formula() {
    let cam = StereoCamera::default();
    let p = Point3::new(0.0, 0.0, 3.0);
    let c = one(
        SensorModel::Stereo(cam),
        p,
        Viewpoint::from_pose(&Pose::identity()),
    );
    let sz = 9.0 * 0.08 / (430.0 * 0.05);
    assert!(close(c[(2, 2)].sqrt(), sz, 1e-12));
    assert!(close(c[(0, 0)].sqrt(), 3.0 * 0.5 / 430.0, 1e-12));
    // Doubling the baseline halves the depth error.
    let wide = StereoCamera {
        baseline: 0.1,
        ..cam
    };
    assert!(close(wide.sigma_axial(3.0), sz / 2.0, 1e-12));
}

#[test]
fn lidar_range_noise_is_constant_and_lateral_grows_with_range() {
    let l = Lidar::default();
    assert!(close(
        l.sigma_angle,
        0.25f64.to_radians() / 12f64.sqrt(),
        1e-12
    ));
    let vp = Viewpoint::at(Point3::new(1.0, 1.0, 1.0));
    for r in [0.5, 4.0, 9.0] {
        let dir = Vector3::new(1.0, -2.0, 0.5).normalize();
        let p = vp.origin + dir * r;
        let c = one(SensorModel::Lidar(l), p, vp);
        assert!(close(var_along(&c, &dir), 0.01 * 0.01, 1e-10));
        let perp = dir.cross(&Vector3::z()).normalize();
        assert!(close(
            var_along(&c, &perp),
            (r * l.sigma_angle).powi(2),
            1e-10
        ));
    }
}

#[test]
fn covariances_rotate_with_a_rigid_motion_of_points_and_sensor() {
    let pose = Pose::from_parts(
        Translation3::new(0.3, -1.0, 2.0),
        UnitQuaternion::from_euler_angles(0.4, -0.7, 1.2),
    );
    let sensor = Pose::from_parts(
        Translation3::new(0.1, 0.0, -0.2),
        UnitQuaternion::from_euler_angles(0.1, 0.2, 0.0),
    );
    let points: Vec<Point3> = (0..20)
        .map(|i| {
            let t = f64::from(i) * 0.1;
            Point3::new(t.sin(), t.cos() * 0.5, 1.5 + t)
        })
        .collect();
    let r = pose.rotation.to_rotation_matrix();
    let r = r.matrix();
    for model in [
        SensorModel::DepthCamera(DepthCamera::default()),
        SensorModel::Stereo(StereoCamera::default()),
        SensorModel::Lidar(Lidar::default()),
    ] {
        let a = model
            .covariances(&points, &Viewpoint::from_pose(&sensor))
            .unwrap();
        let moved: Vec<Point3> = points.iter().map(|p| pose * p).collect();
        let b = model
            .covariances(&moved, &Viewpoint::from_pose(&(pose * sensor)))
            .unwrap();
        for (ca, cb) in a.iter().zip(&b) {
            assert!((r * ca * r.transpose() - cb).norm() < 1e-15 + 1e-9 * cb.norm());
        }
    }
}

#[test]
fn bad_inputs_are_named() {
    let vp = Viewpoint::from_pose(&Pose::identity());
    let cam = SensorModel::DepthCamera(DepthCamera::default());
    let msg = |r: cloudprox::Result<Vec<Matrix3>>| match r {
        Err(Error::InvalidInput(m)) => m,
        other => panic!("expected InvalidInput, got {other:?}"),
    };
    let m = msg(cam.covariances(&[Point3::new(0.0, 0.0, 1.0), Point3::origin()], &vp));
    assert!(m.contains("point 1") && m.contains("origin"), "{m}");
    let m = msg(cam.covariances(&[Point3::new(0.0, 0.0, -1.0)], &vp));
    assert!(m.contains("not in front"), "{m}");
    let m = msg(cam.covariances(&[Point3::new(f64::NAN, 0.0, 1.0)], &vp));
    assert!(m.contains("NaN"), "{m}");
    let bad = SensorModel::Stereo(StereoCamera {
        baseline: 0.0,
        ..StereoCamera::default()
    });
    let m = msg(bad.covariances(&[Point3::new(0.0, 0.0, 1.0)], &vp));
    assert!(m.contains("baseline"), "{m}");
    let bad = SensorModel::Lidar(Lidar {
        sigma_range: f64::NAN,
        ..Lidar::default()
    });
    let m = msg(bad.covariances(&[Point3::new(0.0, 0.0, 1.0)], &vp));
    assert!(m.contains("sigma_range"), "{m}");
    let m = msg(cam.covariances(
        &[Point3::new(0.0, 0.0, 1.0)],
        &Viewpoint {
            origin: Point3::origin(),
            axis: Some(Vector3::zeros()),
        },
    ));
    assert!(m.contains("axis"), "{m}");
}

#[test]
fn depth_quantization_sets_the_noise_correlation_of_elements() {
    // Kinect v1: disparity in 1/8 px, baseline 7.5 cm, focal 580 px, so depth
    // steps of z^2 / 348 m; Khoshelham's sigma_z = 1.425e-3 z^2 makes the
    // quantization's share of the variance the same at every depth.
    let cam = DepthCamera::default();
    let step = |z: f64| z * z * 0.125 / (580.0 * 0.075);
    for z in [0.8, 2.0, 4.0] {
        assert!(close(cam.depth_step(z), step(z), 1e-12));
        let share = (step(z).powi(2) / 12.0) / (1.425e-3 * z * z).powi(2);
        assert!(close(cam.noise_correlation(z), share, 1e-9));
    }
    assert!(close(cam.noise_correlation(2.0), 0.3389, 1e-3));
    // A camera without quantization shares nothing; one whose steps exceed its
    // noise shares everything.
    let continuous = DepthCamera {
        disparity_step_px: 0.0,
        ..cam
    };
    assert_eq!(continuous.noise_correlation(2.0), 0.0);
    let coarse = DepthCamera {
        disparity_step_px: 4.0,
        ..cam
    };
    assert_eq!(coarse.noise_correlation(2.0), 1.0);
    // A cloud seen by the camera builds its elements with the median share; by
    // a laser or with plain sigmas, independent noise.
    let vp = Viewpoint::at(Point3::origin());
    let pts: Vec<Point3> = (0..50)
        .map(|i| Point3::new(0.01 * i as f64, 0.0, 1.0 + 0.04 * i as f64))
        .collect();
    let nguyen = DepthCamera::nguyen_2012();
    let cloud = cloudprox::cloud::PointCloud::from_sensor(
        pts.clone(),
        &SensorModel::DepthCamera(nguyen),
        &vp,
    )
    .unwrap();
    let mut shares: Vec<f64> = pts
        .iter()
        .map(|p| nguyen.noise_correlation(p.coords.norm()))
        .collect();
    shares.sort_by(f64::total_cmp);
    assert!(close(
        cloud.element_settings().noise_correlation,
        shares[25],
        1e-12
    ));
    let laser = cloudprox::cloud::PointCloud::from_sensor(
        pts.clone(),
        &SensorModel::Lidar(Lidar::default()),
        &vp,
    )
    .unwrap();
    assert_eq!(laser.element_settings().noise_correlation, 0.0);
    let plain = cloudprox::cloud::PointCloud::from_sigma(pts, 0.01).unwrap();
    assert_eq!(plain.element_settings().noise_correlation, 0.0);
    // Bad parameters are named.
    let bad = DepthCamera {
        baseline_m: 0.0,
        ..cam
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .to_string()
        .contains("baseline_m"));
}

#[test]
fn ray_covariances_have_their_two_standard_deviations() {
    use cloudprox::uncertainty::ray_covariances;
    let vp = Viewpoint::at(Point3::new(0.0, 0.0, 2.0));
    let pts = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 2.0, 0.5)];
    let cov = ray_covariances(&pts, &vp, 0.03, 0.0075).unwrap();
    for (p, c) in pts.iter().zip(&cov) {
        let u = (p - vp.origin).normalize();
        assert!(close(var_along(c, &u), 0.03 * 0.03, 1e-12));
        let side = u.cross(&Vector3::x()).normalize();
        assert!(close(var_along(c, &side), 0.0075 * 0.0075, 1e-12));
        assert!((c - c.transpose()).amax() < 1e-18);
    }
    // The origin's point is refused, as are negative or non-finite sigmas.
    let msg = |r: Result<Vec<Matrix3>, Error>| r.unwrap_err().to_string();
    assert!(msg(ray_covariances(&[vp.origin], &vp, 0.01, 0.01)).contains("origin"));
    assert!(msg(ray_covariances(&pts, &vp, -0.01, 0.01)).contains("sigma_ray"));
    assert!(msg(ray_covariances(&pts, &vp, 0.01, f64::NAN)).contains("sigma_lat"));
}

#[test]
fn cell_side_of_a_grid_is_its_pitch_times_sqrt_2pi_over_6() {
    // The 6th neighbour of a square grid's inner point is at sqrt(2) h.
    let h = 0.01;
    let pts: Vec<Point3> = (0..60 * 60)
        .map(|k| Point3::new((k % 60) as f64 * h, (k / 60) as f64 * h, 0.0))
        .collect();
    let cloud = cloudprox::cloud::PointCloud::from_sigma(pts, 0.0).unwrap();
    let want = h * (2.0 * std::f64::consts::PI / 6.0).sqrt();
    assert!(
        close(cloud.cell_side(), want, 1e-9),
        "{}",
        cloud.cell_side()
    );
}
