//! Voxel downsampling: lattice counts and centroids, covariance merging, order.

use cloudprox::filter::{voxel_downsample, voxel_downsample_with, CovarianceMerge};
use cloudprox::prelude::*;
use cloudprox::sample::NormalRng;

/// 8 x 8 x 8 points at 0.0125 + 0.025 i: with 0.099 voxels (anchored at the
/// minimum), 2 x 2 x 2 voxels of 64 points each, centroids at 0.05 and 0.15.
fn lattice() -> Vec<Point3> {
    let c = |i: usize| 0.0125 + 0.025 * i as f64;
    (0..512)
        .map(|i| Point3::new(c(i / 64), c(i / 8 % 8), c(i % 8)))
        .collect()
}

#[test]
fn lattice_gives_known_voxels_and_centroids() {
    let points = lattice();
    let v = voxel_downsample(&points, None, 0.099).unwrap();
    assert_eq!(v.points.len(), 8);
    assert_eq!(v.counts, vec![64; 8]);
    assert!(v.covariances.is_none());
    // Ordered by voxel coordinates, x slowest, z fastest.
    for (m, p) in v.points.iter().enumerate() {
        let expect = |bit: usize| if m >> bit & 1 == 1 { 0.15 } else { 0.05 };
        let e = Point3::new(expect(2), expect(1), expect(0));
        assert!((p - e).norm() < 1e-12, "voxel {m}: {p} vs {e}");
    }
}

#[test]
fn covariances_merge_by_the_chosen_rule() {
    let points = lattice();
    let covs: Vec<Matrix3> = (0..points.len())
        .map(|i| {
            let a = 1e-6 * (1.0 + i as f64);
            Matrix3::new(a, 0.1 * a, 0.0, 0.1 * a, 2.0 * a, 0.0, 0.0, 0.0, 3.0 * a)
        })
        .collect();
    let mean = voxel_downsample(&points, Some(&covs), 0.099).unwrap();
    let indep = voxel_downsample_with(
        &points,
        Some(&covs),
        0.099,
        CovarianceMerge::MeanOfIndependent,
    )
    .unwrap();
    let (mc, ic) = (mean.covariances.unwrap(), indep.covariances.unwrap());
    for m in 0..8 {
        let members: Vec<usize> = (0..points.len())
            .filter(|&i| {
                let p = points[i];
                let bit = |a: usize| usize::from(p[a] > 0.1);
                bit(0) << 2 | bit(1) << 1 | bit(2) == m
            })
            .collect();
        let sum: Matrix3 = members.iter().map(|&i| covs[i]).sum();
        let n = members.len() as f64;
        assert!((mc[m] - sum / n).norm() < 1e-18);
        assert!((ic[m] - sum / (n * n)).norm() < 1e-18);
    }
}

#[test]
fn counts_sum_to_n_and_output_is_deterministic() {
    let mut rng = NormalRng::new(5);
    let points: Vec<Point3> = (0..20_000)
        .map(|_| Point3::new(rng.normal(), rng.normal(), 0.1 * rng.normal()))
        .collect();
    let a = voxel_downsample(&points, None, 0.05).unwrap();
    assert_eq!(
        a.counts.iter().map(|&c| c as usize).sum::<usize>(),
        points.len()
    );
    assert_eq!(a.counts.len(), a.points.len());
    let b = voxel_downsample(&points, None, 0.05).unwrap();
    assert_eq!(a, b);
    // Every output point is the centroid of members within one voxel.
    let single = voxel_downsample(&points[..1], None, 0.05).unwrap();
    assert_eq!(single.points, vec![points[0]]);
}
