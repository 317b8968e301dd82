//! The driver: warm-up then sampling for any kernel and adaptation, one chain or several in
//! parallel, with per-chain random streams so that draws do not depend on the thread count.

use std::borrow::BorrowMut;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::clock::Stopwatch;
use super::{Adaptation, Info, Kernel, PhaseCost, State};
use crate::density::{Counted, DensityError, LogDensity};

/// How long a chain runs and what it keeps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChainSettings {
    /// Warm-up (tuning) transitions, discarded.
    pub warmup: usize,
    /// Transitions after warm-up.
    pub draws: usize,
    /// Keep only the last `keep` of the draws (the paper's protocol discards an early part of
    /// the post-tuning draws too); all when `None`.
    pub keep: Option<usize>,
}

impl Default for ChainSettings {
    fn default() -> Self {
        Self {
            warmup: 1000,
            draws: 1000,
            keep: None,
        }
    }
}

impl ChainSettings {
    pub fn validate(&self) -> Result<(), String> {
        if self.draws == 0 {
            return Err("the number of draws must be at least 1".into());
        }
        if let Some(keep) = self.keep
            && (keep == 0 || keep > self.draws)
        {
            return Err(format!("cannot keep {keep} draws of {} drawn", self.draws));
        }
        Ok(())
    }

    pub fn kept(&self) -> usize {
        self.keep.unwrap_or(self.draws)
    }
}

/// The sampler columns of one kept draw (CmdStan's `lp__` … `energy__`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DrawRecord {
    pub lp: f64,
    pub accept_stat: f64,
    pub step_size: f64,
    pub tree_depth: u32,
    pub n_steps: u32,
    pub divergent: bool,
    pub energy: f64,
    /// Importance sampling's normalised (smoothed) weight of the proposal this draw copies;
    /// `None` for the Markov chains, whose draws all weigh the same.
    pub weight: Option<f64>,
}

impl DrawRecord {
    /// The columns of the transition that left the chain at `state`.
    fn of(state: &State, info: &Info) -> Self {
        Self {
            lp: state.log_density,
            accept_stat: info.accept_stat,
            step_size: info.step_size,
            tree_depth: info.tree_depth,
            n_steps: info.n_steps,
            divergent: info.divergent,
            energy: info.energy,
            weight: None,
        }
    }
}

/// Everything a chain produced.
#[derive(Clone, Debug, Serialize)]
pub struct ChainOutput {
    pub chain: usize,
    pub sampler: String,
    /// Names of the reported (constrained) quantities.
    pub names: Vec<String>,
    /// Kept draws, constrained: `draws[i][j]` is quantity j at kept draw i.
    pub draws: Vec<Vec<f64>>,
    /// Kept draws in the sampler's unconstrained coordinates.
    pub unconstrained: Vec<Vec<f64>>,
    pub records: Vec<DrawRecord>,
    /// Warm-up (with the initial point's evaluation) and sampling (all draws, kept or not):
    /// wall time, CPU time of the thread that ran the chain, and evaluations.
    pub warmup: PhaseCost,
    pub sampling: PhaseCost,
    pub uses_gradient: bool,
    pub divergences: usize,
    /// Mean accept_stat over the sampling phase.
    pub mean_accept_stat: f64,
    /// The step size (or proposal scale) the kernel ended with.
    pub final_step_size: f64,
    /// Every warm-up draw (constrained) and its sampler columns, when the run's
    /// [`RunControl::save_warmup`] asked for them; empty otherwise.
    #[serde(skip)]
    pub warmup_draws: Vec<Vec<f64>>,
    #[serde(skip)]
    pub warmup_records: Vec<DrawRecord>,
}

impl ChainOutput {
    /// Draws of quantity `j` over the kept draws.
    pub fn column(&self, j: usize) -> Vec<f64> {
        self.draws.iter().map(|d| d[j]).collect()
    }
}

