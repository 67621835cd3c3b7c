//! STL: ascii and binary reading, writing, detection, corrupt inputs.

use crate::common;

use cloudprox::io::stl::{read_stl_mesh, write_stl_mesh};
use cloudprox::io::{read_mesh_bytes, Encoding, MeshData, MeshFormat};
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
            assert_eq!(path, "t.stl");
            assert_eq!(format, "STL");
            problem
        }
        Err(e) => panic!("expected a format error, got {e:?}"),
        Ok(m) => panic!("expected a format error, got a mesh {m:?}"),
    }
}

fn assert_problem(bytes: &[u8], needles: &[&str]) {
    let p = problem(read_stl_mesh(bytes, "t.stl"));
    for n in needles {
        assert!(p.contains(n), "{p:?} should contain {n:?}");
    }
}

/// The triangles of a mesh as coordinates (equal for meshes equal up to welding).
fn triangles(mesh: &Mesh) -> Vec<[[f64; 3]; 3]> {
    mesh.faces()
        .iter()
        .map(|f| {
            f.map(|v| {
                let p = mesh.vertices()[v as usize];
                [p.x, p.y, p.z]
            })
        })
        .collect()
}

fn tetrahedron() -> Mesh {
    Mesh::new(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .unwrap()
}

/// A mesh with coordinates that are not representable in f32 and a -0.0.
fn awkward_mesh() -> Mesh {
    Mesh::new(
        vec![
            Point3::new(0.1, -0.0, 1e-7),
            Point3::new(1.0 / 3.0, 123456.789, -2.5e20),
            Point3::new(-7.25, 0.2, 3.0),
            Point3::new(5.0, 5.0, 5.0),
        ],
        vec![[0, 1, 2], [1, 2, 3], [0, 3, 1]],
    )
    .unwrap()
}

const TETRA_ASCII: &str = "solid tetra
  facet normal 0 0 -1
    outer loop
      vertex 0 0 0
      vertex 0 1 0
      vertex 1 0 0
    endloop
  endfacet
  FACET NORMAL 0 -1 0
    OUTER LOOP
      VERTEX 0 0 0
      Vertex 1.0e0 0 0
      vertex 0 0 1
    ENDLOOP
  ENDFACET
  facet normal -1 0 0 outer loop vertex 0 0 0 vertex 0 0 1 vertex 0 1 0 endloop endfacet
  facet normal 1 1 1
\touter    loop
      vertex 1 0 0
      vertex 0 1 0

      vertex 0 0 1
    endloop
  endfacet
endsolid tetra
";

#[test]
fn ascii_tetrahedron_welds_corners() {
    let m = read_stl_mesh(TETRA_ASCII.as_bytes(), "t.stl").unwrap();
    assert_eq!(m.dropped_faces, 0);
    assert_eq!(m.mesh.vertices().len(), 4);
    assert_eq!(m.mesh.faces().len(), 4);
    // Vertices are numbered in order of first appearance.
    let expected = Mesh::new(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ],
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 3]],
    )
    .unwrap();
    assert_eq!(m.mesh, expected);
    assert!(m.mesh.is_closed());
}

#[test]
fn ascii_crlf_and_several_solids() {
    let text = TETRA_ASCII.replace('\n', "\r\n");
    let two = format!("{text}\r\n{text}");
    let m = read_stl_mesh(two.as_bytes(), "t.stl").unwrap();
    assert_eq!(m.mesh.vertices().len(), 4);
    assert_eq!(m.mesh.faces().len(), 8);
}

#[test]
fn round_trip_ascii_is_exact() {
    for mesh in [tetrahedron(), awkward_mesh()] {
        let bytes = write_stl_mesh(&mesh, Encoding::Ascii).unwrap();
        assert!(bytes.starts_with(b"solid"));
        let back = read_stl_mesh(&bytes, "t.stl").unwrap();
        assert_eq!(back.dropped_faces, 0);
        assert_eq!(back.mesh.vertices().len(), mesh.vertices().len());
        assert_eq!(triangles(&back.mesh), triangles(&mesh));
    }
}

#[test]
fn round_trip_binary_within_f32() {
    for mesh in [tetrahedron(), awkward_mesh()] {
        let bytes = write_stl_mesh(&mesh, Encoding::BinaryLittleEndian).unwrap();
        assert_eq!(bytes.len(), 84 + 50 * mesh.faces().len());
        let back = read_stl_mesh(&bytes, "t.stl").unwrap();
        assert_eq!(back.dropped_faces, 0);
        let rounded: Vec<[[f64; 3]; 3]> = triangles(&mesh)
            .into_iter()
            .map(|t| t.map(|p| p.map(|c| f64::from(c as f32))))
            .collect();
        assert_eq!(triangles(&back.mesh), rounded);
    }
    // Through the dispatch too.
    let bytes = cloudprox::io::write_mesh_bytes(
        &tetrahedron(),
        MeshFormat::Stl,
        Encoding::BinaryLittleEndian,
    )
    .unwrap();
    let back = read_mesh_bytes(&bytes, "t.stl", MeshFormat::Stl).unwrap();
    assert_eq!(triangles(&back.mesh), triangles(&tetrahedron()));
}

#[test]
fn other_encodings_are_invalid_input() {
    for e in [Encoding::BinaryBigEndian, Encoding::BinaryCompressed] {
        assert!(matches!(
            write_stl_mesh(&tetrahedron(), e),
            Err(Error::InvalidInput(_))
        ));
    }
}

