//! A grammar parameter as the compiled grammar lists it: its type ([`ParamKind`]) and values
//! ([`ParamValue`]), which scripts, sessions, the command line and the editor share.

use serde::{Deserialize, Serialize};

/// A grammar parameter (`param NAME [: TYPE] = DEFAULT [in LO..HI]`): a value the grammar
/// uses and a user may set when compiling it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Param {
    pub name: String,
    /// Absent in JSON for a number (so files from before types read as numbers).
    #[serde(default, skip_serializing_if = "ParamKind::is_number")]
    pub kind: ParamKind,
    /// The value this grammar was compiled with: the override given, else the default.
    pub value: ParamValue,
    /// The value written in the grammar.
    pub default: ParamValue,
    /// The inclusive range `[low, high]` of allowed values of a number, `int` or `seed`, when
    /// the grammar declares one; without one, any finite number (any whole one, any whole one
    /// from 0) is allowed.
    pub range: Option<[f64; 2]>,
}

/// The type of a grammar parameter (docs/language.md, "Parameters").
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum ParamKind {
    /// Any finite number (no type written, or `: number`).
    #[default]
    Number,
    /// A whole number (`: int`).
    Int,
    /// On or off (`: bool`): switches `if NAME { ... }` blocks of the model.
    Bool,
    /// A whole number from 0 (`: seed`) that shuffles the variants of the model's chains.
    Seed,
    /// One of the named pieces (`: choice("a", "b")`), used where a piece's name goes.
    Choice { choices: Vec<String> },
}

impl ParamKind {
    /// The type as written after the colon (`number` for an untyped parameter).
    pub fn word(&self) -> &'static str {
        match self {
            ParamKind::Number => "number",
            ParamKind::Int => "int",
            ParamKind::Bool => "bool",
            ParamKind::Seed => "seed",
            ParamKind::Choice { .. } => "choice",
        }
    }

    /// The type with its article, as messages say it: a `bool`, an `int`.
    pub fn with_article(&self) -> String {
        let article = if *self == ParamKind::Int { "an" } else { "a" };
        format!("{article} `{}`", self.word())
    }

    /// Whether it is a plain number (no type, or `: number`).
    pub fn is_number(&self) -> bool {
        *self == ParamKind::Number
    }

    /// Whether its values are numbers (a number, `int` or `seed`).
    pub fn is_numeric(&self) -> bool {
        matches!(self, ParamKind::Number | ParamKind::Int | ParamKind::Seed)
    }

    /// Whether its values are whole numbers (`int` or `seed`).
    pub fn is_whole(&self) -> bool {
        matches!(self, ParamKind::Int | ParamKind::Seed)
    }
}

/// A parameter's value: a number (of a number, `int` or `seed`), on or off (`bool`) or the
/// name of a choice. In JSON (scripts, sessions) a number, `true`/`false` or a string.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    Number(f64),
    Bool(bool),
    Text(String),
}

impl ParamValue {
    /// A value typed on a command line (`--param NAME=VALUE`): a number when it reads as one,
    /// `true` or `false` as on or off, else the text (a choice). The grammar checks its type.
    pub fn parse(text: &str) -> Self {
        let t = text.trim();
        match t {
            "true" => ParamValue::Bool(true),
            "false" => ParamValue::Bool(false),
            _ => t
                .parse::<f64>()
                .map_or_else(|_| ParamValue::Text(t.to_string()), ParamValue::Number),
        }
    }

    /// The number, when it is one.
    pub fn number(&self) -> Option<f64> {
        match self {
            ParamValue::Number(v) => Some(*v),
            _ => None,
        }
    }

    /// On or off, when it is one.
    pub fn bool(&self) -> Option<bool> {
        match self {
            ParamValue::Bool(b) => Some(*b),
            _ => None,
        }
    }

    /// The choice's name, when it is one.
    pub fn text(&self) -> Option<&str> {
        match self {
            ParamValue::Text(t) => Some(t),
            _ => None,
        }
    }
}

/// As a user types it: `6`, `1.5`, `true`, `brick`.
impl std::fmt::Display for ParamValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamValue::Number(v) => f.write_str(&crate::format::format_number(*v)),
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::Text(t) => f.write_str(t),
        }
    }
}

/// A number equals the number it holds (tests and callers compare with plain numbers).
impl PartialEq<f64> for ParamValue {
    fn eq(&self, other: &f64) -> bool {
        self.number() == Some(*other)
    }
}

impl From<f64> for ParamValue {
    fn from(v: f64) -> Self {
        ParamValue::Number(v)
    }
}

impl From<bool> for ParamValue {
    fn from(b: bool) -> Self {
        ParamValue::Bool(b)
    }
}

impl From<&str> for ParamValue {
    fn from(t: &str) -> Self {
        ParamValue::Text(t.to_string())
    }
}

impl From<String> for ParamValue {
    fn from(t: String) -> Self {
        ParamValue::Text(t)
    }
}
