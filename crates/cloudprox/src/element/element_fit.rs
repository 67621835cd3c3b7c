//! The tests and the curvature rule that make a group of points a surface
//! element.

use nalgebra::{SMatrix, SVector};

use crate::element::element_types::footprint_cell;
use crate::element::{ElementSettings, FootprintPoint, SurfaceElement};
use crate::math::{Matrix3, Point3, PrincipalAxes, Vector3};
use crate::probability::normal_quantile;
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

/// The curvature statistic above which a group of at least twice
/// [`ElementSettings::min_points`] splits: `2 x 3`, Mallows' Cp for the
/// quadric's three curvature coefficients.
///
/// With the noise known, the weighted residual sum of the plane exceeds the
/// quadric's by the curvature's Wald statistic `W` (the fits are nested), and
/// each fit's standardized expected squared error over the points is
/// estimated without bias by its residual sum plus twice its coefficient
/// count, less the point count (Mallows' Cp, AIC with known variance): the
/// two estimates differ by `W - 6`. So the plane is estimated to describe the
/// surface at least as well as the quadric while `W <= 6`. A test of significance (`W` against the
/// chi-square quantile, 11.3 at 1%) keeps the plane until curvature is
/// *certain*: it let through sags several times the plane's own stated
/// standard deviation, which the element's uncertainty leaves out, and where
/// element boundaries fell differently in two noise draws their surfaces
/// differed by more than either stated. On the real meshes of
/// `benches/realmesh.py --poses 400` this rule halved the hard flips between
/// noise draws (0.5% noise: 0.50% -> 0.17%; 2%: 1.00% -> 0.50%) and raised
/// the decided accuracy (0.971 -> 0.981, 0.983 -> 0.984). Its price: a flat
/// face's `W` approximately follows the chi-square law with 3 degrees of
/// freedom, above 6 one time in nine, so flat faces are split more often
/// than at 1% (see `docs/architecture.md`).
pub(crate) const CURVATURE_SPLIT: Real = 6.0;

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
    let group = Group {
        points,
        sensor,
        spacing,
        idx,
        first,
        settings,
    };
    group.fit(true)
}

/// The element the points `idx` make, or `None` where [`fit_element`] would
/// split them: the same tests, for a caller that does not split a group
/// that fails (the merge), so the search for two surfaces in a failed
/// group's residuals is left out.
pub(crate) fn element_of(
    points: &[Point3],
    sensor: &[Matrix3],
    spacing: &[Real],
    idx: &[u32],
    first: u32,
    settings: &ElementSettings,
) -> Option<Box<SurfaceElement>> {
    if idx.len() < settings.min_points {
        return None;
    }
    let group = Group {
        points,
        sensor,
        spacing,
        idx,
        first,
        settings,
    };
    match group.fit(false) {
        Fit::Element(e) => Some(e),
        Fit::Split(_) => None,
    }
}

/// A group of points under test, with what the tests read.
struct Group<'a> {
    points: &'a [Point3],
    sensor: &'a [Matrix3],
    spacing: &'a [Real],
    idx: &'a [u32],
    first: u32,
    settings: &'a ElementSettings,
}

/// Tangential coordinates, height and variance along the normal of each point.
type Local = Vec<(Real, Real, Real, Real)>;

