//! Stanford PLY: points (the `vertex` element) and meshes (plus the `face`
//! element), in `ascii`, `binary_little_endian` and `binary_big_endian`.
//!
//! Reading: every scalar type (`char uchar short ushort int uint float double`
//! and `int8 ... float64`) and list properties anywhere, including in the
//! `vertex` element; elements other than `vertex` and `face` are skipped.
//! `x y z` are required; `nx ny nz` become normals and `cov_xx cov_xy cov_xz
//! cov_yy cov_yz cov_zz` covariances (cloudprox writes these, so clouds
//! round-trip with their uncertainty). [`CloudData::fields`] lists every vertex
//! property. A mesh's polygons (`vertex_indices` or `vertex_index`) are
//! fan-triangulated; triangles repeating a vertex are dropped and counted.
//!
//! Writing: `x y z` as `double`, plus normals and covariances when present.

use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::io::cloud_data::{cov_from_fields, cov_to_fields};
use crate::io::text::{parse_f64, parse_i64, push_row, show, Tokens};
use crate::io::{ByteCursor, CloudData, CloudDataBuilder, Encoding, MeshData};
use crate::math::{Point3, Vector3};
use crate::shape::Mesh;

const FORMAT: &str = "PLY";

/// Vertex properties cloudprox reads, in slot order.
const SLOTS: [&str; 12] = [
    "x", "y", "z", "nx", "ny", "nz", "cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz",
];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::I8 => "char",
            Self::U8 => "uchar",
            Self::I16 => "short",
            Self::U16 => "ushort",
            Self::I32 => "int",
            Self::U32 => "uint",
            Self::F32 => "float",
            Self::F64 => "double",
        }
    }

    fn range(self) -> Option<(i64, i64)> {
        Some(match self {
            Self::I8 => (i8::MIN.into(), i8::MAX.into()),
            Self::U8 => (0, u8::MAX.into()),
            Self::I16 => (i16::MIN.into(), i16::MAX.into()),
            Self::U16 => (0, u16::MAX.into()),
            Self::I32 => (i32::MIN.into(), i32::MAX.into()),
            Self::U32 => (0, u32::MAX.into()),
            Self::F32 | Self::F64 => return None,
        })
    }
}

