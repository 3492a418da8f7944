//! The live assembly: the compiled grammar, the current [`AssemblyData`] (positions, instances,
//! docks, chains, parts), per-part rotations, and the handles the user holds.
//!
//! The solver reads the parts and handles and writes positions, rotations and active states.
//! Rules (paper 5.1) rewrite `data` between frames and then call [`Assembly::topology_changed`],
//! which bumps [`Assembly::generation`]; the solver rebuilds its sparsity pattern and symbolic
//! factorisation only when the generation changes.

use std::sync::Arc;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, PartKind};
use glam::DVec2;

/// Identity of a handle; never reused within one assembly.
pub type HandleId = u64;

/// Whether a handle follows the user or stays put.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HandleKind {
    /// The part the user is dragging or rotating.
    Grab,
    /// A part fixed where it was when pinned.
    Pin,
}

/// The instance (piece element) a handle holds, by stable id, with the anchor of each of its
/// vertices. Rules renumber and re-lay vertices (a stretch gives the first element fresh `to`
/// vertices), so [`Assembly::topology_changed`] re-reads the handle's vertices from the
/// instance instead of trusting the remapped vertex list.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldInstance {
    /// `Instance::id` (stable across rewrites), not an index.
    pub(crate) id: u64,
    /// Anchor of the instance's `k`-th vertex (piece-vertex order).
    pub(crate) anchor: Vec<DVec2>,
}

/// A handle (paper Eq. 3): a set of vertices with a target rigid placement. The target of
/// vertex `k` is `centre + translation + rot(angle) * (anchor[k] - centre)`. Made by the
/// assembly's `hold_*`, moved by [`Assembly::move_handle`] (a gesture's
/// `session::Grab`); its fields are the library's.
#[derive(Clone, Debug, PartialEq)]
pub struct Handle {
    pub(crate) id: HandleId,
    pub(crate) kind: HandleKind,
    /// The part the handle was made from, if any (informative; parts are renumbered by rules).
    pub(crate) part: Option<usize>,
    /// The instance the handle holds, when it was made by [`Assembly::hold_instance`]; its
    /// vertices follow that instance across rewrites.
    pub(crate) held: Option<HeldInstance>,
    /// Global vertex indices the handle holds.
    pub(crate) vertices: Vec<usize>,
    /// Positions of `vertices` when the handle was made.
    pub(crate) anchor: Vec<DVec2>,
    /// Centroid of `anchor`; rotations turn about it.
    pub(crate) centre: DVec2,
    pub(crate) translation: DVec2,
    /// Rotation in radians, counter-clockwise.
    pub(crate) angle: f64,
}

impl Handle {
    pub fn id(&self) -> HandleId {
        self.id
    }

    pub fn kind(&self) -> HandleKind {
        self.kind
    }

    /// The part the handle was made from, if any (informative; rules renumber parts).
    pub fn part(&self) -> Option<usize> {
        self.part
    }

    /// The stable id of the instance the handle holds, when it holds one.
    pub fn held_instance(&self) -> Option<u64> {
        self.held.as_ref().map(|h| h.id)
    }

    /// Global vertex indices the handle holds.
    pub fn vertices(&self) -> &[usize] {
        &self.vertices
    }

    /// How far the target is moved from where the handle was made.
    pub fn translation(&self) -> DVec2 {
        self.translation
    }

    /// How far the target is turned (radians, counter-clockwise) about its centre.
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// Target position of the handle's `k`-th vertex.
    pub fn target(&self, k: usize) -> DVec2 {
        let rot = DVec2::from_angle(self.angle);
        self.centre + self.translation + rot.rotate(self.anchor[k] - self.centre)
    }

    /// Where the handle's centroid currently wants to be.
    pub fn target_centre(&self) -> DVec2 {
        self.centre + self.translation
    }

    /// Holds the vertices at `at` (one per vertex) from now on, unmoved and unturned: a saved
    /// pin put back where it held. Ignored unless `at` has one point per vertex.
    pub(crate) fn place(&mut self, at: &[DVec2]) {
        if at.len() != self.anchor.len() || at.is_empty() {
            return;
        }
        self.centre = at.iter().copied().sum::<DVec2>() / at.len() as f64;
        self.translation = DVec2::ZERO;
        self.angle = 0.0;
        self.anchor = at.to_vec();
        if let Some(held) = &mut self.held {
            held.anchor = at.to_vec();
        }
    }
}

