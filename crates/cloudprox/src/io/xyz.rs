//! Text point clouds, one point per line: XYZ (whitespace-separated) and CSV
//! (comma- or semicolon-separated), read by one reader.
//!
//! Reading: the delimiter is taken from the first data line (a comma if it
//! has one, else a semicolon if it has one, else whitespace). Blank lines and
//! lines starting with `#` or `//` are skipped. If the first data line is not
//! all numbers it is a header of column names, which must name `x`, `y` and `z`
//! (case-insensitive); so is a comment `//X Y Z ...` right before the first
//! data line with one name per column (CloudCompare's column header).
//! `nx ny nz` (or `normal_x ...`) become normals and `cov_xx cov_xy cov_xz
//! cov_yy cov_yz cov_zz` covariances.
//!
//! Without a header, columns 0, 1, 2 are `x y z`, and six or nine numeric
//! columns are read the way the common tools write them:
//!
//! | columns | written by | read as |
//! |---|---|---|
//! | `x y z nx ny nz` | CGAL `write_XYZ` (its `kitten.xyz`), Open3D `.xyzn`, MeshLab | normals |
//! | `x y z r g b` | Open3D `.xyzrgb` (0..1), CloudCompare (0..255) | colours `r g b` |
//! | `x y z r g b nx ny nz` | CloudCompare (its default order: point, colour, normal) | colours, normals |
//! | `x y z nx ny nz r g b` | | normals, colours |
//!
//! A triple is taken for normals when every row's has length 1 (within 1 %)
//! or 0, for colours when all its values are in `[0, 1]` or integers in
//! `[0, 255]`; a triple that is neither keeps the names `col3`, `col4`, ...
//! (as every other column count does). The extensions `.xyzn` and `.xyzrgb`
//! (Open3D's) say which the fourth to sixth columns are. Colours are named
//! in [`CloudData::fields`] and otherwise not read. Every row must have the
//! same number of columns and every value must be a number. Errors name the
//! format `CSV` when the file name ends in `.csv`, else `XYZ`.
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

/// What the fourth to ninth columns of a header-less file hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Triple {
    Normals,
    Colours,
    Unknown,
}

/// Whether every row's triple at `start` is a unit vector (1 %) or zero,
/// over the rows whose point is finite.
fn unit_rows(values: &[f64], columns: usize, start: usize) -> bool {
    values.chunks_exact(columns).all(|row| {
        if !row[..3].iter().all(|v| v.is_finite()) {
            return true;
        }
        let n = (row[start].powi(2) + row[start + 1].powi(2) + row[start + 2].powi(2)).sqrt();
        n == 0.0 || (n - 1.0).abs() <= 1e-2
    })
}

/// Whether every row's triple at `start` is a colour: all in `[0, 1]`, or
/// all integers in `[0, 255]`.
fn colour_rows(values: &[f64], columns: usize, start: usize) -> bool {
    let triples = || values.chunks_exact(columns).map(|r| &r[start..start + 3]);
    triples().all(|t| t.iter().all(|v| (0.0..=1.0).contains(v)))
        || triples().all(|t| {
            t.iter()
                .all(|v| (0.0..=255.0).contains(v) && v.fract() == 0.0)
        })
}

