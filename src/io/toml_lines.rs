//! Where in a TOML text a key is written: the dotted key path assigned on each line and the
//! table each header opens. `toml` reports byte spans and only some keys, and checks made
//! after parsing have no span at all; these give every error a line and a key.

use std::path::Path;

use super::error::{InputError, line_and_column};

/// One line for a TOML error: the line from the error's byte span, the key from the text there
/// (qualified by its table, since `U` is both a motor parameter and a channel) or, for a key in a
/// table header or a multi-line value, from the message.
pub(super) fn toml_error(text: &str, path: &Path, e: &toml::de::Error) -> InputError {
    let line = e
        .span()
        .map(|span| line_and_column(text.as_bytes(), span.start).0);
    let field = line
        .and_then(|l| key_paths(text).get(l - 1).cloned().flatten())
        .or_else(|| backticked(e.message()));
    let mut message = e.message().replace('\n', "; ");
    if message.starts_with("unknown field") {
        message.push_str(" (keys are case-sensitive)");
    }
    InputError::new(path, message)
        .at_line_opt(line)
        .for_field_opt(field)
}

/// The first `name` in a message like "unknown field `name`, expected ...".
fn backticked(message: &str) -> Option<String> {
    let rest = &message[message.find('`')? + 1..];
    Some(rest[..rest.find('`')?].to_owned())
}

/// For every line of `text`, the dotted path of the table its header opens (`terms.x`), if any.
pub(super) fn table_headers(text: &str) -> Vec<Option<String>> {
    text.lines()
        .map(|raw| {
            let line = raw.trim();
            let inner = line.strip_prefix('[')?.trim_start_matches('[');
            Some(key_segments(inner.split(']').next().unwrap_or("")).join("."))
        })
        .collect()
}

/// For every line of `text`, the dotted path of the key assigned there (`motor.R`), if any.
///
/// A small line scanner, not a TOML parser: it only has to find where keys are written in files
/// that `toml` already accepted (or where it stopped), so that errors found after parsing point at
/// a line too.
pub(super) fn key_paths(text: &str) -> Vec<Option<String>> {
    let mut table: Vec<String> = Vec::new();
    text.lines()
        .map(|raw| {
            let line = raw.trim();
            if line.starts_with('[') {
                let inner = line.trim_start_matches('[');
                let inner = inner.split(']').next().unwrap_or("");
                table = key_segments(inner);
                None
            } else if line.starts_with('#') {
                None
            } else {
                let (key, _) = line.split_once('=')?;
                let segments = key_segments(key);
                if segments.is_empty() {
                    return None;
                }
                Some(
                    table
                        .iter()
                        .chain(&segments)
                        .cloned()
                        .collect::<Vec<_>>()
                        .join("."),
                )
            }
        })
        .collect()
}

fn key_segments(key: &str) -> Vec<String> {
    key.split('.')
        .map(|s| s.trim().trim_matches(|c| c == '"' || c == '\'').to_owned())
        .filter(|s| !s.is_empty())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_found_with_their_table() {
        let paths =
            key_paths("schema = 1\n[motor]\n  \"R\" = 2 # x\n# c = 1\n[channels]\nU = \"V\"\n");
        assert_eq!(
            paths,
            [
                Some("schema".into()),
                None,
                Some("motor.R".into()),
                None,
                None,
                Some("channels.U".into())
            ]
        );
        assert_eq!(key_paths("motor.J = 1\n"), [Some("motor.J".to_owned())]);
    }
}
