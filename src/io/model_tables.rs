//! The tables of schema-2 model files that say what a model holds beyond the motor: which
//! physics terms are on (`[terms.NAME]`), what is calibrated with which prior (`[calibrate]`),
//! and the discrepancy (`[discrepancy]`). Read from the parsed TOML, checked key by key, so that
//! every mistake names its key and line.

use std::fmt::Write;

use serde::Deserialize;

use super::error::InputError;
use crate::bayes::BasisKind;
use crate::motor::{ActiveTerm, MotorParam, Term};
use crate::parameter::{ParamId, Prior};

/// A parameter the model file calibrates, with its prior (`None`: the term's default).
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrateEntry {
    /// The parameter, as the file names it (`R`, `"coulomb_friction.T_c"`).
    pub id: ParamId,
    pub prior: Option<Prior>,
}

/// `[discrepancy]`: the basis (`None` for `basis = "none"`, i.e. BM1) and the degree K.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscrepancyChoice {
    pub basis: Option<BasisKind>,
    pub degree: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDiscrepancy {
    basis: Option<String>,
    degree: Option<usize>,
}

/// Where a key was written, for errors: the line of `path`, if the file has it.
pub(super) type Locate<'a> = &'a dyn Fn(&str) -> Option<usize>;

fn error(file: &std::path::Path, locate: Locate, field: &str, message: String) -> InputError {
    InputError::new(file, message)
        .at_line_opt(locate(field))
        .for_field(field)
}

fn number(value: &toml::Value) -> Option<f64> {
    match value {
        toml::Value::Float(v) => Some(*v),
        toml::Value::Integer(v) => Some(*v as f64),
        _ => None,
    }
}

/// `[terms.NAME]` tables: each switches a term on, with parameter values and settings.
pub(super) fn parse_terms(
    table: &toml::Table,
    file: &std::path::Path,
    locate: Locate,
) -> Result<Vec<ActiveTerm>, InputError> {
    let mut terms = Vec::new();
    for (name, value) in table {
        let field = format!("terms.{name}");
        let Some((params, settings)) = Term::declarations(name) else {
            return Err(error(
                file,
                locate,
                &field,
                format!(
                    "unknown term '{name}' (known: {})",
                    Term::ALL_NAMES.join(", ")
                ),
            ));
        };
        let Some(entries) = value.as_table() else {
            return Err(error(
                file,
                locate,
                &field,
                format!("[terms.{name}] must be a table of its parameters and settings"),
            ));
        };
        let mut values: Vec<f64> = params.iter().map(|p| p.default).collect();
        let mut setting_values: Vec<f64> = settings.iter().map(|s| s.default).collect();
        // The parameters the table lists: a law's active coefficients.
        let mut listed = Vec::new();
        for (key, v) in entries {
            let key_field = format!("{field}.{key}");
            let slot = if let Some(i) = params.iter().position(|p| p.key == key) {
                listed.push(i);
                &mut values[i]
            } else if let Some(i) = settings.iter().position(|s| s.key == key) {
                let choices = settings[i].choices;
                if !choices.is_empty() {
                    let chosen = v
                        .as_str()
                        .and_then(|c| choices.iter().position(|k| *k == c));
                    let Some(index) = chosen else {
                        let names: Vec<String> =
                            choices.iter().map(|c| format!("\"{c}\"")).collect();
                        return Err(error(
                            file,
                            locate,
                            &key_field,
                            format!("{name}.{key} must be one of {}, not {v}", names.join(", ")),
                        ));
                    };
                    setting_values[i] = index as f64;
                    continue;
                }
                &mut setting_values[i]
            } else if name == "law" {
                // A law's keys are balance:function pairs: say which half is unknown.
                let why = crate::motor::dictionary::index_of(key)
                    .err()
                    .unwrap_or_else(|| format!("unknown key '{key}'"));
                return Err(error(file, locate, &key_field, format!("term law: {why}")));
            } else {
                let known: Vec<&str> = params
                    .iter()
                    .map(|p| p.key)
                    .chain(settings.iter().map(|s| s.key))
                    .collect();
                return Err(error(
                    file,
                    locate,
                    &key_field,
                    format!(
                        "unknown key '{key}' of term {name} (known: {})",
                        known.join(", ")
                    ),
                ));
            };
            match number(v) {
                Some(x) if x.is_finite() => *slot = x,
                _ => {
                    return Err(error(
                        file,
                        locate,
                        &key_field,
                        format!("{name}.{key} must be a finite number, not {v}"),
                    ));
                }
            }
        }
        let mut term = Term::from_name(name, &setting_values)
            .expect("declared above")
            .map_err(|e| error(file, locate, &field, e))?;
        if let Term::Law(law) = term {
            term = Term::Law(law.with_active(listed));
        }
        terms.push(ActiveTerm { term, values });
    }
    Ok(terms)
}

