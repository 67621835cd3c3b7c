//! The exact-side query: a mesh's surface as the separating surface.

use crate::common::{RADIUS, SIGMA};

use cloudprox::prelude::*;
use cloudprox::probability::{contact_probability, normal_cdf, ElementReading};
use cloudprox::query::collide::MeshSide;
use cloudprox::query::exact_side::{
    collide_cloud_exact, collide_exact_cloud, collide_exact_cloud_many,
};
use cloudprox::sample::{add_noise, sphere};
use cloudprox::shape::MeshDistance;
use nalgebra::{Translation3, UnitQuaternion};

/// The unit cube (half extent 0.5) as a signed distance.
fn unit_cube() -> MeshDistance {
    MeshDistance::new(&Mesh::cuboid(0.5, 0.5, 0.5).unwrap()).unwrap()
}

/// A flat 30 x 30 grid at 1 cm pitch, `gap` below the cube's bottom face.
fn plane(gap: f64) -> Vec<Point3> {
    (0..900)
        .map(|i| {
            let (u, v) = (
                f64::from(i % 30) * 0.01 - 0.145,
                f64::from(i / 30) * 0.01 - 0.145,
            );
            Point3::new(u, v, -0.5 - gap)
        })
        .collect()
}

fn query(cloud: &PointCloud, pose_cloud: &Pose) -> CollisionResult {
    collide_exact_cloud(
        &Pose::identity(),
        &unit_cube(),
        pose_cloud,
        cloud,
        &CollisionRequest::default(),
    )
    .unwrap()
}

#[test]
fn p_over_noise_draws_follows_the_plane_fit_error() {
    // A noisy plane (2 mm) under the cube: flat elements of hundreds of
    // points whose fitted height is known to about sigma / 30 at their mean
    // (more towards their edges, where P reads them). Over 60 draws: at the
    // contact P is near 1/2 on average; at 20 standard errors of the fit
    // outside (0.67 sigma of a point), almost always free; 20 inside,
    // almost always collision.
    let sigma = 0.002;
    let se = sigma / 30.0;
    let draws = |gap: f64| -> Vec<f64> {
        (0..60)
            .map(|seed| {
                let pts = add_noise(&plane(gap), sigma, seed);
                query(
                    &PointCloud::from_sigma(pts, sigma).unwrap(),
                    &Pose::identity(),
                )
                .probability
            })
            .collect()
    };
    let at_contact = draws(0.0);
    let mean = at_contact.iter().sum::<f64>() / 60.0;
    assert!((0.35..0.85).contains(&mean), "mean P at contact {mean}");
    let outside = draws(20.0 * se);
    let inside = draws(-20.0 * se);
    let share = |v: &[f64], f: fn(f64) -> bool| v.iter().filter(|&&p| f(p)).count();
    assert!(share(&outside, |p| p <= 0.1) >= 55, "{outside:?}");
    assert!(share(&inside, |p| p >= 0.9) >= 55, "{inside:?}");
    // Far beyond the single points' reach (1 cm = 5 sigma of a point): 0.
    assert_eq!(draws(0.01).iter().copied().fold(0.0, f64::max), 0.0);
}

