//! The torque a model misses, against speed: the binned inverse-model residual before and after
//! the selected terms (a jump at zero speed is Coulomb friction, a slope viscous friction, a
//! constant an offset or a load).

use std::path::Path;

use plotters::prelude::*;

use super::PlotError;
use super::frame::*;

/// One curve: the mean missing torque per speed bin.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MissingTorqueCurve {
    pub label: String,
    pub speed: Vec<f64>,
    pub torque: Vec<f64>,
}

/// The figure's data: curves over a shared speed axis, with the axes' units.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MissingTorquePlot {
    pub title: String,
    pub speed_unit: String,
    pub torque_unit: String,
    pub curves: Vec<MissingTorqueCurve>,
}

pub fn missing_torque(path: &Path, plot: &MissingTorquePlot) -> Result<(), PlotError> {
    if plot.curves.is_empty() {
        return Err(PlotError::new("missing-torque plot: no curves"));
    }
    for c in &plot.curves {
        check_len(
            &format!("curve {:?}", c.label),
            c.torque.len(),
            c.speed.len(),
        )?;
    }
    if !plot
        .curves
        .iter()
        .any(|c| any_finite(&c.speed) && any_finite(&c.torque))
    {
        return Err(PlotError::new(
            "missing-torque plot: no finite data to plot",
        ));
    }
    let colours = [C_BLUE, C_VERMILLION];
    render(path, (WIDTH, MIN_HEIGHT), |root| {
        let body = titled(root, &plot.title)?;
        let xa = linear_axis(
            plot.curves.iter().flat_map(|c| c.speed.iter().copied()),
            0.04,
            0.0,
            false,
            10,
        )
        .unwrap_or_else(|| Axis::fallback(false));
        let ya = linear_axis(
            plot.curves
                .iter()
                .flat_map(|c| c.torque.iter().copied())
                .chain([0.0]),
            0.06,
            0.0,
            false,
            y_ticks_for(MIN_HEIGHT - TITLE_H - X_AREA),
        )
        .unwrap_or_else(|| Axis::fallback(false));
        let y_area = y_label_area(root, [&ya]);
        let rows = stack_rows(&body, 1, X_AREA);
        let mut p = Panel::new(
            &rows[0],
            PanelSpec {
                x: xa,
                y: ya,
                x_desc: &with_unit("speed", &plot.speed_unit),
                y_desc: &with_unit("missing torque (bin mean)", &plot.torque_unit),
                x_ticks: true,
                x_area: X_AREA,
                y_area,
            },
        )?;
        p.hline(0.0, BLACK.stroke_width(1), true)?;
        for (c, colour) in plot.curves.iter().zip(colours.iter().cycle()) {
            let points: Vec<(f64, f64)> = c
                .speed
                .iter()
                .copied()
                .zip(c.torque.iter().copied())
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            p.markers(&points, Shape::Circle, 4, colour.to_rgba(), true)?;
            p.legend_item(
                &c.label,
                Icon::Marker {
                    shape: Shape::Circle,
                    color: colour.to_rgba(),
                    filled: true,
                    line: false,
                    arrow: false,
                },
            );
        }
        p.finish()?;
        Ok(())
    })
}
