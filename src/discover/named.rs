//! The dynamic term a fingerprint names, fitted from the fingerprint's estimate: a delay names
//! `input_delay` (τ), a lag names `sensor_lag` on its channel (τ), a resonance that rings after
//! the input steps names `compliant_coupling` (f_r and ζ; the load's share from several
//! starts); an oscillation that runs on regardless of the input (a forced one: a pulsing load,
//! a rectified supply's ripple, mains pickup on a sensor) names the `law` in sin and cos(2πft)
//! at its frequency, in either balance and in what is read of its channel, and where the input
//! changes level the supply's ripple, those times U; a state or drift fingerprint names the
//! `law` with its functions. The dynamic terms are also ranked with the library (started from
//! the same estimates, `unexplained::starts`); this is the second chance for what the selected
//! model still leaves.
//!
//! Each is tried beside the selected terms and alone (a library term selected for a delay
//! absorbs part of it, and beside the delay is then dead weight), scored as every candidate is
//! (log L̂ − ½·d·ln N), and taken when the better of the two beats the selected model by more
//! than [`EVIDENCE_THRESHOLD`]: the ranking's rule, for the ranking's reason.

use rayon::prelude::*;

use crate::error::Error;
use crate::motor::Term;
use crate::motor::dictionary::{
    self, BALANCES, FUNCTIONS, N_FUNCTIONS, ODE_BALANCES, PERIODIC, RIPPLES, SUPPLY_RIPPLE,
    ripple_of,
};
use crate::motor::terms::Law;
use crate::parameter::ParamId;
use crate::study::Problem;

use super::candidate::{Candidate, Starts, fit_candidate_started, fit_candidate_warmed};
use super::settings::EVIDENCE_THRESHOLD;
use super::shape_search::best_shape;
use super::unexplained::{Fingerprint, frequency_search_cost, whole_order};

/// The term a fingerprint names, with its settings and the parameter values it starts at.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedTerm {
    pub term: Term,
    pub start: Vec<(&'static str, f64)>,
    /// What its score pays for the grid its start was the best of (a frequency's ln G in
    /// place of its ½·ln N: `unexplained::frequency_search_cost`).
    pub search_penalty: f64,
    /// The half-width [Hz] of a search through the ODE for a periodic law's frequency around
    /// the one it starts at; none where the fingerprint's frequency is taken as found.
    pub frequency_search: Option<f64>,
    /// The half-width of a search through the ODE for the angle's harmonic k around the one
    /// it starts at, where the order search found it between the grid's (`unexplained::order`):
    /// its residual's peak places k within a quarter of the angle's Fourier spacing, and a
    /// quarter is a drift of a quarter period over the record.
    pub harmonic_search: Option<f64>,
}

/// The terms `fingerprint` names on `problem`'s base: one, or none; a forced oscillation, whose
/// channel does not say which balance it enters (a ripple of the supply shows in ω as a load's
/// shows in I), names a law in each.
pub fn named_terms(problem: &Problem, fingerprint: &Fingerprint) -> Vec<NamedTerm> {
    match fingerprint {
        Fingerprint::Oscillation {
            frequency_hz,
            ringing: false,
            sensor: false,
            frequencies,
            channel,
            ..
        } => (0..ODE_BALANCES)
            .map(|b| (b, PERIODIC))
            .chain(input_varies(problem).then_some((1, SUPPLY_RIPPLE)))
            .chain(reading_of(channel).map(|b| (b, PERIODIC)))
            .filter_map(|(b, functions)| {
                forced_law(problem, b, functions, *frequency_hz, *frequencies)
            })
            .map(|mut named| {
                named.frequency_search = supply_search(problem, &named);
                named
            })
            .collect(),
        Fingerprint::State { .. } => std::iter::once(fingerprint.clone())
            .chain(ripple_twin(fingerprint))
            .flat_map(|f| {
                let pair = phase_twin(&f);
                let order = whole_order_twin(pair.as_ref().unwrap_or(&f));
                std::iter::once(f).chain(pair).chain(order)
            })
            .filter_map(|f| named_term(problem, &f))
            .collect(),
        _ => named_term(problem, fingerprint).into_iter().collect(),
    }
}

