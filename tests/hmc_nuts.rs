//! HMC and NUTS with Stan's warm-up, against Gaussians whose moments are known.

use motorcal::density::{DensityError, LogDensity};
use motorcal::diagnostics::{ess_bulk, rhat};
use motorcal::sampler::adapt::{
    AdaptationSettings, AdaptationState, DualAveraging, DualAveragingSettings, HamiltonianKernel,
    StepSizeAdaptation, WarmupSchedule, WindowedAdaptation,
};
use motorcal::sampler::hamiltonian::{PhasePoint, leapfrog};
use motorcal::sampler::hmc::{Hmc, HmcSettings};
use motorcal::sampler::metric::{Metric, MetricKind};
use motorcal::sampler::nuts::{Nuts, NutsSettings};
use motorcal::sampler::targets::{Gaussian, check_gaussian_moments};
use motorcal::sampler::{ChainOutput, ChainSettings, Kernel, NoAdaptation, State, run_chains};
use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const SEED: u64 = 20_241_107;

fn ill_conditioned() -> Gaussian {
    Gaussian::correlated(8, 0.9, 100.0)
}

/// Over-dispersed starting points, a different one per chain: chains that agree did not
/// merely start together.
fn inits(target: &Gaussian, n_chains: usize) -> Vec<Vec<f64>> {
    let sd: Vec<f64> = target.variances().iter().map(|v| v.sqrt()).collect();
    (0..n_chains)
        .map(|c| {
            (0..target.mean.len())
                .map(|j| target.mean[j] + sd[j] * (((c * 7 + j * 3) % 5) as f64 - 2.0))
                .collect()
        })
        .collect()
}

fn run<K>(
    target: &Gaussian,
    settings: &ChainSettings,
    n_chains: usize,
    kernel: impl Fn() -> K + Sync,
    adaptation: AdaptationSettings,
) -> Vec<(ChainOutput, K)>
where
    K: Kernel<motorcal::density::Counted<Gaussian>> + HamiltonianKernel + Send,
{
    run_chains(
        &inits(target, n_chains),
        settings,
        SEED,
        |_| {
            let adapt = WindowedAdaptation::new(adaptation.clone()).map_err(DensityError::fatal)?;
            Ok((target.clone(), kernel(), adapt))
        },
        None,
    )
    .unwrap()
}

/// Stan's warm-up with a 200-iteration terminal buffer instead of 50. After the last metric
/// window dual averaging restarts at 10× the searched step size, crashes to a tiny one and
/// climbs back; 50 iterations leave that climb in the average, and the final step size
/// overshoots the target acceptance (see `stan_default_terminal_buffer_overshoots_the_target`).
fn long_terminal_buffer() -> AdaptationSettings {
    AdaptationSettings {
        term_buffer: 200,
        ..AdaptationSettings::default()
    }
}

fn relative_frobenius_error(estimate: &DMatrix<f64>, truth: &DMatrix<f64>) -> f64 {
    (estimate - truth).norm() / truth.norm()
}

/// How long the Gaussian tests run, and how many Monte Carlo standard errors they allow.
struct Protocol {
    chains: usize,
    warmup: usize,
    draws: usize,
    mcse: f64,
}

/// The default test run, well inside the time budget (four chains, ~0.1 s each).
const QUICK: Protocol = Protocol {
    chains: 4,
    warmup: 1500,
    draws: 1000,
    mcse: 4.0,
};

/// Sixteen times the draws at a tighter tolerance, for the `--ignored` runs.
const LONG: Protocol = Protocol {
    chains: 16,
    warmup: 1500,
    draws: 4000,
    mcse: 3.5,
};

