//! Robot links as exact sides (`MeshSide::Exact`, the default): each link's
//! cached signed distance against the environment cloud, the broad phase
//! before any signed distance, and agreement with sampled links where the
//! answer is clear.

use crate::robot_common;

use cloudprox::prelude::*;
use cloudprox::query::exact_side::collide_exact_cloud;
use cloudprox::query::MeshSide;
use cloudprox::robot::{
    check_motion, collide_robot, collide_robot_many, MotionRequest, Robot, RobotCollisionResult,
    RobotRequest,
};
use cloudprox::sample::add_noise;
use robot_common::{arm, wall};

const SIGMA: f64 = 0.001;
/// Half the height of the paddle's box.
const HALF_Z: f64 = 0.02;

/// A box on a vertical slider above a turntable: `world` (no geometry),
/// `lift` prismatic along z -> `carriage` (no geometry), `turn` revolute
/// about x -> `paddle`, a 0.1 x 0.1 x 0.04 box centred on the joint.
const PADDLE_URDF: &str = r#"<?xml version="1.0"?>
<robot name="paddle">
  <link name="world"/>
  <link name="carriage"/>
  <link name="paddle">
    <collision><geometry><box size="0.1 0.1 0.04"/></geometry></collision>
  </link>
  <joint name="lift" type="prismatic">
    <parent link="world"/><child link="carriage"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="turn" type="revolute">
    <parent link="carriage"/><child link="paddle"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1.6" upper="1.6" effort="1" velocity="1"/>
  </joint>
</robot>
"#;

fn paddle() -> Robot {
    Robot::from_urdf_str(PADDLE_URDF, "paddle.urdf", None, &[]).unwrap()
}

/// The plane z = 0, 0.4 m square on a 5 mm grid, noise `SIGMA`.
fn floor(seed: u64) -> PointCloud {
    let pts: Vec<Point3> = (0..81 * 81)
        .map(|i| {
            Point3::new(
                f64::from(i % 81) * 0.005 - 0.2,
                f64::from(i / 81) * 0.005 - 0.2,
                0.0,
            )
        })
        .collect();
    PointCloud::from_sigma(add_noise(&pts, SIGMA, seed), SIGMA).unwrap()
}

fn request(side: MeshSide, model: QueryModel) -> RobotRequest {
    RobotRequest {
        mesh_side: side,
        collide: CollisionRequest {
            model,
            ..CollisionRequest::default()
        },
        ..RobotRequest::default()
    }
}

const SIDES: [MeshSide; 2] = [MeshSide::Exact, MeshSide::Sampled];
const MODELS: [QueryModel; 2] = [QueryModel::Elements, QueryModel::Points];

fn query(robot: &Robot, q: &[f64], cloud: &PointCloud, req: &RobotRequest) -> RobotCollisionResult {
    collide_robot(robot, q, &Pose::identity(), cloud, req).unwrap()
}

#[test]
fn the_links_signed_distance_is_built_with_the_robot() {
    let robot = paddle();
    let g = robot.links()[2].geometry.as_ref().unwrap();
    let d = &g.distance;
    assert!((d.signed_distance(&Point3::origin()) + HALF_Z).abs() < 1e-12);
    assert!((d.signed_distance(&Point3::new(0.0, 0.0, 0.1)) - 0.08).abs() < 1e-12);
    // A clone of the geometry shares it.
    let copy = g.clone();
    assert!(std::sync::Arc::ptr_eq(&copy.distance, &g.distance));
}

#[test]
fn a_box_through_a_noisy_plane_collides_and_ten_sigma_above_is_free() {
    let (robot, cloud) = (paddle(), floor(1));
    for model in MODELS {
        let req = request(MeshSide::Exact, model);
        let through = query(&robot, &[0.0, 0.0], &cloud, &req);
        assert_eq!(through.state, CollisionState::Collision, "{model:?}");
        assert!(through.probability > 0.99, "{model:?}");
        // The bottom face 10 sigma above the plane.
        let above = query(&robot, &[HALF_Z + 10.0 * SIGMA, 0.0], &cloud, &req);
        assert_eq!(above.state, CollisionState::Free, "{model:?}");
        assert!(above.probability < 1e-3, "{model:?}: {}", above.probability);
        // Nothing is trained for an exact link.
        assert_eq!(through.stats.counters.solver_iterations, 0);
        assert!(through.stats.counters.node_pairs_visited > 0);
        let link = &through.links[0];
        assert!(link.queried);
        assert!(link.result.as_ref().unwrap().probabilities_a.is_empty());
    }
}

