//! Contact regions: a patch's trained surface, per-sample margins and
//! probabilities, and the contact point, normal and separation estimate.

use crate::classify::{train, Classification};
use crate::error::Result;
use crate::math::{Matrix3, Point3, Pose, PrincipalAxes, Vector3};
use crate::probability::point_probability;
use crate::query::collide::CollisionRequest;
use crate::Real;

/// A classified patch, in the frame its points were given in.
pub(crate) struct PatchFit {
    pub classification: Classification,
    /// Per-point probabilities (Eq. 3), A's points first.
    pub probabilities: Vec<Real>,
    /// A point on the surface where the two sides come closest.
    pub point: Point3,
    /// The surface's unit normal there, from A towards B.
    pub normal: Vector3,
    /// The separation estimate (see [`crate::query::ContactPatch::separation`]);
    /// not computed (NaN) when `contact` is false.
    pub separation: Real,
}

/// Trains the surface for `pts` (the first `na` from A) and derives the per-point
/// probabilities (Eq. 3), the contact point, normal and separation estimate.
pub(crate) fn fit_patch(
    pts: &[Point3],
    covs: &[Matrix3],
    na: usize,
    axis: &Vector3,
    spacing: Real,
    sigma: Real,
    request: &CollisionRequest,
    contact: bool,
) -> Result<PatchFit> {
    let labels: Vec<Real> = (0..pts.len())
        .map(|i| if i < na { 1.0 } else { -1.0 })
        .collect();
    let classification = train(pts, covs, &labels, &request.classify)?;
    let sep = &classification.separator;
    let mut probabilities = Vec::with_capacity(pts.len());
    let mut margins = Vec::with_capacity(pts.len());
    let form = sep.quadratic_form(&Pose::identity());
    for ((x, cov), &c) in pts.iter().zip(covs).zip(&labels) {
        let (f, g) = form.value_and_gradient(x);
        probabilities.push(point_probability(f, &g, cov, c));
        let gn = g.norm();
        margins.push(if gn > 0.0 { c * f / gn } else { c * f });
    }
    // The contact point: between the point of each side closest to (or deepest
    // across) the surface, projected onto it.
    let deepest = |range: std::ops::Range<usize>| -> Point3 {
        let k = range
            .clone()
            .min_by(|&i, &j| margins[i].total_cmp(&margins[j]))
            .unwrap_or(range.start);
        pts[k]
    };
    let mid = nalgebra::center(&deepest(0..na), &deepest(na..pts.len()));
    let point = sep.project(&mid);
    let (_, g) = sep.value_and_gradient_local(&point);
    let normal = if g.norm() > 0.0 {
        -g.normalize()
    } else {
        (mean(&pts[na..]) - mean(&pts[..na])).normalize()
    };
    if !contact {
        return Ok(PatchFit {
            classification,
            probabilities,
            point,
            normal,
            separation: Real::NAN,
        });
    }
    // The separation is measured along the near region's axis (unlike the trained
    // surface's normal, it stays meaningful when the clouds interpenetrate and the
    // surface cannot separate them), on lines through up to 64 of the patch's
    // points; the smallest is where the surfaces come closest or cross deepest.
    // Only points within two sampling spacings (the patch's median) of a line
    // count for it, and a line needs 3 of each side.
    let radius = 2.0 * spacing;
    // Along a line, one cloud may show several surfaces (both faces of a thin
    // plate): offsets further apart than this belong to different surfaces.
    let split = (4.0 * sigma).max(0.5 * spacing);
    let stride = pts.len().div_ceil(64).max(1);
    let (lines_a, lines_b) = (
        LineIndex::new(&pts[..na], axis, radius),
        LineIndex::new(&pts[na..], axis, radius),
    );
    let separation = pts
        .iter()
        .step_by(stride)
        .filter_map(|x| {
            let sb = axial_offset(lines_b.near_line(x), x, axis, radius, -1.0, split)?;
            let sa = axial_offset(lines_a.near_line(x), x, axis, radius, 1.0, split)?;
            Some(sb - sa)
        })
        .reduce(Real::min)
        .unwrap_or_else(|| {
            let inf = Real::INFINITY;
            axial_offset(pts[na..].iter(), &mid, axis, inf, -1.0, split).unwrap_or(0.0)
                - axial_offset(pts[..na].iter(), &mid, axis, inf, 1.0, split).unwrap_or(0.0)
        });
    Ok(PatchFit {
        classification,
        probabilities,
        point,
        normal,
        separation,
    })
}

/// Unit eigenvector of the smallest eigenvalue of the points' scatter, oriented
/// along `towards`.
pub(crate) fn least_spread_axis(pts: &[Point3], towards: &Vector3) -> Vector3 {
    let axis = PrincipalAxes::of(pts.iter().copied()).least();
    if axis.dot(towards) < 0.0 {
        -axis
    } else {
        axis
    }
}

pub(crate) fn mean(p: &[Point3]) -> Vector3 {
    p.iter().map(|x| x.coords).sum::<Vector3>() / p.len() as Real
}