/// Every claim the Gaussian tests make about a kernel × metric, with the ESS per gradient
/// printed for the record (`cargo test --release --test hmc_nuts -- --nocapture`).
fn assert_samples_ill_conditioned_gaussian<K>(protocol: &Protocol, kernel: impl Fn() -> K + Sync)
where
    K: Kernel<motorcal::density::Counted<Gaussian>> + HamiltonianKernel + Send,
{
    let target = ill_conditioned();
    let settings = ChainSettings {
        warmup: protocol.warmup,
        draws: protocol.draws,
        keep: None,
    };
    let results = run(
        &target,
        &settings,
        protocol.chains,
        kernel,
        long_terminal_buffer(),
    );
    let (chains, kernels): (Vec<ChainOutput>, Vec<K>) = results.into_iter().unzip();
    let name = &chains[0].sampler;

    let d = target.mean.len();
    let columns = |j: usize| -> Vec<Vec<f64>> { chains.iter().map(|c| c.column(j)).collect() };
    let worst_rhat = (0..d).map(|j| rhat(&columns(j))).fold(0.0, f64::max);
    let min_ess = (0..d)
        .map(|j| ess_bulk(&columns(j)))
        .fold(f64::INFINITY, f64::min);
    let gradients: u64 = chains.iter().map(|c| c.sampling.gradient_evaluations).sum();
    let divergences: usize = chains.iter().map(|c| c.divergences).sum();
    let accept = chains.iter().map(|c| c.mean_accept_stat).sum::<f64>() / chains.len() as f64;
    let leapfrogs = gradients as f64 / (chains.len() * settings.draws) as f64;
    let metric_errors: Vec<f64> = kernels
        .iter()
        .filter_map(|k| match k.metric() {
            Metric::Dense(m) => Some(relative_frobenius_error(
                m.inverse_mass(),
                &target.covariance,
            )),
            Metric::Diagonal(_) => None,
        })
        .collect();
    eprintln!(
        "{name}: min bulk ESS {min_ess:.0} over {gradients} gradients = {:.4} ESS/gradient; \
         {leapfrogs:.1} leapfrogs/draw; step sizes {:.3?}; accept {accept:.3}; worst R-hat \
         {worst_rhat:.4}; dense metric errors {metric_errors:.3?}",
        min_ess / gradients as f64,
        chains.iter().map(|c| c.final_step_size).collect::<Vec<_>>(),
    );

    let (z_mean, z_var) = check_gaussian_moments(&chains, &target, protocol.mcse).unwrap();
    eprintln!("{name}: worst |z| of a mean {z_mean:.2}, of a variance {z_var:.2}");
    assert!(worst_rhat <= 1.01, "{name}: R-hat {worst_rhat}");
    assert_eq!(divergences, 0, "{name}: divergences after warm-up");
    assert!(
        (accept - 0.8).abs() <= 0.1,
        "{name}: mean accept_stat {accept} after adapting to 0.8"
    );
    for error in metric_errors {
        assert!(
            error < 0.3,
            "{name}: adapted inverse mass is {error:.3} (relative Frobenius) from the covariance"
        );
    }
}

fn nuts(kind: MetricKind) -> Nuts {
    Nuts::new(Metric::identity(8, kind), NutsSettings::default()).unwrap()
}

/// Integration time for the Gaussian tests: a quarter period of the widest direction left
/// after the metric (with the diagonal metric the AR(1) correlation keeps an eigenvalue near
/// 6, i.e. a scale near 2.5).
fn hmc(kind: MetricKind) -> Hmc {
    let settings = HmcSettings {
        integration_time: match kind {
            MetricKind::Diagonal => 4.0,
            MetricKind::Dense => std::f64::consts::FRAC_PI_2,
        },
        ..HmcSettings::default()
    };
    Hmc::new(Metric::identity(8, kind), settings).unwrap()
}

#[test]
fn nuts_diag_samples_an_ill_conditioned_gaussian() {
    assert_samples_ill_conditioned_gaussian(&QUICK, || nuts(MetricKind::Diagonal));
}

#[test]
fn nuts_dense_samples_an_ill_conditioned_gaussian_and_learns_its_covariance() {
    assert_samples_ill_conditioned_gaussian(&QUICK, || nuts(MetricKind::Dense));
}

#[test]
fn hmc_diag_samples_an_ill_conditioned_gaussian() {
    assert_samples_ill_conditioned_gaussian(&QUICK, || hmc(MetricKind::Diagonal));
}

#[test]
fn hmc_dense_samples_an_ill_conditioned_gaussian_and_learns_its_covariance() {
    assert_samples_ill_conditioned_gaussian(&QUICK, || hmc(MetricKind::Dense));
}

fn state_at(target: &mut Gaussian, x: &[f64]) -> State {
    let mut gradient = vec![0.0; x.len()];
    let log_density = target.log_density_and_gradient(x, &mut gradient).unwrap();
    State {
        x: x.to_vec(),
        log_density,
        gradient,
    }
}

