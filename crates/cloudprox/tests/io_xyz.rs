//! XYZ / CSV reading and writing.

use crate::common;

use cloudprox::io::xyz::{read_xyz, write_xyz};
use cloudprox::io::CloudData;
use cloudprox::prelude::*;

fn format_err<T: std::fmt::Debug>(r: Result<T>, needle: &str) {
    match r {
        Err(Error::Format {
            problem,
            format,
            path,
        }) => {
            let csv = std::path::Path::new(&path)
                .extension()
                .is_some_and(|e| e == "csv");
            let expected = if csv { "CSV" } else { "XYZ" };
            assert_eq!(format, expected);
            assert!(
                problem.contains(needle),
                "problem {problem:?} does not mention {needle:?}"
            );
        }
        other => panic!("expected an XYZ format error mentioning {needle:?}, got {other:?}"),
    }
}

fn sample_cloud() -> CloudData {
    let points = vec![
        Point3::new(0.1, -0.2, 0.3),
        Point3::new(1.0 / 3.0, 123_456.789, -1e-7),
        Point3::new(-5.5, 1e-300, 2.0f64.sqrt()),
    ];
    let mut c = CloudData::from_points(points);
    c.normals = Some(vec![
        Vector3::z(),
        Vector3::x(),
        Vector3::new(0.6, 0.8, 0.0),
    ]);
    c.fields.extend(["nx", "ny", "nz"].map(String::from));
    c
}

#[test]
fn round_trips_exactly() {
    let cloud = sample_cloud();
    for delim in [b',', b';'] {
        let bytes = write_xyz(&cloud, delim).unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        let sep = delim as char;
        assert!(text.starts_with(&format!("x{sep}y{sep}z{sep}nx{sep}ny{sep}nz\n")));
        assert_eq!(read_xyz(&bytes, "t.csv").unwrap(), cloud);
    }
    let plain = CloudData::from_points(cloud.points.clone());
    for delim in [b' ', b'\t'] {
        let bytes = write_xyz(&cloud, delim).unwrap();
        assert!(!bytes.starts_with(b"x"));
        assert_eq!(read_xyz(&bytes, "t.xyz").unwrap(), plain);
    }
    let csv = write_xyz(&plain, b',').unwrap();
    assert!(csv.starts_with(b"x,y,z\n"));
    assert_eq!(read_xyz(&csv, "t.csv").unwrap(), plain);
    // Covariances travel in CSV.
    let mut with_cov = plain.clone();
    with_cov.covariances = Some(vec![
        Matrix3::new(
            1.0, 0.5, 0.25, 0.5, 2.0, 0.125, 0.25, 0.125, 3.0
        );
        3
    ]);
    with_cov
        .fields
        .extend(["cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"].map(String::from));
    assert_eq!(
        read_xyz(&write_xyz(&with_cov, b',').unwrap(), "c.csv").unwrap(),
        with_cov
    );
    assert!(matches!(
        write_xyz(&plain, b'x'),
        Err(Error::InvalidInput(_))
    ));
}

#[test]
fn reads_hand_written_variants() {
    let xyz = "# scanner output\n// another comment\n\n1 2 3 255 0\n  4.5\t-6 7e-1   0 1 \r\nnan 1 1 0 0\n";
    let c = read_xyz(xyz.as_bytes(), "s.xyz").unwrap();
    assert_eq!(
        c.points,
        [Point3::new(1.0, 2.0, 3.0), Point3::new(4.5, -6.0, 0.7)]
    );
    assert_eq!(c.skipped, 1);
    assert_eq!(c.fields, ["x", "y", "z", "col3", "col4"]);
    let csv = "\"id\",\"X\",\"Y\",\"Z\",\"NX\",\"NY\",\"NZ\"\n0, 1, 2, 3, 0, 0, 1\n1,4,5,6,1,0,0\n";
    let c = read_xyz(csv.as_bytes(), "s.csv").unwrap();
    assert_eq!(
        c.points,
        [Point3::new(1.0, 2.0, 3.0), Point3::new(4.0, 5.0, 6.0)]
    );
    assert_eq!(c.normals.unwrap()[1], Vector3::x());
    assert_eq!(c.fields, ["id", "X", "Y", "Z", "NX", "NY", "NZ"]);
    let semi = "z;y;x\n1;2;3\n";
    assert_eq!(
        read_xyz(semi.as_bytes(), "s.csv").unwrap().points,
        [Point3::new(3.0, 2.0, 1.0)]
    );
    assert!(read_xyz(b"", "e.xyz").unwrap().points.is_empty());
    assert!(read_xyz(b"x,y,z\n", "e.csv").unwrap().points.is_empty());
}

#[test]
fn corrupt_inputs_are_format_errors() {
    format_err(
        read_xyz(b"1 2 3\n4 5\n", "t.xyz"),
        "line 2: 2 column(s), expected 3 (as on line 1)",
    );
    format_err(
        read_xyz(b"1 2 3\n4 5 6 7\n", "t.xyz"),
        "line 2: 4 column(s), expected 3",
    );
    format_err(
        read_xyz(b"1 2\n3 4\n", "t.xyz"),
        "line 1: 2 column(s), expected at least 3",
    );
    format_err(
        read_xyz(b"a,b,c\n1,2,3\n", "t.csv"),
        "the header must name columns x, y and z; it has no 'x'",
    );
    format_err(
        read_xyz(b"x,y,z\n1,2,3\n4,abc,6\n", "t.csv"),
        "line 3, column 2: 'abc' is not a number",
    );
    format_err(
        read_xyz(b"x,y,z\n1,,3\n", "t.csv"),
        "line 2, column 2: '' is not a number",
    );
    format_err(
        read_xyz(b"\x93NUMPY\x01\x00", "t.xyz"),
        "the header must name",
    );
    // Truncated mid-row.
    let good = write_xyz(&sample_cloud(), b',').unwrap();
    format_err(
        read_xyz(&good[..good.len() - 8], "t.csv"),
        "column(s), expected 6",
    );
}

