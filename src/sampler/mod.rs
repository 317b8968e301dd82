//! MCMC: transition kernels, their adaptation, and one driver that runs warm-up and sampling
//! for every sampler, so that all of them are counted, stored and diagnosed the same way.
//!
//! A kernel is a pure transition `State → State` with an [`Info`] about what it did; an
//! adaptation watches the `Info`s during warm-up and retunes the kernel's parameters, then
//! freezes them. The driver knows neither's internals.

pub mod adapt;
pub mod adaptive_metropolis;
pub mod clock;
pub mod collapsed;
pub mod cost;
pub mod driver;
pub mod fisher_mala;
pub mod hamiltonian;
pub mod hmc;
pub mod importance;
pub mod independence;
pub mod langevin;
pub mod mala;
pub mod metric;
pub mod metropolis;
pub mod nuts;
pub mod proposal;
pub mod targets;
pub mod welford;

pub use cost::PhaseCost;
pub use driver::{
    BUDGET_SPENT, ChainOutput, ChainSettings, DrawRecord, RunControl, STOPPED, WarmChain,
    run_chain, run_chains, run_chains_until, sample_chains, warm_up_chains,
};

use rand_chacha::ChaCha8Rng;

use crate::density::{DensityError, LogDensity};

/// Where a chain is: position, log density there, and its gradient when the kernel uses one
/// (empty otherwise).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub x: Vec<f64>,
    pub log_density: f64,
    pub gradient: Vec<f64>,
}

/// What one transition did: the columns of CmdStan's output and what adaptation needs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Info {
    /// Mean Metropolis acceptance probability of the transition (for NUTS, averaged over the
    /// tree as in Stan).
    pub accept_stat: f64,
    /// Whether the state moved.
    pub accepted: bool,
    pub divergent: bool,
    pub step_size: f64,
    pub tree_depth: u32,
    /// Leapfrog steps (or proposals, for Metropolis sweeps) in this transition.
    pub n_steps: u32,
    /// The Hamiltonian at the new state (−log density for gradient-free kernels).
    pub energy: f64,
    /// Per-block acceptance for variable-at-a-time kernels (empty otherwise).
    pub block_accepted: Vec<bool>,
}

impl Info {
    /// The record of a kernel that makes one proposal per transition (MALA, Fisher-MALA,
    /// adaptive Metropolis): no tree, one step, energy −log π at the state it ends in.
    pub fn single_proposal(
        accept_stat: f64,
        accepted: bool,
        divergent: bool,
        step_size: f64,
        log_density: f64,
    ) -> Self {
        Self {
            accept_stat,
            accepted,
            divergent,
            step_size,
            tree_depth: 0,
            n_steps: 1,
            energy: -log_density,
            block_accepted: Vec::new(),
        }
    }
}

/// The random stream of one chain.
pub type ChainRng = ChaCha8Rng;

/// What a transition returns: its record, or the fatal error that ends the chain.
pub type Transition = Result<Info, DensityError>;

/// A transition kernel. `step` must leave `state` a valid state of the chain even when the
/// density fails recoverably (the proposal is then rejected).
pub trait Kernel<P: LogDensity> {
    /// A short name for tables and file names (e.g. "nuts-dense").
    fn name(&self) -> String;
    /// Whether the kernel evaluates gradients (ESS is then reported per gradient evaluation).
    fn uses_gradient(&self) -> bool;
    /// Builds the state at `x` (evaluating the density, and the gradient if the kernel needs it).
    fn init_state(&mut self, density: &mut P, x: &[f64]) -> Result<State, DensityError> {
        if self.uses_gradient() {
            let mut gradient = vec![0.0; x.len()];
            let log_density = density.log_density_and_gradient(x, &mut gradient)?;
            Ok(State {
                x: x.to_vec(),
                log_density,
                gradient,
            })
        } else {
            Ok(State {
                x: x.to_vec(),
                log_density: density.log_density(x)?,
                gradient: Vec::new(),
            })
        }
    }
    /// One transition. A fatal density error aborts the chain.
    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition;
}

/// Tunes a kernel during warm-up from the transitions it observes; frozen afterwards.
pub trait Adaptation<K> {
    /// Called after every warm-up transition `iteration` (0-based) of `n_warmup`.
    fn observe(
        &mut self,
        kernel: &mut K,
        state: &State,
        info: &Info,
        iteration: usize,
        n_warmup: usize,
    );
    /// Called once when warm-up ends: set the final tuned values.
    fn finish(&mut self, kernel: &mut K);
}

/// An adaptation that never changes anything (a fixed kernel, or one reloaded from disk).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoAdaptation;

impl<K> Adaptation<K> for NoAdaptation {
    fn observe(&mut self, _: &mut K, _: &State, _: &Info, _: usize, _: usize) {}
    fn finish(&mut self, _: &mut K) {}
}

/// The log density at a random-walk proposal: a recoverable failure counts as zero density, so
/// the proposal is rejected like one outside the support.
pub(crate) fn proposal_log_density<P: LogDensity>(
    density: &mut P,
    x: &[f64],
) -> Result<f64, DensityError> {
    match density.log_density(x) {
        Ok(lp) => Ok(lp),
        Err(e) if e.recoverable => Ok(f64::NEG_INFINITY),
        Err(e) => Err(e),
    }
}

/// The Metropolis decision for a symmetric proposal: the acceptance probability and whether
/// the proposal is taken. −∞ (outside the support, or a failed solve) and NaN give
/// probability 0; a uniform is drawn only when the decision is not already certain.
pub(crate) fn random_walk_decision(
    proposed: f64,
    current: f64,
    rng: &mut ChaCha8Rng,
) -> (f64, bool) {
    use rand::RngExt;
    let log_ratio = proposed - current;
    let accept_prob = if log_ratio >= 0.0 {
        1.0
    } else if log_ratio.is_nan() {
        0.0
    } else {
        log_ratio.exp()
    };
    let accepted = accept_prob >= 1.0 || (accept_prob > 0.0 && rng.random::<f64>() < accept_prob);
    (accept_prob, accepted)
}
