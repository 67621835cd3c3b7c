//! Where two sampled surfaces cross: the evidence a separating surface misses.
//!
//! Near a crossing of two surfaces the points within the noise's reach of the
//! other cloud form a band along the crossing line, half on each side of the
//! other surface, and a separator can often be bent through the band; the
//! points that show the crossing (past it, inside the other object) lie beyond
//! the noise's reach. This test looks at the geometry instead: around a point of
//! one cloud it fits the other cloud's local plane and asks whether the point's
//! own neighbourhood lies on *both* sides of it, beyond the noise. Two touching
//! surfaces (tangent, or an edge on a face) keep one side; two crossing surfaces
//! do not.

use crate::bvh::{Neighbourhoods, PointSearch};
use crate::math::{Matrix3, Point3, PrincipalAxes, Vector3};
use crate::probability::{normal_cdf, NEIGHBOURHOOD};
use crate::uncertainty::{directional_std_of, max_std};
use crate::Real;

/// Fewest points of the other cloud that define a local plane.
const MIN_PLANE_POINTS: usize = 6;
/// The other cloud's local points must be this flat: their standard deviation
/// along the plane's normal at most this many times the noise along it (an
/// edge or a corner is not a plane).
const MAX_THICKNESS: Real = 1.5;
/// A plane spreads in its second direction at least this many times its
/// thickness and the noise (standard deviations): a line of points is no plane.
const MIN_SPREAD: Real = 2.0;
/// Radius of the other cloud's neighbourhood, in standard deviations of the
/// pair's noise (at least the distance to the 6th nearest own point: the own
/// neighbourhood is the point and its 6 nearest, [`NEIGHBOURHOOD`]).
const RADIUS_SIGMAS: Real = 4.0;

/// The probability, per point of `own`, that the surface sampled by `own`
/// crosses the surface sampled by `other` there (both clouds in one frame, with
/// their covariances).
///
/// For a point `x`: its own neighbourhood is `x` and its 6 nearest `own`
/// points; the other cloud's is its points within `r = max(d_6, 4 s)` of `x`
/// (`d_6` the distance to the 6th nearest own point, `s` the largest noise
/// standard deviation of either cloud within `d_6`). The other points give a
/// plane by principal components when there are at least 6 and they are flat:
/// thickness along the normal at most 1.5 times their noise along it, spread in
/// the second direction at least twice the thickness and the noise (a line of
/// points is no plane). Each own neighbour `y` that lies over the other surface
/// (its projection within one spacing plus `s` of a projected other point) has
/// the offset `o = n . (y - c)` in units of `s_y = sqrt(n^T Sigma_y n +
/// sigma_plane^2)`. With `u` the largest offset on one side and `l` on the
/// other, the surface is above the plane with probability at least
/// `1 - m Phi(-u)` (a union bound over the `m` neighbours, as the largest of `m`
/// noisy offsets is selected) and below it with `1 - m Phi(-l)`; the product
/// (clamped at 0) is returned. Points without a flat enough other neighbourhood
/// get 0.
///
/// The neighbourhoods come from a hierarchy over each cloud (the same points a
/// scan over all of them finds: the cost grows with the neighbourhoods, not
/// with the clouds' sizes).
///
/// # Panics
///
/// If a covariance slice is shorter than its points.
pub fn crossing_probabilities(
    own: &[Point3],
    own_cov: &[Matrix3],
    other: &[Point3],
    other_cov: &[Matrix3],
) -> Vec<Real> {
    if own.is_empty() || other.len() < MIN_PLANE_POINTS {
        return vec![0.0; own.len()];
    }
    let std = |c: &[Matrix3], n: usize| c[..n].iter().map(max_std).collect::<Vec<Real>>();
    let (own_std, other_std) = (std(own_cov, own.len()), std(other_cov, other.len()));
    let own_search = PointSearch::new(own);
    let near = own_search.neighbourhoods(NEIGHBOURHOOD);
    crossing_probabilities_in(
        (&own_search, own_cov, &own_std),
        &near,
        (&PointSearch::new(other), other_cov, &other_std),
    )
}

/// One side of [`crossing_probabilities_in`]: its search, covariances and
/// largest standard deviations ([`max_std`]), point by point.
pub(crate) type CrossingSide<'s, 'a> = (&'s PointSearch<'a>, &'s [Matrix3], &'s [Real]);

