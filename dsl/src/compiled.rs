//! The compiled grammar: plain serde data that the compiler produces and every later phase
//! (solver, rules, renderer, editor) consumes. It knows nothing of source text or spans.
//!
//! Architecture invariant: this module depends on nothing but serde and glam. The live
//! assembly in the `clay` crate holds an [`AssemblyData`] and keeps it valid after every rule,
//! so the renderer and the session files see one shape of data whatever produced it.
//!
//! Indices: `PieceId`, `SiteTypeId`, rule indices are positions in the grammar's vectors;
//! vertex indices inside a piece are positions in [`Piece::vertices`]; global vertex indices are
//! positions in [`AssemblyData::positions`].

use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Largest absolute position a model's vertex may have when it is read back (a session, a
/// compiled grammar): gestures stay within the +/-1e9 m of grammars and scripts, a model
/// sculpted by them stays well inside this, and the solver's squared distances stay far from
/// overflow (issue 47: a session's positions of 1e308 ran to an infinite energy).
pub const MAX_MODEL_COORDINATE: f64 = 1e12;

/// Bumped whenever the JSON form changes incompatibly.
pub const FORMAT_VERSION: u32 = 1;

/// Everything the runtime needs to know about a grammar, and its initial assembly.
///
/// In its JSON form the initial assembly has no parts: they follow from the instances and
/// chains ([`CompiledGrammar::parts`]) and are most of its size (a stretch part repeats its
/// rule's rest states), so they are written out and rebuilt on reading. A file that lists
/// parts (an older `clayc build`) keeps them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "Unparted")]
pub struct CompiledGrammar {
    pub format_version: u32,
    /// The path the grammar was compiled from, as given (for messages and session files).
    pub source: String,
    pub solver: SolverParams,
    /// The grammar's parameters (`param`), in declaration order, with the values it was
    /// compiled with: what a tool offers to change.
    pub params: Vec<Param>,
    pub site_types: Vec<SiteType>,
    pub pieces: Vec<Piece>,
    pub stretch_rules: Vec<StretchRule>,
    pub merge_rules: Vec<MergeRule>,
    /// Written and derived cut rules (derived ones have `derived: true`).
    pub cut_rules: Vec<CutRule>,
    /// The initial assembly described by the `model` block.
    #[serde(serialize_with = "without_parts")]
    pub assembly: AssemblyData,
}

/// [`CompiledGrammar`] as read, its initial assembly's parts perhaps left out.
#[derive(Deserialize)]
struct Unparted {
    format_version: u32,
    source: String,
    solver: SolverParams,
    /// Absent in files written before parameters existed.
    #[serde(default)]
    params: Vec<Param>,
    site_types: Vec<SiteType>,
    pieces: Vec<Piece>,
    stretch_rules: Vec<StretchRule>,
    merge_rules: Vec<MergeRule>,
    cut_rules: Vec<CutRule>,
    assembly: AssemblyData,
}

impl From<Unparted> for CompiledGrammar {
    fn from(u: Unparted) -> Self {
        let mut grammar = CompiledGrammar {
            format_version: u.format_version,
            source: u.source,
            solver: u.solver,
            params: u.params,
            site_types: u.site_types,
            pieces: u.pieces,
            stretch_rules: u.stretch_rules,
            merge_rules: u.merge_rules,
            cut_rules: u.cut_rules,
            assembly: u.assembly,
        };
        if grammar.assembly.parts.is_empty() {
            // an assembly whose indices do not hold keeps no parts: its check says why
            if let Some(parts) = grammar.try_parts(&grammar.assembly) {
                grammar.assembly.parts = parts;
            }
        }
        grammar
    }
}

/// Writes an assembly without its parts (see [`CompiledGrammar`]).
fn without_parts<S: serde::Serializer>(a: &AssemblyData, s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Unparted<'a> {
        positions: &'a [DVec2],
        instances: &'a [Instance],
        docks: &'a [Dock],
        chains: &'a [Chain],
        next_id: u64,
    }
    Unparted {
        positions: &a.positions,
        instances: &a.instances,
        docks: &a.docks,
        chains: &a.chains,
        next_id: a.next_id,
    }
    .serialize(s)
}

