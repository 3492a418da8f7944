//! `--param NAME=VALUE` (issue 39): values for a grammar's `param` declarations, given to
//! `clayc check`, `build`, `run`, `render` and `export`. The flag only reads the pair; whether
//! the grammar has such a parameter and whether the value is in its range is the compiler's
//! judgement (E070, E071), reported as every other diagnostic is.

use std::path::Path;

use clay_dsl::CompileOptions;
use clay_dsl::compiled::{CompiledGrammar, ParamValue};

/// The `--param` flag, flattened into each subcommand's arguments.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ParamArgs {
    /// Set a grammar parameter (`param NAME ... = ...`) to a number, `true` or `false` (a
    /// `bool`) or a choice's name; repeatable, the last value of a name counts. A name the
    /// grammar does not declare (E070), a value outside its range (E071) or of another type
    /// (E073: 2.5 for an `int`) is an error.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    pub params: Vec<(String, ParamValue)>,
}

impl ParamArgs {
    /// The compile options that set these parameters (the file system as loader).
    pub fn options(&self) -> CompileOptions<'static> {
        CompileOptions {
            params: self.params.clone(),
            ..CompileOptions::default()
        }
    }

    /// Whether no parameter was given.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }
}

/// `NAME=VALUE`, a name and a value: a finite number, `true`, `false` or a choice's name (its
/// type is the grammar's to check). clap names the flag in its message.
pub fn parse_param(s: &str) -> Result<(String, ParamValue), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found `{s}` (no `=`)"))?;
    let (name, value) = (name.trim(), value.trim());
    let is_name = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !is_name {
        return Err(format!(
            "`{name}` is not a parameter name (letters, digits and `_`, not starting with a digit)"
        ));
    }
    if value.is_empty() {
        return Err(format!(
            "{name}=: the value must be a number, `true` or `false`, or a choice's name"
        ));
    }
    let parsed = ParamValue::parse(value);
    if parsed.number().is_some_and(|n| !n.is_finite()) {
        return Err(format!("{name}={value}: the value must be a finite number"));
    }
    Ok((name.to_string(), parsed))
}

/// Compiles the grammar `source` (the file `path`) with these parameters, printing its
/// diagnostics; on errors gives the exit code 1.
pub fn compile(source: &str, path: &Path, params: &ParamArgs) -> Result<CompiledGrammar, u8> {
    let name = path.display().to_string();
    // Colour only on a terminal that has not opted out.
    let color = std::io::IsTerminal::is_terminal(&std::io::stderr())
        && std::env::var_os("NO_COLOR").is_none();
    match clay_dsl::compile(source, &name, &params.options()) {
        Ok(compiled) => {
            err!(
                "{}",
                clay_dsl::render(&compiled.warnings, source, &name, color)
            );
            Ok(compiled.grammar)
        }
        Err(diagnostics) => {
            err!("{}", clay_dsl::render(&diagnostics, source, &name, color));
            Err(1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::parse_param;

    #[test]
    fn a_pair_is_read_and_mistakes_say_what_is_wrong() {
        assert_eq!(parse_param("bays=8"), Ok(("bays".to_string(), 8.0.into())));
        assert_eq!(
            parse_param(" w = -1.5e0 "),
            Ok(("w".to_string(), (-1.5).into()))
        );
        // A bool and a choice are read as typed; the grammar judges their types (E073).
        assert_eq!(
            parse_param("towers=false"),
            Ok(("towers".to_string(), false.into()))
        );
        assert_eq!(
            parse_param("wall=brick"),
            Ok(("wall".to_string(), "brick".into()))
        );
        assert!(parse_param("bays").unwrap_err().contains("no `=`"));
        assert!(
            parse_param("=3")
                .unwrap_err()
                .contains("not a parameter name")
        );
        assert!(
            parse_param("2x=3")
                .unwrap_err()
                .contains("not a parameter name")
        );
        assert!(
            parse_param("bays=")
                .unwrap_err()
                .contains("must be a number")
        );
        assert!(parse_param("bays=inf").unwrap_err().contains("finite"));
        assert!(parse_param("bays=NaN").unwrap_err().contains("finite"));
    }
}
