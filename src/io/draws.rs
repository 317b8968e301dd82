//! Posterior draws in CmdStan's CSV layout, which ArviZ's `from_cmdstan` reads; and a reader for
//! those files and for the "long" layout (`chain,draw,<parameters>`) other tools export.

use std::collections::BTreeMap;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::atomic::{AtomicFile, with_path};
use super::error::{InputError, read_text};
use super::table::{self, Line};

/// CmdStan's sampler columns, in its order, before the parameters.
pub const SAMPLER_COLUMNS: [&str; 7] = [
    "lp__",
    "accept_stat__",
    "stepsize__",
    "treedepth__",
    "n_leapfrog__",
    "divergent__",
    "energy__",
];

/// The sampler's state at one draw. Samplers without trees write `treedepth = 0` and the number of
/// gradient evaluations as `n_leapfrog`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SamplerColumns {
    pub lp: f64,
    pub accept_stat: f64,
    pub stepsize: f64,
    pub treedepth: u32,
    pub n_leapfrog: u64,
    pub divergent: bool,
    pub energy: f64,
    /// Importance sampling's weight of the draw, written as `weight__` after `energy__` in a
    /// file made by [`CmdStanWriter::create_weighted`] (ignored otherwise).
    pub weight: Option<f64>,
}

/// Streams one chain's draws to a CmdStan CSV file; the file appears only on
/// [`CmdStanWriter::finish`], so an interrupted run leaves no truncated chain behind.
pub struct CmdStanWriter {
    file: AtomicFile,
    n_params: usize,
    weighted: bool,
    line: String,
}

impl CmdStanWriter {
    /// Starts a file with `metadata` as `# key = value` lines (seed, settings, versions) and the
    /// header row.
    pub fn create(
        path: &Path,
        metadata: &[(String, String)],
        param_names: &[String],
    ) -> io::Result<Self> {
        Self::create_weighted(path, metadata, param_names, false)
    }

    /// As [`create`](Self::create), with a `weight__` column after CmdStan's sampler columns
    /// when `weighted` (importance sampling's draws; readers skip it as a sampler column).
    pub fn create_weighted(
        path: &Path,
        metadata: &[(String, String)],
        param_names: &[String],
        weighted: bool,
    ) -> io::Result<Self> {
        let invalid =
            |message: String| with_path(path, io::Error::new(io::ErrorKind::InvalidInput, message));
        if param_names.is_empty() {
            return Err(invalid("no parameter names".into()));
        }
        for (i, name) in param_names.iter().enumerate() {
            // Names that the reader (or ArviZ) would split, skip or take for sampler columns.
            if name.is_empty()
                || name.contains([',', '\n', '\r', '"'])
                || name.trim() != name
                || name.starts_with('#')
                || name.ends_with("__")
            {
                return Err(invalid(format!(
                    "parameter name '{name}' cannot be a CmdStan column"
                )));
            }
            if param_names[..i].contains(name) {
                return Err(invalid(format!("parameter name '{name}' appears twice")));
            }
        }

        let mut head = String::new();
        for (key, value) in metadata {
            head.push_str(&format!("# {} = {}\n", one_line(key), one_line(value)));
        }
        head.push_str(&SAMPLER_COLUMNS.join(","));
        if weighted {
            head.push_str(",weight__");
        }
        for name in param_names {
            head.push(',');
            head.push_str(name);
        }
        head.push('\n');
        let mut file = AtomicFile::create(path)?;
        file.write_all(head.as_bytes())
            .map_err(|e| with_path(path, e))?;
        Ok(Self {
            file,
            n_params: param_names.len(),
            weighted,
            line: String::new(),
        })
    }

    /// Appends one draw.
    pub fn write_draw(&mut self, sampler: &SamplerColumns, params: &[f64]) -> io::Result<()> {
        if params.len() != self.n_params {
            return Err(with_path(
                self.file.path(),
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "{} parameter values for {} parameter columns",
                        params.len(),
                        self.n_params
                    ),
                ),
            ));
        }
        let line = &mut self.line;
        line.clear();
        table::push_number(line, sampler.lp);
        line.push(',');
        table::push_number(line, sampler.accept_stat);
        line.push(',');
        table::push_number(line, sampler.stepsize);
        line.push_str(&format!(
            ",{},{},{},",
            sampler.treedepth,
            sampler.n_leapfrog,
            u8::from(sampler.divergent)
        ));
        table::push_number(line, sampler.energy);
        if self.weighted {
            line.push(',');
            table::push_number(line, sampler.weight.unwrap_or(f64::NAN));
        }
        for &p in params {
            line.push(',');
            table::push_number(line, p);
        }
        line.push('\n');
        let path = self.file.path().to_path_buf();
        self.file
            .write_all(self.line.as_bytes())
            .map_err(|e| with_path(&path, e))
    }

    /// Writes free-form `#` lines between draws, as CmdStan does for the adapted step size and
    /// metric after warm-up ("Adaptation terminated").
    pub fn write_comment(&mut self, text: &str) -> io::Result<()> {
        let mut out = String::new();
        for line in text.lines() {
            out.push_str("# ");
            out.push_str(line);
            out.push('\n');
        }
        let path = self.file.path().to_path_buf();
        self.file
            .write_all(out.as_bytes())
            .map_err(|e| with_path(&path, e))
    }

    /// Puts the file in place.
    pub fn finish(self) -> io::Result<()> {
        self.file.commit()
    }
}

