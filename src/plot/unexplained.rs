//! The evidence behind an "unexplained" verdict: per channel, the residual the selected model
//! leaves (in noise σ) with the part the leading fingerprint explains drawn through it, and the
//! spectrum of what a sinusoid at each frequency would gain (nats), where a resonance or a
//! periodic load stands out as a peak.

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

/// One row of the figure: points and a curve over one x axis.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnexplainedRow {
    pub x_desc: String,
    pub y_desc: String,
    pub x: Vec<f64>,
    /// Drawn as small grey points (may be empty).
    pub points: Vec<f64>,
    pub points_label: String,
    /// Drawn as a line.
    pub curve: Vec<f64>,
    pub curve_label: String,
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnexplainedPlot {
    pub title: String,
    pub rows: Vec<UnexplainedRow>,
}

pub fn unexplained(path: &Path, plot: &UnexplainedPlot) -> Result<(), PlotError> {
    if plot.rows.is_empty() {
        return Err(PlotError::new("unexplained plot: no rows"));
    }
    for r in &plot.rows {
        check_len(&r.curve_label, r.curve.len(), r.x.len())?;
        if !r.points.is_empty() {
            check_len(&r.points_label, r.points.len(), r.x.len())?;
        }
    }
    let row_h = 320;
    let height = (TITLE_H + X_AREA * plot.rows.len() as u32 + row_h * plot.rows.len() as u32)
        .max(MIN_HEIGHT);
    render(path, (WIDTH, height), |root| {
        let body = titled(root, &plot.title)?;
        let axes: Vec<(Axis, Axis)> = plot
            .rows
            .iter()
            .map(|r| {
                let x = linear_axis(r.x.iter().copied(), 0.02, 0.0, false, 10)
                    .unwrap_or_else(|| Axis::fallback(false));
                let y = linear_axis(
                    r.points.iter().chain(&r.curve).copied().chain([0.0]),
                    0.06,
                    0.0,
                    false,
                    y_ticks_for(row_h),
                )
                .unwrap_or_else(|| Axis::fallback(false));
                (x, y)
            })
            .collect();
        let y_area = y_label_area(root, axes.iter().map(|(_, y)| y));
        let areas = body.split_evenly((plot.rows.len(), 1));
        for ((r, (xa, ya)), area) in plot.rows.iter().zip(axes).zip(&areas) {
            let mut p = Panel::new(
                area,
                PanelSpec {
                    x: xa,
                    y: ya,
                    x_desc: &r.x_desc,
                    y_desc: &r.y_desc,
                    x_ticks: true,
                    x_area: X_AREA,
                    y_area,
                },
            )?;
            p.hline(0.0, BLACK.stroke_width(1), true)?;
            if !r.points.is_empty() {
                p.points(&r.x, &r.points, 2, C_GREY.filled())?;
                p.legend_item(&r.points_label, Icon::Dots(C_GREY.to_rgba()));
            }
            p.line(&r.x, &r.curve, C_VERMILLION.stroke_width(2))?;
            p.legend_item(
                &r.curve_label,
                Icon::Line {
                    color: C_VERMILLION.to_rgba(),
                    width: 2,
                    dashed: false,
                },
            );
            p.finish()?;
        }
        Ok(())
    })
}
