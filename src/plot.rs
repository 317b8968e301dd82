//! Figures of the tool, one function each, rendered to PNG with plotters' bitmap backend.
//!
//! Every function takes plain data, validates it (empty or inconsistent input is a
//! [`PlotError`] and no file is touched), renders into a temporary file next to the
//! target and renames it into place, so a failed plot never leaves a half-written file.
//!
//! Text is rendered with an embedded copy of DejaVu Sans (`assets/DejaVuSans.ttf`, see
//! `assets/DejaVuSans-LICENSE.txt`), registered once, thread-safely, as `"sans-serif"`.
//!
//! Robustness: non-finite values are skipped, a zero-width data range is padded, and on a
//! logarithmic axis non-positive values are skipped.

use std::fmt;
use std::fs;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

use std::ops::Range;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};

// ---------------------------------------------------------------------------------------
// Public data types
// ---------------------------------------------------------------------------------------

/// Error of a plotting function: a human-readable message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotError {
    message: String,
}

impl PlotError {
    /// A new error with the given message.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
        }
    }

    /// The message of the error.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "plot error: {}", self.message)
    }
}

impl std::error::Error for PlotError {}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for PlotError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        Self::new(format!("drawing failed: {e}"))
    }
}

/// Posterior predictive check of one recording (see [`posterior_predictive`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PredictivePlot {
    /// Figure title.
    pub title: String,
    /// Sample times [s].
    pub times: Vec<f64>,
    /// One entry per measured channel, each drawn as two stacked panels.
    pub channels: Vec<ChannelPrediction>,
}

/// Measured data and predictions of one channel; all vectors are aligned with the times.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChannelPrediction {
    /// Channel name, e.g. "I" or "ω".
    pub name: String,
    /// Physical unit, e.g. "A" or "rad/s" (may be empty).
    pub unit: String,
    /// Measured values y (NaN marks a missing sample).
    pub measured: Vec<f64>,
    /// Calibrated simulation model G(θ̂).
    pub model: Vec<f64>,
    /// Posterior mean of the model plus discrepancy G + δ.
    pub mean: Vec<f64>,
    /// Lower end of the 95% band of G + δ.
    pub lower: Vec<f64>,
    /// Upper end of the 95% band of G + δ.
    pub upper: Vec<f64>,
    /// Estimated measurement-noise standard deviation σ̂ (same unit as the channel).
    pub sigma: f64,
}

/// Posterior of the discrepancy δ of one channel (see [`discrepancy_band`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DiscrepancyBand {
    /// Channel name.
    pub name: String,
    /// Physical unit (may be empty).
    pub unit: String,
    /// Posterior mean of δ, aligned with the times.
    pub mean: Vec<f64>,
    /// Lower end of the 95% band.
    pub lower: Vec<f64>,
    /// Upper end of the 95% band.
    pub upper: Vec<f64>,
    /// Optional reference discrepancy d0 (drawn dashed), aligned with the times.
    pub reference: Option<Vec<f64>>,
}

/// MCMC draws of one parameter (see [`traces`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TraceSeries {
    /// Parameter name, used as the axis label.
    pub name: String,
    /// One vector of draws per chain.
    pub chains: Vec<Vec<f64>>,
    /// Optional reference (true) value, drawn as a dashed line.
    pub reference: Option<f64>,
}

/// One sampler's efficiency as a function of the discrepancy degree K
/// (see [`ess_per_second`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SamplerCurve {
    /// Sampler name, shown in the legend.
    pub sampler: String,
    /// Points `(k, value, lower_bound)`; `lower_bound` marks values from unconverged runs,
    /// which overstate the sampler (its ratios are lower bounds) and are drawn hollow with a
    /// downward arrow.
    pub points: Vec<(f64, f64, bool)>,
}

/// A quantity as a function of the discrepancy degree K (see [`k_study`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KSeries {
    /// Quantity name, used in the axis label.
    pub name: String,
    /// Physical unit (may be empty).
    pub unit: String,
    /// Discrepancy degrees.
    pub k: Vec<f64>,
    /// Posterior mean per K.
    pub mean: Vec<f64>,
    /// Optional lower end of a 95% interval per K.
    pub lower: Option<Vec<f64>>,
    /// Optional upper end of a 95% interval per K.
    pub upper: Option<Vec<f64>>,
    /// Optional posterior standard deviation per K (drawn as a ±sd band).
    pub sd: Option<Vec<f64>>,
    /// Optional reference value (dashed horizontal line).
    pub reference: Option<f64>,
    /// Logarithmic y axis.
    pub log_y: bool,
}

// ---------------------------------------------------------------------------------------
// Figures
// ---------------------------------------------------------------------------------------

const WIDTH: u32 = 1200;
const MIN_HEIGHT: u32 = 800;
const TITLE_H: u32 = 50;
const X_AREA: u32 = 62;

/// Posterior predictive check of one recording.
///
/// Per channel two stacked panels: on top the measured points (small, grey), the
/// calibrated model G(θ̂) (dashed), the posterior mean of G + δ (solid) and its 95% band
/// (shaded); below the residuals y − (G + δ) with a ±2σ̂ noise band.
pub fn posterior_predictive(path: &Path, plot: &PredictivePlot) -> Result<(), PlotError> {
    let n = plot.times.len();
    if n == 0 {
        return Err(PlotError::new("posterior predictive plot: no time points"));
    }
    if plot.channels.is_empty() {
        return Err(PlotError::new("posterior predictive plot: no channels"));
    }
    for ch in &plot.channels {
        for (field, v) in [
            ("measured", &ch.measured),
            ("model", &ch.model),
            ("mean", &ch.mean),
            ("lower", &ch.lower),
            ("upper", &ch.upper),
        ] {
            check_len(&format!("channel {:?}: {field}", ch.name), v.len(), n)?;
        }
    }
    let any_data = plot.channels.iter().any(|c| {
        [&c.measured, &c.model, &c.mean, &c.lower, &c.upper]
            .iter()
            .any(|v| any_finite(v))
    });
    if !any_finite(&plot.times) || !any_data {
        return Err(PlotError::new(
            "posterior predictive plot: no finite data to plot",
        ));
    }

    let nch = plot.channels.len() as u32;
    let height = (TITLE_H + 620 * nch).max(MIN_HEIGHT);
    let block_h = (height - TITLE_H) / nch;
    let top_h = (f64::from(block_h) * 0.6) as u32;
    let bottom_h = block_h - top_h;

    render(path, (WIDTH, height), |root| {
        let body = titled(root, &plot.title)?;
        let xa = linear_axis(plot.times.iter().copied(), 0.0, 0.0, false, 8)
            .unwrap_or_else(|| Axis::fallback(false));

        // Axes first, so that all panels share the width of the y label area.
        let mut top_axes = Vec::new();
        let mut res_axes = Vec::new();
        let mut residuals = Vec::new();
        for ch in &plot.channels {
            let vals = ch
                .measured
                .iter()
                .chain(&ch.model)
                .chain(&ch.mean)
                .chain(&ch.lower)
                .chain(&ch.upper)
                .copied();
            let target = y_ticks_for(top_h.saturating_sub(20));
            top_axes.push(linear_axis(vals, 0.05, 0.0, false, target));
            let res: Vec<f64> = ch
                .measured
                .iter()
                .zip(&ch.mean)
                .map(|(y, m)| y - m)
                .collect();
            let two_sigma = valid_sigma(ch.sigma).map(|s| 2.0 * s);
            let rvals = res
                .iter()
                .copied()
                .chain(two_sigma.into_iter().flat_map(|s| [s, -s]))
                .chain([0.0]);
            let target = y_ticks_for(bottom_h.saturating_sub(X_AREA + 20));
            res_axes.push(linear_axis(rvals, 0.08, 0.0, false, target));
            residuals.push(res);
        }
        let y_area = y_label_area(
            root,
            top_axes.iter().chain(&res_axes).filter_map(|a| a.as_ref()),
        );

        let blocks = body.split_evenly((plot.channels.len(), 1));
        for (i, (ch, block)) in plot.channels.iter().zip(&blocks).enumerate() {
            let (top, bottom) = block.split_vertically(top_h);
            let label = with_unit(&ch.name, &ch.unit);

            // Top panel: data, model, model + discrepancy.
            let ya = top_axes[i].clone();
            let mut p = Panel::new(
                &top,
                PanelSpec {
                    x: xa.clone(),
                    y: ya.clone().unwrap_or_else(|| Axis::fallback(false)),
                    x_desc: "",
                    y_desc: &label,
                    x_ticks: false,
                    x_area: 0,
                    y_area,
                },
            )?;
            if ya.is_none() {
                p.note("no finite data")?;
            }
            p.band(&plot.times, &ch.lower, &ch.upper, C_BLUE.mix(0.22))?;
            p.points(&plot.times, &ch.measured, 2, C_GREY.mix(0.55).filled())?;
            p.dashed(&plot.times, &ch.model, C_VERMILLION.stroke_width(2))?;
            p.line(&plot.times, &ch.mean, C_BLUE.stroke_width(2))?;
            p.legend_item("measured", Icon::Dots(C_GREY.mix(0.7)));
            p.legend_item(
                "calibrated model G(θ*)",
                Icon::Line {
                    color: C_VERMILLION.to_rgba(),
                    width: 2,
                    dashed: true,
                },
            );
            p.legend_item(
                "G + δ posterior mean",
                Icon::Line {
                    color: C_BLUE.to_rgba(),
                    width: 2,
                    dashed: false,
                },
            );
            p.legend_item("G + δ 95% band", Icon::Band(C_BLUE.mix(0.22)));
            // The residual panel below has no room for a legend of its own.
            p.legend_item("residual y − (G + δ), below", Icon::Dots(C_GREY.mix(0.7)));
            if let Some(s) = valid_sigma(ch.sigma) {
                p.legend_item(
                    &format!(
                        "±2σ noise band, σ = {}",
                        with_space_unit(&fmt_sig(s), &ch.unit)
                    ),
                    Icon::Band(C_GREEN.mix(0.2)),
                );
            }
            p.finish()?;

            // Bottom panel: residuals.
            let ra = res_axes[i].clone();
            let mut p = Panel::new(
                &bottom,
                PanelSpec {
                    x: xa.clone(),
                    y: ra.clone().unwrap_or_else(|| Axis::fallback(false)),
                    x_desc: "time [s]",
                    y_desc: &with_unit("residual", &ch.unit),
                    x_ticks: true,
                    x_area: X_AREA,
                    y_area,
                },
            )?;
            if let Some(s) = valid_sigma(ch.sigma) {
                let ends = [xa.lo, xa.hi];
                p.band(&ends, &[-2.0 * s; 2], &[2.0 * s; 2], C_GREEN.mix(0.2))?;
            }
            p.hline(0.0, BLACK.mix(0.6).stroke_width(1), false)?;
            p.points(&plot.times, &residuals[i], 2, C_GREY.mix(0.6).filled())?;
            p.finish()?;
        }
        Ok(())
    })
}

