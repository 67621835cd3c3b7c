//! Grasp targets (`RobotRequest::target`) and link padding
//! (`RobotRequest::padding`, `link_padding`) on the test arm.
//!
//! At `q = 0` the arm's `link3` sphere (radius 0.03) is centred at
//! `(0.3, 0, 0.3)`, so its nearest point to a wall `x = x0` is at `x = 0.33`;
//! the base box's face `x = 0.1` spans `|y| <= 0.1`, `|z| <= 0.05`.

use std::sync::Arc;

use crate::robot_common;

use cloudprox::prelude::*;
use cloudprox::query::MeshSide;
use cloudprox::robot::{
    check_motion, collide_robot, collide_robot_many, GraspTarget, MotionRequest,
    RobotCollisionResult, RobotRequest,
};
use robot_common::{arm, wall};

const SIGMA: f64 = 0.002;
const Q0: [f64; 4] = [0.0; 4];

fn far_scene() -> PointCloud {
    wall(5.0, 0.3, 0.05, SIGMA, 7)
}

fn link_p(r: &RobotCollisionResult, link: usize) -> f64 {
    r.links.iter().find(|l| l.link == link).unwrap().probability
}

fn query(cloud: &PointCloud, req: &RobotRequest) -> RobotCollisionResult {
    collide_robot(&arm(), &Q0, &Pose::identity(), cloud, req).unwrap()
}

fn with_target(cloud: PointCloud, allowed: &[&str]) -> RobotRequest {
    RobotRequest {
        target: Some(GraspTarget::cloud(
            Arc::new(cloud),
            allowed.iter().map(ToString::to_string).collect(),
        )),
        ..RobotRequest::default()
    }
}

#[test]
fn robot_fingers_on_the_target_are_free_when_allowed_and_collide_otherwise() {
    // A patch pressed 5 mm into link3's sphere.
    let target = wall(0.325, 0.3, 0.02, SIGMA, 3);
    let allowed = query(
        &far_scene(),
        &with_target(target.clone(), &["link3", "link4", "tool"]),
    );
    assert_eq!(
        allowed.state,
        CollisionState::Free,
        "{}",
        allowed.probability
    );
    let t = allowed.target.unwrap();
    assert_eq!(t.state, CollisionState::Collision, "{t:?}");
    assert!(t.probability > 0.99 && t.other_probability < 1e-6, "{t:?}");
    let link3 = allowed.links.iter().find(|l| l.link == 3).unwrap();
    assert!(link3.target.as_ref().unwrap().probability > 0.99);
    assert!(link3.probability < 1e-6);

    let denied = query(&far_scene(), &with_target(target, &[]));
    assert_eq!(denied.state, CollisionState::Collision);
    assert!(link_p(&denied, 3) > 0.99);
    let t = denied.target.unwrap();
    assert!(t.probability == 0.0 && t.other_probability > 0.99, "{t:?}");
}

#[test]
fn robot_another_link_hitting_the_target_still_collides() {
    // The patch x = 0.15 cuts link2's bar (x in [0, 0.3] at z = 0.3).
    let target = wall(0.15, 0.3, 0.02, SIGMA, 4);
    let r = query(
        &far_scene(),
        &with_target(target, &["link3", "link4", "tool"]),
    );
    assert_eq!(r.state, CollisionState::Collision);
    assert!(link_p(&r, 2) > 0.99);
    let t = r.target.unwrap();
    assert!(t.other_probability > 0.99 && t.probability < 1e-6, "{t:?}");
}

#[test]
fn robot_target_enters_batches_and_motions() {
    let target = wall(0.325, 0.3, 0.02, SIGMA, 3);
    let robot = arm();
    let qs = vec![Q0.to_vec(), vec![1.5, 0.0, 0.0, 0.0]];
    for (allowed, unsafe_) in [(vec!["link3", "link4", "tool"], false), (vec![], true)] {
        let req = with_target(target.clone(), &allowed);
        let batch = collide_robot_many(&robot, &qs, &Pose::identity(), &far_scene(), &req).unwrap();
        let single = query(&far_scene(), &req);
        assert_eq!(batch[0].probability, single.probability);
        assert_eq!(batch[0].target, single.target);
        let motion = MotionRequest {
            robot: req,
            ..MotionRequest::default()
        };
        let m = check_motion(
            &robot,
            &qs[1],
            &qs[0],
            &Pose::identity(),
            &far_scene(),
            &motion,
        )
        .unwrap();
        assert_eq!(!m.safe, unsafe_, "{m:?}");
    }
}

#[test]
fn robot_mesh_target_reads_like_its_cloud() {
    // A 2 cm cube centred 1 cm beyond link3's tip: it overlaps the sphere.
    let cube = Arc::new(Mesh::cuboid(0.01, 0.01, 0.01).unwrap());
    let pose = Pose::translation(0.335, 0.0, 0.3);
    let req = |allowed: Vec<String>| RobotRequest {
        target: Some(GraspTarget::mesh(Arc::clone(&cube), pose, allowed)),
        ..RobotRequest::default()
    };
    let free = query(&far_scene(), &req(vec!["link3".into()]));
    assert_eq!(free.state, CollisionState::Free);
    assert_eq!(free.target.unwrap().state, CollisionState::Collision);
    let hit = query(&far_scene(), &req(Vec::new()));
    assert_eq!(hit.state, CollisionState::Collision);
}

