//! Sculpting scripts (issue 3): the JSON script format and its validation, with messages that
//! name the offending step (its index, kind and line/column in the file). A script is replayed
//! by [`crate::session::replay`].

use glam::DVec2;
use serde_json::Value;

use crate::assembly::Compass;
use clay_dsl::MAX_COORDINATE;

/// Largest frame count a single step may ask for (keeps a typo from running for hours).
pub const MAX_FRAMES: u64 = 100_000;

/// How a step picks what to hold: an instance (piece element), e.g. one brick of a wall, not
/// the two-element stretch part around it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Selector {
    /// The instance whose centroid is nearest the point.
    At(DVec2),
    /// The instance with the vertex reaching furthest in a compass direction.
    Extreme(Compass),
}

/// Where a drag takes the current handle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// Move by this offset.
    By(DVec2),
    /// Move the handle's centroid to this point.
    To(DVec2),
}

/// One step of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// Make the selected instance the current handle (releasing the previous grab; pins stay).
    Grab(Selector),
    /// Fix the selected instance where it is.
    Pin(Selector),
    /// Let go of the pin on the selected instance (the one it picks must be pinned).
    Unpin(Selector),
    /// Move the current handle linearly over `frames` frames (0: jump, no frame).
    Drag { motion: Motion, frames: u64 },
    /// Turn the current handle about its centroid over `frames` frames.
    Rotate { degrees: f64, frames: u64 },
    /// Let go of the current handle (pins stay).
    Release,
    /// Run frames without moving anything.
    Hold { frames: u64 },
    /// The next frame's passes stop after at most `pass1` and `pass2` iterations: an
    /// editor's time budget stopped that frame there (its report's `pass1_iterations` and
    /// `l2_iterations`), so its replay stops there too. Runs no frame itself; a budget never
    /// adds iterations to what the solver's settings allow.
    Budget { pass1: u64, pass2: u64 },
    /// Cut the connection nearest the point (needs the rules hook).
    Cut { at: DVec2 },
}

/// A parsed script.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    pub steps: Vec<Step>,
    /// The grammar parameters the gestures were made with (`"params": {"bays": 6}`), when
    /// the script says: a gesture grabs what is under a point, so on a model of other counts
    /// it grabs something else and folds the model ([`Script::check_params`]).
    pub params: std::collections::BTreeMap<String, clay_dsl::compiled::ParamValue>,
}

/// A malformed script: which step (if any), where it is and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct ScriptError {
    /// Index of the offending step in `steps`, `None` for the document as a whole.
    pub step: Option<usize>,
    pub message: String,
    /// 1-based line and column of the offending step (of the JSON syntax error), when known.
    pub position: Option<(usize, usize)>,
    /// What to do about it, when there is more to say than the message.
    pub hint: Option<String>,
}