/// Posterior of the model discrepancy δ per channel: posterior mean, 95% band and,
/// optionally, a reference discrepancy d0 (dashed); one panel per channel, shared time axis.
pub fn discrepancy_band(
    path: &Path,
    title: &str,
    times: &[f64],
    channels: &[DiscrepancyBand],
) -> Result<(), PlotError> {
    let n = times.len();
    if n == 0 {
        return Err(PlotError::new("discrepancy plot: no time points"));
    }
    if channels.is_empty() {
        return Err(PlotError::new("discrepancy plot: no channels"));
    }
    for ch in channels {
        for (field, v) in [
            ("mean", &ch.mean),
            ("lower", &ch.lower),
            ("upper", &ch.upper),
        ] {
            check_len(&format!("channel {:?}: {field}", ch.name), v.len(), n)?;
        }
        if let Some(r) = &ch.reference {
            check_len(&format!("channel {:?}: reference", ch.name), r.len(), n)?;
        }
    }
    let any_data = channels.iter().any(|c| {
        any_finite(&c.mean)
            || any_finite(&c.lower)
            || any_finite(&c.upper)
            || c.reference.as_deref().is_some_and(any_finite)
    });
    if !any_finite(times) || !any_data {
        return Err(PlotError::new("discrepancy plot: no finite data to plot"));
    }

    let nch = channels.len() as u32;
    let height = (TITLE_H + X_AREA + 380 * nch).max(MIN_HEIGHT);
    let row_h = (height - TITLE_H - X_AREA) / nch;

    render(path, (WIDTH, height), |root| {
        let body = titled(root, title)?;
        let xa = linear_axis(times.iter().copied(), 0.0, 0.0, false, 8)
            .unwrap_or_else(|| Axis::fallback(false));
        let axes: Vec<Option<Axis>> = channels
            .iter()
            .map(|c| {
                let vals = c
                    .mean
                    .iter()
                    .chain(&c.lower)
                    .chain(&c.upper)
                    .chain(c.reference.iter().flatten())
                    .chain(&[0.0])
                    .copied();
                linear_axis(vals, 0.06, 0.0, false, y_ticks_for(row_h - 20))
            })
            .collect();
        let y_area = y_label_area(root, axes.iter().flatten());
        let rows = stack_rows(&body, channels.len(), X_AREA);
        for (i, (ch, area)) in channels.iter().zip(&rows).enumerate() {
            let last = i + 1 == channels.len();
            let mut p = Panel::new(
                area,
                PanelSpec {
                    x: xa.clone(),
                    y: axes[i].clone().unwrap_or_else(|| Axis::fallback(false)),
                    x_desc: "time [s]",
                    y_desc: &with_unit(&format!("δ {}", ch.name), &ch.unit),
                    x_ticks: last,
                    x_area: if last { X_AREA } else { 0 },
                    y_area,
                },
            )?;
            if axes[i].is_none() {
                p.note("no finite data")?;
            }
            p.hline(0.0, BLACK.mix(0.5).stroke_width(1), false)?;
            p.band(times, &ch.lower, &ch.upper, C_BLUE.mix(0.22))?;
            if let Some(r) = &ch.reference {
                p.dashed(times, r, C_VERMILLION.stroke_width(2))?;
            }
            p.line(times, &ch.mean, C_BLUE.stroke_width(2))?;
            p.legend_item(
                "δ posterior mean",
                Icon::Line {
                    color: C_BLUE.to_rgba(),
                    width: 2,
                    dashed: false,
                },
            );
            p.legend_item("δ 95% band", Icon::Band(C_BLUE.mix(0.22)));
            if ch.reference.is_some() {
                p.legend_item(
                    "reference discrepancy d₀",
                    Icon::Line {
                        color: C_VERMILLION.to_rgba(),
                        width: 2,
                        dashed: true,
                    },
                );
            }
            p.finish()?;
        }
        Ok(())
    })
}

/// Trace plots: one row per parameter with the draws of every chain against the
/// iteration (one colour per chain) and, beside it, the marginal density (pooled
/// histogram plus one kernel density estimate per chain) on the same value axis.
pub fn traces(path: &Path, title: &str, series: &[TraceSeries]) -> Result<(), PlotError> {
    if series.is_empty() {
        return Err(PlotError::new("trace plot: no parameters"));
    }
    for s in series {
        if s.chains.iter().all(|c| c.is_empty()) {
            return Err(PlotError::new(format!(
                "trace plot: parameter {:?} has no draws",
                s.name
            )));
        }
    }
    if !series
        .iter()
        .any(|s| s.chains.iter().any(|c| any_finite(c)))
    {
        return Err(PlotError::new("trace plot: no finite draws"));
    }

    let n_chains = series.iter().map(|s| s.chains.len()).max().unwrap_or(0);
    let max_len = series
        .iter()
        .flat_map(|s| s.chains.iter().map(Vec::len))
        .max()
        .unwrap_or(0);
    let has_ref = series
        .iter()
        .any(|s| s.reference.is_some_and(f64::is_finite));
    let npar = series.len() as u32;
    const STRIP_H: u32 = 40;
    let height = (TITLE_H + STRIP_H + X_AREA + 230 * npar).max(MIN_HEIGHT);
    let row_h = (height - TITLE_H - STRIP_H - X_AREA) / npar;
    let trace_w = (f64::from(WIDTH) * 0.72) as u32;

    render(path, (WIDTH, height), |root| {
        let body = titled(root, title)?;
        let (strip, body) = body.split_vertically(STRIP_H);

        // Legend strip.
        let mut items: Vec<LegendItem> = (0..n_chains)
            .map(|c| LegendItem {
                label: format!("chain {}", c + 1),
                icon: Icon::Line {
                    color: palette(c).to_rgba(),
                    width: 2,
                    dashed: false,
                },
            })
            .collect();
        items.push(LegendItem {
            label: "pooled histogram".into(),
            icon: Icon::Band(C_HIST.to_rgba()),
        });
        if has_ref {
            items.push(LegendItem {
                label: "reference".into(),
                icon: Icon::Line {
                    color: BLACK.to_rgba(),
                    width: 2,
                    dashed: true,
                },
            });
        }
        draw_legend_strip(&strip, &items)?;

        let xa = linear_axis([0.0, max_len.saturating_sub(1) as f64], 0.0, 0.0, true, 8)
            .unwrap_or_else(|| Axis::fallback(false));
        let axes: Vec<Option<Axis>> = series
            .iter()
            .map(|s| {
                let vals = s.chains.iter().flatten().copied().chain(s.reference);
                linear_axis(vals, 0.05, 0.0, false, y_ticks_for(row_h - 20))
            })
            .collect();
        let y_area = y_label_area(root, axes.iter().flatten());
        let rows = stack_rows(&body, series.len(), X_AREA);
        for (i, (s, row)) in series.iter().zip(&rows).enumerate() {
            let last = i + 1 == series.len();
            let (left, right) = row.split_horizontally(trace_w);
            let ya = axes[i].clone().unwrap_or_else(|| Axis::fallback(false));
            let x_area = if last { X_AREA } else { 0 };

            // Trace panel.
            let mut p = Panel::new(
                &left,
                PanelSpec {
                    x: xa.clone(),
                    y: ya.clone(),
                    x_desc: "iteration",
                    y_desc: &s.name,
                    x_ticks: last,
                    x_area,
                    y_area,
                },
            )?;
            if axes[i].is_none() {
                p.note("no finite draws")?;
            }
            let (pw, _) = p.pixel_size();
            for (c, chain) in s.chains.iter().enumerate() {
                let (xs, ys) = decimate(chain, (pw as usize).max(100));
                p.line(&xs, &ys, palette(c).mix(0.85).stroke_width(1))?;
            }
            if let Some(r) = s.reference.filter(|r| r.is_finite()) {
                p.hline(r, BLACK.stroke_width(2), true)?;
            }
            p.finish()?;

            // Marginal panel: density on x, parameter value on y.
            let hist = histogram(s.chains.iter().flatten().copied(), &ya);
            let kdes: Vec<Vec<(f64, f64)>> = s.chains.iter().map(|c| kde(c, &ya)).collect();
            let dmax = hist
                .iter()
                .map(|b| b.2)
                .chain(kdes.iter().flatten().map(|p| p.1))
                .fold(0.0_f64, f64::max);
            let da = if dmax > 0.0 && dmax.is_finite() {
                linear_axis([0.0, dmax * 1.08], 0.0, 0.0, false, 3)
            } else {
                None
            }
            .unwrap_or_else(|| Axis::fallback(false));
            let mut m = Panel::new(
                &right,
                PanelSpec {
                    x: da,
                    y: ya,
                    x_desc: "density",
                    y_desc: "",
                    x_ticks: false,
                    x_area,
                    y_area: 0,
                },
            )?;
            m.bars_horizontal(&hist, C_HIST.filled())?;
            for (c, curve) in kdes.iter().enumerate() {
                let (d, v): (Vec<f64>, Vec<f64>) = curve.iter().map(|&(v, d)| (d, v)).unzip();
                m.line(&d, &v, palette(c).stroke_width(2))?;
            }
            if let Some(r) = s.reference.filter(|r| r.is_finite()) {
                m.hline(r, BLACK.stroke_width(2), true)?;
            }
            m.finish()?;
        }
        Ok(())
    })
}

