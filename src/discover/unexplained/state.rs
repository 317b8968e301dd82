//! The state fingerprint: which functions of the state and input the residual follows, and in
//! which balance.
//!
//! At a model's MAP the law term is added at zero coefficients, with every function of the
//! dictionary (`motor::dictionary`) active in the torque and in the voltage balance; one
//! sensitivity solve gives each coefficient's whitened output sensitivities, the columns an
//! alternative "the balance misses c·f" adds. They are projected off the model's own Jacobian
//! and regressed on, exactly as the verdict's other alternatives are (`regression`), so the
//! coefficients are the law's own, in its units, to first order.
//!
//! **Sparse selection by evidence**, per balance: forward selection over the balance's columns,
//! the column that raises the linearised gain most added while it raises it by more than
//! ½·ln N + ln(columns tried at that step) + [`EVIDENCE_THRESHOLD`]. The reasoning, fixed before
//! any case was run: ½·ln N is the BIC price of one coefficient, as every candidate of the
//! ranking pays it; ln(columns tried) pays for having picked the best of that many (under the
//! model each gain is ½χ²₁, and the largest of m exceeds a level about m times as often as one
//! does, i.e. costs ln m nats); the threshold is the ranking's margin, for the ranking's
//! reason. With N = 1002 and the 21 columns of each balance (the torque balance's twenty-first,
//! the angle θ, added after this was fixed, moved its bar by ln(21/20) = 0.05 nats)
//! the first column needs a gain of 3.45 + 3.04 + 2 = 8.49 nats: 21·P(χ²₁ > 17.0) ≈ 0.1% per
//! balance on a null record (the current limit's six columns, in the voltage balance only,
//! raise its bar by ln(27/21) = 0.25 nats). The
//! fingerprint's score is
//! the gain less the first two prices of each column taken (as the other alternatives' scores
//! are their gain less ½·ln N per degree and the logarithm of their grid); the verdict's
//! threshold then applies to it as to them.
//!
//! The Stribeck function's ω_s is a shape, not a coefficient: it is searched over a grid of
//! shares of the record's speed scale, each value one more column tried. So is the harmonic k
//! of sin(k·θ) and cos(k·θ) (an eccentric load's once per revolution, a cogging torque's slot
//! count): each k of [`HARMONICS`] two more columns, one k at most in a law. A ripple in the
//! angle has a phase, so the pair sin(k·θ), cos(k·θ) is also offered as one move, paying
//! ½·ln N for each of its two coefficients: taken one at a time, neither half of a ripple whose
//! phase is between them may clear the bar that the two clear together, and the first step
//! would go to whatever single function mimics the ripple's start. A ripple between the
//! grid's whole k (a bearing's ball-pass order) is offered at the order the residual peaks at
//! (`order`), its columns paying that search's ln G once. The periodic functions of
//! time (frequency f a setting) are left to the oscillation alternative, which searches the
//! frequency. The current limit I_lim of `sign(I)*max(|I|-I_lim,0)` is a shape too, searched
//! over shares of the model's largest predicted current (a limit above it leaves no trace).

use nalgebra::DMatrix;

use crate::error::Error;
use crate::forward::ForwardModel;
use crate::motor::dictionary::{
    self, CURRENT_LIMIT, FADE, FUNCTIONS, N_FUNCTIONS, ODE_BALANCES, RIPPLES, STRIBECK, Shapes,
    ripple_of,
};
use crate::motor::terms::Law;
use crate::motor::{ActiveTerm, MotorModel, Term};

use super::super::candidate::Candidate;
use super::super::settings::EVIDENCE_THRESHOLD;
pub(super) use super::column::{Column, Harmonic, OnGrid, Shape, best_on_grid};
use super::fingerprint::LawFunction;
use super::regression::{coefficient_sds, explain, gain};
use super::{Context, Evidence, Fingerprint};

/// The Stribeck speeds tried, as shares of the speed scale (no-load speed U/c_m): a hump a
/// few hundredths of the way to full speed, as dry friction's is.
const STRIBECK_SHARES: [f64; 6] = [0.004, 0.008, 0.016, 0.032, 0.064, 0.128];

/// The current limits tried, as shares of the model's largest predicted |I|: a limit cuts the
/// peak, by a little or by half.
const CURRENT_LIMIT_SHARES: [f64; 6] = [0.5, 0.6, 0.7, 0.8, 0.9, 0.95];