/// Runs one chain: `settings.warmup` transitions with adaptation, then `settings.draws`
/// with the kernel frozen.
#[allow(clippy::too_many_arguments)]
pub fn run_chain<P, K, A>(
    density: P,
    kernel: K,
    adaptation: A,
    init: &[f64],
    settings: &ChainSettings,
    rng: &mut ChaCha8Rng,
    chain: usize,
    progress: Option<&ProgressBar>,
) -> Result<(ChainOutput, K), DensityError>
where
    P: LogDensity,
    K: Kernel<Counted<P>>,
    A: Adaptation<K>,
{
    let chain_run = ChainRun {
        init,
        settings,
        chain,
        progress,
        control: RunControl::default(),
    };
    run_chain_until(density, kernel, adaptation, rng, chain_run)
}

/// The message of a run stopped by its stop flag.
pub const STOPPED: &str = "stopped on request";

/// The message of a chain that spent [`RunControl::work_budget`].
pub const BUDGET_SPENT: &str = "a chain spent its work budget";

/// What a caller asks of a run beside its settings: a flag that stops it, whether the
/// warm-up's draws are kept too, a count of transitions, and the work a chain may spend. None
/// changes a draw; the flag and the budget may end the run.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunControl<'a> {
    /// Checked between transitions: once set, the run ends with the fatal error [`STOPPED`].
    pub stop: Option<&'a AtomicBool>,
    /// Keep every warm-up draw in [`ChainOutput::warmup_draws`] and `warmup_records`.
    pub save_warmup: bool,
    /// Counts every chain's transitions, warm-up and sampling, for a caller's own progress
    /// display (the Python bindings draw theirs from it).
    pub transitions: Option<&'a AtomicUsize>,
    /// The work each chain may spend, warm-up and sampling together ([`Counted::work`]:
    /// gradients plus the integrator's right-hand sides), checked between transitions: a
    /// chain past it ends with the fatal error [`BUDGET_SPENT`]. In the integrator's work, not
    /// gradients alone, because a stiff corner of parameter space makes each gradient many
    /// times dearer; in counts, not time, so that whether a run ends early is the same on
    /// every machine and thread count.
    pub work_budget: Option<u64>,
}

/// One chain's place in a run.
#[derive(Clone, Copy)]
struct ChainRun<'a> {
    init: &'a [f64],
    settings: &'a ChainSettings,
    chain: usize,
    progress: Option<&'a ProgressBar>,
    control: RunControl<'a>,
}

/// [`run_chain`] under a [`RunControl`]: its warm-up, then its sampling, on the same thread.
fn run_chain_until<P, K, A>(
    density: P,
    kernel: K,
    adaptation: A,
    rng: &mut ChaCha8Rng,
    run: ChainRun<'_>,
) -> Result<(ChainOutput, K), DensityError>
where
    P: LogDensity,
    K: Kernel<Counted<P>>,
    A: Adaptation<K>,
{
    warm_up(density, kernel, adaptation, rng, run)?.sample()
}

/// Ends a run whose stop flag is set, or a chain past its work budget.
fn check<P: LogDensity>(
    control: &RunControl<'_>,
    density: &Counted<P>,
) -> Result<(), DensityError> {
    if control
        .stop
        .is_some_and(|flag| flag.load(Ordering::Relaxed))
    {
        return Err(DensityError::fatal(STOPPED));
    }
    if control
        .work_budget
        .is_some_and(|budget| density.work() >= budget)
    {
        return Err(DensityError::fatal(BUDGET_SPENT));
    }
    Ok(())
}

/// A chain at the end of its warm-up, its kernel adapted and frozen, before its first draw:
/// what [`warm_up_chains`] hands back so that a caller can judge the warm-up of every chain
/// before any of them spends its draws. `R` is its random stream, owned or borrowed.
pub struct WarmChain<'a, P, K, R = ChaCha8Rng> {
    density: Counted<P>,
    kernel: K,
    state: State,
    rng: R,
    run: ChainRun<'a>,
    reporter: Reporter<'a>,
    names: Vec<String>,
    warmup: PhaseCost,
    warmup_draws: Vec<Vec<f64>>,
    warmup_records: Vec<DrawRecord>,
}

