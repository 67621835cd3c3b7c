//! NPY reading and writing.

use crate::common;

use cloudprox::io::npy::{read_npy, write_npy};
use cloudprox::io::CloudData;
use cloudprox::prelude::*;

fn format_err<T: std::fmt::Debug>(r: Result<T>, needle: &str) {
    match r {
        Err(Error::Format {
            problem, format, ..
        }) => {
            assert_eq!(format, "NPY");
            assert!(
                problem.contains(needle),
                "problem {problem:?} does not mention {needle:?}"
            );
        }
        other => panic!("expected an NPY format error mentioning {needle:?}, got {other:?}"),
    }
}

fn sample_cloud() -> CloudData {
    CloudData::from_points(vec![
        Point3::new(0.1, -0.2, 0.3),
        Point3::new(1.0 / 3.0, 123_456.789, -1e-7),
        Point3::new(-5.5, 1e-300, 2.0f64.sqrt()),
    ])
}

/// An NPY file with this version, header dict and data.
fn npy(major: u8, dict: &str, data: &[u8]) -> Vec<u8> {
    let mut out = b"\x93NUMPY".to_vec();
    out.extend_from_slice(&[major, 0]);
    let dict = format!("{dict}\n");
    if major == 1 {
        out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(dict.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(dict.as_bytes());
    out.extend_from_slice(data);
    out
}

#[test]
fn round_trips_exactly_with_aligned_header() {
    for cloud in [sample_cloud(), CloudData::from_points(vec![])] {
        let bytes = write_npy(&cloud).unwrap();
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        assert_eq!(bytes[10 + header_len - 1], b'\n');
        assert_eq!(bytes.len(), 10 + header_len + 24 * cloud.points.len());
        assert_eq!(read_npy(&bytes, "t.npy").unwrap(), cloud);
    }
}

#[test]
fn reads_every_variant() {
    // (2, 4) float32 big endian, C order, version 2.0.
    let vals: [f32; 8] = [1.0, 2.0, 3.0, 9.0, 4.0, 5.0, 6.0, 9.0];
    let data: Vec<u8> = vals.iter().flat_map(|v| v.to_be_bytes()).collect();
    let c = read_npy(
        &npy(
            2,
            "{'descr': '>f4', 'fortran_order': False, 'shape': (2, 4), }",
            &data,
        ),
        "a.npy",
    )
    .unwrap();
    assert_eq!(
        c.points,
        [Point3::new(1.0, 2.0, 3.0), Point3::new(4.0, 5.0, 6.0)]
    );
    assert_eq!(c.fields, ["x", "y", "z", "col3"]);
    // (2, 3) float64 little endian, Fortran order (column by column), version 3.0.
    let vals: [f64; 6] = [1.0, 4.0, 2.0, 5.0, 3.0, f64::NAN];
    let data: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
    let c = read_npy(
        &npy(
            3,
            "{\"shape\": (2,3), \"fortran_order\": True, \"descr\": \"<f8\"}",
            &data,
        ),
        "b.npy",
    )
    .unwrap();
    assert_eq!(c.points, [Point3::new(1.0, 2.0, 3.0)]);
    assert_eq!(c.skipped, 1);
    // <f4 and >f8.
    let data: Vec<u8> = [7.0f32, 8.0, 9.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let c = read_npy(
        &npy(
            1,
            "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 3)}",
            &data,
        ),
        "c.npy",
    )
    .unwrap();
    assert_eq!(c.points, [Point3::new(7.0, 8.0, 9.0)]);
    let data: Vec<u8> = [7.0f64, 8.0, 9.0]
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    let c = read_npy(
        &npy(
            1,
            "{'descr': '>f8', 'fortran_order': False, 'shape': (1L, 3L)}",
            &data,
        ),
        "d.npy",
    )
    .unwrap();
    assert_eq!(c.points, [Point3::new(7.0, 8.0, 9.0)]);
}

#[test]
fn corrupt_inputs_are_format_errors() {
    let d = |s: &str| npy(1, s, &[0u8; 48]);
    format_err(read_npy(b"", "t.npy"), "wrong magic");
    format_err(read_npy(b"PK\x03\x04 zip", "t.npy"), "wrong magic");
    format_err(
        read_npy(&npy(4, "{}", &[]), "t.npy"),
        "unsupported NPY version 4.0",
    );
    format_err(read_npy(b"\x93NUMPY\x01", "t.npy"), "truncated");
    format_err(
        read_npy(
            &d("{'descr': '<i8', 'fortran_order': False, 'shape': (2, 3)}"),
            "t.npy",
        ),
        "unsupported dtype '<i8'",
    );
    format_err(
        read_npy(&d("{'descr': [('x', '<f4'), ('y', '<f4'), ('z', '<f4')], 'fortran_order': False, 'shape': (2,)}"), "t.npy"),
        "structured dtypes are not supported",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': False, 'shape': (6,)}"),
            "t.npy",
        ),
        "is not 2-D",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2)}"),
            "t.npy",
        ),
        "fewer than 3 columns",
    );
    format_err(
        read_npy(&d("{'descr': '<f8', 'shape': (2, 3)}"), "t.npy"),
        "no 'fortran_order' key",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': 0, 'shape': (2, 3)}"),
            "t.npy",
        ),
        "'fortran_order' is not True or False",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3)"),
            "t.npy",
        ),
        "header dict",
    );
    format_err(
        read_npy(&d("{'descr': '<f8, 'fortran_order': False}"), "t.npy"),
        "header dict",
    );
    format_err(read_npy(&d("['descr']"), "t.npy"), "expected '{'");
    format_err(
        read_npy(&d("{'descr': '<f8', 'fortran_order': False, 'shape': (4000000000, 3)}"), "t.npy"),
        "truncated: shape (4000000000, 3) of 8-byte floats needs 96000000000 bytes of data, found 48",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': False, 'shape': (18446744073709551615, 3)}"),
            "t.npy",
        ),
        "truncated",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999999, 3)}"),
            "t.npy",
        ),
        "integer too large",
    );
    format_err(
        read_npy(
            &d("{'descr': '<f8', 'fortran_order': False, 'shape': (0, 4000000000)}"),
            "t.npy",
        ),
        "more than 65536 columns",
    );
    let good = write_npy(&sample_cloud()).unwrap();
    for cut in [5, 9, 20, 127, 128, 140, good.len() - 1] {
        assert!(
            matches!(read_npy(&good[..cut], "t.npy"), Err(Error::Format { .. })),
            "cut {cut}"
        );
    }
    format_err(read_npy(&good[..good.len() - 1], "t.npy"), "truncated");
}

#[test]
fn prefixes_and_bit_flips_never_panic() {
    let file = write_npy(&sample_cloud()).unwrap();
    common::for_each_corruption(&file, &[0, 1, 2, 3, 4, 5, 6, 7], |f| {
        let _ = read_npy(f, "f.npy");
    });
}