#[test]
fn per_point_probabilities_are_eq_3() {
    // Five scattered points under the bottom face, anisotropic covariances:
    // the gradient is -z there, so p = Phi(-d / sigma_z).
    let d = [0.001, 0.002, 0.0005, -0.001, 0.003];
    let pts: Vec<Point3> = d
        .iter()
        .enumerate()
        .map(|(i, &d)| Point3::new(0.1 * i as f64 - 0.2, 0.05, -0.5 - d))
        .collect();
    let sz = 0.0015;
    let cov = Matrix3::from_diagonal(&Vector3::new(4e-6, 9e-6, sz * sz));
    let cloud = PointCloud::from_covariances(pts, vec![cov; 5]).unwrap();
    let r = query(&cloud, &Pose::identity());
    assert_eq!(r.probabilities_b.len(), 5);
    assert!(r.probabilities_a.is_empty());
    for (i, &d) in d.iter().enumerate() {
        let want = normal_cdf(-d / sz);
        let got = r.probabilities_b.get(i);
        assert!((got - want).abs() < 1e-12, "point {i}: {got} vs {want}");
    }
    // Single points: each reads its Eq. 3 gap and standard deviation, and
    // P is the elements model's over them.
    let readings: Vec<ElementReading> = (0..5)
        .map(|k| ElementReading {
            own: k,
            other: k,
            gap: d[k as usize],
            std: sz,
            fit_std: sz,
            beside: false,
            contact: 0,
            at: None,
            direction: Vector3::zeros(),
        })
        .collect();
    assert!((r.probability - contact_probability(&readings)).abs() < 1e-12);
}

/// A noisy sphere cloud (radius 0.1 m) and a 10 cm cube mesh `gap` above it.
fn sphere_scene() -> (PointCloud, Mesh) {
    let pts = add_noise(&sphere(&Point3::origin(), RADIUS, 2000), SIGMA, 31);
    let cloud = PointCloud::from_sigma(pts, SIGMA).unwrap();
    (cloud, Mesh::cuboid(0.05, 0.05, 0.05).unwrap())
}

fn cube_pose(gap: f64) -> Pose {
    Pose::translation(0.0, 0.0, RADIUS + 0.05 + gap)
}

#[test]
fn invariant_under_a_rigid_motion_of_both_and_either_order() {
    let (cloud, mesh) = sphere_scene();
    let cube = MeshDistance::new(&mesh).unwrap();
    let m = Pose::from_parts(
        Translation3::new(0.4, -1.2, 0.7),
        UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
    );
    let req = CollisionRequest::default();
    for gap in [3.0 * SIGMA, 0.0, -2.0 * SIGMA] {
        let a = collide_exact_cloud(&cube_pose(gap), &cube, &Pose::identity(), &cloud, &req);
        let b = collide_exact_cloud(&(m * cube_pose(gap)), &cube, &m, &cloud, &req);
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!((a.probability - b.probability).abs() < 1e-9);
        assert_eq!(a.state, b.state);
        let (pa, pb) = (a.probabilities_b.to_dense(), b.probabilities_b.to_dense());
        assert!(pa.iter().zip(&pb).all(|(x, y)| (x - y).abs() < 1e-9));
        let swapped = collide_cloud_exact(&m, &cloud, &(m * cube_pose(gap)), &cube, &req).unwrap();
        assert!((swapped.probability - b.probability).abs() < 1e-12);
        assert_eq!(swapped.probabilities_a, b.probabilities_b);
        assert!(swapped.probabilities_b.is_empty());
    }
}

#[test]
fn agrees_with_the_sampled_path_at_clear_gaps() {
    let (cloud, mesh) = sphere_scene();
    let req = CollisionRequest::default();
    for (gap, want) in [
        (20.0 * SIGMA, CollisionState::Free),
        (10.0 * SIGMA, CollisionState::Free),
        (-5.0 * SIGMA, CollisionState::Collision),
        (-10.0 * SIGMA, CollisionState::Collision),
    ] {
        let run = |side| {
            let sampling = MeshSampling {
                side,
                ..MeshSampling::default()
            };
            collide_mesh_cloud(
                &cube_pose(gap),
                &mesh,
                &Pose::identity(),
                &cloud,
                &req,
                &sampling,
            )
            .unwrap()
        };
        let (exact, sampled) = (run(MeshSide::Exact), run(MeshSide::Sampled));
        assert_eq!(exact.state, want, "gap {gap}: P = {}", exact.probability);
        assert_eq!(
            sampled.state, want,
            "gap {gap}: P = {}",
            sampled.probability
        );
    }
}

