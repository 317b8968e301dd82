//! Explicit Runge–Kutta integration generic over the number type.
//!
//! Step-size control and every branch look at real parts only, so an `f64` run and a dual-number
//! run take the same steps and the dual part is the exact derivative of the numerical solution.

mod dopri5;
mod exact_lag;
mod sampled;

pub use dopri5::{RHS_PER_STEP, solve};
pub use exact_lag::ExactLag;
pub use sampled::{HeldInputSystem, solve_sampled};

use serde::{Deserialize, Serialize};

/// A first-order system y' = f(t, y), piecewise smooth between breakpoints.
pub trait OdeSystem<D> {
    fn n_states(&self) -> usize;
    /// Sorted times at which f jumps. The integrator stops exactly on each and restarts, so that
    /// no step straddles a discontinuity.
    fn breakpoints(&self) -> &[f64];
    /// f on the `segment`-th interval between breakpoints (0 before the first).
    fn rhs(&self, t: f64, segment: usize, y: &[D], dy: &mut [D]);
    /// A discrete event applied to the state when the integrator reaches breakpoint `index`
    /// (e.g. a sampled controller); none by default.
    fn at_breakpoint(&self, _index: usize, _y: &mut [D]) {}
    /// States that lag another through τ·ẏ = x − y and feed nothing back (a sensor's filter):
    /// the integrator advances them in closed form from x's dense output over each step, so
    /// that a lag far faster than the dynamics does not bound the step. Their right-hand side
    /// must stay zero. Their zero error still counts in the error norm's mean, which loosens
    /// it by √(n/(n−1)): a lag on the reversal record takes 338 steps where the motor without
    /// it takes 344 (tests/dynamic_terms.rs). None by default.
    fn exact_lags(&self) -> Vec<ExactLag<D>> {
        Vec::new()
    }
}

/// Tolerances and limits of the integrator.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverSettings {
    pub rtol: f64,
    pub atol: f64,
    /// Steps (accepted or rejected) before giving up: a stiff corner of parameter space must
    /// reject a proposal, never hang a chain.
    pub max_steps: usize,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            atol: 1e-8,
            max_steps: 50_000,
        }
    }
}

impl SolverSettings {
    /// The tighter tolerance used to generate synthetic data.
    pub fn for_data_generation() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-10,
            ..Self::default()
        }
    }
}

/// What one solve cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SolverStats {
    pub accepted_steps: usize,
    pub rejected_steps: usize,
    pub rhs_evaluations: usize,
}

/// A numerical failure. All of them are recoverable: the parameters that caused it get zero
/// density, like a divergent trajectory.
#[derive(Clone, Debug, PartialEq)]
pub enum OdeError {
    TooManySteps { t: f64, max_steps: usize },
    StepSizeUnderflow { t: f64, h: f64 },
    NonFinite { t: f64 },
    BadOutputTimes(String),
}

impl std::fmt::Display for OdeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OdeError::TooManySteps { t, max_steps } => {
                write!(f, "integrator gave up after {max_steps} steps at t = {t}")
            }
            OdeError::StepSizeUnderflow { t, h } => {
                write!(f, "step size underflow (h = {h:e}) at t = {t}")
            }
            OdeError::NonFinite { t } => write!(f, "solution became non-finite at t = {t}"),
            OdeError::BadOutputTimes(msg) => write!(f, "bad output times: {msg}"),
        }
    }
}

impl std::error::Error for OdeError {}
