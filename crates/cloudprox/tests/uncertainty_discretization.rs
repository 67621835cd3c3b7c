//! The k-nearest-neighbour discretization covariance.

use cloudprox::prelude::*;
use cloudprox::sample::add_noise;

fn grid(h: f64, n: usize) -> Vec<Point3> {
    (0..n)
        .flat_map(|i| (0..n).map(move |j| Point3::new(i as f64 * h, j as f64 * h, 0.0)))
        .collect()
}

#[test]
fn flat_grid_spreads_along_the_surface_only() {
    let h = 0.01;
    let cloud = PointCloud::from_sigma(grid(h, 30), 0.0)
        .unwrap()
        .with_discretization(&DiscretizationSettings::default())
        .unwrap();
    for (i, c) in cloud.covariances().iter().enumerate() {
        // interior points only (borders have one-sided neighbourhoods)
        let p = cloud.points()[i];
        if p.x < 3.0 * h || p.y < 3.0 * h || p.x > 26.0 * h || p.y > 26.0 * h {
            continue;
        }
        assert!(c[(2, 2)].abs() < 1e-12, "normal variance {}", c[(2, 2)]);
        // 10 neighbours of a square grid reach about 1.5 h: tangential std of order h/2..h.
        for axis in 0..2 {
            let s = c[(axis, axis)].sqrt();
            assert!(
                s > 0.3 * h && s < 1.2 * h,
                "tangential std {s} for spacing {h}"
            );
        }
    }
}

#[test]
fn sensor_noise_is_not_counted_twice() {
    let h = 0.01;
    let sigma = 0.002;
    let noisy = add_noise(&grid(h, 30), sigma, 4);
    let cloud = PointCloud::from_sigma(noisy, sigma)
        .unwrap()
        .with_discretization(&DiscretizationSettings::default())
        .unwrap();
    // The total normal variance stays close to the sensor's, on average.
    let mean_zz: f64 =
        cloud.covariances().iter().map(|c| c[(2, 2)]).sum::<f64>() / cloud.len() as f64;
    assert!(
        mean_zz < 1.5 * sigma * sigma,
        "normal variance {mean_zz} vs sensor {}",
        sigma * sigma
    );
    assert!(mean_zz >= sigma * sigma * (1.0 - 1e-12));
    // And every covariance is still a valid covariance.
    for (i, c) in cloud.covariances().iter().enumerate() {
        cloudprox::uncertainty::validate_covariance(c, &format!("point {i}")).unwrap();
    }
}

#[test]
fn sparser_sampling_means_larger_discretization_error() {
    let spread = |h: f64| {
        let c = PointCloud::from_sigma(grid(h, 20), 0.0)
            .unwrap()
            .with_discretization(&DiscretizationSettings::default())
            .unwrap();
        c.covariances()[210].trace().sqrt()
    };
    let (s1, s2) = (spread(0.01), spread(0.02));
    assert!(
        (s2 / s1 - 2.0).abs() < 1e-6,
        "spread scales with spacing: {s1} {s2}"
    );
}

#[test]
fn bad_settings_are_rejected() {
    let c = PointCloud::from_sigma(grid(0.01, 5), 0.0).unwrap();
    let e = c
        .clone()
        .with_discretization(&DiscretizationSettings {
            k: 1,
            weight_scale: 2.0,
        })
        .unwrap_err();
    assert!(e.to_string().contains("k must be"));
    let e = c
        .with_discretization(&DiscretizationSettings {
            k: 10,
            weight_scale: -1.0,
        })
        .unwrap_err();
    assert!(e.to_string().contains("weight_scale"));
}

#[test]
fn spacing_is_the_distance_to_the_sixth_neighbour() {
    // On a square grid of spacing h the 6th nearest neighbour of an interior point
    // is a diagonal one, at h sqrt 2.
    let h = 0.01;
    let cloud = PointCloud::from_sigma(grid(h, 12), 0.0).unwrap();
    let i = 5 * 12 + 6;
    assert!((cloud.spacing()[i] - h * 2f64.sqrt()).abs() < 1e-12);
    let node_max = cloud.node_spacing()[0];
    assert!(cloud.spacing().iter().all(|&s| s <= node_max));
}
