//! Sparse Cholesky (LLT) of the global step's normal matrix: one symbolic analysis by faer
//! (AMD ordering, forced supernodal) per sparsity pattern, numeric factors recomputed whenever
//! the weights change (ours, [`numeric`]; faer's where ours cannot lay the factor out),
//! and our in-place solves for the two-column right-hand side. The matrix is passed as its
//! lower triangle in compressed sparse column form.

use std::ops::Range;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

mod layout;
mod numeric;
mod split;

use super::chunks::join;
pub use layout::FactorError;
use layout::{SupernodalLayout, by_width};
use split::Split;

/// Supernode amalgamation: two adjacent supernodes of `n` columns in all merge when
/// `n <= w` and less than a fraction `z` of the merged block would be explicit zeros, for
/// the first `(w, z)` that holds. faer's default, `[(4, 1.0), (16, 0.8), (48, 0.1), ..]`,
/// suits factorisation, whose dense kernels like wide blocks. Here a factor serves four
/// solves (eight substitutions) per frame and is refactorised only when the held vertices
/// change, and a substitution streams every stored value, zero or not: with the default a
/// third of the city's factor is padding (4.73M values at 100k parts, 2.95M nonzeros). These
/// thresholds keep supernodes of a few columns (width-1 supernodes cost more per value than
/// they save) and cut the solve by about a fifth at 10k parts and a third at 100k
/// (docs/performance.md).
const RELAX: &[(usize, f64)] = &[(4, 0.25), (16, 0.1), (usize::MAX, 0.02)];

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
    /// The second half's copy of the pairs in a split substitution ([`Substitution`]).
    spare: Vec<[f64; 2]>,
    /// Our numeric factorisation's map of the matrix into the factor (`None`: faer's).
    scatter: Option<numeric::Scatter>,
}