fn integrate(target: &mut Gaussian, metric: &Metric, z: &mut PhasePoint, step: f64, n: usize) {
    for _ in 0..n {
        leapfrog(target, metric, z, step).unwrap();
    }
}

#[test]
fn leapfrog_is_reversible_and_its_energy_error_is_second_order() {
    let mut target = ill_conditioned();
    let metric = Metric::dense(target.covariance.clone()).unwrap();
    // From the mode the momentum alone sets the energy, which is then a typical one.
    let mode: Vec<f64> = target.mean.iter().copied().collect();
    let start = state_at(&mut target, &mode);
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let mut z0 = PhasePoint::new(8);
    z0.load_state(&start);
    z0.refresh_momentum(&metric, &mut rng);

    let mut z = z0.clone();
    integrate(&mut target, &metric, &mut z, 0.1, 20);
    let flipped: Vec<f64> = z.p.iter().map(|p| -p).collect();
    z.set_momentum(&metric, &flipped);
    integrate(&mut target, &metric, &mut z, 0.1, 20);
    let scale = target.covariance.diagonal().map(f64::sqrt);
    for j in 0..8 {
        let error = (z.x[j] - z0.x[j]).abs() / scale[j];
        assert!(error < 1e-10, "x.{} returns {error:e} (in sd) off", j + 1);
        assert!((z.p[j] + z0.p[j]).abs() < 1e-10 * (1.0 + z0.p[j].abs()));
    }

    // The worst energy error over a fixed time T = 1 shrinks 4× when ε halves.
    let mut worst_energy_error = |step: f64| {
        let mut z = z0.clone();
        let mut worst = 0.0f64;
        for _ in 0..(1.0 / step).round() as usize {
            leapfrog(&mut target, &metric, &mut z, step).unwrap();
            worst = worst.max((z.energy() - z0.energy()).abs());
        }
        worst
    };
    let (coarse, fine) = (worst_energy_error(0.1), worst_energy_error(0.05));
    assert!(coarse < 0.05, "energy error {coarse} at ε = 0.1");
    let order = (coarse / fine).log2();
    assert!((order - 2.0).abs() < 0.25, "energy error order {order}");
}

#[test]
fn dual_averaging_finds_the_step_size_that_hits_the_target_acceptance() {
    // A smooth decreasing acceptance curve with a known solution a(ε*) = 0.8.
    let accept = |eps: f64| (-(eps * eps) / 4.0).exp();
    let solution = (-4.0 * 0.8f64.ln()).sqrt();
    let mut dual = DualAveraging::new(&DualAveragingSettings::default(), 0.01);
    for _ in 0..2000 {
        let eps = dual.step_size();
        dual.update(accept(eps));
    }
    let found = dual.final_step_size();
    assert!(
        (found / solution - 1.0).abs() < 0.02,
        "ε = {found} vs {solution}"
    );
}

#[test]
fn dual_averaging_converges_on_a_one_dimensional_gaussian() {
    let target = Gaussian::correlated(1, 0.0, 1.0);
    let settings = ChainSettings {
        warmup: 1000,
        draws: 2000,
        keep: None,
    };
    let results = run_chains(
        &[vec![3.0], vec![-3.0], vec![0.5], vec![-1.0]],
        &settings,
        SEED,
        |_| {
            let kernel = Nuts::new(
                Metric::identity(1, MetricKind::Diagonal),
                NutsSettings::default(),
            )
            .map_err(DensityError::fatal)?;
            Ok((target.clone(), kernel, StepSizeAdaptation::default()))
        },
        None,
    )
    .unwrap();
    let steps: Vec<f64> = results.iter().map(|(c, _)| c.final_step_size).collect();
    let (lo, hi) = steps.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &s| {
        (lo.min(s), hi.max(s))
    });
    assert!(hi / lo < 1.15, "chains ended with step sizes {steps:?}");
    for (chain, _) in &results {
        let accept = chain.mean_accept_stat;
        assert!(
            (accept - 0.8).abs() < 0.05,
            "accept_stat {accept} with ε = {}",
            chain.final_step_size
        );
    }
}

