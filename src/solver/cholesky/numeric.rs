//! Our numeric supernodal Cholesky: the factor of faer's symbolic analysis (its ordering and
//! supernodes), computed straight into the solve order of [`super::NumericFactor::solve_order`].
//!
//! Why not faer's numeric factorisation: most supernodes of these planar Laplacians are a few
//! columns wide, and faer's per-supernode dense kernels (gemm plans, scratch matrices) cost
//! more there than the arithmetic, as for the solves; on the few wide separators our kernels
//! run independent chains side by side and keep up with faer's (city, interleaved, factor
//! time ours / faer's, one core each: 0.49 at 10k parts and 0.94 at 100k, where 87% of the
//! arithmetic is in supernodes wider than 16 columns), and the factor is made once, in
//! solve order, with no second copy (peak memory at 100k 12% lower). Pass 1 factorises its matrix once per IRLS
//! iteration, so this is most of a frame's factorisation time (docs/performance.md).
//!
//! The method is right-looking: supernodes in order (every update goes to a later one), each
//! factorised densely (its diagonal block by Cholesky, the rows below it by substitution),
//! then its rows below subtract their products from the supernodes of their columns. The
//! order of every sum is fixed by the symbolic structure, so the result does not depend on
//! anything but the matrix. Where the elimination tree has two balanced halves under its top
//! separators ([`split`]), they are factorised side by side (on two threads if asked, the
//! same bits on one), then the top.

use std::ops::Range;

use super::layout::{FactorError, SupernodalLayout, by_width};
use super::split::{self, Split};
use crate::solver::chunks::join;

/// Where each stored value of the matrix (lower triangle, original order) goes in the factor's
/// values in solve order: built once per pattern.
#[derive(Debug, Clone)]
pub(super) struct Scatter {
    /// `position[k]`: the place of the matrix's `k`-th stored value (`u32`: a factor of more
    /// values is left to faer).
    position: Vec<u32>,
    /// `column_supernode[c]`: the supernode holding permuted column `c`.
    column_supernode: Vec<u32>,
    /// The two halves two threads factorise side by side, if the tree has them.
    split: Option<Split>,
    /// The second half's updates of the supernodes after both halves (added after both).
    deferred: Vec<f64>,
    /// Scratch of each half.
    scratch: [Scratch; 2],
}

/// Scratch memory of one thread's factorisation.
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// The rows of one update, as places among the rows below its target supernode.
    relative: Vec<u32>,
    /// A diagonal block row by row ([`substitute_rows`]).
    transposed: Vec<f64>,
}

/// Where a run of supernodes writes: its own values (`near`, the factor's values from
/// `near_offset` on, up to the run's end) and the top's, when the run is a half's subtree
/// (`far`: pieces of the factor, or of a buffer of updates added later, at their offsets).
struct Sink<'a, 'b> {
    near: &'a mut [f64],
    near_offset: usize,
    far: &'a mut [(usize, &'b mut [f64])],
}

impl Sink<'_, '_> {
    /// The values of the supernode whose block starts at `at`, to the end of its slice.
    fn at(&mut self, at: usize) -> &mut [f64] {
        if at >= self.near_offset && at < self.near_offset + self.near.len() {
            return &mut self.near[at - self.near_offset..];
        }
        // a target outside the run is in the top: the piece holding it
        let k = self.far.partition_point(|(offset, _)| *offset <= at) - 1;
        let (offset, piece) = &mut self.far[k];
        &mut piece[at - *offset..]
    }
}

impl Scatter {
    /// The halves the factorisation runs side by side, if it is split.
    pub(super) fn split(&self) -> Option<&Split> {
        self.split.as_ref()
    }

