//! Signed distance to meshes (`shape::MeshDistance`) and its grid
//! (`shape::DistanceField`) against brute force: every triangle's closest
//! point (parry's projection, an implementation of its own) and the exact
//! generalized winding number summed over all faces, on closed, open and
//! non-manifold meshes; the field's error bound on random points; invariance
//! under rigid motion; bad inputs.

use std::sync::Arc;

use cloudprox::prelude::*;
use cloudprox::robot::{capsule_mesh, sphere_mesh};
use cloudprox::sample::NormalRng;
use cloudprox::shape::{DistanceField, FieldValue, MeshDistance, SignMethod};
use nalgebra::{Translation3, UnitQuaternion};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
use proptest::prelude::*;

/// The distance to the nearest triangle, by trying every one.
fn brute_distance(mesh: &Mesh, p: &Point3) -> f64 {
    (0..mesh.faces().len())
        .map(|f| {
            let [a, b, c] = mesh.triangle(f);
            let q = Triangle::new(a, b, c).project_local_point(p, true).point;
            (p - q).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The generalized winding number, summed over every face (solid angles by
/// the formula of Van Oosterom & Strackee).
fn brute_winding(mesh: &Mesh, p: &Point3) -> f64 {
    let mut sum = 0.0;
    for f in 0..mesh.faces().len() {
        let [a, b, c] = mesh.triangle(f).map(|v| v - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// Random points: on the surface moved along random directions by up to
/// `near` (most of them), and uniform in the box grown by `far`.
fn probe_points(mesh: &Mesh, n: usize, near: f64, far: f64, seed: u64) -> Vec<Point3> {
    let mut rng = NormalRng::new(seed);
    let surface = mesh.sample_surface(n, seed).unwrap().points;
    let b = mesh.aabb();
    let mut out = Vec::with_capacity(2 * n);
    for s in surface {
        let dir = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
        out.push(s + dir * (near * (2.0 * rng.uniform() - 1.0)));
    }
    for _ in 0..n {
        out.push(Point3::new(
            b.mins.x - far + (b.maxs.x - b.mins.x + 2.0 * far) * rng.uniform(),
            b.mins.y - far + (b.maxs.y - b.mins.y + 2.0 * far) * rng.uniform(),
            b.mins.z - far + (b.maxs.z - b.mins.z + 2.0 * far) * rng.uniform(),
        ));
    }
    out
}

/// `MeshDistance` of `mesh` against brute force over `reference` (the
/// triangles, and the solid whose winding number says inside): distances to
/// 1e-12, signs wherever the winding number is not within `margin` of 1/2
/// and the point is not on the surface, and the gradient.
fn check_against_brute_force(
    mesh: &Mesh,
    reference: &Mesh,
    margin: f64,
    seed: u64,
) -> MeshDistance {
    let md = MeshDistance::new(mesh).unwrap();
    let extent = mesh.aabb().diagonal_length();
    let points = probe_points(mesh, 400, 0.05 * extent, 0.5 * extent, seed);
    let mut signs = 0;
    for p in &points {
        let c = md.closest(p);
        let d = brute_distance(reference, p);
        assert!(
            (c.distance() - d).abs() < 1e-12,
            "{p:?}: {} vs brute force {d}",
            c.distance()
        );
        assert!((md.distance(p) - d).abs() < 1e-12);
        assert!(
            (c.point - p).norm() - d < 1e-12,
            "the closest point is that far"
        );
        assert!((c.normal.norm() - 1.0).abs() < 1e-12);
        let w = brute_winding(reference, p);
        if (w - 0.5).abs() > margin && d > 1e-9 * extent {
            signs += 1;
            assert_eq!(
                c.is_inside(),
                w > 0.5,
                "{p:?}: w = {w}, sd = {}",
                c.signed_distance
            );
            assert_eq!(md.contains(p), w > 0.5);
            // The gradient points from the closest point outwards.
            let out = if w > 0.5 { c.point - p } else { p - c.point };
            assert!((out / out.norm() - c.normal).norm() < 1e-9);
        }
        assert_eq!(md.signed_distance(p), c.signed_distance);
    }
    assert!(signs > points.len() / 2, "only {signs} signs checked");
    // The batch forms agree with the single queries (and run in parallel).
    let batch = md.signed_distance_many(&points);
    for (p, s) in points.iter().zip(&batch) {
        assert_eq!(*s, md.signed_distance(p));
    }
    md
}

/// Trait-free length of a box's diagonal.
trait Diagonal {
    fn diagonal_length(&self) -> f64;
}

impl Diagonal for cloudprox::bvh::Aabb {
    fn diagonal_length(&self) -> f64 {
        (self.maxs - self.mins).norm()
    }
}

/// A random convex polytope: the hull of points on an ellipsoid.
fn random_hull(n: usize, seed: u64) -> Mesh {
    let mut rng = NormalRng::new(seed);
    let pts: Vec<Point3> = (0..n)
        .map(|_| {
            let v = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            Point3::new(0.1 * v.x, 0.06 * v.y, 0.04 * v.z)
        })
        .collect();
    let (v, f) = parry3d_f64::transformation::convex_hull(&pts);
    Mesh::new(v, f).unwrap()
}

/// A cuboid without its last face (two triangles, x+).
fn open_box() -> Mesh {
    let b = Mesh::cuboid(0.1, 0.08, 0.06).unwrap();
    Mesh::new(b.vertices().to_vec(), b.faces()[..10].to_vec()).unwrap()
}

#[test]
fn closed_meshes_match_brute_force_with_pseudo_normals() {
    let meshes = [
        Mesh::cuboid(0.1, 0.05, 0.02).unwrap(),
        Mesh::cylinder(0.05, 0.1, 48).unwrap(),
        random_hull(300, 3),
        sphere_mesh(0.08).unwrap(),
        capsule_mesh(0.03, 0.2).unwrap(),
    ];
    for (k, m) in meshes.iter().enumerate() {
        let md = check_against_brute_force(m, m, 1e-6, 10 + k as u64);
        assert_eq!(md.sign_method(), SignMethod::PseudoNormal, "mesh {k}");
        assert_eq!(md.topology().self_intersecting, Some(false));
        assert!(md.topology().closed);
    }
}

#[test]
fn winding_number_is_exact_and_pseudo_normals_agree_with_it() {
    let m = Mesh::cylinder(0.05, 0.1, 32).unwrap();
    let pn = MeshDistance::new(&m).unwrap();
    let wn = MeshDistance::with_sign_method(&m, SignMethod::WindingNumber).unwrap();
    assert_eq!(wn.sign_method(), SignMethod::WindingNumber);
    for p in probe_points(&m, 300, 0.02, 0.1, 4) {
        let w = brute_winding(&m, &p);
        assert!((pn.winding_number(&p) - w).abs() < 1e-9, "{p:?}");
        assert!((wn.winding_number(&p) - w).abs() < 1e-9);
        if pn.distance(&p) > 1e-9 {
            assert_eq!(pn.signed_distance(&p), wn.signed_distance(&p));
        }
    }
}

#[test]
fn an_open_box_is_inside_where_its_winding_number_exceeds_one_half() {
    let m = open_box();
    let md = check_against_brute_force(&m, &m, 1e-6, 20);
    assert_eq!(md.sign_method(), SignMethod::WindingNumber);
    assert_eq!(md.topology().boundary_edges, 4);
    assert!(!md.topology().closed);
    // At the centre the missing face subtends 1/6 of the sphere... roughly:
    // w is well above 1/2 everywhere deep inside.
    let centre = Point3::origin();
    assert!(md.winding_number(&centre) > 0.6);
    let mut rng = NormalRng::new(21);
    for _ in 0..500 {
        // Well inside: the inner 80 % in y and z, x up to 75 % of the way to the opening.
        let p = Point3::new(
            -0.1 + 0.15 * rng.uniform(),
            0.8 * 0.08 * (2.0 * rng.uniform() - 1.0),
            0.8 * 0.06 * (2.0 * rng.uniform() - 1.0),
        );
        assert!(md.signed_distance(&p) < 0.0, "{p:?} inside");
        // Outside the box, and beyond the opening's plane.
        let q = Point3::new(0.1 + 0.05 * rng.uniform(), p.y, p.z);
        assert!(md.signed_distance(&q) > 0.0, "{q:?} outside");
    }
    // On the plane of the opening, w = 1/2 at its centre: the boundary of "inside".
    assert!((md.winding_number(&Point3::new(0.1, 0.0, 0.0)) - 0.5).abs() < 1e-9);
    // Forcing pseudo-normals leaves the winding number exact.
    let forced = MeshDistance::with_sign_method(&m, SignMethod::PseudoNormal).unwrap();
    for p in probe_points(&m, 100, 0.02, 0.05, 22) {
        assert!((forced.winding_number(&p) - brute_winding(&m, &p)).abs() < 1e-9);
    }
}

#[test]
fn non_manifold_meshes_match_brute_force_with_winding_numbers() {
    let cube = Mesh::cuboid(0.1, 0.1, 0.1).unwrap();
    // Two overlapping cuboids, one mesh: closed edges, but the shells cross.
    let two = Mesh::merged(&[
        cube.clone(),
        Mesh::cuboid(0.08, 0.05, 0.05)
            .unwrap()
            .transformed(&Pose::translation(0.12, 0.03, 0.0)),
    ])
    .unwrap();
    let md = check_against_brute_force(&two, &two, 1e-6, 30);
    assert_eq!(md.sign_method(), SignMethod::WindingNumber);
    assert_eq!(md.topology().shells, 2);
    // In the overlap the winding number is 2: inside.
    assert!(md.contains(&Point3::new(0.09, 0.03, 0.0)));

    // Two cuboids that cross each other within one shell's box (a plus sign).
    let plus = Mesh::merged(&[
        Mesh::cuboid(0.1, 0.02, 0.02).unwrap(),
        Mesh::cuboid(0.02, 0.1, 0.02).unwrap(),
    ])
    .unwrap();
    let md = check_against_brute_force(&plus, &plus, 1e-6, 31);
    assert_eq!(md.sign_method(), SignMethod::WindingNumber);

    // Duplicated faces: some edges are used by four faces.
    let mut faces = cube.faces().to_vec();
    faces.extend_from_slice(&cube.faces()[..4]);
    let dup = Mesh::new(cube.vertices().to_vec(), faces).unwrap();
    let md = check_against_brute_force(&dup, &dup, 1e-6, 32);
    assert_eq!(md.sign_method(), SignMethod::WindingNumber);
    assert!(md.topology().non_manifold_edges > 0);

    // Duplicated vertices (every face its own corners, as STL stores them):
    // welded back into a closed cube.
    let vertices: Vec<Point3> = cube
        .faces()
        .iter()
        .flat_map(|f| f.map(|i| cube.vertices()[i as usize]))
        .collect();
    let soup_faces: Vec<[u32; 3]> = (0..12u32).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
    let soup = Mesh::new(vertices, soup_faces).unwrap();
    let md = check_against_brute_force(&soup, &cube, 1e-6, 33);
    assert_eq!(md.sign_method(), SignMethod::PseudoNormal);
    assert_eq!(md.topology().vertices, 8);
}

#[test]
fn flipped_faces_are_repaired_to_the_solid_they_came_from() {
    let cube = Mesh::cuboid(0.1, 0.07, 0.05).unwrap();
    // One face flipped.
    let mut faces = cube.faces().to_vec();
    faces[5] = [faces[5][0], faces[5][2], faces[5][1]];
    let one = Mesh::new(cube.vertices().to_vec(), faces).unwrap();
    let md = check_against_brute_force(&one, &cube, 1e-6, 40);
    assert_eq!(md.topology().reoriented_faces, 1);
    assert_eq!(md.sign_method(), SignMethod::PseudoNormal);
    // Every face flipped (an inside-out export).
    let inverted: Vec<[u32; 3]> = cube.faces().iter().map(|f| [f[0], f[2], f[1]]).collect();
    let inv = Mesh::new(cube.vertices().to_vec(), inverted).unwrap();
    let md = check_against_brute_force(&inv, &cube, 1e-6, 41);
    assert_eq!(md.topology().reoriented_faces, 12);
    // A flipped face on an open mesh: repaired too (winding numbers).
    let open = open_box();
    let mut faces = open.faces().to_vec();
    faces[0] = [faces[0][0], faces[0][2], faces[0][1]];
    let flipped_open = Mesh::new(open.vertices().to_vec(), faces).unwrap();
    let md = check_against_brute_force(&flipped_open, &open, 1e-6, 42);
    assert_eq!(md.sign_method(), SignMethod::WindingNumber);
    assert_eq!(md.topology().reoriented_faces, 1);
}

#[test]
fn several_disjoint_shells_keep_pseudo_normals() {
    let m = Mesh::merged(&[
        Mesh::cuboid(0.05, 0.05, 0.05).unwrap(),
        Mesh::cylinder(0.03, 0.05, 24)
            .unwrap()
            .transformed(&Pose::translation(0.2, 0.0, 0.0)),
    ])
    .unwrap();
    let md = check_against_brute_force(&m, &m, 1e-6, 50);
    assert_eq!(md.topology().shells, 2);
    assert_eq!(md.sign_method(), SignMethod::PseudoNormal);
}

#[test]
fn the_bounded_query_stops_at_its_bound() {
    let m = Mesh::cylinder(0.05, 0.1, 32).unwrap();
    let md = MeshDistance::new(&m).unwrap();
    for p in probe_points(&m, 300, 0.05, 0.3, 60) {
        let exact = md.closest(&p);
        for bound in [0.0, 0.01, 0.05, 1.0, f64::INFINITY] {
            match md.closest_within(&p, bound) {
                Some(c) => {
                    assert!(exact.distance() <= bound);
                    assert_eq!(c, exact);
                }
                None => assert!(exact.distance() > bound),
            }
        }
        assert!(md.closest_within(&p, -1.0).is_none());
        assert!(md.closest_within(&p, f64::NAN).is_none());
    }
}

#[test]
fn distances_are_invariant_under_rigid_motion() {
    let meshes = [random_hull(100, 7), open_box()];
    let mut rng = NormalRng::new(70);
    for m in &meshes {
        let md = MeshDistance::new(m).unwrap();
        for _ in 0..5 {
            let axis = Vector3::new(rng.normal(), rng.normal(), rng.normal());
            let pose = Pose::from_parts(
                Translation3::new(rng.normal(), rng.normal(), rng.normal()),
                UnitQuaternion::from_scaled_axis(axis),
            );
            let moved = MeshDistance::new(&m.transformed(&pose)).unwrap();
            assert_eq!(moved.sign_method(), md.sign_method());
            for p in probe_points(m, 50, 0.02, 0.1, 71) {
                let a = md.closest(&p);
                let b = moved.closest(&(pose * p));
                assert!((a.signed_distance - b.signed_distance).abs() < 1e-12);
                assert!((pose * a.point - b.point).norm() < 1e-12);
                assert!((pose * a.normal - b.normal).norm() < 1e-9);
                let c = md.closest_at(&pose, &(pose * p));
                assert!((c.signed_distance - a.signed_distance).abs() < 1e-15);
                assert!((c.point - b.point).norm() < 1e-12);
            }
        }
    }
}

#[test]
fn bad_inputs_give_errors_or_nan_never_a_panic() {
    // Every face degenerate: no surface.
    let flat = Mesh::new(
        vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let err = MeshDistance::new(&flat).unwrap_err().to_string();
    assert!(err.contains("degenerate"), "{err}");
    // Two corners welded into one: degenerate too.
    let welded = Mesh::new(
        vec![
            Point3::origin(),
            Point3::origin(),
            Point3::new(0.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert!(MeshDistance::new(&welded).is_err());
    // A single triangle is a surface: never inside, distance exact.
    let tri = Mesh::new(
        vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let md = MeshDistance::new(&tri).unwrap();
    assert_eq!(md.signed_distance(&Point3::new(0.2, 0.2, -0.5)), 0.5);
    assert_eq!(md.signed_distance(&Point3::new(0.2, 0.2, 0.5)), 0.5);
    // Non-finite points: NaN.
    let cube = MeshDistance::new(&Mesh::cuboid(0.1, 0.1, 0.1).unwrap()).unwrap();
    for p in [
        Point3::new(f64::NAN, 0.0, 0.0),
        Point3::new(0.0, f64::INFINITY, 0.0),
        Point3::new(0.0, 0.0, f64::NEG_INFINITY),
    ] {
        assert!(cube.signed_distance(&p).is_nan());
        assert!(cube.distance(&p).is_nan());
        assert!(cube.winding_number(&p).is_nan());
        assert!(!cube.contains(&p));
        let c = cube.closest(&p);
        assert!(c.point.x.is_nan() && c.normal.x.is_nan() && c.face == usize::MAX);
        assert!(cube
            .closest_within(&p, 1.0)
            .unwrap()
            .signed_distance
            .is_nan());
    }
    // Fields: resolution and band positive and finite, grid not too large.
    let arc = Arc::new(cube);
    for (r, b) in [
        (0.0, 0.01),
        (-1.0, 0.01),
        (f64::NAN, 0.01),
        (0.01, 0.0),
        (0.01, f64::INFINITY),
    ] {
        let err = DistanceField::new(Arc::clone(&arc), r, b)
            .unwrap_err()
            .to_string();
        assert!(err.contains("resolution") || err.contains("band"), "{err}");
    }
    let err = DistanceField::new(Arc::clone(&arc), 1e-5, 0.01)
        .unwrap_err()
        .to_string();
    assert!(err.contains("coarser resolution"), "{err}");
    let field = DistanceField::new(arc, 0.01, 0.02).unwrap();
    let s = field.evaluate(&Point3::new(f64::NAN, 0.0, 0.0));
    assert!(s.distance.is_nan() && s.bound.is_nan());
}

/// The field's bound on `points`: `|exact - interpolated| <= bound`, and
/// every node within the band equal to the exact query's value.
fn check_field(
    md: &Arc<MeshDistance>,
    resolution: f64,
    band: f64,
    points: &[Point3],
) -> DistanceField {
    let field = DistanceField::new(Arc::clone(md), resolution, band).unwrap();
    let [nx, ny, nz] = field.dims();
    // Nodes: a sample of them, exact within the band.
    let mut rng = NormalRng::new(99);
    let mut in_band = 0;
    for _ in 0..3000 {
        let (i, j, k) = (
            (rng.uniform() * nx as f64) as usize % nx,
            (rng.uniform() * ny as f64) as usize % ny,
            (rng.uniform() * nz as f64) as usize % nz,
        );
        let x = field.node_position(i, j, k);
        let v = field.node_value(i, j, k).unwrap();
        let exact = md.closest(&x);
        if v.is_finite() {
            in_band += 1;
            assert!(
                (v.abs() - exact.distance()).abs() < 1e-15,
                "node {x:?}: {v} vs {}",
                exact.distance()
            );
            if exact.distance() > 1e-12 {
                assert_eq!(v < 0.0, exact.is_inside(), "node {x:?}");
            }
        } else {
            assert!(
                exact.distance() > band - 1e-12,
                "node {x:?} is within the band"
            );
            // NaN: the side was not certified (near a hole).
            if !v.is_nan() {
                assert_eq!(v < 0.0, md.contains(&x), "node {x:?}'s side");
            }
        }
    }
    assert!(in_band > 100);
    let mut interpolated = 0;
    let mut worst: f64 = 0.0;
    for p in points {
        let exact = md.signed_distance(p);
        let s = field.evaluate(p);
        assert!(
            (s.distance - exact).abs() <= s.bound,
            "{p:?}: field {} +- {} vs exact {exact}",
            s.distance,
            s.bound
        );
        // At most the half diagonal where the side is certified, four
        // diagonals where it is not (near a hole).
        assert!(s.bound <= 4.0 * 3f64.sqrt() * resolution + 1e-12);
        if !s.exact {
            interpolated += 1;
            worst = worst.max(s.bound / resolution);
        }
        match field.evaluate_in_band(p) {
            FieldValue::Near(n) => assert!((n.distance - exact).abs() <= n.bound),
            FieldValue::Beyond {
                lower_bound,
                inside,
            } => {
                assert!(
                    exact.abs() >= lower_bound,
                    "{p:?}: {exact} below {lower_bound}"
                );
                assert!(lower_bound > band - resolution);
                assert_eq!(inside, exact < 0.0, "{p:?}");
            }
        }
    }
    assert!(
        interpolated > points.len() / 3,
        "{interpolated} of {} interpolated",
        points.len()
    );
    assert!(worst > 0.1, "the bound is never loose? {worst}");
    field
}

#[test]
fn the_field_bound_holds_on_closed_meshes() {
    for (m, seed) in [
        (Mesh::cuboid(0.1, 0.05, 0.03).unwrap(), 80),
        (Mesh::cylinder(0.05, 0.08, 40).unwrap(), 81),
        (random_hull(200, 5), 82),
    ] {
        let md = Arc::new(MeshDistance::new(&m).unwrap());
        let points = probe_points(&m, 2500, 0.03, 0.05, seed);
        let field = check_field(&md, 0.004, 0.02, &points);
        let st = field.stats();
        assert_eq!(
            st.cells_interpolated + st.cells_exact + st.cells_beyond,
            (field.dims()[0] - 1) * (field.dims()[1] - 1) * (field.dims()[2] - 1)
        );
        assert!(st.nodes_in_band > 0 && st.nodes_in_band <= st.nodes);
    }
}

#[test]
fn the_field_bound_holds_on_open_and_non_manifold_meshes() {
    let open = open_box();
    let md = Arc::new(MeshDistance::new(&open).unwrap());
    let points = probe_points(&open, 2500, 0.03, 0.05, 90);
    let field = check_field(&md, 0.004, 0.02, &points);
    // Near the hole some cells need the exact query.
    assert!(field.stats().cells_exact > 0);
    // Points across the opening, where the sign flips away from the surface.
    let mut rng = NormalRng::new(91);
    let across: Vec<Point3> = (0..2000)
        .map(|_| {
            Point3::new(
                0.1 + 0.02 * (2.0 * rng.uniform() - 1.0),
                0.07 * (2.0 * rng.uniform() - 1.0),
                0.05 * (2.0 * rng.uniform() - 1.0),
            )
        })
        .collect();
    for p in &across {
        let s = field.evaluate(p);
        assert!(
            (s.distance - md.signed_distance(p)).abs() <= s.bound,
            "{p:?}"
        );
    }
    let two = Mesh::merged(&[
        Mesh::cuboid(0.06, 0.06, 0.06).unwrap(),
        Mesh::cuboid(0.05, 0.03, 0.03)
            .unwrap()
            .transformed(&Pose::translation(0.07, 0.02, 0.0)),
    ])
    .unwrap();
    let md = Arc::new(MeshDistance::new(&two).unwrap());
    check_field(&md, 0.003, 0.015, &probe_points(&two, 2500, 0.03, 0.04, 92));
}

/// The real Panda hand meshes (the collision STL, closed; the visual OBJ,
/// open and non-manifold), if the Python tests have fetched them into the
/// cache.
fn panda_hand(file: &str) -> Option<Mesh> {
    let cache = std::env::var_os("CLOUDPROX_CACHE")
        .map(std::path::PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME").map(|h| std::path::Path::new(&h).join(".cache/cloudprox"))
        })?;
    let path = cache.join("realfiles/pypi").join(file);
    path.is_file()
        .then(|| cloudprox::io::read_mesh(&path, None).ok())
        .flatten()
        .map(|d| d.mesh)
}

#[test]
fn real_robot_meshes_keep_their_sign() {
    let files = [
        (
            "gym-ignition-models-1.1.1/gym_ignition_models/panda/meshes/collision/hand.stl",
            SignMethod::PseudoNormal,
        ),
        (
            "dm-robotics-panda-0.4.8/dm_robotics/panda/assets/panda/hand.obj",
            SignMethod::WindingNumber,
        ),
    ];
    for (file, method) in files {
        let Some(mesh) = panda_hand(file) else {
            eprintln!("skipped: {file} is not in the cache");
            continue;
        };
        let md = check_against_brute_force(&mesh, &mesh, 0.05, 100);
        assert_eq!(md.sign_method(), method, "{file}: {:?}", md.topology());
        let md = Arc::new(md);
        let points = probe_points(&mesh, 1500, 0.02, 0.03, 101);
        check_field(&md, 0.003, 0.02, &points);
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 24,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(20260501),
        .. ProptestConfig::default()
    })]

    /// Random boxes, anywhere and turned any way: the signed distance of a
    /// point equals the distance to the box in its own frame, computed
    /// analytically.
    #[test]
    fn signed_distance_to_a_moved_box_is_the_analytic_one(
        h in (0.01f64..0.2, 0.01f64..0.2, 0.01f64..0.2),
        t in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        r in (-3.2f64..3.2, -3.2f64..3.2, -3.2f64..3.2),
        q in (-0.5f64..0.5, -0.5f64..0.5, -0.5f64..0.5),
    ) {
        let pose = Pose::from_parts(Translation3::new(t.0, t.1, t.2), UnitQuaternion::from_scaled_axis(Vector3::new(r.0, r.1, r.2)));
        let mesh = Mesh::cuboid(h.0, h.1, h.2).unwrap().transformed(&pose);
        let md = MeshDistance::new(&mesh).unwrap();
        prop_assert_eq!(md.sign_method(), SignMethod::PseudoNormal);
        let local = Point3::new(q.0, q.1, q.2);
        let d = Vector3::new(local.x.abs() - h.0, local.y.abs() - h.1, local.z.abs() - h.2);
        let outside = d.map(|c| c.max(0.0)).norm();
        let analytic = if outside > 0.0 { outside } else { d.max() };
        let got = md.signed_distance(&(pose * local));
        prop_assert!((got - analytic).abs() < 1e-12, "{} vs {}", got, analytic);
    }
}

/// The support point is a vertex farthest along the direction: a cuboid's
/// corner on its diagonals, turned meshes included.
#[test]
fn the_support_point_is_the_farthest_vertex() {
    let mesh = Mesh::cuboid(0.1, 0.2, 0.3).unwrap();
    let d = MeshDistance::new(&mesh).unwrap();
    for (dir, corner) in [
        (Vector3::new(1.0, 1.0, 1.0), Point3::new(0.1, 0.2, 0.3)),
        (Vector3::new(-1.0, 0.5, -2.0), Point3::new(-0.1, 0.2, -0.3)),
        (Vector3::new(0.3, -0.1, 0.01), Point3::new(0.1, -0.2, 0.3)),
    ] {
        assert!((d.support(&dir) - corner).norm() < 1e-12, "{dir:?}");
        let best = mesh
            .vertices()
            .iter()
            .map(|v| v.coords.dot(&dir))
            .fold(f64::NEG_INFINITY, f64::max);
        assert!((d.support(&dir).coords.dot(&dir) - best).abs() < 1e-12);
    }
}
