//! `clay.Session`: a sculpting session on a grammar's model, the script vocabulary as methods
//! (each builds the script step `clayc run` would parse and runs it through
//! `clay::Session::step`), and what the session has made: its summary, positions,
//! instances, rule log, exports and pictures.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyString};
use serde_json::{Value, json};

use clay::{
    Assembly, ExportFileError, ExportFormat, ExportOptions, HandleKind, Overlays, RenderOptions,
    Script, Step, configure, scene,
};
use clay_dsl::compiled::CompiledGrammar;

use crate::convert::{
    finite, guard, integer, is_bool, number, os_error, path_of, point, type_name,
};
use crate::grammar::Grammar;
use crate::{InternalError, ScriptParamsError, SolverError};

/// Largest picture side, as `clayc render --size` allows.
const MAX_SIDE: u32 = clay::MAX_SIDE;

/// The overlays `render_png` draws, as `clayc render --overlay` names them.
const OVERLAYS: [&str; 5] = ["graph", "sites", "strain", "handles", "states"];

struct State {
    asm: Assembly,
    session: clay::Session,
    /// Steps run so far by calls (the index notes name).
    steps: usize,
}

/// A sculpting session on a grammar's model: the solver, the rules, the grab and pins.
///
/// `Session(grammar, **solver_settings)` takes `clayc run --set`'s settings as keywords
/// (`hysteresis`, `norm`, `irls_epsilon`, `merge_distance`, `irls_iterations`,
/// `l2_iterations`, `l2_anderson`, `handle_weight`, `solver="cholesky"|"cg"`). The methods are
/// the script vocabulary of docs/scripts.md; each runs like the same step of `clayc run`.
#[pyclass(module = "clay", name = "Session", frozen)]
pub struct PySession {
    /// The grammar with the session's solver settings written into its `solver` block.
    grammar: Arc<CompiledGrammar>,
    state: Mutex<State>,
}

/// One instance of a piece in the model.
#[pyclass(module = "clay", name = "Instance", frozen, get_all)]
#[derive(Clone)]
pub struct PyInstance {
    /// Stable identity: survives the rules that keep the instance.
    pub id: u64,
    /// The model's name (`wall[3]`) or a generated one for an inserted instance (`wall#12`).
    pub name: String,
    pub piece: String,
    /// The active rest state's name.
    pub state: String,
    /// The stretch chain the instance is an element of, by the name every export gives it
    /// (`wall_n`, as `SceneNode.chain`), or `None`.
    pub chain: Option<String>,
    /// The instance's place in its chain (0 first), or `None`.
    pub index: Option<usize>,
    /// Global vertex indices (rows of `Session.positions`), one per piece vertex.
    pub vertices: Vec<usize>,
    /// The mean of its vertices' positions, in metres.
    pub centroid: (f64, f64),
}

#[pymethods]
impl PyInstance {
    fn __repr__(&self) -> String {
        format!(
            "Instance({}, piece={}, state={})",
            self.name, self.piece, self.state
        )
    }
}

/// A rule that fired: its kind (`replace`, `stretch`, `shrink`, `merge`, `cut`), the frame
/// after which it ran, where (metres), the stable ids of the instances involved and a
/// sentence in the grammar's names.
#[pyclass(module = "clay", name = "RuleEvent", frozen, get_all)]
#[derive(Clone)]
pub struct PyRuleEvent {
    pub kind: String,
    pub frame: u64,
    pub at: (f64, f64),
    pub instances: Vec<u64>,
    pub detail: String,
}

#[pymethods]
impl PyRuleEvent {
    fn __repr__(&self) -> String {
        format!("RuleEvent({}: {})", self.kind, self.detail)
    }

    fn __str__(&self) -> String {
        self.detail.clone()
    }
}

/// Triangles of one colour of one instance, flat-shaded, in metres with z up (x east,
/// y north, z the height `clayc export` gives).
#[pyclass(module = "clay", name = "Primitive", frozen, get_all)]
pub struct PyPrimitive {
    /// The fill colour, sRGB bytes (r, g, b, a).
    pub colour: (u8, u8, u8, u8),
    /// Its material's name in every export and the Blender add-on (`fill_9a958cff`).
    pub material: String,
    /// float32 array of shape (n, 3).
    pub positions: Py<PyAny>,
    /// uint32 array of shape (m, 3): the triangles' corners, counter-clockwise seen from
    /// outside.
    pub triangles: Py<PyAny>,
    /// float32 array of shape (n, 2): each position's planar texture coordinates in metres,
    /// v up (a face looking up is mapped from above, x and y; a wall along itself, v its
    /// height), as the USD and OBJ exports have them (the glTF's with v turned).
    pub uvs: Py<PyAny>,
}

