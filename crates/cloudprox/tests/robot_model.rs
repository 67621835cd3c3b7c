//! URDF loading, forward kinematics against hand-computed poses, mesh URIs,
//! and bad input.

use crate::robot_common;

use std::path::PathBuf;

use cloudprox::io::{write_mesh, Encoding};
use cloudprox::prelude::*;
use cloudprox::robot::{JointKind, Robot};
use robot_common::{arm, arm_poses, temp_dir, ARM_URDF};

#[test]
fn names_limits_and_kinds() {
    let r = arm();
    assert_eq!(r.name(), "arm");
    assert_eq!(r.dof(), 4);
    assert_eq!(r.joint_names(), vec!["j1", "j2", "j3", "j5"]);
    assert_eq!(
        r.link_names(),
        vec!["base", "link1", "link2", "link3", "link4", "tool", "wheel"]
    );
    let limits = r.joint_limits();
    assert_eq!(limits[0], [-3.0, 3.0]);
    assert_eq!(limits[1], [-2.0, 2.0]);
    assert_eq!(limits[2], [0.0, 0.1]);
    assert_eq!(limits[3], [f64::NEG_INFINITY, f64::INFINITY]);
    let kinds: Vec<JointKind> = r.joints().iter().map(|j| j.kind).collect();
    assert_eq!(
        kinds,
        vec![
            JointKind::Revolute,
            JointKind::Revolute,
            JointKind::Prismatic,
            JointKind::Prismatic,
            JointKind::Fixed,
            JointKind::Continuous
        ]
    );
    let mimic = r.joints()[3].mimic.unwrap();
    assert_eq!((mimic.dof, mimic.multiplier, mimic.offset), (2, 2.0, 0.01));
    assert!(r.links()[6].geometry.is_none());
}

#[test]
fn forward_kinematics_matches_hand_computed_poses() {
    let r = arm();
    let configs = [
        [0.0, 0.0, 0.0, 0.0],
        [0.7, -0.4, 0.05, 2.0],
        [-2.5, 1.9, 0.1, -7.0],
        [3.0, -2.0, 0.0, 100.0],
    ];
    for q in configs {
        let poses = r.link_poses(&q, &Pose::identity()).unwrap();
        let expected = arm_poses(&q);
        for (l, (pose, (rot, t))) in poses.iter().zip(&expected).enumerate() {
            let got_r = pose.rotation.to_rotation_matrix();
            assert!(
                (got_r.matrix() - rot).abs().max() < 1e-12,
                "link {l} rotation at {q:?}"
            );
            assert!(
                (pose.translation.vector - t).abs().max() < 1e-12,
                "link {l} translation at {q:?}: {:?} vs {t:?}",
                pose.translation.vector
            );
        }
    }
}

#[test]
fn base_pose_moves_every_link() {
    let r = arm();
    let q = [0.3, 0.2, 0.04, 1.0];
    let base = Pose::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.1, 0.2, -0.3));
    let at_origin = r.link_poses(&q, &Pose::identity()).unwrap();
    let moved = r.link_poses(&q, &base).unwrap();
    for (a, b) in at_origin.iter().zip(&moved) {
        let want = base * a;
        assert!((want.to_homogeneous() - b.to_homogeneous()).abs().max() < 1e-12);
    }
}

#[test]
fn primitive_geometry_has_the_urdf_sizes() {
    let r = arm();
    let g = |i: usize| r.links()[i].geometry.as_ref().unwrap();
    // Box base: 0.2 x 0.2 x 0.1, volume 0.004.
    assert!((g(0).mesh.volume() - 0.004).abs() < 1e-12);
    // Cylinder link1 from z = 0 to 0.2 (origin applied), radius 0.03 (32-gon).
    let b = g(1).aabb;
    assert!((b.mins.z - 0.0).abs() < 1e-12 && (b.maxs.z - 0.2).abs() < 1e-12);
    assert!((b.maxs.x - 0.03).abs() < 1e-12);
    // Spheres and the capsule: vertices on the surface, closed, convex.
    for (i, radius) in [(3, 0.03), (4, 0.02)] {
        let m = &g(i).mesh;
        assert!(m.is_closed() && m.is_convex(1e-12));
        for v in m.vertices() {
            assert!((v.coords.norm() - radius).abs() < 1e-12);
        }
        let exact = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
        assert!(m.volume() < exact && m.volume() > 0.95 * exact);
    }
    let cap = &g(5).mesh;
    assert!(cap.is_closed() && cap.is_convex(1e-12));
    let b = cap.aabb();
    // Capsule along the link's z: length 0.04 plus two caps of 0.01.
    assert!((b.maxs.z - 0.03).abs() < 1e-12 && (b.mins.z + 0.03).abs() < 1e-12);
}

