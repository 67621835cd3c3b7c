//! The signed distance to a triangle mesh: exact closest points on a hierarchy
//! of its triangles, with a sign that survives the meshes robots ship (see
//! [`MeshDistance`]).

use std::sync::{Arc, OnceLock};

use parry3d_f64::query;
use parry3d_f64::shape::Triangle;
use rayon::prelude::*;

use super::signed_bvh::{
    closest_on_triangle, ray_crossing, solid_angle, BoundaryFans, Box3, Feature, Tri, TriangleBvh,
};
use super::signed_topology::{MeshTopology, Repaired, NONE};
use super::Mesh;
use crate::error::{Error, Result};
use crate::math::{Point3, Pose, Vector3};
use crate::Real;

/// How a [`MeshDistance`] tells inside from outside.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SignMethod {
    /// The angle-weighted pseudo-normal of the closest feature (Bærentzen &
    /// Aanæs 2005): exact for a closed, consistently oriented mesh without
    /// self-intersections, at no cost beyond the closest point.
    PseudoNormal,
    /// The generalized winding number `w` (Jacobson et al. 2013), inside when
    /// `w > 1/2`: for open, non-manifold, overlapping or self-intersecting
    /// meshes.
    WindingNumber,
}

impl SignMethod {
    /// `"pseudo_normal"` or `"winding_number"`.
    pub fn name(self) -> &'static str {
        match self {
            SignMethod::PseudoNormal => "pseudo_normal",
            SignMethod::WindingNumber => "winding_number",
        }
    }
}

/// The closest point of a mesh's surface to a query point, with the signed
/// distance and its gradient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// The signed distance (metres): negative inside.
    pub signed_distance: Real,
    /// The closest point on the surface.
    pub point: Point3,
    /// The unit gradient of the signed distance at the query point: from the
    /// closest point towards the query point when outside, the reverse when
    /// inside (the outward normal, either way). On the surface (distance 0),
    /// the pseudo-normal of the closest feature
    /// ([`SignMethod::PseudoNormal`]) or the closest face's normal
    /// ([`SignMethod::WindingNumber`]).
    pub normal: Vector3,
    /// The index of the face the closest point lies on (`usize::MAX` for a
    /// non-finite query point).
    pub face: usize,
}

impl ClosestPoint {
    /// The answer for a non-finite query point.
    const NAN: ClosestPoint = ClosestPoint {
        signed_distance: Real::NAN,
        point: Point3::new(Real::NAN, Real::NAN, Real::NAN),
        normal: Vector3::new(Real::NAN, Real::NAN, Real::NAN),
        face: usize::MAX,
    };

    /// The unsigned distance.
    pub fn distance(&self) -> Real {
        self.signed_distance.abs()
    }

    /// Whether the query point is inside (signed distance below 0).
    pub fn is_inside(&self) -> bool {
        self.signed_distance < 0.0
    }
}

/// The fan that closes one boundary loop: triangles `(a, b, apex)` over its
/// edges, inside the ball of `radius` about `apex`, of total `area`.
#[derive(Debug, Clone)]
pub(crate) struct Cap {
    pub(crate) apex: Point3,
    pub(crate) edges: Vec<[Point3; 2]>,
    pub(crate) radius: Real,
    pub(crate) area: Real,
}

impl Cap {
    /// The fan's winding number at `c`, its gradient there and a bound on the
    /// norm of its Hessian over box `b`: `sum_e l_e / (2 pi g_e^2 g_e)` over
    /// the boundary edges `e` (length `l_e`, ball at least `g_e` from `b`).
    /// The gradient of a solid angle is the Biot-Savart field of its boundary
    /// loop, `grad w(x) = (1 / 4 pi) sum_e integral over e of
    /// (y - x) x dy / |y - x|^3`, whose derivative has norm at most `2 |dy| /
    /// |y - x|^3` per element. `None` if an edge's ball reaches the box.
    pub(crate) fn derivatives(&self, c: &Point3, b: &Box3) -> Option<(Real, Vector3, Real)> {
        let four_pi = 4.0 * std::f64::consts::PI;
        let mut gradient = Vector3::zeros();
        let mut hessian = 0.0;
        for [p, q] in &self.edges {
            let len = (q - p).norm();
            let mid = Point3::from(0.5 * (p.coords + q.coords));
            let gap = b.distance2_to_point(&mid).sqrt() - 0.5 * len;
            if gap <= 0.0 {
                return None;
            }
            hessian += 2.0 * len / (gap * gap * gap);
            let (u, v) = (p - c, q - c);
            let (lu, lv) = (u.norm(), v.norm());
            let den = lu * lv * (lu * lv + u.dot(&v));
            if den > 0.0 {
                gradient += u.cross(&v) * ((lu + lv) / den);
            }
        }
        Some((
            self.winding_number(c),
            gradient / four_pi,
            hessian / four_pi,
        ))
    }

