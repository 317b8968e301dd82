//! The one interface every sampler and the optimiser are generic over: a log density on ℝᵈ
//! (unconstrained coordinates) with its gradient written into a buffer the caller owns.

use std::ops::Range;

use nalgebra::{DMatrix, DVector};

/// A failed evaluation. Recoverable failures (an ODE that blew up, a step cap reached) reject
/// the proposal like a divergence; fatal ones stop the run.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityError {
    pub recoverable: bool,
    pub message: String,
}

impl DensityError {
    pub fn recoverable(message: impl Into<String>) -> Self {
        Self {
            recoverable: true,
            message: message.into(),
        }
    }
    pub fn fatal(message: impl Into<String>) -> Self {
        Self {
            recoverable: false,
            message: message.into(),
        }
    }
}

impl std::fmt::Display for DensityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for DensityError {}

impl From<DensityError> for crate::error::Error {
    fn from(e: DensityError) -> Self {
        crate::error::Error::Numerical(e.message)
    }
}

/// An unnormalised log density. `&mut self` lets an implementation keep scratch space and
/// caches (the motor posterior reuses G(θ) while only noise or discrepancy parameters move).
/// A point outside the support returns `Ok(f64::NEG_INFINITY)`.
pub trait LogDensity {
    fn dim(&self) -> usize;

    /// Names of the unconstrained coordinates.
    fn parameter_names(&self) -> Vec<String>;

    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError>;

    /// The log density, with its gradient written into `grad` (length `dim()`).
    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError>;

    /// Names of the quantities reported in draws (constrained: σ rather than log σ).
    fn output_names(&self) -> Vec<String> {
        self.parameter_names()
    }

    /// Maps an unconstrained point to the reported quantities.
    fn constrain(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(x);
    }

    /// Groups of coordinates that a variable-at-a-time sampler proposes together.
    fn blocks(&self) -> Vec<Range<usize>> {
        (0..self.dim()).map(|i| i..i + 1).collect()
    }

    /// The ODE solves this density has made (none for a closed-form density).
    fn solves(&self) -> SolveCount {
        SolveCount::default()
    }

    /// Whether many of the coordinates enter the likelihood linearly beside a few scales (a
    /// discrepancy's coefficients beside the noise scales). Marginalising many such
    /// coordinates moves the scales' marginal away from the joint mode, the offset that
    /// `laplace-is`'s recentring warm-up is for; without them it has nothing to correct.
    fn has_linear_coefficients(&self) -> bool {
        false
    }

    /// Given the leading coordinates of `x` (θ; the rest is not read), the likelihood's
    /// Gaussian structure in the others: per noise scale, its observations, the residual sum
    /// of squares left after the least-squares coefficients, and those coefficients. `None`
    /// where the density has no such structure; a recoverable error where θ is outside the
    /// support or its solve fails. One plain solve at θ, which the density's next evaluation
    /// at the same θ reuses.
    fn linear_conditionals(&mut self, _x: &[f64]) -> Result<Option<Conditionals>, DensityError> {
        Ok(None)
    }

    /// The number of leading coordinates [`linear_conditionals`](Self::linear_conditionals)
    /// conditions on, without solving anything; `None` where it offers none.
    fn conditioned_on(&self) -> Option<usize> {
        None
    }
}

/// The likelihood given θ, y = G(θ) + B·a + ε with ε ~ N(0, σ²I) per block: what
/// [`LogDensity::linear_conditionals`] returns, and what `collapsed-is` draws σ and a from.
#[derive(Clone, Debug)]
pub struct Conditionals {
    /// The coordinates before this index are θ; every block's coordinates come after it.
    pub leading: usize,
    pub blocks: Vec<LinearBlock>,
}

/// One noise scale σ (a recording's channel) and the coefficients that share it.
#[derive(Clone, Debug)]
pub struct LinearBlock {
    /// The coordinate of log σ.
    pub log_sigma: usize,
    pub observations: usize,
    /// ‖r − B·â‖² with r = y − G(θ): what no coefficient explains.
    pub residual_ss: f64,
    pub coefficients: Option<LinearCoefficients>,
}

impl LinearBlock {
    /// The block of the residual r = y − G(θ): with a basis B (BᵀB = LLᵀ, `gram_factor`) whose
    /// coefficients sit from `offset`, their least-squares values â, the prior's slope
    /// `slope(j, â_j)` at them, and ‖r − Bâ‖² = ‖r‖² − âᵀBᵀr (since Bᵀ(r − Bâ) = 0); without
    /// one, ‖r‖². `None` where L is singular.
    pub fn least_squares(
        log_sigma: usize,
        r: &DVector<f64>,
        basis: Option<(usize, &DMatrix<f64>, &DMatrix<f64>)>,
        slope: impl Fn(usize, f64) -> f64,
    ) -> Option<Self> {
        let mut residual_ss = r.norm_squared();
        let coefficients = match basis {
            None => None,
            Some((offset, b, l)) => {
                let projected = b.tr_mul(r);
                let least_squares =
                    l.tr_solve_lower_triangular(&l.solve_lower_triangular(&projected)?)?;
                residual_ss -= least_squares.dot(&projected);
                let prior_slope =
                    DVector::from_fn(least_squares.len(), |j, _| slope(j, least_squares[j]));
                Some(LinearCoefficients {
                    offset,
                    least_squares,
                    gram_factor: l.clone(),
                    prior_slope,
                })
            }
        };
        Some(Self {
            log_sigma,
            observations: r.len(),
            residual_ss: residual_ss.max(0.0),
            coefficients,
        })
    }
}