#[test]
fn far_is_free_without_a_reading_and_many_poses_agree() {
    let (cloud, mesh) = sphere_scene();
    let cube = MeshDistance::new(&mesh).unwrap();
    let req = CollisionRequest::default();
    let far = collide_exact_cloud(&cube_pose(0.5), &cube, &Pose::identity(), &cloud, &req);
    let far = far.unwrap();
    assert_eq!((far.probability, far.state), (0.0, CollisionState::Free));
    assert_eq!(far.stats.counters.leaf_pairs, 0);
    assert!(far.probabilities_b.values().is_empty());
    let poses: Vec<Pose> = [0.5, 0.01, 0.0, -0.01].map(cube_pose).to_vec();
    let many = collide_exact_cloud_many(&poses, &cube, &Pose::identity(), &cloud, &req).unwrap();
    for (p, r) in poses.iter().zip(&many) {
        let one = collide_exact_cloud(p, &cube, &Pose::identity(), &cloud, &req).unwrap();
        assert_eq!(one, *r);
    }
    // Deciding only: the same P and state, no per-point probabilities.
    let decide = CollisionRequest {
        decide_only: true,
        ..req
    };
    let d = collide_exact_cloud(&poses[2], &cube, &Pose::identity(), &cloud, &decide).unwrap();
    assert_eq!(
        (d.probability, d.state),
        (many[2].probability, many[2].state)
    );
    assert!(d.probabilities_b.values().is_empty());
}

#[test]
fn the_points_model_aggregates_eq_3() {
    let (cloud, mesh) = sphere_scene();
    let cube = MeshDistance::new(&mesh).unwrap();
    let req = CollisionRequest {
        model: QueryModel::Points,
        ..CollisionRequest::default()
    };
    let r = collide_exact_cloud(&cube_pose(SIGMA), &cube, &Pose::identity(), &cloud, &req);
    let r = r.unwrap();
    let max = r
        .probabilities_b
        .values()
        .iter()
        .copied()
        .fold(0.0, f64::max);
    assert!(max > 0.0 && r.probability == max);
    let surface = CollisionRequest {
        aggregation: Aggregation::Surface,
        ..req
    };
    let e = collide_exact_cloud(&cube_pose(0.0), &cube, &Pose::identity(), &cloud, &surface);
    assert!(matches!(e, Err(Error::InvalidInput(m)) if m.contains("surface")));
}

#[test]
fn bad_input_is_an_error() {
    assert!(PointCloud::from_sigma(Vec::new(), SIGMA).is_err());
    assert!(PointCloud::from_sigma(vec![Point3::new(f64::NAN, 0.0, 0.0)], SIGMA).is_err());
    let (cloud, mesh) = sphere_scene();
    let cube = MeshDistance::new(&mesh).unwrap();
    let req = CollisionRequest::default();
    let nan = Pose::translation(f64::NAN, 0.0, 0.0);
    let e = collide_exact_cloud(&nan, &cube, &Pose::identity(), &cloud, &req);
    assert!(matches!(e, Err(Error::InvalidInput(m)) if m.contains("pose_mesh")));
    let e = collide_exact_cloud(&Pose::identity(), &cube, &nan, &cloud, &req);
    assert!(matches!(e, Err(Error::InvalidInput(m)) if m.contains("pose_cloud")));
    let poses = [Pose::identity(), nan];
    let e = collide_exact_cloud_many(&poses, &cube, &Pose::identity(), &cloud, &req);
    assert!(matches!(e, Err(Error::InvalidInput(m)) if m.contains("poses_mesh[1]")));
    let bad = CollisionRequest {
        prune_epsilon: -1.0,
        ..req
    };
    let e = collide_exact_cloud(&Pose::identity(), &cube, &Pose::identity(), &cloud, &bad);
    assert!(matches!(e, Err(Error::InvalidInput(_))));
}

