//! The robust SOCP as Clarabel solves it, checked independently of the assembly:
//! feasibility of Eq. 2 at the returned point and optimality against perturbations.

use cloudprox::classify::{
    train, Classification, ClassifySettings, SocpSolver, SolveStatus, Surface,
};
use cloudprox::math::{Matrix3, Point3, Vector3};
use cloudprox::sample::NormalRng;
use cloudprox::uncertainty::RobustModel;

/// Two noisy, partly overlapping curved patches with random full covariances.
fn scene(n: usize, gap: f64, seed: u64, isotropic: bool) -> (Vec<Point3>, Vec<Matrix3>, Vec<f64>) {
    let mut rng = NormalRng::new(seed);
    let (mut pts, mut covs, mut labels) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        let label = if i % 2 == 0 { 1.0 } else { -1.0 };
        let (x, y) = (rng.uniform() - 0.5, rng.uniform() - 0.5);
        let z = 0.3 * (x * x + y * y) + if label > 0.0 { -gap / 2.0 } else { gap / 2.0 };
        let s = 0.01 + 0.02 * rng.uniform();
        let cov = if isotropic {
            Matrix3::identity() * s * s
        } else {
            let m = Matrix3::from_fn(|_, _| rng.normal() * s);
            m * m.transpose()
        };
        pts.push(Point3::new(x, y, z) + Vector3::new(rng.normal(), rng.normal(), rng.normal()) * s);
        covs.push(cov);
        labels.push(label);
    }
    (pts, covs, labels)
}

/// Objective of Eq. 2 with the smallest feasible slacks for (w, b), evaluated from
/// the definition (normalized coordinates, covariance pushed through the features).
fn objective(
    fit: &Classification,
    w: &[f64],
    b: f64,
    pts: &[Point3],
    covs: &[Matrix3],
    labels: &[f64],
    s: &ClassifySettings,
) -> f64 {
    let sep = &fit.separator;
    let r = s.robust_radius().unwrap();
    let d = sep.surface.dim();
    let mut phi = vec![0.0; d];
    let mut jac = vec![Vector3::zeros(); d];
    let mut total = 0.5 * w.iter().map(|v| v * v).sum::<f64>();
    for ((x, cov), &c) in pts.iter().zip(covs).zip(labels) {
        let u = (x - sep.center) / sep.scale;
        sep.surface.features(&u, &mut phi, &mut jac);
        let f = b + w.iter().zip(&phi).map(|(a, p)| a * p).sum::<f64>();
        let g: Vector3 = w.iter().zip(&jac).map(|(a, j)| j * *a).sum();
        let spread = g.dot(&(cov / (sep.scale * sep.scale) * g)).max(0.0).sqrt();
        total += s.slack_weight * (1.0 - c * f + r * spread).max(0.0);
    }
    total
}

fn check(surface: Surface, isotropic: bool, gap: f64, seed: u64) {
    for solver in [SocpSolver::PrimalDual, SocpSolver::Clarabel] {
        check_with(surface, isotropic, gap, seed, solver);
    }
}

fn check_with(surface: Surface, isotropic: bool, gap: f64, seed: u64, solver: SocpSolver) {
    let (pts, covs, labels) = scene(120, gap, seed, isotropic);
    let settings = ClassifySettings {
        solver,
        surface,
        robust_model: RobustModel::Gaussian,
        robust_eta: 0.9,
        ..ClassifySettings::default()
    };
    let fit = train(&pts, &covs, &labels, &settings).unwrap();
    assert!(
        matches!(fit.status, SolveStatus::Solved | SolveStatus::AlmostSolved),
        "{:?}",
        fit.status
    );
    let sep = &fit.separator;
    let r = settings.robust_radius().unwrap();
    // Feasibility of every constraint of Eq. 2 at the solution, in world units:
    // c f(x) >= 1 - xi + r sqrt(grad^T Sigma grad) (the scale cancels), xi >= 0.
    for (i, ((x, cov), &c)) in pts.iter().zip(&covs).zip(&labels).enumerate() {
        let (f, g) = sep.value_and_gradient(x);
        let xi = fit.slacks[i];
        assert!(xi >= -1e-6, "slack {i} negative: {xi}");
        let rhs = 1.0 - xi + r * g.dot(&(cov * g)).max(0.0).sqrt();
        assert!(
            c * f >= rhs - 1e-5 * (1.0 + rhs.abs()),
            "constraint {i}: {} < {rhs}",
            c * f
        );
    }
    // Optimality: no perturbation of (w, b) lowers the objective (convexity makes a
    // local check a global one).
    let base = objective(&fit, &sep.w, sep.b, &pts, &covs, &labels, &settings);
    let mut rng = NormalRng::new(seed + 1000);
    for _ in 0..200 {
        let step = 1e-3 * (1.0 + sep.w.iter().map(|v| v.abs()).fold(0.0, f64::max));
        let w2: Vec<f64> = sep.w.iter().map(|v| v + step * rng.normal()).collect();
        let b2 = sep.b + step * rng.normal();
        let other = objective(&fit, &w2, b2, &pts, &covs, &labels, &settings);
        assert!(
            other >= base * (1.0 - 1e-6) - 1e-6,
            "perturbation improved {base} to {other}"
        );
    }
}

#[test]
fn linear_isotropic_shared_cone_is_feasible_and_optimal() {
    check(Surface::Linear, true, 0.1, 1);
    check(Surface::Linear, true, -0.05, 2);
}

#[test]
fn linear_full_covariance_cones_are_feasible_and_optimal() {
    check(Surface::Linear, false, 0.1, 3);
    check(Surface::Linear, false, -0.05, 4);
}

