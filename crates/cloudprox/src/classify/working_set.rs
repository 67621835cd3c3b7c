//! Which constraints the interior-point method sees: a working set.
//!
//! Points far on their own side satisfy their constraint with zero slack and do
//! not shape the optimum. The problem is solved first on a working set (the
//! points of each cloud nearest the other cloud; along a motion, the points
//! that supported the previous state's surface, see
//! `query/collide/warm_start.rs`), every other point's
//! constraint is checked at that solution
//! (`c_i f(x_i) - 1 >= r |Sigma_i^(1/2) grad f|`), and every violated one is
//! added until none is. Solving on a subset is a relaxation of the full
//! problem, and a relaxation's optimum that is feasible for the full problem
//! (with zero slacks elsewhere) is the full problem's optimum: the answer is
//! exact. Normalization is the full set's throughout.
//!
//! The primal-dual method's iteration count hardly grows with the points, and
//! each round starts afresh, so a round adds *every* violated constraint (the
//! barrier method this replaced added at most as many as the set held, and
//! needed up to eight rounds).

use crate::bvh::{Bvh, BvhSettings, BvhWorkspace};
use crate::classify::primal_dual::{solve_primal_dual, Solution};
use crate::classify::problem::{cone_data, ConeData, Normalized, MAX_UNKNOWNS};
use crate::classify::Surface;
use crate::math::Point3;
use crate::Real;

/// Most rounds of the working set before solving with every point.
const WORKING_SET_ROUNDS: usize = 4;
/// Points of each cloud in the first working set.
const WORKING_SET_START: usize = 24;

/// A constraint whose margin at the optimum is within this of its bound
/// (`c_i f(x_i) - 1 - r |Sigma_i^(1/2) grad f| <= SUPPORT_MARGIN`, in the
/// normalized units where the bound is 1) is reported as supporting the
/// surface: the constraints a nearby problem (the next state of a motion) will
/// most likely need.
const SUPPORT_MARGIN: Real = 0.25;

/// Solves the robust SOCP of the normalized points `norm` with labels `labels`
/// (`lambda` the slack weight, `r` the robust radius) on a working set of its
/// constraints; `None` when the method does not converge.
///
/// `warm`: `None` for a query on its own; for one of a sequence of nearby
/// problems (the states of a motion), the constraints that supported the
/// previous problem's surface (empty, or one flag per point): the first
/// working set, alone when it holds more points of each cloud than the
/// surface has coefficients (as many as its unknowns), else with the nearest
/// points. Either way the working set adds
/// every violated constraint before it stops, so the optimum is the same to
/// the solver's tolerance; should a hinted round not converge, the problem is
/// solved again without the hint. With `warm` given, also returns per point
/// whether its constraint supports the surface (within [`SUPPORT_MARGIN`] of
/// its bound), for the next problem; otherwise an empty vector.
pub(crate) fn solve_reduced(
    norm: &Normalized,
    labels: &[Real],
    surface: Surface,
    lambda: Real,
    r: Real,
    tol: Real,
    warm: Option<&[bool]>,
) -> Option<(Solution, Vec<bool>)> {
    let n = norm.u.len();
    let d = surface.dim();
    let data = cone_data(norm, labels, surface, r);
    let hint = warm.unwrap_or_default();
    debug_assert!(
        hint.is_empty() || hint.len() == n,
        "one hint flag per point"
    );
    let sol = if n <= 4 * WORKING_SET_START {
        solve_primal_dual(&data, d, lambda, tol)?
    } else {
        let hinted = solve_working_set(&data, norm, labels, d, lambda, tol, hint);
        match hinted {
            None if hint.contains(&true) => {
                solve_working_set(&data, norm, labels, d, lambda, tol, &[])?
            }
            other => other?,
        }
    };
    let support = if warm.is_some() {
        let z = unknowns(&sol);
        data.iter()
            .map(|c| constraint_margin(c, &z) <= SUPPORT_MARGIN)
            .collect()
    } else {
        Vec::new()
    };
    Some((sol, support))
}

/// `(w, b)`, zeros after: the cones' coefficients there are zero too.
fn unknowns(sol: &Solution) -> [Real; MAX_UNKNOWNS] {
    let mut z = [0.0; MAX_UNKNOWNS];
    z[..sol.w.len()].copy_from_slice(&sol.w);
    z[sol.w.len()] = sol.b;
    z
}

/// A constraint's margin at `z`: `c_i f(x_i) - 1 - r |Sigma_i^(1/2) grad f|`
/// (negative where it is violated without slack).
fn constraint_margin(c: &ConeData, z: &[Real; MAX_UNKNOWNS]) -> Real {
    let g = c.apply(z);
    g[0] - 1.0 - (g[1] * g[1] + g[2] * g[2] + g[3] * g[3]).sqrt()
}

