//! The surface-element model of the collide query: calibration on plates,
//! invariances, the hierarchy against brute force, decide-only, per-point
//! probabilities.

use crate::common;

use cloudprox::prelude::*;
use cloudprox::probability::{normal_cdf, normal_quantile, point_probability};
use cloudprox::sample::{add_noise, sphere, NormalRng};
use common::{sphere_pose, spheres, RADIUS, SIGMA};

fn elements() -> CollisionRequest {
    CollisionRequest {
        model: QueryModel::Elements,
        ..CollisionRequest::default()
    }
}

/// A slab: two noisy square faces of `k x k` points at spacing `h`, the face
/// that meets the other slab at z = `a x + b y` and its far face at z = `back`
/// (which says on which side the slab's body is).
fn slab(k: usize, h: f64, tilt: (f64, f64), back: f64, sigma: f64, seed: u64) -> PointCloud {
    let c = (k - 1) as f64 * h / 2.0;
    let grid = move |i: usize, j: usize| (i as f64 * h - c, j as f64 * h - c);
    let pts: Vec<Point3> = (0..k * k)
        .map(|n| {
            let (x, y) = grid(n / k, n % k);
            Point3::new(x, y, tilt.0 * x + tilt.1 * y)
        })
        .chain((0..k * k).map(|n| {
            let (x, y) = grid(n / k, n % k);
            Point3::new(x, y, back)
        }))
        .collect();
    PointCloud::from_sigma(add_noise(&pts, sigma, seed), sigma).unwrap()
}

/// `collide` with B lifted by `z`.
fn collide_at_height(
    a: &PointCloud,
    b: &PointCloud,
    z: f64,
    req: &CollisionRequest,
) -> CollisionResult {
    collide(
        &Pose::identity(),
        a,
        &Pose::translation(0.0, 0.0, z),
        b,
        req,
    )
    .unwrap()
}

/// Two slabs, B above A, whose facing faces are parallel planes at a gap drawn
/// uniformly in +-4 standard errors of its fit; collision is the truth when
/// the gap is below 0. Among the draws whose `P` falls in a bin, the share
/// that truly collides matches the bin's mean `P`. Faces tilted against each
/// other by several times their fits' slope error are read where they come
/// closest: a corner 3 standard errors through the other face reads a
/// collision more likely than not although the centres are far apart.
#[test]
fn parallel_plates_probability_is_calibrated() {
    let (k, h, sigma) = (12, 0.005, 0.001);
    let c = (k - 1) as f64 * h / 2.0;
    // Standard errors of the fitted facing faces' gap at the centre and of
    // their relative slope.
    let n = (k * k) as f64;
    let se = sigma * (2.0 / n).sqrt();
    let sum_u2 = n * h * h * ((k * k - 1) as f64) / 12.0;
    let slope_se = sigma * (2.0 / sum_u2).sqrt();
    let req = elements();
    let mut rng = NormalRng::new(7);
    let mut bins = [(0.0, 0.0, 0usize); 5];
    let mut decided_wrong = 0;
    let draws = 400;
    for draw in 0..draws {
        let gap = (rng.uniform() * 2.0 - 1.0) * 4.0 * se;
        let truth = gap < 0.0;
        let a = slab(k, h, (0.0, 0.0), -0.02, sigma, 1000 + draw);
        let b = slab(k, h, (0.0, 0.0), 0.02, sigma, 5000 + draw);
        let r = collide_at_height(&a, &b, gap, &req);
        let p = r.probability;
        let bin = ((p * 5.0) as usize).min(4);
        bins[bin].0 += p;
        bins[bin].1 += f64::from(u8::from(truth));
        bins[bin].2 += 1;
        if (r.state == CollisionState::Collision && !truth)
            || (r.state == CollisionState::Free && truth)
        {
            decided_wrong += 1;
        }
    }
    eprintln!("bins {bins:?} wrong {decided_wrong}");
    for (i, &(sum_p, hits, count)) in bins.iter().enumerate() {
        if count < 20 {
            continue;
        }
        let (predicted, observed) = (sum_p / count as f64, hits / count as f64);
        assert!(
            (predicted - observed).abs() < 0.15,
            "bin {i}: mean P {predicted:.3}, colliding share {observed:.3} of {count}"
        );
    }
    // Decided states are wrong about as often as the thresholds allow.
    assert!(
        decided_wrong <= draws / 10,
        "{decided_wrong} of {draws} decided wrongly"
    );
    // At +-12 standard errors of the gap (1.4 sigma) the states are decided
    // in most draws: a flat face's group splits now and then (the curvature
    // rule), and a split face's pieces are located less precisely than the
    // whole face, so a few draws stay undecided; none is decided wrongly.
    let (mut free, mut collision) = (0, 0);
    let pairs: u64 = 20;
    for seed in 0..pairs {
        let a = slab(k, h, (0.0, 0.0), -0.02, sigma, 1 + 2 * seed);
        let b = slab(k, h, (0.0, 0.0), 0.02, sigma, 2 + 2 * seed);
        let above = collide_at_height(&a, &b, 12.0 * se, &req).state;
        let below = collide_at_height(&a, &b, -12.0 * se, &req).state;
        assert_ne!(above, CollisionState::Collision, "seed {seed}");
        assert_ne!(below, CollisionState::Free, "seed {seed}");
        free += u64::from(above == CollisionState::Free);
        collision += u64::from(below == CollisionState::Collision);
    }
    assert!(free >= pairs * 3 / 4, "{free} of {pairs} decided free");
    assert!(
        collision >= pairs * 3 / 4,
        "{collision} of {pairs} decided collision"
    );
    // Tilted by six slope errors about y: B's face at x = -c lies 3 standard
    // errors below A's, its centre `6 slope_se c - 3 se` (6.6 se) above.
    let tilt = 6.0 * slope_se;
    let mut likely = 0;
    for seed in 0..pairs {
        let a = slab(k, h, (0.0, 0.0), -0.02, sigma, 300 + seed);
        let b = slab(k, h, (tilt, 0.0), 0.02, sigma, 400 + seed);
        let r = collide_at_height(&a, &b, tilt * c - 3.0 * se, &req);
        likely += u64::from(r.probability > 0.5);
    }
    // (17 of these 20 do: a pair whose most precise reading lies near the
    // corner too reads the variation as within the noise, and the corner
    // is missed.)
    assert!(likely >= pairs * 3 / 4, "{likely} of {pairs} read P > 0.5");
}

