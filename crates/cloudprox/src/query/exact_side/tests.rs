//! The readings against an exact surface, against the noise that made them.

use super::frame::Frame;
use super::readings::element_readings;
use crate::cloud::PointCloud;
use crate::math::{Point3, Pose};
use crate::sample::{add_noise, lcg_uniform};
use crate::shape::{Mesh, MeshDistance};
use crate::Real;

/// A flat 30 x 30 grid at 1 cm pitch, `gap` below the unit cube's bottom face.
fn plane(gap: Real) -> Vec<Point3> {
    (0..900)
        .map(|i| {
            let (u, v) = (
                (i % 30) as Real * 0.01 - 0.145,
                (i / 30) as Real * 0.01 - 0.145,
            );
            Point3::new(u, v, -0.5 - gap)
        })
        .collect()
}

/// A pose at `radius` from the origin along a random direction, turned by
/// a random rotation (of up to 3 rad about a random axis).
fn turned_at(next: &mut impl FnMut() -> Real, radius: Real) -> Pose {
    use nalgebra::{Translation3, UnitQuaternion, Vector3};
    let dir = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
    let axis = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5);
    Pose::from_parts(
        Translation3::from(dir * radius),
        UnitQuaternion::from_scaled_axis(axis * 3.0),
    )
}

#[test]
fn readings_are_the_gap_with_its_fit_error() {
    // Over 120 noise draws, each reading's standardized residual against the
    // exact gap (the plane is parallel to the face, so the gap is the same
    // at every probe) has mean 0 and spread 1: the gaps are unbiased and
    // their standard deviations are the fit's.
    let cube = MeshDistance::new(&Mesh::cuboid(0.5, 0.5, 0.5).unwrap()).unwrap();
    let (sigma, gap) = (0.002, 0.0003);
    let frame = Frame::new(&cube, Pose::identity(), 1e-3);
    let mut z: Vec<Real> = Vec::new();
    for seed in 0..120 {
        let cloud = PointCloud::from_sigma(add_noise(&plane(gap), sigma, seed), sigma).unwrap();
        let els = cloud.elements();
        let scan = element_readings(&frame, els, None);
        assert!(!scan.readings.is_empty());
        // One reading per element: its most critical probe is what P reads.
        for (k, _) in &scan.near {
            let e = &els.elements()[*k as usize];
            if e.is_point() {
                continue;
            }
            // The fit's standard error at the mean: at least sigma / sqrt(m)
            // (a plane's), more with the quadric's curvature terms.
            let (_, var0) = e.surface_point(0.0, 0.0);
            let se = sigma / Real::from(e.count).sqrt();
            assert!(
                (0.999..2.5).contains(&(var0.sqrt() / se)),
                "{} vs {se}",
                var0.sqrt()
            );
            for r in scan.readings.iter().filter(|r| r.own == *k) {
                z.push((gap - r.gap) / r.std);
            }
        }
    }
    let n = z.len() as Real;
    let mean = z.iter().sum::<Real>() / n;
    let sd = (z.iter().map(|x| (x - mean).powi(2)).sum::<Real>() / n).sqrt();
    assert!(mean.abs() < 0.25, "mean {mean} over {n}");
    assert!((0.8..1.25).contains(&sd), "sd {sd} over {n}");
}

#[test]
fn a_cloud_beyond_reach_reads_nothing() {
    let cube = MeshDistance::new(&Mesh::cuboid(0.5, 0.5, 0.5).unwrap()).unwrap();
    let cloud = PointCloud::from_sigma(add_noise(&plane(0.05), 0.002, 1), 0.002).unwrap();
    let scan = element_readings(
        &Frame::new(&cube, Pose::identity(), 1e-3),
        cloud.elements(),
        None,
    );
    // (The hull of the 30 cm wide element reaches the face: it is tested,
    // and its probes are beyond reach.)
    assert!(scan.readings.is_empty());
    // Deep inside the cube (40 cm above the bottom face): every element
    // reads a certain crossing.
    let inside = PointCloud::from_sigma(add_noise(&plane(-0.4), 0.002, 1), 0.002).unwrap();
    let scan = element_readings(
        &Frame::new(&cube, Pose::identity(), 1e-3),
        inside.elements(),
        None,
    );
    assert!(!scan.readings.is_empty());
    assert!(scan.readings.iter().all(|r| r.gap < -10.0 * r.std));
}