fn one_line(text: &str) -> String {
    text.replace(['\n', '\r'], " ")
}

/// Draws of several chains: `chains[chain][parameter][draw]`, parameters named by `names`.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct DrawSet {
    pub names: Vec<String>,
    pub chains: Vec<Vec<Vec<f64>>>,
}

impl DrawSet {
    pub fn n_chains(&self) -> usize {
        self.chains.len()
    }

    pub fn n_draws(&self) -> usize {
        self.chains
            .first()
            .and_then(|c| c.first())
            .map_or(0, Vec::len)
    }

    pub fn n_params(&self) -> usize {
        self.names.len()
    }

    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// One parameter's draws, one slice per chain, as the diagnostics take them.
    pub fn parameter(&self, name: &str) -> Option<Vec<&[f64]>> {
        let i = self.index_of(name)?;
        Some(self.chains.iter().map(|c| c[i].as_slice()).collect())
    }
}

/// One chain as read, with where it came from for errors.
struct ChainRead {
    file: PathBuf,
    /// The chain's label in a long file, for messages.
    label: Option<String>,
    header_line: usize,
    last_line: usize,
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
}

/// Reads draws from CmdStan CSV files (one chain each) and long files (`chain,draw,<parameters>`,
/// any number of chains), in the order given. All chains must have the same parameters (in any
/// column order) and the same number of draws.
pub fn read_draws(paths: &[PathBuf]) -> Result<DrawSet, InputError> {
    if paths.is_empty() {
        return Err(InputError::new("", "no draws files given"));
    }
    let mut chains = Vec::new();
    for path in paths {
        chains.extend(read_draws_file(path)?);
    }

    let first = &chains[0];
    // How the first chain is named in messages about another: by label within the same file.
    let first_seen_from = |c: &ChainRead| match (&first.label, c.file == first.file) {
        (Some(label), true) => format!("chain {label}"),
        (Some(label), false) => format!("chain {label} of {}", first.file.display()),
        (None, _) => first.file.display().to_string(),
    };
    let names = first.names.clone();
    let n_draws = first.columns[0].len();
    let mut described = Vec::with_capacity(chains.len());
    for chain in &chains {
        described.push(first_seen_from(chain));
    }
    let mut set = DrawSet {
        names: names.clone(),
        chains: Vec::with_capacity(chains.len()),
    };
    for (chain, first) in chains.into_iter().zip(described) {
        let err = |message: String| InputError::new(&chain.file, message);
        let mut order = Vec::with_capacity(names.len());
        for name in &names {
            let Some(i) = chain.names.iter().position(|n| n == name) else {
                return Err(err(format!("no parameter '{name}', which {first} has"))
                    .at_line(chain.header_line)
                    .for_field(name.clone()));
            };
            order.push(i);
        }
        if let Some(extra) = chain.names.iter().find(|n| !names.contains(n)) {
            return Err(err(format!("parameter '{extra}' is not in {first}"))
                .at_line(chain.header_line)
                .for_field(extra.clone()));
        }
        let len = chain.columns[0].len();
        if len != n_draws {
            let this = match &chain.label {
                Some(label) => format!("chain {label} has"),
                None => "this file has".to_owned(),
            };
            let e = err(format!(
                "{this} {len} draws, but {first} has {n_draws}; chains must have equal length"
            ))
            .at_line(chain.last_line);
            return Err(if chain.label.is_some() {
                e.for_field("chain")
            } else {
                e
            });
        }
        let mut columns: Vec<Option<Vec<f64>>> = chain.columns.into_iter().map(Some).collect();
        set.chains.push(
            order
                .into_iter()
                .map(|i| columns[i].take().unwrap_or_default())
                .collect(),
        );
    }
    Ok(set)
}

