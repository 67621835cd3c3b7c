//! OFF: reading the variants, writing, corrupt inputs.

use crate::common;

use cloudprox::io::off::{read_off_mesh, write_off_mesh};
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
            assert_eq!(path, "t.off");
            assert_eq!(format, "OFF");
            problem
        }
        Err(e) => panic!("expected a format error, got {e:?}"),
        Ok(m) => panic!("expected a format error, got a mesh {m:?}"),
    }
}

fn assert_problem(text: &str, needles: &[&str]) {
    let p = problem(read_off_mesh(text.as_bytes(), "t.off"));
    for n in needles {
        assert!(p.contains(n), "{p:?} should contain {n:?}");
    }
}

/// A pentagon (fan into 3 triangles) and a triangle, with face colours, vertex
/// colours (COFF) and comments.
const PENTAGON: &str = "COFF
# a pentagon and a triangle
6 2 0

0 0 0  255 0 0 255
2 0 0  0 255 0 255
3 2 0  0 0 255 255   # vertex colour
1 3 0  1 1 1 1
-1 2 0 0.5 0.5 0.5 1
1 1 5  0 0 0 1
5 0 1 2 3 4  1.0 0.0 0.0
3 0 1 5
";

#[test]
fn pentagon_with_colours() {
    let m = read_off_mesh(PENTAGON.as_bytes(), "t.off").unwrap();
    assert_eq!(m.dropped_faces, 0);
    assert_eq!(m.mesh.vertices().len(), 6);
    assert_eq!(m.mesh.vertices()[4], Point3::new(-1.0, 2.0, 0.0));
    assert_eq!(
        m.mesh.faces(),
        &[[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 1, 5]]
    );
}

#[test]
fn header_variants() {
    let body = "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    for header in ["OFF\n", "NOFF\n", "CNOFF\n", "STOFF\n", "OFF # comment\n"] {
        let m = read_off_mesh(format!("{header}{body}").as_bytes(), "t.off").unwrap();
        assert_eq!(m.mesh.faces(), &[[0, 1, 2]]);
    }
    // Counts on the header line; no edge count; CRLF.
    let m = read_off_mesh(
        b"OFF 3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n",
        "t.off",
    )
    .unwrap();
    assert_eq!(m.mesh.faces().len(), 1);
    let m = read_off_mesh(b"OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2", "t.off").unwrap();
    assert_eq!(m.mesh.faces().len(), 1);
    // NOFF: normals after xyz are ignored.
    let m = read_off_mesh(
        b"NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
        "t.off",
    )
    .unwrap();
    assert_eq!(m.mesh.vertices()[1], Point3::new(1.0, 0.0, 0.0));
}

#[test]
fn degenerate_faces_are_counted() {
    let m = read_off_mesh(
        b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 0 1\n",
        "t.off",
    )
    .unwrap();
    assert_eq!(m.dropped_faces, 1);
    assert_eq!(m.mesh.faces().len(), 1);
}

#[test]
fn round_trip_is_exact() {
    let mesh = Mesh::new(
        vec![
            Point3::new(0.1, -0.0, 1e-300),
            Point3::new(1.0 / 3.0, 500000.123456789, -2.5e20),
            Point3::new(-7.25, 0.2, 3.0),
            Point3::new(5.0, 5.0, 5.0),
        ],
        vec![[0, 1, 2], [1, 2, 3], [0, 3, 1]],
    )
    .unwrap();
    let bytes = write_off_mesh(&mesh).unwrap();
    assert!(bytes.starts_with(b"OFF\n4 3 0\n"));
    let back = read_off_mesh(&bytes, "t.off").unwrap();
    assert_eq!(back.mesh, mesh);
    let back = read_mesh_bytes(&bytes, "t.off", MeshFormat::Off).unwrap();
    assert_eq!(back.mesh, mesh);
}

#[test]
fn errors_name_the_line() {
    let v3 = "0 0 0\n1 0 0\n0 1 0\n";
    let cases: Vec<(String, Vec<&str>)> = vec![
        (String::new(), vec!["empty file"]),
        (
            "PLY\n".into(),
            vec!["line 1", "expected the header \"OFF\""],
        ),
        ("4OFF\n".into(), vec!["line 1", "unsupported OFF variant"]),
        ("OFF BINARY\n".into(), vec!["line 1", "binary OFF"]),
        ("OFF\n".into(), vec!["line 1", "expected the counts"]),
        (
            "OFF\n3\n".into(),
            vec!["line 2", "2 or 3 integers", "found 1"],
        ),
        (
            "OFF\n3 x 0\n".into(),
            vec!["line 2", "bad count \"x\"", "number of faces"],
        ),
        (
            "OFF\n-3 1 0\n".into(),
            vec!["line 2", "bad count \"-3\"", "number of vertices"],
        ),
        (
            format!("OFF\n4 1 0\n{v3}"),
            vec![
                "line 5",
                "promises 4 vertices and 1 faces",
                "after 3 vertices",
            ],
        ),
        (
            format!("OFF\n3 2 0\n{v3}3 0 1 2\n"),
            vec!["line 6", "promises 2 faces", "after 1 faces"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n".to_string(),
            vec!["line 4", "vertex 1 needs 3 coordinates"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 y\n0 1 0\n3 0 1 2\n".to_string(),
            vec!["line 4", "malformed number \"y\""],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n".to_string(),
            vec!["line 4", "non-finite"],
        ),
        (
            format!("OFF\n3 1 0\n{v3}3 0 1 3\n"),
            vec!["line 6", "index 3 out of range (0 to 2)"],
        ),
        (
            format!("OFF\n3 1 0\n{v3}3 0 1 -1\n"),
            vec!["line 6", "index -1 out of range"],
        ),
        (
            format!("OFF\n3 1 0\n{v3}3 0 1\n"),
            vec!["line 6", "announces 3 vertices", "only 2 indices"],
        ),
        (
            format!("OFF\n3 1 0\n{v3}2 0 1\n"),
            vec!["line 6", "face 0 has 2 vertices"],
        ),
        (
            format!("OFF\n3 1 0\n{v3}three 0 1 2\n"),
            vec!["line 6", "bad vertex count"],
        ),
        (
            format!("OFF\n3 1 0\n{v3}3 0 1 z\n"),
            vec!["line 6", "malformed vertex index \"z\""],
        ),
        (
            format!("OFF\n3 1 0\n{v3}3 0 1 2\n3 0 1 2\n"),
            vec!["line 7", "after the 1 faces"],
        ),
        (format!("OFF\n3 0 0\n{v3}"), vec!["no faces"]),
        (
            "OFF\n99999999999999999999 1 0\n".into(),
            vec!["line 2", "bad count"],
        ),
        (
            "OFF\n4000000000 4000000000 0\n0 0 0\n".into(),
            vec!["promises 4000000000 vertices", "after 1 vertices"],
        ),
    ];
    for (text, needles) in &cases {
        assert_problem(text, needles);
    }
}

#[test]
fn no_prefix_or_bit_flip_panics() {
    let file = PENTAGON.as_bytes().to_vec();
    common::for_each_corruption(&file, &[0, 2, 5, 7], |f| {
        let _ = read_off_mesh(f, "t.off");
    });
    let garbage = common::garbage(3000, 7);
    assert!(read_off_mesh(&garbage, "t.off").is_err());
    let mut off = b"OFF\n".to_vec();
    off.extend_from_slice(&garbage);
    assert!(read_off_mesh(&off, "t.off").is_err());
}