#[test]
fn spheres_are_decided_within_a_sigma_of_contact() {
    // Five pairs of noise draws (seeds 100-104 and 200-204); the claims hold
    // for the median pair at each gap.
    let req = elements();
    let gaps = [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 6.0];
    let per_draw: Vec<Vec<f64>> = (0..5u64)
        .map(|seed| {
            let sphere_cloud = |s: u64| {
                let pts = add_noise(&sphere(&Point3::origin(), RADIUS, 10000), SIGMA, s);
                PointCloud::from_sigma(pts, SIGMA).unwrap()
            };
            let (a, b) = (sphere_cloud(100 + seed), sphere_cloud(200 + seed));
            gaps.map(|k| {
                collide(&Pose::identity(), &a, &sphere_pose(k * SIGMA), &b, &req)
                    .unwrap()
                    .probability
            })
            .to_vec()
        })
        .collect();
    let ps: Vec<f64> = (0..gaps.len())
        .map(|g| {
            let mut at: Vec<f64> = per_draw.iter().map(|p| p[g]).collect();
            at.sort_by(f64::total_cmp);
            at[at.len() / 2]
        })
        .collect();
    for w in ps.windows(2) {
        assert!(w[1] <= w[0] + 0.05, "{ps:?}");
    }
    // With 10 000 points per sphere the surfaces are located to a fraction of
    // sigma: one sigma either side of contact is decided (or nearly).
    assert!(ps[0] > 0.999 && ps[1] > 0.99 && ps[2] > 0.9, "{ps:?}");
    assert!(ps[5] < 0.1 && ps[6] < 0.01 && ps[7] < 1e-6, "{ps:?}");
    // Touching reads P near 1/2 over the draws (0.44: 0.92, 0.65, 0.19, 0.35
    // and 0.08, the contact's readings pooled into one gap field); a sigma
    // apart is free or nearly in every draw.
    let touching = per_draw.iter().map(|p| p[3]).sum::<f64>() / per_draw.len() as f64;
    assert!((0.2..0.8).contains(&touching), "{touching} of {per_draw:?}");
    assert!(per_draw.iter().all(|p| p[4] < 0.1), "{per_draw:?}");
}

#[test]
fn rigid_motion_and_swapping_change_nothing() {
    let (a, b) = spheres(3000);
    let req = elements();
    let t = Pose::new(Vector3::new(0.3, -0.4, 1.0), Vector3::new(1.0, 2.0, -0.5));
    for gap in [-2.0, 0.0, 1.0, 3.0] {
        let pb = sphere_pose(gap * SIGMA);
        let r0 = collide(&Pose::identity(), &a, &pb, &b, &req).unwrap();
        let r1 = collide(&t, &a, &(t * pb), &b, &req).unwrap();
        assert!((r0.probability - r1.probability).abs() < 1e-9, "gap {gap}");
        let rs = collide(&pb, &b, &Pose::identity(), &a, &req).unwrap();
        assert!(
            (r0.probability - rs.probability).abs() < 1e-6,
            "gap {gap}: {} vs swapped {}",
            r0.probability,
            rs.probability
        );
        assert_eq!(r0.state, rs.state);
    }
}

