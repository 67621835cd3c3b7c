//! A convex polyhedron whose support function climbs its edges.
//!
//! parry's [`ConvexPolyhedron`] finds a support point (the vertex farthest along
//! a direction) by scanning every vertex. GJK asks for one at each of its
//! iterations, so a shape cast of a hull of hundreds of vertices against a
//! scanned surface spends most of its time in these scans. On a convex
//! polytope the farthest vertex can instead be reached by walking along edges,
//! each step to a neighbour farther along the direction: a vertex that is not
//! farthest always has an edge that leads farther (the simplex method's
//! property), so the walk ends only at the farthest one. Started from the best
//! of a few precomputed extreme vertices, the walk visits a handful of
//! vertices and their neighbours instead of all of them.
//!
//! On an exactly convex hull the point returned is the scan's: the same dot
//! products (same arithmetic) decide, and where the walk ends beside a vertex
//! exactly as far (a face or an edge square to the direction) it hands the
//! choice to parry's scan, whose first maximum is the lowest index. A mesh
//! accepted as convex within a tolerance (or near-coplanar faces, where the
//! rounded dot products are not exactly linear) can end the walk at a vertex
//! within that tolerance of the farthest.

use parry3d_f64::bounding_volume::{Aabb, BoundingSphere};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::Isometry;
use parry3d_f64::math::{Point, Real, Vector};
use parry3d_f64::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d_f64::shape::{ConvexPolyhedron, FeatureId, Shape, ShapeType, SupportMap, TypedShape};
use parry3d_f64::utils::point_cloud_support_point_id;

/// Hulls with fewer vertices are scanned: a walk would not be cheaper.
pub(crate) const MIN_CLIMBING_VERTICES: usize = 48;

/// A convex polyhedron with its vertices' neighbours (along edges of the
/// triangles it was built from) and a few extreme vertices to start walks from.
#[derive(Clone)]
pub(crate) struct ClimbingHull {
    poly: ConvexPolyhedron,
    /// Vertex `v`'s neighbours are `neighbours[offsets[v]..offsets[v + 1]]`.
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
    /// The farthest vertices along the 26 directions to a cube's faces, edges
    /// and corners, each once, by increasing index.
    seeds: Vec<u32>,
}

impl ClimbingHull {
    /// The hull `poly`, built by parry from exactly `triangles` over its own
    /// points (their edges include every edge of the polytope). `None` when a
    /// triangle names a vertex the polyhedron does not have, a vertex is in no
    /// triangle (a walk could neither leave nor reach it, and the scan may
    /// pick it), or the polyhedron has too few vertices for a walk to pay.
    pub(crate) fn new(poly: &ConvexPolyhedron, triangles: &[[u32; 3]]) -> Option<Self> {
        let n = poly.points().len();
        if n < MIN_CLIMBING_VERTICES || triangles.iter().flatten().any(|&v| v as usize >= n) {
            return None;
        }
        let mut pairs: Vec<(u32, u32)> = triangles
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, a), (b, c), (c, b), (c, a), (a, c)])
            .filter(|(u, v)| u != v)
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; n + 1];
        for &(u, _) in &pairs {
            offsets[u as usize + 1] += 1;
        }
        if offsets[1..].contains(&0) {
            return None;
        }
        for v in 0..n {
            offsets[v + 1] += offsets[v];
        }
        let neighbours = pairs.iter().map(|&(_, v)| v).collect();
        let mut seeds: Vec<u32> = cube_directions()
            .map(|d| point_cloud_support_point_id(&d, poly.points()) as u32)
            .collect();
        seeds.sort_unstable();
        seeds.dedup();
        Some(Self {
            poly: poly.clone(),
            offsets,
            neighbours,
            seeds,
        })
    }

    fn around(&self, v: usize) -> &[u32] {
        &self.neighbours[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// The index of the farthest vertex along `dir` (the lowest among equals).
    pub(crate) fn support_id(&self, dir: &Vector<Real>) -> usize {
        let pts = self.poly.points();
        let dot = |v: usize| pts[v].coords.dot(dir);
        let mut best = self.seeds[0] as usize;
        let mut best_dot = dot(best);
        for &s in &self.seeds[1..] {
            let d = dot(s as usize);
            if d > best_dot {
                (best, best_dot) = (s as usize, d);
            }
        }
        loop {
            let (mut next, mut next_dot, mut tie) = (best, best_dot, false);
            for &u in self.around(best) {
                let d = dot(u as usize);
                if d > next_dot {
                    (next, next_dot) = (u as usize, d);
                }
                tie |= d == best_dot;
            }
            if next != best {
                (best, best_dot) = (next, next_dot);
            } else if tie {
                // A farthest face or edge square to the direction (special
                // directions only): the scan picks among its vertices.
                return point_cloud_support_point_id(dir, pts);
            } else {
                return best;
            }
        }
    }
}

impl std::fmt::Debug for ClimbingHull {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ClimbingHull({} vertices, {} seeds)",
            self.poly.points().len(),
            self.seeds.len()
        )
    }
}

/// The 26 directions from a cube's centre to its faces, edges and corners.
fn cube_directions() -> impl Iterator<Item = Vector<Real>> {
    (0..27)
        .map(|k| {
            Vector::new(
                Real::from(k % 3) - 1.0,
                Real::from(k / 3 % 3) - 1.0,
                Real::from(k / 9) - 1.0,
            )
        })
        .filter(|d| *d != Vector::zeros())
}

impl SupportMap for ClimbingHull {
    fn local_support_point(&self, dir: &Vector<Real>) -> Point<Real> {
        self.poly.points()[self.support_id(dir)]
    }
}

