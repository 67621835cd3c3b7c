//! Area-weighted random sampling of a mesh's surface.

use super::Mesh;
use crate::error::{Error, Result};
use crate::math::{Point3, Vector3};
use crate::sample::NormalRng;
use crate::Real;

/// Points drawn on a mesh's surface, each with the face it lies on.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSample {
    /// The points (mesh frame).
    pub points: Vec<Point3>,
    /// For each point, the index of its face.
    pub faces: Vec<u32>,
    /// For each point, the unit outward normal of its face.
    pub normals: Vec<Vector3>,
}

impl Mesh {
    /// `n` points drawn uniformly over the surface: a face with probability
    /// proportional to its area, then a uniform point in it (square-root
    /// barycentric warp). Seeded: the same seed gives the same points.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if the mesh has zero area.
    pub fn sample_surface(&self, n: usize, seed: u64) -> Result<SurfaceSample> {
        let mut cumulative = Vec::with_capacity(self.faces().len());
        let mut total = 0.0;
        for f in 0..self.faces().len() {
            total += self.face_area(f);
            cumulative.push(total);
        }
        if total <= 0.0 || !total.is_finite() {
            return Err(Error::invalid(format!(
                "cannot sample a mesh of area {total}"
            )));
        }
        let mut rng = NormalRng::new(seed);
        let mut out = SurfaceSample {
            points: Vec::with_capacity(n),
            faces: Vec::with_capacity(n),
            normals: Vec::with_capacity(n),
        };
        for _ in 0..n {
            let target = rng.uniform() * total;
            let f = cumulative
                .partition_point(|&c| c < target)
                .min(cumulative.len() - 1);
            let [a, b, c] = self.triangle(f);
            let (r1, r2) = (rng.uniform().sqrt(), rng.uniform());
            let p = a.coords * (1.0 - r1) + b.coords * (r1 * (1.0 - r2)) + c.coords * (r1 * r2);
            out.points.push(Point3::from(p));
            out.faces.push(f as u32);
            out.normals.push(self.face_normal_scaled(f).normalize());
        }
        Ok(out)
    }

    /// The surface sampled at `density` points per square metre (`round(density *
    /// area)` points, at least one).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if `density` is not finite and positive or the mesh
    /// has zero area.
    pub fn sample_surface_density(&self, density: Real, seed: u64) -> Result<SurfaceSample> {
        if !(density.is_finite() && density > 0.0) {
            return Err(Error::invalid(format!(
                "sampling density must be finite and > 0, got {density}"
            )));
        }
        let n = (density * self.area()).round().max(1.0);
        if n > 1e9 {
            return Err(Error::invalid(format!(
                "density {density} gives {n:.3e} points, more than 1e9"
            )));
        }
        self.sample_surface(n as usize, seed)
    }
}
