//! The collide query between two noisy clouds: analytic cases, invariances, the
//! hierarchy against brute force.

use crate::common;

use cloudprox::prelude::*;
use cloudprox::probability::normal_cdf;
use cloudprox::query::ALONG_RUN;
use common::{plate_pose, plates, sphere_pose, spheres, SIGMA};

/// The paper's per-point model (this file's subject; the surface elements
/// are tested in `collide_elements.rs`) with `surface`.
fn request(surface: Surface) -> CollisionRequest {
    CollisionRequest {
        model: QueryModel::Points,
        classify: ClassifySettings {
            surface,
            ..ClassifySettings::default()
        },
        ..CollisionRequest::default()
    }
}

/// The query with both clouds' points moved by `t` (B's also by `pb`) and
/// identity poses, instead of the motion given as poses.
fn collide_moved_data(
    a: &PointCloud,
    b: &PointCloud,
    t: &Pose,
    pb: &Pose,
    req: &CollisionRequest,
) -> CollisionResult {
    let (ma, mb) = (a.transformed(t).unwrap(), b.transformed(&(t * pb)).unwrap());
    collide(&Pose::identity(), &ma, &Pose::identity(), &mb, req).unwrap()
}

fn sweep(
    a: &PointCloud,
    b: &PointCloud,
    pose: impl Fn(f64) -> Pose,
    req: &CollisionRequest,
) -> Vec<(f64, f64)> {
    [
        -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 12.0,
    ]
    .iter()
    .map(|&k| {
        let r = collide(&Pose::identity(), a, &pose(k * SIGMA), b, req).unwrap();
        (k, r.probability)
    })
    .collect()
}

fn assert_sweep(name: &str, ps: &[(f64, f64)], slack: f64) {
    for w in ps.windows(2) {
        assert!(
            w[1].1 <= w[0].1 + slack,
            "{name}: P must not increase with the gap: {ps:?}"
        );
    }
    let at = |k: f64| ps.iter().find(|x| x.0 == k).unwrap().1;
    assert!(at(-3.0) > 0.95, "{name}: P at -3 sigma = {}", at(-3.0));
    assert!(at(10.0) < 0.01, "{name}: P at 10 sigma = {}", at(10.0));
}

#[test]
fn spheres_probability_falls_with_separation() {
    let (a, b) = spheres(2000);
    assert_sweep(
        "spheres/quadric",
        &sweep(&a, &b, sphere_pose, &request(Surface::Quadric)),
        1e-6,
    );
}

#[test]
fn spheres_linear_surface_also_orders_separations() {
    let (a, b) = spheres(1000);
    assert_sweep(
        "spheres/linear",
        &sweep(&a, &b, sphere_pose, &request(Surface::Linear)),
        0.02,
    );
}

#[test]
fn plates_probability_falls_with_separation() {
    let (a, b) = plates();
    assert_sweep(
        "plates/quadric",
        &sweep(&a, &b, plate_pose, &request(Surface::Quadric)),
        1e-6,
    );
}

#[test]
fn states_follow_thresholds() {
    let (a, b) = spheres(1000);
    let req = request(Surface::Quadric);
    let deep = collide(&Pose::identity(), &a, &sphere_pose(-5.0 * SIGMA), &b, &req).unwrap();
    assert_eq!(deep.state, CollisionState::Collision);
    let far = collide(&Pose::identity(), &a, &sphere_pose(20.0 * SIGMA), &b, &req).unwrap();
    assert_eq!(far.state, CollisionState::Free);
    assert_eq!(far.probability, 0.0);
    assert!(far.patches.is_empty(), "{:?}", far.stats);
    assert!(far.stats.counters.pruned_bound < 1e-2, "{:?}", far.stats);
}