/// `fingerprint` with its ripple of the angle read as the other of [`RIPPLES`] (sin(k·θ) as
/// I·sin(k·θ), or back), at the same harmonic, the swapped coefficients started at zero; none
/// where it holds no ripple or its balance is not offered the other. To first order the two
/// are near, and the first-order gains can rank them wrongly where the ripple is large: on the
/// slow cogging record 530007 the current's ripple led at first order (38 nats) and the
/// angle's did not clear its price, where through the ODE the angle's law scores 84 nats
/// against 46. So a ripple's law is fitted both ways, and the fits decide.
fn ripple_twin(fingerprint: &Fingerprint) -> Option<Fingerprint> {
    let mut twin = fingerprint.clone();
    let Fingerprint::State {
        balance, functions, ..
    } = &mut twin
    else {
        return None;
    };
    let b = BALANCES.iter().position(|n| n == balance)?;
    let mut swapped = false;
    for f in functions.iter_mut() {
        let i = FUNCTIONS.iter().position(|n| *n == f.name)?;
        let Some(r) = ripple_of(i) else { continue };
        let other = RIPPLES[1 - r][RIPPLES[r].iter().position(|&g| g == i)?];
        if !dictionary::offered_in(other, b) {
            return None;
        }
        f.name = FUNCTIONS[other].to_string();
        f.coefficient = 0.0;
        swapped = true;
    }
    swapped.then_some(twin)
}

/// `fingerprint` with the other half of its ripple's sine-and-cosine pair, started at zero,
/// where it holds one half at an order the order search found (`unexplained::order`). There
/// the first-order k is off by up to a quarter of the angle's Fourier spacing, so the phase the
/// linear regression splits between sine and cosine drifts over the record, and one half can
/// lead at first order where the refined k needs both: on bearing_defect-620001 (truth 5.356
/// periods per revolution) `cos(k*theta)` alone was selected at 5.34. The fits decide, the
/// pair paying ½·ln N more. (Without it that record's law still ends with both halves, at k
/// 5.341 against 5.348 with the pair: a small gain in k, for the fits it costs.)
fn phase_twin(fingerprint: &Fingerprint) -> Option<Fingerprint> {
    let mut twin = fingerprint.clone();
    let Fingerprint::State {
        functions,
        harmonic_width,
        ..
    } = &mut twin
    else {
        return None;
    };
    if *harmonic_width <= 0.0 {
        return None;
    }
    let holds = |f: usize| functions.iter().any(|g| g.name == FUNCTIONS[f]);
    let [held, missing] =
        dictionary::HARMONIC_PAIRS
            .into_iter()
            .find_map(|[s, c]| match (holds(s), holds(c)) {
                (true, false) => Some([s, c]),
                (false, true) => Some([c, s]),
                _ => None,
            })?;
    let at = functions.iter().position(|g| g.name == FUNCTIONS[held])?;
    functions.insert(
        at + 1,
        super::unexplained::LawFunction {
            name: FUNCTIONS[missing].to_string(),
            coefficient: 0.0,
            sd: 0.0,
        },
    );
    Some(twin)
}

/// `fingerprint` (given with both halves of the ripple's pair: its `phase_twin` where it has
/// one) at the grid's whole order nearest the k the order search found, where one lies within
/// the angle's Fourier spacing (`unexplained::whole_order`), the k neither searched nor paid
/// for. A strong ripple moves the angle it depends on, so its residual's peak can lie off a
/// whole order the truth is at: on
/// cogging-770016 (six slots) the first-order regression took sin(6.057·θ) at 49.97 nats over
/// the pair at k = 6 at 36.80, where through the ODE the law at 6 scores higher than the
/// searched one refined to 6.012 (`papers/beyond-library/session11/fixtures.sh`, its output
/// beside it). The fits decide, the searched k paying its grid.
fn whole_order_twin(fingerprint: &Fingerprint) -> Option<Fingerprint> {
    let mut twin = fingerprint.clone();
    if let Fingerprint::State {
        harmonic: Some(k),
        harmonic_price,
        harmonic_width,
        ..
    } = &mut twin
        && *harmonic_width > 0.0
    {
        *k = whole_order(*k, *harmonic_width)?;
        (*harmonic_price, *harmonic_width) = (0.0, 0.0);
        return Some(twin);
    }
    None
}

