//! LAS and LAZ: files written with the `las` crate read back exactly; corrupt
//! and truncated files are format errors.

use crate::common;

use std::io::Cursor;

use cloudprox::io::las::read_las;
use cloudprox::io::{read_point_cloud_bytes, CloudData, CloudFormat};
use cloudprox::Error;
use las::point::Format;
use las::{Builder, Color, Point, Transform, Vector, Vlr, Writer};

const OFFSET: [f64; 3] = [500_000.0, 4_500_000.0, 100.0];
const SCALE: f64 = 0.001;

/// Raw integer coordinates of the test points.
const RAW: [[i32; 3]; 5] = [
    [0, 0, 0],
    [1, 2, 3],
    [-1, -1000, 123_456],
    [999_999_999, -2_000_000_000, 7],
    [2_147_483_647, -2_147_483_648, -1],
];

fn expected(raw: [i32; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| SCALE * f64::from(raw[k]) + OFFSET[k])
}

/// A LAS (or LAZ when `compressed`) file of the test points in `format`.
fn write_file(version: (u8, u8), format: u8, compressed: bool) -> Vec<u8> {
    write_file_with(version, format, compressed, None)
}

/// Like [`write_file`], with an extended record holding `evlr` (LAS 1.4).
fn write_file_with(
    version: (u8, u8),
    format: u8,
    compressed: bool,
    evlr: Option<Vec<u8>>,
) -> Vec<u8> {
    let mut builder = Builder::from(version);
    if let Some(data) = evlr {
        builder.evlrs.push(Vlr {
            user_id: "cloudprox".into(),
            record_id: 7,
            description: "test record".into(),
            data,
        });
    }
    let mut point_format = Format::new(format).unwrap();
    point_format.is_compressed = compressed;
    builder.point_format = point_format;
    let t = |k: usize| Transform {
        scale: SCALE,
        offset: OFFSET[k],
    };
    builder.transforms = Vector {
        x: t(0),
        y: t(1),
        z: t(2),
    };
    let header = builder.into_header().unwrap();
    let mut writer = Writer::new(Cursor::new(Vec::new()), header).unwrap();
    for (i, raw) in RAW.iter().enumerate() {
        let [x, y, z] = expected(*raw);
        let fmt = Format::new(format).unwrap();
        writer
            .write_point(Point {
                x,
                y,
                z,
                intensity: 100 + i as u16,
                return_number: 1,
                number_of_returns: 1,
                gps_time: fmt.has_gps_time.then_some(1000.5 + i as f64),
                color: fmt.has_color.then_some(Color::new(1, 2, 3)),
                nir: fmt.has_nir.then_some(4),
                ..Default::default()
            })
            .unwrap();
    }
    writer.into_inner().unwrap().into_inner()
}

fn check(cloud: &CloudData) {
    assert_eq!(cloud.points.len(), RAW.len());
    assert_eq!(cloud.skipped, 0);
    for (p, raw) in cloud.points.iter().zip(RAW) {
        let e = expected(raw);
        assert_eq!([p.x, p.y, p.z], e, "raw {raw:?}");
    }
    // Millimetre steps at UTM offsets survive.
    let d = cloud.points[1] - cloud.points[0];
    assert!((d.x - 0.001).abs() < 1e-9 && (d.y - 0.002).abs() < 1e-9);
}

fn problem(r: cloudprox::Result<CloudData>, format: &str) -> String {
    match r {
        Err(Error::Format {
            path,
            format: f,
            problem,
        }) => {
            assert_eq!(path, "t.las");
            assert_eq!(f, format);
            problem
        }
        Err(e) => panic!("expected a format error, got {e:?}"),
        Ok(c) => panic!("expected a format error, got {} points", c.points.len()),
    }
}

#[test]
fn las_formats_0_1_3_read_back_exactly() {
    let base = ["x", "y", "z", "intensity", "return_number"];
    for (format, extra) in [
        (0u8, &[][..]),
        (1, &["gps_time"][..]),
        (3, &["gps_time", "red", "green", "blue"][..]),
    ] {
        let bytes = write_file((1, 2), format, false);
        let cloud = read_las(&bytes, "t.las").unwrap();
        check(&cloud);
        for f in base.iter().chain(extra) {
            assert!(
                cloud.fields.iter().any(|g| g == f),
                "{f} in {:?}",
                cloud.fields
            );
        }
        assert!(cloud.fields.iter().any(|g| g == "classification"));
        assert_eq!(
            cloud.fields.iter().any(|g| g == "gps_time"),
            format != 0,
            "{:?}",
            cloud.fields
        );
        let via = read_point_cloud_bytes(&bytes, "t.las", CloudFormat::Las).unwrap();
        assert_eq!(via, cloud);
    }
}