#[test]
fn hierarchy_agrees_with_brute_force() {
    let (a, b) = spheres(1500);
    let brute = CollisionRequest {
        model: QueryModel::Elements,
        use_hierarchy: false,
        ..CollisionRequest::default()
    };
    for gap in [-2.0, -1.0, 0.0, 1.0, 2.0, 4.0, 8.0] {
        let pb = sphere_pose(gap * SIGMA);
        let fast = collide(&Pose::identity(), &a, &pb, &b, &elements()).unwrap();
        let slow = collide(&Pose::identity(), &a, &pb, &b, &brute).unwrap();
        if fast.patches.len() <= 1 && slow.patches.len() <= 1 {
            assert!(
                (fast.probability - slow.probability).abs() < 1e-6,
                "gap {gap}: {} vs {}",
                fast.probability,
                slow.probability
            );
        } else {
            assert_eq!(fast.state, slow.state, "gap {gap}");
        }
    }
}

#[test]
fn decide_only_gives_the_full_querys_state() {
    let (a, b) = spheres(3000);
    for model in [QueryModel::Elements, QueryModel::Points] {
        let full = CollisionRequest {
            model,
            ..CollisionRequest::default()
        };
        let quick = CollisionRequest {
            model,
            decide_only: true,
            ..CollisionRequest::default()
        };
        let mut crossings = 0;
        for gap in [-4.0, -2.0, -1.0, 0.0, 1.0, 2.0, 4.0, 8.0, 20.0] {
            let pb = sphere_pose(gap * SIGMA);
            let r = collide(&Pose::identity(), &a, &pb, &b, &full).unwrap();
            let q = collide(&Pose::identity(), &a, &pb, &b, &quick).unwrap();
            assert_eq!(r.state, q.state, "{model:?} gap {gap}");
            assert!(q.probabilities_a.to_dense().iter().all(|&p| p == 0.0));
            assert_eq!(q.probabilities_a.len(), a.len());
            crossings += q.stats.counters.surface_crossings;
        }
        // The elements' deepest pose (4 sigma, 8 mm) is decided by a crossing
        // of surfaces; the points model has none.
        match model {
            QueryModel::Elements => assert!(crossings >= 1, "{crossings} crossings"),
            QueryModel::Points => assert_eq!(crossings, 0),
        }
    }
}

