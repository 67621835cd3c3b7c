//! Meshes as query objects: an exact mesh against a noisy cloud.

use crate::common;

use cloudprox::prelude::*;
use cloudprox::query::collide::{mesh_sampling_spacing, MeshSide, MESH_SPACING_FACTOR};
use cloudprox::sample::{add_noise, sphere};
use common::{RADIUS, SIGMA};
use nalgebra::{Translation3, UnitQuaternion};

/// A noisy sphere cloud (radius 0.1 m) and a 10 cm cube mesh.
fn scene() -> (PointCloud, Mesh) {
    let pts = add_noise(&sphere(&Point3::origin(), RADIUS, 2000), SIGMA, 31);
    let cloud = PointCloud::from_sigma(pts, SIGMA)
        .unwrap()
        .with_discretization(&DiscretizationSettings::default())
        .unwrap();
    (cloud, Mesh::cuboid(0.05, 0.05, 0.05).unwrap())
}

/// The cube's pose so that its bottom face is `gap` above the sphere's top
/// (exact distance `gap` for gaps > 0: the sphere's pole touches the face centre).
fn cube_pose(gap: f64) -> Pose {
    Pose::translation(0.0, 0.0, RADIUS + 0.05 + gap)
}

fn query(cloud: &PointCloud, mesh: &Mesh, gap: f64) -> CollisionResult {
    collide_mesh_cloud(
        &cube_pose(gap),
        mesh,
        &Pose::identity(),
        cloud,
        &CollisionRequest::default(),
        &MeshSampling::default(),
    )
    .unwrap()
}

#[test]
fn far_is_free_and_penetrating_is_collision() {
    let (cloud, mesh) = scene();
    for gap in [20.0 * SIGMA, 10.0 * SIGMA] {
        let r = query(&cloud, &mesh, gap);
        assert_eq!(
            r.state,
            CollisionState::Free,
            "gap {gap}: P = {}",
            r.probability
        );
    }
    for gap in [-5.0 * SIGMA, -10.0 * SIGMA] {
        let r = query(&cloud, &mesh, gap);
        assert_eq!(
            r.state,
            CollisionState::Collision,
            "gap {gap}: P = {}",
            r.probability
        );
    }
}

#[test]
fn probability_grows_as_the_exact_gap_closes() {
    let (cloud, mesh) = scene();
    let gaps = [10.0, 5.0, 2.0, 0.0, -3.0].map(|g| g * SIGMA);
    let p: Vec<f64> = gaps
        .iter()
        .map(|&g| query(&cloud, &mesh, g).probability)
        .collect();
    for w in p.windows(2) {
        assert!(
            w[1] + 1e-9 >= w[0],
            "P must not fall as the gap closes: {p:?}"
        );
    }
    assert!(p[0] < 0.05 && p[4] > 0.95, "{p:?}");
}

#[test]
fn invariant_under_a_rigid_motion_of_both() {
    let (cloud, mesh) = scene();
    let m = Pose::from_parts(
        Translation3::new(0.4, -1.2, 0.7),
        UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
    );
    for gap in [3.0 * SIGMA, 0.0] {
        let a = query(&cloud, &mesh, gap);
        let b = collide_mesh_cloud(
            &(m * cube_pose(gap)),
            &mesh,
            &m,
            &cloud,
            &CollisionRequest::default(),
            &MeshSampling::default(),
        )
        .unwrap();
        assert!(
            (a.probability - b.probability).abs() < 1e-6,
            "{} vs {}",
            a.probability,
            b.probability
        );
        assert_eq!(a.state, b.state);
    }
}

