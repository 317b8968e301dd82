//! Which parameter a name means: a base parameter of the motor (`R`, `c_g`, …) or a key of a
//! physics term (`coulomb_friction.T_c`). Model files, reports and draws spell it as text; the
//! library holds it as this type, so that the spelling is written and read in one place.

use std::convert::Infallible;
use std::fmt;
use std::str::FromStr;

/// A parameter's identity. Its text (`Display`, [`ParamId::parse`]) is the model file's:
/// the base parameter's key, or `term.key`.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ParamId {
    /// A parameter of the base model, by its key (`R`, `J`, `c_g`).
    Base(String),
    /// A parameter a physics term adds.
    Term { term: String, key: String },
}

impl ParamId {
    /// A base parameter, by its key.
    pub fn base(key: impl Into<String>) -> Self {
        ParamId::Base(key.into())
    }

    /// The parameter `key` of the term `term`.
    pub fn of_term(term: impl Into<String>, key: impl Into<String>) -> Self {
        ParamId::Term {
            term: term.into(),
            key: key.into(),
        }
    }

    /// The identity a name spells: `term.key` (split at its first dot) or a base key. Every
    /// text is some identity; whether the model has it is for the model to say.
    pub fn parse(name: &str) -> Self {
        match name.split_once('.') {
            Some((term, key)) => Self::of_term(term, key),
            None => Self::base(name),
        }
    }

    /// The term the parameter belongs to (`None` for a base parameter).
    pub fn term(&self) -> Option<&str> {
        match self {
            ParamId::Base(_) => None,
            ParamId::Term { term, .. } => Some(term),
        }
    }

    /// The parameter's own key: the base key, or the key within its term.
    pub fn key(&self) -> &str {
        match self {
            ParamId::Base(key) | ParamId::Term { key, .. } => key,
        }
    }

    /// Whether the parameter belongs to the term `term`.
    pub fn is_of(&self, term: &str) -> bool {
        self.term() == Some(term)
    }

    /// The name in draws files: ArviZ reads a dot as an array index, so a term's parameter
    /// `coulomb_friction.T_c` is written `coulomb_friction__T_c`; base names are unchanged.
    pub fn column_name(&self) -> String {
        match self {
            ParamId::Base(key) => key.clone(),
            ParamId::Term { term, key } => format!("{term}__{key}"),
        }
    }
}

impl fmt::Display for ParamId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamId::Base(key) => f.write_str(key),
            ParamId::Term { term, key } => write!(f, "{term}.{key}"),
        }
    }
}

impl FromStr for ParamId {
    type Err = Infallible;

    fn from_str(name: &str) -> Result<Self, Infallible> {
        Ok(Self::parse(name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_text_of_an_identity_reads_back_as_it() {
        for (text, id, column) in [
            ("R", ParamId::base("R"), "R"),
            (
                "coulomb_friction.T_c",
                ParamId::of_term("coulomb_friction", "T_c"),
                "coulomb_friction__T_c",
            ),
        ] {
            assert_eq!(ParamId::parse(text), id);
            assert_eq!(text.parse::<ParamId>(), Ok(id.clone()));
            assert_eq!(id.to_string(), text);
            assert_eq!(id.column_name(), column);
        }
        let t = ParamId::parse("load_step.t_s");
        assert_eq!((t.term(), t.key()), (Some("load_step"), "t_s"));
        assert!(t.is_of("load_step") && !t.is_of("load"));
        let r = ParamId::parse("R");
        assert_eq!((r.term(), r.key()), (None, "R"));
    }
}