/// [`crossing_probabilities`] with the clouds' searches, their points'
/// largest deviations and the own points' neighbourhoods (of
/// [`NEIGHBOURHOOD`] points) made by the caller, who may use them for more
/// (the surface probabilities of the same points).
pub(crate) fn crossing_probabilities_in(
    own: CrossingSide<'_, '_>,
    near: &Neighbourhoods,
    other: CrossingSide<'_, '_>,
) -> Vec<Real> {
    let ((own, own_cov, own_std), (other, other_cov, other_std)) = (own, other);
    let (own_pts, other_pts) = (own.points(), other.points());
    if own_pts.is_empty() || other_pts.len() < MIN_PLANE_POINTS {
        return vec![0.0; own_pts.len()];
    }
    let mut within: Vec<u32> = Vec::new();
    let mut near_other: Vec<u32> = Vec::new();
    let mut projected: Vec<Point3> = Vec::new();
    own_pts
        .iter()
        .enumerate()
        .map(|(i, x)| {
            // The scale: the distance to the 6th nearest own point, or 4 noise
            // standard deviations of the pair, whichever is larger.
            let d_k = near.radius(i);
            let mut noise_at = |search: &PointSearch<'_>, std: &[Real]| {
                search.within(x, d_k, &mut within);
                within.iter().map(|&j| std[j as usize]).fold(0.0, Real::max)
            };
            let noise = noise_at(own, own_std).max(noise_at(other, other_std));
            let r = d_k.max(RADIUS_SIGMAS * noise);
            other.within(x, r, &mut near_other);
            if near_other.len() < MIN_PLANE_POINTS {
                return 0.0;
            }
            let Some((centre, normal, plane_var)) = flat_plane(&near_other, other_pts, other_cov)
            else {
                return 0.0;
            };
            // Over the other surface: an own point whose projection onto the plane
            // is within the other points' spacing (plus noise) of one of them.
            let spacing = r * (std::f64::consts::PI / near_other.len() as Real).sqrt();
            let reach = spacing + noise;
            projected.clear();
            projected.extend(near_other.iter().map(|&j| {
                let q = other_pts[j as usize];
                q - normal * normal.dot(&(q - centre))
            }));
            let (mut up, mut down, mut m) = (Real::NEG_INFINITY, Real::NEG_INFINITY, 0usize);
            for &(_, j) in near.of(i) {
                let (y, c) = (&own_pts[j as usize], &own_cov[j as usize]);
                let along = normal.dot(&(y - centre));
                let foot = y - normal * along;
                let covered = projected.iter().any(|q| (q - foot).norm() <= reach);
                let s = (directional_std_of(c, &normal).powi(2) + plane_var).sqrt();
                if !covered || s <= 0.0 {
                    continue;
                }
                m += 1;
                up = up.max(along / s);
                down = down.max(-along / s);
            }
            // Evidence needs own points on both sides of the plane.
            if m < 2 || up <= 0.0 || down <= 0.0 {
                return 0.0;
            }
            let m = m as Real;
            let side = |z: Real| (1.0 - m * normal_cdf(-z)).max(0.0);
            side(up) * side(down)
        })
        .collect()
}

