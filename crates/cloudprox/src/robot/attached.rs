//! Objects held by a robot: attached to a link, moved with it, queried
//! against the environment as a link is, removed by the self-filter, and
//! checked for collision with the robot's other links.
//!
//! An object is a mesh or a point cloud in its own frame, placed in the frame
//! of the link that holds it. Its collision geometry is prepared as a link's
//! is ([`LinkGeometry::new`]): from the mesh itself, or, for a cloud, from the
//! cloud's convex hull (the hull stands for a cloud object in self-collision,
//! the self-filter and the motion bound; the cloud itself, with its noise,
//! stands for it against the environment).

use std::sync::Arc;

use parry3d_f64::transformation::try_convex_hull;

use super::geometry::LinkGeometry;
use super::model::Robot;
use super::query::SelfCollision;
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Pose;
use crate::query::exact::intersects;
use crate::shape::Mesh;
use crate::Real;

/// What an object given to [`Robot::attach`] is made of, in its own frame.
#[derive(Debug, Clone)]
pub enum AttachedShape {
    /// A triangle mesh: it stands in a query as a link does (its exact
    /// surface, or its sample with [`MeshSide::Sampled`](crate::query::MeshSide)).
    Mesh(Mesh),
    /// A point cloud (the scanned object, with its noise): collided as a
    /// cloud against the environment; its convex hull stands for it in
    /// self-collision and the self-filter.
    Cloud(Arc<PointCloud>),
}

/// An object held by a link of a robot ([`Robot::attach`]).
#[derive(Debug, Clone)]
pub struct AttachedObject {
    pub(crate) name: String,
    pub(crate) link: usize,
    pub(crate) pose: Pose,
    pub(crate) touch_links: Vec<usize>,
    /// Links (with geometry) checked against the object for self-collision:
    /// all but the holding link and the touch links.
    pub(crate) checked_links: Vec<usize>,
    pub(crate) geometry: LinkGeometry,
    pub(crate) cloud: Option<Arc<PointCloud>>,
    /// A cloud object's largest sampling spacing and largest noise standard
    /// deviation (for the broad phase; 0 for a mesh object).
    pub(crate) cloud_spread: (Real, Real),
}

impl AttachedObject {
    /// The object's name (its key in query results).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The index of the link that holds it.
    pub fn link(&self) -> usize {
        self.link
    }

    /// The object's frame in the holding link's frame.
    pub fn pose(&self) -> &Pose {
        &self.pose
    }

    /// The links (indices) allowed to touch the object besides the holding link.
    pub fn touch_links(&self) -> &[usize] {
        &self.touch_links
    }

    /// The links (indices, with geometry) checked against the object for
    /// self-collision: every link with geometry but the holding link and the
    /// touch links.
    pub fn checked_links(&self) -> &[usize] {
        &self.checked_links
    }

    /// The object's collision geometry in its own frame (for a cloud object,
    /// its convex hull).
    pub fn geometry(&self) -> &LinkGeometry {
        &self.geometry
    }

    /// The object's cloud, for a cloud object.
    pub fn cloud(&self) -> Option<&Arc<PointCloud>> {
        self.cloud.as_ref()
    }

    /// The largest distance of the object's geometry from the holding link's
    /// origin.
    pub(crate) fn reach(&self) -> Real {
        self.pose.translation.vector.norm() + self.geometry.radius
    }
}

/// The convex hull of a cloud object's points, as a closed mesh.
fn cloud_hull(name: &str, cloud: &PointCloud) -> Result<Mesh> {
    let degenerate = || {
        Error::invalid(format!(
            "attached object '{name}': the convex hull of its {} points is degenerate \
             (are they collinear or coplanar?)",
            cloud.len()
        ))
    };
    if cloud.len() < 4 {
        return Err(degenerate());
    }
    let (vertices, faces) = try_convex_hull(cloud.points()).map_err(|_| degenerate())?;
    if faces.is_empty() {
        return Err(degenerate());
    }
    let hull = Mesh::new(vertices, faces).map_err(|_| degenerate())?;
    if hull.volume().abs() <= 0.0 {
        return Err(degenerate());
    }
    Ok(hull)
}