/// Sampler efficiency against the discrepancy degree K on a logarithmic y axis: one line
/// with markers per sampler; values from unconverged runs (which overstate the sampler) are
/// drawn hollow with a downward arrow, which the legend explains. `y_label` names the quantity, e.g.
/// "min ESS per second [1/s]" or "min ESS per gradient evaluation".
pub fn ess_per_second(
    path: &Path,
    title: &str,
    y_label: &str,
    curves: &[SamplerCurve],
) -> Result<(), PlotError> {
    if curves.is_empty() || curves.iter().all(|c| c.points.is_empty()) {
        return Err(PlotError::new("efficiency plot: no samplers or no points"));
    }
    let usable = |&&(k, v, _): &&(f64, f64, bool)| k.is_finite() && v.is_finite() && v > 0.0;
    if !curves.iter().any(|c| c.points.iter().any(|p| usable(&p))) {
        return Err(PlotError::new(
            "efficiency plot: no finite positive values for a log scale",
        ));
    }
    let any_lower = curves
        .iter()
        .any(|c| c.points.iter().filter(usable).any(|p| p.2));

    render(path, (WIDTH, MIN_HEIGHT), |root| {
        let body = titled(root, title)?;
        let ks = curves.iter().flat_map(|c| c.points.iter().map(|p| p.0));
        let all_int = curves
            .iter()
            .flat_map(|c| &c.points)
            .filter(|p| p.0.is_finite())
            .all(|p| p.0.fract() == 0.0);
        let xa = linear_axis(ks, 0.04, 0.5, all_int, 12).unwrap_or_else(|| Axis::fallback(false));
        let vals = curves.iter().flat_map(|c| c.points.iter().map(|p| p.1));
        let ya = log_axis(vals, 0.08, 10).unwrap_or_else(|| Axis::fallback(true));
        let y_area = y_label_area(root, [&ya]);
        let mut p = Panel::new(
            &body,
            PanelSpec {
                x: xa,
                y: ya,
                x_desc: "K (discrepancy degree)",
                y_desc: y_label,
                x_ticks: true,
                x_area: X_AREA,
                y_area,
            },
        )?;
        for (i, c) in curves.iter().enumerate() {
            let color = palette(i);
            let shape = Shape::ALL[i % Shape::ALL.len()];
            let mut all: Vec<(f64, f64, bool)> = c
                .points
                .iter()
                .filter(|q| q.0.is_finite())
                .copied()
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0));
            // The line breaks at values that cannot be shown; segments touching a lower
            // bound are dashed.
            for w in all.windows(2) {
                if !(usable(&&w[0]) && usable(&&w[1])) {
                    continue;
                }
                let xs = [w[0].0, w[1].0];
                let ys = [w[0].1, w[1].1];
                if w[0].2 || w[1].2 {
                    p.dashed(&xs, &ys, color.stroke_width(2))?;
                } else {
                    p.line(&xs, &ys, color.stroke_width(2))?;
                }
            }
            let pts: Vec<(f64, f64, bool)> = all.iter().filter(usable).copied().collect();
            let pick = |lb: bool| -> Vec<(f64, f64)> {
                pts.iter()
                    .filter(|q| q.2 == lb)
                    .map(|q| (q.0, q.1))
                    .collect()
            };
            let (exact, lower) = (pick(false), pick(true));
            p.markers(&exact, shape, 6, color.to_rgba(), true)?;
            p.markers(&lower, shape, 6, color.to_rgba(), false)?;
            p.arrows(&lower, 6, color.to_rgba())?;
            p.legend_item(
                &c.sampler,
                Icon::Marker {
                    shape,
                    color: color.to_rgba(),
                    filled: true,
                    line: true,
                    arrow: false,
                },
            );
        }
        if any_lower {
            p.legend_item(
                "not converged: at most this (ratios against it are lower bounds)",
                Icon::Marker {
                    shape: Shape::Circle,
                    color: C_GREY.to_rgba(),
                    filled: false,
                    line: false,
                    arrow: true,
                },
            );
        }
        p.finish()
    })
}

/// Generic "quantity against K" figure, one stacked panel per series sharing the K axis:
/// posterior mean (line with markers), ±1 sd band, optional 95% interval (dashed lines)
/// and optional reference value (dashed horizontal line); per-series log y axis.
pub fn k_study(path: &Path, title: &str, series: &[KSeries]) -> Result<(), PlotError> {
    if series.is_empty() {
        return Err(PlotError::new("K study plot: no series"));
    }
    for s in series {
        let n = s.k.len();
        if n == 0 {
            return Err(PlotError::new(format!(
                "K study plot: series {:?} is empty",
                s.name
            )));
        }
        check_len(&format!("series {:?}: mean", s.name), s.mean.len(), n)?;
        for (field, v) in [("lower", &s.lower), ("upper", &s.upper), ("sd", &s.sd)] {
            if let Some(v) = v {
                check_len(&format!("series {:?}: {field}", s.name), v.len(), n)?;
            }
        }
    }
    if !series
        .iter()
        .any(|s| any_finite(&s.k) && any_finite(&s.mean))
    {
        return Err(PlotError::new("K study plot: no finite data to plot"));
    }

    let ns = series.len() as u32;
    let height = (TITLE_H + X_AREA + 330 * ns).max(MIN_HEIGHT);
    let row_h = (height - TITLE_H - X_AREA) / ns;

    render(path, (WIDTH, height), |root| {
        let body = titled(root, title)?;
        let all_int = series
            .iter()
            .flat_map(|s| &s.k)
            .filter(|k| k.is_finite())
            .all(|k| k.fract() == 0.0);
        let xa = linear_axis(
            series.iter().flat_map(|s| s.k.iter().copied()),
            0.04,
            0.5,
            all_int,
            12,
        )
        .unwrap_or_else(|| Axis::fallback(false));
        let axes: Vec<Option<Axis>> = series
            .iter()
            .map(|s| {
                let (lo_sd, hi_sd) = sd_band(s);
                let vals = s
                    .mean
                    .iter()
                    .chain(s.lower.iter().flatten())
                    .chain(s.upper.iter().flatten())
                    .chain(&lo_sd)
                    .chain(&hi_sd)
                    .copied()
                    .chain(s.reference);
                let target = y_ticks_for(row_h - 20);
                if s.log_y {
                    log_axis(vals, 0.06, target)
                } else {
                    linear_axis(vals, 0.06, 0.0, false, target)
                }
            })
            .collect();
        let y_area = y_label_area(root, axes.iter().flatten());
        let rows = stack_rows(&body, series.len(), X_AREA);
        for (i, (s, area)) in series.iter().zip(&rows).enumerate() {
            let last = i + 1 == series.len();
            let mut p = Panel::new(
                area,
                PanelSpec {
                    x: xa.clone(),
                    y: axes[i].clone().unwrap_or_else(|| Axis::fallback(s.log_y)),
                    x_desc: "K (discrepancy degree)",
                    y_desc: &with_unit(&s.name, &s.unit),
                    x_ticks: last,
                    x_area: if last { X_AREA } else { 0 },
                    y_area,
                },
            )?;
            if axes[i].is_none() {
                p.note("no finite data")?;
            }
            let mut order: Vec<usize> = (0..s.k.len()).collect();
            order.sort_by(|&a, &b| s.k[a].total_cmp(&s.k[b]));
            let sorted = |v: &[f64]| order.iter().map(|&j| v[j]).collect::<Vec<f64>>();
            let ks = sorted(&s.k);
            if let Some(r) = s.reference.filter(|r| r.is_finite()) {
                p.hline(r, BLACK.stroke_width(2), true)?;
            }
            if s.sd.is_some() {
                let (lo, hi) = sd_band(s);
                p.band(&ks, &sorted(&lo), &sorted(&hi), C_BLUE.mix(0.2))?;
            }
            if let (Some(lo), Some(hi)) = (&s.lower, &s.upper) {
                p.dashed(&ks, &sorted(lo), C_BLUE.mix(0.8).stroke_width(1))?;
                p.dashed(&ks, &sorted(hi), C_BLUE.mix(0.8).stroke_width(1))?;
            } else {
                for v in [&s.lower, &s.upper].into_iter().flatten() {
                    p.dashed(&ks, &sorted(v), C_BLUE.mix(0.8).stroke_width(1))?;
                }
            }
            let mean = sorted(&s.mean);
            p.line(&ks, &mean, C_BLUE.stroke_width(2))?;
            let pts: Vec<(f64, f64)> = ks.iter().copied().zip(mean.iter().copied()).collect();
            p.markers(&pts, Shape::Circle, 5, C_BLUE.to_rgba(), true)?;

            p.legend_item(
                "posterior mean",
                Icon::Marker {
                    shape: Shape::Circle,
                    color: C_BLUE.to_rgba(),
                    filled: true,
                    line: true,
                    arrow: false,
                },
            );
            if s.sd.is_some() {
                p.legend_item("± 1 sd", Icon::Band(C_BLUE.mix(0.2)));
            }
            if s.lower.is_some() || s.upper.is_some() {
                p.legend_item(
                    "95% interval",
                    Icon::Line {
                        color: C_BLUE.mix(0.8),
                        width: 1,
                        dashed: true,
                    },
                );
            }
            if s.reference.is_some_and(f64::is_finite) {
                p.legend_item(
                    "reference",
                    Icon::Line {
                        color: BLACK.to_rgba(),
                        width: 2,
                        dashed: true,
                    },
                );
            }
            p.finish()?;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Rendering infrastructure
// ---------------------------------------------------------------------------------------

const FONT: &str = "sans-serif";
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

const C_BLUE: RGBColor = RGBColor(0, 114, 178);
const C_VERMILLION: RGBColor = RGBColor(213, 94, 0);
const C_GREEN: RGBColor = RGBColor(0, 158, 115);
const C_GREY: RGBColor = RGBColor(100, 100, 100);
const C_HIST: RGBColor = RGBColor(215, 215, 215);

/// Colour cycle (Okabe–Ito based, ordered so that neighbours differ in lightness too).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(230, 159, 0),
    RGBColor(30, 30, 30),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(213, 94, 0),
    RGBColor(86, 180, 233),
    RGBColor(160, 140, 20),
];

fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Registers the embedded font exactly once (thread-safe); later calls return the
/// remembered outcome.
fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::new(
            "the embedded DejaVu Sans font could not be registered",
        ))
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type Chart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<TickedRange, TickedRange>>;

/// Renders into a temporary PNG next to `path` and renames it into place on success;
/// on failure (including a panic inside the drawing code) the temporary file is removed.
fn render(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    ensure_font()?;
    let tmp = temp_path(path)?;
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<(), PlotError> {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
        Ok(())
    }))
    .unwrap_or_else(|_| Err(PlotError::new("internal error while drawing")));
    match result {
        Ok(()) => fs::rename(&tmp, path).map_err(|e| {
            let _ = fs::remove_file(&tmp);
            PlotError::new(format!("cannot write {}: {e}", path.display()))
        }),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(PlotError::new(format!(
                "cannot plot {}: {}",
                path.display(),
                e.message
            )))
        }
    }
}