/// A chain's warm-up: the initial state, `settings.warmup` transitions with adaptation, then
/// the adaptation's final values.
fn warm_up<'a, P, K, A, R>(
    density: P,
    mut kernel: K,
    mut adaptation: A,
    mut rng: R,
    run: ChainRun<'a>,
) -> Result<WarmChain<'a, P, K, R>, DensityError>
where
    P: LogDensity,
    K: Kernel<Counted<P>>,
    A: Adaptation<K>,
    R: BorrowMut<ChaCha8Rng>,
{
    let ChainRun {
        settings,
        chain,
        progress,
        control,
        ..
    } = run;
    settings.validate().map_err(DensityError::fatal)?;
    // The warm-up's time includes the initial point's evaluation, as its counts do.
    let warmup_watch = Stopwatch::start();
    let mut density = Counted::new(density);
    let names = density.output_names();
    let mut state: State = kernel.init_state(&mut density, run.init)?;
    if !state.log_density.is_finite() {
        return Err(DensityError::fatal(format!(
            "chain {chain}: the initial point has zero density"
        )));
    }
    let total = settings.warmup + settings.draws;
    let reporter = Reporter::new(progress, total);

    let mut divergences_warmup = 0usize;
    let mut constrained = Vec::new();
    let (mut warmup_draws, mut warmup_records) = (Vec::new(), Vec::new());
    for iteration in 0..settings.warmup {
        check(&control, &density)?;
        let info = kernel.step(&mut density, &mut state, rng.borrow_mut())?;
        divergences_warmup += info.divergent as usize;
        if control.save_warmup {
            density.constrain(&state.x, &mut constrained);
            warmup_draws.push(constrained.clone());
            warmup_records.push(DrawRecord::of(&state, &info));
        }
        adaptation.observe(&mut kernel, &state, &info, iteration, settings.warmup);
        reporter.tick(iteration, &info, divergences_warmup, "warm-up");
        if let Some(count) = control.transitions {
            count.fetch_add(1, Ordering::Relaxed);
        }
    }
    adaptation.finish(&mut kernel);
    let warmup = PhaseCost::counted(warmup_watch.elapsed(), &density);
    Ok(WarmChain {
        density,
        kernel,
        state,
        rng,
        run,
        reporter,
        names,
        warmup,
        warmup_draws,
        warmup_records,
    })
}

impl<P, K, R> WarmChain<'_, P, K, R>
where
    P: LogDensity,
    K: Kernel<Counted<P>>,
    R: BorrowMut<ChaCha8Rng>,
{
    /// The kernel as warm-up left it.
    pub fn kernel(&self) -> &K {
        &self.kernel
    }

    /// What the warm-up cost, the initial point's evaluation included.
    pub fn warmup(&self) -> PhaseCost {
        self.warmup
    }

    /// The sampling: `settings.draws` transitions with the kernel frozen, the last
    /// `settings.kept()` of them kept.
    pub fn sample(self) -> Result<(ChainOutput, K), DensityError> {
        let WarmChain {
            mut density,
            mut kernel,
            mut state,
            mut rng,
            run,
            reporter,
            names,
            warmup,
            warmup_draws,
            warmup_records,
        } = self;
        let ChainRun {
            settings,
            chain,
            control,
            ..
        } = run;
        let first_kept = settings.draws - settings.kept();
        let mut draws = Vec::with_capacity(settings.kept());
        let mut unconstrained = Vec::with_capacity(settings.kept());
        let mut records = Vec::with_capacity(settings.kept());
        let mut constrained = Vec::new();
        let mut divergences = 0usize;
        let mut accept_sum = 0.0;
        let mut last_step_size = f64::NAN;
        let sampling_watch = Stopwatch::start();
        for i in 0..settings.draws {
            check(&control, &density)?;
            let info = kernel.step(&mut density, &mut state, rng.borrow_mut())?;
            divergences += info.divergent as usize;
            accept_sum += info.accept_stat;
            last_step_size = info.step_size;
            if i >= first_kept {
                density.constrain(&state.x, &mut constrained);
                draws.push(constrained.clone());
                unconstrained.push(state.x.clone());
                records.push(DrawRecord::of(&state, &info));
            }
            reporter.tick(settings.warmup + i, &info, divergences, "sampling");
            if let Some(count) = control.transitions {
                count.fetch_add(1, Ordering::Relaxed);
            }
        }
        let sampling = PhaseCost::counted(sampling_watch.elapsed(), &density).after(&warmup);
        reporter.finish(divergences);
        let output = ChainOutput {
            chain,
            sampler: kernel.name(),
            names,
            draws,
            unconstrained,
            records,
            warmup,
            sampling,
            uses_gradient: kernel.uses_gradient(),
            divergences,
            mean_accept_stat: accept_sum / settings.draws as f64,
            final_step_size: last_step_size,
            warmup_draws,
            warmup_records,
        };
        Ok((output, kernel))
    }
}

