//! Exact time of impact: how far an [`ExactShape`] moves along a straight line
//! before its signed distance to another reaches a target.

use nalgebra::Translation3;
use parry3d_f64::query::{self, PointQuery, Ray, ShapeCastOptions};
use parry3d_f64::shape::{Shape, TriMesh};
use rayon::prelude::*;

use super::exact::{as_shape, intersects, proximity};
use super::exact_shape::{ExactPart, ExactShape};
use crate::cloud::validate_pose;
use crate::error::{Error, Result};
use crate::math::{Pose, Vector3};
use crate::Real;

/// Precision of a penetration target (metres): the search past contact stops
/// when the signed distance is within this of the target.
pub const IMPACT_TOLERANCE: Real = 1e-10;

/// Relative precision of parry's shape casts: the distance at the travel a
/// cast returns is its target to about this fraction of the cast's reach.
const CAST_PRECISION: Real = 1e-7;

/// Most signed-distance evaluations of the search past contact.
const MAX_STEPS: usize = 200;

/// A part as the casts see it: its representation, and the shape handed to
/// parry's casts ([`ExactShape::cast_shape`]: a large hull's climbing support).
#[derive(Clone, Copy)]
struct CastPart<'a> {
    part: &'a ExactPart,
    shape: &'a dyn Shape,
}

impl<'a> CastPart<'a> {
    fn of(shape: &'a ExactShape, i: usize) -> Self {
        Self {
            part: &shape.parts[i],
            shape: shape.cast_shape(i),
        }
    }
}

/// `pose` translated by `t` along the unit `direction`.
fn moved(pose: &Pose, direction: &Vector3, t: Real) -> Pose {
    Pose::from_parts(
        Translation3::from(pose.translation.vector + direction * t),
        pose.rotation,
    )
}

/// The first travel (at most `max_travel`) along `direction` at which part `a`
/// comes within `target` (>= 0) of part `b`. A convex part and a mesh: the
/// part with more triangles is cast against the other (parry prunes the outer
/// shape's hierarchy with the inner shape's whole box); two meshes: see
/// [`cast_mesh_mesh`]. The casts reach only as far as [`vertex_ray_bound`]
/// (their swept boxes were most of their cost on a scanned surface), and as
/// far as `max_travel` only if that finds nothing.
fn cast_pair(
    pa: &Pose,
    a: CastPart<'_>,
    direction: &Vector3,
    pb: &Pose,
    b: CastPart<'_>,
    target: Real,
    max_travel: Real,
) -> Result<Option<Real>> {
    let options = ShapeCastOptions {
        max_time_of_impact: max_travel,
        target_distance: target,
        stop_at_penetration: true,
        compute_impact_geometry_on_penetration: false,
    };
    let cast = |reach: Real| {
        cast_pair_within(
            pa,
            a,
            direction,
            pb,
            b,
            ShapeCastOptions {
                max_time_of_impact: reach,
                ..options
            },
        )
    };
    // Two convex parts are one GJK cast, with no tree for a shorter reach to
    // prune: the bound would only add its rays.
    let both_convex = matches!(
        (a.part, b.part),
        (ExactPart::Convex(_), ExactPart::Convex(_))
    );
    let bound = if both_convex {
        None
    } else {
        vertex_ray_bound(pa, a.part, direction, pb, b.part, max_travel)
    };
    if let Some(bound) = bound {
        // Slack for the casts' own rounding: the bound is a travel where the
        // parts touch, the cast's answer at most that.
        let reach = (bound * (1.0 + 1e-9) + 1e-12).min(max_travel);
        if let Some(t) = cast(reach)? {
            return Ok(Some(t));
        }
    }
    cast(max_travel)
}

