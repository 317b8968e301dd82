//! Axes: range, ticks and labels, linear or logarithmic.

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

// ---------------------------------------------------------------------------------------
// Axes: range, ticks, labels
// ---------------------------------------------------------------------------------------

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum TickFmt {
    /// Fixed-point with this many decimals.
    Fixed(usize),
    /// Scientific with this many mantissa decimals.
    Sci(usize),
    /// Each tick on its own, shortest representation (log axes).
    Sig,
}

/// One axis in plot coordinates: data values map through [`Axis::tr`] (identity, or log10
/// on a logarithmic axis) to the range `lo..hi`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Axis {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) log: bool,
    pub(crate) ticks: Vec<f64>,
    pub(crate) fmt: TickFmt,
}

impl Axis {
    /// Axis for a panel without usable data.
    pub(crate) fn fallback(log: bool) -> Axis {
        if log {
            log_axis([1.0, 10.0], 0.0, 5)
        } else {
            linear_axis([0.0, 1.0], 0.0, 0.0, false, 5)
        }
        .expect("fixed finite range")
    }

    /// Data value → plot coordinate, `None` if it cannot be shown on this axis.
    pub(crate) fn tr(&self, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if self.log {
            (v > 0.0).then(|| v.log10())
        } else {
            Some(v)
        }
    }

    /// Tick label of a plot coordinate.
    pub(crate) fn label(&self, p: f64) -> String {
        if self.log {
            return fmt_sig(10f64.powf(p));
        }
        match self.fmt {
            TickFmt::Fixed(d) => format!("{p:.d$}"),
            TickFmt::Sci(d) => format!("{p:.d$e}"),
            TickFmt::Sig => fmt_sig(p),
        }
    }

    pub(crate) fn coord(&self) -> TickedRange {
        TickedRange {
            lo: self.lo,
            hi: self.hi,
            ticks: self.ticks.clone(),
        }
    }
}

/// Linear plotters coordinate over plot coordinates with our own tick positions (bold
/// grid lines and labels; no light grid lines).
pub(crate) struct TickedRange {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) ticks: Vec<f64>,
}

impl Ranged for TickedRange {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = (v - self.lo) / (self.hi - self.lo);
        let px = f64::from(limit.0) + t * f64::from(limit.1 - limit.0);
        // Saturating conversion; far-away values end up outside the plotting area.
        px.round().clamp(-1e6, 1e6) as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// A "nice" tick step (1, 2, 2.5 or 5 times a power of ten) giving about `target` ticks
/// inside `lo..=hi`, and at least three where the candidates allow.
pub(crate) fn nice_step(lo: f64, hi: f64, target: usize, integer: bool) -> f64 {
    let raw = (hi - lo) / target.max(2) as f64;
    let e0 = raw.log10().floor() as i32;
    let cands: &[f64] = if integer {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0, 2.0, 2.5, 5.0]
    };
    let mut best: Option<(f64, f64)> = None;
    for e in (e0 - 1)..=(e0 + 1) {
        for &c in cands {
            let step = c * 10f64.powi(e);
            if integer && step < 1.0 {
                continue;
            }
            let n = linear_ticks(lo, hi, step).len() as f64;
            let score = (n - target as f64).abs()
                + if n < 3.0 { 100.0 } else { 0.0 }
                + if c == 2.5 { 0.5 } else { 0.0 };
            // Ascending steps: on a tie the coarser one wins.
            if best.is_none_or(|(s, _)| score <= s) {
                best = Some((score, step));
            }
        }
    }
    best.map_or(1.0, |(_, step)| step)
}

pub(crate) fn linear_ticks(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let i0 = (lo / step - 1e-9).ceil() as i64;
    let i1 = (hi / step + 1e-9).floor() as i64;
    (i0..=i1)
        .take(1000)
        .map(|i| {
            let t = i as f64 * step;
            if t.abs() < step * 1e-9 { 0.0 } else { t }
        })
        .collect()
}

