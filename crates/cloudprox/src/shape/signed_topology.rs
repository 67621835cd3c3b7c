//! What a mesh's connectivity says about its inside, before any distance is
//! asked: vertices welded, faces re-oriented to agree with their neighbours and
//! shells turned outwards, edges counted (boundary, non-manifold), and the
//! boundary grouped into loops for the fans that close it.

use std::collections::HashMap;

use super::Mesh;
use crate::math::{Point3, Vector3};
use crate::Real;

/// No neighbour across an edge (a boundary or non-manifold edge).
pub(crate) const NONE: u32 = u32::MAX;

/// A face is degenerate when twice its area is below this fraction of its
/// longest edge squared (an angle below about 1e-10 rad), or when welding
/// made two of its corners one vertex.
const DEGENERATE: Real = 1e-10;

/// What [`MeshDistance`](super::MeshDistance) found about a mesh's
/// connectivity, after welding vertices with equal coordinates and repairing
/// the orientation of its faces. It decides the [`SignMethod`](super::SignMethod).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshTopology {
    /// Vertices after welding those with exactly equal coordinates.
    pub vertices: usize,
    /// Shells: the sets of faces connected across edges shared by exactly two faces.
    pub shells: usize,
    /// Edges on the boundary (counted with multiplicity: the net number of
    /// times an edge is used in one direction more than in the other, after
    /// re-orientation). 0 for a closed mesh.
    pub boundary_edges: usize,
    /// Edges shared by more than two faces.
    pub non_manifold_edges: usize,
    /// Faces of (nearly) zero area, or whose corners welding made coincide.
    pub degenerate_faces: usize,
    /// Faces whose corner order was reversed: to agree with their neighbours,
    /// or because their whole shell faced inwards (negative volume).
    pub reoriented_faces: usize,
    /// Whether every edge is shared by exactly two faces, used once in each
    /// direction (after re-orientation).
    pub closed: bool,
    /// Whether two faces that share no vertex touch or cross: checked only for
    /// a closed mesh whose shells' boxes are disjoint (`None` otherwise).
    pub self_intersecting: Option<bool>,
}

/// A mesh's welded and re-oriented faces with their adjacency.
#[derive(Debug, Clone)]
pub(crate) struct Repaired {
    /// The welded vertices.
    pub(crate) positions: Vec<Point3>,
    /// Per input face, its welded corners in the repaired orientation.
    pub(crate) faces: Vec<[u32; 3]>,
    /// Per face, whether it is degenerate.
    pub(crate) degenerate: Vec<bool>,
    /// Per face, its shell (`NONE` for a face whose corners coincide).
    pub(crate) shell: Vec<u32>,
    /// Per face and local edge `k` (corner `k` to `k + 1`), the face across it
    /// when exactly two faces share it, else `NONE`.
    pub(crate) neighbors: Vec<[u32; 3]>,
    /// The net boundary: directed edges (welded ids) left after cancelling
    /// every edge against a reverse.
    pub(crate) boundary: Vec<[u32; 2]>,
    /// The summary (`self_intersecting` is filled in later).
    pub(crate) summary: MeshTopology,
}

/// `x` with `-0.0` as `0.0`, as bits (welding key).
fn key(x: Real) -> u64 {
    (x + 0.0).to_bits()
}

/// One use of an undirected edge by a face.
#[derive(Debug, Clone, Copy)]
struct EdgeUse {
    lo: u32,
    hi: u32,
    face: u32,
    local: u8,
    /// Whether the face runs the edge from `lo` to `hi`.
    forward: bool,
}