/// The fade's time constants tried (`dictionary::FADE`): the record's duration halved, and
/// halved again while at least two sample intervals (a faster fade is over before the second
/// sample). Halving keeps exp(−t/τ)'s column near its neighbours' (its correlation with the
/// column at 2τ is 0.94 over a long record), as the Stribeck grid's doubling does. The best τ
/// of a balance is offered as one move paying ln G (`column::best_on_grid`), as a spot or a step
/// pays its grid: offered as seven columns, each paying only the step's look-elsewhere, the fade
/// had seven tries at the noise where a function of the state has one, and on a spin-up, whose
/// current falls about as exp(−t/τ_m), it took four laws of the state by 2 nats or less
/// (bearing_defect-770006, dead_time-900009, flux_saturation-680011, load_friction-510021:
/// papers/beyond-library.md, session 31).
pub(super) fn fade_grid(duration: f64, interval: f64) -> Vec<f64> {
    (1..)
        .map(|j| duration / 2f64.powi(j))
        .take_while(|&tau| tau >= 2.0 * interval)
        .collect()
}

/// At most this many functions per balance: a law longer than that is no longer a fingerprint.
const MAX_FUNCTIONS: usize = 4;

/// The harmonics k of sin(k·θ), cos(k·θ) tried, those the record samples
/// ([`sampled_ripple`]): once per revolution (an eccentric or unbalanced load) up to the slot
/// counts of small motors' cogging. Above a few kilohertz of
/// k·ω/2π a ripple's torque is averaged by the inertia before the speed shows it, so larger k
/// would be columns for chance alone.
const HARMONICS: [f64; 7] = [1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0];

/// Whether the record samples a ripple of `k` periods per revolution at least twice a period
/// at its speed scale (the no-load speed at its largest input): k·ω·Δt < π. A faster ripple is
/// one the samples alias and the inertia averages; its evidence would come from the slow
/// passages alone, where a hump or a load looks the same, and its law's every solve resolves
/// the ripple's periods (k = 8 on the paper's motor at 2400 rad/s: some 1500 in half a
/// second), a fit of minutes for a term the record cannot confirm.
fn sampled_ripple(k: f64, speed: f64, interval: f64) -> bool {
    k * speed * interval < std::f64::consts::PI
}

/// The half-width of the search through the ODE around an order the order search found, as a
/// share of the angle's Fourier spacing 1/R: the peak places k within a quarter of it.
const SEARCH_WIDTH: f64 = 0.25;

/// The grid's order nearest a searched `k` fitted with half-width `width`, where it lies within
/// one of the angle's Fourier spacings (`width / SEARCH_WIDTH`): the whole order the ripple
/// may be at, its peak pulled aside by the ripple's own push on the angle (see `fingerprints`).
pub fn whole_order(k: f64, width: f64) -> Option<f64> {
    let cell = width / SEARCH_WIDTH;
    HARMONICS
        .into_iter()
        .min_by(|a, b| (a - k).abs().total_cmp(&(b - k).abs()))
        .filter(|w| (w - k).abs() <= cell)
}

