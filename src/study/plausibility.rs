//! Recordings that cannot be this motor as set up: a dead channel, a unit or sign error, two
//! channels swapped, time in milliseconds, a channel that does not follow the model at all.
//! Checked before any physics is asked of the recording, from one solve of the model as given
//! per record (and one more with the time in seconds read as milliseconds), in well under a
//! second on a 501-sample record.
//!
//! **The rules and why.**
//! - *Dead or constant*: a channel whose spread is below [`DEAD_SHARE`] of the spread the model
//!   predicts for it. Noise alone gives a recorded channel some spread; a logger that wrote
//!   zeros, or a column that holds a constant, gives none.
//! - *Scale*: the best scale `a` of the model's prediction for the channel (least squares
//!   through the origin, y ≈ a·g). Nothing a model leaves out makes a motor run several times
//!   faster or draw several times more current than its supply and constants allow (a
//!   torque-constant or sensor-gain error is tens of percent), so a best scale above
//!   [`SCALE_BAND`] is no physics of this motor; what is left out is mostly dissipation or
//!   load, which can hold a rig well below its prediction, so the floor is lower,
//!   [`SCALE_FLOOR`]; a negative scale is never physics. The likely causes are then tested
//!   where cheap — a unit factor (10^±3, 10^±6, rpm for rad/s), a sign flip, the channels
//!   swapped, the time in milliseconds — each a hypothesis "the record is the model seen through
//!   this mistake" that, undone, leaves the channel on the model's scale, compared with the record as it is by the Gaussian log likelihood at each
//!   channel's maximum-likelihood noise: −N/2·ln(RSS_fix / RSS_as_is). A cause is named when it
//!   wins by more than [`EVIDENCE_NATS`]; the time in milliseconds is tested on every record,
//!   since it leaves the scale alone. When no known factor explains an off-scale channel but
//!   the scaled prediction still holds at least [`FOLLOWS_SHARE`] of its variation, the channel
//!   is the model's shape at another scale: a unit or scaling the file does not state (named
//!   by its order of magnitude); otherwise the channel does not follow the model at all.
//!
//! A record that passes keeps its diagnosis untouched: nothing here changes the problem.

use serde::Serialize;

use crate::error::Error;

use super::{Problem, RecordPrediction, predict_records};

/// A channel whose standard deviation is below this share of its predicted one is dead or
/// constant: one part in a thousand is below any noise a logger records on a moving motor.
pub const DEAD_SHARE: f64 = 1e-3;

/// The factor by which a record may exceed the model's prediction before the excess cannot be
/// physics (see the module's doc).
pub const SCALE_BAND: f64 = 3.0;

/// The share of the prediction below which a record cannot be this motor: what a model leaves
/// out is mostly dissipation or load (friction, drag, a load torque, a voltage drop), which can
/// hold a rig far below the speed its drive alone would reach — HSM150's documented viscous
/// model predicts about four times the speed measured — but not at a thirtieth of it while it
/// still moves.
pub const SCALE_FLOOR: f64 = 1.0 / 30.0;

/// The log-likelihood lead a mistake must have over the record as it is to be named: a Bayes
/// factor of e¹⁰ ≈ 22 000, for a handful of hypotheses tested at once. The mistakes this
/// names lead by thousands of nats on a 501-sample record.
pub const EVIDENCE_NATS: f64 = 10.0;

/// The share of a channel's variation the scaled prediction must hold for the channel to be
/// called the model's shape at another scale: noise, or another quantity, holds next to none of
/// it (pure noise a few per cent at most on 501 samples); a scaled record of this motor nearly
/// all of it. A half is far from both.
pub const FOLLOWS_SHARE: f64 = 0.5;

/// rad/s recorded as rpm: the value is 60/(2π) times larger.
const RPM_PER_RAD_S: f64 = 60.0 / (2.0 * std::f64::consts::PI);

/// One thing wrong with a record, as the commands report it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// The record's file (or label).
    pub record: String,
    /// The channel's column name in the model file's terms (`I`, `omega`, `q`, `force`), or
    /// `t` for the time.
    pub channel: String,
    /// What is wrong, with what was expected.
    pub finding: String,
    /// What to check.
    pub likely_cause: String,
    /// The log-likelihood lead of the likely cause over the record as it is (nats), where a
    /// cause was tested; `None` for a dead channel.
    pub evidence: Option<f64>,
}

impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {}: {}; {}",
            self.record, self.channel, self.finding, self.likely_cause
        )?;
        if let Some(e) = self.evidence {
            write!(f, " (log likelihood {e:+.0} nats over the record as it is)")?;
        }
        Ok(())
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn sd(v: &[f64]) -> f64 {
    let m = mean(v);
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

fn rss(y: &[f64], g: &[f64], scale: f64) -> f64 {
    y.iter().zip(g).map(|(a, b)| (a - scale * b).powi(2)).sum()
}

/// The Gaussian log likelihood of `n` residuals with sum of squares `rss` at their
/// maximum-likelihood σ, up to a constant shared by every hypothesis about the same record.
fn log_likelihood(n: usize, rss: f64) -> f64 {
    -0.5 * n as f64 * rss.max(f64::MIN_POSITIVE).ln()
}

/// How much better a hypothesis explains the record than the record as it is (nats).
fn lead(n: usize, rss_fix: f64, rss_as_is: f64) -> f64 {
    log_likelihood(n, rss_fix) - log_likelihood(n, rss_as_is)
}

/// The share of a channel's variation the prediction at `scale` explains (R²).
fn explained_share(y: &[f64], g: &[f64], scale: f64) -> f64 {
    let m = mean(y);
    let total: f64 = y.iter().map(|v| (v - m).powi(2)).sum();
    if total > 0.0 {
        1.0 - rss(y, g, scale) / total
    } else {
        0.0
    }
}

/// The unit and sign mistakes tested, as (factor the record carries, its cause).
fn scale_mistakes(channel: &str, unit: &str) -> Vec<(f64, String)> {
    let mut out = vec![(
        -1.0,
        format!("{channel} has the wrong sign (a sensor or a wiring reversed)"),
    )];
    for (factor, prefix) in [(1e3, "m"), (1e6, "µ"), (1e-3, "k"), (1e-6, "M")] {
        out.push((
            factor,
            format!("{channel} is in {prefix}{unit}, not {unit} (a factor {factor:e})"),
        ));
    }
    if unit == "rad/s" {
        out.push((
            RPM_PER_RAD_S,
            format!("{channel} is in rpm, not rad/s (a factor 60/2π)"),
        ));
        out.push((
            1.0 / RPM_PER_RAD_S,
            format!("{channel} is in rad/s where the model expects rpm (a factor 2π/60)"),
        ));
    }
    out
}

/// The findings of one record's prediction (none when it is plausible).
fn check_record(problem: &Problem, p: &RecordPrediction) -> Vec<Finding> {
    let mut findings = Vec::new();
    let base = problem.model.base;
    let mut off_scale = Vec::new();
    for (name, measured, predicted) in &p.channels {
        let unit = base.channel_unit(name);
        let (lo, hi) = predicted
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        let predicted_sd = sd(predicted);
        if predicted_sd > 0.0 && sd(measured) <= DEAD_SHARE * predicted_sd {
            let level = mean(measured);
            let what = if measured.iter().all(|v| *v == 0.0) {
                format!("{name} is 0 throughout")
            } else {
                format!("{name} is constant at {level:.4e} {unit}")
            };
            findings.push(Finding {
                record: p.source.clone(),
                channel: name.clone(),
                finding: format!("{what}; the model predicts it from {lo:.4e} to {hi:.4e} {unit}"),
                likely_cause: format!(
                    "was the drive running, and is the column the one with {name}?"
                ),
                evidence: None,
            });
            continue;
        }
        let gg: f64 = predicted.iter().map(|v| v * v).sum();
        let scale = if gg > 0.0 {
            measured
                .iter()
                .zip(predicted)
                .map(|(a, b)| a * b)
                .sum::<f64>()
                / gg
        } else {
            f64::NAN
        };
        if !(SCALE_FLOOR..=SCALE_BAND).contains(&scale) {
            off_scale.push((name.clone(), measured, predicted, scale, unit));
        }
    }
    // Swapped channels: each measured column against the other's prediction.
    if p.channels.len() == 2 && !off_scale.is_empty() {
        let (a, b) = (&p.channels[0], &p.channels[1]);
        let n = a.1.len();
        let as_is =
            log_likelihood(n, rss(&a.1, &a.2, 1.0)) + log_likelihood(n, rss(&b.1, &b.2, 1.0));
        let swapped =
            log_likelihood(n, rss(&b.1, &a.2, 1.0)) + log_likelihood(n, rss(&a.1, &b.2, 1.0));
        if swapped - as_is > EVIDENCE_NATS {
            findings.push(Finding {
                record: p.source.clone(),
                channel: format!("{}/{}", a.0, b.0),
                finding: format!(
                    "{} follows the model's {} and {} its {}",
                    a.0, b.0, b.0, a.0
                ),
                likely_cause: format!(
                    "the columns {} and {} are swapped: check the header or [channels]",
                    a.0, b.0
                ),
                evidence: Some(swapped - as_is),
            });
            return findings;
        }
    }
    for (name, measured, predicted, scale, unit) in off_scale {
        let n = measured.len();
        let as_is = rss(measured, predicted, 1.0);
        // A mistake explains the record only if, undone, it leaves the channel within a factor
        // of three of the model: a factor that merely shrinks the prediction to nothing fits
        // noise better too.
        let best = scale_mistakes(&name, unit)
            .into_iter()
            .filter(|(factor, _)| (1.0 / SCALE_BAND..=SCALE_BAND).contains(&(scale / factor)))
            .map(|(factor, cause)| (lead(n, rss(measured, predicted, factor), as_is), cause))
            .max_by(|x, y| x.0.total_cmp(&y.0));
        let expected = format!(
            "the best scale of the model's prediction is {scale:.3e}, where physics keeps it \
             between {SCALE_FLOOR:.3} and {SCALE_BAND}"
        );
        match best {
            Some((evidence, cause)) if evidence > EVIDENCE_NATS => findings.push(Finding {
                record: p.source.clone(),
                channel: name.clone(),
                finding: expected,
                likely_cause: cause,
                evidence: Some(evidence),
            }),
            // No factor we know, but the channel is the model's shape at another scale: it
            // holds most of its variation (R² ≥ ½ for the scaled prediction), which noise or
            // another quantity would not.
            _ if explained_share(measured, predicted, scale) >= FOLLOWS_SHARE => {
                let order = 10f64.powi(scale.abs().log10().round() as i32);
                findings.push(Finding {
                    record: p.source.clone(),
                    channel: name.clone(),
                    finding: format!("{name} follows the model's shape, scaled: {expected}"),
                    likely_cause: format!(
                        "{name} carries a unit or scale factor of about {}{order:e} that the \
                         file does not state: check the logger's scaling and the column's unit \
                         ({unit} expected)",
                        if scale < 0.0 { "−" } else { "" }
                    ),
                    evidence: Some(lead(n, rss(measured, predicted, scale), as_is)),
                })
            }
            _ => findings.push(Finding {
                record: p.source.clone(),
                channel: name.clone(),
                finding: format!("{name} does not follow the model: {expected}"),
                likely_cause: format!(
                    "is the column {name} at all (noise, another quantity, another rig)?"
                ),
                evidence: None,
            }),
        }
    }
    findings
}

/// Record `r` alone, its time scaled by `time_scale` (1e-3: read as milliseconds).
fn record_problem(problem: &Problem, r: usize, time_scale: f64) -> Problem {
    let mut recording = problem.recordings[r].clone();
    for t in recording.time.iter_mut() {
        *t *= time_scale;
    }
    Problem {
        label: problem.label.clone(),
        recordings: vec![recording],
        model: problem.model.clone(),
        reference: None,
    }
}

/// The summed log likelihood of a record's channels against a prediction of them.
fn record_log_likelihood(p: &RecordPrediction) -> f64 {
    p.channels
        .iter()
        .map(|(_, y, g)| log_likelihood(y.len(), rss(y, g, 1.0)))
        .sum()
}

/// Every finding on every record of `problem`; empty when the recordings can be this motor.
///
/// The time in milliseconds leaves every scale alone, so it is tested on each record on its
/// own: the record read in ms is named when, so read, it passes every other check and explains
/// the data better than the record as it is by more than [`EVIDENCE_NATS`] (or when the model
/// cannot even be solved over the record as it is: 500 "seconds" of a motor whose time
/// constants are milliseconds).
pub fn check(problem: &Problem) -> Result<Vec<Finding>, Error> {
    let mut findings = Vec::new();
    for r in 0..problem.recordings.len() {
        let as_is = predict_records(&record_problem(problem, r, 1.0)).map(|mut p| p.remove(0));
        let in_ms = predict_records(&record_problem(problem, r, 1e-3)).map(|mut p| p.remove(0));
        let plausible_in_ms = in_ms
            .as_ref()
            .ok()
            .filter(|p| check_record(problem, p).is_empty());
        let lead_in_ms = match (&as_is, plausible_in_ms) {
            (Ok(a), Some(m)) => Some(record_log_likelihood(m) - record_log_likelihood(a)),
            (Err(_), Some(_)) => Some(f64::INFINITY),
            _ => None,
        };
        if let Some(gain) = lead_in_ms.filter(|g| *g > EVIDENCE_NATS) {
            let source = &problem.recordings[r];
            findings.push(Finding {
                record: source.source.clone(),
                channel: "t".into(),
                finding: format!(
                    "the record lasts {:.4e} s, and read as milliseconds it is this motor",
                    source.time.last().copied().unwrap_or(0.0)
                ),
                likely_cause: "the time column is in ms, not s".into(),
                evidence: gain.is_finite().then_some(gain),
            });
            continue;
        }
        findings.extend(check_record(problem, &as_is?));
    }
    Ok(findings)
}