#[derive(Debug, Clone)]
enum Kind {
    Scalar(Scalar),
    List(Scalar, Scalar),
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Body {
    Ascii,
    Little,
    Big,
}

#[derive(Debug)]
struct Header {
    body: Body,
    elements: Vec<Element>,
    /// Byte offset of the body.
    start: usize,
    /// Line of the body's first byte (for ascii messages).
    first_line: usize,
}

fn err(name: &str, problem: impl Into<String>) -> Error {
    Error::format(name, FORMAT, problem)
}

fn parse_header(bytes: &[u8], name: &str) -> Result<Header> {
    let mut cur = ByteCursor::new(bytes, name, FORMAT);
    match cur.line() {
        Some(b"ply") => {}
        Some(first) => {
            return Err(err(
                name,
                format!(
                    "wrong magic: the first line must be 'ply', found '{}'",
                    show(first)
                ),
            ))
        }
        None => return Err(err(name, "empty file (no 'ply' line)")),
    }
    let mut body = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut line_no = 1;
    loop {
        line_no += 1;
        let Some(raw) = cur.line() else {
            return Err(err(name, "truncated header: no 'end_header' line"));
        };
        let line = std::str::from_utf8(raw).map_err(|_| {
            err(
                name,
                format!("header line {line_no} is not text: '{}'", show(raw)),
            )
        })?;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            None | Some("comment" | "obj_info") => {}
            Some("end_header") => break,
            Some("format") => {
                if words.len() != 3 {
                    return Err(err(
                        name,
                        format!(
                            "header line {line_no}: expected 'format <type> 1.0', found '{line}'"
                        ),
                    ));
                }
                body = Some(match words[1] {
                    "ascii" => Body::Ascii,
                    "binary_little_endian" => Body::Little,
                    "binary_big_endian" => Body::Big,
                    other => {
                        return Err(err(
                            name,
                            format!("header line {line_no}: unknown format '{other}' (expected ascii, binary_little_endian or binary_big_endian)"),
                        ))
                    }
                });
                if words[2] != "1.0" {
                    return Err(err(
                        name,
                        format!(
                            "header line {line_no}: unsupported version '{}' (expected 1.0)",
                            words[2]
                        ),
                    ));
                }
            }
            Some("element") => {
                let count = (words.len() == 3)
                    .then(|| words[2].parse::<u64>().ok())
                    .flatten()
                    .ok_or_else(|| {
                        err(
                            name,
                            format!("header line {line_no}: expected 'element <name> <count>', found '{line}'"),
                        )
                    })?;
                elements.push(Element {
                    name: words[1].to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let Some(element) = elements.last_mut() else {
                    return Err(err(
                        name,
                        format!("header line {line_no}: property before any element"),
                    ));
                };
                let ty = |s: &str| {
                    Scalar::parse(s).ok_or_else(|| {
                        err(
                            name,
                            format!("header line {line_no}: unknown property type '{s}'"),
                        )
                    })
                };
                let prop = match words.as_slice() {
                    ["property", "list", count, item, pname] => Property {
                        name: (*pname).to_string(),
                        kind: Kind::List(ty(count)?, ty(item)?),
                    },
                    ["property", t, pname] if *t != "list" => Property {
                        name: (*pname).to_string(),
                        kind: Kind::Scalar(ty(t)?),
                    },
                    _ => {
                        return Err(err(
                            name,
                            format!("header line {line_no}: expected 'property <type> <name>' or 'property list <count type> <type> <name>', found '{line}'"),
                        ))
                    }
                };
                if let Kind::List(c, _) = prop.kind {
                    if matches!(c, Scalar::F32 | Scalar::F64) {
                        return Err(err(
                            name,
                            format!("header line {line_no}: list count type of '{}' must be an integer type, found {}", prop.name, c.name()),
                        ));
                    }
                }
                element.props.push(prop);
            }
            Some(other) => {
                return Err(err(
                    name,
                    format!("header line {line_no}: unknown keyword '{other}'"),
                ))
            }
        }
    }
    let body = body.ok_or_else(|| err(name, "header has no 'format' line"))?;
    Ok(Header {
        body,
        elements,
        start: cur.position(),
        first_line: line_no + 1,
    })
}

/// Where values come from: ascii tokens or binary bytes.
enum Source<'a> {
    Ascii(Tokens<'a>),
    Binary(ByteCursor<'a>, bool),
}

/// Where a value is read, for messages.
struct At<'e> {
    element: &'e str,
    index: u64,
    property: &'e str,
}

impl Source<'_> {
    fn value(&mut self, ty: Scalar, name: &str, at: &At) -> Result<f64> {
        match self {
            Source::Ascii(tokens) => {
                let Some((tok, line)) = tokens.next_token() else {
                    return Err(err(
                        name,
                        format!(
                            "truncated: data ends at line {} in element '{}' {} (property '{}')",
                            tokens.line(),
                            at.element,
                            at.index,
                            at.property
                        ),
                    ));
                };
                let bad = || {
                    err(
                        name,
                        format!(
                            "line {line}: expected a value of type {} for property '{}' of element '{}' {}, found '{}'",
                            ty.name(),
                            at.property,
                            at.element,
                            at.index,
                            show(tok)
                        ),
                    )
                };
                match ty.range() {
                    None => parse_f64(tok).ok_or_else(bad),
                    Some((lo, hi)) => {
                        let v = parse_i64(tok).ok_or_else(bad)?;
                        if v < lo || v > hi {
                            return Err(bad());
                        }
                        Ok(v as f64)
                    }
                }
            }
            Source::Binary(cur, big) => {
                let big = *big;
                let pos = cur.position();
                let r = match ty {
                    Scalar::I8 => cur.u8().map(|v| f64::from(i8::from_le_bytes([v]))),
                    Scalar::U8 => cur.u8().map(f64::from),
                    Scalar::I16 => if big { cur.i16_be() } else { cur.i16_le() }.map(f64::from),
                    Scalar::U16 => if big { cur.u16_be() } else { cur.u16_le() }.map(f64::from),
                    Scalar::I32 => if big { cur.i32_be() } else { cur.i32_le() }.map(f64::from),
                    Scalar::U32 => if big { cur.u32_be() } else { cur.u32_le() }.map(f64::from),
                    Scalar::F32 => if big { cur.f32_be() } else { cur.f32_le() }.map(f64::from),
                    Scalar::F64 => {
                        if big {
                            cur.f64_be()
                        } else {
                            cur.f64_le()
                        }
                    }
                };
                r.map_err(|_| {
                    err(
                        name,
                        format!(
                            "truncated: data ends at byte {pos} in element '{}' {} (property '{}', {} bytes needed, {} left)",
                            at.element,
                            at.index,
                            at.property,
                            ty.size(),
                            cur.remaining()
                        ),
                    )
                })
            }
        }
    }

    /// Skips `count` records of fixed `size` bytes in binary (no-op check in ascii).
    fn skip_fixed(&mut self, element: &Element, size: usize, name: &str) -> Result<bool> {
        let Source::Binary(cur, _) = self else {
            return Ok(false);
        };
        let need = usize::try_from(element.count)
            .ok()
            .and_then(|c| c.checked_mul(size));
        match need {
            Some(n) if n <= cur.remaining() => {
                cur.seek(cur.position() + n)?;
                Ok(true)
            }
            _ => Err(err(
                name,
                format!(
                    "truncated: element '{}' has {} records of {size} bytes, but only {} bytes are left at offset {}",
                    element.name,
                    element.count,
                    cur.remaining(),
                    cur.position()
                ),
            )),
        }
    }
}

/// What a walk through the body collects.
struct Collected {
    /// Vertex count.
    vertices: usize,
    /// Polygons as `(face index, first, len)` into `indices`.
    polygons: Vec<(usize, usize, usize)>,
    indices: Vec<u32>,
}

/// Walks the whole body, calling `on_vertex(index, slots)` for every vertex and
/// collecting faces when `want_faces`.
fn walk(
    bytes: &[u8],
    name: &str,
    header: &Header,
    want_faces: bool,
    on_vertex: &mut dyn FnMut(usize, &[f64; 12]),
) -> Result<Collected> {
    let body = &bytes[header.start..];
    let mut src = match header.body {
        Body::Ascii => Source::Ascii(Tokens::new(body, header.first_line)),
        Body::Little => Source::Binary(ByteCursor::new(body, name, FORMAT), false),
        Body::Big => Source::Binary(ByteCursor::new(body, name, FORMAT), true),
    };
    let mut out = Collected {
        vertices: 0,
        polygons: Vec::new(),
        indices: Vec::new(),
    };
    for element in &header.elements {
        if element.props.is_empty() {
            continue;
        }
        let is_vertex = element.name == "vertex";
        let face_prop = (want_faces && element.name == "face")
            .then(|| {
                element.props.iter().position(|p| {
                    matches!(p.kind, Kind::List(..))
                        && (p.name == "vertex_indices" || p.name == "vertex_index")
                })
            })
            .flatten();
        let fixed: Option<usize> = element
            .props
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(t) => Some(t.size()),
                Kind::List(..) => None,
            })
            .sum();
        if !is_vertex && face_prop.is_none() {
            if let Some(size) = fixed {
                if src.skip_fixed(element, size, name)? {
                    continue;
                }
            }
        }
        let slots: Vec<Option<usize>> = element
            .props
            .iter()
            .map(|p| {
                if is_vertex {
                    SLOTS.iter().position(|s| *s == p.name)
                } else {
                    None
                }
            })
            .collect();
        if is_vertex {
            for (p, slot) in element.props.iter().zip(&slots) {
                if slot.is_some() && matches!(p.kind, Kind::List(..)) {
                    return Err(err(
                        name,
                        format!("vertex property '{}' is a list, expected a number", p.name),
                    ));
                }
            }
        }
        let mut values = [0.0f64; 12];
        let mut list_items: Vec<u32> = Vec::new();
        for index in 0..element.count {
            for (pi, p) in element.props.iter().enumerate() {
                let at = At {
                    element: &element.name,
                    index,
                    property: &p.name,
                };
                match p.kind {
                    Kind::Scalar(t) => {
                        let v = src.value(t, name, &at)?;
                        if let Some(s) = slots[pi] {
                            values[s] = v;
                        }
                    }
                    Kind::List(ct, it) => {
                        let n = src.value(ct, name, &at)?;
                        if n < 0.0 {
                            return Err(err(
                                name,
                                format!(
                                    "negative list length {n} in property '{}' of element '{}' {index}",
                                    p.name, element.name
                                ),
                            ));
                        }
                        let keep = face_prop == Some(pi);
                        if keep {
                            list_items.clear();
                        }
                        for _ in 0..n as u64 {
                            let v = src.value(it, name, &at)?;
                            if keep {
                                if v < 0.0 || v.fract() != 0.0 || v > f64::from(u32::MAX) {
                                    return Err(err(
                                        name,
                                        format!("face {index} has an invalid vertex index {v}"),
                                    ));
                                }
                                list_items.push(v as u32);
                            }
                        }
                        if keep {
                            out.polygons.push((
                                index as usize,
                                out.indices.len(),
                                list_items.len(),
                            ));
                            out.indices.extend_from_slice(&list_items);
                        }
                    }
                }
            }
            if is_vertex {
                on_vertex(index as usize, &values);
                out.vertices += 1;
            }
        }
    }
    Ok(out)
}

