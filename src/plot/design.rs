//! What a designed input promises, as `motorcal design` draws it: the input; per measured channel
//! the truth's noise-free prediction with its ±2σ noise band and the rival's best fit to it; and
//! below, their difference against the same band — the part of the record that separates them.

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

/// The design figure (see [`design_figure`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DesignPlot {
    pub title: String,
    /// Sample times [s].
    pub times: Vec<f64>,
    /// The designed input at the sample times: a voltage, or a current command.
    pub input: Vec<f64>,
    /// The input's axis label, e.g. `U [V]` or `I [A]` (a current-driven model's command).
    pub input_label: String,
    /// The candidate taken as the truth, and its best-fitting rival (`None` when pinning: the
    /// model alone is drawn, and no difference).
    pub truth: String,
    pub rival: Option<String>,
    pub channels: Vec<DesignChannel>,
}

/// One measured channel; vectors aligned with the times.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DesignChannel {
    pub name: String,
    pub unit: String,
    /// The truth's noise-free prediction.
    pub truth: Vec<f64>,
    /// The rival fitted to it (empty when there is no rival).
    pub rival: Vec<f64>,
    /// The channel's noise σ.
    pub sigma: f64,
}

/// The input on top, then per channel the predictions panel and (with a rival) the difference
/// panel below it.
pub fn design_figure(path: &Path, plot: &DesignPlot) -> Result<(), PlotError> {
    let n = plot.times.len();
    if n == 0 || plot.channels.is_empty() {
        return Err(PlotError::new("design plot: no time points or no channels"));
    }
    check_len("input", plot.input.len(), n)?;
    for ch in &plot.channels {
        check_len(&format!("channel {:?}: truth", ch.name), ch.truth.len(), n)?;
        if plot.rival.is_some() {
            check_len(&format!("channel {:?}: rival", ch.name), ch.rival.len(), n)?;
        }
    }
    let nch = plot.channels.len() as u32;
    let input_h = 260;
    let block_h = if plot.rival.is_some() { 560 } else { 340 };
    let height = (TITLE_H + input_h + block_h * nch).max(MIN_HEIGHT);
    let block_h = (height - TITLE_H - input_h) / nch;
    let top_h = if plot.rival.is_some() {
        (f64::from(block_h) * 0.6) as u32
    } else {
        block_h
    };
    render(path, (WIDTH, height), |root| {
        let body = titled(root, &plot.title)?;
        let xa = linear_axis(plot.times.iter().copied(), 0.0, 0.0, false, 8)
            .unwrap_or_else(|| Axis::fallback(false));
        let input_axis = linear_axis(
            plot.input.iter().copied().chain([0.0]),
            0.08,
            0.0,
            false,
            y_ticks_for(input_h - 20),
        );
        let mut top_axes = Vec::new();
        let mut diff_axes = Vec::new();
        let mut differences = Vec::new();
        for ch in &plot.channels {
            let band = 2.0 * ch.sigma;
            let values = ch
                .truth
                .iter()
                .flat_map(|v| [v - band, v + band])
                .chain(ch.rival.iter().copied());
            top_axes.push(linear_axis(
                values,
                0.05,
                0.0,
                false,
                y_ticks_for(top_h.saturating_sub(20)),
            ));
            let d: Vec<f64> = ch.truth.iter().zip(&ch.rival).map(|(t, r)| t - r).collect();
            let values = d.iter().copied().chain([band, -band, 0.0]);
            diff_axes.push(linear_axis(
                values,
                0.08,
                0.0,
                false,
                y_ticks_for((block_h - top_h).saturating_sub(X_AREA + 20)),
            ));
            differences.push(d);
        }
        let y_area = y_label_area(
            root,
            std::iter::once(&input_axis)
                .chain(&top_axes)
                .chain(&diff_axes)
                .filter_map(|a| a.as_ref()),
        );
        let (input_area, rest) = body.split_vertically(input_h);
        let mut p = Panel::new(
            &input_area,
            PanelSpec {
                x: xa.clone(),
                y: input_axis.unwrap_or_else(|| Axis::fallback(false)),
                x_desc: "",
                y_desc: &plot.input_label,
                x_ticks: false,
                x_area: 0,
                y_area,
            },
        )?;
        p.hline(0.0, BLACK.mix(0.6).stroke_width(1), false)?;
        p.line(&plot.times, &plot.input, BLACK.stroke_width(2))?;
        p.legend_item(
            "designed input",
            Icon::Line {
                color: BLACK.to_rgba(),
                width: 2,
                dashed: false,
            },
        );
        p.finish()?;

        let blocks = rest.split_evenly((plot.channels.len(), 1));
        let last = plot.channels.len() - 1;
        for (i, (ch, block)) in plot.channels.iter().zip(&blocks).enumerate() {
            let (top, bottom) = block.split_vertically(top_h);
            let alone = plot.rival.is_none();
            let mut p = Panel::new(
                &top,
                PanelSpec {
                    x: xa.clone(),
                    y: top_axes[i].clone().unwrap_or_else(|| Axis::fallback(false)),
                    x_desc: if alone && i == last { "time [s]" } else { "" },
                    y_desc: &with_unit(&ch.name, &ch.unit),
                    x_ticks: alone && i == last,
                    x_area: if alone && i == last { X_AREA } else { 0 },
                    y_area,
                },
            )?;
            let band = 2.0 * ch.sigma;
            let lower: Vec<f64> = ch.truth.iter().map(|v| v - band).collect();
            let upper: Vec<f64> = ch.truth.iter().map(|v| v + band).collect();
            p.band(&plot.times, &lower, &upper, C_BLUE.mix(0.2))?;
            p.line(&plot.times, &ch.truth, C_BLUE.stroke_width(2))?;
            p.legend_item(
                &format!("{}: noise-free prediction", plot.truth),
                Icon::Line {
                    color: C_BLUE.to_rgba(),
                    width: 2,
                    dashed: false,
                },
            );
            p.legend_item(
                &format!(
                    "±2σ noise band, σ = {}",
                    with_space_unit(&fmt_sig(ch.sigma), &ch.unit)
                ),
                Icon::Band(C_BLUE.mix(0.2)),
            );
            let Some(rival) = &plot.rival else {
                p.finish()?;
                continue;
            };
            p.dashed(&plot.times, &ch.rival, C_VERMILLION.stroke_width(2))?;
            p.legend_item(
                &format!("{rival}: best fit to it"),
                Icon::Line {
                    color: C_VERMILLION.to_rgba(),
                    width: 2,
                    dashed: true,
                },
            );
            p.legend_item(
                &format!("difference {} − {rival}, below", plot.truth),
                Icon::Line {
                    color: C_GREEN.to_rgba(),
                    width: 2,
                    dashed: false,
                },
            );
            p.finish()?;

            let mut p = Panel::new(
                &bottom,
                PanelSpec {
                    x: xa.clone(),
                    y: diff_axes[i]
                        .clone()
                        .unwrap_or_else(|| Axis::fallback(false)),
                    x_desc: if i == last { "time [s]" } else { "" },
                    y_desc: &with_unit("difference", &ch.unit),
                    x_ticks: true,
                    x_area: X_AREA,
                    y_area,
                },
            )?;
            let ends = [xa.lo, xa.hi];
            p.band(&ends, &[-band; 2], &[band; 2], C_BLUE.mix(0.2))?;
            p.hline(0.0, BLACK.mix(0.6).stroke_width(1), false)?;
            p.line(&plot.times, &differences[i], C_GREEN.stroke_width(2))?;
            p.finish()?;
        }
        Ok(())
    })
}