/// Numeric values of an LLT factor belonging to a [`SymbolicFactor`].
#[derive(Debug, Default, Clone)]
pub struct NumericFactor {
    /// faer's layout (supernodes column-major); empty when our factorisation made the factor
    /// (then only `solve_order` is kept).
    values: Vec<f64>,
    /// The same values in the order [`SymbolicFactor::solve_in_place`] reads them: each
    /// supernode's diagonal block as faer stores it but with reciprocal diagonal entries
    /// (the substitutions multiply), then the rows below it row by row (faer
    /// stores them column by column), so a below row is read once per substitution rather
    /// than once per column of its supernode.
    solve_order: Vec<f64>,
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
                supernodal_params: SymbolicSupernodalParams { relax: Some(RELAX) },
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
                let row_idx = sn
                    .row_idx()
                    .iter()
                    .map(|&i| u32::try_from(i).ok().filter(|&i| (i as usize) < n))
                    .collect::<Option<Vec<u32>>>()
                    .ok_or_else(|| FactorError("the factor has more rows than fit".into()))?;
                Some(SupernodalLayout {
                    begin,
                    row_start: sn.col_ptr_for_row_idx()[..ns].to_vec(),
                    below: sn.nnz_per_super()[..ns].to_vec(),
                    row_idx,
                    val_start: sn.col_ptr_for_val()[..ns].to_vec(),
                    perm: match symbolic.perm() {
                        Some(p) => p.arrays().0.to_vec(),
                        None => (0..n).collect(),
                    },
                })
            }
            SymbolicCholeskyRaw::Simplicial(_) => None,
        };
        let scatter = (layout.as_ref()).and_then(|l| numeric::Scatter::new(l, col_ptr, row_idx));
        Ok(Self {
            symbolic,
            scratch: MemBuffer::new(req),
            layout,
            pairs: Vec::new(),
            spare: Vec::new(),
            scatter,
        })
    }

    /// Values a numeric factor stores (nonzeros, and the zeros of amalgamated supernodes).
    pub fn stored_values(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Whether factorisations and substitutions run as two halves side by side (on two
    /// threads when asked): the factor is big enough to be split ([`split`]).
    pub fn is_split(&self) -> bool {
        self.scatter.as_ref().is_some_and(|s| s.split().is_some())
    }

    /// Numerically factorises the matrix (same pattern as analysed) into `factor`: by our
    /// supernodal factorisation ([`numeric`]) when the factor is supernodal, else by faer's.
    /// Ours runs two independent halves of the elimination tree on two threads when
    /// `threads > 1`; the factor does not depend on `threads`.
    pub fn factorize(
        &mut self,
        factor: &mut NumericFactor,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        threads: usize,
    ) -> Result<(), FactorError> {
        factor.valid = false;
        if let (Some(layout), Some(scatter)) = (&self.layout, &mut self.scatter) {
            factor.values.clear();
            let len = self.symbolic.len_val();
            scatter.factorise(layout, values, &mut factor.solve_order, len, threads)?;
            factor.valid = true;
            return Ok(());
        }
        self.factorize_with_faer(factor, col_ptr, row_idx, values)
    }

    /// [`SymbolicFactor::factorize`] by faer's numeric factorisation.
    pub fn factorize_with_faer(
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
        if let Some(layout) = &self.layout {
            layout.reorder_for_solve(&factor.values, &mut factor.solve_order);
        }
        factor.valid = true;
        Ok(())
    }

    /// Solves `A X = B` in place; `rhs` holds `ncols` columns of length `n`, column-major.
    ///
    /// Two columns (the x and y of the global step) go through our own supernodal
    /// substitution: the supernodes of these planar Laplacians are a few columns wide, and
    /// faer's per-supernode dense kernels (gemm plans, scratch matrices) cost more there than
    /// the arithmetic; plain loops over both columns at once are several times faster. The
    /// factorisation's two halves substitute side by side on two threads when `threads > 1`
    /// (the same result on one).
    pub fn solve_in_place(
        &mut self,
        factor: &NumericFactor,
        rhs: &mut [f64],
        ncols: usize,
        threads: usize,
    ) {
        debug_assert!(factor.valid);
        if ncols == 2
            && let Some(layout) = &self.layout
        {
            let (n, perm) = (layout.perm.len(), &layout.perm);
            let mut x = std::mem::take(&mut self.pairs);
            x.clear();
            x.extend(perm.iter().map(|&p| [rhs[p], rhs[n + p]]));
            self.solve_in_factor_order(factor, &mut x, threads);
            let perm = &self.layout.as_ref().expect("checked above").perm;
            for (xi, &p) in x.iter().zip(perm) {
                rhs[p] = xi[0];
                rhs[n + p] = xi[1];
            }
            self.pairs = x;
            return;
        }
        self.solve_with_faer(factor, rhs, ncols);
    }

    /// The fill-reducing order of the two-column solve: position `i` of a vector in factor
    /// order holds original row `order[i]`. `None` when the factor is not supernodal (then
    /// only [`SymbolicFactor::solve_in_place`] solves).
    pub fn factor_order(&self) -> Option<&[usize]> {
        self.layout.as_ref().map(|l| l.perm.as_slice())
    }

    /// Solves `A X = B` for two columns given as `(x, y)` pairs already in
    /// [`SymbolicFactor::factor_order`], in place: the caller builds the right-hand side in
    /// that order and reads the solution from it, with no permuting copies. Returns `false`
    /// (and leaves `x` alone) when there is no such order or `x` is not one pair per row.
    pub fn solve_in_factor_order(
        &mut self,
        factor: &NumericFactor,
        x: &mut [[f64; 2]],
        threads: usize,
    ) -> bool {
        debug_assert!(factor.valid);
        match &self.layout {
            Some(layout) if x.len() == layout.perm.len() => {
                let split = self.scatter.as_ref().and_then(|s| s.split());
                let substitution = Substitution {
                    layout,
                    l: &factor.solve_order,
                    split,
                    threads,
                };
                substitution.run(x, &mut self.spare);
                true
            }
            _ => false,
        }
    }

    /// faer's own solve (any number of columns).
    pub fn solve_with_faer(&mut self, factor: &NumericFactor, rhs: &mut [f64], ncols: usize) {
        let n = self.symbolic.nrows();
        debug_assert!(factor.valid);
        let ours;
        let values = match &self.layout {
            Some(layout) if factor.values.is_empty() => {
                ours = layout.faer_order(&factor.solve_order);
                &ours
            }
            _ => &factor.values,
        };
        let llt = LltRef::new(&self.symbolic, values);
        let b = MatMut::from_column_major_slice_mut(rhs, n, ncols);
        llt.solve_in_place_with_conj(Conj::No, b, Par::Seq, MemStack::new(&mut self.scratch));
    }
}

/// `x <- L^-T L^-1 x` for pairs in factor order; `l` in solve order. Supernodes up to 8 wide
/// (nearly all of them in these planar Laplacians) run with their width known to the
/// compiler, so a below row's update stays in registers.
///
/// With a [`Split`], the forward pass runs the two halves side by side (the second on a spare
/// copy of its rows, its updates of the top's rows gathered there from zero and added after
/// both), then the top; the backward pass runs the top, then the halves side by side (the
/// second reading the top's rows from the spare copy). One thread runs the same steps.
struct Substitution<'a> {
    layout: &'a SupernodalLayout,
    l: &'a [f64],
    split: Option<&'a Split>,
    threads: usize,
}

