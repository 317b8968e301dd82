//! Hamiltonian dynamics shared by the HMC kernels (phase points, the leapfrog integrator,
//! Stan's step-size heuristic), and static HMC: a fixed integration time, then a Metropolis
//! correction.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::adapt::{AdaptationState, HamiltonianKernel};
use super::metric::Metric;
use super::{ChainRng, Info, Kernel, State, Transition};
use crate::density::{DensityError, LogDensity};

/// A point of phase space with what the integrator and the U-turn criterion reuse, so that a
/// leapfrog step evaluates the density once and allocates nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct PhasePoint {
    pub x: Vec<f64>,
    pub p: Vec<f64>,
    /// M⁻¹p.
    pub velocity: Vec<f64>,
    /// ∇ log π at `x`.
    pub gradient: Vec<f64>,
    pub log_density: f64,
    pub kinetic_energy: f64,
}

impl PhasePoint {
    pub fn new(dim: usize) -> Self {
        Self {
            x: vec![0.0; dim],
            p: vec![0.0; dim],
            velocity: vec![0.0; dim],
            gradient: vec![0.0; dim],
            log_density: f64::NAN,
            kinetic_energy: 0.0,
        }
    }

    pub fn dim(&self) -> usize {
        self.x.len()
    }

    /// Takes the position part from a chain state (which must carry its gradient).
    pub fn load_state(&mut self, state: &State) {
        self.x.copy_from_slice(&state.x);
        self.gradient.copy_from_slice(&state.gradient);
        self.log_density = state.log_density;
    }

    pub fn store_state(&self, state: &mut State) {
        state.x.copy_from_slice(&self.x);
        state.gradient.copy_from_slice(&self.gradient);
        state.log_density = self.log_density;
    }

    /// Sets the momentum and the quantities derived from it.
    pub fn set_momentum(&mut self, metric: &Metric, p: &[f64]) {
        self.p.copy_from_slice(p);
        self.update_kinetic(metric);
    }

    /// Draws a fresh momentum p ~ N(0, M).
    pub fn refresh_momentum(&mut self, metric: &Metric, rng: &mut ChaCha8Rng) {
        metric.sample_momentum(rng, &mut self.p);
        self.update_kinetic(metric);
    }

    fn update_kinetic(&mut self, metric: &Metric) {
        metric.velocity(&self.p, &mut self.velocity);
        self.kinetic_energy = Metric::kinetic_energy(&self.p, &self.velocity);
    }

    /// H = −log π(x) + ½pᵀM⁻¹p; +∞ rather than NaN where the density is undefined, so that
    /// every comparison treats such a point as infinitely improbable.
    pub fn energy(&self) -> f64 {
        let h = -self.log_density + self.kinetic_energy;
        if h.is_nan() { f64::INFINITY } else { h }
    }

    pub fn copy_from(&mut self, other: &PhasePoint) {
        self.x.copy_from_slice(&other.x);
        self.p.copy_from_slice(&other.p);
        self.velocity.copy_from_slice(&other.velocity);
        self.gradient.copy_from_slice(&other.gradient);
        self.log_density = other.log_density;
        self.kinetic_energy = other.kinetic_energy;
    }
}

/// One leapfrog step of signed size `step` (negative integrates backwards in time). On an
/// error the point is left half-updated: callers discard it.
pub fn leapfrog<P: LogDensity>(
    density: &mut P,
    metric: &Metric,
    z: &mut PhasePoint,
    step: f64,
) -> Result<(), DensityError> {
    let half = 0.5 * step;
    for (p, g) in z.p.iter_mut().zip(&z.gradient) {
        *p += half * g;
    }
    metric.velocity(&z.p, &mut z.velocity);
    for (x, v) in z.x.iter_mut().zip(&z.velocity) {
        *x += step * v;
    }
    z.log_density = density.log_density_and_gradient(&z.x, &mut z.gradient)?;
    for (p, g) in z.p.iter_mut().zip(&z.gradient) {
        *p += half * g;
    }
    z.update_kinetic(metric);
    Ok(())
}

