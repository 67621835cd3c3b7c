//! Every filter rejects bad parameters with an error naming them.

use cloudprox::filter::{
    crop_box, shadow_filter, statistical_outlier_removal, voxel_downsample, SelfFilter,
    ShadowSettings,
};
use cloudprox::io::Grid;
use cloudprox::prelude::*;

fn invalid_mentions<T: std::fmt::Debug>(r: Result<T>, word: &str) {
    match r {
        Err(Error::InvalidInput(msg)) => assert!(msg.contains(word), "{msg:?} lacks {word:?}"),
        other => panic!("expected InvalidInput naming {word:?}, got {other:?}"),
    }
}

fn cloud() -> Vec<Point3> {
    (0..50)
        .map(|i| Point3::new(i as f64 * 0.01, (i % 7) as f64 * 0.01, 0.0))
        .collect()
}

#[test]
fn empty_and_non_finite_clouds() {
    let id = Pose::identity();
    let (lo, hi) = (Point3::origin(), Point3::new(1.0, 1.0, 1.0));
    invalid_mentions(crop_box(&[], &lo, &hi, &id, false), "empty");
    invalid_mentions(voxel_downsample(&[], None, 0.1), "empty");
    invalid_mentions(statistical_outlier_removal(&[], 5, 1.0), "empty");
    invalid_mentions(
        shadow_filter(&[], &lo, None, &ShadowSettings::default()),
        "empty",
    );
    let mut bad = cloud();
    bad[17].y = f64::NAN;
    invalid_mentions(crop_box(&bad, &lo, &hi, &id, false), "point 17");
    invalid_mentions(voxel_downsample(&bad, None, 0.1), "point 17");
    invalid_mentions(statistical_outlier_removal(&bad, 5, 1.0), "point 17");
    invalid_mentions(
        shadow_filter(&bad, &lo, None, &ShadowSettings::default()),
        "point 17",
    );
}

#[test]
fn crop_box_parameters() {
    let p = cloud();
    let id = Pose::identity();
    let (lo, hi) = (Point3::origin(), Point3::new(1.0, 1.0, 1.0));
    invalid_mentions(
        crop_box(&p, &hi, &lo, &id, false),
        "min corner is above max",
    );
    invalid_mentions(
        crop_box(&p, &Point3::new(f64::NAN, 0.0, 0.0), &hi, &id, false),
        "min",
    );
    invalid_mentions(
        crop_box(&p, &lo, &Point3::new(1.0, f64::INFINITY, 1.0), &id, false),
        "max",
    );
    let bad_pose = Pose::translation(f64::NAN, 0.0, 0.0);
    invalid_mentions(crop_box(&p, &lo, &hi, &bad_pose, false), "pose");
    // A flat box is allowed.
    assert!(crop_box(&p, &lo, &Point3::new(1.0, 1.0, 0.0), &id, false).is_ok());
}

#[test]
fn voxel_parameters() {
    let p = cloud();
    for size in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        invalid_mentions(voxel_downsample(&p, None, size), "voxel_size");
    }
    invalid_mentions(voxel_downsample(&p, None, 1e-12), "too small");
    let covs = vec![Matrix3::identity(); 3];
    assert!(matches!(
        voxel_downsample(&p, Some(&covs), 0.1),
        Err(Error::Shape {
            expected: 50,
            got: 3,
            ..
        })
    ));
    let mut covs = vec![Matrix3::identity(); 50];
    covs[4][(1, 1)] = f64::NAN;
    invalid_mentions(voxel_downsample(&p, Some(&covs), 0.1), "covariance 4");
}

#[test]
fn outlier_parameters() {
    let p = cloud();
    invalid_mentions(statistical_outlier_removal(&p, 0, 1.0), "k must");
    invalid_mentions(statistical_outlier_removal(&p, 50, 1.0), "k must");
    invalid_mentions(statistical_outlier_removal(&p, 5, f64::NAN), "std_ratio");
    assert!(statistical_outlier_removal(&p, 49, -0.5).is_ok());
}

#[test]
fn shadow_parameters() {
    let p = cloud();
    let o = Point3::new(0.0, 0.0, -1.0);
    for min_angle in [0.0, -0.1, 1.6, f64::NAN] {
        let s = ShadowSettings {
            min_angle,
            ..ShadowSettings::default()
        };
        invalid_mentions(shadow_filter(&p, &o, None, &s), "min_angle");
    }
    let s = ShadowSettings {
        window: 0,
        ..ShadowSettings::default()
    };
    invalid_mentions(shadow_filter(&p, &o, None, &s), "window");
    let s = ShadowSettings {
        k: 0,
        ..ShadowSettings::default()
    };
    invalid_mentions(shadow_filter(&p, &o, None, &s), "k must");
    let d = ShadowSettings::default();
    invalid_mentions(
        shadow_filter(&p, &Point3::new(f64::NAN, 0.0, 0.0), None, &d),
        "origin",
    );
    let grid = |width, height, pixels: Vec<u32>| Grid {
        width,
        height,
        pixels,
    };
    assert!(matches!(
        shadow_filter(&p, &o, Some(&grid(10, 5, (0..49).collect())), &d),
        Err(Error::Shape {
            expected: 50,
            got: 49,
            ..
        })
    ));
    invalid_mentions(
        shadow_filter(&p, &o, Some(&grid(0, 5, (0..50).collect())), &d),
        "pixels",
    );
    invalid_mentions(
        shadow_filter(&p, &o, Some(&grid(usize::MAX, 3, (0..50).collect())), &d),
        "pixels",
    );
    invalid_mentions(
        shadow_filter(&p, &o, Some(&grid(7, 7, (0..50).collect())), &d),
        "outside",
    );
    let mut dup: Vec<u32> = (0..50).collect();
    dup[9] = 3;
    invalid_mentions(
        shadow_filter(&p, &o, Some(&grid(10, 5, dup)), &d),
        "given to points 3 and 9",
    );
    assert_eq!(
        shadow_filter(&p, &o, Some(&grid(10, 5, (0..50).collect())), &d)
            .unwrap()
            .len(),
        50
    );
}

#[test]
fn self_filter_parameters() {
    let m = Mesh::cuboid(0.1, 0.1, 0.1).unwrap();
    invalid_mentions(SelfFilter::new(vec![], 0.01), "no link");
    for pad in [-0.01, f64::NAN, f64::INFINITY] {
        invalid_mentions(
            SelfFilter::new(vec![(m.clone(), Pose::identity())], pad),
            "padding",
        );
    }
    invalid_mentions(
        SelfFilter::new(
            vec![
                (m.clone(), Pose::identity()),
                (m.clone(), Pose::translation(0.0, f64::NAN, 0.0)),
            ],
            0.01,
        ),
        "link 1",
    );
    let mut f = SelfFilter::new(vec![(m, Pose::identity())], 0.0).unwrap();
    invalid_mentions(
        f.set_poses(&[Pose::translation(f64::INFINITY, 0.0, 0.0)]),
        "link 0",
    );
    assert_eq!(f.poses(), vec![Pose::identity()]);
    assert!(f.apply(&[]).is_empty());
    assert_eq!(f.apply(&[Point3::new(f64::NAN, 0.0, 0.0)]), vec![0]);
}
