//! Whether an exact side can read anything of a cloud at all: a box around
//! the mesh against the cloud's hierarchies, before any signed distance.

use crate::bvh::Aabb;
use crate::cloud::PointCloud;
use crate::probability::normal_quantile;
use crate::query::collide::{CollisionRequest, QueryModel};
use crate::Real;

/// Whether a mesh inside `bounds` (the cloud's frame) may come within the
/// noise's reach of `cloud`: `false` proves that the exact-side query of any
/// mesh inside the box reads `P = 0` (nothing within reach, nothing inside).
/// Returns the answer and the number of hierarchy nodes tested.
///
/// With [`QueryModel::Points`], a point's probability is read only within
/// `reach sigma_i` of the surface (or inside it): the hierarchy over the
/// points, each node at `reach sigma_node`. With
/// [`QueryModel::Elements`], an element reads only where its surface comes
/// within half a spacing `m` plus `reach sqrt(sigma^2 + 2 m^2)` of the mesh
/// (the bound of its probes' search): the hierarchy over the element hulls
/// of each segmentation, each node at its largest `sigma` and `m`.
pub(crate) fn exact_side_may_reach(
    bounds: &Aabb,
    cloud: &PointCloud,
    request: &CollisionRequest,
    stack: &mut Vec<u32>,
) -> (bool, usize) {
    let reach = -normal_quantile(0.5 * request.prune_epsilon);
    match request.model {
        QueryModel::Points => points_near_box(bounds, cloud, reach, stack),
        QueryModel::Elements => {
            let limit =
                |sigma: Real, half: Real| half + reach * (sigma * sigma + 2.0 * half * half).sqrt();
            let mut visited = 0;
            let near = (0..request.segmentations).any(|s| {
                let hulls = cloud.segmentation_after(s).hulls();
                let (near, v) = hulls.near_box(bounds, limit, stack);
                visited += v;
                near
            });
            (near, visited)
        }
    }
}

/// Whether a leaf of the cloud's point hierarchy lies within `reach` times
/// the node's largest standard deviation of `bounds`.
fn points_near_box(
    bounds: &Aabb,
    cloud: &PointCloud,
    reach: Real,
    stack: &mut Vec<u32>,
) -> (bool, usize) {
    let nodes = cloud.bvh().nodes();
    let mut visited = 0;
    stack.clear();
    stack.push(0);
    while let Some(id) = stack.pop() {
        visited += 1;
        let node = &nodes[id as usize];
        if node.aabb.distance(bounds) > reach * node.sigma_max {
            continue;
        }
        match node.children {
            None => return (true, visited),
            Some([l, r]) => {
                stack.push(r);
                stack.push(l);
            }
        }
    }
    (false, visited)
}