    /// The fan's winding number at `p`.
    pub(crate) fn winding_number(&self, p: &Point3) -> Real {
        self.edges
            .iter()
            .map(|[a, b]| solid_angle(p, a, b, &self.apex))
            .sum::<Real>()
            / (4.0 * std::f64::consts::PI)
    }
}

/// Per triangle, the pseudo-normals of its features (not normalised).
#[derive(Debug, Clone, Copy)]
struct PseudoNormals {
    face: Vector3,
    edges: [Vector3; 3],
    vertices: [Vector3; 3],
}

/// Below this many points the batch queries run on the calling thread.
const PARALLEL_MIN: usize = 256;

/// A triangle mesh prepared for signed-distance queries in its own frame: a
/// hierarchy over its triangles and the sign method its topology calls for.
///
/// # The sign
///
/// A [`MeshDistance`] first welds vertices with equal coordinates, re-orients
/// faces to agree with their neighbours (across edges shared by exactly two
/// faces) and turns shells with a negative volume outwards ([`MeshTopology`]
/// reports what it did). The sign is then read one of two ways, chosen from
/// the repaired topology ([`SignMethod`]):
///
/// - **Angle-weighted pseudo-normals** (Bærentzen & Aanæs, "Signed distance
///   computation using the angle weighted pseudonormal", IEEE TVCG 2005) when
///   the mesh bounds a solid without ambiguity: closed (every edge shared by
///   two faces running it in opposite directions), no degenerate face, shells
///   whose boxes are disjoint, and no two faces sharing no vertex that touch or
///   cross. The point is inside when it lies behind the pseudo-normal of the
///   feature (face, edge or corner) its closest point is on. It costs nothing
///   beyond the closest point.
/// - **The generalized winding number** (Jacobson, Kavan & Sorkine-Hornung,
///   "Robust inside-outside segmentation using generalized winding numbers",
///   SIGGRAPH 2013) otherwise: `w(p)`, the sum of the faces' signed solid angles
///   over `4 pi`, is 1 inside and 0 outside a closed surface, and degrades
///   gracefully with holes, duplicated or missing faces, overlapping and nested
///   shells and non-manifold edges. **A point is inside when `w(p) > 1/2`**:
///   for an open mesh that is the region the surface encloses after its holes
///   are closed by the surfaces of least area spanning them, roughly (a cube
///   with a missing face: `w = 5/6` at its centre, `1/2` on the plane of the
///   opening). It is evaluated exactly (no approximation) as `w = k + w_C`:
///   each boundary loop is closed by a fan `C` from the mean of its vertices,
///   `k` is the integer winding number of the closed surface `S - C` (signed
///   crossings of a ray, retried along another direction when one grazes an
///   edge or a corner within rounding), and `w_C` the fans' solid angles
///   (bounded instead where they are far and small). Should every direction
///   graze, the hierarchy sums it: a subtree whose box does not hold the point
///   counts as the fan over its boundary edges, which has the same winding
///   number there.
///
/// Inside overlapping or self-intersecting shells the distance is to the
/// nearest face, internal faces included (the distance to the triangles, as a
/// brute force over them gives): the sign is that of the union, the magnitude
/// can be less than the depth below the union's boundary.
///
/// # Non-finite points
///
/// A query point with a NaN or infinite coordinate gives NaN (distance, point
/// and normal; face `usize::MAX`), never a panic and never an error.
///
/// Built once ([`MeshDistance::new`]); every query takes `&self` and is safe to
/// run from many threads.
///
/// # Example
///
/// ```
/// use cloudprox::prelude::*;
/// use cloudprox::shape::{MeshDistance, SignMethod};
///
/// let cube = MeshDistance::new(&Mesh::cuboid(0.1, 0.1, 0.1).unwrap()).unwrap();
/// assert_eq!(cube.sign_method(), SignMethod::PseudoNormal);
/// assert!((cube.signed_distance(&Point3::new(0.3, 0.0, 0.0)) - 0.2).abs() < 1e-12);
/// let c = cube.closest(&Point3::new(0.0, 0.0, 0.05));
/// assert!((c.signed_distance + 0.05).abs() < 1e-12); // inside: negative
/// assert!((c.normal - Vector3::z()).norm() < 1e-12);
/// ```
#[derive(Debug, Clone)]
pub struct MeshDistance {
    bvh: TriangleBvh,
    method: SignMethod,
    topology: MeshTopology,
    /// Per triangle (leaf order), its unit normal (zero when degenerate).
    normals: Vec<Vector3>,
    /// Per triangle (leaf order), with [`SignMethod::PseudoNormal`].
    pseudo: Vec<PseudoNormals>,
    /// The fans closing the boundary loops (none for a closed mesh).
    caps: Vec<Cap>,
    /// The hierarchical winding number's fans (the fallback when every ray
    /// grazes), made on first use.
    fans: Arc<OnceLock<BoundaryFans>>,
    /// The convex hull's vertices (every vertex when the hull is flat),
    /// made on first use ([`MeshDistance::support`]).
    hull: Arc<OnceLock<Vec<Point3>>>,
    positions: Arc<Vec<Point3>>,
    num_faces: usize,
}

