//! The samples that stand for surface elements in queries.

use crate::cloud::PointCloud;
use crate::element::SurfaceElement;
use crate::math::{Matrix3, Point3};

/// The samples of `elements` (see [`crate::element::SurfaceElements::samples`])
/// and the element each stands for.
pub(crate) fn element_samples(
    cloud: &PointCloud,
    elements: &[SurfaceElement],
    indices: &[u32],
) -> (PointCloud, Vec<u32>) {
    let mut points: Vec<Point3> = Vec::new();
    let mut total: Vec<Matrix3> = Vec::new();
    let mut sensor: Vec<Matrix3> = Vec::new();
    let mut owner: Vec<u32> = Vec::new();
    for (k, e) in elements.iter().enumerate() {
        if e.is_point() {
            let i = indices[e.first as usize] as usize;
            points.push(cloud.points()[i]);
            total.push(cloud.covariances()[i]);
            sensor.push(cloud.sensor_covariances()[i]);
            owner.push(k as u32);
            continue;
        }
        for (u, v) in e.sample_coordinates() {
            let (p, var) = e.surface_point(u, v);
            let cov = e.surface_covariance(var);
            points.push(p);
            total.push(cov);
            sensor.push(cov);
            owner.push(k as u32);
        }
    }
    (
        PointCloud::from_total_and_sensor(points, total, sensor),
        owner,
    )
}