fn vertex_element<'h>(header: &'h Header, name: &str) -> Result<&'h Element> {
    let v = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .ok_or_else(|| err(name, "no 'vertex' element in the header"))?;
    for axis in ["x", "y", "z"] {
        if !v.props.iter().any(|p| p.name == axis) {
            let have: Vec<&str> = v.props.iter().map(|p| p.name.as_str()).collect();
            return Err(err(
                name,
                format!(
                    "vertex element has no property '{axis}' (it has: {})",
                    have.join(", ")
                ),
            ));
        }
    }
    Ok(v)
}

fn has_all(v: &Element, names: &[&str]) -> bool {
    names.iter().all(|n| v.props.iter().any(|p| p.name == *n))
}

/// Reads the vertices of a PLY file as a point cloud.
///
/// # Errors
/// [`Error::Format`] naming the problem: wrong magic, bad header line, missing
/// `x`/`y`/`z`, truncated data, a value that is not a number of its type.
pub fn read_ply(bytes: &[u8], name: &str) -> Result<CloudData> {
    let header = parse_header(bytes, name)?;
    let v = vertex_element(&header, name)?;
    let normals = has_all(v, &SLOTS[3..6]);
    let covs = has_all(v, &SLOTS[6..12]);
    let fields = v.props.iter().map(|p| p.name.clone()).collect();
    let body_len = bytes.len() - header.start;
    let cap = usize::try_from(v.count)
        .unwrap_or(usize::MAX)
        .min(body_len / 3);
    let mut builder = CloudDataBuilder::new(fields, None, normals, covs, cap);
    walk(bytes, name, &header, false, &mut |i, s| {
        let normal = normals.then(|| Vector3::new(s[3], s[4], s[5]));
        let cov = covs.then(|| cov_from_fields([s[6], s[7], s[8], s[9], s[10], s[11]]));
        builder.push(i, Point3::new(s[0], s[1], s[2]), normal, cov);
    })?;
    Ok(builder.finish())
}