/// The working-set rounds (see the module docs), starting from the `hint`ed
/// constraints, with the nearest points unless the hint holds enough of both
/// clouds.
fn solve_working_set(
    data: &[ConeData],
    norm: &Normalized,
    labels: &[Real],
    d: usize,
    lambda: Real,
    tol: Real,
    hint: &[bool],
) -> Option<Solution> {
    let n = data.len();
    // A hint that holds, of each cloud, at least as many points as the
    // surface has unknowns is the first set on its own: it supported a
    // nearby surface, which the nearest points need not (and finding them
    // costs a search over the region). Otherwise the nearest points start,
    // with the hint's.
    let hinted = |label: Real| {
        hint.iter()
            .zip(labels)
            .filter(|&(&h, &c)| h && c == label)
            .count()
    };
    let mut in_set = if hint.len() == n && hinted(1.0) > d && hinted(-1.0) > d {
        hint.to_vec()
    } else {
        let mut nearest = initial_working_set(norm, labels);
        for (s, &h) in nearest.iter_mut().zip(hint) {
            *s |= h;
        }
        nearest
    };
    let mut iterations = 0;
    for _ in 0..WORKING_SET_ROUNDS {
        if 2 * in_set.iter().filter(|&&x| x).count() > n {
            break; // as costly as the full problem: solve that
        }
        let idx: Vec<usize> = (0..n).filter(|&i| in_set[i]).collect();
        let subset: Vec<ConeData> = idx.iter().map(|&i| data[i]).collect();
        let sol = solve_primal_dual(&subset, d, lambda, tol)?;
        iterations += sol.iterations;
        let z = unknowns(&sol);
        let mut violated = false;
        for i in 0..n {
            if in_set[i] {
                continue;
            }
            let g = data[i].apply(&z);
            let u = g[0] - 1.0;
            let viol = (g[1] * g[1] + g[2] * g[2] + g[3] * g[3]).sqrt() - u;
            if viol > 1e-9 * (1.0 + u.abs()) {
                in_set[i] = true;
                violated = true;
            }
        }
        if !violated {
            let mut xi = vec![0.0; n];
            for (k, &i) in idx.iter().enumerate() {
                xi[i] = sol.xi[k];
            }
            return Some(Solution {
                xi,
                iterations,
                ..sol
            });
        }
    }
    let sol = solve_primal_dual(data, d, lambda, tol)?;
    Some(Solution {
        iterations: sol.iterations + iterations,
        ..sol
    })
}

/// Above this many points the nearest opposite point is found with a
/// hierarchy over each cloud's points instead of by testing every opposite
/// pair.
const WORKING_SET_TREE_MIN: usize = 512;

/// The squared distance from each point to the nearest point of the other
/// label (infinite when there is none).
fn nearest_opposite(norm: &Normalized, labels: &[Real]) -> Vec<Real> {
    let n = labels.len();
    // The labels are +1 and -1 ([`super::train`] accepts no other).
    let (pos, neg): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| labels[i] == 1.0);
    let mut d2 = vec![Real::INFINITY; n];
    if n <= WORKING_SET_TREE_MIN {
        // Every pair of opposite labels once, each distance updating both ends.
        for &i in &pos {
            let mut best = Real::INFINITY;
            for &j in &neg {
                let d = (norm.u[i] - norm.u[j]).norm_squared();
                best = best.min(d);
                d2[j] = d2[j].min(d);
            }
            d2[i] = best;
        }
        return d2;
    }
    // One hierarchy per label, each queried by the other label's points.
    let mut ws = BvhWorkspace::default();
    let mut out = Vec::with_capacity(1);
    for (own, other) in [(&pos, &neg), (&neg, &pos)] {
        let points: Vec<Point3> = other.iter().map(|&j| Point3::from(norm.u[j])).collect();
        let Ok(tree) = Bvh::build(&points, &vec![0.0; points.len()], &BvhSettings::default())
        else {
            continue; // no point of the other label
        };
        for &i in own {
            tree.nearest_k(&points, &Point3::from(norm.u[i]), 1, &mut ws, &mut out);
            if let Some(&(d, _)) = out.first() {
                d2[i] = d;
            }
        }
    }
    d2
}

