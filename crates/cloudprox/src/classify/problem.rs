//! The robust SOCP's data: the points in normalized coordinates, the problem
//! assembled in Clarabel's form `min 1/2 z'Pz + q'z, Az + s = b, s in K`, and
//! its reduced form for the specialized method, one small cone per point.
//!
//! The problem (see the [module docs](crate::classify)) has `dim + 1 + n`
//! unknowns `(w, b, xi)`, but each slack `xi_i` appears only in point `i`'s
//! cone and in `xi_i >= 0`: for each point it suffices to keep
//! `a_i = c_i (phi_i, 1)` and the three rows of `B_i = r L_i^T J_i^T` (padded
//! with a zero for `b`), the cone being `(a_i . z + xi_i - 1, B_i z)`,
//! `z = (w, b)` ([`ConeData`]).

use clarabel::algebra::CscMatrix;
use clarabel::solver::SupportedConeT::{self, NonnegativeConeT, SecondOrderConeT};

use crate::classify::Surface;
use crate::math::{Matrix3, Point3, Vector3};
use crate::uncertainty::covariance_factor;
use crate::Real;

/// Points and covariance factors in normalized coordinates `u = (x - center) / scale`.
pub(crate) struct Normalized {
    pub u: Vec<Vector3>,
    /// `L_i / scale` with `L_i L_i^T = Sigma_i`.
    pub factors: Vec<Matrix3>,
    /// `Some(sigma_i / scale)` when every covariance is isotropic.
    pub isotropic: Option<Vec<Real>>,
    pub center: Point3,
    pub scale: Real,
}

impl Normalized {
    pub fn new(points: &[Point3], covs: &[Matrix3]) -> Self {
        let n = points.len() as Real;
        let center = Point3::from(points.iter().map(|p| p.coords).sum::<Vector3>() / n);
        let rms = (points
            .iter()
            .map(|p| (p - center).norm_squared())
            .sum::<Real>()
            / n)
            .sqrt();
        let scale = if rms > 0.0 && rms.is_finite() {
            rms
        } else {
            1.0
        };
        let u = points.iter().map(|p| (p - center) / scale).collect();
        let isotropic = covs
            .iter()
            .map(|c| {
                let s2 = c.trace() / 3.0;
                ((c - Matrix3::identity() * s2).amax() <= 1e-12 * s2.abs().max(Real::MIN_POSITIVE))
                    .then(|| s2.max(0.0).sqrt() / scale)
            })
            .collect::<Option<Vec<Real>>>();
        let factors = covs.iter().map(|c| covariance_factor(c) / scale).collect();
        Self {
            u,
            factors,
            isotropic,
            center,
            scale,
        }
    }
}

/// The assembled problem. Variables are `z = [w (dim), b, xi (n), t?]`.
#[allow(non_snake_case)]
pub(crate) struct SocpProblem {
    pub P: CscMatrix<Real>,
    pub q: Vec<Real>,
    pub A: CscMatrix<Real>,
    pub b: Vec<Real>,
    pub cones: Vec<SupportedConeT<Real>>,
    pub dim: usize,
}

