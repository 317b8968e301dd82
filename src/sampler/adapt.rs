//! Warm-up of the Hamiltonian kernels as in Stan: dual averaging of the step size (Hoffman &
//! Gelman 2014, §3.2) and a windowed estimate of the metric from the chain's own draws, with
//! dual averaging restarted after each window. Works on any kernel that exposes its step size
//! and metric ([`HamiltonianKernel`]), so HMC and NUTS share it.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::metric::{Metric, MetricKind};
use super::{Adaptation, Info, State};

pub use super::hamiltonian::HamiltonianKernel;
// Where the adaptations have always found their estimator.
pub use super::welford::{Welford, WelfordForm};

/// What warm-up tuned: enough to resume sampling later without warm-up (with
/// [`NoAdaptation`](super::NoAdaptation)) or to warm-start another run.
///
/// Save it as TOML ([`AdaptationState::to_toml`]) for a bit-exact round trip: `toml` parses
/// floats exactly, while `serde_json` without its `float_roundtrip` feature may change the last
/// bit of a number, and with it every draw after.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "AdaptationStateRepr")]
pub struct AdaptationState {
    pub step_size: f64,
    pub metric: Metric,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AdaptationStateRepr {
    step_size: f64,
    metric: Metric,
}

impl TryFrom<AdaptationStateRepr> for AdaptationState {
    type Error = String;

    fn try_from(repr: AdaptationStateRepr) -> Result<Self, String> {
        if !(repr.step_size > 0.0 && repr.step_size.is_finite()) {
            return Err(format!(
                "step_size must be positive and finite, got {}",
                repr.step_size
            ));
        }
        Ok(Self {
            step_size: repr.step_size,
            metric: repr.metric,
        })
    }
}

impl AdaptationState {
    /// The kernel's current tuning.
    pub fn of<K: HamiltonianKernel>(kernel: &K) -> Self {
        Self {
            step_size: kernel.step_size(),
            metric: kernel.metric().clone(),
        }
    }

    /// Gives a kernel this tuning (cancelling any pending step-size search).
    pub fn apply_to<K: HamiltonianKernel>(&self, kernel: &mut K) -> Result<(), String> {
        if kernel.metric().dim() != self.metric.dim() {
            return Err(format!(
                "the saved metric is {}-dimensional, the kernel's {}-dimensional",
                self.metric.dim(),
                kernel.metric().dim()
            ));
        }
        *kernel.step_size_mut() = self.step_size;
        *kernel.metric_mut() = self.metric.clone();
        *kernel.search_pending_mut() = false;
        Ok(())
    }

    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("an adaptation state always serialises to TOML")
    }

    pub fn from_toml(text: &str) -> Result<Self, String> {
        toml::from_str(text).map_err(|e| e.message().to_string())
    }
}

/// Dual averaging of log ε towards a target mean acceptance statistic.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DualAveragingSettings {
    /// δ, the target of the mean `accept_stat`.
    pub target_accept: f64,
    /// γ: how strongly log ε is pulled towards μ = log(10 ε₀).
    pub gamma: f64,
    /// t₀: damps the first iterations.
    pub t0: f64,
    /// κ: how fast the averaged iterate forgets early ones.
    pub kappa: f64,
}

impl Default for DualAveragingSettings {
    fn default() -> Self {
        Self {
            target_accept: 0.8,
            gamma: 0.05,
            t0: 10.0,
            kappa: 0.75,
        }
    }
}