impl MeshDistance {
    /// Prepares `mesh` for signed-distance queries, choosing the sign method
    /// from its topology (see [`MeshDistance`]).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if every face of the mesh is degenerate (zero
    /// area: there is no surface to be inside of).
    pub fn new(mesh: &Mesh) -> Result<Self> {
        Self::build(mesh, None)
    }

    /// [`MeshDistance::new`] with the sign method forced. Pseudo-normals on a
    /// mesh that is not closed read, at each boundary edge, the face normal;
    /// their sign can then jump away from the surface near the boundary, which
    /// a [`DistanceField`](super::DistanceField)'s bound does not account for.
    ///
    /// # Errors
    /// As [`MeshDistance::new`].
    pub fn with_sign_method(mesh: &Mesh, method: SignMethod) -> Result<Self> {
        Self::build(mesh, Some(method))
    }

    fn build(mesh: &Mesh, forced: Option<SignMethod>) -> Result<Self> {
        let rep = Repaired::new(mesh);
        if rep.degenerate.iter().all(|&d| d) {
            return Err(Error::invalid(format!(
                "mesh has no surface: all {} faces are degenerate (zero area)",
                mesh.faces().len()
            )));
        }
        let tris: Vec<Tri> = rep
            .faces
            .iter()
            .enumerate()
            .map(|(f, ids)| Tri {
                corners: ids.map(|i| rep.positions[i as usize]),
                ids: *ids,
                face: f as u32,
            })
            .collect();
        let bvh = TriangleBvh::new(&tris);
        let face_normal = |f: usize| -> Vector3 {
            if rep.degenerate[f] {
                return Vector3::zeros();
            }
            let [a, b, c] = rep.faces[f].map(|i| rep.positions[i as usize]);
            (b - a).cross(&(c - a)).normalize()
        };
        let mut topology = rep.summary.clone();
        let method = match forced {
            Some(m) => m,
            None => {
                if topology.closed && topology.degenerate_faces == 0 && shells_apart(&rep, &bvh) {
                    let crossing = self_intersecting(&bvh);
                    topology.self_intersecting = Some(crossing);
                    if crossing {
                        SignMethod::WindingNumber
                    } else {
                        SignMethod::PseudoNormal
                    }
                } else {
                    SignMethod::WindingNumber
                }
            }
        };
        let normals: Vec<Vector3> = bvh
            .tris()
            .iter()
            .map(|t| face_normal(t.face as usize))
            .collect();
        let pseudo = if method == SignMethod::PseudoNormal {
            pseudo_normals(&rep, &bvh, &face_normal)
        } else {
            Vec::new()
        };
        // Empty for a closed mesh; also made when pseudo-normals are forced on
        // an open one, for its winding number.
        let caps = caps(&rep);
        let fans = OnceLock::new();
        Ok(Self {
            bvh,
            method,
            topology,
            normals,
            pseudo,
            caps,
            fans: Arc::new(fans),
            hull: Arc::new(OnceLock::new()),
            positions: Arc::new(rep.positions),
            num_faces: mesh.faces().len(),
        })
    }

