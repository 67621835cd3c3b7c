//! Statistical outlier removal: a dense plane plus 1% far outliers.

use cloudprox::filter::{statistical_outlier_removal, SOR_DEFAULT_K, SOR_DEFAULT_STD_RATIO};
use cloudprox::prelude::*;
use cloudprox::sample::NormalRng;

#[test]
fn far_outliers_are_removed_and_the_plane_kept() {
    let mut rng = NormalRng::new(11);
    // 150 x 150 plane, 1 cm spacing, 0.5 mm noise.
    let mut points: Vec<Point3> = (0..150 * 150)
        .map(|i| {
            Point3::new(
                (i / 150) as f64 * 0.01 + 0.0005 * rng.normal(),
                (i % 150) as f64 * 0.01 + 0.0005 * rng.normal(),
                0.0005 * rng.normal(),
            )
        })
        .collect();
    let plane = points.len();
    let outliers = plane / 100;
    points.extend((0..outliers).map(|_| {
        Point3::new(
            -1.0 + 3.5 * rng.uniform(),
            -1.0 + 3.5 * rng.uniform(),
            0.3 + 1.5 * rng.uniform(),
        )
    }));
    let kept = statistical_outlier_removal(&points, SOR_DEFAULT_K, SOR_DEFAULT_STD_RATIO).unwrap();
    assert!(kept.windows(2).all(|w| w[0] < w[1]));
    let kept_outliers = kept.iter().filter(|&&i| i as usize >= plane).count();
    let kept_plane = kept.len() - kept_outliers;
    assert_eq!(kept_outliers, 0);
    assert!(
        kept_plane as f64 > 0.99 * plane as f64,
        "{kept_plane} of {plane}"
    );
    // PCL's tutorial setting also removes them all.
    let kept = statistical_outlier_removal(&points, 50, 1.0).unwrap();
    assert!(kept.iter().all(|&i| (i as usize) < plane));
}

#[test]
fn a_clean_lattice_loses_nothing() {
    let points: Vec<Point3> = (0..1000)
        .map(|i| Point3::new((i / 100) as f64, (i / 10 % 10) as f64, (i % 10) as f64))
        .collect();
    // Edge and corner points have larger mean distances; with ratio 6 all stay.
    let kept = statistical_outlier_removal(&points, 6, 6.0).unwrap();
    assert_eq!(kept.len(), 1000);
}
