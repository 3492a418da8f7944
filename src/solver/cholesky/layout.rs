//! The supernodal layout of a factor (where each supernode's columns, rows below and dense
//! block live), shared by the substitutions (`cholesky.rs`), the numeric factorisation
//! ([`super::numeric`]) and the elimination tree's split ([`super::split`]); the dispatch of
//! a supernode's width to a kernel of that width; and the error of a failed factorisation.
//! They live here, not in `cholesky.rs`, so that its children share them as siblings and
//! none imports its parent.

/// Why a factorisation failed (the matrix was not numerically positive definite, or faer could
/// not allocate).
#[derive(Debug, Clone, PartialEq)]
pub struct FactorError(pub String);

/// Where each supernode's columns, row pattern and dense block live in the factor.
pub(super) struct SupernodalLayout {
    /// Supernode `s` holds columns `begin[s]..begin[s + 1]` (permuted order).
    pub(super) begin: Vec<usize>,
    /// Rows below the supernode's diagonal block: `row_idx[row_start[s]..][..below[s]]`
    /// (compact: they are streamed on every solve).
    pub(super) row_start: Vec<usize>,
    pub(super) below: Vec<usize>,
    pub(super) row_idx: Vec<u32>,
    /// The dense block (diagonal block on top of the rows below, column-major) starts at
    /// `val_start[s]` in the factor's values.
    pub(super) val_start: Vec<usize>,
    /// `perm[i]`: the original row of permuted row `i`.
    pub(super) perm: Vec<usize>,
}

impl SupernodalLayout {
    /// Supernode `s`: its first column, its width, its rows below the diagonal block and
    /// where its values start.
    pub(super) fn supernode(&self, s: usize) -> (usize, usize, &[u32], usize) {
        let (start, end) = (self.begin[s], self.begin[s + 1]);
        let below = &self.row_idx[self.row_start[s]..][..self.below[s]];
        (start, end - start, below, self.val_start[s])
    }

    /// Copies faer's supernodal values `l` into `out` in solve order (see
    /// [`NumericFactor::solve_order`](super::NumericFactor::solve_order)): same offsets per
    /// supernode, the diagonal block with the reciprocals of its diagonal entries, the block
    /// below it transposed to row-major.
    pub(super) fn reorder_for_solve(&self, l: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.resize(l.len(), 0.0);
        for s in 0..self.val_start.len() {
            let (_, size, below, at) = self.supernode(s);
            let rows = size + below.len();
            let block = &l[at..][..rows * size];
            let target = &mut out[at..][..rows * size];
            let (diagonal, rest) = target.split_at_mut(size * size);
            for c in 0..size {
                diagonal[c * size..][..size].copy_from_slice(&block[c * rows..][..size]);
                // the substitutions multiply by the reciprocal: every column's division sat
                // on the dependency chain (solve at 10k parts: 0.67 -> 0.57-0.60 ms median)
                diagonal[c * size + c] = 1.0 / diagonal[c * size + c];
                for (b, row) in rest.chunks_exact_mut(size).enumerate() {
                    row[c] = block[c * rows + size + b];
                }
            }
        }
    }

    /// The inverse of [`SupernodalLayout::reorder_for_solve`]: faer's layout of a factor in
    /// solve order.
    pub(super) fn faer_order(&self, l: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; l.len()];
        for s in 0..self.val_start.len() {
            let (_, size, below, at) = self.supernode(s);
            let rows = size + below.len();
            let block = &l[at..][..rows * size];
            let target = &mut out[at..][..rows * size];
            let (diagonal, rest) = block.split_at(size * size);
            for c in 0..size {
                target[c * rows..][..size].copy_from_slice(&diagonal[c * size..][..size]);
                target[c * rows + c] = 1.0 / diagonal[c * size + c];
                for (b, row) in rest.chunks_exact(size).enumerate() {
                    target[c * rows + size + b] = row[c];
                }
            }
        }
        out
    }
}

/// Calls `$fixed::<W>(args)` for a supernode width `W` of 1 to 8, else `$wide(width, args)`.
macro_rules! by_width {
    ($width:expr, $fixed:ident, $wide:ident, $($arg:expr),*) => {
        match $width {
            1 => $fixed::<1>($($arg),*),
            2 => $fixed::<2>($($arg),*),
            3 => $fixed::<3>($($arg),*),
            4 => $fixed::<4>($($arg),*),
            5 => $fixed::<5>($($arg),*),
            6 => $fixed::<6>($($arg),*),
            7 => $fixed::<7>($($arg),*),
            8 => $fixed::<8>($($arg),*),
            width => $wide(width, $($arg),*),
        }
    };
}
pub(super) use by_width;
