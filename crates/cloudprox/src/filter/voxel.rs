//! Voxel downsampling: one representative point per occupied voxel.

use rayon::prelude::*;

use super::check_points;
use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Vector3};

/// How the covariances of a voxel's members are merged into the covariance of
/// its representative point (their centroid).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CovarianceMerge {
    /// `Σ = (1/n) Σᵢ Σᵢ`, the mean of the member covariances. The default:
    /// neighbouring pixels of a depth camera have strongly correlated noise
    /// (structured-light and stereo depth is computed over a window of pixels),
    /// so averaging them does not shrink the noise of the mean by `n`; with fully
    /// correlated members the mean's covariance is exactly this, with independent
    /// members it over-estimates by `n`. Conservative, so a collision
    /// probability is never under-estimated because of downsampling.
    #[default]
    Mean,
    /// `Σ = (1/n²) Σᵢ Σᵢ`, the exact covariance of the mean of `n` independent
    /// points. Right for sensors whose points have independent noise (e.g. a
    /// lidar's separate returns); optimistic for depth cameras.
    MeanOfIndependent,
}

/// The result of [`voxel_downsample`]: one point per occupied voxel.
#[derive(Debug, Clone, PartialEq)]
pub struct Voxelized {
    /// The centroid of each occupied voxel's members, ordered by voxel
    /// coordinates `(ix, iy, iz)` lexicographically (x slowest), where
    /// `ix = floor((x - min_x) / voxel_size)` and `min_x` is the cloud's minimum.
    pub points: Vec<Point3>,
    /// The merged covariance of each output point (see [`CovarianceMerge`]),
    /// when covariances were given.
    pub covariances: Option<Vec<Matrix3>>,
    /// How many input points each voxel holds (they sum to the input's length).
    pub counts: Vec<u32>,
}

/// Downsamples a cloud on a grid of cubic voxels of side `voxel_size` (metres):
/// every occupied voxel gives one point, the centroid of its members, and (with
/// `covariances`) the mean of the members' covariances ([`CovarianceMerge::Mean`];
/// see [`voxel_downsample_with`] for the other rule).
///
/// Rule: PCL `pcl::VoxelGrid` (centroid of each voxel's points; Open3D's
/// `voxel_down_sample` likewise). The grid is anchored at the cloud's minimum
/// corner. No default voxel size: it depends on the sensor (1 cm suits a depth
/// camera at about 1 m). The voxel size is *not* added to the covariances: the
/// caller re-estimates the sampling spacing of the output (the kNN
/// discretization estimate).
///
/// Output order is deterministic (voxel coordinates, x slowest). Runs in
/// parallel (a parallel sort of voxel keys, then one pass per voxel).
///
/// # Errors
/// [`Error::InvalidInput`] if the cloud is empty or has a non-finite point, if
/// `voxel_size` is not finite and positive, if the cloud spans more than
/// 2^21 - 1 voxels along an axis (voxel size too small for its extent), or if a
/// covariance has a non-finite entry; [`Error::Shape`] if `covariances` does
/// not have one matrix per point.
pub fn voxel_downsample(
    points: &[Point3],
    covariances: Option<&[Matrix3]>,
    voxel_size: f64,
) -> Result<Voxelized> {
    voxel_downsample_with(points, covariances, voxel_size, CovarianceMerge::Mean)
}

/// [`voxel_downsample`] with the covariance merging rule chosen by `merge`.
///
/// # Errors
/// As [`voxel_downsample`].
pub fn voxel_downsample_with(
    points: &[Point3],
    covariances: Option<&[Matrix3]>,
    voxel_size: f64,
    merge: CovarianceMerge,
) -> Result<Voxelized> {
    const AXIS_BITS: u32 = 21;
    const AXIS_MAX: f64 = ((1u64 << AXIS_BITS) - 1) as f64;
    check_points("voxel_downsample", points)?;
    if !(voxel_size.is_finite() && voxel_size > 0.0) {
        return Err(Error::invalid(format!(
            "voxel_downsample: voxel_size must be finite and > 0, got {voxel_size}"
        )));
    }
    if let Some(c) = covariances {
        if c.len() != points.len() {
            return Err(Error::Shape {
                what: "voxel_downsample: covariances (one per point)".into(),
                expected: points.len(),
                got: c.len(),
            });
        }
        if let Some(i) = c
            .par_iter()
            .position_first(|m| !m.iter().all(|v| v.is_finite()))
        {
            return Err(Error::invalid(format!(
                "voxel_downsample: covariance {i} has a non-finite entry"
            )));
        }
    }
    let mut lo = points[0];
    let mut hi = points[0];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let inv = 1.0 / voxel_size;
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        let cells = ((hi[a] - lo[a]) * inv).floor();
        if cells.is_nan() || cells >= AXIS_MAX {
            return Err(Error::invalid(format!(
                "voxel_downsample: voxel_size {voxel_size} is too small for the cloud's \
                 extent along {axis} ({} m, more than 2^21 - 1 voxels)",
                hi[a] - lo[a]
            )));
        }
    }
    let key = |p: &Point3| -> u64 {
        let c = |a: usize| (((p[a] - lo[a]) * inv).floor() as u64).min(AXIS_MAX as u64);
        (c(0) << (2 * AXIS_BITS)) | (c(1) << AXIS_BITS) | c(2)
    };
    let mut pairs: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (key(p), i as u32))
        .collect();
    pairs.par_sort_unstable();
    let mut starts: Vec<usize> = Vec::new();
    for (pos, w) in pairs.windows(2).enumerate() {
        if w[0].0 != w[1].0 {
            starts.push(pos + 1);
        }
    }
    starts.insert(0, 0);
    starts.push(pairs.len());
    let groups: Vec<(Point3, Option<Matrix3>, u32)> = starts
        .par_windows(2)
        .map(|w| {
            let members = &pairs[w[0]..w[1]];
            let n = members.len() as f64;
            // Sum relative to the first member: no cancellation far from the origin.
            let first = points[members[0].1 as usize];
            let sum: Vector3 = members
                .iter()
                .map(|&(_, i)| points[i as usize] - first)
                .sum();
            let centroid = first + sum / n;
            let cov = covariances.map(|c| {
                let total: Matrix3 = members.iter().map(|&(_, i)| c[i as usize]).sum();
                match merge {
                    CovarianceMerge::Mean => total / n,
                    CovarianceMerge::MeanOfIndependent => total / (n * n),
                }
            });
            (centroid, cov, members.len() as u32)
        })
        .collect();
    let mut out = Voxelized {
        points: Vec::with_capacity(groups.len()),
        covariances: covariances.map(|_| Vec::with_capacity(groups.len())),
        counts: Vec::with_capacity(groups.len()),
    };
    for (p, c, n) in groups {
        out.points.push(p);
        if let (Some(all), Some(c)) = (out.covariances.as_mut(), c) {
            all.push(c);
        }
        out.counts.push(n);
    }
    Ok(out)
}
