//! The probability stage of a query: Eq. 3 of every point of a patch against
//! its trained surface, the paper model's surface probability, and which
//! values count towards the pair's `P` (core points only).

use crate::bvh::Neighbourhoods;
use crate::classify::Separator;
use crate::element::SurfaceElements;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::{
    crossing_probabilities_in, point_probability, surface_probability, CrossingSide, NEIGHBOURHOOD,
};
use crate::uncertainty::directional_std_of;
use crate::Real;

/// Eq. 3 of each point of the elements `owners` of `elements` (moved by `pose`
/// into the separator's frame) against `sep`, with label `label`; the larger
/// of it and what `out` already holds (a point can be in several patches).
pub(crate) fn point_probabilities(
    sep: &Separator,
    pose: &Pose,
    elements: &SurfaceElements,
    owners: &[u32],
    label: Real,
    out: &mut [Real],
) {
    // The surface is turned into the cloud's frame rather than every point
    // and covariance into the separator's.
    let form = sep.quadratic_form(pose);
    for (i, x, cov) in owners.iter().flat_map(|&e| elements.members(e)) {
        let (f, g) = form.value_and_gradient(x);
        let p = point_probability(f, &g, cov, label);
        out[i as usize] = out[i as usize].max(p);
    }
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