#[pymethods]
impl PyPrimitive {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let rows = |a: &Py<PyAny>| -> PyResult<usize> { a.bind(py).len() };
        let (r, g, b, a) = self.colour;
        Ok(format!(
            "Primitive(#{r:02x}{g:02x}{b:02x}{a:02x}, {} vertices, {} triangles)",
            rows(&self.positions)?,
            rows(&self.triangles)?
        ))
    }
}

/// One instance's 3D meshes, as `clayc export` writes its node: the same name, pivot, turn
/// and local geometry.
#[pyclass(module = "clay", frozen, get_all)]
pub struct SceneNode {
    /// The export's node name: letters, digits and `_`, unique (`wall_n_4`, `gate_0`).
    pub name: String,
    /// The instance's name in the model (`wall[3]`, `wall#12`), as `Session.instances` has it.
    pub instance: String,
    pub piece: String,
    pub state: String,
    pub id: u64,
    /// The stretch chain's name in the export (`wall_n`), or `None`.
    pub chain: Option<String>,
    /// The instance's place in that chain (0 at its `from` end), or `None`.
    pub index: Option<usize>,
    /// Where the node stands (x, y) in metres: the centroid of the instance's vertices.
    pub pivot: (f64, f64),
    /// The node's turn about the vertical, radians, counter-clockwise seen from above.
    pub rotation: f64,
    /// The shared mesh's name (`brick__rest`): nodes with the same mesh have the same
    /// primitives, `None` for an instance without geometry.
    pub mesh: Option<String>,
    /// In the node's frame: a point `p` of a primitive is at `pivot + R(rotation) p[:2]`,
    /// height `p[2]`.
    pub primitives: Vec<Py<PyPrimitive>>,
}

#[pymethods]
impl SceneNode {
    fn __repr__(&self) -> String {
        format!(
            "SceneNode({}, {} primitives)",
            self.name,
            self.primitives.len()
        )
    }
}

/// A solver setting's value as `--set` would spell it: a string as it is, an integer (numpy's
/// too) in digits, another number as Rust writes an `f64` (it reads back as the same number).
fn setting_value(name: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    if value.is_instance_of::<PyString>() {
        return value.extract();
    }
    let what = format!("solver setting {name}");
    if let Some(n) = integer(value, &what)? {
        return Ok(n.to_string());
    }
    number(value, &what).map(|x| format!("{x:?}")).map_err(|e| {
        if is_bool(value) {
            e
        } else {
            PyTypeError::new_err(format!(
                "{what} must be a number (or \"cholesky\"/\"cg\" for solver), found {}",
                type_name(value)
            ))
        }
    })
}

/// A frame count or other number for a JSON step: ints stay ints (as JSON has them), floats
/// must be finite; the step's own check says what is allowed.
fn json_number(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Value> {
    match integer(value, what)? {
        Some(n) => Ok(Value::from(n)),
        None => finite(number(value, what)?, what),
    }
}

/// The selector of a grab, pin or unpin: exactly one of `at=(x, y)` and `extreme=`.
fn selector(
    kind: &str,
    at: Option<&Bound<'_, PyAny>>,
    extreme: Option<&Bound<'_, PyAny>>,
) -> PyResult<Value> {
    match (at, extreme) {
        (Some(at), None) => Ok(json!({ "at": point(at, &format!("{kind}: at"))? })),
        (None, Some(dir)) => {
            let dir: String = dir.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "{kind}: extreme must be \"east\", \"west\", \"north\" or \"south\", found {}",
                    type_name(dir)
                ))
            })?;
            Ok(json!({ "extreme": dir }))
        }
        _ => Err(PyTypeError::new_err(format!(
            "{kind} takes at=(x, y) or extreme=\"east\"|\"west\"|\"north\"|\"south\" (one of them)"
        ))),
    }
}

fn none_if_none<'a, 'py>(v: Option<&'a Bound<'py, PyAny>>) -> Option<&'a Bound<'py, PyAny>> {
    v.filter(|v| !v.is_none())
}