fn temp_path(path: &Path) -> Result<PathBuf, PlotError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| PlotError::new(format!("{} is not a file path", path.display())))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    // The bitmap encoder picks the format from the extension, hence `.png` at the end.
    Ok(path.with_file_name(format!(
        ".{}.{}-{n}.tmp.png",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Draws the figure title (if any) and returns the area below it.
fn titled<'b>(root: &Area<'b>, title: &str) -> Result<Area<'b>, PlotError> {
    let (head, body) = root.split_vertically(TITLE_H);
    if !title.is_empty() {
        let (w, h) = head.dim_in_pixel();
        draw_text(
            &head,
            title,
            (w as i32 / 2, h as i32 / 2 + 2),
            26,
            HPos::Center,
        )?;
    }
    Ok(body)
}

/// Splits `area` into `n` rows of equal plot height, the last one `extra` pixels taller
/// (room for the x labels).
fn stack_rows<'b>(area: &Area<'b>, n: usize, extra: u32) -> Vec<Area<'b>> {
    let (_, h) = area.dim_in_pixel();
    let row = (h.saturating_sub(extra) as usize / n.max(1)) as i32;
    let breaks: Vec<i32> = (1..n).map(|i| row * i as i32).collect();
    area.split_by_breakpoints([] as [i32; 0], breaks)
}

fn y_ticks_for(px: u32) -> usize {
    ((px / 45) as usize).clamp(3, 10)
}

/// Width of the y label area that fits the tick labels of all the given axes.
fn y_label_area<'x>(root: &Area<'_>, axes: impl IntoIterator<Item = &'x Axis>) -> u32 {
    let style = TextStyle::from((FONT, 16).into_font());
    let widest = axes
        .into_iter()
        .flat_map(|a| a.ticks.iter().map(move |&t| a.label(t)))
        .map(|s| {
            root.estimate_text_size(&s, &style)
                .map(|d| d.0)
                .unwrap_or(60)
        })
        .max()
        .unwrap_or(40);
    widest + 52
}

// ---------------------------------------------------------------------------------------
// Axes: range, ticks, labels
// ---------------------------------------------------------------------------------------

#[derive(Debug, Clone, Copy, PartialEq)]
enum TickFmt {
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
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: Vec<f64>,
    fmt: TickFmt,
}

impl Axis {
    /// Axis for a panel without usable data.
    fn fallback(log: bool) -> Axis {
        if log {
            log_axis([1.0, 10.0], 0.0, 5)
        } else {
            linear_axis([0.0, 1.0], 0.0, 0.0, false, 5)
        }
        .expect("fixed finite range")
    }

    /// Data value → plot coordinate, `None` if it cannot be shown on this axis.
    fn tr(&self, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if self.log {
            (v > 0.0).then(|| v.log10())
        } else {
            Some(v)
        }
    }

    /// Tick label of a plot coordinate.
    fn label(&self, p: f64) -> String {
        if self.log {
            return fmt_sig(10f64.powf(p));
        }
        match self.fmt {
            TickFmt::Fixed(d) => format!("{p:.d$}"),
            TickFmt::Sci(d) => format!("{p:.d$e}"),
            TickFmt::Sig => fmt_sig(p),
        }
    }

    fn coord(&self) -> TickedRange {
        TickedRange {
            lo: self.lo,
            hi: self.hi,
            ticks: self.ticks.clone(),
        }
    }
}

