//! A specialized interior-point solver for the robust SOCP: a log-barrier method
//! whose Newton systems are reduced to the surface's own `dim + 1` unknowns.
//!
//! The problem (see the [module docs](crate::classify)) has `dim + 1 + n`
//! unknowns `(w, b, xi)` but its structure is an arrow: each slack `xi_i` appears
//! only in point `i`'s cone and in `xi_i >= 0`. The barrier
//!
//! ```text
//! F_t(z, xi) = t (1/2 |w|^2 + lambda sum xi_i) - sum_i log(u_i^2 - |v_i|^2) - sum_i log xi_i,
//! u_i = c_i (w . phi_i + b) + xi_i - 1,   v_i = r L_i^T J_i^T w,   z = (w, b)
//! ```
//!
//! (Boyd & Vandenberghe, *Convex Optimization*, ch. 11; `-log(u^2 - |v|^2)` is the
//! second-order cone's logarithmic barrier, of parameter 2) has a Hessian whose
//! `xi`-block is diagonal, so each Newton step eliminates the slacks (a Schur
//! complement) and solves one `(dim + 1)`-square system: `O(n dim^2)` per step
//! instead of a sparse factorization of the whole KKT system. The duality gap of
//! the central point is at most `theta / t` with `theta = 3 n`; `t` grows by
//! `MU` per outer step until that bound is below the tolerance.
//!
//! Clarabel stays the exact reference: tests compare the two, and [`super::train`]
//! falls back to Clarabel when this method does not converge.

use nalgebra::{DMatrix, DVector};

use crate::bvh::{Bvh, BvhSettings, BvhWorkspace};
use crate::classify::problem::Normalized;
use crate::classify::Surface;
use crate::math::{Point3, Vector3};
use crate::Real;

const MU: Real = 20.0;
const MAX_NEWTON: u32 = 400;
const ALPHA: Real = 0.01;
const BETA: Real = 0.5;

/// The solution of the barrier method.
pub(crate) struct BarrierSolution {
    pub w: Vec<Real>,
    pub b: Real,
    pub xi: Vec<Real>,
    pub newton_steps: u32,
}

/// Per-point constant data: `a_i = c_i (phi_i, 1)`, `B_i` (3 rows of `dim + 1`,
/// last column zero) and `C_i = B_i^T B_i`.
struct PointData {
    a: Vec<Real>,
    bm: Vec<Real>,
    c: Vec<Real>,
}

/// Largest working set tried before solving with every point.
const WORKING_SET_ROUNDS: usize = 8;
/// Points of each cloud in the first working set, and fewest added per round
/// (a round adds as many as the set holds, so it grows geometrically).
const WORKING_SET_STEP: usize = 24;

/// Solves the robust SOCP for all points with a working set of constraints.
///
/// Points far on their own side satisfy their constraint with zero slack and do
/// not shape the optimum. The problem is solved on a working set (first the
/// points of each cloud nearest the other cloud), every other point's constraint
/// is checked at that solution (`c_i f(x_i) - 1 >= r |Sigma_i^(1/2) grad f|`), and
/// the most violated are added until none is. Solving on a subset is a relaxation
/// of the full problem, and a relaxation's optimum that is feasible for the full
/// problem (with zero slacks elsewhere) is the full problem's optimum: the answer
/// is exact. Normalization is the full set's throughout.
pub(crate) fn solve_barrier(
    norm: &Normalized,
    labels: &[Real],
    surface: Surface,
    lambda: Real,
    r: Real,
    tol: Real,
) -> Option<BarrierSolution> {
    let n = norm.u.len();
    let d = surface.dim();
    let m = d + 1;
    let data = point_data(norm, labels, surface, r);
    if n <= 3 * WORKING_SET_STEP {
        let all: Vec<&PointData> = data.iter().collect();
        return solve_subset(&all, d, lambda, tol);
    }
    let mut in_set = initial_working_set(norm, labels);
    let mut total_steps = 0;
    for _ in 0..WORKING_SET_ROUNDS {
        let idx: Vec<usize> = (0..n).filter(|&i| in_set[i]).collect();
        let subset: Vec<&PointData> = idx.iter().map(|&i| &data[i]).collect();
        let sol = solve_subset(&subset, d, lambda, tol)?;
        total_steps += sol.newton_steps;
        let mut z = sol.w.clone();
        z.push(sol.b);
        let mut violated: Vec<(Real, usize)> = (0..n)
            .filter(|&i| !in_set[i])
            .filter_map(|i| {
                let pd = &data[i];
                let u: Real = (0..m).map(|k| pd.a[k] * z[k]).sum::<Real>() - 1.0;
                let mut v2 = 0.0;
                for row in 0..3 {
                    let x: Real = (0..m).map(|k| pd.bm[row * m + k] * z[k]).sum();
                    v2 += x * x;
                }
                let viol = v2.sqrt() - u;
                (viol > 1e-9 * (1.0 + u.abs())).then_some((viol, i))
            })
            .collect();
        if violated.is_empty() {
            let mut xi = vec![0.0; n];
            for (k, &i) in idx.iter().enumerate() {
                xi[i] = sol.xi[k];
            }
            return Some(BarrierSolution {
                xi,
                newton_steps: total_steps,
                ..sol
            });
        }
        violated.sort_by(|a, b| b.0.total_cmp(&a.0));
        // Grow geometrically: at least as many as are in the set already.
        let grow = WORKING_SET_STEP.max(idx.len());
        for &(_, i) in violated.iter().take(grow) {
            in_set[i] = true;
        }
    }
    let all: Vec<&PointData> = data.iter().collect();
    let sol = solve_subset(&all, d, lambda, tol)?;
    Some(BarrierSolution {
        newton_steps: sol.newton_steps + total_steps,
        ..sol
    })
}

