//! The scan pipeline (`scan::ScanPipeline`) and `CloudData::select`: subsets
//! stay aligned, the pipeline agrees with the same steps done by hand, and bad
//! input gives errors that name the problem.

use cloudprox::element::ElementSettings;
use cloudprox::filter::{self, SelfFilter, ShadowSettings};
use cloudprox::io::{CloudData, Grid};
use cloudprox::prelude::*;
use cloudprox::sample::NormalRng;
use cloudprox::scan::{ScanNoise, ScanPipeline, ScanStep, SensorPlacement};

const W: usize = 48;
const H: usize = 36;

/// An organized depth image seen from `sensor` (looking along its +z): a box
/// face at 1 m in front of a wall at 1.6 m, some holes (skipped pixels), a few
/// isolated far points, with normals and (made-up) stored covariances.
fn organized_scan(sensor: &Pose) -> CloudData {
    let mut rng = NormalRng::new(7);
    let f = W as f64 / 2.0 / 30f64.to_radians().tan();
    let mut data = CloudData {
        fields: ["x", "y", "z", "nx", "ny", "nz"].map(String::from).to_vec(),
        normals: Some(Vec::new()),
        covariances: Some(Vec::new()),
        sensor: Some(*sensor),
        ..CloudData::default()
    };
    let mut pixels = Vec::new();
    for row in 0..H {
        for col in 0..W {
            let px = row * W + col;
            if px % 17 == 5 {
                data.skipped += 1; // a hole
                continue;
            }
            let u = (col as f64 + 0.5 - W as f64 / 2.0) / f;
            let v = (row as f64 + 0.5 - H as f64 / 2.0) / f;
            let mut z = if u.abs() < 0.2 && v.abs() < 0.15 {
                1.0
            } else {
                1.6
            };
            if px % 211 == 100 {
                z = 3.5; // an isolated point far behind
            }
            z += 0.002 * rng.normal();
            let local = Point3::new(u * z, v * z, z);
            data.points.push(sensor * local);
            data.normals
                .as_mut()
                .unwrap()
                .push(sensor.rotation * -Vector3::z());
            let s = 1e-6 * (1.0 + (px % 5) as f64);
            data.covariances.as_mut().unwrap().push(Matrix3::new(
                s,
                0.1 * s,
                0.0,
                0.1 * s,
                s,
                0.0,
                0.0,
                0.0,
                2.0 * s,
            ));
            pixels.push(px as u32);
        }
    }
    data.grid = Some(Grid {
        width: W,
        height: H,
        pixels,
    });
    data
}

/// Keeps the entries of `v` at the ascending indices `k`.
fn take<T: Copy>(v: &mut Vec<T>, k: &[u32]) {
    let old = std::mem::take(v);
    *v = k.iter().map(|&i| old[i as usize]).collect();
}

fn sensor_pose() -> Pose {
    Pose::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.0, 0.0, 0.0))
}

#[test]
fn select_keeps_every_per_point_field_aligned() {
    let data = organized_scan(&sensor_pose());
    let n = data.points.len();
    let keep: Vec<bool> = (0..n).map(|i| i % 3 != 1).collect();
    let out = data.select(&keep).unwrap();
    let kept: Vec<usize> = (0..n).filter(|&i| keep[i]).collect();
    assert_eq!(out.points.len(), kept.len());
    let (normals, covs, grid) = (
        data.normals.as_ref().unwrap(),
        data.covariances.as_ref().unwrap(),
        data.grid.as_ref().unwrap(),
    );
    let out_grid = out.grid.as_ref().unwrap();
    assert_eq!((out_grid.width, out_grid.height), (W, H));
    for (j, &i) in kept.iter().enumerate() {
        assert_eq!(out.points[j], data.points[i]);
        assert_eq!(out.normals.as_ref().unwrap()[j], normals[i]);
        assert_eq!(out.covariances.as_ref().unwrap()[j], covs[i]);
        assert_eq!(out_grid.pixels[j], grid.pixels[i]);
    }
    assert_eq!(out.sensor, data.sensor);
    assert_eq!(out.fields, data.fields);
    assert_eq!(out.skipped, data.skipped);
    // The same subset by indices, and the trivial subsets.
    let idx: Vec<u32> = kept.iter().map(|&i| i as u32).collect();
    assert_eq!(data.select_indices(&idx).unwrap(), out);
    assert_eq!(data.select(&vec![true; n]).unwrap(), data);
    let none = data.select(&vec![false; n]).unwrap();
    assert!(none.points.is_empty() && none.grid.unwrap().pixels.is_empty());
}

