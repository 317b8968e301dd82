//! The fit pipeline, for any density with a gradient, a Fisher metric and a starting point:
//! MAP and its Laplace approximation, overdispersed initial points, chains in parallel with the
//! chosen sampler, diagnostics, draws to disk. `fit`, `reproduce`, `bench` (and any command that
//! needs "fit this model") are thin callers.

use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use nalgebra::DVector;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

use crate::density::{Counted, DensityError, FisherMetric, LogDensity, StartingPoint};
use crate::diagnostics::{ParameterSummary, summarize};
use crate::io::{CmdStanWriter, SamplerColumns};
use crate::optimize::{MapEstimate, MapSettings, find_map};
use crate::sampler::NoAdaptation;
use crate::sampler::adapt::{
    AdaptationState, DualAveragingSettings, HamiltonianKernel, StepSizeAdaptation,
    WindowedAdaptation,
};
use crate::sampler::adaptive_metropolis::{AdaptiveMetropolis, HaarioAdaptation};
use crate::sampler::clock::Stopwatch;
use crate::sampler::driver::chain_rng;
use crate::sampler::fisher_mala::{FisherMala, FisherMalaAdaptation};
use crate::sampler::hmc::{Hmc, HmcSettings};
use crate::sampler::mala::{Mala, MalaAdaptation};
use crate::sampler::metric::{Metric, MetricKind};
use crate::sampler::metropolis::{Metropolis, PyMc3Tuning};
use crate::sampler::nuts::{Nuts, NutsSettings};
use crate::sampler::{Adaptation, ChainOutput, Kernel, RunControl, run_chains_until};

use crate::error::{Error, InputError};

pub mod cost;
mod fallback;
mod importance;
mod independence;
pub mod settings;
pub use crate::sampler::PhaseCost;
pub use cost::{RunCost, ratio_2sf};
pub use importance::IS_SHAPE;
pub use settings::{
    LAPLACE_TARGET_ACCEPT, LAPLACE_WARMUP, MapSearch, MetricAdaptation, RunSettings, SamplerKind,
    default_warmup,
};

/// What the pipeline can fit: a log density with a gradient and a Gauss–Newton metric that
/// knows a sensible point to start a search from, and that chains can clone.
pub trait Fittable: FisherMetric + StartingPoint + Clone + Send + Sync {}
impl<P: FisherMetric + StartingPoint + Clone + Send + Sync> Fittable for P {}

/// The result of a run.
#[derive(Clone, Debug, Serialize)]
pub struct RunOutput {
    pub sampler: String,
    #[serde(skip)]
    pub chains: Vec<ChainOutput>,
    pub summaries: Vec<ParameterSummary>,
    pub max_rhat: f64,
    pub min_ess_bulk: f64,
    /// Wall time of the whole run: MAP, initial points, chains, diagnostics.
    pub wall_seconds: f64,
    /// The MAP search and the initial points drawn around it, on the calling thread.
    pub map: PhaseCost,
    /// Warm-up and sampling, each summed over chains, wall time and CPU time alike: the
    /// phases then add up to the chains' whole cost whatever the thread count (a maximum over
    /// chains would not, and with fewer threads than chains a chain's wall time includes
    /// waiting for a core, which its CPU time does not).
    pub warmup: PhaseCost,
    pub sampling: PhaseCost,
    pub divergences: usize,
    pub map_log_density: f64,
    pub log_evidence_laplace: f64,
    /// laplace-is, independence: the Pareto shape k̂ of the importance weights of their
    /// proposals (independence: of its warm-up's; `None` for a warm-up too short to judge and
    /// for the other samplers).
    pub khat: Option<f64>,
    /// laplace-is, independence: k̂ said the Laplace approximation cannot be trusted and NUTS
    /// drew instead.
    pub fell_back: bool,
    /// laplace-is: NUTS was to draw instead, but a chain spent the fallback's gradient budget
    /// ([`RunSettings::fallback_budget`]), and the importance sample with the lower k̂ stands:
    /// draws an approximation k̂ refused for weighing, kept because nothing better was had
    /// within the budget. Its phases do not count the stopped NUTS run (`wall_seconds` does).
    pub fallback_stopped: bool,
}

impl RunOutput {
    pub fn summary(&self, name: &str) -> Option<&ParameterSummary> {
        self.summaries.iter().find(|s| s.name == name)
    }
}

