//! The scan's shadow in a robot query (`RobotRequest::shadow`) on the test arm.
//!
//! At `q = 0` the arm's `link3` sphere (radius 0.03) is centred at
//! `(0.3, 0, 0.3)`; a wall at `x = 0.36` is 3 cm beyond it (15 sigma): free.
//! Seen from `x = 1` the sphere lies 3 to 9 cm behind the wall, in its shadow;
//! seen from `x = -1` it lies in front of it.

use std::sync::Arc;

use crate::robot_common;

use cloudprox::filter::Occlusion;
use cloudprox::prelude::*;
use cloudprox::robot::{collide_robot, RobotRequest, RobotShadow};
use robot_common::{arm, wall};

const SIGMA: f64 = 0.002;
const Q0: [f64; 4] = [0.0; 4];
const LINK3: usize = 3;

fn shadow_from(cloud: &PointCloud, origin: Point3, depth: f64) -> RobotShadow {
    let occ = Occlusion::new(
        cloud.points(),
        Some(cloud.sensor_covariances()),
        cloud.spacing(),
        origin,
        None,
    )
    .unwrap();
    RobotShadow {
        depth,
        ..RobotShadow::new(Arc::new(occ))
    }
}

fn query(
    cloud: &PointCloud,
    shadow: Option<RobotShadow>,
) -> cloudprox::robot::RobotCollisionResult {
    let req = RobotRequest {
        shadow,
        self_collision: false,
        ..RobotRequest::default()
    };
    collide_robot(&arm(), &Q0, &Pose::identity(), cloud, &req).unwrap()
}

fn link(r: &cloudprox::robot::RobotCollisionResult, l: usize) -> &cloudprox::robot::LinkCollision {
    r.links.iter().find(|x| x.link == l).unwrap()
}

#[test]
fn a_link_in_the_walls_shadow_reads_the_prior_not_free() {
    let cloud = wall(0.36, 0.3, 0.2, SIGMA, 11);
    let bare = query(&cloud, None);
    assert_eq!(bare.state, CollisionState::Free, "{}", bare.probability);
    let behind = query(
        &cloud,
        Some(shadow_from(&cloud, Point3::new(1.0, 0.0, 0.3), 0.05)),
    );
    let l3 = link(&behind, LINK3);
    assert!((l3.shadow - 0.5).abs() < 1e-6, "shadow {}", l3.shadow);
    assert!((l3.probability - 0.5).abs() < 1e-6, "P {}", l3.probability);
    assert_eq!(behind.state, CollisionState::Contact);
    // Without the shadow, every link's probability is the query's alone.
    for (a, b) in bare.links.iter().zip(&behind.links) {
        assert!(b.probability >= a.probability);
        assert_eq!(a.shadow, 0.0);
    }
}

#[test]
fn in_front_of_the_wall_or_deeper_than_the_stated_thickness_reads_free() {
    let cloud = wall(0.36, 0.3, 0.2, SIGMA, 11);
    let front = query(
        &cloud,
        Some(shadow_from(&cloud, Point3::new(-1.0, 0.0, 0.3), 0.05)),
    );
    assert!(link(&front, LINK3).shadow < 1e-12);
    assert_eq!(front.state, CollisionState::Free);
    // The sphere is at least 3 cm behind the wall: beyond a 1 cm thickness.
    let thin = query(
        &cloud,
        Some(shadow_from(&cloud, Point3::new(1.0, 0.0, 0.3), 0.01)),
    );
    assert!(
        link(&thin, LINK3).shadow < 1e-9,
        "{}",
        link(&thin, LINK3).shadow
    );
    // Anywhere behind it: the prior.
    let deep = query(
        &cloud,
        Some(shadow_from(
            &cloud,
            Point3::new(1.0, 0.0, 0.3),
            f64::INFINITY,
        )),
    );
    assert!((link(&deep, LINK3).shadow - 0.5).abs() < 1e-6);
}

#[test]
fn a_bad_shadow_is_named() {
    let cloud = wall(0.36, 0.3, 0.2, SIGMA, 11);
    let mut s = shadow_from(&cloud, Point3::new(1.0, 0.0, 0.3), 0.05);
    s.prior = 1.5;
    let req = RobotRequest {
        shadow: Some(s.clone()),
        ..RobotRequest::default()
    };
    let err = collide_robot(&arm(), &Q0, &Pose::identity(), &cloud, &req).unwrap_err();
    assert!(err.to_string().contains("prior"), "{err}");
    s.prior = 0.5;
    s.depth = -1.0;
    let req = RobotRequest {
        shadow: Some(s),
        ..RobotRequest::default()
    };
    let err = collide_robot(&arm(), &Q0, &Pose::identity(), &cloud, &req).unwrap_err();
    assert!(err.to_string().contains("depth"), "{err}");
}
