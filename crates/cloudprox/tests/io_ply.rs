//! PLY reading and writing: round-trips, hand-written files of every variant,
//! meshes, corrupt inputs.

use crate::common;

use cloudprox::io::ply::{read_ply, read_ply_mesh, write_ply, write_ply_mesh};
use cloudprox::io::{CloudData, Encoding};
use cloudprox::prelude::*;
use proptest::prelude::*;

fn format_err<T: std::fmt::Debug>(r: Result<T>, needle: &str) {
    match r {
        Err(Error::Format {
            problem, format, ..
        }) => {
            assert_eq!(format, "PLY");
            assert!(
                problem.contains(needle),
                "problem {problem:?} does not mention {needle:?}"
            );
        }
        other => panic!("expected a PLY format error mentioning {needle:?}, got {other:?}"),
    }
}

fn sample_cloud() -> CloudData {
    let points = vec![
        Point3::new(0.1, -0.2, 0.3),
        Point3::new(1.0 / 3.0, 123_456.789, -1e-7),
        Point3::new(-5.5, 0.0, 2.0f64.sqrt()),
    ];
    let normals = vec![
        Vector3::new(0.0, 0.0, 1.0),
        Vector3::new(0.6, 0.8, 0.0),
        Vector3::new(-1.0, 0.0, 0.0),
    ];
    let covariances = (0..3)
        .map(|i| {
            let s = 1e-6 * f64::from(i + 1);
            Matrix3::new(
                s,
                0.1 * s,
                0.2 * s,
                0.1 * s,
                2.0 * s,
                0.3 * s,
                0.2 * s,
                0.3 * s,
                3.0 * s,
            )
        })
        .collect();
    CloudData {
        points,
        normals: Some(normals),
        covariances: Some(covariances),
        fields: [
            "x", "y", "z", "nx", "ny", "nz", "cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz",
            "cov_zz",
        ]
        .iter()
        .map(|s| (*s).to_string())
        .collect(),
        ..CloudData::default()
    }
}

const ENCODINGS: [Encoding; 3] = [
    Encoding::Ascii,
    Encoding::BinaryLittleEndian,
    Encoding::BinaryBigEndian,
];

#[test]
fn round_trips_every_encoding_exactly() {
    let cloud = sample_cloud();
    for enc in ENCODINGS {
        let bytes = write_ply(&cloud, enc).unwrap();
        let back = read_ply(&bytes, "t.ply").unwrap();
        assert_eq!(back, cloud, "{enc:?}");
    }
    let plain = CloudData::from_points(sample_cloud().points);
    for enc in ENCODINGS {
        let back = read_ply(&write_ply(&plain, enc).unwrap(), "t.ply").unwrap();
        assert_eq!(back, plain, "{enc:?}");
    }
}

#[test]
fn compressed_encoding_is_invalid_input() {
    assert!(matches!(
        write_ply(&sample_cloud(), Encoding::BinaryCompressed),
        Err(Error::InvalidInput(_))
    ));
}

#[test]
fn reads_hand_written_ascii() {
    let text = "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info scanner 7\r\n\
element camera 1\r\nproperty float view_px\r\nproperty list uchar int junk\r\n\
element vertex 3\r\nproperty list uchar float tags\r\nproperty uchar red\r\nproperty float32 x\r\n\
property int16 y\r\nproperty double z\r\nproperty float nx\r\nproperty float ny\r\nproperty float nz\r\n\
element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n\
1.5 2 7 8\r\n\
0 200 1.5 -2 3.25 0 0 1\r\n\
2 1.0 2.0 255 nan 0 0 0 1 0\r\n\
1 9 7 -1e3 32767 1e-3 1 0 0\r\n\
3 0 1 2\r\n";
    let c = read_ply(text.as_bytes(), "hand.ply").unwrap();
    assert_eq!(c.points.len(), 2);
    assert_eq!(c.skipped, 1);
    assert_eq!(c.points[0], Point3::new(1.5, -2.0, 3.25));
    assert_eq!(c.points[1], Point3::new(-1000.0, 32767.0, 1e-3));
    assert_eq!(c.normals.as_ref().unwrap()[1], Vector3::new(1.0, 0.0, 0.0));
    assert!(c.covariances.is_none());
    assert_eq!(c.fields, ["tags", "red", "x", "y", "z", "nx", "ny", "nz"]);
}

/// Builds a binary PLY body with the given endianness.
struct Bin {
    big: bool,
    out: Vec<u8>,
}

impl Bin {
    fn f32(&mut self, v: f32) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
    fn f64(&mut self, v: f64) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
    fn i16(&mut self, v: i16) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.out.extend_from_slice(&b);
        self
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.out.push(v);
        self
    }
}

