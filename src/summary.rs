//! The summary of a session (issue 3's `clayc run --json` object): counts of pieces, states and
//! rules, connectivity, extent, strain, energy and frame times, all finite or reported as not.
//! JSON never holds `null` for a number: a figure that is not finite is written as the largest
//! finite number of its sign (NaN as 0), `finite` is false and `not_finite` names it.

use std::collections::BTreeMap;

use serde::{Serialize, Serializer};

use clay_dsl::compiled::AssemblyData;

use crate::assembly::Assembly;
use crate::figure::figure;
use crate::rules::RuleKind;
use crate::solver::follow::Components;
use crate::solver::{FrameReport, SolverConfig, bbox, elastic_energy, max_edge_strain};

/// Median and largest frame time in milliseconds (0 when no frame ran).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FrameMs {
    #[serde(serialize_with = "finite_number")]
    pub median: f64,
    #[serde(serialize_with = "finite_number")]
    pub max: f64,
}

/// The JSON number for `x`: `x` when finite, else the largest finite number of its sign, or 0
/// for NaN (serde_json would write `null`). The summary's `finite` flag says when this applies.
pub fn json_number(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else if x.is_nan() {
        0.0
    } else {
        f64::MAX.copysign(x)
    }
}

fn finite_number<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(json_number(*x))
}

fn finite_numbers<S: Serializer>(xs: &[f64; 4], s: S) -> Result<S::Ok, S::Error> {
    xs.map(json_number).serialize(s)
}

/// The state of an assembly at the end of a session.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub frames: usize,
    pub vertices: usize,
    pub parts: usize,
    /// Instance count per piece name.
    pub pieces: BTreeMap<String, usize>,
    /// Per piece name, per rest-state name: how many instances have it active
    /// (`instance.state`, also for instances covered by stretch parts).
    pub states: BTreeMap<String, BTreeMap<String, usize>>,
    /// Rules fired per kind: replace, stretch, shrink, merge, cut.
    pub rules_fired: BTreeMap<String, usize>,
    /// Connected components of the part graph (parts sharing a vertex are connected).
    pub components: usize,
    /// `[min x, min y, max x, max y]` of all vertices (zeros for an empty assembly).
    #[serde(serialize_with = "finite_numbers")]
    pub bbox: [f64; 4],
    /// Largest `|length / rest length - 1|` over all edges of the active states.
    #[serde(serialize_with = "finite_number")]
    pub max_edge_strain: f64,
    /// Pass-2 elastic energy of the last frame (of the initial assembly when no frame ran).
    #[serde(serialize_with = "finite_number")]
    pub energy: f64,
    pub frame_ms: FrameMs,
    /// Every coordinate and every figure above is finite.
    pub finite: bool,
    /// The fields that are not finite (`positions` for the coordinates), when any.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_finite: Vec<&'static str>,
}

fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// The number of connected components of an assembly: its parts joined through shared
/// vertices (the solver's [`Components`], counted over the vertices that parts use). A cut
/// that parts a model makes two; a merge that welds two makes one.
pub fn connected_components(data: &AssemblyData) -> usize {
    let n = data.positions.len();
    let components = Components::build(&data.parts, n);
    let mut used: Vec<usize> = data
        .parts
        .iter()
        .filter_map(|p| p.vertices.iter().copied().find(|&v| v < n))
        .map(|v| components.of(v))
        .collect();
    used.sort_unstable();
    used.dedup();
    used.len()
}

/// Summarises `asm` after a session with these frame times, rule counts and last frame.
pub fn summarize(
    asm: &Assembly,
    frame_ms: &[f64],
    rules_fired: &BTreeMap<RuleKind, usize>,
    last: Option<&FrameReport>,
    config: &SolverConfig,
) -> Summary {
    let g = asm.grammar();
    let mut pieces = BTreeMap::new();
    let mut states: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    for inst in &asm.data().instances {
        let Some(piece) = g.pieces.get(inst.piece) else {
            continue;
        };
        *pieces.entry(piece.name.clone()).or_insert(0) += 1;
        let state = piece
            .states
            .get(inst.state)
            .map_or("?", |s| s.name.as_str());
        *states
            .entry(piece.name.clone())
            .or_default()
            .entry(state.to_string())
            .or_insert(0) += 1;
    }
    let finite = asm.data().positions.iter().all(|p| p.is_finite());
    let bbox = match bbox(&asm.data().positions) {
        Some((lo, hi)) => [lo.x, lo.y, hi.x, hi.y],
        None => [0.0; 4],
    };
    let energy = match last {
        Some(r) => r.energy,
        None => elastic_energy(asm, config),
    };
    let times = FrameMs {
        median: median(frame_ms),
        max: frame_ms.iter().copied().fold(0.0, f64::max),
    };
    let max_edge_strain = max_edge_strain(asm);
    let figures = [
        ("positions", finite),
        ("bbox", bbox.iter().all(|x| x.is_finite())),
        ("max_edge_strain", max_edge_strain.is_finite()),
        ("energy", energy.is_finite()),
        (
            "frame_ms",
            times.median.is_finite() && times.max.is_finite(),
        ),
    ];
    let not_finite: Vec<&'static str> = figures
        .iter()
        .filter(|(_, ok)| !ok)
        .map(|(name, _)| *name)
        .collect();
    Summary {
        frames: frame_ms.len(),
        vertices: asm.data().positions.len(),
        parts: asm.data().parts.len(),
        pieces,
        states,
        rules_fired: RuleKind::ALL
            .iter()
            .map(|&k| {
                (
                    k.name().to_string(),
                    rules_fired.get(&k).copied().unwrap_or(0),
                )
            })
            .collect(),
        components: connected_components(asm.data()),
        bbox,
        max_edge_strain,
        energy,
        frame_ms: times,
        finite: not_finite.is_empty(),
        not_finite,
    }
}

impl Summary {
    /// A few lines for people.
    pub fn human(&self) -> String {
        let list = |m: &BTreeMap<String, usize>| {
            m.iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let states = self
            .states
            .iter()
            .map(|(p, s)| format!("{p}: {}", list(s)))
            .collect::<Vec<_>>()
            .join("; ");
        let f = figure;
        let warning = if self.finite {
            String::new()
        } else {
            format!("\nWARNING: not finite: {}", self.not_finite.join(", "))
        };
        format!(
            "{} frames, {} vertices, {} parts, {} component(s)\npieces: {}\nstates: {}\nrules fired: {}\nbbox [{}, {}, {}, {}], max edge strain {}, energy {}\nframe time median {} ms, max {} ms{warning}\n",
            self.frames,
            self.vertices,
            self.parts,
            self.components,
            list(&self.pieces),
            states,
            list(&self.rules_fired),
            f(self.bbox[0], 3),
            f(self.bbox[1], 3),
            f(self.bbox[2], 3),
            f(self.bbox[3], 3),
            f(self.max_edge_strain, 4),
            f(self.energy, 6),
            f(self.frame_ms.median, 2),
            f(self.frame_ms.max, 2),
        )
    }
}