#[test]
fn quadric_cones_are_feasible_and_optimal() {
    check(Surface::Quadric, false, 0.1, 5);
    check(Surface::Quadric, true, 0.02, 6);
    check(Surface::Quadric, false, -0.05, 7);
}

#[test]
fn a_separable_set_is_separated_with_zero_slack() {
    // Far apart: every constraint holds with xi = 0 and every point is on its side.
    let (pts, covs, labels) = scene(60, 1.0, 9, true);
    for surface in [Surface::Linear, Surface::Quadric] {
        let s = ClassifySettings {
            surface,
            ..ClassifySettings::default()
        };
        let fit = train(&pts, &covs, &labels, &s).unwrap();
        assert!(fit.slacks.iter().all(|&x| x < 1e-6), "{surface:?}");
        for (x, &c) in pts.iter().zip(&labels) {
            assert!(c * fit.separator.value_and_gradient(x).0 > 0.0);
        }
    }
}

#[test]
fn train_rejects_bad_labels_and_lengths() {
    let (pts, covs, mut labels) = scene(10, 0.1, 1, true);
    let s = ClassifySettings::default();
    assert!(train(&pts, &covs[..9], &labels, &s).is_err());
    let one_class = vec![1.0; 10];
    assert!(train(&pts, &covs, &one_class, &s)
        .unwrap_err()
        .to_string()
        .contains("both clouds"));
    labels[3] = 0.5;
    assert!(train(&pts, &covs, &labels, &s)
        .unwrap_err()
        .to_string()
        .contains("label 3"));
}

/// [`objective`] at the fit's own `(w, b)`.
fn objective_at_fit(
    fit: &Classification,
    pts: &[Point3],
    covs: &[Matrix3],
    labels: &[f64],
    s: &ClassifySettings,
) -> f64 {
    objective(fit, &fit.separator.w, fit.separator.b, pts, covs, labels, s)
}

#[test]
fn the_specialized_method_agrees_with_clarabel() {
    for (k, surface) in [Surface::Linear, Surface::Quadric].into_iter().enumerate() {
        for (j, &gap) in [0.2, 0.05, 0.0, -0.05, -0.2].iter().enumerate() {
            for isotropic in [true, false] {
                let seed = 100 + 10 * k as u64 + j as u64;
                let (pts, covs, labels) = scene(150, gap, seed, isotropic);
                let s = |solver| ClassifySettings {
                    surface,
                    solver,
                    ..ClassifySettings::default()
                };
                let fb = train(&pts, &covs, &labels, &s(SocpSolver::PrimalDual)).unwrap();
                let fc = train(&pts, &covs, &labels, &s(SocpSolver::Clarabel)).unwrap();
                assert_eq!(
                    fb.solver,
                    SocpSolver::PrimalDual,
                    "{surface:?} gap {gap} iso {isotropic}"
                );
                let ob = objective_at_fit(&fb, &pts, &covs, &labels, &s(SocpSolver::PrimalDual));
                let oc = objective_at_fit(&fc, &pts, &covs, &labels, &s(SocpSolver::Clarabel));
                assert!(
                    (ob - oc).abs() <= 1e-5 * oc.abs().max(1.0),
                    "{surface:?} gap {gap}: specialized {ob} vs clarabel {oc}"
                );
                // w is unique (the objective is strictly convex in w); b need not be
                // (the hinge terms can be flat in b), so only w is compared.
                let dw: f64 = fb
                    .separator
                    .w
                    .iter()
                    .zip(&fc.separator.w)
                    .map(|(x, y)| (x - y).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let nw: f64 = fc.separator.w.iter().map(|x| x * x).sum::<f64>().sqrt();
                assert!(
                    dw <= 1e-3 * nw.max(1.0),
                    "{surface:?} gap {gap}: |dw| = {dw}, |w| = {nw}"
                );
            }
        }
    }
}

#[test]
fn the_specialized_method_solves_large_patches_in_few_iterations() {
    // Interleaved patches: nearly every constraint is active, so the working
    // set gives way to the full problem at once. The optimum must match
    // Clarabel's at 2000 points with anisotropic covariances, and the
    // primal-dual method's iteration count must stay that of a small problem
    // (the barrier method it replaced needed several hundred steps here).
    for (seed, gap) in [(7u64, 0.05), (8, -0.05)] {
        let (pts, covs, labels) = scene(2000, gap, seed, false);
        let s = |solver| ClassifySettings {
            surface: Surface::Quadric,
            solver,
            ..ClassifySettings::default()
        };
        let fb = train(&pts, &covs, &labels, &s(SocpSolver::PrimalDual)).unwrap();
        let fc = train(&pts, &covs, &labels, &s(SocpSolver::Clarabel)).unwrap();
        assert_eq!(fb.solver, SocpSolver::PrimalDual, "gap {gap}: fell back");
        assert!(
            fb.iterations <= 40,
            "gap {gap}: {} iterations",
            fb.iterations
        );
        let ob = objective_at_fit(&fb, &pts, &covs, &labels, &s(SocpSolver::PrimalDual));
        let oc = objective_at_fit(&fc, &pts, &covs, &labels, &s(SocpSolver::Clarabel));
        assert!(
            (ob - oc).abs() <= 1e-5 * oc.abs().max(1.0),
            "gap {gap}: specialized {ob} vs clarabel {oc}"
        );
        assert!(fb.slacks.iter().all(|&x| x >= 0.0) && fb.slacks.len() == pts.len());
    }
}