#[test]
fn prefixes_and_bit_flips_never_panic() {
    let files = [
        write_xyz(&sample_cloud(), b',').unwrap(),
        write_xyz(&sample_cloud(), b' ').unwrap(),
    ];
    for file in &files {
        common::for_each_corruption(file, &[0, 1, 2, 3, 4, 5, 6, 7], |f| {
            let _ = read_xyz(f, "f.xyz");
        });
    }
}

/// `n` rows of `x y z` followed by the given columns of each row.
fn rows(extra: &dyn Fn(usize) -> Vec<String>, n: usize) -> String {
    (0..n)
        .map(|i| {
            let mut r = vec![format!("{}", i as f64 * 0.1), "0.5".into(), "-1".into()];
            r.extend(extra(i));
            r.join(" ") + "\n"
        })
        .collect()
}

/// A unit normal per row, as a tool prints it (six decimals).
fn normal(i: usize) -> [f64; 3] {
    let a = i as f64 * 0.7;
    [a.cos() * 0.6, a.sin() * 0.6, 0.8]
}

fn normal_text(i: usize) -> Vec<String> {
    normal(i).iter().map(|v| format!("{v:.6}")).collect()
}

#[test]
fn six_and_nine_columns_are_normals_and_colours_as_the_tools_write_them() {
    // CGAL write_XYZ (kitten.xyz), Open3D .xyzn, MeshLab: x y z nx ny nz.
    let c = read_xyz(rows(&normal_text, 5).as_bytes(), "kitten.xyz").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "nx", "ny", "nz"]);
    let n = c.normals.unwrap();
    for (i, v) in n.iter().enumerate() {
        assert!((v - Vector3::from(normal(i))).norm() < 1e-6);
    }
    // Open3D .xyzrgb (0..1) and CloudCompare (0..255): x y z r g b.
    let rgb01 = |i: usize| vec![format!("{}", i as f64 / 10.0), "0.25".into(), "1".into()];
    let rgb255 = |i: usize| vec![format!("{}", i * 40), "7".into(), "255".into()];
    for extra in [&rgb01 as &dyn Fn(usize) -> Vec<String>, &rgb255] {
        let c = read_xyz(rows(extra, 5).as_bytes(), "c.xyz").unwrap();
        assert_eq!(c.fields, ["x", "y", "z", "r", "g", "b"]);
        assert!(c.normals.is_none());
    }
    // CloudCompare's default order: x y z r g b nx ny nz; and x y z nx ny nz r g b.
    let cc = |i: usize| [rgb255(i), normal_text(i)].concat();
    let c = read_xyz(rows(&cc, 5).as_bytes(), "cc.xyz").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "r", "g", "b", "nx", "ny", "nz"]);
    assert!((c.normals.unwrap()[3] - Vector3::from(normal(3))).norm() < 1e-6);
    let nc = |i: usize| [normal_text(i), rgb01(i)].concat();
    let c = read_xyz(rows(&nc, 5).as_bytes(), "nc.txt").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "nx", "ny", "nz", "r", "g", "b"]);
    assert!(c.normals.is_some());
    // Neither: the names stay col3 ... (and so do other column counts).
    let other = |i: usize| {
        vec![
            format!("{}", i as f64 * 3.5 - 2.0),
            "-9".into(),
            "12.5".into(),
        ]
    };
    let c = read_xyz(rows(&other, 5).as_bytes(), "o.xyz").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "col3", "col4", "col5"]);
    assert!(c.normals.is_none());
    // Open3D's extensions say which: .xyzn normals, .xyzrgb colours.
    let c = read_xyz(rows(&other, 2).as_bytes(), "o.xyzn").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "nx", "ny", "nz"]);
    let c = read_xyz(rows(&normal_text, 2).as_bytes(), "o.xyzrgb").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "r", "g", "b"]);
    assert!(c.normals.is_none());
}

#[test]
fn cloudcompare_column_header_comment_names_the_columns() {
    let text = "//X,Y,Z,R,G,B,Nx,Ny,Nz\n1,2,3,10,20,30,0,0,1\n4,5,6,40,50,60,1,0,0\n";
    let c = read_xyz(text.as_bytes(), "cc.txt").unwrap();
    assert_eq!(c.fields, ["X", "Y", "Z", "R", "G", "B", "Nx", "Ny", "Nz"]);
    assert_eq!(c.normals.unwrap()[1], Vector3::x());
    assert_eq!(c.points[1], Point3::new(4.0, 5.0, 6.0));
    // A comment that does not name x y z for every column is just a comment.
    let c = read_xyz(b"// two words\n1 2 3 0 0 1\n", "c.xyz").unwrap();
    assert_eq!(c.fields, ["x", "y", "z", "nx", "ny", "nz"]);
}
