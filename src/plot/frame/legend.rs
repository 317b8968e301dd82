//! Legends: icons, word-wrapped text, and placement where the data leave room.

use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::PlotError;
use super::*;

// ---------------------------------------------------------------------------------------
// Legend
// ---------------------------------------------------------------------------------------

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shape {
    Circle,
    Square,
    Triangle,
    Diamond,
    TriangleDown,
    Pentagon,
}

impl Shape {
    pub(crate) const ALL: [Shape; 6] = [
        Shape::Circle,
        Shape::Square,
        Shape::Triangle,
        Shape::Diamond,
        Shape::TriangleDown,
        Shape::Pentagon,
    ];

    /// Polygon vertices (pixel offsets) of a marker of about radius `r`.
    pub(crate) fn vertices(self, r: i32) -> Vec<(i32, i32)> {
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
pub(crate) enum Icon {
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
pub(crate) struct LegendItem {
    pub(crate) label: String,
    pub(crate) icon: Icon,
}

pub(crate) const LEGEND_FONT: u32 = 16;
pub(crate) const ICON_W: i32 = 36;
pub(crate) const ROW_H: i32 = 24;
pub(crate) const PAD: i32 = 8;

/// Draws a legend icon occupying `x..x + ICON_W`, vertically centred on `y`.
pub(crate) fn draw_icon(area: &Area<'_>, icon: &Icon, x: i32, y: i32) -> Result<(), PlotError> {
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
pub(crate) fn word_gap(size: u32) -> i32 {
    // DejaVu Sans space advance (0.318 em) plus a compensation of about 0.06 em.
    (f64::from(size) * 0.38).round() as i32
}

pub(crate) fn text_width(area: &Area<'_>, text: &str, size: u32) -> i32 {
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
pub(crate) fn draw_text(
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
pub(crate) fn draw_legend_box(
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
pub(crate) fn draw_legend_strip(area: &Area<'_>, items: &[LegendItem]) -> Result<(), PlotError> {
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
pub(crate) struct Occupancy {
    pub(crate) nx: usize,
    pub(crate) ny: usize,
    pub(crate) cells: Vec<bool>,
    pub(crate) x: (f64, f64),
    pub(crate) y: (f64, f64),
}

impl Occupancy {
    pub(crate) fn new(x: &Axis, y: &Axis) -> Self {
        let (nx, ny) = (60, 40);
        Self {
            nx,
            ny,
            cells: vec![false; nx * ny],
            x: (x.lo, x.hi),
            y: (y.lo, y.hi),
        }
    }

    pub(crate) fn norm(&self, p: (f64, f64)) -> (f64, f64) {
        (
            (p.0 - self.x.0) / (self.x.1 - self.x.0),
            (p.1 - self.y.0) / (self.y.1 - self.y.0),
        )
    }

    pub(crate) fn mark_norm(&mut self, (u, v): (f64, f64)) {
        if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
            return;
        }
        let i = ((u * self.nx as f64) as usize).min(self.nx - 1);
        let j = ((v * self.ny as f64) as usize).min(self.ny - 1);
        self.cells[j * self.nx + i] = true;
    }

    pub(crate) fn mark(&mut self, p: (f64, f64)) {
        let n = self.norm(p);
        self.mark_norm(n);
    }

    pub(crate) fn mark_path(&mut self, pts: &[(f64, f64)]) {
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

    pub(crate) fn mark_vertical(&mut self, x: f64, y0: f64, y1: f64) {
        self.mark_path(&[(x, y0), (x, y1)]);
    }

    /// Number of marked cells overlapping the normalised box.
    pub(crate) fn count(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> usize {
        let idx = |t: f64, n: usize| ((t * n as f64).floor().max(0.0) as usize).min(n - 1);
        let (i0, i1) = (idx(u0, self.nx), idx(u1, self.nx));
        let (j0, j1) = (idx(v0, self.ny), idx(v1, self.ny));
        (j0..=j1)
            .flat_map(|j| (i0..=i1).map(move |i| (i, j)))
            .filter(|&(i, j)| self.cells[j * self.nx + i])
            .count()
    }
}