/// The whitened sensitivities of the law's coefficients `keys` (parameter indices) at `fit`'s
/// MAP, stacked as `ctx` stacks its channels.
fn law_columns(
    fit: &Candidate,
    ctx: &Context,
    law: &Law,
    shape: Shape,
    keys: &[usize],
) -> Result<DMatrix<f64>, Error> {
    let forward = fit.posterior.forward(0);
    let model = forward.model();
    let mut terms: Vec<ActiveTerm> = model
        .terms()
        .iter()
        .filter(|t| !matches!(t.term, Term::Law(_)))
        .cloned()
        .collect();
    let mut values = vec![0.0; dictionary::BALANCES.len() * N_FUNCTIONS];
    let mut active = keys.to_vec();
    let mut shapes: Shapes = law.shapes;
    // A law the model already holds keeps its functions and values; its columns are the
    // model's own, which the projection removes.
    if let Some(t) = model
        .terms()
        .iter()
        .find(|t| matches!(t.term, Term::Law(_)))
    {
        values.copy_from_slice(&t.values);
        if let Term::Law(own) = &t.term {
            active.extend(&own.active);
            shapes = own.shapes;
        }
    }
    match shape {
        Shape::Own => {}
        Shape::StribeckSpeed(w) => shapes.omega_s = w,
        Shape::Harmonic(h) => shapes.harmonic = h.k,
        Shape::CurrentLimit(i) => shapes.current_limit = i,
        Shape::Spot(s) => (shapes.spot_angle, shapes.spot_width) = (s.spot.theta_0, s.spot.w),
        Shape::Fade(f) => shapes.fade = f.value,
        Shape::SpeedLimit(l) => shapes.speed_limit = l.value,
        Shape::Step(s) => shapes.instant = s.t_s,
    }
    let mut shaped = law.clone().with_active(active);
    shaped.shapes = shapes;
    terms.push(ActiveTerm {
        term: Term::Law(shaped),
        values,
    });
    let with_law = MotorModel::with_base(
        model.base,
        model.nominal.clone(),
        model.input.clone(),
        terms,
    )
    .map_err(Error::invalid)?;
    let mut names = forward.calibrated_names();
    // Each key's column: the model's own where it calibrates it already, else a new one.
    let mut slots = Vec::new();
    for &k in keys {
        let name = format!("law.{}", dictionary::key(k));
        match names.iter().position(|n| *n == name) {
            Some(i) => slots.push(i),
            None => {
                slots.push(names.len());
                names.push(name);
            }
        }
    }
    let lawful = ForwardModel::new(
        with_law,
        forward.times().to_vec(),
        &names,
        *forward.solver(),
    )
    .map_err(Error::invalid)?;
    let mut theta = fit.posterior.theta_of(&fit.map.x);
    theta.resize(names.len(), 0.0);
    let mut outputs = vec![0.0; lawful.n_outputs()];
    let mut jacobian = DMatrix::zeros(lawful.n_outputs(), names.len());
    lawful
        .simulate_with_sensitivities(&theta, &mut outputs, &mut jacobian)
        .map_err(|e| Error::Numerical(format!("the state fingerprint: {e}")))?;
    ctx.whitened_columns(lawful.channels(), &jacobian, &slots)
}