#[test]
fn configuration_errors_name_the_joint() {
    let r = arm();
    let e = r.link_poses(&[0.0, 0.0], &Pose::identity()).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Shape {
                expected: 4,
                got: 2,
                ..
            }
        ),
        "{e}"
    );
    let e = r
        .link_poses(&[0.0, 2.5, 0.0, 0.0], &Pose::identity())
        .unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("j2") && msg.contains("outside its limits"),
        "{msg}"
    );
    let e = r
        .link_poses(&[0.0, 0.0, f64::NAN, 0.0], &Pose::identity())
        .unwrap_err();
    assert!(e.to_string().contains("j3") && e.to_string().contains("not finite"));
    // Continuous joints have no limits.
    assert!(r
        .link_poses(&[0.0, 0.0, 0.0, 1e3], &Pose::identity())
        .is_ok());
    // Clamping is on request only.
    assert_eq!(r.clamp(&[5.0, -5.0, 0.5, 9.0]), vec![3.0, -2.0, 0.1, 9.0]);
}

fn write_box_stl(dir: &std::path::Path, rel: &str) -> PathBuf {
    let path = dir.join(rel);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let mesh = Mesh::cuboid(0.05, 0.02, 0.01).unwrap();
    write_mesh(&path, &mesh, None, Encoding::BinaryLittleEndian).unwrap();
    path
}

fn one_mesh_urdf(uri: &str, scale: Option<&str>) -> String {
    let scale = scale.map_or(String::new(), |s| format!(" scale=\"{s}\""));
    format!(
        r#"<robot name="m"><link name="base"><collision><geometry>
        <mesh filename="{uri}"{scale}/></geometry></collision></link></robot>"#
    )
}

