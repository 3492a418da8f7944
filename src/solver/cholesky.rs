//! Sparse Cholesky (LLT) of the global step's normal matrix with faer: one symbolic analysis
//! (AMD ordering, forced supernodal, sequential) per sparsity pattern, numeric factors
//! recomputed whenever the weights change, and in-place solves for the two-column right-hand
//! side. The matrix is passed as its lower triangle in compressed sparse column form.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

/// Why a factorisation failed (the matrix was not numerically positive definite, or faer could
/// not allocate).
#[derive(Debug, Clone, PartialEq)]
pub struct FactorError(pub String);

/// The symbolic factorisation of one sparsity pattern, with scratch memory for numeric
/// factorisations and solves (allocated once, reused every frame).
pub struct SymbolicFactor {
    symbolic: SymbolicCholesky<usize>,
    scratch: MemBuffer,
    /// The supernodal layout, copied out for [`SymbolicFactor::solve_in_place`]; `None` if
    /// faer chose a simplicial factor anyway.
    layout: Option<SupernodalLayout>,
    /// Both right-hand-side columns interleaved, in the fill-reducing order.
    pairs: Vec<[f64; 2]>,
}

/// Where each supernode's columns, row pattern and dense block live in the factor.
struct SupernodalLayout {
    /// Supernode `s` holds columns `begin[s]..begin[s + 1]` (permuted order).
    begin: Vec<usize>,
    /// Rows below the supernode's diagonal block: `row_idx[row_start[s]..][..below[s]]`.
    row_start: Vec<usize>,
    below: Vec<usize>,
    row_idx: Vec<usize>,
    /// The dense block (diagonal block on top of the rows below, column-major) starts at
    /// `val_start[s]` in the factor's values.
    val_start: Vec<usize>,
    /// `perm[i]`: the original row of permuted row `i`.
    perm: Vec<usize>,
}

/// Numeric values of an LLT factor belonging to a [`SymbolicFactor`].
#[derive(Debug, Default, Clone)]
pub struct NumericFactor {
    values: Vec<f64>,
    valid: bool,
}

impl NumericFactor {
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    pub fn invalidate(&mut self) {
        self.valid = false;
    }
}

impl std::fmt::Debug for SymbolicFactor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SymbolicFactor")
            .field("symbolic", &self.symbolic)
            .finish_non_exhaustive()
    }
}

impl SymbolicFactor {
    /// Analyses the pattern of an `n x n` matrix given by its lower triangle.
    pub fn analyse(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Result<Self, FactorError> {
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                // faer's automatic choice picks simplicial at ~10k vertices, 3x slower here.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(|e| FactorError(format!("symbolic analysis failed: {e:?}")))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(2, Par::Seq),
        ]);
        let layout = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let ns = sn.n_supernodes();
                let mut begin = sn.supernode_begin().to_vec();
                begin.push(n);
                Some(SupernodalLayout {
                    begin,
                    row_start: sn.col_ptr_for_row_idx()[..ns].to_vec(),
                    below: sn.nnz_per_super()[..ns].to_vec(),
                    row_idx: sn.row_idx().to_vec(),
                    val_start: sn.col_ptr_for_val()[..ns].to_vec(),
                    perm: match symbolic.perm() {
                        Some(p) => p.arrays().0.to_vec(),
                        None => (0..n).collect(),
                    },
                })
            }
            SymbolicCholeskyRaw::Simplicial(_) => None,
        };
        Ok(Self {
            symbolic,
            scratch: MemBuffer::new(req),
            layout,
            pairs: Vec::new(),
        })
    }

    /// Numerically factorises the matrix (same pattern as analysed) into `factor`.
    pub fn factorize(
        &mut self,
        factor: &mut NumericFactor,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
    ) -> Result<(), FactorError> {
        let n = self.symbolic.nrows();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let a = SparseColMatRef::new(pattern, values);
        factor.values.resize(self.symbolic.len_val(), 0.0);
        factor.valid = false;
        self.symbolic
            .factorize_numeric_llt(
                &mut factor.values,
                a,
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut self.scratch),
                Default::default(),
            )
            .map_err(|e| FactorError(format!("numeric Cholesky failed: {e:?}")))?;
        factor.valid = true;
        Ok(())
    }

    /// Solves `A X = B` in place; `rhs` holds `ncols` columns of length `n`, column-major.
    ///
    /// Two columns (the x and y of the global step) go through our own supernodal
    /// substitution: the supernodes of these planar Laplacians are a few columns wide, and
    /// faer's per-supernode dense kernels (gemm plans, scratch matrices) cost more there than
    /// the arithmetic; plain loops over both columns at once are several times faster.
    pub fn solve_in_place(&mut self, factor: &NumericFactor, rhs: &mut [f64], ncols: usize) {
        debug_assert!(factor.valid);
        if ncols == 2
            && let Some(layout) = &self.layout
        {
            layout.solve_pairs(&factor.values, rhs, &mut self.pairs);
            return;
        }
        self.solve_with_faer(factor, rhs, ncols);
    }

    /// faer's own solve (any number of columns).
    pub fn solve_with_faer(&mut self, factor: &NumericFactor, rhs: &mut [f64], ncols: usize) {
        let n = self.symbolic.nrows();
        debug_assert!(factor.valid);
        let llt = LltRef::new(&self.symbolic, &factor.values);
        let b = MatMut::from_column_major_slice_mut(rhs, n, ncols);
        llt.solve_in_place_with_conj(Conj::No, b, Par::Seq, MemStack::new(&mut self.scratch));
    }
}

