//! The completion step of `collapsed-is`: θ comes from the Laplace approximation's marginal,
//! and each noise scale σ and the discrepancy coefficients a that share it are drawn from their
//! conditional given θ, which the likelihood y = G(θ) + B·a + ε makes nearly exact:
//!
//! - σ² given θ, with a integrated out under a flat prior, is InvGamma((n − k − 1)/2, S/2),
//!   S the residual sum of squares left after the k least-squares coefficients (the −1 is the
//!   prior's measure in σ, not σ²);
//! - a given θ and σ is N(â + σ²(BᵀB)⁻¹∇log p(â), σ²(BᵀB)⁻¹): the Gaussian likelihood tilted
//!   by its prior's slope at â, exact for a Laplace prior whose coefficients keep their sign.
//!
//! What the proposal leaves out (the priors of σ and a, exactly) the importance weight puts back,
//! and since with a few hundred samples per channel both conditionals are close to exact, the
//! weights vary with θ alone: in the paper's BM2(K) that is one coordinate, not 3 + 2(K + 1).

use nalgebra::DVector;
use rand_distr::{Distribution, Gamma, StandardNormal};

use super::ChainRng;
use crate::density::{DensityError, LinearBlock, LinearCoefficients, LogDensity};
use crate::parameter::ln_gamma;

const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// x with θ = `lead` and every block's σ and a drawn from its conditional, and the log density
/// of that draw under the conditionals (the coordinates log σ and a). `None` where the density
/// cannot be conditioned at θ (outside the support, a failed solve): the caller weighs it zero.
pub fn complete<P: LogDensity>(
    density: &mut P,
    lead: &[f64],
    rng: &mut ChainRng,
) -> Result<Option<(Vec<f64>, f64)>, DensityError> {
    let mut x = vec![0.0; density.dim()];
    x[..lead.len()].copy_from_slice(lead);
    let conditionals = match density.linear_conditionals(&x) {
        Ok(Some(c)) => c,
        Ok(None) => {
            return Err(DensityError::fatal(
                "collapsed importance sampling needs a density with linear conditionals",
            ));
        }
        Err(e) if e.recoverable => return Ok(None),
        Err(e) => return Err(e),
    };
    if conditionals.leading != lead.len() {
        return Err(DensityError::fatal(format!(
            "a proposal over {} coordinates for a density conditioned on {}",
            lead.len(),
            conditionals.leading
        )));
    }
    let mut log_q = 0.0;
    for block in &conditionals.blocks {
        match draw_block(block, &mut x, rng) {
            Some(lq) => log_q += lq,
            None => return Ok(None),
        }
    }
    Ok(Some((x, log_q)))
}

/// σ then a of one block written into x; the log density of the draw, `None` if the block
/// has too few observations beside its coefficients or nothing left unexplained.
fn draw_block(block: &LinearBlock, x: &mut [f64], rng: &mut ChainRng) -> Option<f64> {
    let (shape, rate) = variance_shape_rate(block)?;
    let gamma: f64 = Gamma::new(shape, 1.0).ok()?.sample(rng);
    let variance = rate / gamma;
    x[block.log_sigma] = 0.5 * variance.ln();
    if let Some(c) = &block.coefficients {
        let k = c.least_squares.len();
        let mean = coefficient_mean(c, variance)?;
        let z = DVector::from_iterator(k, (0..k).map(|_| StandardNormal.sample(rng)));
        let spread = c.gram_factor.tr_solve_lower_triangular(&z)? * variance.sqrt();
        for j in 0..k {
            x[c.offset + j] = mean[j] + spread[j];
        }
    }
    block_log_density(block, x)
}

/// The conditional's log density of the block's coordinates in x (log σ and a).
pub fn block_log_density(block: &LinearBlock, x: &[f64]) -> Option<f64> {
    let (shape, rate) = variance_shape_rate(block)?;
    let variance = (2.0 * x[block.log_sigma]).exp();
    // log σ = ½ log σ²: the InvGamma density of σ² times dσ²/dlog σ = 2σ².
    let mut log_q =
        shape * rate.ln() - ln_gamma(shape) - (shape + 1.0) * variance.ln() - rate / variance
            + (2.0 * variance).ln();
    if let Some(c) = &block.coefficients {
        let k = c.least_squares.len();
        let mean = coefficient_mean(c, variance)?;
        let a = DVector::from_iterator(k, (0..k).map(|j| x[c.offset + j]));
        // z = Lᵀ(a − mean)/σ is standard normal under the conditional.
        let z = c.gram_factor.tr_mul(&(a - mean)) / variance.sqrt();
        let half_log_det: f64 = c.gram_factor.diagonal().iter().map(|d| d.ln()).sum();
        log_q += -0.5 * k as f64 * (LN_2PI + variance.ln()) + half_log_det - 0.5 * z.norm_squared();
    }
    Some(log_q)
}

/// InvGamma's shape and scale for σ² given θ; `None` if undefined.
fn variance_shape_rate(block: &LinearBlock) -> Option<(f64, f64)> {
    let k = block
        .coefficients
        .as_ref()
        .map_or(0, |c| c.least_squares.len());
    let shape = 0.5 * (block.observations as f64 - k as f64 - 1.0);
    let rate = 0.5 * block.residual_ss;
    (shape > 0.0 && rate > 0.0 && rate.is_finite()).then_some((shape, rate))
}