impl RayCast for ClimbingHull {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_time_of_impact: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        self.poly
            .cast_local_ray_and_get_normal(ray, max_time_of_impact, solid)
    }
}

impl PointQuery for ClimbingHull {
    fn project_local_point(&self, pt: &Point<Real>, solid: bool) -> PointProjection {
        self.poly.project_local_point(pt, solid)
    }

    fn project_local_point_and_get_feature(
        &self,
        pt: &Point<Real>,
    ) -> (PointProjection, FeatureId) {
        self.poly.project_local_point_and_get_feature(pt)
    }
}

impl Shape for ClimbingHull {
    fn compute_local_aabb(&self) -> Aabb {
        self.poly.local_aabb()
    }

    fn compute_aabb(&self, position: &Isometry<Real>) -> Aabb {
        self.poly.aabb(position)
    }

    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.poly.local_bounding_sphere()
    }

    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }

    fn scale_dyn(&self, _scale: &Vector<Real>, _num_subdivisions: u32) -> Option<Box<dyn Shape>> {
        None
    }

    fn mass_properties(&self, density: Real) -> MassProperties {
        self.poly.mass_properties(density)
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn shape_type(&self) -> ShapeType {
        ShapeType::Custom
    }

    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::Custom(self)
    }

    fn ccd_thickness(&self) -> Real {
        self.poly.ccd_thickness()
    }

    fn ccd_angular_thickness(&self) -> Real {
        self.poly.ccd_angular_thickness()
    }

    fn as_support_map(&self) -> Option<&dyn SupportMap> {
        Some(self as &dyn SupportMap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::NormalRng;
    use parry3d_f64::transformation::convex_hull;

    /// Points on and inside a unit sphere (the inner ones not on the hull).
    fn ball_points(n: usize, seed: u64) -> Vec<Point<Real>> {
        let mut rng = NormalRng::new(seed);
        (0..n)
            .map(|i| {
                let v = Vector::new(rng.normal(), rng.normal(), rng.normal()).normalize();
                let r = if i % 5 == 0 { 0.5 } else { 1.0 };
                Point::from(v * r)
            })
            .collect()
    }

    fn hull(points: &[Point<Real>]) -> (ConvexPolyhedron, ClimbingHull) {
        let (v, t) = convex_hull(points);
        let poly = ConvexPolyhedron::from_convex_mesh(v, &t).expect("a hull");
        let climbing = ClimbingHull::new(&poly, &t).expect("enough vertices");
        (poly, climbing)
    }

    #[test]
    fn walks_to_the_scans_vertex_in_every_direction() {
        let (poly, climbing) = hull(&ball_points(1500, 3));
        assert!(poly.points().len() > 500);
        let mut rng = NormalRng::new(11);
        for _ in 0..5000 {
            let d = Vector::new(rng.normal(), rng.normal(), rng.normal()) * rng.normal().exp();
            assert_eq!(
                climbing.support_id(&d),
                point_cloud_support_point_id(&d, poly.points())
            );
        }
        // Towards each seed direction and the zero vector (every vertex ties).
        for d in cube_directions().chain([Vector::zeros()]) {
            assert_eq!(
                climbing.support_id(&d),
                point_cloud_support_point_id(&d, poly.points())
            );
        }
    }

    #[test]
    fn ties_go_to_the_lowest_index_as_the_scans() {
        // A prism over a 40-gon: along +z the whole top face ties, along any
        // horizontal direction each top vertex ties with the one below it.
        let k = 40;
        let mut pts = Vec::new();
        for z in [1.0, -1.0] {
            for i in 0..k {
                let a = std::f64::consts::TAU * f64::from(i) / f64::from(k);
                pts.push(Point::new(a.cos(), a.sin(), z));
            }
        }
        let (poly, climbing) = hull(&pts);
        assert_eq!(poly.points().len(), 2 * k as usize);
        let mut rng = NormalRng::new(7);
        let horizontal = (0..200).map(|_| Vector::new(rng.normal(), rng.normal(), 0.0));
        let upright = [Vector::z(), -Vector::z(), Vector::new(1e-300, 0.0, 1.0)];
        for d in cube_directions().chain(horizontal).chain(upright) {
            for s in [1.0, 1e-3, 1e6] {
                let want = point_cloud_support_point_id(&(d * s), poly.points());
                assert_eq!(climbing.support_id(&(d * s)), want, "direction {d:?}");
            }
        }
    }

    #[test]
    fn small_hulls_and_foreign_indices_are_left_to_the_scan() {
        let pts = ball_points(40, 1);
        let (v, t) = convex_hull(&pts);
        let poly = ConvexPolyhedron::from_convex_mesh(v, &t).expect("a hull");
        assert!(ClimbingHull::new(&poly, &t).is_none());
        let (poly, _) = hull(&ball_points(600, 2));
        assert!(ClimbingHull::new(&poly, &[[0, 1, poly.points().len() as u32]]).is_none());
        // A vertex in no triangle (here a duplicate of a corner, first in
        // order): no walk could leave or reach it.
        let (v, t) = convex_hull(&ball_points(600, 2));
        let mut with_unused = vec![v[0]];
        with_unused.extend(&v);
        let shifted: Vec<[u32; 3]> = t.iter().map(|f| f.map(|k| k + 1)).collect();
        let poly = ConvexPolyhedron::from_convex_mesh(with_unused, &shifted).expect("a hull");
        assert!(ClimbingHull::new(&poly, &shifted).is_none());
        assert!(ClimbingHull::new(&hull(&ball_points(600, 2)).0, &t).is_some());
    }
}
