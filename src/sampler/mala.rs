//! Preconditioned MALA: one Langevin step with a fixed preconditioner M⁻¹, corrected by
//! Metropolis–Hastings with the asymmetric proposal densities,
//!
//!   x' = x + (ε²/2) M⁻¹ ∇log π(x) + ε L ξ,   M⁻¹ = L Lᵀ,   ξ ~ N(0, I).
//!
//! The adaptation tunes ε by dual averaging toward the acceptance rate that is optimal for
//! MALA (0.574, Roberts & Rosenthal 1998) and, optionally, re-estimates M⁻¹ from warm-up
//! draws in Stan's doubling windows. The dual-averaging controller is shared with the
//! Fisher-metric kernel.

use nalgebra::DMatrix;
use rand::RngExt;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use super::adapt::doubling_windows;
pub use super::adapt::{DualAveraging, DualAveragingSettings};
use super::langevin::{
    Evaluated, check_state, cholesky_in_place, evaluate, lower_mul, lower_tr_mul, metropolis,
};
use super::metric::Metric;
use super::welford::{Welford, WelfordForm};
use super::{Adaptation, ChainRng, Info, Kernel, State, Transition};
use crate::density::LogDensity;

/// A square root L of M⁻¹ (L Lᵀ = M⁻¹), lower triangular when dense.
#[derive(Clone, Debug)]
enum Factor {
    Diagonal(Vec<f64>),
    Dense(DMatrix<f64>),
}

impl Factor {
    /// MALA factors M⁻¹ itself rather than taking the metric's factor: its proposals were
    /// pinned with this factorisation, and a different one rounds differently.
    fn new(metric: &Metric) -> Result<Self, String> {
        match metric {
            Metric::Diagonal(v) => {
                if let Some((i, bad)) = v
                    .iter()
                    .enumerate()
                    .find(|(_, v)| !(v.is_finite() && **v > 0.0))
                {
                    return Err(format!(
                        "inverse mass {bad} at coordinate {i} is not positive and finite"
                    ));
                }
                Ok(Self::Diagonal(v.iter().map(|v| v.sqrt()).collect()))
            }
            Metric::Dense(dense) => {
                let m = dense.inverse_mass();
                if !m.is_square() {
                    return Err(format!(
                        "the inverse mass matrix is {}×{}",
                        m.nrows(),
                        m.ncols()
                    ));
                }
                let mut l = m.clone();
                if !cholesky_in_place(&mut l) {
                    return Err("the inverse mass matrix is not positive definite".into());
                }
                Ok(Self::Dense(l))
            }
        }
    }

    /// out = L v
    fn mul(&self, v: &[f64], out: &mut [f64]) {
        match self {
            Self::Diagonal(s) => {
                for ((o, s), v) in out.iter_mut().zip(s).zip(v) {
                    *o = s * v;
                }
            }
            Self::Dense(l) => lower_mul(l, v, out),
        }
    }

    /// out = Lᵀ v
    fn tr_mul(&self, v: &[f64], out: &mut [f64]) {
        match self {
            Self::Diagonal(s) => {
                for ((o, s), v) in out.iter_mut().zip(s).zip(v) {
                    *o = s * v;
                }
            }
            Self::Dense(l) => lower_tr_mul(l, v, out),
        }
    }
}

/// Preconditioned MALA with a fixed M⁻¹ (fixed during sampling; an adaptation may replace it
/// during warm-up).
#[derive(Clone, Debug)]
pub struct Mala {
    step_size: f64,
    /// M⁻¹, the proposal covariance up to ε².
    preconditioner: Metric,
    factor: Factor,
    noise: Vec<f64>,
    /// Lᵀ∇log π at the current state and at the proposal: the drift in whitened coordinates.
    whitened_gradient: Vec<f64>,
    whitened_gradient_new: Vec<f64>,
    scratch: Vec<f64>,
    proposal: Vec<f64>,
    proposal_gradient: Vec<f64>,
    failures: u64,
}