    /// How the sign is read: [`SignMethod::PseudoNormal`] for a closed,
    /// consistently oriented mesh without self-intersections (after repair),
    /// [`SignMethod::WindingNumber`] otherwise.
    pub fn sign_method(&self) -> SignMethod {
        self.method
    }

    /// What welding and re-orientation found (and decided the sign method).
    pub fn topology(&self) -> &MeshTopology {
        &self.topology
    }

    /// The number of faces of the mesh.
    pub fn num_faces(&self) -> usize {
        self.num_faces
    }

    /// The mesh's support point along `dir`: a vertex farthest along it
    /// (the first of the convex hull's vertices to attain the largest
    /// `p . dir`).
    pub fn support(&self, dir: &Vector3) -> Point3 {
        let hull = self.hull.get_or_init(|| {
            parry3d_f64::transformation::try_convex_hull(&self.positions)
                .map_or_else(|_| self.positions.to_vec(), |(points, _)| points)
        });
        hull.iter()
            .copied()
            .fold((Real::NEG_INFINITY, Point3::origin()), |best, p| {
                let h = p.coords.dot(dir);
                if h > best.0 {
                    (h, p)
                } else {
                    best
                }
            })
            .1
    }

    /// The lower and upper corners of the mesh's bounding box.
    pub fn bounds(&self) -> (Point3, Point3) {
        let b = self.bvh.bounds();
        (Point3::from(b.mins), Point3::from(b.maxs))
    }

    /// The unsigned distance from `p` to the surface (NaN for a non-finite `p`).
    pub fn distance(&self, p: &Point3) -> Real {
        if !finite(p) {
            return Real::NAN;
        }
        self.bvh
            .nearest(p, Real::INFINITY, None)
            .map_or(Real::NAN, |(_, d2)| d2.sqrt())
    }

    /// The signed distance from `p` to the surface: negative inside.
    ///
    /// # Returns
    /// `-d` inside, `d` outside, with `d` the distance to the closest point of
    /// the surface; NaN for a non-finite `p`.
    ///
    /// # Example
    /// ```
    /// # use cloudprox::prelude::*;
    /// # use cloudprox::shape::MeshDistance;
    /// let d = MeshDistance::new(&Mesh::cylinder(0.1, 0.2, 64).unwrap()).unwrap();
    /// assert!((d.signed_distance(&Point3::new(0.0, 0.0, 0.15)) + 0.05).abs() < 1e-12);
    /// ```
    ///
    /// # See also
    /// [`MeshDistance::closest`] for the closest point and the gradient.
    pub fn signed_distance(&self, p: &Point3) -> Real {
        self.closest(p).signed_distance
    }

    /// The closest point of the surface to `p`, the signed distance and its
    /// unit gradient (see [`ClosestPoint`]).
    pub fn closest(&self, p: &Point3) -> ClosestPoint {
        if !finite(p) {
            return ClosestPoint::NAN;
        }
        match self.bvh.nearest(p, Real::INFINITY, None) {
            Some((t, _)) => self.resolve(p, t),
            None => ClosestPoint::NAN,
        }
    }

    /// [`MeshDistance::closest`] if the surface is within `max_distance` of
    /// `p`, else `None`, found without searching farther (for broad phases:
    /// a point far from every triangle costs a few box tests).
    ///
    /// `None` says only that the unsigned distance exceeds `max_distance`; use
    /// [`MeshDistance::contains`] for the side. A negative or NaN
    /// `max_distance` gives `None`; a non-finite `p` gives the NaN answer.
    pub fn closest_within(&self, p: &Point3, max_distance: Real) -> Option<ClosestPoint> {
        if !finite(p) {
            return Some(ClosestPoint::NAN);
        }
        if max_distance.is_nan() || max_distance < 0.0 {
            return None;
        }
        let (t, _) = self.bvh.nearest(p, max_distance * max_distance, None)?;
        Some(self.resolve(p, t))
    }

    /// The generalized winding number of the (repaired) mesh at `p`: 1 inside
    /// and 0 outside a closed surface, fractional near holes. Exact (no
    /// approximation); NaN for a non-finite `p`.
    ///
    /// It is the integer winding number `k` of the surface closed by fans over
    /// its holes (signed crossings of a ray, retried along another direction
    /// when one grazes an edge), plus the fans' own winding number; or, if
    /// every direction grazes, the sum over the hierarchy.
    pub fn winding_number(&self, p: &Point3) -> Real {
        if !finite(p) {
            return Real::NAN;
        }
        match self.closed_winding(p) {
            Some(k) => Real::from(k) + self.caps.iter().map(|c| c.winding_number(p)).sum::<Real>(),
            None => self.fans().winding_number(&self.bvh, p),
        }
    }