#[test]
fn the_mesh_may_be_either_side() {
    let (cloud, mesh) = scene();
    let spacing = mesh_sampling_spacing(&cloud);
    let sample = PointCloud::from_mesh(&mesh, spacing, 0).unwrap();
    for gap in [4.0 * SIGMA, 0.0, -4.0 * SIGMA] {
        let req = CollisionRequest::default();
        let ab = collide(&cube_pose(gap), &sample, &Pose::identity(), &cloud, &req).unwrap();
        let ba = collide(&Pose::identity(), &cloud, &cube_pose(gap), &sample, &req).unwrap();
        // The pooled gap field reads the patches each order builds (up to
        // 0.3 % apart at touching, where the two orders cut the contact
        // into patches differently).
        assert!(
            (ab.probability - ba.probability).abs() < 5e-3,
            "gap {gap}: {} vs {}",
            ab.probability,
            ba.probability
        );
        let sampled = MeshSampling {
            side: MeshSide::Sampled,
            ..MeshSampling::default()
        };
        let direct = collide_mesh_cloud(
            &cube_pose(gap),
            &mesh,
            &Pose::identity(),
            &cloud,
            &req,
            &sampled,
        )
        .unwrap();
        assert_eq!(direct.probability, ab.probability);
    }
}

#[test]
fn mesh_samples_are_exact_across_their_face() {
    let mesh = Mesh::cuboid(0.05, 0.05, 0.05).unwrap();
    let h = 0.01;
    let c = PointCloud::from_mesh(&mesh, h, 3).unwrap();
    // 6 faces of 0.01 m^2 at one point per h^2.
    assert_eq!(c.len(), 600);
    for (p, cov) in c.points().iter().zip(c.covariances()) {
        // The face normal is the axis along which the point is at +-0.05.
        let axis = (0..3)
            .max_by(|&i, &j| p[i].abs().total_cmp(&p[j].abs()))
            .unwrap();
        let n = Vector3::ith(axis, 1.0);
        assert!((n.transpose() * cov * n)[(0, 0)].abs() < 1e-18);
        assert!((cov.trace() - 2.0 * h * h / 12.0).abs() < 1e-15);
    }
    assert!(c.sensor_sigma_max().iter().all(|&s| s == 0.0));
    assert!((MESH_SPACING_FACTOR - 0.5).abs() < 1e-15);
}

#[test]
fn bad_spacing_is_named() {
    let mesh = Mesh::cuboid(0.05, 0.05, 0.05).unwrap();
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        match PointCloud::from_mesh(&mesh, bad, 0) {
            Err(Error::InvalidInput(m)) => assert!(m.contains("spacing"), "{m}"),
            other => panic!("expected InvalidInput, got {other:?}"),
        }
    }
    match PointCloud::from_mesh(&mesh, 1e-6, 0) {
        Err(Error::InvalidInput(m)) => assert!(m.contains("1e9"), "{m}"),
        other => panic!("expected InvalidInput, got {other:?}"),
    }
}

/// The spacing's middle values, kept with the spacings: the mesh sampling
/// spacing is `MESH_SPACING_FACTOR` times the upper middle of the sorted
/// spacings, `cell_side` takes numpy's median; both follow `set_points`.
#[test]
fn sampling_spacing_and_cell_side_are_the_spacings_median() {
    for n in [1999, 2000] {
        let pts = add_noise(&sphere(&Point3::origin(), RADIUS, n), SIGMA, 5);
        let mut cloud = PointCloud::from_sigma(pts, SIGMA).unwrap();
        for round in 0..2 {
            let mut s = cloud.spacing().to_vec();
            s.sort_by(f64::total_cmp);
            let upper = s[n / 2];
            let median = if n % 2 == 1 {
                upper
            } else {
                0.5 * (s[n / 2 - 1] + upper)
            };
            assert_eq!(mesh_sampling_spacing(&cloud), MESH_SPACING_FACTOR * upper);
            let side = median * (std::f64::consts::PI / 6.0).sqrt();
            assert_eq!(cloud.cell_side(), side, "n {n} round {round}");
            // Moved points, twice as far apart: the cached median moves too.
            let scaled: Vec<Point3> = cloud.points().iter().map(|p| p * 2.0).collect();
            cloud.set_points(scaled).unwrap();
        }
    }
}