/// The balance of what is read of `channel` (a pickup on its sensor's cable: mains hum on a
/// current reading runs on whatever the motor does, as a supply's ripple does, and differs
/// from it only by what the ripple would drive through the motor into the other channel).
fn reading_of(channel: &str) -> Option<usize> {
    let balance = format!("measurement:{channel}");
    BALANCES.iter().position(|b| *b == balance)
}

/// Whether any of `problem`'s records is driven by an input that changes level: there a
/// supply's ripple (U·sin, U·cos(2πft)) is told from a periodic law by its amplitude following
/// the input; on a constant input the two are one law, scaled by U, and the plain one is
/// named alone (two fits of one law would differ by their rounding only).
fn input_varies(problem: &Problem) -> bool {
    problem.recordings.iter().any(|r| {
        problem
            .model_for(r)
            .is_ok_and(|m| !m.input.breakpoints().is_empty())
    })
}

/// The supply's ripple's frequency is searched through the ODE within one resolution cell 1/T
/// of the fingerprint's (T the record's span). The fingerprint's search regresses the residual
/// on a sinusoid of constant amplitude, which a ripple following the input's levels is not: on
/// supply_ripple-560008 (input −24/8/24 V) it peaked at 73.38 Hz against the truth's 74.76,
/// where the ripple's law did not beat the plain one; searched, it is taken at 74.80 Hz
/// (`motorcal diagnose` on the fixture prints both). Within the cell the score through the
/// ODE has one peak (the next is a cell away), and the frequency stays one of the band's the
/// fingerprint's grid paid ln G for.
fn supply_search(problem: &Problem, named: &NamedTerm) -> Option<f64> {
    let Term::Law(law) = &named.term else {
        return None;
    };
    let supply = law
        .active
        .iter()
        .any(|k| SUPPLY_RIPPLE.contains(&(k % N_FUNCTIONS)));
    let time = &problem.recording().time;
    let span = time.last()? - time.first()?;
    (supply && span > 0.0).then_some(1.0 / span)
}

/// A law in balance `b` of `functions` — sin and cos(2πft), or the supply's ripple, those
/// times U — at the frequency `f` a search over `frequencies` found. The frequency is a
/// setting of the law, not one of its parameters, so its score pays the search's whole
/// look-elsewhere cost ln G on top of the two coefficients' ½·ln N each (the coupling's
/// frequency, a parameter, pays ln G in place of its ½·ln N).
fn forced_law(
    problem: &Problem,
    b: usize,
    functions: [usize; 2],
    f: f64,
    frequencies: usize,
) -> Option<NamedTerm> {
    let Some(Term::Law(law)) = Term::named("law") else {
        return None;
    };
    let keys: Vec<usize> = functions.iter().map(|&p| b * N_FUNCTIONS + p).collect();
    let start = keys.iter().map(|&k| (law_key(k), 0.0)).collect();
    let mut law = law.with_active(keys);
    law.shapes.frequency = f;
    let present = problem.model.terms.iter().any(|t| t.term.name() == "law");
    let term = Term::Law(law);
    (problem.model.base.accepts(&term) && !present).then_some(NamedTerm {
        term,
        start,
        search_penalty: (frequencies.max(1) as f64).ln(),
        frequency_search: None,
        harmonic_search: None,
    })
}