/// The energy after one leapfrog step: +∞ when the density fails recoverably (the step is then
/// as bad as a divergence), the error itself when it is fatal.
pub(crate) fn energy_after_leapfrog<P: LogDensity>(
    density: &mut P,
    metric: &Metric,
    z: &mut PhasePoint,
    step: f64,
) -> Result<f64, DensityError> {
    match leapfrog(density, metric, z, step) {
        Ok(()) => Ok(z.energy()),
        Err(e) if e.recoverable => Ok(f64::INFINITY),
        Err(e) => Err(e),
    }
}

/// Stan's heuristic for a first step size: from `step_size`, double (or halve) until the
/// acceptance probability of one leapfrog step from `state`, with a fresh momentum each time,
/// crosses 0.8. Gives dual averaging a starting point of the right order of magnitude.
pub(crate) fn find_reasonable_step_size<P: LogDensity>(
    density: &mut P,
    metric: &Metric,
    state: &State,
    step_size: f64,
    rng: &mut ChaCha8Rng,
    z: &mut PhasePoint,
) -> Result<f64, DensityError> {
    if !(step_size > 0.0 && step_size <= 1e7) {
        return Ok(step_size);
    }
    let log_target = 0.8f64.ln();
    let mut trial = |eps: f64, rng: &mut ChaCha8Rng| -> Result<f64, DensityError> {
        z.load_state(state);
        z.refresh_momentum(metric, rng);
        let h0 = z.energy();
        Ok(h0 - energy_after_leapfrog(density, metric, z, eps)?)
    };
    let mut eps = step_size;
    let grow = trial(eps, rng)? > log_target;
    loop {
        let delta = trial(eps, rng)?;
        if grow != (delta > log_target) {
            return Ok(eps);
        }
        eps = if grow { 2.0 * eps } else { 0.5 * eps };
        if eps > 1e7 {
            return Err(DensityError::fatal(
                "the step size grew past 1e7 while searching an initial value: is the posterior improper?",
            ));
        }
        if eps == 0.0 {
            return Err(DensityError::fatal(
                "no step size is small enough for one leapfrog step: is the density discontinuous?",
            ));
        }
    }
}

/// Settings of static HMC.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HmcSettings {
    /// Integration time T in the metric's units (a whitened target has unit scale); each
    /// transition takes ceil(T/ε) leapfrog steps.
    pub integration_time: f64,
    /// Draws each transition's integration time uniformly from T·[1 − jitter, 1 + jitter].
    pub jitter: f64,
    /// An energy error above this marks the transition divergent.
    pub max_energy_error: f64,
    /// A cap on leapfrog steps per transition, so that a collapsing step size slows a chain
    /// down instead of hanging it.
    pub max_steps: u32,
}

impl Default for HmcSettings {
    /// A quarter period of a unit-scale Gaussian, jittered by half: on a target the metric
    /// whitens, consecutive draws are nearly uncorrelated. (Stan's default 2π is a full
    /// period, which brings a Gaussian back where it started; the jitter breaks such
    /// resonances in the directions the metric does not whiten.)
    fn default() -> Self {
        Self {
            integration_time: std::f64::consts::FRAC_PI_2,
            jitter: 0.5,
            max_energy_error: 1000.0,
            max_steps: 1024,
        }
    }
}

impl HmcSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.integration_time > 0.0 && self.integration_time.is_finite()) {
            return Err(format!(
                "the integration time must be positive, got {}",
                self.integration_time
            ));
        }
        if !(0.0..1.0).contains(&self.jitter) {
            return Err(format!(
                "the integration-time jitter must be in [0, 1), got {}",
                self.jitter
            ));
        }
        if !(self.max_energy_error > 0.0) {
            return Err(format!(
                "the divergence threshold must be positive, got {}",
                self.max_energy_error
            ));
        }
        if self.max_steps == 0 {
            return Err("the leapfrog step cap must be at least 1".into());
        }
        Ok(())
    }
}

/// Static HMC with a Euclidean metric.
#[derive(Clone, Debug)]
pub struct Hmc {
    settings: HmcSettings,
    step_size: f64,
    metric: Metric,
    search_pending: bool,
    start: PhasePoint,
    z: PhasePoint,
}