/// Linear plotters coordinate over plot coordinates with our own tick positions (bold
/// grid lines and labels; no light grid lines).
struct TickedRange {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
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
fn nice_step(lo: f64, hi: f64, target: usize, integer: bool) -> f64 {
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

fn linear_ticks(lo: f64, hi: f64, step: f64) -> Vec<f64> {
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
fn linear_axis(
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
fn log_axis(vals: impl IntoIterator<Item = f64>, pad_frac: f64, target: usize) -> Option<Axis> {
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

fn min_max(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    vals.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((a, b)) => Some((a.min(v), b.max(v))),
    })
}

/// Shortest readable representation of a value, rounded to ten significant digits.
fn fmt_sig(v: f64) -> String {
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

// ---------------------------------------------------------------------------------------
// Panels
// ---------------------------------------------------------------------------------------

struct PanelSpec<'s> {
    x: Axis,
    y: Axis,
    x_desc: &'s str,
    y_desc: &'s str,
    /// Tick labels on the x axis (the description is shown whenever `x_area > 0`).
    x_ticks: bool,
    x_area: u32,
    y_area: u32,
}

/// A chart with its axes, a record of where data was drawn (for legend placement) and
/// its legend entries.
struct Panel<'a, 'b> {
    chart: Chart<'a, 'b>,
    x: Axis,
    y: Axis,
    occ: Occupancy,
    legend: Vec<LegendItem>,
}

impl<'a, 'b> Panel<'a, 'b> {
    fn new(area: &'a Area<'b>, spec: PanelSpec<'_>) -> Result<Self, PlotError> {
        let mut builder = ChartBuilder::on(area);
        builder
            .margin_top(12)
            .margin_bottom(4)
            .margin_left(8)
            .margin_right(24)
            .x_label_area_size(spec.x_area)
            .y_label_area_size(spec.y_area);
        let mut chart = builder.build_cartesian_2d(spec.x.coord(), spec.y.coord())?;
        {
            let (xa, ya) = (&spec.x, &spec.y);
            let fx = |v: &f64| xa.label(*v);
            let fy = |v: &f64| ya.label(*v);
            let blank = |_: &f64| String::new();
            let fx: &dyn Fn(&f64) -> String = if spec.x_ticks { &fx } else { &blank };
            let fy: &dyn Fn(&f64) -> String = if spec.y_area > 0 { &fy } else { &blank };
            let mut mesh = chart.configure_mesh();
            mesh.bold_line_style(BLACK.mix(0.09))
                .light_line_style(TRANSPARENT)
                .axis_style(BLACK.mix(0.7))
                .label_style((FONT, 16))
                .axis_desc_style((FONT, 18))
                .x_label_formatter(fx)
                .y_label_formatter(fy);
            if spec.x_area > 0 && !spec.x_desc.is_empty() {
                mesh.x_desc(spec.x_desc);
            }
            if spec.y_area > 0 && !spec.y_desc.is_empty() {
                mesh.y_desc(spec.y_desc);
            }
            mesh.draw()?;
        }
        let occ = Occupancy::new(&spec.x, &spec.y);
        Ok(Panel {
            chart,
            x: spec.x,
            y: spec.y,
            occ,
            legend: Vec::new(),
        })
    }

    fn pixel_size(&self) -> (u32, u32) {
        self.chart.plotting_area().dim_in_pixel()
    }

    /// Points of the polyline through the showable (x, y) pairs, split where a pair is not.
    fn segments(&self, xs: &[f64], ys: &[f64]) -> Vec<Vec<(f64, f64)>> {
        let mut out = Vec::new();
        let mut cur = Vec::new();
        for (&x, &y) in xs.iter().zip(ys) {
            match (self.x.tr(x), self.y.tr(y)) {
                (Some(px), Some(py)) => cur.push((px, py)),
                _ => {
                    if !cur.is_empty() {
                        out.push(std::mem::take(&mut cur));
                    }
                }
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
        out
    }

    fn line(&mut self, xs: &[f64], ys: &[f64], style: ShapeStyle) -> Result<(), PlotError> {
        let segs = self.segments(xs, ys);
        for s in &segs {
            self.occ.mark_path(s);
        }
        self.chart
            .draw_series(segs.into_iter().map(|s| PathElement::new(s, style)))?;
        Ok(())
    }

    fn dashed(&mut self, xs: &[f64], ys: &[f64], style: ShapeStyle) -> Result<(), PlotError> {
        let segs = self.segments(xs, ys);
        for s in &segs {
            self.occ.mark_path(s);
        }
        self.chart.draw_series(
            segs.into_iter()
                .map(|s| DashedPathElement::new(s, 10.0, 6.0, style)),
        )?;
        Ok(())
    }

    /// Horizontal line across the whole panel at data value `y`.
    fn hline(&mut self, y: f64, style: ShapeStyle, dashed: bool) -> Result<(), PlotError> {
        let xs = [self.x.lo, self.x.hi];
        let ys = [y, y];
        if dashed {
            self.dashed(&xs, &ys, style)
        } else {
            self.line(&xs, &ys, style)
        }
    }

    fn points(
        &mut self,
        xs: &[f64],
        ys: &[f64],
        radius: i32,
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
        let pts: Vec<(f64, f64)> = xs
            .iter()
            .zip(ys)
            .filter_map(|(&x, &y)| Some((self.x.tr(x)?, self.y.tr(y)?)))
            .collect();
        for &p in &pts {
            self.occ.mark(p);
        }
        self.chart
            .draw_series(pts.into_iter().map(|p| Circle::new(p, radius, style)))?;
        Ok(())
    }

    /// Shaded area between `lo` and `hi`, split where a value is not showable.
    fn band(
        &mut self,
        xs: &[f64],
        lo: &[f64],
        hi: &[f64],
        color: RGBAColor,
    ) -> Result<(), PlotError> {
        let mut polys = Vec::new();
        let mut run: Vec<(f64, f64, f64)> = Vec::new();
        let flush = |run: &mut Vec<(f64, f64, f64)>, polys: &mut Vec<Vec<(f64, f64)>>| {
            if run.len() >= 2 {
                let mut poly: Vec<(f64, f64)> = run.iter().map(|&(x, _, h)| (x, h)).collect();
                poly.extend(run.iter().rev().map(|&(x, l, _)| (x, l)));
                polys.push(poly);
            }
            run.clear();
        };
        for ((&x, &l), &h) in xs.iter().zip(lo).zip(hi) {
            match (self.x.tr(x), self.y.tr(l), self.y.tr(h)) {
                (Some(px), Some(pl), Some(ph)) => {
                    self.occ.mark_vertical(px, pl, ph);
                    run.push((px, pl, ph));
                }
                _ => flush(&mut run, &mut polys),
            }
        }
        flush(&mut run, &mut polys);
        self.chart
            .draw_series(polys.into_iter().map(|p| Polygon::new(p, color.filled())))?;
        Ok(())
    }

    /// Horizontal bars `(y0, y1, length)` from x = 0 (marginal histograms).
    fn bars_horizontal(
        &mut self,
        bars: &[(f64, f64, f64)],
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
        let rects: Vec<[(f64, f64); 2]> = bars
            .iter()
            .filter(|b| b.0.is_finite() && b.1.is_finite() && b.2.is_finite() && b.2 > 0.0)
            .map(|&(y0, y1, d)| [(0.0, y0), (d, y1)])
            .collect();
        for r in &rects {
            self.occ.mark_vertical(r[1].0 * 0.5, r[0].1, r[1].1);
        }
        self.chart
            .draw_series(rects.into_iter().map(|r| Rectangle::new(r, style)))?;
        Ok(())
    }

    /// Markers of the given shape at data points (hollow ones have a white inside).
    fn markers(
        &mut self,
        pts: &[(f64, f64)],
        shape: Shape,
        r: i32,
        color: RGBAColor,
        filled: bool,
    ) -> Result<(), PlotError> {
        let pts: Vec<(f64, f64)> = pts
            .iter()
            .filter_map(|&(x, y)| Some((self.x.tr(x)?, self.y.tr(y)?)))
            .collect();
        for &p in &pts {
            self.occ.mark(p);
        }
        let verts = shape.vertices(r);
        let mut closed = verts.clone();
        closed.push(verts[0]);
        let fill = if filled { color } else { WHITE.to_rgba() };
        self.chart.draw_series(pts.into_iter().map(|p| {
            EmptyElement::at(p)
                + Polygon::new(verts.clone(), fill.filled())
                + PathElement::new(closed.clone(), color.stroke_width(2))
        }))?;
        Ok(())
    }

    /// Downward arrows below markers of radius `r`: an unconverged run's ESS overstates it, so
    /// its true efficiency lies below the point.
    fn arrows(&mut self, pts: &[(f64, f64)], r: i32, color: RGBAColor) -> Result<(), PlotError> {
        let pts: Vec<(f64, f64)> = pts
            .iter()
            .filter_map(|&(x, y)| Some((self.x.tr(x)?, self.y.tr(y)?)))
            .collect();
        self.chart.draw_series(pts.into_iter().map(|p| {
            EmptyElement::at(p)
                + PathElement::new(vec![(0, r + 2), (0, r + 14)], color.stroke_width(2))
                + Polygon::new(vec![(-5, r + 12), (5, r + 12), (0, r + 21)], color.filled())
        }))?;
        Ok(())
    }

    /// A centred note in an otherwise empty panel.
    fn note(&mut self, text: &str) -> Result<(), PlotError> {
        let area = self.chart.plotting_area().strip_coord_spec();
        let (w, h) = area.dim_in_pixel();
        draw_text(&area, text, (w as i32 / 2, h as i32 / 2), 18, HPos::Center)?;
        Ok(())
    }

    fn legend_item(&mut self, label: &str, icon: Icon) {
        self.legend.push(LegendItem {
            label: label.to_string(),
            icon,
        });
    }

    /// Frame and legend.
    fn finish(self) -> Result<(), PlotError> {
        let area = self.chart.plotting_area().strip_coord_spec();
        let (w, h) = area.dim_in_pixel();
        area.draw(&Rectangle::new(
            [(0, 0), (w as i32 - 1, h as i32 - 1)],
            BLACK.mix(0.7).stroke_width(1),
        ))?;
        if !self.legend.is_empty() {
            draw_legend_box(&area, &self.legend, &self.occ)?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------
// Legend
// ---------------------------------------------------------------------------------------

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    Circle,
    Square,
    Triangle,
    Diamond,
    TriangleDown,
    Pentagon,
}

impl Shape {
    const ALL: [Shape; 6] = [
        Shape::Circle,
        Shape::Square,
        Shape::Triangle,
        Shape::Diamond,
        Shape::TriangleDown,
        Shape::Pentagon,
    ];

    /// Polygon vertices (pixel offsets) of a marker of about radius `r`.
    fn vertices(self, r: i32) -> Vec<(i32, i32)> {
        let r = f64::from(r);
        let ngon = |n: usize, radius: f64, phase: f64| -> Vec<(i32, i32)> {
            (0..n)
                .map(|i| {
                    let a = phase + std::f64::consts::TAU * i as f64 / n as f64;
                    (
                        (radius * a.cos()).round() as i32,
                        (radius * a.sin()).round() as i32,
                    )
                })
                .collect()
        };
        use std::f64::consts::FRAC_PI_2;
        match self {
            Shape::Circle => ngon(20, r, 0.0),
            Shape::Square => ngon(4, r * 1.2, FRAC_PI_2 / 2.0),
            Shape::Triangle => ngon(3, r * 1.3, -FRAC_PI_2),
            Shape::Diamond => ngon(4, r * 1.3, 0.0),
            Shape::TriangleDown => ngon(3, r * 1.3, FRAC_PI_2),
            Shape::Pentagon => ngon(5, r * 1.15, -FRAC_PI_2),
        }
    }
}

#[derive(Debug, Clone)]
enum Icon {
    Line {
        color: RGBAColor,
        width: u32,
        dashed: bool,
    },
    Band(RGBAColor),
    Dots(RGBAColor),
    Marker {
        shape: Shape,
        color: RGBAColor,
        filled: bool,
        line: bool,
        arrow: bool,
    },
}

#[derive(Debug, Clone)]
struct LegendItem {
    label: String,
    icon: Icon,
}

const LEGEND_FONT: u32 = 16;
const ICON_W: i32 = 36;
const ROW_H: i32 = 24;
const PAD: i32 = 8;

/// Draws a legend icon occupying `x..x + ICON_W`, vertically centred on `y`.
fn draw_icon(area: &Area<'_>, icon: &Icon, x: i32, y: i32) -> Result<(), PlotError> {
    match *icon {
        Icon::Line {
            color,
            width,
            dashed,
        } => {
            let style = color.stroke_width(width);
            if dashed {
                area.draw(&DashedPathElement::new(
                    vec![(x, y), (x + ICON_W, y)],
                    10.0,
                    5.0,
                    style,
                ))?;
            } else {
                area.draw(&PathElement::new(vec![(x, y), (x + ICON_W, y)], style))?;
            }
        }
        Icon::Band(color) => {
            area.draw(&Rectangle::new(
                [(x, y - 7), (x + ICON_W, y + 7)],
                color.filled(),
            ))?;
        }
        Icon::Dots(color) => {
            for dx in [6, 18, 30] {
                area.draw(&Circle::new((x + dx, y + (dx % 4) - 1), 3, color.filled()))?;
            }
        }
        Icon::Marker {
            shape,
            color,
            filled,
            line,
            arrow,
        } => {
            // With an arrow: marker on the left, upward arrow on the right.
            let c = (x + if arrow { 11 } else { ICON_W / 2 }, y);
            if line {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + ICON_W, y)],
                    color.stroke_width(2),
                ))?;
            }
            let r = 6;
            let verts = shape.vertices(r);
            let mut closed = verts.clone();
            closed.push(verts[0]);
            let fill = if filled { color } else { WHITE.to_rgba() };
            area.draw(
                &(EmptyElement::at(c)
                    + Polygon::new(verts, fill.filled())
                    + PathElement::new(closed, color.stroke_width(2))),
            )?;
            if arrow {
                let ax = x + 28;
                area.draw(&PathElement::new(
                    vec![(ax, y - 8), (ax, y + 3)],
                    color.stroke_width(2),
                ))?;
                area.draw(&Polygon::new(
                    vec![(ax - 5, y + 2), (ax + 5, y + 2), (ax, y + 10)],
                    color.filled(),
                ))?;
            }
        }
    }
    Ok(())
}

/// Text in the embedded font is laid out word by word: plotters 0.3.7's ab_glyph renderer
/// drops each glyph's left side bearing, which makes spaces look too narrow; an explicit
/// word gap keeps multi-word labels readable.
fn word_gap(size: u32) -> i32 {
    // DejaVu Sans space advance (0.318 em) plus a compensation of about 0.06 em.
    (f64::from(size) * 0.38).round() as i32
}

fn text_width(area: &Area<'_>, text: &str, size: u32) -> i32 {
    let style = TextStyle::from((FONT, size).into_font());
    let words: Vec<&str> = text.split(' ').collect();
    let w: i32 = words
        .iter()
        .filter(|w| !w.is_empty())
        .map(|w| {
            area.estimate_text_size(w, &style)
                .map(|d| d.0 as i32)
                .unwrap_or(size as i32 * w.chars().count() as i32 / 2)
        })
        .sum();
    w + word_gap(size) * (words.len() as i32 - 1).max(0)
}

/// Draws `text` vertically centred on `y`, starting at (`Left`), centred on (`Center`)
/// or ending at (`Right`) `x`.
fn draw_text(
    area: &Area<'_>,
    text: &str,
    (x, y): (i32, i32),
    size: u32,
    align: HPos,
) -> Result<(), PlotError> {
    let style = TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let total = text_width(area, text, size);
    let mut cx = match align {
        HPos::Left => x,
        HPos::Center => x - total / 2,
        HPos::Right => x - total,
    };
    for word in text.split(' ') {
        if !word.is_empty() {
            area.draw(&Text::new(word.to_string(), (cx, y), style.clone()))?;
            cx += text_width(area, word, size);
        }
        cx += word_gap(size);
    }
    Ok(())
}

/// Legend box inside a plotting area, at the corner (or edge middle) covering the least data.
fn draw_legend_box(
    area: &Area<'_>,
    items: &[LegendItem],
    occ: &Occupancy,
) -> Result<(), PlotError> {
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let text_w = items
        .iter()
        .map(|it| text_width(area, &it.label, LEGEND_FONT))
        .max()
        .unwrap_or(0);
    let bw = PAD + ICON_W + PAD + text_w + PAD + 2;
    let bh = 2 * PAD + ROW_H * items.len() as i32 - 4;
    const INSET: i32 = 10;
    let (left, centre, right) = (INSET, (w - bw) / 2, w - bw - INSET);
    let (top, middle, bottom) = (INSET, (h - bh) / 2, h - bh - INSET);
    // In order of preference; the first one covering the least data wins.
    let corners = [
        (right, top),
        (left, top),
        (right, bottom),
        (left, bottom),
        (right, middle),
        (left, middle),
        (centre, top),
        (centre, bottom),
        (centre, middle),
    ];
    let (bx, by) = corners
        .iter()
        .copied()
        .min_by_key(|&(bx, by)| {
            let nx = |px: i32| f64::from(px) / f64::from(w.max(1));
            let ny = |py: i32| 1.0 - f64::from(py) / f64::from(h.max(1));
            occ.count(nx(bx), nx(bx + bw), ny(by + bh), ny(by))
        })
        .unwrap_or(corners[0]);
    area.draw(&Rectangle::new(
        [(bx, by), (bx + bw, by + bh)],
        WHITE.mix(0.88).filled(),
    ))?;
    area.draw(&Rectangle::new(
        [(bx, by), (bx + bw, by + bh)],
        BLACK.mix(0.35).stroke_width(1),
    ))?;
    for (i, it) in items.iter().enumerate() {
        let y = by + PAD + ROW_H / 2 + ROW_H * i as i32 - 2;
        draw_icon(area, &it.icon, bx + PAD, y)?;
        draw_text(
            area,
            &it.label,
            (bx + PAD + ICON_W + PAD, y),
            LEGEND_FONT,
            HPos::Left,
        )?;
    }
    Ok(())
}

/// Horizontal legend centred in `area` (used above multi-panel figures).
fn draw_legend_strip(area: &Area<'_>, items: &[LegendItem]) -> Result<(), PlotError> {
    let (w, h) = area.dim_in_pixel();
    let gap = 28;
    let widths: Vec<i32> = items
        .iter()
        .map(|it| ICON_W + PAD + text_width(area, &it.label, LEGEND_FONT))
        .collect();
    let total: i32 = widths.iter().sum::<i32>() + gap * (items.len() as i32 - 1).max(0);
    let mut x = ((w as i32 - total) / 2).max(4);
    let y = h as i32 / 2;
    for (it, iw) in items.iter().zip(widths) {
        draw_icon(area, &it.icon, x, y)?;
        draw_text(
            area,
            &it.label,
            (x + ICON_W + PAD, y),
            LEGEND_FONT,
            HPos::Left,
        )?;
        x += iw + gap;
    }
    Ok(())
}

/// Coarse grid over a panel recording where data was drawn.
struct Occupancy {
    nx: usize,
    ny: usize,
    cells: Vec<bool>,
    x: (f64, f64),
    y: (f64, f64),
}

impl Occupancy {
    fn new(x: &Axis, y: &Axis) -> Self {
        let (nx, ny) = (60, 40);
        Self {
            nx,
            ny,
            cells: vec![false; nx * ny],
            x: (x.lo, x.hi),
            y: (y.lo, y.hi),
        }
    }

    fn norm(&self, p: (f64, f64)) -> (f64, f64) {
        (
            (p.0 - self.x.0) / (self.x.1 - self.x.0),
            (p.1 - self.y.0) / (self.y.1 - self.y.0),
        )
    }

    fn mark_norm(&mut self, (u, v): (f64, f64)) {
        if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
            return;
        }
        let i = ((u * self.nx as f64) as usize).min(self.nx - 1);
        let j = ((v * self.ny as f64) as usize).min(self.ny - 1);
        self.cells[j * self.nx + i] = true;
    }

    fn mark(&mut self, p: (f64, f64)) {
        let n = self.norm(p);
        self.mark_norm(n);
    }

    fn mark_path(&mut self, pts: &[(f64, f64)]) {
        if let Some(&p) = pts.first() {
            self.mark(p);
        }
        for w in pts.windows(2) {
            let (a, b) = (self.norm(w[0]), self.norm(w[1]));
            let steps = ((b.0 - a.0).abs() * self.nx as f64)
                .max((b.1 - a.1).abs() * self.ny as f64)
                .ceil()
                .clamp(1.0, 400.0) as usize;
            for s in 1..=steps {
                let t = s as f64 / steps as f64;
                self.mark_norm((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
            }
        }
    }

    fn mark_vertical(&mut self, x: f64, y0: f64, y1: f64) {
        self.mark_path(&[(x, y0), (x, y1)]);
    }

    /// Number of marked cells overlapping the normalised box.
    fn count(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> usize {
        let idx = |t: f64, n: usize| ((t * n as f64).floor().max(0.0) as usize).min(n - 1);
        let (i0, i1) = (idx(u0, self.nx), idx(u1, self.nx));
        let (j0, j1) = (idx(v0, self.ny), idx(v1, self.ny));
        (j0..=j1)
            .flat_map(|j| (i0..=i1).map(move |i| (i, j)))
            .filter(|&(i, j)| self.cells[j * self.nx + i])
            .count()
    }
}

// ---------------------------------------------------------------------------------------
// Small numerical helpers
// ---------------------------------------------------------------------------------------

fn check_len(what: &str, got: usize, want: usize) -> Result<(), PlotError> {
    if got == want {
        Ok(())
    } else {
        Err(PlotError::new(format!(
            "{what} has {got} values, expected {want}"
        )))
    }
}

fn any_finite(v: &[f64]) -> bool {
    v.iter().any(|x| x.is_finite())
}

fn valid_sigma(s: f64) -> Option<f64> {
    (s.is_finite() && s > 0.0).then_some(s)
}

fn with_space_unit(value: &str, unit: &str) -> String {
    if unit.is_empty() {
        value.to_string()
    } else {
        format!("{value} {unit}")
    }
}

fn with_unit(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}

/// mean ± sd of a K series (NaN where unavailable).
fn sd_band(s: &KSeries) -> (Vec<f64>, Vec<f64>) {
    match &s.sd {
        Some(sd) => s.mean.iter().zip(sd).map(|(m, d)| (m - d, m + d)).unzip(),
        None => (Vec::new(), Vec::new()),
    }
}

/// Thins a long chain to about `2 * width` points, keeping each bucket's minimum and
/// maximum in order, so the envelope of the trace is preserved. Returns (iteration, value).
fn decimate(chain: &[f64], width: usize) -> (Vec<f64>, Vec<f64>) {
    let n = chain.len();
    if n <= 2 * width {
        return ((0..n).map(|i| i as f64).collect(), chain.to_vec());
    }
    let bucket = n.div_ceil(width);
    let mut xs = Vec::with_capacity(2 * width + 2);
    let mut ys = Vec::with_capacity(2 * width + 2);
    for start in (0..n).step_by(bucket) {
        let end = (start + bucket).min(n);
        let mut lo: Option<usize> = None;
        let mut hi: Option<usize> = None;
        for (i, &v) in chain.iter().enumerate().take(end).skip(start) {
            if !v.is_finite() {
                continue;
            }
            if lo.is_none_or(|j| v < chain[j]) {
                lo = Some(i);
            }
            if hi.is_none_or(|j| v > chain[j]) {
                hi = Some(i);
            }
        }
        match (lo, hi) {
            (Some(a), Some(b)) => {
                let (a, b) = if a <= b { (a, b) } else { (b, a) };
                xs.push(a as f64);
                ys.push(chain[a]);
                if b != a {
                    xs.push(b as f64);
                    ys.push(chain[b]);
                }
            }
            _ => {
                xs.push(start as f64);
                ys.push(f64::NAN);
            }
        }
    }
    (xs, ys)
}

/// Histogram (density-normalised) of the finite draws as bars `(y0, y1, density)`.
fn histogram(vals: impl Iterator<Item = f64>, axis: &Axis) -> Vec<(f64, f64, f64)> {
    let v: Vec<f64> = vals.filter(|x| x.is_finite()).collect();
    let Some((min, max)) = min_max(v.iter().copied()) else {
        return Vec::new();
    };
    let n = v.len() as f64;
    if max - min <= 1e-12 * min.abs().max(max.abs()) {
        let half = (axis.hi - axis.lo) / 80.0;
        return vec![(min - half, min + half, 1.0 / (2.0 * half))];
    }
    let nb = (n.sqrt() as usize).clamp(10, 50);
    let width = (max - min) / nb as f64;
    let mut counts = vec![0usize; nb];
    for &x in &v {
        let b = (((x - min) / width) as usize).min(nb - 1);
        counts[b] += 1;
    }
    counts
        .iter()
        .enumerate()
        .map(|(b, &c)| {
            let y0 = min + b as f64 * width;
            (y0, y0 + width, c as f64 / (n * width))
        })
        .collect()
}

/// Binned Gaussian kernel density estimate (Silverman's bandwidth) on a grid over the axis
/// range; returns (value, density). Empty for fewer than two distinct finite draws.
fn kde(chain: &[f64], axis: &Axis) -> Vec<(f64, f64)> {
    let v: Vec<f64> = chain.iter().copied().filter(|x| x.is_finite()).collect();
    let n = v.len();
    if n < 2 {
        return Vec::new();
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let mut sorted = v.clone();
    sorted.sort_by(f64::total_cmp);
    let q = |p: f64| sorted[((n - 1) as f64 * p).round() as usize];
    let iqr = q(0.75) - q(0.25);
    let spread = if iqr > 0.0 { sd.min(iqr / 1.34) } else { sd };
    let h = 0.9 * spread * (n as f64).powf(-0.2);
    if !(h > 0.0 && h.is_finite()) {
        return Vec::new();
    }
    const G: usize = 256;
    let (lo, hi) = (axis.lo, axis.hi);
    let dx = (hi - lo) / (G - 1) as f64;
    let mut counts = vec![0.0; G];
    for &x in &v {
        let i = ((x - lo) / dx).round();
        if (0.0..G as f64).contains(&i) {
            counts[i as usize] += 1.0;
        }
    }
    let norm = 1.0 / (n as f64 * h * (std::f64::consts::TAU).sqrt());
    let reach = ((5.0 * h / dx).ceil() as usize).min(G);
    (0..G)
        .map(|i| {
            let a = i.saturating_sub(reach);
            let b = (i + reach).min(G - 1);
            let d: f64 = (a..=b)
                .filter(|&j| counts[j] > 0.0)
                .map(|j| {
                    let z = (i as f64 - j as f64) * dx / h;
                    counts[j] * (-0.5 * z * z).exp()
                })
                .sum();
            (lo + i as f64 * dx, d * norm)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;

    const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

    fn out(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("motorcal_plot_{name}.png"))
    }

    fn assert_png(path: &Path) {
        let bytes = fs::read(path).expect("png written");
        assert_eq!(&bytes[..8], &PNG_SIGNATURE, "{}", path.display());
        assert!(
            bytes.len() > 10_000,
            "{} is only {} bytes",
            path.display(),
            bytes.len()
        );
        // No temporary file left next to it.
        let dir = path.parent().unwrap();
        let stem = format!(".{}.", path.file_name().unwrap().to_string_lossy());
        let leftovers = fs::read_dir(dir)
            .unwrap()
            .filter_map(Result::ok)
            .filter(|e| e.file_name().to_string_lossy().starts_with(&stem))
            .count();
        assert_eq!(leftovers, 0, "temporary files left for {}", path.display());
    }

    fn assert_err_no_file(path: &Path, r: Result<(), PlotError>) {
        let _ = fs::remove_file(path);
        assert!(r.is_err());
        assert!(!path.exists());
    }

    /// Small deterministic normal generator (xorshift + Box–Muller).
    struct Rng(u64);
    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn normal(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    fn predictive_example() -> PredictivePlot {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let times: Vec<f64> = (0..400).map(|i| i as f64 * 0.005).collect();
        let mut channels = Vec::new();
        for (name, unit, sigma) in [("I", "A", 0.04), ("ω", "rad/s", 0.8)] {
            let truth = |t: f64| {
                if name == "I" {
                    2.0 * (-t / 0.15).exp() + 0.3 + 0.08 * (9.0 * t).sin()
                } else {
                    40.0 * (1.0 - (-t / 0.3).exp()) - 1.5 * (4.0 * t).sin()
                }
            };
            let model = |t: f64| {
                if name == "I" {
                    2.0 * (-t / 0.16).exp() + 0.3
                } else {
                    40.0 * (1.0 - (-t / 0.3).exp())
                }
            };
            let mean: Vec<f64> = times.iter().map(|&t| truth(t) + 0.01).collect();
            let half: Vec<f64> = times
                .iter()
                .map(|&t| 2.0 * sigma * (0.4 + 0.3 * (3.0 * t).cos().abs()))
                .collect();
            let mut measured: Vec<f64> = times
                .iter()
                .map(|&t| truth(t) + sigma * rng.normal())
                .collect();
            measured[17] = f64::NAN; // a missing sample
            channels.push(ChannelPrediction {
                name: name.into(),
                unit: unit.into(),
                model: times.iter().map(|&t| model(t)).collect(),
                lower: mean.iter().zip(&half).map(|(m, h)| m - h).collect(),
                upper: mean.iter().zip(&half).map(|(m, h)| m + h).collect(),
                mean,
                measured,
                sigma,
            });
        }
        PredictivePlot {
            title: "Posterior predictive check — recording 1".into(),
            times,
            channels,
        }
    }

    #[test]
    fn posterior_predictive_writes_png() {
        let p = out("predictive");
        posterior_predictive(&p, &predictive_example()).unwrap();
        assert_png(&p);
    }

    #[test]
    fn posterior_predictive_rejects_empty_and_inconsistent_input() {
        let p = out("predictive_empty");
        assert_err_no_file(&p, posterior_predictive(&p, &PredictivePlot::default()));
        let mut ex = predictive_example();
        ex.channels.clear();
        assert_err_no_file(&p, posterior_predictive(&p, &ex));
        let mut ex = predictive_example();
        ex.channels[1].upper.pop();
        let err = posterior_predictive(&p, &ex).unwrap_err();
        assert!(err.message().contains("upper"), "{err}");
        assert!(!p.exists());
        let mut ex = predictive_example();
        for ch in &mut ex.channels {
            for v in [
                &mut ch.measured,
                &mut ch.model,
                &mut ch.mean,
                &mut ch.lower,
                &mut ch.upper,
            ] {
                v.iter_mut().for_each(|x| *x = f64::NAN);
            }
        }
        assert_err_no_file(&p, posterior_predictive(&p, &ex));
    }

    #[test]
    fn posterior_predictive_survives_degenerate_data() {
        let p = out("predictive_degenerate");
        let mut ex = predictive_example();
        // Constant channel, infinities, a channel without any finite value, zero sigma.
        let n = ex.times.len();
        ex.channels[0] = ChannelPrediction {
            name: "I".into(),
            unit: "A".into(),
            measured: vec![1.0; n],
            model: vec![1.0; n],
            mean: vec![1.0; n],
            lower: vec![1.0; n],
            upper: vec![f64::INFINITY; n],
            sigma: 0.0,
        };
        ex.channels[1].measured = vec![f64::NAN; n];
        ex.channels[1].model = vec![f64::NEG_INFINITY; n];
        ex.channels[1].mean = vec![f64::NAN; n];
        ex.channels[1].lower = vec![f64::NAN; n];
        ex.channels[1].upper = vec![f64::NAN; n];
        posterior_predictive(&p, &ex).unwrap();
        assert_png(&p);
    }

    fn discrepancy_example() -> (Vec<f64>, Vec<DiscrepancyBand>) {
        let times: Vec<f64> = (0..300).map(|i| i as f64 * 0.01).collect();
        let chans = [("I", "A", 0.05), ("ω", "rad/s", 1.2)]
            .into_iter()
            .map(|(name, unit, a)| {
                let d0: Vec<f64> = times
                    .iter()
                    .map(|&t| a * ((2.1 * t).sin() + 0.3 * (5.0 * t).cos()))
                    .collect();
                let mean: Vec<f64> = d0
                    .iter()
                    .zip(&times)
                    .map(|(d, &t)| d + 0.15 * a * (1.3 * t).cos())
                    .collect();
                let half: Vec<f64> = times.iter().map(|&t| a * (0.25 + 0.1 * t)).collect();
                DiscrepancyBand {
                    name: name.into(),
                    unit: unit.into(),
                    lower: mean.iter().zip(&half).map(|(m, h)| m - h).collect(),
                    upper: mean.iter().zip(&half).map(|(m, h)| m + h).collect(),
                    mean,
                    reference: Some(d0),
                }
            })
            .collect();
        (times, chans)
    }

    #[test]
    fn discrepancy_band_writes_png() {
        let p = out("discrepancy");
        let (t, ch) = discrepancy_example();
        discrepancy_band(&p, "Discrepancy δ, K = 6 (BM2)", &t, &ch).unwrap();
        assert_png(&p);
    }

    #[test]
    fn discrepancy_band_rejects_empty_input() {
        let p = out("discrepancy_empty");
        let (t, mut ch) = discrepancy_example();
        assert_err_no_file(&p, discrepancy_band(&p, "x", &t, &[]));
        assert_err_no_file(&p, discrepancy_band(&p, "x", &[], &ch));
        ch[0].reference.as_mut().unwrap().push(0.0);
        assert_err_no_file(&p, discrepancy_band(&p, "x", &t, &ch));
    }

    fn trace_example(n: usize) -> Vec<TraceSeries> {
        let mut rng = Rng(42);
        [
            ("R [Ω]", 1.2, 0.05, 0.9),
            ("k_e [V·s/rad]", 0.05, 0.002, 0.97),
            ("σ_I [A]", 0.04, 0.003, 0.5),
        ]
        .into_iter()
        .map(|(name, mu, sd, rho)| {
            let chains = (0..4)
                .map(|c| {
                    let mut x = mu + sd * (c as f64 - 1.5);
                    (0..n)
                        .map(|_| {
                            x = mu + rho * (x - mu) + sd * (1.0 - rho * rho).sqrt() * rng.normal();
                            x
                        })
                        .collect()
                })
                .collect();
            TraceSeries {
                name: name.into(),
                chains,
                reference: Some(mu),
            }
        })
        .collect()
    }

    #[test]
    fn traces_writes_png() {
        let p = out("traces");
        traces(&p, "Trace plots, BM1, NUTS", &trace_example(2000)).unwrap();
        assert_png(&p);
        // Long chains are decimated; a constant parameter and NaNs do not break it.
        let mut ex = trace_example(50_000);
        ex[2].chains = vec![vec![0.5; 1000], vec![0.5; 1000]];
        ex[2].reference = None;
        ex[0].chains[1][10] = f64::NAN;
        let p = out("traces_long");
        traces(&p, "Trace plots, long chains", &ex).unwrap();
        assert_png(&p);
    }

    #[test]
    fn traces_rejects_empty_input() {
        let p = out("traces_empty");
        assert_err_no_file(&p, traces(&p, "x", &[]));
        let ex = vec![TraceSeries {
            name: "a".into(),
            chains: vec![vec![]],
            reference: None,
        }];
        assert_err_no_file(&p, traces(&p, "x", &ex));
        let ex = vec![TraceSeries {
            name: "a".into(),
            chains: vec![vec![f64::NAN; 10]],
            reference: None,
        }];
        assert_err_no_file(&p, traces(&p, "x", &ex));
    }

    fn ess_example() -> Vec<SamplerCurve> {
        let ks: Vec<f64> = (0..=10).map(f64::from).collect();
        [
            ("random-walk MH", 40.0, 0.55),
            ("MALA", 90.0, 0.4),
            ("HMC", 150.0, 0.3),
            ("NUTS", 120.0, 0.18),
        ]
        .into_iter()
        .map(|(name, a, decay)| SamplerCurve {
            sampler: name.into(),
            points: ks
                .iter()
                .map(|&k| {
                    let v = a * f64::exp(-decay * k);
                    (k, v, v < 1.0)
                })
                .collect(),
        })
        .collect()
    }

    #[test]
    fn ess_per_second_writes_png() {
        let p = out("ess");
        ess_per_second(
            &p,
            "Sampling efficiency, BM2",
            "min ESS per second [1/s]",
            &ess_example(),
        )
        .unwrap();
        assert_png(&p);
        // Non-positive and non-finite values are skipped on the log axis.
        let mut ex = ess_example();
        ex[0].points[3].1 = 0.0;
        ex[1].points[4].1 = -2.0;
        ex[2].points[5].1 = f64::NAN;
        ex[3].points = vec![(2.0, 5.0, false)];
        let p = out("ess_gradient");
        ess_per_second(&p, "Efficiency per gradient", "min ESS per gradient", &ex).unwrap();
        assert_png(&p);
    }

    #[test]
    fn ess_per_second_rejects_empty_input() {
        let p = out("ess_empty");
        assert_err_no_file(&p, ess_per_second(&p, "x", "y", &[]));
        let ex = vec![SamplerCurve {
            sampler: "MH".into(),
            points: vec![(1.0, 0.0, false), (2.0, -1.0, true)],
        }];
        assert_err_no_file(&p, ess_per_second(&p, "x", "y", &ex));
    }

    fn k_example() -> Vec<KSeries> {
        let k: Vec<f64> = (0..=10).map(f64::from).collect();
        let mean: Vec<f64> = k.iter().map(|&k| 1.2 + 0.1 * (-k).exp()).collect();
        let sd: Vec<f64> = k.iter().map(|&k| 0.01 + 0.004 * k).collect();
        let sig: Vec<f64> = k.iter().map(|&k| 0.3 * (-0.6 * k).exp() + 0.04).collect();
        vec![
            KSeries {
                name: "R".into(),
                unit: "Ω".into(),
                lower: Some(mean.iter().zip(&sd).map(|(m, s)| m - 1.96 * s).collect()),
                upper: Some(mean.iter().zip(&sd).map(|(m, s)| m + 1.96 * s).collect()),
                sd: Some(sd),
                mean,
                k: k.clone(),
                reference: Some(1.2),
                log_y: false,
            },
            KSeries {
                name: "σ_I".into(),
                unit: "A".into(),
                lower: Some(sig.iter().map(|s| s * 0.8).collect()),
                upper: Some(sig.iter().map(|s| s * 1.25).collect()),
                sd: None,
                mean: sig,
                k,
                reference: Some(0.04),
                log_y: true,
            },
        ]
    }

    #[test]
    fn k_study_writes_png() {
        let p = out("kstudy");
        k_study(
            &p,
            "Posterior against the discrepancy degree K",
            &k_example(),
        )
        .unwrap();
        assert_png(&p);
        // All-equal values, NaNs, non-positive values on a log axis.
        let mut ex = k_example();
        ex[0].mean = vec![2.0; 11];
        ex[0].sd = None;
        ex[0].lower = None;
        ex[0].upper = None;
        ex[1].mean[3] = -1.0;
        ex[1].mean[4] = f64::NAN;
        ex[1].lower.as_mut().unwrap()[0] = 0.0;
        let p = out("kstudy_degenerate");
        k_study(&p, "Degenerate", &ex).unwrap();
        assert_png(&p);
    }

    #[test]
    fn k_study_rejects_empty_input() {
        let p = out("kstudy_empty");
        assert_err_no_file(&p, k_study(&p, "x", &[]));
        let mut ex = k_example();
        ex[1].k.clear();
        ex[1].mean.clear();
        assert_err_no_file(&p, k_study(&p, "x", &ex));
        let mut ex = k_example();
        ex[0].sd.as_mut().unwrap().pop();
        assert_err_no_file(&p, k_study(&p, "x", &ex));
    }

    #[test]
    fn failed_plot_leaves_no_file() {
        let dir = std::env::temp_dir().join("motorcal_plot_no_such_dir_x");
        let _ = fs::remove_dir_all(&dir);
        let p = dir.join("f.png");
        let r = ess_per_second(&p, "x", "y", &ess_example());
        assert!(r.is_err());
        assert!(!dir.exists());
    }

    #[test]
    fn plots_from_many_threads() {
        let handles: Vec<_> = (0..4)
            .map(|i| {
                std::thread::spawn(move || {
                    let p = out(&format!("thread_{i}"));
                    ess_per_second(&p, &format!("thread {i}"), "y", &ess_example()).unwrap();
                    assert_png(&p);
                    fs::remove_file(&p).unwrap();
                })
            })
            .collect();
        for h in handles {
            h.join().unwrap();
        }
    }

    #[test]
    fn axes_are_sane() {
        let a = linear_axis([0.0, 1.0], 0.0, 0.0, false, 6).unwrap();
        assert_eq!(a.ticks.first(), Some(&0.0));
        assert_eq!(a.ticks.last(), Some(&1.0));
        assert_eq!(a.label(0.2), "0.2");
        let a = linear_axis([3.0, 3.0], 0.05, 0.0, false, 6).unwrap();
        assert!(a.lo < 3.0 && a.hi > 3.0);
        let a = linear_axis([0.0, 0.0], 0.05, 0.0, false, 6).unwrap();
        assert!(a.lo < 0.0 && a.hi > 0.0);
        assert!(linear_axis([f64::NAN, f64::INFINITY], 0.05, 0.0, false, 6).is_none());
        let a = linear_axis([0.0, 10.0], 0.0, 0.5, true, 12).unwrap();
        assert!(a.ticks.iter().all(|t| t.fract() == 0.0));
        let l = log_axis([0.5, 200.0, -1.0, 0.0], 0.05, 8).unwrap();
        assert!(l.ticks.len() >= 3);
        assert!(l.ticks.iter().any(|&t| l.label(t) == "10"));
        let l = log_axis([300.0, 320.0], 0.05, 8).unwrap();
        assert!(l.ticks.len() >= 2, "{l:?}");
        assert!(log_axis([0.0, -3.0], 0.05, 8).is_none());
        assert_eq!(fmt_sig(1e-5), "1e-5");
        assert_eq!(fmt_sig(0.30000000000000004), "0.3");
    }
}