impl Group<'_> {
    /// [`fit_element`]; a failed group's split rule is searched for between
    /// two surfaces only when `want_rule`.
    fn fit(&self, want_rule: bool) -> Fit {
        let pa = PrincipalAxes::of(self.idx.iter().map(|&i| self.points[i as usize]));
        let local = self.local(&pa);
        let t1 = pa.largest();
        let median = || {
            Fit::Split(SplitRule::Median {
                mean: pa.mean,
                axis: t1,
            })
        };
        let (m, settings) = (self.idx.len(), self.settings);
        let confidence = 1.0 - settings.significance;
        if m < settings.min_points {
            return median();
        }
        let Some((f, residuals)) = weighted_fit_residuals(&local, quadric_row) else {
            return median();
        };
        if !fits_one_surface(&f, &residuals, m, settings) {
            if !want_rule {
                return median();
            }
            return two_surface_rule(&pa, &f, &residuals).unwrap_or_else(median);
        }
        if !curvature_allows_a_plane(&f, m, settings.min_points, confidence) {
            return median();
        }
        self.planar_element(&pa, &local).unwrap_or_else(median)
    }

    /// Each point's coordinates in the principal frame of `pa`, with its
    /// sensor variance along the normal.
    fn local(&self, pa: &PrincipalAxes) -> Local {
        let normal = pa.least();
        let t1 = pa.largest();
        let t2: Vector3 = pa.axes.column(1).into_owned();
        // A floor under the variances: exact samples (no sensor noise) still have
        // coordinates rounded to double precision.
        let scale = pa.variances[2].sqrt() + pa.mean.coords.amax();
        let floor = (1e-9 * scale).powi(2).max(Real::MIN_POSITIVE);
        self.idx
            .iter()
            .map(|&i| {
                let d = self.points[i as usize] - pa.mean;
                let var = directional_std(&self.sensor[i as usize], &normal)
                    .powi(2)
                    .max(floor);
                (d.dot(&t1), d.dot(&t2), d.dot(&normal), var)
            })
            .collect()
    }

    /// The element of a group that passed the residual test and the
    /// curvature rule, if its plane is determined and its points cover its
    /// extent.
    fn planar_element(&self, pa: &PrincipalAxes, local: &Local) -> Option<Fit> {
        // Curvature small enough that a plane would describe the points about as
        // well: the element stays this size. Its surface is still the quadric
        // (fitted over the element's own tangent axes below): a plane lies outside
        // a convex surface near the element's edges by a fraction of the noise,
        // where two surfaces first meet.
        let p = weighted_fit(local, plane_row).filter(spans_a_plane)?;
        let (t1, t2): (Vector3, Vector3) = (pa.largest(), pa.axes.column(1).into_owned());
        // The tangent axes of the points' tightest bounding rectangle (a
        // square face gets axes along its sides, not along its diagonals).
        let (c, s) = tightest_rectangle_axes(local);
        let local: Local = local
            .iter()
            .map(|&(u, v, h, var)| (c * u + s * v, -s * u + c * v, h, var))
            .collect();
        let tangents = [c * t1 + s * t2, -s * t1 + c * t2];
        let p = p.rotated(c, s);
        let e = element(
            pa,
            self.idx,
            self.sensor,
            self.spacing,
            &local,
            tangents,
            self.first,
            self.settings,
            &p,
        );
        covers_its_extent(&e, &local).then(|| Fit::Element(Box::new(e)))
    }
}

/// Where the residuals of a failed group fall into two groups, they
/// sample two surfaces (the fit runs between them): the rule splitting
/// them.
fn two_surface_rule(
    pa: &PrincipalAxes,
    f: &HeightFit<6>,
    residuals: &[(Real, Real)],
) -> Option<Fit> {
    let m = residuals.len();
    let at = two_surfaces(residuals).filter(|&t| {
        let below = residuals.iter().filter(|(r, _)| *r < t).count();
        below >= 3 && m - below >= 3
    })?;
    let t2: Vector3 = pa.axes.column(1).into_owned();
    Some(Fit::Split(SplitRule::TwoSurfaces {
        mean: pa.mean,
        frame: [pa.largest(), t2, pa.least()],
        coef: f.coef.into(),
        at,
    }))
}

/// The residual test: each point within its own noise, and the weighted
/// residual sum within the chi-square quantile.
///
/// Each point within its own noise too: one point far off a surface that
/// the others fit (a flying pixel, the corner of another face) adds less
/// to the sum than the sum's own spread over hundreds of points, but it
/// samples no part of that surface. The largest standardized residual is
/// tested against the largest of `m` standard normals (a Bonferroni bound
/// at the same significance); the residuals' own variance is below the
/// points', so the test errs towards keeping a group.
fn fits_one_surface(
    f: &HeightFit<6>,
    residuals: &[(Real, Real)],
    m: usize,
    settings: &ElementSettings,
) -> bool {
    let z_max = -normal_quantile(0.5 * settings.significance / m as Real);
    let outlier = residuals
        .iter()
        .any(|&(r, var)| r * r > z_max * z_max * var);
    !(outlier || f.residual > chi_square_quantile(m - 6, 1.0 - settings.significance))
}