impl Mala {
    /// A kernel with inverse mass matrix `preconditioner` and step size `step_size` (in the
    /// preconditioner's units: about 1 when M⁻¹ is the posterior covariance in a few
    /// dimensions, shrinking like d^(-1/6)).
    pub fn new(preconditioner: Metric, step_size: f64) -> Result<Self, String> {
        if !(step_size > 0.0 && step_size.is_finite()) {
            return Err(format!(
                "the step size must be positive and finite, not {step_size}"
            ));
        }
        let factor = Factor::new(&preconditioner)?;
        let d = preconditioner.dim();
        Ok(Self {
            step_size,
            preconditioner,
            factor,
            noise: vec![0.0; d],
            whitened_gradient: vec![0.0; d],
            whitened_gradient_new: vec![0.0; d],
            scratch: vec![0.0; d],
            proposal: vec![0.0; d],
            proposal_gradient: vec![0.0; d],
            failures: 0,
        })
    }

    pub fn dim(&self) -> usize {
        self.preconditioner.dim()
    }

    pub fn step_size(&self) -> f64 {
        self.step_size
    }

    pub fn set_step_size(&mut self, step_size: f64) {
        self.step_size = step_size;
    }

    pub fn preconditioner(&self) -> &Metric {
        &self.preconditioner
    }

    /// Replaces M⁻¹ (same dimension); the kernel is unchanged on error.
    pub fn set_preconditioner(&mut self, preconditioner: Metric) -> Result<(), String> {
        if preconditioner.dim() != self.dim() {
            return Err(format!(
                "a preconditioner of dimension {} for a kernel of dimension {}",
                preconditioner.dim(),
                self.dim()
            ));
        }
        self.factor = Factor::new(&preconditioner)?;
        self.preconditioner = preconditioner;
        Ok(())
    }

    /// Proposals rejected because the density failed recoverably (or was not finite inside
    /// its support); each is also reported as divergent.
    pub fn failures(&self) -> u64 {
        self.failures
    }
}

impl<P: LogDensity> Kernel<P> for Mala {
    fn name(&self) -> String {
        "mala".into()
    }

    fn uses_gradient(&self) -> bool {
        true
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        check_state(state, self.dim())?;
        let eps = self.step_size;
        self.factor
            .tr_mul(&state.gradient, &mut self.whitened_gradient);
        for z in &mut self.noise {
            *z = rng.sample(StandardNormal);
        }
        // In whitened coordinates the move is (ε²/2) Lᵀg + ε ξ; L maps it back.
        for ((s, u), z) in self
            .scratch
            .iter_mut()
            .zip(&self.whitened_gradient)
            .zip(&self.noise)
        {
            *s = 0.5 * eps * eps * u + eps * z;
        }
        self.factor.mul(&self.scratch, &mut self.proposal);
        for (p, x) in self.proposal.iter_mut().zip(&state.x) {
            *p += x;
        }

        let mut lp_new = f64::NEG_INFINITY;
        let (log_ratio, failed) =
            match evaluate(density, &self.proposal, &mut self.proposal_gradient)? {
                Evaluated::Finite(lp) => {
                    lp_new = lp;
                    self.factor
                        .tr_mul(&self.proposal_gradient, &mut self.whitened_gradient_new);
                    // The reverse move's whitened residual L⁻¹(x − μ(x')) / ε equals
                    // −ξ − (ε/2) Lᵀ(g + g'), because L⁻¹M⁻¹ = Lᵀ: no triangular solve needed.
                    let mut forward = 0.0;
                    let mut reverse = 0.0;
                    for ((z, u), u_new) in self
                        .noise
                        .iter()
                        .zip(&self.whitened_gradient)
                        .zip(&self.whitened_gradient_new)
                    {
                        let r = z + 0.5 * eps * (u + u_new);
                        forward += z * z;
                        reverse += r * r;
                    }
                    (
                        lp_new - state.log_density + 0.5 * (forward - reverse),
                        false,
                    )
                }
                Evaluated::Outside => (f64::NEG_INFINITY, false),
                Evaluated::Failed => (f64::NEG_INFINITY, true),
            };
        self.failures += failed as u64;
        let (accept_stat, accepted) = metropolis(log_ratio, rng);
        if accepted {
            std::mem::swap(&mut state.x, &mut self.proposal);
            std::mem::swap(&mut state.gradient, &mut self.proposal_gradient);
            state.log_density = lp_new;
        }
        Ok(Info::single_proposal(
            accept_stat,
            accepted,
            failed,
            eps,
            state.log_density,
        ))
    }
}

