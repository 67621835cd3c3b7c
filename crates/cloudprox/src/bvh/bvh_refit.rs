//! Refitting boxes in `O(n)` after points moved, keeping the tree's topology.

use crate::bvh::{Aabb, Bvh};
use crate::error::{Error, Result};
use crate::math::Point3;
use crate::Real;

impl Bvh {
    /// Recomputes every node's box and `sigma_max` for moved points (same count,
    /// same indices), bottom-up in one reverse sweep. The topology is kept, so a
    /// tree whose points moved far from where it was built gets looser boxes:
    /// rebuild it then.
    pub fn refit(&mut self, points: &[Point3], sigmas: &[Real]) -> Result<()> {
        let n = self.indices.len();
        if points.len() != n || sigmas.len() != n {
            return Err(Error::Shape {
                what: "refit points".into(),
                expected: n,
                got: points.len().min(sigmas.len()),
            });
        }
        for id in (0..self.nodes.len()).rev() {
            let (aabb, sigma_max) = if let Some([l, r]) = self.nodes[id].children {
                let (l, r) = (&self.nodes[l as usize], &self.nodes[r as usize]);
                (l.aabb.merged(&r.aabb), l.sigma_max.max(r.sigma_max))
            } else {
                let mut aabb = Aabb::empty();
                let mut s: Real = 0.0;
                for &i in self.node_points(id as u32) {
                    aabb.take_point(&points[i as usize]);
                    s = s.max(sigmas[i as usize]);
                }
                (aabb, s)
            };
            self.nodes[id].aabb = aabb;
            self.nodes[id].sigma_max = sigma_max;
        }
        Ok(())
    }
}
