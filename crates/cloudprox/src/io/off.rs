//! OFF (Object File Format): read and write triangle meshes.
//!
//! Read: a header line `OFF` (also `COFF`, `NOFF`, `CNOFF`, `STOFF`, ... : any
//! of the `ST`, `C`, `N` prefixes), optionally followed on the same line by the
//! counts; then `nv nf [ne]`; then `nv` vertex lines `x y z ...` (values after
//! `z`, such as colours and normals of the C/N variants, are ignored); then `nf`
//! face lines `k i1 ... ik [colour]` with 0-based indices, split into a fan of
//! triangles. `#` starts a comment; blank lines are skipped. The 4D (`4OFF`),
//! n-dimensional (`nOFF`) and binary (`OFF BINARY`) variants are rejected.
//! Anything but blank lines or comments after the last face is an error.
//! Triangles that repeat a vertex are dropped and counted in
//! [`MeshData::dropped_faces`].

use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::io::mesh_text::{finish_mesh, lines, strip_comment, tokens};
use crate::io::text::{parse_f64, parse_i64, push_real, quote};
use crate::io::MeshData;
use crate::math::Point3;
use crate::shape::Mesh;

const FORMAT: &str = "OFF";

/// Whether `keyword` is an OFF header this reader reads.
fn is_off_keyword(keyword: &[u8]) -> bool {
    let Some(prefix) = keyword.strip_suffix(b"OFF") else {
        return false;
    };
    let prefix = prefix.strip_prefix(b"ST").unwrap_or(prefix);
    let prefix = prefix.strip_prefix(b"C").unwrap_or(prefix);
    let prefix = prefix.strip_prefix(b"N").unwrap_or(prefix);
    prefix.is_empty()
}

/// Reads an OFF mesh (see the module docs for what is read).
///
/// # Errors
/// [`Error::Format`] naming the line and the problem.
pub fn read_off_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    let err = |line: usize, problem: String| at(name, line, problem);
    // Non-blank lines, comments removed, as token lists.
    let mut rows = lines(bytes).filter_map(|(n, l)| {
        let t: Vec<&[u8]> = tokens(strip_comment(l)).collect();
        (!t.is_empty()).then_some((n, t))
    });
    let last_line = lines(bytes).last().map_or(1, |(n, _)| n);
    let (nv, nf) = read_counts(name, &mut rows, last_line)?;
    // A vertex line is at least 6 bytes ("0 0 0\n"): never trust the count further.
    let mut vertices = Vec::with_capacity(nv.min(bytes.len() / 6));
    for i in 0..nv {
        let Some((line, t)) = rows.next() else {
            return Err(err(
                last_line,
                format!(
                    "the header promises {nv} vertices and {nf} faces, but the file ends after \
                     {i} vertices"
                ),
            ));
        };
        vertices.push(read_vertex(name, line, i, &t)?);
    }
    let mut triangles = Vec::with_capacity(nf.min(bytes.len() / 8));
    for f in 0..nf {
        let Some((line, t)) = rows.next() else {
            return Err(err(
                last_line,
                format!("the header promises {nf} faces, but the file ends after {f} faces"),
            ));
        };
        let corners = read_face(name, line, f, &t, nv)?;
        for i in 1..corners.len() - 1 {
            triangles.push([corners[0], corners[i], corners[i + 1]]);
        }
    }
    if let Some((line, t)) = rows.next() {
        return Err(err(
            line,
            format!(
                "unexpected {} after the {nf} faces the header promises",
                quote(t[0])
            ),
        ));
    }
    if triangles.is_empty() {
        return Err(Error::format(
            name,
            FORMAT,
            "no faces (the header says 0 faces)",
        ));
    }
    finish_mesh(name, FORMAT, vertices, triangles)
}

/// The error `problem` at `line` of the OFF file `name`.
fn at(name: &str, line: usize, problem: impl std::fmt::Display) -> Error {
    Error::format(name, FORMAT, format!("line {line}: {problem}"))
}

