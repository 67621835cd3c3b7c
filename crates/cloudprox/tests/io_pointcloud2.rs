//! ROS PointCloud2 reading and encoding.

use crate::common;

use cloudprox::io::pointcloud2::{
    read_pointcloud2, write_pointcloud2, PointCloud2Layout, PointField, FLOAT32, FLOAT64, INT16,
    UINT8,
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
    assert_eq!(
        c.grid,
        Some(Grid {
            width: 3,
            height: 2,
            pixels: vec![0, 2, 3, 4]
        })
    );
    assert_eq!(c.points[1], Point3::new(2.0, -2.0, 4.0));
    assert_eq!(c.points[3], Point3::new(4.0, -4.0, 8.0));
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