#[test]
fn an_open_mesh_is_read_by_its_winding_number() {
    // The unit cube without its top face: open, so the sign comes from the
    // winding number. A plane 2 cm below the bottom face is free; one 5 cm
    // above it (inside the open box) collides.
    let cube = Mesh::cuboid(0.5, 0.5, 0.5).unwrap();
    let faces: Vec<[u32; 3]> = (0..cube.faces().len())
        .filter(|&f| cube.face_normal_scaled(f).z <= 0.5 * cube.face_normal_scaled(f).norm())
        .map(|f| cube.faces()[f])
        .collect();
    assert_eq!(faces.len(), 10);
    let open = MeshDistance::new(&Mesh::new(cube.vertices().to_vec(), faces).unwrap()).unwrap();
    assert_eq!(
        open.sign_method(),
        cloudprox::shape::SignMethod::WindingNumber
    );
    let req = CollisionRequest::default();
    let at = |gap: f64| {
        let cloud = PointCloud::from_sigma(add_noise(&plane(gap), 0.002, 5), 0.002).unwrap();
        collide_exact_cloud(&Pose::identity(), &open, &Pose::identity(), &cloud, &req).unwrap()
    };
    assert_eq!(at(0.02).state, CollisionState::Free);
    assert_eq!(at(-0.05).state, CollisionState::Collision);
}

/// A thin bar (2 cm square, 40 cm long) pushed through a wide noisy floor
/// (1.2 m square at 1 cm, sigma 1 mm, with its underside 2 cm below): the
/// floor's elements are tens of centimetres across and their probes miss
/// the bar, whose walls the floor's surface passes through. Read where the
/// surface goes on inside the bar: a collision, at every place the bar
/// goes through (its centre and off it); lifted 3 cm clear, free.
#[test]
fn a_thin_bar_through_a_wide_floor_collides() {
    let bar = MeshDistance::new(&Mesh::cuboid(0.01, 0.01, 0.2).unwrap()).unwrap();
    let floor: Vec<Point3> = (0..121 * 121)
        .flat_map(|i| {
            let (u, v) = (
                f64::from(i % 121) * 0.01 - 0.6,
                f64::from(i / 121) * 0.01 - 0.6,
            );
            [Point3::new(u, v, 0.0), Point3::new(u, v, -0.02)]
        })
        .collect();
    let sigma = 0.001;
    for seed in 0..4u64 {
        let cloud = PointCloud::from_sigma(add_noise(&floor, sigma, 50 + seed), sigma).unwrap();
        let query = |pose: &Pose| {
            collide_exact_cloud(
                pose,
                &bar,
                &Pose::identity(),
                &cloud,
                &CollisionRequest::default(),
            )
            .unwrap()
        };
        for (x, y) in [(0.0, 0.0), (0.137, -0.251), (-0.33, 0.41)] {
            let r = query(&Pose::translation(x, y, 0.0));
            assert_eq!(
                r.state,
                CollisionState::Collision,
                "seed {seed} at ({x}, {y}): P {}",
                r.probability
            );
            let r = query(&Pose::translation(x, y, 0.23));
            assert_eq!(
                r.state,
                CollisionState::Free,
                "seed {seed} at ({x}, {y}) clear: P {}",
                r.probability
            );
        }
    }
}