    /// Whether the winding number at `p` exceeds 1/2, evaluating the fans
    /// exactly only where their bounds leave it in doubt.
    fn winding_inside(&self, p: &Point3) -> bool {
        let Some(k) = self.closed_winding(p) else {
            return self.fans().winding_number(&self.bvh, p) > 0.5;
        };
        let mut w = Real::from(k);
        let mut doubt = 0.0;
        let mut far = Vec::new();
        for cap in &self.caps {
            let gap = (p - cap.apex).norm() - cap.radius;
            let bound = if gap > 0.0 {
                cap.area / (4.0 * std::f64::consts::PI * gap * gap)
            } else {
                Real::INFINITY
            };
            if bound < 0.05 {
                doubt += bound;
                far.push(cap);
            } else {
                w += cap.winding_number(p);
            }
        }
        if (w - 0.5).abs() <= doubt {
            w += far.iter().map(|c| c.winding_number(p)).sum::<Real>();
        }
        w > 0.5
    }

    /// The integer winding number at `p` of the surface closed by the fans
    /// over its holes, by signed ray crossings; `None` if every direction
    /// tried grazes an edge or a corner.
    fn closed_winding(&self, p: &Point3) -> Option<i32> {
        // Directions with no simple relation to the axes or to each other.
        const DIRECTIONS: [[Real; 3]; 6] = [
            [0.267_261_2, 0.534_522_5, 0.801_783_7],
            [-0.618_034, 0.381_966, 0.687_157],
            [0.7, -0.3, -0.6],
            [-0.235_702, -0.942_809, 0.235_702],
            [0.912_870_9, 0.182_574_2, -0.365_148_4],
            [-0.408_248_3, 0.408_248_3, -0.816_496_6],
        ];
        'directions: for d in DIRECTIONS {
            let d = Vector3::from(d);
            let Some(mut k) = self.bvh.ray_crossings(p, &d) else {
                continue;
            };
            for cap in &self.caps {
                for [a, b] in &cap.edges {
                    // The fans count reversed: the surface minus them is closed.
                    match ray_crossing(p, &d, b, a, &cap.apex) {
                        Some(x) => k += x,
                        None => continue 'directions,
                    }
                }
            }
            return Some(k);
        }
        None
    }

    /// Whether `p` is inside: behind the closest feature's pseudo-normal, or
    /// winding number above 1/2, per [`MeshDistance::sign_method`]. False for
    /// a non-finite `p`.
    pub fn contains(&self, p: &Point3) -> bool {
        if !finite(p) {
            return false;
        }
        match self.method {
            SignMethod::PseudoNormal => self.closest(p).is_inside(),
            SignMethod::WindingNumber => self.winding_inside(p),
        }
    }

    /// [`MeshDistance::signed_distance`] of each point (in parallel for large
    /// batches).
    pub fn signed_distance_many(&self, points: &[Point3]) -> Vec<Real> {
        Self::map(points, |p| self.signed_distance(p))
    }

    /// [`MeshDistance::closest`] of each point (in parallel for large batches).
    pub fn closest_many(&self, points: &[Point3]) -> Vec<ClosestPoint> {
        Self::map(points, |p| self.closest(p))
    }

    /// [`MeshDistance::closest_within`] of each point (in parallel for large
    /// batches).
    pub fn closest_within_many(
        &self,
        points: &[Point3],
        max_distance: Real,
    ) -> Vec<Option<ClosestPoint>> {
        Self::map(points, |p| self.closest_within(p, max_distance))
    }

    /// [`MeshDistance::closest`] of points given in the world frame, for the
    /// mesh placed at `pose`: the answer (point and normal) in the world frame.
    pub fn closest_at(&self, pose: &Pose, p: &Point3) -> ClosestPoint {
        let mut c = self.closest(&pose.inverse_transform_point(p));
        c.point = pose * c.point;
        c.normal = pose * c.normal;
        c
    }

    fn map<T: Send>(points: &[Point3], f: impl Fn(&Point3) -> T + Sync + Send) -> Vec<T> {
        if points.len() < PARALLEL_MIN {
            points.iter().map(f).collect()
        } else {
            points.par_iter().with_min_len(64).map(f).collect()
        }
    }

    fn fans(&self) -> &BoundaryFans {
        self.fans
            .get_or_init(|| BoundaryFans::new(&self.bvh, &self.positions))
    }

    /// The answer for `p` whose nearest triangle (leaf order) is `t`.
    fn resolve(&self, p: &Point3, t: u32) -> ClosestPoint {
        let tri = &self.bvh.tris()[t as usize];
        let [a, b, c] = &tri.corners;
        let (q, feature) = closest_on_triangle(p, a, b, c);
        // The distance as the hierarchy and the distance field measure it.
        let d = self.bvh.distance2(p, t).sqrt();
        let inside = self.inside_given(p, &q, t, feature);
        let scale = 1e-14 * self.bvh.bounds().diagonal();
        let gap = (p - q).norm();
        let normal = if d > scale && gap > 0.0 {
            let n = (p - q) / gap;
            if inside {
                -n
            } else {
                n
            }
        } else {
            let n = match self.method {
                SignMethod::PseudoNormal => self.feature_normal(t, feature),
                SignMethod::WindingNumber => self.normals[t as usize],
            };
            n.try_normalize(0.0).unwrap_or_else(Vector3::z)
        };
        ClosestPoint {
            signed_distance: if inside { -d } else { d },
            point: q,
            normal,
            face: tri.face as usize,
        }
    }

    /// The pseudo-normal of `feature` of triangle `t` (leaf order).
    fn feature_normal(&self, t: u32, feature: Feature) -> Vector3 {
        let pn = &self.pseudo[t as usize];
        match feature {
            Feature::Face => pn.face,
            Feature::Edge(k) => pn.edges[k as usize],
            Feature::Vertex(k) => pn.vertices[k as usize],
        }
    }

    /// Whether `p`, whose closest point `q` is on `feature` of triangle `t`, is
    /// inside.
    pub(crate) fn inside_given(&self, p: &Point3, q: &Point3, t: u32, feature: Feature) -> bool {
        match self.method {
            SignMethod::PseudoNormal => (p - q).dot(&self.feature_normal(t, feature)) < 0.0,
            SignMethod::WindingNumber => self.winding_inside(p),
        }
    }

    /// The hierarchy (for the distance field).
    pub(crate) fn bvh(&self) -> &TriangleBvh {
        &self.bvh
    }

    /// The fans closing the boundary loops (empty for a closed mesh).
    pub(crate) fn caps(&self) -> &[Cap] {
        &self.caps
    }
}

