//! Wavefront OBJ: read and write triangle meshes.
//!
//! Read: `v x y z [w]` (also `v x y z r g b [a]` with vertex colours: up to 7
//! numbers, everything after `z` ignored) and `f` with corners `i`, `i/t`,
//! `i//n` or `i/t/n`. Indices are 1-based, or negative: relative to the last
//! vertex defined so far (`-1` is the last one). A positive index may refer to a
//! vertex defined later in the file (it is checked once the file is read).
//! Polygons of any size are split into a fan of triangles; triangles that repeat
//! a vertex are dropped and counted in [`MeshData::dropped_faces`]. All objects
//! and groups of the file become one mesh. `#` starts a comment and a line
//! ending in `\` continues on the next line.
//!
//! Statements that carry no surface geometry (`vt vn vp o g s usemtl mtllib l p
//! mg ...`, and any statement this reader does not know) are ignored, so files
//! with vendor extensions still read. Free-form surfaces (`surf`) are geometry
//! this reader cannot triangulate: they are an error rather than being dropped
//! silently.
//!
//! Errors name the line: a malformed number or index, index 0, an index out of
//! range, a face with fewer than 3 vertices, a non-finite coordinate, no face.

use std::borrow::Cow;
use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::io::mesh_text::{finish_mesh, lines, tokens};
use crate::io::text::{parse_f64, parse_i64, push_real, quote};
use crate::io::MeshData;
use crate::math::Point3;
use crate::shape::Mesh;

const FORMAT: &str = "OBJ";

/// The statements of an OBJ file, comments removed and continuation lines joined,
/// with the number of their first line.
fn statements(bytes: &[u8]) -> Vec<(usize, Cow<'_, [u8]>)> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, Vec<u8>)> = None;
    for (number, raw) in lines(bytes) {
        let line = match raw.iter().position(|&b| b == b'#') {
            Some(i) => &raw[..i],
            None => raw,
        };
        let trimmed = line.trim_ascii_end();
        let (text, continues) = match trimmed.strip_suffix(b"\\") {
            Some(head) => (head, true),
            None => (line, false),
        };
        match (pending.as_mut(), continues) {
            (None, false) => out.push((number, Cow::Borrowed(text))),
            (None, true) => pending = Some((number, [text, b" "].concat())),
            (Some(p), _) => {
                p.1.extend_from_slice(text);
                p.1.push(b' ');
            }
        }
        if !continues {
            if let Some((n, joined)) = pending.take() {
                out.push((n, Cow::Owned(joined)));
            }
        }
    }
    out.extend(pending.map(|(n, joined)| (n, Cow::Owned(joined))));
    out
}