#[test]
fn deciding_only_a_crossing_of_element_surfaces_is_a_collision_without_a_classifier() {
    // Two 10 000-point spheres: interpenetrating by 3 sigma their surfaces
    // cross along a ring, which the hierarchies find before any near set; a
    // sigma apart and beyond nothing crosses, and the query goes on as before.
    let (a, b) = spheres(10000);
    let quick = CollisionRequest {
        model: QueryModel::Elements,
        decide_only: true,
        ..CollisionRequest::default()
    };
    for gap in [-6.0, -3.0, -2.0] {
        let q = collide(&Pose::identity(), &a, &sphere_pose(gap * SIGMA), &b, &quick).unwrap();
        assert_eq!(q.stats.counters.surface_crossings, 1, "gap {gap}");
        assert_eq!(q.state, CollisionState::Collision, "gap {gap}");
        assert!(q.patches.is_empty() && q.stats.counters.points_classified == 0);
        // The crossing's bound at the noise's reach: 1 - 2 Phi(-z).
        let z = -normal_quantile(0.5 * quick.prune_epsilon);
        assert!((q.probability - (1.0 - 2.0 * normal_cdf(-z))).abs() < 1e-12);
    }
    for gap in [1.0, 3.0, 8.0] {
        let q = collide(&Pose::identity(), &a, &sphere_pose(gap * SIGMA), &b, &quick).unwrap();
        assert_eq!(q.stats.counters.surface_crossings, 0, "gap {gap}");
        let full = collide(
            &Pose::identity(),
            &a,
            &sphere_pose(gap * SIGMA),
            &b,
            &elements(),
        );
        assert_eq!(q.state, full.unwrap().state, "gap {gap}");
        if gap >= 3.0 {
            assert_ne!(q.state, CollisionState::Collision, "gap {gap}");
        }
    }
    // The full query reads the crossings only where its patches found no
    // collision: here they did.
    let r = collide(
        &Pose::identity(),
        &a,
        &sphere_pose(-3.0 * SIGMA),
        &b,
        &elements(),
    )
    .unwrap();
    assert_eq!(r.stats.counters.surface_crossings, 0);
    assert_eq!(r.state, CollisionState::Collision);
    // A collision threshold above the reach's confidence asks more of the
    // crossing: both probes then read beyond the threshold's quantile.
    let strict = CollisionRequest {
        model: QueryModel::Elements,
        decide_only: true,
        thresholds: Thresholds {
            collision: 1.0 - 1e-9,
            free: 0.1,
        },
        ..CollisionRequest::default()
    };
    let q = collide(
        &Pose::identity(),
        &a,
        &sphere_pose(-6.0 * SIGMA),
        &b,
        &strict,
    )
    .unwrap();
    assert!(q.probability >= 1.0 - 1e-9);
    // The brute-force path (every pair, no hierarchies) reads the same
    // crossings: at the reach, beyond it (the strict threshold), and none
    // where the surfaces are apart.
    // (Deep into each other the strict threshold's crossing may or may not be
    // read, by how uncertain the curved element surfaces are near their
    // edges; both paths read the same.)
    for (request, gap, crossings) in [
        (&quick, -3.0, Some(1)),
        (&strict, -6.0, None),
        (&quick, 3.0, Some(0)),
    ] {
        let brute = CollisionRequest {
            use_hierarchy: false,
            ..*request
        };
        let pose = sphere_pose(gap * SIGMA);
        let h = collide(&Pose::identity(), &a, &pose, &b, request).unwrap();
        let bf = collide(&Pose::identity(), &a, &pose, &b, &brute).unwrap();
        assert_eq!(bf.stats.counters.node_pairs_visited, 0, "gap {gap}");
        assert_eq!(
            h.stats.counters.surface_crossings, bf.stats.counters.surface_crossings,
            "gap {gap}"
        );
        if let Some(crossings) = crossings {
            assert_eq!(h.stats.counters.surface_crossings, crossings, "gap {gap}");
        }
        if h.stats.counters.surface_crossings > 0 {
            assert_eq!(
                (bf.state, bf.probability),
                (h.state, h.probability),
                "gap {gap}"
            );
        }
    }
}

/// A leg (a cylinder of 5 cm radius, 60 cm long, tilted by 0.2 rad) pushed
/// through a 10 cm slab the size of a room's floor (6.2 x 5.2 m), both sampled
/// at 626 points per square metre with 14.5 mm of noise: a piano's leg through
/// the floor at 0.5% of the piano's size in the reproduction's scene. The
/// slab's faces are flat, so each becomes a few elements of thousands of
/// points and metres across. Five samples per element left the leg's points
/// inside the slab near none of them (no near region in most draws; the
/// patches read a collision in 6 of these 12, the surfaces' crossing read
/// after them in 11); the element pairs whose surfaces face within reach
/// then linked them into the near set (12 of 12). Now such elements are also
/// sampled on a grid of six spacings, so the near rule on the samples finds
/// the leg itself, and the patches read the collision in every draw.
#[test]
fn a_leg_through_a_floor_sized_slab_collides_in_every_draw() {
    let (density, sigma) = (626.0, 0.0145);
    let leg = Mesh::cylinder(0.05, 0.3, 32).unwrap();
    let floor = Mesh::cuboid(3.1, 2.6, 0.05).unwrap();
    let leg_points = leg.sample_surface_density(density, 1).unwrap().points;
    let floor_points = floor.sample_surface_density(density, 2).unwrap().points;
    // The leg's end 1.4-2.4 cm beyond the slab's lower face (its rim tilted).
    let pose = Pose::from_parts(
        nalgebra::Translation3::new(0.0, 0.0, 0.3 - 0.05 - 0.02),
        nalgebra::UnitQuaternion::from_euler_angles(0.2, 0.0, 0.0),
    );
    let full = elements();
    let quick = CollisionRequest {
        decide_only: true,
        ..elements()
    };
    let draws = 12;
    for seed in 0..draws {
        let a = PointCloud::from_sigma(add_noise(&leg_points, sigma, 100 + seed), sigma).unwrap();
        let b = PointCloud::from_sigma(add_noise(&floor_points, sigma, 200 + seed), sigma).unwrap();
        let r = collide(&pose, &a, &Pose::identity(), &b, &full).unwrap();
        let q = collide(&pose, &a, &Pose::identity(), &b, &quick).unwrap();
        // Deciding only never says more than the full query.
        assert_eq!(
            r.state, q.state,
            "draw {seed}: P {} vs {}",
            r.probability, q.probability
        );
        let c = &r.stats.counters;
        assert_eq!(
            r.state,
            CollisionState::Collision,
            "draw {seed}: P {}, {} links, {} regions",
            r.probability,
            c.surface_links,
            c.near_regions
        );
        // The patches said so, not the crossing read after them.
        assert_eq!(c.surface_crossings, 0, "draw {seed}");
        assert!(c.near_regions > 0, "draw {seed}");
        // The floor's points beyond the noise's reach of the leg (half a
        // metre from it, where the floor's elements reach) are no evidence.
        let far = (0..b.len())
            .filter(|&i| b.points()[i].coords.xy().norm() > 0.5)
            .map(|i| r.probabilities_b.get(i))
            .fold(0.0, f64::max);
        assert_eq!(far, 0.0, "draw {seed}");
    }
}

