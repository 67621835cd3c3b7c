//! Loading a robot from a URDF file (parsed by `urdf-rs`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::cache::SpacingCache;
use super::geometry::{capsule_mesh, sphere_mesh, LinkGeometry, CIRCLE_SEGMENTS};
use super::model::{Joint, JointKind, Link, Mimic, Robot};
use crate::error::{Error, Result};
use crate::io::read_mesh;
use crate::math::{Point3, Pose, Vector3};
use crate::query::exact::intersects;
use crate::shape::Mesh;
use crate::Real;

/// Where a URDF's files are looked for.
struct Resolver<'a> {
    urdf: String,
    base_dir: Option<&'a Path>,
    package_dirs: &'a [PathBuf],
}

impl Resolver<'_> {
    fn format_error(&self, problem: impl Into<String>) -> Error {
        Error::format(&self.urdf, "URDF", problem)
    }

    /// The candidate paths of a mesh URI, in the order they are tried.
    fn candidates(&self, uri: &str) -> Vec<PathBuf> {
        let mut out = Vec::new();
        if let Some(rest) = uri.strip_prefix("package://") {
            let (package, inner) = rest.split_once('/').unwrap_or((rest, ""));
            for dir in self.package_dirs {
                out.push(dir.join(package).join(inner));
                if dir.file_name().is_some_and(|n| n == package) {
                    out.push(dir.join(inner));
                }
            }
            if let Some(base) = self.base_dir {
                // The URDF inside its own package (any ancestor named after it),
                // then the package's folders beside the URDF.
                for anc in base.ancestors() {
                    if anc.file_name().is_some_and(|n| n == package) {
                        out.push(anc.join(inner));
                    }
                }
                out.push(base.join(package).join(inner));
                out.push(base.join(inner));
            }
        } else {
            let path = uri.strip_prefix("file://").unwrap_or(uri);
            let p = Path::new(path);
            if p.is_absolute() {
                out.push(p.to_path_buf());
            } else if let Some(base) = self.base_dir {
                out.push(base.join(p));
            } else {
                out.push(p.to_path_buf());
            }
        }
        out
    }

    /// The mesh of a `<mesh filename=...>` of link `link`.
    fn mesh(&self, link: &str, uri: &str) -> Result<Mesh> {
        let candidates = self.candidates(uri);
        let Some(path) = candidates.iter().find(|p| p.is_file()) else {
            let tried: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
            return Err(Error::Io {
                path: uri.to_string(),
                kind: std::io::ErrorKind::NotFound,
                message: format!(
                    "mesh of link '{link}' in {} not found (tried: {}; give package_dirs for package:// URIs)",
                    self.urdf,
                    tried.join(", ")
                ),
            });
        };
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if ext == "dae" {
            return Err(Error::format(
                &path.display().to_string(),
                "mesh",
                format!(
                    "link '{link}': COLLADA (.dae) meshes are not supported (no maintained \
                     COLLADA reader is used by cloudprox); convert it to STL, OBJ, PLY or OFF"
                ),
            ));
        }
        let data = read_mesh(path, None).map_err(|e| match e {
            Error::Format {
                path,
                format,
                problem,
            } => Error::Format {
                path,
                format,
                problem: format!("{problem} (mesh of link '{link}')"),
            },
            other => other,
        })?;
        Ok(data.mesh)
    }
}

fn pose_of(p: &urdf_rs::Pose) -> Option<Pose> {
    let [x, y, z] = *p.xyz;
    let [r, pi, ya] = *p.rpy;
    if ![x, y, z, r, pi, ya].iter().all(|v| v.is_finite()) {
        return None;
    }
    let rotation = nalgebra::UnitQuaternion::from_euler_angles(r, pi, ya);
    Some(Pose::from_parts(
        nalgebra::Translation3::new(x, y, z),
        rotation,
    ))
}

fn geometry_mesh(res: &Resolver<'_>, link: &str, g: &urdf_rs::Geometry) -> Result<Mesh> {
    let named = |e: Error| Error::format(&res.urdf, "URDF", format!("link '{link}': {e}"));
    match g {
        urdf_rs::Geometry::Box { size } => {
            Mesh::cuboid(0.5 * size[0], 0.5 * size[1], 0.5 * size[2]).map_err(named)
        }
        urdf_rs::Geometry::Cylinder { radius, length } => {
            Mesh::cylinder(*radius, 0.5 * length, CIRCLE_SEGMENTS).map_err(named)
        }
        urdf_rs::Geometry::Capsule { radius, length } => {
            capsule_mesh(*radius, *length).map_err(named)
        }
        urdf_rs::Geometry::Sphere { radius } => sphere_mesh(*radius).map_err(named),
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let mesh = res.mesh(link, filename)?;
            let Some(s) = scale else { return Ok(mesh) };
            let s = Vector3::new(s[0], s[1], s[2]);
            if !s.iter().all(|v| v.is_finite() && *v != 0.0) {
                return Err(res.format_error(format!(
                    "link '{link}': mesh scale must be finite and non-zero, got {:?}",
                    s.as_slice()
                )));
            }
            let vertices: Vec<Point3> = mesh
                .vertices()
                .iter()
                .map(|v| Point3::from(v.coords.component_mul(&s)))
                .collect();
            let mut faces = mesh.faces().to_vec();
            // A mirroring scale turns the faces inside out: turn them back.
            if s.x * s.y * s.z < 0.0 {
                for f in &mut faces {
                    f.swap(1, 2);
                }
            }
            Mesh::new(vertices, faces).map_err(named)
        }
    }
}