/// A binary STL of `faces` whose header is `header`.
fn binary(header: &[u8], faces: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend_from_slice(&(faces.len() as u32).to_le_bytes());
    for f in faces {
        out.extend_from_slice(&[0u8; 12]);
        for v in f {
            for c in v {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

#[test]
fn binary_whose_header_starts_with_solid() {
    let faces = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    ];
    let bytes = binary(b"solid exported by some CAD tool", &faces);
    let m = read_stl_mesh(&bytes, "t.stl").unwrap();
    assert_eq!(m.mesh.vertices().len(), 4);
    assert_eq!(m.mesh.faces(), &[[0, 1, 2], [1, 3, 2]]);
}

#[test]
fn welding_drops_and_counts_degenerate_faces() {
    let faces = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 0.0], [-0.0, 0.0, 0.0], [0.0, 1.0, 0.0]], // -0.0 welds to 0.0
        [[2.0, 2.0, 2.0], [2.0, 2.0, 2.0], [2.0, 2.0, 2.0]],
    ];
    let m = read_stl_mesh(&binary(b"x", &faces), "t.stl").unwrap();
    assert_eq!(m.dropped_faces, 2);
    assert_eq!(m.mesh.faces().len(), 1);
    // All faces degenerate: an error, not an empty mesh.
    assert_problem(&binary(b"x", &faces[1..]), &["no faces", "all 2 triangles"]);
}

#[test]
fn empty_files_have_no_triangles() {
    assert_problem(&binary(b"x", &[]), &["no triangles"]);
    assert_problem(&binary(b"solid x", &[]), &["no triangles"]);
    assert_problem(b"solid empty\nendsolid empty\n", &["no triangles"]);
    assert_problem(b"", &["0 bytes", "does not start with \"solid\""]);
}

#[test]
fn truncated_binary_names_count_and_size() {
    let faces = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 3];
    let bytes = binary(b"binary", &faces);
    for cut in [84, 100, 133, 134, 200, bytes.len() - 1] {
        assert_problem(
            &bytes[..cut],
            &[
                "truncated",
                "promises 3 triangles (234 bytes)",
                &format!("only {cut} bytes"),
            ],
        );
    }
    for cut in [0, 10, 80, 83] {
        assert_problem(&bytes[..cut], &["fewer than the 84"]);
    }
    // Trailing bytes are rejected, not ignored.
    let mut long = bytes.clone();
    long.extend_from_slice(b"junk");
    assert_problem(
        &long,
        &["promises 3 triangles (234 bytes)", "238 bytes, 4 more"],
    );
    // A huge count.
    let mut huge = bytes.clone();
    huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_problem(
        &huge,
        &["truncated", &format!("promises {} triangles", u32::MAX)],
    );
    // A binary file starting with "solid" that is truncated says both checks.
    let solid = binary(b"solid x", &faces);
    assert_problem(
        &solid[..150],
        &[
            "line 1",
            "starts with \"solid\"",
            "promises 3 triangles",
            "150 bytes",
        ],
    );
}

#[test]
fn binary_nan_is_an_error() {
    let faces = [[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]]];
    assert_problem(
        &binary(b"x", &faces),
        &["triangle 0", "vertex 1", "non-finite"],
    );
}

#[test]
fn ascii_errors_name_line_and_expectation() {
    let cases: &[(&str, &[&str])] = &[
        ("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n", &[
            "line 6",
            "expected \"vertex\"",
            "\"endloop\"",
        ]),
        ("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 1\nendloop\n", &[
            "line 7",
            "expected \"endloop\"",
            "facets must be triangles",
        ]),
        ("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 zero\n", &[
            "line 5",
            "expected a number in vertex 2",
            "\"zero\"",
        ]),
        ("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\n", &[
            "line 5",
            "non-finite",
        ]),
        ("solid x\nfacet normal 0 0\nouter loop\n", &["line 3", "number in the facet normal"]),
        ("solid x\nfacet 0 0 1\n", &["line 2", "expected \"normal\""]),
        ("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n", &[
            "line 9",
            "\"endsolid\"",
            "end of the file",
        ]),
        ("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\ngarbage\n", &[
            "line 10",
            "\"garbage\"",
        ]),
        ("solid x\npolygon\n", &["line 2", "expected \"facet\" or \"endsolid\""]),
        ("hello world", &["does not start with \"solid\""]),
    ];
    for (text, needles) in cases {
        assert_problem(text.as_bytes(), needles);
    }
}

#[test]
fn no_prefix_or_bit_flip_panics() {
    let ascii = write_stl_mesh(&awkward_mesh(), Encoding::Ascii).unwrap();
    let bin = write_stl_mesh(&awkward_mesh(), Encoding::BinaryLittleEndian).unwrap();
    for file in [&ascii, &bin] {
        common::for_each_corruption(file, &[0, 3, 7], |f| {
            let _ = read_stl_mesh(f, "t.stl");
        });
    }
    // Garbage.
    let garbage = common::garbage(2000, 12345);
    assert!(read_stl_mesh(&garbage, "t.stl").is_err());
    let mut solid = b"solid ".to_vec();
    solid.extend_from_slice(&garbage);
    assert!(read_stl_mesh(&solid, "t.stl").is_err());
}
