//! Construction of a cloud's surface elements: the top-down split (here),
//! the bottom-up merge (`element_merge.rs`), the layout in element order.

use crate::cloud::PointCloud;
use crate::element::element_fit::{fit_element, Fit, SplitRule};
use crate::element::element_merge::merge_neighbours;
use crate::element::element_samples::element_samples;
use crate::element::{ElementSettings, SurfaceElement, SurfaceElements};
use crate::error::Result;
use crate::math::Vector3;
use crate::sample::splitmix64_mix;

impl SurfaceElements {
    /// Groups `cloud`'s points into surface elements (see [`crate::element`]),
    /// in the cloud's own frame. `O(n log n)` tests of `O(m)` each, on
    /// rayon's pool (the split's halves, the merge's unions); the groups do
    /// not depend on the number of threads.
    pub fn build(cloud: &PointCloud, settings: &ElementSettings) -> Result<Self> {
        settings.validate()?;
        let points = cloud.points();
        let sensor = cloud.sensor_covariances();
        let spacing = cloud.spacing();
        let n = points.len();
        // Repair what the median splits cut apart, then lay the groups out
        // contiguously.
        let groups = merge_neighbours(points, sensor, spacing, settings, split(cloud, settings));
        let mut indices = Vec::with_capacity(n);
        let mut elements = Vec::with_capacity(groups.len());
        for (g, mut e) in groups {
            // Fresh copies, made in element order on this thread: the fits
            // ran on rayon's threads, each allocating from its own arena, and
            // a query that walks the elements in order reads these next to
            // each other (scattered, the spheres' near query of criterion was
            // 25% slower with the same elements).
            let (probes, footprint) = (
                std::mem::take(&mut e.probes),
                std::mem::take(&mut e.footprint),
            );
            e.probes = Vec::from(probes.as_slice());
            e.footprint = Vec::from(footprint.as_slice());
            e.first = indices.len() as u32;
            // (The same mean as the fit's for a multi-point element.)
            e.spacing = g.iter().map(|&i| spacing[i as usize]).sum::<f64>() / g.len() as f64;
            indices.extend_from_slice(&g);
            elements.push(e);
        }
        let (samples, sample_owner) = element_samples(cloud, &elements, &indices);
        let covariances = cloud.covariances();
        let sample_is_point = sample_owner
            .iter()
            .map(|&e| elements[e as usize].is_point())
            .collect();
        Ok(SurfaceElements {
            elements,
            points: indices.iter().map(|&i| points[i as usize]).collect(),
            covariances: indices.iter().map(|&i| covariances[i as usize]).collect(),
            indices,
            samples,
            sample_owner,
            sample_is_point,
            hulls: std::sync::OnceLock::new(),
            member_chunks: std::sync::OnceLock::new(),
        })
    }
}

/// The top-down split: every group that fails the element tests is halved
/// (at the median along its widest axis, or between the two surfaces it
/// samples) until it passes or holds too few points, which then stand for
/// themselves. Returns each group's points with its element, in index order.
pub(crate) fn split(
    cloud: &PointCloud,
    settings: &ElementSettings,
) -> Vec<(Vec<u32>, SurfaceElement)> {
    let mut indices: Vec<u32> = (0..cloud.len() as u32).collect();
    split_run(cloud, settings, &mut indices, 0)
}

/// Runs of at least this many points split their two halves in parallel.
const PARALLEL_SPLIT_MIN: usize = 2048;

/// [`split`] of one run of the index order, `run`, which starts at `first`:
/// its groups in index order (the two halves of a split are disjoint runs,
/// so they are split independently, in parallel when large).
fn split_run(
    cloud: &PointCloud,
    settings: &ElementSettings,
    run: &mut [u32],
    first: usize,
) -> Vec<(Vec<u32>, SurfaceElement)> {
    let points = cloud.points();
    let count = run.len();
    if count >= settings.min_points {
        let (sensor, spacing) = (cloud.sensor_covariances(), cloud.spacing());
        match fit_element(points, sensor, spacing, run, first as u32, settings) {
            Fit::Element(e) => return vec![(run.to_vec(), *e)],
            Fit::Split(rule) => {
                let mut k = match &rule {
                    SplitRule::TwoSurfaces { .. } => {
                        partition(run, |i| rule.is_below(&points[i as usize]))
                    }
                    SplitRule::Median { .. } => 0,
                };
                if k == 0 || k == count {
                    let (mean, axis) = match rule {
                        SplitRule::Median { mean, axis } => (mean, axis),
                        SplitRule::TwoSurfaces { mean, frame, .. } => (mean, frame[0]),
                    };
                    let key = |i: u32| (points[i as usize] - mean).dot(&axis);
                    k = split_index(count, first, settings.segmentation);
                    run.select_nth_unstable_by(k, |&a, &b| key(a).total_cmp(&key(b)));
                }
                let (lo, hi) = run.split_at_mut(k);
                let (mut groups, upper) = if count >= PARALLEL_SPLIT_MIN {
                    rayon::join(
                        || split_run(cloud, settings, lo, first),
                        || split_run(cloud, settings, hi, first + k),
                    )
                } else {
                    (
                        split_run(cloud, settings, lo, first),
                        split_run(cloud, settings, hi, first + k),
                    )
                };
                groups.extend(upper);
                return groups;
            }
        }
    }
    // Too few points for an element: each point stands for itself.
    let total = cloud.covariances();
    run.iter()
        .enumerate()
        .map(|(j, &i)| {
            let i = i as usize;
            let e = SurfaceElement {
                first: (first + j) as u32,
                count: 1,
                mean: points[i],
                normal: Vector3::z(),
                tangents: [Vector3::x(), Vector3::y()],
                extent: [[0.0; 2]; 2],
                probes: vec![[0.0; 2]],
                spacing: 0.0,
                cov_mean: total[i],
                height: [0.0; 6],
                height_cov: nalgebra::SMatrix::zeros(),
                common_var: 0.0,
                footprint: Vec::new(),
            };
            (vec![i as u32], e)
        })
        .collect()
}

/// Where a group of `count` points (at least 2), starting at `first` in the
/// index order, is halved along its axis: at the median for segmentation 0,
/// else at a quantile in `[0.4, 0.6]` drawn from the segmentation and the
/// group (a hash of the three: the same segmentation always splits the same
/// group at the same place, on any number of threads).
fn split_index(count: usize, first: usize, segmentation: u32) -> usize {
    if segmentation == 0 {
        return count / 2;
    }
    let h = splitmix64_mix(
        u64::from(segmentation).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (first as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9)
            ^ (count as u64).wrapping_mul(0x94D0_49BB_1331_11EB),
    );
    let unit = (h >> 11) as f64 / (1u64 << 53) as f64;
    let at = (count as f64 * (0.4 + 0.2 * unit)).round() as usize;
    at.clamp(1, count - 1)
}

/// Moves the entries for which `pred` holds to the front; returns their count.
fn partition(slice: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut k = 0;
    for j in 0..slice.len() {
        if pred(slice[j]) {
            slice.swap(j, k);
            k += 1;
        }
    }
    k
}