#[test]
fn select_rejects_wrong_lengths_and_bad_indices() {
    let data = organized_scan(&sensor_pose());
    let n = data.points.len();
    match data.select(&vec![true; n - 1]) {
        Err(Error::Shape {
            what,
            expected,
            got,
        }) => {
            assert!(what.contains("keep mask"), "{what}");
            assert_eq!((expected, got), (n, n - 1));
        }
        other => panic!("expected a shape error, got {other:?}"),
    }
    let mut bad = data.clone();
    bad.covariances.as_mut().unwrap().pop();
    match bad.select(&vec![true; n]) {
        Err(Error::Shape { what, .. }) => assert!(what.contains("covariances"), "{what}"),
        other => panic!("expected a shape error, got {other:?}"),
    }
    let mut bad = data.clone();
    bad.grid.as_mut().unwrap().pixels.push(0);
    match bad.select(&vec![true; n]) {
        Err(Error::Shape { what, .. }) => assert!(what.contains("grid pixels"), "{what}"),
        other => panic!("expected a shape error, got {other:?}"),
    }
    let err = data.select_indices(&[0, n as u32]).unwrap_err();
    assert!(err.to_string().contains("out of range"), "{err}");
    let err = data.select_indices(&[3, 3]).unwrap_err();
    assert!(err.to_string().contains("strictly ascending"), "{err}");
}

/// The pipeline with every step but self, sensor model seen from the file's
/// viewpoint, against the core functions called one after the other.
#[test]
fn pipeline_agrees_with_the_steps_done_by_hand() {
    let pose = sensor_pose();
    let data = organized_scan(&pose);
    let model = SensorModel::DepthCamera(DepthCamera::default());
    let shadow = ShadowSettings::default();
    let lo = Point3::new(-1.0, -1.0, 0.0);
    let hi = Point3::new(1.0, 0.5, 3.0);
    let pipeline = ScanPipeline::new(ScanNoise::Sensor(model))
        .step(ScanStep::crop(lo, hi))
        .step(ScanStep::Shadow(shadow))
        .step(ScanStep::outliers())
        .step(ScanStep::voxel(0.03));
    let out = pipeline.run(&data).unwrap();

    // By hand.
    let vp = Viewpoint::from_pose(&pose);
    let mut points = data.points.clone();
    let mut covs = model.covariances(&points, &vp).unwrap();
    let mut pixels = data.grid.as_ref().unwrap().pixels.clone();
    let mut counts = vec![points.len()];
    let keep = filter::crop_box(&points, &lo, &hi, &Pose::identity(), false).unwrap();
    take(&mut points, &keep);
    take(&mut covs, &keep);
    take(&mut pixels, &keep);
    counts.push(points.len());
    let grid = Grid {
        width: W,
        height: H,
        pixels: pixels.clone(),
    };
    let keep = filter::shadow_filter(&points, &vp.origin, Some(&grid), &shadow).unwrap();
    take(&mut points, &keep);
    take(&mut covs, &keep);
    counts.push(points.len());
    let keep = filter::statistical_outlier_removal(
        &points,
        filter::SOR_DEFAULT_K,
        filter::SOR_DEFAULT_STD_RATIO,
    )
    .unwrap();
    take(&mut points, &keep);
    take(&mut covs, &keep);
    counts.push(points.len());
    let v = filter::voxel_downsample(&points, Some(&covs), 0.03).unwrap();
    counts.push(v.points.len());
    let rho = model.noise_correlation(&v.points, &vp).unwrap();
    let mut expected = PointCloud::from_covariances(v.points, v.covariances.unwrap())
        .unwrap()
        .with_discretization(&DiscretizationSettings::default())
        .unwrap();
    expected
        .set_element_settings(ElementSettings {
            noise_correlation: rho,
            ..*expected.element_settings()
        })
        .unwrap();

    // Every step did something, and the reports say what.
    let names: Vec<&str> = out.steps.iter().map(|s| s.step).collect();
    assert_eq!(names, ["crop", "shadow", "outliers", "voxel"]);
    for (i, s) in out.steps.iter().enumerate() {
        assert_eq!((s.before, s.after), (counts[i], counts[i + 1]), "step {i}");
        assert!(s.removed() > 0, "step {i} removed nothing");
    }
    assert_eq!(out.cloud.points(), expected.points());
    assert_eq!(out.cloud.covariances(), expected.covariances());
    assert_eq!(
        out.cloud.sensor_covariances(),
        expected.sensor_covariances()
    );
    assert_eq!(
        out.cloud.element_settings().noise_correlation,
        expected.element_settings().noise_correlation
    );
    assert!(rho > 0.0);
}

