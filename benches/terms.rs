//! What physics terms cost, side by side in one run, on the paper's data at K = 9:
//!
//! - `terms/none/{f64_solve, log_density_gradient}`: the paper's motor, R calibrated;
//! - `terms/coulomb_friction/…`: the motor with Coulomb friction, R and T_c calibrated;
//! - `terms/all_twelve/…`: every term on, R and the thirteen term parameters calibrated (four
//!   dual-number passes of up to four directions each).
//!
//! `f64_solve` is one plain solve of that model (the reference); `log_density_gradient` is the
//! log density with its full gradient at a new θ (the solve cache is defeated by cycling R).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};

use motorcal::bayes::{CalibrationPosterior, ModelSettings};
use motorcal::density::LogDensity;
use motorcal::motor::Term;
use motorcal::study::Problem;
use motorcal::synthetic::DEFAULT_SEED;

fn posterior(terms: &[&str]) -> (CalibrationPosterior, Vec<f64>) {
    let mut problem = Problem::paper(DEFAULT_SEED).expect("the paper's data");
    if !terms.is_empty() {
        // The terms on at their defaults and calibrated with R, as diagnose builds a candidate
        // (its BM1 setting is not used: the posterior below is BM2(9)).
        let names: Vec<String> = terms.iter().map(|t| t.to_string()).collect();
        problem = problem.with_terms(&names).expect("known terms");
    }
    let mut posterior = problem
        .posterior(&ModelSettings::bm2(9))
        .expect("the posterior builds");
    let x = posterior.initial_point().expect("a start");
    (posterior, x)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("terms");
    for (label, terms) in [
        ("none", vec![]),
        ("coulomb_friction", vec!["coulomb_friction"]),
        ("all_twelve", Term::NAMES.to_vec()),
    ] {
        let (mut posterior, x) = posterior(&terms);
        let forward = posterior.forward(0).clone();
        let theta = posterior.theta_of(&x);
        let mut out = vec![0.0; forward.n_outputs()];
        group.bench_function(format!("{label}/f64_solve"), |b| {
            b.iter(|| {
                forward
                    .simulate(black_box(&theta), &mut out)
                    .expect("solve")
            })
        });
        // R moves by ±10⁻³ of itself in its own coordinate (x or log x): three points, so the
        // two-solve cache never hides the ODE.
        let points: Vec<Vec<f64>> = [0.0, 1e-3, -1e-3]
            .iter()
            .map(|d| {
                let mut p = x.clone();
                p[0] += d * p[0].abs().max(1.0);
                p
            })
            .collect();
        let mut grad = vec![0.0; x.len()];
        let mut i = 0;
        group.bench_function(format!("{label}/log_density_gradient"), |b| {
            b.iter(|| {
                i = (i + 1) % 3;
                posterior
                    .log_density_and_gradient(black_box(&points[i]), &mut grad)
                    .expect("density")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
