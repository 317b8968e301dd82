//! The BM1/BM2 log densities: exact gradients, the metric, the MAP and its Laplace evidence.

use motorcal::bayes::{CalibrationPosterior, ModelSettings, Observations};
use motorcal::density::{FisherMetric, LogDensity};
use motorcal::forward::ForwardModel;
use motorcal::motor::{MotorModel, MotorParameters, VoltageInput};
use motorcal::ode::SolverSettings;
use motorcal::optimize::{MapSettings, find_map};
use motorcal::synthetic::{PaperSetup, paper_measurements};
use nalgebra::DMatrix;

/// The paper's case: data from φ = 1, fitted with the simulation model φ = 0.9 (c_g = 0.009).
fn paper_posterior(settings: &ModelSettings, seed: u64) -> CalibrationPosterior {
    let data = paper_measurements(&PaperSetup::default(), seed).unwrap();
    let model = MotorModel::new(
        MotorParameters::paper_simulation_model(),
        VoltageInput::Constant,
    );
    let forward =
        ForwardModel::new(model, data.times.clone(), &["R"], SolverSettings::default()).unwrap();
    let obs = Observations {
        label: "paper".into(),
        channels: data.measured.clone(),
    };
    CalibrationPosterior::new(vec![(forward, obs)], settings).unwrap()
}

fn relative_gap(a: f64, b: f64) -> f64 {
    (a - b).abs() / (a.abs().max(b.abs()).max(1e-12))
}

#[test]
fn the_full_gradient_matches_central_finite_differences_at_k_0_9_20_and_in_bm1() {
    for settings in [
        ModelSettings::bm1(),
        ModelSettings::bm2(0),
        ModelSettings::bm2(9),
        ModelSettings::bm2(20),
    ] {
        let mut post = paper_posterior(&settings, 7);
        let mut x = post.initial_point().unwrap();
        // Move off the least-squares start so that every gradient component is sizeable, and
        // off the Laplace kinks.
        x[0] *= 0.97;
        for (i, v) in x.iter_mut().enumerate().skip(1) {
            *v += 0.05 * ((i as f64) * 1.3).sin();
        }
        let d = post.dim();
        let mut grad = vec![0.0; d];
        let lp = post.log_density_and_gradient(&x, &mut grad).unwrap();
        assert!(lp.is_finite());
        // A fresh posterior solves the ODE over f64 alone, with no cache to share: the dual
        // solve's real parts and the likelihood built on them must agree with it.
        let fresh = paper_posterior(&settings, 7).log_density(&x).unwrap();
        assert!(
            relative_gap(lp, fresh) < 1e-12,
            "value with gradient {lp} vs a fresh evaluation {fresh}"
        );
        for i in 0..d {
            let h = 1e-5 * x[i].abs().max(0.1);
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[i] += h;
            xm[i] -= h;
            let fd = (post.log_density(&xp).unwrap() - post.log_density(&xm).unwrap()) / (2.0 * h);
            let tol = if i == 0 { 1e-5 } else { 2e-6 };
            assert!(
                relative_gap(fd, grad[i]) < tol || (fd - grad[i]).abs() < 1e-6,
                "{}: coordinate {i} ({}): analytic {} vs finite difference {fd}",
                settings.label(),
                post.parameter_names()[i],
                grad[i]
            );
        }
    }
}

#[test]
fn resistance_at_or_below_zero_has_zero_density() {
    let mut post = paper_posterior(&ModelSettings::bm2(3), 1);
    let mut x = post.initial_point().unwrap();
    x[0] = 0.0;
    assert_eq!(post.log_density(&x).unwrap(), f64::NEG_INFINITY);
    x[0] = -0.05;
    let mut g = vec![0.0; x.len()];
    assert_eq!(
        post.log_density_and_gradient(&x, &mut g).unwrap(),
        f64::NEG_INFINITY
    );
}

