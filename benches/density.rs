//! What one evaluation of the BM2(K) posterior costs on the paper's data, next to the plain
//! ODE solve it is built on, so that the ratios read straight off the group names:
//!
//! - `density/kK/f64_solve`: one Dopri5 solve of the forward model over `f64` at the default
//!   tolerance (`ForwardModel::simulate`) — the reference cost, the same for every K;
//! - `density/kK/log_density`: one log density at a *new* R (the G(θ) cache misses, so this is
//!   the f64 solve plus the likelihood);
//! - `density/kK/log_density_gradient`: log density + full gradient at a new R (a dual-number
//!   solve carrying ∂/∂R, plus Jᵀr and Bᵀr);
//! - `density/kK/log_density_coefficients_only`: a log density where only a discrepancy
//!   coefficient changed (cache hit: what Metropolis-within-Gibbs pays for a non-R block);
//! - `density/kK/fisher_metric`: the Fisher metric at a new R (sensitivity solve + assembly);
//! - `density/kK/fisher_metric_cached`: the Fisher metric right after a gradient at the same
//!   point (the cache hit Fisher-MALA gets: assembly only).
//!
//! "A new R" cycles through the MAP's R and R·(1 ± 10⁻³) from one iteration to the next:
//! the posterior caches the last two solves, so three values make sure the cache never hides
//! the ODE. All evaluations are at (or next to) the
//! MAP of BM2(K). The solver statistics of both R values are printed once per K.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;

use motorcal::bayes::{CalibrationPosterior, ModelSettings};
use motorcal::density::{FisherMetric, LogDensity};
use motorcal::pipeline::map_estimate;
use motorcal::study::Problem;
use motorcal::synthetic::DEFAULT_SEED;

const DEGREES: [usize; 3] = [0, 9, 20];

/// The posterior of BM2(K) and its MAP.
fn setup(problem: &Problem, k: usize) -> (CalibrationPosterior, Vec<f64>) {
    let mut posterior = problem
        .posterior(&ModelSettings::bm2(k))
        .expect("the paper's posterior builds");
    let map = map_estimate(&mut posterior).expect("the MAP is found");
    (posterior, map.x)
}

/// Three points that differ in R only (index 0): the MAP and R·(1 ± 10⁻³).
fn three_resistances(x: &[f64]) -> [Vec<f64>; 3] {
    let mut up = x.to_vec();
    up[0] *= 1.0 + 1e-3;
    let mut down = x.to_vec();
    down[0] *= 1.0 - 1e-3;
    [x.to_vec(), up, down]
}

fn report_solver(posterior: &CalibrationPosterior, points: &[Vec<f64>; 3], k: usize) {
    let forward = posterior.forward(0);
    let mut out = vec![0.0; forward.n_outputs()];
    let mut jac = DMatrix::zeros(forward.n_outputs(), forward.n_calibrated());
    for x in points {
        let plain = forward.simulate(&x[..1], &mut out).expect("solve");
        let dual = forward
            .simulate_with_sensitivities(&x[..1], &mut out, &mut jac)
            .expect("sensitivity solve");
        eprintln!(
            "K = {k:2}, R = {:.6}: dim {}, f64 solve {} accepted / {} rejected steps, {} rhs; \
             sensitivity solve {} / {} steps",
            x[0],
            posterior.dim(),
            plain.accepted_steps,
            plain.rejected_steps,
            plain.rhs_evaluations,
            dual.accepted_steps,
            dual.rejected_steps,
        );
    }
}

fn bench_density(c: &mut Criterion) {
    let problem = Problem::paper(DEFAULT_SEED).expect("the paper's data");
    for k in DEGREES {
        let (mut posterior, x_map) = setup(&problem, k);
        let points = three_resistances(&x_map);
        report_solver(&posterior, &points, k);
        let d = posterior.dim();
        let mut group = c.benchmark_group(format!("density/k{k}"));

        let forward = posterior.forward(0).clone();
        let mut out = vec![0.0; forward.n_outputs()];
        let theta = [x_map[0]];
        group.bench_function("f64_solve", |b| {
            b.iter(|| {
                forward
                    .simulate(black_box(&theta), &mut out)
                    .expect("solve")
            })
        });

        let mut flip = 0usize;
        group.bench_function("log_density", |b| {
            b.iter(|| {
                flip = (flip + 1) % 3;
                posterior
                    .log_density(black_box(&points[flip]))
                    .expect("density")
            })
        });

        let mut grad = vec![0.0; d];
        group.bench_function("log_density_gradient", |b| {
            b.iter(|| {
                flip = (flip + 1) % 3;
                let lp = posterior
                    .log_density_and_gradient(black_box(&points[flip]), &mut grad)
                    .expect("gradient");
                black_box(&grad);
                lp
            })
        });

        // The first coefficient of the first channel; R stays put, so G(θ) comes from the cache.
        let a = posterior
            .coefficient_range(0, 0)
            .expect("BM2 has coefficients")
            .start;
        let mut coefficients = [x_map.clone(), x_map.clone()];
        coefficients[1][a] += 0.1;
        posterior.log_density(&coefficients[0]).expect("density");
        group.bench_function("log_density_coefficients_only", |b| {
            b.iter(|| {
                flip = (flip + 1) % 2;
                posterior
                    .log_density(black_box(&coefficients[flip]))
                    .expect("density")
            })
        });

        let mut metric = DMatrix::zeros(d, d);
        group.bench_function("fisher_metric", |b| {
            b.iter(|| {
                flip = (flip + 1) % 3;
                posterior
                    .fisher_metric(black_box(&points[flip]), &mut metric)
                    .expect("metric");
                black_box(&metric);
            })
        });

        posterior
            .log_density_and_gradient(&points[0], &mut grad)
            .expect("gradient");
        group.bench_function("fisher_metric_cached", |b| {
            b.iter(|| {
                posterior
                    .fisher_metric(black_box(&points[0]), &mut metric)
                    .expect("metric");
                black_box(&metric);
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bench_density);
criterion_main!(benches);