/// A face tilted by `atan(0.5)` whose lower end lies just above a flat face,
/// both sampled at 4 mm with 0.1 mm of noise: the fitted surfaces are
/// located to a few hundredths of a millimetre, but where a sampled face
/// ends is known only to about half a spacing, which moves its end by
/// `sin(theta) h/2` (0.89 mm) towards the other face. At half that gap the
/// query is undecided; at four times it, free.
#[test]
fn a_face_ending_at_an_angle_over_another_is_uncertain_by_half_a_spacing() {
    let (h, sigma, slope): (f64, f64, f64) = (0.004, 0.0001, 0.5);
    let k = 12;
    let c = (k - 1) as f64 * h / 2.0;
    let edge_sd = (slope / (1.0 + slope * slope).sqrt()) * h / 2.0;
    // A's facing face at z = slope x (its body above it), B's flat and wider
    // below it (its body below).
    let a = slab(k, h, (slope, 0.0), slope * c + 0.02, sigma, 1);
    let b = slab(3 * k, h, (0.0, 0.0), -0.02, sigma, 2);
    let req = elements();
    let lowest = -slope * c;
    let near = collide_at_height(&a, &b, lowest - 0.5 * edge_sd, &req);
    assert_eq!(
        near.state,
        CollisionState::Contact,
        "P = {}",
        near.probability
    );
    assert!(near.probability > 0.05, "P = {}", near.probability);
    let far = collide_at_height(&a, &b, lowest - 4.0 * edge_sd, &req);
    assert_eq!(far.state, CollisionState::Free, "P = {}", far.probability);
}

#[test]
fn flat_faces_meeting_at_an_angle_cross_and_parallel_ones_never_do() {
    // A's slab face tilted by 0.2 rad about y through B's (flat) face: the
    // faces cross along the y axis. B's face lifted so that A's face lies
    // 2 sigma below it everywhere: parallel, no crossing (though in contact).
    let sigma = 0.0005;
    let a = slab(30, 0.004, (0.2, 0.0), -0.05, sigma, 1);
    let tilted_back = slab(30, 0.004, (0.0, 0.0), 0.05, sigma, 2);
    let quick = CollisionRequest {
        model: QueryModel::Elements,
        decide_only: true,
        ..CollisionRequest::default()
    };
    let q = collide_at_height(&a, &tilted_back, 0.0, &quick);
    assert_eq!(q.stats.counters.surface_crossings, 1);
    assert_eq!(q.state, CollisionState::Collision);
    // The full query, with the hierarchies and without: the same state.
    for use_hierarchy in [true, false] {
        let full = CollisionRequest {
            model: QueryModel::Elements,
            use_hierarchy,
            ..CollisionRequest::default()
        };
        let r = collide_at_height(&a, &tilted_back, 0.0, &full);
        assert_eq!(r.state, CollisionState::Collision, "{use_hierarchy}");
    }
    let flat = slab(30, 0.004, (0.0, 0.0), -0.05, sigma, 3);
    for z in [-2.0 * sigma, 0.0, 2.0 * sigma] {
        let q = collide_at_height(&flat, &tilted_back, z, &quick);
        assert_eq!(q.stats.counters.surface_crossings, 0, "height {z}");
    }
}

/// The box around `points` and the largest `sqrt(trace)` of `covs`.
fn box_and_std(points: &[Point3], covs: &[Matrix3]) -> (Point3, Point3, f64) {
    let mut lo = Point3::from([f64::INFINITY; 3]);
    let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let std = covs.iter().map(|c| c.trace().sqrt()).fold(0.0, f64::max);
    (lo, hi, std)
}

