//! Quantities against the discrepancy degree K (Figures 8–11 of the paper).

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

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
        let axes: Vec<(Option<Axis>, bool, String)> = series
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
                let axis = if s.log_y {
                    log_axis(vals, 0.06, target)
                } else {
                    linear_axis(vals, 0.06, 0.0, false, target)
                };
                (axis, s.log_y, with_unit(&s.name, &s.unit))
            })
            .collect();
        stacked_panels(root, &body, &xa, "K (discrepancy degree)", &axes, |i, p| {
            let s = &series[i];
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
            Ok(())
        })
    })
}

/// mean ± sd of a K series (NaN where unavailable).
fn sd_band(s: &KSeries) -> (Vec<f64>, Vec<f64>) {
    match &s.sd {
        Some(sd) => s.mean.iter().zip(sd).map(|(m, d)| (m - d, m + d)).unzip(),
        None => (Vec::new(), Vec::new()),
    }
}
