//! Hamiltonian dynamics, shared by every Hamiltonian kernel: phase points, the leapfrog
//! integrator, Stan's step-size heuristic, and the step size and metric a kernel moves with
//! ([`Dynamics`]). HMC and NUTS keep only their trajectory rules.

use rand_chacha::ChaCha8Rng;

use super::State;
use super::adapt::AdaptationState;
use super::metric::Metric;
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

/// Checks that the kernel's metric fits the chain and runs a requested step-size search:
/// what every Hamiltonian transition does first.
fn prepare_transition<P: LogDensity>(
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

/// The step size and metric a Hamiltonian kernel moves with, and whether Stan's step-size
/// heuristic still has to run before the next transition.
#[derive(Clone, Debug)]
pub struct Dynamics {
    pub step_size: f64,
    pub metric: Metric,
    /// Whether the step-size search runs before the next transition (it needs the density and
    /// the random stream, which only a transition has); cleared once it ran.
    pub search_pending: bool,
}

impl Dynamics {
    /// Step size still unknown: the search starts from ε = 1 before the first transition.
    pub fn new(metric: Metric) -> Self {
        Self {
            step_size: 1.0,
            metric,
            search_pending: true,
        }
    }

    /// What an earlier warm-up tuned (e.g. reloaded with `--load-adaptation`): no search.
    pub fn tuned(state: &AdaptationState) -> Self {
        Self {
            step_size: state.step_size,
            metric: state.metric.clone(),
            search_pending: false,
        }
    }

    /// Checks the state's dimensions and runs a pending step-size search: what every
    /// Hamiltonian transition does first.
    pub(crate) fn prepare<P: LogDensity>(
        &mut self,
        density: &mut P,
        state: &State,
        rng: &mut ChaCha8Rng,
        scratch: &mut PhasePoint,
    ) -> Result<(), DensityError> {
        prepare_transition(
            density,
            &self.metric,
            &mut self.step_size,
            &mut self.search_pending,
            state,
            rng,
            scratch,
        )
    }
}

/// A kernel whose step size and Euclidean metric warm-up can tune.
pub trait HamiltonianKernel {
    fn dynamics(&self) -> &Dynamics;
    fn dynamics_mut(&mut self) -> &mut Dynamics;

    fn step_size(&self) -> f64 {
        self.dynamics().step_size
    }
    fn step_size_mut(&mut self) -> &mut f64 {
        &mut self.dynamics_mut().step_size
    }
    fn metric(&self) -> &Metric {
        &self.dynamics().metric
    }
    fn metric_mut(&mut self) -> &mut Metric {
        &mut self.dynamics_mut().metric
    }
    fn search_pending_mut(&mut self) -> &mut bool {
        &mut self.dynamics_mut().search_pending
    }
    /// Fixes the step size (no initial search).
    fn with_step_size(mut self, step_size: f64) -> Self
    where
        Self: Sized,
    {
        let d = self.dynamics_mut();
        d.step_size = step_size;
        d.search_pending = false;
        self
    }
}