/// A joint's unit axis (zero for a fixed joint).
fn joint_axis(res: &Resolver<'_>, j: &urdf_rs::Joint, kind: JointKind) -> Result<Vector3> {
    if kind == JointKind::Fixed {
        return Ok(Vector3::zeros());
    }
    let axis = Vector3::new(j.axis.xyz[0], j.axis.xyz[1], j.axis.xyz[2]);
    let n = axis.norm();
    if !(n.is_finite() && n > 0.0) {
        return Err(res.format_error(format!(
            "joint '{}': <axis xyz> must be a finite non-zero vector, got {:?}",
            j.name,
            axis.as_slice()
        )));
    }
    Ok(axis / n)
}

/// A joint's position limits: none for a continuous joint, zero for a fixed
/// one, its `<limit>` (required, an interval) otherwise.
fn joint_limits(res: &Resolver<'_>, j: &urdf_rs::Joint, kind: JointKind) -> Result<[Real; 2]> {
    let l = &j.limit;
    match kind {
        JointKind::Fixed => Ok([0.0, 0.0]),
        JointKind::Continuous => Ok([Real::NEG_INFINITY, Real::INFINITY]),
        JointKind::Revolute | JointKind::Prismatic => {
            if l.lower == 0.0 && l.upper == 0.0 && l.velocity == 0.0 && l.effort == 0.0 {
                return Err(res.format_error(format!(
                    "{} joint '{}' has no <limit> (URDF requires one)",
                    kind.name(),
                    j.name
                )));
            }
            if !(l.lower.is_finite() && l.upper.is_finite() && l.lower <= l.upper) {
                return Err(res.format_error(format!(
                    "joint '{}': limits [{}, {}] are not an interval",
                    j.name, l.lower, l.upper
                )));
            }
            Ok([l.lower, l.upper])
        }
    }
}

/// The joints in tree order (breadth first from the `root` link); an error
/// naming the joints the root does not reach.
fn tree_order(
    res: &Resolver<'_>,
    links: &[Link],
    joints: &[Joint],
    root: usize,
) -> Result<Vec<usize>> {
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
    for (i, j) in joints.iter().enumerate() {
        children[j.parent].push(i);
    }
    let mut order = Vec::with_capacity(joints.len());
    let mut queue = std::collections::VecDeque::from([root]);
    while let Some(l) = queue.pop_front() {
        for &j in &children[l] {
            order.push(j);
            queue.push_back(joints[j].child);
        }
    }
    if order.len() != joints.len() {
        let stray: Vec<&str> = (0..joints.len())
            .filter(|j| !order.contains(j))
            .map(|j| joints[j].name.as_str())
            .collect();
        return Err(res.format_error(format!(
            "joints not reachable from the root link '{}' (a cycle): {}",
            links[root].name,
            stray.join(", ")
        )));
    }
    Ok(order)
}

fn link_geometry(res: &Resolver<'_>, link: &urdf_rs::Link) -> Result<Option<LinkGeometry>> {
    if link.collision.is_empty() {
        return Ok(None);
    }
    let mut parts = Vec::with_capacity(link.collision.len());
    for (k, c) in link.collision.iter().enumerate() {
        let origin = pose_of(&c.origin).ok_or_else(|| {
            res.format_error(format!(
                "link '{}': collision {k} has a non-finite <origin>",
                link.name
            ))
        })?;
        parts.push(geometry_mesh(res, &link.name, &c.geometry)?.transformed(&origin));
    }
    LinkGeometry::new(&link.name, parts).map(Some)
}

fn joint_kind(res: &Resolver<'_>, j: &urdf_rs::Joint) -> Result<JointKind> {
    Ok(match j.joint_type {
        urdf_rs::JointType::Revolute => JointKind::Revolute,
        urdf_rs::JointType::Continuous => JointKind::Continuous,
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        urdf_rs::JointType::Fixed => JointKind::Fixed,
        ref other => {
            return Err(res.format_error(format!(
            "joint '{}': type {other:?} is not supported (revolute, continuous, prismatic, fixed)",
            j.name
        )))
        }
    })
}

