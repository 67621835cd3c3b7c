//! Discretization error: how sparsely the surface around each point was sampled.

use crate::bvh::{knn_of_every_point, Bvh};
use crate::error::{Error, Result};
use crate::math::{Matrix3, Point3, Vector3};
use crate::Real;

/// Settings of the k-nearest-neighbour discretization estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscretizationSettings {
    /// Number of neighbours `k` (FCL used 10).
    pub k: usize,
    /// The Gaussian weight is `exp(-d^2 / s^2)` with `s = weight_scale * d_k`, `d_k`
    /// the distance to the k-th neighbour (FCL: 2).
    pub weight_scale: Real,
}

impl Default for DiscretizationSettings {
    fn default() -> Self {
        Self {
            k: 10,
            weight_scale: 2.0,
        }
    }
}

impl DiscretizationSettings {
    /// Checks `k >= 2` and a finite positive `weight_scale`.
    pub fn validate(&self) -> Result<()> {
        if self.k < 2 {
            return Err(Error::invalid(format!(
                "discretization k must be >= 2, got {}",
                self.k
            )));
        }
        if !(self.weight_scale.is_finite() && self.weight_scale > 0.0) {
            return Err(Error::invalid(format!(
                "discretization weight_scale must be finite and > 0, got {}",
                self.weight_scale
            )));
        }
        Ok(())
    }
}

/// The discretization covariance of every point, from its `k` nearest neighbours.
///
/// For point `i` with neighbours `j` at distances `d_j` (itself included), weights
/// `w_j = exp(-d_j^2 / s^2)` with `s = weight_scale * d_k` (distances, not squared
/// distances as FCL's code had), the weighted scatter of the neighbourhood about its
/// weighted mean is
/// `S_i = sum_j w_j (x_j - m)(x_j - m)^T / sum_j w_j`.
/// Part of that scatter is the sensor noise of the neighbours themselves: in the
/// normal direction of a flat, densely sampled surface `S_i` is exactly the sensor
/// covariance. Counting it again would inflate the noise, so the sensor covariance
/// is subtracted and the result projected back onto the PSD cone:
/// `Sigma_disc,i = psd(S_i - Sigma_sensor,i)`. What remains is the spread of the
/// surface patch a sample stands for (tangential) plus any curvature it spans.
///
/// `sensor` holds the sensor covariances (same length as `points`); clouds with
/// fewer than `k + 1` points use all points. The neighbours come from `bvh`
/// up to [`GRID_KNN_MIN_POINTS`](crate::bvh::GRID_KNN_MIN_POINTS) points and from the hashed grid of the
/// spatial search above (exact as well, and much cheaper on large clouds; the
/// same neighbours but where distances tie).
pub fn discretization_covariances(
    points: &[Point3],
    sensor: &[Matrix3],
    bvh: &Bvh,
    settings: &DiscretizationSettings,
) -> Result<Vec<Matrix3>> {
    check_inputs(points, sensor, settings)?;
    if points.len() < 2 {
        return Ok(vec![Matrix3::zeros(); points.len()]);
    }
    let k = settings.k.min(points.len() - 1);
    Ok(knn_of_every_point(points, bvh, k, |i, neighbours| {
        of_neighbourhood(points, neighbours, &sensor[i], settings)
    }))
}

impl DiscretizationSettings {
    /// [`discretization_covariances`] with these settings and, from the
    /// same neighbourhoods, every point's distance to its `nth` nearest
    /// other point (the last of the k-NN pass of `min(nth, n - 1)`
    /// neighbours: that distance does not depend on how ties are broken).
    /// `None` for the distances when the neighbourhoods hold fewer than
    /// `nth + 1` points (`k < nth`, or a cloud of one point).
    pub(crate) fn covariances_and_nth_distance(
        &self,
        points: &[Point3],
        sensor: &[Matrix3],
        bvh: &Bvh,
        nth: usize,
    ) -> Result<(Vec<Matrix3>, Option<Vec<Real>>)> {
        check_inputs(points, sensor, self)?;
        if points.len() < 2 || self.k < nth {
            let cov = discretization_covariances(points, sensor, bvh, self)?;
            return Ok((cov, None));
        }
        let k = self.k.min(points.len() - 1);
        let at = nth.min(points.len() - 1);
        let both: Vec<(Matrix3, Real)> = knn_of_every_point(points, bvh, k, |i, neighbours| {
            let cov = of_neighbourhood(points, neighbours, &sensor[i], self);
            (cov, neighbours.get(at).map_or(0.0, |&(d2, _)| d2.sqrt()))
        });
        let (cov, nth_distance) = both.into_iter().unzip();
        Ok((cov, Some(nth_distance)))
    }
}