impl Robot {
    /// Attaches an object to the link named `link`: it is held at `pose` (the
    /// object's frame in the link's frame) and moves with the link.
    ///
    /// From then on every query of the robot reads the object as it reads a
    /// link: [`collide_robot`](super::collide_robot) queries it against the
    /// environment cloud (its entry in [`RobotCollisionResult::links`](super::RobotCollisionResult::links)
    /// has the index `links().len() + k`, `k` its place in
    /// [`Robot::attached_objects`], and is named `name` by
    /// [`Robot::entry_name`]); [`Robot::self_filter`] removes the points on it;
    /// self-collision checks it against every link with geometry but `link`
    /// and the `touch_links` (MoveIt's touch links: the fingers that grasp
    /// it); [`check_motion`](super::check_motion)'s motion bound covers it.
    /// Attached objects are not checked against each other.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the problem: `link` or a touch link is
    /// not a link of the robot; `name` is empty, or already names an attached
    /// object or a link; `pose` has a non-finite entry; the mesh is rejected
    /// as a link's would be ([`LinkGeometry::new`]); the cloud is empty or
    /// flat (its convex hull has no volume). On error the robot is unchanged.
    pub fn attach(
        &mut self,
        link: &str,
        shape: AttachedShape,
        pose: &Pose,
        name: &str,
        touch_links: &[&str],
    ) -> Result<()> {
        let holder = self.named_link(link, "attach to")?;
        if name.is_empty() {
            return Err(Error::invalid("an attached object needs a non-empty name"));
        }
        if self.attached_index(name).is_some() {
            return Err(Error::invalid(format!(
                "robot '{}' already holds an object named '{name}' (detach it first)",
                self.name
            )));
        }
        if self.link_index(name).is_some() {
            return Err(Error::invalid(format!(
                "'{name}' is a link of robot '{}': an attached object needs a name of its own",
                self.name
            )));
        }
        let t = &pose.translation.vector;
        let q = pose.rotation.quaternion();
        if !t.iter().chain(q.coords.iter()).all(|c| c.is_finite()) {
            return Err(Error::invalid(format!(
                "the pose of attached object '{name}' has a non-finite entry"
            )));
        }
        let mut touch = Vec::with_capacity(touch_links.len());
        for t in touch_links {
            touch.push(self.named_link(t, "touch")?);
        }
        touch.sort_unstable();
        touch.dedup();
        let label = format!("attached object '{name}'");
        let (geometry, cloud) = match shape {
            AttachedShape::Mesh(mesh) => (LinkGeometry::labelled(&label, vec![mesh])?, None),
            AttachedShape::Cloud(cloud) => {
                if cloud.is_empty() {
                    return Err(Error::invalid(format!("{label}: the cloud is empty")));
                }
                let hull = cloud_hull(name, &cloud)?;
                (LinkGeometry::labelled(&label, vec![hull])?, Some(cloud))
            }
        };
        let checked_links = (0..self.links.len())
            .filter(|&l| l != holder && !touch.contains(&l) && self.links[l].geometry.is_some())
            .collect();
        let largest = |v: &[Real]| v.iter().copied().fold(0.0, Real::max);
        let cloud_spread = cloud.as_ref().map_or((0.0, 0.0), |c| {
            (largest(c.spacing()), largest(c.sigma_max()))
        });
        self.attached.push(AttachedObject {
            name: name.to_string(),
            link: holder,
            pose: *pose,
            touch_links: touch,
            checked_links,
            geometry,
            cloud,
            cloud_spread,
        });
        self.attached_changed();
        Ok(())
    }

