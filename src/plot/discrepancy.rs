//! The posterior of the discrepancy δ per channel, with a reference d0 where one is known.

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

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
        let axes: Vec<(Option<Axis>, bool, String)> = channels
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
                (
                    linear_axis(vals, 0.06, 0.0, false, y_ticks_for(row_h - 20)),
                    false,
                    with_unit(&format!("δ {}", c.name), &c.unit),
                )
            })
            .collect();
        stacked_panels(root, &body, &xa, "time [s]", &axes, |i, p| {
            let ch = &channels[i];
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
            Ok(())
        })
    })
}