/// A tilted link-like box (4 x 4 x 20 cm) pressed 12 mm into a wide noisy
/// floor (1.2 m square at 1 cm, sigma 1 mm) by one corner, over a hole in
/// the floor's sampling (a shadow, 6 mm about the corner): the floor's
/// elements are tens of centimetres across, their probes lie farther from
/// the box than their search radius, and the closest points from an
/// element's mean lead to the box's side. Read across from the box's
/// deepest vertex (at the hole's edge there): a collision; lifted 2 cm
/// clear, free.
#[test]
fn a_corner_pressed_into_a_wide_floor_beside_a_hole_collides() {
    let link = MeshDistance::new(&Mesh::cuboid(0.02, 0.02, 0.1).unwrap()).unwrap();
    let turn = UnitQuaternion::from_euler_angles(0.5, 0.35, 0.2);
    // The box's lowest corner after the turn, put at (0.137, -0.251, -6 mm).
    let lowest = [-1.0, 1.0]
        .iter()
        .flat_map(|&x| [-1.0, 1.0].map(move |y| (x, y)))
        .flat_map(|(x, y)| {
            [-1.0, 1.0].map(move |z| turn * Point3::new(0.02 * x, 0.02 * y, 0.1 * z))
        })
        .min_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap();
    let corner = Point3::new(0.137, -0.251, -0.012);
    let at = |lift: f64| {
        Pose::from_parts(
            Translation3::from(corner - lowest + Vector3::new(0.0, 0.0, lift)),
            turn,
        )
    };
    let floor: Vec<Point3> = (0..121 * 121)
        .flat_map(|i| {
            let (u, v) = (
                f64::from(i % 121) * 0.01 - 0.6,
                f64::from(i / 121) * 0.01 - 0.6,
            );
            [Point3::new(u, v, 0.0), Point3::new(u, v, -0.02)]
        })
        .filter(|p| (p.x - corner.x).hypot(p.y - corner.y) > 0.006)
        .collect();
    let inside = floor
        .iter()
        .filter(|p| link.signed_distance(&(at(0.0).inverse() * **p)) < 0.0)
        .count();
    assert!(inside >= 3, "{inside} floor points inside the box");
    let sigma = 0.001;
    for seed in 0..4u64 {
        let cloud = PointCloud::from_sigma(add_noise(&floor, sigma, 70 + seed), sigma).unwrap();
        let query = |pose: &Pose| {
            collide_exact_cloud(
                pose,
                &link,
                &Pose::identity(),
                &cloud,
                &CollisionRequest::default(),
            )
            .unwrap()
        };
        let r = query(&at(0.0));
        assert_eq!(
            r.state,
            CollisionState::Collision,
            "seed {seed}: P {}",
            r.probability
        );
        let r = query(&at(0.02));
        assert_eq!(
            r.state,
            CollisionState::Free,
            "seed {seed} clear: P {}",
            r.probability
        );
    }
}

#[test]
fn per_point_probabilities_of_a_mesh_pressed_deep_match_brute_force() {
    // The cube pressed 3 cm into the sphere, and just touching it: every
    // point's stored p against Eq. 3 at its exact closest point, point by
    // point. Far outside and deep inside the search is skipped: p below
    // epsilon / 2 is stored as 0, above 1 - epsilon / 2 as 1.
    use cloudprox::probability::point_probability;
    let (cloud, mesh) = sphere_scene();
    let cube = MeshDistance::new(&mesh).unwrap();
    let req = CollisionRequest::default();
    let half = 0.5 * req.prune_epsilon;
    for gap in [-0.03, 0.0] {
        let pose = cube_pose(gap);
        let r = collide_exact_cloud(&pose, &cube, &Pose::identity(), &cloud, &req).unwrap();
        let got = r.probabilities_b.to_dense();
        let (mut deep, mut near) = (0, 0);
        for (i, (p, cov)) in cloud.points().iter().zip(cloud.covariances()).enumerate() {
            let c = cube.closest(&(pose.inverse() * p));
            let n = pose.rotation * c.normal;
            let want = point_probability(c.signed_distance, &n, cov, 1.0);
            assert!(
                (got[i] - want).abs() <= half + 1e-12,
                "gap {gap}, point {i}: {} vs {want}",
                got[i]
            );
            deep += usize::from(want > 1.0 - half);
            near += usize::from(want > half && want <= 1.0 - half);
        }
        if gap < 0.0 {
            assert!(deep > 100 && near > 10, "{deep} deep, {near} near");
        }
    }
}