/// An upper bound on the travel of [`cast_pair`] for any `target >= 0`: the
/// first travel at which a vertex of one part, moving along the relative
/// direction, lies on the other part (its distance 0 there), as rays of the
/// part with fewer vertices against the other part (its tree for a mesh).
/// `None` when no vertex meets the other part within `max_travel` (an edge or
/// a face may still). A vertex that no face uses would bound nothing: the
/// casts with that reach then find nothing and [`cast_pair`] casts again with
/// the full reach, so a bound can cost time but never change the answer.
fn vertex_ray_bound(
    pa: &Pose,
    a: &ExactPart,
    direction: &Vector3,
    pb: &Pose,
    b: &ExactPart,
    max_travel: Real,
) -> Option<Real> {
    fn vertices(p: &ExactPart) -> &[parry3d_f64::math::Point<Real>] {
        match p {
            ExactPart::Convex(c) => c.points(),
            ExactPart::Mesh { mesh, .. } => mesh.vertices(),
        }
    }
    // The vertices of `from` at `pf` move by `dir` towards `to` at `pt`.
    let (pf, from, dir, pt, to) = if vertices(a).len() <= vertices(b).len() {
        (pa, a, *direction, pb, b)
    } else {
        (pb, b, -direction, pa, a)
    };
    let shape = as_shape(to);
    let mut best: Option<Real> = None;
    for v in vertices(from) {
        let ray = Ray::new(pf * v, dir);
        let reach = best.unwrap_or(max_travel);
        if let Some(t) = shape.cast_ray(pt, &ray, reach, false) {
            if t <= reach {
                best = Some(t);
            }
        }
    }
    best
}

/// [`cast_pair`] with the reach of `options` (its target included).
fn cast_pair_within(
    pa: &Pose,
    a: CastPart<'_>,
    direction: &Vector3,
    pb: &Pose,
    b: CastPart<'_>,
    options: ShapeCastOptions,
) -> Result<Option<Real>> {
    let triangles = |p: &ExactPart| match p {
        ExactPart::Convex(_) => 0,
        ExactPart::Mesh { mesh, .. } => mesh.num_triangles(),
    };
    let max_travel = options.max_time_of_impact;
    let zero = Vector3::zeros();
    if let (ExactPart::Mesh { mesh: ma, .. }, ExactPart::Mesh { mesh: mb, .. }) = (a.part, b.part) {
        return Ok(cast_mesh_mesh(pa, ma, direction, pb, mb, options));
    }
    let hit = if triangles(b.part) > triangles(a.part) {
        // b moves by -direction relative to a: the same travel.
        query::cast_shapes(pb, &-direction, b.shape, pa, &zero, a.shape, options)
    } else {
        query::cast_shapes(pa, direction, a.shape, pb, &zero, b.shape, options)
    }
    .map_err(|_| Error::invalid("parry cannot cast this pair of parts"))?;
    Ok(hit
        .map(|h| h.time_of_impact.max(0.0))
        .filter(|&t| t <= max_travel))
}

/// Two triangle meshes: each triangle of the one with fewer triangles is cast
/// against the other's tree, the nearest first, each with the best travel so
/// far as its reach (parry's own mesh-mesh cast prunes the
/// outer tree with the inner mesh's whole box, and gives every inner cast the
/// full reach: far slower for a gripper against a scanned surface).
fn cast_mesh_mesh(
    pa: &Pose,
    a: &TriMesh,
    direction: &Vector3,
    pb: &Pose,
    b: &TriMesh,
    options: ShapeCastOptions,
) -> Option<Real> {
    // Cast the smaller mesh, moving by `dir` relative to the larger one.
    let (ps, small, dir, pl, large) = if a.num_triangles() <= b.num_triangles() {
        (pa, a, *direction, pb, b)
    } else {
        (pb, b, -direction, pa, a)
    };
    // Each triangle's key: the smallest distance of its corners to the other
    // mesh at the start (point queries on its tree, cheap). A corner within
    // the target means the start is; otherwise the nearest triangles go first,
    // so that a hit comes early and shortens every later cast.
    let corner: Vec<Real> = small
        .vertices()
        .iter()
        .map(|v| large.distance_to_point(pl, &(ps * v), false))
        .collect();
    // With its longest edge: no point of the triangle is nearer than its
    // nearest corner less that edge, and a move by `L` brings it at most `L`
    // closer, so a triangle whose bound exceeds the target plus the best
    // travel so far cannot hit first and is skipped.
    let verts = small.vertices();
    let mut order: Vec<(Real, Real, usize)> = small
        .indices()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let near = t
                .iter()
                .map(|&k| corner[k as usize])
                .fold(Real::INFINITY, Real::min);
            let [p, q, r] = t.map(|k| verts[k as usize]);
            let edge = (p - q).norm().max((q - r).norm()).max((r - p).norm());
            (near, edge, i)
        })
        .collect();
    if order.iter().any(|&(d, _, _)| d <= options.target_distance) {
        return Some(0.0);
    }
    order.sort_by(|x, y| x.0.total_cmp(&y.0));
    let zero = Vector3::zeros();
    // Relative to the smaller of the reach and the moving mesh's size (the
    // reach may be infinite).
    let size = 2.0 * small.local_aabb().half_extents().norm();
    let negligible = IMPACT_TOLERANCE.max(CAST_PRECISION * options.max_time_of_impact.min(size));
    let mut best: Option<Real> = None;
    for (near, edge, i) in order {
        let reach = best.unwrap_or(options.max_time_of_impact);
        if near - edge > options.target_distance + reach {
            continue;
        }
        let tri = small.triangle(i as u32);
        let hit = query::cast_shapes(
            ps,
            &dir,
            &tri,
            pl,
            &zero,
            large,
            ShapeCastOptions {
                max_time_of_impact: reach,
                ..options
            },
        )
        .ok()
        .flatten()
        .map(|h| h.time_of_impact.max(0.0))
        .filter(|&t| t <= reach);
        if let Some(t) = hit {
            best = Some(t);
            // Within the casts' own precision of zero (about 1e-7 of the
            // reach or of the mesh's size): no later triangle can improve it
            // by more. A start in
            // contact that the corners alone did not show (large triangles
            // lying on the surface) took seconds of casts that all touch at
            // about zero travel.
            if t <= negligible {
                break;
            }
        }
    }
    best
}

