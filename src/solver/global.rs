//! The global step (paper 4.1, Eq. 4 and 7): with rotations and active states fixed the energy
//! is quadratic, its normal matrix a weighted graph Laplacian plus a diagonal (handles and the
//! proximal term), the same for x and y. This module owns the sparsity pattern (lower triangle,
//! compressed sparse columns, built once per assembly generation), fills its values and the
//! two-column right-hand side in place, and multiplies by the matrix.

use std::ops::Range;

use clay_dsl::compiled::Part;
use glam::DVec2;

use super::chunks;

/// One edge of one part, resolved to global vertices and its slot in the matrix values
/// (indices packed as `u32`, 40 bytes where `usize` took 64: the solver takes no model with
/// more vertices or parts than `u32` counts).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeSlot {
    pub part: u32,
    /// Part-local vertex indices of the edge's ends.
    pub local: [u32; 2],
    /// Global vertex indices `x`, `y`.
    pub x: u32,
    pub y: u32,
    /// Index of the `(max(x, y), min(x, y))` entry in the values, or `None` for an edge whose
    /// ends are one global vertex (it contributes nothing to the matrix).
    pub slot: Option<usize>,
}

impl EdgeSlot {
    /// The global ends `(x, y)`.
    pub fn ends(&self) -> (usize, usize) {
        (self.x as usize, self.y as usize)
    }
}

/// The sparsity pattern of the normal matrix for one assembly generation.
#[derive(Clone, Debug, Default)]
pub struct Pattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column; the first entry of column `j` is `j` itself.
    pub row_idx: Vec<usize>,
    /// Every edge of every part, part by part.
    pub edges: Vec<EdgeSlot>,
    /// The global ends `[x, y]` of `edges`, packed and compact (the solver takes no model
    /// with more vertices than `u32` counts): the per-iteration loops stream these instead
    /// of the whole slots.
    pub ends: Vec<[u32; 2]>,
    /// Per vertex, the edges it ends (compressed rows, each vertex's in edge order; an edge
    /// whose ends are one vertex is left out): `2 k` for the `x` end of edge `k`, `2 k + 1`
    /// for its `y` end. The right-hand side is gathered from these vertex by vertex, so its
    /// rows can be filled in parallel and still add their terms in the order of the serial
    /// scatter. Empty when an entry would not fit `u32` (then the scatter runs).
    pub incident_start: Vec<u32>,
    pub incident: Vec<u32>,
    /// Beside `incident`: for an end at the edge's smaller vertex, the place of the edge's
    /// entry within that vertex's column (the column holds it, below the diagonal); 0 (the
    /// diagonal's place) at the larger vertex.
    pub incident_entry: Vec<u32>,
    /// Per edge, its part (packed: the weighted right-hand side reads one per edge end).
    pub edge_part: Vec<u32>,
    /// Per part, how many of `edges` are its (they are consecutive, part by part).
    pub part_edges: Vec<usize>,
}