/// The MAP from the posterior's own starting point.
pub fn map_estimate<P: Fittable>(posterior: &mut P) -> Result<MapEstimate, Error> {
    map_estimate_with(posterior, &MapSettings::default())
}

/// As [`map_estimate`], by the search `settings`.
pub fn map_estimate_with<P: Fittable>(
    posterior: &mut P,
    settings: &MapSettings,
) -> Result<MapEstimate, Error> {
    let start = posterior.initial_point()?;
    Ok(find_map(posterior, &start, settings)?)
}

/// Initial points: the MAP plus N(0, (c²) H⁻¹) jitter, on a random stream of its own so the
/// samplers' streams are untouched. A jittered point with zero density is redrawn closer.
pub fn initial_points<P: LogDensity>(
    posterior: &mut P,
    map: &MapEstimate,
    chains: usize,
    dispersion: f64,
    seed: u64,
) -> Result<Vec<Vec<f64>>, Error> {
    let d = map.x.len();
    let (l_inv_t, _) = map.whitening().map_err(Error::Numerical)?;
    let mut inits = Vec::with_capacity(chains);
    for chain in 0..chains {
        let mut rng = chain_rng(seed ^ 0x1a17_0000, chain);
        let mut scale = dispersion;
        let point = loop {
            let z = DVector::from_iterator(d, (0..d).map(|_| StandardNormal.sample(&mut rng)));
            let dx = &l_inv_t * z * scale;
            let x: Vec<f64> = map.x.iter().zip(dx.iter()).map(|(a, b)| a + b).collect();
            match posterior.log_density(&x) {
                Ok(lp) if lp.is_finite() => break x,
                _ if scale > 1e-3 => scale *= 0.5,
                _ => break map.x.clone(),
            }
        };
        inits.push(point);
    }
    Ok(inits)
}

/// One progress bar per chain, or none when quiet.
pub fn progress_bars(
    chains: usize,
    label: &str,
    quiet: bool,
) -> Option<(MultiProgress, Vec<ProgressBar>)> {
    if quiet {
        return None;
    }
    let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr_with_hz(5));
    let style = ProgressStyle::with_template("{prefix:>24} [{bar:30}] {pos:>7}/{len:7} {msg}")
        .expect("valid template")
        .progress_chars("=> ");
    let bars = (0..chains)
        .map(|c| {
            let bar = multi.add(ProgressBar::new(1));
            bar.set_style(style.clone());
            bar.set_prefix(format!("{label} chain {}", c + 1));
            bar
        })
        .collect();
    Some((multi, bars))
}

/// Runs any kernel/adaptation pair on clones of the posterior from the given initial points.
pub fn execute<P, K, A, F>(
    posterior: &P,
    inits: &[Vec<f64>],
    settings: &RunSettings,
    label: &str,
    make: F,
) -> Result<Vec<(ChainOutput, K)>, Error>
where
    P: Fittable,
    K: Kernel<Counted<P>> + Send,
    A: Adaptation<K>,
    F: Fn(usize) -> Result<(K, A), DensityError> + Sync,
{
    let bars = progress_bars(inits.len(), label, settings.quiet);
    let work = || {
        run_chains_until(
            inits,
            &settings.chain,
            settings.seed,
            |c| {
                let (k, a) = make(c)?;
                Ok((posterior.clone(), k, a))
            },
            bars.as_ref().map(|(_, b)| b.as_slice()),
            run_control(settings),
        )
    };
    Ok(in_pool(settings.threads, work)??)
}

/// What the settings ask of the chains beside their length: the stop flag, the warm-up's
/// draws, the transition count, the work budget.
fn run_control(settings: &RunSettings) -> RunControl<'_> {
    RunControl {
        stop: settings.stop.as_deref(),
        save_warmup: settings.save_warmup,
        transitions: settings.transitions.as_deref(),
        work_budget: settings.work_budget,
    }
}

/// `work` on a pool of `threads` (rayon's global pool when `None`).
fn in_pool<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> Result<T, Error> {
    match threads {
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::setting("threads", n, e.to_string()))?
            .install(work)),
        None => Ok(work()),
    }
}

