//! STL, ascii and binary: read and write.
//!
//! **Binary**: an 80-byte header, a little-endian `u32` triangle count, then 50
//! bytes per triangle (normal and three vertices as `f32`, a `u16` attribute).
//! **Ascii**: `solid name`, then per triangle `facet normal nx ny nz`, `outer
//! loop`, three `vertex x y z`, `endloop`, `endfacet`, and finally `endsolid`.
//! Keywords are case-insensitive and tokens may be spread over lines in any
//! whitespace; several `solid ... endsolid` blocks in one file become one mesh.
//!
//! **Detection.** Many binary files begin their header with `solid`, so the size
//! decides first: the file is binary when it is exactly `84 + 50 * count` bytes
//! long (`count` read at offset 80). Otherwise it is read as ascii when it starts
//! (after whitespace) with `solid`, and is a format error saying which check failed
//! when it does not. A binary file must have exactly the size its count promises:
//! trailing bytes after the last triangle are rejected (they are either a
//! corrupt count or data this reader would otherwise drop silently).
//!
//! STL stores every triangle with its own copies of its corners; the reader
//! welds corners with exactly equal coordinates (`-0.0` equal to `0.0`) into
//! shared vertices. Triangles that repeat a vertex after welding are dropped and
//! counted in [`MeshData::dropped_faces`]. Stored normals are ignored (the
//! winding order defines the orientation). A file with no triangle is an error.

use crate::error::{Error, Result};
use crate::io::mesh_text::{finish_mesh, Welder};
use crate::io::text::{parse_f64, push_real, quote, Tokens};
use crate::io::{ByteCursor, Encoding, MeshData};
use crate::shape::Mesh;

const FORMAT: &str = "STL";
const HEADER_LEN: usize = 80;
const TRIANGLE_LEN: usize = 50;

/// Reads an STL mesh, ascii or binary (see the module docs for the detection).
///
/// # Errors
/// [`Error::Format`] naming the problem: for binary files the offset and the
/// triangle, for ascii files the line and what was expected there.
pub fn read_stl_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    let starts_solid = starts_with_solid(bytes);
    let promised = binary_size(bytes);
    if let Some((count, size)) = promised {
        if size == Some(bytes.len()) {
            return read_binary(bytes, name, count);
        }
    }
    if starts_solid {
        return read_ascii(bytes, name).map_err(|e| match (e, promised) {
            (
                Error::Format {
                    path,
                    format,
                    problem,
                },
                Some((count, size)),
            ) => Error::Format {
                path,
                format,
                problem: format!(
                    "{problem} (read as ascii because it starts with \"solid\" and its size \
                     does not fit binary STL: {})",
                    binary_size_note(count, size, bytes.len())
                ),
            },
            (e, _) => e,
        });
    }
    let problem = match promised {
        None => format!(
            "the file has {} bytes, fewer than the 84 of a binary STL header, and does not \
             start with \"solid\" (ascii STL)",
            bytes.len()
        ),
        Some((count, size)) => format!(
            "not binary STL: {}; not ascii STL: it does not start with \"solid\"",
            binary_size_note(count, size, bytes.len())
        ),
    };
    Err(Error::format(name, FORMAT, problem))
}

/// The triangle count at offset 80 and the size it implies (`None` on overflow).
fn binary_size(bytes: &[u8]) -> Option<(u32, Option<usize>)> {
    let raw: [u8; 4] = bytes.get(HEADER_LEN..HEADER_LEN + 4)?.try_into().ok()?;
    let count = u32::from_le_bytes(raw);
    let size = (count as usize)
        .checked_mul(TRIANGLE_LEN)
        .and_then(|n| n.checked_add(HEADER_LEN + 4));
    Some((count, size))
}