/// A compass direction for picking the part reaching furthest that way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compass {
    East,
    West,
    North,
    South,
}

impl Compass {
    pub fn direction(self) -> DVec2 {
        match self {
            Compass::East => DVec2::X,
            Compass::West => -DVec2::X,
            Compass::North => DVec2::Y,
            Compass::South => -DVec2::Y,
        }
    }
}

/// The live assembly being sculpted.
#[derive(Clone, Debug)]
pub struct Assembly {
    grammar: Arc<CompiledGrammar>,
    /// The contract data. Private: a change of topology must be followed by
    /// [`Assembly::topology_changed`], which the crate's rules do; other crates read it, move
    /// vertices ([`Assembly::positions_mut`]) and choose states ([`Assembly::set_active_state`]).
    data: AssemblyData,
    /// Per part: the rotation of its active rest state onto the current pose, as a unit
    /// complex number `(cos, sin)`.
    rotations: Vec<DVec2>,
    handles: Vec<Handle>,
    next_handle: HandleId,
    generation: u64,
}

impl Assembly {
    /// The grammar's initial assembly. Parts are derived from the grammar when the compiled
    /// assembly lists none.
    pub fn new(grammar: Arc<CompiledGrammar>) -> Self {
        let data = grammar.assembly.clone();
        Self::from_data(grammar, data)
    }

    /// An assembly over given data (session files, synthetic benchmarks).
    pub fn from_data(grammar: Arc<CompiledGrammar>, mut data: AssemblyData) -> Self {
        if data.parts.is_empty() && !data.instances.is_empty() {
            data.parts = grammar.parts(&data);
        }
        let rotations = vec![DVec2::X; data.parts.len()];
        Self {
            grammar,
            data,
            rotations,
            handles: Vec::new(),
            next_handle: 0,
            generation: 0,
        }
    }

    pub fn grammar(&self) -> &CompiledGrammar {
        &self.grammar
    }

    pub fn grammar_arc(&self) -> &Arc<CompiledGrammar> {
        &self.grammar
    }

    /// Structural generation: changes whenever parts, vertices or edges may have changed.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Makes this assembly equal to `other` without reallocating, when `other` is this one's
    /// structure a solver frame later: same grammar, same generation and the same counts. A
    /// frame only moves positions, switches active states, turns rotations and moves handle
    /// targets, so only those are copied. Returns false and changes nothing otherwise (the
    /// caller clones). Both must descend from one assembly: generations count from 0 in
    /// every assembly, so two unrelated ones can share one.
    pub fn sync_from(&mut self, other: &Assembly) -> bool {
        let same = Arc::ptr_eq(&self.grammar, &other.grammar)
            && self.generation == other.generation
            && self.data.positions.len() == other.data.positions.len()
            && self.data.parts.len() == other.data.parts.len()
            && self.data.instances.len() == other.data.instances.len()
            && self.rotations.len() == other.rotations.len();
        if !same {
            return false;
        }
        self.data.positions.copy_from_slice(&other.data.positions);
        for (mine, theirs) in self.data.parts.iter_mut().zip(&other.data.parts) {
            mine.active = theirs.active;
        }
        for (mine, theirs) in self.data.instances.iter_mut().zip(&other.data.instances) {
            mine.state = theirs.state;
        }
        self.rotations.copy_from_slice(&other.rotations);
        self.handles.clone_from(&other.handles);
        self.next_handle = other.next_handle;
        true
    }

    /// Rules call this after rewriting `data` (parts, vertices, docks). Bumps the generation so
    /// the solver rebuilds its pattern, resizes the rotations, re-reads the vertices of handles
    /// that hold an instance (see `HeldInstance`), and drops handles whose vertices no longer
    /// exist (rules that renumber vertices should remap handles first, through
    /// `handles_mut`).
    /// The contract data: positions, instances, docks, chains and parts.
    pub fn data(&self) -> &AssemblyData {
        &self.data
    }

