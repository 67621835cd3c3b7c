//! Point Cloud Library PCD, v0.7 (and v0.6, whose header has no `VERSION`
//! line), with `DATA ascii`, `binary` and `binary_compressed` (LZF, the
//! uncompressed data stored field by field).
//!
//! Values are read as their declared type: an `F4` field is an `f32` in ascii
//! data too (`0.1` reads as `0.1f32`).
//!
//! Reading: `x y z` are required (types `F4`, `F8` or any integer type);
//! `normal_x normal_y normal_z` (or `nx ny nz`) become normals and `cov_xx
//! cov_xy cov_xz cov_yy cov_yz cov_zz` covariances. Fields with `COUNT > 1`
//! (descriptors) and packed `rgb` are skipped but named in
//! [`CloudData::fields`]. A cloud with `HEIGHT > 1` is organized: the pixel of
//! each kept point is in [`CloudData::grid`], and its no-return points are
//! left out and counted: NaN points (the holes of a depth image) in
//! [`CloudData::skipped`], points at exactly the `VIEWPOINT`'s origin (where a
//! lidar driver writes a beam that returned nothing, `0 0 0` in a raw frame)
//! in [`CloudData::at_origin`].
//!
//! `VIEWPOINT tx ty tz qw qx qy qz` becomes [`CloudData::sensor`], as PCL reads
//! it: the identity `0 0 0 1 0 0 0`, written or left out (the format's
//! default), is the sensor at the origin looking along +z (a raw sensor frame),
//! and [`CloudData::sensor_is_default`] says so.
//!
//! Writing: `x y z` and normals as `F4`, the type PCL's point types, Open3D
//! and RViz read (Open3D reads `F8` binary values as 0), so coordinates
//! round-trip within `f32` rounding (use PLY for exact `f64`); covariances as
//! `F8` (exact; they are cloudprox's own fields, other readers skip them);
//! `VIEWPOINT` from
//! [`CloudData::sensor`] (identity when none), `WIDTH`/`HEIGHT` from
//! [`CloudData::grid`] when it is consistent (pixels strictly increasing and
//! inside the image; the pixels it does not hold are written as NaN records),
//! else `WIDTH n HEIGHT 1`.

use std::fmt::Write as _;

use nalgebra::{Quaternion, Translation3, UnitQuaternion};

use crate::error::{Error, Result};
use crate::io::cloud_data::{cov_from_fields, cov_to_fields, COV_FIELDS};
use crate::io::lzf;
use crate::io::text::{parse_f32, parse_f64, show};
use crate::io::{ByteCursor, CloudData, CloudDataBuilder, Encoding};
use crate::math::{Point3, Pose, Vector3};

const FORMAT: &str = "PCD";

fn err(name: &str, problem: impl Into<String>) -> Error {
    Error::format(name, FORMAT, problem)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

#[derive(Debug, Clone)]
struct Field {
    name: String,
    size: usize,
    kind: u8,
    count: usize,
}

#[derive(Debug)]
struct Header {
    fields: Vec<Field>,
    width: usize,
    height: usize,
    points: usize,
    viewpoint: Option<[f64; 7]>,
    data: Data,
    start: usize,
    first_line: usize,
}

fn parse_usize(name: &str, line_no: usize, key: &str, w: &str) -> Result<usize> {
    w.parse::<usize>().map_err(|_| {
        err(
            name,
            format!(
                "header line {line_no}: {key} must be a non-negative integer, found '{}'",
                show(w.as_bytes())
            ),
        )
    })
}

#[allow(clippy::too_many_lines)]
fn parse_header(bytes: &[u8], name: &str) -> Result<Header> {
    let mut cur = ByteCursor::new(bytes, name, FORMAT);
    let mut keys = HeaderKeys::default();
    let mut line_no = 0;
    let mut seen_keyword = false;
    let data = loop {
        line_no += 1;
        let Some(raw) = cur.line() else {
            return Err(err(
                name,
                if seen_keyword {
                    "truncated header: no DATA line".to_string()
                } else {
                    "empty file (no PCD header)".to_string()
                },
            ));
        };
        let line = std::str::from_utf8(raw).map_err(|_| {
            err(
                name,
                format!(
                    "wrong magic or corrupt header: line {line_no} is not text ('{}')",
                    show(raw)
                ),
            )
        })?;
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(&key) = words.first() else { continue };
        if key.starts_with('#') {
            continue;
        }
        let at = HeaderLine {
            name,
            line_no,
            line,
            seen_keyword,
        };
        if let Some(data) = keys.read(&at, key, &words[1..])? {
            break data;
        }
        seen_keyword = true;
    };
    let fields = keys.fields(name)?;
    let (width, height, points) = dimensions(name, keys.width, keys.height, keys.points)?;
    Ok(Header {
        fields,
        width,
        height,
        points,
        viewpoint: keys.viewpoint,
        data,
        start: cur.position(),
        first_line: line_no + 1,
    })
}

/// Where in a PCD header a line is, for its errors.
struct HeaderLine<'a> {
    name: &'a str,
    line_no: usize,
    line: &'a str,
    /// Whether a keyword came before (else an unknown one is a wrong magic).
    seen_keyword: bool,
}

