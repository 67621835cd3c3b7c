//! PCD reading and writing: round-trips of ascii / binary / binary_compressed,
//! hand-written files (organized with NaN holes, VIEWPOINT, v0.6 headers,
//! descriptors, a hand-made LZF stream), corrupt inputs.

use crate::common;

use cloudprox::io::pcd::{read_pcd, write_pcd};
use cloudprox::io::{CloudData, Encoding, Grid};
use cloudprox::prelude::*;
use nalgebra::{Translation3, UnitQuaternion};
use proptest::prelude::*;

fn format_err<T: std::fmt::Debug>(r: Result<T>, needle: &str) {
    match r {
        Err(Error::Format {
            problem, format, ..
        }) => {
            assert_eq!(format, "PCD");
            assert!(
                problem.contains(needle),
                "problem {problem:?} does not mention {needle:?}"
            );
        }
        other => panic!("expected a PCD format error mentioning {needle:?}, got {other:?}"),
    }
}

fn sample_cloud() -> CloudData {
    let points = vec![
        Point3::new(0.1, -0.2, 0.3),
        Point3::new(1.0 / 3.0, 123_456.789, -1e-7),
        Point3::new(-5.5, 0.0, 2.0f64.sqrt()),
        Point3::new(7.0, 8.0, 9.0),
    ];
    let normals = points.iter().map(|p| p.coords.normalize()).collect();
    let covariances = (0..4)
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
            "x", "y", "z", "normal_x", "normal_y", "normal_z", "cov_xx", "cov_xy", "cov_xz",
            "cov_yy", "cov_yz", "cov_zz",
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
    Encoding::BinaryCompressed,
];

fn sensor_pose() -> Pose {
    Pose::from_parts(
        Translation3::new(0.5, -1.25, 2.0),
        UnitQuaternion::from_euler_angles(0.1, -0.4, 2.0),
    )
}

fn assert_pose_close(a: &Pose, b: &Pose) {
    assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
    assert!(a.rotation.angle_to(&b.rotation) < 1e-9, "{a:?} vs {b:?}");
}

/// The cloud as the writer stores it: points and normals as `f32`,
/// covariances exact; no sensor pose becomes the default `VIEWPOINT` (the
/// identity), which reads back as the sensor at the origin.
fn rounded(cloud: &CloudData) -> CloudData {
    let mut c = cloud.clone();
    if c.sensor.is_none() {
        c.sensor = Some(Pose::identity());
        c.sensor_is_default = true;
    }
    for p in &mut c.points {
        *p = p.map(|v| f64::from(v as f32));
    }
    if let Some(normals) = c.normals.as_mut() {
        for n in normals {
            *n = n.map(|v| f64::from(v as f32));
        }
    }
    c
}