#[test]
fn expressing_the_clouds_in_another_frame_changes_nothing() {
    // The near region is chosen point by point from distances alone, so moving the
    // data (which changes the hierarchies' leaves) instead of the poses gives the
    // same regions and P, as long as no region is large enough to be cut into
    // patches (cuts at a median are not stable on symmetric contacts).
    let (a, b) = spheres(2000);
    let req = request(Surface::Quadric);
    let t = Pose::new(Vector3::new(0.3, -0.4, 1.0), Vector3::new(1.0, 2.0, -0.5));
    for gap in [-1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0] {
        let pb = sphere_pose(gap * SIGMA);
        let r0 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
        let r1 = collide_moved_data(&a, &b, &t, &pb, &req);
        assert_eq!(
            r0.stats.counters.points_classified, r1.stats.counters.points_classified,
            "gap {gap}"
        );
        assert!(
            (r0.probability - r1.probability).abs() < 1e-3,
            "gap {gap}: {} vs {}",
            r0.probability,
            r1.probability
        );
    }
}

#[test]
fn per_point_probabilities_are_the_gaussian_cdf_of_the_plane_distance() {
    let (a, b) = spheres(800);
    let pose_b = sphere_pose(2.0 * SIGMA);
    let r = collide(
        &Pose::identity(),
        &a,
        &pose_b,
        &b,
        &request(Surface::Linear),
    )
    .unwrap();
    assert!(!r.patches.is_empty());
    for reg in &r.patches {
        // The plane in its training frame: n . x + d = 0 with n = w / scale.
        let sep = &reg.separator;
        let n = Vector3::new(sep.w[0], sep.w[1], sep.w[2]) / sep.scale;
        let d = sep.b - n.dot(&sep.center.coords);
        for &i in &reg.indices_a {
            let x = sep.frame.inverse_transform_point(&a.points()[i as usize]);
            let dist = (n.dot(&x.coords) + d) / n.norm();
            let want = normal_cdf(-dist / SIGMA);
            assert!((r.probabilities_a.get(i as usize) - want).abs() < 1e-12);
        }
        for &i in &reg.indices_b {
            let x = sep
                .frame
                .inverse_transform_point(&(pose_b * b.points()[i as usize]));
            let dist = (n.dot(&x.coords) + d) / n.norm();
            let want = normal_cdf(dist / SIGMA);
            assert!((r.probabilities_b.get(i as usize) - want).abs() < 1e-12);
        }
    }
}

#[test]
fn moving_both_clouds_rigidly_changes_nothing() {
    let (a, b) = spheres(1000);
    let req = request(Surface::Quadric);
    let t = Pose::new(Vector3::new(0.3, -1.2, 0.7), Vector3::new(0.4, -0.9, 2.1));
    for gap in [-2.0, 1.0, 3.0] {
        let pb = sphere_pose(gap * SIGMA);
        let r0 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
        let r1 = collide(&t, &a, &(t * pb), &b, &req).unwrap();
        assert!((r0.probability - r1.probability).abs() < 1e-6, "gap {gap}");
        let (p0, p1) = (r0.probabilities_a.to_dense(), r1.probabilities_a.to_dense());
        let dmax = p0
            .iter()
            .zip(&p1)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(dmax < 1e-4, "gap {gap}: per-point difference {dmax}");
        assert_eq!(r0.patches.len(), r1.patches.len());
        for (g0, g1) in r0.patches.iter().zip(&r1.patches) {
            assert!(((t * g0.point) - g1.point).norm() < 1e-6);
            assert!(((t * g0.normal) - g1.normal).norm() < 1e-5);
            assert!((g0.separation - g1.separation).abs() < 1e-6);
        }
    }
}

#[test]
fn the_classifier_is_equivariant_under_rotations_of_the_data() {
    // Moving the data itself (not the poses) changes the hierarchies' leaves and
    // hence the near regions; with one region of all points the remaining
    // difference is the classifier's, whose regularizer is rotation invariant.
    let (a, b) = spheres(300);
    let t = Pose::new(Vector3::new(0.3, -1.2, 0.7), Vector3::new(0.4, -0.9, 2.1));
    for surface in [Surface::Quadric, Surface::Linear] {
        let req = CollisionRequest {
            model: QueryModel::Points,
            classify: ClassifySettings {
                surface,
                ..ClassifySettings::default()
            },
            use_hierarchy: false,
            region_max_points: 10_000,
            ..CollisionRequest::default()
        };
        for gap in [-2.0, 1.0, 3.0] {
            let pb = sphere_pose(gap * SIGMA);
            let r0 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
            let r2 = collide_moved_data(&a, &b, &t, &pb, &req);
            assert!(
                (r0.probability - r2.probability).abs() < 1e-5,
                "{surface:?} gap {gap}: {} vs {}",
                r0.probability,
                r2.probability
            );
        }
    }
}