/// Where one side's surface crosses the line through `point` along `axis`: among
/// the side's 12 points nearest that line (within `radius` of it), sorted by
/// their offset along `axis` starting from the end that faces the other cloud
/// (`facing = +1`: the largest offsets first), the median of the leading run of
/// offsets less than `split` apart, i.e. of the surface nearest the other cloud;
/// `None` with fewer than 3 points near the line or 2 in that run. Medians keep
/// the estimate unbiased by the noise on a flat contact.
fn axial_offset<'a>(
    pts: impl Iterator<Item = &'a Point3>,
    point: &Point3,
    axis: &Vector3,
    radius: Real,
    facing: Real,
    split: Real,
) -> Option<Real> {
    let r2 = radius * radius;
    let mut by_lateral: Vec<(Real, Real)> = pts
        .filter_map(|x| {
            let d = x - point;
            let along = d.dot(axis);
            let lat = (d - axis * along).norm_squared();
            (lat <= r2).then_some((lat, along))
        })
        .collect();
    if by_lateral.len() < 3 {
        return None;
    }
    let k = 12.min(by_lateral.len());
    by_lateral.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
    let mut along: Vec<Real> = by_lateral[..k].iter().map(|x| facing * x.1).collect();
    along.sort_by(|a, b| b.total_cmp(a));
    let run = 1 + along.windows(2).take_while(|w| w[0] - w[1] < split).count();
    if run < 2 {
        return None;
    }
    Some(facing * along[run / 2])
}

/// One side's points binned by their position across an axis, so that the
/// points near a line along the axis are found without a pass over all of
/// them: square cells (a little wider than the search radius) in a plane
/// across the axis, the points sorted by cell so that a column of three cells
/// is one run.
struct LineIndex<'a> {
    pts: &'a [Point3],
    /// Two unit vectors across the axis.
    across: [Vector3; 2],
    /// The cells' width.
    cell: Real,
    /// Point indices sorted by cell, with their cells.
    sorted: Vec<((i64, i64), u32)>,
}

impl<'a> LineIndex<'a> {
    fn new(pts: &'a [Point3], axis: &Vector3, radius: Real) -> Self {
        // Any unit vector not along the axis spans the plane with it.
        let helper = if axis.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1 = axis.cross(&helper).normalize();
        let e2 = axis.cross(&e1);
        // Wider than the radius by more than rounding: a point within the
        // radius of a line lies in the line's cell or a neighbour.
        let cell = radius * (1.0 + 1e-6);
        let mut index = Self {
            pts,
            across: [e1, e2],
            cell,
            sorted: Vec::new(),
        };
        if cell.is_finite() && cell > 0.0 {
            index.sorted = pts
                .iter()
                .enumerate()
                .map(|(k, x)| (index.cell_of(x), k as u32))
                .collect();
            index.sorted.sort_unstable();
        }
        index
    }

    fn cell_of(&self, x: &Point3) -> (i64, i64) {
        let c = |e: &Vector3| (x.coords.dot(e) / self.cell).floor() as i64;
        (c(&self.across[0]), c(&self.across[1]))
    }

    /// Every point within the radius of the line through `x` along the axis,
    /// and some others nearby (all points when the radius is not a positive
    /// finite number).
    fn near_line(&self, x: &Point3) -> impl Iterator<Item = &'a Point3> + '_ {
        let all = self.sorted.is_empty();
        let (ci, cj) = if all { (0, 0) } else { self.cell_of(x) };
        let runs = (-1..=1).map(move |di| {
            if all {
                return if di == 0 { 0..self.pts.len() } else { 0..0 };
            }
            // (Saturating: a cell index saturates for a coordinate far beyond
            // the cell width, and its neighbour must not overflow.)
            let column = ci.saturating_add(di);
            let (first, last) = (
                (column, cj.saturating_sub(1)),
                (column, cj.saturating_add(1)),
            );
            let lo = self.sorted.partition_point(|&(c, _)| c < first);
            let hi = self.sorted.partition_point(|&(c, _)| c <= last);
            lo..hi
        });
        runs.flat_map(move |run| {
            run.map(move |k| {
                let k = if all { k } else { self.sorted[k].1 as usize };
                &self.pts[k]
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point within the radius of a line is among the index's
    /// candidates, for lines through the points and beside them, axes along
    /// and across the coordinate axes.
    #[test]
    fn line_index_finds_every_point_near_a_line() {
        let mut state = 7_u64;
        let mut unit = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as Real / (1u64 << 53) as Real
        };
        let pts: Vec<Point3> = (0..400)
            .map(|_| Point3::new(unit() - 0.5, unit() - 0.5, 0.2 * unit()))
            .collect();
        for axis in [
            Vector3::z(),
            Vector3::x(),
            Vector3::new(0.3, -0.5, 0.8).normalize(),
        ] {
            let radius = 0.07;
            let index = LineIndex::new(&pts, &axis, radius);
            let lines = pts
                .iter()
                .step_by(13)
                .copied()
                .chain([Point3::new(0.6, 0.6, 0.0)]);
            for x in lines {
                // (The points are distinct: found by value.)
                let found: Vec<Point3> = index.near_line(&x).copied().collect();
                for p in &pts {
                    let d = p - x;
                    let lateral = (d - axis * d.dot(&axis)).norm();
                    if lateral <= radius {
                        assert!(found.contains(p), "missed {p}");
                    }
                }
                // Each point at most once.
                let mut keys: Vec<[u64; 3]> = found
                    .iter()
                    .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                    .collect();
                keys.sort_unstable();
                keys.dedup();
                assert_eq!(keys.len(), found.len());
            }
        }
        // Without a finite radius, every point.
        let all = LineIndex::new(&pts, &Vector3::z(), Real::INFINITY);
        assert_eq!(all.near_line(&Point3::origin()).count(), pts.len());
    }
}
