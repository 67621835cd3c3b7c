//! Nearest-neighbour and radius queries on one hierarchy.

use crate::bvh::{Bvh, BvhWorkspace};
use crate::math::Point3;
use crate::Real;

/// Offers point `j` at squared distance `d2` (not NaN: the points are
/// finite) to `out`, the `k` (at least 1) nearest so far, at most `k` of
/// them, sorted by distance and, where distances tie, by index: it enters
/// only before the `k`-th, which then leaves (ties at the `k`-th distance go
/// to the smaller index, as in the hashed grid's k-NN). Moved into place by
/// swaps: `k` is small, a shift by `Vec::insert` costs a `memcpy` call.
#[inline]
pub(crate) fn offer_nearest(out: &mut Vec<(Real, u32)>, k: usize, d2: Real, j: u32) {
    debug_assert!(k > 0 && out.len() <= k && !d2.is_nan());
    let before = |&(d, i): &(Real, u32)| d < d2 || (d == d2 && i < j);
    if out.len() < k {
        out.push((d2, j));
    } else if before(&out[k - 1]) {
        return;
    } else {
        out[k - 1] = (d2, j);
    }
    let mut p = out.len() - 1;
    while p > 0 && !before(&out[p - 1]) {
        out.swap(p - 1, p);
        p -= 1;
    }
}

impl Bvh {
    /// The `k` points nearest to `query`, as `(squared distance, point index)`
    /// sorted by distance and, where distances tie, by index (so ties at the
    /// `k`-th distance go to the smaller index), written into `out` (cleared
    /// first). `points` must be the
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
                        offer_nearest(out, k, (points[i as usize] - query).norm_squared(), i);
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

    /// Every point within `radius` of `query`, i.e. with `(p - query).norm() <=
    /// radius` (this exact test, so that a caller scanning all points with it
    /// finds the same ones), as indices in the tree's order, written into
    /// `out` (cleared first). `points` must be the positions the tree was built or
    /// refitted over.
    pub fn within_radius(
        &self,
        points: &[Point3],
        query: &Point3,
        radius: Real,
        workspace: &mut BvhWorkspace,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        if radius.is_nan() || radius < 0.0 {
            return;
        }
        // Boxes are pruned against a slightly larger radius: the box distance
        // and the norm round differently, and a point on the sphere must not
        // be lost to rounding.
        let prune = radius * (1.0 + 1e-9) + Real::MIN_POSITIVE;
        let prune2 = prune * prune;
        let stack = &mut workspace.node_stack;
        stack.clear();
        stack.push(0);
        while let Some(id) = stack.pop() {
            let node = &self.nodes[id as usize];
            if node.aabb.distance_squared_to_point(query) > prune2 {
                continue;
            }
            match node.children {
                None => out.extend(
                    self.node_points(id)
                        .iter()
                        .filter(|&&i| (points[i as usize] - query).norm() <= radius),
                ),
                Some([l, r]) => {
                    stack.push(r);
                    stack.push(l);
                }
            }
        }
    }
}