#[test]
fn swapping_the_clouds_gives_the_same_probability() {
    let (a, b) = spheres(1000);
    let req = request(Surface::Quadric);
    for gap in [-1.0, 2.0, 4.0] {
        let pb = sphere_pose(gap * SIGMA);
        let ab = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
        let ba = collide(&pb, &b, &Pose::identity(), &a, &req).unwrap();
        assert!((ab.probability - ba.probability).abs() < 1e-6, "gap {gap}");
        let (p_ab, p_ba) = (ab.probabilities_a.to_dense(), ba.probabilities_b.to_dense());
        let d = p_ab.iter().zip(&p_ba).map(|(x, y)| (x - y).abs());
        assert!(d.fold(0.0, f64::max) < 1e-5);
        for (ra, rb) in ab.patches.iter().zip(&ba.patches) {
            assert!(
                (ra.normal + rb.normal).norm() < 1e-5,
                "normals point from A to B"
            );
        }
    }
}

#[test]
fn collide_many_equals_a_loop_of_collide() {
    let (a, b) = spheres(600);
    let req = request(Surface::Quadric);
    let poses: Vec<Pose> = (0..8)
        .map(|k| {
            Pose::new(
                Vector3::new(-0.2 - 0.002 * k as f64, 0.01 * k as f64, 0.0),
                Vector3::new(0.0, 0.1 * k as f64, 0.0),
            )
        })
        .collect();
    let many = collide_many(&poses, &a, &Pose::identity(), &b, &req).unwrap();
    for (p, m) in poses.iter().zip(&many) {
        let one = collide(p, &a, &Pose::identity(), &b, &req).unwrap();
        assert_eq!(one.probability, m.probability);
        assert_eq!(one.probabilities_b, m.probabilities_b);
    }
}

/// A approaching B from 6 sigma apart to 3 sigma into it, in steps of a
/// quarter sigma: `collide_along` answers as `collide_many` (each query's
/// classifier starting from the last one's support changes the work, not the
/// optimum: `P` and the per-point probabilities move by the solver's
/// tolerance, 1.4e-5 and 4e-5 at most here) with fewer solver iterations
/// (573 against 801 for the points, 468 against 638 for the elements), for
/// both models; and its answers do not depend on the number of threads.
#[test]
fn collide_along_answers_as_collide_many_with_fewer_iterations() {
    let (a, b) = spheres(2000);
    let poses: Vec<Pose> = (0..=36)
        .map(|k| {
            let gap = (6.0 - 0.25 * f64::from(k)) * SIGMA;
            Pose::translation(-2.0 * common::RADIUS - gap, 0.0, 0.0)
        })
        .collect();
    assert!(poses.len() > 2 * ALONG_RUN);
    for model in [QueryModel::Points, QueryModel::Elements] {
        let req = CollisionRequest {
            model,
            ..CollisionRequest::default()
        };
        let id = Pose::identity();
        let along = collide_along(&poses, &a, &id, &b, &req).unwrap();
        let many = collide_many(&poses, &a, &id, &b, &req).unwrap();
        let iterations = |rs: &[CollisionResult]| -> u64 {
            rs.iter().map(|r| r.stats.counters.solver_iterations).sum()
        };
        // The elements model's `P` combines every facing pair's reading over
        // the contact, so a warm start's slightly different separating surface
        // moves it a little more than the points model's largest tail.
        let tolerance = if model == QueryModel::Points {
            1e-4
        } else {
            1e-3
        };
        for (k, (x, y)) in along.iter().zip(&many).enumerate() {
            assert!(
                (x.probability - y.probability).abs() <= tolerance,
                "{model:?} pose {k}: along {} many {}",
                x.probability,
                y.probability
            );
            let (px, py) = (x.probabilities_b.to_dense(), y.probabilities_b.to_dense());
            for (p, q) in px.iter().zip(&py) {
                assert!((p - q).abs() <= 1e-4, "{model:?} pose {k}: {p} vs {q}");
            }
        }
        // Each run's first pose is queried cold: exactly collide_many's.
        for k in (0..poses.len()).step_by(ALONG_RUN) {
            assert_eq!(along[k].probability, many[k].probability, "pose {k}");
            assert_eq!(along[k].probabilities_b, many[k].probabilities_b);
            assert_eq!(
                along[k].stats.counters.solver_iterations,
                many[k].stats.counters.solver_iterations
            );
        }
        let classified = many.iter().filter(|r| r.stats.counters.patches > 0).count();
        assert!(classified >= 20, "{model:?}: {classified} poses classified");
        assert!(
            iterations(&along) < iterations(&many),
            "{model:?}: {} iterations along, {} one by one",
            iterations(&along),
            iterations(&many)
        );
        let one_thread = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| collide_along(&poses, &a, &id, &b, &req).unwrap());
        for (x, y) in along.iter().zip(&one_thread) {
            assert_eq!(x.probability, y.probability);
            assert_eq!(x.probabilities_b, y.probabilities_b);
        }
    }
}