/// Reads an OBJ mesh (see the module docs for what is read).
///
/// # Errors
/// [`Error::Format`] naming the line and the problem.
pub fn read_obj_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    let err = |line: usize, problem: String| {
        Error::format(name, FORMAT, format!("line {line}: {problem}"))
    };
    let mut vertices: Vec<Point3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // (line, 0-based index) of positive indices past the vertices defined so far.
    let mut forward: Vec<(usize, u64)> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    for (line, text) in statements(bytes) {
        let mut toks = tokens(&text);
        let Some(keyword) = toks.next() else { continue };
        match keyword {
            b"v" => {
                let args: Vec<&[u8]> = toks.collect();
                if !(3..=7).contains(&args.len()) {
                    return Err(err(
                        line,
                        format!(
                            "a vertex needs 3 to 7 numbers (x y z [w] or x y z r g b [a]), \
                             found {}",
                            args.len()
                        ),
                    ));
                }
                let mut xyz = [0.0; 3];
                for (k, a) in args.iter().enumerate() {
                    let x = parse_f64(a).ok_or_else(|| {
                        err(line, format!("malformed number {} in a vertex", quote(a)))
                    })?;
                    if k < 3 {
                        if !x.is_finite() {
                            return Err(err(
                                line,
                                format!("non-finite vertex coordinate {}", quote(a)),
                            ));
                        }
                        xyz[k] = x;
                    }
                }
                if vertices.len() >= u32::MAX as usize {
                    return Err(err(line, "more than 2^32 - 1 vertices".into()));
                }
                vertices.push(Point3::new(xyz[0], xyz[1], xyz[2]));
            }
            b"f" | b"fo" => {
                corners.clear();
                for a in toks {
                    corners.push(corner_index(a, vertices.len(), line, &mut forward, &err)?);
                }
                if corners.len() < 3 {
                    return Err(err(
                        line,
                        format!("a face needs at least 3 vertices, found {}", corners.len()),
                    ));
                }
                for i in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[i], corners[i + 1]]);
                }
            }
            b"surf" => {
                return Err(err(
                    line,
                    "free-form surfaces (\"surf\") are not supported; export the mesh as \
                     polygons"
                        .into(),
                ))
            }
            // vt vn vp o g s usemtl mtllib l p mg ... and unknown statements.
            _ => {}
        }
    }
    let n = vertices.len() as u64;
    if let Some(&(line, index)) = forward.iter().find(|&&(_, i)| i >= n) {
        return Err(err(
            line,
            format!(
                "face vertex index {} out of range: the file defines {n} vertices",
                index + 1
            ),
        ));
    }
    if triangles.is_empty() {
        return Err(Error::format(name, FORMAT, "no faces (no \"f\" statement)"));
    }
    finish_mesh(name, FORMAT, vertices, triangles)
}

/// The 0-based vertex index of one face corner (`i`, `i/t`, `i//n`, `i/t/n`).
fn corner_index(
    token: &[u8],
    defined: usize,
    line: usize,
    forward: &mut Vec<(usize, u64)>,
    err: &impl Fn(usize, String) -> Error,
) -> Result<u32> {
    let mut parts = token.split(|&b| b == b'/');
    let first = parts.next().unwrap_or_default();
    let rest: Vec<&[u8]> = parts.collect();
    let malformed = || {
        err(
            line,
            format!(
                "malformed face vertex {} (expected i, i/t, i//n or i/t/n with integer indices)",
                quote(token)
            ),
        )
    };
    if rest.len() > 2
        || rest
            .iter()
            .any(|p| !p.is_empty() && parse_i64(p).is_none_or(|v| v == 0))
    {
        return Err(malformed());
    }
    let index = parse_i64(first).ok_or_else(malformed)?;
    if index == 0 {
        return Err(err(
            line,
            format!(
                "face vertex index 0 in {} (indices start at 1)",
                quote(token)
            ),
        ));
    }
    let resolved = if index > 0 {
        let i = index.unsigned_abs() - 1;
        if i >= defined as u64 {
            forward.push((line, i));
        }
        i
    } else {
        let back = index.unsigned_abs();
        match (defined as u64).checked_sub(back) {
            Some(i) => i,
            None => {
                return Err(err(
                    line,
                    format!(
                        "face vertex index {index} out of range: {defined} vertices defined so far"
                    ),
                ))
            }
        }
    };
    u32::try_from(resolved).map_err(|_| {
        err(
            line,
            format!("face vertex index {index} out of range (more than 2^32 - 1)"),
        )
    })
}

/// Encodes a mesh as OBJ: one `v x y z` line per vertex (written so it reads
/// back to exactly the same `f64`) and one `f a b c` line per face (1-based).
///
/// # Errors
/// Never fails; the `Result` matches the other writers.
pub fn write_obj_mesh(mesh: &Mesh) -> Result<Vec<u8>> {
    let mut out = String::from("# written by cloudprox\n");
    for v in mesh.vertices() {
        out.push('v');
        for &c in v.coords.iter() {
            out.push(' ');
            push_real(&mut out, c);
        }
        out.push('\n');
    }
    for f in mesh.faces() {
        let _ = writeln!(out, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    Ok(out.into_bytes())
}
