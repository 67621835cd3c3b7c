//! Point, vector, matrix and pose aliases used throughout the crate.

/// The scalar type of every coordinate, covariance and probability.
pub type Real = f64;

/// A point in 3D space (metres).
pub type Point3 = nalgebra::Point3<Real>;
/// A vector in 3D space.
pub type Vector3 = nalgebra::Vector3<Real>;
/// A 3x3 matrix (covariances are in metres squared).
pub type Matrix3 = nalgebra::Matrix3<Real>;
/// A 4x4 homogeneous matrix.
pub type Matrix4 = nalgebra::Matrix4<Real>;
/// A rigid pose (rotation then translation), mapping an object's own frame to the world.
pub type Pose = nalgebra::Isometry3<Real>;

/// Mean and principal axes of a set of points: the eigen-decomposition of their
/// scatter matrix (about the mean, divided by the count), axes sorted by
/// ascending variance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrincipalAxes {
    /// The points' mean.
    pub mean: Point3,
    /// Variances along the axes, ascending (`variances[0]` is the least spread).
    pub variances: Vector3,
    /// Unit axes, one per column, in the order of `variances`.
    pub axes: Matrix3,
}

impl PrincipalAxes {
    /// The principal axes of `points` (at least one point; a single point gets
    /// zero variances and the coordinate axes).
    pub fn of<I>(points: I) -> Self
    where
        I: IntoIterator<Item = Point3>,
        I::IntoIter: Clone,
    {
        let it = points.into_iter();
        let (sum, n) = it.clone().fold((Vector3::zeros(), 0usize), |(s, n), p| {
            (s + p.coords, n + 1)
        });
        let n = n.max(1) as Real;
        let mean = sum / n;
        let scatter = it.fold(Matrix3::zeros(), |s, p| {
            let d = p.coords - mean;
            s + d * d.transpose()
        }) / n;
        let eig = scatter.symmetric_eigen();
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        let mut axes = Matrix3::identity();
        let mut variances = Vector3::zeros();
        for (k, &o) in order.iter().enumerate() {
            let axis = eig.eigenvectors.column(o).into_owned();
            if axis.iter().all(|c| c.is_finite()) && axis.norm() > 0.5 {
                axes.set_column(k, &axis);
            }
            variances[k] = eig.eigenvalues[o].max(0.0);
        }
        Self {
            mean: Point3::from(mean),
            variances,
            axes,
        }
    }

    /// The axis of least spread (a plane's normal).
    pub fn least(&self) -> Vector3 {
        self.axes.column(0).into_owned()
    }

    /// The axis of largest spread.
    pub fn largest(&self) -> Vector3 {
        self.axes.column(2).into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_axes_of_an_ellipse_of_points() {
        // Points on an axis-aligned ellipse (x half-axis 3, y 1) in the z = 2 plane.
        let pts: Vec<Point3> = (0..64)
            .map(|k| {
                let t = Real::from(k) * std::f64::consts::TAU / 64.0;
                Point3::new(3.0 * t.cos(), t.sin(), 2.0)
            })
            .collect();
        let pa = PrincipalAxes::of(pts.iter().copied());
        assert!((pa.mean - Point3::new(0.0, 0.0, 2.0)).norm() < 1e-12);
        assert!(pa.variances[0].abs() < 1e-12);
        assert!((pa.variances[1] - 0.5).abs() < 1e-12);
        assert!((pa.variances[2] - 4.5).abs() < 1e-12);
        assert!(pa.least().cross(&Vector3::z()).norm() < 1e-9);
        assert!(pa.largest().cross(&Vector3::x()).norm() < 1e-9);
        let one = PrincipalAxes::of([Point3::new(1.0, 2.0, 3.0)]);
        assert_eq!(one.variances, Vector3::zeros());
    }
}