impl Robot {
    /// Loads a robot from a URDF file. Mesh URIs are resolved as in ROS tools:
    /// `package://NAME/PATH` as `DIR/NAME/PATH` (or `DIR/PATH` when `DIR` is
    /// named `NAME`) for each of `package_dirs`, then against the URDF's own
    /// folders (an ancestor named `NAME`, or the URDF's folder); `file://PATH`
    /// and plain paths as absolute, or relative to the URDF's folder.
    ///
    /// # Errors
    /// [`Error::Io`] if the URDF or a mesh cannot be found or read (the message
    /// names the link and the paths tried); [`Error::Format`] for malformed XML,
    /// an unsupported joint type or mesh format (COLLADA), a joint naming an
    /// unknown link, a link with two parents, no single root or a cycle, a
    /// revolute or prismatic joint without limits, a bad mimic; all name the
    /// file and the joint or link.
    pub fn from_urdf_file(path: &Path, package_dirs: &[PathBuf]) -> Result<Self> {
        let xml = std::fs::read_to_string(path).map_err(|e| Error::io(path, &e))?;
        Self::from_urdf_str(
            &xml,
            &path.display().to_string(),
            path.parent(),
            package_dirs,
        )
    }

    /// Loads a robot from URDF text. `name` stands for the file in errors;
    /// relative mesh paths are resolved against `base_dir` (see
    /// [`Robot::from_urdf_file`]).
    ///
    /// # Errors
    /// As [`Robot::from_urdf_file`].
    pub fn from_urdf_str(
        xml: &str,
        name: &str,
        base_dir: Option<&Path>,
        package_dirs: &[PathBuf],
    ) -> Result<Self> {
        let res = Resolver {
            urdf: name.to_string(),
            base_dir,
            package_dirs,
        };
        let parsed = urdf_rs::read_from_string(xml).map_err(|e| res.format_error(e.to_string()))?;
        if parsed.links.is_empty() {
            return Err(res.format_error("no <link>"));
        }
        let mut link_index = HashMap::new();
        for (i, l) in parsed.links.iter().enumerate() {
            if link_index.insert(l.name.as_str(), i).is_some() {
                return Err(res.format_error(format!("two links are named '{}'", l.name)));
            }
        }
        let mut joint_index = HashMap::new();
        for (i, j) in parsed.joints.iter().enumerate() {
            if joint_index.insert(j.name.as_str(), i).is_some() {
                return Err(res.format_error(format!("two joints are named '{}'", j.name)));
            }
        }
        let mut links: Vec<Link> = Vec::with_capacity(parsed.links.len());
        for l in &parsed.links {
            links.push(Link {
                name: l.name.clone(),
                parent_joint: None,
                geometry: link_geometry(&res, l)?,
            });
        }
        let mut joints = Vec::with_capacity(parsed.joints.len());
        let mut dof_joints = Vec::new();
        for (i, j) in parsed.joints.iter().enumerate() {
            let kind = joint_kind(&res, j)?;
            let find = |which: &str, name: &str| {
                link_index.get(name).copied().ok_or_else(|| {
                    res.format_error(format!(
                        "joint '{}': {which} link '{name}' is not defined",
                        j.name
                    ))
                })
            };
            let parent = find("parent", &j.parent.link)?;
            let child = find("child", &j.child.link)?;
            if let Some(other) = links[child].parent_joint {
                return Err(res.format_error(format!(
                    "link '{}' is the child of two joints ('{}' and '{}')",
                    j.child.link, parsed.joints[other].name, j.name
                )));
            }
            links[child].parent_joint = Some(i);
            let origin = pose_of(&j.origin).ok_or_else(|| {
                res.format_error(format!("joint '{}': non-finite <origin>", j.name))
            })?;
            let axis = joint_axis(&res, j, kind)?;
            let limits = joint_limits(&res, j, kind)?;
            let dof = if kind != JointKind::Fixed && j.mimic.is_none() {
                dof_joints.push(i);
                Some(dof_joints.len() - 1)
            } else {
                None
            };
            joints.push(Joint {
                name: j.name.clone(),
                kind,
                parent,
                child,
                origin,
                axis,
                limits,
                mimic: None,
                dof,
            });
        }
        resolve_mimics(&res, &parsed, &joint_index, &mut joints)?;
        let roots: Vec<usize> = (0..links.len())
            .filter(|&l| links[l].parent_joint.is_none())
            .collect();
        if roots.len() != 1 {
            let names: Vec<&str> = roots.iter().map(|&r| links[r].name.as_str()).collect();
            return Err(res.format_error(format!(
                "a robot is one tree of links with one root, found {} roots: {}",
                roots.len(),
                if names.is_empty() {
                    "none (the joints form a cycle)".to_string()
                } else {
                    names.join(", ")
                }
            )));
        }
        let root = roots[0];
        let order = tree_order(&res, &links, &joints, root)?;
        let mut robot = Robot {
            name: parsed.name.clone(),
            links,
            joints,
            root,
            order,
            dof_joints,
            self_pairs: Vec::new(),
            ignored_pairs: Vec::new(),
            motion_weights: Vec::new(),
            attached: Vec::new(),
            samples: SpacingCache::default(),
            shadow_samples: SpacingCache::default(),
        };
        robot.compute_motion_weights();
        robot.compute_self_pairs();
        Ok(robot)
    }