/// A step parsed as a script's would be, its error a `ValueError`.
fn parse_step(value: Value) -> PyResult<Step> {
    Step::from_json(&value).map_err(|e| {
        let mut message = e.to_string();
        if let Some(hint) = e.hint {
            message.push_str(&format!(" ({hint})"));
        }
        PyValueError::new_err(message)
    })
}

impl PySession {
    fn lock(&self) -> PyResult<MutexGuard<'_, State>> {
        self.state.lock().map_err(|_| {
            InternalError::new_err(
                "this session stopped at an internal error in an earlier call; start a new one",
            )
        })
    }

    /// Runs steps without the GIL. Notes name a script's steps by their index in the script,
    /// a call's by how many steps the session ran before it.
    fn run_steps(&self, py: Python<'_>, steps: &[Step], from_script: bool) -> PyResult<()> {
        py.detach(|| {
            guard("a step", || {
                let mut st = self.lock()?;
                let State {
                    asm,
                    session,
                    steps: done,
                } = &mut *st;
                for (k, step) in steps.iter().enumerate() {
                    let index = if from_script { k } else { *done };
                    *done += 1;
                    session
                        .step(asm, index, step)
                        .map_err(|e| SolverError::new_err(format!("step {index}: {e}")))?;
                }
                Ok(())
            })
        })
    }

    fn step(&self, py: Python<'_>, value: Value) -> PyResult<()> {
        let step = parse_step(value)?;
        self.run_steps(py, &[step], false)
    }
}

fn events(log: &[clay::RuleEvent]) -> Vec<PyRuleEvent> {
    log.iter()
        .map(|e| PyRuleEvent {
            kind: e.kind.name().to_string(),
            frame: e.frame,
            at: (e.at.x, e.at.y),
            instances: e.instances.clone(),
            detail: e.detail.clone(),
        })
        .collect()
}

#[pymethods]
impl PySession {
    #[new]
    #[pyo3(signature = (grammar, **solver_settings))]
    fn new(
        py: Python<'_>,
        grammar: &Bound<'_, Grammar>,
        solver_settings: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut settings = Vec::new();
        for (k, v) in solver_settings.into_iter().flatten() {
            let name: String = k.extract()?;
            let value = setting_value(&name, &v)?;
            settings.push((name, value));
        }
        let compiled = grammar.get().compiled.clone();
        py.detach(|| {
            guard("starting the session", || {
                let mut grammar = CompiledGrammar::clone(&compiled);
                let config = configure(
                    &mut grammar,
                    settings.iter().map(|(n, v)| (n.as_str(), v.as_str())),
                )
                .map_err(|e| PyValueError::new_err(format!("solver setting {e}")))?;
                let grammar = Arc::new(grammar);
                let asm = Assembly::new(grammar.clone());
                if let Err(problems) = asm.validate() {
                    return Err(PyValueError::new_err(format!(
                        "the compiled assembly is inconsistent:\n  {}",
                        problems.join("\n  ")
                    )));
                }
                Ok(Self {
                    grammar,
                    state: Mutex::new(State {
                        asm,
                        session: clay::Session::new(config),
                        steps: 0,
                    }),
                })
            })
        })
    }

    /// Makes the instance at `at=(x, y)` (the one whose centroid is nearest) or the one
    /// reaching furthest `extreme="east"|"west"|"north"|"south"` the current grab, letting go
    /// of the previous one (pins stay). A pinned instance's pin gives way while it is held.
    #[pyo3(signature = (at = None, extreme = None))]
    fn grab(
        &self,
        py: Python<'_>,
        at: Option<&Bound<'_, PyAny>>,
        extreme: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let sel = selector("grab", none_if_none(at), none_if_none(extreme))?;
        self.step(py, json!({ "grab": sel }))
    }

    /// Pins the selected instance where it is (selected as in `grab`).
    #[pyo3(signature = (at = None, extreme = None))]
    fn pin(
        &self,
        py: Python<'_>,
        at: Option<&Bound<'_, PyAny>>,
        extreme: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let sel = selector("pin", none_if_none(at), none_if_none(extreme))?;
        self.step(py, json!({ "pin": sel }))
    }

    /// Lets go of the pin on the selected instance (selected as in `grab`).
    #[pyo3(signature = (at = None, extreme = None))]
    fn unpin(
        &self,
        py: Python<'_>,
        at: Option<&Bound<'_, PyAny>>,
        extreme: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let sel = selector("unpin", none_if_none(at), none_if_none(extreme))?;
        self.step(py, json!({ "unpin": sel }))
    }