/// A binary PLY with an element before the vertices (with a list), a list
/// property inside the vertex element, a quad face, and an element after.
fn hand_binary(big: bool) -> Vec<u8> {
    let fmt = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let header = format!(
        "ply\nformat {fmt} 1.0\ncomment hand\nelement material 2\nproperty list uchar ushort ids\nproperty double w\n\
element vertex 4\nproperty float x\nproperty list int uchar flags\nproperty short y\nproperty float64 z\n\
element face 2\nproperty uchar kind\nproperty list uchar uint vertex_indices\n\
element edge 2\nproperty int a\nproperty int b\nend_header\n"
    );
    let mut b = Bin {
        big,
        out: header.into_bytes(),
    };
    // materials: list of 2 ushorts then a double; then an empty list.
    b.u8(2).u8(0).u8(1).u8(0).u8(2).f64(0.5);
    b.u8(0).f64(1.5);
    // vertices
    let pts: [(f32, u32, i16, f64); 4] = [
        (0.0, 0, 0, 0.0),
        (1.0, 2, 0, 0.0),
        (1.0, 0, 1, 0.0),
        (0.0, 1, 1, 0.25),
    ];
    for (x, nflags, y, z) in pts {
        b.f32(x).u32(nflags);
        for k in 0..nflags {
            b.u8(k as u8);
        }
        b.i16(y).f64(z);
    }
    // faces: a quad, and a triangle repeating a vertex.
    b.u8(7).u8(4).u32(0).u32(1).u32(2).u32(3);
    b.u8(7).u8(3).u32(1).u32(1).u32(2);
    // edges
    b.u32(0).u32(1).u32(1).u32(2);
    b.out
}

#[test]
fn reads_hand_written_binary_both_endians() {
    for big in [false, true] {
        let bytes = hand_binary(big);
        let c = read_ply(&bytes, "hand.ply").unwrap();
        assert_eq!(
            c.points,
            [
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.25)
            ]
        );
        assert_eq!(c.fields, ["x", "flags", "y", "z"]);
        let m = read_ply_mesh(&bytes, "hand.ply").unwrap();
        assert_eq!(m.mesh.faces(), [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.dropped_faces, 1);
        // Cut anywhere: always an error, never a panic.
        for cut in [bytes.len() - 1, bytes.len() - 9, bytes.len() - 30, 300, 260] {
            assert!(
                read_ply_mesh(&bytes[..cut], "cut.ply").is_err(),
                "cut {cut}"
            );
        }
    }
}

#[test]
fn mesh_round_trips_and_errors() {
    let mesh = Mesh::new(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.1, 0.2, 1.0 / 3.0),
        ],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    )
    .unwrap();
    for enc in ENCODINGS {
        let bytes = write_ply_mesh(&mesh, enc).unwrap();
        let back = read_ply_mesh(&bytes, "m.ply").unwrap();
        assert_eq!(back.mesh, mesh, "{enc:?}");
        assert_eq!(back.dropped_faces, 0);
        // The vertices also read as a cloud.
        assert_eq!(read_ply(&bytes, "m.ply").unwrap().points, mesh.vertices());
    }
    assert!(matches!(
        write_ply_mesh(&mesh, Encoding::BinaryCompressed),
        Err(Error::InvalidInput(_))
    ));
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_index\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    format_err(
        read_ply_mesh(format!("{head}3 0 1 2\n3 0 1 7\n").as_bytes(), "m.ply"),
        "face 1 refers to vertex 7, but there are 3 vertices",
    );
    format_err(
        read_ply_mesh(format!("{head}3 0 1 2\n2 0 1\n").as_bytes(), "m.ply"),
        "face 1 has 2 vertices",
    );
    format_err(
        read_ply_mesh(format!("{head}3 0 1 2\n3 0 1 -1\n").as_bytes(), "m.ply"),
        "face 1 has an invalid vertex index -1",
    );
    format_err(
        read_ply_mesh(format!("{head}3 0 0 2\n3 1 1 1\n").as_bytes(), "m.ply"),
        "no usable face (2 dropped",
    );
    let points_only = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
    format_err(
        read_ply_mesh(points_only.as_bytes(), "p.ply"),
        "no 'face' element",
    );
}