    /// The scatter map of the matrix (`col_ptr`, `row_idx`: lower triangle, original order)
    /// into `layout`; `None` if an entry has no place in it (then faer factorises).
    pub(super) fn new(
        layout: &SupernodalLayout,
        col_ptr: &[usize],
        row_idx: &[usize],
    ) -> Option<Self> {
        let n = layout.perm.len();
        let mut inverse = vec![0usize; n];
        for (i, &p) in layout.perm.iter().enumerate() {
            *inverse.get_mut(p)? = i;
        }
        let mut column_supernode = vec![0u32; n];
        for s in 0..layout.val_start.len() {
            let (start, size, _, _) = layout.supernode(s);
            column_supernode[start..start + size].fill(u32::try_from(s).ok()?);
        }
        let mut position = Vec::with_capacity(row_idx.len());
        for c in 0..n {
            for &r in &row_idx[*col_ptr.get(c)?..*col_ptr.get(c + 1)?] {
                let (a, b) = (*inverse.get(r)?, inverse[c]);
                let (col, row) = (a.min(b), a.max(b));
                let (start, size, below, at) = layout.supernode(column_supernode[col] as usize);
                let place = if row < start + size {
                    at + (col - start) * size + (row - start)
                } else {
                    let k = below.binary_search(&u32::try_from(row).ok()?).ok()?;
                    at + size * size + k * size + (col - start)
                };
                position.push(u32::try_from(place).ok()?);
            }
        }
        if !nested(layout, &column_supernode) {
            return None;
        }
        let split = split::find(layout, &column_supernode);
        Some(Self {
            position,
            column_supernode,
            split,
            deferred: Vec::new(),
            scratch: Default::default(),
        })
    }

    /// Factorises the matrix with stored values `values` into `out` (solve order: each
    /// supernode's diagonal block column-major with reciprocal diagonal entries, then its rows
    /// below row-major); the two halves of the split on two threads when `threads > 1`, with
    /// the same result.
    pub(super) fn factorise(
        &mut self,
        layout: &SupernodalLayout,
        values: &[f64],
        out: &mut Vec<f64>,
        len: usize,
        threads: usize,
    ) -> Result<(), FactorError> {
        out.clear();
        out.resize(len, 0.0);
        for (&place, &v) in self.position.iter().zip(values) {
            out[place as usize] += v;
        }
        let count = layout.val_start.len();
        let columns = &self.column_supernode[..];
        let [one, two] = &mut self.scratch;
        let Some(split) = &self.split else {
            return run(
                layout,
                columns,
                &mut self.scratch,
                threads,
                0..count,
                whole(out),
            );
        };
        // the factor's values cut at the groups' boundaries: each half's subtrees, and the
        // top's runs (written directly by the first half, through `deferred` by the second)
        let value_range = |r: &Range<usize>| {
            let end = layout.val_start.get(r.end).copied().unwrap_or(len);
            layout.val_start[r.start]..end
        };
        let mut groups: Vec<(usize, Range<usize>)> = (split.halves.iter().enumerate())
            .flat_map(|(h, runs)| runs.iter().map(move |r| (h, r.clone())))
            .chain(split.top.iter().map(|r| (2, r.clone())))
            .collect();
        groups.sort_by_key(|(_, r)| r.start);
        let top_len: usize = split.top.iter().map(|r| value_range(r).len()).sum();
        self.deferred.clear();
        self.deferred.resize(top_len, 0.0);
        let mut halves: [Vec<Subtree>; 2] = Default::default();
        let (mut direct, mut through) = (Vec::new(), Vec::new());
        let (mut rest, mut deferred) = (&mut out[..], &mut self.deferred[..]);
        for (h, nodes) in groups {
            let values = value_range(&nodes);
            let piece;
            (piece, rest) = std::mem::take(&mut rest).split_at_mut(values.len());
            if h == 2 {
                let buffer;
                (buffer, deferred) = std::mem::take(&mut deferred).split_at_mut(values.len());
                direct.push((values.start, piece));
                through.push((values.start, buffer));
            } else {
                halves[h].push((nodes, values.start, piece));
            }
        }
        let [first, second] = halves;
        let half = |scratch: &mut Scratch, runs: Vec<Subtree>, top: &mut Far| {
            for (nodes, near_offset, near) in runs {
                let sink = Sink {
                    near,
                    near_offset,
                    far: &mut top[..],
                };
                run(
                    layout,
                    columns,
                    std::slice::from_mut(scratch),
                    1,
                    nodes,
                    sink,
                )?;
            }
            Ok::<(), FactorError>(())
        };
        let (a, b) = join(
            threads,
            || half(one, first, &mut direct),
            || half(two, second, &mut through),
        );
        a.and(b)?;
        let mut added = 0;
        for r in &split.top {
            let values = value_range(r);
            let buffer = &self.deferred[added..][..values.len()];
            for (v, d) in out[values.clone()].iter_mut().zip(buffer) {
                *v += d;
            }
            added += values.len();
        }
        for nodes in &split.top {
            let both = &mut self.scratch[..];
            run(layout, columns, both, threads, nodes.clone(), whole(out))?;
        }
        Ok(())
    }
}

