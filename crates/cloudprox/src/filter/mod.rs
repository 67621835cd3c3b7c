//! The pipeline's first step: filters that clean a sensor cloud before queries.
//!
//! | filter | function | corresponds to |
//! |---|---|---|
//! | robot's own points | [`SelfFilter`] | ROS `robot_self_filter` (PR2 pipeline) |
//! | veil / mixed pixels | [`shadow_filter`] | ROS `laser_filters` `ScanShadowsFilter` |
//! | crop box | [`crop_box`] | PCL `CropBox` |
//! | voxel downsampling | [`voxel_downsample`] | PCL `VoxelGrid` |
//! | statistical outliers | [`statistical_outlier_removal`] | PCL `StatisticalOutlierRemoval` |
//! | what the sensor did not see (space behind the observed surfaces) | [`Occlusion`] | OctoMap's unknown space |
//!
//! Filters that only remove points return the **indices of the kept points, in
//! ascending order** (`Vec<u32>`), so that the caller can subset points,
//! covariances, normals and pixels alike. [`voxel_downsample`] makes new points
//! and returns them in a [`Voxelized`].
//!
//! Every filter runs in parallel over points (rayon). The neighbour searches of
//! [`statistical_outlier_removal`] and of the unorganized [`shadow_filter`] use the
//! hashed uniform grid of [`crate::bvh`] (cell size calibrated to the cloud's occupancy),
//! which is much cheaper to build on millions of points than a tree. Its cost
//! grows with the density contrast of the cloud (a depth image is 4x denser at
//! half the distance) and it degrades on many exactly repeated points (thousands
//! at one spot share one cell); downsample such clouds with
//! [`voxel_downsample`] first.
//!
//! Inputs are checked: an empty cloud, a point with a non-finite coordinate, or a
//! parameter out of its domain gives [`crate::Error::InvalidInput`] naming it.

mod crop_box;
mod occlusion;
mod outlier;
mod self_filter;
mod shadow;
mod voxel;

pub use crop_box::crop_box;
pub use occlusion::{Occlusion, Visibility};
pub use outlier::{statistical_outlier_removal, SOR_DEFAULT_K, SOR_DEFAULT_STD_RATIO};
pub use self_filter::{SelfFilter, SELF_FILTER_DEFAULT_PADDING};
pub use shadow::{shadow_filter, ShadowSettings};
pub use voxel::{voxel_downsample, voxel_downsample_with, CovarianceMerge, Voxelized};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::Point3;

/// Checks that a filter's input cloud is non-empty, indexable by `u32` and finite.
pub(crate) fn check_points(filter: &str, points: &[Point3]) -> Result<()> {
    if points.is_empty() {
        return Err(Error::invalid(format!("{filter}: the cloud is empty")));
    }
    if u32::try_from(points.len()).is_err() {
        return Err(Error::invalid(format!(
            "{filter}: {} points is more than the 2^32 - 1 a filter indexes",
            points.len()
        )));
    }
    if let Some(i) = points
        .par_iter()
        .position_first(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(Error::invalid(format!(
            "{filter}: point {i} has a non-finite coordinate ({}, {}, {})",
            points[i].x, points[i].y, points[i].z
        )));
    }
    Ok(())
}
