//! What a fit predicts: G(θ) + δ with its credible band per channel, and the residuals.

use crate::bayes::CalibrationPosterior;
use crate::sampler::ChainOutput;

use crate::error::Error;

/// Draws used for bands: enough for stable 95% quantiles, few enough to solve the ODE for each.
const BAND_DRAWS: usize = 400;

/// Per channel, at every sample time.
#[derive(Clone, Debug)]
pub struct ChannelPredictive {
    pub name: String,
    pub unit: String,
    pub measured: Vec<f64>,
    /// G at the posterior mean of θ.
    pub model: Vec<f64>,
    /// Posterior mean of G(θ) + δ and its 95% band.
    pub mean: Vec<f64>,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Posterior mean of δ and its 95% band.
    pub discrepancy_mean: Vec<f64>,
    pub discrepancy_lower: Vec<f64>,
    pub discrepancy_upper: Vec<f64>,
    /// Posterior mean of the channel's noise σ.
    pub sigma: f64,
}

#[derive(Clone, Debug)]
pub struct Predictive {
    pub times: Vec<f64>,
    pub channels: Vec<ChannelPredictive>,
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * q;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// The posterior predictive of recording `record` from the chains' unconstrained draws.
pub fn posterior_predictive(
    posterior: &mut CalibrationPosterior,
    chains: &[ChainOutput],
    record: usize,
) -> Result<Predictive, Error> {
    let all: Vec<&Vec<f64>> = chains.iter().flat_map(|c| c.unconstrained.iter()).collect();
    if all.is_empty() {
        return Err(Error::Numerical("no draws to predict from".into()));
    }
    let stride = (all.len() / BAND_DRAWS).max(1);
    let picked: Vec<&Vec<f64>> = all.iter().step_by(stride).copied().collect();
    let d = all[0].len();
    let mut mean_x = vec![0.0; d];
    for x in &all {
        for (m, v) in mean_x.iter_mut().zip(x.iter()) {
            *m += v / all.len() as f64;
        }
    }
    let times = posterior.forward(record).times().to_vec();
    let base = posterior.forward(record).model().base;
    let m = times.len();
    let names: Vec<String> = posterior
        .forward(record)
        .channels()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let model_at_mean = posterior.simulate(&mean_x, record)?;
    // totals[c][draw][i] and discrepancies likewise
    let mut totals = vec![Vec::with_capacity(picked.len()); names.len()];
    let mut deltas = vec![Vec::with_capacity(picked.len()); names.len()];
    for x in &picked {
        let g = posterior.simulate(x, record)?;
        for c in 0..names.len() {
            let delta = posterior.discrepancy(x, record, c);
            totals[c].push(
                (0..m)
                    .map(|i| g[c * m + i] + delta[i])
                    .collect::<Vec<f64>>(),
            );
            deltas[c].push(delta);
        }
    }
    let band = |rows: &[Vec<f64>]| {
        let mut mean = vec![0.0; m];
        let mut lower = vec![0.0; m];
        let mut upper = vec![0.0; m];
        let mut column = vec![0.0; rows.len()];
        for i in 0..m {
            for (k, r) in rows.iter().enumerate() {
                column[k] = r[i];
            }
            mean[i] = column.iter().sum::<f64>() / rows.len() as f64;
            column.sort_by(|a, b| a.total_cmp(b));
            lower[i] = quantile(&column, 0.025);
            upper[i] = quantile(&column, 0.975);
        }
        (mean, lower, upper)
    };
    let mut channels = Vec::new();
    for (c, name) in names.iter().enumerate() {
        let (mean, lower, upper) = band(&totals[c]);
        let (dm, dl, du) = band(&deltas[c]);
        let si = posterior.log_sigma_index(record, c);
        let sigma = all.iter().map(|x| x[si].exp()).sum::<f64>() / all.len() as f64;
        channels.push(ChannelPredictive {
            name: name.clone(),
            unit: base.channel_unit(name).into(),
            measured: posterior.observed(record, c).to_vec(),
            model: model_at_mean[c * m..(c + 1) * m].to_vec(),
            mean,
            lower,
            upper,
            discrepancy_mean: dm,
            discrepancy_lower: dl,
            discrepancy_upper: du,
            sigma,
        });
    }
    Ok(Predictive { times, channels })
}

/// A channel's replicated recordings: `[chain][draw][sample]`.
pub type Replicated = Vec<Vec<Vec<f64>>>;

/// Replicated recordings, one per kept draw: y_rep = G(θ) + δ(a) + σ·ε, ε ~ N(0, 1) — what
/// ArviZ calls the posterior predictive, per record and channel. The
/// noise comes from `seed`'s own stream per chain, so the same draws and seed replicate alike
/// whatever the thread count. One plain solve per draw.
pub fn replicated_recordings(
    posterior: &mut CalibrationPosterior,
    chains: &[ChainOutput],
    seed: u64,
) -> Result<Vec<Vec<Replicated>>, Error> {
    use rand_distr::{Distribution, StandardNormal};
    let records = posterior.n_records();
    let mut out: Vec<Vec<Replicated>> = (0..records)
        .map(|r| vec![Vec::with_capacity(chains.len()); posterior.channel_names(r).len()])
        .collect();
    for (c, chain) in chains.iter().enumerate() {
        let mut rng = crate::sampler::driver::chain_rng(seed ^ 0x9e37_79b9_7f4a_7c15, c);
        for per_record in out.iter_mut() {
            for per_channel in per_record.iter_mut() {
                per_channel.push(Vec::with_capacity(chain.unconstrained.len()));
            }
        }
        for x in &chain.unconstrained {
            for (r, per_record) in out.iter_mut().enumerate() {
                // y − residual = G(θ) + δ(a) at this draw.
                let residuals = posterior.residuals(x, r)?;
                for (ch, residual) in residuals.iter().enumerate() {
                    let sigma = x[posterior.log_sigma_index(r, ch)].exp();
                    let observed = posterior.observed(r, ch);
                    let replicated = observed
                        .iter()
                        .zip(residual)
                        .map(|(y, e)| {
                            let noise: f64 = StandardNormal.sample(&mut rng);
                            y - e + sigma * noise
                        })
                        .collect();
                    per_record[ch][c].push(replicated);
                }
            }
        }
    }
    Ok(out)
}