#[test]
fn robot_padding_zero_is_no_padding_bit_for_bit() {
    let cloud = wall(0.335, 0.3, 0.05, SIGMA, 5);
    let plain = query(&cloud, &RobotRequest::default());
    let zero = query(
        &cloud,
        &RobotRequest {
            padding: 0.0,
            link_padding: vec![("link3".into(), 0.0)],
            ..RobotRequest::default()
        },
    );
    assert_eq!(plain.probability.to_bits(), zero.probability.to_bits());
    for (a, b) in plain.links.iter().zip(&zero.links) {
        assert_eq!(a.probability.to_bits(), b.probability.to_bits());
        // The query results but their wall times.
        let values = |l: &cloudprox::robot::LinkCollision| {
            l.result.as_ref().map(|r| {
                let mut r = r.clone();
                r.stats.time_seconds = 0.0;
                r
            })
        };
        assert_eq!(values(a), values(b));
    }
}

#[test]
fn robot_padding_d_at_clearance_c_reads_as_clearance_c_minus_d() {
    // The base box's face x = 0.1, a patch in front of it (|y|, |z| <= 0.03).
    for model in [QueryModel::Elements, QueryModel::Points] {
        for (c, d) in [(0.006, 0.004), (0.004, 0.004), (0.008, 0.002)] {
            let base = |req: RobotRequest, clearance: f64| {
                let cloud = wall(0.1 + clearance, 0.0, 0.03, SIGMA, 6);
                let req = RobotRequest {
                    collide: CollisionRequest {
                        model,
                        ..CollisionRequest::default()
                    },
                    self_collision: false,
                    ..req
                };
                link_p(&query(&cloud, &req), 0)
            };
            let padded = base(
                RobotRequest {
                    padding: d,
                    ..RobotRequest::default()
                },
                c,
            );
            let closer = base(RobotRequest::default(), c - d);
            let unpadded = base(RobotRequest::default(), c);
            assert!(
                (padded - closer).abs() < 1e-6,
                "{model:?} c={c} d={d}: {padded} vs {closer}"
            );
            assert!(padded > unpadded, "{padded} <= {unpadded}");
        }
    }
}

#[test]
fn robot_padding_moves_a_sampled_links_samples_along_its_normals() {
    // The base's face x = 0.1 sampled: its samples on that face move to
    // x = 0.1 + d, so the padded base at clearance c reads about as the bare
    // base at c - d (its other faces' samples move too, elsewhere).
    let sampled = |padding: f64, clearance: f64| {
        let cloud = wall(0.1 + clearance, 0.0, 0.03, SIGMA, 6);
        let req = RobotRequest {
            mesh_side: MeshSide::Sampled,
            mesh_spacing: Some(0.005),
            self_collision: false,
            padding,
            ..RobotRequest::default()
        };
        link_p(&query(&cloud, &req), 0)
    };
    // Two sampled sheets read contact only where they meet (a wall pressed
    // in parallel to a face is a second sheet, separable from it), and not
    // monotonically within a millimetre of it: compare at touching.
    let c = 0.008;
    assert!(sampled(0.0, c) < 1e-6);
    let (padded, touching) = (sampled(c, c), sampled(0.0, 0.0));
    assert!(padded > 0.2 && touching > 0.2, "{padded} {touching}");
    assert_eq!(sampled(0.0, c).to_bits(), {
        let cloud = wall(0.1 + c, 0.0, 0.03, SIGMA, 6);
        let req = RobotRequest {
            mesh_side: MeshSide::Sampled,
            mesh_spacing: Some(0.005),
            self_collision: false,
            link_padding: vec![("base".into(), 0.0)],
            ..RobotRequest::default()
        };
        link_p(&query(&cloud, &req), 0).to_bits()
    });
}

#[test]
fn robot_padding_by_link_name_pads_that_link_only() {
    // A wall near both the base (x = 0.1) and nothing else: padding link3
    // changes nothing; padding the base raises its P.
    let cloud = wall(0.108, 0.0, 0.03, SIGMA, 8);
    let plain = query(&cloud, &RobotRequest::default());
    let other = query(
        &cloud,
        &RobotRequest {
            link_padding: vec![("link3".into(), 0.01)],
            ..RobotRequest::default()
        },
    );
    let own = query(
        &cloud,
        &RobotRequest {
            link_padding: vec![("base".into(), 0.01)],
            ..RobotRequest::default()
        },
    );
    assert_eq!(link_p(&plain, 0).to_bits(), link_p(&other, 0).to_bits());
    assert!(
        link_p(&own, 0) > link_p(&plain, 0) + 0.1,
        "{} {}",
        link_p(&own, 0),
        link_p(&plain, 0)
    );
    for l in 1..6 {
        assert_eq!(link_p(&plain, l), link_p(&own, l));
    }
}

#[test]
fn robot_padding_and_target_bad_inputs_name_the_problem() {
    let cloud = far_scene();
    let robot = arm();
    let err = |req: RobotRequest| {
        collide_robot(&robot, &Q0, &Pose::identity(), &cloud, &req)
            .unwrap_err()
            .to_string()
    };
    for d in [-0.01, f64::NAN, f64::INFINITY] {
        let e = err(RobotRequest {
            padding: d,
            ..RobotRequest::default()
        });
        assert!(e.contains("padding must be finite and >= 0"), "{e}");
        let e = err(RobotRequest {
            link_padding: vec![("link2".into(), d)],
            ..RobotRequest::default()
        });
        assert!(e.contains("padding of link 'link2'"), "{e}");
    }
    let e = err(RobotRequest {
        link_padding: vec![("gripper".into(), 0.01)],
        ..RobotRequest::default()
    });
    assert!(
        e.contains("'gripper'") && e.contains("does not have"),
        "{e}"
    );
    let e = err(with_target(wall(0.3, 0.3, 0.02, SIGMA, 1), &["finger"]));
    assert!(e.contains("allowed_links names 'finger'"), "{e}");
}
