//! Shadow (veil) filter: remove mixed pixels at depth discontinuities.

use rayon::prelude::*;

use super::check_points;
use crate::bvh::for_each_knn;
use crate::error::{Error, Result};
use crate::io::Grid;
use crate::math::{Point3, Vector3};

/// Settings of [`shadow_filter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowSettings {
    /// The smallest angle (radians) allowed between a point's viewing ray and the
    /// direction to a neighbour; a neighbour seen at less than `min_angle` or more
    /// than `π - min_angle` removes the point. Default 10° (ROS `laser_filters`
    /// `ScanShadowsFilter`: `min_angle` 10°, `max_angle` 170°). Must be in
    /// `(0, π/2)`.
    pub min_angle: f64,
    /// Organized clouds: the neighbours of a pixel are the pixels at most
    /// `window` rows and columns away (`(2 window + 1)² - 1` of them). Default 1
    /// (ROS `neighbors`/`window` 1). Must be at least 1.
    pub window: usize,
    /// Unorganized clouds: the number of neighbours in viewing direction
    /// examined. Default 8 (the 3x3 pixel window of an organized cloud). Must be
    /// at least 1.
    pub k: usize,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            min_angle: 10f64.to_radians(),
            window: 1,
            k: 8,
        }
    }
}

impl ShadowSettings {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the field out of its domain.
    pub fn validate(&self) -> Result<()> {
        if !(self.min_angle.is_finite()
            && self.min_angle > 0.0
            && self.min_angle < std::f64::consts::FRAC_PI_2)
        {
            return Err(Error::invalid(format!(
                "shadow_filter: min_angle must be in (0, pi/2) radians, got {}",
                self.min_angle
            )));
        }
        if self.window == 0 {
            return Err(Error::invalid("shadow_filter: window must be at least 1"));
        }
        if self.k == 0 {
            return Err(Error::invalid("shadow_filter: k must be at least 1"));
        }
        Ok(())
    }
}

/// Whether `p` (viewing ray `ray = p - origin`) sees `q` along its ray.
fn along_ray(p: &Point3, ray: &Vector3, ray_norm: f64, q: &Point3, cos_max: f64) -> bool {
    let d = q - p;
    let dn = d.norm();
    dn > 0.0 && ray.dot(&d).abs() > cos_max * ray_norm * dn
}

