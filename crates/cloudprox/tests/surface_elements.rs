//! Surface elements: flat patches, curvature, thin parts, the covariance of the mean.

use cloudprox::element::{ElementSettings, SurfaceElements};
use cloudprox::prelude::*;
use cloudprox::sample::{add_noise, sphere};

/// A noisy square grid of `k x k` points at spacing `h` in the plane z = `z`.
fn grid(k: usize, h: f64, z: f64) -> Vec<Point3> {
    (0..k)
        .flat_map(|i| (0..k).map(move |j| Point3::new(i as f64 * h, j as f64 * h, z)))
        .collect()
}

#[test]
fn flat_patch_becomes_large_elements_with_covariance_sigma_over_n() {
    let sigma = 0.001;
    let cloud = PointCloud::from_sigma(add_noise(&grid(40, 0.005, 0.0), sigma, 1), sigma).unwrap();
    let el = cloud.elements();
    let covered: usize = el
        .elements()
        .iter()
        .filter(|e| !e.is_point())
        .map(|e| e.count as usize)
        .sum();
    let largest = el.elements().iter().map(|e| e.count).max().unwrap();
    eprintln!(
        "elements {} multi {} covered {covered} largest {largest}",
        el.elements().len(),
        el.multi_point_count()
    );
    assert!(covered >= 1500, "{covered} of 1600 points in elements");
    assert!(largest >= 200, "largest element {largest}");
    for e in el.elements().iter().filter(|e| !e.is_point()) {
        let n = f64::from(e.count);
        let expected = Matrix3::identity() * (sigma * sigma / n);
        assert!((e.cov_mean - expected).amax() < 1e-15);
        assert!(e.normal.z.abs() > 0.99);
    }
}

#[test]
fn element_size_shrinks_with_curvature() {
    let sigma = 0.0005;
    let mean_count = |radius: f64| -> f64 {
        // Same sampling density (points per square metre) on both spheres.
        let n = (4.0 * std::f64::consts::PI * radius * radius / (0.004f64 * 0.004)) as usize;
        let pts = add_noise(&sphere(&Point3::origin(), radius, n), sigma, 2);
        let cloud = PointCloud::from_sigma(pts, sigma).unwrap();
        let el = cloud.elements();
        let multi: Vec<f64> = el
            .elements()
            .iter()
            .filter(|e| !e.is_point())
            .map(|e| f64::from(e.count))
            .collect();
        eprintln!(
            "r {radius}: n {n} elements {} multi {} mean {}",
            el.elements().len(),
            multi.len(),
            multi.iter().sum::<f64>() / multi.len() as f64
        );
        multi.iter().sum::<f64>() / multi.len() as f64
    };
    let small = mean_count(0.05);
    let large = mean_count(0.4);
    assert!(
        large > 2.0 * small,
        "mean element size {small} (r = 5 cm) vs {large} (r = 40 cm)"
    );
}

#[test]
fn the_two_faces_of_a_thin_plate_never_share_an_element() {
    let sigma = 0.0005;
    let thickness = 0.004; // 8 sigma
    let mut pts = grid(30, 0.004, 0.0);
    pts.extend(grid(30, 0.004, thickness));
    let cloud = PointCloud::from_sigma(add_noise(&pts, sigma, 3), sigma).unwrap();
    let el = cloud.elements();
    for k in 0..el.elements().len() as u32 {
        let faces: Vec<bool> = el.element_points(k).iter().map(|&i| i >= 900).collect();
        assert!(
            faces.iter().all(|&f| f == faces[0]),
            "element {k} mixes the faces"
        );
    }
    assert!(el.multi_point_count() >= 2);
}

#[test]
fn bad_settings_are_named() {
    let cloud = PointCloud::from_sigma(grid(5, 0.01, 0.0), 0.001).unwrap();
    for (s, word) in [
        (
            ElementSettings {
                significance: 0.0,
                ..Default::default()
            },
            "significance",
        ),
        (
            ElementSettings {
                min_points: 3,
                ..Default::default()
            },
            "min_points",
        ),
        (
            ElementSettings {
                noise_correlation: 1.5,
                ..Default::default()
            },
            "noise_correlation",
        ),
    ] {
        let e = SurfaceElements::build(&cloud, &s).unwrap_err();
        assert!(e.to_string().contains(word), "{e}");
    }
}

#[test]
fn coplanar_patches_apart_never_share_an_element() {
    // Two flat 10 x 10 patches (5 mm spacing) on one plane, 20 cm apart: one
    // plane fits both within the noise, but the plane between them was never
    // sampled, so no element may span the gap.
    let sigma = 0.001;
    let mut pts = grid(10, 0.005, 0.0);
    pts.extend(
        grid(10, 0.005, 0.0)
            .iter()
            .map(|p| p + Vector3::new(0.25, 0.0, 0.0)),
    );
    let cloud = PointCloud::from_sigma(add_noise(&pts, sigma, 3), sigma).unwrap();
    let el = cloud.elements();
    assert!(el.multi_point_count() >= 2);
    for (k, e) in el.elements().iter().enumerate() {
        let sides: Vec<bool> = el
            .element_points(k as u32)
            .iter()
            .map(|&i| i < 100)
            .collect();
        assert!(
            sides.iter().all(|&s| s) || sides.iter().all(|&s| !s),
            "element {k} of {} points spans both patches (extent {:?})",
            e.count,
            e.extent
        );
        // The rectangle an element claims is covered by its points.
        let [[u0, u1], [v0, v1]] = e.extent;
        if !e.is_point() {
            assert!((u1 - u0) <= 0.06 && (v1 - v0) <= 0.06, "{:?}", e.extent);
        }
    }
}

#[test]
fn an_element_covers_where_its_points_are_not_its_rectangle_corners() {
    // A flat disc of radius 5 cm (1600 points, 1 mm noise): its elements'
    // rectangles (from the points' spread along the principal axes) stick out
    // of the disc at their corners; the footprint does not.
    let sigma = 0.001;
    let pts: Vec<Point3> = grid(60, 0.002, 0.0)
        .into_iter()
        .map(|p| p - Vector3::new(0.059, 0.059, 0.0))
        .filter(|p| p.coords.xy().norm() <= 0.05)
        .collect();
    let cloud = PointCloud::from_sigma(add_noise(&pts, sigma, 4), sigma).unwrap();
    let el = cloud.elements();
    let mut corners_outside = 0;
    for (k, e) in el.elements().iter().enumerate() {
        if e.is_point() {
            continue;
        }
        // Every point of the element is covered.
        for &i in el.element_points(k as u32) {
            let d = cloud.points()[i as usize] - e.mean;
            assert!(e.covers(d.dot(&e.tangents[0]), d.dot(&e.tangents[1])));
        }
        // Corners of the rectangle that lie off the disc by more than two
        // spacings are not.
        for (u, v) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let (cu, cv) = (e.extent[0][u], e.extent[1][v]);
            let x = e.mean + e.tangents[0] * cu + e.tangents[1] * cv;
            if x.coords.xy().norm() > 0.05 + 2.0 * e.spacing {
                corners_outside += 1;
                assert!(!e.covers(cu, cv), "corner {x:?} of element {k}");
            }
        }
    }
    assert!(corners_outside > 0, "no rectangle corner left the disc");
}