impl Repaired {
    /// Welds, re-orients and counts.
    pub(crate) fn new(mesh: &Mesh) -> Self {
        let (positions, mut faces) = weld(mesh);
        let degenerate = degenerate_faces(&faces, &positions);
        let (mut neighbors, mates) = adjacency(&faces);
        let (mut flip, shell, shells) = orient_shells(&faces, &mates);
        turn_inward_shells(&faces, &positions, &shell, shells, &mut flip);
        let mut reoriented = 0;
        for f in 0..faces.len() {
            if flip[f] {
                reoriented += 1;
                let [a, b, c] = faces[f];
                faces[f] = [a, c, b];
                // Edges of (a, c, b): a-c (old 2), c-b (old 1), b-a (old 0).
                let nb = neighbors[f];
                neighbors[f] = [nb[2], nb[1], nb[0]];
            }
        }
        let (boundary, non_manifold, closed) = count_edges(&faces);
        let summary = MeshTopology {
            vertices: positions.len(),
            shells: shells as usize,
            boundary_edges: boundary.len(),
            non_manifold_edges: non_manifold,
            degenerate_faces: degenerate.iter().filter(|&&d| d).count(),
            reoriented_faces: reoriented,
            closed: closed && faces.iter().all(|f| !repeats(f)),
            self_intersecting: None,
        };
        Self {
            positions,
            faces,
            degenerate,
            shell,
            neighbors,
            boundary,
            summary,
        }
    }

    /// The boundary split into connected loops (sets of edges sharing
    /// vertices). Each is a cycle: every vertex has as many edges in as out.
    pub(crate) fn boundary_loops(&self) -> Vec<Vec<[u32; 2]>> {
        fn find(parent: &mut HashMap<u32, u32>, v: u32) -> u32 {
            let mut r = v;
            while let Some(&p) = parent.get(&r) {
                if p == r {
                    break;
                }
                r = p;
            }
            // Point the start straight at the root.
            parent.insert(v, r);
            r
        }
        let mut parent: HashMap<u32, u32> = HashMap::new();
        for &[a, b] in &self.boundary {
            parent.entry(a).or_insert(a);
            parent.entry(b).or_insert(b);
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                parent.insert(ra, rb);
            }
        }
        let mut loops: HashMap<u32, Vec<[u32; 2]>> = HashMap::new();
        for &e in &self.boundary {
            let r = find(&mut parent, e[0]);
            loops.entry(r).or_default().push(e);
        }
        let mut out: Vec<Vec<[u32; 2]>> = loops.into_values().collect();
        out.sort_unstable();
        out
    }
}

/// Whether a face repeats a vertex.
fn repeats(f: &[u32; 3]) -> bool {
    f[0] == f[1] || f[1] == f[2] || f[0] == f[2]
}

/// The mesh with vertices of equal coordinates welded: the distinct
/// positions and the faces over them.
fn weld(mesh: &Mesh) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut ids: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.vertices().len());
    let mut positions = Vec::with_capacity(mesh.vertices().len());
    let remap: Vec<u32> = mesh
        .vertices()
        .iter()
        .map(|v| {
            *ids.entry([key(v.x), key(v.y), key(v.z)])
                .or_insert_with(|| {
                    positions.push(Point3::new(v.x + 0.0, v.y + 0.0, v.z + 0.0));
                    (positions.len() - 1) as u32
                })
        })
        .collect();
    let faces = mesh
        .faces()
        .iter()
        .map(|f| f.map(|i| remap[i as usize]))
        .collect();
    (positions, faces)
}

/// Per face, whether it is degenerate: a repeated vertex, or an area at most
/// `DEGENERATE` times its longest edge squared.
fn degenerate_faces(faces: &[[u32; 3]], positions: &[Point3]) -> Vec<bool> {
    faces
        .iter()
        .map(|f| {
            if repeats(f) {
                return true;
            }
            let [a, b, c] = f.map(|i| positions[i as usize]);
            let longest = (b - a)
                .norm_squared()
                .max((c - b).norm_squared())
                .max((a - c).norm_squared());
            (b - a).cross(&(c - a)).norm() <= DEGENERATE * longest
        })
        .collect()
}