/// The indices (ascending) of the points kept by the shadow (veil) filter.
///
/// A depth sensor gives "veil" or "shadow" points (mixed pixels) at depth
/// discontinuities: a pixel straddling a foreground edge and the background
/// reads a depth in between, so the points trail away from the edge along the
/// viewing rays. Rule (ROS `laser_filters` `ScanShadowsFilter`, the PR2
/// pipeline's shadow filter, extended from a scan line to an image): for point
/// `p` and each neighbour `q`, `θ` is the angle between the viewing ray
/// `p - origin` and `q - p`; `p` is removed when, for some neighbour, `θ <
/// min_angle` or `θ > π - min_angle`. The neighbours are the image pixels within
/// `settings.window` of `p`'s pixel when `grid` is given (organized cloud: the
/// pixel of point `i` is `grid.pixels[i]`), else the `settings.k` points nearest
/// to it *in viewing direction* (the nearest unit vectors `(q - origin)/|q -
/// origin|`: its pixels in a virtual image taken from `origin`; Euclidean
/// neighbours would not do, as a veil is a curtain of points along the rays,
/// dense along the edge and sparse across it).
/// `origin` is the sensor's position in the cloud's frame. Defaults: see
/// [`ShadowSettings`] (10°, window 1, k 8).
///
/// Trade-off: the rule cannot tell a veil from a real surface seen at a grazing
/// angle (a floor far ahead, a wall nearly parallel to the rays): that surface
/// also runs along the rays, and its points are removed when the angle between
/// surface and ray is under `min_angle`. A larger `min_angle` removes veils more
/// completely but eats more grazing surfaces; about 10° is the usual compromise
/// (such points also have the worst depth noise). The foreground and background
/// points right next to a veil are removed with it (their neighbour, the veil
/// point, lies along their ray), as in ROS. Points at the origin are kept.
///
/// # Errors
/// [`Error::InvalidInput`] if the cloud is empty or has a non-finite point, if
/// `origin` is not finite, if a setting is out of its domain
/// ([`ShadowSettings::validate`]), if the grid's `width × height` is zero or
/// too large, or a pixel is outside the image or repeated; [`Error::Shape`] if
/// the grid does not have one pixel per point.
pub fn shadow_filter(
    points: &[Point3],
    origin: &Point3,
    grid: Option<&Grid>,
    settings: &ShadowSettings,
) -> Result<Vec<u32>> {
    check_points("shadow_filter", points)?;
    settings.validate()?;
    if !origin.coords.iter().all(|c| c.is_finite()) {
        return Err(Error::invalid("shadow_filter: origin is not finite"));
    }
    let cos_max = settings.min_angle.cos();
    let origin = *origin;
    let removed: Vec<bool> = if let Some(grid) = grid {
        organized(points, &origin, grid, settings.window, cos_max)?
    } else {
        // Neighbours in viewing direction: the pixels around a point in a
        // virtual image taken from the origin.
        let directions: Vec<Point3> = points
            .par_iter()
            .map(|p| {
                let ray = p - origin;
                let n = ray.norm();
                if n > 0.0 {
                    Point3::from(ray / n)
                } else {
                    Point3::origin()
                }
            })
            .collect();
        for_each_knn(&directions, settings.k, |i, nb| {
            let p = &points[i];
            let ray = p - origin;
            let ray_norm = ray.norm();
            ray_norm > 0.0
                && nb
                    .iter()
                    .any(|&(_, j)| along_ray(p, &ray, ray_norm, &points[j as usize], cos_max))
        })
    };
    Ok(removed
        .par_iter()
        .enumerate()
        .filter_map(|(i, &r)| (!r).then_some(i as u32))
        .collect())
}

fn organized(
    points: &[Point3],
    origin: &Point3,
    grid: &Grid,
    window: usize,
    cos_max: f64,
) -> Result<Vec<bool>> {
    if grid.pixels.len() != points.len() {
        return Err(Error::Shape {
            what: "shadow_filter: grid pixels (one per point)".into(),
            expected: points.len(),
            got: grid.pixels.len(),
        });
    }
    let (w, h) = (grid.width, grid.height);
    let size = w
        .checked_mul(h)
        .filter(|&s| s > 0 && u32::try_from(s).is_ok())
        .ok_or_else(|| {
            Error::invalid(format!(
                "shadow_filter: grid {w} x {h} must have between 1 and 2^32 - 1 pixels"
            ))
        })?;
    let mut image = vec![u32::MAX; size];
    for (i, &px) in grid.pixels.iter().enumerate() {
        let slot = image.get_mut(px as usize).ok_or_else(|| {
            Error::invalid(format!(
                "shadow_filter: pixel {px} of point {i} is outside the {w} x {h} image"
            ))
        })?;
        if *slot != u32::MAX {
            return Err(Error::invalid(format!(
                "shadow_filter: pixel {px} is given to points {} and {i}",
                *slot
            )));
        }
        *slot = i as u32;
    }
    let win = window.min(w.max(h));
    Ok(points
        .par_iter()
        .zip(grid.pixels.par_iter())
        .map(|(p, &px)| {
            let ray = p - origin;
            let ray_norm = ray.norm();
            if ray_norm == 0.0 {
                return false;
            }
            let (row, col) = (px as usize / w, px as usize % w);
            for r in row.saturating_sub(win)..=(row + win).min(h - 1) {
                for c in col.saturating_sub(win)..=(col + win).min(w - 1) {
                    if r == row && c == col {
                        continue;
                    }
                    let j = image[r * w + c];
                    if j != u32::MAX && along_ray(p, &ray, ray_norm, &points[j as usize], cos_max) {
                        return true;
                    }
                }
            }
            false
        })
        .collect())
}