impl HeaderLine<'_> {
    /// The error `message` at this line.
    fn error(&self, message: impl std::fmt::Display) -> Error {
        err(
            self.name,
            format!("header line {}: {message}", self.line_no),
        )
    }

    /// A count or size read from `word` after `key`.
    fn usize(&self, key: &str, word: &str) -> Result<usize> {
        parse_usize(self.name, self.line_no, key, word)
    }
}

/// The values of a PCD header's keyword lines read so far.
#[derive(Default)]
struct HeaderKeys {
    names: Option<Vec<String>>,
    sizes: Option<Vec<usize>>,
    types: Option<Vec<u8>>,
    counts: Option<Vec<usize>>,
    width: Option<usize>,
    height: Option<usize>,
    points: Option<usize>,
    viewpoint: Option<[f64; 7]>,
}

impl HeaderKeys {
    /// Reads one keyword line (`key` and its `args`): the data encoding at
    /// the `DATA` line that ends the header, `None` before it.
    fn read(&mut self, at: &HeaderLine<'_>, key: &str, args: &[&str]) -> Result<Option<Data>> {
        let expect_n = |n: usize| -> Result<()> {
            if args.len() == n {
                Ok(())
            } else {
                Err(at.error(format!(
                    "{key} needs {n} value(s), found {}: '{}'",
                    args.len(),
                    at.line
                )))
            }
        };
        let usizes =
            |key: &str| -> Result<Vec<usize>> { args.iter().map(|w| at.usize(key, w)).collect() };
        match key {
            "VERSION" => {}
            "FIELDS" | "COLUMNS" => {
                if args.is_empty() {
                    return Err(at.error("FIELDS is empty"));
                }
                self.names = Some(args.iter().map(|s| (*s).to_string()).collect());
            }
            "SIZE" => self.sizes = Some(usizes("SIZE")?),
            "TYPE" => self.types = Some(field_types(at, args)?),
            "COUNT" => self.counts = Some(usizes("COUNT")?),
            "WIDTH" | "HEIGHT" | "POINTS" => {
                expect_n(1)?;
                let v = Some(at.usize(key, args[0])?);
                match key {
                    "WIDTH" => self.width = v,
                    "HEIGHT" => self.height = v,
                    _ => self.points = v,
                }
            }
            "VIEWPOINT" => {
                expect_n(7)?;
                self.viewpoint = Some(viewpoint(at, args)?);
            }
            "DATA" => {
                expect_n(1)?;
                return data_encoding(at, args[0]).map(Some);
            }
            other => return Err(unknown_keyword(at, other)),
        }
        Ok(None)
    }

