//! The third verdict: structure the selected model leaves that no term of the library holds.
//!
//! After the forward selection (or with nothing selected) the selected model's MAP residuals
//! are asked whether generic alternatives that can hold "anything" explain them better than
//! white noise: a discrepancy polynomial in time per channel (degrees up to a tenth of the
//! samples), an autoregression of the residual (p = 1, 2, 4, 8), a sinusoid through the record
//! and a damped sinusoid ringing after each input step (`oscillation`; offered only where it
//! beats a transient after each step that does not ring, itself generic: `transient`), every
//! channel late by
//! τ (an input delay), one channel filtered with time constant τ (a sensor lag) and with a
//! second-order filter that rings (a resonant sensor, `resonance`), a channel that runs ahead
//! of the model (its derivative with a lead's sign: generic, no sensor leads, but a balance
//! whose fast dynamics the model has too slow looks so), isolated samples far off (a
//! contaminated normal of one channel's residual, `outliers`), a noise whose spread follows the
//! slope (the sampling instants' jitter, `slope_noise`), a torque at a few isolated instants
//! (a part knocking, a coupling catching: `knocks`), and the state fingerprints of the
//! balances and of what is read (`state`). Each is
//! scored as the ranking scores a term: its linearised gain in log likelihood with the model's
//! parameters refitted beside it (`regression`), less ½·ln N per degree of freedom, less the
//! logarithm of the grid a search ran over. The same alternatives are scored on the model as
//! given, less the score the selected terms gained over it: an effect the library holds only
//! in part (a term selected that absorbs most of it) then still shows.
//!
//! **The threshold** is the ranking's, [`EVIDENCE_THRESHOLD`] (2 nats), fixed before any case
//! was run, for the same reason. Under the model each alternative's gain is ½χ²_d; with the
//! BIC penalty at N = 1002 a one-degree alternative clears it with probability
//! P(χ²₁ > 2·(3.45 + 2)) ≈ 0.1%, a searched sinusoid with about the same (its grid's multiplicity
//! is paid for), and the larger alternatives far less often. About twenty alternatives per
//! record, most nested in one another, give a false alarm on a null record of about 1–2%,
//! which with the ranking's 1% stays within the 5% asked for.
//!
//! The **fingerprint** is the specific alternative (oscillation, delay, lag) with the best
//! score, unless a generic one (polynomial, autoregression) beats every specific one by more
//! than the threshold: then the kind is `unknown`. Others within the threshold of the leader
//! are listed as alternatives.

mod as_given;
mod column;
mod context;
mod figure;
mod fingerprint;
mod generic;
mod knocks;
mod order;
mod oscillation;
mod outliers;
mod quantized;
mod reading;
mod reading_step;
mod regression;
mod resonance;
mod slope_noise;
mod spans;
mod spot;
mod starts;
mod state;
mod step_screen;
mod timing;
mod torque_response;
mod transient;

use nalgebra::DMatrix;
use serde::Serialize;

use crate::bayes::{DiscrepancyBasis, Legendre};
use crate::error::Error;
use crate::study::Problem;

use super::candidate::Candidate;
use super::settings::EVIDENCE_THRESHOLD;
pub use as_given::{AsGiven, beyond_the_library};
pub use context::{Context, Scored};
pub use figure::{FOLDED_BINS, Folded, UnexplainedFigure};
pub use fingerprint::{
    EquationTerm, Fingerprint, LawFunction, equation_with, with_shapes, with_speed_limit,
    with_spot, with_time,
};
use generic::{Generic, GenericKind};
pub use oscillation::{frequency_search_cost, lowest_frequency_over};
pub use spans::Span;
use spans::spans;
pub use starts::{DYNAMIC, dynamic_starts};
pub use state::whole_order;
pub use step_screen::StepScreen;

/// Autoregression orders tried.
const AR_ORDERS: [usize; 4] = [1, 2, 4, 8];
/// Polynomial degrees tried (those below a tenth of the samples).
const DEGREES: [usize; 6] = [2, 4, 8, 16, 24, 32];