/// Above this many points the nearest opposite point is found with a
/// hierarchy over each cloud's points instead of by testing every pair.
const WORKING_SET_TREE_MIN: usize = 512;

/// The squared distance from each point to the nearest point of the other
/// label (infinite when there is none).
fn nearest_opposite(norm: &Normalized, labels: &[Real]) -> Vec<Real> {
    let n = labels.len();
    if n <= WORKING_SET_TREE_MIN {
        return (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| labels[j] != labels[i])
                    .map(|j| (norm.u[i] - norm.u[j]).norm_squared())
                    .fold(Real::INFINITY, Real::min)
            })
            .collect();
    }
    // One hierarchy per label, each queried by the other label's points.
    let mut d2 = vec![Real::INFINITY; n];
    let mut ws = BvhWorkspace::default();
    let mut out = Vec::with_capacity(1);
    for label in [1.0, -1.0] {
        let (own, other): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| labels[i] == label);
        let points: Vec<Point3> = other.iter().map(|&j| Point3::from(norm.u[j])).collect();
        let Ok(tree) = Bvh::build(&points, &vec![0.0; points.len()], &BvhSettings::default())
        else {
            continue; // no point of the other label
        };
        for i in own {
            tree.nearest_k(&points, &Point3::from(norm.u[i]), 1, &mut ws, &mut out);
            if let Some(&(d, _)) = out.first() {
                d2[i] = d;
            }
        }
    }
    d2
}

/// The `WORKING_SET_STEP` points of each cloud nearest any point of the other.
fn initial_working_set(norm: &Normalized, labels: &[Real]) -> Vec<bool> {
    let n = labels.len();
    let mut nearest: Vec<(Real, usize)> = nearest_opposite(norm, labels)
        .into_iter()
        .enumerate()
        .map(|(i, d2)| (d2, i))
        .collect();
    nearest.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut in_set = vec![false; n];
    for label in [1.0, -1.0] {
        for &(_, i) in nearest
            .iter()
            .filter(|(_, i)| labels[*i] == label)
            .take(WORKING_SET_STEP)
        {
            in_set[i] = true;
        }
    }
    in_set
}

