//! Marginal posteriors of the discrepancy coefficients a_j per channel, with the least-squares
//! coefficients of the reference discrepancy d0 where it is known (Figures 14/17, new).

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

/// The coefficients of one channel's discrepancy (see [`coefficient_marginals`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CoefficientMarginals {
    /// Channel name.
    pub name: String,
    /// Unit of the coefficients (the channel's).
    pub unit: String,
    /// Posterior mean of a_j, j = 0..=K.
    pub mean: Vec<f64>,
    /// 95% interval of a_j.
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Least-squares coefficients of d0 in the same basis, where d0 is known.
    pub reference: Option<Vec<f64>>,
}

/// One panel per channel: for each j the 95% interval (vertical bar), the posterior mean (dot)
/// and the least-squares coefficient of d0 (hollow diamond).
pub fn coefficient_marginals(
    path: &Path,
    title: &str,
    channels: &[CoefficientMarginals],
) -> Result<(), PlotError> {
    if channels.is_empty() {
        return Err(PlotError::new("coefficient plot: no channels"));
    }
    for ch in channels {
        let n = ch.mean.len();
        if n == 0 {
            return Err(PlotError::new(format!(
                "coefficient plot: channel {:?} has no coefficients",
                ch.name
            )));
        }
        check_len(&format!("channel {:?}: lower", ch.name), ch.lower.len(), n)?;
        check_len(&format!("channel {:?}: upper", ch.name), ch.upper.len(), n)?;
        if let Some(r) = &ch.reference {
            check_len(&format!("channel {:?}: reference", ch.name), r.len(), n)?;
        }
    }
    if !channels.iter().any(|c| any_finite(&c.mean)) {
        return Err(PlotError::new("coefficient plot: no finite data to plot"));
    }
    let nch = channels.len() as u32;
    let height = (TITLE_H + X_AREA + 340 * nch).max(MIN_HEIGHT);
    let row_h = (height - TITLE_H - X_AREA) / nch;
    render(path, (WIDTH, height), |root| {
        let body = titled(root, title)?;
        let n_max = channels.iter().map(|c| c.mean.len()).max().unwrap_or(1);
        let xa = linear_axis([-0.5, n_max as f64 - 0.5], 0.0, 0.0, false, 10)
            .unwrap_or_else(|| Axis::fallback(false));
        let axes: Vec<(Option<Axis>, bool, String)> = channels
            .iter()
            .map(|c| {
                let vals = c
                    .lower
                    .iter()
                    .chain(&c.upper)
                    .chain(&c.mean)
                    .chain(c.reference.iter().flatten())
                    .chain(&[0.0])
                    .copied();
                (
                    linear_axis(vals, 0.06, 0.0, false, y_ticks_for(row_h - 20)),
                    false,
                    with_unit(&format!("a_j of δ {}", c.name), &c.unit),
                )
            })
            .collect();
        stacked_panels(root, &body, &xa, "coefficient index j", &axes, |i, p| {
            let ch = &channels[i];
            p.hline(0.0, BLACK.mix(0.5).stroke_width(1), false)?;
            let js: Vec<f64> = (0..ch.mean.len()).map(|j| j as f64).collect();
            for (j, (&lo, &hi)) in ch.lower.iter().zip(&ch.upper).enumerate() {
                p.line(&[j as f64, j as f64], &[lo, hi], C_BLUE.stroke_width(3))?;
            }
            p.points(&js, &ch.mean, 4, C_BLUE.filled())?;
            p.legend_item(
                "posterior mean and 95% interval",
                Icon::Marker {
                    shape: Shape::Circle,
                    color: C_BLUE.to_rgba(),
                    filled: true,
                    line: true,
                    arrow: false,
                },
            );
            if let Some(r) = &ch.reference {
                let pts: Vec<(f64, f64)> = js.iter().copied().zip(r.iter().copied()).collect();
                p.markers(&pts, Shape::Diamond, 6, C_VERMILLION.to_rgba(), false)?;
                p.legend_item(
                    "least-squares coefficients of d₀",
                    Icon::Marker {
                        shape: Shape::Diamond,
                        color: C_VERMILLION.to_rgba(),
                        filled: false,
                        line: false,
                        arrow: false,
                    },
                );
            }
            Ok(())
        })
    })
}