impl Hmc {
    /// A kernel whose step size is still unknown: Stan's heuristic searches one before the
    /// first transition, from ε = 1.
    pub fn new(metric: Metric, settings: HmcSettings) -> Result<Self, String> {
        settings.validate()?;
        let d = metric.dim();
        Ok(Self {
            settings,
            step_size: 1.0,
            metric,
            search_pending: true,
            start: PhasePoint::new(d),
            z: PhasePoint::new(d),
        })
    }

    /// A kernel tuned earlier (e.g. reloaded with `--load-adaptation`): no search.
    pub fn from_adaptation(state: &AdaptationState, settings: HmcSettings) -> Result<Self, String> {
        Ok(Self::new(state.metric.clone(), settings)?.with_step_size(state.step_size))
    }

    /// Fixes the step size (no initial search).
    pub fn with_step_size(mut self, step_size: f64) -> Self {
        self.step_size = step_size;
        self.search_pending = false;
        self
    }

    pub fn settings(&self) -> &HmcSettings {
        &self.settings
    }
}

impl HamiltonianKernel for Hmc {
    fn step_size(&self) -> f64 {
        self.step_size
    }
    fn step_size_mut(&mut self) -> &mut f64 {
        &mut self.step_size
    }
    fn metric(&self) -> &Metric {
        &self.metric
    }
    fn metric_mut(&mut self) -> &mut Metric {
        &mut self.metric
    }
    fn search_pending_mut(&mut self) -> &mut bool {
        &mut self.search_pending
    }
}

/// Checks that the kernel's metric fits the chain and runs a requested step-size search:
/// what every Hamiltonian transition does first.
pub(crate) fn prepare_transition<P: LogDensity>(
    density: &mut P,
    metric: &Metric,
    step_size: &mut f64,
    search_pending: &mut bool,
    state: &State,
    rng: &mut ChaCha8Rng,
    scratch: &mut PhasePoint,
) -> Result<(), DensityError> {
    if metric.dim() != state.x.len() || state.gradient.len() != state.x.len() {
        return Err(DensityError::fatal(format!(
            "a {}-dimensional metric cannot move a {}-dimensional state with a {}-long gradient",
            metric.dim(),
            state.x.len(),
            state.gradient.len()
        )));
    }
    if *search_pending {
        *step_size = find_reasonable_step_size(density, metric, state, *step_size, rng, scratch)?;
        *search_pending = false;
    }
    Ok(())
}

impl<P: LogDensity> Kernel<P> for Hmc {
    fn name(&self) -> String {
        format!("hmc-{}", self.metric.kind().suffix())
    }

    fn uses_gradient(&self) -> bool {
        true
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        prepare_transition(
            density,
            &self.metric,
            &mut self.step_size,
            &mut self.search_pending,
            state,
            rng,
            &mut self.z,
        )?;
        let eps = self.step_size;
        let s = &self.settings;
        let time = s.integration_time * (1.0 + s.jitter * (2.0 * rng.random::<f64>() - 1.0));
        let n_steps = ((time / eps).ceil().max(1.0)).min(s.max_steps as f64) as u32;

        self.start.load_state(state);
        self.start.refresh_momentum(&self.metric, rng);
        let h0 = self.start.energy();
        self.z.copy_from(&self.start);
        let mut h = h0;
        let mut taken = 0;
        while taken < n_steps {
            h = energy_after_leapfrog(density, &self.metric, &mut self.z, eps)?;
            taken += 1;
            if h - h0 > s.max_energy_error {
                break;
            }
        }
        let divergent = !(h - h0 <= s.max_energy_error);
        let accept_stat = if divergent {
            0.0
        } else {
            (h0 - h).exp().min(1.0)
        };
        let accepted = !divergent && rng.random::<f64>() < accept_stat;
        if accepted {
            self.z.store_state(state);
        }
        Ok(Info {
            accept_stat,
            accepted,
            divergent,
            step_size: eps,
            tree_depth: 0,
            n_steps: taken,
            energy: if accepted { h } else { h0 },
            block_accepted: Vec::new(),
        })
    }
}
