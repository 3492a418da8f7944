//! The solver settings, one table: each setting's name, range, default and meaning. The
//! compiler checks a grammar's `solver { }` block against it; `clayc --set`, sessions, the
//! editor's sliders and the Python package check what they are given against it (through
//! `clay::apply_setting`); docs/language.md and docs/scripts.md list it, and a test compares
//! them with it. One truth per setting.

/// What values a setting takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// A finite number from `lo` to `hi` (`hi` may be infinite); with `open_lo` (`open_hi`)
    /// the bound itself is out.
    Number {
        lo: f64,
        hi: f64,
        open_lo: bool,
        open_hi: bool,
    },
    /// A whole number from 0 to `max`.
    Count { max: u32 },
    /// One of the words.
    Word(&'static [&'static str]),
}

impl Range {
    /// Whether the number `x` is in the range (never for a [`Range::Word`]).
    pub fn allows(&self, x: f64) -> bool {
        match *self {
            Range::Number {
                lo,
                hi,
                open_lo,
                open_hi,
            } => {
                x.is_finite()
                    && if open_lo { x > lo } else { x >= lo }
                    && if open_hi { x < hi } else { x <= hi }
            }
            Range::Count { max } => x.fract() == 0.0 && (0.0..=f64::from(max)).contains(&x),
            Range::Word(_) => false,
        }
    }

    /// The range in words, as the compiler says it: "at least 0 and below 1".
    pub fn words(&self) -> String {
        match *self {
            Range::Number {
                lo,
                hi,
                open_lo,
                open_hi,
            } => {
                let low = format!("{} {}", if open_lo { "above" } else { "at least" }, num(lo));
                if hi.is_infinite() {
                    low
                } else {
                    let high = format!("{} {}", if open_hi { "below" } else { "at most" }, num(hi));
                    format!("{low} and {high}")
                }
            }
            Range::Count { max } => format!("a whole number from 0 to {max}"),
            Range::Word(words) => either(words),
        }
    }

    /// The range as an interval, as `--set` and the docs' tables say it: "in [0, 1)".
    pub fn interval(&self) -> String {
        match *self {
            Range::Number {
                lo, hi, open_lo, ..
            } if hi.is_infinite() => {
                format!("{} {}", if open_lo { "above" } else { "at least" }, num(lo))
            }
            Range::Number {
                lo,
                hi,
                open_lo,
                open_hi,
            } => format!(
                "in {}{}, {}{}",
                if open_lo { '(' } else { '[' },
                num(lo),
                num(hi),
                if open_hi { ')' } else { ']' }
            ),
            Range::Count { max } => format!("an integer from 0 to {max}"),
            Range::Word(words) => either(words),
        }
    }
}

/// A setting's default: a number, or one of its words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Default {
    Number(f64),
    Word(&'static str),
}

impl Default {
    /// The number (0 for a word).
    pub fn number(&self) -> f64 {
        match *self {
            Default::Number(x) => x,
            Default::Word(_) => 0.0,
        }
    }
}

impl std::fmt::Display for Default {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Default::Number(x) => f.write_str(&num(x)),
            Default::Word(w) => f.write_str(w),
        }
    }
}

/// One solver setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    pub name: &'static str,
    pub range: Range,
    pub default: Default,
    /// Whether a grammar's `solver { }` block may set it (else only a session: `--set`, the
    /// editor, Python).
    pub in_grammar: bool,
    pub meaning: &'static str,
}