#[test]
fn refitted_cloud_answers_like_a_fresh_one() {
    let (mut a, b) = spheres(600);
    let _ = a.bvh();
    let shift = Vector3::new(0.05, 0.0, 0.0);
    let moved: Vec<Point3> = a.points().iter().map(|p| p + shift).collect();
    a.set_points(moved.clone()).unwrap();
    a.bvh().assert_well_formed(a.points(), a.sensor_sigma_max());
    let fresh = PointCloud::from_sigma(moved, SIGMA).unwrap();
    let req = request(Surface::Quadric);
    let pb = sphere_pose(0.05 + 2.0 * SIGMA);
    let r1 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
    let r2 = collide(&Pose::identity(), &fresh, &pb, &b, &req).unwrap();
    assert!((r1.probability - r2.probability).abs() < 1e-9);
}

#[test]
fn separation_estimate_tracks_the_exact_gap() {
    // A noisy ball above a noisy plate: the deepest patch's separation follows the
    // exact gap, with the right sign when they interpenetrate.
    let plate =
        cloudprox::sample::box_surface(&Point3::origin(), &Vector3::new(0.2, 0.2, 0.01), 0.008);
    let ball = cloudprox::sample::sphere(&Point3::origin(), 0.05, 1500);
    let a = PointCloud::from_sigma(cloudprox::sample::add_noise(&plate, SIGMA, 1), SIGMA).unwrap();
    let b = PointCloud::from_sigma(cloudprox::sample::add_noise(&ball, SIGMA, 2), SIGMA).unwrap();
    let req = request(Surface::Quadric);
    for gap in [-0.005, 0.0, 0.005, 0.01, 0.02] {
        let pose_b = Pose::translation(0.0, 0.0, 0.06 + gap);
        let r = collide(&Pose::identity(), &a, &pose_b, &b, &req).unwrap();
        if r.patches.is_empty() {
            // Beyond the noise's reach there is no near region to measure in.
            assert!(
                gap > 6.0 * SIGMA && r.state == CollisionState::Free,
                "gap {gap}"
            );
            continue;
        }
        let sep = r
            .patches
            .iter()
            .map(|g| g.separation)
            .fold(f64::INFINITY, f64::min);
        assert!(
            (sep - gap).abs() < 2.0 * SIGMA,
            "exact gap {gap}: estimated {sep}"
        );
    }
}