impl DualAveragingSettings {
    /// Settings for single-proposal kernels (MALA and its manifold version): their
    /// acceptance statistic is noisier than a whole trajectory's, the iterates scatter more in
    /// log ε, and because acceptance is concave in log ε near the target the frozen average
    /// then accepts too often (0.61–0.66 for 0.574 on an 8-d Gaussian with Stan's γ = 0.05);
    /// γ = 0.1 halves that bias.
    pub fn single_proposal(target_accept: f64) -> Self {
        Self {
            target_accept,
            gamma: 0.1,
            ..Self::default()
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        if !(self.target_accept > 0.0 && self.target_accept < 1.0) {
            return Err(format!(
                "the target acceptance must be in (0, 1), got {}",
                self.target_accept
            ));
        }
        if !(self.gamma > 0.0 && self.t0 >= 0.0 && self.kappa > 0.0 && self.kappa <= 1.0) {
            return Err(format!(
                "dual averaging needs γ > 0, t0 ≥ 0 and κ in (0, 1], got γ = {}, t0 = {}, κ = {}",
                self.gamma, self.t0, self.kappa
            ));
        }
        Ok(())
    }
}

const LOG_STEP_BOUND: f64 = 300.0;

/// The dual-averaging iteration: the current iterate x is what the next transitions use, the
/// average x̄ what sampling uses.
#[derive(Clone, Debug, PartialEq)]
pub struct DualAveraging {
    settings: DualAveragingSettings,
    mu: f64,
    counter: f64,
    s_bar: f64,
    x: f64,
    x_bar: f64,
}

impl DualAveraging {
    /// Starts at ε₀ with μ = log(10 ε₀): a bias towards larger steps, which are cheaper.
    pub fn new(settings: &DualAveragingSettings, initial_step_size: f64) -> Self {
        let mut da = Self {
            settings: settings.clone(),
            mu: 0.0,
            counter: 0.0,
            s_bar: 0.0,
            x: 0.0,
            x_bar: 0.0,
        };
        da.restart(initial_step_size);
        da
    }

    /// Starts afresh from `step_size`, forgetting the averages (after the metric or the
    /// preconditioner changed).
    pub fn restart(&mut self, step_size: f64) {
        self.mu = (10.0 * step_size).ln();
        self.counter = 0.0;
        self.s_bar = 0.0;
        self.x = step_size.ln();
        self.x_bar = step_size.ln();
    }

    /// Learns from one transition's `accept_stat`; returns the step size for the next one.
    pub fn update(&mut self, accept_stat: f64) -> f64 {
        let s = &self.settings;
        // A NaN statistic says as little as a zero one: shrink.
        let accept = if accept_stat.is_nan() {
            0.0
        } else {
            accept_stat.clamp(0.0, 1.0)
        };
        self.counter += 1.0;
        let eta = 1.0 / (self.counter + s.t0);
        self.s_bar = (1.0 - eta) * self.s_bar + eta * (s.target_accept - accept);
        // Bounded so that a long run of rejections cannot drive ε to exactly 0 (or ∞).
        self.x = (self.mu - self.s_bar * self.counter.sqrt() / s.gamma)
            .clamp(-LOG_STEP_BOUND, LOG_STEP_BOUND);
        let weight = self.counter.powf(-s.kappa);
        self.x_bar = (1.0 - weight) * self.x_bar + weight * self.x;
        self.x.exp()
    }

    /// The step size of the latest iterate.
    pub fn step_size(&self) -> f64 {
        self.x.exp()
    }

    /// The averaged step size, for sampling.
    pub fn final_step_size(&self) -> f64 {
        self.x_bar.exp()
    }
}

/// Step-size adaptation only (for a metric known in advance, e.g. from the MAP Hessian).
#[derive(Clone, Debug)]
pub struct StepSizeAdaptation {
    settings: DualAveragingSettings,
    dual: Option<DualAveraging>,
    restart_pending: bool,
}

impl StepSizeAdaptation {
    pub fn new(settings: DualAveragingSettings) -> Result<Self, String> {
        settings.validate()?;
        Ok(Self {
            settings,
            dual: None,
            restart_pending: true,
        })
    }

    /// Restarts dual averaging at the step size of the next transition (after the kernel has
    /// searched a new one for a new metric).
    fn restart(&mut self) {
        self.restart_pending = true;
    }

    fn observe_step<K: HamiltonianKernel>(&mut self, kernel: &mut K, info: &Info) {
        if self.restart_pending || self.dual.is_none() {
            self.dual = Some(DualAveraging::new(&self.settings, info.step_size));
            self.restart_pending = false;
        }
        let dual = self.dual.as_mut().expect("just set");
        *kernel.step_size_mut() = dual.update(info.accept_stat);
    }

    fn finish_step<K: HamiltonianKernel>(&mut self, kernel: &mut K) {
        if let Some(dual) = &self.dual {
            *kernel.step_size_mut() = dual.final_step_size();
        }
        // Sampling must run with the averaged step size, not a fresh search's.
        *kernel.search_pending_mut() = false;
    }
}

impl Default for StepSizeAdaptation {
    fn default() -> Self {
        Self::new(DualAveragingSettings::default()).expect("the defaults are valid")
    }
}

impl<K: HamiltonianKernel> Adaptation<K> for StepSizeAdaptation {
    fn observe(&mut self, kernel: &mut K, _: &State, info: &Info, _: usize, _: usize) {
        self.observe_step(kernel, info);
    }