/// Diagnostics of every reported quantity over all chains.
pub fn summarize_chains(chains: &[ChainOutput]) -> Vec<ParameterSummary> {
    let Some(first) = chains.first() else {
        return Vec::new();
    };
    first
        .names
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let columns: Vec<Vec<f64>> = chains.iter().map(|c| c.column(j)).collect();
            summarize(name.clone(), &columns)
        })
        .collect()
}

/// Collects chain outputs into a run summary.
pub fn finish_run(
    sampler: &str,
    chains: Vec<ChainOutput>,
    map: &MapEstimate,
    started: Instant,
) -> RunOutput {
    let summaries = summarize_chains(&chains);
    let max_rhat = summaries
        .iter()
        .map(|s| s.rhat)
        .fold(f64::NEG_INFINITY, f64::max);
    let min_ess_bulk = summaries
        .iter()
        .map(|s| s.ess_bulk)
        .fold(f64::INFINITY, f64::min);
    RunOutput {
        sampler: sampler.to_string(),
        max_rhat,
        min_ess_bulk,
        wall_seconds: started.elapsed().as_secs_f64(),
        // The MAP is not a chain's: the caller that ran one fills it in.
        map: PhaseCost::default(),
        warmup: chains.iter().map(|c| c.warmup).sum(),
        sampling: chains.iter().map(|c| c.sampling).sum(),
        divergences: chains.iter().map(|c| c.divergences).sum(),
        map_log_density: map.log_density,
        log_evidence_laplace: map.log_evidence_laplace,
        khat: None,
        fell_back: false,
        fallback_stopped: false,
        summaries,
        chains,
    }
}

/// Runs `settings.sampler` on the posterior from overdispersed starts around the MAP.
pub fn run_sampler<P: Fittable>(
    posterior: &mut P,
    settings: &RunSettings,
    label: &str,
) -> Result<RunOutput, Error> {
    settings.validate()?;
    let started = Instant::now();
    let map_watch = Stopwatch::start();
    // The MAP on a counting copy: the same computation (the posterior's cache changes speed,
    // never values), with its evaluations counted toward the whole cost.
    let mut counted = Counted::new(posterior.clone());
    let map = map_estimate_with(&mut counted, &settings.map_search.settings())?;
    let inits = initial_points(
        &mut counted,
        &map,
        settings.chains,
        settings.init_dispersion,
        settings.seed,
    )?;
    let map_cost = PhaseCost::counted(map_watch.elapsed(), &counted);
    let label = format!("{label} {}", settings.sampler.name());
    match settings.sampler {
        SamplerKind::LaplaceIs | SamplerKind::CollapsedIs => {
            return importance::laplace_is(posterior, &map, map_cost, settings, &label, started);
        }
        SamplerKind::Independence => {
            return independence::independence(
                posterior, &map, map_cost, &inits, settings, &label, started,
            );
        }
        _ => {}
    }
    let chains = dispatch(posterior, &map, &inits, settings, &label)?;
    Ok(RunOutput {
        map: map_cost,
        ..finish_run(settings.sampler.name(), chains, &map, started)
    })
}

fn dispatch<P: Fittable>(
    posterior: &P,
    map: &MapEstimate,
    inits: &[Vec<f64>],
    settings: &RunSettings,
    label: &str,
) -> Result<Vec<ChainOutput>, Error> {
    let fatal = DensityError::fatal;
    match settings.sampler {
        SamplerKind::Metropolis => Ok(outputs(execute(posterior, inits, settings, label, |_| {
            Ok((Metropolis::for_density(posterior), PyMc3Tuning::new()))
        })?)),
        SamplerKind::AdaptiveMetropolis => {
            Ok(outputs(execute(posterior, inits, settings, label, |_| {
                // Started from the Laplace covariance: the posterior's scales span ten orders of
                // magnitude, which an isotropic start would spend the warm-up discovering.
                let kernel = AdaptiveMetropolis::from_precision(&map.hessian).map_err(fatal)?;
                Ok((kernel, HaarioAdaptation::default()))
            })?))
        }
        SamplerKind::Mala => Ok(outputs(execute(posterior, inits, settings, label, |_| {
            let preconditioner = lower_triangle_covariance(&map.hessian).map_err(fatal)?;
            // With the Laplace covariance as preconditioner the target is nearly whitened, where
            // MALA's optimal step is about 1.65·d^(−1/3).
            let step = 1.65 * (map.x.len() as f64).powf(-1.0 / 3.0);
            Ok((
                Mala::new(preconditioner, step).map_err(fatal)?,
                MalaAdaptation::step_size_only(),
            ))
        })?)),
        SamplerKind::LaplaceIs | SamplerKind::CollapsedIs | SamplerKind::Independence => {
            Err(Error::invalid(
                "the Laplace samplers judge their proposals by k̂: run_sampler sends them to their own paths",
            ))
        }
        SamplerKind::FisherMala => Ok(outputs(execute(posterior, inits, settings, label, |_| {
            let step = 1.65 * (map.x.len() as f64).powf(-1.0 / 3.0);
            Ok((
                FisherMala::new(step).map_err(fatal)?,
                FisherMalaAdaptation::default(),
            ))
        })?)),
        SamplerKind::HmcDiag | SamplerKind::HmcDense => hamiltonian(
            posterior,
            map,
            inits,
            settings,
            label,
            |loaded, metric| match loaded {
                Some(state) => Hmc::from_adaptation(state, HmcSettings::default()),
                None => Hmc::new(metric, HmcSettings::default()),
            },
        ),
        SamplerKind::NutsDiag | SamplerKind::NutsDense => hamiltonian(
            posterior,
            map,
            inits,
            settings,
            label,
            |loaded, metric| match loaded {
                Some(state) => Nuts::from_adaptation(state, NutsSettings::default()),
                None => Nuts::new(metric, NutsSettings::default()),
            },
        ),
    }
}

