//! Sparse Cholesky (LLT) of the global step's normal matrix with faer: one symbolic analysis
//! (AMD ordering, forced supernodal, sequential) per sparsity pattern, numeric factors
//! recomputed whenever the weights change, and in-place solves for the two-column right-hand
//! side. The matrix is passed as its lower triangle in compressed sparse column form.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
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
        Ok(Self {
            symbolic,
            scratch: MemBuffer::new(req),
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
    pub fn solve_in_place(&mut self, factor: &NumericFactor, rhs: &mut [f64], ncols: usize) {
        let n = self.symbolic.nrows();
        debug_assert!(factor.valid);
        let llt = LltRef::new(&self.symbolic, &factor.values);
        let b = MatMut::from_column_major_slice_mut(rhs, n, ncols);
        llt.solve_in_place_with_conj(Conj::No, b, Par::Seq, MemStack::new(&mut self.scratch));
    }
}
