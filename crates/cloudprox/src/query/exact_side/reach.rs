//! Whether an exact side can read anything of a cloud at all: a box around
//! the mesh against the cloud's hierarchies, before any signed distance.

use crate::bvh::Aabb;
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::query::collide::{CollisionRequest, QueryModel};
use crate::Real;

/// Whether a mesh inside the box `local` of its own frame, at `pose` in the
/// cloud's frame, may come within the noise's reach (`reach` standard
/// deviations, `-Phi^-1(epsilon / 2)` for the request's `prune_epsilon`) of
/// `cloud`: `false` proves that the exact-side query of any mesh inside the
/// box reads nothing within reach and nothing inside: `P = 0`, but for the
/// readings of single points farther than the reach (each below
/// `epsilon / 2`, as the per-point probabilities leave them). Returns the
/// answer and the number of hierarchy nodes tested.
///
/// The box, moved into the cloud's frame, descends the cloud's hierarchy;
/// at each leaf within reach, its points or elements are tested against the
/// box in the mesh's frame. With [`QueryModel::Points`], a point's
/// probability is read only within `reach sigma_i` of the surface (or
/// inside it): the hierarchy over the points, each node at `reach` times its
/// largest `sigma`. With [`QueryModel::Elements`], an element reads only
/// where its surface comes within half a spacing `m` plus
/// `reach sqrt(sigma^2 + 2 m^2)` of the mesh (the bound of its probes'
/// search): the hierarchy over the element hulls of each segmentation, each
/// node at its largest `sigma` and `m`, each element's surface against the
/// box along separating axes. A single point is read at its own Eq. 3 gap,
/// which beyond `reach sigma` gives less than `epsilon / 2`, however sparse
/// its sampling (the exact side keeps such a reading within half its
/// spacing: a scan's stray points, spaced tens of centimetres apart, would
/// otherwise keep every link near).
pub(crate) fn exact_side_may_reach(
    (local, pose): (&Aabb, &Pose),
    cloud: &PointCloud,
    (request, reach): (&CollisionRequest, Real),
    stack: &mut Vec<u32>,
) -> (bool, usize) {
    let world = local.transformed(pose);
    let to_local = pose.inverse();
    match request.model {
        QueryModel::Points => points_near_box((&world, local, &to_local), cloud, reach, stack),
        QueryModel::Elements => {
            let limit =
                |sigma: Real, half: Real| half + reach * (sigma * sigma + 2.0 * half * half).sqrt();
            let mut visited = 0;
            let near = (0..request.segmentations).any(|s| {
                let hulls = cloud.segmentation_after(s).hulls();
                let leaf = |h: &crate::element::Hull| {
                    let own = if h.point {
                        reach * h.sigma
                    } else {
                        limit(h.sigma, h.margin)
                    };
                    h.box_gap(&to_local, local) <= own
                };
                let (near, v) = hulls.near_box(&world, limit, leaf, stack);
                visited += v;
                near
            });
            (near, visited)
        }
    }
}

/// Whether a point of the cloud lies within `reach` times its largest
/// standard deviation of the box (`world` in the cloud's frame, `local` in
/// the mesh's, `to_local` from the one to the other): the hierarchy's nodes
/// against `world`, each leaf's points against `local`.
fn points_near_box(
    (world, local, to_local): (&Aabb, &Aabb, &Pose),
    cloud: &PointCloud,
    reach: Real,
    stack: &mut Vec<u32>,
) -> (bool, usize) {
    let bvh = cloud.bvh();
    let (points, sigma) = (cloud.points(), cloud.sigma_max());
    let mut visited = 0;
    stack.clear();
    stack.push(0);
    while let Some(id) = stack.pop() {
        visited += 1;
        let node = &bvh.nodes()[id as usize];
        if node.aabb.distance(world) > reach * node.sigma_max {
            continue;
        }
        match node.children {
            None => {
                let near = bvh.node_points(id).iter().any(|&i| {
                    let x = to_local * points[i as usize];
                    let r = reach * sigma[i as usize];
                    local.distance_squared_to_point(&x) <= r * r
                });
                if near {
                    return (true, visited);
                }
            }
            Some([l, r]) => {
                stack.push(r);
                stack.push(l);
            }
        }
    }
    (false, visited)
}