/// The top's pieces of the factor's values a half writes to: (offset, values), in order.
type Far<'a> = Vec<(usize, &'a mut [f64])>;

/// A half's subtree: its supernodes, and the factor's values they hold (offset, values).
type Subtree<'a> = (Range<usize>, usize, &'a mut [f64]);

/// A sink over all of the factor's values.
fn whole(out: &mut [f64]) -> Sink<'_, 'static> {
    Sink {
        near: out,
        near_offset: 0,
        far: &mut [],
    }
}

/// Factorises the supernodes `range` (each after every supernode below it), writing through
/// `sink`. With two scratches, `threads > 1` and no far pieces (the top, or a factor that is
/// not split), a supernode with much work below its diagonal block shares it with a second
/// thread ([`share_rows`]).
fn run(
    layout: &SupernodalLayout,
    column_supernode: &[u32],
    scratch: &mut [Scratch],
    threads: usize,
    range: Range<usize>,
    mut sink: Sink,
) -> Result<(), FactorError> {
    for s in range {
        let (start, size, below, at) = layout.supernode(s);
        let local = at - sink.near_offset;
        let end_of_block = local + (size + below.len()) * size;
        let (head, later) = std::mem::take(&mut sink.near).split_at_mut(end_of_block);
        let block = &mut head[local..];
        let (diagonal, rows) = block.split_at_mut(size * size);
        let wide = threads > 1 && scratch.len() > 1 && sink.far.is_empty();
        let wide = wide && (size * size * size) as f64 / 3.0 >= 4.0 * MIN_SHARED;
        let factorised = if wide {
            factorise_diagonal_shared(diagonal, size, threads)
        } else {
            factorise_diagonal(diagonal, size)
        };
        factorised.map_err(|c| {
            FactorError(format!(
                "numeric Cholesky failed: the matrix is not positive definite (column {})",
                start + c
            ))
        })?;
        // the substitutions multiply by the reciprocals: a division per value sat on
        // each row's dependency chain
        for c in 0..size {
            diagonal[c * size + c] = 1.0 / diagonal[c * size + c];
        }
        let mut rest = Sink {
            near: later,
            near_offset: sink.near_offset + end_of_block,
            far: std::mem::take(&mut sink.far),
        };
        let (w, b) = (size as f64, below.len() as f64);
        let shared = threads > 1 && rest.far.is_empty() && b * w * (w + b / 2.0) >= MIN_SHARED;
        match scratch {
            [one, two, ..] if shared => {
                let rows = share_rows(diagonal, size, rows, [one, two], threads);
                let s = Shared {
                    layout,
                    column_supernode,
                    below,
                    rows,
                    size,
                };
                s.update_later([one, two], threads, rest.near, rest.near_offset);
            }
            [one, ..] => {
                substitute_rows(diagonal, size, rows, &mut one.transposed);
                let all = 0..below.len();
                let (columns, rows) = (column_supernode, &*rows);
                update_later(layout, columns, one, below, rows, size, all, &mut rest);
            }
            [] => unreachable!("run has a scratch"),
        }
        sink = rest;
    }
    Ok(())
}

/// The work (multiply-adds) below a supernode's diagonal block from which [`run`] shares it
/// between two threads: a thread's hand-over costs some microseconds.
pub(super) const MIN_SHARED: f64 = 100_000.0;

/// [`substitute_rows`] with the rows cut in two halves, one per thread (each row is computed
/// alone, so the cut changes no bit); returns the rows.
fn share_rows<'a>(
    diagonal: &[f64],
    size: usize,
    rows: &'a mut [f64],
    [one, two]: [&mut Scratch; 2],
    threads: usize,
) -> &'a [f64] {
    let cut = rows.len() / size / 2 * size;
    let (a, b) = rows.split_at_mut(cut);
    join(
        threads,
        || substitute_rows(diagonal, size, a, &mut one.transposed),
        || substitute_rows(diagonal, size, b, &mut two.transposed),
    );
    rows
}

