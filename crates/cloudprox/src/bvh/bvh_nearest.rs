//! k-nearest-neighbour queries on one hierarchy.

use crate::bvh::{Bvh, BvhWorkspace};
use crate::math::Point3;
use crate::Real;

impl Bvh {
    /// The `k` points nearest to `query`, as `(squared distance, point index)`
    /// sorted by distance, written into `out` (cleared first). `points` must be the
    /// positions the tree was built or refitted over.
    pub fn nearest_k(
        &self,
        points: &[Point3],
        query: &Point3,
        k: usize,
        workspace: &mut BvhWorkspace,
        out: &mut Vec<(Real, u32)>,
    ) {
        out.clear();
        if k == 0 {
            return;
        }
        let stack = &mut workspace.node_heap;
        stack.clear();
        stack.push((self.nodes[0].aabb.distance_squared_to_point(query), 0));
        while let Some((d2_box, id)) = stack.pop() {
            if out.len() == k && d2_box > out[k - 1].0 {
                continue;
            }
            let node = &self.nodes[id as usize];
            match node.children {
                None => {
                    for &i in self.node_points(id) {
                        let d2 = (points[i as usize] - query).norm_squared();
                        if out.len() < k || d2 < out[k - 1].0 {
                            let pos = out.partition_point(|&(d, _)| d <= d2);
                            out.insert(pos, (d2, i));
                            out.truncate(k);
                        }
                    }
                }
                Some([l, r]) => {
                    let dl = self.nodes[l as usize].aabb.distance_squared_to_point(query);
                    let dr = self.nodes[r as usize].aabb.distance_squared_to_point(query);
                    // Push the farther child first so the nearer one is popped next.
                    if dl <= dr {
                        stack.push((dr, r));
                        stack.push((dl, l));
                    } else {
                        stack.push((dl, l));
                        stack.push((dr, r));
                    }
                }
            }
        }
    }
}
