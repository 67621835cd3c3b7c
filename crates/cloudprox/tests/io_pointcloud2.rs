//! ROS PointCloud2 reading and encoding.

use crate::common;

use cloudprox::io::pointcloud2::{
    decode_pointcloud2, encode_pointcloud2, read_pointcloud2, read_pointcloud2_message,
    read_pointcloud2_named, write_pointcloud2, MessageEncoding, PointCloud2Header,
    PointCloud2Layout, PointField, FLOAT32, FLOAT64, INT16, UINT8,
};
use cloudprox::io::{CloudData, Grid};
use cloudprox::prelude::*;

fn format_err<T: std::fmt::Debug>(r: Result<T>, needle: &str) {
    match r {
        Err(Error::Format {
            problem,
            format,
            path,
        }) => {
            assert_eq!(format, "PointCloud2");
            assert_eq!(path, "PointCloud2");
            assert!(
                problem.contains(needle),
                "problem {problem:?} does not mention {needle:?}"
            );
        }
        other => panic!("expected a PointCloud2 format error mentioning {needle:?}, got {other:?}"),
    }
}

fn field(name: &str, offset: u32, datatype: u8) -> PointField {
    PointField {
        name: name.into(),
        offset,
        datatype,
        count: 1,
    }
}

#[test]
fn round_trips_within_f32() {
    let mut cloud = CloudData::from_points(vec![
        Point3::new(0.1, -0.2, 0.3),
        Point3::new(1.0 / 3.0, 123.456, -1e-7),
    ]);
    let (layout, data) = write_pointcloud2(&cloud).unwrap();
    assert_eq!(
        (
            layout.height,
            layout.width,
            layout.point_step,
            layout.row_step
        ),
        (1, 2, 12, 24)
    );
    assert_eq!(data.len(), 24);
    let back = read_pointcloud2(&layout, &data).unwrap();
    assert_eq!(back.fields, cloud.fields);
    for (a, b) in back.points.iter().zip(&cloud.points) {
        assert_eq!(a.map(|c| c as f32), b.map(|c| c as f32));
    }
    cloud.normals = Some(vec![Vector3::z(), Vector3::new(0.6, 0.8, 0.0)]);
    let (layout, data) = write_pointcloud2(&cloud).unwrap();
    let back = read_pointcloud2(&layout, &data).unwrap();
    let n = back.normals.unwrap();
    assert!((n[1] - Vector3::new(0.6, 0.8, 0.0)).norm() < 1e-7);
    assert_eq!(
        back.fields,
        ["x", "y", "z", "normal_x", "normal_y", "normal_z"]
    );
}

/// An organized 3 x 2 big-endian cloud with padding: x y z as float64 at 8,
/// 0, 16; intensity (uint8) at 24; an int16 `ring` at 26; point_step 32;
/// row_step 100 (4 bytes of row padding).
fn organized() -> (PointCloud2Layout, Vec<u8>) {
    let layout = PointCloud2Layout {
        height: 2,
        width: 3,
        fields: vec![
            field("y", 0, FLOAT64),
            field("x", 8, FLOAT64),
            field("z", 16, FLOAT64),
            field("intensity", 24, UINT8),
            field("ring", 26, INT16),
        ],
        is_bigendian: true,
        point_step: 32,
        row_step: 100,
    };
    let mut data = vec![0xAAu8; 200];
    for r in 0..2 {
        for c in 0..3 {
            let at = r * 100 + c * 32;
            let pixel = (r * 3 + c) as f64;
            let x = if pixel == 1.0 || pixel == 5.0 {
                f64::NAN
            } else {
                pixel
            };
            data[at..at + 8].copy_from_slice(&(-pixel).to_be_bytes());
            data[at + 8..at + 16].copy_from_slice(&x.to_be_bytes());
            data[at + 16..at + 24].copy_from_slice(&(2.0 * pixel).to_be_bytes());
        }
    }
    (layout, data)
}

#[test]
fn reads_organized_big_endian_with_holes() {
    let (layout, data) = organized();
    let c = read_pointcloud2(&layout, &data).unwrap();
    assert_eq!(c.skipped, 2);
    // Pixel 0 is (0, -0, 0): a no-return of an organized cloud, left out.
    assert_eq!(c.at_origin, 1);
    assert_eq!(c.no_returns(), 3);
    assert_eq!(
        c.grid,
        Some(Grid {
            width: 3,
            height: 2,
            pixels: vec![2, 3, 4]
        })
    );
    assert_eq!(c.points[0], Point3::new(2.0, -2.0, 4.0));
    assert_eq!(c.points[2], Point3::new(4.0, -4.0, 8.0));
    assert_eq!(c.fields, ["y", "x", "z", "intensity", "ring"]);
    // Extra data past row_step * height is ignored.
    let mut longer = data.clone();
    longer.extend_from_slice(&[1, 2, 3]);
    assert_eq!(read_pointcloud2(&layout, &longer).unwrap(), c);
}