/// The curvature rule: the extent stays below the curvature scale, the
/// plane is kept only where it describes the points' surface as well as
/// the quadric is expected to (Mallows' Cp, see [`CURVATURE_SPLIT`]).
fn curvature_allows_a_plane(
    f: &HeightFit<6>,
    m: usize,
    min_points: usize,
    confidence: Real,
) -> bool {
    let curvature = f.coef.fixed_rows::<3>(3).into_owned();
    let cov_curvature: Mat3 = f.cov.fixed_view::<3, 3>(3, 3).into_owned();
    let wald = match cov_curvature.cholesky() {
        Some(c) => curvature.dot(&c.solve(&curvature)),
        None => Real::INFINITY,
    };
    // A group too small for both halves to be elements would leave at least
    // one half as single points, each with its full noise: there only a
    // significant curvature splits it.
    let split_at = if m >= 2 * min_points {
        CURVATURE_SPLIT
    } else {
        chi_square_quantile(3, confidence)
    };
    wald.is_finite() && wald <= split_at
}

/// `sqrt(v^T cov v)`: [`crate::uncertainty::directional_std_of`] written
/// out, the same operations in the same order (nalgebra's `cov * v` sums the
/// columns scaled by `v`'s entries, left to right), for the fits' passes over
/// every point.
fn directional_std(cov: &Matrix3, v: &Vector3) -> Real {
    let r: [Real; 3] =
        std::array::from_fn(|i| cov[(i, 0)] * v[0] + cov[(i, 1)] * v[1] + cov[(i, 2)] * v[2]);
    (v[0] * r[0] + v[1] * r[1] + v[2] * r[2]).max(0.0).sqrt()
}

/// Whether an element's points cover the surface its extent claims: at least
/// half of the cells of side twice the points' mean sampling spacing over the
/// extent's rectangle hold a point, and no strip of empty cells runs across
/// it. Two coplanar patches apart (the faces of two
/// objects on one plane, or what a crop or a voxel grid left of them) pass the
/// residual test and the curvature rule together, but the plane between them was never
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
    // No empty strip across the extent either: the columns (and the rows) of
    // cells that hold a point follow one another.
    let contiguous = |key: fn(&(i32, i32)) -> i32| {
        let mut lines: Vec<i32> = occupied.iter().map(key).collect();
        lines.sort_unstable();
        lines.dedup();
        lines.windows(2).all(|w| w[1] - w[0] <= 1)
    };
    occupied.len() as Real >= 0.5 * expected && contiguous(|c| c.0) && contiguous(|c| c.1)
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
    let (chol, coef) = solve_normal_equations(local, row)?;
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

/// [`weighted_fit`] with each point's residual from the fit and its variance.
fn weighted_fit_residuals<const D: usize>(
    local: &[(Real, Real, Real, Real)],
    row: fn(Real, Real) -> SVector<Real, D>,
) -> Option<(HeightFit<D>, Vec<(Real, Real)>)> {
    let (chol, coef) = solve_normal_equations(local, row)?;
    let residuals: Vec<(Real, Real)> = local
        .iter()
        .map(|&(u, v, h, var)| (h - row(u, v).dot(&coef), var))
        .collect();
    let residual: Real = residuals.iter().map(|&(r, var)| r.powi(2) / var).sum();
    residual.is_finite().then(|| {
        let fit = HeightFit {
            coef,
            cov: chol.inverse(),
            residual,
        };
        (fit, residuals)
    })
}

/// The Cholesky factor of the weighted normal matrix of `local`'s heights
/// over `row` and the coefficients it solves for; `None` when the points do
/// not determine them. (Inlined into each fit: the solve of the
/// triangular factors then unrolls at the fit's size; called, the two took
/// 7% of an element build.)
#[allow(clippy::inline_always)] // measured: see above
#[inline(always)]
fn solve_normal_equations<const D: usize>(
    local: &[(Real, Real, Real, Real)],
    row: fn(Real, Real) -> SVector<Real, D>,
) -> Option<(
    nalgebra::Cholesky<Real, nalgebra::Const<D>>,
    SVector<Real, D>,
)> {
    let mut normal_matrix = SMatrix::<Real, D, D>::zeros();
    let mut rhs = SVector::<Real, D>::zeros();
    for &(u, v, h, var) in local {
        let x = row(u, v);
        normal_matrix += x * x.transpose() / var;
        rhs += x * (h / var);
    }
    let chol = normal_matrix.cholesky()?;
    let coef = chol.solve(&rhs);
    Some((chol, coef))
}

