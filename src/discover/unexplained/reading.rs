//! The state fingerprints of what is read: a measured channel's residual regressed on
//! functions of the predicted state and the input in that channel alone, selected as a
//! balance's are (`state`).

use nalgebra::DMatrix;

use crate::motor::Term;
use crate::motor::dictionary::{
    self, CONSTANT, CURRENT_LIMIT, FADE, HEAT, I_HEAT, N_FUNCTIONS, OMEGA_SPOT, Point,
    READING_RIPPLE, RIPPLES, SIGN_I, SPEED_LIMIT, STEP, Shapes, THETA,
};

use super::super::candidate::Candidate;
use super::state::{Column, Harmonic, OnGrid, Shape, best_on_grid, select};
use super::{Context, Evidence};

/// The functions a measured channel is offered in (`measurement:I`, `measurement:omega`): a
/// sensor that reads the input besides its own channel (a leakage path on the supply side of a
/// current sensor reads I + U/R_p), one that reads its own channel nonlinearly, one that
/// drifts, one that reads the speed with an offset. The speed's own linear gain is the
/// library's `speed_gain`, not offered on ω, nor is the current's offset, the library's
/// `current_offset`, offered on I. Where the input is held constant, U is the constant on ω:
/// a speed sensor's zero is the simpler reading of it, and U is not offered there.
///
/// Not the other channel (crosstalk), although it was at first: what a channel reads of the
/// other is, to first order, what a lag of it reads. A filtered ω is ω − τ·dω/dt, and dω/dt
/// follows I; offered, `measured ω += −0.115·I` took a resonant speed sensor's place
/// (resonant_sensor-510014: 3.9 nats over `sensor_lag`, whose fit is where the ringing is
/// looked for, so the ringing went unreported). Crosstalk is left to laws written by hand.
/// With five columns on ω the first needs ½·ln N + ln 5 + 2 = 7.1 nats at N = 1002: as the
/// balances' selection reasons, about 5·P(χ²₁ > 14.2) ≈ 0.1% per channel on a null record (on
/// I, with the current limit's six, ln 10: 7.8 nats). The speed's ripple adds two columns and
/// one pair per harmonic sampled: at 24 V (k = 1 only) ln 8, 0.47 nats more on ω; on a slow
/// record sampling all seven, ln 26, 1.65 nats more. The current's reading is offered the
/// angle's own ripple the same way, sin(k·θ) and cos(k·θ) alone: a Hall cell beside the rotor
/// that reads the magnet's field (or a shunt's pickup of a commutator) adds to I what the angle
/// decides, not the current. Before it was offered, magnet_pickup-825001 to -825004 (`measured
/// I += sin(θ + φ)` at 2 V) were named laws of the torque or voltage balance in the angle: the
/// right order, the wrong place. Its moves (each of the pair alone, and the pair) raise the
/// price of I's first column by the logarithm of how many more are tried: about half a nat
/// on the six of session 20's 118 whose score it moved, and no selection or kind there.
///
/// The speed's reading is offered the angle, θ = ∫ω: a speed read through a coupling
/// capacitor (a first-order high-pass of time constant τ) reads ω less its own low-pass, about
/// ω − θ/τ while t ≪ τ. It drifts with the angle turned, not with time, and the two part
/// wherever the speed is not steady (the start, a reversal). Without it, such a reading was
/// named a drift in time in the voltage balance. One column more on ω raises its first's price
/// by ln(9/8), 0.12 nats.
///
/// The current's reading is offered the heat the winding has drawn, E = ∫R·I² dt of the
/// predicted current (as the law's own state is), alone and times I: a shunt or a Hall cell in
/// the winding's circuit warms with the same I², and a reading whose zero drifts with its
/// temperature reads heat, one whose gain drifts reads I·heat. Before, a gain drifting so
/// (sensor_gain_heat-920003 to -920015, session 31's fifteenth set) was named a law in I and a
/// fade, or `unknown`. Two columns more on I raise its first's price by ln(10/8), 0.22 nats.
///
/// The heat is offered on ω too (not its product): a tachometer or an encoder's electronics
/// on the motor's end shield warm with the winding, and a zero that drifts with its
/// temperature reads the heat drawn (tacho_heat_offset-930003 to -930015, session 32's
/// sixteenth set, were named a state of the voltage balance or a drift in time). The current's
/// sign (`dictionary::SIGN_I`, smoothed over the law's I_s) is offered on I: a sensor's dead
/// band. One column more on each raises its first's price by ln(9/8) and ln(11/10), 0.12 and
/// 0.10 nats.
const MEASURED: [usize; 12] = [0, 1, 2, 5, 7, 9, 12, CONSTANT, THETA, HEAT, I_HEAT, SIGN_I];
/// The input, offered where it varies.
const INPUT: usize = 9;
/// Those of them that read the speed (`omega`, `omega*|omega|`, `omega^3`, `theta`), and the
/// current (`I`, `I*|I|`, `I*heat`, `sign(I)`): offered only on that channel's own reading.
const READS_SPEED: [usize; 4] = [0, 1, 2, THETA];
const READS_CURRENT: [usize; 4] = [5, 7, I_HEAT, SIGN_I];
/// The speed itself read on the speed's channel: a gain, the library's `speed_gain`.
const SPEED: usize = 0;