/// Eq. 3 with each point's own full covariance: `p_i = Phi(-y_i f(x_i) /
/// sqrt(g^T Sigma_i g))`, on plates noisier across the gap than along it (A
/// anisotropic, B isotropic). Moved from the Python suite.
#[test]
fn per_point_probabilities_use_each_points_full_covariance() {
    let grid: Vec<Point3> = (0..144)
        .map(|k| Point3::new(0.01 * f64::from(k / 12), 0.01 * f64::from(k % 12), 0.0))
        .collect();
    let cov = Matrix3::from_diagonal(&Vector3::new(4e-6, 1e-6, 9e-6));
    let a = PointCloud::from_covariances(
        cloudprox::sample::add_noise(&grid, 1e-3, 1),
        vec![cov; grid.len()],
    )
    .unwrap();
    let b = PointCloud::from_sigma(cloudprox::sample::add_noise(&grid, 1e-3, 2), 0.002).unwrap();
    let pose_b = Pose::translation(0.0, 0.0, 0.006);
    let r = collide(
        &Pose::identity(),
        &a,
        &pose_b,
        &b,
        &request(Surface::Linear),
    )
    .unwrap();
    assert!(!r.patches.is_empty());
    let mut checked = 0;
    for patch in &r.patches {
        for (indices, side, probabilities, label) in [
            (&patch.indices_a, 0, &r.probabilities_a, 1.0),
            (&patch.indices_b, 1, &r.probabilities_b, -1.0),
        ] {
            for &i in indices {
                let i = i as usize;
                let (x, sigma) = if side == 0 {
                    (a.points()[i], cov)
                } else {
                    (pose_b * b.points()[i], Matrix3::identity() * 4e-6)
                };
                let (f, g) = patch.separator.value_and_gradient(&x);
                let std = (g.transpose() * sigma * g)[(0, 0)].sqrt();
                let want = normal_cdf(-label * f / std);
                assert!(
                    (probabilities.get(i) - want).abs() <= 1e-9 * want.max(1e-6),
                    "side {side} point {i}: {} vs {want}",
                    probabilities.get(i)
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 0);
}

/// Without noise the state is exact: apart is `P = 0`, overlapping `P = 1`.
/// Moved from the Python suite.
#[test]
fn clouds_without_noise_are_decided_exactly() {
    let pts = cloudprox::sample::sphere(&Point3::origin(), 0.1, 300);
    let a = PointCloud::from_sigma(pts.clone(), 0.0).unwrap();
    let b = PointCloud::from_sigma(pts, 0.0).unwrap();
    let req = CollisionRequest::default();
    let far = collide(
        &Pose::identity(),
        &a,
        &Pose::translation(0.25, 0.0, 0.0),
        &b,
        &req,
    )
    .unwrap();
    assert_eq!((far.probability, far.state), (0.0, CollisionState::Free));
    let deep = collide(
        &Pose::identity(),
        &a,
        &Pose::translation(0.1, 0.0, 0.0),
        &b,
        &req,
    )
    .unwrap();
    assert_eq!(
        (deep.probability, deep.state),
        (1.0, CollisionState::Collision)
    );
}

/// Two 10 cm spheres overlapping by half (1 mm noise): the neighbourhood
/// means of the `surface` aggregation cancel at the crossing, yet every
/// aggregation of the points model and the elements model read a collision.
/// Moved from the Python suite.
#[test]
fn deep_interpenetration_is_a_collision_for_every_aggregation_and_model() {
    let pts = cloudprox::sample::sphere(&Point3::origin(), 0.1, 2000);
    let noisy = |seed| {
        PointCloud::from_sigma(cloudprox::sample::add_noise(&pts, 0.001, seed), 0.001).unwrap()
    };
    let (a, b) = (noisy(1), noisy(2));
    let points = |aggregation| CollisionRequest {
        model: QueryModel::Points,
        aggregation,
        ..CollisionRequest::default()
    };
    let elements = CollisionRequest {
        model: QueryModel::Elements,
        ..CollisionRequest::default()
    };
    for req in [
        points(Aggregation::Max),
        points(Aggregation::Surface),
        elements,
    ] {
        let r = collide(
            &Pose::identity(),
            &a,
            &Pose::translation(0.1, 0.0, 0.0),
            &b,
            &req,
        )
        .unwrap();
        assert_eq!(
            r.state,
            CollisionState::Collision,
            "{:?} {:?}: P = {}",
            req.model,
            req.aggregation,
            r.probability
        );
    }
}

#[test]
fn a_sparse_cloud_against_a_dense_one_gets_bounded_patches() {
    // Three points (one on the surface, two well inside) against a 20 000-point
    // sphere: the sparse cloud's wide spacing makes most of the sphere near,
    // and no cut can keep points of both clouds in each half, so the sparse
    // points are shared between patches.
    let b = PointCloud::from_sigma(
        cloudprox::sample::sphere(&Point3::origin(), 0.1, 20_000),
        0.0005,
    )
    .unwrap();
    let a = PointCloud::from_sigma(
        vec![
            Point3::new(0.1, 0.0, 0.0),
            Point3::new(0.02, 0.03, 0.0),
            Point3::new(0.0, -0.02, 0.03),
        ],
        0.0005,
    )
    .unwrap();
    // The points model's regions (the elements model's samples are few).
    let request = CollisionRequest {
        model: QueryModel::Points,
        region_max_points: 500,
        ..CollisionRequest::default()
    };
    let r = collide(&Pose::identity(), &a, &Pose::identity(), &b, &request).unwrap();
    assert!(r.patches.len() > 1);
    let mut in_patches_a = [0; 3];
    let mut in_patches_b = vec![0; b.len()];
    for p in &r.patches {
        assert!(p.indices_a.len() + p.indices_b.len() <= 500, "{p:?}");
        p.indices_a
            .iter()
            .for_each(|&i| in_patches_a[i as usize] += 1);
        p.indices_b
            .iter()
            .for_each(|&i| in_patches_b[i as usize] += 1);
    }
    // The dense cloud is partitioned; the sparse points are shared.
    assert!(in_patches_b.iter().all(|&c| c <= 1));
    assert!(in_patches_a.iter().any(|&c| c > 1), "{in_patches_a:?}");
    // A shared point reports its largest value over its patches.
    assert!(r.probability >= r.patches.iter().map(|p| p.probability).fold(0.0, f64::max) - 1e-12);
}

/// One points-model query gives `P` under each of the paper's three
/// aggregations: `point_aggregates` equals, bit for bit, the `probability`
/// of a query asking for that aggregation, whichever aggregation (the
/// `surface` one too) and surface family the first query asked for, from
/// well apart through contact to deep overlap. The elements model and
/// `decide_only` have none.
#[test]
fn one_points_query_gives_every_paper_aggregate() {
    let (a, b) = spheres(1500);
    let with = |surface, aggregation| CollisionRequest {
        aggregation,
        ..request(surface)
    };
    let paper = [
        Aggregation::Max,
        Aggregation::Union,
        Aggregation::Independent,
    ];
    let mut nonzero = 0;
    for gap in [-4.0 * SIGMA, -SIGMA, 0.0, SIGMA, 3.0 * SIGMA, 8.0 * SIGMA] {
        let pose = sphere_pose(gap);
        for surface in [Surface::Quadric, Surface::Linear] {
            let own = |agg| collide(&Pose::identity(), &a, &pose, &b, &with(surface, agg));
            let each: Vec<f64> = paper.iter().map(|&g| own(g).unwrap().probability).collect();
            nonzero += usize::from(each[2] > each[0]);
            for asked in [Aggregation::Max, Aggregation::Surface, Aggregation::Union] {
                let r = own(asked).unwrap();
                let got = r.point_aggregates.expect("a points-model query has them");
                for (g, want) in paper.iter().zip(&each) {
                    assert_eq!(
                        got.get(*g).unwrap().to_bits(),
                        want.to_bits(),
                        "gap {gap}, {surface:?}, asked {asked:?}, {g:?}"
                    );
                }
                assert_eq!(got.get(Aggregation::Surface), None);
                if asked != Aggregation::Surface {
                    assert_eq!(got.get(asked), Some(r.probability));
                }
            }
        }
    }
    // The three differ somewhere (else the test could not tell them apart).
    assert!(nonzero >= 4, "independent above max at {nonzero} cases");
    let pose = sphere_pose(0.0);
    let elements = CollisionRequest {
        model: QueryModel::Elements,
        ..CollisionRequest::default()
    };
    let decide = CollisionRequest {
        decide_only: true,
        ..request(Surface::Quadric)
    };
    for req in [elements, decide] {
        let r = collide(&Pose::identity(), &a, &pose, &b, &req).unwrap();
        assert_eq!(r.point_aggregates, None);
    }
}
