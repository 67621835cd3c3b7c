//! Crop box: keep the points inside (or outside) an oriented box.

use rayon::prelude::*;

use super::check_points;
use crate::error::{Error, Result};
use crate::math::{Point3, Pose};

/// Checks that a pose has finite rotation and translation.
pub(crate) fn check_pose(what: &str, pose: &Pose) -> Result<()> {
    let t = &pose.translation.vector;
    let q = pose.rotation.quaternion();
    if t.iter().chain(q.coords.iter()).all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(Error::invalid(format!("{what} has a non-finite entry")))
    }
}

/// The indices (ascending) of the points inside the box `[min, max]` given in
/// the box's frame, whose pose in the cloud's frame is `pose`; with `invert`, the
/// indices of the points outside it instead.
///
/// Rule (PCL `pcl::CropBox`, with its `setTransform` pose and `setNegative` as
/// `invert`): a point `p` is inside iff `min <= pose⁻¹ · p <= max` on every axis,
/// bounds included. There are no defaults; `Pose::identity()` gives an
/// axis-aligned box in the cloud's frame.
///
/// Runs in parallel over points (a few milliseconds per million points).
///
/// # Errors
/// [`Error::InvalidInput`] if the cloud is empty or has a non-finite point, if
/// `min` or `max` has a non-finite coordinate, if `min` is above `max` on an
/// axis (a flat box, `min == max` on an axis, is allowed), or if `pose` is not
/// finite.
pub fn crop_box(
    points: &[Point3],
    min: &Point3,
    max: &Point3,
    pose: &Pose,
    invert: bool,
) -> Result<Vec<u32>> {
    check_points("crop_box", points)?;
    for (name, c) in [("min", min), ("max", max)] {
        if !c.coords.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(format!(
                "crop_box: {name} corner ({}, {}, {}) is not finite",
                c.x, c.y, c.z
            )));
        }
    }
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        if min[a] > max[a] {
            return Err(Error::invalid(format!(
                "crop_box: min corner is above max corner on {axis} ({} > {})",
                min[a], max[a]
            )));
        }
    }
    check_pose("crop_box: pose", pose)?;
    let inverse = pose.inverse();
    let (min, max) = (*min, *max);
    Ok(points
        .par_iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let l = inverse * p;
            let inside = (0..3).all(|a| l[a] >= min[a] && l[a] <= max[a]);
            (inside != invert).then_some(i as u32)
        })
        .collect())
}