/// Whether every coordinate is finite.
fn finite(p: &Point3) -> bool {
    p.coords.iter().all(|c| c.is_finite())
}

/// Whether the shells' boxes are pairwise disjoint (so that no shell can hold
/// or cross another).
fn shells_apart(rep: &Repaired, bvh: &TriangleBvh) -> bool {
    if rep.summary.shells <= 1 {
        return true;
    }
    let mut boxes = vec![Box3::EMPTY; rep.summary.shells];
    for t in bvh.tris() {
        let s = rep.shell[t.face as usize];
        if s != NONE {
            boxes[s as usize] = boxes[s as usize].merged(&Box3::of_triangle(&t.corners));
        }
    }
    boxes.sort_unstable_by(|a, b| a.mins[0].total_cmp(&b.mins[0]));
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            if b.mins[0] > a.maxs[0] {
                break;
            }
            if a.distance2_to_box(b) == 0.0 {
                return false;
            }
        }
    }
    true
}

/// Whether two triangles that share no vertex touch or cross.
fn self_intersecting(bvh: &TriangleBvh) -> bool {
    let tris = bvh.tris();
    let margin = 1e-9 * bvh.bounds().diagonal();
    let id = Pose::identity();
    bvh.any_overlapping_pair(margin, &mut |s, t| {
        let (a, b) = (&tris[s as usize], &tris[t as usize]);
        if a.ids.iter().any(|i| b.ids.contains(i)) {
            return false;
        }
        if separated_by_plane(&a.corners, &b.corners, margin)
            || separated_by_plane(&b.corners, &a.corners, margin)
        {
            return false;
        }
        let ta = Triangle::new(a.corners[0], a.corners[1], a.corners[2]);
        let tb = Triangle::new(b.corners[0], b.corners[1], b.corners[2]);
        query::distance(&id, &ta, &id, &tb).map_or(true, |d| d <= margin)
    })
}