#[test]
fn the_observed_information_is_close_to_the_hessian_at_the_mode() {
    let mut post = paper_posterior(&ModelSettings::bm2(3), 3);
    let start = post.initial_point().unwrap();
    let map = find_map(&mut post, &start, &MapSettings::default()).unwrap();
    let d = post.dim();
    let mut metric = DMatrix::zeros(d, d);
    post.observed_information(&map.x, &mut metric).unwrap();
    // Finite-difference Hessian of −log π from the exact gradient.
    let mut hessian = DMatrix::zeros(d, d);
    for i in 0..d {
        let h = 1e-5 * map.x[i].abs().max(1e-2);
        let (mut gp, mut gm) = (vec![0.0; d], vec![0.0; d]);
        let mut xp = map.x.clone();
        let mut xm = map.x.clone();
        xp[i] += h;
        xm[i] -= h;
        post.log_density_and_gradient(&xp, &mut gp).unwrap();
        post.log_density_and_gradient(&xm, &mut gm).unwrap();
        for j in 0..d {
            hessian[(j, i)] = -(gp[j] - gm[j]) / (2.0 * h);
        }
    }
    let hessian = (&hessian + hessian.transpose()) * 0.5;
    // Compare in the metric's own scale: M^{-1/2} H M^{-1/2} should be near the identity.
    let chol = metric.clone().cholesky().unwrap();
    let l_inv = chol.l().try_inverse().unwrap();
    let whitened = &l_inv * &hessian * l_inv.transpose();
    let gap = (&whitened - DMatrix::identity(d, d)).norm() / (d as f64).sqrt();
    assert!(
        gap < 0.05,
        "observed information differs from the Hessian by {gap} (whitened, RMS)"
    );
}

#[test]
fn map_of_bm1_is_biased_and_bm2_removes_most_of_the_bias() {
    // The paper's central claim at the mode: with φ = 0.9, BM1's R is ~10% low and σ_I is
    // inflated; BM2(K = 9) brings R back near R₀ = 0.1 and σ_I near the noise level.
    let mut bm1 = paper_posterior(&ModelSettings::bm1(), 11);
    let start = bm1.initial_point().unwrap();
    let map1 = find_map(&mut bm1, &start, &MapSettings::default()).unwrap();
    let mut bm2 = paper_posterior(&ModelSettings::bm2(9), 11);
    let start = bm2.initial_point().unwrap();
    let map2 = find_map(&mut bm2, &start, &MapSettings::default()).unwrap();
    eprintln!(
        "BM1 MAP R = {}, σ_I = {}; BM2 MAP R = {}, σ_I = {}",
        map1.x[0],
        map1.x[1].exp(),
        map2.x[0],
        map2.x[1].exp()
    );
    assert!(
        map1.newton_decrement < 1e-6 && map2.newton_decrement < 1e-6,
        "{} {}",
        map1.newton_decrement,
        map2.newton_decrement
    );
    assert!((map1.x[0] - 0.0903).abs() < 0.002, "BM1 R = {}", map1.x[0]);
    assert!(map1.x[1].exp() > 5.0, "BM1 σ_I = {}", map1.x[1].exp());
    assert!((map2.x[0] - 0.1).abs() < 0.004, "BM2 R = {}", map2.x[0]);
    assert!(
        (map2.x[1].exp() - 2.0).abs() < 0.3,
        "BM2 σ_I = {}",
        map2.x[1].exp()
    );
}

#[test]
fn laplace_evidence_of_bm1_agrees_with_importance_sampling() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut post = paper_posterior(&ModelSettings::bm1(), 5);
    let start = post.initial_point().unwrap();
    let map = find_map(&mut post, &start, &MapSettings::default()).unwrap();
    // Importance sampling from the Laplace approximation itself: its log-mean weight is the
    // exact log evidence up to Monte Carlo error, and the Laplace value must sit close to it.
    let d = post.dim();
    let chol = map.hessian.clone().cholesky().unwrap();
    let l_inv_t = chol.l().transpose().try_inverse().unwrap();
    let log_det_cov = -2.0 * chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let n = 4000;
    let mut log_w = Vec::with_capacity(n);
    for _ in 0..n {
        let z: Vec<f64> = (0..d).map(|_| StandardNormal.sample(&mut rng)).collect();
        let dx = &l_inv_t * nalgebra::DVector::from_vec(z.clone());
        let x: Vec<f64> = map.x.iter().zip(dx.iter()).map(|(a, b)| a + b).collect();
        let log_q = -0.5 * z.iter().map(|v| v * v).sum::<f64>()
            - 0.5 * d as f64 * (2.0 * std::f64::consts::PI).ln()
            - 0.5 * log_det_cov;
        log_w.push(post.log_density(&x).unwrap() - log_q);
    }
    let max = log_w.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let log_z = max + (log_w.iter().map(|w| (w - max).exp()).sum::<f64>() / n as f64).ln();
    eprintln!(
        "log evidence: Laplace {} vs importance sampling {log_z}",
        map.log_evidence_laplace
    );
    assert!((log_z - map.log_evidence_laplace).abs() < 0.1);
}