/// Eq. 3 of each point of a patch against its surface, or 0 where the point
/// lies farther from the box around the other side's points than the two
/// sides' noise can reach (brute force, in B's frame).
#[test]
fn per_point_probabilities_are_eq3_against_the_reported_surface() {
    let (a, b) = spheres(3000);
    let pb = sphere_pose(SIGMA);
    let request = elements();
    let r = collide(&Pose::identity(), &a, &pb, &b, &request).unwrap();
    assert_eq!(r.patches.len(), 1);
    let region = &r.patches[0];
    assert!(!region.indices_a.is_empty() && !region.indices_b.is_empty());
    let reach = -normal_quantile(0.5 * request.prune_epsilon);
    let rot = *pb.rotation.to_rotation_matrix().matrix();
    let side =
        |cloud: &PointCloud, idx: &[u32], pose: &Pose, turn: &Matrix3| -> Vec<(Point3, Matrix3)> {
            idx.iter()
                .map(|&i| {
                    let c = cloud.covariances()[i as usize];
                    (
                        pose * cloud.points()[i as usize],
                        turn * c * turn.transpose(),
                    )
                })
                .collect()
        };
    let sa = side(
        &a,
        &region.indices_a,
        &Pose::identity(),
        &Matrix3::identity(),
    );
    let sb = side(&b, &region.indices_b, &pb, &rot);
    let split =
        |s: &[(Point3, Matrix3)]| -> (Vec<Point3>, Vec<Matrix3>) { s.iter().copied().unzip() };
    let (boxes_a, boxes_b) = (split(&sa), split(&sb));
    let (box_a, box_b) = (
        box_and_std(&boxes_a.0, &boxes_a.1),
        box_and_std(&boxes_b.0, &boxes_b.1),
    );
    let mut counts = [0usize; 2];
    let mut check = |own: &[(Point3, Matrix3)],
                     idx: &[u32],
                     other: &(Point3, Point3, f64),
                     label: f64,
                     got: &dyn Fn(usize) -> f64| {
        for (&i, (x, cov)) in idx.iter().zip(own) {
            let outside = (other.0 - x)
                .sup(&(x - other.1))
                .sup(&Vector3::zeros())
                .norm();
            let radius = reach * (cov.trace().sqrt() + other.2);
            let want = if outside > radius {
                counts[1] += 1;
                0.0
            } else {
                counts[0] += 1;
                let (f, g) = region.separator.value_and_gradient(x);
                point_probability(f, &g, cov, label)
            };
            assert!(
                (want - got(i as usize)).abs() < 1e-9,
                "point {i}: {} vs {want}",
                got(i as usize)
            );
        }
    };
    check(&sa, &region.indices_a, &box_b, 1.0, &|i| {
        r.probabilities_a.get(i)
    });
    check(&sb, &region.indices_b, &box_a, -1.0, &|i| {
        r.probabilities_b.get(i)
    });
    // Both rules are exercised: the spheres' patch elements reach past the
    // other sphere's noise.
    assert!(counts[0] > 0 && counts[1] > 0, "{counts:?}");
    // The region holds tens of samples, not thousands of points.
    assert!(r.stats.counters.points_classified < 400, "{:?}", r.stats);
    // Every point of the patch's elements is reported, none outside it.
    let inside: std::collections::HashSet<u32> = region.indices_a.iter().copied().collect();
    for (i, &p) in r.probabilities_a.to_dense().iter().enumerate() {
        if !inside.contains(&(i as u32)) {
            assert_eq!(p, 0.0, "point {i} outside the patch");
        }
    }
    assert!(region
        .indices_a
        .iter()
        .any(|&i| r.probabilities_a.get(i as usize) > 0.0));
}

#[test]
fn moved_points_give_the_elements_of_a_fresh_cloud() {
    let (a, _) = spheres(2000);
    let mut moved = a.clone();
    let shifted: Vec<Point3> = a
        .points()
        .iter()
        .map(|p| p + Vector3::new(0.01, 0.0, 0.0))
        .collect();
    let _ = moved.elements();
    moved.set_points(shifted.clone()).unwrap();
    let fresh = PointCloud::from_sigma(shifted, SIGMA).unwrap();
    assert_eq!(moved.elements().elements(), fresh.elements().elements());
    // The elements' own copies of their points moved too: a query near
    // contact reads the same per-point probabilities from either cloud.
    let (_, b) = spheres(2000);
    let pose = sphere_pose(0.01 + SIGMA);
    let r = collide(&Pose::identity(), &moved, &pose, &b, &elements()).unwrap();
    let f = collide(&Pose::identity(), &fresh, &pose, &b, &elements()).unwrap();
    assert!(
        !r.probabilities_a.indices().is_empty(),
        "no point near contact"
    );
    assert_eq!(r.probability, f.probability);
    assert_eq!(r.probabilities_a, f.probabilities_a);
    assert_eq!(r.probabilities_b, f.probabilities_b);
}