#[test]
fn warmup_windows_follow_stan() {
    let windows = |n| WarmupSchedule::stan(n, 75, 50, 25).windows;
    assert_eq!(
        windows(1000),
        vec![75..100, 100..150, 150..250, 250..450, 450..950]
    );
    assert_eq!(
        windows(2000),
        vec![75..100, 100..150, 150..250, 250..450, 450..850, 850..1950]
    );
    // Stan never stretches the first window, whatever remains after it.
    assert_eq!(windows(160), vec![75..100, 100..110]);
    // Too short for the defaults: 15 % initial and 10 % terminal buffers, one window.
    assert_eq!(windows(100), vec![15..90]);
    assert!(windows(19).is_empty());
}

#[test]
fn tree_depth_never_exceeds_the_maximum() {
    let target = ill_conditioned();
    let settings = ChainSettings {
        warmup: 100,
        draws: 200,
        keep: None,
    };
    // The identity metric on a target with scales 1…100 needs long trajectories: the cap bites.
    let results = run_chains(
        &inits(&target, 2),
        &settings,
        SEED,
        |_| {
            let kernel = Nuts::new(
                Metric::identity(8, MetricKind::Diagonal),
                NutsSettings {
                    max_depth: 3,
                    ..NutsSettings::default()
                },
            )
            .map_err(DensityError::fatal)?;
            Ok((target.clone(), kernel, StepSizeAdaptation::default()))
        },
        None,
    )
    .unwrap();
    let records: Vec<_> = results.iter().flat_map(|(c, _)| &c.records).collect();
    assert!(records.iter().all(|r| r.tree_depth <= 3 && r.n_steps <= 7));
    assert!(
        records.iter().any(|r| r.tree_depth == 3),
        "the cap never bit"
    );
}

/// N(0, 1) whose evaluation fails recoverably beyond a wall at x = 1, like an ODE solver that
/// gives up in a stiff corner.
#[derive(Clone)]
struct Walled;

impl LogDensity for Walled {
    fn dim(&self) -> usize {
        1
    }
    fn parameter_names(&self) -> Vec<String> {
        vec!["x".into()]
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        if x[0] > 1.0 {
            return Err(DensityError::recoverable("beyond the wall"));
        }
        Ok(-0.5 * x[0] * x[0])
    }
    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        grad[0] = -x[0];
        self.log_density(x)
    }
}

#[test]
fn a_recoverable_density_error_is_a_divergence_not_a_panic() {
    let settings = ChainSettings {
        warmup: 200,
        draws: 500,
        keep: None,
    };
    let inits = vec![vec![0.0], vec![-1.0]];
    let metric = || Metric::identity(1, MetricKind::Diagonal);
    let nuts = run_chains(
        &inits,
        &settings,
        SEED,
        |_| {
            Ok((
                Walled,
                Nuts::new(metric(), NutsSettings::default()).unwrap(),
                WindowedAdaptation::default(),
            ))
        },
        None,
    )
    .unwrap();
    let hmc = run_chains(
        &inits,
        &settings,
        SEED,
        |_| {
            Ok((
                Walled,
                Hmc::new(metric(), HmcSettings::default()).unwrap(),
                WindowedAdaptation::default(),
            ))
        },
        None,
    )
    .unwrap();
    let chains: Vec<&ChainOutput> = nuts
        .iter()
        .map(|(c, _)| c)
        .chain(hmc.iter().map(|(c, _)| c))
        .collect();
    for chain in chains {
        assert!(
            chain.divergences > 0,
            "{}: the wall was never reported",
            chain.sampler
        );
        assert!(
            chain.draws.iter().all(|x| x[0] <= 1.0),
            "{}: a draw beyond the wall",
            chain.sampler
        );
        let flagged = chain.records.iter().filter(|r| r.divergent).count();
        assert_eq!(flagged, chain.divergences);
    }
}

fn nuts_dense_draws(threads: usize) -> Vec<(Vec<Vec<f64>>, Vec<f64>)> {
    let target = ill_conditioned();
    let settings = ChainSettings {
        warmup: 300,
        draws: 200,
        keep: None,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        run(
            &target,
            &settings,
            3,
            || nuts(MetricKind::Dense),
            AdaptationSettings::default(),
        )
    })
    .into_iter()
    .map(|(c, _)| (c.draws, c.records.iter().map(|r| r.accept_stat).collect()))
    .collect()
}

#[test]
fn the_same_seed_gives_bit_identical_draws_on_one_or_two_threads() {
    let one = nuts_dense_draws(1);
    let two = nuts_dense_draws(2);
    assert!(one == two, "draws depend on the thread count");
    assert!(one[0].0 != one[1].0, "chains share a random stream");
}