/// One supernode's factorised rows below, for updates shared by two threads.
struct Shared<'a> {
    layout: &'a SupernodalLayout,
    column_supernode: &'a [u32],
    below: &'a [u32],
    rows: &'a [f64],
    size: usize,
}

impl Shared<'_> {
    /// [`update_later`] with the targets cut in two runs of about equal work, one per thread:
    /// each target receives one group of products, computed as on one thread, and the runs'
    /// values are apart (`later`: the factor's values from `offset` on).
    fn update_later(
        &self,
        [one, two]: [&mut Scratch; 2],
        threads: usize,
        later: &mut [f64],
        offset: usize,
    ) {
        let (below, n) = (self.below, self.below.len());
        // each group (rows in one target's columns) costs about its rows times the rows after
        let mut groups = Vec::new();
        let (mut g, mut total) = (0, 0.0);
        while g < n {
            let t = self.column_supernode[below[g] as usize] as usize;
            let (start, width, _, at) = self.layout.supernode(t);
            let group = below[g..]
                .iter()
                .take_while(|&&r| (r as usize) < start + width)
                .count();
            total += (group * (n - g)) as f64;
            groups.push((g, at, total));
            g += group;
        }
        // the second run starts after the group that reaches half the work
        let k = groups.iter().position(|&(_, _, sum)| sum >= total / 2.0);
        let (cut, split_at) = match k.and_then(|k| groups.get(k + 1)) {
            Some(&(g, at, _)) => (g, at - offset),
            None => (n, later.len()),
        };
        let (a, b) = later.split_at_mut(split_at);
        let (layout, columns, rows, size) =
            (self.layout, self.column_supernode, self.rows, self.size);
        join(
            threads,
            || {
                let mut sink = Sink {
                    near: a,
                    near_offset: offset,
                    far: &mut [],
                };
                update_later(layout, columns, one, below, rows, size, 0..cut, &mut sink);
            },
            || {
                let mut sink = Sink {
                    near: b,
                    near_offset: offset + split_at,
                    far: &mut [],
                };
                update_later(layout, columns, two, below, rows, size, cut..n, &mut sink);
            },
        );
    }
}

/// Subtracts the products of one supernode's rows below (`rows`, row-major, `size` wide,
/// at permuted rows `below`) from the supernodes of their columns, through `sink` (every
/// target lies after the supernode).
#[allow(clippy::too_many_arguments)]
fn update_later(
    layout: &SupernodalLayout,
    column_supernode: &[u32],
    scratch: &mut Scratch,
    below: &[u32],
    rows: &[f64],
    size: usize,
    groups: Range<usize>,
    sink: &mut Sink,
) {
    let mut g = groups.start;
    while g < groups.end {
        let t = column_supernode[below[g] as usize] as usize;
        let (start, width, target_below, at) = layout.supernode(t);
        let end = start + width;
        let group = below[g..]
            .iter()
            .take_while(|&&r| (r as usize) < end)
            .count();
        // the rows after the group are among the target's rows below (the supernodal
        // structure): their places, by one merge of the two sorted lists
        scratch.relative.clear();
        let mut k = 0;
        for &r in &below[g + group..] {
            while target_below[k] != r {
                k += 1;
            }
            scratch.relative.push(k as u32);
        }
        let target = Target {
            start,
            width,
            relative: &scratch.relative,
        };
        let values = sink.at(at);
        let source = Source {
            below,
            rows,
            g,
            group,
        };
        by_width!(size, update, update_wide, target, source, values);
        g += group;
    }
}

/// Whether every supernode's rows below, past the columns of the supernode they first fall
/// in, are among that supernode's rows below: what the update's merge relies on (true of a
/// supernodal Cholesky structure; checked once per pattern so a violation means faer's
/// factorisation rather than a wrong factor).
fn nested(layout: &SupernodalLayout, column_supernode: &[u32]) -> bool {
    (0..layout.val_start.len()).all(|s| {
        let (_, _, below, _) = layout.supernode(s);
        let mut g = 0;
        while g < below.len() {
            let (start, width, target, _) =
                layout.supernode(column_supernode[below[g] as usize] as usize);
            let group = below[g..]
                .iter()
                .take_while(|&&r| (r as usize) < start + width)
                .count();
            let mut k = 0;
            for &r in &below[g + group..] {
                while k < target.len() && target[k] != r {
                    k += 1;
                }
                if k == target.len() {
                    return false;
                }
            }
            g += group;
        }
        true
    })
}