    /// Detaches the object named `name` and returns it; the other objects
    /// keep their order.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the objects held if the robot holds no
    /// object named `name`.
    pub fn detach(&mut self, name: &str) -> Result<AttachedObject> {
        let k = self.attached_index(name).ok_or_else(|| {
            let held: Vec<&str> = self.attached.iter().map(|o| o.name.as_str()).collect();
            Error::invalid(format!(
                "robot '{}' holds no object named '{name}'; it holds: {}",
                self.name,
                if held.is_empty() {
                    "nothing".to_string()
                } else {
                    held.join(", ")
                }
            ))
        })?;
        let object = self.attached.remove(k);
        self.attached_changed();
        Ok(object)
    }

    /// The objects held, in the order they were attached.
    pub fn attached_objects(&self) -> &[AttachedObject] {
        &self.attached
    }

    /// The place in [`Robot::attached_objects`] of the object named `name`.
    pub fn attached_index(&self, name: &str) -> Option<usize> {
        self.attached.iter().position(|o| o.name == name)
    }

    /// The name of the entry `i` of a query's per-link results and
    /// self-collisions: a link's name for `i < links().len()`, else the name
    /// of the attached object `i - links().len()`.
    pub fn entry_name(&self, i: usize) -> Option<&str> {
        match self.links.get(i) {
            Some(l) => Some(&l.name),
            None => self
                .attached
                .get(i - self.links.len())
                .map(|o| o.name.as_str()),
        }
    }

    /// Every attached object's pose (object frame to world) at configuration
    /// `q`, the root link at `base`: its link's pose composed with its pose in
    /// the link, in [`Robot::attached_objects`] order.
    ///
    /// # Errors
    /// As [`Robot::check_configuration`].
    pub fn attached_poses(&self, q: &[Real], base: &Pose) -> Result<Vec<Pose>> {
        Ok(self.attached_poses_from(&self.link_poses(q, base)?))
    }

    /// The attached objects' poses from the links' poses.
    pub(crate) fn attached_poses_from(&self, link_poses: &[Pose]) -> Vec<Pose> {
        self.attached
            .iter()
            .map(|o| link_poses[o.link] * o.pose)
            .collect()
    }

    /// The number of object-link pairs checked for self-collision.
    pub(crate) fn attached_pairs(&self) -> usize {
        self.attached.iter().map(|o| o.checked_links.len()).sum()
    }

    /// Self-collision of the attached objects at the links' poses: each
    /// object against its checked links (exact shapes), as entries
    /// `(link, links().len() + k)`.
    pub(crate) fn attached_self_collisions(&self, link_poses: &[Pose]) -> Vec<SelfCollision> {
        let n = self.links.len();
        let object_poses = self.attached_poses_from(link_poses);
        let mut out = Vec::new();
        for (k, (object, pose)) in self.attached.iter().zip(&object_poses).enumerate() {
            for &l in &object.checked_links {
                let Some(g) = &self.links[l].geometry else {
                    continue;
                };
                if intersects(&link_poses[l], &g.exact, pose, &object.geometry.exact) {
                    out.push(SelfCollision {
                        link_a: l,
                        link_b: n + k,
                    });
                }
            }
        }
        out
    }

    /// The index of the link named `link`, or an error saying what it was
    /// wanted for.
    fn named_link(&self, link: &str, purpose: &str) -> Result<usize> {
        self.link_index(link).ok_or_else(|| {
            Error::invalid(format!(
                "cannot {purpose} '{link}': robot '{}' has no link of that name; its links: {}",
                self.name,
                self.link_names().join(", ")
            ))
        })
    }

    /// Drops what depends on the objects held: the cached samples and the
    /// motion bound's weights.
    fn attached_changed(&mut self) {
        self.samples.clear();
        self.shadow_samples.clear();
        self.compute_motion_weights();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Point3, Vector3};
    use crate::query::{MeshSide, QueryModel};
    use crate::robot::{collide_robot, RobotRequest};