#[test]
fn surfaces_that_cannot_reach_are_decided_free_without_a_classifier() {
    // 1 mm of noise on 3000-point spheres: an element of tens of points locates
    // its surface to a fraction of a millimetre, so a few sigma apart the
    // points are near (their noise reaches across: the points model
    // classifies them) but no element faces the other sphere within the
    // noise's reach of the fitted surfaces: the element hulls (or, failing
    // them, each patch's facing pairs) decide the pair free.
    let (a, b) = spheres(3000);
    let points = CollisionRequest {
        model: QueryModel::Points,
        ..CollisionRequest::default()
    };
    let mut pruned = 0;
    for gap in [3.0, 4.0, 5.0, 6.0, 7.0] {
        let pose = sphere_pose(gap * SIGMA);
        let r = collide(&Pose::identity(), &a, &pose, &b, &elements()).unwrap();
        if r.stats.counters.points_classified > 0 {
            continue;
        }
        let p = collide(&Pose::identity(), &a, &pose, &b, &points).unwrap();
        if p.stats.counters.points_classified == 0 {
            continue;
        }
        pruned += 1;
        assert!(r.patches.is_empty(), "gap {gap}");
        assert_eq!(r.probability, 0.0);
        assert_eq!(r.state, CollisionState::Free);
        assert!(r
            .probabilities_a
            .to_dense()
            .iter()
            .chain(&r.probabilities_b.to_dense())
            .all(|&p| p == 0.0));
        assert_eq!(
            (r.probabilities_a.len(), r.probabilities_b.len()),
            (a.len(), b.len())
        );
    }
    assert!(pruned >= 1, "no gap between 3 and 7 sigma was pruned");
    let near = collide(&Pose::identity(), &a, &sphere_pose(SIGMA), &b, &elements()).unwrap();
    assert_eq!(
        near.stats.counters.patches_beyond_reach, 0,
        "{:?}",
        near.stats
    );
    assert!(!near.patches.is_empty());
}

/// Two noisy spheres of `na`, `nb` points (radii `ra`, `rb`, noise `sigma`,
/// `outliers` points off each surface: single-point elements) whose exact
/// surfaces are `gap` sigma apart along `dir`, B turned by `rot`.
#[allow(clippy::too_many_arguments)]
fn sphere_scene(
    (na, nb): (usize, usize),
    (ra, rb): (f64, f64),
    sigma: f64,
    outliers: usize,
    gap: f64,
    dir: Vector3,
    rot: Vector3,
    seed: u64,
) -> (PointCloud, PointCloud, Pose) {
    let cloud = |n: usize, r: f64, seed: u64| {
        let mut pts = add_noise(&sphere(&Point3::origin(), r, n), sigma, seed);
        let mut rng = NormalRng::new(seed + 100);
        for _ in 0..outliers {
            let d = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            pts.push(Point3::from(d * (r + sigma * 8.0 * (rng.uniform() - 0.5))));
        }
        PointCloud::from_sigma(pts, sigma).unwrap()
    };
    let (a, b) = (cloud(na, ra, seed), cloud(nb, rb, seed + 1));
    let pose = Pose::new(dir.normalize() * (ra + rb + gap * sigma), rot);
    (a, b, pose)
}

use proptest::prelude::*;

