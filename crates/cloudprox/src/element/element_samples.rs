//! The samples that stand for surface elements in queries.

use crate::cloud::PointCloud;
use crate::element::SurfaceElement;
use crate::math::{Matrix3, Point3};
use crate::Real;

/// The pitch, in the element's sampling spacings, of the grid on which a large
/// element is also sampled. Five samples cannot hold a separating surface to a
/// face half a metre across where another object meets it between them (a
/// gripper through a scanned table top, 7 sigma deep, was read free: the
/// surface trained on them bent around the gripper). On a grid of pitch `p`
/// the samples' own spacing is about `p sqrt 2`, so the near rule's half
/// spacing reaches every point of the surface from some sample, and a large
/// element costs the classifier about one sample per `p^2` of its points.
/// Measured at 4, 6 and 8 (the reproduction's piano levels, the Kinect frame,
/// the criterion spheres): at 4 the 5 mm spheres 3 sigma into each other
/// took 2.8x as long (grid samples over their curved elements cut the region
/// four times), at 8 the 0.5% level's median query was 6.4 ms against 5.5;
/// the Kinect frame read the same at all three.
pub(crate) const GRID_PITCH_SPACINGS: Real = 6.0;

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
        let grid = grid_coordinates(e, GRID_PITCH_SPACINGS * e.spacing);
        for (u, v) in e.sample_coordinates().into_iter().chain(grid) {
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

/// Tangential coordinates of the centres of a grid of pitch about `pitch` over
/// `e`'s extent (cells of equal size, at least two along some tangent), where
/// the surface was sampled ([`SurfaceElement::covers`]); none for an element
/// less than two pitches across along both tangents.
fn grid_coordinates(e: &SurfaceElement, pitch: Real) -> Vec<(Real, Real)> {
    let [[u0, u1], [v0, v1]] = e.extent;
    if !(pitch.is_finite() && pitch > 0.0) {
        return Vec::new();
    }
    let cells = |lo: Real, hi: Real| ((hi - lo) / pitch).floor().max(1.0) as usize;
    let (nu, nv) = (cells(u0, u1), cells(v0, v1));
    if nu < 2 && nv < 2 {
        return Vec::new();
    }
    let (du, dv) = ((u1 - u0) / nu as Real, (v1 - v0) / nv as Real);
    (0..nu)
        .flat_map(|i| (0..nv).map(move |j| (i, j)))
        .map(|(i, j)| (u0 + (i as Real + 0.5) * du, v0 + (j as Real + 0.5) * dv))
        .filter(|&(u, v)| e.covers(u, v))
        .collect()
}
