//! The probability stage of a query: Eq. 3 of every point of a patch against
//! its trained surface, the paper model's surface probability, and which
//! values count towards the pair's `P` (core points only).

use crate::classify::Separator;
use crate::element::SurfaceElements;
use crate::math::{Matrix3, Point3, Pose};
use crate::probability::{point_probability, surface_probability};
use crate::uncertainty::directional_std_of;
use crate::Real;

/// Neighbours behind a surface probability: the point and its 6 nearest.
const SURFACE_NEIGHBOURS: usize = 7;

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
/// from the point and its nearest neighbours among that side's patch points
/// (neighbours beyond the patch belong to surfaces the separator was not
/// fitted to, e.g. the far face of a thin plate).
pub(crate) fn surface_probabilities(
    sep: &Separator,
    pts: &[Point3],
    covs: &[Matrix3],
    label: Real,
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
    let k = SURFACE_NEIGHBOURS.min(pts.len());
    let mut by_distance: Vec<(Real, usize)> = Vec::with_capacity(pts.len());
    let (mut m, mut s) = (Vec::with_capacity(k), Vec::with_capacity(k));
    pts.iter()
        .map(|x| {
            by_distance.clear();
            by_distance.extend(
                pts.iter()
                    .enumerate()
                    .map(|(j, y)| ((x - y).norm_squared(), j)),
            );
            by_distance.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
            m.clear();
            s.clear();
            for &(_, j) in &by_distance[..k] {
                m.push(margins[j]);
                s.push(stds[j]);
            }
            surface_probability(&m, &s)
        })
        .collect()
}