/// The first travel at which the closest part pair comes within `target` (>= 0):
/// pairs are taken in the order of their boxes' distance, which bounds their
/// travel from below (a translation by `L` changes a distance by at most `L`).
fn cast_shapes_to(
    pose_a: &Pose,
    a: &ExactShape,
    direction: &Vector3,
    pose_b: &Pose,
    b: &ExactShape,
    target: Real,
    max_travel: Real,
) -> Result<Option<Real>> {
    let boxes_b: Vec<_> = b.aabbs.iter().map(|x| x.transformed(pose_b)).collect();
    let mut pairs: Vec<(Real, usize, usize)> = Vec::new();
    for (i, box_a) in a.aabbs.iter().enumerate() {
        let box_a = box_a.transformed(pose_a);
        for (j, box_b) in boxes_b.iter().enumerate() {
            pairs.push(((box_a.distance(box_b) - target).max(0.0), i, j));
        }
    }
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut best: Option<Real> = None;
    for (lower_bound, i, j) in pairs {
        let reach = best.unwrap_or(max_travel);
        if lower_bound > reach {
            break;
        }
        let hit = cast_pair(
            pose_a,
            CastPart::of(a, i),
            direction,
            pose_b,
            CastPart::of(b, j),
            target,
            reach,
        )?;
        if let Some(t) = hit {
            best = Some(best.map_or(t, |x| x.min(t)));
        }
    }
    Ok(best)
}

/// The signed distance of `a` moved by `t` (an error where the depth is unknown).
fn signed_at(
    pose_a: &Pose,
    a: &ExactShape,
    direction: &Vector3,
    pose_b: &Pose,
    b: &ExactShape,
    t: Real,
) -> Result<Real> {
    let s = proximity(&moved(pose_a, direction, t), a, pose_b, b).signed_distance();
    if s.is_nan() {
        return Err(Error::invalid(
            "a negative target needs penetration depths, which are known only \
             between convex parts (a non-convex part intersects)",
        ));
    }
    Ok(s)
}

