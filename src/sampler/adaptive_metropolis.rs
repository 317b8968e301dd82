//! Adaptive Metropolis (Haario, Saksman and Tamminen 2001): a joint Gaussian random walk whose
//! covariance is learnt from the chain's own history during warm-up, the strongest baseline that
//! needs no gradient.
//!
//! The proposal is x' = x + λ·L z, z ~ N(0, I), with L Lᵀ = (2.38²/d)·(Σ + ε·diag Σ). The factor
//! 2.38²/d is optimal for Gaussian targets (Gelman, Roberts and Gilks 1996); λ is a global scale
//! that [`HaarioAdaptation`] drives toward an acceptance rate of 0.234, because a start covariance
//! off by orders of magnitude would otherwise leave the chain stuck and its history uninformative.

use nalgebra::DMatrix;
use rand_distr::{Distribution, StandardNormal};

use super::welford::{Welford, WelfordForm};
use super::{
    Adaptation, ChainRng, Info, Kernel, State, Transition, proposal_log_density,
    random_walk_decision,
};
use crate::density::{DensityError, LogDensity};

/// The ridge is relative to each coordinate's own variance, i.e. added to the correlation
/// matrix: an absolute ε·I would swamp a coordinate of variance 10⁻⁸ (the motor's R) and
/// vanish beside one of variance 10².
const RELATIVE_RIDGE: f64 = 1e-8;

/// Joint Gaussian random-walk Metropolis with a full proposal covariance.
#[derive(Clone, Debug)]
pub struct AdaptiveMetropolis {
    covariance: DMatrix<f64>,
    /// Lower Cholesky factor of (2.38²/d)·(Σ + ε·diag Σ).
    factor: DMatrix<f64>,
    scale: f64,
    z: Vec<f64>,
    proposal: Vec<f64>,
}

impl AdaptiveMetropolis {
    /// A kernel whose proposal covariance is (2.38²/d)·`covariance` (e.g. the Laplace covariance
    /// H⁻¹ at the MAP), with global scale 1.
    pub fn new(covariance: DMatrix<f64>) -> Result<Self, String> {
        let d = covariance.nrows();
        if d == 0 {
            return Err("the proposal covariance is empty".into());
        }
        let mut kernel = Self {
            covariance: DMatrix::zeros(d, d),
            factor: DMatrix::zeros(d, d),
            scale: 1.0,
            z: vec![0.0; d],
            proposal: vec![0.0; d],
        };
        kernel.set_covariance(&covariance)?;
        Ok(kernel)
    }

    /// Start covariance `variance`·I, for when no curvature is known.
    pub fn isotropic(dim: usize, variance: f64) -> Result<Self, String> {
        if !(variance.is_finite() && variance > 0.0) {
            return Err(format!(
                "the start variance must be positive and finite, got {variance}"
            ));
        }
        Self::new(DMatrix::from_diagonal_element(dim, dim, variance))
    }

    /// Start covariance H⁻¹ from a precision H (the negative Hessian at the MAP).
    pub fn from_precision(precision: &DMatrix<f64>) -> Result<Self, String> {
        let chol = precision
            .clone()
            .cholesky()
            .ok_or_else(|| "the precision matrix is not positive definite".to_string())?;
        Self::new(chol.inverse())
    }

    pub fn dim(&self) -> usize {
        self.covariance.nrows()
    }

