//! Self-filter: remove the points that lie on the robot itself.

use parry3d_f64::query::{PointQuery, PointQueryWithLocation};
use parry3d_f64::shape::{TriMesh, TriMeshFlags};
use rayon::prelude::*;

use super::crop_box::check_pose;
use crate::bvh::Aabb;
use crate::error::{Error, Result};
use crate::math::{Point3, Pose, Vector3};
use crate::shape::Mesh;

/// One link prepared for point queries.
#[derive(Clone)]
struct Link {
    /// The mesh in the link's frame (pseudo-normals when closed).
    mesh: TriMesh,
    /// Whether the mesh bounds a solid (closed, consistently oriented).
    closed: bool,
    /// The mesh's bounding box in its own frame, grown by the padding.
    local_box: Aabb,
    pose: Pose,
    inverse: Pose,
    /// `local_box` moved by `pose` (an axis-aligned box around it).
    world_box: Aabb,
}

impl std::fmt::Debug for Link {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Link({} triangles, closed: {}, pose: {:?})",
            self.mesh.num_triangles(),
            self.closed,
            self.pose
        )
    }
}

/// The default padding of a self-filter (metres): 1 cm, the low end of the PR2
/// pipeline's 1-3 cm (the Python bindings' `padding=None`, the command line's
/// `self:MESH` without a padding).
pub const SELF_FILTER_DEFAULT_PADDING: f64 = 0.01;

/// Removes the points of a cloud that lie on the robot, given the meshes of its
/// links and their poses. Built once (acceleration structures per link), then
/// applied to every frame; [`SelfFilter::set_poses`] moves the links.
///
/// Rule (ROS `robot_self_filter`, the PR2 pipeline's self filter, which tests
/// points against the link meshes grown by a padding): a point is removed when it
/// lies within `padding` of a link's surface, or inside a *closed* link. A link
/// mesh counts as closed when every edge is shared by exactly two faces, once in
/// each direction ([`Mesh::is_closed`]); its inside is then decided by parry's
/// pseudo-normal test (meshes wound inward are flipped first). Meshes from files
/// are often open (holes, duplicated seams, inconsistent winding): for those only
/// the distance to the surface counts, so a point deep inside an open link
/// further than `padding` from every face is kept. [`SelfFilter::new`] takes the
/// padding explicitly; [`SELF_FILTER_DEFAULT_PADDING`] (1 cm) is what callers that
/// leave it out get. The PR2 pipeline uses 1 to 3 cm; use at least 2-3 sensor
/// sigmas plus the error of the link poses.
///
/// Each point is first rejected by each link's padded bounding box (in the cloud
/// frame, then in the link's frame), so points far from the robot cost a few
/// comparisons; points are processed in parallel.
#[derive(Debug, Clone)]
pub struct SelfFilter {
    links: Vec<Link>,
    padding: f64,
}

impl SelfFilter {
    /// Prepares the links, each a mesh in its own frame and its pose in the
    /// cloud's frame, for a `padding` in metres.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] if there is no link, `padding` is negative or not
    /// finite, a pose is not finite, or parry rejects a mesh (naming the link).
    pub fn new(links: Vec<(Mesh, Pose)>, padding: f64) -> Result<Self> {
        if links.is_empty() {
            return Err(Error::invalid("SelfFilter: no link given"));
        }
        if !(padding.is_finite() && padding >= 0.0) {
            return Err(Error::invalid(format!(
                "SelfFilter: padding must be finite and >= 0, got {padding}"
            )));
        }
        let mut out = Vec::with_capacity(links.len());
        for (i, (mesh, pose)) in links.into_iter().enumerate() {
            check_pose(&format!("SelfFilter: pose of link {i}"), &pose)?;
            let closed = mesh.is_closed();
            let mut faces = mesh.faces().to_vec();
            if closed && mesh.volume() < 0.0 {
                for f in &mut faces {
                    f.swap(1, 2);
                }
            }
            let flags = if closed {
                TriMeshFlags::ORIENTED
            } else {
                TriMeshFlags::empty()
            };
            let tri = TriMesh::with_flags(mesh.vertices().to_vec(), faces, flags).map_err(|e| {
                Error::invalid(format!(
                    "SelfFilter: link {i}: parry rejected the mesh: {e}"
                ))
            })?;
            let mut local_box = mesh.aabb();
            let pad = Vector3::repeat(padding);
            local_box.mins -= pad;
            local_box.maxs += pad;
            out.push(Link {
                mesh: tri,
                closed,
                local_box,
                pose,
                inverse: pose.inverse(),
                world_box: local_box.transformed(&pose),
            });
        }
        Ok(Self {
            links: out,
            padding,
        })
    }

    /// Moves the links: `poses[i]` is link `i`'s new pose in the cloud's frame.
    ///
    /// # Errors
    /// [`Error::Shape`] if there is not one pose per link; [`Error::InvalidInput`]
    /// if a pose is not finite (the filter is then unchanged).
    pub fn set_poses(&mut self, poses: &[Pose]) -> Result<()> {
        if poses.len() != self.links.len() {
            return Err(Error::Shape {
                what: "SelfFilter::set_poses: poses (one per link)".into(),
                expected: self.links.len(),
                got: poses.len(),
            });
        }
        for (i, pose) in poses.iter().enumerate() {
            check_pose(&format!("SelfFilter: pose of link {i}"), pose)?;
        }
        for (link, pose) in self.links.iter_mut().zip(poses) {
            link.pose = *pose;
            link.inverse = pose.inverse();
            link.world_box = link.local_box.transformed(pose);
        }
        Ok(())
    }

    /// The links' poses, in link order.
    pub fn poses(&self) -> Vec<Pose> {
        self.links.iter().map(|l| l.pose).collect()
    }

    /// Whether each link is treated as closed (inside points removed), in link order.
    pub fn closed(&self) -> Vec<bool> {
        self.links.iter().map(|l| l.closed).collect()
    }

    /// The padding (metres).
    pub fn padding(&self) -> f64 {
        self.padding
    }

    /// Whether `p` (cloud frame) lies on the robot.
    pub fn is_on_robot(&self, p: &Point3) -> bool {
        self.links.iter().any(|link| {
            if !contains(&link.world_box, p) {
                return false;
            }
            let local = link.inverse * p;
            if !contains(&link.local_box, &local) {
                return false;
            }
            if link.closed {
                let (proj, _) = link.mesh.project_local_point_and_get_location(&local, true);
                proj.is_inside || (proj.point - local).norm() <= self.padding
            } else {
                link.mesh
                    .project_local_point_with_max_dist(&local, false, self.padding)
                    .is_some_and(|proj| (proj.point - local).norm() <= self.padding)
            }
        })
    }

    /// The indices (ascending) of the points that are *not* on the robot.
    /// Points with a non-finite coordinate are kept (they cannot be judged;
    /// remove them before, as the readers do).
    pub fn apply(&self, points: &[Point3]) -> Vec<u32> {
        points
            .par_iter()
            .enumerate()
            .filter_map(|(i, p)| (!self.is_on_robot(p)).then_some(i as u32))
            .collect()
    }
}

fn contains(b: &Aabb, p: &Point3) -> bool {
    (0..3).all(|a| p[a] >= b.mins[a] && p[a] <= b.maxs[a])
}