/// The verdict's report: `null` in the JSON when nothing is left.
#[derive(Clone, Debug, Serialize)]
pub struct Unexplained {
    /// The leading alternative's score over the selected model (nats).
    pub evidence: f64,
    pub channels: Vec<String>,
    #[serde(rename = "where")]
    pub spans: Vec<Span>,
    pub fingerprint: Fingerprint,
    pub alternatives: Vec<Fingerprint>,
    /// Every kind that clears the threshold on its own, best first, the leader among them (a
    /// delay beaten by a lag on one channel is still worth fitting as the term it names).
    #[serde(skip)]
    pub considered: Vec<Fingerprint>,
    pub suggestion: String,
    /// The evidence behind the fingerprint, for the command's figure.
    #[serde(skip)]
    pub figure: UnexplainedFigure,
}

/// Everything scored on one model's residuals: the fingerprints and the generic alternatives.
#[derive(Clone)]
struct Scores {
    fingerprints: Vec<Evidence>,
    generic: Vec<Generic>,
}

impl Scores {
    /// Every score against a bar raised by `shift` nats: what `scores(ctx, shift)` gives.
    fn shifted(mut self, shift: f64) -> Self {
        for e in &mut self.fingerprints {
            e.fingerprint = e.fingerprint.clone().shifted(shift);
        }
        for g in &mut self.generic {
            g.scored.score -= shift;
        }
        self
    }
}

/// A fingerprint with what it explains, and of which residual (whitened, stacked), for the
/// figure.
#[derive(Clone)]
struct Evidence {
    fingerprint: Fingerprint,
    residual: Vec<f64>,
    explained: Vec<f64>,
}

fn scores(ctx: &Context, shift: f64) -> Scores {
    let mut fingerprints = Vec::new();
    let mut generic = Vec::new();
    let n = ctx.n;
    let span = ctx.times[n - 1];
    for c in 0..ctx.channels.len() {
        let name = ctx.channels[c].clone();
        for k in DEGREES.iter().copied().filter(|k| (k + 1) * 10 <= n) {
            let Ok(basis) = Legendre::new(k, span) else {
                continue;
            };
            let b = ctx.in_channel(c, &basis.matrix(&ctx.times));
            generic.push(Generic {
                channel: c,
                kind: GenericKind::Polynomial,
                scored: ctx.score(&b, 0.0),
            });
        }
        for p in AR_ORDERS.iter().copied().filter(|p| p * 10 <= n) {
            let lags = DMatrix::from_fn(
                n,
                p,
                |i, l| {
                    if i > l { ctx.y[c * n + i - l - 1] } else { 0.0 }
                },
            );
            generic.push(Generic {
                channel: c,
                kind: GenericKind::Autoregression,
                scored: ctx.score(&ctx.in_channel(c, &lags), 0.0),
            });
        }
        // A ringing claims a frequency only where it beats a transient that does not ring.
        let transient = transient::search(ctx, c);
        let rings_not = |o: &oscillation::Oscillation| {
            o.ringing()
                && transient
                    .as_ref()
                    .is_some_and(|t| t.scored.score >= o.scored.score)
        };
        for o in oscillation::search(ctx, c)
            .into_iter()
            .filter(|o| !rings_not(o))
        {
            fingerprints.push(Evidence {
                fingerprint: o.fingerprint(&name, shift),
                residual: ctx.y.as_slice().to_vec(),
                explained: o.scored.explained.fitted.as_slice().to_vec(),
            });
        }
        if let Some(t) = transient {
            generic.push(Generic {
                channel: c,
                kind: GenericKind::Transient(t.taus),
                scored: t.scored,
            });
        }
        fingerprints.extend(quantized::evidence(ctx, c, shift));
        if let Some(o) = outliers::evidence(ctx, c) {
            generic.push(Generic {
                channel: c,
                kind: o.kind,
                scored: o.scored,
            });
        }
        // A lag: y_measured ≈ ŷ − τ·dŷ/dt on this channel alone (τ > 0), then fitted exactly.
        let d = DMatrix::from_column_slice(n, 1, &ctx.derivative(c));
        let s = ctx.score(&ctx.in_channel(c, &d), 0.0);
        let mut lag = None;
        if s.explained.coefficients[0] > 0.0 {
            // The channel runs ahead of the model: no sensor leads, but a balance whose fast
            // dynamics the model has too slow (an inductance too large) looks like this. Generic:
            // it says something is left, not what.
            generic.push(Generic {
                channel: c,
                kind: GenericKind::Lead,
                scored: s.clone(),
            });
        }
        if s.explained.coefficients[0] < 0.0
            && let Some(t) = timing::fit(ctx, &ctx.fine, Some(c), -s.explained.coefficients[0])
        {
            lag = (t.gain > 0.5 * ctx.ln_n).then_some(t.tau);
            fingerprints.push(Evidence {
                fingerprint: Fingerprint::Lag {
                    channel: name,
                    seconds: t.tau,
                    sd: t.sd,
                    score: t.gain - 0.5 * ctx.ln_n - shift,
                },
                residual: ctx.y.as_slice().to_vec(),
                explained: t.change,
            });
        }
        // The lag's next model: a sensor that rings.
        fingerprints.extend(resonance::evidence(ctx, c, lag, shift));
    }
    for k in knocks::evidence(ctx) {
        generic.push(Generic {
            channel: k.channel,
            kind: GenericKind::Knocks(k.starts, k.added),
            scored: k.scored,
        });
    }
    if let Some(j) = slope_noise::evidence(ctx) {
        generic.push(Generic {
            channel: j.channel,
            kind: j.kind,
            scored: j.scored,
        });
    }
    // A delay: every channel late by the same τ.
    let mut d = DMatrix::zeros(ctx.m(), 1);
    for c in 0..ctx.channels.len() {
        for (i, v) in ctx.derivative(c).into_iter().enumerate() {
            d[(c * n + i, 0)] = v;
        }
    }
    let s = ctx.score(&d, 0.0);
    if s.explained.coefficients[0] < 0.0
        && ctx.channels.len() > 1
        && let Some(t) = timing::fit(ctx, &ctx.fine, None, -s.explained.coefficients[0])
    {
        fingerprints.push(Evidence {
            fingerprint: Fingerprint::Delay {
                seconds: t.tau,
                sd: t.sd,
                score: t.gain - 0.5 * ctx.ln_n - shift,
            },
            residual: ctx.y.as_slice().to_vec(),
            explained: t.change,
        });
    }
    for g in &mut generic {
        g.scored.score -= shift;
    }
    Scores {
        fingerprints,
        generic,
    }
}

