//! Determinism and thread safety: a query gives the same answer every time, at
//! any number of rayon threads, and from many threads sharing one cloud (whose
//! hierarchy and elements are built on first use, possibly by several threads
//! at once).

use crate::common;

use std::sync::Arc;

use cloudprox::prelude::*;
use common::{sphere_pose, spheres, SIGMA};

fn requests() -> [CollisionRequest; 2] {
    [QueryModel::Points, QueryModel::Elements].map(|model| CollisionRequest {
        model,
        ..CollisionRequest::default()
    })
}

/// Poses of B from well inside A to beyond the noise's reach.
fn poses() -> Vec<Pose> {
    [-6.0, -2.0, 0.0, 1.0, 3.0, 8.0]
        .iter()
        .map(|&k| sphere_pose(k * SIGMA))
        .collect()
}

#[test]
fn two_runs_of_a_query_are_equal() {
    let (a, b) = spheres(3000);
    for req in requests() {
        for pose in poses() {
            let first = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
            let second = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
            // Equality leaves out the wall time, which differs between runs.
            assert_eq!(first, second, "{:?}", req.model);
        }
    }
}

#[test]
fn results_do_not_depend_on_the_number_of_rayon_threads() {
    let (a, b) = spheres(3000);
    let poses = poses();
    for req in requests() {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| collide_many(&poses, &b, &Pose::identity(), &a, &req).unwrap())
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one, two, "{:?}", req.model);
        // And the batch agrees with single queries.
        for (pose, r) in poses.iter().zip(&one) {
            let single = collide(pose, &b, &Pose::identity(), &a, &req).unwrap();
            assert_eq!(&single, r, "{:?}", req.model);
        }
    }
}

#[test]
fn eight_threads_sharing_fresh_clouds_get_the_serial_answers() {
    let poses = poses();
    for req in requests() {
        // Serial answers on clouds of their own.
        let (a, b) = spheres(3000);
        let serial: Vec<CollisionResult> = poses
            .iter()
            .map(|p| collide(&Pose::identity(), &a, p, &b, &req).unwrap())
            .collect();
        // Fresh clouds (nothing built yet), shared by eight threads that all
        // query at once: the lazy builds race.
        let (a, b) = spheres(3000);
        let shared = Arc::new((a, b));
        let handles: Vec<_> = (0..8)
            .map(|t| {
                let shared = Arc::clone(&shared);
                let poses = poses.clone();
                std::thread::spawn(move || {
                    let (a, b) = &*shared;
                    // Each thread starts at a different pose.
                    (0..poses.len())
                        .map(|k| {
                            let i = (k + t) % poses.len();
                            let r = collide(&Pose::identity(), a, &poses[i], b, &req).unwrap();
                            (i, r)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in handles {
            for (i, r) in h.join().unwrap() {
                assert_eq!(r, serial[i], "{:?} pose {i}", req.model);
            }
        }
    }
}