/// HMC or NUTS: the metric warm-started from the MAP (dense or its diagonal, by the sampler's
/// name) or a reloaded adaptation, tuned as the settings say unless reloaded, and the
/// adaptation saved.
fn hamiltonian<P, K, B>(
    posterior: &P,
    map: &MapEstimate,
    inits: &[Vec<f64>],
    settings: &RunSettings,
    label: &str,
    build: B,
) -> Result<Vec<ChainOutput>, Error>
where
    P: Fittable,
    K: Kernel<Counted<P>> + HamiltonianKernel + Send,
    B: Fn(Option<&AdaptationState>, Metric) -> Result<K, String> + Sync,
{
    let kind = if matches!(
        settings.sampler,
        SamplerKind::HmcDense | SamplerKind::NutsDense
    ) {
        MetricKind::Dense
    } else {
        MetricKind::Diagonal
    };
    let loaded = load_adaptation(settings)?;
    let runs = execute(posterior, inits, settings, label, |_| {
        let kernel =
            build(loaded.as_ref(), warm_metric(map, kind)?).map_err(DensityError::fatal)?;
        Ok((
            kernel,
            hamiltonian_adaptation(loaded.is_some(), settings.metric_adaptation),
        ))
    })?;
    save_adaptation(settings, runs.first().map(|(_, k)| AdaptationState::of(k)))?;
    Ok(outputs(runs))
}

fn outputs<K>(runs: Vec<(ChainOutput, K)>) -> Vec<ChainOutput> {
    runs.into_iter().map(|(o, _)| o).collect()
}

/// MALA's preconditioner: the Laplace covariance H⁻¹ with its lower triangle mirrored into
/// the upper. MALA factors the lower triangle (as it always has), and the mirrored matrix is
/// exactly symmetric, so the metric keeps it as it is; `Metric::from_precision` would average
/// the two triangles, which differ in the last bit, and move every MALA draw.
fn lower_triangle_covariance(hessian: &nalgebra::DMatrix<f64>) -> Result<Metric, String> {
    let mut covariance = hessian
        .clone()
        .cholesky()
        .ok_or("the Hessian is not positive definite")?
        .inverse();
    for j in 0..covariance.ncols() {
        for i in 0..j {
            covariance[(i, j)] = covariance[(j, i)];
        }
    }
    Metric::dense(covariance)
}

/// The metric a Hamiltonian sampler starts from: the Laplace covariance (dense) or its
/// diagonal, kept or refined by Stan's windows as [`MetricAdaptation`] says.
fn warm_metric(map: &MapEstimate, kind: MetricKind) -> Result<Metric, DensityError> {
    Metric::from_precision(&map.hessian, kind).map_err(DensityError::fatal)
}