#[test]
fn the_robot_result_is_the_exact_side_query_of_each_link() {
    let (robot, cloud) = (arm(), wall(0.40, 0.3, 0.1, 0.002, 4));
    let q = [0.05, 0.02, 0.07, 0.0];
    for model in MODELS {
        let req = RobotRequest {
            broad_phase: false,
            ..request(MeshSide::Exact, model)
        };
        let r = query(&robot, &q, &cloud, &req);
        let poses = robot.link_poses(&q, &Pose::identity()).unwrap();
        let mut max_p: f64 = 0.0;
        for entry in &r.links {
            let g = robot.links()[entry.link].geometry.as_ref().unwrap();
            let direct = collide_exact_cloud(
                &poses[entry.link],
                &g.distance,
                &Pose::identity(),
                &cloud,
                &req.collide,
            )
            .unwrap();
            assert_eq!(direct.probability, entry.probability, "link {}", entry.link);
            max_p = max_p.max(direct.probability);
        }
        assert_eq!(r.probability, max_p);
        assert!(r.probability > 0.0, "{model:?}");
    }
}

#[test]
fn exact_and_sampled_links_agree_where_the_answer_is_clear() {
    let (robot, cloud) = (paddle(), floor(2));
    // Deep through the plane, or 10 sigma and more above it (level or tilted).
    let clear = [
        ([0.0, 0.0], CollisionState::Collision),
        ([-0.01, 0.3], CollisionState::Collision),
        ([HALF_Z + 10.0 * SIGMA, 0.0], CollisionState::Free),
        ([0.06 + 10.0 * SIGMA, 0.8], CollisionState::Free),
        ([0.5, 0.0], CollisionState::Free),
    ];
    for model in MODELS {
        for (q, expected) in clear {
            for side in SIDES {
                let r = query(&robot, &q, &cloud, &request(side, model));
                assert_eq!(
                    r.state, expected,
                    "{side:?} {model:?} {q:?}: {}",
                    r.probability
                );
            }
        }
    }
}

#[test]
fn a_decide_only_query_answers_the_full_querys_state() {
    let (robot, cloud) = (arm(), wall(0.30, 0.3, 0.1, 0.002, 5));
    let mut decided = 0;
    for model in MODELS {
        let full = request(MeshSide::Exact, model);
        let mut fast = full.clone();
        fast.collide.decide_only = true;
        for i in 0..24 {
            let t = f64::from(i) / 23.0;
            let q = [0.6 * (t - 0.5), 0.4 * (0.5 - t), 0.1 * t, 0.0];
            let a = query(&robot, &q, &cloud, &full);
            let b = query(&robot, &q, &cloud, &fast);
            assert_eq!(a.state, b.state, "{model:?} {q:?}");
            decided += b.stats.counters.links_after_decision;
            if b.stats.counters.links_after_decision > 0 {
                // It returned at the first link that decided.
                let first = b.links.iter().position(|l| l.probability.is_nan()).unwrap();
                let p = b.links[first - 1].probability;
                assert!(p >= fast.collide.thresholds.collision);
                assert!(b.links[first..].iter().all(|l| !l.queried));
            }
        }
    }
    // Some queries were decided before their last link (not vacuous).
    assert!(decided > 0);
}

#[test]
fn a_common_rigid_motion_of_base_and_cloud_changes_nothing() {
    let (robot, cloud) = (arm(), wall(0.40, 0.3, 0.1, 0.002, 6));
    let motion = Pose::new(Vector3::new(0.7, -1.2, 0.4), Vector3::new(0.3, -0.5, 0.9));
    let moved = cloud.transformed(&motion).unwrap();
    for model in MODELS {
        let req = request(MeshSide::Exact, model);
        let mut seen = Vec::new();
        for q in [
            [0.0, 0.0, 0.065, 0.0],
            [0.0, 0.0, 0.1, 0.0],
            [0.3, 0.1, 0.02, 0.0],
            [0.0, 0.0, 0.0, 0.0],
        ] {
            let a = query(&robot, &q, &cloud, &req);
            let b = collide_robot(&robot, &q, &motion, &moved, &req).unwrap();
            assert!(
                (a.probability - b.probability).abs() < 1e-6,
                "{model:?} {q:?}: {} vs {}",
                a.probability,
                b.probability
            );
            assert_eq!(a.state, b.state);
            for (x, y) in a.links.iter().zip(&b.links) {
                assert!((x.probability - y.probability).abs() < 1e-6);
            }
            seen.push(a.state);
        }
        assert!(seen.contains(&CollisionState::Collision), "{model:?}");
        assert!(seen.contains(&CollisionState::Free), "{model:?}");
    }
}

#[test]
fn a_configuration_far_from_the_cloud_queries_no_link() {
    let (robot, cloud) = (arm(), wall(5.0, 0.3, 0.1, 0.002, 7));
    for model in MODELS {
        let r = query(
            &robot,
            &[0.4, -0.3, 0.05, 0.0],
            &cloud,
            &request(MeshSide::Exact, model),
        );
        assert_eq!(r.probability, 0.0);
        assert_eq!(r.state, CollisionState::Free);
        assert_eq!(r.stats.counters.links_with_geometry, 6);
        assert_eq!(r.stats.counters.links_queried, 0);
        assert_eq!(r.stats.counters.node_pairs_visited, 0);
        // Each link stops at the root of the cloud's hierarchy.
        assert_eq!(r.stats.counters.broad_phase_nodes, 6, "{model:?}");
        assert!(r.links.iter().all(|l| !l.queried && l.result.is_none()));
    }
}