impl Pattern {
    /// Builds the pattern for `n` vertices and the parts' edges (all rest states of a part share
    /// its edges, so the pattern does not depend on the active states or on handles).
    pub fn build(n: usize, parts: &[Part]) -> Self {
        let mut below: Vec<Vec<usize>> = vec![Vec::new(); n];
        for part in parts {
            for e in &part.edges {
                let (x, y) = (part.vertices[e[0]], part.vertices[e[1]]);
                if x != y {
                    below[x.min(y)].push(x.max(y));
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (j, rows) in below.iter_mut().enumerate() {
            rows.sort_unstable();
            rows.dedup();
            row_idx.push(j);
            row_idx.extend_from_slice(rows);
            col_ptr.push(row_idx.len());
        }
        // the solver checks that every vertex and part index fits before it builds a pattern
        let compact = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
        let mut edges = Vec::new();
        for (pi, part) in parts.iter().enumerate() {
            for e in &part.edges {
                let (x, y) = (part.vertices[e[0]], part.vertices[e[1]]);
                let slot = (x != y).then(|| {
                    let (lo, hi) = (x.min(y), x.max(y));
                    let col = &row_idx[col_ptr[lo]..col_ptr[lo + 1]];
                    // present by construction
                    col_ptr[lo] + col.binary_search(&hi).unwrap_or(0)
                });
                edges.push(EdgeSlot {
                    part: compact(pi),
                    local: e.map(compact),
                    x: compact(x),
                    y: compact(y),
                    slot,
                });
            }
        }
        let ends = edges.iter().map(|e| [e.x, e.y]).collect();
        let (incident_start, incident) = incidence(n, &edges);
        let incident_entry = incident_entries(&col_ptr, &edges, &incident_start, &incident);
        let edge_part = edges.iter().map(|e| e.part).collect();
        let part_edges = parts.iter().map(|p| p.edges.len()).collect();
        Self {
            n,
            col_ptr,
            row_idx,
            edges,
            ends,
            incident_start,
            incident,
            incident_entry,
            edge_part,
            part_edges,
        }
    }

    /// Adds every edge's target (times its part's weight, when `weights`, one per part, is
    /// given) to row `x` and
    /// subtracts it from row `y` of `rows` (one `(x, y)` pair per vertex, holding the handle
    /// and proximal terms), each row's terms in edge order, as a serial scatter over the
    /// edges would: the same bits, on `threads` threads ([`chunks::rows`]).
    pub fn gather_rhs(
        &self,
        weights: Option<&[f64]>,
        targets: &[DVec2],
        rows: &mut [DVec2],
        threads: usize,
    ) {
        let (start, incident) = (&self.incident_start, &self.incident);
        let gather = |first: usize, chunk: &mut [DVec2]| {
            for (v, row) in (first..).zip(chunk.iter_mut()) {
                let mut acc = *row;
                for &k in &incident[start[v] as usize..start[v + 1] as usize] {
                    let e = (k >> 1) as usize;
                    let t = match weights {
                        Some(w) => w[self.edge_part[e] as usize] * targets[e],
                        None => targets[e],
                    };
                    if k & 1 == 0 {
                        acc += t;
                    } else {
                        acc -= t;
                    }
                }
                *row = acc;
            }
        };
        chunks::rows(threads, rows, &gather);
    }

    /// Pass 1's right-hand side in columns (`rhs`: every row's x, then every y): `extra` (the
    /// handle and proximal terms) plus the weighted edge targets, gathered row by row into
    /// `rows` ([`Pattern::gather_rhs`]).
    pub fn weighted_rhs(
        &self,
        weights: &[f64],
        targets: &[DVec2],
        extra: &[DVec2],
        rows: &mut Vec<DVec2>,
        rhs: &mut Vec<f64>,
        threads: usize,
    ) {
        rows.clear();
        rows.extend_from_slice(extra);
        self.gather_rhs(Some(weights), targets, rows, threads);
        rhs.clear();
        rhs.extend(rows.iter().map(|p| p.x));
        rhs.extend(rows.iter().map(|p| p.y));
    }

    /// Whether [`Pattern::gather_rhs`] can run (the incidence was built).
    pub fn can_gather(&self) -> bool {
        self.incident_start.len() == self.n + 1
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Fills `values` with the weighted Laplacian of the edges (`weights`: one per part, for
    /// all its edges) plus `diagonal`: column by column on `threads` threads
    /// ([`chunks::columns`]) from the incidence, each entry's terms in edge order as the
    /// serial scatter adds them (the same bits).
    pub fn fill_values(
        &self,
        weights: &[f64],
        diagonal: &[f64],
        values: &mut Vec<f64>,
        threads: usize,
    ) {
        if !self.can_gather() {
            return self.scatter_values(weights, diagonal, values);
        }
        values.clear();
        values.resize(self.nnz(), 0.0);
        let (start, incident) = (&self.incident_start, &self.incident);
        let fill = |columns: Range<usize>, out: &mut [f64]| {
            let base = self.col_ptr[columns.start];
            for j in columns {
                let (lo, hi) = (self.col_ptr[j], self.col_ptr[j + 1]);
                let column = &mut out[lo - base..hi - base];
                // the diagonal: its edges' weights in edge order, then the diagonal term
                let mut diag = 0.0;
                let ends = start[j] as usize..start[j + 1] as usize;
                for (&k, &entry) in incident[ends.clone()]
                    .iter()
                    .zip(&self.incident_entry[ends])
                {
                    let w = weights[self.edge_part[(k >> 1) as usize] as usize];
                    diag += w;
                    if entry > 0 {
                        column[entry as usize] -= w;
                    }
                }
                column[0] = diag + diagonal[j];
            }
        };
        chunks::columns(threads, &self.col_ptr, values, &fill);
    }

    /// [`Pattern::fill_values`] as a serial scatter over the edges (when the incidence is not
    /// built).
    fn scatter_values(&self, weights: &[f64], diagonal: &[f64], values: &mut Vec<f64>) {
        values.clear();
        values.resize(self.nnz(), 0.0);
        for e in &self.edges {
            if let Some(slot) = e.slot {
                let w = weights[e.part as usize];
                let (x, y) = e.ends();
                values[self.col_ptr[x]] += w;
                values[self.col_ptr[y]] += w;
                values[slot] -= w;
            }
        }
        for (j, &d) in diagonal.iter().enumerate() {
            values[self.col_ptr[j]] += d;
        }
    }

    /// [`Pattern::fill_values`] with every weight 1 (the least-squares matrix), without a
    /// slice of ones.
    pub fn fill_unit_values(&self, diagonal: &[f64], values: &mut Vec<f64>) {
        values.clear();
        values.resize(self.nnz(), 0.0);
        for e in &self.edges {
            if let Some(slot) = e.slot {
                let (x, y) = e.ends();
                values[self.col_ptr[x]] += 1.0;
                values[self.col_ptr[y]] += 1.0;
                values[slot] -= 1.0;
            }
        }
        for (j, &d) in diagonal.iter().enumerate() {
            values[self.col_ptr[j]] += d;
        }
    }

    /// `out = A * x` for the symmetric matrix stored as its lower triangle; `x` and `out` are
    /// column-major with `ncols` columns.
    pub fn multiply(&self, values: &[f64], x: &[f64], out: &mut [f64], ncols: usize) {
        let n = self.n;
        out[..n * ncols].fill(0.0);
        for c in 0..ncols {
            let (xc, oc) = (&x[c * n..(c + 1) * n], &mut out[c * n..(c + 1) * n]);
            for j in 0..n {
                let xj = xc[j];
                let mut acc = 0.0;
                let range = self.col_ptr[j]..self.col_ptr[j + 1];
                for (&i, &v) in self.row_idx[range.clone()].iter().zip(&values[range]) {
                    oc[i] += v * xj;
                    if i != j {
                        acc += v * xc[i];
                    }
                }
                oc[j] += acc;
            }
        }
    }
}

/// Per vertex, the edge ends at it, in edge order ([`Pattern::incident`]); empty when an
/// entry would not fit `u32`.
fn incidence(n: usize, edges: &[EdgeSlot]) -> (Vec<u32>, Vec<u32>) {
    if u32::try_from(2 * edges.len() + 1).is_err() {
        return (Vec::new(), Vec::new());
    }
    let mut start = vec![0u32; n + 1];
    for e in edges.iter().filter(|e| e.slot.is_some()) {
        let (x, y) = e.ends();
        start[x + 1] += 1;
        start[y + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut incident = vec![0u32; start[n] as usize];
    for (k, e) in edges.iter().enumerate().filter(|(_, e)| e.slot.is_some()) {
        let (x, y) = e.ends();
        for (v, end) in [(x, 0), (y, 1)] {
            incident[fill[v] as usize] = (2 * k + end) as u32;
            fill[v] += 1;
        }
    }
    (start, incident)
}

/// Per entry of the incidence, [`Pattern::incident_entry`].
fn incident_entries(
    col_ptr: &[usize],
    edges: &[EdgeSlot],
    start: &[u32],
    incident: &[u32],
) -> Vec<u32> {
    let mut entries = vec![0u32; incident.len()];
    for (j, pair) in start.windows(2).enumerate() {
        let range = pair[0] as usize..pair[1] as usize;
        for (&k, entry) in incident[range.clone()].iter().zip(&mut entries[range]) {
            let e = &edges[(k >> 1) as usize];
            if let Some(slot) = e.slot
                && e.x.min(e.y) as usize == j
            {
                // within the column of a vertex index that fits u32 (the solver checks)
                *entry = (slot - col_ptr[j]) as u32;
            }
        }
    }
    entries
}

/// Writes the right-hand side: for each edge, `w * R_xy (x0 - y0)` (`w` its part's weight in
/// `weights`) into row x and its negation into row y, plus `extra` (handle and proximal
/// terms), for the x column then the y column.
pub fn fill_rhs(
    edges: &[EdgeSlot],
    weights: &[f64],
    targets: &[DVec2],
    extra: &[DVec2],
    rhs: &mut Vec<f64>,
) {
    let n = extra.len();
    rhs.clear();
    rhs.resize(2 * n, 0.0);
    for (i, e) in extra.iter().enumerate() {
        rhs[i] = e.x;
        rhs[n + i] = e.y;
    }
    for (e, &t) in edges.iter().zip(targets) {
        if e.slot.is_some() {
            let w = weights[e.part as usize];
            let c = w * t;
            let (x, y) = e.ends();
            rhs[x] += c.x;
            rhs[n + x] += c.y;
            rhs[y] -= c.x;
            rhs[n + y] -= c.y;
        }
    }
}

/// [`fill_rhs`] with every weight 1 (the least-squares pass), over the packed edge ends. An
/// edge whose ends are one vertex adds and removes the same target at one row, so it is
/// skipped as `fill_rhs` skips it.
pub fn fill_rhs_unit(ends: &[[u32; 2]], targets: &[DVec2], extra: &[DVec2], rhs: &mut Vec<f64>) {
    let n = extra.len();
    rhs.clear();
    rhs.resize(2 * n, 0.0);
    let (xs, ys) = rhs.split_at_mut(n);
    for (i, e) in extra.iter().enumerate() {
        xs[i] = e.x;
        ys[i] = e.y;
    }
    for (&[x, y], &t) in ends.iter().zip(targets) {
        let (x, y) = (x as usize, y as usize);
        if x != y {
            xs[x] += t.x;
            ys[x] += t.y;
            xs[y] -= t.x;
            ys[y] -= t.y;
        }
    }
}

/// Relative residual `|b - A x| / |b|` over both columns.
pub fn relative_residual(
    pattern: &Pattern,
    values: &[f64],
    x: &[f64],
    b: &[f64],
    scratch: &mut Vec<f64>,
) -> f64 {
    scratch.resize(b.len(), 0.0);
    pattern.multiply(values, x, scratch, 2);
    let (mut num, mut den) = (0.0, 0.0);
    for (ax, bi) in scratch.iter().zip(b) {
        num += (bi - ax) * (bi - ax);
        den += bi * bi;
    }
    if den > 0.0 {
        (num / den).sqrt()
    } else {
        num.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clay_dsl::compiled::PartKind;

    /// Parts over a strip of `n` vertices: quads of overlapping vertex runs (so neighbours
    /// share edges and an entry gets several terms), a part whose two ends are one vertex (an
    /// edge with no entry), and an edgeless part.
    fn strip_parts(n: usize) -> Vec<Part> {
        let part = |vertices: Vec<usize>, edges: Vec<[usize; 2]>| Part {
            kind: PartKind::Piece { instance: 0 },
            vertices,
            edges,
            states: Vec::new(),
            active: 0,
        };
        let mut parts: Vec<Part> = (0..n - 3)
            .step_by(2)
            .map(|a| {
                part(
                    vec![a, a + 1, a + 2, a + 3],
                    vec![[0, 1], [1, 2], [2, 3], [0, 3], [0, 2]],
                )
            })
            .collect();
        parts.push(part(vec![5, 5, 9], vec![[0, 1], [1, 2]]));
        parts.push(part(vec![7], Vec::new()));
        parts
    }

    #[test]
    fn matrix_values_by_columns_equal_the_serial_scatter_bit_for_bit() {
        // enough vertices for the columns to run as tasks on two threads
        let n = 5 * 4096 + 3;
        let parts = strip_parts(n);
        let pattern = Pattern::build(n, &parts);
        assert!(pattern.can_gather());
        // weights whose sums round: added in another order they would differ in the last bits
        let weights: Vec<f64> = (0..parts.len())
            .map(|i| 1.0 / (1.0 + (i as f64 * 0.618).fract() * 1e3) + (i % 7) as f64 * 1e-9)
            .collect();
        let diagonal: Vec<f64> = (0..n).map(|j| 1e-3 * (j % 11) as f64 + 1e-7).collect();
        let mut serial = Vec::new();
        pattern.scatter_values(&weights, &diagonal, &mut serial);
        for threads in [1, 2] {
            let mut by_columns = vec![f64::NAN; 3];
            pattern.fill_values(&weights, &diagonal, &mut by_columns, threads);
            assert_eq!(by_columns.len(), serial.len());
            let differ =
                (serial.iter().zip(&by_columns)).position(|(a, b)| a.to_bits() != b.to_bits());
            assert_eq!(differ, None, "{threads} threads: first differing value");
        }
        // a shared edge (vertices 2-3 belong to two quads) sums both parts' weights
        let slot = pattern.col_ptr[2]
            + pattern.row_idx[pattern.col_ptr[2]..pattern.col_ptr[3]]
                .binary_search(&3)
                .unwrap();
        assert_eq!(serial[slot], -weights[0] - weights[1]);
    }
}
