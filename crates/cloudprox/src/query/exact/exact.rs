//! Exact proximity of two posed [`ExactShape`]s.

use parry3d_f64::query;
use parry3d_f64::shape::Shape;
use rayon::prelude::*;

use super::exact_shape::{ExactPart, ExactShape};
use super::mesh_distance::{mesh_mesh_distance, TriangleTree};
use crate::cloud::validate_pose;
use crate::error::Result;
use crate::math::Pose;
use crate::Real;

/// The exact answer for a pair of objects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactProximity {
    /// Whether the two objects' solids (or surfaces, for open parts) intersect.
    pub intersecting: bool,
    /// The distance between them (metres); 0 when intersecting.
    pub distance: Real,
    /// When intersecting: the largest penetration depth over the intersecting
    /// pairs of parts (EPA), if every such pair is convex; `None` otherwise.
    pub penetration_depth: Option<Real>,
}

impl ExactProximity {
    /// The signed distance: the distance when apart, minus the penetration depth
    /// when intersecting (NaN if the depth is unknown, see
    /// [`ExactProximity::penetration_depth`]).
    pub fn signed_distance(&self) -> Real {
        if self.intersecting {
            self.penetration_depth.map_or(Real::NAN, |d| -d)
        } else {
            self.distance
        }
    }
}

pub(super) fn as_shape(p: &ExactPart) -> &dyn Shape {
    match p {
        ExactPart::Convex(c) => c,
        ExactPart::Mesh { mesh, .. } => mesh,
    }
}

/// A point of a part (its first vertex), for containment tests.
fn some_point(p: &ExactPart) -> parry3d_f64::math::Point<Real> {
    match p {
        ExactPart::Convex(c) => c.points()[0],
        ExactPart::Mesh { mesh, .. } => mesh.vertices()[0],
    }
}

fn contains(part: &ExactPart, pose: &Pose, other: &ExactPart, other_pose: &Pose) -> bool {
    let closed = match part {
        ExactPart::Convex(_) => true,
        ExactPart::Mesh { closed, .. } => *closed,
    };
    closed && as_shape(part).contains_point(pose, &(other_pose * some_point(other)))
}

/// Whether one part pair intersects (surfaces crossing, or one solid holding the other).
fn pair_intersects(pa: &Pose, a: &ExactPart, pb: &Pose, b: &ExactPart) -> bool {
    query::intersection_test(pa, as_shape(a), pb, as_shape(b)).unwrap_or(false)
        || contains(a, pa, b, pb)
        || contains(b, pb, a, pa)
}

/// One part pair: `(intersecting, distance, penetration depth if known)`.
fn part_pair(
    pa: &Pose,
    (a, ta): (&ExactPart, Option<&TriangleTree>),
    pb: &Pose,
    (b, tb): (&ExactPart, Option<&TriangleTree>),
) -> (bool, Real, Option<Real>) {
    let (sa, sb) = (as_shape(a), as_shape(b));
    if let (ExactPart::Convex(_), ExactPart::Convex(_)) = (a, b) {
        let d = query::distance(pa, sa, pb, sb).unwrap_or(Real::NAN);
        if d > 0.0 {
            return (false, d, None);
        }
        let depth = query::contact(pa, sa, pb, sb, 0.0)
            .ok()
            .flatten()
            .map_or(0.0, |c| (-c.dist).max(0.0));
        return (true, 0.0, Some(depth));
    }
    if pair_intersects(pa, a, pb, b) {
        return (true, 0.0, None);
    }
    let d = match (a, ta, b, tb) {
        (
            ExactPart::Mesh { mesh: ma, .. },
            Some(ta),
            ExactPart::Mesh { mesh: mb, .. },
            Some(tb),
        ) => mesh_mesh_distance(pa, (ma, ta), pb, (mb, tb)),
        _ => query::distance(pa, sa, pb, sb).unwrap_or(Real::NAN),
    };
    (false, d, None)
}

/// Exact proximity of `a` at `pose_a` and `b` at `pose_b` (each pose maps the
/// object's frame to the world).
///
/// Part pairs whose bounding boxes are farther apart than the best distance found
/// so far are skipped (they can neither intersect nor be closer). Two triangle
/// meshes that do not intersect get their distance from a traversal of both
/// meshes' hierarchies at once, nearest node pair first.
///
/// # Errors
/// [`Error::InvalidInput`](crate::Error::InvalidInput) if a pose is not finite,
/// its rotation is not a unit quaternion, or its translation is beyond
/// [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE) (a `Pose` built from parts
/// can hold any of these; the message names the pose).
pub fn exact_proximity(
    pose_a: &Pose,
    a: &ExactShape,
    pose_b: &Pose,
    b: &ExactShape,
) -> Result<ExactProximity> {
    validate_pose(pose_a, "pose_a")?;
    validate_pose(pose_b, "pose_b")?;
    Ok(proximity(pose_a, a, pose_b, b))
}