/// The term `fingerprint` names on `problem`'s base, if one does.
pub fn named_term(problem: &Problem, fingerprint: &Fingerprint) -> Option<NamedTerm> {
    let mut search_penalty = 0.0;
    let mut harmonic_search = None;
    let (term, start) = match fingerprint {
        Fingerprint::Delay { seconds, .. } => {
            (Term::named("input_delay")?, vec![("tau", *seconds)])
        }
        Fingerprint::Lag {
            channel, seconds, ..
        } => {
            let index = ["I", "omega"].iter().position(|c| c == channel)?;
            let term = Term::from_name("sensor_lag", &[index as f64])?.ok()?;
            (term, vec![("tau", *seconds)])
        }
        Fingerprint::Oscillation {
            frequency_hz,
            damping_ratio,
            ringing: true,
            sensor: false,
            frequencies,
            ..
        } => {
            search_penalty = frequency_search_cost(*frequencies, problem.n_observations());
            (
                Term::named("compliant_coupling")?,
                vec![
                    ("f_r", *frequency_hz),
                    ("zeta", damping_ratio.unwrap_or(0.1).clamp(1e-3, 1.0)),
                ],
            )
        }
        Fingerprint::State { .. } | Fingerprint::Drift { .. } => {
            let (balance, functions, omega_s, harmonic, current_limit, fade, instant) =
                match fingerprint {
                    Fingerprint::State {
                        balance,
                        functions,
                        omega_s,
                        harmonic,
                        current_limit,
                        fade,
                        instant,
                        harmonic_price,
                        harmonic_width,
                        ..
                    } => {
                        // A k the order search found pays its grid, as a searched frequency does,
                        // and is refined through the ODE; a spot's (θ₀, w) pays its grid, unrefined.
                        search_penalty = *harmonic_price;
                        harmonic_search = (*harmonic_width > 0.0).then_some(*harmonic_width);
                        (
                            balance,
                            functions,
                            *omega_s,
                            *harmonic,
                            *current_limit,
                            *fade,
                            *instant,
                        )
                    }
                    Fingerprint::Drift {
                        balance,
                        functions,
                        fade,
                        instant,
                        shape_price,
                        ..
                    } => {
                        search_penalty = *shape_price;
                        (balance, functions, None, None, None, *fade, *instant)
                    }
                    _ => return None,
                };
            let Some(Term::Law(law)) = Term::named("law") else {
                return None;
            };
            let b = BALANCES.iter().position(|n| n == balance)?;
            let mut keys = Vec::new();
            let mut start = Vec::new();
            for f in functions {
                let k = b * N_FUNCTIONS + FUNCTIONS.iter().position(|n| *n == f.name)?;
                keys.push(k);
                start.push((law_key(k), f.coefficient));
            }
            let mut law = law.with_active(keys);
            if let Some(w) = omega_s {
                law.shapes.omega_s = w;
            }
            if let Some(k) = harmonic {
                law.shapes.harmonic = k;
            }
            if let Some(i) = current_limit {
                law.shapes.current_limit = i;
            }
            if let Some(tau) = fade {
                law.shapes.fade = tau;
            }
            if let Some(t_s) = instant {
                law.shapes.instant = t_s;
            }
            if let Fingerprint::State {
                speed_limit: Some(w),
                ..
            } = fingerprint
            {
                law.shapes.speed_limit = *w;
            }
            if let Fingerprint::State { spot: Some(p), .. } = fingerprint {
                (law.shapes.spot_angle, law.shapes.spot_width) = (p.theta_0, p.w);
            }
            (Term::Law(law), start)
        }
        _ => return None,
    };
    let present = problem
        .model
        .terms
        .iter()
        .any(|t| t.term.name() == term.name());
    (problem.model.base.accepts(&term) && !present).then_some(NamedTerm {
        term,
        start,
        search_penalty,
        frequency_search: None,
        harmonic_search,
    })
}