    /// The fields the header's FIELDS, SIZE, TYPE and COUNT lines describe,
    /// checked against each other.
    fn fields(&self, name: &str) -> Result<Vec<Field>> {
        let names = self
            .names
            .as_ref()
            .ok_or_else(|| err(name, "header has no FIELDS line"))?;
        let n = names.len();
        let sizes = self
            .sizes
            .as_ref()
            .ok_or_else(|| err(name, "header has no SIZE line"))?;
        let types = self
            .types
            .as_ref()
            .ok_or_else(|| err(name, "header has no TYPE line"))?;
        let counts = self.counts.clone().unwrap_or_else(|| vec![1; n]);
        for (key, len) in [
            ("SIZE", sizes.len()),
            ("TYPE", types.len()),
            ("COUNT", counts.len()),
        ] {
            if len != n {
                return Err(err(
                    name,
                    format!("{key} has {len} values but FIELDS names {n} fields"),
                ));
            }
        }
        (0..n)
            .map(|i| field(name, &names[i], sizes[i], types[i], counts[i]))
            .collect()
    }
}

/// One field of a PCD header, its size checked against its type.
fn field(file: &str, name: &str, size: usize, kind: u8, count: usize) -> Result<Field> {
    let ok = match kind {
        b'F' => matches!(size, 4 | 8),
        _ => matches!(size, 1 | 2 | 4 | 8),
    };
    if !ok {
        return Err(err(
            file,
            format!(
                "field '{name}' has TYPE {} with SIZE {size} (F needs 4 or 8, I and U need 1, 2, 4 or 8)",
                kind as char
            ),
        ));
    }
    if count == 0 {
        return Err(err(file, format!("field '{name}' has COUNT 0")));
    }
    Ok(Field {
        name: name.to_string(),
        size,
        kind,
        count,
    })
}

/// A TYPE line's field types (`F`, `I` or `U`, either case).
fn field_types(at: &HeaderLine<'_>, args: &[&str]) -> Result<Vec<u8>> {
    args.iter()
        .map(|w| match *w {
            "F" | "I" | "U" | "f" | "i" | "u" => Ok(w.as_bytes()[0].to_ascii_uppercase()),
            _ => Err(at.error(format!(
                "TYPE must be F, I or U, found '{}'",
                show(w.as_bytes())
            ))),
        })
        .collect()
}

/// A VIEWPOINT line's seven finite values.
fn viewpoint(at: &HeaderLine<'_>, args: &[&str]) -> Result<[f64; 7]> {
    let mut v = [0.0; 7];
    for (slot, w) in v.iter_mut().zip(args) {
        *slot = parse_f64(w.as_bytes())
            .filter(|x| x.is_finite())
            .ok_or_else(|| {
                at.error(format!(
                    "VIEWPOINT value '{}' is not a finite number",
                    show(w.as_bytes())
                ))
            })?;
    }
    Ok(v)
}

/// A DATA line's encoding.
fn data_encoding(at: &HeaderLine<'_>, word: &str) -> Result<Data> {
    match word {
        "ascii" => Ok(Data::Ascii),
        "binary" => Ok(Data::Binary),
        "binary_compressed" => Ok(Data::Compressed),
        other => Err(at.error(format!(
            "unknown DATA '{}' (expected ascii, binary or binary_compressed)",
            show(other.as_bytes())
        ))),
    }
}

/// The error for a line starting with `key`, which no PCD header has: a
/// wrong magic when no keyword came before.
fn unknown_keyword(at: &HeaderLine<'_>, key: &str) -> Error {
    if at.seen_keyword {
        at.error(format!("unknown keyword '{}'", show(key.as_bytes())))
    } else {
        err(
            at.name,
            format!(
                "wrong magic: line {} starts with '{}', not a PCD header keyword (VERSION, FIELDS, ...)",
                at.line_no,
                show(key.as_bytes())
            ),
        )
    }
}

/// The cloud's `(width, height, points)` from its WIDTH, HEIGHT and POINTS
/// lines: WIDTH with HEIGHT 1 by default, POINTS their product; POINTS alone
/// is an unorganized cloud.
fn dimensions(
    name: &str,
    width: Option<usize>,
    height: Option<usize>,
    points: Option<usize>,
) -> Result<(usize, usize, usize)> {
    match (width, height, points) {
        (Some(w), h, p) => {
            let h = h.unwrap_or(1);
            let wh = w
                .checked_mul(h)
                .ok_or_else(|| err(name, format!("WIDTH {w} x HEIGHT {h} overflows")))?;
            let p = p.unwrap_or(wh);
            if p != wh {
                return Err(err(
                    name,
                    format!("POINTS {p} is not WIDTH {w} x HEIGHT {h} = {wh}"),
                ));
            }
            Ok((w, h, p))
        }
        (None, None, Some(p)) => Ok((p, 1, p)),
        (None, Some(_), _) => Err(err(name, "header has HEIGHT but no WIDTH line")),
        (None, None, None) => Err(err(name, "header has neither WIDTH nor POINTS")),
    }
}

