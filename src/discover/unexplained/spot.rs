//! A spot of the angle in what is read of ω: the reading off over a narrow span of each
//! revolution, at the same angle every turn (an encoder line damaged or missing, a worn segment
//! of a tachogenerator's commutator).
//!
//! Such a spot is a sum of many harmonics of the angle, each too small to pay its ½·ln N: a
//! span of w radians carries some 1/w of them. One ripple of k (`reading`) takes a share of it
//! at best, and a law in several pays for each. The spot itself is one coefficient at a shape
//! searched: the bump ω·exp(−2·(1 − cos(θ − θ₀))/w²) (`dictionary::OMEGA_SPOT`) at widths
//! π/2, π/4, … down to the angle the record turns in one sample at its speed scale (a narrower
//! spot falls between samples), each at centres w/2 apart (a centre off by w/4 at most keeps
//! exp(−1/16) of the column's projection, 94%). The best of the G columns is offered to the
//! selection as one move paying ½·ln N + ln G, the ln G of its search fixed with the grid
//! before any case was run, as the order search's is; the verdict's threshold then applies.
//! With the widths to π/32 that is 248 columns, ln G = 5.5 nats: a null record's best column
//! is the largest of 248 gains of ½χ²₁ about, clearing ½·ln N + ln G + 2 (11.0 nats at N =
//! 1002) with probability about 248·P(χ²₁ > 22) ≈ 0.07%.

use std::f64::consts::PI;

use nalgebra::DMatrix;

use crate::motor::dictionary::{self, OMEGA_SPOT, Point, Shapes, Spot};

use super::state::{Column, Shape, select};
use super::{Context, Evidence};

/// The widest spot tried, and how many halvings below it at most.
const WIDEST: f64 = PI / 2.0;
const HALVINGS: i32 = 4;

/// A spot offered, and what finding it cost (ln G).
#[derive(Clone, Copy, Debug)]
pub(super) struct SpotShape {
    pub spot: Spot,
    pub price: f64,
}

/// The grid of (θ₀, w) tried on a record whose speed scale turns `per_sample` radians between
/// samples: widths from π/2 by halvings while at least `per_sample`, centres w/2 apart.
pub(super) fn grid(per_sample: f64) -> Vec<Spot> {
    let mut out = Vec::new();
    for j in 0..=HALVINGS {
        let width = WIDEST / 2f64.powi(j);
        if width < per_sample {
            break;
        }
        let centres = (4.0 * PI / width).round() as usize;
        out.extend((0..centres).map(|i| Spot::new(2.0 * PI * i as f64 / centres as f64, width)));
    }
    out
}

/// The spot's fingerprint on what is read of ω (channel `c`), where the best spot of the grid
/// clears the selection's bar: the columns ω·spot(θ) at the predicted speed and angle `theta`,
/// the law's other shapes `shapes`, on a record turning `per_sample` radians a sample.
pub(super) fn fingerprints(
    ctx: &Context,
    c: usize,
    shapes: &Shapes,
    theta: &[f64],
    per_sample: f64,
    shift: f64,
) -> Vec<Evidence> {
    let spots = grid(per_sample);
    let column = |spot: &Spot| -> DMatrix<f64> {
        let s = Shapes {
            spot_angle: spot.theta_0,
            spot_width: spot.w,
            ..*shapes
        };
        let mut b = DMatrix::zeros(ctx.m(), 1);
        for i in 0..ctx.n {
            let t = ctx.times[i];
            let x = Point {
                t,
                current: 0.0,
                speed: ctx.fine.at(c, t),
                voltage: 0.0,
                charge: 0.0,
                heat: 0.0,
                theta: theta[i],
            };
            b[(c * ctx.n + i, 0)] = dictionary::value(OMEGA_SPOT, &x, &s) / ctx.sigma[c];
        }
        ctx.projector.residualize(&b)
    };
    // The best single column by its gain ½·(b̃·y)²/(b̃·b̃); the first of equals, so the same
    // record gives the same spot.
    let mut best: Option<(f64, Spot, DMatrix<f64>)> = None;
    for spot in &spots {
        let b = column(spot);
        let bb = b.column(0).norm_squared();
        if bb <= 0.0 {
            continue;
        }
        let gain = 0.5 * b.column(0).dot(&ctx.y).powi(2) / bb;
        if best.as_ref().is_none_or(|(g, _, _)| gain > *g) {
            best = Some((gain, *spot, b));
        }
    }
    let Some((_, spot, b_tilde)) = best else {
        return Vec::new();
    };
    let shape = SpotShape {
        spot,
        price: (spots.len() as f64).ln(),
    };
    let columns = [Column::new(OMEGA_SPOT, Shape::Spot(shape))];
    select(
        ctx,
        &columns,
        &b_tilde,
        "measurement:omega",
        shift,
        |_: &Column| true,
    )
    .into_iter()
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_stops_at_the_angle_a_sample_turns_and_spaces_centres_half_a_width() {
        // 0.19 rad a sample (a slow record): π/2 to π/16, 8 + 16 + 32 + 64 centres.
        let g = grid(0.19);
        assert_eq!(g.len(), 8 + 16 + 32 + 64);
        let narrowest = g.iter().map(|s| s.w).fold(f64::INFINITY, f64::min);
        assert!((narrowest - PI / 16.0).abs() < 1e-12);
        // The paper's motor at 24 V turns 2.4 rad a sample: no spot is resolved.
        assert!(grid(2.4).is_empty());
        // Every centre lies in one turn.
        assert!(g.iter().all(|s| (0.0..2.0 * PI).contains(&s.theta_0)));
    }
}