/// Past contact (travel `t0`): a travel where the signed distance `s` reaches
/// `target` (< 0). `s` changes by at most `L` over a translation by `L`, so a
/// step of `s - target` never passes a crossing (conservative advancement);
/// each step also tries the secant's root, and once a pose at or below the
/// target is found the crossing is bisected.
#[allow(clippy::too_many_arguments)]
fn search_past_contact(
    pose_a: &Pose,
    a: &ExactShape,
    direction: &Vector3,
    pose_b: &Pose,
    b: &ExactShape,
    target: Real,
    t0: Real,
    max_travel: Real,
) -> Result<Option<Real>> {
    let f = |t: Real| signed_at(pose_a, a, direction, pose_b, b, t).map(|s| s - target);
    let (mut lo, mut f_lo) = (t0, f(t0)?);
    let mut upper: Option<Real> = None;
    let mut steps = 1;
    while upper.is_none() && steps < MAX_STEPS {
        if f_lo <= IMPACT_TOLERANCE {
            return Ok(Some(lo));
        }
        let safe = lo + f_lo;
        if safe > max_travel {
            return Ok(None);
        }
        let f_safe = f(safe)?;
        steps += 1;
        if f_safe <= 0.0 {
            upper = Some(safe);
            break;
        }
        let slope = (f_lo - f_safe) / (safe - lo);
        (lo, f_lo) = (safe, f_safe);
        // The secant's root only serves as a bracket: a crossing between `lo`
        // and it cannot be ruled out, so `lo` advances by safe steps alone.
        if slope > 0.0 && f_safe > IMPACT_TOLERANCE {
            let guess = (safe + f_safe / slope).min(max_travel);
            let f_guess = f(guess)?;
            steps += 1;
            if f_guess <= 0.0 {
                upper = Some(guess);
            }
        }
    }
    let Some(mut hi) = upper else {
        return Ok(None);
    };
    while steps < MAX_STEPS && hi - lo > IMPACT_TOLERANCE {
        let mid = 0.5 * (lo + hi);
        let f_mid = f(mid)?;
        steps += 1;
        if f_mid <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
        if f_mid.abs() <= IMPACT_TOLERANCE {
            return Ok(Some(mid));
        }
    }
    Ok(Some(hi))
}

/// How far `a`, starting at `pose_a`, moves along `direction` (its orientation
/// kept) before its signed distance to `b` at `pose_b` first reaches `target`
/// (metres; the travel is in metres along the unit direction).
///
/// - `target >= 0`: the first travel at which the distance comes down to
///   `target`, by parry's shape casting (GJK directional distance) over the part
///   pairs: exact for contact between polyhedra, within GJK's relative
///   tolerance (about 1e-7 of the travel) for a gap, which it casts with one
///   shape rounded by the gap. Between two meshes a travel within 1e-7 of the
///   smaller of `max_travel` and the moving mesh's size from zero is returned
///   as found (the start is at the target to the casts' precision), without
///   casting the remaining triangles.
/// - `target < 0`: a penetration depth of `-target`: the first contact as
///   above, then a search along the line past it on the signed distance of
///   [`exact_proximity`](super::exact_proximity) (conservative advancement, secant steps, bisection;
///   to within [`IMPACT_TOLERANCE`]). It is the first crossing unless the
///   signed distance dips below the target and comes back between two
///   evaluations.
///
/// Returns `Some(0.0)` when the objects start at or within the target (for
/// `target >= 0`, when they start closer than it or intersecting, containment
/// included), `None` when the target is not reached within `max_travel` (or,
/// for a negative target, within 200 evaluations).
///
/// # Errors
/// [`Error::InvalidInput`] if a pose is not finite (or its translation beyond
/// the coordinate range), `direction` is not a finite non-zero vector,
/// `target` is not finite, `max_travel` is NaN or negative, or `target < 0`
/// while an intersecting part pair is not convex (its depth is unknown).
pub fn exact_time_of_impact(
    pose_a: &Pose,
    a: &ExactShape,
    direction: &Vector3,
    pose_b: &Pose,
    b: &ExactShape,
    target: Real,
    max_travel: Real,
) -> Result<Option<Real>> {
    validate_pose(pose_a, "pose_a")?;
    validate_pose(pose_b, "pose_b")?;
    let norm = direction.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(Error::invalid(format!(
            "direction {:?} is not a finite non-zero vector",
            direction.as_slice()
        )));
    }
    if !target.is_finite() {
        return Err(Error::invalid(format!("target {target} is not finite")));
    }
    if max_travel.is_nan() || max_travel < 0.0 {
        return Err(Error::invalid(format!(
            "max_travel {max_travel} is not >= 0"
        )));
    }
    let direction = direction / norm;
    if intersects(pose_a, a, pose_b, b) {
        if target >= 0.0 {
            return Ok(Some(0.0));
        }
        if signed_at(pose_a, a, &direction, pose_b, b, 0.0)? <= target {
            return Ok(Some(0.0));
        }
        return search_past_contact(pose_a, a, &direction, pose_b, b, target, 0.0, max_travel);
    }
    let contact = cast_shapes_to(
        pose_a,
        a,
        &direction,
        pose_b,
        b,
        target.max(0.0),
        max_travel,
    )?;
    match contact {
        Some(t0) if target < 0.0 => {
            search_past_contact(pose_a, a, &direction, pose_b, b, target, t0, max_travel)
        }
        other => Ok(other),
    }
}