/// Reads one binary value as f64.
fn value(b: &[u8], kind: u8) -> f64 {
    let a = |n: usize| -> [u8; 8] {
        let mut x = [0u8; 8];
        x[..n].copy_from_slice(&b[..n]);
        x
    };
    match (kind, b.len()) {
        (b'F', 4) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        (b'F', _) => f64::from_le_bytes(a(8)),
        (b'I', 1) => f64::from(i8::from_le_bytes([b[0]])),
        (b'I', 2) => f64::from(i16::from_le_bytes([b[0], b[1]])),
        (b'I', 4) => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        (b'I', _) => i64::from_le_bytes(a(8)) as f64,
        (_, 1) => f64::from(b[0]),
        (_, 2) => f64::from(u16::from_le_bytes([b[0], b[1]])),
        (_, 4) => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        _ => u64::from_le_bytes(a(8)) as f64,
    }
}

/// Indices of the fields cloudprox reads: x y z, normals, covariances.
struct Layout {
    xyz: [usize; 3],
    normals: Option<[usize; 3]>,
    covs: Option<[usize; 6]>,
}

fn layout(h: &Header, name: &str) -> Result<Layout> {
    let find = |n: &str| h.fields.iter().position(|f| f.name == n);
    let names = || {
        h.fields
            .iter()
            .map(|f| f.name.as_str())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut xyz = [0; 3];
    for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = find(axis)
            .ok_or_else(|| err(name, format!("no field '{axis}' (FIELDS {})", names())))?;
        if h.fields[*slot].count != 1 {
            return Err(err(
                name,
                format!(
                    "field '{axis}' has COUNT {}, expected 1",
                    h.fields[*slot].count
                ),
            ));
        }
    }
    let group = |names: &[&str]| -> Option<Vec<usize>> {
        names
            .iter()
            .map(|n| find(n).filter(|&i| h.fields[i].count == 1))
            .collect()
    };
    let normals = group(&["normal_x", "normal_y", "normal_z"])
        .or_else(|| group(&["nx", "ny", "nz"]))
        .map(|v| [v[0], v[1], v[2]]);
    let covs = group(&COV_FIELDS).map(|v| [v[0], v[1], v[2], v[3], v[4], v[5]]);
    Ok(Layout { xyz, normals, covs })
}

/// Where each of a run of consecutive items of these lengths starts.
fn starts(lengths: impl Iterator<Item = usize>) -> Vec<usize> {
    lengths
        .scan(0, |o, len| {
            let at = *o;
            *o += len;
            Some(at)
        })
        .collect()
}

fn push_point(b: &mut CloudDataBuilder, l: &Layout, index: usize, v: &dyn Fn(usize) -> f64) {
    let p = Point3::new(v(l.xyz[0]), v(l.xyz[1]), v(l.xyz[2]));
    let n = l.normals.map(|n| Vector3::new(v(n[0]), v(n[1]), v(n[2])));
    let c = l.covs.map(|c| cov_from_fields(c.map(v)));
    b.push(index, p, n, c);
}

/// The sensor pose of a `VIEWPOINT` (the identity when there is none, as PCL
/// reads it) and whether it is that default.
fn sensor(v: Option<[f64; 7]>, name: &str) -> Result<(Pose, bool)> {
    let v = v.unwrap_or(DEFAULT_VIEWPOINT);
    if v == DEFAULT_VIEWPOINT {
        return Ok((Pose::identity(), true));
    }
    let q = UnitQuaternion::try_new(Quaternion::new(v[3], v[4], v[5], v[6]), 1e-12)
        .ok_or_else(|| err(name, "VIEWPOINT quaternion qw qx qy qz is zero"))?;
    Ok((
        Pose::from_parts(Translation3::new(v[0], v[1], v[2]), q),
        false,
    ))
}