/// The solver parameters of paper 4.3 and 5.2.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverParams {
    /// Fraction by which a rest state must be closer before the part switches to it.
    pub hysteresis: f64,
    /// The exponent p of the IRLS pass.
    pub norm: f64,
    /// Epsilon in the IRLS weight `1 / (|r| + eps)^(2 - p)`.
    pub irls_epsilon: f64,
    /// Default distance at which a free site merges with a compatible one.
    pub merge_distance: f64,
}

impl Default for SolverParams {
    /// The defaults of the settings table (`crate::settings`).
    fn default() -> Self {
        let default = |name| crate::settings::setting(name).map_or(0.0, |s| s.default.number());
        Self {
            hysteresis: default("hysteresis"),
            norm: default("norm"),
            irls_epsilon: default("irls_epsilon"),
            merge_distance: default("merge_distance"),
        }
    }
}

pub use crate::param::{Param, ParamKind, ParamValue};

/// A site type and the types it may dock with (symmetric, already closed over).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SiteType {
    pub name: String,
    pub docks_with: Vec<usize>,
}

/// A piece: a small 2D graph with docking sites and one or more rest states.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Piece {
    pub name: String,
    /// Vertex names; a vertex's index is its position here.
    pub vertices: Vec<String>,
    /// Undirected edges as pairs of piece-vertex indices, each pair stored once.
    pub edges: Vec<[usize; 2]>,
    pub sites: Vec<Site>,
    /// `states[0]` is the base state (`base`); the others are the alternatives, in source order.
    pub states: Vec<RestState>,
    /// The two opposite sites (`[from, to]`, site indices) that skinned geometry stretches
    /// between; set by `axis` or by a stretch rule naming the piece.
    pub axis: Option<[usize; 2]>,
}

/// A docking site of a piece.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Site {
    pub name: String,
    pub site_type: usize,
    /// Piece-vertex indices in counter-clockwise order around the piece. When two sites dock,
    /// vertex `i` of one meets vertex `n - 1 - i` of the other.
    pub vertices: Vec<usize>,
    /// Unit outward direction in the base state's coordinates.
    pub out: DVec2,
}

/// One rest state of a piece: a position for every vertex, and the proxy geometry shown while
/// it is active.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RestState {
    pub name: String,
    /// One position per piece vertex, in the piece's coordinates.
    pub positions: Vec<DVec2>,
    /// The proxy geometry shown while this state is active.
    pub geometry: Vec<Proxy>,
    /// Index of the state whose `positions` the geometry's coordinates are authored against
    /// (this state's own index, or 0 when the state has no geometry of its own and shows the
    /// base state's).
    pub geometry_frame: usize,
}

/// A piece of proxy geometry (paper 5.2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Proxy {
    pub shape: ProxyShape,
    pub fill: Rgba,
    pub binding: Binding,
    /// Heights for the 3D export (`extrude`); absent for flat geometry, which the export gives
    /// a default thickness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extrude: Option<Extrude>,
}

/// A proxy's prism in the 3D export: its floor `base` metres above the ground, `height` metres
/// tall. The solver's deformation moves the floor plan only; these stay (paper 6).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Extrude {
    pub height: f64,
    pub base: f64,
}

/// The outline of a proxy.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ProxyShape {
    /// A closed polygon (not repeating its first point), possibly concave, with holes.
    Polygon {
        outer: Vec<DVec2>,
        holes: Vec<Vec<DVec2>>,
    },
    /// A thick open polyline.
    Polyline { points: Vec<DVec2>, width: f64 },
    /// Triangles of a 3D mesh asset (`mesh "tower.glb"`), embedded so that a compiled grammar
    /// needs no other file. Vertex `i` is at floor-plan point `points[i]` (piece coordinates,
    /// which the part's deformation moves) and `heights[i]` metres above the ground (which it
    /// never changes, paper 6). Triangles are counter-clockwise seen from outside the solid.
    Mesh {
        points: Vec<DVec2>,
        heights: Vec<f64>,
        triangles: Vec<[u32; 3]>,
    },
}

/// How proxy geometry follows its part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Binding {
    /// Carried by the part's best rigid motion (connectors: towers, junctions).
    Rigid,
    /// Linear blend skinning between the frames of the piece's axis sites (linear pieces).
    Skinned,
}