impl std::fmt::Display for ScriptError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.step {
            Some(i) => write!(f, "step {i}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for ScriptError {}

impl ScriptError {
    /// The message for the script at `path`: `error: FILE:LINE:COLUMN: step N: ...` and, when
    /// there is one, its hint on a second line (`  = help: ...`).
    pub fn located(&self, path: &std::path::Path) -> String {
        let at = match self.position {
            Some((line, column)) => format!("{}:{line}:{column}", path.display()),
            None => path.display().to_string(),
        };
        match &self.hint {
            Some(hint) => format!("error: {at}: {self}\n  = help: {hint}"),
            None => format!("error: {at}: {self}"),
        }
    }
}

/// What is wrong with one step, before it is tied to its index and position.
struct Fault {
    message: String,
    hint: Option<String>,
}

impl From<String> for Fault {
    fn from(message: String) -> Self {
        Self {
            message,
            hint: None,
        }
    }
}

impl From<&str> for Fault {
    fn from(message: &str) -> Self {
        message.to_string().into()
    }
}

fn number(v: &Value, what: &str) -> Result<f64, String> {
    match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        _ => Err(format!("{what} must be a finite number, found {v}")),
    }
}

/// A coordinate: a finite number within +/-[`MAX_COORDINATE`] metres, like grammar coordinates
/// (E013), so that no later computation can overflow.
fn coordinate(v: &Value, what: &str) -> Result<f64, Fault> {
    let x = number(v, what)?;
    if x.abs() > MAX_COORDINATE {
        return Err(Fault {
            message: format!("{what}: coordinate {x:e} is outside +/-{MAX_COORDINATE:e} m"),
            hint: Some(format!(
                "script coordinates are metres and must lie within +/-{MAX_COORDINATE:e}, as in grammars (E013)"
            )),
        });
    }
    Ok(x)
}

fn point(v: &Value, what: &str) -> Result<DVec2, Fault> {
    match v.as_array().map(Vec::as_slice) {
        Some([x, y]) => Ok(DVec2::new(coordinate(x, what)?, coordinate(y, what)?)),
        _ => Err(format!("{what} must be an array of two numbers [x, y], found {v}").into()),
    }
}

fn frames(obj: &serde_json::Map<String, Value>, kind: &str) -> Result<u64, String> {
    count(obj, kind, "frames")
}

/// The whole number `obj[key]`, from 0 to [`MAX_FRAMES`].
fn count(obj: &serde_json::Map<String, Value>, kind: &str, key: &str) -> Result<u64, String> {
    let v = obj
        .get(key)
        .ok_or_else(|| format!("{kind} needs \"{key}\""))?;
    match v.as_u64() {
        Some(n) if n <= MAX_FRAMES => Ok(n),
        _ => Err(format!(
            "{kind}: \"{key}\" must be an integer from 0 to {MAX_FRAMES}, found {v}"
        )),
    }
}

fn object<'a>(v: &'a Value, kind: &str) -> Result<&'a serde_json::Map<String, Value>, String> {
    v.as_object()
        .ok_or_else(|| format!("{kind} takes an object, found {v}"))
}

fn only_keys(
    obj: &serde_json::Map<String, Value>,
    kind: &str,
    allowed: &[&str],
) -> Result<(), String> {
    for k in obj.keys() {
        if !allowed.contains(&k.as_str()) {
            return Err(format!(
                "{kind}: unknown field \"{k}\" (expected {})",
                allowed.join(", ")
            ));
        }
    }
    Ok(())
}

fn selector(v: &Value, kind: &str) -> Result<Selector, Fault> {
    let obj = object(v, kind)?;
    match (obj.get("at"), obj.get("extreme"), obj.len()) {
        (Some(at), None, 1) => Ok(Selector::At(point(at, &format!("{kind}: \"at\""))?)),
        (None, Some(dir), 1) => match dir.as_str() {
            Some("east") => Ok(Selector::Extreme(Compass::East)),
            Some("west") => Ok(Selector::Extreme(Compass::West)),
            Some("north") => Ok(Selector::Extreme(Compass::North)),
            Some("south") => Ok(Selector::Extreme(Compass::South)),
            _ => Err(format!(
                "{kind}: \"extreme\" must be \"east\", \"west\", \"north\" or \"south\", found {dir}"
            )
            .into()),
        },
        _ => Err(format!(
            "{kind} takes {{\"at\": [x, y]}} or {{\"extreme\": \"east\"|\"west\"|\"north\"|\"south\"}}"
        )
        .into()),
    }
}