#[test]
fn a_saved_adaptation_resumes_with_identical_draws() {
    let target = ill_conditioned();
    let warmup = ChainSettings {
        warmup: 300,
        draws: 1,
        keep: None,
    };
    let tuned: Vec<Nuts> = run(
        &target,
        &warmup,
        2,
        || nuts(MetricKind::Dense),
        AdaptationSettings::default(),
    )
    .into_iter()
    .map(|(_, k)| k)
    .collect();

    let saved: Vec<String> = tuned
        .iter()
        .map(|k| AdaptationState::of(k).to_toml())
        .collect();
    let reloaded: Vec<AdaptationState> = saved
        .iter()
        .map(|t| AdaptationState::from_toml(t).unwrap())
        .collect();
    for (kernel, state) in tuned.iter().zip(&reloaded) {
        assert_eq!(
            &AdaptationState::of(kernel),
            state,
            "the TOML round trip changed a bit"
        );
    }

    let sampling = ChainSettings {
        warmup: 0,
        draws: 300,
        keep: None,
    };
    let resume = |from_file: bool| -> Vec<Vec<Vec<f64>>> {
        run_chains(
            &inits(&target, 2),
            &sampling,
            SEED + 1,
            |c| {
                let kernel = if from_file {
                    Nuts::from_adaptation(&reloaded[c], NutsSettings::default()).unwrap()
                } else {
                    tuned[c].clone()
                };
                Ok((target.clone(), kernel, NoAdaptation))
            },
            None,
        )
        .unwrap()
        .into_iter()
        .map(|(c, _)| c.draws)
        .collect()
    };
    assert!(resume(true) == resume(false));
}

#[test]
fn a_dense_metric_draws_momenta_with_covariance_m() {
    let inverse_mass = DMatrix::from_row_slice(2, 2, &[4.0, 1.8, 1.8, 1.0]);
    let metric = Metric::dense(inverse_mass.clone()).unwrap();
    let mass = inverse_mass.try_inverse().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let n = 100_000;
    let mut p = [0.0; 2];
    let mut second_moment = DMatrix::zeros(2, 2);
    let mut kinetic = 0.0;
    let mut velocity = [0.0; 2];
    for _ in 0..n {
        metric.sample_momentum(&mut rng, &mut p);
        for i in 0..2 {
            for j in 0..2 {
                second_moment[(i, j)] += p[i] * p[j] / n as f64;
            }
        }
        metric.velocity(&p, &mut velocity);
        kinetic += Metric::kinetic_energy(&p, &velocity) / n as f64;
    }
    assert!(relative_frobenius_error(&second_moment, &mass) < 0.02);
    // ½pᵀM⁻¹p is ½χ²₂: mean 1.
    assert!(
        (kinetic - 1.0).abs() < 0.02,
        "mean kinetic energy {kinetic}"
    );
}

#[test]
fn a_metric_from_the_precision_is_the_covariance() {
    let target = ill_conditioned();
    let precision = target.covariance.clone().try_inverse().unwrap();
    let dense = Metric::from_precision(&precision, MetricKind::Dense).unwrap();
    assert!(relative_frobenius_error(&dense.inverse_mass_matrix(), &target.covariance) < 1e-9);
    let diagonal = Metric::from_precision(&precision, MetricKind::Diagonal).unwrap();
    for (got, want) in diagonal
        .inverse_mass_matrix()
        .diagonal()
        .iter()
        .zip(target.variances())
    {
        assert!((got / want - 1.0).abs() < 1e-9);
    }
    assert!(Metric::from_precision(&-precision, MetricKind::Dense).is_err());
}

#[test]
fn an_adaptation_state_rejects_a_malformed_file() {
    let bad = [
        "step_size = 0.5\n[metric.dense]\ninverse_mass = [[1.0, 2.0], [2.0, 1.0]]\n",
        "step_size = 0.5\n[metric.dense]\ninverse_mass = [[1.0, 0.0], [0.0]]\n",
        "step_size = -1.0\n[metric.diagonal]\ninverse_mass = [1.0]\n",
        "step_size = 0.5\n[metric.diagonal]\ninverse_mass = [0.0]\n",
    ];
    for text in bad {
        assert!(
            AdaptationState::from_toml(text).is_err(),
            "accepted:\n{text}"
        );
    }
    let good = AdaptationState::from_toml(
        "step_size = 0.5\n[metric.diagonal]\ninverse_mass = [1.0, 2.0]\n",
    )
    .unwrap();
    assert_eq!(good.metric.dim(), 2);
}

