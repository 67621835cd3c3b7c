//! The two tests that make a group of points a surface element.

use nalgebra::{SMatrix, SVector};

use crate::element::element_types::footprint_cell;
use crate::element::{ElementSettings, FootprintPoint, SurfaceElement};
use crate::math::{Matrix3, Point3, PrincipalAxes, Vector3};
use crate::probability::normal_quantile;
use crate::uncertainty::directional_std_of;
use crate::Real;

/// The `p`-quantile of the chi-square law with `dof` degrees of freedom, by the
/// Wilson–Hilferty cube-root approximation (relative error below 1% for
/// `dof >= 3` and `p` in `[0.5, 0.999]`).
pub fn chi_square_quantile(dof: usize, p: Real) -> Real {
    let k = dof.max(1) as Real;
    let c = 2.0 / (9.0 * k);
    let z = normal_quantile(p);
    k * (1.0 - c + z * c.sqrt()).powi(3).max(0.0)
}

/// What the tests say of a group.
pub(crate) enum Fit {
    /// The group is an element.
    Element(Box<SurfaceElement>),
    /// It is not; split it as the rule says.
    Split(SplitRule),
}

/// How a group that is no element is split in two.
pub(crate) enum SplitRule {
    /// At the median along the axis of largest spread.
    Median { mean: Point3, axis: Vector3 },
    /// The group samples two surfaces and the fitted quadric runs between them:
    /// by the residual from it, below `at` or not.
    TwoSurfaces {
        mean: Point3,
        frame: [Vector3; 3],
        coef: [Real; 6],
        at: Real,
    },
}

impl SplitRule {
    /// For [`SplitRule::TwoSurfaces`], whether `x` is on the lower surface.
    pub(crate) fn is_below(&self, x: &Point3) -> bool {
        match self {
            SplitRule::Median { .. } => false,
            SplitRule::TwoSurfaces {
                mean,
                frame,
                coef,
                at,
            } => {
                let d = x - mean;
                let (u, v, h) = (d.dot(&frame[0]), d.dot(&frame[1]), d.dot(&frame[2]));
                h - quadric_row(u, v).dot(&Vec6::from(*coef)) < *at
            }
        }
    }
}

fn quadric_row(u: Real, v: Real) -> Vec6 {
    Vec6::new(1.0, u, v, u * u, u * v, v * v)
}

type Vec6 = SVector<Real, 6>;
type Mat3 = SMatrix<Real, 3, 3>;

/// Tests the points `idx` of `points` (sensor covariances `sensor`) as one
/// surface element (see [`crate::element`]). `first` is stored in the element.
pub(crate) fn fit_element(
    points: &[Point3],
    sensor: &[Matrix3],
    spacing: &[Real],
    idx: &[u32],
    first: u32,
    settings: &ElementSettings,
) -> Fit {
    let pa = PrincipalAxes::of(idx.iter().map(|&i| points[i as usize]));
    let normal = pa.least();
    let t1 = pa.largest();
    let t2: Vector3 = pa.axes.column(1).into_owned();
    let m = idx.len();
    // A floor under the variances: exact samples (no sensor noise) still have
    // coordinates rounded to double precision.
    let scale = pa.variances[2].sqrt() + pa.mean.coords.amax();
    let floor = (1e-9 * scale).powi(2).max(Real::MIN_POSITIVE);
    let local: Vec<(Real, Real, Real, Real)> = idx
        .iter()
        .map(|&i| {
            let d = points[i as usize] - pa.mean;
            let var = directional_std_of(&sensor[i as usize], &normal)
                .powi(2)
                .max(floor);
            (d.dot(&t1), d.dot(&t2), d.dot(&normal), var)
        })
        .collect();
    let median = || {
        Fit::Split(SplitRule::Median {
            mean: pa.mean,
            axis: t1,
        })
    };
    let confidence = 1.0 - settings.significance;
    if m < settings.min_points {
        return median();
    }
    let Some(f) = weighted_fit(&local, quadric_row) else {
        return median();
    };
    if f.residual > chi_square_quantile(m - 6, confidence) {
        // No smooth surface explains the points: where the residuals fall into
        // two groups, they sample two surfaces (the fit runs between them).
        let residuals: Vec<(Real, Real)> = local
            .iter()
            .map(|&(u, v, h, var)| (h - quadric_row(u, v).dot(&f.coef), var))
            .collect();
        let at = two_surfaces(&residuals).filter(|&t| {
            let below = residuals.iter().filter(|(r, _)| *r < t).count();
            below >= 3 && m - below >= 3
        });
        return match at {
            Some(at) => Fit::Split(SplitRule::TwoSurfaces {
                mean: pa.mean,
                frame: [t1, t2, normal],
                coef: f.coef.into(),
                at,
            }),
            None => median(),
        };
    }
    // The extent stays below the curvature scale: significant curvature splits.
    let curvature = f.coef.fixed_rows::<3>(3).into_owned();
    let cov_curvature: Mat3 = f.cov.fixed_view::<3, 3>(3, 3).into_owned();
    let wald = match cov_curvature.cholesky() {
        Some(c) => curvature.dot(&c.solve(&curvature)),
        None => Real::INFINITY,
    };
    if !wald.is_finite() || wald > chi_square_quantile(3, confidence) {
        return median();
    }
    // Curvature too small to detect: the element's surface is the plane (the
    // quadric's extra coefficients would only add their noise).
    match weighted_fit(&local, plane_row) {
        Some(p) if spans_a_plane(&p) => {
            let e = element(&pa, idx, sensor, spacing, &local, first, settings, &p);
            if covers_its_extent(&e, &local) {
                Fit::Element(Box::new(e))
            } else {
                median()
            }
        }
        _ => median(),
    }
}