#[test]
fn solves_are_counted_where_the_cache_misses_a_gradient_with_its_directions() {
    use motorcal::density::{Counted, SolveCount};
    let mut searched = paper_posterior(&ModelSettings::bm2(3), 1);
    let mut x = searched.initial_point().unwrap();
    // A clone is a new evaluator: it counts from zero.
    let mut post = searched.clone();
    assert_eq!(post.solves(), SolveCount::default());
    // The solves by kind; the integrator's work is checked beside them.
    let kinds = |c: SolveCount| (c.plain, c.dual, c.directions);
    // The clone keeps the cache, not the count: a new R (index 0) makes the first solve.
    x[0] *= 1.001;
    post.log_density(&x).unwrap();
    assert_eq!(kinds(post.solves()), (1, 0, 0));
    let one_plain = post.solves().rhs_evaluations;
    assert!(one_plain > 0);
    // Only a coefficient moves: the cached solve serves it, at no work.
    let last = x.len() - 1;
    x[last] += 0.1;
    post.log_density(&x).unwrap();
    assert_eq!(kinds(post.solves()), (1, 0, 0));
    assert_eq!(post.solves().rhs_evaluations, one_plain);
    let mut grad = vec![0.0; x.len()];
    post.log_density_and_gradient(&x, &mut grad).unwrap();
    assert_eq!(kinds(post.solves()), (1, 1, 1));
    // One calibrated parameter, one dual pass: it takes the plain solve's steps (the step
    // control sees real parts only), so the same right-hand sides.
    assert_eq!(post.solves().rhs_evaluations, 2 * one_plain);
    x[0] *= 1.001;
    post.log_density(&x).unwrap();
    assert_eq!(kinds(post.solves()), (2, 1, 1));
    // A chain's work (what a run's work budget counts): its gradients and the integrator's
    // right-hand sides.
    let mut counted = Counted::new(searched.clone());
    x[0] *= 1.001;
    counted.log_density_and_gradient(&x, &mut grad).unwrap();
    assert_eq!(counted.work(), 1 + counted.solves().rhs_evaluations);
    assert!(counted.work() > 1);
}

/// A diagnosis's sampled fits start from the ranking's MAP search (`MapSearch::Ranking`), which
/// stops L-BFGS at a whitened gradient of 10⁻² and polishes with Newton steps to the log
/// density's rounding: it lands on the precise search's mode, within a thousandth of a
/// posterior sd in every direction, and its log density to 10⁻⁹ of itself.
#[test]
fn the_ranking_s_map_search_lands_on_the_precise_search_s_mode() {
    for settings in [ModelSettings::bm1(), ModelSettings::bm2(9)] {
        let mut post = paper_posterior(&settings, 11);
        let start = post.initial_point().unwrap();
        let precise = find_map(&mut post, &start, &MapSettings::default()).unwrap();
        let ranking = find_map(&mut post, &start, &MapSettings::ranking()).unwrap();
        // The offset in the posterior's own scale: L^T (x_r − x_p), L L^T the Hessian.
        let chol = precise.hessian.clone().cholesky().unwrap();
        let dx = nalgebra::DVector::from_iterator(
            post.dim(),
            ranking.x.iter().zip(&precise.x).map(|(r, p)| r - p),
        );
        let whitened = chol.l().transpose() * dx;
        let worst = whitened.amax();
        eprintln!(
            "{}: offset {worst:e} sd, iterations {} vs {}, log density {} vs {}",
            settings.label(),
            ranking.iterations,
            precise.iterations,
            ranking.log_density,
            precise.log_density
        );
        assert!(worst < 1e-3, "{}: offset {worst} sd", settings.label());
        assert!(
            relative_gap(ranking.log_density, precise.log_density) < 1e-9,
            "{}: {} vs {}",
            settings.label(),
            ranking.log_density,
            precise.log_density
        );
    }
}