/// An sRGB colour with straight alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rgba(pub [u8; 4]);

/// Stretch and shrink (paper 5.1): a piece repeating along its axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StretchRule {
    /// The piece the rule is written for (also `variants[0].piece` when no variants are given).
    pub piece: usize,
    /// Pieces that may be inserted, with target frequencies summing to 1. All variants share
    /// the vertex list, edges and site names of `piece`.
    pub variants: Vec<Variant>,
    /// Site index (valid for every variant) that faces the previous element.
    pub from: usize,
    /// Site index (valid for every variant) that faces the next element.
    pub to: usize,
    /// The chain never shrinks below this many elements (at least 2).
    pub min: usize,
    /// The chain never grows beyond this many elements (`None`: no bound).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<usize>,
    /// The two-element part and its one-, two- and three-element rest states.
    pub part: StretchPart,
}

/// A variant of a stretch rule and its target frequency.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variant {
    pub piece: usize,
    pub frequency: f64,
}

/// The two-element part of a stretch rule: element 0 docked to element 1 through
/// `to` -> `from`. Element 1's `from` vertices are not listed: they are element 0's `to` ones.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StretchPart {
    pub vertices: Vec<ElementVertex>,
    /// Edges between indices of `vertices`, both elements' edges, each stored once.
    pub edges: Vec<[usize; 2]>,
    /// Three rest states named `one`, `two`, `three`: the two-element pose scaled along the axis
    /// by 1/2, 1 and 3/2 (element 0's `from` site centre is the fixed origin).
    pub states: Vec<PartState>,
}

/// A vertex of the two-element part: which element, and which piece vertex of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ElementVertex {
    pub element: u8,
    pub vertex: usize,
}

/// A merge rule (paper 5.1, merging).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MergeRule {
    /// The free site that moves onto the target.
    pub mover: SiteRef,
    /// The site it welds to.
    pub target: SiteRef,
    /// The junction that replaces the target's instance, or `None` for a direct weld.
    pub junction: Option<SiteRef>,
    /// The rule's own weld distance in metres (`within`); `None` follows the live
    /// `merge_distance`, so `--set merge_distance` and the editor's slider reach it.
    pub within: Option<f64>,
}

impl MergeRule {
    /// The weld distance in metres under the given solver parameters.
    pub fn distance(&self, params: &SolverParams) -> f64 {
        self.within.unwrap_or(params.merge_distance)
    }
}

/// A cut rule: cutting `junction.site` turns the junction back into `into`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CutRule {
    pub junction: SiteRef,
    pub into: usize,
    /// True when derived from a merge rule rather than written.
    pub derived: bool,
}

/// A site of a piece: `(piece index, site index)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SiteRef {
    pub piece: usize,
    pub site: usize,
}

/// An assembly: instances of pieces sharing vertices at docked sites, covered by parts.
/// Both the compiler's initial assembly and the live one after rules have this form.
/// `Default` is the empty assembly.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AssemblyData {
    /// Global vertex positions in metres.
    pub positions: Vec<DVec2>,
    pub instances: Vec<Instance>,
    pub docks: Vec<Dock>,
    pub chains: Vec<Chain>,
    #[serde(default)]
    pub parts: Vec<Part>,
    /// The id the next new instance gets; ids are never reused.
    pub next_id: u64,
}

/// An instance of a piece in an assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Instance {
    /// Stable identity: survives rules that do not remove this instance.
    pub id: u64,
    /// The model's name (`t1`, `wall[3]`), or a generated one for instances rules insert.
    pub name: String,
    pub piece: usize,
    /// Global vertex index of each piece vertex.
    pub vertices: Vec<usize>,
    /// The active rest state (index into the piece's `states`), which picks the geometry shown.
    pub state: usize,
}

/// Two instance sites docked together; their vertices are shared (vertex `i` of `a`'s site is
/// the same global vertex as vertex `n - 1 - i` of `b`'s).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Dock {
    pub a: InstanceSite,
    pub b: InstanceSite,
}

/// A site of an instance: `(instance index, site index)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct InstanceSite {
    pub instance: usize,
    pub site: usize,
}