#[test]
fn las_1_4_format_6_and_8() {
    for format in [6u8, 8] {
        let bytes = write_file((1, 4), format, false);
        let cloud = read_las(&bytes, "t.las").unwrap();
        check(&cloud);
        assert!(cloud.fields.iter().any(|g| g == "scanner_channel"));
        assert_eq!(cloud.fields.iter().any(|g| g == "nir"), format == 8);
    }
}

#[test]
fn laz_formats_0_1_3_read_back_exactly() {
    for format in [0u8, 1, 3] {
        let bytes = write_file((1, 2), format, true);
        let cloud = read_las(&bytes, "t.laz").unwrap();
        check(&cloud);
    }
    let bytes = write_file((1, 4), 7, true);
    check(&read_las(&bytes, "t.laz").unwrap());
}

#[test]
fn truncated_las_names_count_and_size() {
    let bytes = write_file((1, 2), 1, false);
    let len = bytes.len();
    // Point records are 28 bytes in format 1.
    for cut in [len - 1, len - 28, len - 60] {
        let p = problem(read_las(&bytes[..cut], "t.las"), "LAS");
        assert!(p.contains("truncated"), "{p}");
        assert!(p.contains("promises 5 points of 28 bytes"), "{p}");
        assert!(p.contains(&format!("the file has {cut} bytes")), "{p}");
    }
    for cut in [0, 3, 100, 226] {
        let p = problem(read_las(&bytes[..cut], "t.las"), "LAS");
        assert!(p.contains("LASF") || p.contains("227 bytes"), "{p}");
    }
    // A point count that overflows.
    let mut huge = bytes.clone();
    huge[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = problem(read_las(&huge, "t.las"), "LAS");
    assert!(p.contains(&format!("promises {} points", u32::MAX)), "{p}");
}

#[test]
fn truncated_laz_is_an_error() {
    let bytes = write_file((1, 2), 3, true);
    let len = bytes.len();
    for cut in [len - 1, len - 8, len - 20, len / 2, 400, 300, 230] {
        if cut >= len {
            continue;
        }
        let r = read_las(&bytes[..cut], "t.las");
        assert!(
            matches!(&r, Err(Error::Format { format, .. }) if format == "LAZ"),
            "cut {cut} of {len}: {r:?}"
        );
    }
    // More points promised than the compressed data holds.
    let mut more = bytes.clone();
    more[107..111].copy_from_slice(&6u32.to_le_bytes());
    let r = read_las(&more, "t.las");
    assert!(matches!(&r, Err(Error::Format { .. })), "{r:?}");
}

#[test]
fn bad_headers() {
    let bytes = write_file((1, 2), 0, false);
    let p = problem(
        read_las(b"PK\x03\x04 not a las file at all", "t.las"),
        "LAS",
    );
    assert!(p.contains("signature"), "{p}");
    let mut zero_scale = bytes.clone();
    zero_scale[131..139].copy_from_slice(&0.0f64.to_le_bytes());
    let p = problem(read_las(&zero_scale, "t.las"), "LAS");
    assert!(p.contains("x scale factor is 0"), "{p}");
    let mut nan_offset = bytes.clone();
    nan_offset[171..179].copy_from_slice(&f64::NAN.to_le_bytes());
    let p = problem(read_las(&nan_offset, "t.las"), "LAS");
    assert!(p.contains("z offset is NaN"), "{p}");
    let mut far = bytes.clone();
    far[96..100].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = problem(read_las(&far, "t.las"), "LAS");
    assert!(p.contains("point data starts at offset"), "{p}");
    let mut format = bytes.clone();
    format[104] = 42;
    let p = problem(read_las(&format, "t.las"), "LAS");
    assert!(p.contains("42"), "{p}");
}

#[test]
fn no_prefix_or_bit_flip_panics() {
    for (bytes, name) in [
        (write_file((1, 2), 3, false), "a.las"),
        (write_file((1, 4), 6, false), "b.las"),
        (write_file((1, 2), 3, true), "c.laz"),
        (write_file((1, 4), 7, true), "d.laz"),
    ] {
        common::for_each_corruption(&bytes, &[0, 4, 7], |f| {
            let _ = read_las(f, name);
        });
    }
}

#[test]
fn extended_records_are_checked() {
    let bytes = write_file_with((1, 4), 6, false, Some(vec![9u8; 100]));
    check(&read_las(&bytes, "t.las").unwrap());
    // The extended record's length field (at its offset + 20) promises more than the file holds.
    let start = u64::from_le_bytes(bytes[235..243].try_into().unwrap()) as usize;
    assert_eq!(u32::from_le_bytes(bytes[243..247].try_into().unwrap()), 1);
    let mut long = bytes.clone();
    long[start + 20..start + 28].copy_from_slice(&u64::MAX.to_le_bytes());
    let p = problem(read_las(&long, "t.las"), "LAS");
    assert!(
        p.contains(&format!("extended record at offset {start}")),
        "{p}"
    );
    let p = problem(read_las(&bytes[..bytes.len() - 1], "t.las"), "LAS");
    assert!(p.contains("extended record"), "{p}");
    let mut far = bytes.clone();
    far[235..243].copy_from_slice(&(1u64 << 40).to_le_bytes());
    let p = problem(read_las(&far, "t.las"), "LAS");
    assert!(p.contains("1 extended records from offset"), "{p}");
}

/// fuzz target `las` (laspy's `1_4_w_evlr.laz`, mutated): a layered LAZ chunk
/// (LAS 1.4 point formats) whose layer size reads 4 GiB made the decoder
/// allocate and zero 4 GiB before it found the data missing. Every layered
/// chunk's layer sizes must now fit in the file.
#[test]
fn layered_chunk_sizes_must_fit_in_the_file() {
    for format in [6, 7] {
        let bytes = write_file((1, 4), format, true);
        check(&read_las(&bytes, "t.las").unwrap());
        let start = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
        let record_len = usize::from(u16::from_le_bytes(bytes[105..107].try_into().unwrap()));
        // Chunk table offset, first point, point count, then the layer sizes.
        let sizes = start + 8 + record_len + 4;
        for layer in [0, 1, 8] {
            let mut big = bytes.clone();
            let at = sizes + 4 * layer;
            big[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
            let p = problem(read_las(&big, "t.las"), "LAZ");
            assert!(
                p.contains("the layers of chunk 0") && p.contains("add up to"),
                "{p}"
            );
        }
        let p = problem(read_las(&bytes[..sizes + 8], "t.las"), "LAZ");
        assert!(p.contains("truncated"), "{p}");
    }
    // The second input the fuzzer found: the laszip record's compressor set to
    // 1 (point-wise). The decoder still decodes the LAS 1.4 items in layers,
    // without the chunk table offset, so it read its layer sizes 8 bytes
    // early: from the chunk's layer sizes and data.
    let bytes = write_file((1, 4), 6, true);
    let vlr = bytes
        .windows(14)
        .position(|w| w == b"laszip encoded")
        .unwrap()
        - 2;
    let mut pointwise = bytes.clone();
    pointwise[vlr + 54..vlr + 56].copy_from_slice(&1u16.to_le_bytes());
    let p = problem(read_las(&pointwise, "t.las"), "LAZ");
    assert!(p.contains("chunk 0"), "{p}");
    // A layered file without points has no chunk to check.
    let mut builder = Builder::from((1, 4));
    let mut point_format = Format::new(6).unwrap();
    point_format.is_compressed = true;
    builder.point_format = point_format;
    let writer = Writer::new(Cursor::new(Vec::new()), builder.into_header().unwrap()).unwrap();
    let empty = writer.into_inner().unwrap().into_inner();
    assert_eq!(read_las(&empty, "t.las").unwrap().points.len(), 0);
}

/// An item whose size is not its type's (here point 10 at 21 bytes and GPS
/// time at 7: the same total) would have the decoder read past its slices
/// with unchecked reads in release builds: a format error.
#[test]
fn laszip_items_have_their_fixed_sizes() {
    let bytes = write_file((1, 2), 3, true);
    let vlr = bytes
        .windows(14)
        .position(|w| w == b"laszip encoded")
        .unwrap()
        - 2;
    let items = vlr + 54 + 34;
    assert_eq!(u16::from_le_bytes([bytes[items], bytes[items + 1]]), 6);
    let mut odd = bytes.clone();
    odd[items + 2..items + 4].copy_from_slice(&21u16.to_le_bytes());
    odd[items + 8..items + 10].copy_from_slice(&7u16.to_le_bytes());
    let p = problem(read_las(&odd, "t.las"), "LAZ");
    assert!(p.contains("item of type 6 is 21 bytes, not 20"), "{p}");
}

/// Found by the fuzz target `las` (2026-11-25, 208 708 executions): a LAZ file
/// whose chunk table offset lies before the point data makes the `laz` crate
/// take the offset from the file's last 8 bytes, and it sized its chunk table
/// from the count found there (up to 2^32 entries of 16 bytes) before reading
/// it. The header check now follows the crate to that table too.
#[test]
fn a_chunk_table_found_at_the_end_must_fit_in_the_file() {
    let mut bytes = write_file((1, 2), 1, true);
    let n = read_las(&bytes, "t.las").unwrap().points.len();
    let start = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
    let table = i64::from_le_bytes(bytes[start..start + 8].try_into().unwrap());
    assert!(usize::try_from(table).unwrap() > start);
    // The file read back as written, with the offset moved to the end.
    bytes[start..start + 8].copy_from_slice(&(-1i64).to_le_bytes());
    bytes.extend_from_slice(&table.to_le_bytes());
    assert_eq!(read_las(&bytes, "t.las").unwrap().points.len(), n);
    // A count of 2^32 - 1 chunks there is refused before any allocation.
    let t = usize::try_from(table).unwrap();
    bytes[t + 4..t + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = problem(read_las(&bytes, "t.las"), "LAZ");
    assert!(p.contains("4294967295 chunks"), "{p}");
}