/// Per face and edge, the face across it and that face's local edge
/// (`NONE` unless exactly two faces share the edge).
type Adjacency = (Vec<[u32; 3]>, Vec<[(u32, u8); 3]>);

/// The faces' adjacency across edges shared by exactly two faces: the
/// neighbour across each edge, and with it the neighbour's local edge.
fn adjacency(faces: &[[u32; 3]]) -> Adjacency {
    let n = faces.len();
    let uses = edge_uses(faces, &repeats);
    let mut neighbors = vec![[NONE; 3]; n];
    let mut mates: Vec<[(u32, u8); 3]> = vec![[(NONE, 0); 3]; n];
    for group in groups(&uses) {
        if let [u, v] = group {
            if u.face != v.face {
                neighbors[u.face as usize][u.local as usize] = v.face;
                neighbors[v.face as usize][v.local as usize] = u.face;
                mates[u.face as usize][u.local as usize] = (v.face, v.local);
                mates[v.face as usize][v.local as usize] = (u.face, u.local);
            }
        }
    }
    (neighbors, mates)
}

/// Each shell oriented consistently, breadth first across shared edges: per
/// face whether to flip it and its shell (`NONE` for a face repeating a
/// vertex), and the number of shells.
fn orient_shells(faces: &[[u32; 3]], mates: &[[(u32, u8); 3]]) -> (Vec<bool>, Vec<u32>, u32) {
    let n = faces.len();
    let forward = |f: u32, k: u8| {
        let face = &faces[f as usize];
        face[k as usize] < face[(k as usize + 1) % 3]
    };
    let mut flip = vec![false; n];
    let mut shell = vec![NONE; n];
    let mut shells = 0u32;
    for start in 0..n {
        if shell[start] != NONE || repeats(&faces[start]) {
            continue;
        }
        shell[start] = shells;
        let mut queue = vec![start as u32];
        while let Some(f) = queue.pop() {
            for k in 0..3u8 {
                let (g, kg) = mates[f as usize][k as usize];
                if g == NONE || shell[g as usize] != NONE {
                    continue;
                }
                // Consistent when the two faces run the edge in opposite
                // directions once flipped.
                let along_f = forward(f, k) ^ flip[f as usize];
                flip[g as usize] = forward(g, kg) ^ !along_f;
                shell[g as usize] = shells;
                queue.push(g);
            }
        }
        shells += 1;
    }
    (flip, shell, shells)
}

/// Turns the shells that face inwards (a negative volume about their
/// centroid, with the flips so far).
fn turn_inward_shells(
    faces: &[[u32; 3]],
    positions: &[Point3],
    shell: &[u32],
    shells: u32,
    flip: &mut [bool],
) {
    let mut sums = vec![(Vector3::zeros(), 0usize); shells as usize];
    for (f, face) in faces.iter().enumerate() {
        if shell[f] != NONE {
            let s = &mut sums[shell[f] as usize];
            for &v in face {
                s.0 += positions[v as usize].coords;
            }
            s.1 += 3;
        }
    }
    let centroids: Vec<Vector3> = sums.iter().map(|(s, k)| s / (*k).max(1) as Real).collect();
    let mut volume = vec![0.0 as Real; shells as usize];
    let mut extent = vec![0.0 as Real; shells as usize];
    for (f, face) in faces.iter().enumerate() {
        if shell[f] == NONE {
            continue;
        }
        let s = shell[f] as usize;
        let c = centroids[s];
        let [a, b, d] = face.map(|i| positions[i as usize].coords - c);
        let v = a.dot(&b.cross(&d)) / 6.0;
        volume[s] += if flip[f] { -v } else { v };
        extent[s] = extent[s].max(a.norm()).max(b.norm()).max(d.norm());
    }
    for f in 0..faces.len() {
        if shell[f] != NONE {
            let s = shell[f] as usize;
            if volume[s] < -1e-12 * extent[s].powi(3) {
                flip[f] = !flip[f];
            }
        }
    }
}