/// A maximal run of stretchable instances docked `to` -> `from`, in order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Chain {
    pub rule: usize,
    pub instances: Vec<usize>,
    /// How the chain's element count last changed: +1 a stretch, -1 a shrink, 0 not yet
    /// (the solver makes a reversal wait for most of an element: `docs/solver.md`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub trend: i8,
}

fn is_zero(x: &i8) -> bool {
    *x == 0
}

/// A part (paper 4.1): vertices, edges, and the set of alternative rest states.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Part {
    pub kind: PartKind,
    /// Global vertex indices.
    pub vertices: Vec<usize>,
    /// Edges between indices of `vertices`.
    pub edges: Vec<[usize; 2]>,
    /// The rest-state set A_i; every state has one position per vertex.
    pub states: Vec<PartState>,
    /// The active state.
    pub active: usize,
}

/// What a part covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PartKind {
    /// One instance of a piece that is not covered by a stretch chain.
    Piece { instance: usize },
    /// Elements `first` and `first + 1` of a chain.
    Stretch { chain: usize, first: usize },
}

/// The rest states of a [`PartKind::Stretch`] part, by index (paper 5.1, Fig. 7b): its two
/// elements squeezed into one element's length, at rest, and stretched to three's.
pub const STRETCH_ONE: usize = 0;
pub const STRETCH_TWO: usize = 1;
pub const STRETCH_THREE: usize = 2;

/// A named rest position set of a part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartState {
    pub name: String,
    pub positions: Vec<DVec2>,
}

impl CompiledGrammar {
    /// Whether site types `a` and `b` may dock.
    pub fn types_dock(&self, a: usize, b: usize) -> bool {
        self.site_types[a].docks_with.contains(&b)
    }

    /// The part covering one instance with the piece's own rest states.
    pub fn piece_part(&self, assembly: &AssemblyData, instance: usize) -> Part {
        let inst = &assembly.instances[instance];
        let piece = &self.pieces[inst.piece];
        Part {
            kind: PartKind::Piece { instance },
            vertices: inst.vertices.clone(),
            edges: piece.edges.clone(),
            states: piece
                .states
                .iter()
                .map(|s| PartState {
                    name: s.name.clone(),
                    positions: s.positions.clone(),
                })
                .collect(),
            active: inst.state.min(piece.states.len().saturating_sub(1)),
        }
    }

    /// The two-element part over elements `first` and `first + 1` of a chain, starting in its
    /// two-element state. Panics if `first + 1` is not an element of the chain.
    pub fn stretch_part(&self, assembly: &AssemblyData, chain: usize, first: usize) -> Part {
        let c = &assembly.chains[chain];
        let rule = &self.stretch_rules[c.rule];
        let vertices = rule
            .part
            .vertices
            .iter()
            .map(|ev| {
                assembly.instances[c.instances[first + ev.element as usize]].vertices[ev.vertex]
            })
            .collect();
        Part {
            kind: PartKind::Stretch { chain, first },
            vertices,
            edges: rule.part.edges.clone(),
            states: rule.part.states.clone(),
            active: 1,
        }
    }

    /// [`CompiledGrammar::parts`], or `None` when an index of the assembly (a chain's
    /// instance or rule, an instance's piece or vertex) does not hold, where that would panic.
    pub fn try_parts(&self, assembly: &AssemblyData) -> Option<Vec<Part>> {
        let instances = &assembly.instances;
        for inst in instances {
            let piece = self.pieces.get(inst.piece)?;
            let n = piece.states.first().map_or(0, |s| s.positions.len());
            if inst.vertices.len() < n
                || inst.vertices.iter().any(|&v| v >= assembly.positions.len())
            {
                return None;
            }
        }
        for c in &assembly.chains {
            let rule = self.stretch_rules.get(c.rule)?;
            if c.instances.iter().any(|&i| i >= instances.len()) {
                return None;
            }
            for first in 0..c.instances.len().saturating_sub(1) {
                for ev in &rule.part.vertices {
                    let i = *c.instances.get(first + ev.element as usize)?;
                    instances[i].vertices.get(ev.vertex)?;
                }
            }
        }
        Some(self.parts(assembly))
    }