#[test]
fn round_trips_every_encoding_within_f32() {
    let mut cloud = sample_cloud();
    for enc in ENCODINGS {
        let bytes = write_pcd(&cloud, enc).unwrap();
        assert!(String::from_utf8_lossy(&bytes)
            .contains("SIZE 4 4 4 4 4 4 8 8 8 8 8 8\nTYPE F F F F F F F F F F F F\n"));
        let back = read_pcd(&bytes, "t.pcd").unwrap();
        assert_eq!(back, rounded(&cloud), "{enc:?}");
        assert_eq!(back.covariances, cloud.covariances, "{enc:?}");
    }
    // With a sensor pose and an organized grid (2 x 2, every pixel present).
    cloud.sensor = Some(sensor_pose());
    cloud.grid = Some(Grid {
        width: 2,
        height: 2,
        pixels: vec![0, 1, 2, 3],
    });
    for enc in ENCODINGS {
        let bytes = write_pcd(&cloud, enc).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("WIDTH 2\nHEIGHT 2\n"), "{enc:?}");
        let mut back = read_pcd(&bytes, "t.pcd").unwrap();
        assert_pose_close(back.sensor.as_ref().unwrap(), &sensor_pose());
        back.sensor = cloud.sensor;
        assert_eq!(back, rounded(&cloud), "{enc:?}");
    }
    // A grid with holes is written organized, the holes as NaN records.
    cloud.grid = Some(Grid {
        width: 3,
        height: 2,
        pixels: vec![0, 2, 3, 5],
    });
    let bytes = write_pcd(&cloud, Encoding::BinaryCompressed).unwrap();
    assert!(String::from_utf8_lossy(&bytes).contains("WIDTH 3\nHEIGHT 2\n"));
    let back = read_pcd(&bytes, "t.pcd").unwrap();
    assert_eq!(back.skipped, 2);
    assert_eq!(back.grid.unwrap().pixels, vec![0, 2, 3, 5]);
    // An inconsistent grid (pixels not increasing) is written unorganized.
    cloud.grid = Some(Grid {
        width: 3,
        height: 2,
        pixels: vec![2, 0, 3, 5],
    });
    let bytes = write_pcd(&cloud, Encoding::BinaryCompressed).unwrap();
    assert!(String::from_utf8_lossy(&bytes).contains("WIDTH 4\nHEIGHT 1\n"));
    assert!(read_pcd(&bytes, "t.pcd").unwrap().grid.is_none());
    // Plain points, and an empty cloud.
    for cloud in [
        CloudData::from_points(sample_cloud().points),
        CloudData::from_points(vec![]),
    ] {
        for enc in ENCODINGS {
            let back = read_pcd(&write_pcd(&cloud, enc).unwrap(), "t.pcd").unwrap();
            assert_eq!(back, rounded(&cloud), "{enc:?}");
        }
    }
    assert!(matches!(
        write_pcd(&cloud, Encoding::BinaryBigEndian),
        Err(Error::InvalidInput(_))
    ));
}

#[test]
fn compressor_shrinks_repetitive_clouds() {
    let cloud = CloudData::from_points(vec![Point3::new(1.0, 2.0, 3.0); 1000]);
    let bytes = write_pcd(&cloud, Encoding::BinaryCompressed).unwrap();
    assert!(bytes.len() < 2000, "{} bytes", bytes.len());
    assert_eq!(read_pcd(&bytes, "t.pcd").unwrap(), rounded(&cloud));
}

const ORGANIZED: &str = "# .PCD v0.7 - Point Cloud Data file format
VERSION 0.7
FIELDS x y z rgb
SIZE 4 4 4 4
TYPE F F F F
COUNT 1 1 1 1
WIDTH 3
HEIGHT 2
VIEWPOINT 1 2 3 0 0 0 1
POINTS 6
DATA ascii
0 0 1 4.2108e+06
nan nan nan 0
1 0 1 0
NaN 0 1 0
0 1 2 0

2 2 2 0
";