/// The step size alone, Stan's windows, or nothing for a reloaded adaptation.
fn hamiltonian_adaptation(loaded: bool, metric: MetricAdaptation) -> HamiltonianAdaptation {
    match (loaded, metric) {
        (true, _) => HamiltonianAdaptation::Fixed(NoAdaptation),
        (false, MetricAdaptation::Laplace) => HamiltonianAdaptation::StepSize(
            StepSizeAdaptation::new(DualAveragingSettings {
                target_accept: LAPLACE_TARGET_ACCEPT,
                ..DualAveragingSettings::default()
            })
            .expect("a valid target"),
        ),
        (false, MetricAdaptation::Windows) => HamiltonianAdaptation::Windowed(Box::default()),
    }
}

/// The Hamiltonian kernels' adaptation, chosen at run time.
enum HamiltonianAdaptation {
    Fixed(NoAdaptation),
    StepSize(StepSizeAdaptation),
    Windowed(Box<WindowedAdaptation>),
}

impl<K: HamiltonianKernel> Adaptation<K> for HamiltonianAdaptation {
    fn observe(
        &mut self,
        kernel: &mut K,
        state: &crate::sampler::State,
        info: &crate::sampler::Info,
        i: usize,
        n: usize,
    ) {
        match self {
            HamiltonianAdaptation::Fixed(a) => {
                Adaptation::<K>::observe(a, kernel, state, info, i, n)
            }
            HamiltonianAdaptation::StepSize(a) => a.observe(kernel, state, info, i, n),
            HamiltonianAdaptation::Windowed(a) => a.observe(kernel, state, info, i, n),
        }
    }
    fn finish(&mut self, kernel: &mut K) {
        match self {
            HamiltonianAdaptation::Fixed(a) => Adaptation::<K>::finish(a, kernel),
            HamiltonianAdaptation::StepSize(a) => a.finish(kernel),
            HamiltonianAdaptation::Windowed(a) => a.finish(kernel),
        }
    }
}

fn load_adaptation(settings: &RunSettings) -> Result<Option<AdaptationState>, Error> {
    let Some(path) = &settings.load_adaptation else {
        return Ok(None);
    };
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Input(InputError::new(path, format!("cannot read: {e}"))))?;
    AdaptationState::from_toml(&text)
        .map(Some)
        .map_err(|e| Error::Input(InputError::new(path, e)))
}

fn save_adaptation(settings: &RunSettings, state: Option<AdaptationState>) -> Result<(), Error> {
    if let (Some(path), Some(state)) = (&settings.save_adaptation, state) {
        crate::io::write_atomically(path, state.to_toml().as_bytes())?;
    }
    Ok(())
}

/// Writes each chain's draws in CmdStan's CSV layout with the run's provenance.
pub fn write_draws(
    dir: &Path,
    prefix: &str,
    run: &RunOutput,
    metadata: &[(String, String)],
) -> Result<Vec<PathBuf>, Error> {
    let mut paths = Vec::new();
    for chain in &run.chains {
        let path = dir.join(format!(
            "{prefix}-{}-chain{}.csv",
            run.sampler,
            chain.chain + 1
        ));
        let mut meta = metadata.to_vec();
        meta.push(("sampler".into(), run.sampler.clone()));
        meta.push(("chain".into(), (chain.chain + 1).to_string()));
        let weighted = chain.records.iter().any(|r| r.weight.is_some());
        let mut writer = CmdStanWriter::create_weighted(&path, &meta, &chain.names, weighted)?;
        for (draw, record) in chain.draws.iter().zip(&chain.records) {
            let columns = SamplerColumns {
                lp: record.lp,
                accept_stat: record.accept_stat,
                stepsize: record.step_size,
                treedepth: record.tree_depth,
                n_leapfrog: record.n_steps as u64,
                divergent: record.divergent,
                energy: record.energy,
                weight: record.weight,
            };
            writer.write_draw(&columns, draw)?;
        }
        writer.finish()?;
        paths.push(path);
    }
    Ok(paths)
}

/// The mean of every chain's unconstrained draws.
pub fn posterior_mean(run: &RunOutput) -> Vec<f64> {
    let all: Vec<&Vec<f64>> = run
        .chains
        .iter()
        .flat_map(|c| c.unconstrained.iter())
        .collect();
    let d = all.first().map_or(0, |x| x.len());
    let mut mean = vec![0.0; d];
    for x in &all {
        for (m, v) in mean.iter_mut().zip(x.iter()) {
            *m += v / all.len() as f64;
        }
    }
    mean
}
