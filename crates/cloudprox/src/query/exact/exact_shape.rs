//! Objects prepared for exact queries: one parry shape per mesh part.

use parry3d_f64::shape::{ConvexPolyhedron, Shape, TriMesh, TriMeshFlags};
use parry3d_f64::transformation::try_convex_hull;

use super::climbing_hull::ClimbingHull;
use super::exact::as_shape;
use super::mesh_distance::TriangleTree;
use crate::bvh::Aabb;
use crate::cloud::MAX_COORDINATE;
use crate::error::{Error, Result};
use crate::shape::Mesh;
use crate::Real;

/// Relative tolerance (of the part's bounding-box diagonal) of the convexity test.
const CONVEX_TOLERANCE: Real = 1e-9;

/// How one part is represented for exact queries.
#[derive(Clone)]
pub enum ExactPart {
    /// A closed convex part: GJK distances, EPA penetration depths.
    Convex(ConvexPolyhedron),
    /// Any other part. `closed` tells whether point containment is meaningful.
    Mesh {
        /// The triangle mesh (with pseudo-normals when closed).
        mesh: TriMesh,
        /// Whether the part bounds a solid.
        closed: bool,
    },
}

impl std::fmt::Debug for ExactPart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExactPart::Convex(c) => write!(f, "Convex({} vertices)", c.points().len()),
            ExactPart::Mesh { mesh, closed } => write!(
                f,
                "Mesh({} triangles, closed: {closed})",
                mesh.num_triangles()
            ),
        }
    }
}

/// An object made of mesh parts, prepared once for many exact queries.
#[derive(Debug, Clone)]
pub struct ExactShape {
    pub(crate) parts: Vec<ExactPart>,
    pub(crate) aabbs: Vec<Aabb>,
    /// The hierarchy over each mesh part's triangles (`None` for a convex
    /// part).
    pub(crate) trees: Vec<Option<TriangleTree>>,
    /// Each large convex part again, with a support function that walks its
    /// edges (the shape casts' GJK calls it at every iteration).
    climbing: Vec<Option<ClimbingHull>>,
}

impl ExactShape {
    /// Prepare `parts` (in the object's own frame) as solids where they are
    /// closed: closed convex parts get GJK/EPA, other closed parts containment.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if there is no part, a vertex is beyond
    /// [`MAX_COORDINATE`], or parry rejects a part (the message names the part
    /// and parry's reason).
    pub fn new(parts: &[Mesh]) -> Result<Self> {
        Self::build(parts, true)
    }

    /// Prepare `parts` as bare surfaces, closed or not: two objects intersect iff
    /// their triangles do (no containment, no penetration depth). For meshes
    /// whose orientation or closedness is not to be trusted, such as surfaces
    /// reconstructed from a scan.
    ///
    /// # Errors
    /// As [`ExactShape::new`].
    pub fn surfaces(parts: &[Mesh]) -> Result<Self> {
        Self::build(parts, false)
    }

    fn build(parts: &[Mesh], solid: bool) -> Result<Self> {
        if parts.is_empty() {
            return Err(Error::invalid("an exact shape needs at least one part"));
        }
        let mut out = Vec::with_capacity(parts.len());
        let mut climbing = Vec::with_capacity(parts.len());
        for (i, m) in parts.iter().enumerate() {
            // parry asserts (panics) on the degenerate projections that
            // overflowing coordinates produce.
            if let Some(v) = m
                .vertices()
                .iter()
                .position(|v| v.coords.amax() > MAX_COORDINATE)
            {
                return Err(Error::invalid(format!(
                    "part {i}: vertex {v} is beyond +-{MAX_COORDINATE:e} m"
                )));
            }
            let diag = m.aabb().half_extents().norm() * 2.0;
            let part = if solid && m.is_convex(CONVEX_TOLERANCE * diag.max(Real::MIN_POSITIVE)) {
                // The triangles parry builds the polyhedron from (the part's
                // own, else its hull's) give the climbing hull its edges.
                let (c, triangles) =
                    match ConvexPolyhedron::from_convex_mesh(m.vertices().to_vec(), m.faces()) {
                        Some(c) => (Some(c), m.faces().to_vec()),
                        None => match try_convex_hull(m.vertices()) {
                            Ok((v, t)) => (ConvexPolyhedron::from_convex_mesh(v, &t), t),
                            Err(_) => (None, Vec::new()),
                        },
                    };
                let c = c.ok_or_else(|| {
                    Error::invalid(format!(
                        "part {i}: parry could not build its convex polyhedron"
                    ))
                })?;
                climbing.push(ClimbingHull::new(&c, &triangles));
                ExactPart::Convex(c)
            } else {
                climbing.push(None);
                let closed = solid && m.is_closed();
                let flags = if closed {
                    TriMeshFlags::ORIENTED
                } else {
                    TriMeshFlags::empty()
                };
                let mesh = TriMesh::with_flags(m.vertices().to_vec(), m.faces().to_vec(), flags)
                    .map_err(|e| {
                        Error::invalid(format!("part {i}: parry rejected the mesh: {e}"))
                    })?;
                ExactPart::Mesh { mesh, closed }
            };
            out.push(part);
        }
        let trees = out
            .iter()
            .map(|p| match p {
                ExactPart::Mesh { mesh, .. } => TriangleTree::new(mesh).map(Some),
                ExactPart::Convex(_) => Ok(None),
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            parts: out,
            aabbs: parts.iter().map(Mesh::aabb).collect(),
            trees,
            climbing,
        })
    }

    /// The prepared parts.
    pub fn parts(&self) -> &[ExactPart] {
        &self.parts
    }

    /// The shape that casts of part `i` use: a large convex part's climbing
    /// hull (the same support points, found along its edges), else the part.
    pub(crate) fn cast_shape(&self, i: usize) -> &dyn Shape {
        match &self.climbing[i] {
            Some(c) => c,
            None => as_shape(&self.parts[i]),
        }
    }

    /// Part `i` with its triangle hierarchy (a mesh part's).
    pub(crate) fn part(&self, i: usize) -> (&ExactPart, Option<&TriangleTree>) {
        (&self.parts[i], self.trees[i].as_ref())
    }
}