    /// The data, for the crate's solver and rules, which keep the invariants (a rule that
    /// changes parts, vertices or edges calls [`Assembly::topology_changed`]).
    pub(crate) fn data_mut(&mut self) -> &mut AssemblyData {
        &mut self.data
    }

    /// The data, leaving the assembly.
    pub fn into_data(self) -> AssemblyData {
        self.data
    }

    /// The vertex positions, to move (their number is fixed: moving changes no topology).
    pub fn positions_mut(&mut self) -> &mut [DVec2] {
        &mut self.data.positions
    }

    /// Makes `state` the active rest state of `part` (as the solver's local step does).
    /// Returns false, changing nothing, when either index is out of range.
    pub fn set_active_state(&mut self, part: usize, state: usize) -> bool {
        match self.data.parts.get_mut(part) {
            Some(p) if state < p.states.len() => {
                p.active = state;
                true
            }
            _ => false,
        }
    }

    pub fn topology_changed(&mut self) {
        self.generation += 1;
        self.rotations.resize(self.data.parts.len(), DVec2::X);
        let mut handles = std::mem::take(&mut self.handles);
        for h in &mut handles {
            self.follow_instance(h);
        }
        self.handles = handles;
        let n = self.data.positions.len();
        self.handles.retain(|h| h.vertices.iter().all(|&v| v < n));
    }

