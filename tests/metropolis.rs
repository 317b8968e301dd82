//! The gradient-free samplers: the paper's PyMC3-style Metropolis and adaptive Metropolis sample
//! Gaussians correctly, are reproducible across thread counts, and the paper's Metropolis
//! reproduces the paper's BM1 posterior.

use std::ops::Range;

use motorcal::bayes::{CalibrationPosterior, ModelSettings, Observations};
use motorcal::density::{DensityError, LogDensity};
use motorcal::diagnostics::rhat;
use motorcal::forward::ForwardModel;
use motorcal::motor::{MotorModel, MotorParameters, VoltageInput};
use motorcal::ode::SolverSettings;
use motorcal::optimize::{MapSettings, find_map};
use motorcal::sampler::adaptive_metropolis::{AdaptiveMetropolis, HaarioAdaptation};
use motorcal::sampler::metropolis::{Metropolis, PyMc3Tuning};
use motorcal::sampler::targets::{Gaussian, check_gaussian_moments};
use motorcal::sampler::{ChainOutput, ChainSettings, run_chains};
use motorcal::synthetic::{PaperSetup, paper_measurements};
use nalgebra::DMatrix;

/// A Gaussian whose coordinates are grouped into the given blocks, as the motor posterior
/// groups its discrepancy coefficients.
#[derive(Clone)]
struct Blocked {
    inner: Gaussian,
    blocks: Vec<Range<usize>>,
}

impl LogDensity for Blocked {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn parameter_names(&self) -> Vec<String> {
        self.inner.parameter_names()
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        self.inner.log_density(x)
    }
    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        self.inner.log_density_and_gradient(x, grad)
    }
    fn blocks(&self) -> Vec<Range<usize>> {
        self.blocks.clone()
    }
}

/// Standard deviations over four orders of magnitude; the middle pair is proposed jointly.
fn diagonal_target() -> Blocked {
    let sd = [0.01, 1.0, 2.0, 100.0];
    let cov = DMatrix::from_fn(4, 4, |i, j| if i == j { sd[i] * sd[i] } else { 0.0 });
    Blocked {
        inner: Gaussian::new(vec![1.0, -2.0, 0.5, 30.0], cov),
        blocks: vec![0..1, 1..3, 3..4],
    }
}

/// Starting points a few standard deviations apart, so that R̂ sees chains that had to meet.
fn dispersed_inits(target: &Gaussian, n: usize) -> Vec<Vec<f64>> {
    let sd: Vec<f64> = target.variances().iter().map(|v| v.sqrt()).collect();
    (0..n)
        .map(|c| {
            (0..sd.len())
                .map(|i| {
                    target.mean[i] + sd[i] * 2.0 * (1.7 * (c * sd.len() + i) as f64 + 0.3).sin()
                })
                .collect()
        })
        .collect()
}

fn paper_metropolis_on_diagonal(seed: u64, settings: &ChainSettings) -> Vec<ChainOutput> {
    let target = diagonal_target();
    let inits = dispersed_inits(&target.inner, 4);
    run_chains(
        &inits,
        settings,
        seed,
        |_| {
            Ok((
                target.clone(),
                Metropolis::for_density(&target),
                PyMc3Tuning::new(),
            ))
        },
        None,
    )
    .unwrap()
    .into_iter()
    .map(|(output, _)| output)
    .collect()
}

fn adaptive_on_correlated(
    seed: u64,
    settings: &ChainSettings,
) -> Vec<(ChainOutput, AdaptiveMetropolis)> {
    let target = Gaussian::correlated(4, 0.5, 10.0);
    let inits = dispersed_inits(&target, 4);
    run_chains(
        &inits,
        settings,
        seed,
        // The identity is a poor start (the target's sds run from 1 to 10, correlated): the
        // adaptation must learn both the shape and the scale.
        |_| {
            Ok((
                target.clone(),
                AdaptiveMetropolis::isotropic(4, 1.0).unwrap(),
                HaarioAdaptation::default(),
            ))
        },
        None,
    )
    .unwrap()
}