    fn finish(&mut self, kernel: &mut K) {
        self.finish_step(kernel);
    }
}

/// Stan's warm-up schedule: an initial buffer where only the step size adapts (the chain
/// travels to the typical set), then metric windows of doubling length, each estimating the
/// metric afresh from its own draws, then a terminal buffer where the step size adapts to the
/// last metric.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WarmupSchedule {
    /// The warm-up iterations whose draws each metric estimate uses; the metric is updated
    /// after the last iteration of each.
    pub windows: Vec<Range<usize>>,
}

impl WarmupSchedule {
    /// Stan's windows for `n_warmup` iterations: windows of `base_window`, 2·`base_window`, …
    /// after `init_buffer` iterations, the last one stretched to end `term_buffer` iterations
    /// before the end of warm-up when the next doubling would not fit. With fewer than
    /// init + base + term iterations the buffers shrink to 15 % and 10 % of warm-up and one
    /// window takes the rest; below 20 iterations the metric is not adapted. As in Stan, the
    /// first window is never stretched, so a short remainder can make a short last window
    /// (160 iterations: windows of 25 and 10).
    pub fn stan(
        n_warmup: usize,
        init_buffer: usize,
        term_buffer: usize,
        base_window: usize,
    ) -> Self {
        if n_warmup < 20 {
            return Self {
                windows: Vec::new(),
            };
        }
        let (init_buffer, term_buffer, base_window) =
            if init_buffer + base_window + term_buffer > n_warmup {
                let init = (0.15 * n_warmup as f64) as usize;
                let term = (0.1 * n_warmup as f64) as usize;
                (init, term, n_warmup - init - term)
            } else {
                (init_buffer, term_buffer, base_window)
            };
        Self {
            windows: doubling_windows(init_buffer, n_warmup - term_buffer, base_window, false),
        }
    }

    pub(crate) fn collects(&self, iteration: usize) -> bool {
        match (self.windows.first(), self.windows.last()) {
            (Some(first), Some(last)) => first.start <= iteration && iteration < last.end,
            _ => false,
        }
    }

    pub(crate) fn ends_window(&self, iteration: usize) -> bool {
        self.windows.iter().any(|w| w.end == iteration + 1)
    }
}

/// Settings of Stan's warm-up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AdaptationSettings {
    pub step_size: DualAveragingSettings,
    /// Estimate the metric in windows (otherwise only the step size adapts).
    pub adapt_metric: bool,
    pub init_buffer: usize,
    pub term_buffer: usize,
    pub base_window: usize,
}

impl Default for AdaptationSettings {
    fn default() -> Self {
        Self {
            step_size: DualAveragingSettings::default(),
            adapt_metric: true,
            init_buffer: 75,
            term_buffer: 50,
            base_window: 25,
        }
    }
}

impl AdaptationSettings {
    pub fn validate(&self) -> Result<(), String> {
        self.step_size.validate()?;
        if self.base_window == 0 {
            return Err("the first metric window must be at least 1 iteration".into());
        }
        Ok(())
    }
}

/// Stan's warm-up: dual averaging throughout, and the metric (diagonal or dense, whichever the
/// kernel has) re-estimated at the end of each window of [`WarmupSchedule::stan`] from that
/// window's draws, shrunk toward the metric in use: (n/(n+5))·Σ̂ + (5/(n+5))·M⁻¹ (Stan shrinks
/// toward 10⁻³·I instead; see the estimator for why not here). After each update
/// the kernel searches a new initial step size and dual averaging restarts from it.
///
/// The metric starts from whatever the kernel has (the identity, or e.g.
/// [`Metric::from_precision`] of the MAP Hessian); the windows replace it.
#[derive(Clone, Debug)]
pub struct WindowedAdaptation {
    settings: AdaptationSettings,
    step: StepSizeAdaptation,
    schedule: Option<WarmupSchedule>,
    estimator: Option<CovarianceEstimator>,
}

impl WindowedAdaptation {
    pub fn new(settings: AdaptationSettings) -> Result<Self, String> {
        settings.validate()?;
        Ok(Self {
            step: StepSizeAdaptation::new(settings.step_size.clone())?,
            settings,
            schedule: None,
            estimator: None,
        })
    }
}