#[test]
fn the_broad_phase_changes_the_cost_not_the_answer() {
    let (robot, cloud) = (arm(), wall(0.40, 0.3, 0.1, 0.002, 3));
    for model in MODELS {
        let with = request(MeshSide::Exact, model);
        let without = RobotRequest {
            broad_phase: false,
            ..with.clone()
        };
        let mut skipped = 0;
        // Turned links near the wall, grazing it or a few sigma off.
        let turned = (0..30).map(|i| {
            let t = f64::from(i);
            [
                0.3 * (0.7 * t).sin(),
                0.5 * (1.3 * t).cos(),
                0.05 + 0.05 * (0.9 * t).sin(),
                0.0,
            ]
        });
        let configurations = [
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.06, 0.0],
            [0.0, 0.0, 0.075, 0.0],
            [0.2, -0.1, 0.1, 0.0],
            [1.5, 0.0, 0.1, 0.0],
        ];
        for q in configurations.into_iter().chain(turned) {
            let a = query(&robot, &q, &cloud, &with);
            let b = query(&robot, &q, &cloud, &without);
            assert_eq!(b.stats.counters.links_queried, 6);
            skipped += 6 - a.stats.counters.links_queried;
            robot_common::assert_same_answer(&a, &b, &format!("{model:?} {q:?}"));
        }
        assert!(skipped > 0, "{model:?}");
    }
}

#[test]
fn batches_and_motions_read_exact_links() {
    let (robot, cloud) = (paddle(), floor(8));
    let req = RobotRequest::default();
    assert_eq!(req.mesh_side, MeshSide::Exact);
    let qs: Vec<Vec<f64>> = (0..9)
        .map(|i| vec![-0.02 + 0.01 * f64::from(i), 0.2])
        .collect();
    let many = collide_robot_many(&robot, &qs, &Pose::identity(), &cloud, &req).unwrap();
    for (q, m) in qs.iter().zip(&many) {
        assert_eq!(*m, query(&robot, q, &cloud, &req));
    }
    // Lowered through the plane: unsafe; moved sideways 10 sigma above: safe.
    let motion = MotionRequest::default();
    let down = check_motion(
        &robot,
        &[0.1, 0.0],
        &[-0.05, 0.0],
        &Pose::identity(),
        &cloud,
        &motion,
    );
    assert!(!down.unwrap().safe);
    let h = HALF_Z + 10.0 * SIGMA;
    let side = check_motion(
        &robot,
        &[h, -0.0],
        &[h + 0.05, 0.0],
        &Pose::identity(),
        &cloud,
        &motion,
    );
    assert!(side.unwrap().safe);
}

#[test]
fn exact_links_reject_what_they_cannot_read() {
    let (robot, cloud) = (paddle(), floor(9));
    // A sampling spacing samples the links.
    let spaced = RobotRequest {
        mesh_spacing: Some(0.002),
        ..RobotRequest::default()
    };
    let e = collide_robot(&robot, &[0.0, 0.0], &Pose::identity(), &cloud, &spaced).unwrap_err();
    assert!(e.to_string().contains("mesh_spacing"), "{e}");
    let sampled = RobotRequest {
        mesh_side: MeshSide::Sampled,
        ..spaced
    };
    assert!(collide_robot(&robot, &[0.0, 0.0], &Pose::identity(), &cloud, &sampled).is_ok());
    // The surface aggregation reads a trained surface.
    let mut surface = request(MeshSide::Exact, QueryModel::Points);
    surface.collide.aggregation = Aggregation::Surface;
    let e = collide_robot(&robot, &[0.0, 0.0], &Pose::identity(), &cloud, &surface).unwrap_err();
    assert!(e.to_string().contains("surface"), "{e}");
    surface.mesh_side = MeshSide::Sampled;
    assert!(collide_robot(&robot, &[0.0, 0.0], &Pose::identity(), &cloud, &surface).is_ok());
}

#[test]
fn a_tilted_box_near_the_reach_is_skipped_only_where_it_reads_nothing() {
    let (robot, cloud) = (paddle(), floor(10));
    for model in MODELS {
        let with = request(MeshSide::Exact, model);
        let without = RobotRequest {
            broad_phase: false,
            ..with.clone()
        };
        let (mut skipped, mut read) = (0, 0);
        for i in 0..40 {
            let tilt = 0.1 * f64::from(i % 8);
            // The lowest corner from 2 sigma below the plane to 37 above.
            let low = 0.05 * tilt.sin() + HALF_Z * tilt.cos();
            let q = [low + SIGMA * f64::from(i - 2), tilt];
            let a = query(&robot, &q, &cloud, &with);
            let b = query(&robot, &q, &cloud, &without);
            assert_eq!(a.probability, b.probability, "{model:?} {q:?}");
            skipped += usize::from(a.stats.counters.links_queried == 0);
            read += usize::from(b.probability > 0.0);
        }
        assert!(
            skipped > 0 && read > 0,
            "{model:?}: {skipped} skipped, {read} read"
        );
    }
}
