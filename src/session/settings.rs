//! Solver settings by name (`clayc run --set NAME=VALUE`, the Python package's
//! `Session(grammar, **settings)`): the names, their ranges, and a grammar's `solver` block
//! overridden by them. One definition, so every front end checks the same ranges.

use clay_dsl::compiled::CompiledGrammar;

use crate::solver::{SolverConfig, SolverKind};

/// Every setting's name, in the order the messages list them (`clay_dsl::settings`, the one
/// table of names, ranges and defaults).
pub const SETTING_NAMES: [&str; 9] = {
    let mut names = [""; 9];
    let mut k = 0;
    while k < 9 {
        names[k] = clay_dsl::settings::SETTINGS[k].name;
        k += 1;
    }
    names
};

/// Applies one setting, checking the name and the range (the one table,
/// `clay_dsl::settings`). Messages start with `NAME=VALUE:` (or `NAME:` for an unknown name);
/// front ends prefix them with how the setting was given.
pub fn apply_setting(
    config: &mut SolverConfig,
    merge_distance: &mut f64,
    name: &str,
    value: &str,
) -> Result<(), String> {
    let (name, value) = (name.trim(), value.trim());
    let Some(setting) = clay_dsl::settings::setting(name) else {
        let (last, rest) = SETTING_NAMES.split_last().unwrap_or((&"", &[]));
        return Err(format!(
            "{name}: unknown parameter (expected {} or {last})",
            rest.join(", ")
        ));
    };
    let range = setting.range;
    if let clay_dsl::settings::Range::Word(words) = range {
        if !words.contains(&value) {
            return Err(format!("{name}={value}: expected {}", range.words()));
        }
        config.kind = if value == "cg" {
            SolverKind::Cg
        } else {
            SolverKind::Cholesky
        };
        return Ok(());
    }
    let number: f64 = value
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
        .ok_or_else(|| format!("{name}={value}: the value must be a finite number"))?;
    if !range.allows(number) {
        return Err(format!("{name}={value}: must be {}", range.interval()));
    }
    match name {
        "hysteresis" => config.hysteresis = number,
        "norm" => config.norm = number,
        "irls_epsilon" => config.irls_epsilon = number,
        "merge_distance" => *merge_distance = number,
        "irls_iterations" => config.irls_iterations = number as usize,
        "l2_iterations" => config.l2_iterations = number as usize,
        "l2_anderson" => config.l2_anderson = number as usize,
        _ => config.handle_weight = number,
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
        let mut grammar =
            clay_dsl::compile(&source, "wall.clay", &clay_dsl::CompileOptions::default())
                .unwrap()
                .grammar;
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
