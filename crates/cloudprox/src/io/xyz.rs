//! Text point clouds, one point per line: XYZ (whitespace-separated) and CSV
//! (comma- or semicolon-separated), read by one reader.
//!
//! Reading: the delimiter is taken from the first data line (a comma if it
//! has one, else a semicolon if it has one, else whitespace). Blank lines and
//! lines starting with `#` or `//` are skipped. If the first data line is not
//! all numbers it is a header of column names, which must name `x`, `y` and `z`
//! (case-insensitive); `nx ny nz` (or `normal_x ...`) become normals and `cov_xx
//! cov_xy cov_xz cov_yy cov_yz cov_zz` covariances. Without a header, columns
//! 0, 1, 2 are `x y z` and the rest are named `col3`, `col4`, ... Every row
//! must have the same number of columns and every value must be a number.
//! Errors name the format `CSV` when the file name ends in `.csv`, else `XYZ`.
//!
//! Writing ([`write_xyz`]): with `,` or `;` a header line `x,y,z` (plus
//! `,nx,ny,nz` and `,cov_xx,...` when present); with ` ` or `\t` no header and
//! only `x y z` (unnamed extra columns would not be read back as normals).
//! Values are written in their shortest form that reads back as the same
//! `f64`, so files round-trip exactly.

use crate::error::{Error, Result};
use crate::io::cloud_data::{cov_from_fields, cov_to_fields, COV_FIELDS};
use crate::io::text::{parse_f64, push_row, show};
use crate::io::{CloudData, CloudDataBuilder};
use crate::math::{Point3, Vector3};

/// The format named in errors: `CSV` for a `.csv` file, else `XYZ`.
fn err(name: &str, problem: impl Into<String>) -> Error {
    let csv = std::path::Path::new(name)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    Error::format(name, if csv { "CSV" } else { "XYZ" }, problem)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Delim {
    Space,
    Char(u8),
}

fn split(line: &[u8], d: Delim) -> Vec<&[u8]> {
    match d {
        Delim::Space => line
            .split(u8::is_ascii_whitespace)
            .filter(|t| !t.is_empty())
            .collect(),
        Delim::Char(c) => line
            .split(move |&b| b == c)
            .map(<[u8]>::trim_ascii)
            .collect(),
    }
}

fn is_skipped(line: &[u8]) -> bool {
    let t = line.trim_ascii();
    t.is_empty() || t.starts_with(b"#") || t.starts_with(b"//")
}

fn unquote(t: &[u8]) -> String {
    let s = String::from_utf8_lossy(t);
    s.trim_matches(|c| c == '"' || c == '\'').trim().to_string()
}

/// Reads an XYZ/CSV file.
///
/// # Errors
/// [`Error::Format`] naming the line: a header without `x`/`y`/`z`, fewer than
/// 3 columns, a row with a different number of columns than the first, a
/// value that is not a number.
pub fn read_xyz(bytes: &[u8], name: &str) -> Result<CloudData> {
    let lines: Vec<(usize, &[u8])> = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix(b"\r").unwrap_or(l)))
        .filter(|(_, l)| !is_skipped(l))
        .collect();
    let Some(&(first_no, first)) = lines.first() else {
        return Ok(CloudData::from_points(Vec::new()));
    };
    let delim = if first.contains(&b',') {
        Delim::Char(b',')
    } else if first.contains(&b';') {
        Delim::Char(b';')
    } else {
        Delim::Space
    };
    let first_tokens = split(first, delim);
    let numeric = first_tokens.iter().all(|t| parse_f64(t).is_some());
    let columns = first_tokens.len();
    let (fields, rows) = if numeric {
        if columns < 3 {
            return Err(err(
                name,
                format!("line {first_no}: {columns} column(s), expected at least 3 (x y z)"),
            ));
        }
        let mut f: Vec<String> = vec!["x".into(), "y".into(), "z".into()];
        f.extend((3..columns).map(|i| format!("col{i}")));
        (f, &lines[..])
    } else {
        (
            first_tokens.iter().map(|t| unquote(t)).collect(),
            &lines[1..],
        )
    };
    let lower: Vec<String> = fields.iter().map(|f| f.to_ascii_lowercase()).collect();
    let find = |n: &str| lower.iter().position(|f| f == n);
    let mut xyz = [0usize; 3];
    for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = find(axis).ok_or_else(|| {
            err(
                name,
                format!(
                    "line {first_no}: the header must name columns x, y and z; it has no '{axis}' (found: {})",
                    show(first)
                ),
            )
        })?;
    }
    let group = |names: &[&str]| -> Option<Vec<usize>> { names.iter().map(|n| find(n)).collect() };
    let normals =
        group(&["nx", "ny", "nz"]).or_else(|| group(&["normal_x", "normal_y", "normal_z"]));
    let covs = group(&COV_FIELDS);
    let mut b = CloudDataBuilder::new(fields, None, normals.is_some(), covs.is_some(), rows.len());
    let mut values = vec![0.0f64; columns];
    for (i, &(no, line)) in rows.iter().enumerate() {
        let tokens = split(line, delim);
        if tokens.len() != columns {
            return Err(err(
                name,
                format!(
                    "line {no}: {} column(s), expected {columns} (as on line {first_no})",
                    tokens.len()
                ),
            ));
        }
        for (c, t) in tokens.iter().enumerate() {
            values[c] = parse_f64(t).ok_or_else(|| {
                err(
                    name,
                    format!("line {no}, column {}: '{}' is not a number", c + 1, show(t)),
                )
            })?;
        }
        let v = |k: usize| values[k];
        let p = Point3::new(v(xyz[0]), v(xyz[1]), v(xyz[2]));
        let n = normals
            .as_ref()
            .map(|n| Vector3::new(v(n[0]), v(n[1]), v(n[2])));
        let c = covs
            .as_ref()
            .map(|c| cov_from_fields([0, 1, 2, 3, 4, 5].map(|k| v(c[k]))));
        b.push(i, p, n, c);
    }
    Ok(b.finish())
}

