//! A specialized primal-dual interior-point method for the robust SOCP, with
//! Newton systems reduced to the surface's own `dim + 1` unknowns.
//!
//! In conic form the problem (see the [module docs](crate::classify)) reads
//!
//! ```text
//! minimize    1/2 x^T P x + q^T x          x = (z, xi),  z = (w, b)
//! subject to  s = G x - h,  s in K,
//! ```
//!
//! where `P` is the identity on `w`, `q = lambda` on the slacks, and `K` holds,
//! for each point, the second-order cone of `s_i = (a_i . z + xi_i - 1, B_i z)`
//! (`a_i = c_i (phi_i, 1)`, `B_i = r L_i^T J_i^T` padded with a zero column for
//! `b`) and the half-line of `xi_i >= 0`. The method is the standard
//! infeasible-start path-following method with Nesterov-Todd scaling and
//! Mehrotra's predictor-corrector (Vandenberghe, *The CVXOPT linear and
//! quadratic cone program solvers*, 2010; Nocedal & Wright ch. 14): each
//! iteration solves the Newton system twice with one factorization and moves
//! both primal and dual variables: 11-14 iterations from 100 to 2000 points,
//! where the log-barrier method it replaced took 50-460 Newton steps.
//!
//! The Newton system's matrix `P + G^T W^-2 G` is an arrow: the NT scaling
//! `W_i^2 = eta_i^2 (2 wb_i wb_i^T - J)` of each cone couples only `z` and
//! `xi_i`, so each slack is eliminated in closed form (a Schur complement) and
//! one `(dim + 1)`-square system is factored per iteration, `O(n dim^2)` work:
//! with `v_i = J wb_i`, `p_i = v_i0 a_i + B_i^T v_i,1:3` and `c = eta_i^-2`,
//! point `i` adds `c (2 p p^T - a a^T + B^T B)` to the `z` block,
//! `c (2 v_0 p - a)` to the `z, xi_i` column and `c (2 v_0^2 - 1) + y_i / s_i`
//! (its half-line's scaling) to the `xi_i` diagonal.
//!
//! As the iteration count hardly grows with the points, which points it sees
//! is [`super::working_set`]'s choice.
//!
//! Clarabel stays the exact reference: tests compare the two, and
//! [`super::train`] falls back to Clarabel when this method does not converge.

use nalgebra::{DMatrix, DVector};

use crate::classify::problem::{ConeData, MAX_UNKNOWNS};
use crate::Real;

/// Iteration limit (the method converges in far fewer).
const MAX_ITER: u32 = 80;
/// Fraction of the largest feasible step taken.
const STEP_FRACTION: Real = 0.99;

type Cone = [Real; 4];

fn dot4(x: &Cone, y: &Cone) -> Real {
    x[0] * y[0] + x[1] * y[1] + x[2] * y[2] + x[3] * y[3]
}