#[test]
fn stored_and_isotropic_noise_and_the_self_step_agree_with_by_hand() {
    let data = organized_scan(&sensor_pose());
    // A robot link: a box around part of the box face.
    let link = Mesh::cuboid(0.1, 0.1, 0.1).unwrap();
    let link_pose = Pose::new(Vector3::new(0.1, -0.2, 1.3), Vector3::zeros());
    let self_filter = SelfFilter::new(vec![(link, link_pose)], 0.01).unwrap();
    let keep = self_filter.apply(&data.points);
    assert!(keep.len() < data.points.len());
    let kept = data.select_indices(&keep).unwrap();

    let stored = ScanPipeline::new(ScanNoise::Stored)
        .step(ScanStep::SelfFilter(self_filter.clone()))
        .run(&data)
        .unwrap();
    let expected = PointCloud::from_covariances(kept.points.clone(), kept.covariances.unwrap())
        .unwrap()
        .with_discretization(&DiscretizationSettings::default())
        .unwrap();
    assert_eq!(stored.cloud.covariances(), expected.covariances());
    assert_eq!(stored.cloud.element_settings().noise_correlation, 0.0);

    let iso = ScanPipeline::new(ScanNoise::Isotropic(0.002))
        .step(ScanStep::SelfFilter(self_filter))
        .discretization(None)
        .run(&data)
        .unwrap();
    let expected = PointCloud::from_sigma(kept.points, 0.002).unwrap();
    assert_eq!(iso.cloud.points(), expected.points());
    assert_eq!(iso.cloud.covariances(), expected.covariances());
}

#[test]
fn origin_placement_is_used_by_the_sensor_model_and_the_shadow_step() {
    let data = organized_scan(&sensor_pose());
    let origin = Point3::new(0.1, -0.2, 0.3);
    let model = SensorModel::Lidar(Lidar::default());
    let out = ScanPipeline::new(ScanNoise::Sensor(model))
        .placement(SensorPlacement::Origin(origin))
        .step(ScanStep::voxel(0.05))
        .step(ScanStep::shadow())
        .run(&data)
        .unwrap();
    let covs = model
        .covariances(&data.points, &Viewpoint::at(origin))
        .unwrap();
    let v = filter::voxel_downsample(&data.points, Some(&covs), 0.05).unwrap();
    // After the voxel step there are no pixels: the shadow step searches neighbours.
    let keep = filter::shadow_filter(&v.points, &origin, None, &ShadowSettings::default()).unwrap();
    assert_eq!(out.steps[1].after, keep.len());
    let expected: Vec<Point3> = keep.iter().map(|&i| v.points[i as usize]).collect();
    assert_eq!(out.cloud.points(), &expected[..]);
}