#[test]
fn corrupt_inputs_are_format_errors() {
    let good = write_ply(&sample_cloud(), Encoding::BinaryLittleEndian).unwrap();
    let header_len = good.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    format_err(read_ply(b"", "e.ply"), "empty file");
    format_err(read_ply(b"PLY\nformat ascii 1.0\n", "e.ply"), "wrong magic");
    format_err(read_ply(b"\x00\x01\x02binary", "e.ply"), "wrong magic");
    format_err(
        read_ply(&good[..header_len - 11], "t.ply"),
        "no 'end_header'",
    );
    for cut in [header_len, header_len + 1, header_len + 100, good.len() - 1] {
        format_err(read_ply(&good[..cut], "t.ply"), "truncated");
    }
    let ascii = write_ply(&sample_cloud(), Encoding::Ascii).unwrap();
    let body_start = ascii
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    // Cut at every line start of the body: some values are missing.
    for cut in (body_start..ascii.len()).filter(|&i| ascii[i - 1] == b'\n') {
        format_err(read_ply(&ascii[..cut], "t.ply"), "truncated");
    }
    let make = |header: &str, body: &str| format!("ply\n{header}end_header\n{body}").into_bytes();
    let xyz = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    format_err(
        read_ply(
            &make(&format!("format ascii 2.0\n{xyz}"), "1 2 3\n"),
            "t.ply",
        ),
        "unsupported version '2.0'",
    );
    format_err(
        read_ply(
            &make(&format!("format binary_middle_endian 1.0\n{xyz}"), ""),
            "t.ply",
        ),
        "unknown format 'binary_middle_endian'",
    );
    format_err(read_ply(&make(xyz, "1 2 3\n"), "t.ply"), "no 'format' line");
    format_err(
        read_ply(
            &make(
                "format ascii 1.0\nelement vertex 1\nproperty float128 x\n",
                "",
            ),
            "t.ply",
        ),
        "unknown property type 'float128'",
    );
    format_err(
        read_ply(&make("format ascii 1.0\nproperty float x\n", ""), "t.ply"),
        "property before any element",
    );
    format_err(
        read_ply(
            &make("format ascii 1.0\nelement vertex many\n", ""),
            "t.ply",
        ),
        "header line 3",
    );
    format_err(
        read_ply(
            &make(
                "format ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\n",
                "1 2\n",
            ),
            "t.ply",
        ),
        "no property 'y' (it has: x, z)",
    );
    format_err(
        read_ply(&make("format ascii 1.0\nelement face 1\n", ""), "t.ply"),
        "no 'vertex' element",
    );
    format_err(
        read_ply(&make("format ascii 1.0\nbogus line\n", ""), "t.ply"),
        "unknown keyword 'bogus'",
    );
    format_err(
        read_ply(&make(&format!("format ascii 1.0\n{xyz}"), "1 abc 3\n"), "t.ply"),
        "line 8: expected a value of type float for property 'y' of element 'vertex' 0, found 'abc'",
    );
    format_err(
        read_ply(
            &make(
                "format ascii 1.0\nelement vertex 1\nproperty uchar x\nproperty float y\nproperty float z\n",
                "300 0 0\n",
            ),
            "t.ply",
        ),
        "expected a value of type uchar",
    );
    // Counts far larger than the data: an error, no huge allocation.
    let huge = "element vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n";
    format_err(
        read_ply(
            &make(&format!("format binary_little_endian 1.0\n{huge}"), "abcd"),
            "t.ply",
        ),
        "truncated",
    );
    format_err(
        read_ply(
            &make(&format!("format ascii 1.0\n{huge}"), "1 2 3\n"),
            "t.ply",
        ),
        "truncated",
    );
    format_err(
        read_ply(
            &make(
                &format!("format binary_little_endian 1.0\nelement junk 4000000000\nproperty double a\n{xyz}"),
                "abcdefgh",
            ),
            "t.ply",
        ),
        "element 'junk' has 4000000000 records of 8 bytes",
    );
    format_err(
        read_ply(
            &make(
                "format binary_little_endian 1.0\nelement vertex 1\nproperty list uint float x\nproperty float y\nproperty float z\n",
                "",
            ),
            "t.ply",
        ),
        "'x' is a list",
    );
}

fn cloud_strategy() -> impl Strategy<Value = CloudData> {
    prop::collection::vec(
        (-1e6f64..1e6, -1e6f64..1e6, -1e6f64..1e6, any::<bool>()),
        0..40,
    )
    .prop_map(|v| {
        let mut c =
            CloudData::from_points(v.iter().map(|&(x, y, z, _)| Point3::new(x, y, z)).collect());
        if v.first().is_some_and(|p| p.3) {
            c.normals = Some(
                v.iter()
                    .map(|&(x, y, z, _)| Vector3::new(z, x, y))
                    .collect(),
            );
            c.fields.extend(["nx", "ny", "nz"].map(String::from));
        }
        c
    })
}

proptest! {
    #[test]
    fn proptest_round_trip(cloud in cloud_strategy(), enc in 0usize..3) {
        let bytes = write_ply(&cloud, ENCODINGS[enc]).unwrap();
        let back = read_ply(&bytes, "p.ply").unwrap();
        prop_assert_eq!(back, cloud);
    }
}

#[test]
fn prefixes_and_bit_flips_never_panic() {
    let mesh = Mesh::new(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let files = [
        write_ply(&sample_cloud(), Encoding::Ascii).unwrap(),
        write_ply(&sample_cloud(), Encoding::BinaryBigEndian).unwrap(),
        write_ply_mesh(&mesh, Encoding::Ascii).unwrap(),
        write_ply_mesh(&mesh, Encoding::BinaryLittleEndian).unwrap(),
        hand_binary(false),
    ];
    for file in &files {
        common::for_each_corruption(file, &[0, 1, 2, 3, 4, 5, 6, 7], |f| {
            let _ = read_ply(f, "f.ply");
            let _ = read_ply_mesh(f, "f.ply");
        });
    }
}
