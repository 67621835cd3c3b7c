//! Structural checks of a hierarchy.

use crate::bvh::Bvh;
use crate::math::Point3;
use crate::Real;

impl Bvh {
    /// Panics unless the tree is well formed for `points` and `sigmas`: every index
    /// appears exactly once, children partition their parent's range, every box
    /// contains its points and its children's boxes, and every `sigma_max` bounds
    /// the sigmas below it. Meant for tests and debugging.
    pub fn assert_well_formed(&self, points: &[Point3], sigmas: &[Real]) {
        let mut seen = vec![false; points.len()];
        for &i in &self.indices {
            assert!(!seen[i as usize], "index {i} appears twice");
            seen[i as usize] = true;
        }
        assert!(seen.iter().all(|&s| s), "some point is in no leaf");
        for (id, node) in self.nodes.iter().enumerate() {
            for &i in self.node_points(id as u32) {
                let p = &points[i as usize];
                assert!(
                    node.aabb.distance_squared_to_point(p) == 0.0,
                    "node {id} does not contain point {i}"
                );
                assert!(
                    sigmas[i as usize] <= node.sigma_max,
                    "node {id}: sigma_max too small"
                );
            }
            if let Some([l, r]) = node.children {
                let (ln, rn) = (&self.nodes[l as usize], &self.nodes[r as usize]);
                assert!(
                    l as usize > id && r as usize > id,
                    "children must follow parents"
                );
                assert_eq!(
                    ln.first, node.first,
                    "left child must start where its parent does"
                );
                assert_eq!(rn.first, ln.first + ln.count, "children must be contiguous");
                assert_eq!(
                    ln.count + rn.count,
                    node.count,
                    "children must partition the parent"
                );
            }
        }
    }
}