#[test]
fn a_step_that_removes_every_point_is_reported_and_stops_the_pipeline() {
    let data = organized_scan(&sensor_pose());
    let pipeline = ScanPipeline::new(ScanNoise::Isotropic(0.001))
        .step(ScanStep::outliers())
        .step(ScanStep::crop(
            Point3::new(5.0, 5.0, 5.0),
            Point3::new(6.0, 6.0, 6.0),
        ))
        .step(ScanStep::voxel(0.01));
    let filtered = pipeline.filter(&data).unwrap();
    assert_eq!(filtered.emptied_by(), Some(1));
    assert_eq!(filtered.steps.len(), 2, "the voxel step must not run");
    assert_eq!(filtered.steps[1].after, 0);
    let err = pipeline.run(&data).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidInput(m) if m.contains("step 1 (crop) removed every point")),
        "{err}"
    );
}

#[test]
fn bad_input_gives_errors_naming_the_problem() {
    let data = organized_scan(&sensor_pose());
    let msg = |r: Result<cloudprox::scan::Scan>| r.unwrap_err().to_string();
    let iso = ScanPipeline::new(ScanNoise::Isotropic(0.001));

    let empty = CloudData {
        skipped: 4,
        ..CloudData::default()
    };
    assert!(msg(iso.run(&empty)).contains("no point with finite coordinates (4 skipped)"));

    let mut nan = data.clone();
    nan.points[3].y = f64::NAN;
    assert!(msg(iso.run(&nan)).contains("point 3 has a non-finite coordinate"));

    let mut short = data.clone();
    short.normals.as_mut().unwrap().pop();
    assert!(matches!(iso.run(&short), Err(Error::Shape { .. })));
    let what = msg(iso.run(&short));
    assert!(
        what.contains("scan pipeline") && what.contains("normals"),
        "{what}"
    );

    let bare = CloudData::from_points(data.points.clone());
    assert!(msg(ScanPipeline::new(ScanNoise::Stored).run(&bare)).contains("stores no covariances"));
    let lidar = ScanPipeline::new(ScanNoise::Sensor(SensorModel::Lidar(Lidar::default())));
    assert!(msg(lidar.run(&bare)).contains("records no sensor viewpoint"));
    assert!(msg(iso.clone().step(ScanStep::shadow()).run(&bare))
        .contains("step 0 (shadow) needs the sensor origin"));
    let nan_origin =
        lidar
            .clone()
            .placement(SensorPlacement::Origin(Point3::new(f64::NAN, 0.0, 0.0)));
    assert!(msg(nan_origin.run(&data)).contains("sensor origin must be finite"));
    assert!(
        msg(ScanPipeline::new(ScanNoise::Isotropic(f64::NAN)).run(&data))
            .contains("sigma must be finite")
    );
    assert!(msg(iso.clone().step(ScanStep::voxel(0.0)).run(&data)).contains("voxel_size"));
    let far_k = ScanStep::Outliers {
        k: data.points.len(),
        std_ratio: 2.0,
    };
    assert!(msg(iso.clone().step(far_k).run(&data)).contains("statistical_outlier_removal"));
    // A camera pose the scan's points are behind. A lidar has no optical
    // axis: the same pose places it and its points all around are seen.
    let behind = Pose::new(Vector3::new(0.0, 0.0, 5.0), Vector3::zeros());
    let camera = ScanPipeline::new(ScanNoise::Sensor(SensorModel::DepthCamera(
        DepthCamera::default(),
    )));
    assert!(
        msg(camera.placement(SensorPlacement::Pose(behind)).run(&data))
            .contains("not in front of the sensor")
    );
    assert!(lidar
        .placement(SensorPlacement::Pose(behind))
        .run(&data)
        .is_ok());
}
