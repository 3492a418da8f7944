//! A grammar compiles with every value of its switches: after the compilation a user asked
//! for, each other value of each `bool` and `choice` parameter is compiled once more (the
//! others as given), and its errors join the result, each saying which value shows it.
//!
//! Architecture Invariant: a grammar that compiles, compiles with every value of every `bool`
//! and `choice` parameter taken one at a time; so switching one in the editor, Python or
//! Blender never turns a working model into an error. (Combinations of several switches are
//! not tried: their number grows as a product.)

use crate::compiled::{Param, ParamKind, ParamValue};
use crate::diagnostic::Diagnostics;

/// At most this many other values are compiled: a grammar with more switch values is checked
/// for the first ones only (each compilation costs about what the first did).
const MAX_OTHER_VALUES: usize = 32;

/// The errors of each other switch value of the grammar whose parameters compiled as
/// `declared` with the values `params` (each compiled by `compile`, which gives its
/// diagnostics when it fails), each with a hint naming the value; one per mistake.
pub(super) fn other_value_errors(
    declared: &[Param],
    params: &[(String, ParamValue)],
    compile: impl Fn(&[(String, ParamValue)]) -> Option<Diagnostics>,
) -> Diagnostics {
    let mut others: Vec<(String, ParamValue)> = Vec::new();
    for p in declared {
        match &p.kind {
            ParamKind::Bool => {
                let on = p.value == ParamValue::Bool(true);
                others.push((p.name.clone(), ParamValue::Bool(!on)));
            }
            ParamKind::Choice { choices } => others.extend(
                (choices.iter())
                    .filter(|c| p.value.text() != Some(c.as_str()))
                    .map(|c| (p.name.clone(), ParamValue::Text(c.clone()))),
            ),
            _ => {}
        }
    }
    let mut found = Diagnostics::new();
    for (name, value) in others.into_iter().take(MAX_OTHER_VALUES) {
        let mut values = params.to_vec();
        values.push((name.clone(), value.clone()));
        let Some(diags) = compile(&values) else {
            continue;
        };
        let shown = match &value {
            ParamValue::Text(t) => format!("\"{t}\""),
            v => v.to_string(),
        };
        for mut d in diags.items.into_iter().filter(|d| d.is_error()) {
            let seen = found.items.iter().any(|f| {
                f.code == d.code && f.primary.span == d.primary.span && f.message == d.message
            });
            if seen {
                continue;
            }
            d.hints.insert(
                0,
                format!(
                    "this happens with `{name}` set to {shown}: a grammar must compile with \
                     every value of its `bool` and `choice` parameters"
                ),
            );
            found.push(d);
        }
        if found.sources.is_empty() {
            found.sources = diags.sources;
        }
    }
    found
}