impl Substitution<'_> {
    fn run(&self, x: &mut [[f64; 2]], spare: &mut Vec<[f64; 2]>) {
        let count = self.layout.val_start.len();
        let Some(split) = self.split else {
            self.forward(0..count, x);
            self.backward(0..count, x);
            return;
        };
        let columns = |r: &Range<usize>| self.layout.begin[r.start]..self.layout.begin[r.end];
        let [first, second] = &split.halves;
        spare.resize(x.len(), [0.0; 2]);
        for r in second {
            spare[columns(r)].copy_from_slice(&x[columns(r)]);
        }
        for r in &split.top {
            spare[columns(r)].fill([0.0; 2]);
        }
        let halves = |x: &mut [[f64; 2]], spare: &mut [[f64; 2]], forward: bool| {
            let side = |runs: &[Range<usize>], x: &mut [[f64; 2]]| {
                for r in runs {
                    if forward {
                        self.forward(r.clone(), x);
                    } else {
                        self.backward(r.clone(), x);
                    }
                }
            };
            join(self.threads, || side(first, x), || side(second, spare));
            for r in second {
                x[columns(r)].copy_from_slice(&spare[columns(r)]);
            }
        };
        halves(x, spare, true);
        for r in &split.top {
            for c in columns(r) {
                x[c] = [x[c][0] + spare[c][0], x[c][1] + spare[c][1]];
            }
        }
        for r in &split.top {
            self.forward(r.clone(), x);
        }
        for r in split.top.iter().rev() {
            self.backward(r.clone(), x);
        }
        for r in &split.top {
            spare[columns(r)].copy_from_slice(&x[columns(r)]);
        }
        halves(x, spare, false);
    }

    /// Forward substitution through the supernodes `range`, in order.
    fn forward(&self, range: Range<usize>, x: &mut [[f64; 2]]) {
        for s in range {
            let (start, size, below, at) = self.layout.supernode(s);
            let block = &self.l[at..][..(size + below.len()) * size];
            by_width!(size, forward, forward_wide, block, start, below, x);
        }
    }

    /// Backward substitution through the supernodes `range`, in reverse order.
    fn backward(&self, range: Range<usize>, x: &mut [[f64; 2]]) {
        for s in range.rev() {
            let (start, size, below, at) = self.layout.supernode(s);
            let block = &self.l[at..][..(size + below.len()) * size];
            by_width!(size, backward, backward_wide, block, start, below, x);
        }
    }
}