/// How the warm-up re-estimates M⁻¹.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PreconditionerAdaptation {
    /// Keep the constructor's M⁻¹ (e.g. the inverse MAP Hessian).
    #[default]
    Fixed,
    /// Marginal variances of the warm-up draws.
    Diagonal,
    /// Full covariance of the warm-up draws, shrunk toward its diagonal.
    Dense,
}

/// Settings of [`MalaAdaptation`]. The window fractions are Stan's (75, 50 and 25 of 1000).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MalaAdaptationSettings {
    pub step_size: DualAveragingSettings,
    pub preconditioner: PreconditionerAdaptation,
    /// Fraction of warm-up spent on the step size alone before the first window, while the
    /// chain travels from its start into the typical set.
    pub initial_buffer: f64,
    /// Fraction of warm-up at the end spent on the step size alone, for the final M⁻¹.
    pub final_buffer: f64,
    /// Length of the first estimation window, as a fraction; each next window is twice as long.
    pub first_window: f64,
}

impl Default for MalaAdaptationSettings {
    fn default() -> Self {
        Self {
            step_size: DualAveragingSettings::single_proposal(0.574),
            preconditioner: PreconditionerAdaptation::Fixed,
            initial_buffer: 0.075,
            final_buffer: 0.05,
            first_window: 0.025,
        }
    }
}

impl MalaAdaptationSettings {
    pub fn validate(&self) -> Result<(), String> {
        self.step_size.validate()?;
        let ok = |f: f64| (0.0..1.0).contains(&f);
        if !(ok(self.initial_buffer)
            && ok(self.final_buffer)
            && self.first_window > 0.0
            && self.initial_buffer + self.final_buffer + self.first_window <= 1.0)
        {
            return Err(
                "the warm-up fractions must be in [0, 1) and leave room for a window".into(),
            );
        }
        Ok(())
    }
}

/// Tunes a [`Mala`] during warm-up: ε by dual averaging throughout, and M⁻¹ (unless fixed) at
/// the end of each of Stan's doubling windows, from the draws of that window only. A single
/// window over the second half of warm-up would learn the scales from draws that the initial
/// M⁻¹ kept from spreading out (with M⁻¹ = I on scales that span 100×, the widest coordinate
/// has barely moved); each doubling window starts from a better M⁻¹ and sees more of the
/// target. After every update ε restarts, since its scale is relative to M⁻¹.
#[derive(Clone, Debug)]
pub struct MalaAdaptation {
    settings: MalaAdaptationSettings,
    dual: DualAveraging,
    /// Window ends (exclusive iteration indices), computed on the first observation.
    windows: Vec<(usize, usize)>,
    window: usize,
    estimator: CovarianceEstimator,
}

impl MalaAdaptation {
    /// Dual averaging starts from the kernel's step size at the first warm-up transition.
    pub fn new(settings: MalaAdaptationSettings) -> Result<Self, String> {
        settings.validate()?;
        settings.step_size.validate()?;
        let dual = DualAveraging::new(&settings.step_size, 1.0);
        Ok(Self {
            settings,
            dual,
            windows: Vec::new(),
            window: 0,
            estimator: CovarianceEstimator::default(),
        })
    }

    /// Step size only, toward 0.574, with the kernel's M⁻¹ kept.
    pub fn step_size_only() -> Self {
        Self::new(MalaAdaptationSettings::default()).expect("the default settings are valid")
    }

    /// Step size and M⁻¹ re-estimated as `preconditioner` says, with the other defaults.
    pub fn with_preconditioner(preconditioner: PreconditionerAdaptation) -> Self {
        Self::new(MalaAdaptationSettings {
            preconditioner,
            ..MalaAdaptationSettings::default()
        })
        .expect("the default settings are valid")
    }

    /// The estimation windows `[start, end)` for a warm-up of `n_warmup` transitions.
    pub fn windows_for(&self, n_warmup: usize) -> Vec<(usize, usize)> {
        if self.settings.preconditioner == PreconditionerAdaptation::Fixed {
            return Vec::new();
        }
        let n = n_warmup as f64;
        let start = (self.settings.initial_buffer * n).round() as usize;
        let end = n_warmup - (self.settings.final_buffer * n).round() as usize;
        let size = ((self.settings.first_window * n).round() as usize).max(1);
        // Fewer than ~10 draws per window estimate nothing useful.
        if end <= start || end - start < 10 {
            return Vec::new();
        }
        doubling_windows(start, end, size, true)
            .into_iter()
            .map(|w| (w.start, w.end))
            .collect()
    }
}