/// The verdict on the first record: `None` when the selected model leaves nothing a generic
/// alternative finds, by more than the threshold, on it or on the model as given.
pub fn unexplained(
    problem: &Problem,
    selected: &Candidate,
    none: &Candidate,
    as_given: &AsGiven,
) -> Result<Option<Unexplained>, Error> {
    if problem.recordings.is_empty() {
        return Ok(None);
    }
    let ctx = Context::of(problem, selected, 0)?;
    if ctx.n < 20 {
        return Ok(None);
    }
    // With nothing selected the selected model is the model as given, scored once already.
    let mut all = match as_given.scores(0.0) {
        Some(s) if selected.added.is_empty() => s,
        _ => scores(&ctx, 0.0),
    };
    // The noise models among the model as given's generic alternatives, against what the
    // selected terms gained: no term holds a noise's shape, so a term that gained less than
    // one of them did (a jitter's few late samples on the current's flanks fitted as a lag)
    // is no evidence that the noise is what the model assumes.
    let mut noise_on_none: Vec<Generic> = Vec::new();
    if selected.added.is_empty() {
        all.fingerprints.extend(as_given.shifted(0.0));
    } else {
        all.fingerprints
            .extend(state::fingerprints(selected, &ctx, 0.0)?);
        // What the selected terms gained over the model as given is the bar an alternative on
        // the model as given must clear to count against them. A law a library term absorbs
        // almost whole (Stribeck friction taken as Coulomb friction, a supply that sags with
        // the charge taken as a back-EMF constant) shows best there.
        let shift = selected.score - none.score;
        let on_none = match as_given.scores(shift) {
            Some(s) => s,
            None => scores(&Context::of(problem, none, 0)?, shift),
        };
        all.fingerprints.extend(on_none.fingerprints);
        all.fingerprints.extend(as_given.shifted(shift));
        noise_on_none = (on_none.generic.into_iter())
            .filter(|g| g.kind.is_noise())
            .collect();
    }
    // The best generic alternative, and whether it was seen on the model as given.
    let best_generic = (all.generic.iter().map(|g| (g, false)))
        .chain(noise_on_none.iter().map(|g| (g, true)))
        .max_by(|a, b| a.0.scored.score.total_cmp(&b.0.scored.score));
    let mut candidates: Vec<Evidence> = all.fingerprints;
    if let Some((g, on_none)) = best_generic {
        let residual = match on_none && !as_given.residual().is_empty() {
            true => as_given.residual(),
            false => ctx.y.as_slice(),
        };
        candidates.push(Evidence {
            fingerprint: Fingerprint::Unknown {
                score: g.scored.score,
            },
            residual: residual.to_vec(),
            explained: g.scored.explained.fitted.as_slice().to_vec(),
        });
    }
    // A generic alternative leads only when it beats every specific one by more than the
    // threshold: it can hold anything, so it must buy its generality.
    let rank = |f: &Fingerprint| match f {
        Fingerprint::Unknown { score } => score - EVIDENCE_THRESHOLD,
        other => other.score(),
    };
    candidates.sort_by(|a, b| rank(&b.fingerprint).total_cmp(&rank(&a.fingerprint)));
    // One of each kind (per channel, and ringing or not): the best, whichever model it was
    // scored on.
    let mut seen = Vec::new();
    candidates.retain(|e| {
        let key = e.fingerprint.identity();
        let fresh = !seen.contains(&key);
        seen.push(key);
        fresh
    });
    let evidence = candidates
        .iter()
        .map(|e| e.fingerprint.score())
        .chain(best_generic.map(|(g, _)| g.scored.score))
        .fold(f64::NEG_INFINITY, f64::max);
    if !(evidence > EVIDENCE_THRESHOLD) {
        return Ok(None);
    }
    // A specific kind leads only where it clears the threshold itself; otherwise what is left
    // is `unknown` (the generic alternatives' evidence).
    let eligible = |e: &Evidence| {
        matches!(e.fingerprint, Fingerprint::Unknown { .. })
            || e.fingerprint.score() > EVIDENCE_THRESHOLD
    };
    candidates.retain(eligible);
    if candidates.is_empty() {
        return Ok(None);
    }
    let lead = rank(&candidates[0].fingerprint);
    let fingerprint = candidates[0].fingerprint.clone();
    let considered: Vec<Fingerprint> = candidates
        .iter()
        .map(|e| e.fingerprint.clone())
        .filter(|f| f.score() > EVIDENCE_THRESHOLD)
        .collect();
    let alternatives: Vec<Fingerprint> = candidates[1..]
        .iter()
        .map(|e| e.fingerprint.clone())
        .filter(|f| f.score() > EVIDENCE_THRESHOLD && lead - rank(f) <= EVIDENCE_THRESHOLD)
        .collect();
    let figure = UnexplainedFigure {
        times: ctx.times.clone(),
        channels: ctx.channels.clone(),
        residual: candidates[0].residual.clone(),
        explained: candidates[0].explained.clone(),
        spectrum: (0..ctx.channels.len())
            .map(|c| oscillation::spectrum(&ctx, c))
            .collect(),
        folded: figure::folded(&ctx, &fingerprint, &candidates[0].residual),
    };
    let mut channels = Vec::new();
    let mut where_ = Vec::new();
    for c in 0..ctx.channels.len() {
        let best = (all.generic.iter())
            .chain(&noise_on_none)
            .filter(|g| g.channel == c)
            .max_by(|a, b| a.scored.score.total_cmp(&b.scored.score));
        if best.is_some_and(|g| g.scored.score > EVIDENCE_THRESHOLD) {
            channels.push(ctx.channels[c].clone());
            let polynomial = all
                .generic
                .iter()
                .filter(|g| g.channel == c && g.kind == GenericKind::Polynomial)
                .max_by(|a, b| a.scored.score.total_cmp(&b.scored.score));
            if let Some(g) = polynomial {
                where_.extend(spans(&ctx, c, &g.scored.explained));
            }
        }
    }
    if channels.is_empty() {
        channels = ctx.channels.clone();
    }
    let mut suggestion = fingerprint.suggestion(&channels);
    if let (Fingerprint::Unknown { .. }, Some((g, on_none))) = (&fingerprint, best_generic)
        && let Some((spans, sentence)) = g.reported(&ctx)
    {
        suggestion = match on_none {
            true => format!(
                "{sentence}; seen on the model as given, where it explains {:.1} nats more \
                 than the selected terms gained",
                g.scored.score
            ),
            false => sentence,
        };
        if let Some(spans) = spans {
            where_ = spans;
        }
    }
    Ok(Some(Unexplained {
        evidence,
        channels,
        spans: where_,
        fingerprint,
        alternatives,
        considered,
        suggestion,
        figure,
    }))
}