#[test]
fn mesh_uris_resolve_against_package_dirs_and_the_urdf_folder() {
    let dir = temp_dir("uris");
    write_box_stl(&dir, "share/my_robot/meshes/part.stl");
    write_box_stl(&dir, "urdf_dir/meshes/rel.stl");
    // package:// against a folder holding the package.
    let urdf = dir.join("urdf_dir/robot.urdf");
    std::fs::write(
        &urdf,
        one_mesh_urdf("package://my_robot/meshes/part.stl", None),
    )
    .unwrap();
    let r = Robot::from_urdf_file(&urdf, &[dir.join("share")]).unwrap();
    assert!((r.links()[0].geometry.as_ref().unwrap().mesh.volume() - 8e-5).abs() < 1e-9);
    // ... and against the package's own folder.
    assert!(Robot::from_urdf_file(&urdf, &[dir.join("share/my_robot")]).is_ok());
    // Without package_dirs the error names the link and the URI.
    let e = Robot::from_urdf_file(&urdf, &[]).unwrap_err();
    match &e {
        Error::Io {
            kind,
            message,
            path,
        } => {
            assert_eq!(*kind, std::io::ErrorKind::NotFound);
            assert!(path.contains("package://my_robot/meshes/part.stl"));
            assert!(message.contains("link 'base'"), "{message}");
        }
        other => panic!("expected Io, got {other:?}"),
    }
    // Relative, file:// relative and file:// absolute paths, with a scale.
    for uri in [
        "meshes/rel.stl".to_string(),
        "file://meshes/rel.stl".to_string(),
        format!("file://{}", dir.join("urdf_dir/meshes/rel.stl").display()),
    ] {
        std::fs::write(&urdf, one_mesh_urdf(&uri, Some("2 1 3"))).unwrap();
        let r = Robot::from_urdf_file(&urdf, &[]).unwrap();
        let g = r.links()[0].geometry.as_ref().unwrap();
        assert!((g.mesh.volume() - 8e-5 * 6.0).abs() < 1e-9, "{uri}");
        assert!(
            (g.aabb.maxs - Point3::new(0.1, 0.02, 0.03)).norm() < 1e-6,
            "{uri}"
        );
    }
    // A mirroring scale keeps the mesh outward.
    std::fs::write(&urdf, one_mesh_urdf("meshes/rel.stl", Some("-1 1 1"))).unwrap();
    let r = Robot::from_urdf_file(&urdf, &[]).unwrap();
    assert!(r.links()[0].geometry.as_ref().unwrap().mesh.volume() > 0.0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn unsupported_and_malformed_files_are_named() {
    let dir = temp_dir("bad");
    std::fs::write(dir.join("visual.dae"), "<COLLADA/>").unwrap();
    let urdf = dir.join("r.urdf");
    std::fs::write(&urdf, one_mesh_urdf("visual.dae", None)).unwrap();
    let e = Robot::from_urdf_file(&urdf, &[]).unwrap_err();
    assert!(e.to_string().contains("COLLADA"), "{e}");
    let e = Robot::from_urdf_file(&dir.join("missing.urdf"), &[]).unwrap_err();
    assert!(matches!(
        e,
        Error::Io {
            kind: std::io::ErrorKind::NotFound,
            ..
        }
    ));
    std::fs::remove_dir_all(&dir).ok();

    let bad = |xml: &str| {
        Robot::from_urdf_str(xml, "t.urdf", None, &[])
            .unwrap_err()
            .to_string()
    };
    let msg = bad("<robot name='x'><link name='a'>");
    assert!(msg.contains("t.urdf") && msg.contains("URDF"), "{msg}");
    let msg = bad(&ARM_URDF.replace("<parent link=\"link1\"/>", "<parent link=\"nope\"/>"));
    assert!(msg.contains("j2") && msg.contains("nope"), "{msg}");
    let msg = bad(&ARM_URDF.replace("type=\"continuous\"", "type=\"floating\""));
    assert!(msg.contains("j5") && msg.contains("not supported"), "{msg}");
    let msg = bad(&ARM_URDF.replace("<mimic joint=\"j3\"", "<mimic joint=\"j9\""));
    assert!(msg.contains("j4") && msg.contains("j9"), "{msg}");
    let msg = bad(&ARM_URDF.replace(
        "<limit lower=\"-2\" upper=\"2\" effort=\"1\" velocity=\"1\"/>",
        "",
    ));
    assert!(msg.contains("j2") && msg.contains("no <limit>"), "{msg}");
    let msg = bad(&ARM_URDF.replace("lower=\"-3\" upper=\"3\"", "lower=\"3\" upper=\"-3\""));
    assert!(
        msg.contains("j1") && msg.contains("not an interval"),
        "{msg}"
    );
    // Two roots.
    let msg = bad(&ARM_URDF.replace(
        "<link name=\"wheel\"/>",
        "<link name=\"wheel\"/><link name=\"stray\"/>",
    ));
    assert!(msg.contains("2 roots") && msg.contains("stray"), "{msg}");
    // A link with two parents.
    let msg = bad(&ARM_URDF.replace("<child link=\"wheel\"/>", "<child link=\"link3\"/>"));
    assert!(msg.contains("link3") && msg.contains("two joints"), "{msg}");
}

#[test]
fn mimic_chains_compose() {
    let xml = ARM_URDF
        .replace(
            "<link name=\"wheel\"/>",
            "<link name=\"wheel\"/><link name=\"m2\"/>",
        )
        .replace(
            "</robot>",
            r#"<joint name="j6" type="revolute"><parent link="link2"/><child link="m2"/>
           <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
           <mimic joint="j4" multiplier="-3" offset="0.5"/></joint></robot>"#,
        );
    let r = Robot::from_urdf_str(&xml, "t.urdf", None, &[]).unwrap();
    // j6 = -3 * (2 * j3 + 0.01) + 0.5
    let m = r.joints()[6].mimic.unwrap();
    assert_eq!(m.dof, 2);
    assert!((m.multiplier + 6.0).abs() < 1e-15 && (m.offset - 0.47).abs() < 1e-15);
    let q = [0.0, 0.0, 0.05, 0.0];
    let poses = r.link_poses(&q, &Pose::identity()).unwrap();
    let angle: f64 = -3.0 * (2.0 * 0.05 + 0.01) + 0.5;
    let rel = poses[2].inverse() * poses[7];
    assert!((rel.rotation.angle() - angle.abs()).abs() < 1e-12);
}

#[test]
fn adjacent_links_are_not_checked_for_self_collision() {
    let r = arm();
    let name = |(a, b): (usize, usize)| (r.link_names()[a], r.link_names()[b]);
    let ignored: Vec<_> = r.ignored_pairs().iter().map(|&p| name(p)).collect();
    for pair in [
        ("base", "link1"),
        ("link1", "link2"),
        ("link2", "link3"),
        ("link2", "tool"),
    ] {
        assert!(ignored.contains(&pair), "{pair:?} not in {ignored:?}");
    }
    let checked: Vec<_> = r.self_collision_pairs().iter().map(|&p| name(p)).collect();
    assert!(checked.contains(&("base", "link2")), "{checked:?}");
    assert!(!checked.iter().any(|p| ignored.contains(p)));
}
