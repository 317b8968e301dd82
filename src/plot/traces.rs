//! Trace plots with each parameter's marginal beside its draws.

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

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