/// The names of a header-less file's columns (see the module docs).
fn column_names(values: &[f64], columns: usize, extension: &str) -> Vec<String> {
    let mut names: Vec<String> = ["x", "y", "z"].map(String::from).to_vec();
    names.extend((3..columns).map(|i| format!("col{i}")));
    let classify = |start: usize| {
        if unit_rows(values, columns, start) {
            Triple::Normals
        } else if colour_rows(values, columns, start) {
            Triple::Colours
        } else {
            Triple::Unknown
        }
    };
    let colour = |start: usize| {
        if colour_rows(values, columns, start) {
            Triple::Colours
        } else {
            Triple::Unknown
        }
    };
    let triples: Vec<Triple> = match (columns, extension) {
        (c, "xyzn") if c >= 6 => vec![Triple::Normals],
        (c, "xyzrgb") if c >= 6 => vec![Triple::Colours],
        (6, _) => vec![classify(3)],
        (9, _) => match (unit_rows(values, 9, 3), unit_rows(values, 9, 6)) {
            (true, _) => vec![Triple::Normals, colour(6)],
            (false, true) => vec![colour(3), Triple::Normals],
            (false, false) => vec![colour(3), colour(6)],
        },
        _ => Vec::new(),
    };
    for (k, t) in triples.iter().enumerate() {
        let set: [&str; 3] = match t {
            Triple::Normals => ["nx", "ny", "nz"],
            Triple::Colours => ["r", "g", "b"],
            Triple::Unknown => continue,
        };
        for (j, n) in set.iter().enumerate() {
            names[3 + 3 * k + j] = (*n).to_string();
        }
    }
    names
}

/// A CloudCompare column header: the comment `//X Y Z ...` with one name per
/// column, naming `x`, `y` and `z`, no name a number.
fn comment_header(line: &[u8], delim: Delim, columns: usize) -> Option<Vec<String>> {
    let body = line.trim_ascii().strip_prefix(b"//")?;
    let tokens = split(body, delim);
    let names: Vec<String> = tokens.iter().map(|t| unquote(t)).collect();
    let lower: Vec<String> = names.iter().map(|n| n.to_ascii_lowercase()).collect();
    let ok = names.len() == columns
        && tokens.iter().all(|t| parse_f64(t).is_none())
        && ["x", "y", "z"].iter().all(|a| lower.iter().any(|n| n == a));
    ok.then_some(names)
}

/// Reads an XYZ/CSV file.
///
/// # Errors
/// [`Error::Format`] naming the line: a header without `x`/`y`/`z`, fewer than
/// 3 columns, a row with a different number of columns than the first, a
/// value that is not a number.
pub fn read_xyz(bytes: &[u8], name: &str) -> Result<CloudData> {
    let all: Vec<(usize, &[u8])> = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix(b"\r").unwrap_or(l)))
        .collect();
    let Some(first_at) = all.iter().position(|(_, l)| !is_skipped(l)) else {
        return Ok(CloudData::from_points(Vec::new()));
    };
    let lines: Vec<(usize, &[u8])> = all[first_at..]
        .iter()
        .copied()
        .filter(|(_, l)| !is_skipped(l))
        .collect();
    let (first_no, first) = lines[0];
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
    let comment_names = all[..first_at]
        .iter()
        .rev()
        .find(|(_, l)| l.trim_ascii().starts_with(b"//"))
        .filter(|_| numeric)
        .and_then(|(_, l)| comment_header(l, delim, columns));
    let (header, rows) = if numeric {
        if columns < 3 {
            return Err(err(
                name,
                format!("line {first_no}: {columns} column(s), expected at least 3 (x y z)"),
            ));
        }
        (comment_names, &lines[..])
    } else {
        (
            Some(first_tokens.iter().map(|t| unquote(t)).collect()),
            &lines[1..],
        )
    };
    let mut values = Vec::with_capacity(rows.len().saturating_mul(columns));
    for &(no, line) in rows {
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
            values.push(parse_f64(t).ok_or_else(|| {
                err(
                    name,
                    format!("line {no}, column {}: '{}' is not a number", c + 1, show(t)),
                )
            })?);
        }
    }
    let fields = header.unwrap_or_else(|| {
        let ext = std::path::Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        column_names(&values, columns, &ext)
    });
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
    if columns > 0 {
        for (i, v) in values.chunks_exact(columns).enumerate() {
            let p = Point3::new(v[xyz[0]], v[xyz[1]], v[xyz[2]]);
            let n = normals
                .as_ref()
                .map(|n| Vector3::new(v[n[0]], v[n[1]], v[n[2]]));
            let c = covs
                .as_ref()
                .map(|c| cov_from_fields([0, 1, 2, 3, 4, 5].map(|k| v[c[k]])));
            b.push(i, p, n, c);
        }
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
