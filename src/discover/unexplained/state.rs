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
//! reason. With N = 1002 and the 21 columns of the voltage balance (20 of the torque balance)
//! the first column needs a gain of 3.45 + 3.04 + 2 = 8.49 nats: 21·P(χ²₁ > 17.0) ≈ 0.1% per
//! balance on a null record. The
//! fingerprint's score is
//! the gain less the first two prices of each column taken (as the other alternatives' scores
//! are their gain less ½·ln N per degree and the logarithm of their grid); the verdict's
//! threshold then applies to it as to them.
//!
//! The Stribeck function's ω_s is a shape, not a coefficient: it is searched over a grid of
//! shares of the record's speed scale, each value one more column tried. The periodic
//! functions of time (frequency f a setting) are left to the oscillation alternative, which
//! searches the frequency.

use nalgebra::DMatrix;

use crate::error::Error;
use crate::forward::ForwardModel;
use crate::motor::dictionary::{self, FUNCTIONS, N_FUNCTIONS};
use crate::motor::terms::Law;
use crate::motor::{ActiveTerm, MotorModel, Term};

use super::super::candidate::Candidate;
use super::super::settings::EVIDENCE_THRESHOLD;
use super::fingerprint::LawFunction;
use super::regression::{coefficient_sds, explain, gain};
use super::{Context, Evidence, Fingerprint};

/// The Stribeck speeds tried, as shares of the speed scale (no-load speed U/c_m): a hump a
/// few hundredths of the way to full speed, as dry friction's is.
const STRIBECK_SHARES: [f64; 6] = [0.004, 0.008, 0.016, 0.032, 0.064, 0.128];

/// At most this many functions per balance: a law longer than that is no longer a fingerprint.
const MAX_FUNCTIONS: usize = 4;

/// The dictionary's index of the Stribeck function.
const STRIBECK: usize = 4;

/// A column of the regression: a function (dictionary index) and the Stribeck speed it has.
struct Column {
    function: usize,
    omega_s: Option<f64>,
}

/// The whitened sensitivities of the law's coefficients `keys` (parameter indices) at `fit`'s
/// MAP, stacked as `ctx` stacks its channels.
fn law_columns(
    fit: &Candidate,
    ctx: &Context,
    law: Law,
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
    let mut values = vec![0.0; 2 * N_FUNCTIONS];
    let mut active = keys.to_vec();
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
        }
    }
    terms.push(ActiveTerm {
        term: Term::Law(law.with_active(active)),
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
    let plain: Vec<usize> = (0..N_FUNCTIONS)
        .filter(|&f| f != STRIBECK && !dictionary::PERIODIC.contains(&f))
        .collect();
    let mut columns: Vec<Column> = Vec::new();
    let mut blocks: Vec<DMatrix<f64>> = Vec::new();
    // Torque columns then voltage columns, per block: block j holds the balance-major keys.
    let keys: Vec<usize> = (0..2)
        .flat_map(|b| plain.iter().map(move |&f| b * N_FUNCTIONS + f))
        .collect();
    blocks.push(law_columns(fit, ctx, law.clone(), &keys)?);
    columns.extend(plain.iter().map(|&f| Column {
        function: f,
        omega_s: None,
    }));
    let speed = model.magnitudes(ctx.times[ctx.n - 1]).speed;
    for share in STRIBECK_SHARES {
        let mut shaped = law.clone();
        shaped.shapes.omega_s = share * speed;
        let keys = [STRIBECK, N_FUNCTIONS + STRIBECK];
        blocks.push(law_columns(fit, ctx, shaped, &keys)?);
        columns.push(Column {
            function: STRIBECK,
            omega_s: Some(share * speed),
        });
    }
    let mut out = Vec::new();
    for balance in 0..2 {
        // The balance's column of each regressor, in `columns`' order.
        let mut b = DMatrix::zeros(ctx.m(), columns.len());
        for j in 0..plain.len() {
            b.set_column(j, &blocks[0].column(balance * plain.len() + j));
        }
        for s in 0..STRIBECK_SHARES.len() {
            b.set_column(plain.len() + s, &blocks[1 + s].column(balance));
        }
        let b_tilde = ctx.projector.residualize(&b);
        if let Some(e) = select(ctx, &columns, &b_tilde, balance, shift) {
            out.push(e);
        }
    }
    Ok(out)
}

/// Forward selection of one balance's columns (see the module's doc), and the fingerprint it
/// makes.
fn select(
    ctx: &Context,
    columns: &[Column],
    b_tilde: &DMatrix<f64>,
    balance: usize,
    shift: f64,
) -> Option<Evidence> {
    let mut chosen: Vec<usize> = Vec::new();
    let (mut current, mut score) = (0.0, 0.0);
    while chosen.len() < MAX_FUNCTIONS {
        // One Stribeck speed at most: the law has one ω_s.
        let stribeck_taken = chosen.iter().any(|&j| columns[j].omega_s.is_some());
        let open: Vec<usize> = (0..columns.len())
            .filter(|j| !chosen.contains(j))
            .filter(|&j| !(stribeck_taken && columns[j].omega_s.is_some()))
            .filter(|&j| dictionary::offered_in(columns[j].function, balance))
            .collect();
        if open.is_empty() {
            break;
        }
        let price = 0.5 * ctx.ln_n + (open.len() as f64).ln();
        let best = open
            .iter()
            .map(|&j| {
                let mut set = chosen.clone();
                set.push(j);
                (j, gain(&ctx.y, &b_tilde.select_columns(&set)))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        if best.1 - current <= price + EVIDENCE_THRESHOLD {
            break;
        }
        score += best.1 - current - price;
        current = best.1;
        chosen.push(best.0);
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
    let balance = dictionary::BALANCES[balance].to_string();
    let drift = |f: &LawFunction| match f.name.as_str() {
        "t" => Some("time"),
        "charge" | "U*charge" => Some("charge"),
        "heat" => Some("heat"),
        _ => None,
    };
    let fingerprint = if functions.iter().all(|f| drift(f).is_some()) {
        Fingerprint::Drift {
            variable: drift(&functions[0]).expect("checked").to_string(),
            balance,
            functions,
            score: score - shift,
        }
    } else {
        Fingerprint::State {
            balance,
            functions,
            omega_s: chosen.iter().find_map(|&j| columns[j].omega_s),
            score: score - shift,
        }
    };
    Some(Evidence {
        fingerprint,
        residual: ctx.y.as_slice().to_vec(),
        explained: e.fitted.as_slice().to_vec(),
    })
}