/// The random stream of chain `chain` under master seed `seed`: independent of which thread
/// runs the chain and of how many chains run.
pub fn chain_rng(seed: u64, chain: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(chain as u64 + 1);
    rng
}

/// Runs one chain per initial point in parallel on the current rayon pool. `make` builds the
/// density, kernel and adaptation of a chain from its index (each chain owns its density, so
/// caches and scratch space are never shared).
pub fn run_chains<P, K, A, F>(
    inits: &[Vec<f64>],
    settings: &ChainSettings,
    seed: u64,
    make: F,
    progress: Option<&[ProgressBar]>,
) -> Result<Vec<(ChainOutput, K)>, DensityError>
where
    P: LogDensity,
    K: Kernel<Counted<P>> + Send,
    A: Adaptation<K>,
    F: Fn(usize) -> Result<(P, K, A), DensityError> + Sync,
{
    run_chains_until(inits, settings, seed, make, progress, RunControl::default())
}

/// [`run_chains`] under a [`RunControl`]: stopped soon after its flag is set (every chain
/// checks it between transitions), keeping the warm-up's draws if asked.
pub fn run_chains_until<P, K, A, F>(
    inits: &[Vec<f64>],
    settings: &ChainSettings,
    seed: u64,
    make: F,
    progress: Option<&[ProgressBar]>,
    control: RunControl<'_>,
) -> Result<Vec<(ChainOutput, K)>, DensityError>
where
    P: LogDensity,
    K: Kernel<Counted<P>> + Send,
    A: Adaptation<K>,
    F: Fn(usize) -> Result<(P, K, A), DensityError> + Sync,
{
    inits
        .par_iter()
        .enumerate()
        .map(|(chain, init)| {
            let (density, kernel, adaptation) = make(chain)?;
            let mut rng = chain_rng(seed, chain);
            let bar = progress.and_then(|bars| bars.get(chain));
            let chain_run = ChainRun {
                init,
                settings,
                chain,
                progress: bar,
                control,
            };
            run_chain_until(density, kernel, adaptation, &mut rng, chain_run)
        })
        .collect()
}

/// The first half of [`run_chains_until`]: every chain's warm-up in parallel, each on its own
/// stream, stopped at the end of warm-up. [`sample_chains`] then draws exactly what
/// [`run_chains_until`] would have: the split moves no draw, it lets a caller look at every
/// adapted kernel first and spend no draws on a run it would not trust.
pub fn warm_up_chains<'a, P, K, A, F>(
    inits: &'a [Vec<f64>],
    settings: &'a ChainSettings,
    seed: u64,
    make: F,
    progress: Option<&'a [ProgressBar]>,
    control: RunControl<'a>,
) -> Result<Vec<WarmChain<'a, P, K>>, DensityError>
where
    P: LogDensity + Send,
    K: Kernel<Counted<P>> + Send,
    A: Adaptation<K>,
    F: Fn(usize) -> Result<(P, K, A), DensityError> + Sync,
{
    inits
        .par_iter()
        .enumerate()
        .map(|(chain, init)| {
            let (density, kernel, adaptation) = make(chain)?;
            let chain_run = ChainRun {
                init,
                settings,
                chain,
                progress: progress.and_then(|bars| bars.get(chain)),
                control,
            };
            warm_up(
                density,
                kernel,
                adaptation,
                chain_rng(seed, chain),
                chain_run,
            )
        })
        .collect()
}