/// Whether an element's points cover the surface its extent claims: at least
/// half of the cells of side twice the points' mean sampling spacing over the
/// extent's rectangle hold a point. Two coplanar patches apart (the faces of two
/// objects on one plane, or what a crop or a voxel grid left of them) pass the
/// residual and curvature tests together, but the plane between them was never
/// sampled and must not be probed. A uniformly sampled surface leaves a cell of
/// that side empty with probability about `exp(-24 / pi)`, 0.05 %.
fn covers_its_extent(e: &SurfaceElement, local: &[(Real, Real, Real, Real)]) -> bool {
    let cell = 2.0 * e.spacing;
    if !(cell > 0.0 && cell.is_finite()) {
        return true;
    }
    let cells = |k: usize| ((e.extent[k][1] - e.extent[k][0]) / cell).round().max(1.0);
    let expected = cells(0) * cells(1);
    let mut occupied: Vec<(i32, i32)> = local
        .iter()
        .map(|&(u, v, _, _)| footprint_cell(u, v, cell))
        .collect();
    occupied.sort_unstable();
    occupied.dedup();
    occupied.len() as Real >= 0.5 * expected
}

/// The most points of an element's surface probed in a query.
const MAX_PROBES: usize = 25;

/// A weighted least-squares fit of the heights over the tangent plane.
struct HeightFit<const D: usize> {
    coef: SVector<Real, D>,
    /// Covariance of `coef` (inverse of the weighted normal matrix).
    cov: SMatrix<Real, D, D>,
    /// Weighted residual sum of squares.
    residual: Real,
}

/// Fits `h(u, v) = row(u, v) . coef` to `local` (tangential coordinates, height,
/// variance per point), each point weighted by its inverse variance; `None` when
/// the points do not determine the coefficients (collinear points).
fn weighted_fit<const D: usize>(
    local: &[(Real, Real, Real, Real)],
    row: fn(Real, Real) -> SVector<Real, D>,
) -> Option<HeightFit<D>> {
    let mut normal_matrix = SMatrix::<Real, D, D>::zeros();
    let mut rhs = SVector::<Real, D>::zeros();
    for &(u, v, h, var) in local {
        let x = row(u, v);
        normal_matrix += x * x.transpose() / var;
        rhs += x * (h / var);
    }
    let chol = normal_matrix.cholesky()?;
    let coef = chol.solve(&rhs);
    let residual: Real = local
        .iter()
        .map(|&(u, v, h, var)| (h - row(u, v).dot(&coef)).powi(2) / var)
        .sum();
    residual.is_finite().then(|| HeightFit {
        coef,
        cov: chol.inverse(),
        residual,
    })
}

/// The largest standard deviation of a fitted plane's slope: beyond it the
/// points lie along a line (a strip one sample wide), around which any plane
/// fits, and the plane's normal says nothing.
const MAX_SLOPE_SD: Real = 0.5;

/// Whether a fitted plane's slopes are determined (see [`MAX_SLOPE_SD`]).
fn spans_a_plane(fit: &HeightFit<3>) -> bool {
    fit.cov[(1, 1)].sqrt() <= MAX_SLOPE_SD && fit.cov[(2, 2)].sqrt() <= MAX_SLOPE_SD
}

fn plane_row(u: Real, v: Real) -> SVector<Real, 3> {
    SVector::<Real, 3>::new(1.0, u, v)
}