    /// Σ, the target covariance estimate the proposal is built from (before 2.38²/d and λ).
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.covariance
    }

    /// The global scale λ multiplying the proposal's standard deviations.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    pub fn set_scale(&mut self, scale: f64) -> Result<(), String> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(format!(
                "the proposal scale must be positive and finite, got {scale}"
            ));
        }
        self.scale = scale;
        Ok(())
    }

    /// Replaces Σ. On failure (wrong size, non-finite, not positive definite even with the ridge)
    /// the kernel is unchanged, so an adaptation can simply keep the previous proposal.
    pub fn set_covariance(&mut self, covariance: &DMatrix<f64>) -> Result<(), String> {
        let d = self.dim();
        if covariance.nrows() != d || covariance.ncols() != d {
            return Err(format!(
                "a {}×{} covariance for dimension {d}",
                covariance.nrows(),
                covariance.ncols()
            ));
        }
        if covariance.iter().any(|v| !v.is_finite()) {
            return Err("the proposal covariance has non-finite entries".into());
        }
        if let Some(i) = (0..d).find(|&i| covariance[(i, i)] <= 0.0) {
            return Err(format!(
                "the proposal variance of coordinate {i} is {}",
                covariance[(i, i)]
            ));
        }
        let symmetric = (covariance + covariance.transpose()) * 0.5;
        let mut regularised = symmetric.clone();
        for i in 0..d {
            regularised[(i, i)] *= 1.0 + RELATIVE_RIDGE;
        }
        regularised *= 2.38 * 2.38 / d as f64;
        let chol = regularised
            .cholesky()
            .ok_or_else(|| "the proposal covariance is not positive definite".to_string())?;
        self.factor = chol.unpack();
        self.covariance = symmetric;
        Ok(())
    }
}

impl<P: LogDensity> Kernel<P> for AdaptiveMetropolis {
    fn name(&self) -> String {
        "adaptive-metropolis".into()
    }

    fn uses_gradient(&self) -> bool {
        false
    }

    fn init_state(&mut self, density: &mut P, x: &[f64]) -> Result<State, DensityError> {
        if x.len() != self.dim() || density.dim() != self.dim() {
            return Err(DensityError::fatal(format!(
                "a proposal of dimension {} for a density of dimension {} and a start of dimension {}",
                self.dim(),
                density.dim(),
                x.len()
            )));
        }
        Ok(State {
            x: x.to_vec(),
            log_density: density.log_density(x)?,
            gradient: Vec::new(),
        })
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        let d = self.dim();
        if state.x.len() != d {
            return Err(DensityError::fatal(format!(
                "a state of dimension {} for a proposal of dimension {d}",
                state.x.len()
            )));
        }
        for z in &mut self.z {
            *z = StandardNormal.sample(rng);
        }
        for i in 0..d {
            let mut step = 0.0;
            for j in 0..=i {
                step += self.factor[(i, j)] * self.z[j];
            }
            self.proposal[i] = state.x[i] + self.scale * step;
        }
        let proposed = proposal_log_density(density, &self.proposal)?;
        let (accept_prob, accepted) = random_walk_decision(proposed, state.log_density, rng);
        if accepted {
            state.x.copy_from_slice(&self.proposal);
            state.log_density = proposed;
        }
        Ok(Info::single_proposal(
            accept_prob,
            accepted,
            false,
            self.scale,
            state.log_density,
        ))
    }
}

/// How [`HaarioAdaptation`] learns during warm-up.
#[derive(Clone, Debug, PartialEq)]
pub struct HaarioSettings {
    /// Fraction of warm-up ignored before the history is recorded: the transient from the start
    /// would inflate the covariance along the path the chain came in by.
    pub start_fraction: f64,
    /// Warm-up iterations between covariance updates.
    pub update_interval: usize,
    /// The acceptance rate λ is driven toward (Roberts, Gelman and Gilks 1997).
    pub target_accept: f64,
    /// The Robbins–Monro gain is (t + 1)^(−κ): κ ∈ (½, 1] makes λ settle while still
    /// following the covariance updates early on.
    pub gain_exponent: f64,
    /// The kernel's initial covariance counts as this many observations per dimension in the
    /// estimate: a few hundred autocorrelated warm-up states estimate a 23-dimensional
    /// covariance with correlations of 0.99 badly, and a good start (the Laplace covariance)
    /// should not be thrown away for it.
    pub initial_weight_per_dim: f64,
}