#[test]
fn invalid_layouts_are_format_errors() {
    let (layout, data) = organized();
    let with = |f: &dyn Fn(&mut PointCloud2Layout)| {
        let mut l = layout.clone();
        f(&mut l);
        l
    };
    format_err(
        read_pointcloud2(&with(&|l| l.fields[2].name = "w".into()), &data),
        "no field 'z' (fields: y, x, w, intensity, ring)",
    );
    format_err(
        read_pointcloud2(&with(&|l| l.fields[3].datatype = 9), &data),
        "field 'intensity' has unknown datatype 9",
    );
    format_err(
        read_pointcloud2(&with(&|l| l.fields[4].offset = 31), &data),
        "field 'ring' (offset 31, 1 x 2 bytes) reaches past point_step 32",
    );
    format_err(
        read_pointcloud2(&with(&|l| l.fields[3].count = u32::MAX), &data),
        "reaches past point_step",
    );
    format_err(
        read_pointcloud2(&with(&|l| l.width = 4), &data),
        "point_step 32 x width 4 is more than row_step 100",
    );
    format_err(
        read_pointcloud2(&with(&|l| l.height = 4_000_000_000), &data),
        "truncated: row_step 100 x height 4000000000 bytes needed, data has 200",
    );
    for cut in [0, 1, 99, 100, 199] {
        format_err(read_pointcloud2(&layout, &data[..cut]), "truncated");
    }
    // A point_step of 0 cannot hold x.
    format_err(
        read_pointcloud2(
            &PointCloud2Layout {
                height: 1,
                width: u32::MAX,
                fields: vec![
                    field("x", 0, FLOAT32),
                    field("y", 0, FLOAT32),
                    field("z", 0, FLOAT32),
                ],
                is_bigendian: false,
                point_step: 0,
                row_step: 0,
            },
            &[],
        ),
        "reaches past point_step 0",
    );
    // Empty clouds are fine.
    let empty = read_pointcloud2(&with(&|l| l.height = 0), &[]).unwrap();
    assert!(empty.points.is_empty());
}

#[test]
fn prefixes_and_bit_flips_never_panic() {
    let (layout, data) = organized();
    common::for_each_corruption(&data, &[0, 1, 2, 3, 4, 5, 6, 7], |d| {
        let _ = read_pointcloud2(&layout, d);
    });
    // Random-ish layouts never panic either.
    for seed in 0u32..2000 {
        let h = |k: u32| seed.wrapping_mul(2_654_435_761).rotate_left(k * 5);
        let l = PointCloud2Layout {
            height: h(1) % 4,
            width: h(2) % 9,
            fields: vec![
                field("x", h(3) % 40, (h(4) % 10) as u8),
                field("y", h(5) % 40, FLOAT32),
                field("z", h(6) % 40, FLOAT64),
            ],
            is_bigendian: h(7) % 2 == 0,
            point_step: h(8) % 48,
            row_step: h(9) % 200,
        };
        let _ = read_pointcloud2(&l, &data);
    }
}

#[test]
fn duplicate_and_empty_fields_are_named() {
    let field = |name: &str, offset: u32, count: u32| PointField {
        name: name.into(),
        offset,
        datatype: FLOAT32,
        count,
    };
    let layout = |fields: Vec<PointField>| PointCloud2Layout {
        height: 1,
        width: 1,
        fields,
        is_bigendian: false,
        point_step: 16,
        row_step: 16,
    };
    let data = [0u8; 16];
    let twice = layout(vec![
        field("x", 0, 1),
        field("y", 4, 1),
        field("z", 8, 1),
        field("x", 12, 1),
    ]);
    let msg = read_pointcloud2(&twice, &data).unwrap_err().to_string();
    assert!(msg.contains("field 'x' appears twice"), "{msg}");
    let empty = layout(vec![field("x", 0, 0), field("y", 4, 1), field("z", 8, 1)]);
    let msg = read_pointcloud2(&empty, &data).unwrap_err().to_string();
    assert!(msg.contains("field 'x' has count 0"), "{msg}");
}