fn worst_rhat(chains: &[ChainOutput]) -> f64 {
    (0..chains[0].names.len())
        .map(|j| rhat(&chains.iter().map(|c| c.column(j)).collect::<Vec<_>>()))
        .fold(0.0, f64::max)
}

#[test]
fn the_paper_metropolis_samples_a_gaussian_with_scales_four_orders_apart() {
    let settings = ChainSettings {
        warmup: 2000,
        draws: 20000,
        keep: None,
    };
    let chains = paper_metropolis_on_diagonal(20260101, &settings);
    let target = diagonal_target();
    let (z_mean, z_var) = check_gaussian_moments(&chains, &target.inner, 4.0).unwrap();
    let worst = worst_rhat(&chains);
    let accept: Vec<f64> = chains.iter().map(|c| c.mean_accept_stat).collect();
    eprintln!(
        "metropolis: worst |z| mean {z_mean:.2}, variance {z_var:.2}; R̂ ≤ {worst:.4}; accept {accept:.3?}"
    );
    assert!(worst <= 1.01, "R̂ = {worst}");
}

#[test]
fn adaptive_metropolis_samples_a_correlated_gaussian_from_an_identity_start() {
    let settings = ChainSettings {
        warmup: 3000,
        draws: 20000,
        keep: None,
    };
    let runs = adaptive_on_correlated(7, &settings);
    let target = Gaussian::correlated(4, 0.5, 10.0);
    let chains: Vec<ChainOutput> = runs.iter().map(|(c, _)| c.clone()).collect();
    let (z_mean, z_var) = check_gaussian_moments(&chains, &target, 4.0).unwrap();
    let worst = worst_rhat(&chains);
    let accept: Vec<f64> = chains.iter().map(|c| c.mean_accept_stat).collect();
    let scales: Vec<f64> = runs.iter().map(|(_, k)| k.scale()).collect();
    eprintln!(
        "adaptive metropolis: worst |z| mean {z_mean:.2}, variance {z_var:.2}; R̂ ≤ {worst:.4}; accept {accept:.3?}; λ {scales:.3?}"
    );
    assert!(worst <= 1.01, "R̂ = {worst}");
    // The learnt covariance is the target's, to within what 2700 correlated warm-up draws allow.
    for (_, kernel) in &runs {
        let learnt = kernel.covariance();
        for i in 0..4 {
            let ratio = learnt[(i, i)] / target.covariance[(i, i)];
            assert!(
                (0.5..2.0).contains(&ratio),
                "variance {i}: learnt/true = {ratio}"
            );
        }
    }
}

#[test]
fn draws_are_bit_identical_on_one_thread_and_on_two() {
    let settings = ChainSettings {
        warmup: 300,
        draws: 500,
        keep: Some(400),
    };
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let metropolis: Vec<Vec<Vec<f64>>> = paper_metropolis_on_diagonal(3, &settings)
                .into_iter()
                .map(|c| c.draws)
                .collect();
            let adaptive: Vec<Vec<Vec<f64>>> = adaptive_on_correlated(3, &settings)
                .into_iter()
                .map(|(c, _)| c.draws)
                .collect();
            (metropolis, adaptive)
        })
    };
    let (one, two) = (on(1), on(2));
    let bits = |draws: &Vec<Vec<Vec<f64>>>| -> Vec<u64> {
        draws
            .iter()
            .flatten()
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(
        bits(&one.0),
        bits(&two.0),
        "metropolis draws depend on the thread count"
    );
    assert_eq!(
        bits(&one.1),
        bits(&two.1),
        "adaptive Metropolis draws depend on the thread count"
    );
    // …and the chains are not copies of one another.
    assert_ne!(one.0[0], one.0[1]);
}

/// The paper's case: data from φ = 1, fitted with the simulation model φ = 0.9.
fn paper_bm1_posterior(seed: u64) -> CalibrationPosterior {
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
    CalibrationPosterior::new(vec![(forward, obs)], &ModelSettings::bm1()).unwrap()
}