    /// Moves the grab `by=(dx, dy)`, or its centroid `to=(x, y)`, linearly over `frames`
    /// solver frames (0: a jump, no frame).
    #[pyo3(signature = (by = None, to = None, frames = None))]
    fn drag(
        &self,
        py: Python<'_>,
        by: Option<&Bound<'_, PyAny>>,
        to: Option<&Bound<'_, PyAny>>,
        frames: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut body = serde_json::Map::new();
        match (none_if_none(by), none_if_none(to)) {
            (Some(by), None) => {
                body.insert("by".into(), point(by, "drag: by")?);
            }
            (None, Some(to)) => {
                body.insert("to".into(), point(to, "drag: to")?);
            }
            _ => {
                return Err(PyTypeError::new_err(
                    "drag takes by=(dx, dy) or to=(x, y) (one of them)",
                ));
            }
        }
        body.insert("frames".into(), frames_value(frames, "drag")?);
        self.step(py, json!({ "drag": body }))
    }

    /// Turns the grab about its centroid by `degrees` (counter-clockwise) over `frames`
    /// frames.
    #[pyo3(signature = (degrees, frames = None))]
    fn rotate(
        &self,
        py: Python<'_>,
        degrees: &Bound<'_, PyAny>,
        frames: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let degrees = json_number(degrees, "rotate: degrees")?;
        let frames = frames_value(frames, "rotate")?;
        self.step(
            py,
            json!({ "rotate": { "degrees": degrees, "frames": frames } }),
        )
    }

    /// Runs `frames` frames without moving anything.
    #[pyo3(signature = (frames = None))]
    fn hold(&self, py: Python<'_>, frames: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let frames = frames_value(frames, "hold")?;
        self.step(py, json!({ "hold": { "frames": frames } }))
    }

    /// Lets go of the grab (a grabbed pinned instance is pinned again where it is).
    fn release(&self, py: Python<'_>) -> PyResult<()> {
        self.step(py, json!({ "release": {} }))
    }

    /// Cuts the connection nearest `at=(x, y)` (the cut rule); a cut with nothing within reach
    /// does nothing and says so in `notes`.
    fn cut(&self, py: Python<'_>, at: &Bound<'_, PyAny>) -> PyResult<()> {
        let at = point(at, "cut: at")?;
        self.step(py, json!({ "cut": { "at": at } }))
    }

    /// Runs one sculpting frame (a solver frame, then the rules) and returns the rules that
    /// fired in it.
    fn frame(&self, py: Python<'_>) -> PyResult<Vec<PyRuleEvent>> {
        py.detach(|| {
            guard("a frame", || {
                let mut st = self.lock()?;
                let State { asm, session, .. } = &mut *st;
                let frame = session
                    .frame(asm)
                    .map_err(|e| SolverError::new_err(e.to_string()))?;
                Ok(events(&frame.events))
            })
        })
    }

    /// Runs a script: a path to a script file (JSON, docs/scripts.md) or the script itself as
    /// a dict (`{"steps": [...]}`). The whole script is checked before any step runs; a bad
    /// one raises `ValueError` naming the step, its line and column.
    fn run_script(&self, py: Python<'_>, script: &Bound<'_, PyAny>) -> PyResult<()> {
        let (text, name) = if script.is_instance_of::<PyDict>() || script.is_instance_of::<PyList>()
        {
            let dumps = py.import("json")?.getattr("dumps")?;
            let text: String = dumps.call1((script,))?.extract()?;
            (text, PathBuf::from("<script>"))
        } else {
            let path = path_of(script).map_err(|_| {
                PyTypeError::new_err(format!(
                    "run_script takes a path or a dict {{\"steps\": [...]}}, found {}",
                    type_name(script)
                ))
            })?;
            let text = clay_dsl::read_input_string(Path::new(&path), clay_dsl::MAX_SOURCE_BYTES)
                .map_err(|e| os_error(&e, Path::new(&path)))?;
            (text, path)
        };
        let script = Script::parse(&text).map_err(|e| {
            let message = e.located(&name);
            PyValueError::new_err(
                message
                    .strip_prefix("error: ")
                    .unwrap_or(&message)
                    .to_string(),
            )
        })?;
        script
            .check_params(&self.grammar)
            .map_err(|why| ScriptParamsError::new_err(format!("{}: {why}", name.display())))?;
        self.run_steps(py, &script.steps, true)
    }