/// â + σ²(BᵀB)⁻¹∇log p(â), with (BᵀB)⁻¹ = L⁻ᵀL⁻¹.
fn coefficient_mean(c: &LinearCoefficients, variance: f64) -> Option<DVector<f64>> {
    let l = &c.gram_factor;
    let tilt = l.tr_solve_lower_triangular(&l.solve_lower_triangular(&c.prior_slope)?)?;
    Some(&c.least_squares + tilt * variance)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::LinearCoefficients;
    use crate::sampler::driver::chain_rng;
    use crate::sampler::importance::{Proposed, importance_sample_with};
    use crate::sampler::proposal::LaplaceProposal;
    use crate::sampler::targets::LinearRegression;
    use nalgebra::DMatrix;

    /// A regression whose θ column is correlated with the basis, as R is with δ's low orders.
    fn regression() -> LinearRegression {
        let n = 60;
        let t = |i: usize| i as f64 / (n - 1) as f64;
        let g = DVector::from_fn(n, |i, _| 1.0 + 0.5 * t(i) + (6.0 * t(i)).sin());
        let basis = DMatrix::from_fn(n, 3, |i, j| t(i).powi(j as i32));
        let mut rng = chain_rng(3, 0);
        let y = DVector::from_fn(n, |i, _| {
            let noise: f64 = StandardNormal.sample(&mut rng);
            2.0 * g[i] - 1.0 + 0.3 * t(i) + 0.4 * noise
        });
        LinearRegression { g, basis, y }
    }

    #[test]
    fn the_conditional_density_integrates_to_one() {
        // One coefficient beside σ: a 2-D Riemann sum over (log σ, a).
        let block = LinearBlock {
            log_sigma: 0,
            observations: 12,
            residual_ss: 3.0,
            coefficients: Some(LinearCoefficients {
                offset: 1,
                least_squares: DVector::from_vec(vec![0.7]),
                gram_factor: DMatrix::from_element(1, 1, 2.0),
                prior_slope: DVector::from_vec(vec![-0.3]),
            }),
        };
        let (h_s, h_a) = (0.005, 0.005);
        let mut total = 0.0;
        for i in -600..200 {
            for j in -800..800 {
                let x = [i as f64 * h_s, 0.7 + j as f64 * h_a];
                total += block_log_density(&block, &x).unwrap().exp() * h_s * h_a;
            }
        }
        assert!((total - 1.0).abs() < 2e-3, "∫q = {total}");
    }

    #[test]
    fn a_draw_reports_the_density_it_was_drawn_from() {
        let mut target = regression();
        let mut rng = chain_rng(5, 0);
        let conditionals = target
            .linear_conditionals(&[2.0, 0.0, 0.0, 0.0, 0.0])
            .unwrap()
            .unwrap();
        let (x, log_q) = complete(&mut target, &[2.0], &mut rng).unwrap().unwrap();
        let again = block_log_density(&conditionals.blocks[0], &x).unwrap();
        assert!((log_q - again).abs() < 1e-12, "{log_q} vs {again}");
    }

    #[test]
    fn on_a_conjugate_regression_the_weights_are_nearly_flat_and_the_moments_exact() {
        let target = regression();
        let (beta, inverse, s) = target.least_squares();
        let (n, p) = (target.y.len() as f64, 4.0);
        let mean_variance = s / (n - p - 3.0);
        // The proposal over θ alone: the marginal's centre and (Gaussian) spread.
        let sd_theta = (mean_variance * inverse[(0, 0)]).sqrt();
        let proposal =
            LaplaceProposal::new(&[beta[0]], &DMatrix::from_element(1, 1, sd_theta.powi(-2)))
                .unwrap()
                .with_shape(30.0, 1.0)
                .unwrap();
        let run = importance_sample_with(&proposal, Proposed::Leading, 4, 0, 1000, 11, |_| {
            Ok(target.clone())
        })
        .unwrap();
        assert!(run.khat() < 0.5, "k̂ = {}", run.khat());
        // Only θ's marginal is approximated, and it is nearly the t: nearly every draw counts.
        assert!(run.weights_ess() > 3600.0, "ESS {}", run.weights_ess());
        let ess = run.weights_ess();
        let draws: Vec<&Vec<f64>> = run.chains.iter().flat_map(|c| c.draws.iter()).collect();
        let mean_of = |f: &dyn Fn(&[f64]) -> f64| {
            draws.iter().map(|x| f(x)).sum::<f64>() / draws.len() as f64
        };
        for (j, coordinate) in [0, 2, 3, 4].into_iter().enumerate() {
            let sd = (mean_variance * inverse[(j, j)]).sqrt();
            let mean = mean_of(&|x| x[coordinate]);
            assert!(
                (mean - beta[j]).abs() < 4.0 * sd / ess.sqrt(),
                "β{j}: {mean} vs {}",
                beta[j]
            );
        }
        // E[σ²] = (S/2)/(α − 1) with α = (n − p − 1)/2; σ²'s sd is E[σ²]/√(α − 2).
        let variance = mean_of(&|x| (2.0 * x[1]).exp());
        let sd_variance = mean_variance / (0.5 * (n - p - 1.0) - 2.0).sqrt();
        assert!(
            (variance - mean_variance).abs() < 4.0 * sd_variance / ess.sqrt(),
            "E[σ²] {variance} vs {mean_variance}"
        );
    }

    #[test]
    fn the_draws_do_not_depend_on_the_thread_count() {
        let target = regression();
        let proposal = LaplaceProposal::new(&[2.0], &DMatrix::from_element(1, 1, 100.0)).unwrap();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    importance_sample_with(&proposal, Proposed::Leading, 3, 40, 200, 9, |_| {
                        Ok(target.clone())
                    })
                })
                .unwrap()
        };
        let (one, two) = (run(1), run(2));
        for (a, b) in one.chains.iter().zip(&two.chains) {
            assert_eq!(a.draws, b.draws);
        }
        assert_eq!(one.psis, two.psis);
    }
}
