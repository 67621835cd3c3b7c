//! A validated triangle mesh.

use crate::bvh::Aabb;
use crate::error::{Error, Result};
use crate::math::{Point3, Pose, Vector3};
use crate::Real;

/// A triangle mesh: vertices and faces (counter-clockwise seen from outside when
/// the mesh bounds a solid), in the object's own frame (metres).
///
/// Construction validates it: at least one face, finite coordinates, indices in
/// range, no face repeating a vertex. Degenerate (zero-area) faces are allowed but
/// never sampled.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    vertices: Vec<Point3>,
    faces: Vec<[u32; 3]>,
}

impl Mesh {
    /// A mesh from its vertices and faces.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the first problem: no vertex or face, a
    /// non-finite coordinate, an index out of range, a face with a repeated vertex.
    pub fn new(vertices: Vec<Point3>, faces: Vec<[u32; 3]>) -> Result<Self> {
        if vertices.is_empty() {
            return Err(Error::invalid("mesh has no vertices"));
        }
        if faces.is_empty() {
            return Err(Error::invalid("mesh has no faces"));
        }
        if vertices.len() > u32::MAX as usize {
            return Err(Error::invalid("mesh has more than 2^32 - 1 vertices"));
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.coords.iter().all(|c| c.is_finite()))
        {
            return Err(Error::invalid(format!(
                "mesh vertex {i} has a non-finite coordinate: {:?}",
                vertices[i].coords.as_slice()
            )));
        }
        let n = vertices.len() as u32;
        for (f, face) in faces.iter().enumerate() {
            if let Some(&bad) = face.iter().find(|&&v| v >= n) {
                return Err(Error::invalid(format!(
                    "mesh face {f} refers to vertex {bad}, but there are {n} vertices"
                )));
            }
            if face[0] == face[1] || face[1] == face[2] || face[0] == face[2] {
                return Err(Error::invalid(format!(
                    "mesh face {f} repeats a vertex: {face:?}"
                )));
            }
        }
        Ok(Self { vertices, faces })
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Point3] {
        &self.vertices
    }

    /// The faces (vertex indices).
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The three corners of face `f`.
    pub fn triangle(&self, f: usize) -> [Point3; 3] {
        let [i, j, k] = self.faces[f];
        [
            self.vertices[i as usize],
            self.vertices[j as usize],
            self.vertices[k as usize],
        ]
    }

    /// The (unnormalised) normal of face `f`: twice its area long, outward for a
    /// counter-clockwise face.
    pub fn face_normal_scaled(&self, f: usize) -> Vector3 {
        let [a, b, c] = self.triangle(f);
        (b - a).cross(&(c - a))
    }

    /// The area of face `f` (square metres).
    pub fn face_area(&self, f: usize) -> Real {
        0.5 * self.face_normal_scaled(f).norm()
    }

    /// The total surface area (square metres).
    pub fn area(&self) -> Real {
        (0..self.faces.len()).map(|f| self.face_area(f)).sum()
    }

    /// The axis-aligned bounding box of the vertices.
    pub fn aabb(&self) -> Aabb {
        let mut b = Aabb::empty();
        for v in &self.vertices {
            b.take_point(v);
        }
        b
    }

    /// Whether every edge is shared by exactly two faces, once in each direction
    /// (the mesh bounds a solid and its faces are consistently oriented).
    pub fn is_closed(&self) -> bool {
        let mut edges: Vec<(u32, u32)> = self
            .faces
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .collect();
        edges.sort_unstable();
        if edges.windows(2).any(|w| w[0] == w[1]) {
            return false;
        }
        edges
            .iter()
            .all(|&(a, b)| edges.binary_search(&(b, a)).is_ok())
    }

    /// Whether the mesh is closed and bounds a convex solid: every vertex lies
    /// behind (or within `tolerance` of) every face's plane.
    pub fn is_convex(&self, tolerance: Real) -> bool {
        if !self.is_closed() {
            return false;
        }
        (0..self.faces.len()).all(|f| {
            let n = self.face_normal_scaled(f);
            let len = n.norm();
            if len == 0.0 {
                return true;
            }
            let n = n / len;
            let a = self.vertices[self.faces[f][0] as usize];
            self.vertices.iter().all(|v| n.dot(&(v - a)) <= tolerance)
        })
    }

    /// The enclosed volume (cubic metres; meaningful for a closed, outward-oriented mesh).
    pub fn volume(&self) -> Real {
        (0..self.faces.len())
            .map(|f| {
                let [a, b, c] = self.triangle(f);
                a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
            })
            .sum()
    }

    /// The mesh moved by a rigid pose.
    pub fn transformed(&self, pose: &Pose) -> Self {
        Self {
            vertices: self.vertices.iter().map(|v| pose * v).collect(),
            faces: self.faces.clone(),
        }
    }

    /// Several meshes as one (faces re-indexed).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if `meshes` is empty.
    pub fn merged(meshes: &[Mesh]) -> Result<Self> {
        if meshes.is_empty() {
            return Err(Error::invalid("no mesh to merge"));
        }
        let mut vertices = Vec::new();
        let mut faces = Vec::new();
        for m in meshes {
            let base = vertices.len() as u32;
            vertices.extend_from_slice(&m.vertices);
            faces.extend(
                m.faces
                    .iter()
                    .map(|f| [f[0] + base, f[1] + base, f[2] + base]),
            );
        }
        Self::new(vertices, faces)
    }
}