/// The `WORKING_SET_START` points of each cloud nearest any point of the other.
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
            .take(WORKING_SET_START)
        {
            in_set[i] = true;
        }
    }
    in_set
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classify::Surface;
    use crate::math::Matrix3;
    use crate::sample::{add_noise, sphere};

    #[test]
    fn the_nearest_opposite_point_is_the_brute_forces() {
        // Two interpenetrating noisy spheres, above the size where the
        // hierarchies take over and below it (the scan over opposite pairs);
        // and one label alone (no opposite point).
        for (na, nb) in [(700, 500), (150, 90)] {
            let a = add_noise(&sphere(&Point3::origin(), 0.1, na), 0.002, 1);
            let b = add_noise(&sphere(&Point3::new(0.15, 0.0, 0.0), 0.1, nb), 0.002, 2);
            let points: Vec<Point3> = a.iter().chain(&b).copied().collect();
            let labels: Vec<Real> = (0..points.len())
                .map(|i| if i < a.len() { 1.0 } else { -1.0 })
                .collect();
            let covs = vec![Matrix3::identity() * 4e-6; points.len()];
            let norm = Normalized::new(&points, &covs);
            assert_eq!(points.len() > WORKING_SET_TREE_MIN, na == 700);
            let fast = nearest_opposite(&norm, &labels);
            for (i, &d2) in fast.iter().enumerate() {
                let brute = (0..points.len())
                    .filter(|&j| labels[j] != labels[i])
                    .map(|j| (norm.u[i] - norm.u[j]).norm_squared())
                    .fold(Real::INFINITY, Real::min);
                assert_eq!(d2, brute, "{na} + {nb} points, point {i}");
            }
            let alone = vec![1.0; points.len()];
            assert!(nearest_opposite(&norm, &alone)
                .iter()
                .all(|d| d.is_infinite()));
        }
    }

    /// Two noisy spheres 0.1 m across, B's centre `dx` from A's, as the
    /// solver's normalized problem with labels.
    fn two_spheres(dx: Real) -> (Normalized, Vec<Real>) {
        let a = add_noise(&sphere(&Point3::origin(), 0.1, 400), 0.002, 1);
        let b = add_noise(&sphere(&Point3::new(dx, 0.0, 0.0), 0.1, 400), 0.002, 2);
        // The caps facing each other: the near region a query would classify.
        let cap_a = a.iter().filter(|p| p.x > 0.06);
        let cap_b = b.iter().filter(|p| p.x < dx - 0.06);
        let labels: Vec<Real> = cap_a
            .clone()
            .map(|_| 1.0)
            .chain(cap_b.clone().map(|_| -1.0))
            .collect();
        let points: Vec<Point3> = cap_a.chain(cap_b).copied().collect();
        let covs = vec![Matrix3::identity() * 4e-6; points.len()];
        (Normalized::new(&points, &covs), labels)
    }

    #[test]
    fn a_hint_changes_the_work_not_the_answer() {
        let solve = |dx: Real, hint: &[bool]| {
            let (norm, labels) = two_spheres(dx);
            assert!(labels.len() > 4 * WORKING_SET_START);
            solve_reduced(
                &norm,
                &labels,
                Surface::Quadric,
                100.0,
                1.0,
                1e-7,
                Some(hint),
            )
            .unwrap()
        };
        // The first state (the spheres 15 mm, 7.5 sigma, into each other):
        // cold. Every point with slack supports the surface.
        let (first, support) = solve(0.185, &[]);
        assert_eq!(support.len(), first.xi.len());
        for (i, &xi) in first.xi.iter().enumerate() {
            assert!(xi < 1e-6 || support[i], "point {i} has slack {xi}");
        }
        let supporting = support.iter().filter(|&&s| s).count();
        assert!(supporting > 0 && supporting < support.len());
        // The same problem again, hinted with its own support: the first
        // round is the optimum.
        let (again, _) = solve(0.185, &support);
        assert!(again.iterations <= first.iterations);
        // The next state of a motion (B 1.5 mm further in), cold and hinted
        // with the first state's support (the caps hold the same points).
        let (cold, _) = solve(0.1835, &[]);
        let (warm, _) = solve(0.1835, &support);
        assert!(
            warm.iterations < cold.iterations,
            "hinted {} iterations, cold {}",
            warm.iterations,
            cold.iterations
        );
        for (x, y) in warm
            .w
            .iter()
            .chain([&warm.b])
            .zip(cold.w.iter().chain([&cold.b]))
        {
            assert!((x - y).abs() <= 1e-5 * (1.0 + y.abs()), "{x} vs {y}");
        }
        for (x, y) in warm.xi.iter().zip(&cold.xi) {
            assert!((x - y).abs() <= 1e-5, "slack {x} vs {y}");
        }
    }
}