    /// The summary of the session so far: the same dict `clayc run --json` prints (frames,
    /// vertices, parts, pieces, states, rules_fired, components, bbox, max_edge_strain,
    /// energy, frame_ms, finite).
    fn summary(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let text = py.detach(|| {
            guard("the summary", || {
                let st = self.lock()?;
                serde_json::to_string(&st.session.summary(&st.asm))
                    .map_err(|e| InternalError::new_err(e.to_string()))
            })
        })?;
        Ok(py
            .import("json")?
            .getattr("loads")?
            .call1((text,))?
            .unbind())
    }

    /// Every vertex position in metres: a numpy float64 array of shape (vertices, 2), a copy.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f64> = {
            let st = self.lock()?;
            st.asm
                .data()
                .positions
                .iter()
                .flat_map(|p| [p.x, p.y])
                .collect()
        };
        let n = flat.len() / 2;
        Ok(PyArray1::from_vec(py, flat).reshape([n, 2])?.into_any())
    }

    /// The model's instances (clay.Instance), in the assembly's order.
    #[getter]
    fn instances(&self) -> PyResult<Vec<PyInstance>> {
        let st = self.lock()?;
        let (grammar, data) = (st.asm.grammar(), st.asm.data());
        // The export's chain names and places (`clay::chain_places`): one vocabulary.
        let place = clay::chain_places(data);
        Ok(data
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let piece = grammar.pieces.get(inst.piece);
                let centroid = st
                    .asm
                    .instance_centroid(i)
                    .map_or((f64::NAN, f64::NAN), |c| (c.x, c.y));
                PyInstance {
                    id: inst.id,
                    name: inst.name.clone(),
                    piece: piece.map_or(String::new(), |p| p.name.clone()),
                    state: piece
                        .and_then(|p| p.states.get(inst.state))
                        .map_or(String::new(), |s| s.name.clone()),
                    chain: place.get(i).cloned().flatten().map(|p| p.name),
                    index: place.get(i).cloned().flatten().map(|p| p.index),
                    vertices: inst.vertices.clone(),
                    centroid,
                }
            })
            .collect())
    }

    /// Every rule that fired so far, in order (clay.RuleEvent).
    #[getter]
    fn rule_log(&self) -> PyResult<Vec<PyRuleEvent>> {
        Ok(events(self.lock()?.session.rule_log()))
    }

    /// Why steps did nothing (a grab that found no instance, a cut with nothing near), in
    /// order: what `clayc run` prints as notes.
    #[getter]
    fn notes(&self) -> PyResult<Vec<String>> {
        Ok(self.lock()?.session.notes().to_vec())
    }

    /// Solver frames run so far.
    #[getter]
    fn frames(&self) -> PyResult<usize> {
        Ok(self.lock()?.session.frame_ms().len())
    }

    /// The session's solver settings written into the grammar's `solver` block, as in
    /// `Grammar.solver`.
    #[getter]
    fn solver<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.grammar.solver;
        let d = PyDict::new(py);
        d.set_item("hysteresis", s.hysteresis)?;
        d.set_item("norm", s.norm)?;
        d.set_item("irls_epsilon", s.irls_epsilon)?;
        d.set_item("merge_distance", s.merge_distance)?;
        Ok(d)
    }

    /// Writes the model as 3D meshes, as `clayc export` does: `.glb` or `.gltf` (glTF 2.0),
    /// `.obj` (with its `.mtl` beside it), `.usda` (USD, Z up) or `.usdc` (USD's binary form,
    /// through usd-core's `pxr` when installed), by the path's extension. `thickness` is the height
    /// of flat proxy geometry in metres. Raises `ValueError` for another extension, `OSError`
    /// when the file cannot be written.
    #[pyo3(signature = (path, thickness = None))]
    fn export(
        &self,
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
        thickness: Option<f64>,
    ) -> PyResult<()> {
        let path = path_of(path)?;
        let options = export_options(thickness)?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("usdc"))
        {
            return self.export_usdc(py, &path, &options);
        }
        let Some(format) = ExportFormat::of_path(&path) else {
            return Err(PyValueError::new_err(format!(
                "cannot tell the format of `{}`: {}",
                path.display(),
                ExportFormat::unknown(&path)
            )));
        };
        self.write(py, &path, format, &options)
    }

    /// The model drawn as `clayc render` draws it: PNG bytes of `size=(width, height)`
    /// pixels. `overlays` names any of "graph", "sites", "strain", "handles", "states";
    /// `view="iso"` draws the isometric view of the 3D export instead (no overlays).
    #[pyo3(signature = (size = (1024, 768), overlays = None, view = "plan"))]
    fn render_png<'py>(
        &self,
        py: Python<'py>,
        size: (i64, i64),
        overlays: Option<Vec<String>>,
        view: &str,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let side = |n: i64| -> PyResult<u32> {
            u32::try_from(n)
                .ok()
                .filter(|n| (1..=MAX_SIDE).contains(n))
                .ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "size: {n} is not between 1 and {MAX_SIDE} pixels"
                    ))
                })
        };
        let (width, height) = (side(size.0)?, side(size.1)?);
        let overlays = overlays.unwrap_or_default();
        if let Some(bad) = overlays.iter().find(|o| !OVERLAYS.contains(&o.as_str())) {
            return Err(PyValueError::new_err(format!(
                "unknown overlay {bad:?} (expected {})",
                OVERLAYS.join(", ")
            )));
        }
        let iso = match view {
            "plan" => false,
            "iso" if overlays.is_empty() => true,
            "iso" => {
                return Err(PyValueError::new_err(
                    "the iso view has no overlays: drop overlays or use view=\"plan\"",
                ));
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "unknown view {view:?} (expected \"plan\" or \"iso\")"
                )));
            }
        };
        let png = py.detach(|| {
            guard("the picture", || {
                let st = self.lock()?;
                let data = st.asm.data();
                let result = if iso {
                    let scene = scene(&self.grammar, data, &ExportOptions::default());
                    clay::iso_pixmap(&scene, width, height).and_then(|p| {
                        p.encode_png()
                            .map_err(|e| clay::RenderError::Encode(e.to_string()))
                    })
                } else {
                    let has = |k: &str| overlays.iter().any(|o| o == k);
                    let held = |kind: HandleKind| -> Vec<usize> {
                        if !has("handles") {
                            return Vec::new();
                        }
                        (st.asm.handles().iter())
                            .filter(|h| h.kind() == kind)
                            .flat_map(|h| h.vertices().iter().copied())
                            .collect()
                    };
                    let options = RenderOptions {
                        width,
                        height,
                        overlays: Overlays {
                            part_graph: has("graph"),
                            sites: has("sites"),
                            strain: has("strain"),
                            states: has("states"),
                            handles: held(HandleKind::Grab),
                            pins: held(HandleKind::Pin),
                        },
                        ..RenderOptions::default()
                    };
                    clay::render_png(&self.grammar, data, &options)
                };
                result.map_err(|e| PyValueError::new_err(format!("cannot draw the model: {e}")))
            })
        })?;
        Ok(PyBytes::new(py, &png))
    }

    /// The model's 3D meshes as `clayc export` builds them, for a host application (the
    /// Blender add-on): one clay.SceneNode per instance, in the instances' order, each at its
    /// pivot and turned as the export's node, with one clay.Primitive per fill colour in the
    /// node's frame, in metres with z up.
    #[pyo3(signature = (thickness = None))]
    fn scene(&self, py: Python<'_>, thickness: Option<f64>) -> PyResult<Vec<SceneNode>> {
        let options = export_options(thickness)?;
        let built = py.detach(|| {
            guard("the scene", || {
                let st = self.lock()?;
                Ok(scene(&self.grammar, st.asm.data(), &options))
            })
        })?;
        let mesh_names: Vec<&str> = built.meshes.iter().map(|m| m.name.as_str()).collect();
        let mut nodes = Vec::with_capacity(built.nodes.len());
        for node in built.nodes {
            let mut primitives = Vec::with_capacity(node.primitives.len());
            for p in node
                .primitives
                .into_iter()
                .filter(|p| !p.indices.is_empty())
            {
                let [r, g, b, a] = built.materials.get(p.material).map_or([0; 4], |c| c.0);
                // glTF's y-up (x, height, -north) back to the floor plan's z-up.
                let n = p.positions.len();
                let flat: Vec<f32> = (p.positions.iter())
                    .flat_map(|q| [q[0], -q[2], q[1]])
                    .collect();
                let positions = PyArray1::from_vec(py, flat).reshape([n, 3])?;
                let m = p.indices.len() / 3;
                let triangles = PyArray1::from_vec(py, p.indices).reshape([m, 3])?;
                let uv: Vec<f32> = p.uvs.iter().flat_map(|t| [t[0], -t[1]]).collect();
                let uvs = PyArray1::from_vec(py, uv).reshape([p.uvs.len(), 2])?;
                primitives.push(Py::new(
                    py,
                    PyPrimitive {
                        colour: (r, g, b, a),
                        material: clay::material_name(clay_dsl::compiled::Rgba([r, g, b, a])),
                        positions: positions.into_any().unbind(),
                        triangles: triangles.into_any().unbind(),
                        uvs: uvs.into_any().unbind(),
                    },
                )?);
            }
            let (chain, index) = match node.chain {
                Some(c) => (Some(c.name), Some(c.index)),
                None => (None, None),
            };
            nodes.push(SceneNode {
                name: node.name,
                instance: node.instance,
                piece: node.piece,
                state: node.state,
                id: node.id,
                chain,
                index,
                pivot: (node.pivot.x, node.pivot.y),
                rotation: node.turn.y.atan2(node.turn.x),
                mesh: node
                    .mesh
                    .and_then(|m| mesh_names.get(m))
                    .map(|m| m.to_string()),
                primitives,
            });
        }
        Ok(nodes)
    }

    fn __repr__(&self) -> PyResult<String> {
        let st = self.lock()?;
        Ok(format!(
            "Session({} instances, {} frames)",
            st.asm.data().instances.len(),
            st.session.frame_ms().len()
        ))
    }
}