/// A float32 organized 4 x 2 cloud (x y z at 0 4 8, intensity at 12) with a
/// no-return at the origin and a NaN hole, little or big endian.
fn float_grid(big: bool) -> (PointCloud2Layout, Vec<u8>) {
    let pts: [[f32; 3]; 8] = [
        [1.0, 0.0, 0.5],
        [0.0, 0.0, 0.0],
        [f32::NAN, 0.0, 0.0],
        [-1.0, 2.0, 3.0],
        [0.25, 0.5, 0.75],
        [-0.0, 0.0, -0.0],
        [4.0, 5.0, 6.0],
        [7.0, 8.0, 9.0],
    ];
    let mut data = Vec::new();
    for (i, p) in pts.iter().enumerate() {
        for v in p.iter().chain(std::iter::once(&(i as f32))) {
            data.extend_from_slice(&if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    }
    let layout = PointCloud2Layout {
        height: 2,
        width: 4,
        fields: vec![
            field("x", 0, FLOAT32),
            field("y", 4, FLOAT32),
            field("z", 8, FLOAT32),
            field("intensity", 12, FLOAT32),
        ],
        is_bigendian: big,
        point_step: 16,
        row_step: 64,
    };
    (layout, data)
}

#[test]
fn organized_no_returns_are_counted_and_their_pixels_kept() {
    for big in [false, true] {
        let (layout, data) = float_grid(big);
        let c = read_pointcloud2(&layout, &data).unwrap();
        assert_eq!((c.skipped, c.at_origin, c.no_returns()), (1, 2, 3));
        assert_eq!(c.grid.as_ref().unwrap().pixels, vec![0, 3, 4, 6, 7]);
        assert_eq!(c.points[1], Point3::new(-1.0, 2.0, 3.0));
        // The general reader (normals present) agrees with the float32 fast path.
        let mut with_normals = layout.clone();
        with_normals.point_step = 16;
        with_normals.fields.push(field("normal_x", 12, FLOAT32));
        with_normals.fields.push(field("normal_y", 12, FLOAT32));
        with_normals.fields.push(field("normal_z", 12, FLOAT32));
        let g = read_pointcloud2(&with_normals, &data).unwrap();
        assert_eq!(g.points, c.points);
        assert_eq!(g.grid, c.grid);
        assert_eq!((g.skipped, g.at_origin), (1, 2));
        // Unorganized: the origin points are kept (they may be real points).
        let mut flat = layout.clone();
        flat.height = 1;
        flat.width = 8;
        flat.row_step = 128;
        let f = read_pointcloud2(&flat, &data).unwrap();
        assert_eq!(
            (f.points.len(), f.skipped, f.at_origin, f.no_returns()),
            (7, 1, 0, 0)
        );
    }
}

#[test]
fn serialized_messages_round_trip_in_both_encodings() {
    let (layout, data) = float_grid(false);
    let header = PointCloud2Header {
        stamp_ns: 1_700_000_000_123_456_789,
        frame_id: "velodyne".into(),
        is_dense: false,
    };
    let direct = read_pointcloud2(&layout, &data).unwrap();
    for encoding in [MessageEncoding::Cdr, MessageEncoding::Ros1] {
        let bytes = encode_pointcloud2(&header, &layout, &data, encoding);
        let msg = decode_pointcloud2(&bytes, encoding, "m").unwrap();
        assert_eq!(msg.header, header);
        assert_eq!(msg.layout, layout);
        assert_eq!(msg.data, &data[..]);
        // The data is borrowed from the message, not copied.
        let start = bytes.as_ptr() as usize;
        let at = msg.data.as_ptr() as usize;
        assert!(at >= start && at + msg.data.len() <= start + bytes.len());
        let (cloud, h) = read_pointcloud2_message(&bytes, encoding, "m").unwrap();
        assert_eq!(cloud, direct);
        assert_eq!(h, header);
        // Every cut is a format error naming the message, never a panic.
        for cut in 0..bytes.len() {
            match read_pointcloud2_message(&bytes[..cut], encoding, "bag.db3 (topic /p)") {
                Err(Error::Format { path, problem, .. }) => {
                    assert_eq!(path, "bag.db3 (topic /p)");
                    assert!(problem.contains("truncated"), "cut {cut}: {problem}");
                }
                other => panic!("cut {cut}: expected a format error, got {other:?}"),
            }
        }
    }
}

#[test]
fn big_endian_cdr_and_bad_encapsulations() {
    let (layout, data) = float_grid(true);
    let header = PointCloud2Header {
        stamp_ns: -5,
        frame_id: String::new(),
        is_dense: true,
    };
    // A big-endian CDR message, written by hand: encapsulation 0x0000.
    let mut m = vec![0u8, 0, 0, 0];
    let be = |m: &mut Vec<u8>, v: u32| {
        while (m.len() - 4) % 4 != 0 {
            m.push(0);
        }
        m.extend_from_slice(&v.to_be_bytes());
    };
    be(&mut m, (-1i32) as u32);
    be(&mut m, 999_999_995);
    be(&mut m, 1);
    m.push(0); // frame_id "" with its NUL
    be(&mut m, layout.height);
    be(&mut m, layout.width);
    be(&mut m, layout.fields.len() as u32);
    for f in &layout.fields {
        be(&mut m, f.name.len() as u32 + 1);
        m.extend_from_slice(f.name.as_bytes());
        m.push(0);
        be(&mut m, f.offset);
        m.push(f.datatype);
        be(&mut m, f.count);
    }
    m.push(1);
    be(&mut m, layout.point_step);
    be(&mut m, layout.row_step);
    be(&mut m, data.len() as u32);
    m.extend_from_slice(&data);
    m.push(1);
    let msg = decode_pointcloud2(&m, MessageEncoding::Cdr, "be").unwrap();
    assert_eq!(msg.header, header);
    assert_eq!(msg.layout, layout);
    let cloud = read_pointcloud2_named(&msg.layout, msg.data, "be").unwrap();
    assert_eq!(cloud.points.len(), 5);
    m[1] = 7;
    format_err_named(
        decode_pointcloud2(&m, MessageEncoding::Cdr, "be"),
        "be",
        "unsupported CDR encapsulation 0x0007",
    );
    // A field count the message cannot hold allocates nothing.
    let mut huge = encode_pointcloud2(&header, &layout, &data, MessageEncoding::Ros1);
    huge[4 + 8 + 4 + 8..4 + 8 + 4 + 12].copy_from_slice(&u32::MAX.to_le_bytes());
    format_err_named(
        decode_pointcloud2(&huge, MessageEncoding::Ros1, "huge"),
        "huge",
        "4294967295 fields announced",
    );
}

#[test]
fn missing_fields_name_the_message() {
    let (mut layout, data) = float_grid(false);
    layout.fields.retain(|f| f.name != "z");
    let header = PointCloud2Header {
        stamp_ns: 0,
        frame_id: "f".into(),
        is_dense: false,
    };
    let bytes = encode_pointcloud2(&header, &layout, &data, MessageEncoding::Cdr);
    format_err_named(
        read_pointcloud2_message(&bytes, MessageEncoding::Cdr, "b.mcap (topic /p, message 3)")
            .map(|r| r.0),
        "b.mcap (topic /p, message 3)",
        "no field 'z' (fields: x, y, intensity)",
    );
}

fn format_err_named<T: std::fmt::Debug>(r: Result<T>, name: &str, needle: &str) {
    match r {
        Err(Error::Format { problem, path, .. }) => {
            assert_eq!(path, name);
            assert!(
                problem.contains(needle),
                "{problem:?} does not mention {needle:?}"
            );
        }
        other => panic!("expected a format error mentioning {needle:?}, got {other:?}"),
    }
}

#[test]
fn transform_moves_points_normals_covariances_and_sensor() {
    use cloudprox::math::{Matrix3, Pose};
    use nalgebra::{Translation3, UnitQuaternion};
    let mut c = CloudData::from_points(vec![Point3::new(1.0, 0.0, 0.0)]);
    c.normals = Some(vec![Vector3::x()]);
    c.covariances = Some(vec![Matrix3::from_diagonal(&Vector3::new(4.0, 1.0, 1.0))]);
    c.sensor = Some(Pose::identity());
    c.sensor_is_default = true;
    let pose = Pose::from_parts(
        Translation3::new(0.0, 0.0, 2.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
    );
    c.transform(&pose);
    assert!((c.points[0] - Point3::new(0.0, 1.0, 2.0)).norm() < 1e-12);
    assert!((c.normals.as_ref().unwrap()[0] - Vector3::y()).norm() < 1e-12);
    let cov = c.covariances.as_ref().unwrap()[0];
    assert!((cov - Matrix3::from_diagonal(&Vector3::new(1.0, 4.0, 1.0))).norm() < 1e-12);
    assert_eq!(c.sensor, Some(pose));
    assert!(!c.sensor_is_default);
}
