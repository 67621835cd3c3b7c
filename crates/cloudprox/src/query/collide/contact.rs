//! Contact regions: a patch's trained surface, per-sample margins and
//! probabilities, and the contact point, normal and separation estimate.

use crate::classify::{train_hinted, Classification, Surface};
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
    /// Per point, whether its constraint supports the surface (empty unless
    /// warm-started, or when the specialized solver did not solve it).
    pub support: Vec<bool>,
}

/// Trains the surface for `pts` (the first `na` from A) and derives the per-point
/// probabilities (Eq. 3), the contact point, normal and separation estimate.
/// The fewest samples a quadric separating surface is trained on.
const MIN_QUADRIC_SAMPLES: usize = 3 * 10;

pub(crate) fn fit_patch(
    pts: &[Point3],
    covs: &[Matrix3],
    na: usize,
    axis: &Vector3,
    spacing: Real,
    sigma: Real,
    request: &CollisionRequest,
    contact: bool,
    warm: Option<&[bool]>,
) -> Result<PatchFit> {
    let labels: Vec<Real> = (0..pts.len())
        .map(|i| if i < na { 1.0 } else { -1.0 })
        .collect();
    // A quadric has ten coefficients: trained on fewer than three samples per
    // coefficient (a few elements' samples) it is free to fold away from the
    // samples and put the surfaces they stand for on the wrong side (two flat
    // faces 1.4 sigma apart, 15 samples: 77% of one face's points across the
    // surface); a plane is trained there instead.
    let mut settings = request.classify;
    if settings.surface == Surface::Quadric && pts.len() < MIN_QUADRIC_SAMPLES {
        settings.surface = Surface::Linear;
    }
    let (classification, support) = train_hinted(pts, covs, &labels, &settings, warm)?;
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
            support,
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
    let frame = AxialFrame::new(axis);
    let (side_a, side_b) = (
        AxialSide::new(&frame, &pts[..na]),
        AxialSide::new(&frame, &pts[na..]),
    );
    let mut scratch = Vec::new();
    let separation = pts
        .iter()
        .step_by(stride)
        .filter_map(|x| {
            let x = frame.coordinates(x);
            let sb = side_b.offset(&x, radius, -1.0, split, &mut scratch)?;
            let sa = side_a.offset(&x, radius, 1.0, split, &mut scratch)?;
            Some(sb - sa)
        })
        .reduce(Real::min)
        .unwrap_or_else(|| {
            let (inf, mid) = (Real::INFINITY, frame.coordinates(&mid));
            side_b
                .offset(&mid, inf, -1.0, split, &mut scratch)
                .unwrap_or(0.0)
                - side_a
                    .offset(&mid, inf, 1.0, split, &mut scratch)
                    .unwrap_or(0.0)
        });
    Ok(PatchFit {
        classification,
        probabilities,
        point,
        normal,
        separation,
        support,
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

/// The mean of the points' coordinates.
pub(crate) fn mean(p: &[Point3]) -> Vector3 {
    p.iter().map(|x| x.coords).sum::<Vector3>() / p.len() as Real
}

/// Coordinates along an axis and across it: `(u, v)` in the plane normal to
/// the axis, then the offset along it.
struct AxialFrame {
    axis: Vector3,
    across: [Vector3; 2],
}

impl AxialFrame {
    fn new(axis: &Vector3) -> Self {
        // Any unit vector not parallel to the axis spans the plane with it.
        let helper = if axis.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = axis.cross(&helper).normalize();
        let v = axis.cross(&u);
        Self {
            axis: *axis,
            across: [u, v],
        }
    }

    fn coordinates(&self, x: &Point3) -> [Real; 3] {
        let c = x.coords;
        [
            c.dot(&self.across[0]),
            c.dot(&self.across[1]),
            c.dot(&self.axis),
        ]
    }
}

/// One side's points in an [`AxialFrame`], sorted by their first coordinate
/// across the axis, so the points near a line along the axis are found in a
/// slab of that coordinate.
struct AxialSide {
    coords: Vec<[Real; 3]>,
}

impl AxialSide {
    fn new(frame: &AxialFrame, pts: &[Point3]) -> Self {
        let mut coords: Vec<[Real; 3]> = pts.iter().map(|x| frame.coordinates(x)).collect();
        coords.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]));
        Self { coords }
    }

    /// Where this side's surface crosses the line through `line` (frame
    /// coordinates) along the axis: among the side's 12 points nearest that
    /// line (within `radius` of it), sorted by their offset along the axis
    /// starting from the end that faces the other cloud (`facing = +1`: the
    /// largest offsets first), the median of the leading run of offsets less
    /// than `split` apart, i.e. of the surface nearest the other cloud; `None`
    /// with fewer than 3 points near the line or 2 in that run. Medians keep
    /// the estimate unbiased by the noise on a flat contact.
    fn offset(
        &self,
        line: &[Real; 3],
        radius: Real,
        facing: Real,
        split: Real,
        by_lateral: &mut Vec<(Real, Real)>,
    ) -> Option<Real> {
        let r2 = radius * radius;
        let lo = self.coords.partition_point(|c| c[0] < line[0] - radius);
        let hi = self.coords.partition_point(|c| c[0] <= line[0] + radius);
        by_lateral.clear();
        by_lateral.extend(self.coords[lo..hi].iter().filter_map(|c| {
            let (du, dv) = (c[0] - line[0], c[1] - line[1]);
            let lat = du * du + dv * dv;
            (lat <= r2).then_some((lat, c[2] - line[2]))
        }));
        if by_lateral.len() < 3 {
            return None;
        }
        let k = 12.min(by_lateral.len());
        by_lateral.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
        let mut along = [0.0; 12];
        for (o, x) in along.iter_mut().zip(&by_lateral[..k]) {
            *o = facing * x.1;
        }
        let along = &mut along[..k];
        along.sort_unstable_by(|a, b| b.total_cmp(a));
        let run = 1 + along.windows(2).take_while(|w| w[0] - w[1] < split).count();
        if run < 2 {
            return None;
        }
        Some(facing * along[run / 2])
    }
}