/// `thickness` as `clayc export --thickness` takes it (`ExportOptions::with_thickness`).
impl PySession {
    /// Writes the session's scene to `path` in `format`.
    fn write(
        &self,
        py: Python<'_>,
        path: &Path,
        format: ExportFormat,
        options: &ExportOptions,
    ) -> PyResult<()> {
        py.detach(|| {
            guard("the export", || {
                let scene = {
                    let st = self.lock()?;
                    scene(&self.grammar, st.asm.data(), options)
                };
                // the .obj before its .mtl, as `clayc export` writes them
                clay::write_export(&scene, path, format).map_err(|e| match e {
                    ExportFileError::Encode(e) => {
                        InternalError::new_err(format!("cannot encode the model: {e}"))
                    }
                    ExportFileError::Write(at, e) => os_error(&e, &at),
                })
            })
        })
    }

    /// `.usdc`, USD's binary crate form, which no Rust crate writes: the `.usda` export,
    /// converted by usd-core's `pxr` (`Usd.Stage.Export` picks the form by the extension) when
    /// it is installed; without it a `ValueError` says how to get it.
    fn export_usdc(&self, py: Python<'_>, path: &Path, options: &ExportOptions) -> PyResult<()> {
        let usd = py.import("pxr.Usd").map_err(|_| {
            PyValueError::new_err(format!(
                "cannot write `{}`: USD's binary form is written through usd-core's `pxr`, which \
                 is not installed (pip install usd-core); or export .usda",
                path.display()
            ))
        })?;
        let text = path.with_extension("clay-export.usda");
        self.write(py, &text, ExportFormat::Usda, options)?;
        let converted = (|| -> PyResult<bool> {
            let stage = usd
                .getattr("Stage")?
                .call_method1("Open", (text.to_string_lossy().into_owned(),))?;
            stage
                .call_method1("Export", (path.to_string_lossy().into_owned(),))?
                .extract()
        })();
        let _ = std::fs::remove_file(&text);
        if converted? {
            Ok(())
        } else {
            Err(pyo3::exceptions::PyOSError::new_err(format!(
                "usd-core could not write `{}`",
                path.display()
            )))
        }
    }
}

fn export_options(thickness: Option<f64>) -> PyResult<ExportOptions> {
    match thickness {
        None => Ok(ExportOptions::default()),
        Some(t) => ExportOptions::with_thickness(t)
            .map_err(|e| PyValueError::new_err(format!("thickness: {e}"))),
    }
}

/// A step's frame count (1 when not given).
fn frames_value(frames: Option<&Bound<'_, PyAny>>, kind: &str) -> PyResult<Value> {
    match none_if_none(frames) {
        None => Ok(Value::from(1)),
        Some(f) => json_number(f, &format!("{kind}: frames")),
    }
}