    /// A base box (0.2 x 0.2 x 0.1 at the origin), a turn about z at
    /// (0, 0, 0.05) holding `arm` (a 0.4 x 0.04 x 0.04 bar from x = 0 to 0.4
    /// at z = 0.1), and a fixed `finger` (a 0.02 cube) at the bar's end.
    const URDF: &str = r#"<robot name="holder">
      <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
      <link name="arm"><collision><origin xyz="0.2 0 0.05"/><geometry><box size="0.4 0.04 0.04"/></geometry></collision></link>
      <link name="finger"><collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision></link>
      <joint name="turn" type="revolute"><parent link="base"/><child link="arm"/>
        <origin xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="weld" type="fixed"><parent link="arm"/><child link="finger"/>
        <origin xyz="0.4 0 0.05"/></joint>
    </robot>"#;

    fn holder() -> Robot {
        Robot::from_urdf_str(URDF, "holder.urdf", None, &[]).unwrap()
    }

    /// A cube of half side `h`.
    fn cube(h: Real) -> Mesh {
        Mesh::cuboid(h, h, h).unwrap()
    }

    /// A held 0.1 m cube at 0.1 m beyond the finger (along the arm).
    fn holding() -> Robot {
        let mut r = holder();
        let pose = Pose::translation(0.1, 0.0, 0.0);
        r.attach("finger", AttachedShape::Mesh(cube(0.05)), &pose, "box", &[])
            .unwrap();
        r
    }

    /// Noisy points on the plane x = `x0` around (x0, 0, z0), 0.4 m square.
    fn wall(x0: Real, z0: Real) -> PointCloud {
        let mut pts = Vec::new();
        for i in 0..41 {
            for j in 0..41 {
                let y = -0.2 + 0.01 * Real::from(i);
                let z = z0 - 0.2 + 0.01 * Real::from(j);
                pts.push(Point3::new(x0, y, z));
            }
        }
        PointCloud::from_sigma(pts, 0.002).unwrap()
    }

