//! OBJ: reading every corner form, writing, corrupt inputs.

use crate::common;

use cloudprox::io::obj::{read_obj_mesh, write_obj_mesh};
use cloudprox::io::{read_mesh_bytes, MeshData, MeshFormat};
use cloudprox::math::Point3;
use cloudprox::shape::Mesh;
use cloudprox::Error;

fn problem(r: cloudprox::Result<MeshData>) -> String {
    match r {
        Err(Error::Format {
            path,
            format,
            problem,
        }) => {
            assert_eq!(path, "t.obj");
            assert_eq!(format, "OBJ");
            problem
        }
        Err(e) => panic!("expected a format error, got {e:?}"),
        Ok(m) => panic!("expected a format error, got a mesh {m:?}"),
    }
}

fn assert_problem(text: &str, needles: &[&str]) {
    let p = problem(read_obj_mesh(text.as_bytes(), "t.obj"));
    for n in needles {
        assert!(p.contains(n), "{p:?} should contain {n:?}");
    }
}

/// A unit cube: quads, negative indices, every corner form, groups, comments,
/// a continuation line and statements that are ignored.
const CUBE: &str = r"# unit cube
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vn 0 0 -1
g bottom
usemtl red
s off
f 1 4 3 2
g top
v 0 0 1 1.0
v 1 0 1 0.5 0.5 0.5
v 1 1 1
v 0 1 1     # a comment after a vertex
f -4/1 -3/2 -2/1 -1/2
f 1//1 2//1 6//1 5//1
f 2/1/1 3/2/1 \
  7/1/1 6/2/1
l 1 2
p 3
curv2 1 2
f 3 4 8 7
f 4 1 5 8
";

#[test]
fn unit_cube_with_quads_and_negative_indices() {
    let m = read_obj_mesh(CUBE.as_bytes(), "t.obj").unwrap();
    assert_eq!(m.dropped_faces, 0);
    assert_eq!(m.mesh.vertices().len(), 8);
    assert_eq!(m.mesh.faces().len(), 12);
    assert_eq!(m.mesh.vertices()[6], Point3::new(1.0, 1.0, 1.0));
    // Fan triangulation of "f -4 -3 -2 -1" after 8 vertices: 5 6 7 8.
    assert_eq!(m.mesh.faces()[2], [4, 5, 6]);
    assert_eq!(m.mesh.faces()[3], [4, 6, 7]);
    // Continuation line.
    assert_eq!(m.mesh.faces()[6], [1, 2, 6]);
    assert!(m.mesh.is_closed());
    assert!((m.mesh.volume().abs() - 1.0).abs() < 1e-12);
    assert!((m.mesh.area() - 6.0).abs() < 1e-12);
}

#[test]
fn forward_references_and_degenerate_faces() {
    // A positive index may refer to a vertex defined later.
    let m = read_obj_mesh(b"f 1 2 3\nf 1 1 2\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "t.obj").unwrap();
    assert_eq!(m.mesh.faces(), &[[0, 1, 2]]);
    assert_eq!(m.dropped_faces, 1);
    assert_problem(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\n",
        &["no faces", "all 1 triangles repeat a vertex"],
    );
}

#[test]
fn round_trip_is_exact() {
    let mesh = Mesh::new(
        vec![
            Point3::new(0.1, -0.0, 1e-300),
            Point3::new(1.0 / 3.0, 6378137.000123, -2.5e20),
            Point3::new(-7.25, 0.2, f64::MIN_POSITIVE),
            Point3::new(5.0, 5.0, 5.0),
        ],
        vec![[0, 1, 2], [1, 2, 3], [0, 3, 1]],
    )
    .unwrap();
    let bytes = write_obj_mesh(&mesh).unwrap();
    let back = read_obj_mesh(&bytes, "t.obj").unwrap();
    assert_eq!(back.dropped_faces, 0);
    assert_eq!(back.mesh, mesh);
    let back = read_mesh_bytes(&bytes, "t.obj", MeshFormat::Obj).unwrap();
    assert_eq!(back.mesh, mesh);
}

#[test]
fn errors_name_the_line() {
    let v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            format!("{v3}v 1 2 x\n"),
            vec!["line 4", "malformed number \"x\""],
        ),
        (
            format!("{v3}v 1 2\n"),
            vec!["line 4", "3 to 7 numbers", "found 2"],
        ),
        (format!("{v3}v 1 2 inf\n"), vec!["line 4", "non-finite"]),
        (format!("{v3}f 1 2 0\n"), vec!["line 4", "index 0"]),
        (
            format!("{v3}f 1 2 4\n"),
            vec!["line 4", "index 4 out of range", "3 vertices"],
        ),
        (
            format!("{v3}\n\nf -1 -2 -4\n"),
            vec![
                "line 6",
                "index -4 out of range",
                "3 vertices defined so far",
            ],
        ),
        (
            format!("{v3}f 1 2\n"),
            vec!["line 4", "at least 3 vertices, found 2"],
        ),
        (
            format!("{v3}f 1 2 3/x\n"),
            vec!["line 4", "malformed face vertex \"3/x\""],
        ),
        (
            format!("{v3}f 1 2 3/1/1/1\n"),
            vec!["line 4", "malformed face vertex"],
        ),
        (
            format!("{v3}f 1 2 3/0\n"),
            vec!["line 4", "malformed face vertex"],
        ),
        (
            format!("{v3}f 1 2 99999999999999999999\n"),
            vec!["line 4", "malformed face vertex"],
        ),
        (
            format!("{v3}f 1 2 3 \\\n 9\n"),
            vec!["line 4", "index 9 out of range"],
        ),
        (
            format!("{v3}surf 0 1 0 1 1 2 3\n"),
            vec!["line 4", "free-form"],
        ),
        (v3.to_string(), vec!["no faces"]),
        (String::new(), vec!["no faces"]),
    ];
    for (text, needles) in &cases {
        assert_problem(text, needles);
    }
}

#[test]
fn no_prefix_or_bit_flip_panics() {
    common::for_each_corruption(CUBE.as_bytes(), &[0, 2, 5, 7], |f| {
        let _ = read_obj_mesh(f, "t.obj");
    });
    assert!(read_obj_mesh(&common::garbage(3000, 99), "t.obj").is_err());
    let _ = read_obj_mesh(b"f -9223372036854775808 1 2\nv 0 0 0\n", "t.obj");
}
