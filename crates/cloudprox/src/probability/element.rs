//! The probability that the fitted surfaces of two clouds' elements cross.

use crate::classify::Separator;
use crate::element::SurfaceElement;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::pair::crossing;
use crate::uncertainty::directional_std_of;
use crate::Real;

/// Elements of the other side tried as the facing one (the nearest by mean).
const FACING_CANDIDATES: usize = 6;
/// A surface point faces another when their offset across the surface is at
/// most this many sampling spacings (half a spacing: samples of two touching
/// surfaces can be that far apart, as in the near rule).
const FACING_SPACINGS: Real = 0.5;

/// One side's elements of a patch, posed in the separator's frame.
pub struct ElementSide<'a> {
    /// The elements.
    pub elements: Vec<&'a SurfaceElement>,
    /// Pose of their cloud's frame in the separator's frame.
    pub pose: Pose,
    /// +1 for cloud A, -1 for cloud B.
    pub label: Real,
}

impl ElementSide<'_> {
    /// The point of element `k`'s fitted surface over tangential coordinates
    /// `(u, v)` (clamped to its range), in the separator's frame, and its
    /// covariance there.
    fn surface(&self, k: usize, u: Real, v: Real) -> (Point3, Matrix3) {
        let e = self.elements[k];
        let r = self.pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        if e.is_point() {
            return (self.pose * e.mean, r * e.cov_mean * r.transpose());
        }
        let [[u0, u1], [v0, v1]] = e.extent;
        let (x, var) = e.surface_point(u.clamp(u0, u1), v.clamp(v0, v1));
        (self.pose * x, r * e.surface_covariance(var) * r.transpose())
    }

    /// Element `k`'s tangential coordinates of a point `x` of the separator's frame.
    fn coordinates(&self, k: usize, x: &Point3) -> (Real, Real) {
        let e = self.elements[k];
        let d = self.pose.inverse_transform_point(x) - e.mean;
        (d.dot(&e.tangents[0]), d.dot(&e.tangents[1]))
    }

    /// Element `k`'s surface at its probes ([`SurfaceElement::probes`]; its
    /// point for a single-point element).
    fn probes(&self, k: usize) -> impl Iterator<Item = (Point3, Matrix3)> + '_ {
        self.elements[k]
            .probes
            .iter()
            .map(move |&[u, v]| self.surface(k, u, v))
    }
}

/// Per element of `own`, the probability that its fitted surface and the
/// other side's cross.
///
/// At each of its probes `x` (see [`SurfaceElement::probes`]), the other side's
/// facing surface point `y` is the point of one of its nearest elements at
/// `x`'s tangential coordinates (clamped to that element's range) that lies
/// within half a sampling spacing of `x` across its surface. The two surfaces
/// there are `g = (y - x) . u` apart along the separating surface's unit normal
/// `u` at their midpoint (oriented from A to B: only the direction of `sep` is
/// used, not where it runs), with the standard deviation
/// `s = sqrt(u^T (Sigma_x + Sigma_y) u)` of the two fitted surfaces, and cross
/// with probability `Phi(-g / s)`. A pair farther apart than the noise can
/// reach (`|y - x| > h/2 + reach_sds s`, `h` the spacing) cannot cross there
/// and counts 0: a deep crossing shows where the surfaces cross, not far from
/// it. The element's value is the largest over its probes.
pub fn element_crossing_probabilities(
    own: &ElementSide<'_>,
    other: &ElementSide<'_>,
    sep: &Separator,
    reach_sds: Real,
) -> Vec<Real> {
    let other_means: Vec<Point3> = other.elements.iter().map(|e| other.pose * e.mean).collect();
    let mut nearest: Vec<(Real, usize)> = Vec::with_capacity(other_means.len());
    (0..own.elements.len())
        .map(|k| {
            let own_spacing = own.elements[k].spacing;
            own.probes(k)
                .map(|(x, cov_x)| {
                    nearest.clear();
                    nearest.extend(
                        other_means
                            .iter()
                            .enumerate()
                            .map(|(j, m)| ((m - x).norm_squared(), j)),
                    );
                    let c = FACING_CANDIDATES.min(nearest.len());
                    if c == 0 {
                        return 0.0;
                    }
                    nearest.select_nth_unstable_by(c - 1, |a, b| a.0.total_cmp(&b.0));
                    let facing = nearest[..c]
                        .iter()
                        .filter_map(|&(_, j)| {
                            let (u, v) = other.coordinates(j, &x);
                            let (y, cov_y) = other.surface(j, u, v);
                            let e = other.elements[j];
                            let d = y - x;
                            let lateral = if e.is_point() {
                                d.norm()
                            } else {
                                let n = other.pose.rotation * e.normal;
                                (d - n * n.dot(&d)).norm()
                            };
                            let allowed = FACING_SPACINGS * own_spacing.max(e.spacing);
                            (lateral <= allowed).then_some((y, cov_y, allowed))
                        })
                        .min_by(|a, b| {
                            (a.0 - x)
                                .norm_squared()
                                .total_cmp(&(b.0 - x).norm_squared())
                        });
                    let Some((y, cov_y, allowed)) = facing else {
                        return 0.0;
                    };
                    let (_, g) = sep.value_and_gradient_local(&nalgebra::center(&x, &y));
                    let gn = g.norm();
                    if gn <= 0.0 || !gn.is_finite() {
                        return 0.0;
                    }
                    // From A towards B: f decreases from A's side to B's.
                    let u = g / (-gn);
                    let gap = own.label * (y - x).dot(&u);
                    let sd = directional_std_of(&(cov_x + cov_y), &u);
                    if (y - x).norm() > allowed + reach_sds * sd {
                        return 0.0;
                    }
                    crossing(gap, sd)
                })
                .fold(0.0, Real::max)
        })
        .collect()
}