/// The law's parameter key `k` as the term declares it (a static text, as `start` keys are).
fn law_key(k: usize) -> &'static str {
    let key = dictionary::key(k);
    Term::named("law")
        .and_then(|t| t.params().iter().find(|p| p.key == key).map(|p| p.key))
        .expect("the law declares every key of the dictionary")
}

/// `named` fitted beside `with` (the selected terms, or none), started at `with`'s estimates
/// and the fingerprint's; a frequency found by a grid search pays the grid's multiplicity, as
/// in the ranking. A law whose frequency or harmonic is searched is fitted at each value
/// tried (`shape_search`), and the best fit is kept.
fn fit_named(problem: &Problem, with: &Candidate, named: &NamedTerm) -> Result<Candidate, Error> {
    let Term::Law(law) = &named.term else {
        return fit_named_at(problem, with, named, None);
    };
    // The shape searched (the frequency, or the angle's harmonic), its start and half-width.
    let (start, width, frequency) = match (named.frequency_search, named.harmonic_search) {
        (Some(w), _) => (law.shapes.frequency, w, true),
        (None, Some(w)) => (law.shapes.harmonic, w, false),
        (None, None) => return fit_named_at(problem, with, named, None),
    };
    // A law extending the one `with` holds keeps the shape that law already reads
    // (`extended`): searched, every value tried would fit the same model.
    if added_law(with).is_some_and(|held| held.reads(frequency)) {
        return fit_named_at(problem, with, named, None);
    }
    let at = |x: f64| {
        let mut law = law.clone();
        if frequency {
            law.shapes.frequency = x;
        } else {
            law.shapes.harmonic = x;
        }
        NamedTerm {
            term: Term::Law(law),
            frequency_search: None,
            harmonic_search: None,
            ..named.clone()
        }
    };
    // The values tried lie within a quarter of the record's Fourier spacing of the start, where
    // the coefficients hardly move: each fit continues from the best fit so far, not from the
    // fingerprint's regression (what bounds a fit that crawls is `MapSettings::ranking`'s cap).
    let first = fit_named_at(problem, with, &at(start), None);
    let best = best_shape(start, width, first.as_ref().ok().cloned(), |x, warm| {
        fit_named_at(problem, with, &at(x), warm).ok()
    });
    // None only where every fit failed, the start's among them: its error says why.
    best.map_or(first, Ok)
}

/// `named` fitted beside `with` at its settings as they are, its parameters started at
/// `warm`'s estimates where given (a fit of the same term at a nearby shape).
fn fit_named_at(
    problem: &Problem,
    with: &Candidate,
    named: &NamedTerm,
    warm: Option<&Candidate>,
) -> Result<Candidate, Error> {
    let name = named.term.name().to_string();
    let mut added = with.added.clone();
    let term = match (&named.term, added_law(with)) {
        // A law named beside a fit that holds one already (the verdict after a law found more
        // in the same balance: the other half of a ripple's phase) extends that law; its
        // coefficients start at the fit's estimates, its shapes are kept where it has them.
        (Term::Law(more), Some(held)) => Term::Law(held.extended(more)),
        _ => {
            added.push(name.clone());
            named.term.clone()
        }
    };
    let mut starts = starts_of(named);
    starts.terms = vec![term];
    // A fit of the same model at a nearby shape gives two starts: every parameter at its
    // estimates, or `with`'s beside its law's coefficients. Each alone stalled on
    // bearing_defect-690003, thousands of nats below the other on some shapes; the search
    // runs from whichever starts higher.
    let Some(warm) = warm else {
        return fit_candidate_started(problem, &added, Some(with), &starts);
    };
    let mut with_law = with.clone();
    with_law.theta = warm
        .theta
        .iter()
        .filter(|(k, _)| ParamId::parse(k).is_of(&name))
        .chain(&with.theta)
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    fit_candidate_warmed(problem, &added, &[warm, &with_law], &starts)
}

