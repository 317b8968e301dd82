//! What `design` reads of a `diagnose --json` report: its candidates (the selected term, its
//! ties and a drive's tied pairs), their fits, and the selected model a pin design sits at.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;

use crate::motor::MotorParam;

use super::super::AppError;

pub(super) fn read_diagnosis(path: &Path) -> Result<Value, AppError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| AppError::Usage(format!("--diagnosis {}: {e}", path.display())))?;
    let value: Value = serde_json::from_str(&text).map_err(|e| {
        AppError::Usage(format!(
            "--diagnosis {}:{}: not a diagnose --json report: {e}",
            path.display(),
            e.line()
        ))
    })?;
    if !value["ranking"].is_array() {
        return Err(AppError::Usage(format!(
            "--diagnosis {}: field 'ranking' missing: not a diagnose --json report",
            path.display()
        )));
    }
    Ok(value)
}

/// The selected term and its ties, and the pairs a drive's records cannot tell apart
/// (`tied_pairs`: Coulomb friction and a load on records that never reverse).
pub(super) fn default_candidates(diagnosis: &Value) -> Result<Vec<String>, AppError> {
    let mut names = vec![diagnosis["selected"].as_str().unwrap_or("none").to_string()];
    let ties = diagnosis["ties"].as_array().into_iter().flatten();
    let pairs = diagnosis["tied_pairs"]
        .as_array()
        .into_iter()
        .flatten()
        .flat_map(|pair| pair.as_array().into_iter().flatten());
    for tie in ties.chain(pairs) {
        if let Some(t) = tie.as_str()
            && !names.iter().any(|n| n == t)
        {
            names.push(t.to_string());
        }
    }
    if names.len() < 2 {
        return Err(AppError::Usage(
            "the diagnosis reports no tie: name the candidates with --separate".into(),
        ));
    }
    Ok(names)
}

/// A candidate's fitted values from the diagnosis's ranking, keyed as the model's parameters.
pub(super) fn candidate_values(
    diagnosis: &Value,
    name: &str,
) -> Result<BTreeMap<String, f64>, AppError> {
    let entry = diagnosis["ranking"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|e| e["effect"].as_str() == Some(name))
        .ok_or_else(|| {
            AppError::Usage(format!(
                "--separate {name}: the diagnosis's ranking has no fit of '{name}'"
            ))
        })?;
    let base: Vec<&str> = MotorParam::ALL.iter().map(|p| p.key()).collect();
    let mut values = BTreeMap::new();
    for (key, v) in entry["params"].as_object().into_iter().flatten() {
        let Some(v) = v.as_f64() else { continue };
        if key == "I_sat" {
            continue;
        }
        let key = if base.contains(&key.as_str()) || key.contains('.') {
            key.clone()
        } else {
            format!("{name}.{key}")
        };
        values.insert(key, v);
    }
    Ok(values)
}

/// A diagnosis's selected terms and the selected model's MAP (`selected_set`,
/// `selected_params`), keyed as the model's parameters are.
pub(super) fn selected_model(
    diagnosis: &Value,
) -> Result<(Vec<String>, BTreeMap<String, f64>), AppError> {
    let terms: Option<Vec<String>> = diagnosis["selected_set"].as_array().map(|a| {
        a.iter()
            .filter_map(|t| t.as_str().map(String::from))
            .collect()
    });
    let Some(terms) = terms else {
        return Err(AppError::Usage(
            "--diagnosis: the report has no selected_set (is it a `diagnose --json` report?)"
                .into(),
        ));
    };
    if terms.iter().any(|t| t == "law") {
        // A law's functions are in the amended model.toml `diagnose --out` wrote, not in the
        // report's term names.
        return Err(AppError::Usage(
            "--pin with --diagnosis: the selected model holds a discovered law; give the \
             amended model.toml that `diagnose --out` wrote as --model instead"
                .into(),
        ));
    }
    let values = diagnosis["selected_params"]
        .as_object()
        .into_iter()
        .flatten()
        .filter(|(key, _)| !key.ends_with("I_sat"))
        .filter_map(|(key, v)| Some((key.clone(), v.as_f64()?)))
        .collect();
    Ok((terms, values))
}