/// The accepted element: the fitted plane, the covariance of the mean, the
/// surface's range and where it is probed.
fn element(
    pa: &PrincipalAxes,
    idx: &[u32],
    sensor: &[Matrix3],
    spacing: &[Real],
    local: &[(Real, Real, Real, Real)],
    first: u32,
    settings: &ElementSettings,
    fit: &HeightFit<3>,
) -> SurfaceElement {
    let rho = settings.noise_correlation;
    let n = idx.len() as Real;
    let sum_cov: Matrix3 = idx.iter().map(|&i| sensor[i as usize]).sum();
    let cov_mean = sum_cov * ((1.0 - rho) / (n * n) + rho / n);
    let mean_var = local.iter().map(|t| t.3).sum::<Real>() / n;
    // The surface's half width along each tangent from the points' spread: a
    // surface sampled uniformly over `[-e, e]` (each sample standing for its
    // cell) has positional variance `e^2 / 3`, and the noise along the tangent
    // adds its own variance `s^2`, so `e = sqrt(3 (var - s^2))`. Unlike the
    // points' range, it is not pushed out by the outermost noisy points.
    let tangents = [pa.largest(), pa.axes.column(1).into_owned()];
    let range = |k: usize| -> [Real; 2] {
        let noise_var = idx
            .iter()
            .map(|&i| directional_std_of(&sensor[i as usize], &tangents[k]).powi(2))
            .sum::<Real>()
            / n;
        let e = (3.0 * (pa.variances[2 - k] - noise_var).max(0.0)).sqrt();
        [-e, e]
    };
    let extent = [range(0), range(1)];
    // Where the element's surface is probed: at most `MAX_PROBES` of its
    // points' tangential coordinates (the extremes along each tangent, then a
    // stride over the rest), kept inside the extent, so the fitted surface is
    // never extrapolated beyond the points.
    let mut order: Vec<usize> = Vec::with_capacity(MAX_PROBES);
    let extreme = |k: usize, hi: bool| -> usize {
        let key = |t: &(Real, Real, Real, Real)| if k == 0 { t.0 } else { t.1 };
        let cmp = |a: &(usize, &(Real, Real, Real, Real)),
                   b: &(usize, &(Real, Real, Real, Real))| {
            key(a.1).total_cmp(&key(b.1))
        };
        let it = local.iter().enumerate();
        if hi { it.max_by(cmp) } else { it.min_by(cmp) }.map_or(0, |(i, _)| i)
    };
    for (k, hi) in [(0, false), (0, true), (1, false), (1, true)] {
        order.push(extreme(k, hi));
    }
    let stride = local.len().div_ceil(MAX_PROBES - order.len()).max(1);
    order.extend((0..local.len()).step_by(stride));
    order.sort_unstable();
    order.dedup();
    order.truncate(MAX_PROBES);
    let probes = order
        .iter()
        .map(|&i| {
            let clamp = |x: Real, r: [Real; 2]| x.clamp(r[0], r[1]);
            [clamp(local[i].0, extent[0]), clamp(local[i].1, extent[1])]
        })
        .collect();
    let height = fit.coef.into();
    let height_cov = fit.cov * (1.0 - rho);
    // Where the surface was sampled, by cells of one mean spacing.
    let h = idx.iter().map(|&i| spacing[i as usize]).sum::<Real>() / n;
    let mut footprint: Vec<FootprintPoint> = if h > 0.0 {
        local
            .iter()
            .map(|&(u, v, _, _)| {
                let (i, j) = footprint_cell(u, v, h);
                (i, j, u as f32, v as f32)
            })
            .collect()
    } else {
        Vec::new()
    };
    footprint.sort_unstable_by_key(|a| (a.0, a.1));
    SurfaceElement {
        first,
        count: idx.len() as u32,
        mean: pa.mean,
        normal: pa.least(),
        extent,
        probes,
        tangents,
        cov_mean,
        height,
        height_cov,
        common_var: rho * mean_var,
        spacing: h,
        footprint,
    }
}

/// Where the values (residuals, with their variances) fall into two groups
/// that are each as tight as the noise and whose means are more than four noise
/// standard deviations apart, as the two faces of a thin plate do: the value
/// that splits them best (Otsu's rule, the largest between-group variance), or
/// `None`. A surface too curved for its quadric has large residuals too, but not
/// in two tight groups.
fn two_surfaces(values: &[(Real, Real)]) -> Option<Real> {
    let m = values.len();
    if m < 4 {
        return None;
    }
    let mut h: Vec<Real> = values.iter().map(|t| t.0).collect();
    h.sort_by(Real::total_cmp);
    let noise_var = values.iter().map(|t| t.1).sum::<Real>() / m as Real;
    let total: Real = h.iter().sum();
    let total_sq: Real = h.iter().map(|x| x * x).sum();
    let (mut best, mut at) = (0.0, None);
    let mut below = 0.0;
    for k in 1..m {
        below += h[k - 1];
        let (n0, n1) = (k as Real, (m - k) as Real);
        let (mu0, mu1) = (below / n0, (total - below) / n1);
        let between = n0 * n1 * (mu1 - mu0).powi(2);
        if between > best {
            best = between;
            at = Some((k, mu1 - mu0));
        }
    }
    let (k, gap) = at?;
    // Within-group variance: total scatter less the between-group part.
    let m_r = m as Real;
    let within = (total_sq - total * total / m_r - best / m_r) / m_r;
    (gap > 4.0 * noise_var.sqrt() && within <= 4.0 * noise_var).then(|| 0.5 * (h[k - 1] + h[k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_quantiles_match_tables() {
        // Tabulated 0.99 quantiles.
        for (k, q) in [(3, 11.345), (10, 23.209), (50, 76.154), (200, 249.445)] {
            let r = chi_square_quantile(k, 0.99);
            assert!((r - q).abs() / q < 0.01, "{k}: {r} vs {q}");
        }
        assert!((chi_square_quantile(20, 0.5) - 19.337).abs() < 0.05);
    }
}