/// The barrier method on the points `data`.
fn solve_subset(data: &[&PointData], d: usize, lambda: Real, tol: Real) -> Option<BarrierSolution> {
    let n = data.len();
    let m = d + 1;

    let mut z = vec![0.0; m];
    let mut xi = vec![2.0; n];
    let theta = 3.0 * n as Real;
    let f0 = |z: &[Real], xi: &[Real]| -> Real {
        0.5 * z[..d].iter().map(|x| x * x).sum::<Real>() + lambda * xi.iter().sum::<Real>()
    };
    let mut t = (theta / f0(&z, &xi).max(1e-12)).max(1e-6);
    let mut steps = 0u32;

    // Scratch.
    let mut u = vec![0.0; n];
    let mut v = vec![[0.0; 3]; n];
    let mut g = vec![0.0; n];
    let mut s = DMatrix::<Real>::zeros(m, m);
    let mut rhs = DVector::<Real>::zeros(m);
    let mut h = vec![0.0; n * m];
    let mut dd = vec![0.0; n];
    let mut grad_xi = vec![0.0; n];
    let mut dz = vec![0.0; m];
    let mut neg_grad_z = vec![0.0; m];
    let mut dxi = vec![0.0; n];

    loop {
        // Centering: Newton's method on F_t.
        loop {
            if steps >= MAX_NEWTON {
                return None;
            }
            steps += 1;
            eval_cones(data, &z, &xi, &mut u, &mut v, &mut g, m);
            // Accumulate the Schur complement S (lower triangle, row-major in a
            // fixed array) and the reduced right-hand side.
            let mut sacc = [0.0; 100];
            let mut racc = [0.0; 10];
            for k in 0..d {
                sacc[k * m + k] = t;
                racc[k] = -t * z[k];
                neg_grad_z[k] = -t * z[k];
            }
            neg_grad_z[d] = 0.0;
            for i in 0..n {
                let (ui, vi, gi) = (u[i], v[i], g[i]);
                let pd = data[i];
                let a = &pd.a[..m];
                // q = u a - B^T v
                let mut q = [0.0; 10];
                for k in 0..m {
                    q[k] = ui * a[k]
                        - vi[0] * pd.bm[k]
                        - vi[1] * pd.bm[m + k]
                        - vi[2] * pd.bm[2 * m + k];
                }
                let c1 = 2.0 / gi;
                let c2 = 4.0 / (gi * gi);
                let k00 = -c1 + c2 * ui * ui;
                let di = k00 + 1.0 / (xi[i] * xi[i]);
                let inv_d = 1.0 / di;
                dd[i] = di;
                let gx = t * lambda - c1 * ui - 1.0 / xi[i];
                grad_xi[i] = gx;
                // h = -c1 a + c2 u q;  S_i = c1 (C - a a^T) + c2 q q^T - h h^T / D
                //   = c1 C + alpha a a^T + beta q q^T + gamma (a q^T + q a^T)
                let alpha = -c1 - c1 * c1 * inv_d;
                let beta = c2 - c2 * c2 * ui * ui * inv_d;
                let gamma = c1 * c2 * ui * inv_d;
                let hi = &mut h[i * m..(i + 1) * m];
                for k in 0..m {
                    let hk = -c1 * a[k] + c2 * ui * q[k];
                    hi[k] = hk;
                    neg_grad_z[k] += c1 * q[k];
                    racc[k] += c1 * q[k] + hk * gx * inv_d;
                    let (ak, qk) = (a[k], q[k]);
                    let ca = alpha * ak + gamma * qk;
                    let cq = beta * qk + gamma * ak;
                    let row = &mut sacc[k * m..=k * m + k];
                    let crow = &pd.c[k * m..=k * m + k];
                    for l in 0..=k {
                        row[l] += c1 * crow[l] + ca * a[l] + cq * q[l];
                    }
                }
            }
            for k in 0..m {
                rhs[k] = racc[k];
                for l in 0..=k {
                    s[(k, l)] = sacc[k * m + l];
                    s[(l, k)] = sacc[k * m + l];
                }
            }
            let sol = s
                .clone()
                .cholesky()
                .map(|c| c.solve(&rhs))
                .or_else(|| s.clone().lu().solve(&rhs))?;
            dz.copy_from_slice(sol.as_slice());
            let mut decrement = 0.0;
            for i in 0..n {
                let hi = &h[i * m..(i + 1) * m];
                let hdz: Real = hi.iter().zip(&dz).map(|(a, b)| a * b).sum();
                dxi[i] = (-grad_xi[i] - hdz) / dd[i];
                decrement -= grad_xi[i] * dxi[i];
            }
            decrement += neg_grad_z.iter().zip(&dz).map(|(a, b)| a * b).sum::<Real>();
            if !decrement.is_finite() {
                return None;
            }
            // Centred enough: the decrement estimates F_t - min F_t, judged against
            // the size of F_t's terms so that rounding cannot keep it from stopping.
            if decrement * 0.5 <= 1e-9 * (1.0 + t * f0(&z, &xi)) {
                break;
            }
            // Backtracking line search: stay strictly feasible, then Armijo.
            let phi0 = barrier_value(data, &z, &xi, t, lambda, d, m)?;
            let mut step = 1.0;
            let mut z_new = vec![0.0; m];
            let mut xi_new = vec![0.0; n];
            loop {
                for k in 0..m {
                    z_new[k] = z[k] + step * dz[k];
                }
                for i in 0..n {
                    xi_new[i] = xi[i] + step * dxi[i];
                }
                if let Some(phi) = barrier_value(data, &z_new, &xi_new, t, lambda, d, m) {
                    if phi <= phi0 - ALPHA * step * decrement {
                        break;
                    }
                }
                step *= BETA;
                if step < 1e-14 {
                    // No progress possible at this t: treat as centred.
                    break;
                }
            }
            if step < 1e-14 {
                break;
            }
            z.copy_from_slice(&z_new);
            xi.copy_from_slice(&xi_new);
        }
        let obj = f0(&z, &xi);
        if theta / t <= tol * obj.abs().max(1.0) {
            break;
        }
        t *= MU;
    }
    if z.iter().chain(&xi).all(|x| x.is_finite()) {
        Some(BarrierSolution {
            w: z[..d].to_vec(),
            b: z[d],
            xi,
            newton_steps: steps,
        })
    } else {
        None
    }
}

