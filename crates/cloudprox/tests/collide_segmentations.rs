//! The elements model averaged over segmentations of the clouds: the element
//! sets themselves, the mean the query returns, its invariances, decide-only
//! and bad requests.

use crate::common;

use cloudprox::element::{ElementSettings, SurfaceElements};
use cloudprox::prelude::*;
use common::{sphere_pose, spheres, SIGMA};

fn averaged(k: u32) -> CollisionRequest {
    CollisionRequest {
        model: QueryModel::Elements,
        segmentations: k,
        ..CollisionRequest::default()
    }
}

/// Each point's element (index into the element list), per point of the cloud.
fn owners(els: &SurfaceElements, n: usize) -> Vec<usize> {
    let mut owner = vec![usize::MAX; n];
    for (e, el) in els.elements().iter().enumerate() {
        let first = el.first as usize;
        for &i in &els.indices()[first..first + el.count as usize] {
            assert_eq!(owner[i as usize], usize::MAX, "point {i} in two elements");
            owner[i as usize] = e;
        }
    }
    owner
}

#[test]
fn segmentations_group_the_same_points_differently_and_deterministically() {
    let (a, _) = spheres(3000);
    let n = a.len();
    let base = owners(a.segmentation(0), n);
    // Segmentation 0 is the cloud's own (the median splits).
    assert_eq!(a.elements().elements(), a.segmentation(0).elements());
    assert!(
        base.iter().all(|&o| o != usize::MAX),
        "every point in an element"
    );
    for k in 1..4 {
        let els = a.segmentation(k);
        let own = owners(els, n);
        assert!(own.iter().all(|&o| o != usize::MAX), "segmentation {k}");
        // Another grouping: some pair of points together in one and apart in
        // the other.
        let differs = (1..n).any(|i| (base[i] == base[i - 1]) != (own[i] == own[i - 1]));
        assert!(differs, "segmentation {k} groups as segmentation 0");
        // Built again from the settings alone: the same elements.
        let settings = ElementSettings {
            segmentation: k,
            ..ElementSettings::default()
        };
        let again = SurfaceElements::build(&a, &settings).unwrap();
        assert_eq!(again.elements(), els.elements(), "segmentation {k}");
    }
}

#[test]
fn the_query_is_the_mean_of_one_query_per_segmentation() {
    let (a, b) = spheres(3000);
    let k = 3;
    for gap in [-2.0, 0.0, 1.0, 3.0] {
        let pb = sphere_pose(gap * SIGMA);
        let mean = collide(&Pose::identity(), &a, &pb, &b, &averaged(k)).unwrap();
        // One query per segmentation: clouds whose own segmentation is s.
        let mut runs = Vec::new();
        for s in 0..k {
            let settings = ElementSettings {
                segmentation: s,
                ..ElementSettings::default()
            };
            let (mut a_s, mut b_s) = (a.clone(), b.clone());
            a_s.set_element_settings(settings).unwrap();
            b_s.set_element_settings(settings).unwrap();
            runs.push(collide(&Pose::identity(), &a_s, &pb, &b_s, &averaged(1)).unwrap());
        }
        let p = runs.iter().map(|r| r.probability).sum::<f64>() / f64::from(k);
        // The runs are combined in segmentation order, wherever they ran:
        // the mean to the bit.
        assert_eq!(
            mean.probability.to_bits(),
            p.to_bits(),
            "gap {gap}: {} vs {p}",
            mean.probability
        );
        assert_eq!(mean.state, CollisionRequest::default().thresholds.state(p));
        let dense: Vec<Vec<f64>> = runs.iter().map(|r| r.probabilities_a.to_dense()).collect();
        for (i, q) in mean.probabilities_a.to_dense().iter().enumerate() {
            let expected = dense.iter().map(|d| d[i]).sum::<f64>() / f64::from(k);
            assert_eq!(q.to_bits(), expected.to_bits(), "gap {gap}, point {i}");
        }
        assert_eq!(
            mean.patches.len(),
            runs.iter().map(|r| r.patches.len()).sum::<usize>()
        );
        assert_eq!(mean.stats.counters.patches, mean.patches.len());
        // The segmentations do differ near contact (else the mean is moot).
        if gap.abs() <= 1.0 {
            assert!(
                runs.iter()
                    .any(|r| (r.probability - runs[0].probability).abs() > 1e-9),
                "gap {gap}: every segmentation reads {}",
                runs[0].probability
            );
        }
    }
}