/// The state and drift fingerprints of `fit` (one per balance that clears the selection), each
/// scored less `shift`. None on a drive base, whose law is not written.
pub(super) fn fingerprints(
    fit: &Candidate,
    ctx: &Context,
    shift: f64,
) -> Result<Vec<Evidence>, Error> {
    let model = fit.posterior.forward(0).model();
    if model.drive.is_some() || fit.posterior.n_records() != 1 {
        return Ok(Vec::new());
    }
    let Some(Term::Law(law)) = Term::named("law") else {
        return Ok(Vec::new());
    };
    // The shapes the model's own law fixes already: its columns are the model's, so only its
    // own ω_s and k are tried where it holds those functions.
    let own = model.terms().iter().find_map(|t| match &t.term {
        Term::Law(l) => Some(l.clone()),
        _ => None,
    });
    let holds = |f: usize| {
        own.as_ref()
            .is_some_and(|l| l.active.iter().any(|k| k % N_FUNCTIONS == f))
    };
    let speed = model.magnitudes(ctx.times[ctx.n - 1]).speed;
    let stribeck_speeds: Vec<f64> = match &own {
        Some(l) if holds(STRIBECK) => vec![l.shapes.omega_s],
        _ => STRIBECK_SHARES.iter().map(|s| s * speed).collect(),
    };
    // The model's own law's k was paid for where it was found.
    let harmonics: Vec<Harmonic> = match &own {
        Some(l) if (0..N_FUNCTIONS).any(|f| dictionary::reads_harmonic(f) && holds(f)) => {
            vec![Harmonic::on_grid(l.shapes.harmonic)]
        }
        _ => {
            let interval = ctx.interval();
            let mut grid: Vec<Harmonic> = HARMONICS
                .into_iter()
                .filter(|&k| sampled_ripple(k, speed, interval))
                .map(Harmonic::on_grid)
                .collect();
            // The order between the grid's the residual peaks at, where no grid point holds
            // it: more than a quarter of the angle's Fourier spacing (1/R) from every one of
            // them. A whole order δk away keeps sinc²(π·δk·R) of the ripple's power, 81% at a
            // quarter of 1/R, where the law's shape search (`width`) takes over; within a whole
            // spacing it was lost: on bearing_defect-770014 (k 2.967, R 6.2) the search's 2.899
            // was dropped for k = 3, whose column the regression passed over for I·sin θ, and
            // σ_ω stayed 12% above the noise (papers/beyond-library.md, session 10). Within a
            // spacing of a whole order, the law is also fitted at that order (`whole_order`):
            // a strong cogging's peak lies off its slot count as its own ripple moves the
            // angle, and the fits decide. Up to what the record samples and the grid's top
            // (above it the inertia averages).
            let top = HARMONICS[HARMONICS.len() - 1];
            let k_max = (std::f64::consts::PI / (speed * interval)).min(top);
            if let Some(o) = super::order::search(ctx, k_max)
                && grid
                    .iter()
                    .all(|h| (o.k - h.k).abs() > SEARCH_WIDTH * o.cell)
            {
                grid.push(Harmonic {
                    k: o.k,
                    price: o.price,
                    width: SEARCH_WIDTH * o.cell,
                });
            }
            grid
        }
    };
    let current_limits: Vec<f64> = match &own {
        Some(l) if holds(CURRENT_LIMIT) => vec![l.shapes.current_limit],
        _ => ctx
            .channels
            .iter()
            .position(|c| c == "I")
            .map(|c| ctx.fine.shares_of_peak(c, &CURRENT_LIMIT_SHARES))
            .unwrap_or_default(),
    };
    let fades: Vec<f64> = match &own {
        Some(l) if holds(FADE) => vec![l.shapes.fade],
        _ => fade_grid(ctx.times[ctx.n - 1], ctx.interval()),
    };
    let plain: Vec<usize> = (0..N_FUNCTIONS)
        .filter(|&f| f != STRIBECK && f != CURRENT_LIMIT && f != FADE && ripple_of(f).is_none())
        .filter(|&f| !dictionary::reads_frequency(f))
        // Only what a balance is offered: the others' columns would be solved for nothing.
        .filter(|&f| (0..ODE_BALANCES).any(|b| dictionary::offered_in(f, b)))
        .collect();
    let mut columns: Vec<Column> = Vec::new();
    // Per block, its functions; its columns are balance-major (torque's, then voltage's).
    let mut blocks: Vec<(Vec<usize>, DMatrix<f64>)> = Vec::new();
    let mut add = |functions: Vec<usize>, shape: Shape| -> Result<(), Error> {
        let keys: Vec<usize> = (0..ODE_BALANCES)
            .flat_map(|b| functions.iter().map(move |&f| b * N_FUNCTIONS + f))
            .collect();
        let b = law_columns(fit, ctx, &law, shape, &keys)?;
        columns.extend(functions.iter().map(|&f| Column::new(f, shape)));
        blocks.push((functions, b));
        Ok(())
    };
    add(plain, Shape::Own)?;
    for w in stribeck_speeds {
        add(vec![STRIBECK], Shape::StribeckSpeed(w))?;
    }
    for &h in &harmonics {
        add(RIPPLES.concat(), Shape::Harmonic(h))?;
    }
    for &i in &current_limits {
        add(vec![CURRENT_LIMIT], Shape::CurrentLimit(i))?;
    }
    for fade in OnGrid::at(&fades) {
        add(vec![FADE], Shape::Fade(fade))?;
    }
    let mut out = Vec::new();
    for balance in 0..ODE_BALANCES {
        // The balance's column of each regressor, in `columns`' order.
        let mut b = DMatrix::zeros(ctx.m(), columns.len());
        let mut j = 0;
        for (functions, block) in &blocks {
            for i in 0..functions.len() {
                b.set_column(j, &block.column(balance * functions.len() + i));
                j += 1;
            }
        }
        let b_tilde = ctx.projector.residualize(&b);
        let name = dictionary::BALANCES[balance];
        // A balance whose law holds one of the angle's ripples is not offered the other: the
        // two are near, and the second would hold the first's ripple twice.
        let own_ripple = own.as_ref().and_then(|l| {
            l.active
                .iter()
                .filter(|&&k| k / N_FUNCTIONS == balance)
                .find_map(|&k| ripple_of(k % N_FUNCTIONS))
        });
        let offered_here = |c: &Column| {
            let f = c.function;
            dictionary::offered_in(f, balance)
                && ripple_of(f).is_none_or(|r| own_ripple.is_none_or(|o| o == r))
        };
        // One fade, the best τ of the grid for this balance.
        let fade = best_on_grid(&columns, &b_tilde, &ctx.y, Column::fade, offered_here);
        let offered = |c: &Column| offered_here(c) && (c.fade().is_none() || c.fade() == fade);
        let first = select(ctx, &columns, &b_tilde, name, shift, offered);
        // A ripple in the angle on its own as well, where the selection took another
        // function first: on a record that spins up from rest the ripple's net early push is
        // what a Stribeck hump also gives, and to first order the two are near; the fits
        // through the ODE (`named::fit_named_terms`) decide between the laws.
        let took_angle = |e: &Evidence| match &e.fingerprint {
            Fingerprint::State { harmonic, .. } => harmonic.is_some(),
            _ => false,
        };
        let add_ripple = first.as_ref().is_some_and(|e| !took_angle(e));
        // And the ripple at the order searched between the grid's, where the selection took
        // another k: to first order a large ripple at the grid's nearest k (in the current's
        // share of the torque) led on bearing_defect-620001 (truth 5.36 periods per
        // revolution, I·cos(6θ) taken); the fits decide, as above.
        let searched = columns
            .iter()
            .find(|c| c.harmonic().is_some() && c.price() > 0.0)
            .and_then(|c| c.harmonic());
        let took_searched = |e: &Evidence| match &e.fingerprint {
            Fingerprint::State { harmonic, .. } => *harmonic == searched,
            _ => false,
        };
        let add_searched = searched.is_some() && first.as_ref().is_some_and(|e| !took_searched(e));
        out.extend(first);
        if add_ripple {
            let angle = |c: &Column| ripple_of(c.function).is_some() && offered(c);
            out.extend(select(ctx, &columns, &b_tilde, name, shift, angle));
        }
        if add_searched {
            let at = |c: &Column| c.harmonic() == searched && offered(c);
            out.extend(select(ctx, &columns, &b_tilde, name, shift, at));
        }
    }
    out.extend(super::reading::fingerprints(
        fit,
        ctx,
        &current_limits,
        &harmonics,
        &fades,
        speed * ctx.interval(),
        shift,
    ));
    Ok(out)
}

