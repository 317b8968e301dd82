//! Sampler efficiency against the discrepancy degree K.

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

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