/// The largest standard deviation of a fitted plane's slope: beyond it the
/// points lie along a line (a strip one sample wide), around which any plane
/// fits, and the plane's normal says nothing.
const MAX_SLOPE_SD: Real = 0.5;

impl HeightFit<3> {
    /// The plane's fit in tangent axes turned by the angle of cosine `c` and
    /// sine `s` (`u' = c u + s v`, `v' = -s u + c v`).
    fn rotated(&self, c: Real, s: Real) -> Self {
        let j = SMatrix::<Real, 3, 3>::new(1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c);
        Self {
            coef: j * self.coef,
            cov: j * self.cov * j.transpose(),
            residual: self.residual,
        }
    }
}

/// The direction `(cos, sin)`, in the tangential coordinates of `local`, of
/// the longer side of the smallest-area rectangle holding the points (its
/// sides run along an edge of their convex hull). Principal axes are the
/// directions of largest and smallest spread, which a square or a disc leaves
/// to the noise: a square's may run along its diagonals, where a rectangle
/// summary would claim corners outside the face. `(1, 0)` for fewer than three
/// points in general position.
fn tightest_rectangle_axes(local: &[(Real, Real, Real, Real)]) -> (Real, Real) {
    let hull = convex_hull_2d(local.iter().map(|t| (t.0, t.1)).collect());
    let mut best = (Real::INFINITY, (1.0, 0.0));
    for k in 0..hull.len() {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = dx.hypot(dy);
        if len <= 0.0 || !len.is_finite() {
            continue;
        }
        let (c, s) = (dx / len, dy / len);
        let (mut lo, mut hi) = ([Real::INFINITY; 2], [Real::NEG_INFINITY; 2]);
        for &(u, v) in &hull {
            let q = [c * u + s * v, -s * u + c * v];
            for i in 0..2 {
                lo[i] = lo[i].min(q[i]);
                hi[i] = hi[i].max(q[i]);
            }
        }
        let (wu, wv) = (hi[0] - lo[0], hi[1] - lo[1]);
        if wu * wv < best.0 {
            // The longer side first.
            best = (wu * wv, if wu >= wv { (c, s) } else { (-s, c) });
        }
    }
    best.1
}