/// The edges of the repaired faces: the boundary edges (each as many times
/// as its uses fail to pair, in the direction of the surplus), the number of
/// edges shared by more than two faces, and whether every edge is used once
/// each way.
fn count_edges(faces: &[[u32; 3]]) -> (Vec<[u32; 2]>, usize, bool) {
    let uses = edge_uses(faces, &repeats);
    let mut boundary = Vec::new();
    let mut non_manifold = 0;
    let mut closed = true;
    for group in groups(&uses) {
        let fwd = group.iter().filter(|u| u.forward).count();
        let bwd = group.len() - fwd;
        if group.len() > 2 {
            non_manifold += 1;
        }
        if fwd != 1 || bwd != 1 {
            closed = false;
        }
        let (lo, hi) = (group[0].lo, group[0].hi);
        let edge = if fwd > bwd { [lo, hi] } else { [hi, lo] };
        for _ in 0..fwd.abs_diff(bwd) {
            boundary.push(edge);
        }
    }
    (boundary, non_manifold, closed)
}

/// Every edge use of the faces that do not repeat a vertex, sorted by edge.
fn edge_uses(faces: &[[u32; 3]], repeats: &impl Fn(&[u32; 3]) -> bool) -> Vec<EdgeUse> {
    let mut uses = Vec::with_capacity(3 * faces.len());
    for (f, face) in faces.iter().enumerate() {
        if repeats(face) {
            continue;
        }
        for k in 0..3u8 {
            let (a, b) = (face[k as usize], face[(k as usize + 1) % 3]);
            uses.push(EdgeUse {
                lo: a.min(b),
                hi: a.max(b),
                face: f as u32,
                local: k,
                forward: a < b,
            });
        }
    }
    uses.sort_unstable_by_key(|u| (u.lo, u.hi, u.face, u.local));
    uses
}

/// The runs of `uses` that share an edge.
fn groups(uses: &[EdgeUse]) -> impl Iterator<Item = &[EdgeUse]> {
    uses.chunk_by(|a, b| a.lo == b.lo && a.hi == b.hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_with_one_face_flipped_and_vertices_duplicated_is_repaired() {
        let cube = Mesh::cuboid(1.0, 1.0, 1.0).unwrap_or_else(|e| panic!("{e}"));
        let mut faces = cube.faces().to_vec();
        faces[3] = [faces[3][0], faces[3][2], faces[3][1]];
        // Duplicate every vertex: each face gets its own corners.
        let vertices: Vec<Point3> = faces
            .iter()
            .flat_map(|f| f.map(|i| cube.vertices()[i as usize]))
            .collect();
        let faces: Vec<[u32; 3]> = (0..faces.len() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect();
        let mesh = Mesh::new(vertices, faces).unwrap_or_else(|e| panic!("{e}"));
        let r = Repaired::new(&mesh);
        assert_eq!(r.summary.vertices, 8);
        assert_eq!(r.summary.shells, 1);
        assert!(r.summary.closed);
        assert_eq!(r.summary.boundary_edges, 0);
        assert_eq!(r.summary.reoriented_faces, 1);
        // The whole cube inverted is turned back out.
        let inverted: Vec<[u32; 3]> = cube.faces().iter().map(|f| [f[0], f[2], f[1]]).collect();
        let inv = Mesh::new(cube.vertices().to_vec(), inverted).unwrap_or_else(|e| panic!("{e}"));
        let r = Repaired::new(&inv);
        assert_eq!(r.summary.reoriented_faces, 12);
        assert!(r.summary.closed);
        // One face removed: a loop of 4 boundary edges.
        let open = Mesh::new(cube.vertices().to_vec(), cube.faces()[..10].to_vec())
            .unwrap_or_else(|e| panic!("{e}"));
        let r = Repaired::new(&open);
        assert!(!r.summary.closed);
        assert_eq!(r.summary.boundary_edges, 4);
        assert_eq!(r.boundary_loops().len(), 1);
    }
}
