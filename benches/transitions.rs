//! The cost of one transition of each sampler on BM2(K = 9) with the paper's data, in the
//! stationary regime: each kernel is built as `motorcal fit` builds it (warm-started from the
//! MAP's Laplace approximation), adapted by a full warm-up of `WARMUP` transitions from the MAP
//! outside the timed loop, and then timed while it keeps stepping from where its warm-up ended.
//!
//! Group `transition/k9`, one function per sampler (`nuts-dense`, `mala`, …). After each, the
//! mean numbers of density and gradient evaluations and of leapfrog steps (or block proposals)
//! per timed transition are printed, with the acceptance rate (per block for the paper's
//! Metropolis), which turns the times into multiples of the `density` bench's costs: a NUTS
//! transition is mostly its leapfrog steps, a Metropolis sweep mostly its ODE solves.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;
use rand_chacha::ChaCha8Rng;

use motorcal::bayes::{CalibrationPosterior, ModelSettings};
use motorcal::density::{Counted, LogDensity};
use motorcal::pipeline::map_estimate;
use motorcal::sampler::adapt::WindowedAdaptation;
use motorcal::sampler::adaptive_metropolis::{AdaptiveMetropolis, HaarioAdaptation};
use motorcal::sampler::driver::chain_rng;
use motorcal::sampler::fisher_mala::{FisherMala, FisherMalaAdaptation};
use motorcal::sampler::hmc::{Hmc, HmcSettings};
use motorcal::sampler::mala::{Mala, MalaAdaptation};
use motorcal::sampler::metric::{Metric, MetricKind};
use motorcal::sampler::metropolis::{Metropolis, PyMc3Tuning};
use motorcal::sampler::nuts::{Nuts, NutsSettings};
use motorcal::sampler::{Adaptation, ChainSettings, Kernel, State, run_chain};
use motorcal::study::Problem;
use motorcal::synthetic::DEFAULT_SEED;

const K: usize = 9;
const WARMUP: usize = 1000;

type Target = Counted<CalibrationPosterior>;

/// Everything the kernels are built from.
struct Setup {
    posterior: CalibrationPosterior,
    map_x: Vec<f64>,
    hessian: DMatrix<f64>,
}

/// Adapts `kernel` by `WARMUP` transitions from the MAP; returns it with the point the warm-up
/// reached.
fn adapted<K, A>(setup: &Setup, kernel: K, adaptation: A) -> (K, Vec<f64>)
where
    K: Kernel<Target>,
    A: Adaptation<K>,
{
    let settings = ChainSettings {
        warmup: WARMUP,
        draws: 1,
        keep: None,
    };
    let mut rng = chain_rng(DEFAULT_SEED, 0);
    let (output, kernel) = run_chain(
        setup.posterior.clone(),
        kernel,
        adaptation,
        &setup.map_x,
        &settings,
        &mut rng,
        0,
        None,
    )
    .expect("the warm-up runs");
    let x = output.unconstrained.last().expect("one draw").clone();
    (kernel, x)
}

/// A kernel adapted and running, with what it has done since the timing started.
struct Live<K> {
    kernel: K,
    density: Target,
    state: State,
    rng: ChaCha8Rng,
    transitions: u64,
    accepted: u64,
    steps: u64,
    /// Acceptances per block, for variable-at-a-time kernels.
    block_accepted: Vec<u64>,
}

