//! A trained separating surface, evaluated in world coordinates.

use crate::classify::Surface;
use crate::math::{Point3, Pose, Vector3};
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