/// [`exact_proximity`] on poses already checked by the caller.
pub(crate) fn proximity(
    pose_a: &Pose,
    a: &ExactShape,
    pose_b: &Pose,
    b: &ExactShape,
) -> ExactProximity {
    let boxes_a: Vec<_> = a.aabbs.iter().map(|x| x.transformed(pose_a)).collect();
    let boxes_b: Vec<_> = b.aabbs.iter().map(|x| x.transformed(pose_b)).collect();
    let mut pairs: Vec<(Real, usize, usize)> = boxes_a
        .iter()
        .enumerate()
        .flat_map(|(i, ba)| {
            boxes_b
                .iter()
                .enumerate()
                .map(move |(j, bb)| (ba.distance(bb), i, j))
        })
        .collect();
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out = ExactProximity {
        intersecting: false,
        distance: Real::INFINITY,
        penetration_depth: None,
    };
    let mut depth_known = true;
    for (lower_bound, i, j) in pairs {
        if lower_bound > 0.0 && lower_bound > out.distance {
            break;
        }
        let (hit, d, depth) = part_pair(pose_a, a.part(i), pose_b, b.part(j));
        if hit {
            out.intersecting = true;
            out.distance = 0.0;
            match depth {
                Some(p) => {
                    out.penetration_depth = Some(out.penetration_depth.map_or(p, |q| q.max(p)));
                }
                None => depth_known = false,
            }
        } else if !out.intersecting {
            out.distance = out.distance.min(d);
        }
    }
    if !depth_known {
        out.penetration_depth = None;
    }
    out
}

/// Whether `a` at `pose_a` and `b` at `pose_b` intersect: the `intersecting` of
/// [`exact_proximity`] without the distance, which costs far more for large
/// meshes that are apart.
///
/// # Errors
/// As [`exact_proximity`].
pub fn exact_intersects(
    pose_a: &Pose,
    a: &ExactShape,
    pose_b: &Pose,
    b: &ExactShape,
) -> Result<bool> {
    validate_pose(pose_a, "pose_a")?;
    validate_pose(pose_b, "pose_b")?;
    Ok(intersects(pose_a, a, pose_b, b))
}

/// [`exact_intersects`] on poses already checked by the caller.
pub(crate) fn intersects(pose_a: &Pose, a: &ExactShape, pose_b: &Pose, b: &ExactShape) -> bool {
    let boxes_b: Vec<_> = b.aabbs.iter().map(|x| x.transformed(pose_b)).collect();
    a.aabbs.iter().enumerate().any(|(i, box_a)| {
        let box_a = box_a.transformed(pose_a);
        boxes_b.iter().enumerate().any(|(j, box_b)| {
            box_a.distance(box_b) <= 0.0
                && pair_intersects(pose_a, &a.parts[i], pose_b, &b.parts[j])
        })
    })
}

/// Checks every pose of a `_many` query (named by index) and `pose_b`.
fn validate_poses(poses_a: &[Pose], pose_b: &Pose) -> Result<()> {
    for (i, p) in poses_a.iter().enumerate() {
        validate_pose(p, &format!("poses_a[{i}]"))?;
    }
    validate_pose(pose_b, "pose_b")
}

/// [`exact_intersects`] for many poses of `a`, in parallel.
///
/// # Errors
/// As [`exact_proximity`], for the first bad pose (by index; the message names
/// it), before any query runs.
pub fn exact_intersects_many(
    poses_a: &[Pose],
    a: &ExactShape,
    pose_b: &Pose,
    b: &ExactShape,
) -> Result<Vec<bool>> {
    validate_poses(poses_a, pose_b)?;
    Ok(poses_a
        .par_iter()
        .map(|p| intersects(p, a, pose_b, b))
        .collect())
}

/// [`exact_proximity`] for many poses of `a`, in parallel.
///
/// # Errors
/// As [`exact_intersects_many`].
pub fn exact_proximity_many(
    poses_a: &[Pose],
    a: &ExactShape,
    pose_b: &Pose,
    b: &ExactShape,
) -> Result<Vec<ExactProximity>> {
    validate_poses(poses_a, pose_b)?;
    Ok(poses_a
        .par_iter()
        .map(|p| proximity(p, a, pose_b, b))
        .collect())
}
