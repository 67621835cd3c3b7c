//! Helpers shared by the mesh readers and writers (STL, OBJ, OFF): building
//! [`MeshData`] from parsed triangles, welding, lines and comments.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::io::MeshData;
use crate::math::Point3;
use crate::shape::Mesh;

/// Welds vertices by exact coordinate equality (`-0.0` equals `0.0`).
#[derive(Debug, Default)]
pub(crate) struct Welder {
    index: HashMap<[u64; 3], u32>,
    /// The distinct vertices, in order of first appearance.
    pub vertices: Vec<Point3>,
}

impl Welder {
    /// The index of `p`, adding it if new; `None` past `u32::MAX` vertices.
    pub fn add(&mut self, p: [f64; 3]) -> Option<u32> {
        // `+ 0.0` turns -0.0 into 0.0 so both weld together.
        let key = p.map(|c| (c + 0.0).to_bits());
        if let Some(&i) = self.index.get(&key) {
            return Some(i);
        }
        let i = u32::try_from(self.vertices.len()).ok()?;
        self.vertices.push(Point3::new(p[0], p[1], p[2]));
        self.index.insert(key, i);
        Some(i)
    }
}

/// Builds the [`MeshData`]: drops (and counts) triangles that repeat a vertex,
/// and turns a mesh that is still invalid into an [`Error::Format`].
pub(crate) fn finish_mesh(
    name: &str,
    format: &str,
    vertices: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
) -> Result<MeshData> {
    let total = triangles.len();
    if total == 0 {
        return Err(Error::format(name, format, "no faces"));
    }
    let faces: Vec<[u32; 3]> = triangles
        .into_iter()
        .filter(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2])
        .collect();
    let dropped_faces = total - faces.len();
    if faces.is_empty() {
        return Err(Error::format(
            name,
            format,
            format!("no faces: all {total} triangles repeat a vertex"),
        ));
    }
    let mesh = Mesh::new(vertices, faces).map_err(|e| match e {
        Error::InvalidInput(msg) => Error::format(name, format, msg),
        other => other,
    })?;
    Ok(MeshData {
        mesh,
        dropped_faces,
    })
}

/// The text lines of a file with their 1-based numbers; `\r\n` and `\n` both end
/// a line.
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let body = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    let mut it = body.split(|&b| b == b'\n').enumerate();
    let empty = bytes.is_empty();
    std::iter::from_fn(move || {
        if empty {
            return None;
        }
        it.next()
            .map(|(i, l)| (i + 1, l.strip_suffix(b"\r").unwrap_or(l)))
    })
}

/// The whitespace-separated tokens of a line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace)
        .filter(|t| !t.is_empty())
}

/// `line` without a `#` comment.
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}