/// Validates the settings and the number of sensor covariances.
fn check_inputs(
    points: &[Point3],
    sensor: &[Matrix3],
    settings: &DiscretizationSettings,
) -> Result<()> {
    settings.validate()?;
    if sensor.len() != points.len() {
        return Err(Error::Shape {
            what: "sensor covariances".into(),
            expected: points.len(),
            got: sensor.len(),
        });
    }
    Ok(())
}

/// Neighbourhoods up to this size keep their weights between the two passes
/// of [`of_neighbourhood`] (larger ones compute them twice, the same values).
const KEPT_WEIGHTS: usize = 32;

/// One point's discretization covariance from its `neighbours` (itself
/// included, as `(squared distance, index)` nearest first).
fn of_neighbourhood(
    points: &[Point3],
    neighbours: &[(Real, u32)],
    sensor_i: &Matrix3,
    settings: &DiscretizationSettings,
) -> Matrix3 {
    let d_k = neighbours.last().map_or(0.0, |&(d2, _)| d2.sqrt());
    if d_k <= 0.0 {
        return Matrix3::zeros();
    }
    let s = settings.weight_scale * d_k;
    let weight = |d2: Real| (-d2 / (s * s)).exp();
    let mut kept = [0.0; KEPT_WEIGHTS];
    let keep = neighbours.len() <= KEPT_WEIGHTS;
    let mut wsum = 0.0;
    let mut mean = Vector3::zeros();
    for (n, &(d2, j)) in neighbours.iter().enumerate() {
        let w = weight(d2);
        if keep {
            kept[n] = w;
        }
        wsum += w;
        mean += w * points[j as usize].coords;
    }
    mean /= wsum;
    let mut scatter = Matrix3::zeros();
    for (n, &(d2, j)) in neighbours.iter().enumerate() {
        let w = if keep { kept[n] } else { weight(d2) };
        let o = points[j as usize].coords - mean;
        scatter += w * o * o.transpose();
    }
    scatter /= wsum;
    project_psd(&(scatter - sensor_i))
}

/// The nearest positive semi-definite matrix (negative eigenvalues set to zero).
fn project_psd(m: &Matrix3) -> Matrix3 {
    let sym = 0.5 * (m + m.transpose());
    let eig = sym.symmetric_eigen();
    let vals = eig.eigenvalues.map(|l| l.max(0.0));
    let v = eig.eigenvectors;
    let c = v * Matrix3::from_diagonal(&vals) * v.transpose();
    0.5 * (c + c.transpose())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BvhSettings, BvhWorkspace, GRID_KNN_MIN_POINTS};
    use crate::sample::{add_noise, box_surface};

    /// Above the grid's threshold the covariances are those the tree's
    /// neighbours give (the points are noisy: no distances tie).
    #[test]
    fn grid_and_tree_neighbourhoods_give_the_same_covariances() {
        let pts = add_noise(
            &box_surface(&Point3::origin(), &Vector3::new(0.3, 0.2, 0.1), 0.004),
            0.001,
            5,
        );
        assert!(pts.len() > GRID_KNN_MIN_POINTS);
        let sensor: Vec<Matrix3> = (0..pts.len())
            .map(|i| Matrix3::identity() * (1e-6 * (1.0 + (i % 3) as Real)))
            .collect();
        let sigmas = vec![0.0; pts.len()];
        let bvh = Bvh::build(&pts, &sigmas, &BvhSettings::default()).unwrap();
        let settings = DiscretizationSettings::default();
        let grid = discretization_covariances(&pts, &sensor, &bvh, &settings).unwrap();
        let (mut ws, mut nn) = (BvhWorkspace::default(), Vec::new());
        let mut nonzero = 0;
        for (i, p) in pts.iter().enumerate() {
            bvh.nearest_k(&pts, p, settings.k + 1, &mut ws, &mut nn);
            let tree = of_neighbourhood(&pts, &nn, &sensor[i], &settings);
            let scale = tree.norm().max(1e-30);
            assert!(
                (grid[i] - tree).norm() <= 1e-12 * scale,
                "point {i}: {} vs {}",
                grid[i],
                tree
            );
            nonzero += usize::from(tree.norm() > 0.0);
        }
        assert!(nonzero > pts.len() / 2);
    }
}