#[test]
fn the_hierarchy_finds_every_element_the_one_by_one_test_keeps() {
    // Fast path against brute force: over random poses of a small box about
    // a noisy plane, every element that `standing` does not place beyond
    // reach is among the hierarchy's candidates (and they come in order).
    use super::frame::Standing;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};
    let boxy = MeshDistance::new(&Mesh::cuboid(0.03, 0.02, 0.01).unwrap()).unwrap();
    let cloud = PointCloud::from_sigma(add_noise(&plane(0.0), 0.002, 3), 0.002).unwrap();
    let els = cloud.elements();
    let mut next = lcg_uniform(7);
    let mut found = 0;
    for _ in 0..200 {
        let t = Translation3::new(
            0.3 * next() - 0.15,
            0.3 * next() - 0.15,
            -0.5 + 0.06 * next() - 0.03,
        );
        let axis = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5);
        let turn = UnitQuaternion::from_scaled_axis(axis * 3.0);
        // The cloud in the box's frame.
        let frame = Frame::new(&boxy, Pose::from_parts(t, turn).inverse(), 1e-3);
        let mut candidates = Vec::new();
        frame.candidates(els, &mut candidates);
        assert!(candidates.windows(2).all(|w| w[0] < w[1]));
        for k in 0..els.elements().len() as u32 {
            if frame.standing(els, k) != Standing::Beyond {
                found += 1;
                assert!(candidates.binary_search(&k).is_ok(), "element {k} missed");
            }
        }
    }
    assert!(
        found > 50,
        "only {found} elements near the box over all poses"
    );
}

#[test]
fn decide_only_stops_at_a_decisive_element_with_the_full_querys_state() {
    // A 10 cm cube about a noisy sphere of radius 0.1 m (3000 points,
    // sigma 1 mm), its centre from 15 cm outside the sphere to 6 cm inside,
    // turned at random: the state of a decide_only query is the full
    // query's, its P at most the full P; where the cube is pressed through
    // the shell, the elements deep inside it decide before the rest are read.
    use crate::query::exact_side::collide_exact_cloud;
    use crate::query::CollisionRequest;
    use crate::sample::sphere;
    let cube = MeshDistance::new(&Mesh::cuboid(0.05, 0.05, 0.05).unwrap()).unwrap();
    let shell = sphere(&Point3::origin(), 0.1, 3000);
    let cloud = PointCloud::from_sigma(add_noise(&shell, 0.001, 5), 0.001).unwrap();
    let full = CollisionRequest::default();
    let decide = CollisionRequest {
        decide_only: true,
        ..CollisionRequest::default()
    };
    let mut next = lcg_uniform(11);
    let (mut states, mut fewer) = ([0; 3], 0);
    for i in 0..100 {
        // The cube's centre at radius 0.25 (its farthest corner 6 cm out of
        // the shell) down to 0.04.
        let radius = 0.25 - 0.21 * Real::from(i) / 99.0;
        let pose = turned_at(&mut next, radius);
        let a = collide_exact_cloud(&pose, &cube, &Pose::identity(), &cloud, &full).unwrap();
        let d = collide_exact_cloud(&pose, &cube, &Pose::identity(), &cloud, &decide).unwrap();
        assert_eq!(
            a.state, d.state,
            "radius {radius}: P {} vs {}",
            a.probability, d.probability
        );
        assert!(d.probability <= a.probability + 1e-12);
        states[a.state as usize] += 1;
        let (ta, td) = (a.stats.counters.leaf_pairs, d.stats.counters.leaf_pairs);
        assert!(td <= ta, "{td} readings against {ta}");
        if td < ta {
            fewer += 1;
        }
    }
    assert!(states[0] > 10 && states[2] > 10, "states {states:?}");
    assert!(
        fewer > states[2] / 2,
        "{fewer} of {} collisions decided early",
        states[2]
    );
}

#[test]
fn a_distance_field_changes_nothing_but_the_searches() {
    // The cube about the noisy sphere, from well outside to pressed deep,
    // with and without its distance field (and a padding): the same P and
    // state, each point's p within epsilon / 2 (a point the field places
    // beyond reach is stored as 0 or 1).
    use super::query::collide_exact_cloud_padded;
    use crate::query::CollisionRequest;
    use crate::sample::sphere;
    use crate::shape::DistanceField;
    use std::sync::Arc;
    let cube = Arc::new(MeshDistance::new(&Mesh::cuboid(0.05, 0.05, 0.05).unwrap()).unwrap());
    let field = DistanceField::new(Arc::clone(&cube), 0.004, 0.024).unwrap();
    let shell = sphere(&Point3::origin(), 0.1, 3000);
    let cloud = PointCloud::from_sigma(add_noise(&shell, 0.001, 9), 0.001).unwrap();
    let req = CollisionRequest::default();
    let half = 0.5 * req.prune_epsilon;
    let mut next = lcg_uniform(3);
    for i in 0..40 {
        let radius = 0.25 - 0.21 * Real::from(i) / 39.0;
        let pose = turned_at(&mut next, radius);
        let padding = if i % 3 == 0 { 0.003 } else { 0.0 };
        let query = |f: Option<&DistanceField>| {
            collide_exact_cloud_padded(&pose, (&cube, padding, f), &Pose::identity(), &cloud, &req)
                .unwrap()
        };
        let (a, b) = (query(None), query(Some(&field)));
        assert_eq!(a.probability, b.probability, "radius {radius}");
        assert_eq!(a.state, b.state);
        let (pa, pb) = (a.probabilities_b.to_dense(), b.probabilities_b.to_dense());
        for (x, y) in pa.iter().zip(&pb) {
            assert!((x - y).abs() <= half, "radius {radius}: {x} vs {y}");
        }
    }
}