/// A measurement rather than a requirement: the realised acceptance of NUTS with Stan's
/// default warm-up on the diagonal-metric test (0.88–0.92 per chain when measured).
#[test]
#[ignore]
fn stan_default_terminal_buffer_overshoots_the_target() {
    let target = ill_conditioned();
    let settings = ChainSettings {
        warmup: 1000,
        draws: 1000,
        keep: None,
    };
    for term_buffer in [50, 200] {
        let adaptation = AdaptationSettings {
            term_buffer,
            ..AdaptationSettings::default()
        };
        let results = run(
            &target,
            &settings,
            8,
            || nuts(MetricKind::Diagonal),
            adaptation,
        );
        let accept: Vec<f64> = results.iter().map(|(c, _)| c.mean_accept_stat).collect();
        let mean = accept.iter().sum::<f64>() / accept.len() as f64;
        eprintln!(
            "terminal buffer {term_buffer}: mean accept_stat {mean:.3} (chains {accept:.3?})"
        );
        if term_buffer == 50 {
            assert!(mean > 0.85, "the overshoot is gone: {mean}");
        }
    }
}

#[test]
#[ignore]
fn long_runs_sample_the_ill_conditioned_gaussian_tightly() {
    assert_samples_ill_conditioned_gaussian(&LONG, || nuts(MetricKind::Diagonal));
    assert_samples_ill_conditioned_gaussian(&LONG, || nuts(MetricKind::Dense));
    assert_samples_ill_conditioned_gaussian(&LONG, || hmc(MetricKind::Diagonal));
    assert_samples_ill_conditioned_gaussian(&LONG, || hmc(MetricKind::Dense));
}

/// Counts the calling thread's heap allocations, so that a test can claim a transition
/// allocates nothing while other tests run on other threads.
struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

unsafe impl std::alloc::GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// N(0, diag(variances)) evaluated without allocating, unlike the general [`Gaussian`].
struct IndependentGaussian(Vec<f64>);

impl LogDensity for IndependentGaussian {
    fn dim(&self) -> usize {
        self.0.len()
    }
    fn parameter_names(&self) -> Vec<String> {
        (0..self.0.len()).map(|i| format!("x.{i}")).collect()
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        Ok(x.iter().zip(&self.0).map(|(x, v)| -0.5 * x * x / v).sum())
    }
    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        for ((g, x), v) in grad.iter_mut().zip(x).zip(&self.0) {
            *g = -x / v;
        }
        self.log_density(x)
    }
}

fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(|n| n.get());
    f();
    ALLOCATIONS.with(|n| n.get()) - before
}

fn assert_transitions_allocate_nothing<K: Kernel<IndependentGaussian>>(mut kernel: K) {
    let mut density = IndependentGaussian((1..=6).map(|i| i as f64).collect());
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let mut state = kernel.init_state(&mut density, &[0.5; 6]).unwrap();
    // The first transition searches the step size; later ones only integrate.
    kernel.step(&mut density, &mut state, &mut rng).unwrap();
    let mut leapfrogs = 0;
    let allocations = allocations_in(|| {
        for _ in 0..200 {
            leapfrogs += kernel
                .step(&mut density, &mut state, &mut rng)
                .unwrap()
                .n_steps;
        }
    });
    assert_eq!(
        allocations,
        0,
        "{}: {allocations} allocations in {leapfrogs} leapfrog steps",
        kernel.name()
    );
}

#[test]
fn transitions_allocate_nothing() {
    assert!(
        allocations_in(|| drop(std::hint::black_box(vec![0u8; 8]))) > 0,
        "the counter is blind"
    );
    for kind in [MetricKind::Diagonal, MetricKind::Dense] {
        let metric = Metric::identity(6, kind);
        assert_transitions_allocate_nothing(
            Nuts::new(metric.clone(), NutsSettings::default()).unwrap(),
        );
        assert_transitions_allocate_nothing(Hmc::new(metric, HmcSettings::default()).unwrap());
    }
}