/// `x^T J x = x_0^2 - |x_1|^2`.
fn jdet(x: &Cone) -> Real {
    x[0] * x[0] - (x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
}

/// The Jordan product `x o y = (x . y, x_0 y_1 + y_0 x_1)`.
fn jprod(x: &Cone, y: &Cone) -> Cone {
    [
        dot4(x, y),
        x[0] * y[1] + y[0] * x[1],
        x[0] * y[2] + y[0] * x[2],
        x[0] * y[3] + y[0] * x[3],
    ]
}

/// Solves `l o x = r` for `x` (`l` in the cone's interior).
fn jdiv(l: &Cone, r: &Cone) -> Cone {
    let det = jdet(l);
    let x0 = (l[0] * r[0] - (l[1] * r[1] + l[2] * r[2] + l[3] * r[3])) / det;
    [
        x0,
        (r[1] - x0 * l[1]) / l[0],
        (r[2] - x0 * l[2]) / l[0],
        (r[3] - x0 * l[3]) / l[0],
    ]
}

/// The Nesterov-Todd scaling of one cone: `W = eta Wb`,
/// `Wb = [[w_0, w_1^T], [w_1, I + w_1 w_1^T / (1 + w_0)]]`, so that
/// `W^-1 s = W y = lambda`.
#[derive(Clone, Copy, Default)]
struct Scaling {
    w: Cone,
    eta: Real,
}

impl Scaling {
    fn new(s: &Cone, y: &Cone) -> Option<Self> {
        let (sd, yd) = (jdet(s), jdet(y));
        if !(sd > 0.0 && yd > 0.0 && s[0] > 0.0 && y[0] > 0.0) {
            return None;
        }
        let (sn, yn) = (sd.sqrt(), yd.sqrt());
        let sb = s.map(|x| x / sn);
        let yb = y.map(|x| x / yn);
        let gamma = Real::midpoint(1.0, dot4(&sb, &yb)).sqrt();
        let k = 1.0 / (2.0 * gamma);
        Some(Self {
            w: [
                k * (sb[0] + yb[0]),
                k * (sb[1] - yb[1]),
                k * (sb[2] - yb[2]),
                k * (sb[3] - yb[3]),
            ],
            eta: (sn / yn).sqrt(),
        })
    }

    /// `Wb x`.
    fn apply_bar(&self, x: &Cone) -> Cone {
        let w = &self.w;
        let w1x1 = w[1] * x[1] + w[2] * x[2] + w[3] * x[3];
        let k = x[0] + w1x1 / (1.0 + w[0]);
        [
            w[0] * x[0] + w1x1,
            x[1] + k * w[1],
            x[2] + k * w[2],
            x[3] + k * w[3],
        ]
    }

    /// `W x`.
    fn apply(&self, x: &Cone) -> Cone {
        self.apply_bar(x).map(|v| v * self.eta)
    }

    /// `W^-1 x = J Wb J x / eta`.
    fn apply_inv(&self, x: &Cone) -> Cone {
        let jx = [x[0], -x[1], -x[2], -x[3]];
        let y = self.apply_bar(&jx);
        [y[0], -y[1], -y[2], -y[3]].map(|v| v / self.eta)
    }

    /// `W^-2 x = (2 J w w^T J - J) x / eta^2`.
    fn apply_inv_sq(&self, x: &Cone) -> Cone {
        let v = [self.w[0], -self.w[1], -self.w[2], -self.w[3]];
        let k = 2.0 * dot4(&v, x);
        let c = 1.0 / (self.eta * self.eta);
        [
            c * (k * v[0] - x[0]),
            c * (k * v[1] + x[1]),
            c * (k * v[2] + x[2]),
            c * (k * v[3] + x[3]),
        ]
    }
}

/// The largest `alpha` (at most `cap`) with `x + alpha dx` in the cone, `x` in
/// its interior.
fn cone_step(x: &Cone, dx: &Cone, cap: Real) -> Real {
    let a = jdet(dx);
    if a >= 0.0 && dx[0] >= 0.0 {
        return cap; // a direction inside the cone never leaves it
    }
    // A cone is convex: if the step's end is inside, so is the whole step
    // (most cones, once another has set a small cap): no root needed.
    let end = [
        x[0] + cap * dx[0],
        x[1] + cap * dx[1],
        x[2] + cap * dx[2],
        x[3] + cap * dx[3],
    ];
    if end[0] > 0.0 && jdet(&end) > 0.0 {
        return cap;
    }
    let b = x[0] * dx[0] - (x[1] * dx[1] + x[2] * dx[2] + x[3] * dx[3]);
    let c = jdet(x);
    let disc = b * b - a * c;
    // (x + alpha dx)^T J (x + alpha dx) = a alpha^2 + 2 b alpha + c, c > 0.
    let root = if a < 0.0 {
        let sq = disc.max(0.0).sqrt();
        if b < 0.0 {
            c / (sq - b)
        } else {
            (b + sq) / (-a)
        }
    } else if b < 0.0 && disc >= 0.0 {
        c / (disc.sqrt() - b)
    } else {
        Real::INFINITY
    };
    // Along the cone's axis the first component must stay positive as well.
    let axis = if dx[0] < 0.0 {
        -x[0] / dx[0]
    } else {
        Real::INFINITY
    };
    root.min(axis).min(cap)
}

fn half_line_step(x: Real, dx: Real, cap: Real) -> Real {
    if dx < 0.0 {
        (-x / dx).min(cap)
    } else {
        cap
    }
}

/// An optimum of the robust SOCP.
pub(crate) struct Solution {
    pub w: Vec<Real>,
    pub b: Real,
    pub xi: Vec<Real>,
    /// Interior-point iterations.
    pub iterations: u32,
}

/// The primal-dual method on the cones `data` (surface dimension `d`: 3 or
/// 9, the linear and quadric surfaces; `None` for any other).
pub(crate) fn solve_primal_dual(
    data: &[ConeData],
    d: usize,
    lambda: Real,
    tol: Real,
) -> Option<Solution> {
    // One solver per number of unknowns, so that every per-point loop over
    // them has a constant length (unrolled; the same operations in the same
    // order, so the same results as a loop over a run-time length).
    match d + 1 {
        4 => solve_fixed::<4>(data, lambda, tol),
        MAX_UNKNOWNS => solve_fixed::<MAX_UNKNOWNS>(data, lambda, tol),
        _ => None,
    }
}

/// [`solve_primal_dual`] with `M = d + 1` unknowns `z = (w, b)`.
fn solve_fixed<const M: usize>(data: &[ConeData], lambda: Real, tol: Real) -> Option<Solution> {
    let n = data.len();
    let m = M;
    let d = M - 1;
    let nu = (2 * n) as Real;

    // Start: x = 0 with unit slacks, s and y on the cones' axes, y splitting
    // lambda between each point's two constraints (dual residual zero in xi).
    let mut z = [0.0; M];
    let mut xi = vec![1.0; n];
    let mut sc: Vec<Cone> = vec![[1.0, 0.0, 0.0, 0.0]; n];
    let mut yc: Vec<Cone> = vec![[0.5 * lambda, 0.0, 0.0, 0.0]; n];
    let mut sn = vec![1.0; n];
    let mut yn = vec![0.5 * lambda; n];

    // Scratch.
    let mut scal = vec![Scaling::default(); n];
    let mut rs: Vec<Cone> = vec![[0.0; 4]; n];
    let mut rsn = vec![0.0; n];
    let mut rz = [0.0; M];
    let mut rxi = vec![0.0; n];
    let mut delta = vec![0.0; n];
    let mut hcol: Vec<[Real; M]> = vec![[0.0; M]; n];
    let mut s_mat = DMatrix::<Real>::zeros(m, m);
    let (mut aff, mut cor) = (Direction::<M>::new(n), Direction::<M>::new(n));
    // Each point's `B^T B` (packed lower triangle), fixed over the iterations:
    // the Schur complement then adds three terms per entry, not five.
    let btb: Vec<[Real; PACKED]> = data.iter().map(|pd| packed_btb(pd, m)).collect();

    for iter in 0..MAX_ITER {
        // Residuals: r_s = s - (G x - h), r_d = P x + q - G^T y.
        let mut res_p: Real = 0.0;
        for k in 0..m {
            rz[k] = if k < d { z[k] } else { 0.0 };
        }
        for i in 0..n {
            let pd = &data[i];
            let g = pd.apply(&z);
            let y = &yc[i];
            rs[i] = [
                sc[i][0] - (g[0] + xi[i] - 1.0),
                sc[i][1] - g[1],
                sc[i][2] - g[2],
                sc[i][3] - g[3],
            ];
            rsn[i] = sn[i] - xi[i];
            res_p = res_p
                .max(rs[i].iter().fold(0.0, |a: Real, x| a.max(x.abs())))
                .max(rsn[i].abs());
            pd.add_transposed(&y.map(|x| -x), &mut rz);
            rxi[i] = lambda - y[0] - yn[i];
        }
        let res_d = rz.iter().chain(&rxi).fold(0.0, |a: Real, x| a.max(x.abs()));
        let gap: Real = (0..n).map(|i| dot4(&sc[i], &yc[i]) + sn[i] * yn[i]).sum();
        let pobj =
            0.5 * z[..d].iter().map(|x| x * x).sum::<Real>() + lambda * xi.iter().sum::<Real>();
        let zmax = z.iter().fold(1.0, |a: Real, x| a.max(x.abs()));
        if res_p <= tol * zmax && res_d <= tol * (lambda + zmax) && gap <= tol * pobj.abs().max(1.0)
        {
            return finite_solution(&z, &xi, d, iter);
        }
        let mu = gap / nu;

        // Scalings, the Schur complement S and its per-point pieces.
        let mut sacc = [0.0; PACKED];
        for k in 0..d {
            sacc[tri(k) + k] = 1.0;
        }
        for i in 0..n {
            let sc_i = Scaling::new(&sc[i], &yc[i])?;
            scal[i] = sc_i;
            let pd = &data[i];
            let a = &pd.a;
            let v = [sc_i.w[0], -sc_i.w[1], -sc_i.w[2], -sc_i.w[3]];
            let c1 = 1.0 / (sc_i.eta * sc_i.eta);
            let mut p = [0.0; M];
            pd.add_transposed(&v, &mut p);
            let di = c1 * (2.0 * v[0] * v[0] - 1.0) + yn[i] / sn[i];
            delta[i] = di;
            let inv_d = 1.0 / di;
            // S_i = c1 B^T B + alpha a a^T + beta p p^T + gamma (a p^T + p a^T)
            let alpha = -c1 - c1 * c1 * inv_d;
            let beta = 2.0 * c1 - 4.0 * c1 * c1 * v[0] * v[0] * inv_d;
            let gamma = 2.0 * c1 * c1 * v[0] * inv_d;
            let hi = &mut hcol[i];
            let bb = &btb[i];
            for k in 0..m {
                hi[k] = c1 * (2.0 * v[0] * p[k] - a[k]);
                let ca = alpha * a[k] + gamma * p[k];
                let cp = beta * p[k] + gamma * a[k];
                let at = tri(k);
                let row = sacc[at..=at + k].iter_mut().zip(&bb[at..=at + k]);
                for (l, (x, b)) in row.enumerate() {
                    *x += ca * a[l] + cp * p[l] + c1 * b;
                }
            }
        }
        for k in 0..m {
            for l in 0..=k {
                let x = sacc[tri(k) + l];
                s_mat[(k, l)] = x;
                s_mat[(l, k)] = x;
            }
        }
        let chol = s_mat.clone().cholesky()?;

        // The Newton direction whose scaled complementarity is
        // `W^-1 ds + W dy = lambda \ rc`, given `wq = W (lambda \ rc)` per cone
        // and `wqn = rc / y` per half-line, with the largest step that keeps
        // `s` and `y` in their cones.
        let solve_dir = |wq: &[Cone], wqn: &[Real], dir: &mut Direction<M>| -> Option<Real> {
            // t = W^-2 (wq + r_s), and the reduced right-hand side.
            let mut rhs_z = rz.map(|x| -x);
            for i in 0..n {
                let u = [
                    wq[i][0] + rs[i][0],
                    wq[i][1] + rs[i][1],
                    wq[i][2] + rs[i][2],
                    wq[i][3] + rs[i][3],
                ];
                let t = scal[i].apply_inv_sq(&u);
                dir.tc[i] = t;
                let tn = yn[i] / sn[i] * (wqn[i] + rsn[i]);
                dir.tn[i] = tn;
                data[i].add_transposed(&t, &mut rhs_z);
                let rhs_xi = -rxi[i] + t[0] + tn;
                dir.rhs_xi[i] = rhs_xi;
                let f = rhs_xi / delta[i];
                for (r, h) in rhs_z.iter_mut().zip(&hcol[i]) {
                    *r -= h * f;
                }
            }
            let dz = chol.solve(&DVector::from_column_slice(&rhs_z));
            dir.dz.copy_from_slice(dz.as_slice());
            let mut alpha: Real = 1.0 / STEP_FRACTION;
            for i in 0..n {
                let hi = &hcol[i];
                let hdz: Real = hi.iter().zip(&dir.dz).map(|(a, b)| a * b).sum();
                let dxi = (dir.rhs_xi[i] - hdz) / delta[i];
                dir.dxi[i] = dxi;
                let g = data[i].apply(&dir.dz);
                let gdx = [g[0] + dxi, g[1], g[2], g[3]];
                let mg = scal[i].apply_inv_sq(&gdx);
                let t = &dir.tc[i];
                let dy = [t[0] - mg[0], t[1] - mg[1], t[2] - mg[2], t[3] - mg[3]];
                let r = &rs[i];
                let ds = [gdx[0] - r[0], gdx[1] - r[1], gdx[2] - r[2], gdx[3] - r[3]];
                let dyn_ = dir.tn[i] - yn[i] / sn[i] * dxi;
                let dsn = dxi - rsn[i];
                alpha = cone_step(&sc[i], &ds, alpha);
                alpha = cone_step(&yc[i], &dy, alpha);
                alpha = half_line_step(sn[i], dsn, alpha);
                alpha = half_line_step(yn[i], dyn_, alpha);
                dir.dsc[i] = ds;
                dir.dyc[i] = dy;
                dir.dsn[i] = dsn;
                dir.dyn_[i] = dyn_;
            }
            dir.is_finite().then_some(alpha)
        };

        // Predictor: the affine direction (target lambda o lambda -> 0, so
        // lambda \ rc = -lambda and W (lambda \ rc) = -s).
        let wq: Vec<Cone> = sc.iter().map(|x| x.map(|v| -v)).collect();
        let wqn: Vec<Real> = sn.iter().map(|v| -v).collect();
        let alpha_aff = solve_dir(&wq, &wqn, &mut aff)?.min(1.0);
        let sigma = (1.0 - alpha_aff).powi(3);

        // Corrector: centring plus Mehrotra's second-order term.
        let mut wq = wq;
        let mut wqn = wqn;
        for i in 0..n {
            let lam = scal[i].apply(&yc[i]);
            let ds = scal[i].apply_inv(&aff.dsc[i]);
            let dy = scal[i].apply(&aff.dyc[i]);
            let corr = jprod(&ds, &dy);
            let ll = jprod(&lam, &lam);
            let rc = [
                sigma * mu - ll[0] - corr[0],
                -ll[1] - corr[1],
                -ll[2] - corr[2],
                -ll[3] - corr[3],
            ];
            wq[i] = scal[i].apply(&jdiv(&lam, &rc));
            let corr_n = aff.dsn[i] * aff.dyn_[i];
            wqn[i] = (sigma * mu - sn[i] * yn[i] - corr_n) / yn[i];
        }
        let alpha = (STEP_FRACTION * solve_dir(&wq, &wqn, &mut cor)?).min(1.0);
        let dir = &cor;
        for k in 0..m {
            z[k] += alpha * dir.dz[k];
        }
        for i in 0..n {
            xi[i] += alpha * dir.dxi[i];
            for k in 0..4 {
                sc[i][k] += alpha * dir.dsc[i][k];
                yc[i][k] += alpha * dir.dyc[i][k];
            }
            sn[i] += alpha * dir.dsn[i];
            yn[i] += alpha * dir.dyn_[i];
        }
    }
    None
}

/// Entries of a packed lower triangle of `MAX_UNKNOWNS` rows.
const PACKED: usize = MAX_UNKNOWNS * (MAX_UNKNOWNS + 1) / 2;

/// Where row `k` of a packed lower triangle starts (column `l <= k` at
/// `tri(k) + l`).
#[inline]
fn tri(k: usize) -> usize {
    k * (k + 1) / 2
}

/// `B^T B` of one point's cone over the first `m` unknowns, as a packed lower
/// triangle (row `k`, column `l <= k` at `k (k + 1) / 2 + l`).
fn packed_btb(pd: &ConeData, m: usize) -> [Real; PACKED] {
    let mut out = [0.0; PACKED];
    for k in 0..m {
        let at = tri(k);
        for l in 0..=k {
            out[at + l] =
                pd.b[0][k] * pd.b[0][l] + pd.b[1][k] * pd.b[1][l] + pd.b[2][k] * pd.b[2][l];
        }
    }
    out
}

fn finite_solution(z: &[Real], xi: &[Real], d: usize, iterations: u32) -> Option<Solution> {
    z.iter().chain(xi).all(|x| x.is_finite()).then(|| Solution {
        w: z[..d].to_vec(),
        b: z[d],
        xi: xi.iter().map(|x| x.max(0.0)).collect(),
        iterations,
    })
}

/// One Newton direction of every variable, with its scratch.
struct Direction<const M: usize> {
    dz: [Real; M],
    dxi: Vec<Real>,
    dsc: Vec<Cone>,
    dyc: Vec<Cone>,
    dsn: Vec<Real>,
    dyn_: Vec<Real>,
    tc: Vec<Cone>,
    tn: Vec<Real>,
    rhs_xi: Vec<Real>,
}

impl<const M: usize> Direction<M> {
    fn new(n: usize) -> Self {
        Self {
            dz: [0.0; M],
            dxi: vec![0.0; n],
            dsc: vec![[0.0; 4]; n],
            dyc: vec![[0.0; 4]; n],
            dsn: vec![0.0; n],
            dyn_: vec![0.0; n],
            tc: vec![[0.0; 4]; n],
            tn: vec![0.0; n],
            rhs_xi: vec![0.0; n],
        }
    }

    fn is_finite(&self) -> bool {
        self.dz.iter().chain(&self.dxi).all(|x| x.is_finite())
            && self
                .dsc
                .iter()
                .chain(&self.dyc)
                .flatten()
                .all(|x| x.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scaling_maps_s_and_y_to_the_same_point() {
        let s = [2.0, 0.3, -0.5, 0.7];
        let y = [1.5, -0.2, 0.4, 0.1];
        let w = Scaling::new(&s, &y).unwrap();
        let a = w.apply_inv(&s);
        let b = w.apply(&y);
        for k in 0..4 {
            assert!((a[k] - b[k]).abs() < 1e-12, "{a:?} vs {b:?}");
        }
        // W^-2 (W W x) = x
        let x = [0.3, 1.0, -2.0, 0.5];
        let back = w.apply_inv_sq(&w.apply(&w.apply(&x)));
        for k in 0..4 {
            assert!((back[k] - x[k]).abs() < 1e-12);
        }
        // lambda \ (lambda o x) = x
        let l = w.apply(&y);
        let q = jdiv(&l, &jprod(&l, &x));
        for k in 0..4 {
            assert!((q[k] - x[k]).abs() < 1e-12);
        }
    }

    #[test]
    fn only_the_surfaces_numbers_of_unknowns_are_solved() {
        // The linear and quadric surfaces (3 and 9 coefficients) have their
        // own solvers; any other dimension is refused (the caller falls back
        // to Clarabel), not solved with a wrong layout.
        let mut cone = ConeData {
            a: [0.0; MAX_UNKNOWNS],
            b: [[0.0; MAX_UNKNOWNS]; 3],
        };
        // `a . z` reads `w_0 + b` (linear: `b` is z_3) or `w_0 + w_3 + b`
        // (quadric: `b` is z_9).
        for k in [0, 3, 9] {
            cone.a[k] = 1.0;
        }
        let mut other = cone;
        other.a = cone.a.map(|x| -x);
        let data = [cone, other];
        for d in [3, 9] {
            assert!(solve_primal_dual(&data, d, 1.0, 1e-8).is_some(), "d = {d}");
        }
        for d in [0, 2, 5, 10] {
            assert!(solve_primal_dual(&data, d, 1.0, 1e-8).is_none(), "d = {d}");
        }
    }

    #[test]
    fn the_cone_step_stops_on_the_boundary() {
        let x = [2.0, 0.5, 0.0, 0.0];
        for dx in [
            [-1.0, 0.3, 0.2, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [1.0, -3.0, 0.0, 0.0],
        ] {
            let a = cone_step(&x, &dx, 1e9);
            let p = [
                x[0] + a * dx[0],
                x[1] + a * dx[1],
                x[2] + a * dx[2],
                x[3] + a * dx[3],
            ];
            assert!(
                jdet(&p).abs() < 1e-9 && p[0] >= -1e-12,
                "{dx:?}: {a} -> {p:?}"
            );
        }
        // Inside the cone's direction: no bound.
        assert_eq!(cone_step(&x, &[1.0, 0.1, 0.0, 0.0], 5.0), 5.0);
        // A cap short of the boundary is kept; one past it is cut to it.
        let dx = [-1.0, 0.3, 0.2, 0.0];
        let edge = cone_step(&x, &dx, 1e9);
        for cap in [0.5 * edge, edge * (1.0 - 1e-9)] {
            assert_eq!(cone_step(&x, &dx, cap), cap);
        }
        assert_eq!(cone_step(&x, &dx, 2.0 * edge), edge);
    }
}