/// In-place dense Cholesky of the lower triangle of a `size x size` column-major block;
/// `Err(c)` at the first column whose pivot is not positive and finite.
///
/// Column `j` below the diagonal takes `L_ij = (A_ij - sum_k L_ik L_jk) / L_jj` with the sum
/// over `k` in increasing order, subtracted from the stored value one product at a time; the
/// loop runs over `k` outside and `i` inside so the rows' chains are independent (they overlap
/// in the pipeline and vectorise along the contiguous column) while every value sees the same
/// operations in the same order as the textbook loop: the factor is the same to the bit.
fn factorise_diagonal(d: &mut [f64], size: usize) -> Result<(), usize> {
    for j in 0..size {
        let (done, rest) = d.split_at_mut(j * size);
        let column = &mut rest[..size];
        let mut pivot = column[j];
        for k in 0..j {
            let l = done[k * size + j];
            pivot -= l * l;
        }
        if !(pivot > 0.0 && pivot.is_finite()) {
            return Err(j);
        }
        let ljj = pivot.sqrt();
        column[j] = ljj;
        let below = &mut column[j + 1..];
        for k in 0..j {
            let l = done[k * size + j];
            let source = &done[k * size + j + 1..][..below.len()];
            for (v, &x) in below.iter_mut().zip(source) {
                *v -= x * l;
            }
        }
        for v in below {
            *v /= ljj;
        }
    }
    Ok(())
}

/// [`factorise_diagonal`] by panels of columns, the updates of the columns after a panel
/// shared by two threads (`threads > 1`): each value still subtracts the products of the
/// columns before it one by one in increasing order, so the factor is the same to the bit.
fn factorise_diagonal_shared(d: &mut [f64], size: usize, threads: usize) -> Result<(), usize> {
    const PANEL: usize = 32;
    let mut p0 = 0;
    while p0 < size {
        let p1 = (p0 + PANEL).min(size);
        // the panel's columns: the products of its earlier columns, then the pivot
        for j in p0..p1 {
            let (done, rest) = d.split_at_mut(j * size);
            let column = &mut rest[..size];
            for k in p0..j {
                let l = done[k * size + j];
                let source = &done[k * size + j..k * size + size];
                for (v, &x) in column[j..].iter_mut().zip(source) {
                    *v -= x * l;
                }
            }
            let pivot = column[j];
            if !(pivot > 0.0 && pivot.is_finite()) {
                return Err(j);
            }
            let ljj = pivot.sqrt();
            column[j] = ljj;
            for v in &mut column[j + 1..] {
                *v /= ljj;
            }
        }
        if p1 == size {
            break;
        }
        // the panel's products into every later column, in two runs of about equal work
        // (column j has size - j values)
        let total: usize = (p1..size).map(|j| size - j).sum();
        let (mut m, mut sum) = (p1, 0);
        while m < size && 2 * sum < total {
            sum += size - m;
            m += 1;
        }
        let (head, rest) = d.split_at_mut(p1 * size);
        let panel = &head[p0 * size..];
        let (a, b) = rest.split_at_mut((m - p1) * size);
        let trailing = |columns: &mut [f64], first: usize| {
            for (c, column) in columns.chunks_exact_mut(size).enumerate() {
                let j = first + c;
                for k in 0..p1 - p0 {
                    let source = &panel[k * size..][..size];
                    let l = source[j];
                    for (v, &x) in column[j..].iter_mut().zip(&source[j..]) {
                        *v -= x * l;
                    }
                }
            }
        };
        join(threads, || trailing(a, p1), || trailing(b, m));
        p0 = p1;
    }
    Ok(())
}