/// What a fit of `named` starts from: its settings, its parameters' values and what its score
/// pays for the grid its start was the best of.
pub(super) fn starts_of(named: &NamedTerm) -> Starts {
    let name = named.term.name();
    let mut starts = Starts {
        terms: vec![named.term.clone()],
        ..Starts::default()
    };
    for &(key, value) in &named.start {
        starts
            .values
            .insert(ParamId::of_term(name, key).to_string(), value);
    }
    if named.search_penalty > 0.0 {
        starts
            .search_penalty
            .insert(name.to_string(), named.search_penalty);
    }
    starts
}

/// The law `fit`'s model holds, if one.
pub(super) fn law_of(fit: &Candidate) -> Option<&Law> {
    fit.problem.model.terms.iter().find_map(|t| match &t.term {
        Term::Law(law) => Some(law),
        _ => None,
    })
}

/// The law the diagnosis added to `fit`'s model, if one (not a law the user's model holds):
/// a law named beside it extends it.
fn added_law(fit: &Candidate) -> Option<&Law> {
    law_of(fit).filter(|_| fit.added.iter().any(|a| a == "law"))
}

/// The fingerprints to name, and the fits to name each beside.
pub type Naming<'a> = (Vec<&'a Fingerprint>, Vec<&'a Candidate>);

/// The best fit of a term the fingerprints name (every kind that cleared the threshold on its
/// own, not only the leader: the fits, not the linearised scores, decide), each fitted beside
/// every one of its group's bases, when it beats `selected` by more than the threshold. Where
/// the user named the candidates (`allowed`), only those may be added: the list says what the
/// diagnosis may add to the model, whichever way it finds them.
pub fn fit_named_terms<'a>(
    problem: &Problem,
    groups: impl IntoIterator<Item = Naming<'a>>,
    selected: &Candidate,
    allowed: Option<&[String]>,
) -> Result<Option<Candidate>, Error> {
    let mut jobs: Vec<(&Candidate, NamedTerm)> = Vec::new();
    for (fingerprints, bases) in groups {
        let mut named: Vec<NamedTerm> = Vec::new();
        for n in fingerprints
            .into_iter()
            .flat_map(|f| named_terms(problem, f))
        {
            if !named.iter().any(|m| m.same_term(&n))
                && allowed.is_none_or(|a| a.iter().any(|c| c == n.term.name()))
            {
                named.push(n);
            }
        }
        for n in named {
            for &with in &bases {
                // The same term from the same start beside the same fit is one fit, however
                // many groups name it: the model as given's laws are often the verdict's after
                // a library term that does not touch them (cogging-770012 fitted four laws,
                // each with its harmonic searched, twice over).
                if adds_nothing(with, &n)
                    || jobs.iter().any(|(w, m)| std::ptr::eq(*w, with) && *m == n)
                {
                    continue;
                }
                jobs.push((with, n.clone()));
            }
        }
    }
    // A fit that fails (a stiff resonance far from the data) is no candidate, not an error of
    // the diagnosis.
    let fits: Vec<Candidate> = jobs
        .par_iter()
        .filter_map(|(with, n)| fit_named(problem, with, n).ok())
        .collect();
    Ok(fits
        .into_iter()
        .filter(|f| f.score - selected.score > EVIDENCE_THRESHOLD)
        .max_by(|a, b| a.score.total_cmp(&b.score)))
}

/// Whether `named` is a law whose every function the law `with` holds already has: the law it
/// extends would be `with`'s own, refitted from another start.
fn adds_nothing(with: &Candidate, named: &NamedTerm) -> bool {
    match (&named.term, added_law(with)) {
        (Term::Law(more), Some(held)) => more.active.iter().all(|k| held.active.contains(k)),
        _ => false,
    }
}

impl NamedTerm {
    /// Two fingerprints name the same term where its name is the same (the first, the
    /// stronger, gives the start), except laws, which are told apart by their functions.
    fn same_term(&self, other: &NamedTerm) -> bool {
        match (&self.term, &other.term) {
            (Term::Law(a), Term::Law(b)) => a == b,
            (a, b) => a.name() == b.name(),
        }
    }
}