/// Encodes a point cloud as text with this delimiter: `,` or `;` (CSV, with a
/// header line naming the columns, normals and covariances included when
/// present), ` ` or `\t` (XYZ, no header, `x y z` only).
///
/// # Errors
/// [`Error::InvalidInput`] for any other delimiter, or when normals or
/// covariances do not have one entry per point.
pub fn write_xyz(cloud: &CloudData, delimiter: u8) -> Result<Vec<u8>> {
    let header = match delimiter {
        b',' | b';' => true,
        b' ' | b'\t' => false,
        other => {
            return Err(Error::invalid(format!(
                "XYZ/CSV delimiter must be ',', ';', ' ' or '\\t', got {:?}",
                other as char
            )))
        }
    };
    let n = cloud.points.len();
    cloud.check_lengths()?;
    let sep = delimiter as char;
    let normals = cloud.normals.as_ref().filter(|_| header);
    let covs = cloud.covariances.as_ref().filter(|_| header);
    let mut out = String::new();
    if header {
        let mut names = vec!["x", "y", "z"];
        if normals.is_some() {
            names.extend_from_slice(&["nx", "ny", "nz"]);
        }
        if covs.is_some() {
            names.extend_from_slice(&COV_FIELDS);
        }
        out.push_str(&names.join(&sep.to_string()));
        out.push('\n');
    }
    let mut row = Vec::with_capacity(12);
    for i in 0..n {
        row.clear();
        row.extend(cloud.points[i].coords.iter());
        if let Some(normals) = normals {
            row.extend(normals[i].iter());
        }
        if let Some(covs) = covs {
            row.extend(cov_to_fields(&covs[i]));
        }
        push_row(&mut out, &row, sep);
    }
    Ok(out.into_bytes())
}