/// Whether `name` is a parameter of the base model or of a term (term on or not).
fn check_parameter_name(name: &ParamId) -> Result<(), String> {
    match name {
        ParamId::Base(key) if key == "T_L" => {
            Err("T_L is not a parameter of its own: calibrate load_torque.T_0".into())
        }
        ParamId::Base(key) if MotorParam::from_key(key).is_some() => Ok(()),
        ParamId::Base(_) => Err(format!(
            "unknown parameter '{name}' (the motor's are {}; a term's are written term.key)",
            MotorParam::ALL
                .iter()
                .map(|p| p.key())
                .collect::<Vec<_>>()
                .join(", ")
        )),
        ParamId::Term { term, key } => match Term::declarations(term) {
            None => Err(format!(
                "unknown term '{term}' (known: {})",
                Term::ALL_NAMES.join(", ")
            )),
            Some((params, _)) if params.iter().any(|p| p.key == key) => Ok(()),
            Some((params, _)) => Err(format!(
                "term {term} has no parameter '{key}' (its parameters: {})",
                params.iter().map(|p| p.key).collect::<Vec<_>>().join(", ")
            )),
        },
    }
}

/// The prior families a model file can name, with their arguments.
const FAMILIES: [(&str, [&str; 2]); 4] = [
    ("normal", ["mean", "sd"]),
    ("lognormal", ["median", "sigma"]),
    ("half_normal", ["scale", ""]),
    ("uniform", ["lower", "upper"]),
];

fn parse_prior(
    name: &ParamId,
    entry: &toml::Table,
    file: &std::path::Path,
    locate: Locate,
) -> Result<Option<Prior>, InputError> {
    let field = format!("calibrate.{name}");
    if entry.is_empty() {
        return Ok(None);
    }
    let Some(family) = entry.get("prior") else {
        return Err(error(
            file,
            locate,
            &format!("{field}.prior"),
            format!("{name}: missing 'prior' (one of normal, lognormal, half_normal, uniform)"),
        ));
    };
    let family = family.as_str().unwrap_or("");
    let Some((_, args)) = FAMILIES.iter().find(|(f, _)| *f == family) else {
        return Err(error(
            file,
            locate,
            &format!("{field}.prior"),
            format!(
                "{name}: unknown prior family '{}' (known: normal, lognormal, half_normal, \
                 uniform)",
                entry["prior"]
            ),
        ));
    };
    let args: Vec<&str> = args.iter().copied().filter(|a| !a.is_empty()).collect();
    for key in entry.keys() {
        if key != "prior" && !args.contains(&key.as_str()) {
            return Err(error(
                file,
                locate,
                &format!("{field}.{key}"),
                format!(
                    "{name}: a {family} prior takes {}, not '{key}'",
                    args.join(" and ")
                ),
            ));
        }
    }
    let mut values = Vec::new();
    for arg in &args {
        let arg_field = format!("{field}.{arg}");
        match entry.get(*arg).map(number) {
            None => {
                return Err(error(
                    file,
                    locate,
                    &arg_field,
                    format!("{name}: the {family} prior needs '{arg}'"),
                ));
            }
            Some(None) => {
                return Err(error(
                    file,
                    locate,
                    &arg_field,
                    format!("{name}: '{arg}' must be a number"),
                ));
            }
            Some(Some(v)) => values.push(v),
        }
    }
    let prior = match family {
        "normal" => Prior::Normal {
            mean: values[0],
            sd: values[1],
        },
        "lognormal" => Prior::LogNormal {
            median: values[0],
            sigma: values[1],
        },
        "half_normal" => Prior::HalfNormal { scale: values[0] },
        _ => Prior::Uniform {
            lower: values[0],
            upper: values[1],
        },
    };
    prior
        .validate()
        .map_err(|e| error(file, locate, &field, format!("{name}: {e}")))?;
    Ok(Some(prior))
}

/// `[calibrate]`: `name = { prior = …, args }` or `name = {}`, with a term's parameters written
/// `"term.key"` (or as a dotted key). A term named here but not in `[terms]` is switched on at
/// its default values.
pub(super) fn parse_calibrate(
    table: &toml::Table,
    terms: &mut Vec<ActiveTerm>,
    file: &std::path::Path,
    locate: Locate,
) -> Result<Vec<CalibrateEntry>, InputError> {
    let mut flat: Vec<(ParamId, &toml::Value)> = Vec::new();
    for (key, value) in table {
        let nested = Term::declarations(key).is_some()
            && value
                .as_table()
                .is_some_and(|t| !t.is_empty() && t.values().all(|v| v.is_table()));
        if nested {
            for (sub, v) in value.as_table().expect("checked") {
                flat.push((ParamId::of_term(key, sub), v));
            }
        } else {
            flat.push((ParamId::parse(key), value));
        }
    }
    let mut entries = Vec::new();
    for (name, value) in flat {
        let field = format!("calibrate.{name}");
        check_parameter_name(&name).map_err(|e| error(file, locate, &field, e))?;
        let Some(entry) = value.as_table() else {
            return Err(error(
                file,
                locate,
                &field,
                format!(
                    "{name} must be an inline table: {{ prior = \"normal\", mean = …, sd = … }}, \
                     or {{}} for the default prior"
                ),
            ));
        };
        let prior = parse_prior(&name, entry, file, locate)?;
        if let Some(term) = name.term()
            && !terms.iter().any(|t| t.term.name() == term)
        {
            terms.push(ActiveTerm::with_defaults(
                Term::named(term).expect("checked above"),
            ));
        }
        // A law coefficient named here is one of the law's functions, listed or not.
        if let Some(active) = terms.iter_mut().find(|t| name.is_of(t.term.name()))
            && let Term::Law(law) = &active.term
            && let Ok(k) = crate::motor::dictionary::index_of(name.key())
        {
            let mut keys = law.active.clone();
            keys.push(k);
            active.term = Term::Law(law.clone().with_active(keys));
        }
        entries.push(CalibrateEntry { id: name, prior });
    }
    Ok(entries)
}

