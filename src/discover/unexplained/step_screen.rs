//! A forward step's screen where fits are dear: before a candidate is fitted beside a model
//! that holds a dynamic term (every solve through a resonance's or a filter's states costs
//! seconds, and a step fits every candidate), or on a record of more than 5 000 samples (each
//! solve as dear: on EMPS's 24 841 samples the forward steps were most of a diagnosis), its gain is
//! estimated to first order, as the
//! verdict estimates an alternative's (`regression`): the whitened residual of the current
//! model regressed on the candidate's sensitivities at its absent value, the current model's
//! own sensitivities projected out. That is Rao's score test, the gain a full fit would find
//! when the term's effect is linear in its size near zero.
//!
//! **The rule**: a candidate is skipped when its linearised score (gain − ½·d·ln N) falls short
//! of the selection threshold (+2) by more than ½·ln N (3.45 nats at N = 1002): a skipped one
//! would have needed the nonlinearity to add more than a whole parameter's penalty beyond the
//! first-order estimate, where near the absent value the difference is of second order in the
//! term's size. (A first version skipped below −½·ln N, which a one-parameter term cannot
//! reach: it never skipped anything.) The nonlinear parameters a size does not
//! linearise (a switching time, a resonance's frequency) are held where the starts put them,
//! or at their defaults; a term with a switching time is never skipped, its gain hangs on
//! where it switches.

use nalgebra::DMatrix;

use crate::error::Error;
use crate::motor::Term;
use crate::parameter::ParamId;
use crate::study::Problem;

use super::super::candidate::{Candidate, Starts};
use super::super::settings::EVIDENCE_THRESHOLD;
use super::Context;
use super::regression::explain;

/// The current model's whitened residual and sensitivities, for screening the candidates of
/// one step.
pub struct StepScreen {
    ctx: Context,
}

impl StepScreen {
    /// The screen at `current`'s MAP (first record).
    pub fn of(problem: &Problem, current: &Candidate) -> Result<Self, Error> {
        Ok(Self {
            ctx: Context::of(problem, current, 0)?,
        })
    }

    /// Whether `name` is worth a full fit beside `current`.
    pub fn worth_fitting(&self, current: &Candidate, name: &str, starts: &Starts) -> bool {
        if Term::named(name).is_none_or(|t| t.record_time()) {
            return true;
        }
        match self.linear_score(current, name, starts) {
            Ok(score) => score > EVIDENCE_THRESHOLD - 0.5 * self.ctx.ln_n,
            // A screen that cannot be computed decides nothing.
            Err(_) => true,
        }
    }

    /// gain − ½·d·ln N of `name` added to `current`, to first order.
    fn linear_score(&self, current: &Candidate, name: &str, starts: &Starts) -> Result<f64, Error> {
        let ctx = &self.ctx;
        // `current.problem` holds the current terms, with the settings they were fitted with.
        let mut amended = current.problem.with_terms(&[name.to_string()])?;
        for active in &mut amended.model.terms {
            if active.term.name() == name
                && let Some(set) = starts.terms.iter().find(|t| t.name() == name)
            {
                active.term = set.clone();
            }
        }
        let posterior = amended.posterior(&crate::bayes::ModelSettings::bm1())?;
        let forward = posterior.forward(0).clone();
        // The current model's values; the new term's sizes at zero (absent), its other
        // parameters where the starts or the defaults put them.
        let term = Term::named(name).expect("a known term");
        let mut theta = Vec::new();
        let mut new_columns = Vec::new();
        for (i, c) in posterior.calibrated().iter().enumerate() {
            let value = match current.theta.get(&c.name) {
                Some(&v) => v,
                None => {
                    new_columns.push(i);
                    let key = ParamId::parse(&c.name);
                    let p = term
                        .params()
                        .iter()
                        .find(|p| p.key == key.key())
                        .expect("the term's parameter");
                    if p.default == 0.0 {
                        0.0
                    } else {
                        starts.values.get(&c.name).copied().unwrap_or(p.default)
                    }
                }
            };
            theta.push(value);
        }
        let mut outputs = vec![0.0; forward.n_outputs()];
        let mut jacobian = DMatrix::zeros(forward.n_outputs(), forward.n_calibrated());
        forward
            .simulate_with_sensitivities(&theta, &mut outputs, &mut jacobian)
            .map_err(|e| Error::Numerical(format!("the step screen: {e}")))?;
        let b = ctx.whitened_columns(forward.channels(), &jacobian, &new_columns)?;
        let e = explain(&ctx.y, &ctx.projector.residualize(&b));
        Ok(e.gain - 0.5 * new_columns.len() as f64 * ctx.ln_n)
    }
}