/// The PCD format's default `VIEWPOINT tx ty tz qw qx qy qz`.
const DEFAULT_VIEWPOINT: [f64; 7] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];

/// Reads a PCD file.
///
/// # Errors
/// [`Error::Format`] naming the problem: not a PCD header, a missing or
/// inconsistent header line (POINTS not WIDTH x HEIGHT, a bad SIZE/TYPE pair),
/// no `x`/`y`/`z`, data shorter than the header says, a corrupt LZF stream or a
/// decompressed size that differs from the header's, a non-numeric value.
pub fn read_pcd(bytes: &[u8], name: &str) -> Result<CloudData> {
    let h = parse_header(bytes, name)?;
    let l = layout(&h, name)?;
    let body = &bytes[h.start..];
    let fields = h.fields.iter().map(|f| f.name.clone()).collect();
    let organized = (h.height > 1).then_some((h.width, h.height));
    let cap = h.points.min(body.len() / 3);
    let mut b = CloudDataBuilder::new(
        fields,
        organized,
        l.normals.is_some(),
        l.covs.is_some(),
        cap,
    );
    let (pose, default) = sensor(h.viewpoint, name)?;
    b.set_sensor(Some(pose));
    b.set_sensor_is_default(default);
    b.set_no_return_origin(Some(Point3::from(pose.translation.vector)));
    let step = h
        .fields
        .iter()
        .try_fold(0usize, |s, f| s.checked_add(f.size.checked_mul(f.count)?))
        .ok_or_else(|| err(name, "point size overflows"))?;
    // Byte offset of each field inside a point record.
    let offsets = starts(h.fields.iter().map(|f| f.size * f.count));
    let total = || {
        h.points.checked_mul(step).ok_or_else(|| {
            err(
                name,
                format!("POINTS {} x {step} bytes per point overflows", h.points),
            )
        })
    };
    match h.data {
        Data::Ascii => read_ascii(body, &h, &l, name, &mut b)?,
        Data::Binary => {
            let need = total()?;
            if body.len() < need {
                return Err(err(
                    name,
                    format!(
                        "truncated: {} points of {step} bytes need {need} bytes of binary data, found {}",
                        h.points,
                        body.len()
                    ),
                ));
            }
            for i in 0..h.points {
                let rec = &body[i * step..(i + 1) * step];
                push_point(&mut b, &l, i, &|f| {
                    let o = offsets[f];
                    value(&rec[o..o + h.fields[f].size], h.fields[f].kind)
                });
            }
        }
        Data::Compressed => {
            let need = total()?;
            let mut cur = ByteCursor::new(body, name, FORMAT);
            let sizes = cur.u32_le().and_then(|c| Ok((c, cur.u32_le()?)));
            let (csize, usize_) = sizes.map_err(|_| {
                err(
                    name,
                    format!("truncated: binary_compressed data needs an 8-byte size header, found {} bytes", body.len()),
                )
            })?;
            let (csize, usize_) = (csize as usize, usize_ as usize);
            if usize_ != need {
                return Err(err(
                    name,
                    format!(
                        "binary_compressed uncompressed size {usize_} differs from POINTS {} x {step} bytes = {need}",
                        h.points
                    ),
                ));
            }
            if csize > cur.remaining() {
                return Err(err(
                    name,
                    format!(
                        "truncated: compressed size is {csize} bytes, only {} left",
                        cur.remaining()
                    ),
                ));
            }
            let data = if need == 0 && csize == 0 {
                Vec::new()
            } else {
                lzf::decompress(cur.take(csize)?, need)
                    .map_err(|e| err(name, format!("binary_compressed: {e}")))?
            };
            // Field by field: field f's block starts at points * (sum of previous record sizes).
            let starts: Vec<usize> = offsets.iter().map(|o| o * h.points).collect();
            for i in 0..h.points {
                push_point(&mut b, &l, i, &|f| {
                    let s = h.fields[f].size;
                    let at = starts[f] + i * s * h.fields[f].count;
                    value(&data[at..at + s], h.fields[f].kind)
                });
            }
        }
    }
    Ok(b.finish())
}

