//! Crop box: known counts on a lattice, a rotated box, invert, rigid invariance.

use cloudprox::filter::crop_box;
use cloudprox::prelude::*;

/// 10 x 10 x 10 points at (i + 0.5) / 10 in the unit cube (none on a box face below).
fn lattice() -> Vec<Point3> {
    let c = |i: usize| (i as f64 + 0.5) * 0.1;
    (0..1000)
        .map(|i| Point3::new(c(i / 100), c(i / 10 % 10), c(i % 10)))
        .collect()
}

#[test]
fn axis_aligned_box_keeps_the_points_inside() {
    let points = lattice();
    let (min, max) = (Point3::new(0.2, 0.2, 0.2), Point3::new(0.6, 0.6, 0.6));
    let kept = crop_box(&points, &min, &max, &Pose::identity(), false).unwrap();
    assert_eq!(kept.len(), 64); // 0.25, 0.35, 0.45, 0.55 on each axis
    assert!(kept.windows(2).all(|w| w[0] < w[1]));
    for &i in &kept {
        let p = points[i as usize];
        assert!((0..3).all(|a| p[a] > 0.2 && p[a] < 0.6));
    }
    let out = crop_box(&points, &min, &max, &Pose::identity(), true).unwrap();
    assert_eq!(out.len(), 936);
    let mut all: Vec<u32> = kept.iter().chain(&out).copied().collect();
    all.sort_unstable();
    assert_eq!(all, (0..1000).collect::<Vec<u32>>());
}

#[test]
fn rotated_box_keeps_a_diamond() {
    // A 0.4-wide cube at the centre turned 45 degrees about z: in xy the points
    // with |u| + |v| <= 0.2 sqrt(2) (12 of them), in z 0.35..0.65 (4 layers).
    let points = lattice();
    let pose = Pose::new(
        Vector3::new(0.5, 0.5, 0.5),
        Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_4),
    );
    let (min, max) = (Point3::new(-0.2, -0.2, -0.2), Point3::new(0.2, 0.2, 0.2));
    let kept = crop_box(&points, &min, &max, &pose, false).unwrap();
    assert_eq!(kept.len(), 48);
    let out = crop_box(&points, &min, &max, &pose, true).unwrap();
    assert_eq!(out.len(), 1000 - 48);
}

#[test]
fn crop_box_commutes_with_a_rigid_transform() {
    let points = lattice();
    let pose = Pose::new(Vector3::new(0.45, 0.5, 0.52), Vector3::new(0.3, -0.2, 0.7));
    let (min, max) = (Point3::new(-0.3, -0.2, -0.25), Point3::new(0.25, 0.3, 0.2));
    let t = Pose::new(Vector3::new(3.0, -1.0, 0.5), Vector3::new(-1.0, 0.4, 2.0));
    let moved: Vec<Point3> = points.iter().map(|p| t * p).collect();
    for invert in [false, true] {
        let a = crop_box(&points, &min, &max, &pose, invert).unwrap();
        let b = crop_box(&moved, &min, &max, &(t * pose), invert).unwrap();
        assert_eq!(a, b);
        assert!(!a.is_empty());
    }
}