fn binary_size_note(count: u32, size: Option<usize>, len: usize) -> String {
    match size {
        Some(size) if size > len => format!(
            "truncated: the header promises {count} triangles ({size} bytes) but the file has \
             only {len} bytes"
        ),
        Some(size) => format!(
            "the header promises {count} triangles ({size} bytes) but the file has {len} bytes, \
             {} more",
            len - size
        ),
        None => format!("the header promises {count} triangles, more than fit in memory"),
    }
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    bytes
        .get(start..start + 5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
}

fn read_binary(bytes: &[u8], name: &str, count: u32) -> Result<MeshData> {
    if count == 0 {
        return Err(Error::format(
            name,
            FORMAT,
            "no triangles (binary STL with a triangle count of 0)",
        ));
    }
    let mut cur = ByteCursor::new(bytes, name, FORMAT);
    cur.seek(HEADER_LEN + 4)?;
    let mut welder = Welder::default();
    let mut triangles = Vec::with_capacity(count as usize);
    for t in 0..count as usize {
        let start = cur.position();
        let _normal = cur.take(12)?;
        let mut face = [0u32; 3];
        for (k, corner) in face.iter_mut().enumerate() {
            let p = [
                f64::from(cur.f32_le()?),
                f64::from(cur.f32_le()?),
                f64::from(cur.f32_le()?),
            ];
            if !p.iter().all(|c| c.is_finite()) {
                return Err(cur.error(format!(
                    "triangle {t} (offset {start}) vertex {k} has a non-finite coordinate {p:?}"
                )));
            }
            *corner = welder
                .add(p)
                .ok_or_else(|| cur.error("more than 2^32 - 1 distinct vertices"))?;
        }
        let _attribute = cur.u16_le()?;
        triangles.push(face);
    }
    finish_mesh(name, FORMAT, welder.vertices, triangles)
}

/// The ascii STL parser: tokens and the file's name for errors.
struct Ascii<'a> {
    tokens: Tokens<'a>,
    name: &'a str,
}

impl Ascii<'_> {
    fn error(&self, line: usize, problem: impl std::fmt::Display) -> Error {
        Error::format(self.name, FORMAT, format!("line {line}: {problem}"))
    }

    /// The next token, which must be `keyword` (case-insensitive).
    fn expect(&mut self, keyword: &str, context: &str) -> Result<usize> {
        match self.tokens.next_token().map(|(t, l)| (l, t)) {
            Some((line, t)) if t.eq_ignore_ascii_case(keyword.as_bytes()) => Ok(line),
            Some((line, t)) => Err(self.error(
                line,
                format!("expected \"{keyword}\" {context}, found {}", quote(t)),
            )),
            None => Err(self.error(
                self.tokens.current_line(),
                format!("expected \"{keyword}\" {context}, found the end of the file"),
            )),
        }
    }

    fn number(&mut self, what: &str) -> Result<f64> {
        match self.tokens.next_token().map(|(t, l)| (l, t)) {
            Some((line, t)) => match parse_f64(t) {
                Some(x) if x.is_finite() => Ok(x),
                Some(_) => {
                    Err(self.error(line, format!("non-finite number {} in {what}", quote(t))))
                }
                None => Err(self.error(
                    line,
                    format!("expected a number in {what}, found {}", quote(t)),
                )),
            },
            None => Err(self.error(
                self.tokens.current_line(),
                format!("expected a number in {what}, found the end of the file"),
            )),
        }
    }
}

