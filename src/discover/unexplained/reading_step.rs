//! A change at an instant in what is read: a channel's reading off by a constant from some
//! instant on (a sensor re-zeroing its offset, or switching its range, while the record ran; a
//! sensor knocked on its mount).
//!
//! No smooth function of the state holds it, and `t` (a change that goes on at one rate) holds
//! only its trend: on current_offset_step-910007 (an offset of 2.6 A from 0.31 s) the law
//! `measured I += 5.08·t` was discovered and something was still left, `unknown`
//! (papers/beyond-library.md, session 31). The step itself is one coefficient at an instant
//! searched: step(t − t_s) (`dictionary::STEP`) at every sample instant with at least
//! [`MARGIN`] samples on either side (a step at the record's edge is an offset, or one
//! outlier), the best of the G columns offered to the selection as one move paying ½·ln N +
//! ln G, as the spot of the angle pays its grid (`spot`); the verdict's threshold then applies.
//! At N = 1002 and 497 instants a channel, the first move needs 3.45 + 6.21 + 2 = 11.7 nats:
//! the largest of 497 gains of ½χ²₁ (neighbours' gains strongly correlated, so fewer
//! independent ones) clears it with probability below 497·P(χ²₁ > 23.3) ≈ 0.07% per channel.

use nalgebra::DMatrix;

use super::column::StepShape;
use super::regression::best_single_column;
use super::state::{Column, Shape, select};
use super::{Context, Evidence};
use crate::motor::dictionary::STEP;

/// Samples at least on either side of a step's instant.
const MARGIN: usize = 2;

/// The step fingerprint of what is read of channel `c` (`balance` its law balance), where the
/// best instant clears the selection's bar.
pub(super) fn fingerprints(ctx: &Context, c: usize, balance: &str, shift: f64) -> Vec<Evidence> {
    let n = ctx.n;
    if n < 2 * MARGIN + 2 {
        return Vec::new();
    }
    let instants: Vec<usize> = (MARGIN..=n - MARGIN).collect();
    let b_tilde = ctx
        .projector
        .residualize(&steps(ctx.m(), n, c, ctx.sigma[c], &instants));
    let Some((_, j)) = best_single_column(&b_tilde, &ctx.y, |_| true) else {
        return Vec::new();
    };
    let shape = StepShape {
        // Midway between the last sample before and the first after: the law reads the
        // step at the samples' own instants, none of them on its edge.
        t_s: 0.5 * (ctx.times[instants[j] - 1] + ctx.times[instants[j]]),
        price: (instants.len() as f64).ln(),
    };
    let columns = [Column::new(STEP, Shape::Step(shape))];
    let chosen = b_tilde.columns(j, 1).into_owned();
    select(ctx, &columns, &chosen, balance, shift, |_: &Column| true)
        .into_iter()
        .collect()
}

/// The whitened steps of channel `c` (of `n` samples, noise `sigma`) at each of `instants`:
/// column j is 1/σ from sample `instants[j]` on, in a record of `m` stacked rows.
fn steps(m: usize, n: usize, c: usize, sigma: f64, instants: &[usize]) -> DMatrix<f64> {
    let mut b = DMatrix::zeros(m, instants.len());
    for (j, &first) in instants.iter().enumerate() {
        for i in first..n {
            b[(c * n + i, j)] = 1.0 / sigma;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discover::settings::EVIDENCE_THRESHOLD;
    use nalgebra::DVector;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    const N: usize = 501;

    fn noise(seed: u64) -> DVector<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        DVector::from_fn(2 * N, |_, _| normal.sample(&mut rng))
    }

    /// What the best instant must gain: ½·ln N for its size, ln G for where it is, and the
    /// threshold.
    fn bar(instants: usize) -> f64 {
        0.5 * ((2 * N) as f64).ln() + (instants as f64).ln() + EVIDENCE_THRESHOLD
    }

    /// Under the model the best of 497 instants gains about 4 nats on white noise against the
    /// bar's 11.7: on 200 white records, none pays (the model's own columns projected out
    /// would only lower the gains).
    #[test]
    fn on_white_noise_no_step_pays_for_its_instant() {
        let instants: Vec<usize> = (MARGIN..=N - MARGIN).collect();
        let b = steps(2 * N, N, 0, 1.0, &instants);
        let alarms: Vec<u64> = (0..200)
            .filter(|&seed| {
                best_single_column(&b, &noise(seed), |_| true)
                    .is_some_and(|(g, _)| g > bar(instants.len()))
            })
            .collect();
        assert!(
            alarms.is_empty(),
            "steps chosen on white records {alarms:?}"
        );
    }

    /// A step of 1.2 σ from sample 310 on what is read of ω (some 140 nats) pays on each of
    /// 100 noisy records, and is placed within 10 samples of its instant on at least 90 (a
    /// sample's shift costs about 1.2²/2 nats, against a noise that wanders by about 1.2·√k
    /// over k samples, the baseline free: half are within a sample).
    #[test]
    fn a_step_in_the_noise_pays_and_is_found_near_its_instant() {
        let instants: Vec<usize> = (MARGIN..=N - MARGIN).collect();
        let b = steps(2 * N, N, 1, 1.0, &instants);
        let mut near = 0;
        for seed in 0..100 {
            let mut y = noise(seed);
            for i in 310..N {
                y[N + i] += 1.2;
            }
            let (gain, j) = best_single_column(&b, &y, |_| true).unwrap();
            assert!(gain > bar(instants.len()), "seed {seed}: gain {gain}");
            near += usize::from(instants[j].abs_diff(310) <= 10);
        }
        assert!(near >= 90, "{near} of 100 within 10 samples");
    }
}
