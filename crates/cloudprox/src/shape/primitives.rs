//! Closed convex primitives as meshes: boxes and cylinders (prisms).

use super::Mesh;
use crate::error::{Error, Result};
use crate::math::Point3;
use crate::Real;

fn positive(what: &str, v: Real) -> Result<Real> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(format!(
            "{what} must be finite and > 0, got {v}"
        )))
    }
}

impl Mesh {
    /// A box centred at the origin with half extents `(hx, hy, hz)`: 8 vertices,
    /// 12 outward-facing triangles.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if a half extent is not finite and positive.
    pub fn cuboid(hx: Real, hy: Real, hz: Real) -> Result<Self> {
        let (hx, hy, hz) = (
            positive("half extent x", hx)?,
            positive("half extent y", hy)?,
            positive("half extent z", hz)?,
        );
        let vertices = (0..8)
            .map(|i| {
                let s = |bit: u32| if i & (1 << bit) == 0 { -1.0 } else { 1.0 };
                Point3::new(s(0) * hx, s(1) * hy, s(2) * hz)
            })
            .collect();
        // Vertex i has x bit 0, y bit 1, z bit 2.
        let faces = vec![
            [0, 2, 1],
            [1, 2, 3], // z-
            [4, 5, 6],
            [5, 7, 6], // z+
            [0, 1, 4],
            [1, 5, 4], // y-
            [2, 6, 3],
            [3, 6, 7], // y+
            [0, 4, 2],
            [2, 4, 6], // x-
            [1, 3, 5],
            [3, 7, 5], // x+
        ];
        Self::new(vertices, faces)
    }

    /// A cylinder along z centred at the origin, approximated by a prism with
    /// `segments` sides whose vertices lie on the circle of `radius`.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if `radius` or `half_height` is not finite and
    /// positive, or `segments < 3`.
    pub fn cylinder(radius: Real, half_height: Real, segments: usize) -> Result<Self> {
        let radius = positive("radius", radius)?;
        let h = positive("half height", half_height)?;
        if segments < 3 {
            return Err(Error::invalid(format!(
                "a cylinder needs at least 3 segments, got {segments}"
            )));
        }
        let n = segments as u32;
        let mut vertices = Vec::with_capacity(2 * segments + 2);
        for z in [-h, h] {
            for k in 0..segments {
                let t = 2.0 * std::f64::consts::PI * k as Real / segments as Real;
                vertices.push(Point3::new(radius * t.cos(), radius * t.sin(), z));
            }
        }
        vertices.push(Point3::new(0.0, 0.0, -h));
        vertices.push(Point3::new(0.0, 0.0, h));
        let (bottom, top) = (2 * n, 2 * n + 1);
        let mut faces = Vec::with_capacity(4 * segments);
        for k in 0..n {
            let k1 = (k + 1) % n;
            faces.push([k, k1, n + k1]);
            faces.push([k, n + k1, n + k]);
            faces.push([bottom, k1, k]);
            faces.push([top, n + k, n + k1]);
        }
        Self::new(vertices, faces)
    }
}