fn check_encoding(encoding: Encoding) -> Result<&'static str> {
    match encoding {
        Encoding::Ascii => Ok("ascii"),
        Encoding::BinaryLittleEndian => Ok("binary_little_endian"),
        Encoding::BinaryBigEndian => Ok("binary_big_endian"),
        Encoding::BinaryCompressed => Err(Error::invalid(
            "PLY has no compressed encoding; use Ascii, BinaryLittleEndian or BinaryBigEndian",
        )),
    }
}

/// Writes rows of doubles in the encoding.
fn push_rows(out: &mut Vec<u8>, encoding: Encoding, row: &[f64], text: &mut String) {
    match encoding {
        Encoding::Ascii => {
            text.clear();
            push_row(text, row, ' ');
            out.extend_from_slice(text.as_bytes());
        }
        Encoding::BinaryBigEndian => {
            for v in row {
                out.extend_from_slice(&v.to_be_bytes());
            }
        }
        _ => {
            for v in row {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
}

/// Encodes a point cloud as PLY: `x y z` as `double`, plus `nx ny nz` and
/// `cov_xx cov_xy cov_xz cov_yy cov_yz cov_zz` when the cloud has them.
///
/// # Errors
/// [`Error::InvalidInput`] for [`Encoding::BinaryCompressed`] or when the
/// normals/covariances do not have one entry per point.
pub fn write_ply(cloud: &CloudData, encoding: Encoding) -> Result<Vec<u8>> {
    let format = check_encoding(encoding)?;
    let n = cloud.points.len();
    cloud.check_lengths()?;
    let mut head =
        format!("ply\nformat {format} 1.0\ncomment written by cloudprox\nelement vertex {n}\n");
    let mut names = vec!["x", "y", "z"];
    if cloud.normals.is_some() {
        names.extend_from_slice(&SLOTS[3..6]);
    }
    if cloud.covariances.is_some() {
        names.extend_from_slice(&SLOTS[6..12]);
    }
    for p in &names {
        let _ = writeln!(head, "property double {p}");
    }
    head.push_str("end_header\n");
    let mut out = head.into_bytes();
    let mut row = Vec::with_capacity(12);
    let mut text = String::new();
    for i in 0..n {
        row.clear();
        row.extend_from_slice(cloud.points[i].coords.as_slice());
        if let Some(normals) = &cloud.normals {
            row.extend_from_slice(normals[i].as_slice());
        }
        if let Some(covs) = &cloud.covariances {
            row.extend_from_slice(&cov_to_fields(&covs[i]));
        }
        push_rows(&mut out, encoding, &row, &mut text);
    }
    Ok(out)
}

/// Reads a PLY mesh: the `vertex` element's `x y z` and the `face` element's
/// `vertex_indices` (or `vertex_index`) lists, fan-triangulated. Triangles that
/// repeat a vertex are dropped and counted in [`MeshData::dropped_faces`].
///
/// # Errors
/// [`Error::Format`] as for [`read_ply`], plus: no `face` element or no index
/// list in it, a face with fewer than 3 vertices or an index out of range
/// (naming the face), a non-finite vertex, no face left.
pub fn read_ply_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    let header = parse_header(bytes, name)?;
    let v = vertex_element(&header, name)?;
    let face = header
        .elements
        .iter()
        .find(|e| e.name == "face")
        .ok_or_else(|| err(name, "no 'face' element in the header"))?;
    if !face.props.iter().any(|p| {
        matches!(p.kind, Kind::List(..)) && (p.name == "vertex_indices" || p.name == "vertex_index")
    }) {
        return Err(err(
            name,
            "the 'face' element has no 'vertex_indices' (or 'vertex_index') list property",
        ));
    }
    let cap = usize::try_from(v.count)
        .unwrap_or(usize::MAX)
        .min((bytes.len() - header.start) / 3);
    let mut vertices = Vec::with_capacity(cap);
    let collected = walk(bytes, name, &header, true, &mut |_, s| {
        vertices.push(Point3::new(s[0], s[1], s[2]));
    })?;
    let nv = vertices.len();
    let mut faces = Vec::with_capacity(collected.polygons.len());
    let mut dropped = 0;
    for &(f, first, len) in &collected.polygons {
        let poly = &collected.indices[first..first + len];
        if len < 3 {
            return Err(err(
                name,
                format!("face {f} has {len} vertices; a face needs at least 3"),
            ));
        }
        if let Some(&bad) = poly.iter().find(|&&i| i as usize >= nv) {
            return Err(err(
                name,
                format!("face {f} refers to vertex {bad}, but there are {nv} vertices"),
            ));
        }
        for k in 1..len - 1 {
            let t = [poly[0], poly[k], poly[k + 1]];
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                dropped += 1;
            } else {
                faces.push(t);
            }
        }
    }
    if let Some(i) = vertices
        .iter()
        .position(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(err(name, format!("vertex {i} has a non-finite coordinate")));
    }
    if faces.is_empty() {
        return Err(err(
            name,
            format!("the mesh has no usable face ({dropped} dropped because they repeat a vertex)"),
        ));
    }
    let mesh = Mesh::new(vertices, faces).map_err(|e| err(name, e.to_string()))?;
    Ok(MeshData {
        mesh,
        dropped_faces: dropped,
    })
}

/// Encodes a mesh as PLY: `x y z` as `double`, faces as `list uchar uint
/// vertex_indices`.
///
/// # Errors
/// [`Error::InvalidInput`] for [`Encoding::BinaryCompressed`].
pub fn write_ply_mesh(mesh: &Mesh, encoding: Encoding) -> Result<Vec<u8>> {
    let format = check_encoding(encoding)?;
    let head = format!(
        "ply\nformat {format} 1.0\ncomment written by cloudprox\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.vertices().len(),
        mesh.faces().len()
    );
    let mut out = head.into_bytes();
    let mut text = String::new();
    for v in mesh.vertices() {
        push_rows(&mut out, encoding, v.coords.as_slice(), &mut text);
    }
    for f in mesh.faces() {
        match encoding {
            Encoding::Ascii => {
                out.extend_from_slice(format!("3 {} {} {}\n", f[0], f[1], f[2]).as_bytes());
            }
            Encoding::BinaryBigEndian => {
                out.push(3);
                for i in f {
                    out.extend_from_slice(&i.to_be_bytes());
                }
            }
            _ => {
                out.push(3);
                for i in f {
                    out.extend_from_slice(&i.to_le_bytes());
                }
            }
        }
    }
    Ok(out)
}