impl Default for HaarioSettings {
    fn default() -> Self {
        Self {
            start_fraction: 0.1,
            update_interval: 50,
            target_accept: 0.234,
            gain_exponent: 0.6,
            initial_weight_per_dim: 10.0,
        }
    }
}

impl HaarioSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..1.0).contains(&self.start_fraction) {
            return Err(format!(
                "start_fraction must be in [0, 1), got {}",
                self.start_fraction
            ));
        }
        if self.update_interval == 0 {
            return Err("update_interval must be at least 1".into());
        }
        if !(self.initial_weight_per_dim >= 0.0 && self.initial_weight_per_dim.is_finite()) {
            return Err(format!(
                "initial_weight_per_dim must be a non-negative number, got {}",
                self.initial_weight_per_dim
            ));
        }
        if !(self.target_accept > 0.0 && self.target_accept < 1.0) {
            return Err(format!(
                "target_accept must be in (0, 1), got {}",
                self.target_accept
            ));
        }
        if !(self.gain_exponent > 0.5 && self.gain_exponent <= 1.0) {
            return Err(format!(
                "gain_exponent must be in (0.5, 1], got {}",
                self.gain_exponent
            ));
        }
        Ok(())
    }
}

/// Haario's adaptation: the running (Welford) mean and covariance of the warm-up states after
/// the first `start_fraction`, copied into the kernel every `update_interval` iterations and at
/// the end of warm-up; plus Robbins–Monro on log λ toward `target_accept`. Frozen at `finish`.
#[derive(Clone, Debug, Default)]
pub struct HaarioAdaptation {
    settings: HaarioSettings,
    /// Accepted moves among the recorded states: a covariance from a chain that barely moved
    /// is degenerate, so it is not used until the chain has moved more often than d times.
    moves: usize,
    /// The recorded states' mean and covariance, in Haario's symmetric Welford form.
    welford: Welford,
    /// The kernel's covariance when warm-up began.
    initial: Option<DMatrix<f64>>,
}

impl HaarioAdaptation {
    pub fn new(settings: HaarioSettings) -> Result<Self, String> {
        settings.validate()?;
        Ok(Self {
            settings,
            ..Self::default()
        })
    }

    pub fn settings(&self) -> &HaarioSettings {
        &self.settings
    }

    /// States recorded so far.
    pub fn samples(&self) -> usize {
        self.welford.count()
    }

    /// The sample covariance of the recorded states (divisor n − 1), once there are two.
    pub fn sample_covariance(&self) -> Option<DMatrix<f64>> {
        let n = self.welford.count();
        (n >= 2).then(|| self.welford.m2_matrix() / (n - 1) as f64)
    }

    fn record(&mut self, x: &[f64], accepted: bool) {
        let d = x.len();
        if self.welford.dim() != d {
            self.welford = Welford::new(d, true, WelfordForm::ScaledDelta);
            self.moves = 0;
        }
        self.moves += accepted as usize;
        self.welford.add(x);
    }

    fn update_covariance(&self, kernel: &mut AdaptiveMetropolis) {
        let d = kernel.dim();
        if self.welford.count() < (2 * d).max(20) || self.moves <= d {
            return;
        }
        if let Some(cov) = self.sample_covariance() {
            let blended = match &self.initial {
                Some(initial) => {
                    let n0 = self.settings.initial_weight_per_dim * d as f64;
                    let n = (self.welford.count() - 1) as f64;
                    (initial * n0 + cov * n) / (n0 + n)
                }
                None => cov,
            };
            // A failure (a coordinate that never moved) keeps the previous proposal.
            let _ = kernel.set_covariance(&blended);
        }
    }
}