/// `row <- row L^-T` for every row below a factorised diagonal block `d` (its diagonal
/// entries already replaced by their reciprocals), rows `size` wide and row-major.
///
/// Four rows at a time: each row's value is the same chain of operations as alone (so the
/// result is the same to the bit), but four chains run side by side and each entry of `d` is
/// loaded once for the four. `transposed` is scratch for `d` row by row (contiguous reads).
fn substitute_rows(d: &[f64], size: usize, rows: &mut [f64], transposed: &mut Vec<f64>) {
    transposed.clear();
    transposed.extend((0..size * size).map(|at| d[(at % size) * size + at / size]));
    let lt = &transposed[..];
    let mut quads = rows.chunks_exact_mut(4 * size);
    for quad in &mut quads {
        let (r0, rest) = quad.split_at_mut(size);
        let (r1, rest) = rest.split_at_mut(size);
        let (r2, r3) = rest.split_at_mut(size);
        for c in 0..size {
            let l = &lt[c * size..][..c];
            let (mut v0, mut v1, mut v2, mut v3) = (r0[c], r1[c], r2[c], r3[c]);
            for k in 0..c {
                v0 -= r0[k] * l[k];
                v1 -= r1[k] * l[k];
                v2 -= r2[k] * l[k];
                v3 -= r3[k] * l[k];
            }
            let inv = lt[c * size + c];
            (r0[c], r1[c], r2[c], r3[c]) = (v0 * inv, v1 * inv, v2 * inv, v3 * inv);
        }
    }
    for row in quads.into_remainder().chunks_exact_mut(size) {
        for c in 0..size {
            let l = &lt[c * size..][..c];
            let mut v = row[c];
            for k in 0..c {
                v -= row[k] * l[k];
            }
            row[c] = v * lt[c * size + c];
        }
    }
}

/// The supernode an update goes to: its first column, its width, and the places among its
/// rows below of the update's rows after those in its columns.
struct Target<'a> {
    start: usize,
    width: usize,
    relative: &'a [u32],
}

/// The supernode an update comes from: its rows below (`rows`, row-major, at permuted rows
/// `below`) and the `group` of them from `g` that fall in the target's columns.
struct Source<'a> {
    below: &'a [u32],
    rows: &'a [f64],
    g: usize,
    group: usize,
}

/// Subtracts from `values` (the target's, in solve order) the products of row `j` with the
/// rows after it, for the `group` rows `j` from `g` that fall in the target's columns; rows
/// `S` wide. Rows in the target's columns go to its diagonal block (column-major), the rest to
/// its rows below (row-major).
#[inline]
fn update<const S: usize>(target: Target, source: Source, values: &mut [f64]) {
    let Source {
        below,
        rows,
        g,
        group,
    } = source;
    let rows: &[[f64; S]] = rows.as_chunks::<S>().0;
    let w = target.width;
    let (diagonal, lower) = values.split_at_mut(w * w);
    let dot = |a: &[f64; S], b: &[f64; S]| {
        let mut d = 0.0;
        for k in 0..S {
            d += a[k] * b[k];
        }
        d
    };
    for j in g..g + group {
        let column = below[j] as usize - target.start;
        let xj = &rows[j];
        let col = &mut diagonal[column * w..][..w];
        for (&r, xi) in below[j..g + group].iter().zip(&rows[j..g + group]) {
            col[r as usize - target.start] -= dot(xi, xj);
        }
        for (&k, xi) in target.relative.iter().zip(&rows[g + group..]) {
            lower[k as usize * w + column] -= dot(xi, xj);
        }
    }
}

/// [`update`] for rows of any width. The products of row `j` with four rows after it are
/// summed side by side (four independent chains, each summed in the same order as one dot
/// product alone: the same values to the bit), so each entry of row `j` is loaded once for
/// four products and the additions overlap rather than wait on one another.
fn update_wide(size: usize, target: Target, source: Source, values: &mut [f64]) {
    let Source {
        below,
        rows,
        g,
        group,
    } = source;
    let w = target.width;
    let (diagonal, lower) = values.split_at_mut(w * w);
    let row = |i: usize| &rows[i * size..][..size];
    for j in g..g + group {
        let column = below[j] as usize - target.start;
        let xj = row(j);
        // rows in the target's columns, then the rest: one list of (row, place) pairs
        let in_block = (j..g + group).map(|i| (i, column * w + below[i] as usize - target.start));
        dots_into(rows, size, xj, in_block, |place, d| diagonal[place] -= d);
        let beyond = (g + group..)
            .zip(target.relative)
            .map(|(i, &k)| (i, k as usize * w + column));
        dots_into(rows, size, xj, beyond, |place, d| lower[place] -= d);
    }
}