fn step(v: &Value) -> Result<Step, Fault> {
    let obj = v
        .as_object()
        .ok_or_else(|| format!("a step must be an object, found {v}"))?;
    if obj.len() != 1 {
        return Err(format!(
            "a step must have exactly one key (grab, pin, unpin, drag, rotate, release, hold, budget, cut), found {}",
            if obj.is_empty() {
                "none".to_string()
            } else {
                obj.keys().cloned().collect::<Vec<_>>().join(", ")
            }
        )
        .into());
    }
    let (kind, body) = obj.iter().next().ok_or("empty step")?;
    match kind.as_str() {
        "grab" => Ok(Step::Grab(selector(body, "grab")?)),
        "pin" => Ok(Step::Pin(selector(body, "pin")?)),
        "unpin" => Ok(Step::Unpin(selector(body, "unpin")?)),
        "drag" => {
            let o = object(body, "drag")?;
            only_keys(o, "drag", &["by", "to", "frames"])?;
            let motion = match (o.get("by"), o.get("to")) {
                (Some(by), None) => Motion::By(point(by, "drag: \"by\"")?),
                (None, Some(to)) => Motion::To(point(to, "drag: \"to\"")?),
                _ => return Err("drag needs exactly one of \"by\" or \"to\"".into()),
            };
            Ok(Step::Drag {
                motion,
                frames: frames(o, "drag")?,
            })
        }
        "rotate" => {
            let o = object(body, "rotate")?;
            only_keys(o, "rotate", &["degrees", "frames"])?;
            let degrees = number(
                o.get("degrees").ok_or("rotate needs \"degrees\"")?,
                "rotate: \"degrees\"",
            )?;
            Ok(Step::Rotate {
                degrees,
                frames: frames(o, "rotate")?,
            })
        }
        "release" => {
            let o = object(body, "release")?;
            only_keys(o, "release", &[])?;
            Ok(Step::Release)
        }
        "hold" => {
            let o = object(body, "hold")?;
            only_keys(o, "hold", &["frames"])?;
            Ok(Step::Hold {
                frames: frames(o, "hold")?,
            })
        }
        "budget" => {
            let o = object(body, "budget")?;
            only_keys(o, "budget", &["pass1", "pass2"])?;
            Ok(Step::Budget {
                pass1: count(o, "budget", "pass1")?,
                pass2: count(o, "budget", "pass2")?,
            })
        }
        "cut" => {
            let o = object(body, "cut")?;
            only_keys(o, "cut", &["at"])?;
            Ok(Step::Cut {
                at: point(o.get("at").ok_or("cut needs \"at\"")?, "cut: \"at\"")?,
            })
        }
        other => Err(format!(
            "unknown step \"{other}\" (expected grab, pin, unpin, drag, rotate, release, hold, budget or cut)"
        )
        .into()),
    }
}

impl Step {
    /// Parses and validates one step, as a script's `"steps"` holds it (`{"drag": {"by":
    /// [1, 0], "frames": 10}}`): what a binding builds for a step given as a call. The error
    /// has no step index or position.
    pub fn from_json(value: &Value) -> Result<Self, ScriptError> {
        step(value).map_err(|fault| ScriptError {
            step: None,
            message: fault.message,
            position: None,
            hint: fault.hint,
        })
    }
}