/// Linear axis over the finite values, padded by `pad_frac` of the span (at least
/// `abs_pad`); an all-equal range is widened. `None` without finite values.
pub(crate) fn linear_axis(
    vals: impl IntoIterator<Item = f64>,
    pad_frac: f64,
    abs_pad: f64,
    integer: bool,
    target: usize,
) -> Option<Axis> {
    let (min, max) = min_max(vals.into_iter().filter(|v| v.is_finite()))?;
    let span = max - min;
    if !span.is_finite() {
        return None;
    }
    let (lo, hi) = if span <= 1e-12 * min.abs().max(max.abs()) {
        let c = 0.5 * (min + max);
        let pad = if c != 0.0 { 0.1 * c.abs() } else { 1.0 }.max(abs_pad);
        (c - pad, c + pad)
    } else {
        let pad = (span * pad_frac).max(abs_pad);
        (min - pad, max + pad)
    };
    if !(hi - lo).is_finite() || hi <= lo {
        return None;
    }
    let step = nice_step(lo, hi, target, integer);
    let ticks = linear_ticks(lo, hi, step);
    let mant = step / 10f64.powf(step.log10().floor());
    let extra = usize::from((mant - 2.5).abs() < 1e-6);
    let m = lo.abs().max(hi.abs());
    let fmt = if !(1e-3..1e5).contains(&m) {
        let digits = (m.log10().floor() - step.log10().floor()).max(0.0) as usize;
        TickFmt::Sci(digits + extra)
    } else {
        let d = (-step.log10() - 1e-9).ceil().max(0.0) as usize;
        TickFmt::Fixed(d + extra)
    };
    Some(Axis {
        lo,
        hi,
        log: false,
        ticks,
        fmt,
    })
}

/// Logarithmic axis over the finite positive values (others are skipped), padded by
/// `pad_frac` of the span in decades. `None` without such values.
pub(crate) fn log_axis(
    vals: impl IntoIterator<Item = f64>,
    pad_frac: f64,
    target: usize,
) -> Option<Axis> {
    let (min, max) = min_max(
        vals.into_iter()
            .filter(|v| v.is_finite() && *v > 0.0)
            .map(f64::log10),
    )?;
    let span = max - min;
    let (lo, hi) = if span < 1e-9 {
        (min - 0.3, max + 0.3)
    } else {
        (min - span * pad_frac, max + span * pad_frac)
    };
    let target = target.max(3);
    let span = hi - lo;
    let decades = |every: i64| -> Vec<f64> {
        let d0 = lo.ceil() as i64;
        let d1 = hi.floor() as i64;
        (d0..=d1)
            .filter(|d| d.rem_euclid(every) == 0)
            .map(|d| d as f64)
            .collect()
    };
    let multiples = |ms: &[f64]| -> Vec<f64> {
        let d0 = lo.floor() as i64;
        let d1 = hi.ceil() as i64;
        (d0..=d1)
            .flat_map(|d| ms.iter().map(move |m| d as f64 + m.log10()))
            .filter(|&t| t >= lo - 1e-12 && t <= hi + 1e-12)
            .collect()
    };
    let mut ticks = if span > target as f64 {
        decades((span / target as f64).ceil() as i64)
    } else {
        let mut chosen = decades(1);
        for ms in [
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0][..],
            &[1.0, 2.0, 3.0, 5.0][..],
            &[1.0, 2.0, 5.0][..],
            &[1.0, 3.0][..],
        ] {
            let t = multiples(ms);
            if t.len() <= target {
                chosen = t;
                break;
            }
        }
        chosen
    };
    if ticks.len() < 2 {
        // Less than a decade: linear ticks in value space.
        let (vlo, vhi) = (10f64.powf(lo), 10f64.powf(hi));
        let step = nice_step(vlo, vhi, target.min(6), false);
        ticks = linear_ticks(vlo, vhi, step)
            .into_iter()
            .filter(|&v| v > 0.0)
            .map(f64::log10)
            .collect();
    }
    Some(Axis {
        lo,
        hi,
        log: true,
        ticks,
        fmt: TickFmt::Sig,
    })
}

pub(crate) fn min_max(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    vals.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((a, b)) => Some((a.min(v), b.max(v))),
    })
}

/// Shortest readable representation of a value, rounded to ten significant digits.
pub(crate) fn fmt_sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { format!("{v}") };
    }
    let r: f64 = format!("{v:.9e}").parse().unwrap_or(v);
    let a = r.abs();
    if (1e-3..1e5).contains(&a) {
        format!("{r}")
    } else {
        format!("{r:e}")
    }
}
