//! The posterior predictive check of one recording: data, model, G + δ with its band, and
//! the residuals with the noise band.

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

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