#[test]
fn the_paper_metropolis_reproduces_the_biased_bm1_posterior_of_the_paper() {
    let mut posterior = paper_bm1_posterior(11);
    let start = posterior.initial_point().unwrap();
    let map = find_map(&mut posterior, &start, &MapSettings::default()).unwrap();
    // The paper's protocol: PyMC3 Metropolis, 500 tuning steps, chains of 1500 of which the
    // last 700 are kept, three chains.
    let settings = ChainSettings {
        warmup: 500,
        draws: 1500,
        keep: Some(700),
    };
    let inits = vec![map.x.clone(); 3];
    let runs = run_chains(
        &inits,
        &settings,
        2018,
        |_| {
            Ok((
                posterior.clone(),
                Metropolis::for_density(&posterior),
                PyMc3Tuning::new(),
            ))
        },
        None,
    )
    .unwrap();
    let chains: Vec<&ChainOutput> = runs.iter().map(|(c, _)| c).collect();
    let mean_of = |j: usize| {
        let all: Vec<f64> = chains.iter().flat_map(|c| c.column(j)).collect();
        all.iter().sum::<f64>() / all.len() as f64
    };
    let (r, sigma_i, sigma_omega) = (mean_of(0), mean_of(1), mean_of(2));
    let scalings: Vec<Vec<String>> = runs
        .iter()
        .map(|(_, k)| k.scaling().iter().map(|s| format!("{s:.1e}")).collect())
        .collect();
    let accept: Vec<f64> = chains.iter().map(|c| c.mean_accept_stat).collect();
    eprintln!(
        "BM1 Metropolis: R {r:.5}, σ_I {sigma_i:.3}, σ_ω {sigma_omega:.4} (MAP R {:.5}, σ_I {:.3}); \
         scalings {scalings:?}; accept {accept:.3?}; R̂ R {:.3}",
        map.x[0],
        map.x[1].exp(),
        rhat(&chains.iter().map(|c| c.column(0)).collect::<Vec<_>>())
    );
    assert_eq!(
        chains[0].names[1], "sigma_I",
        "the second reported quantity should be σ_I"
    );
    assert!(
        (r - 0.0903).abs() <= 0.02 * 0.0903,
        "posterior mean of R = {r}"
    );
    assert!(
        (5.5..=7.0).contains(&sigma_i),
        "posterior mean of σ_I = {sigma_i}"
    );
}

/// Fails recoverably everywhere except at the origin, like an ODE that blows up off the mode.
struct FailsOffOrigin;

impl LogDensity for FailsOffOrigin {
    fn dim(&self) -> usize {
        2
    }
    fn parameter_names(&self) -> Vec<String> {
        vec!["a".into(), "b".into()]
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        if x.iter().all(|v| *v == 0.0) {
            Ok(-1.0)
        } else {
            Err(DensityError::recoverable("solver gave up"))
        }
    }
    fn log_density_and_gradient(&mut self, x: &[f64], _: &mut [f64]) -> Result<f64, DensityError> {
        self.log_density(x)
    }
}

#[test]
fn a_proposal_the_density_cannot_evaluate_is_rejected_and_the_chain_goes_on() {
    use motorcal::sampler::{Kernel, State};
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let start = State {
        x: vec![0.0, 0.0],
        log_density: -1.0,
        gradient: Vec::new(),
    };
    let mut metropolis = Metropolis::for_density(&FailsOffOrigin);
    let mut state = start.clone();
    for _ in 0..10 {
        let info = metropolis
            .step(&mut FailsOffOrigin, &mut state, &mut rng)
            .unwrap();
        assert_eq!(info.block_accepted, vec![false, false]);
        assert_eq!((info.accept_stat, info.n_steps), (0.0, 2));
    }
    assert_eq!(state, start);
    let mut adaptive = AdaptiveMetropolis::isotropic(2, 1.0).unwrap();
    for _ in 0..10 {
        let info = adaptive
            .step(&mut FailsOffOrigin, &mut state, &mut rng)
            .unwrap();
        assert!(!info.accepted);
    }
    assert_eq!(state, start);
}
