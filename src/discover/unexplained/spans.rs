//! Where a channel's residual departs from zero: the report's `where`, from the best
//! polynomial of each channel that clears the threshold.

use serde::Serialize;

use super::Context;
use super::regression::Explained;
use crate::discover::fits::MISMATCH_MIN_SHARE;

/// Where the best polynomial of a channel departs from zero by more than two of its sds.
#[derive(Clone, Debug, Serialize)]
pub struct Span {
    pub channel: String,
    pub t_start: f64,
    pub t_end: f64,
}

/// Samples where a fitted curve departs from zero by more than two of its sds, as intervals of
/// at least `MISMATCH_MIN_SHARE` of the record.
pub(super) fn spans(ctx: &Context, c: usize, e: &Explained) -> Vec<Span> {
    let n = ctx.n;
    runs(ctx, c, MISMATCH_MIN_SHARE, |i| {
        let k = c * n + i;
        e.fitted[k].abs() > 2.0 * e.fitted_sd[k]
    })
}

/// The runs of consecutive samples of channel c where `off` holds, as intervals lasting at least
/// `min_share` of the record.
pub(super) fn runs(
    ctx: &Context,
    c: usize,
    min_share: f64,
    off: impl Fn(usize) -> bool,
) -> Vec<Span> {
    let n = ctx.n;
    let duration = ctx.times[n - 1] - ctx.times[0];
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    for i in 0..=n {
        match (i < n && off(i), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                let (a, b) = (ctx.times[s], ctx.times[i - 1]);
                if b - a >= min_share * duration {
                    out.push(Span {
                        channel: ctx.channels[c].clone(),
                        t_start: a,
                        t_end: b,
                    });
                }
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// The report's `where` for isolated samples of channel c (an outlier's, a knock's start): one
/// instant each.
pub(super) fn at_samples(ctx: &Context, c: usize, samples: &[usize]) -> Vec<Span> {
    samples
        .iter()
        .map(|&i| Span {
            channel: ctx.channels[c].clone(),
            t_start: ctx.times[i],
            t_end: ctx.times[i],
        })
        .collect()
}

/// Instants [s] as a sentence lists them: the first eight, then an ellipsis.
pub(super) fn listed(times: &[f64]) -> String {
    let shown: Vec<String> = times.iter().take(8).map(|t| format!("{t:.4}")).collect();
    let more = if times.len() > 8 { ", …" } else { "" };
    format!("{}{more}", shown.join(", "))
}