    /// All parts of an assembly: a stretch part for every consecutive pair of every chain of
    /// two or more elements, and a piece part for every other instance (including the element of
    /// a one-element chain).
    pub fn parts(&self, assembly: &AssemblyData) -> Vec<Part> {
        let mut covered = vec![false; assembly.instances.len()];
        let mut parts = Vec::new();
        for (ci, chain) in assembly.chains.iter().enumerate() {
            if chain.instances.len() < 2 {
                continue;
            }
            for &i in &chain.instances {
                covered[i] = true;
            }
            for first in 0..chain.instances.len() - 1 {
                parts.push(self.stretch_part(assembly, ci, first));
            }
        }
        for (i, done) in covered.iter().enumerate() {
            if !done {
                parts.push(self.piece_part(assembly, i));
            }
        }
        parts
    }
}

/// Tolerance (metres) within which docked vertices must coincide in a compiled model.
pub const COINCIDENCE_TOLERANCE: f64 = 1e-4;

impl AssemblyData {
    /// The instances a part covers, in chain order: one for a piece part, two for a stretch
    /// part (none for a part that does not exist).
    pub fn part_instances(&self, part: usize) -> Vec<usize> {
        match self.parts.get(part).map(|p| p.kind) {
            Some(PartKind::Piece { instance }) => vec![instance],
            Some(PartKind::Stretch { chain, first }) => (self.chains.get(chain))
                .map(|c| c.instances.iter().skip(first).take(2).copied().collect())
                .unwrap_or_default(),
            None => Vec::new(),
        }
    }

    /// Checks the structural invariants every assembly keeps, whether the compiler or a rule made
    /// it ([`AssemblyData::problems`]); returns the first problem found, in words.
    pub fn check(&self, grammar: &CompiledGrammar) -> Result<(), String> {
        match self.problems(grammar).into_iter().next() {
            Some(problem) => Err(problem),
            None => Ok(()),
        }
    }