/// Random [`sphere_scene`]s: `points` per sphere, radii 3-8 cm, noise 0.5-4
/// mm, up to 5 outliers, exact gap in `gaps` (sigmas), any direction and
/// turn; with the gap.
fn sphere_scenes(
    points: std::ops::Range<usize>,
    gaps: std::ops::Range<f64>,
) -> impl Strategy<Value = (PointCloud, PointCloud, Pose, f64)> {
    let dir = prop::array::uniform3(-1.0f64..1.0)
        .prop_filter("non-zero", |d| d.iter().map(|x| x * x).sum::<f64>() > 0.01);
    (
        (points.clone(), points),
        (0.03f64..0.08, 0.03f64..0.08),
        0.0005f64..0.004,
        0usize..6,
        gaps,
        dir,
        prop::array::uniform3(-3.0f64..3.0),
        0u64..1000,
    )
        .prop_map(|(n, r, sigma, outliers, gap, dir, rot, seed)| {
            let rot = Vector3::from(rot);
            let (a, b, pose) =
                sphere_scene(n, r, sigma, outliers, gap, Vector3::from(dir), rot, seed);
            (a, b, pose, gap)
        })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(20261124),
        .. ProptestConfig::default()
    })]

    /// The hierarchy path (which first bounds the element hulls, then finds
    /// the near set with the trees) against the brute-force path (every
    /// sample pair, no hulls): where the hulls say the clouds are free, the
    /// brute-force query finds no probability either, and the states agree
    /// wherever either is decisive.
    #[test]
    fn element_hierarchy_agrees_with_brute_force(
        (a, b, pose_b, gap) in sphere_scenes(300..1500, -3.0..14.0),
    ) {
        let brute = CollisionRequest { model: QueryModel::Elements, use_hierarchy: false, ..CollisionRequest::default() };
        let h = collide(&Pose::identity(), &a, &pose_b, &b, &elements()).unwrap();
        let bf = collide(&Pose::identity(), &a, &pose_b, &b, &brute).unwrap();
        let (ph, pb) = (h.probability, bf.probability);
        if h.stats.counters.near_regions == 0 {
            prop_assert_eq!(ph, 0.0);
            prop_assert!(pb < 1e-9, "hulls apart at gap {} sigma, brute force P = {}", gap, pb);
        }
        for (x, y, what) in [(ph, pb, "hierarchy decisive"), (pb, ph, "brute force decisive")] {
            prop_assert!(!(x <= 0.01 && y > 0.1), "{}: {} vs {} at gap {} sigma", what, x, y, gap);
            prop_assert!(!(x >= 0.99 && y < 0.9), "{}: {} vs {} at gap {} sigma", what, x, y, gap);
        }
    }

    /// Deciding only gives the full query's state, with or without a crossing
    /// of element surfaces found first (sphere pairs of random sizes, noise,
    /// outliers and poses from 6 sigma of interpenetration to 6 apart).
    #[test]
    fn decide_only_agrees_with_the_full_query(
        (a, b, pose_b, gap) in sphere_scenes(300..3000, -6.0..6.0),
    ) {
        let quick = CollisionRequest { model: QueryModel::Elements, decide_only: true, ..CollisionRequest::default() };
        let r = collide(&Pose::identity(), &a, &pose_b, &b, &elements()).unwrap();
        let q = collide(&Pose::identity(), &a, &pose_b, &b, &quick).unwrap();
        prop_assert_eq!(
            r.state, q.state,
            "gap {} sigma: full P = {}, decide-only P = {} (crossings {})",
            gap, r.probability, q.probability, q.stats.counters.surface_crossings
        );
    }
}

/// A stray point with 5 mm of noise whose spacing (10 cm to its nearest
/// neighbours, a scan's flying pixel) lets it stand for 5 cm of surface, over
/// a plate: whether it is near is the near rule's to say, on the point itself,
/// as in the points model. A single point's hull bounds its reach in every
/// direction at once (`sqrt(3)` of its standard deviation for isotropic
/// noise), looser than the near rule along the gap; read as a link, that
/// bound made a near region at 7.4 and 7.6 cm, where the near rule keeps the
/// point apart (the Kinect frame: regions of points 8 sigma from the gripper).
#[test]
fn a_stray_point_is_near_a_surface_only_by_the_near_rule() {
    let plate = slab(40, 0.005, (0.0, 0.0), -0.02, 0.001, 7);
    let points = CollisionRequest {
        model: QueryModel::Points,
        ..CollisionRequest::default()
    };
    for (d, near) in [
        (0.05, true),
        (0.06, true),
        (0.074, false),
        (0.076, false),
        (0.09, false),
    ] {
        // A noisy parallel patch 10 cm above the point gives it its spacing.
        let grid: Vec<Point3> = (0..900)
            .map(|n| {
                let (i, j) = ((n / 30) as f64, (n % 30) as f64);
                Point3::new(i * 0.003 - 0.045, j * 0.003 - 0.045, d + 0.1)
            })
            .collect();
        let mut pts = add_noise(&grid, 0.001, 11);
        let mut sigmas = vec![0.001; pts.len()];
        pts.push(Point3::new(0.0, 0.0, d));
        sigmas.push(0.005);
        let b = PointCloud::from_sigmas(pts, sigmas).unwrap();
        let els = b.elements();
        let stray = (0..els.elements().len() as u32)
            .find(|&k| els.element_points(k).contains(&900))
            .unwrap();
        assert!(
            els.elements()[stray as usize].is_point(),
            "d {d}: the stray point is an element of its own"
        );
        let id = Pose::identity();
        let r = collide(&id, &plate, &id, &b, &elements()).unwrap();
        let p = collide(&id, &plate, &id, &b, &points).unwrap();
        let (c, cp) = (&r.stats.counters, &p.stats.counters);
        assert_eq!(c.surface_links, 0, "d {d}");
        assert_eq!(cp.near_regions > 0, near, "d {d}: the near rule");
        assert_eq!(c.near_regions > 0, near, "d {d}: {c:?}");
        assert_eq!(r.state, CollisionState::Free, "d {d}");
    }
}