/// The convex hull of `pts` in counter-clockwise order (Andrew's monotone
/// chain), without collinear points.
fn convex_hull_2d(mut pts: Vec<(Real, Real)>) -> Vec<(Real, Real)> {
    // (Unstable: points equal in this order are the same point.)
    pts.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut lower = half_hull(pts.iter());
    let mut upper = half_hull(pts.iter().rev());
    // Each chain ends where the other starts.
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

/// One chain of [`convex_hull_2d`]: the points in order, keeping left turns.
fn half_hull<'a>(pts: impl Iterator<Item = &'a (Real, Real)>) -> Vec<(Real, Real)> {
    let cross = |o: (Real, Real), a: (Real, Real), b: (Real, Real)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut chain: Vec<(Real, Real)> = Vec::new();
    for &p in pts {
        while chain.len() >= 2 && cross(chain[chain.len() - 2], chain[chain.len() - 1], p) <= 0.0 {
            chain.pop();
        }
        chain.push(p);
    }
    chain
}

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
    tangents: [Vector3; 2],
    first: u32,
    settings: &ElementSettings,
    fit: &HeightFit<3>,
) -> SurfaceElement {
    let rho = settings.noise_correlation;
    let n = idx.len() as Real;
    let sum_cov: Matrix3 = idx.iter().map(|&i| sensor[i as usize]).sum();
    let cov_mean = sum_cov * ((1.0 - rho) / (n * n) + rho / n);
    let mean_var = local.iter().map(|t| t.3).sum::<Real>() / n;
    // The surface's range along each tangent: where its sampled edges are,
    // read from the points with their noise taken out (see `sampled_edges`).
    let range = |k: usize| -> [Real; 2] {
        let noise_var = idx
            .iter()
            .map(|&i| directional_std(&sensor[i as usize], &tangents[k]).powi(2))
            .sum::<Real>()
            / n;
        let mut along: Vec<Real> = local
            .iter()
            .map(|t| if k == 0 { t.0 } else { t.1 })
            .collect();
        sampled_edges(&mut along, noise_var.sqrt())
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
    // The surface is the quadric over the element's own tangent axes (the
    // plane where the points do not determine one: then its curvature terms
    // are 0 and certain).
    let quadric = weighted_fit(local, quadric_row)
        .map(|q| lateral_noise_corrected(&q, idx, sensor, &tangents))
        .filter(|(coef, cov)| curvature_matters(fit, coef, cov, &extent));
    let (height, height_cov) = if let Some((coef, cov)) = quadric {
        (coef.into(), cov * (1.0 - rho))
    } else {
        let mut coef = [0.0; 6];
        coef[..3].copy_from_slice(fit.coef.as_slice());
        let mut cov = SMatrix::<Real, 6, 6>::zeros();
        cov.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(fit.cov * (1.0 - rho)));
        (coef, cov)
    };
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

/// Whether an element's surface is better read as the quadric `(coef, cov)`
/// than as the plane `plane` where two surfaces first meet, at the corners of
/// its extent: there the plane's sag `d = q - p` is largest. The quadric reads
/// the surface without that bias and with the variance `var(q) - var(p)` more
/// (the fits are nested); the plane's expected squared error exceeds the
/// quadric's where `d^2 - var(d) > var(d)` (the local form of Mallows' Cp,
/// with `d^2 - var(d)` estimating the squared bias). A flat face keeps its plane (its
/// `d` is noise: one corner in six reads above twice its variance by chance),
/// a curved patch takes the quadric.
const QUADRIC_AT: Real = 2.0;

fn curvature_matters(
    plane: &HeightFit<3>,
    coef: &Vec6,
    cov: &SMatrix<Real, 6, 6>,
    extent: &[[Real; 2]; 2],
) -> bool {
    let [[u0, u1], [v0, v1]] = *extent;
    [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
        .iter()
        .any(|&(u, v)| {
            let (q, p) = (quadric_row(u, v), plane_row(u, v));
            let d = q.dot(coef) - p.dot(&plane.coef);
            let var = q.dot(&(cov * q)) - p.dot(&(plane.cov * p));
            d * d > QUADRIC_AT * var.max(0.0)
        })
}

/// The quadric `fit` of points whose noise also moves them along the surface
/// (covariances `sensor` of the points `idx`, tangents `tangents`), corrected
/// for that: a point moved by `(du, dv)` along a curved surface lies off it by
/// the surface's rise there, so the points' heights over the surface average
/// `c_uu s_uu + c_uv s_uv + c_vv s_vv` more than the surface's own (`c` the
/// quadric's curvature coefficients, `s` the points' mean covariance along
/// the tangents): a convex surface is read that much outside itself. The
/// constant term is lowered by it, and the covariance of the coefficients
/// carries the correction's uncertainty (it is linear in the curvature).
fn lateral_noise_corrected(
    fit: &HeightFit<6>,
    idx: &[u32],
    sensor: &[Matrix3],
    tangents: &[Vector3; 2],
) -> (Vec6, SMatrix<Real, 6, 6>) {
    let n = idx.len() as Real;
    let along = |a: &Vector3, b: &Vector3| {
        idx.iter()
            .map(|&i| a.dot(&(sensor[i as usize] * b)))
            .sum::<Real>()
            / n
    };
    let [t1, t2] = tangents;
    let mut m = SMatrix::<Real, 6, 6>::identity();
    m[(0, 3)] = -along(t1, t1);
    m[(0, 4)] = -along(t1, t2);
    m[(0, 5)] = -along(t2, t2);
    (m * fit.coef, m * fit.cov * m.transpose())
}

/// Where a surface sampled at the tangential coordinates `along` (noisy,
/// with noise standard deviation `s` along the tangent) has its edges.
///
/// Without noise, the outermost points. With it, the points near an edge are
/// smeared across it: a surface sampled at density `rho` (points per unit
/// length of the tangent) up to an edge puts `rho s / sqrt(2 pi)` of its points
/// beyond it on average (the integral of the normal tail). The edge is read as
/// the point past which as many points lie as that predicts, `rho` counted in
/// the window of `2 s` inside it (where the smear leaves about 0.8 of the
/// density: `1 - (1/2) int_0^2 (1 - Phi(z)) dz`), so `m ≈ c / (0.8 * 2 *
/// sqrt(2 pi)) ≈ c / 4` points beyond for `c` points in the window. Unlike the
/// points' spread (`var = e^2 / 3` for a uniform sampling of `[-e, e]`), it
/// follows the density near each edge: a floor seen at a grazing angle has its
/// points bunched towards the camera and its noise running along the rays,
/// nearly in the floor's plane, and a spread estimate covers a fraction of it.
/// Unlike the outermost points, it is not pushed out by the noise (by about
/// `s sqrt(2 ln n)`). Sorts `along`.
fn sampled_edges(along: &mut [Real], s: Real) -> [Real; 2] {
    along.sort_unstable_by(Real::total_cmp);
    let hi = upper_edge(along, s);
    along.reverse();
    for x in along.iter_mut() {
        *x = -*x;
    }
    let lo = -upper_edge(along, s);
    [lo.min(hi), hi.max(lo)]
}

/// Points beyond a sampled edge per point in the window of `2 s` inside it
/// (see [`sampled_edges`]).
const BEYOND_PER_WINDOW_POINT: Real = 0.25;

/// The upper edge of [`sampled_edges`] over ascending `sorted`: the point with
/// the fewest points `m` beyond it such that `m >= c / 4 - 1/2`, `c` the points
/// in the window `(edge - 2 s, edge]`. `0` for no points.
fn upper_edge(sorted: &[Real], s: Real) -> Real {
    let n = sorted.len();
    if n == 0 {
        return 0.0;
    }
    let window = 2.0 * s;
    // `low`: the first index inside the window of the current edge; it only
    // moves down as the edge does.
    let mut low = n - 1;
    for m in 0..n {
        let top = n - 1 - m;
        let edge = sorted[top];
        low = low.min(top);
        while low > 0 && sorted[low - 1] > edge - window {
            low -= 1;
        }
        let c = (top + 1 - low) as Real;
        if m as Real >= BEYOND_PER_WINDOW_POINT * c - 0.5 {
            return edge;
        }
    }
    sorted[0]
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
    h.sort_unstable_by(Real::total_cmp);
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
    use crate::cloud::PointCloud;
    use crate::sample::NormalRng;
    use crate::uncertainty::directional_std_of;

    /// The written-out directional standard deviation is the library's,
    /// bit for bit, on random covariances and directions.
    #[test]
    fn directional_std_is_directional_std_of_bit_for_bit() {
        let mut rng = NormalRng::new(5);
        for _ in 0..2000 {
            let a = Matrix3::from_fn(|_, _| rng.normal() * 1e-3);
            let cov = a * a.transpose();
            let v = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            let (got, want) = (directional_std(&cov, &v), directional_std_of(&cov, &v));
            assert_eq!(got.to_bits(), want.to_bits(), "{cov} {v}");
        }
    }

    /// [`element_of`] gives the element [`fit_element`] does, and `None`
    /// where it splits: on the halves, quarters and unions of neighbouring
    /// groups of a noisy box (faces, edges, corners and too-small groups).
    #[test]
    fn element_of_agrees_with_fit_element() {
        let mut rng = NormalRng::new(7);
        let sigma = 0.002;
        let mut points = Vec::new();
        for axis in 0..3 {
            for side in [0.0, 1.0] {
                for _ in 0..400 {
                    let x: [Real; 3] = std::array::from_fn(|a| {
                        let t = if a == axis { side } else { rng.uniform() };
                        0.3 * t + sigma * rng.normal()
                    });
                    points.push(Point3::from(x));
                }
            }
        }
        let cloud = PointCloud::from_sigma(points, sigma).expect("finite points");
        let (p, sensor, spacing) = (cloud.points(), cloud.sensor_covariances(), cloud.spacing());
        let settings = ElementSettings::default();
        let mut order: Vec<u32> = (0..p.len() as u32).collect();
        order.sort_by(|&a, &b| p[a as usize].x.total_cmp(&p[b as usize].x));
        let (mut elements, mut splits) = (0, 0);
        for size in [4, 12, 40, 150, 600] {
            for run in order.chunks(size) {
                let fit = fit_element(p, sensor, spacing, run, 3, &settings);
                match (fit, element_of(p, sensor, spacing, run, 3, &settings)) {
                    (Fit::Element(a), Some(b)) => {
                        assert_eq!(a, b);
                        elements += 1;
                    }
                    (Fit::Split(_), None) => splits += 1,
                    _ => panic!("the two disagree on a group of {}", run.len()),
                }
            }
        }
        assert!(elements > 0 && splits > 0, "{elements} {splits}");
    }

    #[test]
    fn sampled_edges_take_the_noise_out_of_the_range() {
        // Without noise: the outermost points.
        let mut exact: Vec<Real> = (0..=20).map(|i| Real::from(i) * 0.1 - 1.0).collect();
        let [lo, hi] = sampled_edges(&mut exact, 0.0);
        assert!((lo + 1.0).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12);
        // A dense uniform sampling of [-1, 2] with noise 0.05: the outermost
        // points lie about 0.05 sqrt(2 ln n) = 0.2 beyond the edges; the edges
        // are read within a fifth of that.
        let mut rng = NormalRng::new(3);
        let s = 0.05;
        let mut along: Vec<Real> = (0..4000)
            .map(|_| -1.0 + 3.0 * rng.uniform() + s * rng.normal())
            .collect();
        let (min, max) = along
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        assert!(min < -1.1 && max > 2.1, "{min} {max}");
        let [lo, hi] = sampled_edges(&mut along, s);
        assert!(
            (lo + 1.0).abs() < 0.04 && (hi - 2.0).abs() < 0.04,
            "{lo} {hi}"
        );
        // A density falling to the far edge (a floor seen at a grazing angle):
        // the far edge is still found, where a spread estimate
        // (`sqrt(3 (var - s^2))` about the mean) stops short of it.
        let mut along: Vec<Real> = (0..4000)
            .map(|_| 2.0 * (1.0 - rng.uniform().sqrt()) + s * rng.normal())
            .collect();
        let n = along.len() as Real;
        let mean = along.iter().sum::<Real>() / n;
        let var = along.iter().map(|x| (x - mean).powi(2)).sum::<Real>() / n;
        let spread_hi = mean + (3.0 * (var - s * s)).sqrt();
        let [lo, hi] = sampled_edges(&mut along, s);
        assert!(lo.abs() < 0.04 && (hi - 2.0).abs() < 0.15, "{lo} {hi}");
        assert!(spread_hi < 1.7, "{spread_hi}");
    }

    #[test]
    fn the_tightest_rectangle_runs_along_a_squares_sides() {
        for deg in [0.0, 30.0, 45.0, 80.0] {
            let t: Real = Real::to_radians(deg);
            let local: Vec<(Real, Real, Real, Real)> = (0..144)
                .map(|k| {
                    let (x, y) = (Real::from(k / 12) - 5.5, Real::from(k % 12) - 5.5);
                    (
                        t.cos() * x - t.sin() * y,
                        t.sin() * x + t.cos() * y,
                        0.0,
                        1.0,
                    )
                })
                .collect();
            let (c, s) = tightest_rectangle_axes(&local);
            // A side's direction, up to quarter turns.
            let off = (s.atan2(c) - t).rem_euclid(std::f64::consts::FRAC_PI_2);
            let off = off.min(std::f64::consts::FRAC_PI_2 - off);
            assert!(off < 1e-9, "{deg}: off by {off}");
        }
        // A 3 x 1 strip: the longer side first.
        let local: Vec<(Real, Real, Real, Real)> = (0..40)
            .map(|k| (Real::from(k % 4) * 0.1, Real::from(k / 4) * 0.3, 0.0, 1.0))
            .collect();
        let (c, s) = tightest_rectangle_axes(&local);
        assert!(c.abs() < 1e-9 && (s.abs() - 1.0).abs() < 1e-9, "{c} {s}");
    }

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