/// [`exact_time_of_impact`] for many starts of `a`, each with its direction
/// and target, in parallel.
///
/// # Errors
/// [`Error::Shape`] if `directions` or `targets` do not have one entry per
/// pose; otherwise the first error of [`exact_time_of_impact`] (by pose index).
pub fn exact_time_of_impact_many(
    poses_a: &[Pose],
    a: &ExactShape,
    directions: &[Vector3],
    pose_b: &Pose,
    b: &ExactShape,
    targets: &[Real],
    max_travel: Real,
) -> Result<Vec<Option<Real>>> {
    for (what, got) in [("directions", directions.len()), ("targets", targets.len())] {
        if got != poses_a.len() {
            return Err(Error::Shape {
                what: format!("{what} (one per pose)"),
                expected: poses_a.len(),
                got,
            });
        }
    }
    poses_a
        .par_iter()
        .zip(directions.par_iter())
        .zip(targets.par_iter())
        .map(|((p, d), &t)| exact_time_of_impact(p, a, d, pose_b, b, t, max_travel))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::random_rotations;
    use crate::math::Point3;
    use crate::sample::NormalRng;
    use crate::shape::Mesh;

    /// An open, wavy surface: a 41 x 41 grid over a 1 m square, 3 cm waves.
    fn terrain() -> ExactShape {
        let n = 41u32;
        let mut vertices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (f64::from(i) / 40.0 - 0.5, f64::from(j) / 40.0 - 0.5);
                vertices.push(Point3::new(x, y, 0.03 * (6.0 * x).sin() * (5.0 * y).cos()));
            }
        }
        let mut faces = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let k = j * n + i;
                faces.push([k, k + 1, k + n + 1]);
                faces.push([k, k + n + 1, k + n]);
            }
        }
        ExactShape::surfaces(&[Mesh::new(vertices, faces).unwrap()]).unwrap()
    }

    /// A 0.4 m square of two triangles: large faces, far corners.
    fn square() -> Mesh {
        let v = [(-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2)];
        let vertices = v.iter().map(|&(x, y)| Point3::new(x, y, 0.0)).collect();
        Mesh::new(vertices, vec![[0, 1, 2], [0, 2, 3]]).unwrap()
    }

    /// A convex hull of `n` points on an ellipsoid of half-axes `axes`.
    fn ellipsoid_hull(n: usize, axes: [Real; 3]) -> ExactShape {
        let points: Vec<Point3> = crate::sample::sphere(&Point3::origin(), 1.0, n)
            .iter()
            .map(|p| Point3::new(axes[0] * p.x, axes[1] * p.y, axes[2] * p.z))
            .collect();
        let (v, t) = parry3d_f64::transformation::convex_hull(&points);
        ExactShape::new(&[Mesh::new(v, t).unwrap()]).unwrap()
    }

    /// Part 0 of `shape` as the casts saw it before climbing hulls.
    fn scanning(shape: &ExactShape) -> CastPart<'_> {
        CastPart {
            part: &shape.parts[0],
            shape: as_shape(&shape.parts[0]),
        }
    }

    /// A large hull's casts walk its edges for support points (its climbing
    /// hull): every travel is bit for bit the scanning polyhedron's, at random
    /// poses over a wavy surface and against another large hull.
    #[test]
    fn a_climbing_hull_casts_as_the_polyhedron() {
        use parry3d_f64::shape::ShapeType;
        let ground = terrain();
        let pebble = ellipsoid_hull(400, [0.06, 0.03, 0.02]);
        let stone = ellipsoid_hull(300, [0.05, 0.05, 0.03]);
        for s in [&pebble, &stone] {
            assert_eq!(s.cast_shape(0).shape_type(), ShapeType::Custom);
        }
        let stone_at = Pose::translation(0.0, 0.0, -0.05);
        let rotations = random_rotations(60, 3);
        let mut rng = NormalRng::new(5);
        let (mut hits, mut convex_hits) = (0, 0);
        for (k, rotation) in rotations.iter().enumerate() {
            let start = Pose::from_parts(
                Translation3::new(0.3 * rng.normal(), 0.3 * rng.normal(), 0.2),
                *rotation,
            );
            let dir = Vector3::new(0.3 * rng.normal(), 0.3 * rng.normal(), -1.0).normalize();
            let options = ShapeCastOptions {
                max_time_of_impact: 1.0,
                target_distance: [0.0, 0.01][k % 2],
                stop_at_penetration: true,
                compute_impact_geometry_on_penetration: false,
            };
            let o = Pose::identity();
            let soil = CastPart::of(&ground, 0);
            let climbing = CastPart::of(&pebble, 0);
            let walk = cast_pair_within(&start, climbing, &dir, &o, soil, options).unwrap();
            let scan = cast_pair_within(&start, scanning(&pebble), &dir, &o, soil, options);
            assert_eq!(walk, scan.unwrap(), "pose {k}");
            hits += usize::from(walk.is_some());
            // Hull against hull: one GJK cast of two support maps.
            let (st, still) = (CastPart::of(&stone, 0), scanning(&stone));
            let walk = cast_pair_within(&start, climbing, &dir, &stone_at, st, options).unwrap();
            let scan = cast_pair_within(&start, scanning(&pebble), &dir, &stone_at, still, options);
            assert_eq!(walk, scan.unwrap(), "pose {k}, two hulls");
            convex_hits += usize::from(walk.is_some());
        }
        assert!(
            hits >= 40 && convex_hits >= 5,
            "{hits} and {convex_hits} hits"
        );
    }

    /// The vertex bound only shortens the casts' reach: the travel is the
    /// full-reach cast's to the casts' precision, and never beyond the bound,
    /// for convex, non-convex and open movers in random poses and directions
    /// over a wavy surface.
    #[test]
    fn the_vertex_bound_keeps_the_full_reach_travel() {
        let ground = terrain();
        let cube = Mesh::cuboid(0.04, 0.03, 0.02).unwrap();
        let l_shape = Mesh::merged(&[
            cube.clone(),
            cube.transformed(&Pose::translation(0.08, 0.0, -0.04)),
        ])
        .unwrap();
        let movers = [
            ExactShape::new(&[cube]).unwrap(),
            ExactShape::new(&[l_shape]).unwrap(),
            ExactShape::surfaces(&[square()]).unwrap(),
        ];
        let rotations = random_rotations(60, 7);
        let mut rng = NormalRng::new(11);
        let (max_travel, mut bounded, mut hits) = (1.0, 0, 0);
        for (k, rotation) in rotations.iter().enumerate() {
            let mover = &movers[k % movers.len()];
            let start = Pose::from_parts(
                Translation3::new(0.3 * rng.normal(), 0.3 * rng.normal(), 0.35),
                *rotation,
            );
            let tilt = Vector3::new(0.3 * rng.normal(), 0.3 * rng.normal(), -1.0).normalize();
            let target = [0.0, 0.01, 0.05][(k / 3) % 3];
            let o = Pose::identity();
            // Every other pose the ground moves (the other way) instead: the
            // part with fewer vertices is then the second.
            let (pa, a, dir, pb, b) = if k % 2 == 0 {
                (
                    &start,
                    CastPart::of(mover, 0),
                    tilt,
                    &o,
                    CastPart::of(&ground, 0),
                )
            } else {
                (
                    &o,
                    CastPart::of(&ground, 0),
                    -tilt,
                    &start,
                    CastPart::of(mover, 0),
                )
            };
            let got = cast_pair(pa, a, &dir, pb, b, target, max_travel).unwrap();
            let options = ShapeCastOptions {
                max_time_of_impact: max_travel,
                target_distance: target,
                stop_at_penetration: true,
                compute_impact_geometry_on_penetration: false,
            };
            let full = cast_pair_within(pa, a, &dir, pb, b, options).unwrap();
            let bound = vertex_ray_bound(pa, a.part, &dir, pb, b.part, max_travel);
            match (got, full) {
                (Some(t), Some(u)) => {
                    hits += 1;
                    assert!((t - u).abs() <= 1e-7 * max_travel, "pose {k}: {t} vs {u}");
                    if let Some(bound) = bound {
                        bounded += 1;
                        assert!(u <= bound * (1.0 + 1e-9) + 1e-12, "pose {k}: {u} > {bound}");
                    }
                }
                (None, None) => assert!(bound.is_none(), "pose {k}: a vertex hits, no cast"),
                other => panic!("pose {k}: {other:?}"),
            }
        }
        // The case is not vacuous: most poses hit, most with a bound.
        assert!(
            hits >= 40 && bounded >= 30,
            "{hits} hits, {bounded} bounded"
        );
    }

    /// Large triangles lying at the target at the start, every corner far:
    /// the travel is zero to the casts' precision.
    #[test]
    fn large_faces_at_the_target_from_the_start_travel_about_zero() {
        let block = ExactShape::surfaces(&[Mesh::cuboid(0.05, 0.05, 0.05).unwrap()]).unwrap();
        let plate = ExactShape::surfaces(&[square()]).unwrap();
        let (gap, o) = (0.02, Pose::identity());
        let start = Pose::translation(0.03, -0.01, 0.05 + gap);
        let t = exact_time_of_impact(&start, &plate, &-Vector3::z(), &o, &block, gap, 1.0)
            .unwrap()
            .unwrap();
        assert!(t <= CAST_PRECISION, "{t}");
        // A millimetre higher: the millimetre.
        let start = Pose::translation(0.03, -0.01, 0.051 + gap);
        let t = exact_time_of_impact(&start, &plate, &-Vector3::z(), &o, &block, gap, 1.0)
            .unwrap()
            .unwrap();
        assert!((t - 0.001).abs() <= CAST_PRECISION, "{t}");
        // An unbounded reach: the first hit's travel is not taken as zero,
        // the earliest hit is. The plate tilted and moved over the block in
        // many ways (in some no corner is over it, in some the triangle cast
        // first is not the one that hits first), against the travel to the
        // lowest corner of the block's top face under the tilted plane.
        let mut compared = 0;
        for (i, j, roll, pitch) in (0..9).flat_map(|i| {
            (0..9).flat_map(move |j| {
                [(0.1, 0.05), (-0.1, 0.05), (0.05, -0.1), (-0.07, -0.07)].map(|(r, p)| (i, j, r, p))
            })
        }) {
            let (x, y) = (0.05 * f64::from(i) - 0.2, 0.05 * f64::from(j) - 0.2);
            let tilted = Pose::from_parts(
                Translation3::new(x, y, 0.3),
                nalgebra::UnitQuaternion::from_euler_angles(roll, pitch, 0.0),
            );
            let down = -Vector3::z();
            let u = exact_time_of_impact(&tilted, &plate, &down, &o, &block, 0.0, Real::INFINITY)
                .unwrap();
            let normal = tilted.rotation * Vector3::z();
            let inverse = tilted.inverse();
            // The block's top corners under the plate, and their travels.
            let lowest = [(-0.05, -0.05), (-0.05, 0.05), (0.05, -0.05), (0.05, 0.05)]
                .iter()
                .filter_map(|&(cx, cy)| {
                    let p = Point3::new(cx, cy, 0.05);
                    let t = -(p.coords - tilted.translation.vector).dot(&normal) / normal.z;
                    let local = inverse * (p + Vector3::z() * t);
                    (local.x.abs() < 0.2 && local.y.abs() < 0.2).then_some(t)
                })
                .fold(Real::INFINITY, Real::min);
            // Only where the block's top corners decide it (a plate edge may
            // meet the block first where the plate overhangs no corner).
            let covered = [(-0.05, -0.05), (0.05, 0.05)].iter().all(|&(cx, cy)| {
                let local = inverse * Point3::new(cx, cy, 0.05);
                local.x.abs() < 0.15 && local.y.abs() < 0.15
            });
            if covered {
                let u = u.unwrap();
                assert!(
                    (u - lowest).abs() <= 1e-9,
                    "({x}, {y}, {roll}, {pitch}): {u} vs {lowest}"
                );
                compared += 1;
            }
        }
        assert!(compared >= 20, "{compared}");
    }
}