/// The coefficients a of one block at their least-squares value given θ.
#[derive(Clone, Debug)]
pub struct LinearCoefficients {
    /// The coordinate of a₁; the others follow it.
    pub offset: usize,
    /// â = (BᵀB)⁻¹Bᵀr.
    pub least_squares: DVector<f64>,
    /// L with BᵀB = LLᵀ (lower triangular).
    pub gram_factor: DMatrix<f64>,
    /// ∇log p(a) of the coefficients' prior at â: the conditional is tilted by it.
    pub prior_slope: DVector<f64>,
}

/// ODE solves made: plain f64 solves, and dual-number solves with the number of derivative
/// directions they carried (θ's dimension each). A density evaluation that the posterior's
/// cache serves makes none.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SolveCount {
    pub plain: u64,
    pub dual: u64,
    pub directions: u64,
    /// The right-hand side's evaluations over those solves (each pass of a dual solve's
    /// counted): the integrator's work, which a stiff corner of parameter space multiplies
    /// where the number of solves does not show it.
    pub rhs_evaluations: u64,
}

impl SolveCount {
    /// Solve-equivalents: a plain solve is one, a dual solve carrying n directions is 1 + n
    /// (forward mode integrates the value and each direction alongside it; the yardstick,
    /// `examples/minimal_dopri5.rs`, prints what one costs against a plain solve).
    pub fn equivalents(&self) -> u64 {
        self.plain + self.dual + self.directions
    }
}

impl std::ops::Add for SolveCount {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            plain: self.plain + o.plain,
            dual: self.dual + o.dual,
            directions: self.directions + o.directions,
            rhs_evaluations: self.rhs_evaluations + o.rhs_evaluations,
        }
    }
}

impl std::ops::Sub for SolveCount {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            plain: self.plain - o.plain,
            dual: self.dual - o.dual,
            directions: self.directions - o.directions,
            rhs_evaluations: self.rhs_evaluations - o.rhs_evaluations,
        }
    }
}

/// A counter that a clone does not inherit: a cloned density is a new evaluator (each chain
/// owns one) and counts its own solves from zero.
#[derive(Debug, Default)]
pub struct SolveCounter(pub SolveCount);

impl Clone for SolveCounter {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// A log density that also offers a positive-definite metric: the expected Fisher information
/// plus the prior's curvature (the Gauss–Newton approximation of the negative Hessian).
pub trait FisherMetric: LogDensity {
    fn fisher_metric(&mut self, x: &[f64], metric: &mut DMatrix<f64>) -> Result<(), DensityError>;

    /// A closer approximation of −∇² log π where one is cheap (e.g. exact in the noise scales);
    /// the metric by default. Not guaranteed positive definite away from the mode.
    fn observed_information(
        &mut self,
        x: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), DensityError> {
        self.fisher_metric(x, out)
    }
}

/// A density that knows where a search for its mode should start (the nominal model, a
/// least-squares discrepancy, the noise of what is left).
pub trait StartingPoint: LogDensity {
    fn initial_point(&mut self) -> Result<Vec<f64>, DensityError>;
}

/// Counts evaluations, so that ESS per gradient is measured, not guessed.
#[derive(Clone, Debug)]
pub struct Counted<P> {
    pub inner: P,
    pub density_evaluations: u64,
    pub gradient_evaluations: u64,
    pub metric_evaluations: u64,
}

impl<P> Counted<P> {
    pub fn new(inner: P) -> Self {
        Self {
            inner,
            density_evaluations: 0,
            gradient_evaluations: 0,
            metric_evaluations: 0,
        }
    }
}

impl<P: LogDensity> Counted<P> {
    /// The work spent so far: gradient evaluations plus the integrator's right-hand-side
    /// evaluations. Where the density integrates an ODE the second dominates and follows what
    /// each gradient cost; for a closed-form density it is the gradients alone.
    pub fn work(&self) -> u64 {
        self.gradient_evaluations + self.inner.solves().rhs_evaluations
    }
}

impl<P: LogDensity> LogDensity for Counted<P> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn parameter_names(&self) -> Vec<String> {
        self.inner.parameter_names()
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        self.density_evaluations += 1;
        self.inner.log_density(x)
    }
    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        self.gradient_evaluations += 1;
        self.inner.log_density_and_gradient(x, grad)
    }
    fn output_names(&self) -> Vec<String> {
        self.inner.output_names()
    }
    fn constrain(&self, x: &[f64], out: &mut Vec<f64>) {
        self.inner.constrain(x, out)
    }
    fn blocks(&self) -> Vec<Range<usize>> {
        self.inner.blocks()
    }
    fn solves(&self) -> SolveCount {
        self.inner.solves()
    }
    fn has_linear_coefficients(&self) -> bool {
        self.inner.has_linear_coefficients()
    }
    fn linear_conditionals(&mut self, x: &[f64]) -> Result<Option<Conditionals>, DensityError> {
        self.inner.linear_conditionals(x)
    }
    fn conditioned_on(&self) -> Option<usize> {
        self.inner.conditioned_on()
    }
}

impl<P: StartingPoint> StartingPoint for Counted<P> {
    fn initial_point(&mut self) -> Result<Vec<f64>, DensityError> {
        self.inner.initial_point()
    }
}

impl<P: FisherMetric> FisherMetric for Counted<P> {
    fn fisher_metric(&mut self, x: &[f64], metric: &mut DMatrix<f64>) -> Result<(), DensityError> {
        self.metric_evaluations += 1;
        self.inner.fisher_metric(x, metric)
    }
    fn observed_information(
        &mut self,
        x: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), DensityError> {
        self.metric_evaluations += 1;
        self.inner.observed_information(x, out)
    }
}