#[test]
fn organized_with_nan_holes_and_viewpoint() {
    let c = read_pcd(ORGANIZED.as_bytes(), "org.pcd").unwrap();
    assert_eq!(c.points.len(), 4);
    assert_eq!(c.skipped, 2);
    assert_eq!(
        c.grid,
        Some(Grid {
            width: 3,
            height: 2,
            pixels: vec![0, 2, 4, 5]
        })
    );
    assert_eq!(c.points[3], Point3::new(2.0, 2.0, 2.0));
    assert_eq!(c.fields, ["x", "y", "z", "rgb"]);
    // Quaternion (w, x, y, z) = (0, 0, 0, 1): half a turn about z.
    let sensor = c.sensor.unwrap();
    assert_eq!(sensor.translation.vector, Vector3::new(1.0, 2.0, 3.0));
    let r = sensor.rotation * Vector3::x();
    assert!((r - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
    assert!(!c.sensor_is_default);
    // The identity viewpoint, written or left out, is PCL's default: the sensor
    // at the origin (a raw sensor frame), flagged as the default.
    for text in [
        ORGANIZED.replace("VIEWPOINT 1 2 3 0 0 0 1", "VIEWPOINT 0 0 0 1 0 0 0"),
        ORGANIZED.replace("VIEWPOINT 1 2 3 0 0 0 1\n", ""),
    ] {
        let c = read_pcd(text.as_bytes(), "o.pcd").unwrap();
        assert_eq!(c.sensor, Some(Pose::identity()));
        assert!(c.sensor_is_default);
    }
    let zero = ORGANIZED.replace("VIEWPOINT 1 2 3 0 0 0 1", "VIEWPOINT 1 2 3 0 0 0 0");
    format_err(read_pcd(zero.as_bytes(), "o.pcd"), "quaternion");
}

/// Header for x y z as F4 plus a 2-float descriptor and a U1 label.
fn header(data: &str, points: usize) -> String {
    format!(
        "VERSION .7\nFIELDS x y z desc label\nSIZE 4 4 4 4 1\nTYPE F F F F U\nCOUNT 1 1 1 2 1\nWIDTH {points}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {data}\n"
    )
}

fn record(p: [f32; 3], desc: [f32; 2], label: u8) -> Vec<u8> {
    let mut v = Vec::new();
    for x in p.iter().chain(&desc) {
        v.extend_from_slice(&x.to_le_bytes());
    }
    v.push(label);
    v
}

const P: [[f32; 3]; 2] = [[1.5, -2.0, 0.25], [3.0, 4.0, 5.0]];

#[test]
fn reads_hand_written_binary_with_descriptors() {
    let mut bytes = header("binary", 2).into_bytes();
    bytes.extend(record(P[0], [9.0, 9.0], 7));
    bytes.extend(record(P[1], [8.0, 8.0], 255));
    let c = read_pcd(&bytes, "b.pcd").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "desc", "label"]);
    assert_eq!(
        c.points,
        [Point3::new(1.5, -2.0, 0.25), Point3::new(3.0, 4.0, 5.0)]
    );
    assert!(c.sensor == Some(Pose::identity()) && c.sensor_is_default && c.grid.is_none());
    for cut in [bytes.len() - 1, bytes.len() - 21, bytes.len() - 22] {
        format_err(
            read_pcd(&bytes[..cut], "b.pcd"),
            "truncated: 2 points of 21 bytes need 42 bytes",
        );
    }
}