impl Default for WindowedAdaptation {
    fn default() -> Self {
        Self::new(AdaptationSettings::default()).expect("the defaults are valid")
    }
}

impl<K: HamiltonianKernel> Adaptation<K> for WindowedAdaptation {
    fn observe(
        &mut self,
        kernel: &mut K,
        state: &State,
        info: &Info,
        iteration: usize,
        n_warmup: usize,
    ) {
        self.step.observe_step(kernel, info);
        if !self.settings.adapt_metric {
            return;
        }
        let s = &self.settings;
        let schedule = self.schedule.get_or_insert_with(|| {
            WarmupSchedule::stan(n_warmup, s.init_buffer, s.term_buffer, s.base_window)
        });
        if schedule.collects(iteration) {
            let metric = kernel.metric();
            self.estimator
                .get_or_insert_with(|| CovarianceEstimator::new(metric.dim(), metric.kind()))
                .add(&state.x);
        }
        if schedule.ends_window(iteration) {
            if let Some(estimator) = &mut self.estimator {
                // A failed estimate (non-finite draws) keeps the previous metric rather than
                // stopping warm-up: the next window gets another chance.
                if let Ok(metric) = estimator.regularised_metric(kernel.metric()) {
                    *kernel.metric_mut() = metric;
                }
                estimator.reset();
            }
            *kernel.search_pending_mut() = true;
            self.step.restart();
        }
    }

    fn finish(&mut self, kernel: &mut K) {
        self.step.finish_step(kernel);
    }
}

/// Doubling windows `[a, b)` between `start` and `end`: the first `first_size` long, each
/// next one twice the last, and a window whose successor would not fit stretched to `end`
/// (Stan's rule). Stan never stretches the first window (`stretch_first = false`); MALA's
/// fractional schedule does.
pub fn doubling_windows(
    start: usize,
    end: usize,
    first_size: usize,
    stretch_first: bool,
) -> Vec<Range<usize>> {
    let mut windows = Vec::new();
    let (mut a, mut size) = (start, first_size);
    while a < end {
        let mut b = (a + size).min(end);
        if (stretch_first || !windows.is_empty()) && b + 2 * size > end {
            b = end;
        }
        windows.push(a..b);
        a = b;
        size *= 2;
    }
    windows
}

/// The metric a Stan window estimates, regularised toward the metric in use.
#[derive(Clone, Debug)]
struct CovarianceEstimator {
    kind: MetricKind,
    welford: Welford,
}

impl CovarianceEstimator {
    fn new(dim: usize, kind: MetricKind) -> Self {
        Self {
            kind,
            welford: Welford::new(dim, kind == MetricKind::Dense, WelfordForm::DeviationAfter),
        }
    }

    fn reset(&mut self) {
        self.welford.reset();
    }

    fn add(&mut self, x: &[f64]) {
        self.welford.add(x);
    }

    /// Stan's shrinkage, n/(n+5)·Σ̂ + 5/(n+5)·(prior), with the prior the metric in use
    /// rather than Stan's 1e-3·I: Stan's ridge assumes unit scales, and on the motor
    /// posterior (Var R ≈ 1e-8) it would inflate R's variance a thousandfold and force a step
    /// size thirty times too small. Shrinking toward the current metric is scale-free, and a
    /// short window (fewer draws than dimensions) cannot make a good warm start singular.
    fn regularised_metric(&self, current: &Metric) -> Result<Metric, String> {
        if self.welford.count() < 2 {
            return Err("a window needs at least two draws".into());
        }
        let n = self.welford.count() as f64;
        let weight = n / ((n + 5.0) * (n - 1.0));
        let prior_weight = 5.0 / (n + 5.0);
        let prior = current.inverse_mass_matrix();
        match self.kind {
            MetricKind::Diagonal => Metric::diagonal(
                self.welford
                    .m2_diagonal()
                    .iter()
                    .enumerate()
                    .map(|(i, m)| weight * m + prior_weight * prior[(i, i)])
                    .collect(),
            ),
            MetricKind::Dense => {
                // Welford's sum is symmetric up to rounding, which `Metric::dense` evens out.
                Metric::dense(self.welford.m2_matrix() * weight + prior * prior_weight)
            }
        }
    }
}
