//! Self-filter: a robot link hovering 3 cm above a table, inside points, open
//! meshes, moved links, rigid invariance.

use cloudprox::filter::SelfFilter;
use cloudprox::prelude::*;
use cloudprox::sample::add_noise;

const SIGMA: f64 = 0.002;

/// A 1 m x 1 m table at z = 0 sampled every 5 mm, with noise.
fn table() -> Vec<Point3> {
    let grid: Vec<Point3> = (0..200 * 200)
        .map(|i| Point3::new((i / 200) as f64 * 0.005, (i % 200) as f64 * 0.005, 0.0))
        .collect();
    add_noise(&grid, SIGMA, 1)
}

/// The link's pose: its lowest point 3 cm above the table.
fn link_pose(mesh: &Mesh) -> Pose {
    let dz = -mesh.aabb().mins.z;
    Pose::new(
        Vector3::new(0.5, 0.45, 0.03 + dz),
        Vector3::new(0.0, 0.0, 0.6),
    )
}

fn scene(mesh: &Mesh) -> (Vec<Point3>, usize, Pose) {
    let pose = link_pose(mesh);
    let mut points = table();
    let n_table = points.len();
    let link: Vec<Point3> = mesh
        .sample_surface(4000, 2)
        .unwrap()
        .points
        .iter()
        .map(|p| pose * p)
        .collect();
    points.extend(add_noise(&link, SIGMA, 3));
    (points, n_table, pose)
}

#[test]
fn link_points_are_removed_and_table_points_kept() {
    for mesh in [
        Mesh::cuboid(0.1, 0.06, 0.05).unwrap(),
        Mesh::cylinder(0.05, 0.1, 32).unwrap(),
    ] {
        let (points, n_table, pose) = scene(&mesh);
        let filter = SelfFilter::new(vec![(mesh.clone(), pose)], 0.01).unwrap();
        assert_eq!(filter.closed(), vec![true]);
        let kept = filter.apply(&points);
        assert!(kept.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(kept, (0..n_table as u32).collect::<Vec<_>>());
    }
}

fn inside_points(mesh: &Mesh, pose: &Pose) -> Vec<Point3> {
    // A lattice over the box shrunk by 2 cm, so every point is > padding inside.
    let b = mesh.aabb();
    let (lo, hi) = (
        b.mins + Vector3::repeat(0.02),
        b.maxs - Vector3::repeat(0.02),
    );
    let c = |a: f64, z: f64, t: usize| a + (z - a) * t as f64 / 4.0;
    (0..125)
        .map(|i| {
            pose * Point3::new(
                c(lo.x, hi.x, i / 25),
                c(lo.y, hi.y, i / 5 % 5),
                c(lo.z, hi.z, i % 5),
            )
        })
        .collect()
}

#[test]
fn inside_points_of_a_closed_link_are_removed_even_if_wound_inward() {
    let mesh = Mesh::cuboid(0.1, 0.06, 0.05).unwrap();
    let pose = link_pose(&mesh);
    let inside = inside_points(&mesh, &pose);
    let filter = SelfFilter::new(vec![(mesh.clone(), pose)], 0.01).unwrap();
    assert!(filter.apply(&inside).is_empty());
    let flipped: Vec<[u32; 3]> = mesh.faces().iter().map(|&[a, b, c]| [a, c, b]).collect();
    let inward = Mesh::new(mesh.vertices().to_vec(), flipped).unwrap();
    let filter = SelfFilter::new(vec![(inward, pose)], 0.01).unwrap();
    assert!(filter.apply(&inside).is_empty());
    // And the table is still kept (the inside test did not invert).
    let t = table();
    assert_eq!(filter.apply(&t).len(), t.len());
}

#[test]
fn open_links_use_distance_only() {
    let mesh = Mesh::cuboid(0.1, 0.06, 0.05).unwrap();
    // Drop the two triangles of the top face (z+): the mesh is open.
    let faces: Vec<[u32; 3]> = mesh
        .faces()
        .iter()
        .copied()
        .filter(|f| !f.iter().all(|&v| mesh.vertices()[v as usize].z > 0.0))
        .collect();
    assert_eq!(faces.len(), 10);
    let open = Mesh::new(mesh.vertices().to_vec(), faces).unwrap();
    let pose = link_pose(&mesh);
    let filter = SelfFilter::new(vec![(open.clone(), pose)], 0.01).unwrap();
    assert_eq!(filter.closed(), vec![false]);
    let centre = pose * Point3::origin();
    assert_eq!(filter.apply(&[centre]), vec![0]); // 5 cm from every face: kept
    let near_side = pose * Point3::new(0.1 + 0.005, 0.0, 0.0);
    let near_bottom = pose * Point3::new(0.0, 0.0, -0.05 + 0.004);
    assert!(filter.apply(&[near_side, near_bottom]).is_empty());
}

#[test]
fn moving_the_links_and_rigid_invariance() {
    let mesh = Mesh::cuboid(0.1, 0.06, 0.05).unwrap();
    let (points, n_table, pose) = scene(&mesh);
    let cyl = Mesh::cylinder(0.03, 0.08, 16).unwrap();
    let cyl_pose = Pose::new(Vector3::new(0.2, 0.2, 0.2), Vector3::new(1.0, 0.0, 0.0));
    let mut filter =
        SelfFilter::new(vec![(mesh.clone(), pose), (cyl.clone(), cyl_pose)], 0.01).unwrap();
    let kept = filter.apply(&points);
    assert_eq!(kept.len(), n_table);
    // Same filter, everything moved by a rigid transform.
    let t = Pose::new(Vector3::new(-2.0, 1.0, 0.7), Vector3::new(0.4, -1.1, 0.3));
    let moved: Vec<Point3> = points.iter().map(|p| t * p).collect();
    let moved_filter = SelfFilter::new(vec![(mesh, t * pose), (cyl, t * cyl_pose)], 0.01).unwrap();
    assert_eq!(moved_filter.apply(&moved), kept);
    // Lifting the box link 1 m keeps its points.
    filter
        .set_poses(&[Pose::translation(0.0, 0.0, 1.0) * pose, cyl_pose])
        .unwrap();
    assert_eq!(filter.apply(&points).len(), points.len());
    assert_eq!(filter.poses()[1], cyl_pose);
    assert!(filter.set_poses(&[pose]).is_err());
}