impl Adaptation<Mala> for MalaAdaptation {
    fn observe(
        &mut self,
        kernel: &mut Mala,
        state: &State,
        info: &Info,
        iteration: usize,
        n_warmup: usize,
    ) {
        if iteration == 0 {
            self.dual.restart(kernel.step_size());
            self.windows = self.windows_for(n_warmup);
            self.window = 0;
            self.estimator
                .reset(kernel.dim(), self.settings.preconditioner);
        }
        kernel.set_step_size(self.dual.update(info.accept_stat));

        let Some(&(start, end)) = self.windows.get(self.window) else {
            return;
        };
        if iteration >= start {
            self.estimator.push(&state.x);
        }
        if iteration + 1 == end {
            if let Some(p) = self.estimator.estimate(kernel.preconditioner()) {
                // An estimate that fails to factor keeps the old M⁻¹: warm-up goes on.
                if kernel.set_preconditioner(p).is_ok() {
                    let step = self.dual.final_step_size();
                    kernel.set_step_size(step);
                    self.dual.restart(step);
                }
            }
            self.estimator
                .reset(kernel.dim(), self.settings.preconditioner);
            self.window += 1;
        }
    }

    fn finish(&mut self, kernel: &mut Mala) {
        kernel.set_step_size(self.dual.final_step_size());
    }
}

/// The window's draws, in the toolkit's Welford estimator, and how M⁻¹ is re-estimated.
#[derive(Clone, Debug, Default)]
struct CovarianceEstimator {
    kind: PreconditionerAdaptation,
    welford: Welford,
}

impl CovarianceEstimator {
    fn reset(&mut self, dim: usize, kind: PreconditionerAdaptation) {
        self.kind = kind;
        // A fixed M⁻¹ estimates nothing: a diagonal estimator of no use costs nothing either.
        self.welford = Welford::new(
            dim,
            kind == PreconditionerAdaptation::Dense,
            WelfordForm::DeviationAfter,
        );
    }

    fn push(&mut self, x: &[f64]) {
        if self.kind != PreconditionerAdaptation::Fixed {
            self.welford.add(x);
        }
    }

    /// The window's estimate of M⁻¹, or None when there are too few draws to say anything.
    /// A coordinate that never moved in the window keeps its previous variance. The dense
    /// covariance is shrunk toward its own diagonal with weight 5/(n + 5), a scale-free target
    /// (Stan's shrinkage toward 10⁻³·I would swamp coordinates whose variance is 10⁻⁸), which
    /// keeps it positive definite even with fewer draws than dimensions.
    fn estimate(&self, previous: &Metric) -> Option<Metric> {
        let w2 = &self.welford;
        if w2.count() < 3 {
            return None;
        }
        let dim = w2.dim();
        let n = w2.count() as f64;
        let old = previous.inverse_mass_diagonal();
        let variance = |i: usize, m2: f64| {
            let v = m2 / (n - 1.0);
            if v > 0.0 && v.is_finite() { v } else { old[i] }
        };
        match self.kind {
            PreconditionerAdaptation::Fixed => None,
            PreconditionerAdaptation::Diagonal => Some(Metric::Diagonal(
                (0..dim).map(|i| variance(i, w2.m2(i, i))).collect(),
            )),
            PreconditionerAdaptation::Dense => {
                let w = n / (n + 5.0);
                let diag: Vec<f64> = (0..dim).map(|i| variance(i, w2.m2(i, i))).collect();
                let cov = DMatrix::from_fn(dim, dim, |i, j| {
                    if i == j {
                        diag[i]
                    } else {
                        // M₂ is symmetric up to rounding; the mean of both triangles is.
                        let c = 0.5 * (w2.m2(j, i) + w2.m2(i, j)) / (n - 1.0);
                        if c.is_finite() { w * c } else { 0.0 }
                    }
                });
                // Symmetric by construction, so `Metric::dense` leaves it as it is; one that
                // is not positive definite keeps the old M⁻¹.
                Metric::dense(cov).ok()
            }
        }
    }
}