/// Forward substitution `L y = b` through one supernode `S` columns wide starting at column
/// `start`: its diagonal block (column-major, `S x S`), then each row below it (row-major).
#[inline]
fn forward<const S: usize>(block: &[f64], start: usize, below: &[u32], x: &mut [[f64; 2]]) {
    let (diagonal, rows) = block.split_at(S * S);
    let xs: &mut [[f64; 2]; S] = (&mut x[start..start + S]).try_into().expect("S columns");
    for c in 0..S {
        let col = &diagonal[c * S..][..S];
        let inv = col[c]; // 1 / L_cc (see `reorder_for_solve`)
        let xc = [xs[c][0] * inv, xs[c][1] * inv];
        xs[c] = xc;
        for r in c + 1..S {
            xs[r][0] -= col[r] * xc[0];
            xs[r][1] -= col[r] * xc[1];
        }
    }
    let xs = *xs;
    for (&i, row) in below.iter().zip(rows.chunks_exact(S)) {
        let xi = &mut x[i as usize];
        let mut a = *xi;
        for c in 0..S {
            a[0] -= row[c] * xs[c][0];
            a[1] -= row[c] * xs[c][1];
        }
        *xi = a;
    }
}

/// Backward substitution `L^T z = y` through one supernode (see [`forward`]).
#[inline]
fn backward<const S: usize>(block: &[f64], start: usize, below: &[u32], x: &mut [[f64; 2]]) {
    let (diagonal, rows) = block.split_at(S * S);
    let mut acc: [[f64; 2]; S] = x[start..start + S].try_into().expect("S columns");
    for (&i, row) in below.iter().zip(rows.chunks_exact(S)) {
        let xi = x[i as usize];
        for c in 0..S {
            acc[c][0] -= row[c] * xi[0];
            acc[c][1] -= row[c] * xi[1];
        }
    }
    for c in (0..S).rev() {
        let col = &diagonal[c * S..][..S];
        let mut a = acc[c];
        for r in c + 1..S {
            a[0] -= col[r] * acc[r][0];
            a[1] -= col[r] * acc[r][1];
        }
        let inv = col[c]; // 1 / L_cc (see `reorder_for_solve`)
        acc[c] = [a[0] * inv, a[1] * inv];
    }
    x[start..start + S].copy_from_slice(&acc);
}

/// [`forward`] for a supernode of any width.
fn forward_wide(size: usize, block: &[f64], start: usize, below: &[u32], x: &mut [[f64; 2]]) {
    let (diagonal, rows) = block.split_at(size * size);
    for c in 0..size {
        let col = &diagonal[c * size..][..size];
        let inv = col[c]; // 1 / L_cc (see `reorder_for_solve`)
        let xc = [x[start + c][0] * inv, x[start + c][1] * inv];
        x[start + c] = xc;
        for r in c + 1..size {
            x[start + r][0] -= col[r] * xc[0];
            x[start + r][1] -= col[r] * xc[1];
        }
    }
    for (&i, row) in below.iter().zip(rows.chunks_exact(size)) {
        let mut a = x[i as usize];
        for (&v, xc) in row.iter().zip(&x[start..start + size]) {
            a[0] -= v * xc[0];
            a[1] -= v * xc[1];
        }
        x[i as usize] = a;
    }
}