/// Every solver setting, in the order messages and docs list them.
pub const SETTINGS: [Setting; 9] = [
    Setting {
        name: "hysteresis",
        range: Range::Number {
            lo: 0.0,
            hi: 1.0,
            open_lo: false,
            open_hi: true,
        },
        default: Default::Number(0.15),
        in_grammar: true,
        meaning: "a part switches to a nearer rest state only when it is this fraction closer (paper 4.3)",
    },
    Setting {
        name: "norm",
        range: Range::Number {
            lo: 0.0,
            hi: 2.0,
            open_lo: true,
            open_hi: false,
        },
        default: Default::Number(0.5),
        in_grammar: true,
        meaning: "the exponent p of pass 1's sub-quadratic norm (paper 5.2); 2 is plain least squares",
    },
    Setting {
        name: "irls_epsilon",
        range: Range::Number {
            lo: 0.0,
            hi: 1.0,
            open_lo: true,
            open_hi: false,
        },
        default: Default::Number(0.001),
        in_grammar: true,
        meaning: "the epsilon in pass 1's IRLS weight 1 / (abs(r) + epsilon)^(2 - p)",
    },
    Setting {
        name: "merge_distance",
        range: Range::Number {
            lo: 0.0,
            hi: f64::INFINITY,
            open_lo: false,
            open_hi: false,
        },
        default: Default::Number(0.5),
        in_grammar: true,
        meaning: "how close (metres) a free site must come to a compatible one to merge (0: never by distance alone)",
    },
    Setting {
        name: "irls_iterations",
        range: Range::Count { max: 1000 },
        default: Default::Number(5.0),
        in_grammar: false,
        meaning: "most pass-1 (IRLS) iterations per frame (a pass stops earlier once converged)",
    },
    Setting {
        name: "l2_iterations",
        range: Range::Count { max: 1000 },
        default: Default::Number(5.0),
        in_grammar: false,
        meaning: "most pass-2 iterations per frame (stops earlier once converged; 0 shows pass 1's pose)",
    },
    Setting {
        name: "l2_anderson",
        range: Range::Count { max: 16 },
        default: Default::Number(1.0),
        in_grammar: false,
        meaning: "how many past iterates pass 2's Anderson acceleration mixes (0: the plain local/global iteration)",
    },
    Setting {
        name: "handle_weight",
        range: Range::Number {
            lo: 1.0,
            hi: 1e12,
            open_lo: false,
            open_hi: false,
        },
        default: Default::Number(1e6),
        in_grammar: false,
        meaning: "handle weight relative to the mean edge weight",
    },
    Setting {
        name: "solver",
        range: Range::Word(&["cholesky", "cg"]),
        default: Default::Word("cholesky"),
        in_grammar: false,
        meaning: "linear solver of the global step",
    },
];

/// The setting called `name`.
pub fn setting(name: &str) -> Option<&'static Setting> {
    SETTINGS.iter().find(|s| s.name == name)
}

/// The names a grammar's `solver { }` block takes.
pub fn grammar_names() -> impl Iterator<Item = &'static str> {
    SETTINGS.iter().filter(|s| s.in_grammar).map(|s| s.name)
}

/// A number as the docs write it: `0.15`, `1e6`, `1e12`.
fn num(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e5 || x.abs() < 1e-4) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn either(words: &[&str]) -> String {
    match words.split_last() {
        Some((last, [])) => (*last).to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_say_what_they_allow() {
        let h = setting("hysteresis").unwrap().range;
        assert!(h.allows(0.0) && !h.allows(1.0) && !h.allows(f64::NAN));
        assert_eq!(h.words(), "at least 0 and below 1");
        assert_eq!(h.interval(), "in [0, 1)");
        let m = setting("merge_distance").unwrap().range;
        assert!(m.allows(0.0) && m.allows(1e9) && !m.allows(f64::INFINITY) && !m.allows(-1.0));
        assert_eq!(m.interval(), "at least 0");
        let c = setting("l2_anderson").unwrap().range;
        assert!(c.allows(16.0) && !c.allows(17.0) && !c.allows(1.5));
        assert_eq!(
            setting("handle_weight").unwrap().range.interval(),
            "in [1, 1e12]"
        );
        assert_eq!(setting("solver").unwrap().range.words(), "cholesky or cg");
        for s in SETTINGS {
            let ok = match (s.range, s.default) {
                (Range::Word(w), Default::Word(d)) => w.contains(&d),
                (r, Default::Number(x)) => r.allows(x),
                _ => false,
            };
            assert!(ok, "{}'s default is out of its range", s.name);
        }
    }
}