    fn err_msg(e: Error) -> String {
        match e {
            Error::InvalidInput(m) => m,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn attached_object_moves_with_its_link() {
        let r = holding();
        let base = Pose::translation(0.3, -0.2, 0.1);
        let finger = r.link_index("finger").unwrap();
        for q in [-1.0, 0.0, 0.7, 2.5] {
            let links = r.link_poses(&[q], &base).unwrap();
            let objects = r.attached_poses(&[q], &base).unwrap();
            let expected = links[finger] * Pose::translation(0.1, 0.0, 0.0);
            assert!((objects[0].to_matrix() - expected.to_matrix()).amax() < 1e-12);
        }
        // At q = 0.5 the box's centre is on the circle of radius 0.5 about z.
        let objects = r.attached_poses(&[0.5], &Pose::identity()).unwrap();
        let c = objects[0].translation.vector;
        assert!((c - Vector3::new(0.5 * 0.5f64.cos(), 0.5 * 0.5f64.sin(), 0.1)).norm() < 1e-12);
    }

    #[test]
    fn held_box_collides_where_the_bare_robot_is_free() {
        // The finger ends at x = 0.41; the held box spans x in [0.45, 0.55].
        let cloud = wall(0.5, 0.1);
        for side in [MeshSide::Exact, MeshSide::Sampled] {
            let request = RobotRequest {
                mesh_side: side,
                ..RobotRequest::default()
            };
            let bare =
                collide_robot(&holder(), &[0.0], &Pose::identity(), &cloud, &request).unwrap();
            assert!(bare.probability < 1e-6, "{side:?}: {}", bare.probability);
            let mut r = holding();
            let held = collide_robot(&r, &[0.0], &Pose::identity(), &cloud, &request).unwrap();
            assert!(held.probability > 0.99, "{side:?}: {}", held.probability);
            let entry = held.links.last().unwrap();
            assert_eq!(r.entry_name(entry.link), Some("box"));
            assert!(entry.probability > 0.99);
            // Turned away, the box misses the wall.
            let turned = collide_robot(&r, &[1.5], &Pose::identity(), &cloud, &request).unwrap();
            assert!(
                turned.probability < 1e-6,
                "{side:?}: {}",
                turned.probability
            );
            let object = r.detach("box").unwrap();
            assert_eq!(object.name(), "box");
            let again = collide_robot(&r, &[0.0], &Pose::identity(), &cloud, &request).unwrap();
            assert_eq!(again.probability, bare.probability);
            assert_eq!(again.links.len(), bare.links.len());
        }
    }

    #[test]
    fn held_cloud_collides_as_a_cloud() {
        let mut r = holder();
        let pts: Vec<Point3> = cube(0.05).sample_surface(2000, 3).unwrap().points.clone();
        let object = Arc::new(PointCloud::from_sigma(pts, 0.001).unwrap());
        let pose = Pose::translation(0.1, 0.0, 0.0);
        r.attach("finger", AttachedShape::Cloud(object), &pose, "scan", &[])
            .unwrap();
        assert!(r.attached_objects()[0].cloud().is_some());
        let cloud = wall(0.5, 0.1);
        let hit = collide_robot(
            &r,
            &[0.0],
            &Pose::identity(),
            &cloud,
            &RobotRequest::default(),
        )
        .unwrap();
        assert!(hit.probability > 0.99, "{}", hit.probability);
        let miss = collide_robot(
            &r,
            &[1.5],
            &Pose::identity(),
            &cloud,
            &RobotRequest::default(),
        )
        .unwrap();
        assert!(miss.probability < 1e-6, "{}", miss.probability);
    }

    #[test]
    fn broad_phase_reads_a_held_cloud_with_its_noise() {
        // A noisy held cloud (sigma 1 cm) 3 cm from the wall: beyond the
        // wall's own reach, within the cloud's (the points model's near rule;
        // the elements model's test reads both clouds' element hulls).
        let mut r = holder();
        let pts = cube(0.05).sample_surface(2000, 3).unwrap().points;
        let object = Arc::new(PointCloud::from_sigma(pts, 0.01).unwrap());
        let pose = Pose::translation(0.1, 0.0, 0.0);
        r.attach("finger", AttachedShape::Cloud(object), &pose, "scan", &[])
            .unwrap();
        let cloud = wall(0.58, 0.1);
        let query = |broad_phase| {
            let mut request = RobotRequest {
                broad_phase,
                ..RobotRequest::default()
            };
            request.collide.model = QueryModel::Points;
            collide_robot(&r, &[0.0], &Pose::identity(), &cloud, &request).unwrap()
        };
        let (with, without) = (query(true), query(false));
        assert!(without.probability > 1e-6, "{}", without.probability);
        assert!(with.links.last().unwrap().queried);
        assert!((with.probability - without.probability).abs() < 1e-9);
    }

    #[test]
    fn held_object_touching_its_link_is_not_self_collision() {
        // A bar beyond the finger (arm frame x in [0.405, 0.505]): it
        // overlaps the finger (its holder), not the arm (x <= 0.4).
        let mut r = holder();
        let bar = Mesh::cuboid(0.05, 0.005, 0.005).unwrap();
        let pose = Pose::translation(0.055, 0.0, 0.0);
        r.attach("finger", AttachedShape::Mesh(bar), &pose, "short", &[])
            .unwrap();
        assert!(r.self_collisions(&[0.0]).unwrap().is_empty());
        // Longer, reaching back into the arm's bar (arm frame x in [0.22, 0.42]).
        let long = Mesh::cuboid(0.1, 0.005, 0.005).unwrap();
        let back = Pose::translation(-0.08, 0.0, 0.0);
        r.attach(
            "finger",
            AttachedShape::Mesh(long.clone()),
            &back,
            "long",
            &[],
        )
        .unwrap();
        let arm = r.link_index("arm").unwrap();
        let n = r.links().len();
        let found = r.self_collisions(&[0.0]).unwrap();
        assert_eq!(
            found,
            [SelfCollision {
                link_a: arm,
                link_b: n + 1
            }]
        );
        assert_eq!(r.entry_name(found[0].link_b), Some("long"));
        // Reported by the query too, and gone with `arm` as a touch link.
        let cloud = wall(2.0, 0.0);
        let q = collide_robot(
            &r,
            &[0.0],
            &Pose::identity(),
            &cloud,
            &RobotRequest::default(),
        )
        .unwrap();
        assert_eq!(q.self_collisions, found);
        r.detach("long").unwrap();
        r.attach("finger", AttachedShape::Mesh(long), &back, "long", &["arm"])
            .unwrap();
        assert!(r.self_collisions(&[0.0]).unwrap().is_empty());
        assert_eq!(r.attached_objects()[1].touch_links(), [arm]);
    }

    #[test]
    fn self_filter_removes_points_on_the_held_object() {
        let r = holding();
        let on_box = Point3::new(0.5, 0.0, 0.1);
        let far = Point3::new(0.5, 0.5, 0.1);
        let f = r.self_filter(&[0.0], &Pose::identity(), 0.01).unwrap();
        assert_eq!(f.apply(&[on_box, far]), [1]);
        let f = holder()
            .self_filter(&[0.0], &Pose::identity(), 0.01)
            .unwrap();
        assert_eq!(f.apply(&[on_box, far]), [0, 1]);
    }

    #[test]
    fn motion_bound_covers_the_held_object() {
        let bare = holder().displacement_bound(&[0.1]);
        let held = holding().displacement_bound(&[0.1]);
        // The box's far corner is ~0.55 m from the turn's axis.
        assert!(held > bare);
        assert!(held >= 0.1 * 0.55, "{held}");
    }

    #[test]
    fn attach_errors_name_the_problem() {
        let mut r = holding();
        let id = Pose::identity();
        let mesh = || AttachedShape::Mesh(cube(0.01));
        let unknown = err_msg(r.attach("hand", mesh(), &id, "x", &[]).unwrap_err());
        assert!(
            unknown.contains("no link of that name") && unknown.contains("'hand'"),
            "{unknown}"
        );
        assert!(unknown.contains("base, arm, finger"), "{unknown}");
        let dup = err_msg(r.attach("arm", mesh(), &id, "box", &[]).unwrap_err());
        assert!(dup.contains("already holds an object named 'box'"), "{dup}");
        let link = err_msg(r.attach("arm", mesh(), &id, "finger", &[]).unwrap_err());
        assert!(link.contains("'finger' is a link"), "{link}");
        let touch = err_msg(r.attach("arm", mesh(), &id, "y", &["palm"]).unwrap_err());
        assert!(touch.contains("cannot touch 'palm'"), "{touch}");
        let mut nan = Pose::identity();
        nan.translation.vector.x = Real::NAN;
        let bad = err_msg(r.attach("arm", mesh(), &nan, "z", &[]).unwrap_err());
        assert!(bad.contains("pose of attached object 'z'"), "{bad}");
        let flat: Vec<Point3> = (0..10)
            .map(|i| Point3::new(Real::from(i), 0.0, 0.0))
            .collect();
        let flat = Arc::new(PointCloud::from_sigma(flat, 0.01).unwrap());
        let degenerate = err_msg(
            r.attach("arm", AttachedShape::Cloud(flat), &id, "w", &[])
                .unwrap_err(),
        );
        assert!(degenerate.contains("degenerate"), "{degenerate}");
        let missing = err_msg(r.detach("cup").unwrap_err());
        assert!(
            missing.contains("no object named 'cup'") && missing.contains("box"),
            "{missing}"
        );
        // Nothing was added by the failed calls.
        assert_eq!(r.attached_objects().len(), 1);
    }
}