/// Assembles
/// `min 1/2 |w|^2 + lambda sum xi` s.t. `c_i (w.phi_i + b) - 1 + xi_i >= r |L_i^T J_i^T w|`, `xi >= 0`.
///
/// With a linear surface and isotropic covariances, `|L_i^T w| = s_i |w|`, so one
/// cone `t >= |w|` and `n` linear constraints `... >= r s_i t` replace the `n` cones.
pub(crate) fn assemble(
    norm: &Normalized,
    labels: &[Real],
    surface: Surface,
    lambda: Real,
    r: Real,
) -> SocpProblem {
    let n = norm.u.len();
    let d = surface.dim();
    let (col_b, col_xi) = (d, d + 1);
    let shared_cone = surface == Surface::Linear && norm.isotropic.is_some();
    let n_vars = d + 1 + n + usize::from(shared_cone);
    let col_t = d + 1 + n;

    let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |i: usize, j: usize, v: Real| {
        if v != 0.0 {
            rows.push(i);
            cols.push(j);
            vals.push(v);
        }
    };
    let mut b = Vec::new();
    let mut cones = Vec::new();

    // xi_i >= 0
    for i in 0..n {
        push(i, col_xi + i, -1.0);
        b.push(0.0);
    }
    let mut phi = [0.0; 9];
    let mut jac = [Vector3::zeros(); 9];
    // `shared_cone` holds exactly when `sig` is `Some` and the surface linear.
    if let (true, Some(sig)) = (shared_cone, norm.isotropic.as_ref()) {
        // c_i (w.u_i + b) + xi_i - 1 - r s_i t >= 0
        for i in 0..n {
            let row = n + i;
            let c = labels[i];
            for k in 0..3 {
                push(row, k, -c * norm.u[i][k]);
            }
            push(row, col_b, -c);
            push(row, col_xi + i, -1.0);
            push(row, col_t, r * sig[i]);
            b.push(-1.0);
        }
        cones.push(NonnegativeConeT(2 * n));
        // (t, w) in SOC
        let row0 = 2 * n;
        push(row0, col_t, -1.0);
        b.push(0.0);
        for k in 0..d {
            push(row0 + 1 + k, k, -1.0);
            b.push(0.0);
        }
        cones.push(SecondOrderConeT(d + 1));
    } else {
        cones.push(NonnegativeConeT(n));
        for i in 0..n {
            let row0 = n + 4 * i;
            let c = labels[i];
            surface.features(&norm.u[i], &mut phi[..d], &mut jac[..d]);
            // first component: c_i (w.phi_i + b) + xi_i - 1
            for k in 0..d {
                push(row0, k, -c * phi[k]);
            }
            push(row0, col_b, -c);
            push(row0, col_xi + i, -1.0);
            b.push(-1.0);
            // rest: r L_i^T J_i^T w
            let lt = norm.factors[i].transpose();
            for m in 0..3 {
                for k in 0..d {
                    push(row0 + 1 + m, k, -r * (lt.row(m) * jac[k])[0]);
                }
                b.push(0.0);
            }
            cones.push(SecondOrderConeT(4));
        }
    }
    let m = b.len();
    let a = CscMatrix::new_from_triplets(m, n_vars, rows, cols, vals);
    let p = CscMatrix::new_from_triplets(
        n_vars,
        n_vars,
        (0..d).collect(),
        (0..d).collect(),
        vec![1.0; d],
    );
    let mut q = vec![0.0; n_vars];
    for v in &mut q[col_xi..col_xi + n] {
        *v = lambda;
    }
    SocpProblem {
        P: p,
        q,
        A: a,
        b,
        cones,
        dim: d,
    }
}

/// The largest `dim + 1` of any surface (the quadric's 9 coefficients and `b`).
pub(crate) const MAX_UNKNOWNS: usize = 10;

/// One point's constraint: `a = c_i (phi_i, 1)` and the rows of `B_i`.
#[derive(Clone, Copy)]
pub(crate) struct ConeData {
    pub a: [Real; MAX_UNKNOWNS],
    pub b: [[Real; MAX_UNKNOWNS]; 3],
}

impl ConeData {
    /// `(a . z, B z)` over the first `M` unknowns (a constant length, so the
    /// solver's loops unroll; the working set's check passes all
    /// [`MAX_UNKNOWNS`], zero past the surface's own).
    #[inline]
    pub fn apply<const M: usize>(&self, z: &[Real; M]) -> [Real; 4] {
        const { assert!(M <= MAX_UNKNOWNS) };
        let mut g = [0.0; 4];
        for (k, &zk) in z.iter().enumerate() {
            g[0] += self.a[k] * zk;
            g[1] += self.b[0][k] * zk;
            g[2] += self.b[1][k] * zk;
            g[3] += self.b[2][k] * zk;
        }
        g
    }

    /// `out += t_0 a + B^T t_(1:3)` over the first `M` unknowns.
    #[inline]
    pub fn add_transposed<const M: usize>(&self, t: &[Real; 4], out: &mut [Real; M]) {
        const { assert!(M <= MAX_UNKNOWNS) };
        for (k, o) in out.iter_mut().enumerate() {
            *o +=
                t[0] * self.a[k] + t[1] * self.b[0][k] + t[2] * self.b[1][k] + t[3] * self.b[2][k];
        }
    }
}

/// Each point's cone in the reduced form (see [`ConeData`]).
pub(crate) fn cone_data(
    norm: &Normalized,
    labels: &[Real],
    surface: Surface,
    r: Real,
) -> Vec<ConeData> {
    let d = surface.dim();
    let mut phi = [0.0; 9];
    let mut jac = [Vector3::zeros(); 9];
    norm.u
        .iter()
        .zip(labels)
        .zip(&norm.factors)
        .map(|((u, &c), l)| {
            surface.features(u, &mut phi[..d], &mut jac[..d]);
            let mut cone = ConeData {
                a: [0.0; MAX_UNKNOWNS],
                b: [[0.0; MAX_UNKNOWNS]; 3],
            };
            for k in 0..d {
                cone.a[k] = c * phi[k];
            }
            cone.a[d] = c;
            let lt = l.transpose();
            for (row, b) in cone.b.iter_mut().enumerate() {
                for k in 0..d {
                    b[k] = r * lt.row(row).dot(&jac[k].transpose());
                }
            }
            cone
        })
        .collect()
}