/// Forward selection of one balance's columns (see the module's doc), and the fingerprint it
/// makes.
pub(super) fn select(
    ctx: &Context,
    columns: &[Column],
    b_tilde: &DMatrix<f64>,
    balance: &str,
    shift: f64,
    offered: impl Fn(&Column) -> bool,
) -> Option<Evidence> {
    let mut chosen: Vec<usize> = Vec::new();
    let (mut current, mut score) = (0.0, 0.0);
    while chosen.len() < MAX_FUNCTIONS {
        // One Stribeck speed and one harmonic at most: the law has one ω_s and one k.
        let stribeck = chosen.iter().find_map(|&j| columns[j].omega_s());
        let harmonic = chosen.iter().find_map(|&j| columns[j].harmonic());
        let limit = chosen.iter().find_map(|&j| columns[j].current_limit());
        let fade = chosen.iter().find_map(|&j| columns[j].fade());
        // And one of the angle's two ripples (`dictionary::RIPPLES`).
        let ripple = chosen.iter().find_map(|&j| ripple_of(columns[j].function));
        let open: Vec<usize> = (0..columns.len())
            .filter(|j| !chosen.contains(j))
            .filter(|&j| stribeck.is_none() || columns[j].omega_s().is_none())
            .filter(|&j| limit.is_none() || columns[j].current_limit().is_none())
            .filter(|&j| fade.is_none() || columns[j].fade().is_none())
            .filter(|&j| {
                harmonic.is_none() || columns[j].harmonic().is_none_or(|k| Some(k) == harmonic)
            })
            .filter(|&j| {
                ripple.is_none() || ripple_of(columns[j].function).is_none_or(|r| Some(r) == ripple)
            })
            .filter(|&j| offered(&columns[j]))
            .collect();
        // The moves: each open column, and each harmonic's sin and cos together (of the
        // angle, the angle times the current, the speed times the angle in what is read of
        // ω): a ripple's phase is the record's.
        let mut moves: Vec<Vec<usize>> = open.iter().map(|&j| vec![j]).collect();
        for [sin, cos] in dictionary::HARMONIC_PAIRS {
            for &j in open.iter().filter(|&&j| columns[j].function == sin) {
                let k = columns[j].harmonic();
                let pair = open
                    .iter()
                    .find(|&&c| columns[c].function == cos && columns[c].harmonic() == k);
                if let Some(&c) = pair
                    && chosen.len() + 2 <= MAX_FUNCTIONS
                {
                    moves.push(vec![j, c]);
                }
            }
        }
        if moves.is_empty() {
            break;
        }
        let look_elsewhere = (moves.len() as f64).ln();
        let best = moves
            .iter()
            .map(|m| {
                let mut set = chosen.clone();
                set.extend(m);
                let g = gain(&ctx.y, &b_tilde.select_columns(&set));
                // A searched order is paid for once, by the move that first takes it; a fade's
                // τ, a step's instant or a spot by the move that takes it (one of each at most).
                let searched = m
                    .iter()
                    .filter(|&&j| harmonic.is_none() || columns[j].harmonic().is_none())
                    .map(|&j| columns[j].price())
                    .fold(0.0, f64::max);
                let price = 0.5 * ctx.ln_n * m.len() as f64 + look_elsewhere + searched;
                (m, g, g - current - price)
            })
            .max_by(|a, b| a.2.total_cmp(&b.2))?;
        if best.2 <= EVIDENCE_THRESHOLD {
            break;
        }
        score += best.2;
        current = best.1;
        chosen.extend(best.0);
    }
    if chosen.is_empty() {
        return None;
    }
    let b_set = b_tilde.select_columns(&chosen);
    let e = explain(&ctx.y, &b_set);
    let sds = coefficient_sds(&b_set);
    let functions: Vec<LawFunction> = chosen
        .iter()
        .enumerate()
        .map(|(i, &j)| LawFunction {
            name: FUNCTIONS[columns[j].function].to_string(),
            coefficient: e.coefficients[i],
            sd: sds[i],
        })
        .collect();
    let balance = balance.to_string();
    let drift = |f: &LawFunction| match f.name.as_str() {
        "t" | "exp(-t/tau)" | "step(t-t_s)" => Some("time"),
        "charge" | "U*charge" => Some("charge"),
        // A gain drifting with the heat (what is read of I, `reading`) as the heat itself.
        "heat" | "I*heat" | "omega*heat" | "sign(omega)*heat" => Some("heat"),
        _ => None,
    };
    let fade = chosen.iter().find_map(|&j| columns[j].fade());
    let fingerprint = if functions.iter().all(|f| drift(f).is_some()) {
        Fingerprint::Drift {
            variable: drift(&functions[0]).expect("checked").to_string(),
            balance,
            functions,
            fade,
            instant: chosen.iter().find_map(|&j| columns[j].instant()),
            shape_price: chosen
                .iter()
                .map(|&j| columns[j].price())
                .fold(0.0, f64::max),
            score: score - shift,
        }
    } else {
        Fingerprint::State {
            balance,
            functions,
            omega_s: chosen.iter().find_map(|&j| columns[j].omega_s()),
            harmonic: chosen.iter().find_map(|&j| columns[j].harmonic()),
            current_limit: chosen.iter().find_map(|&j| columns[j].current_limit()),
            speed_limit: chosen.iter().find_map(|&j| columns[j].speed_limit()),
            spot: chosen.iter().find_map(|&j| columns[j].spot()),
            fade,
            instant: chosen.iter().find_map(|&j| columns[j].instant()),
            step: None,
            harmonic_price: chosen
                .iter()
                .map(|&j| columns[j].price())
                .fold(0.0, f64::max),
            harmonic_width: chosen
                .iter()
                .map(|&j| columns[j].width())
                .fold(0.0, f64::max),
            score: score - shift,
        }
    };
    Some(Evidence {
        fingerprint,
        residual: ctx.y.as_slice().to_vec(),
        explained: e.fitted.as_slice().to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_ripples_the_samples_resolve_are_offered() {
        // The paper's motor at 24 V turns at some 2400 rad/s, sampled every millisecond: 2.4 rad
        // a sample, so once per revolution is resolved and twice is not.
        let offered: Vec<f64> = HARMONICS
            .into_iter()
            .filter(|&k| sampled_ripple(k, 2400.0, 1e-3))
            .collect();
        assert_eq!(offered, vec![1.0]);
        // A positioning stage at 10 rad/s resolves every slot count of the grid.
        assert!(HARMONICS.iter().all(|&k| sampled_ripple(k, 10.0, 1e-3)));
    }

    #[test]
    fn a_fade_is_tried_from_half_the_record_down_to_two_samples() {
        // 0.5 s at 1 kHz: 250, 125, 62.5, … down to 3.9 ms (1.95 ms would be under two samples).
        let g = fade_grid(0.5, 1e-3);
        assert_eq!(g.len(), 7);
        assert_eq!(g[0], 0.25);
        assert!((g[6] - 0.5 / 128.0).abs() < 1e-15);
        assert!(g.windows(2).all(|w| w[1] == w[0] / 2.0));
    }
}