    /// Splits the link pairs with geometry into those checked for
    /// self-collision and those ignored (see [`Robot::ignored_pairs`]).
    fn compute_self_pairs(&mut self) {
        let with_geometry: Vec<usize> = (0..self.links.len())
            .filter(|&l| self.links[l].geometry.is_some())
            .collect();
        // The nearest ancestor with geometry of each link.
        let geometric_parent = |mut l: usize| -> Option<usize> {
            loop {
                let j = self.links[l].parent_joint?;
                l = self.joints[j].parent;
                if self.links[l].geometry.is_some() {
                    return Some(l);
                }
            }
        };
        let q0 = self.reference_configuration();
        let poses = self.link_poses_unchecked(&q0, &Pose::identity());
        let mut checked = Vec::new();
        let mut ignored = Vec::new();
        for (x, &a) in with_geometry.iter().enumerate() {
            for &b in &with_geometry[x + 1..] {
                let adjacent = geometric_parent(a) == Some(b) || geometric_parent(b) == Some(a);
                let touching = || {
                    let (ga, gb) = (
                        self.links[a].geometry.as_ref().map(|g| &g.exact),
                        self.links[b].geometry.as_ref().map(|g| &g.exact),
                    );
                    match (ga, gb) {
                        (Some(ga), Some(gb)) => intersects(&poses[a], ga, &poses[b], gb),
                        _ => false,
                    }
                };
                if adjacent || touching() {
                    ignored.push((a, b));
                } else {
                    checked.push((a, b));
                }
            }
        }
        self.self_pairs = checked;
        self.ignored_pairs = ignored;
    }
}

/// Fills in every mimic joint, chains of mimics composed.
fn resolve_mimics(
    res: &Resolver<'_>,
    parsed: &urdf_rs::Robot,
    joint_index: &HashMap<&str, usize>,
    joints: &mut [Joint],
) -> Result<()> {
    for (i, j) in parsed.joints.iter().enumerate() {
        let Some(m) = &j.mimic else { continue };
        if joints[i].kind == JointKind::Fixed {
            return Err(res.format_error(format!(
                "joint '{}': a fixed joint cannot mimic another",
                j.name
            )));
        }
        let (mut multiplier, mut offset) = (1.0, 0.0);
        let mut current = i;
        let mut steps = 0;
        let direct = loop {
            let Some(mm) = &parsed.joints[current].mimic else {
                break None;
            };
            let target = *joint_index.get(mm.joint.as_str()).ok_or_else(|| {
                res.format_error(format!(
                    "joint '{}' mimics joint '{}', which is not defined",
                    parsed.joints[current].name, mm.joint
                ))
            })?;
            let (k, c) = (mm.multiplier.unwrap_or(1.0), mm.offset.unwrap_or(0.0));
            if !(k.is_finite() && c.is_finite()) {
                return Err(res.format_error(format!(
                    "joint '{}': mimic multiplier and offset must be finite",
                    parsed.joints[current].name
                )));
            }
            // value(current) = k * value(target) + c
            offset += multiplier * c;
            multiplier *= k;
            current = target;
            steps += 1;
            if steps > joints.len() {
                return Err(
                    res.format_error(format!("joint '{}': its mimic joints form a cycle", j.name))
                );
            }
            if joints[current].dof.is_some() {
                break Some(current);
            }
        };
        let Some(master) = direct else {
            return Err(res.format_error(format!(
                "joint '{}' mimics a chain ending at fixed joint '{}'",
                j.name, parsed.joints[current].name
            )));
        };
        // Both hold by the loop above (the mimicked joint exists, the chain
        // ends at a joint with a degree of freedom); an error, not a panic,
        // if that ever changes.
        let (Some(&target), Some(dof)) = (joint_index.get(m.joint.as_str()), joints[master].dof)
        else {
            return Err(res.format_error(format!(
                "joint '{}' mimics '{}', which has no degree of freedom",
                j.name, m.joint
            )));
        };
        joints[i].mimic = Some(Mimic {
            joint: target,
            dof,
            multiplier,
            offset,
        });
    }
    Ok(())
}
