//! The columns a state fingerprint's selection is offered: a dictionary function and the shape
//! it is evaluated at (the Stribeck speed, the angle's harmonic, the current limit, a spot of
//! the angle, a fade's time constant, the speed limit), with what finding that shape cost.

use crate::motor::dictionary::Spot;

use super::regression::best_single_column;
use super::spot::SpotShape;

/// A column of the regression: a function (dictionary index) and the shape it has, the
/// Stribeck speed, the angle's harmonic, the current limit, a spot of the angle, a fade's time
/// constant or the speed limit.
pub(super) struct Column {
    pub function: usize,
    pub shape: Shape,
}

impl Column {
    pub fn new(function: usize, shape: Shape) -> Self {
        Self { function, shape }
    }

    pub fn omega_s(&self) -> Option<f64> {
        match self.shape {
            Shape::StribeckSpeed(w) => Some(w),
            _ => None,
        }
    }

    pub fn harmonic(&self) -> Option<f64> {
        match self.shape {
            Shape::Harmonic(h) => Some(h.k),
            _ => None,
        }
    }

    pub fn current_limit(&self) -> Option<f64> {
        match self.shape {
            Shape::CurrentLimit(i) => Some(i),
            _ => None,
        }
    }

    pub fn instant(&self) -> Option<f64> {
        match self.shape {
            Shape::Step(s) => Some(s.t_s),
            _ => None,
        }
    }

    pub fn fade(&self) -> Option<f64> {
        match self.shape {
            Shape::Fade(f) => Some(f.value),
            _ => None,
        }
    }

    pub fn speed_limit(&self) -> Option<f64> {
        match self.shape {
            Shape::SpeedLimit(l) => Some(l.value),
            _ => None,
        }
    }

    pub fn spot(&self) -> Option<Spot> {
        match self.shape {
            Shape::Spot(s) => Some(s.spot),
            _ => None,
        }
    }

    /// What a move taking it pays on top of its ½·ln N and the step's look-elsewhere, for a
    /// shape found by a search of its own (an order between the grid's, `order`: ln G).
    pub fn price(&self) -> f64 {
        match self.shape {
            Shape::Harmonic(h) => h.price,
            Shape::Spot(s) => s.price,
            Shape::Step(s) => s.price,
            Shape::Fade(f) | Shape::SpeedLimit(f) => f.price,
            _ => 0.0,
        }
    }

    /// For such a shape, the half-width of its refinement through the ODE (`named`).
    pub fn width(&self) -> f64 {
        match self.shape {
            Shape::Harmonic(h) => h.width,
            _ => 0.0,
        }
    }
}

/// A harmonic k of the angle offered, with what a column at it pays for its search (the
/// grid's nothing: their number is in each step's look-elsewhere; the order search's ln G)
/// and the half-width of its refinement through the ODE (0: none).
#[derive(Clone, Copy, Debug)]
pub(super) struct Harmonic {
    pub k: f64,
    pub price: f64,
    pub width: f64,
}

impl Harmonic {
    pub fn on_grid(k: f64) -> Self {
        Self {
            k,
            price: 0.0,
            width: 0.0,
        }
    }
}

/// How a column (a block of them) shapes the law it is evaluated on.
#[derive(Clone, Copy)]
pub(super) enum Shape {
    /// The model's law's shapes (or the dictionary's defaults).
    Own,
    StribeckSpeed(f64),
    Harmonic(Harmonic),
    CurrentLimit(f64),
    Spot(SpotShape),
    /// The time constant τ of exp(−t/τ), and what its search cost (ln G).
    Fade(OnGrid),
    /// The speed limit ω_lim of what is read of ω, and what its search cost (ln G).
    SpeedLimit(OnGrid),
    /// The instant of step(t − t_s), and what its search cost (ln G).
    Step(StepShape),
}

/// A shape's value offered from a grid (a fade's τ, a speed limit), and what finding it cost
/// (ln G over the grid; nothing for the model's own law's value, paid for where it was found).
#[derive(Clone, Copy, Debug)]
pub(super) struct OnGrid {
    pub value: f64,
    pub price: f64,
}

impl OnGrid {
    /// The shapes offered at `values`: a grid's each paying ln G, the model's own law's one
    /// value nothing (paid for where it was found).
    pub fn at(values: &[f64]) -> Vec<OnGrid> {
        let price = if values.len() > 1 {
            (values.len() as f64).ln()
        } else {
            0.0
        };
        values
            .iter()
            .map(|&value| OnGrid { value, price })
            .collect()
    }
}

/// The column of `columns` with the shape `shape` reads (a fade's τ, a speed limit), offered
/// where `offered` allows it, whose gain on `y`, ½·(b̃·y)²/(b̃·b̃) of its column of `b_tilde`,
/// is largest: its shape's value. Such a shape is offered at that value alone, as one move
/// paying its grid's ln G, as a spot of the angle or a step is (`spot`, `reading_step`).
pub(super) fn best_on_grid(
    columns: &[Column],
    b_tilde: &nalgebra::DMatrix<f64>,
    y: &nalgebra::DVector<f64>,
    shape: impl Fn(&Column) -> Option<f64>,
    offered: impl Fn(&Column) -> bool,
) -> Option<f64> {
    let member = |j: usize| shape(&columns[j]).is_some() && offered(&columns[j]);
    best_single_column(b_tilde, y, member).and_then(|(_, j)| shape(&columns[j]))
}

/// A step's instant offered, and what finding it cost (ln G over the instants tried).
#[derive(Clone, Copy, Debug)]
pub(super) struct StepShape {
    pub t_s: f64,
    pub price: f64,
}
