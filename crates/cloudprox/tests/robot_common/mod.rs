//! The small test robot of the robot tests and its analytic kinematics.
#![allow(dead_code)]

use std::path::PathBuf;

use cloudprox::prelude::*;
use cloudprox::robot::Robot;
use cloudprox::sample::add_noise;

/// A three-joint arm on a box base:
/// * `base` (root): a 0.2 x 0.2 x 0.1 box centred at the origin;
/// * `j1` revolute about z at (0, 0, 0.1), limits [-3, 3] -> `link1`: a cylinder of
///   radius 0.03 and length 0.2 from z = 0 to 0.2;
/// * `j2` revolute about y at (0, 0, 0.2) -> `link2`: a 0.3 x 0.04 x 0.04 box from
///   x = 0 to 0.3, limits [-2, 2];
/// * `j3` prismatic along x at (0.3, 0, 0), limits [0, 0.1] -> `link3`: a sphere of
///   radius 0.03;
/// * `j4` prismatic along y at (0.3, 0, 0), mimic of `j3` (x 2, + 0.01) -> `link4`:
///   a sphere of radius 0.02;
/// * `tool_joint` fixed at (0.3, 0, 0.05), rpy (0, 0, pi/2) -> `tool`: a capsule of
///   radius 0.01 and length 0.04;
/// * `j5` continuous about z on the base at (0, 0.3, 0) -> `wheel` (no geometry).
pub const ARM_URDF: &str = r#"<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="link1">
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.03" length="0.2"/></geometry></collision>
  </link>
  <link name="link2">
    <collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry></collision>
  </link>
  <link name="link3">
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="link4">
    <collision><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <link name="tool">
    <collision><geometry><capsule radius="0.01" length="0.04"/></geometry></collision>
  </link>
  <link name="wheel"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="j3" type="prismatic">
    <parent link="link2"/><child link="link3"/>
    <origin xyz="0.3 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/>
  </joint>
  <joint name="j4" type="prismatic">
    <parent link="link2"/><child link="link4"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.3" effort="1" velocity="1"/>
    <mimic joint="j3" multiplier="2" offset="0.01"/>
  </joint>
  <joint name="tool_joint" type="fixed">
    <parent link="link2"/><child link="tool"/>
    <origin xyz="0.3 0 0.05" rpy="0 0 1.5707963267948966"/>
  </joint>
  <joint name="j5" type="continuous">
    <parent link="base"/><child link="wheel"/>
    <origin xyz="0 0.3 0"/><axis xyz="0 0 1"/>
  </joint>
</robot>
"#;

/// The arm, loaded from text.
pub fn arm() -> Robot {
    Robot::from_urdf_str(ARM_URDF, "arm.urdf", None, &[]).unwrap()
}

fn rz(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn ry(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Hand-computed poses (rotation, translation) of the arm's links at
/// `q = [j1, j2, j3, j5]`, root at the identity, in link order
/// (base, link1, link2, link3, link4, tool, wheel).
pub fn arm_poses(q: &[f64]) -> Vec<(Matrix3, Vector3)> {
    let (a, b, c, w) = (q[0], q[1], q[2], q[3]);
    let r2 = rz(a) * ry(b);
    let o2 = Vector3::new(0.0, 0.0, 0.3);
    vec![
        (Matrix3::identity(), Vector3::zeros()),
        (rz(a), Vector3::new(0.0, 0.0, 0.1)),
        (r2, o2),
        (r2, o2 + r2 * Vector3::new(0.3 + c, 0.0, 0.0)),
        (r2, o2 + r2 * Vector3::new(0.3, 2.0 * c + 0.01, 0.0)),
        (
            r2 * rz(std::f64::consts::FRAC_PI_2),
            o2 + r2 * Vector3::new(0.3, 0.0, 0.05),
        ),
        (rz(w), Vector3::new(0.0, 0.3, 0.0)),
    ]
}

/// A noisy square patch of the plane `x = x0` (1 cm grid, `half` metres around
/// `(x0, 0, z0)` in y and z), isotropic noise `sigma`.
pub fn wall(x0: f64, z0: f64, half: f64, sigma: f64, seed: u64) -> PointCloud {
    let n = (2.0 * half / 0.01).round() as i64;
    let mut pts = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            pts.push(Point3::new(
                x0,
                -half + i as f64 * 0.01,
                z0 - half + j as f64 * 0.01,
            ));
        }
    }
    PointCloud::from_sigma(add_noise(&pts, sigma, seed), sigma).unwrap()
}

/// A fresh empty folder under the system's temporary folder.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "cloudprox-robot-{name}-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Asserts that two robot results give the same `P`, and each link the same
/// probability and state (`what` names the case in a failure).
pub fn assert_same_answer(
    a: &cloudprox::robot::RobotCollisionResult,
    b: &cloudprox::robot::RobotCollisionResult,
    what: &str,
) {
    assert_eq!(a.probability, b.probability, "{what}");
    for (x, y) in a.links.iter().zip(&b.links) {
        assert_eq!(x.probability, y.probability, "{what} link {}", x.link);
        assert_eq!(x.state, y.state, "{what} link {}", x.link);
    }
}