#[test]
fn the_mean_keeps_the_invariances_and_decide_only_its_state() {
    let (a, b) = spheres(3000);
    let req = averaged(4);
    let quick = CollisionRequest {
        decide_only: true,
        ..req
    };
    let t = Pose::new(Vector3::new(0.3, -0.4, 1.0), Vector3::new(1.0, 2.0, -0.5));
    for gap in [-4.0, -1.0, 0.0, 1.0, 2.0, 8.0] {
        let pb = sphere_pose(gap * SIGMA);
        let r0 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
        let moved = collide(&t, &a, &(t * pb), &b, &req).unwrap();
        assert!(
            (r0.probability - moved.probability).abs() < 1e-9,
            "gap {gap}"
        );
        let swapped = collide(&pb, &b, &Pose::identity(), &a, &req).unwrap();
        assert!(
            (r0.probability - swapped.probability).abs() < 1e-6,
            "gap {gap}: {} vs swapped {}",
            r0.probability,
            swapped.probability
        );
        let q = collide(&Pose::identity(), &a, &pb, &b, &quick).unwrap();
        assert_eq!(q.state, r0.state, "gap {gap}");
        // Its runs leave out the per-point work and nothing that `P` reads:
        // the same `P` to the bit, no per-point probabilities, no separation
        // estimates (the full query's patches have theirs).
        assert_eq!(
            q.probability.to_bits(),
            r0.probability.to_bits(),
            "gap {gap}"
        );
        assert!(q.probabilities_a.indices().is_empty());
        assert!(q.probabilities_b.indices().is_empty());
        assert_eq!(q.patches.len(), r0.patches.len(), "gap {gap}");
        assert!(q.patches.iter().all(|p| p.separation.is_nan()), "gap {gap}");
        assert!(
            r0.patches.iter().all(|p| !p.separation.is_nan()),
            "gap {gap}"
        );
    }
    // Far apart and deep inside: every segmentation agrees.
    let far = collide(&Pose::identity(), &a, &sphere_pose(20.0 * SIGMA), &b, &req).unwrap();
    assert_eq!(far.state, CollisionState::Free);
    let deep = collide(&Pose::identity(), &a, &sphere_pose(-6.0 * SIGMA), &b, &req).unwrap();
    assert_eq!(deep.state, CollisionState::Collision);
}

#[test]
fn bad_segmentation_counts_are_named() {
    let (a, b) = spheres(500);
    for (request, needle) in [
        (averaged(0), "segmentations must be in 1..=16, got 0"),
        (averaged(17), "segmentations must be in 1..=16, got 17"),
        (
            CollisionRequest {
                model: QueryModel::Points,
                segmentations: 2,
                ..CollisionRequest::default()
            },
            "needs model 'elements'",
        ),
    ] {
        let err = collide(&Pose::identity(), &a, &sphere_pose(0.0), &b, &request).unwrap_err();
        assert!(err.to_string().contains(needle), "{err}");
    }
}

#[test]
fn many_poses_and_a_motion_average_as_single_queries_do() {
    let (a, b) = spheres(2000);
    let req = averaged(2);
    let poses: Vec<Pose> = [3.0, 1.5, 0.5, -0.5, -1.5]
        .iter()
        .map(|g| sphere_pose(g * SIGMA))
        .collect();
    let id = Pose::identity();
    let many = collide_many(&poses, &a, &id, &b, &req).unwrap();
    let along = collide_along(&poses, &a, &id, &b, &req).unwrap();
    for (k, pose) in poses.iter().enumerate() {
        let one = collide(pose, &a, &id, &b, &req).unwrap();
        assert_eq!(many[k].probability, one.probability, "pose {k}");
        assert_eq!(many[k].probabilities_a, one.probabilities_a, "pose {k}");
        // The warm start changes the first segmentation's work, not its
        // optimum (to the solver's tolerance).
        assert!(
            (along[k].probability - one.probability).abs() < 1e-6,
            "pose {k}: along {} vs {}",
            along[k].probability,
            one.probability
        );
        assert_eq!(along[k].state, one.state, "pose {k}");
    }
}

#[test]
fn a_clouds_own_segmentation_is_its_elements_and_moves_with_its_points() {
    let (a, _) = spheres(1500);
    let mut own = a.clone();
    own.set_element_settings(ElementSettings {
        segmentation: 5,
        ..ElementSettings::default()
    })
    .unwrap();
    assert_eq!(own.elements().elements(), a.segmentation(5).elements());
    assert_eq!(own.segmentation(0).elements(), a.elements().elements());
    let t = Pose::new(Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.3, -0.2, 0.1));
    let mut moved = a.clone();
    let _ = moved.segmentation(3).elements().len();
    moved.transform(&t).unwrap();
    let fresh = a.transformed(&t).unwrap();
    assert_eq!(
        moved.segmentation(3).elements(),
        fresh.segmentation(3).elements()
    );
    let bad = ElementSettings {
        segmentation: cloudprox::cloud::MAX_SEGMENTATIONS,
        ..ElementSettings::default()
    };
    let err = own.set_element_settings(bad).unwrap_err();
    assert!(
        err.to_string()
            .contains("element segmentation must be below 16, got 16"),
        "{err}"
    );
}