impl SupernodalLayout {
    /// `rhs` (two columns of length n) <- `A^-1 rhs` with `A = P^T L L^T P`.
    fn solve_pairs(&self, l: &[f64], rhs: &mut [f64], x: &mut Vec<[f64; 2]>) {
        let n = self.perm.len();
        x.clear();
        x.extend(self.perm.iter().map(|&p| [rhs[p], rhs[n + p]]));
        let supernodes = self.val_start.len();
        // L y = P b, supernode by supernode
        for s in 0..supernodes {
            let (start, end) = (self.begin[s], self.begin[s + 1]);
            let size = end - start;
            let below = &self.row_idx[self.row_start[s]..][..self.below[s]];
            let rows = size + below.len();
            let block = &l[self.val_start[s]..][..rows * size];
            for c in 0..size {
                let col = &block[c * rows..(c + 1) * rows];
                let d = col[c];
                let xc = [x[start + c][0] / d, x[start + c][1] / d];
                x[start + c] = xc;
                for r in c + 1..size {
                    let xr = &mut x[start + r];
                    xr[0] -= col[r] * xc[0];
                    xr[1] -= col[r] * xc[1];
                }
                for (&i, &v) in below.iter().zip(&col[size..]) {
                    let xi = &mut x[i];
                    xi[0] -= v * xc[0];
                    xi[1] -= v * xc[1];
                }
            }
        }
        // L^T z = y, in reverse
        for s in (0..supernodes).rev() {
            let (start, end) = (self.begin[s], self.begin[s + 1]);
            let size = end - start;
            let below = &self.row_idx[self.row_start[s]..][..self.below[s]];
            let rows = size + below.len();
            let block = &l[self.val_start[s]..][..rows * size];
            for c in (0..size).rev() {
                let col = &block[c * rows..(c + 1) * rows];
                let mut acc = x[start + c];
                for r in c + 1..size {
                    let xr = x[start + r];
                    acc[0] -= col[r] * xr[0];
                    acc[1] -= col[r] * xr[1];
                }
                for (&i, &v) in below.iter().zip(&col[size..]) {
                    let xi = x[i];
                    acc[0] -= v * xi[0];
                    acc[1] -= v * xi[1];
                }
                let d = col[c];
                x[start + c] = [acc[0] / d, acc[1] / d];
            }
        }
        for (xi, &p) in x.iter().zip(&self.perm) {
            rhs[p] = xi[0];
            rhs[n + p] = xi[1];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path graph Laplacian plus a diagonal, with extra long-range edges so the supernodes
    /// get rows below their diagonal blocks.
    fn matrix(n: usize) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        let mut diag = vec![0.5; n];
        let mut edge = |a: usize, b: usize, w: f64| {
            let (lo, hi) = (a.min(b), a.max(b));
            cols[lo].push((hi, -w));
            diag[a] += w;
            diag[b] += w;
        };
        for i in 0..n - 1 {
            edge(i, i + 1, 1.0 + (i % 7) as f64);
        }
        for i in (0..n - 9).step_by(3) {
            edge(i, i + 9, 0.25);
        }
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for (j, col) in cols.iter_mut().enumerate() {
            col.sort_by_key(|e| e.0);
            row_idx.push(j);
            values.push(diag[j]);
            for &(i, v) in col.iter() {
                row_idx.push(i);
                values.push(v);
            }
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx, values)
    }

    #[test]
    fn our_supernodal_solve_matches_faers() {
        let n = 300;
        let (col_ptr, row_idx, values) = matrix(n);
        let mut symbolic = SymbolicFactor::analyse(n, &col_ptr, &row_idx).unwrap();
        assert!(symbolic.layout.is_some());
        let mut factor = NumericFactor::default();
        symbolic
            .factorize(&mut factor, &col_ptr, &row_idx, &values)
            .unwrap();
        let b: Vec<f64> = (0..2 * n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let (mut ours, mut theirs) = (b.clone(), b.clone());
        symbolic.solve_in_place(&factor, &mut ours, 2);
        symbolic.solve_with_faer(&factor, &mut theirs, 2);
        let scale = theirs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, t) in ours.iter().zip(&theirs) {
            assert!((a - t).abs() <= 1e-12 * scale, "{a} vs {t}");
        }
    }
}