fn read_ascii(
    body: &[u8],
    h: &Header,
    l: &Layout,
    name: &str,
    b: &mut CloudDataBuilder,
) -> Result<()> {
    if h.points == 0 {
        return Ok(());
    }
    let columns: usize = h.fields.iter().map(|f| f.count).sum();
    // Each value takes at least one byte: bounds the buffers below.
    if columns > body.len() {
        return Err(err(
            name,
            format!(
                "truncated: a line needs {columns} values (one per field and COUNT), but only {} bytes of data follow the header",
                body.len()
            ),
        ));
    }
    // Column of each field's first value.
    let first = starts(h.fields.iter().map(|f| f.count));
    // Whether each column is an F4 field: those values are f32, as in binary data.
    let single: Vec<bool> = h
        .fields
        .iter()
        .flat_map(|f| std::iter::repeat_n(f.kind == b'F' && f.size == 4, f.count))
        .collect();
    let mut cur = ByteCursor::new(body, name, FORMAT);
    let mut line_no = h.first_line - 1;
    let mut values = vec![0.0f64; columns];
    let mut i = 0;
    while i < h.points {
        line_no += 1;
        let Some(line) = cur.line() else {
            return Err(err(
                name,
                format!(
                    "truncated: POINTS is {} but the data ends after {i} points (line {line_no})",
                    h.points
                ),
            ));
        };
        let mut n = 0;
        for tok in line
            .split(u8::is_ascii_whitespace)
            .filter(|t| !t.is_empty())
        {
            if n < columns {
                let v = if single[n] {
                    parse_f32(tok).map(f64::from)
                } else {
                    parse_f64(tok)
                };
                values[n] = v.ok_or_else(|| {
                    err(
                        name,
                        format!("line {line_no}: value '{}' is not a number", show(tok)),
                    )
                })?;
            }
            n += 1;
        }
        if n == 0 {
            continue;
        }
        if n != columns {
            return Err(err(
                name,
                format!("line {line_no}: {n} values, expected {columns} (one per field and COUNT)"),
            ));
        }
        push_point(b, l, i, &|f| values[first[f]]);
        i += 1;
    }
    Ok(())
}