    /// Points an instance handle at its instance's current vertices. When the instance is
    /// gone (a shrink removed it, a merge replaced it), the handle moves to the instance that
    /// now owns most of its surviving (already remapped) vertices, holding it as its rest shape
    /// fitted rigidly to where it is now, so the targets move only by the instance's current
    /// distortion. Without such an instance the handle keeps its surviving vertices and holds
    /// no instance any more.
    fn follow_instance(&self, h: &mut Handle) {
        let Some(held) = h.held.take() else {
            return;
        };
        let n = self.data.positions.len();
        let instances = &self.data.instances;
        if let Some(ii) = instances.iter().position(|i| i.id == held.id)
            && instances[ii].vertices.len() == held.anchor.len()
            && instances[ii].vertices.iter().all(|&v| v < n)
        {
            h.vertices = instances[ii].vertices.clone();
            h.anchor = held.anchor.clone();
            h.part = self.piece_part(ii);
            h.held = Some(held);
            return;
        }
        let owner = instances
            .iter()
            .enumerate()
            .map(|(ii, inst)| {
                let shared = inst
                    .vertices
                    .iter()
                    .filter(|v| h.vertices.contains(v))
                    .count();
                (ii, shared)
            })
            .filter(|&(ii, shared)| shared > 0 && instances[ii].vertices.iter().all(|&v| v < n))
            .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)));
        let Some((ii, _)) = owner else {
            h.part = None;
            return;
        };
        // Hold the new instance as a rigid copy of its rest shape, placed where it fits its
        // current pose best: a rewritten instance may be laid out stretched at this moment,
        // and anchoring it there would hold it stretched for good.
        let inst = &instances[ii];
        let current: Vec<DVec2> = inst
            .vertices
            .iter()
            .map(|&v| self.data.positions[v])
            .collect();
        let placed = match self
            .grammar
            .pieces
            .get(inst.piece)
            .and_then(|p| p.states.get(inst.state))
            .filter(|s| s.positions.len() == current.len())
        {
            Some(rest) => {
                let map = crate::fit::rigid(&rest.positions, &current);
                let placed: Vec<DVec2> = rest.positions.iter().map(|&q| map.apply(q)).collect();
                if placed.iter().all(|p| p.is_finite()) {
                    placed
                } else {
                    current
                }
            }
            None => current,
        };
        let unturn = DVec2::from_angle(-h.angle);
        let anchor: Vec<DVec2> = placed
            .iter()
            .map(|&p| h.centre + unturn.rotate(p - h.centre - h.translation))
            .collect();
        h.vertices = inst.vertices.clone();
        h.anchor = anchor.clone();
        h.part = self.piece_part(ii);
        h.held = Some(HeldInstance {
            id: inst.id,
            anchor,
        });
    }

    /// The piece part over instance `instance`, if it has one (elements of stretch chains are
    /// covered by two-element stretch parts instead).
    pub fn piece_part(&self, instance: usize) -> Option<usize> {
        self.data
            .parts
            .iter()
            .position(|p| p.kind == PartKind::Piece { instance })
    }

    /// Per-part rotations (unit complex numbers) from the last solver frame.
    pub fn rotations(&self) -> &[DVec2] {
        &self.rotations
    }

    pub(crate) fn rotations_mut(&mut self) -> &mut [DVec2] {
        &mut self.rotations
    }

    pub fn handles(&self) -> &[Handle] {
        &self.handles
    }

    pub(crate) fn handles_mut(&mut self) -> &mut Vec<Handle> {
        &mut self.handles
    }

    pub fn handle(&self, id: HandleId) -> Option<&Handle> {
        self.handles.iter().find(|h| h.id == id)
    }

    /// Moves handle `id`'s target: where it was made, moved by `translation` and turned by
    /// `angle` radians about its centre. Returns whether anything changed; a non-finite move
    /// or a handle that is gone changes nothing.
    pub fn move_handle(&mut self, id: HandleId, translation: DVec2, angle: f64) -> bool {
        if !(translation.is_finite() && angle.is_finite()) {
            return false;
        }
        match self.handle_mut(id) {
            Some(h) if h.translation != translation || h.angle != angle => {
                h.translation = translation;
                h.angle = angle;
                true
            }
            _ => false,
        }
    }

    pub(crate) fn handle_mut(&mut self, id: HandleId) -> Option<&mut Handle> {
        self.handles.iter_mut().find(|h| h.id == id)
    }

    /// Makes a handle over a part's vertices at their current positions. `None` if the part
    /// does not exist.
    pub fn hold_part(&mut self, part: usize, kind: HandleKind) -> Option<HandleId> {
        let vertices = self.data.parts.get(part)?.vertices.clone();
        let id = self.hold_vertices(vertices, kind)?;
        if let Some(h) = self.handle_mut(id) {
            h.part = Some(part);
        }
        Some(id)
    }

    /// Makes a handle over arbitrary vertices (e.g. a column of a grid). `None` if the list is
    /// empty or names a vertex that does not exist.
    pub fn hold_vertices(&mut self, vertices: Vec<usize>, kind: HandleKind) -> Option<HandleId> {
        let n = self.data.positions.len();
        if vertices.is_empty() || vertices.iter().any(|&v| v >= n) {
            return None;
        }
        let anchor: Vec<DVec2> = vertices.iter().map(|&v| self.data.positions[v]).collect();
        let centre = anchor.iter().copied().sum::<DVec2>() / anchor.len() as f64;
        let id = self.next_handle;
        self.next_handle += 1;
        self.handles.push(Handle {
            id,
            kind,
            part: None,
            held: None,
            vertices,
            anchor,
            centre,
            translation: DVec2::ZERO,
            angle: 0.0,
        });
        Some(id)
    }

    /// Makes a handle over one instance (piece element) at its current pose: the brick the
    /// user grabbed, also when it is an element of a stretch chain, whose parts are two-element
    /// windows. The handle follows the instance across rules' rewrites (see `HeldInstance`).
    /// `None` if the instance does not exist or has no vertices.
    pub fn hold_instance(&mut self, instance: usize, kind: HandleKind) -> Option<HandleId> {
        let inst = self.data.instances.get(instance)?;
        let (vertices, stable) = (inst.vertices.clone(), inst.id);
        let id = self.hold_vertices(vertices, kind)?;
        let part = self.piece_part(instance);
        if let Some(h) = self.handle_mut(id) {
            h.part = part;
            h.held = Some(HeldInstance {
                id: stable,
                anchor: h.anchor.clone(),
            });
        }
        Some(id)
    }

    /// Removes a handle; returns whether it existed.
    pub fn release(&mut self, id: HandleId) -> bool {
        let before = self.handles.len();
        self.handles.retain(|h| h.id != id);
        before != self.handles.len()
    }

    /// Centroid of a part's current vertex positions.
    pub fn part_centroid(&self, part: usize) -> DVec2 {
        let p = &self.data.parts[part];
        if p.vertices.is_empty() {
            return DVec2::ZERO;
        }
        p.vertices
            .iter()
            .map(|&v| self.data.positions[v])
            .sum::<DVec2>()
            / p.vertices.len() as f64
    }

    /// The part whose centroid is nearest `point` (ties: lowest index). `None` without parts.
    pub fn part_nearest(&self, point: DVec2) -> Option<usize> {
        (0..self.data.parts.len())
            .filter(|&i| !self.data.parts[i].vertices.is_empty())
            .map(|i| (i, self.part_centroid(i).distance_squared(point)))
            .filter(|(_, d)| d.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The part with the vertex reaching furthest in `dir` (ties broken by the centroid, then
    /// the lowest index). `None` without parts.
    pub fn part_extreme(&self, dir: Compass) -> Option<usize> {
        let d = dir.direction();
        furthest(
            (0..self.data.parts.len())
                .filter(|&i| !self.data.parts[i].vertices.is_empty())
                .map(|i| {
                    let reach = self.reach(&self.data.parts[i].vertices, d);
                    (i, reach, self.part_centroid(i).dot(d))
                }),
        )
    }

    /// How far the furthest of `vertices` reaches along `d`.
    fn reach(&self, vertices: &[usize], d: DVec2) -> f64 {
        vertices
            .iter()
            .map(|&v| self.data.positions[v].dot(d))
            .fold(f64::MIN, f64::max)
    }

    /// Centroid of an instance's current vertex positions (`None`: no such instance or no
    /// vertices).
    pub fn instance_centroid(&self, instance: usize) -> Option<DVec2> {
        let vs = &self.data.instances.get(instance)?.vertices;
        if vs.is_empty() || vs.iter().any(|&v| v >= self.data.positions.len()) {
            return None;
        }
        Some(vs.iter().map(|&v| self.data.positions[v]).sum::<DVec2>() / vs.len() as f64)
    }

    /// The instance of `part` whose centre is nearest `at` (a stretch part covers two): what
    /// a handle made where the pointer is on that part holds.
    pub fn instance_of_part_at(&self, part: usize, at: DVec2) -> Option<usize> {
        let d = |i| {
            self.instance_centroid(i)
                .map_or(f64::INFINITY, |c| c.distance_squared(at))
        };
        (self.data.part_instances(part).into_iter()).min_by(|&a, &b| d(a).total_cmp(&d(b)))
    }

    /// The instance (piece element) whose centroid is nearest `point` (ties: lowest index).
    /// `None` without instances.
    pub fn instance_nearest(&self, point: DVec2) -> Option<usize> {
        (0..self.data.instances.len())
            .filter_map(|i| Some((i, self.instance_centroid(i)?.distance_squared(point))))
            .filter(|(_, d)| d.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The instance with the vertex reaching furthest in `dir` (ties broken by the centroid,
    /// then the lowest index). `None` without instances.
    pub fn instance_extreme(&self, dir: Compass) -> Option<usize> {
        let d = dir.direction();
        furthest((0..self.data.instances.len()).filter_map(|i| {
            let centre = self.instance_centroid(i)?;
            let reach = self.reach(&self.data.instances[i].vertices, d);
            Some((i, reach, centre.dot(d)))
        }))
    }

    /// Checks indices and invariants of the data ([`AssemblyData::problems`], the one check of
    /// an assembly's data), the rotations and the handles. Returns every problem found, one
    /// line each.
    pub fn validate(&self) -> Result<(), Vec<String>> {
        let d = &self.data;
        let n = d.positions.len();
        let mut errors = d.problems(&self.grammar);
        if self.rotations.len() != d.parts.len() {
            errors.push(format!(
                "{} rotations for {} parts (topology_changed not called?)",
                self.rotations.len(),
                d.parts.len()
            ));
        }
        for h in &self.handles {
            if h.vertices.iter().any(|&v| v >= n) || h.anchor.len() != h.vertices.len() {
                errors.push(format!("handle {}: vertices out of range", h.id));
            }
        }
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }
}

/// The index whose `(reach, centre)` is largest: the furthest reach, ties broken by the
/// centre, then by the lowest index (so the choice does not depend on iteration order).
fn furthest(candidates: impl Iterator<Item = (usize, f64, f64)>) -> Option<usize> {
    candidates
        .max_by(|a, b| {
            a.1.total_cmp(&b.1)
                .then(a.2.total_cmp(&b.2))
                .then(b.0.cmp(&a.0))
        })
        .map(|(i, _, _)| i)
}