/// Centre, unit normal and the variance of the plane's offset along the normal
/// of the `idx` points, if they are flat; `None` otherwise.
fn flat_plane(idx: &[u32], pts: &[Point3], covs: &[Matrix3]) -> Option<(Point3, Vector3, Real)> {
    let n = idx.len() as Real;
    let pa = PrincipalAxes::of(idx.iter().map(|&j| pts[j as usize]));
    let (centre, thickness_var, spread_var) = (pa.mean, pa.variances[0], pa.variances[1]);
    let normal: Vector3 = pa.least();
    let noise_var = idx
        .iter()
        .map(|&j| directional_std_of(&covs[j as usize], &normal).powi(2))
        .sum::<Real>()
        / n;
    // Flat: thin along the normal, as the noise; a plane, not a line: spread
    // in both other directions well beyond the noise.
    let noise_var = noise_var.max(Real::MIN_POSITIVE);
    if thickness_var > MAX_THICKNESS * MAX_THICKNESS * noise_var
        || spread_var < MIN_SPREAD * MIN_SPREAD * noise_var.max(thickness_var)
    {
        return None;
    }
    Some((centre, normal, noise_var / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(z: impl Fn(Real, Real) -> Real, h: Real, n: i32) -> Vec<Point3> {
        let mut out = Vec::new();
        for i in -n..=n {
            for j in -n..=n {
                let (x, y) = (Real::from(i) * h, Real::from(j) * h);
                out.push(Point3::new(x, y, z(x, y)));
            }
        }
        out
    }

    fn iso(n: usize, s: Real) -> Vec<Matrix3> {
        vec![Matrix3::identity() * s * s; n]
    }

    /// The crossing test as first written (every point scanned for every
    /// point), kept as the reference of the searches that replaced the scans.
    #[allow(clippy::too_many_lines)]
    fn scanning_reference(
        own: &[Point3],
        own_cov: &[Matrix3],
        other: &[Point3],
        other_cov: &[Matrix3],
    ) -> Vec<Real> {
        let mut by_distance: Vec<(Real, usize)> = Vec::with_capacity(own.len().max(other.len()));
        let mut near_other: Vec<usize> = Vec::new();
        own.iter()
            .map(|x| {
                // The scale: the distance to the 6th nearest own point, or 4 noise
                // standard deviations of the pair, whichever is larger.
                by_distance.clear();
                by_distance.extend(
                    own.iter()
                        .enumerate()
                        .map(|(j, y)| ((x - y).norm_squared(), j)),
                );
                let k = NEIGHBOURHOOD.min(by_distance.len());
                by_distance.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
                let d_k = by_distance[k - 1].0.sqrt();
                let own_near: Vec<usize> = by_distance[..k].iter().map(|&(_, j)| j).collect();
                let noise_at = |pts: &[Point3], covs: &[Matrix3], within: Real| {
                    pts.iter()
                        .zip(covs)
                        .filter(|(p, _)| (*p - x).norm() <= within)
                        .map(|(_, c)| max_std(c))
                        .fold(0.0, Real::max)
                };
                let noise = noise_at(own, own_cov, d_k).max(noise_at(other, other_cov, d_k));
                let r = d_k.max(RADIUS_SIGMAS * noise);
                near_other.clear();
                near_other.extend((0..other.len()).filter(|&j| (other[j] - x).norm() <= r));
                if near_other.len() < MIN_PLANE_POINTS {
                    return 0.0;
                }
                let Some((centre, normal, plane_var)) =
                    flat_plane(&idx32(&near_other), other, other_cov)
                else {
                    return 0.0;
                };
                // Over the other surface: an own point whose projection onto the plane
                // is within the other points' spacing (plus noise) of one of them.
                let spacing = r * (std::f64::consts::PI / near_other.len() as Real).sqrt();
                let reach = spacing + noise;
                let (mut up, mut down, mut m) = (Real::NEG_INFINITY, Real::NEG_INFINITY, 0usize);
                for &j in &own_near {
                    let (y, c) = (&own[j], &own_cov[j]);
                    let along = normal.dot(&(y - centre));
                    let foot = y - normal * along;
                    let covered = near_other.iter().any(|&j| {
                        let q = other[j] - normal * normal.dot(&(other[j] - centre));
                        (q - foot).norm() <= reach
                    });
                    let s = (directional_std_of(c, &normal).powi(2) + plane_var).sqrt();
                    if !covered || s <= 0.0 {
                        continue;
                    }
                    m += 1;
                    up = up.max(along / s);
                    down = down.max(-along / s);
                }
                // Evidence needs own points on both sides of the plane.
                if m < 2 || up <= 0.0 || down <= 0.0 {
                    return 0.0;
                }
                let m = m as Real;
                let side = |z: Real| (1.0 - m * normal_cdf(-z)).max(0.0);
                side(up) * side(down)
            })
            .collect()
    }

    fn idx32(idx: &[usize]) -> Vec<u32> {
        idx.iter().map(|&j| j as u32).collect()
    }

    /// Two noisy sheets crossing at an angle, sampled unevenly, with
    /// anisotropic covariances: the searches find exactly the neighbourhoods
    /// the scans of the first version found, so every probability is the same
    /// number. On a lattice (ties at the 6th neighbour) the hierarchy and a
    /// scan break the ties alike.
    #[test]
    fn searches_give_the_scans_probabilities() {
        let mut uniform = crate::sample::lcg_uniform(17);
        let s = 0.002;
        let mut sheet = |tilt: Real, n: usize| {
            let mut pts = Vec::new();
            let mut covs = Vec::new();
            for i in 0..n {
                let (u, v) = (uniform() - 0.5, 0.6 * (uniform() - 0.5));
                // Denser towards one end: the neighbourhoods' sizes vary.
                let u = 0.4 * u * u.abs().sqrt();
                let noise = (uniform() - 0.5) * 2.0 * s;
                pts.push(Point3::new(u, v, tilt * u + noise));
                let a = 1.0 + (i % 3) as Real;
                covs.push(Matrix3::from_diagonal(&Vector3::new(a, 1.0, 2.0)) * s * s);
            }
            (pts, covs)
        };
        let (a, ca) = sheet(0.0, 900);
        let (b, cb) = sheet(1.5, 700);
        let mut positive = 0;
        for (own, own_cov, other, other_cov) in [(&a, &ca, &b, &cb), (&b, &cb, &a, &ca)] {
            let fast = crossing_probabilities(own, own_cov, other, other_cov);
            assert_eq!(fast, scanning_reference(own, own_cov, other, other_cov));
            positive += fast.iter().filter(|&&p| p > 0.5).count();
            assert!(fast.iter().filter(|&&p| p == 0.0).count() > own.len() / 2);
        }
        assert!(positive > 20, "{positive}");
        // Lattices crossing: the tree and the scan agree where distances tie.
        let floor = grid(|_, _| 0.0, 0.005, 12);
        let tilted = grid(|x, _| x, 0.005, 12);
        let (cf, ct) = (iso(floor.len(), 0.001), iso(tilted.len(), 0.001));
        let std = |c: &[Matrix3]| c.iter().map(max_std).collect::<Vec<Real>>();
        let (sf, st) = (std(&cf), std(&ct));
        let scan_own = PointSearch::scan(&tilted[..]);
        let near = scan_own.neighbourhoods(NEIGHBOURHOOD);
        let scan = crossing_probabilities_in(
            (&scan_own, &ct, &st),
            &near,
            (&PointSearch::scan(&floor[..]), &cf, &sf),
        );
        let fast = crossing_probabilities(&tilted, &ct, &floor, &cf);
        assert_eq!(fast, scan);
        assert!(fast.iter().any(|&p| p > 0.99));
        // Too few other points for a plane, and an empty cloud.
        assert_eq!(
            crossing_probabilities(&a, &ca, &b[..5], &cb[..5]),
            vec![0.0; a.len()]
        );
        assert!(crossing_probabilities(&[], &[], &b, &cb).is_empty());
    }

    #[test]
    fn crossing_planes_are_seen_and_touching_ones_are_not() {
        let s = 0.001;
        let floor = grid(|_, _| 0.0, 0.005, 6);
        // A plane tilted by 45 degrees through the floor: crossing.
        let tilted = grid(|x, _| x, 0.005, 6);
        let p =
            crossing_probabilities(&tilted, &iso(tilted.len(), s), &floor, &iso(floor.len(), s));
        let centre = p[p.len() / 2];
        assert!(centre > 0.99, "{centre}");
        // The same plane lifted: the near points are all above the floor.
        let lifted = grid(|x, _| 0.002 + x.abs(), 0.005, 6);
        let p =
            crossing_probabilities(&lifted, &iso(lifted.len(), s), &floor, &iso(floor.len(), s));
        assert!(
            p.iter().all(|&q| q < 1e-6),
            "{:?}",
            p.iter().fold(0.0, |a: Real, &b| a.max(b))
        );
        // A parallel plane 1 sigma above: touching.
        let touching = grid(|_, _| s, 0.005, 6);
        let p = crossing_probabilities(
            &touching,
            &iso(touching.len(), s),
            &floor,
            &iso(floor.len(), s),
        );
        assert!(p.iter().all(|&q| q < 1e-6));
    }

    #[test]
    fn no_evidence_over_a_hole() {
        // The other plane has a hole under the probe: no own point lies over it,
        // so there is no evidence of a crossing (not certainty).
        let s = 0.001;
        let holed: Vec<Point3> = grid(|_, _| 0.0, 0.005, 8)
            .into_iter()
            .filter(|p| p.x.abs() > 0.012 || p.y.abs() > 0.012)
            .collect();
        let probe = grid(|_, _| 0.0005, 0.002, 2);
        let p = crossing_probabilities(&probe, &iso(probe.len(), s), &holed, &iso(holed.len(), s));
        assert!(p.iter().all(|&q| q == 0.0), "{p:?}");
    }

    #[test]
    fn an_edge_is_not_a_plane() {
        // The other cloud is a right-angled edge (two half planes): no plane, no
        // crossing, even for points that straddle its faces.
        let s = 0.0005;
        let mut edge: Vec<Point3> = grid(|_, _| 0.0, 0.005, 6)
            .into_iter()
            .filter(|p| p.x <= 0.0)
            .collect();
        edge.extend(
            grid(|_, _| 0.0, 0.005, 6)
                .into_iter()
                .filter(|p| p.x <= 0.0)
                .map(|p| Point3::new(0.0, p.y, p.x)),
        );
        let probe = grid(|x, _| 0.01 - x, 0.005, 2);
        let p = crossing_probabilities(&probe, &iso(probe.len(), s), &edge, &iso(edge.len(), s));
        assert!(p.iter().all(|&q| q == 0.0), "{p:?}");
    }
}
