//! The example grammars whose curved rest states are now derived (`state left bend 90`,
//! `state right mirror left`) compile to what their hand-computed versions compiled to. The
//! hand-computed files are kept as they were in tests/fixtures/before/.
//!
//! Tolerances: the old files wrote the bent coordinates rounded to 6 significant digits (1.27324,
//! 0.173808), so a bent coordinate there is off the exact arc by up to 5e-6 m; those (the
//! positions and geometry of the derived states, in the pieces and in the model's parts) are
//! compared within 1e-5. Everything else (the base state, its geometry, sites, edges, the solver
//! values, the placed model) was never rounded and is compared within 1e-9. The bent geometry
//! must also have exactly as many points as the hand-computed one: both cut a quarter turn into
//! 16 straight pieces.

use clay_dsl::{CompileOptions, compile};
use serde_json::Value;

/// Coordinates of derived states compared this loosely (see the module comment).
const ROUNDED: f64 = 1e-5;
/// Everything else.
const EXACT: f64 = 1e-9;

fn compiled(path: &str) -> Value {
    let dir = env!("CARGO_MANIFEST_DIR");
    let src = std::fs::read_to_string(format!("{dir}/{path}")).unwrap();
    let mut g = compile(&src, "grammar.clay", &CompileOptions::default())
        .unwrap_or_else(|d| panic!("{path} does not compile: {d:?}"))
        .grammar;
    g.source = String::new();
    serde_json::to_value(&g).unwrap()
}

/// Walks both values in step; `loose` is true below a rest state named in `derived`.
fn compare(old: &Value, new: &Value, path: &str, loose: bool, derived: &[&str], worst: &mut f64) {
    match (old, new) {
        (Value::Number(a), Value::Number(b)) => {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            let tol = if loose { ROUNDED } else { EXACT };
            assert!((a - b).abs() <= tol, "{path}: {a} vs {b} (tolerance {tol})");
            if loose {
                *worst = worst.max((a - b).abs());
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            assert_eq!(a.len(), b.len(), "{path}: lengths differ");
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                compare(x, y, &format!("{path}[{i}]"), loose, derived, worst);
            }
        }
        (Value::Object(a), Value::Object(b)) => {
            let keys = |m: &serde_json::Map<String, Value>| m.keys().cloned().collect::<Vec<_>>();
            assert_eq!(keys(a), keys(b), "{path}: fields differ");
            let is_derived = a
                .get("name")
                .and_then(Value::as_str)
                .is_some_and(|n| derived.contains(&n))
                && a.contains_key("positions");
            for (k, x) in a {
                let loose = loose || is_derived;
                compare(x, &b[k], &format!("{path}.{k}"), loose, derived, worst);
            }
        }
        _ => assert_eq!(old, new, "{path}"),
    }
}

fn same_as_before(name: &str, derived: &[&str]) {
    let old = compiled(&format!("tests/fixtures/before/{name}.clay"));
    let new = compiled(&format!("grammars/{name}.clay"));
    let mut worst = 0.0;
    compare(&old, &new, name, false, derived, &mut worst);
    // The derived states were really compared, and really differ only by the rounding.
    assert!(
        worst > 0.0 && worst < 5.1e-6,
        "{name}: worst difference {worst}"
    );
}

fn source(path: &str) -> String {
    std::fs::read_to_string(format!("{}/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

#[test]
fn bend_clay_derives_the_hand_computed_quarter_turns() {
    same_as_before("bend", &["left", "right"]);
    let text = source("grammars/bend.clay");
    assert!(text.contains("state left bend 90") && text.contains("state right mirror left"));
    assert!(
        !text.contains("1.77324"),
        "hand-computed coordinates are gone"
    );
}

#[test]
fn streets_clay_derives_the_hand_computed_quarter_turns() {
    same_as_before("streets", &["left", "right"]);
    let text = source("grammars/streets.clay");
    assert!(text.contains("state left bend 90") && text.contains("state right mirror left"));
    assert!(
        !text.contains("1.77324"),
        "hand-computed coordinates are gone"
    );
}
