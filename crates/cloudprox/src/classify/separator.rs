//! A trained separating surface, evaluated in world coordinates.

use crate::classify::Surface;
use crate::math::{Matrix3, Point3, Pose, Vector3};
use crate::Real;

/// The surface `f(x) = w . phi((frame^-1 x - center) / scale) + b`, positive on
/// cloud A's side and negative on cloud B's. `center` and the coefficients live in
/// the frame the surface was trained in; `frame` maps that frame to the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Separator {
    /// Feature family.
    pub surface: Surface,
    /// Feature weights (length [`Surface::dim`]).
    pub w: Vec<Real>,
    /// Offset.
    pub b: Real,
    /// Normalization centre (world frame of the problem).
    pub center: Point3,
    /// Normalization scale (metres).
    pub scale: Real,
    /// Pose of the training frame in the world (identity when trained in the world).
    pub frame: Pose,
}

impl Separator {
    /// `f(x)` and its gradient `grad f(x)` at a world point (complete, world units).
    pub fn value_and_gradient(&self, x: &Point3) -> (Real, Vector3) {
        let (f, g) = self.value_and_gradient_local(&self.frame.inverse_transform_point(x));
        (f, self.frame.rotation * g)
    }

    /// `f` at a point given in the training frame.
    pub fn value_local(&self, x: &Point3) -> Real {
        self.value_and_gradient_local(x).0
    }

    /// `f` and its gradient at a point given in the training frame.
    pub fn value_and_gradient_local(&self, x: &Point3) -> (Real, Vector3) {
        let u = (x - self.center) / self.scale;
        let d = self.surface.dim();
        let mut phi = [0.0; 9];
        let mut jac = [Vector3::zeros(); 9];
        self.surface.features(&u, &mut phi[..d], &mut jac[..d]);
        let mut f = self.b;
        let mut g = Vector3::zeros();
        for k in 0..d {
            f += self.w[k] * phi[k];
            g += self.w[k] * jac[k];
        }
        (f, g / self.scale)
    }

    /// The surface as a polynomial of degree two in the coordinates of another
    /// frame, posed at `pose` in the training frame: one matrix-vector product
    /// per evaluation instead of the feature map, and no point or gradient to
    /// rotate (both feature families are of degree at most two, so the form is
    /// the same surface).
    pub fn quadratic_form(&self, pose: &Pose) -> QuadraticForm {
        let w = &self.w;
        let mut quadratic = Matrix3::zeros();
        if self.surface == Surface::Quadric {
            let h = std::f64::consts::FRAC_1_SQRT_2;
            quadratic = Matrix3::new(
                w[3],
                h * w[6],
                h * w[7],
                h * w[6],
                w[4],
                h * w[8],
                h * w[7],
                h * w[8],
                w[5],
            );
        }
        let r = pose.rotation.to_rotation_matrix().into_inner();
        let s = self.scale;
        QuadraticForm {
            center: pose.inverse_transform_point(&self.center),
            linear: r.transpose() * Vector3::new(w[0], w[1], w[2]) / s,
            quadratic: r.transpose() * quadratic * r / (s * s),
            offset: self.b,
        }
    }

    /// `x` moved onto the surface by a few Newton steps along the gradient.
    pub fn project(&self, x: &Point3) -> Point3 {
        let mut p = *x;
        for _ in 0..4 {
            let (f, g) = self.value_and_gradient(&p);
            let n2 = g.norm_squared();
            if n2 <= 0.0 || !f.is_finite() {
                break;
            }
            p -= g * (f / n2);
        }
        p
    }
}

/// A [`Separator`] in the coordinates of one frame
/// ([`Separator::quadratic_form`]): `f(x) = b + l . d + d^T Q d` with
/// `d = x - c`, centred on the separator's own centre so that no large
/// coordinates cancel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraticForm {
    center: Point3,
    linear: Vector3,
    quadratic: Matrix3,
    offset: Real,
}

impl QuadraticForm {
    /// `f` and its gradient at a point of the form's frame.
    #[inline]
    pub fn value_and_gradient(&self, x: &Point3) -> (Real, Vector3) {
        let d = x - self.center;
        let qd = self.quadratic * d;
        (
            self.offset + d.dot(&(self.linear + qd)),
            self.linear + 2.0 * qd,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn the_quadratic_form_is_the_surface_in_the_other_frame() {
        let pose = Pose::from_parts(
            Translation3::new(0.3, -1.2, 2.0),
            UnitQuaternion::from_euler_angles(0.4, -0.9, 1.7),
        );
        for surface in [Surface::Linear, Surface::Quadric] {
            let w: Vec<Real> = (0..surface.dim()).map(|k| 0.7 - 0.31 * k as Real).collect();
            let sep = Separator {
                surface,
                w,
                b: -0.2,
                center: Point3::new(0.1, 0.5, -0.3),
                scale: 0.04,
                frame: Pose::identity(),
            };
            let form = sep.quadratic_form(&pose);
            for k in 0..20 {
                let t = k as Real;
                let p = Point3::new((0.9 * t).sin(), (1.3 * t).cos(), 0.05 * t - 0.4);
                let (f, g) = form.value_and_gradient(&p);
                let (f0, g0) = sep.value_and_gradient_local(&(pose * p));
                let g0 = pose.rotation.inverse() * g0;
                let tol = 1e-12 * (1.0 + f0.abs());
                assert!((f - f0).abs() <= tol, "{surface:?}: {f} vs {f0}");
                assert!((g - g0).norm() <= 1e-12 * (1.0 + g0.norm()), "{surface:?}");
            }
        }
    }
}
