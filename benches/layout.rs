//! Criterion benchmark of the local step's per-part loop in two data layouts (issue 21):
//! vertex positions as one array of `(x, y)` pairs, which is what the solver keeps, against
//! a structure of arrays, `x` and `y` apart. The loop is the fixed-state local step's core
//! on the bench's city (`clayc bench --parts N`): per part, gather and centre its vertices,
//! fit the active rest state's rotation, write its edges' targets and sum their squared
//! residuals. One kernel serves both layouts through the position lookup it is given, so
//! they do the same arithmetic in the same order (each run asserts equal sums).

use std::sync::Arc;

use clay::{Assembly, synthetic};
use criterion::{Criterion, criterion_group};
use glam::DVec2;

/// The city's parts, flattened as the solver's rest cache flattens them.
struct Parts {
    /// Part `i`'s vertices are `vertices[first_vertex[i]..first_vertex[i + 1]]`.
    first_vertex: Vec<u32>,
    vertices: Vec<u32>,
    /// The active state's centred rest position of each entry of `vertices`.
    rest: Vec<DVec2>,
    /// Part `i`'s edges are `ends[first_edge[i]..first_edge[i + 1]]` (global vertices).
    first_edge: Vec<u32>,
    ends: Vec<[u32; 2]>,
    rest_edges: Vec<DVec2>,
}

impl Parts {
    fn of(asm: &Assembly) -> Self {
        let mut p = Parts {
            first_vertex: vec![0],
            vertices: vec![],
            rest: vec![],
            first_edge: vec![0],
            ends: vec![],
            rest_edges: vec![],
        };
        for part in &asm.data().parts {
            let state = &part.states[part.active.min(part.states.len() - 1)].positions;
            let centre = state.iter().sum::<DVec2>() / state.len() as f64;
            for (k, &v) in part.vertices.iter().enumerate() {
                p.vertices.push(v as u32);
                p.rest.push(state[k] - centre);
            }
            p.first_vertex.push(p.vertices.len() as u32);
            for &[a, b] in &part.edges {
                p.ends
                    .push([part.vertices[a] as u32, part.vertices[b] as u32]);
                p.rest_edges.push(state[a] - state[b]);
            }
            p.first_edge.push(p.ends.len() as u32);
        }
        p
    }

    /// One pass of the loop, positions read through `at`; returns the residuals' sum.
    #[inline(always)]
    fn pass(&self, at: impl Fn(u32) -> DVec2, targets: &mut [DVec2]) -> f64 {
        let mut total = 0.0;
        for i in 0..self.first_vertex.len() - 1 {
            let range = self.first_vertex[i] as usize..self.first_vertex[i + 1] as usize;
            let (vertices, rest) = (&self.vertices[range.clone()], &self.rest[range]);
            let centre = vertices.iter().map(|&v| at(v)).sum::<DVec2>() / vertices.len() as f64;
            let (mut dot, mut cross) = (0.0, 0.0);
            for (r, &v) in rest.iter().zip(vertices) {
                let q = at(v) - centre;
                dot += r.dot(q);
                cross += r.perp_dot(q);
            }
            let rotation = DVec2::new(dot, cross).normalize_or(DVec2::X);
            let edges = self.first_edge[i] as usize..self.first_edge[i + 1] as usize;
            for k in edges {
                let t = rotation.rotate(self.rest_edges[k]);
                targets[k] = t;
                let [x, y] = self.ends[k];
                total += (t - (at(x) - at(y))).length_squared();
            }
        }
        total
    }
}

fn layouts(c: &mut Criterion) {
    let mut group = c.benchmark_group("local_step_layout");
    for parts in [10_000, 100_000] {
        let asm = Assembly::new(Arc::new(synthetic::city(parts)));
        let flat = Parts::of(&asm);
        // a deformed pose, so rotations and residuals are not trivial
        let pairs: Vec<DVec2> = (asm.data().positions.iter())
            .map(|q| *q + DVec2::new((q.y * 0.01).sin(), (q.x * 0.013).cos()) * 0.3)
            .collect();
        let xs: Vec<f64> = pairs.iter().map(|q| q.x).collect();
        let ys: Vec<f64> = pairs.iter().map(|q| q.y).collect();
        let mut targets = vec![DVec2::ZERO; flat.ends.len()];
        let by_pairs = flat.pass(|v| pairs[v as usize], &mut targets);
        let by_arrays = flat.pass(|v| DVec2::new(xs[v as usize], ys[v as usize]), &mut targets);
        assert_eq!(
            by_pairs.to_bits(),
            by_arrays.to_bits(),
            "the layouts disagree"
        );
        group.bench_function(format!("pairs/{parts}"), |b| {
            b.iter(|| flat.pass(|v| pairs[v as usize], &mut targets))
        });
        group.bench_function(format!("arrays/{parts}"), |b| {
            b.iter(|| flat.pass(|v| DVec2::new(xs[v as usize], ys[v as usize]), &mut targets))
        });
    }
    group.finish();
}

criterion_group!(benches, layouts);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
