//! Solver settings by name (`clayc run --set NAME=VALUE`, the Python package's
//! `Session(grammar, **settings)`): the names, their ranges, and a grammar's `solver` block
//! overridden by them. One definition, so every front end checks the same ranges.

use clay_dsl::compiled::CompiledGrammar;

use crate::solver::{SolverConfig, SolverKind};

/// Every setting's name, in the order the messages list them.
pub const SETTING_NAMES: [&str; 9] = [
    "hysteresis",
    "norm",
    "irls_epsilon",
    "merge_distance",
    "irls_iterations",
    "l2_iterations",
    "l2_anderson",
    "handle_weight",
    "solver",
];

/// Applies one setting, checking the name and the range. Messages start with `NAME=VALUE:`
/// (or `NAME:` for an unknown name); front ends prefix them with how the setting was given.
pub fn apply_setting(
    config: &mut SolverConfig,
    merge_distance: &mut f64,
    name: &str,
    value: &str,
) -> Result<(), String> {
    let (name, value) = (name.trim(), value.trim());
    if name == "solver" {
        config.kind = match value {
            "cholesky" => SolverKind::Cholesky,
            "cg" => SolverKind::Cg,
            _ => return Err(format!("solver={value}: expected cholesky or cg")),
        };
        return Ok(());
    }
    if !SETTING_NAMES.contains(&name) {
        let (last, rest) = SETTING_NAMES.split_last().unwrap_or((&"", &[]));
        return Err(format!(
            "{name}: unknown parameter (expected {} or {last})",
            rest.join(", ")
        ));
    }
    let number: f64 = value
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
        .ok_or_else(|| format!("{name}={value}: the value must be a finite number"))?;
    let check = |ok: bool, range: &str| {
        if ok {
            Ok(())
        } else {
            Err(format!("{name}={value}: must be {range}"))
        }
    };
    let count = |x: f64| x.fract() == 0.0 && (0.0..=1000.0).contains(&x);
    match name {
        "hysteresis" => {
            check((0.0..1.0).contains(&number), "in [0, 1)")?;
            config.hysteresis = number;
        }
        "norm" => {
            check(number > 0.0 && number <= 2.0, "in (0, 2]")?;
            config.norm = number;
        }
        "irls_epsilon" => {
            check(number > 0.0 && number <= 1.0, "in (0, 1]")?;
            config.irls_epsilon = number;
        }
        "merge_distance" => {
            check(number >= 0.0, "at least 0")?;
            *merge_distance = number;
        }
        "irls_iterations" => {
            check(count(number), "an integer from 0 to 1000")?;
            config.irls_iterations = number as usize;
        }
        "l2_iterations" => {
            check(count(number), "an integer from 0 to 1000")?;
            config.l2_iterations = number as usize;
        }
        "l2_anderson" => {
            check(
                number.fract() == 0.0 && (0.0..=16.0).contains(&number),
                "an integer from 0 to 16",
            )?;
            config.l2_anderson = number as usize;
        }
        _ => {
            check((1.0..=1e12).contains(&number), "in [1, 1e12]")?;
            config.handle_weight = number;
        }
    }
    Ok(())
}

/// The solver settings of a session on `grammar`: its `solver` block with `settings`
/// (name, value) applied in order; the overridden grammar parameters are written back into
/// the grammar, which the rules read. The first bad setting is the error.
pub fn configure<'a>(
    grammar: &mut CompiledGrammar,
    settings: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> Result<SolverConfig, String> {
    let mut config = SolverConfig::from_params(&grammar.solver);
    let mut merge_distance = grammar.solver.merge_distance;
    for (name, value) in settings {
        apply_setting(&mut config, &mut merge_distance, name, value)?;
    }
    grammar.solver.hysteresis = config.hysteresis;
    grammar.solver.norm = config.norm;
    grammar.solver.irls_epsilon = config.irls_epsilon;
    grammar.solver.merge_distance = merge_distance;
    Ok(config)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_checked_by_name_and_range() {
        let source =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/grammars/wall.clay"))
                .unwrap();
        let mut grammar = clay_dsl::compile(&source, "wall.clay").unwrap().grammar;
        let config = configure(&mut grammar, [("norm", "2"), ("merge_distance", "0.3")]).unwrap();
        assert_eq!(config.norm, 2.0);
        assert_eq!(grammar.solver.norm, 2.0);
        assert_eq!(grammar.solver.merge_distance, 0.3);
        let e = configure(&mut grammar, [("hysteresis", "1")]).unwrap_err();
        assert_eq!(e, "hysteresis=1: must be in [0, 1)");
        let e = configure(&mut grammar, [("nrom", "1")]).unwrap_err();
        assert!(
            e.starts_with("nrom: unknown parameter (expected hysteresis, norm,"),
            "{e}"
        );
        assert!(e.ends_with("handle_weight or solver)"), "{e}");
        let e = configure(&mut grammar, [("norm", "NaN")]).unwrap_err();
        assert_eq!(e, "norm=NaN: the value must be a finite number");
    }
}