fn point_data(norm: &Normalized, labels: &[Real], surface: Surface, r: Real) -> Vec<PointData> {
    let d = surface.dim();
    let m = d + 1;
    let mut phi = [0.0; 9];
    let mut jac = [Vector3::zeros(); 9];
    norm.u
        .iter()
        .zip(labels)
        .zip(&norm.factors)
        .map(|((u, &c), l)| {
            surface.features(u, &mut phi[..d], &mut jac[..d]);
            let mut a = vec![0.0; m];
            for k in 0..d {
                a[k] = c * phi[k];
            }
            a[d] = c;
            let lt = l.transpose();
            let mut bm = vec![0.0; 3 * m];
            for row in 0..3 {
                for k in 0..d {
                    bm[row * m + k] = r * lt.row(row).dot(&jac[k].transpose());
                }
            }
            let mut cm = vec![0.0; m * m];
            for k in 0..m {
                for l in 0..m {
                    cm[k * m + l] = (0..3).map(|row| bm[row * m + k] * bm[row * m + l]).sum();
                }
            }
            PointData { a, bm, c: cm }
        })
        .collect()
}

fn eval_cones(
    data: &[&PointData],
    z: &[Real],
    xi: &[Real],
    u: &mut [Real],
    v: &mut [[Real; 3]],
    g: &mut [Real],
    m: usize,
) {
    for (i, pd) in data.iter().enumerate() {
        let mut ui = xi[i] - 1.0;
        for k in 0..m {
            ui += pd.a[k] * z[k];
        }
        let mut vi = [0.0; 3];
        for (row, x) in vi.iter_mut().enumerate() {
            *x = (0..m).map(|k| pd.bm[row * m + k] * z[k]).sum();
        }
        u[i] = ui;
        v[i] = vi;
        g[i] = ui * ui - (vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2]);
    }
}

/// `F_t` at `(z, xi)`, or `None` outside the barrier's domain.
fn barrier_value(
    data: &[&PointData],
    z: &[Real],
    xi: &[Real],
    t: Real,
    lambda: Real,
    d: usize,
    m: usize,
) -> Option<Real> {
    let mut val =
        t * (0.5 * z[..d].iter().map(|x| x * x).sum::<Real>() + lambda * xi.iter().sum::<Real>());
    // sum of logs as the log of running products, flushed before they leave a safe
    // range: one logarithm per several points instead of two per point.
    let mut prod = 1.0;
    for (i, pd) in data.iter().enumerate() {
        if xi[i] <= 0.0 {
            return None;
        }
        let mut ui = xi[i] - 1.0;
        for k in 0..m {
            ui += pd.a[k] * z[k];
        }
        if ui <= 0.0 {
            return None;
        }
        let mut v2 = 0.0;
        for row in 0..3 {
            let x: Real = (0..m).map(|k| pd.bm[row * m + k] * z[k]).sum();
            v2 += x * x;
        }
        let gi = ui * ui - v2;
        if gi <= 0.0 {
            return None;
        }
        prod *= gi * xi[i];
        if !(1e-100..=1e100).contains(&prod) {
            val -= prod.ln();
            prod = 1.0;
        }
    }
    val -= prod.ln();
    val.is_finite().then_some(val)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Matrix3;
    use crate::sample::{add_noise, sphere};

    #[test]
    fn the_nearest_opposite_point_from_the_hierarchies_is_the_brute_forces() {
        // Two interpenetrating noisy spheres, above the size where the
        // hierarchies take over; and one label alone (no opposite point).
        let a = add_noise(&sphere(&Point3::origin(), 0.1, 700), 0.002, 1);
        let b = add_noise(&sphere(&Point3::new(0.15, 0.0, 0.0), 0.1, 500), 0.002, 2);
        let points: Vec<Point3> = a.iter().chain(&b).copied().collect();
        let labels: Vec<Real> = (0..points.len())
            .map(|i| if i < a.len() { 1.0 } else { -1.0 })
            .collect();
        let covs = vec![Matrix3::identity() * 4e-6; points.len()];
        let norm = Normalized::new(&points, &covs);
        assert!(points.len() > WORKING_SET_TREE_MIN);
        let fast = nearest_opposite(&norm, &labels);
        for (i, &d2) in fast.iter().enumerate() {
            let brute = (0..points.len())
                .filter(|&j| labels[j] != labels[i])
                .map(|j| (norm.u[i] - norm.u[j]).norm_squared())
                .fold(Real::INFINITY, Real::min);
            assert_eq!(d2, brute, "point {i}");
        }
        let alone = vec![1.0; points.len()];
        assert!(nearest_opposite(&norm, &alone)
            .iter()
            .all(|d| d.is_infinite()));
    }
}