fn read_ascii(bytes: &[u8], name: &str) -> Result<MeshData> {
    let mut p = Ascii {
        tokens: Tokens::new(bytes, 1),
        name,
    };
    let mut welder = Welder::default();
    let mut triangles = Vec::new();
    let mut solids = 0usize;
    loop {
        match p.tokens.next_token().map(|(t, l)| (l, t)) {
            None if solids > 0 => break,
            None => {
                return Err(p.error(
                    p.tokens.current_line(),
                    "expected \"solid\", found the end of the file",
                ))
            }
            Some((_, t)) if t.eq_ignore_ascii_case(b"solid") => {}
            Some((line, t)) => {
                return Err(p.error(
                    line,
                    format!(
                        "expected \"solid\" {}, found {}",
                        if solids == 0 {
                            "at the start"
                        } else {
                            "or the end of the file after \"endsolid\""
                        },
                        quote(t)
                    ),
                ))
            }
        }
        solids += 1;
        p.tokens.skip_line();
        loop {
            let Some((line, t)) = p.tokens.next_token().map(|(t, l)| (l, t)) else {
                return Err(p.error(
                    p.tokens.current_line(),
                    "expected \"facet\" or \"endsolid\", found the end of the file",
                ));
            };
            if t.eq_ignore_ascii_case(b"endsolid") {
                p.tokens.skip_line();
                break;
            }
            if !t.eq_ignore_ascii_case(b"facet") {
                return Err(p.error(
                    line,
                    format!("expected \"facet\" or \"endsolid\", found {}", quote(t)),
                ));
            }
            p.expect("normal", "after \"facet\"")?;
            for _ in 0..3 {
                p.number("the facet normal")?;
            }
            p.expect("outer", "after the facet normal")?;
            p.expect("loop", "after \"outer\"")?;
            let mut face = [0u32; 3];
            for (k, corner) in face.iter_mut().enumerate() {
                let line = p.expect("vertex", &format!("(vertex {} of 3 of the facet)", k + 1))?;
                let what = format!("vertex {} of the facet", k + 1);
                let v = [p.number(&what)?, p.number(&what)?, p.number(&what)?];
                *corner = welder
                    .add(v)
                    .ok_or_else(|| p.error(line, "more than 2^32 - 1 distinct vertices"))?;
            }
            p.expect("endloop", "after 3 vertices (facets must be triangles)")?;
            p.expect("endfacet", "after \"endloop\"")?;
            triangles.push(face);
        }
    }
    if triangles.is_empty() {
        return Err(Error::format(
            name,
            FORMAT,
            "no triangles (ascii STL with no facet)",
        ));
    }
    finish_mesh(name, FORMAT, welder.vertices, triangles)
}

/// The unit normal of a face, or zero for a degenerate face.
fn unit_normal(mesh: &Mesh, f: usize) -> [f64; 3] {
    let n = mesh.face_normal_scaled(f);
    let len = n.norm();
    if len > 0.0 && len.is_finite() {
        [n.x / len, n.y / len, n.z / len]
    } else {
        [0.0; 3]
    }
}

/// Encodes a mesh as STL: `Encoding::Ascii` (coordinates written so they read
/// back exactly) or `Encoding::BinaryLittleEndian` (coordinates rounded to `f32`).
///
/// # Errors
/// [`Error::InvalidInput`] for another encoding, or a binary mesh with more than
/// `u32::MAX` faces.
pub fn write_stl_mesh(mesh: &Mesh, encoding: Encoding) -> Result<Vec<u8>> {
    match encoding {
        Encoding::Ascii => Ok(write_ascii(mesh).into_bytes()),
        Encoding::BinaryLittleEndian => write_binary(mesh),
        other => Err(Error::invalid(format!(
            "STL is written as Ascii or BinaryLittleEndian, not {other:?}"
        ))),
    }
}

fn write_ascii(mesh: &Mesh) -> String {
    let mut out = String::from("solid cloudprox\n");
    for (f, face) in mesh.faces().iter().enumerate() {
        out.push_str("facet normal");
        for c in unit_normal(mesh, f) {
            out.push(' ');
            push_real(&mut out, c);
        }
        out.push_str("\n  outer loop\n");
        for &v in face {
            out.push_str("    vertex");
            for &c in mesh.vertices()[v as usize].coords.iter() {
                out.push(' ');
                push_real(&mut out, c);
            }
            out.push('\n');
        }
        out.push_str("  endloop\nendfacet\n");
    }
    out.push_str("endsolid cloudprox\n");
    out
}

fn write_binary(mesh: &Mesh) -> Result<Vec<u8>> {
    let count = u32::try_from(mesh.faces().len()).map_err(|_| {
        Error::invalid(format!(
            "binary STL holds at most {} triangles, the mesh has {}",
            u32::MAX,
            mesh.faces().len()
        ))
    })?;
    let mut out = Vec::with_capacity(HEADER_LEN + 4 + TRIANGLE_LEN * mesh.faces().len());
    let mut header = [0u8; HEADER_LEN];
    let text = b"binary STL written by cloudprox";
    header[..text.len()].copy_from_slice(text);
    out.extend_from_slice(&header);
    out.extend_from_slice(&count.to_le_bytes());
    for (f, face) in mesh.faces().iter().enumerate() {
        for c in unit_normal(mesh, f) {
            out.extend_from_slice(&(c as f32).to_le_bytes());
        }
        for &v in face {
            for &c in mesh.vertices()[v as usize].coords.iter() {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    Ok(out)
}