/// [`backward`] for a supernode of any width.
fn backward_wide(size: usize, block: &[f64], start: usize, below: &[u32], x: &mut [[f64; 2]]) {
    let (diagonal, rows) = block.split_at(size * size);
    for (&i, row) in below.iter().zip(rows.chunks_exact(size)) {
        let xi = x[i as usize];
        for (&v, a) in row.iter().zip(&mut x[start..start + size]) {
            a[0] -= v * xi[0];
            a[1] -= v * xi[1];
        }
    }
    for c in (0..size).rev() {
        let col = &diagonal[c * size..][..size];
        let mut a = x[start + c];
        for r in c + 1..size {
            a[0] -= col[r] * x[start + r][0];
            a[1] -= col[r] * x[start + r][1];
        }
        let inv = col[c]; // 1 / L_cc (see `reorder_for_solve`)
        x[start + c] = [a[0] * inv, a[1] * inv];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower triangle (compressed columns) of a weighted graph Laplacian on `n` vertices
    /// plus `shift` on the diagonal; repeated edges add up.
    fn laplacian(
        n: usize,
        shift: f64,
        edges: &[(usize, usize, f64)],
    ) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        let mut diag = vec![shift; n];
        for &(a, b, w) in edges {
            cols[a.min(b)].push((a.max(b), -w));
            diag[a] += w;
            diag[b] += w;
        }
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for (j, col) in cols.iter_mut().enumerate() {
            col.sort_by_key(|e| e.0);
            col.dedup_by(|a, b| {
                let same = a.0 == b.0;
                if same {
                    b.1 += a.1;
                }
                same
            });
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

    /// A path graph Laplacian plus a diagonal, with extra long-range edges so the supernodes
    /// get rows below their diagonal blocks.
    fn matrix(n: usize) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut edges: Vec<(usize, usize, f64)> = (0..n - 1)
            .map(|i| (i, i + 1, 1.0 + (i % 7) as f64))
            .collect();
        edges.extend((0..n - 9).step_by(3).map(|i| (i, i + 9, 0.25)));
        laplacian(n, 0.5, &edges)
    }

    /// Our numeric factorisation gives faer's factor to rounding, on a grid with a clique
    /// (supernodes of every width) and on the path with long edges.
    #[test]
    fn our_numeric_factor_matches_faers() {
        for (col_ptr, row_idx, values) in [matrix(300), grid_with_clique(24)] {
            let n = col_ptr.len() - 1;
            let mut symbolic = SymbolicFactor::analyse(n, &col_ptr, &row_idx).unwrap();
            assert!(symbolic.scatter.is_some());
            let (mut ours, mut theirs) = (NumericFactor::default(), NumericFactor::default());
            symbolic
                .factorize(&mut ours, &col_ptr, &row_idx, &values, 2)
                .unwrap();
            (symbolic)
                .factorize_with_faer(&mut theirs, &col_ptr, &row_idx, &values)
                .unwrap();
            assert!(ours.values.is_empty(), "ours keeps only the solve order");
            assert_same_factor(&symbolic, &ours, &theirs, n);
        }
    }

    /// Asserts that our factor and faer's agree to rounding (every value faer specifies).
    fn assert_same_factor(
        symbolic: &SymbolicFactor,
        ours: &NumericFactor,
        theirs: &NumericFactor,
        n: usize,
    ) {
        let scale = theirs
            .solve_order
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let layout = symbolic.layout.as_ref().unwrap();
        let mut compared = 0;
        for s in 0..layout.val_start.len() {
            let (_, size, below, at) = layout.supernode(s);
            // faer leaves the diagonal block's upper triangle unspecified: not read
            let lower = (0..size).flat_map(|c| (c..size).map(move |r| at + c * size + r));
            let rows = at + size * size..at + (size + below.len()) * size;
            for i in lower.chain(rows) {
                let (a, t) = (ours.solve_order[i], theirs.solve_order[i]);
                assert!((a - t).abs() <= 1e-12 * scale, "supernode {s}: {a} vs {t}");
                compared += 1;
            }
        }
        assert!(compared > n, "{compared} values compared");
    }

    /// A factorisation big enough to run as two halves on two threads (`cholesky/split.rs`)
    /// gives faer's factor and solution to rounding, and the same bits on one thread as on two.
    #[test]
    fn the_split_factorisation_and_solve_are_faers_on_any_thread_count() {
        let (col_ptr, row_idx, values) = grid_with_clique(60);
        let n = col_ptr.len() - 1;
        let mut symbolic = SymbolicFactor::analyse(n, &col_ptr, &row_idx).unwrap();
        let count = symbolic.layout.as_ref().unwrap().val_start.len();
        let split = symbolic.scatter.as_ref().and_then(|s| s.split()).unwrap();
        // the halves' subtrees and the top cover every supernode once
        let mut covered = vec![0; count];
        let runs = split.halves.iter().flatten().chain(&split.top);
        runs.flat_map(Clone::clone).for_each(|s| covered[s] += 1);
        assert!(covered.iter().all(|&c| c == 1), "{split:?}");
        assert!(split.halves.iter().all(|h| !h.is_empty()), "{split:?}");
        // and a top supernode whose rows below two threads share
        let layout = symbolic.layout.as_ref().unwrap();
        let shared = split.top.iter().flat_map(Clone::clone).any(|s| {
            let (_, size, below, _) = layout.supernode(s);
            let (w, b) = (size as f64, below.len() as f64);
            b * w * (w + b / 2.0) >= numeric::MIN_SHARED
        });
        assert!(shared, "no shared supernode");
        let mut factors = [(); 3].map(|()| NumericFactor::default());
        for (factor, threads) in factors.iter_mut().zip([1, 2]) {
            (symbolic)
                .factorize(factor, &col_ptr, &row_idx, &values, threads)
                .unwrap();
        }
        let [one, two, theirs] = &mut factors;
        (symbolic)
            .factorize_with_faer(theirs, &col_ptr, &row_idx, &values)
            .unwrap();
        let bits = |f: &NumericFactor| {
            f.solve_order
                .iter()
                .map(|v| v.to_bits())
                .collect::<Vec<_>>()
        };
        assert!(bits(one) == bits(two), "one thread and two differ");
        assert_same_factor(&symbolic, one, theirs, n);
        // the split substitution: faer's solution to rounding, the same bits on two threads
        let b: Vec<f64> = (0..2 * n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let (_, ours) = solves_as_faer(&mut symbolic, (&col_ptr, &row_idx, &values), &b, 1e-12);
        let mut on_two = b.clone();
        symbolic.solve_in_place(one, &mut on_two, 2, 2);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(
            bits(&on_two) == bits(&ours),
            "the solve differs on two threads"
        );
        // a pivot that fails in either half is an error, not a factor
        let mut indefinite = values.clone();
        indefinite[col_ptr[n / 3]] = -1.0;
        for threads in [1, 2] {
            let err = symbolic.factorize(one, &col_ptr, &row_idx, &indefinite, threads);
            assert!(
                err.is_err() && !one.is_valid(),
                "{threads} threads: {err:?}"
            );
        }
    }

    /// A matrix that is not positive definite is refused with the column, not factorised.
    #[test]
    fn an_indefinite_matrix_is_an_error() {
        let (col_ptr, row_idx, mut values) = matrix(50);
        values[col_ptr[20]] = -1.0; // a negative diagonal entry
        let mut symbolic = SymbolicFactor::analyse(50, &col_ptr, &row_idx).unwrap();
        let mut factor = NumericFactor::default();
        let err = symbolic.factorize(&mut factor, &col_ptr, &row_idx, &values, 1);
        assert!(err.is_err() && !factor.is_valid(), "{err:?}");
        values[col_ptr[20]] = f64::NAN;
        assert!(
            symbolic
                .factorize(&mut factor, &col_ptr, &row_idx, &values, 2)
                .is_err()
        );
    }

    #[test]
    fn our_supernodal_solve_matches_faers() {
        let n = 300;
        let (col_ptr, row_idx, values) = matrix(n);
        let mut symbolic = SymbolicFactor::analyse(n, &col_ptr, &row_idx).unwrap();
        assert!(symbolic.layout.is_some());
        let b: Vec<f64> = (0..2 * n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        solves_as_faer(&mut symbolic, (&col_ptr, &row_idx, &values), &b, 1e-12);
    }

    /// Factorises the matrix (`col_ptr`, `row_idx`, `values`), solves for `b` (two columns)
    /// with our substitution and with faer's, asserts they agree to `tolerance` of the
    /// largest entry, and returns the factor and our solution.
    fn solves_as_faer(
        symbolic: &mut SymbolicFactor,
        (col_ptr, row_idx, values): (&[usize], &[usize], &[f64]),
        b: &[f64],
        tolerance: f64,
    ) -> (NumericFactor, Vec<f64>) {
        let mut factor = NumericFactor::default();
        symbolic
            .factorize(&mut factor, col_ptr, row_idx, values, 1)
            .unwrap();
        let (mut ours, mut theirs) = (b.to_vec(), b.to_vec());
        symbolic.solve_in_place(&factor, &mut ours, 2, 1);
        symbolic.solve_with_faer(&factor, &mut theirs, 2);
        let scale = theirs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, t) in ours.iter().zip(&theirs) {
            assert!((a - t).abs() <= tolerance * scale, "{a} vs {t}");
        }
        (factor, ours)
    }

    /// A `side x side` grid Laplacian (the shape of the solver's matrices) with one dense
    /// clique, so that the factor has narrow supernodes and at least one wider than 8.
    fn grid_with_clique(side: usize) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = side * side;
        let mut edges = Vec::new();
        for i in 0..side {
            for j in 0..side {
                let v = i * side + j;
                if i + 1 < side {
                    edges.push((v, v + side, 1.0 + (j % 3) as f64));
                }
                if j + 1 < side {
                    edges.push((v, v + 1, 0.5));
                }
            }
        }
        let clique: Vec<usize> = (0..14).map(|k| 100 + 17 * k).collect();
        for (a, &x) in clique.iter().enumerate() {
            for &y in &clique[a + 1..] {
                edges.push((x, y, 0.25));
            }
        }
        laplacian(n, 1e-3, &edges)
    }

    /// A grid Laplacian (the shape of the solver's matrices) with one dense clique, so that
    /// the factor has narrow supernodes (the fixed-width substitutions) and at least one
    /// wider than 8 columns (the any-width one).
    #[test]
    fn every_supernode_width_solves_as_faer_does() {
        let side = 24;
        let n = side * side;
        let (col_ptr, row_idx, values) = grid_with_clique(side);
        let mut symbolic = SymbolicFactor::analyse(n, &col_ptr, &row_idx).unwrap();
        let layout = symbolic.layout.as_ref().unwrap();
        let widths: Vec<usize> = layout.begin.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(widths.iter().any(|&w| w > 8), "{widths:?}");
        assert!(widths.iter().any(|&w| w <= 8), "{widths:?}");
        let b: Vec<f64> = (0..2 * n).map(|i| ((i * 53) % 13) as f64 - 6.0).collect();
        let (factor, ours) =
            solves_as_faer(&mut symbolic, (&col_ptr, &row_idx, &values), &b, 1e-10);
        // the same solve with the caller gathering into and reading from the factor's order
        let order = symbolic.factor_order().unwrap().to_vec();
        let mut pairs: Vec<[f64; 2]> = order.iter().map(|&v| [b[v], b[n + v]]).collect();
        assert!(symbolic.solve_in_factor_order(&factor, &mut pairs, 1));
        for (pair, &v) in pairs.iter().zip(&order) {
            assert_eq!(pair[0].to_bits(), ours[v].to_bits());
            assert_eq!(pair[1].to_bits(), ours[n + v].to_bits());
        }
        // a vector of the wrong length is refused, not solved
        assert!(!symbolic.solve_in_factor_order(&factor, &mut pairs[1..], 1));
    }
}
