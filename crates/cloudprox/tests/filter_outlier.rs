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

/// PCL's rule by brute force: all pairwise distances, the k smallest per point.
fn brute_force_sor(points: &[Point3], k: usize, std_ratio: f64) -> Vec<u32> {
    let mean_distance: Vec<f64> = (0..points.len())
        .map(|i| {
            let mut d: Vec<f64> = (0..points.len())
                .filter(|&j| j != i)
                .map(|j| (points[j] - points[i]).norm_squared())
                .collect();
            // The k smallest, ascending (the order of the sum): a selection,
            // then a sort of those alone.
            if k < d.len() {
                d.select_nth_unstable_by(k, f64::total_cmp);
            }
            d[..k].sort_by(f64::total_cmp);
            d[..k].iter().map(|d2| d2.sqrt()).sum::<f64>() / k as f64
        })
        .collect();
    let n = mean_distance.len() as f64;
    let mean = mean_distance.iter().sum::<f64>() / n;
    let var = mean_distance
        .iter()
        .map(|d| (d - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    let threshold = mean + std_ratio * var.sqrt();
    (0..points.len() as u32)
        .filter(|&i| mean_distance[i as usize] <= threshold)
        .collect()
}

#[test]
fn kept_set_equals_brute_force_on_uneven_clouds() {
    for seed in [1, 2, 3] {
        let mut rng = NormalRng::new(seed);
        // A sparse noisy plane, a patch 30x denser, a line, far points and
        // exact duplicates.
        let mut points: Vec<Point3> = (0..2000)
            .map(|_| Point3::new(rng.uniform(), rng.uniform(), 0.002 * rng.normal()))
            .collect();
        points.extend((0..1500).map(|_| {
            Point3::new(
                0.3 + 0.15 * rng.uniform(),
                0.3 + 0.15 * rng.uniform(),
                0.1 + 0.001 * rng.normal(),
            )
        }));
        points.extend((0..300).map(|i| Point3::new(1.5, i as f64 * 1e-3, 0.0)));
        points.extend((0..40).map(|_| {
            Point3::new(
                6.0 * rng.uniform() - 3.0,
                6.0 * rng.uniform() - 3.0,
                2.0 * rng.normal(),
            )
        }));
        for c in 0..30 {
            points.push(points[(c * 7919) % points.len()]);
        }
        for (k, ratio) in [(1, 1.0), (8, 0.5), (20, 2.0), (30, -0.2)] {
            let got = statistical_outlier_removal(&points, k, ratio).unwrap();
            let want = brute_force_sor(&points, k, ratio);
            assert_eq!(got, want, "seed {seed}, k {k}, ratio {ratio}");
        }
    }
}