/// The second half of [`run_chains_until`]: every warmed-up chain's sampling, in parallel.
pub fn sample_chains<P, K>(
    chains: Vec<WarmChain<'_, P, K>>,
) -> Result<Vec<(ChainOutput, K)>, DensityError>
where
    P: LogDensity + Send,
    K: Kernel<Counted<P>> + Send,
{
    chains.into_par_iter().map(WarmChain::sample).collect()
}

/// Updates a progress bar at most ~10 times a second, with the chain's health in the message.
struct Reporter<'a> {
    bar: Option<&'a ProgressBar>,
    last: std::cell::Cell<Instant>,
    accepted: std::cell::Cell<(u64, u64)>,
}

impl<'a> Reporter<'a> {
    fn new(bar: Option<&'a ProgressBar>, total: usize) -> Self {
        if let Some(b) = bar {
            b.set_length(total as u64);
            b.set_position(0);
        }
        Self {
            bar,
            last: std::cell::Cell::new(Instant::now()),
            accepted: std::cell::Cell::new((0, 0)),
        }
    }

    fn tick(&self, iteration: usize, info: &Info, divergences: usize, phase: &str) {
        let Some(bar) = self.bar else { return };
        let (acc, n) = self.accepted.get();
        self.accepted
            .set((acc + (info.accept_stat * 1000.0) as u64, n + 1));
        if self.last.get().elapsed() < Duration::from_millis(100) {
            return;
        }
        self.last.set(Instant::now());
        let (acc, n) = self.accepted.get();
        bar.set_position(iteration as u64 + 1);
        bar.set_message(format!(
            "{phase}  accept {:.2}  step {:.2e}  divergences {divergences}",
            acc as f64 / 1000.0 / n.max(1) as f64,
            info.step_size
        ));
    }

    fn finish(&self, divergences: usize) {
        if let Some(bar) = self.bar {
            let (acc, n) = self.accepted.get();
            bar.set_position(bar.length().unwrap_or(0));
            bar.finish_with_message(format!(
                "done  accept {:.2}  divergences {divergences}",
                acc as f64 / 1000.0 / n.max(1) as f64
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::mala::{Mala, MalaAdaptation};
    use crate::sampler::metric::{Metric, MetricKind};
    use crate::sampler::targets::Gaussian;

    #[test]
    fn a_run_split_at_the_end_of_warm_up_draws_what_a_run_in_one_piece_does() {
        let target = Gaussian::correlated(3, 0.5, 10.0);
        let inits = vec![vec![0.1; 3], vec![-0.2; 3], vec![0.3; 3]];
        let settings = ChainSettings {
            warmup: 50,
            draws: 40,
            keep: Some(30),
        };
        let make = |_| {
            let kernel = Mala::new(Metric::identity(3, MetricKind::Diagonal), 0.5).unwrap();
            Ok((target.clone(), kernel, MalaAdaptation::step_size_only()))
        };
        let whole = run_chains(&inits, &settings, 8, make, None).unwrap();
        let control = RunControl::default();
        let warm = warm_up_chains(&inits, &settings, 8, make, None, control).unwrap();
        let counts = |c: PhaseCost| (c.density_evaluations, c.gradient_evaluations);
        assert_eq!(counts(warm[1].warmup()), counts(whole[1].0.warmup));
        let split = sample_chains(warm).unwrap();
        for ((a, _), (b, _)) in whole.iter().zip(&split) {
            assert_eq!(a.draws, b.draws);
            assert_eq!(a.records, b.records);
            assert_eq!(
                a.sampling.density_evaluations,
                b.sampling.density_evaluations
            );
        }
    }
}
