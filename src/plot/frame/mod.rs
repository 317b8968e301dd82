//! The frame every figure is drawn in: the embedded font, colours, atomic rendering to PNG,
//! titles and stacked rows; the axes, panels and legends are its submodules. A new figure is a
//! new file beside its siblings in `plot/` that draws into this frame.

use std::fs;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::HPos;

use super::PlotError;

mod axis;
mod legend;
mod panel;

pub(crate) use axis::*;
pub(crate) use legend::*;
pub(crate) use panel::*;

pub(crate) const WIDTH: u32 = 1200;
pub(crate) const MIN_HEIGHT: u32 = 800;
pub(crate) const TITLE_H: u32 = 50;
pub(crate) const X_AREA: u32 = 62;

// ---------------------------------------------------------------------------------------
// Rendering infrastructure
// ---------------------------------------------------------------------------------------

pub(crate) const FONT: &str = "sans-serif";
pub(crate) static FONT_BYTES: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");

pub(crate) const C_BLUE: RGBColor = RGBColor(0, 114, 178);
pub(crate) const C_VERMILLION: RGBColor = RGBColor(213, 94, 0);
pub(crate) const C_GREEN: RGBColor = RGBColor(0, 158, 115);
pub(crate) const C_GREY: RGBColor = RGBColor(100, 100, 100);
pub(crate) const C_HIST: RGBColor = RGBColor(215, 215, 215);

/// Colour cycle (Okabe–Ito based, ordered so that neighbours differ in lightness too).
pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(230, 159, 0),
    RGBColor(30, 30, 30),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(213, 94, 0),
    RGBColor(86, 180, 233),
    RGBColor(160, 140, 20),
];

pub(crate) fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Registers the embedded font exactly once (thread-safe); later calls return the
/// remembered outcome.
pub(crate) fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::new(
            "the embedded DejaVu Sans font could not be registered",
        ))
    }
}

pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
pub(crate) type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<TickedRange, TickedRange>>;

/// Renders into a temporary PNG next to `path` and renames it into place on success;
/// on failure (including a panic inside the drawing code) the temporary file is removed.
pub(crate) fn render(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    ensure_font()?;
    let tmp = temp_path(path)?;
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<(), PlotError> {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
        Ok(())
    }))
    .unwrap_or_else(|_| Err(PlotError::new("internal error while drawing")));
    match result {
        Ok(()) => fs::rename(&tmp, path).map_err(|e| {
            let _ = fs::remove_file(&tmp);
            PlotError::new(format!("cannot write {}: {e}", path.display()))
        }),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(PlotError::new(format!(
                "cannot plot {}: {}",
                path.display(),
                e.message
            )))
        }
    }
}

pub(crate) fn temp_path(path: &Path) -> Result<PathBuf, PlotError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| PlotError::new(format!("{} is not a file path", path.display())))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    // The bitmap encoder picks the format from the extension, hence `.png` at the end.
    Ok(path.with_file_name(format!(
        ".{}.{}-{n}.tmp.png",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Draws the figure title (if any) and returns the area below it.
pub(crate) fn titled<'b>(root: &Area<'b>, title: &str) -> Result<Area<'b>, PlotError> {
    let (head, body) = root.split_vertically(TITLE_H);
    if !title.is_empty() {
        let (w, h) = head.dim_in_pixel();
        draw_text(
            &head,
            title,
            (w as i32 / 2, h as i32 / 2 + 2),
            26,
            HPos::Center,
        )?;
    }
    Ok(body)
}

/// Splits `area` into `n` rows of equal plot height, the last one `extra` pixels taller
/// (room for the x labels).
/// Panels stacked on `body`, one per entry of `y_axes` (axis, log scale, description), sharing
/// the x axis: tick labels and the x description on the last only, a note where a row had no
/// finite data (its axis `None`), and `draw` filling each before it is finished.
pub(crate) fn stacked_panels<'b>(
    root: &Area<'b>,
    body: &Area<'b>,
    x: &Axis,
    x_desc: &str,
    y_axes: &[(Option<Axis>, bool, String)],
    mut draw: impl FnMut(usize, &mut Panel<'_, 'b>) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    let y_area = y_label_area(root, y_axes.iter().filter_map(|(a, _, _)| a.as_ref()));
    let rows = stack_rows(body, y_axes.len(), X_AREA);
    for (i, ((axis, log, y_desc), area)) in y_axes.iter().zip(&rows).enumerate() {
        let last = i + 1 == y_axes.len();
        let mut p = Panel::new(
            area,
            PanelSpec {
                x: x.clone(),
                y: axis.clone().unwrap_or_else(|| Axis::fallback(*log)),
                x_desc,
                y_desc,
                x_ticks: last,
                x_area: if last { X_AREA } else { 0 },
                y_area,
            },
        )?;
        if axis.is_none() {
            p.note("no finite data")?;
        }
        draw(i, &mut p)?;
        p.finish()?;
    }
    Ok(())
}

pub(crate) fn stack_rows<'b>(area: &Area<'b>, n: usize, extra: u32) -> Vec<Area<'b>> {
    let (_, h) = area.dim_in_pixel();
    let row = (h.saturating_sub(extra) as usize / n.max(1)) as i32;
    let breaks: Vec<i32> = (1..n).map(|i| row * i as i32).collect();
    area.split_by_breakpoints([] as [i32; 0], breaks)
}

pub(crate) fn y_ticks_for(px: u32) -> usize {
    ((px / 45) as usize).clamp(3, 10)
}

/// Width of the y label area that fits the tick labels of all the given axes.
pub(crate) fn y_label_area<'x>(root: &Area<'_>, axes: impl IntoIterator<Item = &'x Axis>) -> u32 {
    let style = TextStyle::from((FONT, 16).into_font());
    let widest = axes
        .into_iter()
        .flat_map(|a| a.ticks.iter().map(move |&t| a.label(t)))
        .map(|s| {
            root.estimate_text_size(&s, &style)
                .map(|d| d.0)
                .unwrap_or(60)
        })
        .max()
        .unwrap_or(40);
    widest + 52
}

// ---------------------------------------------------------------------------------------
// Small numerical helpers
// ---------------------------------------------------------------------------------------

pub(crate) fn check_len(what: &str, got: usize, want: usize) -> Result<(), PlotError> {
    if got == want {
        Ok(())
    } else {
        Err(PlotError::new(format!(
            "{what} has {got} values, expected {want}"
        )))
    }
}

pub(crate) fn any_finite(v: &[f64]) -> bool {
    v.iter().any(|x| x.is_finite())
}

pub(crate) fn valid_sigma(s: f64) -> Option<f64> {
    (s.is_finite() && s > 0.0).then_some(s)
}

pub(crate) fn with_space_unit(value: &str, unit: &str) -> String {
    if unit.is_empty() {
        value.to_string()
    } else {
        format!("{value} {unit}")
    }
}

pub(crate) fn with_unit(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}