/// The speed limits ω_lim tried in what is read of ω, the gap below the predicted peak speed
/// halved from half the peak seven times (50% down to 0.8% below it), fixed before any record
/// was scored with them. A clip acts where the speed is above it; on a spin-up the speed nears
/// its top as exp(−t/τ_m), so the time it spends above a level grows with the logarithm of
/// that level's gap to the top, and halving the gap spaces the columns evenly in that time.
/// The last, 0.8% below the peak, is reached after ln 128 ≈ 4.9 mechanical time constants,
/// half of a record of ten: a clip nearer the top acts on the record's last part alone, as
/// that column does. The best of them is offered alone, one move paying ln 7
/// (`column::best_on_grid`), as a fade's τ is.
const SPEED_LIMIT_GAPS: [f64; 7] = [0.5, 0.25, 0.125, 0.0625, 0.03125, 0.015625, 0.0078125];

/// The state fingerprints of the measured channels: the residual of a channel regressed on
/// functions of the predicted state and the input in that channel alone (a measurement adds
/// to what is read, not to a balance: the column is the function itself, no solve needed),
/// selected as a balance's are; the law's measurement balances hold them, so a fingerprint
/// here names a law as a balance's does (`named`). The current is also offered beyond each of
/// `current_limits` (`sign(I)*max(|I|-I_lim,0)`): a reading clipped at its sensor's or its
/// converter's range is I less that, which in the voltage balance would be a drive's limit
/// acting on the motor — the two told apart by ω, which the clip leaves alone. The speed is
/// also offered times the angle's ripple at each of `harmonics` (θ the predicted speed's
/// integral from the record's start, as the law's own state is), its sine and cosine one move
/// as a balance's ripples are; and a spot of the angle on ω (`spot`), the record turning
/// `per_sample` radians between samples at its speed scale. Each channel is also offered a
/// fade at the best of `fades` (a zero settling after switch-on, exp(−t/τ), paying ln G over
/// them) and a change at an instant (`reading_step`).
pub(super) fn fingerprints(
    fit: &Candidate,
    ctx: &Context,
    current_limits: &[f64],
    harmonics: &[Harmonic],
    fades: &[f64],
    per_sample: f64,
    shift: f64,
) -> Vec<Evidence> {
    let model = fit.posterior.forward(0).model();
    // The functions offered read no shape but the current limit's and the harmonic; the
    // dictionary's defaults stand for the others. (`harmonics` is the model's own law's k
    // alone where that law holds a ripple already: a law has one k.)
    let Some(Term::Law(law)) = Term::named("law") else {
        return Vec::new();
    };
    let index = |name: &str| ctx.channels.iter().position(|c| c == name);
    let (current, speed) = (index("I"), index("omega"));
    // What the model's own law reads already. Its columns are in the model's Jacobian, but
    // evaluated here on the predicted reading (which the law itself has amended: a clipped
    // current's hinge is near zero) they would not be projected out.
    let held: Vec<usize> = model
        .terms()
        .iter()
        .find_map(|t| match &t.term {
            Term::Law(l) => Some(l.active.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let input_varies = !model.input.breakpoints().is_empty();
    // The angle, once for both channels (ω's ripple reads it), and the heat drawn (I's).
    let theta = ctx.angle().unwrap_or_else(|| vec![0.0; ctx.n]);
    let resistance = fit
        .theta
        .get("R")
        .copied()
        .unwrap_or(model.nominal.resistance);
    let heat = current.map_or_else(
        || vec![0.0; ctx.n],
        |k| {
            ctx.fine
                .integral_of_at(k, |i| resistance * i * i, &ctx.times)
        },
    );
    let mut out = Vec::new();
    for (c, channel) in ctx.channels.iter().enumerate() {
        if Some(c) != current && Some(c) != speed {
            continue;
        }
        let balance = format!("measurement:{channel}");
        let Some(b) = dictionary::BALANCES.iter().position(|n| *n == balance) else {
            continue;
        };
        let fresh = |f: usize| !held.contains(&(b * N_FUNCTIONS + f));
        let functions: Vec<usize> = MEASURED
            .into_iter()
            .filter(|&f| !(Some(c) == speed && f == SPEED))
            .filter(|f| Some(c) == speed || !READS_SPEED.contains(f))
            .filter(|f| Some(c) == current || !READS_CURRENT.contains(f))
            .filter(|&f| fresh(f))
            .filter(|&f| f != CONSTANT || Some(c) == speed)
            // The heat is the predicted current's: none where the current is not read.
            .filter(|&f| f != HEAT || current.is_some())
            .filter(|&f| f != INPUT || Some(c) != speed || input_varies)
            .collect();
        let mut columns: Vec<Column> = functions
            .iter()
            .map(|&f| Column::new(f, Shape::Own))
            .collect();
        if Some(c) == current && fresh(CURRENT_LIMIT) {
            columns.extend(
                current_limits
                    .iter()
                    .map(|&i| Column::new(CURRENT_LIMIT, Shape::CurrentLimit(i))),
            );
        }
        // A reading clipped at the top of its range (ω's; the current's is the hinge above).
        if Some(c) == speed && fresh(SPEED_LIMIT) {
            let limits = ctx
                .fine
                .shares_of_peak(c, &SPEED_LIMIT_GAPS.map(|g| 1.0 - g));
            columns.extend(
                OnGrid::at(&limits)
                    .into_iter()
                    .map(|l| Column::new(SPEED_LIMIT, Shape::SpeedLimit(l))),
            );
        }
        // A zero that settles (a sensor warming up, its offset fading).
        if fresh(FADE) {
            columns.extend(
                OnGrid::at(fades)
                    .into_iter()
                    .map(|f| Column::new(FADE, Shape::Fade(f))),
            );
        }
        // The angle's ripple each reading is offered: ω's scaled by the speed, I's alone.
        let ripple = if Some(c) == speed {
            READING_RIPPLE
        } else {
            RIPPLES[0]
        };
        if ripple.iter().all(|&f| fresh(f)) {
            for &h in harmonics {
                columns.extend(ripple.map(|f| Column::new(f, Shape::Harmonic(h))));
            }
        }
        let shapes: Vec<Shapes> = columns
            .iter()
            .map(|column| Shapes {
                current_limit: column.current_limit().unwrap_or(law.shapes.current_limit),
                harmonic: column.harmonic().unwrap_or(law.shapes.harmonic),
                fade: column.fade().unwrap_or(law.shapes.fade),
                speed_limit: column.speed_limit().unwrap_or(law.shapes.speed_limit),
                ..law.shapes
            })
            .collect();
        let mut b = DMatrix::zeros(ctx.m(), columns.len());
        for i in 0..ctx.n {
            let t = ctx.times[i];
            let x = Point {
                t,
                current: current.map_or(0.0, |k| ctx.fine.at(k, t)),
                speed: speed.map_or(0.0, |k| ctx.fine.at(k, t)),
                voltage: model.input.value_at(t).unwrap_or(model.nominal.voltage),
                charge: 0.0,
                heat: heat[i],
                theta: theta[i],
            };
            for (j, column) in columns.iter().enumerate() {
                b[(c * ctx.n + i, j)] =
                    dictionary::value(column.function, &x, &shapes[j]) / ctx.sigma[c];
            }
        }
        let b_tilde = ctx.projector.residualize(&b);
        // One fade, the best τ of the grid for this channel, and one speed limit.
        let fade = best_on_grid(&columns, &b_tilde, &ctx.y, Column::fade, |_| true);
        let limit = best_on_grid(&columns, &b_tilde, &ctx.y, Column::speed_limit, |_| true);
        out.extend(select(
            ctx,
            &columns,
            &b_tilde,
            &balance,
            shift,
            |c: &Column| {
                (c.fade().is_none() || c.fade() == fade)
                    && (c.speed_limit().is_none() || c.speed_limit() == limit)
            },
        ));
    }
    // And a change at an instant on each channel read, a move of its own (its search paid by
    // its price), where the model's law holds none (a law has one t_s).
    if !held.iter().any(|k| k % N_FUNCTIONS == STEP) {
        for (c, channel) in ctx.channels.iter().enumerate() {
            if Some(c) == current || Some(c) == speed {
                let balance = format!("measurement:{channel}");
                out.extend(super::reading_step::fingerprints(ctx, c, &balance, shift));
            }
        }
    }
    // And a spot of the angle on ω, a move of its own (its search paid by its price), where
    // the model's law holds none (a law has one θ₀ and w).
    if let Some(c) = speed
        && !held.iter().any(|k| k % N_FUNCTIONS == OMEGA_SPOT)
    {
        out.extend(super::spot::fingerprints(
            ctx,
            c,
            &law.shapes,
            &theta,
            per_sample,
            shift,
        ));
    }
    out
}