/// For every `(i, place)` of `pairs`, `apply(place, row_i . x)` (rows `size` wide), four dot
/// products at a time; each one sums its products from `k = 0` up, from `-0.0` as
/// `Iterator::sum` does.
#[inline]
fn dots_into(
    rows: &[f64],
    size: usize,
    x: &[f64],
    pairs: impl Iterator<Item = (usize, usize)>,
    mut apply: impl FnMut(usize, f64),
) {
    let row = |i: usize| &rows[i * size..][..size];
    let mut pending = [(0usize, 0usize); 4];
    let mut count = 0;
    for pair in pairs {
        pending[count] = pair;
        count += 1;
        if count == 4 {
            let [a, b, c, e] = pending.map(|(i, _)| row(i));
            let mut d = [-0.0f64; 4];
            for k in 0..size {
                let xk = x[k];
                d[0] += a[k] * xk;
                d[1] += b[k] * xk;
                d[2] += c[k] * xk;
                d[3] += e[k] * xk;
            }
            for (&(_, place), d) in pending.iter().zip(d) {
                apply(place, d);
            }
            count = 0;
        }
    }
    for &(i, place) in &pending[..count] {
        let d = row(i).iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        apply(place, d);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic values in (-1, 1).
    fn values(count: usize, seed: u64) -> Vec<f64> {
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        (0..count)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    /// A positive definite `size x size` block, column-major.
    fn spd(size: usize, seed: u64) -> Vec<f64> {
        let a = values(size * size, seed);
        let mut m = vec![0.0; size * size];
        for i in 0..size {
            for j in 0..size {
                m[j * size + i] = (0..size).map(|k| a[k * size + i] * a[k * size + j]).sum();
            }
            m[i * size + i] += size as f64;
        }
        m
    }

    /// The kernels reorder loops, never sums: their results equal the textbook loops' to the
    /// bit (the factor, and so every frame, does not depend on how they are scheduled).
    #[test]
    fn kernels_equal_the_textbook_loops_bit_for_bit() {
        for size in [1, 3, 4, 5, 9, 17, 40, 75] {
            let mut ours = spd(size, size as u64);
            let mut textbook = ours.clone();
            factorise_diagonal(&mut ours, size).unwrap();
            for j in 0..size {
                let mut pivot = textbook[j * size + j];
                for k in 0..j {
                    pivot -= textbook[k * size + j] * textbook[k * size + j];
                }
                let ljj = pivot.sqrt();
                textbook[j * size + j] = ljj;
                for i in j + 1..size {
                    let mut v = textbook[j * size + i];
                    for k in 0..j {
                        v -= textbook[k * size + i] * textbook[k * size + j];
                    }
                    textbook[j * size + i] = v / ljj;
                }
            }
            let lower = |m: &[f64]| -> Vec<u64> {
                (0..size)
                    .flat_map(|c| (c..size).map(move |r| c * size + r))
                    .map(|at| m[at].to_bits())
                    .collect()
            };
            assert_eq!(lower(&ours), lower(&textbook), "diagonal block {size}");
            for threads in [1, 2] {
                let mut shared = spd(size, size as u64);
                factorise_diagonal_shared(&mut shared, size, threads).unwrap();
                assert_eq!(
                    lower(&shared),
                    lower(&textbook),
                    "{size} by panels, {threads}"
                );
            }

            for c in 0..size {
                ours[c * size + c] = 1.0 / ours[c * size + c];
            }
            for count in [1, 4, 7] {
                let mut rows = values(count * size, 7 + count as u64);
                let mut reference = rows.clone();
                substitute_rows(&ours, size, &mut rows, &mut Vec::new());
                for row in reference.chunks_exact_mut(size) {
                    for c in 0..size {
                        let mut v = row[c];
                        for k in 0..c {
                            v -= row[k] * ours[k * size + c];
                        }
                        row[c] = v * ours[c * size + c];
                    }
                }
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&rows), bits(&reference), "{count} rows of {size}");

                let x = values(size, 99);
                let pairs = (0..count).map(|i| (i, count - 1 - i));
                let mut got = vec![0.0; count];
                dots_into(&rows, size, &x, pairs, |place, d| got[place] = d);
                for (i, row) in rows.chunks_exact(size).enumerate() {
                    let d = row.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>();
                    assert_eq!(
                        got[count - 1 - i].to_bits(),
                        d.to_bits(),
                        "dot {i} of {size}"
                    );
                }
            }
        }
    }
}
