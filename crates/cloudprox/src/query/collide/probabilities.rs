//! The probability stage of a query: Eq. 3 of every point of a patch against
//! its trained surface, the paper model's surface probability, and which
//! values count towards the pair's `P` (core points only).

use crate::bvh::{Aabb, Neighbourhoods};
use crate::classify::Separator;
use crate::element::SurfaceElements;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::{
    crossing_probabilities_in, point_probability, surface_probability, CrossingSide, NEIGHBOURHOOD,
};
use crate::uncertainty::directional_std_of;
use crate::Real;

/// One side of a patch for [`point_probabilities`]: its elements, the
/// owners among them, and the pose that moves them into the separator's
/// frame.
pub(crate) type PatchSide<'a> = (&'a SurfaceElements, &'a [u32], &'a Pose);

/// Eq. 3 of each point of the elements `owners` of `own` (moved by its
/// pose into the separator's frame) against `sep`, with label `label`; the
/// larger of it and what `out` already holds (a point can be in several
/// patches).
///
/// A point farther from the other side's points (the box around the points
/// of its elements `owners`) than the two sides' noise can reach (`reach`
/// times the sum of their deviations) is left out: as the points model's
/// context points, a surface that puts it on the wrong side misfits there
/// (a floor element two metres across under a table's contact), which is no
/// evidence of a collision.
pub(crate) fn point_probabilities(
    sep: &Separator,
    own: PatchSide<'_>,
    other: PatchSide<'_>,
    (label, reach): (Real, Real),
    out: &mut [Real],
) {
    let (elements, owners, pose) = own;
    let (near, other_std) = members_box(other);
    // The surface is turned into the cloud's frame rather than every point
    // and covariance into the separator's.
    let form = sep.quadratic_form(pose);
    for (i, x, cov) in owners.iter().flat_map(|&e| elements.members(e)) {
        let radius = reach * (cov.trace().max(0.0).sqrt() + other_std);
        if near.distance_squared_to_point(&(pose * x)) > radius * radius {
            continue;
        }
        let (f, g) = form.value_and_gradient(x);
        let p = point_probability(f, &g, cov, label);
        out[i as usize] = out[i as usize].max(p);
    }
}

/// The box (separator's frame) around the points of one side's elements
/// `owners`, and a bound on their deviations (the largest `sqrt(trace)` of
/// their covariances).
fn members_box((elements, owners, pose): PatchSide<'_>) -> (Aabb, Real) {
    let mut b = Aabb::empty();
    let mut std: Real = 0.0;
    for (_, x, cov) in owners.iter().flat_map(|&e| elements.members(e)) {
        b.take_point(&(pose * x));
        std = std.max(cov.trace().max(0.0).sqrt());
    }
    (b, std)
}

/// The values of the `(point index, value)` pairs whose point is a core point.
/// Only they count towards `P`: a context point is beyond the noise's reach of
/// the other cloud, so a surface that puts it on the wrong side misfits; that is
/// no evidence of a collision.
pub(crate) fn core_values<'a>(
    points: impl Iterator<Item = (usize, Real)> + 'a,
    core: &'a [bool],
) -> impl Iterator<Item = Real> + 'a {
    points.filter(|&(i, _)| core[i]).map(|(_, v)| v)
}

/// `(point index, value)` pairs of a patch's points `idx` and their `values`.
pub(crate) fn indexed<'a>(
    idx: &'a [u32],
    values: &'a [Real],
) -> impl Iterator<Item = (usize, Real)> + 'a {
    idx.iter().map(|&i| i as usize).zip(values.iter().copied())
}

/// The surface probability `q_i` ([`surface_probability`]) of each of one side's
/// points of a patch (`pts`, `covs` in the separator's frame, label `label`),
/// from the point's neighbourhood `near` among that side's patch points
/// (neighbours beyond the patch belong to surfaces the separator was not
/// fitted to, e.g. the far face of a thin plate).
fn surface_probabilities(
    sep: &Separator,
    pts: &[Point3],
    covs: &[Matrix3],
    label: Real,
    near: &Neighbourhoods,
) -> Vec<Real> {
    let form = sep.quadratic_form(&Pose::identity());
    let (margins, stds): (Vec<Real>, Vec<Real>) = pts
        .iter()
        .zip(covs)
        .map(|(x, c)| {
            let (f, g) = form.value_and_gradient(x);
            (label * f, directional_std_of(c, &g))
        })
        .unzip();
    let (mut m, mut s) = (Vec::new(), Vec::new());
    (0..pts.len())
        .map(|i| {
            m.clear();
            s.clear();
            for &(_, j) in near.of(i) {
                m.push(margins[j as usize]);
                s.push(stds[j as usize]);
            }
            surface_probability(&m, &s)
        })
        .collect()
}

/// The points model's `surface` inputs of one side of a patch (`own`, label
/// `label`, against `other`; each its search, covariances and largest
/// deviations, in the separator's frame): for each point,
/// the larger of its surface probability against `sep` and the probability
/// that its surface crosses the other's there ([`crossing_probabilities_in`]).
/// Each point's neighbourhood is found once for both.
pub(crate) fn surface_side(
    sep: &Separator,
    own: CrossingSide<'_, '_>,
    other: CrossingSide<'_, '_>,
    label: Real,
) -> Vec<Real> {
    let near = own.0.neighbourhoods(NEIGHBOURHOOD);
    let q = surface_probabilities(sep, own.0.points(), own.1, label, &near);
    let c = crossing_probabilities_in(own, &near, other);
    q.into_iter().zip(c).map(|(q, c)| q.max(c)).collect()
}