/// Whether `b`'s corners are all more than `margin` on one side of `a`'s plane.
fn separated_by_plane(a: &[Point3; 3], b: &[Point3; 3], margin: Real) -> bool {
    let n = (a[1] - a[0]).cross(&(a[2] - a[0]));
    let len = n.norm();
    if len == 0.0 {
        return false;
    }
    let n = n / len;
    let s = b.map(|v| n.dot(&(v - a[0])));
    s.iter().all(|&x| x > margin) || s.iter().all(|&x| x < -margin)
}

/// The pseudo-normals of every triangle's features (leaf order): the face's
/// normal, each edge's sum of its two faces' normals, each corner's sum of its
/// faces' normals weighted by their angle there.
fn pseudo_normals(
    rep: &Repaired,
    bvh: &TriangleBvh,
    face_normal: &impl Fn(usize) -> Vector3,
) -> Vec<PseudoNormals> {
    let mut at_vertex = vec![Vector3::zeros(); rep.positions.len()];
    for (f, ids) in rep.faces.iter().enumerate() {
        let n = face_normal(f);
        let p = ids.map(|i| rep.positions[i as usize]);
        for k in 0..3 {
            let u = p[(k + 1) % 3] - p[k];
            let v = p[(k + 2) % 3] - p[k];
            let angle = u.cross(&v).norm().atan2(u.dot(&v));
            at_vertex[ids[k] as usize] += n * angle;
        }
    }
    bvh.tris()
        .iter()
        .map(|t| {
            let f = t.face as usize;
            let n = face_normal(f);
            let edges = std::array::from_fn(|k| {
                let g = rep.neighbors[f][k];
                if g == NONE {
                    n
                } else {
                    n + face_normal(g as usize)
                }
            });
            PseudoNormals {
                face: n,
                edges,
                vertices: t.ids.map(|i| at_vertex[i as usize]),
            }
        })
        .collect()
}

/// The fans that close the boundary loops: one apex per loop, at the mean of
/// its vertices.
fn caps(rep: &Repaired) -> Vec<Cap> {
    rep.boundary_loops()
        .into_iter()
        .map(|edges| {
            let mut sum = Vector3::zeros();
            for [a, _] in &edges {
                sum += rep.positions[*a as usize].coords;
            }
            let apex = Point3::from(sum / edges.len() as Real);
            let edges: Vec<[Point3; 2]> = edges
                .iter()
                .map(|&[a, b]| [rep.positions[a as usize], rep.positions[b as usize]])
                .collect();
            let radius = edges
                .iter()
                .map(|[a, _]| (a - apex).norm())
                .fold(0.0, Real::max);
            let area = edges
                .iter()
                .map(|[a, b]| 0.5 * (a - apex).cross(&(b - apex)).norm())
                .sum();
            Cap {
                apex,
                edges,
                radius,
                area,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fans_gradient_is_the_biot_savart_field_of_its_loop() {
        // A square loop, fanned from its centre, seen from points off it.
        let corners = [
            Point3::new(-0.1, -0.1, 0.0),
            Point3::new(0.1, -0.1, 0.0),
            Point3::new(0.1, 0.1, 0.02),
            Point3::new(-0.1, 0.1, 0.0),
        ];
        let cap = Cap {
            apex: Point3::origin(),
            edges: (0..4).map(|k| [corners[k], corners[(k + 1) % 4]]).collect(),
            radius: 0.15,
            area: 0.04,
        };
        for p in [
            Point3::new(0.03, 0.02, 0.25),
            Point3::new(0.4, -0.1, -0.03),
            Point3::new(-0.05, 0.45, 0.1),
        ] {
            let b = Box3 {
                mins: p.into(),
                maxs: p.into(),
            };
            let (w, g, _) = cap.derivatives(&p, &b).unwrap_or_else(|| panic!("{p:?}"));
            let e = 1e-6;
            let fd = Vector3::from_fn(|k, _| {
                let mut a = p;
                let mut z = p;
                a[k] += e;
                z[k] -= e;
                (cap.winding_number(&a) - cap.winding_number(&z)) / (2.0 * e)
            });
            assert!(
                (g - fd).norm() < 1e-6 * (1.0 + fd.norm()),
                "{p:?}: {g:?} vs {fd:?}"
            );
            assert_eq!(w, cap.winding_number(&p));
        }
    }
}