pub(super) fn parse_discrepancy(
    raw: &RawDiscrepancy,
    file: &std::path::Path,
    locate: Locate,
) -> Result<DiscrepancyChoice, InputError> {
    let basis = match raw.basis.as_deref().unwrap_or("legendre") {
        "legendre" => Some(BasisKind::Legendre),
        "bspline" => Some(BasisKind::Bspline),
        "none" => None,
        other => {
            return Err(error(
                file,
                locate,
                "discrepancy.basis",
                format!("unknown basis '{other}' (known: legendre, bspline, none)"),
            ));
        }
    };
    let degree = raw.degree.unwrap_or(9);
    if basis == Some(BasisKind::Bspline) && degree < crate::bayes::bspline::MIN_BSPLINE_DEGREE {
        return Err(error(
            file,
            locate,
            "discrepancy.degree",
            format!(
                "a B-spline basis needs degree ≥ {} (one cubic span), not {degree}",
                crate::bayes::bspline::MIN_BSPLINE_DEGREE
            ),
        ));
    }
    if let Some(kind) = basis
        && degree > kind.max_degree()
    {
        return Err(error(
            file,
            locate,
            "discrepancy.degree",
            format!(
                "degree {degree} is larger than the maximum {} of the {} basis",
                kind.max_degree(),
                kind.name()
            ),
        ));
    }
    Ok(DiscrepancyChoice { basis, degree })
}

/// A number as TOML writes it and reads back bit for bit (Rust's shortest round-trip form).
pub(super) fn toml_number(v: f64) -> String {
    let text = format!("{v:?}");
    if text.contains(['.', 'e', 'E']) {
        text
    } else {
        format!("{text}.0")
    }
}

/// TOML text of the schema-2 tables.
pub(super) fn write_tables(
    out: &mut String,
    terms: &[ActiveTerm],
    calibrate: Option<&[CalibrateEntry]>,
    discrepancy: Option<&DiscrepancyChoice>,
) {
    for t in terms {
        let _ = writeln!(out, "\n[terms.{}]", t.term.name());
        for (k, (decl, v)) in t.term.params().iter().zip(&t.values).enumerate() {
            match &t.term {
                // A law writes its active coefficients alone, keyed "balance:function".
                Term::Law(law) if law.active.contains(&k) => {
                    let _ = writeln!(out, "\"{}\" = {}", decl.key, toml_number(*v));
                }
                Term::Law(_) => {}
                _ => {
                    let _ = writeln!(out, "{} = {}", decl.key, toml_number(*v));
                }
            }
        }
        for (decl, v) in t.term.setting_decls().iter().zip(t.term.settings()) {
            match decl.choices.get(v as usize) {
                Some(choice) => {
                    let _ = writeln!(out, "{} = \"{choice}\"", decl.key);
                }
                None => {
                    let _ = writeln!(out, "{} = {}", decl.key, toml_number(v));
                }
            }
        }
    }
    if let Some(entries) = calibrate {
        out.push_str("\n[calibrate]\n");
        for e in entries {
            let args = match e.prior {
                None => String::new(),
                Some(Prior::Normal { mean, sd }) => format!(
                    " prior = \"normal\", mean = {}, sd = {} ",
                    toml_number(mean),
                    toml_number(sd)
                ),
                Some(Prior::LogNormal { median, sigma }) => format!(
                    " prior = \"lognormal\", median = {}, sigma = {} ",
                    toml_number(median),
                    toml_number(sigma)
                ),
                Some(Prior::HalfNormal { scale }) => {
                    format!(" prior = \"half_normal\", scale = {} ", toml_number(scale))
                }
                Some(Prior::Uniform { lower, upper }) => format!(
                    " prior = \"uniform\", lower = {}, upper = {} ",
                    toml_number(lower),
                    toml_number(upper)
                ),
                // Laplace and inverse-gamma priors are never read from a model file; one made
                // in code is written as the normal of the same mean and variance.
                Some(other) => format!(
                    " prior = \"normal\", mean = {}, sd = {} ",
                    toml_number(other.mean()),
                    toml_number(other.variance().sqrt())
                ),
            };
            let _ = writeln!(out, "\"{}\" = {{{args}}}", e.id);
        }
    }
    if let Some(d) = discrepancy {
        let basis = d.basis.map_or("none", |b| b.name());
        let _ = writeln!(
            out,
            "\n[discrepancy]\nbasis = \"{basis}\"\ndegree = {}",
            d.degree
        );
    }
}