impl Adaptation<AdaptiveMetropolis> for HaarioAdaptation {
    fn observe(
        &mut self,
        kernel: &mut AdaptiveMetropolis,
        state: &State,
        info: &Info,
        iteration: usize,
        n_warmup: usize,
    ) {
        if self.initial.is_none() {
            self.initial = Some(kernel.covariance().clone());
        }
        let gain = (iteration as f64 + 1.0).powf(-self.settings.gain_exponent);
        let log_scale = kernel.scale.ln() + gain * (info.accept_stat - self.settings.target_accept);
        // Bounded so that a long run of rejections cannot underflow the scale to zero.
        kernel.scale = log_scale.clamp(-30.0, 30.0).exp();

        let start = (self.settings.start_fraction * n_warmup as f64).ceil() as usize;
        if iteration < start {
            return;
        }
        self.record(&state.x, info.accepted);
        if (iteration + 1 - start).is_multiple_of(self.settings.update_interval) {
            self.update_covariance(kernel);
        }
    }

    fn finish(&mut self, kernel: &mut AdaptiveMetropolis) {
        self.update_covariance(kernel);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_matches_the_two_pass_covariance() {
        let xs: Vec<Vec<f64>> = (0..50)
            .map(|i| {
                let t = i as f64;
                vec![
                    (0.7 * t).sin() * 3.0 + 1.0,
                    (1.3 * t).cos() - 0.2 * t,
                    1e-4 * (0.3 * t).sin(),
                ]
            })
            .collect();
        let mut adapt = HaarioAdaptation::default();
        for x in &xs {
            adapt.record(x, true);
        }
        let n = xs.len() as f64;
        let mean: Vec<f64> = (0..3)
            .map(|i| xs.iter().map(|x| x[i]).sum::<f64>() / n)
            .collect();
        let cov = adapt.sample_covariance().unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let two_pass = xs
                    .iter()
                    .map(|x| (x[i] - mean[i]) * (x[j] - mean[j]))
                    .sum::<f64>()
                    / (n - 1.0);
                assert!(
                    (cov[(i, j)] - two_pass).abs() <= 1e-12 * two_pass.abs().max(1e-8),
                    "({i},{j})"
                );
            }
        }
    }

    #[test]
    fn the_proposal_factor_carries_the_optimal_scaling_and_a_relative_ridge() {
        let cov = DMatrix::from_row_slice(2, 2, &[4.0, 1e-3, 1e-3, 1e-6]);
        let kernel = AdaptiveMetropolis::new(cov.clone()).unwrap();
        let l = &kernel.factor;
        let rebuilt = l * l.transpose();
        let s = 2.38 * 2.38 / 2.0;
        assert!((rebuilt[(0, 0)] / (s * 4.0) - 1.0).abs() < 1e-7);
        assert!((rebuilt[(1, 1)] / (s * 1e-6) - 1.0).abs() < 1e-7);
        assert!((rebuilt[(0, 1)] / (s * 1e-3) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_covariance_that_is_not_positive_definite_leaves_the_kernel_unchanged() {
        let mut kernel = AdaptiveMetropolis::isotropic(2, 1.0).unwrap();
        let bad = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(kernel.set_covariance(&bad).is_err());
        assert_eq!(kernel.covariance(), &DMatrix::identity(2, 2));
    }

    #[test]
    fn the_scale_rises_when_everything_is_accepted_and_falls_when_nothing_is() {
        let mut kernel = AdaptiveMetropolis::isotropic(2, 1.0).unwrap();
        let mut adapt = HaarioAdaptation::default();
        let state = State {
            x: vec![0.0, 0.0],
            log_density: 0.0,
            gradient: Vec::new(),
        };
        let all = Info {
            accept_stat: 1.0,
            accepted: true,
            ..Info::default()
        };
        for i in 0..20 {
            adapt.observe(&mut kernel, &state, &all, i, 1000);
        }
        assert!(kernel.scale() > 2.0, "{}", kernel.scale());
        let none = Info {
            accept_stat: 0.0,
            accepted: false,
            ..Info::default()
        };
        let before = kernel.scale();
        for i in 20..200 {
            adapt.observe(&mut kernel, &state, &none, i, 1000);
        }
        assert!(
            kernel.scale() < before / 2.0,
            "{} vs {before}",
            kernel.scale()
        );
    }
}
