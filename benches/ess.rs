//! Seconds per effective sample of NUTS (dense metric), MALA, Fisher-MALA and adaptive
//! Metropolis on BM2(K), K ∈ {0, 9, 20}, with the paper's data.
//!
//! **What criterion's "time" means here.** Not the time of one run: each criterion iteration
//! is a whole `run_sampler` run of 4 chains (`fit`'s defaults: warm-up and draws below, MAP
//! start with overdispersed initial points) on a single thread, and the value returned to
//! criterion is
//!
//! ```text
//!     (warm-up + sampling seconds, summed over the 4 chains) / min over parameters of bulk-ESS
//! ```
//!
//! i.e. the single-core cost of one effective sample of the worst-mixing parameter. Lower is
//! better, and medians compare directly across samplers and K (1/value is ESS per second of one
//! core). The MAP search and the initial points, the same for every sampler, are excluded: the
//! chains' own clocks are summed, not the wall time of `run_sampler`. Every iteration uses a
//! new seed (chains and initial points; the data stay the paper's), so the spread criterion
//! reports includes the run-to-run variability of the ESS estimate, not just timing noise. A
//! run whose minimum bulk-ESS is below 1 (or not finite) counts as one effective sample.
//!
//! After each benchmark a summary line is printed (medians over its runs): min bulk-ESS, max
//! R-hat, chain seconds, seconds per ESS counting the sampling phase only, and gradient (or,
//! for adaptive Metropolis, density) evaluations per effective sample, warm-up included.
//!
//! Chain lengths default to 1000 warm-up + 1000 draws per chain; override with the environment
//! variables `MOTORCAL_BENCH_WARMUP` and `MOTORCAL_BENCH_DRAWS`. Criterion's `sample_size` is
//! 10 with flat sampling (one run per sample when a run takes longer than
//! measurement-time / 10), so a benchmark costs about eleven runs.

use std::time::Duration;

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};

use motorcal::bayes::ModelSettings;
use motorcal::pipeline::{RunOutput, RunSettings, SamplerKind, run_sampler};
use motorcal::sampler::ChainSettings;
use motorcal::study::Problem;
use motorcal::synthetic::DEFAULT_SEED;

const DEGREES: [usize; 3] = [0, 9, 20];
const SAMPLERS: [SamplerKind; 4] = [
    SamplerKind::NutsDense,
    SamplerKind::Mala,
    SamplerKind::FisherMala,
    SamplerKind::AdaptiveMetropolis,
];
const CHAINS: usize = 4;

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// What one run contributed, for the printed summary.
struct RunStats {
    ess: f64,
    max_rhat: f64,
    chain_seconds: f64,
    sampling_seconds: f64,
    evaluations: f64,
}

impl RunStats {
    fn of(run: &RunOutput, uses_gradient: bool) -> Self {
        let chain_seconds = run
            .chains
            .iter()
            .map(|c| c.warmup.cpu_seconds + c.sampling.cpu_seconds)
            .sum();
        let sampling_seconds = run.chains.iter().map(|c| c.sampling.cpu_seconds).sum();
        let evaluations = run
            .chains
            .iter()
            .map(|c| {
                let n = if uses_gradient {
                    c.warmup.gradient_evaluations + c.sampling.gradient_evaluations
                } else {
                    c.warmup.density_evaluations + c.sampling.density_evaluations
                };
                n as f64
            })
            .sum();
        let ess = if run.min_ess_bulk.is_finite() {
            run.min_ess_bulk.max(1.0)
        } else {
            1.0
        };
        Self {
            ess,
            max_rhat: run.max_rhat,
            chain_seconds,
            sampling_seconds,
            evaluations,
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn bench_ess(c: &mut Criterion) {
    let chain = ChainSettings {
        warmup: env_usize("MOTORCAL_BENCH_WARMUP", 1000),
        draws: env_usize("MOTORCAL_BENCH_DRAWS", 1000),
        keep: None,
    };
    let problem = Problem::paper(DEFAULT_SEED).expect("the paper's data");
    for k in DEGREES {
        let posterior = problem
            .posterior(&ModelSettings::bm2(k))
            .expect("the paper's posterior builds");
        let mut group = c.benchmark_group(format!("ess/k{k}"));
        group.sampling_mode(SamplingMode::Flat);
        for sampler in SAMPLERS {
            let mut runs: Vec<RunStats> = Vec::new();
            let mut next_seed = DEFAULT_SEED;
            group.bench_function(sampler.name(), |b| {
                b.iter_custom(|iters| {
                    let mut per_ess = Duration::ZERO;
                    for _ in 0..iters {
                        let settings = RunSettings {
                            sampler,
                            chains: CHAINS,
                            chain: chain.clone(),
                            seed: next_seed,
                            threads: Some(1),
                            quiet: true,
                            ..RunSettings::default()
                        };
                        next_seed += 1;
                        let mut p = posterior.clone();
                        let run = run_sampler(&mut p, &settings, "bench").expect("the run");
                        let stats = RunStats::of(&run, sampler.uses_gradient());
                        per_ess += Duration::from_secs_f64(stats.chain_seconds / stats.ess);
                        runs.push(stats);
                    }
                    per_ess
                })
            });
            let pick = |f: fn(&RunStats) -> f64| median(runs.iter().map(f).collect());
            eprintln!(
                "ess/k{k}/{}: {} runs of {CHAINS}×({}+{}); median min bulk-ESS {:.0}, \
                 max R-hat {:.3}, chain seconds {:.2}, sampling-only s/ESS {:.2e}, \
                 {} per ESS {:.1}",
                sampler.name(),
                runs.len(),
                chain.warmup,
                chain.draws,
                pick(|r| r.ess),
                pick(|r| r.max_rhat),
                pick(|r| r.chain_seconds),
                pick(|r| r.sampling_seconds / r.ess),
                if sampler.uses_gradient() {
                    "gradients"
                } else {
                    "densities"
                },
                pick(|r| r.evaluations / r.ess),
            );
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(10));
    targets = bench_ess
}
criterion_main!(benches);