    /// Every problem of the structural invariants every assembly keeps, whether the compiler or
    /// a rule made it, one line each: indices in range, vertex counts matching pieces and rest
    /// states, docked sites sharing their vertices in opposite order, chains docked `to` ->
    /// `from` element by element, every position finite. The one check of an assembly's data
    /// (`clay::Assembly::validate` adds the live assembly's rotations and handles).
    // Long because: one short check per invariant, in the order the invariants build on each other.
    pub fn problems(&self, grammar: &CompiledGrammar) -> Vec<String> {
        let mut out = Vec::new();
        let nv = self.positions.len();
        let far = MAX_MODEL_COORDINATE;
        if let Some(i) =
            (self.positions.iter()).position(|p| !p.is_finite() || p.abs().max_element() > far)
        {
            out.push(format!(
                "vertex {i} is at {}, not a finite position within +/-{far:e} m",
                self.positions[i]
            ));
        }
        for (ii, inst) in self.instances.iter().enumerate() {
            let Some(piece) = grammar.pieces.get(inst.piece) else {
                out.push(format!(
                    "instance {ii} ({}) names piece {} which does not exist",
                    inst.name, inst.piece
                ));
                continue;
            };
            if inst.vertices.len() != piece.vertices.len() {
                out.push(format!(
                    "instance {ii} ({}) has {} vertices, piece `{}` has {}",
                    inst.name,
                    inst.vertices.len(),
                    piece.name,
                    piece.vertices.len()
                ));
                continue;
            }
            if let Some(&v) = inst.vertices.iter().find(|&&v| v >= nv) {
                out.push(format!(
                    "instance {ii} ({}) uses vertex {v} of {nv}",
                    inst.name
                ));
                continue;
            }
            if inst.state >= piece.states.len() {
                out.push(format!(
                    "instance {ii} ({}) is in state {} of {}",
                    inst.name,
                    inst.state,
                    piece.states.len()
                ));
                continue;
            }
            if inst.id >= self.next_id {
                out.push(format!(
                    "instance {ii} ({}) has id {} but next_id is {}",
                    inst.name, inst.id, self.next_id
                ));
                continue;
            }
        }
        let mut ids: Vec<u64> = self.instances.iter().map(|i| i.id).collect();
        ids.sort_unstable();
        if ids.windows(2).any(|w| w[0] == w[1]) {
            out.push("two instances share an id".to_string());
        }
        for (di, dock) in self.docks.iter().enumerate() {
            let sites = [dock.a, dock.b].map(|s| self.site_vertices(grammar, s));
            let (Some(a), Some(b)) = (&sites[0], &sites[1]) else {
                out.push(format!(
                    "dock {di} names an instance or site that does not exist"
                ));
                continue;
            };
            if a.len() != b.len() {
                out.push(format!(
                    "dock {di} joins sites of {} and {} vertices",
                    a.len(),
                    b.len()
                ));
                continue;
            }
            if a.iter().zip(b.iter().rev()).any(|(x, y)| x != y) {
                out.push(format!(
                    "dock {di}: the docked sites do not share their vertices"
                ));
                continue;
            }
        }
        // each dock both ways, looked up per pair of elements (a scan of every dock per pair
        // made each rule's check quadratic in the model: half of a fuzzed sculpt's time)
        let docked: std::collections::HashSet<(InstanceSite, InstanceSite)> = (self.docks.iter())
            .flat_map(|d| [(d.a, d.b), (d.b, d.a)])
            .collect();
        for (ci, chain) in self.chains.iter().enumerate() {
            let Some(rule) = grammar.stretch_rules.get(chain.rule) else {
                out.push(format!(
                    "chain {ci} names stretch rule {} which does not exist",
                    chain.rule
                ));
                continue;
            };
            if let Some(&i) = chain.instances.iter().find(|&&i| i >= self.instances.len()) {
                out.push(format!(
                    "chain {ci} names instance {i} which does not exist"
                ));
                continue;
            }
            for w in chain.instances.windows(2) {
                let to = InstanceSite {
                    instance: w[0],
                    site: rule.to,
                };
                let from = InstanceSite {
                    instance: w[1],
                    site: rule.from,
                };
                if !docked.contains(&(to, from)) {
                    out.push(format!(
                        "chain {ci}: elements {} and {} are not docked",
                        w[0], w[1]
                    ));
                    continue;
                }
            }
        }
        for (pi, part) in self.parts.iter().enumerate() {
            if let Some(&v) = part.vertices.iter().find(|&&v| v >= nv) {
                out.push(format!("part {pi} uses vertex {v} of {nv}"));
                continue;
            }
            if part
                .edges
                .iter()
                .flatten()
                .any(|&e| e >= part.vertices.len())
            {
                out.push(format!(
                    "part {pi} has an edge to a vertex it does not have"
                ));
                continue;
            }
            if part.active >= part.states.len() {
                out.push(format!(
                    "part {pi} is in state {} of {}",
                    part.active,
                    part.states.len()
                ));
                continue;
            }
            if part
                .states
                .iter()
                .any(|s| s.positions.len() != part.vertices.len())
            {
                out.push(format!(
                    "part {pi} has a rest state with the wrong number of positions"
                ));
                continue;
            }
            if part
                .states
                .iter()
                .any(|s| s.positions.iter().any(|p| !p.is_finite()))
            {
                out.push(format!(
                    "part {pi} has a rest state with a non-finite position"
                ));
                continue;
            }
            match part.kind {
                PartKind::Piece { instance } if instance >= self.instances.len() => {
                    out.push(format!(
                        "part {pi} covers instance {instance} which does not exist"
                    ));
                    continue;
                }
                PartKind::Stretch { chain, first } => {
                    let ok = self
                        .chains
                        .get(chain)
                        .is_some_and(|c| first + 1 < c.instances.len());
                    if !ok {
                        out.push(format!(
                            "part {pi} covers chain {chain} elements {first}.. which do not exist"
                        ));
                        continue;
                    }
                }
                PartKind::Piece { .. } => {}
            }
        }
        out
    }

    /// The global vertices of an instance's site, in the site's order; `None` if out of range.
    pub fn site_vertices(&self, grammar: &CompiledGrammar, s: InstanceSite) -> Option<Vec<usize>> {
        let inst = self.instances.get(s.instance)?;
        let site = grammar.pieces.get(inst.piece)?.sites.get(s.site)?;
        site.vertices
            .iter()
            .map(|&v| inst.vertices.get(v).copied())
            .collect()
    }
}