#[test]
fn reads_hand_made_literal_only_lzf() {
    // Column-major: all x, then all y, z, desc (2 floats each), label.
    let mut raw = Vec::new();
    for axis in 0..3 {
        for p in P {
            raw.extend_from_slice(&p[axis].to_le_bytes());
        }
    }
    for p in 0..2 {
        raw.extend_from_slice(&(p as f32).to_le_bytes());
        raw.extend_from_slice(&(p as f32).to_le_bytes());
    }
    raw.extend_from_slice(&[1, 2]);
    assert_eq!(raw.len(), 42);
    // Literal runs of at most 32 bytes: control byte = length - 1.
    let mut lzf = Vec::new();
    for chunk in raw.chunks(32) {
        lzf.push((chunk.len() - 1) as u8);
        lzf.extend_from_slice(chunk);
    }
    let mut bytes = header("binary_compressed", 2).into_bytes();
    bytes.extend_from_slice(&(lzf.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&lzf);
    let c = read_pcd(&bytes, "c.pcd").unwrap();
    assert_eq!(
        c.points,
        [Point3::new(1.5, -2.0, 0.25), Point3::new(3.0, 4.0, 5.0)]
    );
    // A back-reference inside the stream: the x column is "1.5, 1.5" written as
    // 4 literal bytes plus a 4-byte copy from 4 bytes back.
    let mut raw2 = raw.clone();
    raw2[4..8].copy_from_slice(&1.5f32.to_le_bytes());
    let mut lzf2 = vec![3];
    lzf2.extend_from_slice(&raw2[..4]);
    lzf2.extend_from_slice(&[2 << 5, 3]); // length 2 + 2 = 4, offset 3 + 1 = 4
    for chunk in raw2[8..].chunks(32) {
        lzf2.push((chunk.len() - 1) as u8);
        lzf2.extend_from_slice(chunk);
    }
    let mut bytes2 = header("binary_compressed", 2).into_bytes();
    bytes2.extend_from_slice(&(lzf2.len() as u32).to_le_bytes());
    bytes2.extend_from_slice(&42u32.to_le_bytes());
    bytes2.extend_from_slice(&lzf2);
    let c2 = read_pcd(&bytes2, "c.pcd").unwrap();
    assert_eq!(c2.points[1].x, 1.5);
    // Corrupt variants.
    let with = |csize: u32, usize_: u32, stream: &[u8]| {
        let mut b = header("binary_compressed", 2).into_bytes();
        b.extend_from_slice(&csize.to_le_bytes());
        b.extend_from_slice(&usize_.to_le_bytes());
        b.extend_from_slice(stream);
        b
    };
    format_err(
        read_pcd(&with(lzf.len() as u32, 41, &lzf), "c.pcd"),
        "uncompressed size 41 differs from POINTS 2 x 21 bytes = 42",
    );
    format_err(
        read_pcd(&with(lzf.len() as u32 + 5, 42, &lzf), "c.pcd"),
        "truncated: compressed size",
    );
    format_err(
        read_pcd(
            &with(lzf.len() as u32 - 1, 42, &lzf[..lzf.len() - 1]),
            "c.pcd",
        ),
        "runs past the end",
    );
    format_err(
        read_pcd(&with(2, 42, &[0x20, 0x05]), "c.pcd"),
        "back-reference",
    );
    format_err(
        read_pcd(&with(0, 0, &[])[..], "c.pcd"),
        "uncompressed size 0 differs",
    );
    let mut short = header("binary_compressed", 2).into_bytes();
    short.extend_from_slice(&[1, 0, 0]);
    format_err(read_pcd(&short, "c.pcd"), "8-byte size header");
}

#[test]
fn reads_old_headers_integer_and_double_coordinates() {
    // v0.6: no VERSION, no COUNT, no VIEWPOINT; x as I2, y as U4, z as F8.
    let mut bytes =
        b"FIELDS x y z\nSIZE 2 4 8\nTYPE I U F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n"
            .to_vec();
    for (x, y, z) in [(-3i16, 7u32, 0.125f64), (4, 4_000_000_000, -1e300)] {
        bytes.extend_from_slice(&x.to_le_bytes());
        bytes.extend_from_slice(&y.to_le_bytes());
        bytes.extend_from_slice(&z.to_le_bytes());
    }
    let c = read_pcd(&bytes, "old.pcd").unwrap();
    assert_eq!(
        c.points,
        [Point3::new(-3.0, 7.0, 0.125), Point3::new(4.0, 4e9, -1e300)]
    );
    // POINTS alone (no WIDTH), normals as nx ny nz, CRLF line ends.
    let text = "FIELDS x y z nx ny nz\r\nSIZE 4 4 4 4 4 4\r\nTYPE F F F F F F\r\nPOINTS 1\r\nDATA ascii\r\n1 2 3 0 0 1\r\n";
    let c = read_pcd(text.as_bytes(), "n.pcd").unwrap();
    assert_eq!(c.normals.unwrap()[0], Vector3::new(0.0, 0.0, 1.0));
}

#[test]
fn corrupt_inputs_are_format_errors() {
    format_err(read_pcd(b"", "e.pcd"), "empty file");
    format_err(read_pcd(b"ply\nformat ascii 1.0\n", "e.pcd"), "wrong magic");
    format_err(
        read_pcd(b"\x89PNG\r\n\x1a\n\xff\xfe", "e.pcd"),
        "wrong magic",
    );
    let ok = header("ascii", 2);
    format_err(
        read_pcd(ok.replace("DATA ascii\n", "").as_bytes(), "h.pcd"),
        "no DATA line",
    );
    let bad = |from: &str, to: &str, needle: &str| {
        let h = ok.replace(from, to) + "1 2 3 4 5 6\n1 2 3 4 5 6\n";
        format_err(read_pcd(h.as_bytes(), "h.pcd"), needle);
    };
    bad(
        "POINTS 2",
        "POINTS 4000000000",
        "POINTS 4000000000 is not WIDTH 2 x HEIGHT 1 = 2",
    );
    bad(
        "SIZE 4 4 4 4 1",
        "SIZE 4 4 3 4 1",
        "field 'z' has TYPE F with SIZE 3",
    );
    bad(
        "SIZE 4 4 4 4 1",
        "SIZE 4 4 4 4 16",
        "field 'label' has TYPE U with SIZE 16",
    );
    bad(
        "TYPE F F F F U",
        "TYPE F F F F Q",
        "TYPE must be F, I or U, found 'Q'",
    );
    bad(
        "SIZE 4 4 4 4 1",
        "SIZE 4 4 4 4",
        "SIZE has 4 values but FIELDS names 5 fields",
    );
    bad(
        "WIDTH 2",
        "WIDTH two",
        "WIDTH must be a non-negative integer, found 'two'",
    );
    bad(
        "WIDTH 2",
        "WIDTH -2",
        "WIDTH must be a non-negative integer",
    );
    bad(
        "VIEWPOINT 0 0 0 1 0 0 0",
        "VIEWPOINT 0 0 0 1 0 0",
        "VIEWPOINT needs 7 value(s), found 6",
    );
    bad(
        "VIEWPOINT 0 0 0 1 0 0 0",
        "VIEWPOINT 0 0 x 1 0 0 0",
        "VIEWPOINT value 'x'",
    );
    bad(
        "DATA ascii",
        "DATA binary_zipped",
        "unknown DATA 'binary_zipped'",
    );
    bad(
        "FIELDS x y z desc label",
        "FIELDS x y w desc label",
        "no field 'z' (FIELDS x y w desc label)",
    );
    bad(
        "COUNT 1 1 1 2 1",
        "COUNT 2 1 1 1 1",
        "field 'x' has COUNT 2",
    );
    bad(
        "COUNT 1 1 1 2 1",
        "COUNT 1 1 1 0 1",
        "field 'desc' has COUNT 0",
    );
    bad("HEIGHT 1", "HEIGHT 1\nSPEED 3", "unknown keyword 'SPEED'");
    format_err(
        read_pcd(format!("{ok}1 2 3 4 5 6\n").as_bytes(), "a.pcd"),
        "ends after 1 points",
    );
    format_err(
        read_pcd(format!("{ok}1 2 3 4 5 6\n1 2 3 4 5\n").as_bytes(), "a.pcd"),
        "line 12: 5 values, expected 6",
    );
    format_err(
        read_pcd(
            format!("{ok}1 2 3 4 5 6\n1 2 zz 4 5 6\n").as_bytes(),
            "a.pcd",
        ),
        "line 12: value 'zz' is not a number",
    );
    // Counts too large for the data, in every encoding.
    let huge = |data: &str| {
        let mut h = header(data, 2)
            .replace("WIDTH 2", "WIDTH 4000000000")
            .replace("POINTS 2", "POINTS 4000000000")
            .into_bytes();
        h.extend_from_slice(&[0u8; 64]);
        h
    };
    format_err(
        read_pcd(&huge("binary"), "h.pcd"),
        "truncated: 4000000000 points",
    );
    format_err(
        read_pcd(&huge("binary_compressed"), "h.pcd"),
        "differs from POINTS 4000000000",
    );
    format_err(read_pcd(&huge("ascii"), "h.pcd"), "value");
    let wide = ok.replace("COUNT 1 1 1 2 1", "COUNT 1 1 1 4000000000 1") + "1 2 3\n";
    format_err(
        read_pcd(wide.as_bytes(), "w.pcd"),
        "a line needs 4000000004 values",
    );
    // Lowercase TYPE letters are accepted (Open3D does too).
    let lower = ok.replace("TYPE F F F F U", "TYPE f f f f u") + "1 2 3 4 5 6\n1 2 3 4 5 6\n";
    assert_eq!(read_pcd(lower.as_bytes(), "l.pcd").unwrap().points.len(), 2);
    // Truncated files written by the writer, cut at several points.
    for enc in [Encoding::BinaryLittleEndian, Encoding::BinaryCompressed] {
        let good = write_pcd(&sample_cloud(), enc).unwrap();
        let body = good.windows(5).position(|w| w == b"DATA ").unwrap();
        let body = body + good[body..].iter().position(|&b| b == b'\n').unwrap() + 1;
        for cut in [body, body + 3, body + 8, body + 20, good.len() - 1] {
            format_err(read_pcd(&good[..cut], "t.pcd"), "truncated");
        }
        format_err(read_pcd(&good[..body - 3], "t.pcd"), "");
    }
}

fn cloud_strategy() -> impl Strategy<Value = CloudData> {
    prop::collection::vec(
        (
            -1e6f64..1e6,
            -1e6f64..1e6,
            prop_oneof![Just(0.5f64), -1e6f64..1e6],
        ),
        0..60,
    )
    .prop_map(|v| CloudData::from_points(v.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect()))
}

proptest! {
    #[test]
    fn proptest_binary_compressed_round_trip(cloud in cloud_strategy()) {
        let bytes = write_pcd(&cloud, Encoding::BinaryCompressed).unwrap();
        prop_assert_eq!(read_pcd(&bytes, "p.pcd").unwrap(), rounded(&cloud));
    }
}

#[test]
fn prefixes_and_bit_flips_never_panic() {
    let mut cloud = sample_cloud();
    cloud.sensor = Some(sensor_pose());
    let mut files: Vec<Vec<u8>> = ENCODINGS
        .iter()
        .map(|&e| write_pcd(&cloud, e).unwrap())
        .collect();
    files.push(ORGANIZED.as_bytes().to_vec());
    for file in &files {
        common::for_each_corruption(file, &[0, 1, 2, 3, 4, 5, 6, 7], |f| {
            let _ = read_pcd(f, "f.pcd");
        });
    }
}

#[test]
fn organized_cloud_with_holes_round_trips_in_every_encoding() {
    let points = vec![
        Point3::new(0.0, 0.0, 1.0),
        Point3::new(0.5, 0.0, 1.5),
        Point3::new(0.0, 0.25, 2.0),
        Point3::new(0.5, 0.25, 2.5),
    ];
    let mut cloud = CloudData::from_points(points.clone());
    cloud.grid = Some(Grid {
        width: 3,
        height: 2,
        pixels: vec![0, 2, 3, 5],
    });
    for enc in [
        Encoding::Ascii,
        Encoding::BinaryLittleEndian,
        Encoding::BinaryCompressed,
    ] {
        let bytes = write_pcd(&cloud, enc).unwrap();
        let back = read_pcd(&bytes, "holes.pcd").unwrap();
        assert_eq!(back.points, points, "{enc:?}");
        assert_eq!(back.skipped, 2, "{enc:?}");
        let g = back.grid.expect("organized");
        assert_eq!((g.width, g.height), (3, 2));
        assert_eq!(g.pixels, vec![0, 2, 3, 5]);
    }
}

#[test]
fn organized_no_returns_at_the_viewpoint_origin_are_left_out() {
    let body = "0 0 0\n1 0 2\nnan nan nan\n0 0 0\n0.5 0.5 1\n2 2 2\n";
    let head = |viewpoint: &str, height: usize| {
        format!(
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {}\n\
             HEIGHT {height}\n{viewpoint}POINTS 6\nDATA ascii\n{body}",
            6 / height
        )
    };
    // The default viewpoint: the sensor at (0, 0, 0), where the driver put its no-returns.
    let c = read_pcd(head("", 2).as_bytes(), "o.pcd").unwrap();
    assert_eq!(
        (c.points.len(), c.skipped, c.at_origin, c.no_returns()),
        (3, 1, 2, 3)
    );
    assert_eq!(c.grid.as_ref().unwrap().pixels, vec![1, 4, 5]);
    // A VIEWPOINT elsewhere: the points at its origin are the no-returns.
    let c = read_pcd(head("VIEWPOINT 2 2 2 1 0 0 0\n", 2).as_bytes(), "o.pcd").unwrap();
    assert_eq!((c.points.len(), c.at_origin), (4, 1));
    assert_eq!(c.grid.as_ref().unwrap().pixels, vec![0, 1, 3, 4]);
    // Unorganized: a point at the origin may be a real point, and is kept.
    let c = read_pcd(head("", 1).as_bytes(), "o.pcd").unwrap();
    assert_eq!(
        (c.points.len(), c.skipped, c.at_origin, c.no_returns()),
        (5, 1, 0, 0)
    );
}