/// Reads the header keyword and the counts line (on the header's line or
/// the next): the numbers of vertices and faces.
fn read_counts<'a>(
    name: &str,
    rows: &mut impl Iterator<Item = (usize, Vec<&'a [u8]>)>,
    last_line: usize,
) -> Result<(usize, usize)> {
    let err = |line: usize, problem: String| at(name, line, problem);
    let Some((line, header)) = rows.next() else {
        return Err(Error::format(
            name,
            FORMAT,
            "empty file: expected the header \"OFF\"",
        ));
    };
    let keyword = header[0];
    if !is_off_keyword(keyword) {
        let problem = if keyword.ends_with(b"OFF") {
            format!(
                "unsupported OFF variant {} (only OFF, COFF, NOFF, CNOFF, STOFF ... in 3D)",
                quote(keyword)
            )
        } else {
            format!("expected the header \"OFF\", found {}", quote(keyword))
        };
        return Err(err(line, problem));
    }
    let mut counts_tokens: Vec<&[u8]> = header[1..].to_vec();
    let mut counts_line = line;
    if counts_tokens
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
    {
        return Err(err(line, "binary OFF is not supported".into()));
    }
    if counts_tokens.is_empty() {
        let Some((l, t)) = rows.next() else {
            return Err(err(
                last_line,
                "expected the counts \"nv nf ne\" after the header, found the end of the file"
                    .into(),
            ));
        };
        counts_tokens = t;
        counts_line = l;
    }
    if !(2..=3).contains(&counts_tokens.len()) {
        return Err(err(
            counts_line,
            format!(
                "expected the counts \"nv nf ne\" (2 or 3 integers), found {} values",
                counts_tokens.len()
            ),
        ));
    }
    let mut counts = [0usize; 3];
    for (k, t) in counts_tokens.iter().enumerate() {
        counts[k] = parse_i64(t)
            .and_then(|v| usize::try_from(v).ok())
            .ok_or_else(|| {
                err(
                    counts_line,
                    format!(
                        "bad count {}: expected a non-negative integer for {}",
                        quote(t),
                        [
                            "the number of vertices",
                            "the number of faces",
                            "the number of edges"
                        ][k]
                    ),
                )
            })?;
    }
    let [nv, nf, _ne] = counts;
    if nv > u32::MAX as usize {
        return Err(err(
            counts_line,
            format!("{nv} vertices: more than 2^32 - 1"),
        ));
    }
    Ok((nv, nf))
}

/// Vertex `i`, read from the tokens `t` of `line`: three finite coordinates
/// (anything after them, a colour or a normal, is left).
fn read_vertex(name: &str, line: usize, i: usize, t: &[&[u8]]) -> Result<Point3> {
    if t.len() < 3 {
        return Err(at(
            name,
            line,
            format!("vertex {i} needs 3 coordinates, found {} values", t.len()),
        ));
    }
    let mut xyz = [0.0; 3];
    for k in 0..3 {
        xyz[k] = match parse_f64(t[k]) {
            Some(x) if x.is_finite() => x,
            Some(_) => {
                return Err(at(
                    name,
                    line,
                    format!("vertex {i} has a non-finite coordinate {}", quote(t[k])),
                ))
            }
            None => {
                return Err(at(
                    name,
                    line,
                    format!("vertex {i}: malformed number {}", quote(t[k])),
                ))
            }
        };
    }
    Ok(Point3::new(xyz[0], xyz[1], xyz[2]))
}

/// Face `f`'s vertex indices (at least 3, each below `nv`), read from the
/// tokens `t` of `line` (anything after them, a colour, is left).
fn read_face(name: &str, line: usize, f: usize, t: &[&[u8]], nv: usize) -> Result<Vec<u32>> {
    let err = |problem: String| at(name, line, problem);
    let k = parse_i64(t[0])
        .and_then(|v| usize::try_from(v).ok())
        .ok_or_else(|| {
            err(format!(
                "face {f}: bad vertex count {}: expected a non-negative integer",
                quote(t[0])
            ))
        })?;
    if k < 3 {
        return Err(err(format!(
            "face {f} has {k} vertices; a face needs at least 3"
        )));
    }
    if t.len() - 1 < k {
        return Err(err(format!(
            "face {f} announces {k} vertices but the line has only {} indices",
            t.len() - 1
        )));
    }
    t[1..=k]
        .iter()
        .map(|tok| {
            let index = parse_i64(tok)
                .ok_or_else(|| err(format!("face {f}: malformed vertex index {}", quote(tok))))?;
            match u32::try_from(index) {
                Ok(i) if (i as usize) < nv => Ok(i),
                _ => Err(err(format!(
                    "face {f}: vertex index {index} out of range ({})",
                    if nv == 0 {
                        "the file has no vertices".to_string()
                    } else {
                        format!("0 to {}", nv - 1)
                    }
                ))),
            }
        })
        .collect()
}

/// Encodes a mesh as OFF: vertex coordinates written so they read back to
/// exactly the same `f64`, faces as `3 a b c`.
///
/// # Errors
/// Never fails; the `Result` matches the other writers.
pub fn write_off_mesh(mesh: &Mesh) -> Result<Vec<u8>> {
    let mut out = format!("OFF\n{} {} 0\n", mesh.vertices().len(), mesh.faces().len());
    for v in mesh.vertices() {
        let mut first = true;
        for &c in v.coords.iter() {
            if !first {
                out.push(' ');
            }
            first = false;
            push_real(&mut out, c);
        }
        out.push('\n');
    }
    for f in mesh.faces() {
        let _ = writeln!(out, "3 {} {} {}", f[0], f[1], f[2]);
    }
    Ok(out.into_bytes())
}