fn read_draws_file(path: &Path) -> Result<Vec<ChainRead>, InputError> {
    let text = read_text(path, |text, line, column| {
        table::column_at(text, line, column)
    })?;
    let err = |message: String| InputError::new(path, message);
    let Some((header_line, header)) = table::header(&text) else {
        return Err(err(
            "no header line: the file is empty or has only comments".into(),
        ));
    };

    let chain_col = header.iter().position(|&n| n == "chain");
    // CmdStan never writes a `chain` column; a long export may carry sampler columns too.
    let long = chain_col.is_some();
    // Parameters: everything but CmdStan's sampler columns and the long layout's indices.
    let params: Vec<usize> = (0..header.len())
        .filter(|&i| {
            let n = header[i];
            !(n.ends_with("__") || (long && (n == "chain" || n == "draw")))
        })
        .collect();
    if params.is_empty() {
        return Err(err(format!(
            "no parameter columns in the header ({})",
            header.join(",")
        ))
        .at_line(header_line));
    }
    for (k, &i) in params.iter().enumerate() {
        if params[..k].iter().any(|&j| header[j] == header[i]) {
            return Err(err("parameter column appears twice".into())
                .at_line(header_line)
                .for_field(header[i]));
        }
    }
    let names: Vec<String> = params.iter().map(|&i| header[i].to_owned()).collect();

    // Chain label → (its last line, its parameter columns), in label order.
    let mut by_chain: BTreeMap<i64, (usize, Vec<Vec<f64>>)> = BTreeMap::new();
    let mut last_line = header_line;
    for entry in table::lines(&text) {
        let (line, cells) = match entry {
            Line::Cells { line, cells } if line != header_line => (line, cells),
            Line::Cells { .. } => continue,
            Line::Comment(comment) => {
                // CmdStan with save_warmup writes the warm-up draws first and marks the end of
                // adaptation with this comment; only the draws after it are the posterior.
                if !long && comment.starts_with("Adaptation terminated") {
                    by_chain.clear();
                }
                continue;
            }
        };
        if cells.len() != header.len() {
            let e = err(format!(
                "{} cells, but the header has {} columns",
                cells.len(),
                header.len()
            ))
            .at_line(line);
            return Err(match header.get(cells.len()) {
                Some(missing) => e.for_field(*missing),
                None => e,
            });
        }
        let label = match chain_col {
            Some(c) => {
                parse_chain(cells[c]).map_err(|m| err(m).at_line(line).for_field("chain"))?
            }
            None => 0,
        };
        let (last, columns) = by_chain
            .entry(label)
            .or_insert_with(|| (line, vec![Vec::new(); params.len()]));
        *last = line;
        for (column, &i) in columns.iter_mut().zip(&params) {
            let v = table::parse_number(cells[i])
                .map_err(|m| err(m).at_line(line).for_field(header[i]))?;
            column.push(v);
        }
        last_line = line;
    }
    if by_chain.is_empty() {
        return Err(err("no draws after the header".into()).at_line(last_line));
    }
    Ok(by_chain
        .into_iter()
        .map(|(label, (last, columns))| ChainRead {
            file: path.to_path_buf(),
            label: long.then(|| label.to_string()),
            header_line,
            last_line: last,
            names: names.clone(),
            columns,
        })
        .collect())
}

/// A chain label: an integer, possibly written as a float by a dataframe library ("1.0").
fn parse_chain(cell: &str) -> Result<i64, String> {
    if let Ok(c) = cell.parse::<i64>() {
        return Ok(c);
    }
    match cell.parse::<f64>() {
        Ok(c) if c.fract() == 0.0 && c.abs() < 1e15 => Ok(c as i64),
        _ => Err(format!(
            "chain label '{}' is not an integer",
            table::truncate(cell, 40)
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_labels_are_integers_however_written() {
        assert_eq!(parse_chain("3"), Ok(3));
        assert_eq!(parse_chain("2.0"), Ok(2));
        assert!(parse_chain("1.5").is_err());
        assert!(parse_chain("nan").is_err());
        assert!(parse_chain("1e300").is_err());
    }

    #[test]
    fn names_that_would_not_read_back_are_refused() {
        let dir = std::env::temp_dir().join(format!("motorcal-draws-{}", std::process::id()));
        let path = dir.join("never.csv");
        for names in [
            vec![],
            vec!["a,b"],
            vec!["lp__"],
            vec!["a", "a"],
            vec![" a"],
        ] {
            let names: Vec<String> = names.into_iter().map(String::from).collect();
            assert!(
                CmdStanWriter::create(&path, &[], &names).is_err(),
                "{names:?}"
            );
        }
        assert!(!path.exists());
    }
}