/// Rosenbrock's valley as least squares in d/2 pairs, r = (10·(y − x²), 1 − x) per pair:
/// log π = −½‖r‖², its mode at all ones, its Gauss–Newton metric JᵀJ the Fisher metric.
struct RosenbrockValley {
    dim: usize,
}

impl RosenbrockValley {
    fn residuals_and_jacobian(&self, x: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
        let mut r = vec![0.0; self.dim];
        let mut jac = DMatrix::zeros(self.dim, self.dim);
        for p in 0..self.dim / 2 {
            let (i, j) = (2 * p, 2 * p + 1);
            r[i] = 10.0 * (x[j] - x[i] * x[i]);
            jac[(i, i)] = -20.0 * x[i];
            jac[(i, j)] = 10.0;
            r[j] = 1.0 - x[i];
            jac[(j, i)] = -1.0;
        }
        (r, jac)
    }
}

impl LogDensity for RosenbrockValley {
    fn dim(&self) -> usize {
        self.dim
    }
    fn parameter_names(&self) -> Vec<String> {
        (0..self.dim).map(|i| format!("x{i}")).collect()
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, motorcal::density::DensityError> {
        let (r, _) = self.residuals_and_jacobian(x);
        Ok(-0.5 * r.iter().map(|v| v * v).sum::<f64>())
    }
    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, motorcal::density::DensityError> {
        let (r, jac) = self.residuals_and_jacobian(x);
        let g = -(jac.transpose() * nalgebra::DVector::from_column_slice(&r));
        grad.copy_from_slice(g.as_slice());
        Ok(-0.5 * r.iter().map(|v| v * v).sum::<f64>())
    }
}

impl FisherMetric for RosenbrockValley {
    fn fisher_metric(
        &mut self,
        x: &[f64],
        metric: &mut DMatrix<f64>,
    ) -> Result<(), motorcal::density::DensityError> {
        let (_, jac) = self.residuals_and_jacobian(x);
        metric.copy_from(&(jac.transpose() * jac));
        Ok(())
    }
}

/// A candidate fit's L-BFGS stops at its iteration cap where the log density is too rough for
/// it to reach its gradient tolerance (a law that makes the ODE stiff); the Gauss–Newton polish
/// on the Fisher metric then carries the search to the mode. Cut after 2 and 5 iterations in
/// Rosenbrock's valley (three pairs from (−1.2, 1), which the uncapped search follows in 34
/// iterations), the search still ends at its mode, in fewer iterations.
#[test]
fn a_map_search_cut_short_by_its_iteration_cap_is_finished_by_the_polish() {
    let mut valley = RosenbrockValley { dim: 6 };
    let start: Vec<f64> = (0..6)
        .map(|i| if i % 2 == 0 { -1.2 } else { 1.0 })
        .collect();
    let whole = find_map(&mut valley, &start, &MapSettings::ranking()).unwrap();
    for cap in [2, 5] {
        let settings = MapSettings {
            max_iterations: cap,
            ..MapSettings::ranking()
        };
        let cut = find_map(&mut valley, &start, &settings).unwrap();
        let worst = cut.x.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
        eprintln!(
            "cap {cap}: {} iterations (uncapped {}), farthest coordinate {worst:e} from the mode",
            cut.iterations, whole.iterations
        );
        assert!(cut.iterations < whole.iterations, "cap {cap}");
        assert!(worst < 1e-6, "cap {cap}: {:?}", cut.x);
    }
}
