//! Panels: a chart with its axes, what was drawn where, and its legend entries.

use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::HPos;

use super::super::PlotError;
use super::*;

// ---------------------------------------------------------------------------------------
// Panels
// ---------------------------------------------------------------------------------------

pub(crate) struct PanelSpec<'s> {
    pub(crate) x: Axis,
    pub(crate) y: Axis,
    pub(crate) x_desc: &'s str,
    pub(crate) y_desc: &'s str,
    /// Tick labels on the x axis (the description is shown whenever `x_area > 0`).
    pub(crate) x_ticks: bool,
    pub(crate) x_area: u32,
    pub(crate) y_area: u32,
}

/// A chart with its axes, a record of where data was drawn (for legend placement) and
/// its legend entries.
pub(crate) struct Panel<'a, 'b> {
    pub(crate) chart: Chart<'a, 'b>,
    pub(crate) x: Axis,
    pub(crate) y: Axis,
    pub(crate) occ: Occupancy,
    pub(crate) legend: Vec<LegendItem>,
}

impl<'a, 'b> Panel<'a, 'b> {
    pub(crate) fn new(area: &'a Area<'b>, spec: PanelSpec<'_>) -> Result<Self, PlotError> {
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

    pub(crate) fn pixel_size(&self) -> (u32, u32) {
        self.chart.plotting_area().dim_in_pixel()
    }

    /// Points of the polyline through the showable (x, y) pairs, split where a pair is not.
    pub(crate) fn segments(&self, xs: &[f64], ys: &[f64]) -> Vec<Vec<(f64, f64)>> {
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

    pub(crate) fn line(
        &mut self,
        xs: &[f64],
        ys: &[f64],
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
        let segs = self.segments(xs, ys);
        for s in &segs {
            self.occ.mark_path(s);
        }
        self.chart
            .draw_series(segs.into_iter().map(|s| PathElement::new(s, style)))?;
        Ok(())
    }

    pub(crate) fn dashed(
        &mut self,
        xs: &[f64],
        ys: &[f64],
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
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
    pub(crate) fn hline(
        &mut self,
        y: f64,
        style: ShapeStyle,
        dashed: bool,
    ) -> Result<(), PlotError> {
        let xs = [self.x.lo, self.x.hi];
        let ys = [y, y];
        if dashed {
            self.dashed(&xs, &ys, style)
        } else {
            self.line(&xs, &ys, style)
        }
    }

    pub(crate) fn points(
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
    pub(crate) fn band(
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
    pub(crate) fn bars_horizontal(
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
    pub(crate) fn markers(
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
    pub(crate) fn arrows(
        &mut self,
        pts: &[(f64, f64)],
        r: i32,
        color: RGBAColor,
    ) -> Result<(), PlotError> {
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
    pub(crate) fn note(&mut self, text: &str) -> Result<(), PlotError> {
        let area = self.chart.plotting_area().strip_coord_spec();
        let (w, h) = area.dim_in_pixel();
        draw_text(&area, text, (w as i32 / 2, h as i32 / 2), 18, HPos::Center)?;
        Ok(())
    }

    pub(crate) fn legend_item(&mut self, label: &str, icon: Icon) {
        self.legend.push(LegendItem {
            label: label.to_string(),
            icon,
        });
    }

    /// Frame and legend.
    pub(crate) fn finish(self) -> Result<(), PlotError> {
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