/// Appends `v` as a little-endian float of `size` bytes (4 or 8).
fn put(out: &mut Vec<u8>, v: f64, size: usize) {
    if size == 4 {
        out.extend_from_slice(&(v as f32).to_le_bytes());
    } else {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

/// Encodes a point cloud as PCD v0.7 (`Ascii` → `DATA ascii`,
/// `BinaryLittleEndian` → `DATA binary`, `BinaryCompressed` →
/// `DATA binary_compressed`): `x y z` and normals as `F4`, covariances as
/// `F8` (see the module documentation). A cloud with a consistent [`crate::io::Grid`]
/// is written organized (`WIDTH x HEIGHT` records, NaN for the pixels it does
/// not hold), else unorganized.
///
/// # Errors
/// [`Error::InvalidInput`] for [`Encoding::BinaryBigEndian`] or when the
/// normals/covariances do not have one entry per point.
pub fn write_pcd(cloud: &CloudData, encoding: Encoding) -> Result<Vec<u8>> {
    let data =
        match encoding {
            Encoding::Ascii => "ascii",
            Encoding::BinaryLittleEndian => "binary",
            Encoding::BinaryCompressed => "binary_compressed",
            Encoding::BinaryBigEndian => return Err(Error::invalid(
                "PCD has no big-endian encoding; use Ascii, BinaryLittleEndian or BinaryCompressed",
            )),
        };
    let n = cloud.points.len();
    cloud.check_lengths()?;
    let mut names = vec!["x", "y", "z"];
    if cloud.normals.is_some() {
        names.extend_from_slice(&["normal_x", "normal_y", "normal_z"]);
    }
    if cloud.covariances.is_some() {
        names.extend_from_slice(&COV_FIELDS);
    }
    let k = names.len();
    // Bytes per field: F4 for coordinates and normals, F8 for covariances.
    let sizes: Vec<usize> = names
        .iter()
        .map(|n| if n.starts_with("cov_") { 8 } else { 4 })
        .collect();
    let step: usize = sizes.iter().sum();
    // Organized when the grid is consistent (pixels strictly increasing, inside
    // the image): every pixel becomes a record, missing ones NaN (as PCL writes
    // the holes of a depth image).
    let organized = cloud.grid.as_ref().filter(|g| {
        g.pixels.len() == n
            && g.width.checked_mul(g.height).is_some()
            && g.pixels.windows(2).all(|w| w[0] < w[1])
            && g.pixels
                .last()
                .is_none_or(|&p| (p as usize) < g.width * g.height)
    });
    let (width, height, slots): (usize, usize, Vec<Option<usize>>) = match organized {
        Some(g) => {
            let mut slots = vec![None; g.width * g.height];
            for (i, &p) in g.pixels.iter().enumerate() {
                slots[p as usize] = Some(i);
            }
            (g.width, g.height, slots)
        }
        None => (n, 1, (0..n).map(Some).collect()),
    };
    let records = slots.len();
    let pose = cloud.sensor.unwrap_or_else(Pose::identity);
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    let mut head = String::from(
        "# .PCD v0.7 - Point Cloud Data file format (written by cloudprox)\nVERSION 0.7\n",
    );
    let _ = writeln!(head, "FIELDS {}", names.join(" "));
    head.push_str("SIZE");
    for s in &sizes {
        let _ = write!(head, " {s}");
    }
    head.push('\n');
    let _ = writeln!(head, "TYPE{}", " F".repeat(k));
    let _ = writeln!(head, "COUNT{}", " 1".repeat(k));
    let _ = writeln!(head, "WIDTH {width}\nHEIGHT {height}");
    let _ = writeln!(
        head,
        "VIEWPOINT {} {} {} {} {} {} {}",
        t.x, t.y, t.z, q.w, q.i, q.j, q.k
    );
    let _ = writeln!(head, "POINTS {records}\nDATA {data}");
    let row = |slot: usize| -> Vec<f64> {
        let Some(i) = slots[slot] else {
            return vec![f64::NAN; k];
        };
        let mut r: Vec<f64> = cloud.points[i].coords.iter().copied().collect();
        if let Some(normals) = &cloud.normals {
            r.extend(normals[i].iter());
        }
        if let Some(covs) = &cloud.covariances {
            r.extend(cov_to_fields(&covs[i]));
        }
        r
    };
    let mut out = head.into_bytes();
    match encoding {
        Encoding::Ascii => {
            // Shortest forms that read back as the same f32 / f64.
            let mut text = String::new();
            for i in 0..records {
                for (f, (v, &size)) in row(i).into_iter().zip(&sizes).enumerate() {
                    let sep = if f == 0 { "" } else { " " };
                    let _ = if size == 4 {
                        write!(text, "{sep}{:?}", v as f32)
                    } else {
                        write!(text, "{sep}{v:?}")
                    };
                }
                text.push('\n');
            }
            out.extend_from_slice(text.as_bytes());
        }
        Encoding::BinaryLittleEndian => {
            out.reserve(records * step);
            for i in 0..records {
                for (v, &size) in row(i).into_iter().zip(&sizes) {
                    put(&mut out, v, size);
                }
            }
        }
        _ => {
            // Field by field: all values of field 0, then of field 1, ...
            let mut raw = Vec::with_capacity(records * step);
            let rows: Vec<Vec<f64>> = (0..records).map(row).collect();
            for (f, &size) in sizes.iter().enumerate() {
                for r in &rows {
                    put(&mut raw, r[f], size);
                }
            }
            let packed = lzf::compress(&raw);
            let sizes = |x: usize| {
                u32::try_from(x).map_err(|_| {
                    Error::invalid(format!(
                        "cloud too large for PCD binary_compressed ({x} bytes; the format stores sizes in 32 bits)"
                    ))
                })
            };
            out.extend_from_slice(&sizes(packed.len())?.to_le_bytes());
            out.extend_from_slice(&sizes(raw.len())?.to_le_bytes());
            out.extend_from_slice(&packed);
        }
    }
    Ok(out)
}