impl Script {
    /// Parses and validates a script; every error names the step index, its line and column
    /// and what is wrong.
    pub fn parse(json: &str) -> Result<Self, ScriptError> {
        if json.trim().is_empty() {
            return Err(ScriptError {
                step: None,
                message: "the script is empty: expected {\"steps\": [...]}".into(),
                position: Some((1, 1)),
                hint: None,
            });
        }
        let doc: Value = serde_json::from_str(json).map_err(json_error)?;
        // an error about the document is placed where it is: its first token, or the key or
        // value it is about (issue 47: they had no line and column)
        let keys = top_level_keys(json);
        let start = json.len() - json.trim_start().len();
        let whole = |message: String, at: usize| ScriptError {
            step: None,
            message,
            position: Some(clay_dsl::line_col(json, at)),
            hint: None,
        };
        let obj = doc.as_object().ok_or_else(|| {
            whole(
                "the script must be an object {\"steps\": [...]}".into(),
                start,
            )
        })?;
        if let Some(k) = obj.keys().find(|k| *k != "steps" && *k != "params") {
            let at = keys
                .iter()
                .find(|(name, ..)| name == k)
                .map_or(start, |k| k.1);
            return Err(whole(
                format!("unknown top-level field \"{k}\" (expected \"steps\" or \"params\")"),
                at,
            ));
        }
        let mut params = std::collections::BTreeMap::new();
        if let Some(v) = obj.get("params") {
            let at = keys
                .iter()
                .find(|(name, ..)| name == "params")
                .map_or(start, |k| k.2);
            let table = v.as_object().ok_or_else(|| {
                whole(
                    "\"params\" must be an object of parameter names to values".into(),
                    at,
                )
            })?;
            for (name, value) in table {
                use clay_dsl::compiled::ParamValue;
                let typed = match value {
                    Value::Number(_) => value
                        .as_f64()
                        .filter(|x| x.is_finite())
                        .map(ParamValue::Number),
                    Value::Bool(b) => Some(ParamValue::Bool(*b)),
                    Value::String(t) => Some(ParamValue::Text(t.clone())),
                    _ => None,
                };
                let Some(typed) = typed else {
                    return Err(whole(
                        format!(
                            "\"params\": {name} must be a finite number, true or false, or a choice in quotes; found {value}"
                        ),
                        at,
                    ));
                };
                params.insert(name.clone(), typed);
            }
        }
        let value_at = keys
            .iter()
            .find(|(name, ..)| name == "steps")
            .map_or(start, |k| k.2);
        let steps = obj
            .get("steps")
            .ok_or_else(|| whole("the script needs \"steps\": [...]".into(), start))?
            .as_array()
            .ok_or_else(|| whole("\"steps\" must be an array".into(), value_at))?;
        let steps = steps
            .iter()
            .enumerate()
            .map(|(i, v)| {
                step(v).map_err(|fault| ScriptError {
                    step: Some(i),
                    message: fault.message,
                    position: step_offsets(json)
                        .get(i)
                        .map(|&at| clay_dsl::line_col(json, at)),
                    hint: fault.hint,
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(Self { steps, params })
    }

    /// Whether the script may replay on `grammar`: every parameter it says it was made with
    /// has that value there. A gesture is recorded as points and offsets; on a model of other
    /// counts it grabs another part and folds the model (issue 48: Blender's Reload did), so a
    /// script that says its parameters refuses any other values, in words with what to do.
    pub fn check_params(
        &self,
        grammar: &clay_dsl::compiled::CompiledGrammar,
    ) -> Result<(), String> {
        let differ: Vec<String> = (self.params.iter())
            .filter_map(
                |(name, recorded)| match grammar.params.iter().find(|p| p.name == *name) {
                    Some(p) if p.value == *recorded => None,
                    Some(p) => Some(format!("{name} = {recorded} (the grammar has {})", p.value)),
                    None => Some(format!(
                        "{name} = {recorded} (the grammar has no such parameter)"
                    )),
                },
            )
            .collect();
        if differ.is_empty() {
            return Ok(());
        }
        let with: Vec<String> = (self.params.iter())
            .map(|(n, v)| format!("--param {n}={v}"))
            .collect();
        Err(format!(
            "the script was recorded with {}: its gestures would grab other parts of this model; compile the grammar with its values ({}), or record the gestures again",
            differ.join(", "),
            with.join(" ")
        ))
    }

    /// Total solver frames the script runs.
    pub fn frame_count(&self) -> u64 {
        self.steps
            .iter()
            .map(|s| match s {
                Step::Drag { frames, .. } | Step::Rotate { frames, .. } | Step::Hold { frames } => {
                    *frames
                }
                _ => 0,
            })
            .sum()
    }
}

impl Step {
    /// The step as a script holds it: the inverse of [`Step::from_json`] (numbers written so
    /// they read back bit for bit).
    pub fn to_json(&self) -> Value {
        use serde_json::json;
        let point = |p: DVec2| json!([p.x, p.y]);
        let selector = |s: &Selector| match s {
            Selector::At(p) => json!({"at": point(*p)}),
            Selector::Extreme(dir) => json!({"extreme": match dir {
                Compass::East => "east",
                Compass::West => "west",
                Compass::North => "north",
                Compass::South => "south",
            }}),
        };
        match self {
            Step::Grab(s) => json!({"grab": selector(s)}),
            Step::Pin(s) => json!({"pin": selector(s)}),
            Step::Unpin(s) => json!({"unpin": selector(s)}),
            Step::Drag {
                motion: Motion::By(d),
                frames,
            } => json!({"drag": {"by": point(*d), "frames": frames}}),
            Step::Drag {
                motion: Motion::To(p),
                frames,
            } => json!({"drag": {"to": point(*p), "frames": frames}}),
            Step::Rotate { degrees, frames } => {
                json!({"rotate": {"degrees": degrees, "frames": frames}})
            }
            Step::Release => json!({"release": {}}),
            Step::Hold { frames } => json!({"hold": {"frames": frames}}),
            Step::Budget { pass1, pass2 } => json!({"budget": {"pass1": pass1, "pass2": pass2}}),
            Step::Cut { at } => json!({"cut": {"at": point(*at)}}),
        }
    }
}

impl Script {
    /// The script as JSON text, one step a line (`{"steps": [` ... `]}`), which
    /// [`Script::parse`] reads back as this script.
    pub fn to_json(&self) -> String {
        let steps: Vec<String> = self.steps.iter().map(|s| s.to_json().to_string()).collect();
        let params = if self.params.is_empty() {
            String::new()
        } else {
            let table: serde_json::Map<String, Value> = (self.params.iter())
                .map(|(n, v)| (n.clone(), serde_json::to_value(v).unwrap_or(Value::Null)))
                .collect();
            format!("\"params\": {}, ", Value::Object(table))
        };
        if steps.is_empty() {
            return format!("{{{params}\"steps\": []}}\n");
        }
        format!("{{{params}\"steps\": [\n  {}\n]}}\n", steps.join(",\n  "))
    }
}

/// A JSON syntax error at its 1-based line and column. serde_json counts a position at the
/// start of a line as column 0, and its message ends with that position, which the error
/// carries apart.
fn json_error(e: serde_json::Error) -> ScriptError {
    let text = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let what = text.strip_suffix(&suffix).unwrap_or(&text);
    ScriptError {
        step: None,
        message: format!("the script is not valid JSON: {what}"),
        position: (e.line() > 0).then(|| (e.line(), e.column().max(1))),
        hint: None,
    }
}

/// Byte offsets where the elements of the top-level `"steps"` array of valid JSON start (of the
/// last such array, as serde_json keeps the last of repeated keys).
/// The keys of the top-level object of `json` (valid JSON), each with the offsets of its
/// opening quote and of its value's first byte. A key written with escapes is not recognised
/// (its error is then placed at the document's start).
fn top_level_keys(json: &str) -> Vec<(String, usize, usize)> {
    let bytes = json.as_bytes();
    let (mut keys, mut depth, mut i) = (Vec::new(), 0usize, 0usize);
    // the last string at depth 1 and where it began, until a `:` makes it a key
    let mut string: Option<(usize, usize)> = None;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                let start = i;
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                if depth == 1 {
                    string = Some((start, i.min(bytes.len())));
                }
            }
            b':' if depth == 1 => {
                if let Some((start, end)) = string.take() {
                    let value = i + 1 + json[i + 1..].len() - json[i + 1..].trim_start().len();
                    keys.push((json[start + 1..end].to_string(), start, value));
                }
            }
            b'[' | b'{' => depth += 1,
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    keys
}

fn step_offsets(json: &str) -> Vec<usize> {
    let bytes = json.as_bytes();
    let (mut offsets, mut depth, mut i) = (Vec::new(), 0usize, 0usize);
    let mut last_string: (usize, usize) = (0, 0);
    // Depth inside the steps array while scanning it; an element starts at the next token.
    let mut in_steps: Option<usize> = None;
    let mut element_next = false;
    while i < bytes.len() {
        let b = bytes[i];
        if b.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if element_next && b != b']' {
            offsets.push(i);
        }
        element_next = false;
        match b {
            b'"' => {
                let start = i + 1;
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                if depth == 1 {
                    last_string = (start, i.min(bytes.len()));
                }
            }
            b'[' | b'{' => {
                depth += 1;
                let key = &bytes[last_string.0..last_string.1];
                if b == b'[' && depth == 2 && in_steps.is_none() && key == b"steps" {
                    offsets.clear();
                    in_steps = Some(depth);
                    element_next = true;
                }
            }
            b']' | b'}' => {
                if in_steps == Some(depth) {
                    in_steps = None;
                }
                depth = depth.saturating_sub(1);
            }
            b',' if in_steps == Some(depth) => element_next = true,
            _ => {}
        }
        i += 1;
    }
    offsets
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_written_as_json_reads_back_as_itself() {
        let script = Script {
            steps: vec![
                Step::Pin(Selector::Extreme(Compass::West)),
                Step::Grab(Selector::At(DVec2::new(0.1 + 0.2, -1.0 / 3.0))),
                Step::Drag {
                    motion: Motion::By(DVec2::new(1e-17, 4.0)),
                    frames: 1,
                },
                Step::Drag {
                    motion: Motion::To(DVec2::new(-2.5, 1e9)),
                    frames: 0,
                },
                Step::Rotate {
                    degrees: -(std::f64::consts::PI.to_degrees()),
                    frames: 3,
                },
                Step::Hold { frames: MAX_FRAMES },
                Step::Release,
                Step::Unpin(Selector::Extreme(Compass::North)),
                Step::Pin(Selector::Extreme(Compass::South)),
                Step::Grab(Selector::Extreme(Compass::East)),
                Step::Cut {
                    at: DVec2::new(6.0, 0.0),
                },
            ],
            ..Script::default()
        };
        let text = script.to_json();
        assert_eq!(Script::parse(&text), Ok(script.clone()), "{text}");
        assert_eq!(
            text.lines().count(),
            script.steps.len() + 2,
            "one step a line"
        );
        assert_eq!(
            Script::parse(&Script::default().to_json()),
            Ok(Script::default())
        );
    }

    #[test]
    fn the_parameters_a_script_says_read_back_and_refuse_other_values() {
        let mut script = Script::parse("{\"steps\": [{\"hold\": {\"frames\": 2}}]}").unwrap();
        assert!(script.params.is_empty());
        script.params.insert("bays".into(), 6.0.into());
        script.params.insert("width".into(), 1.5.into());
        let text = script.to_json();
        assert!(
            text.starts_with("{\"params\": {\"bays\":6.0,\"width\":1.5}, "),
            "{text}"
        );
        assert_eq!(Script::parse(&text), Ok(script.clone()));
        // Against a grammar: the same values pass; another value, or a name it lacks, refuses
        // with the values to use.
        let source = "param bays = 4 in 2..12\nparam width = 1 in 0.5..2\nsite type j\n\
                      piece b { vertex a (0, 0) vertex c (width, 0) vertex d (width, 1) edges a-c-d-a }\n\
                      model { x = b }\n";
        let compile = |bays: f64, width: f64| {
            let options = clay_dsl::CompileOptions::default()
                .param("bays", bays)
                .param("width", width);
            clay_dsl::compile(source, "g.clay", &options)
                .unwrap()
                .grammar
        };
        assert_eq!(script.check_params(&compile(6.0, 1.5)), Ok(()));
        let why = script.check_params(&compile(4.0, 1.5)).unwrap_err();
        assert!(why.contains("bays = 6 (the grammar has 4)"), "{why}");
        assert!(why.contains("--param bays=6 --param width=1.5"), "{why}");
        script.params.insert("height".into(), 2.0.into());
        let why = script.check_params(&compile(6.0, 1.5)).unwrap_err();
        assert!(
            why.contains("height = 2 (the grammar has no such parameter)"),
            "{why}"
        );
        // A script that says nothing replays anywhere.
        assert_eq!(Script::default().check_params(&compile(4.0, 1.0)), Ok(()));
        // What is not a table of finite numbers is refused where it is.
        for bad in [
            "{\"params\": [1], \"steps\": []}",
            "{\"params\": {\"bays\": null}, \"steps\": []}",
        ] {
            let e = Script::parse(bad).unwrap_err();
            assert_eq!(e.position, Some((1, 12)), "{bad}: {e}");
            assert!(e.message.starts_with("\"params\""), "{e}");
        }
    }

    #[test]
    fn an_empty_or_blank_script_is_reported_at_line_1_column_1() {
        for text in ["", "  \n\t\n"] {
            let e = Script::parse(text).unwrap_err();
            assert_eq!(e.position, Some((1, 1)), "{text:?}");
            assert_eq!(e.step, None);
            assert_eq!(
                e.message, "the script is empty: expected {\"steps\": [...]}",
                "{text:?}"
            );
        }
    }

    /// Issue 47: errors about the document as a whole had no line and column.
    #[test]
    fn errors_about_the_document_are_placed_at_what_they_are_about() {
        for (text, at, message) in [
            ("\n  [1, 2]", (2, 3), "must be an object"),
            (
                "{\n  \"steps\": [],\n  \"extra\": 1\n}",
                (3, 3),
                "\"extra\"",
            ),
            ("{\"é\": 0,\n \"stepz\": []}", (2, 2), "\"stepz\""),
            ("{\n\"steps\":\n    3}", (3, 5), "must be an array"),
            ("  {}", (1, 3), "needs \"steps\""),
        ] {
            let e = Script::parse(text).unwrap_err();
            assert_eq!(e.position, Some(at), "{text:?}: {e:?}");
            assert!(e.message.contains(message), "{text:?}: {e:?}");
        }
    }

    #[test]
    fn a_json_error_at_the_start_of_a_line_is_at_column_1() {
        // serde_json says "line 2 column 0" for the end of this text.
        let e = Script::parse("{\"steps\": [\n").unwrap_err();
        assert_eq!(e.position, Some((2, 1)), "{e:?}");
        assert_eq!(
            e.message, "the script is not valid JSON: EOF while parsing a list",
            "{e:?}"
        );
    }
}