/// Times one transition of an adapted kernel, then prints evaluations per transition. The
/// warm-up runs inside the benchmark's closure, so a filtered-out sampler costs nothing.
fn bench_kernel<K, A>(c: &mut Criterion, setup: &Setup, name: &str, kernel: K, adaptation: A)
where
    K: Kernel<Target>,
    A: Adaptation<K>,
{
    let mut pending = Some((kernel, adaptation));
    let mut live: Option<Live<K>> = None;
    c.benchmark_group(format!("transition/k{K}"))
        .bench_function(name, |b| {
            let live = live.get_or_insert_with(|| {
                let (kernel, adaptation) = pending.take().expect("built once");
                let (mut kernel, x) = adapted(setup, kernel, adaptation);
                let mut density = Counted::new(setup.posterior.clone());
                let state = kernel.init_state(&mut density, &x).expect("initial state");
                density.density_evaluations = 0;
                density.gradient_evaluations = 0;
                Live {
                    kernel,
                    density,
                    state,
                    rng: chain_rng(DEFAULT_SEED, 1),
                    transitions: 0,
                    accepted: 0,
                    steps: 0,
                    block_accepted: Vec::new(),
                }
            });
            b.iter(|| {
                let info = live
                    .kernel
                    .step(&mut live.density, &mut live.state, &mut live.rng)
                    .expect("transition");
                live.transitions += 1;
                live.accepted += info.accepted as u64;
                live.steps += info.n_steps as u64;
                live.block_accepted
                    .resize(info.block_accepted.len().max(live.block_accepted.len()), 0);
                for (n, &a) in live.block_accepted.iter_mut().zip(&info.block_accepted) {
                    *n += a as u64;
                }
                black_box(info.accept_stat)
            })
        });
    if let Some(live) = live {
        let n = live.transitions.max(1) as f64;
        let blocks: Vec<String> = live
            .block_accepted
            .iter()
            .map(|&a| format!("{:.2}", a as f64 / n))
            .collect();
        eprintln!(
            "{name}: per transition {:.2} densities, {:.2} gradients, {:.2} steps; \
             accepted {:.2}{}",
            live.density.density_evaluations as f64 / n,
            live.density.gradient_evaluations as f64 / n,
            live.steps as f64 / n,
            live.accepted as f64 / n,
            if blocks.is_empty() {
                String::new()
            } else {
                format!(" (per block: {})", blocks.join(" "))
            },
        );
    }
}

fn bench_transitions(c: &mut Criterion) {
    let problem = Problem::paper(DEFAULT_SEED).expect("the paper's data");
    let mut posterior = problem
        .posterior(&ModelSettings::bm2(K))
        .expect("the paper's posterior builds");
    let map = map_estimate(&mut posterior).expect("the MAP is found");
    let d = posterior.dim();
    let setup = Setup {
        posterior,
        map_x: map.x.clone(),
        hessian: map.hessian.clone(),
    };
    let h = &setup.hessian;
    // As in `motorcal fit`: MALA's optimal step on a target the preconditioner whitens.
    let mala_step = 1.65 * (d as f64).powf(-1.0 / 3.0);
    let metric = |kind| Metric::from_precision(h, kind).expect("positive definite Hessian");

    bench_kernel(
        c,
        &setup,
        "metropolis",
        Metropolis::for_density(&setup.posterior),
        PyMc3Tuning::new(),
    );
    bench_kernel(
        c,
        &setup,
        "adaptive-metropolis",
        AdaptiveMetropolis::from_precision(h).expect("kernel"),
        HaarioAdaptation::default(),
    );
    bench_kernel(
        c,
        &setup,
        "mala",
        Mala::new(
            Metric::from_precision(h, MetricKind::Dense).expect("kernel"),
            mala_step,
        )
        .expect("kernel"),
        MalaAdaptation::step_size_only(),
    );
    bench_kernel(
        c,
        &setup,
        "fisher-mala",
        FisherMala::new(mala_step).expect("kernel"),
        FisherMalaAdaptation::default(),
    );
    for (name, kind) in [
        ("hmc-diag", MetricKind::Diagonal),
        ("hmc-dense", MetricKind::Dense),
    ] {
        bench_kernel(
            c,
            &setup,
            name,
            Hmc::new(metric(kind), HmcSettings::default()).expect("kernel"),
            WindowedAdaptation::default(),
        );
    }
    for (name, kind) in [
        ("nuts-diag", MetricKind::Diagonal),
        ("nuts-dense", MetricKind::Dense),
    ] {
        bench_kernel(
            c,
            &setup,
            name,
            Nuts::new(metric(kind), NutsSettings::default()).expect("kernel"),
            WindowedAdaptation::default(),
        );
    }
}

criterion_group!(benches, bench_transitions);
criterion_main!(benches);
