//! The global step (paper 4.1, 5.2): the positions that minimise the weighted edge energy
//! for the local step's edge targets, with the handles and the proximal term, by a sparse
//! solve: Cholesky (the factor kept between solves while the matrix stays the same; pass 1's
//! IRLS matrix refactorised each iteration beside its right-hand side) or CG. Free components
//! keep their centroids.
//!
//! `global.rs` holds the normal equations' sparsity pattern and fills their values and
//! right-hand sides; this file is the step of the frame that assembles, factorises and solves
//! them, an `impl Solver` block apart from the passes that call it.

use std::time::Instant;

use glam::DVec2;

use super::cholesky::NumericFactor;
use super::clock::ms_since;
use super::config::SolverKind;
use super::global::{self, Pattern};
use super::report::{FrameReport, SolverError};
use super::state::{Solver, Work};
use super::{cg, chunks};

impl Solver {
    /// Global step: solves for `next` with the current edge targets and the weights of `pass`.
    /// A component with no held vertex keeps its centroid: only the tiny proximal term fixes
    /// its position, so the solve's rounding, divided by that term's weight, would otherwise
    /// let it drift (measured: a free street crept 1.4e-6 m in 40 frames while another part
    /// of the model was dragged).
    pub(super) fn solve_global(
        &mut self,
        f: &[DVec2],
        next: &mut [DVec2],
        pass: Pass,
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        self.solve_global_raw(f, next, pass, report)?;
        let t = Instant::now();
        self.keep_free_centroids(f, next);
        report.phases.bookkeeping += ms_since(t);
        Ok(())
    }

    /// Shifts every component without a held vertex so its centroid in `next` is the one in
    /// `f` (in exact arithmetic the solve already does: the Laplacian's rows of a component sum
    /// to zero, so the proximal term alone sets its centroid).
    fn keep_free_centroids(&self, f: &[DVec2], next: &mut [DVec2]) {
        // only the free components' vertices, each component's in ascending order (the sum
        // a pass over every vertex would make, for a tenth of the reads in the bench's city)
        for &c in &self.free_components {
            let members = self.components.members(c);
            let mut shift = DVec2::ZERO;
            let mut count = 0.0;
            for &v in members {
                shift += f[v as usize] - next[v as usize];
                count += 1.0;
            }
            for &v in members {
                next[v as usize] += shift / count;
            }
        }
    }

    // Long because: the global step's variants (Cholesky or CG, pass 1 or 2) share their set-up and fallbacks.
    fn solve_global_raw(
        &mut self,
        f: &[DVec2],
        next: &mut [DVec2],
        pass: Pass,
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let n = f.len();
        if pass == Pass::LeastSquares
            && cfg.kind == SolverKind::Cholesky
            && self.factor_slot.len() == n
        {
            return self.solve_least_squares_ordered(f, next, report);
        }
        let t = Instant::now();
        let w = &mut self.work;
        // the handle and proximal weights are multiples of the component's mean edge weight
        // (pass 1's reweighted edges; 1 in least squares): a far component's weights change
        // nothing here
        w.diagonal.clear();
        w.extra.clear();
        for (v, ((&count, &sum), &p)) in w.handle_count.iter().zip(&w.handle_sum).zip(f).enumerate()
        {
            let mean = match pass {
                Pass::Irls => self.units.weight(self.components.of(v)),
                Pass::LeastSquares => 1.0,
            };
            let (lambda, mu) = (cfg.handle_weight * mean, cfg.proximal_weight * mean);
            w.diagonal.push(lambda * count + mu);
            w.extra.push(lambda * sum + mu * p);
        }
        report.phases.assembly += ms_since(t);
        if pass == Pass::Irls
            && cfg.kind == SolverKind::Cholesky
            && cfg.pcg_max_iterations == 0
            && self.symbolic.is_some()
            && self.pattern.can_gather()
        {
            return self.solve_irls_factored(next, report);
        }
        let t = Instant::now();
        let w = &mut self.work;
        let weights: &[f64] = match pass {
            Pass::Irls if self.pattern.can_gather() => {
                let (rows, rhs) = (&mut w.vertex_rhs, &mut w.rhs);
                let threads = cfg.thread_count();
                (self.pattern).weighted_rhs(&w.weights, &w.targets, &w.extra, rows, rhs, threads);
                &w.weights
            }
            Pass::Irls => {
                global::fill_rhs(
                    &self.pattern.edges,
                    &w.weights,
                    &w.targets,
                    &w.extra,
                    &mut w.rhs,
                );
                &w.weights
            }
            Pass::LeastSquares => {
                global::fill_rhs_unit(&self.pattern.ends, &w.targets, &w.extra, &mut w.rhs);
                &[]
            }
        };
        match pass {
            Pass::Irls => {
                let threads = cfg.thread_count();
                (self.pattern).fill_values(weights, &w.diagonal, &mut w.values, threads);
            }
            Pass::LeastSquares => refresh_least_squares(&self.pattern, w, &mut self.l2_factor),
        }
        let values = if pass == Pass::LeastSquares {
            &w.l2_values
        } else {
            &w.values
        };
        w.solution.clear();
        w.solution.extend(f.iter().map(|p| p.x));
        w.solution.extend(f.iter().map(|p| p.y));
        report.phases.assembly += ms_since(t);
        match (cfg.kind, self.symbolic.as_mut()) {
            (SolverKind::Cholesky, Some(symbolic)) => {
                let factor = if pass == Pass::LeastSquares {
                    &mut self.l2_factor
                } else {
                    &mut self.irls_factor
                };
                // Pass 1: the kept factor of an earlier IRLS matrix (same pattern, other
                // weights) preconditions CG on this one; only when that takes too long is the
                // matrix factorised afresh.
                let mut solved = false;
                if pass == Pass::Irls && factor.is_valid() && cfg.pcg_max_iterations > 0 {
                    let t = Instant::now();
                    let outcome = {
                        let factor = &*factor;
                        let mut precondition = |z: &mut [f64]| {
                            symbolic.solve_in_place(factor, z, 2, cfg.thread_count())
                        };
                        cg::solve(
                            &self.pattern,
                            values,
                            &w.rhs,
                            &mut w.solution,
                            cg::CgStop {
                                tolerance: cfg.pcg_tolerance,
                                max_iterations: cfg.pcg_max_iterations,
                                reference: Some(elastic_norm(&w.rhs, &w.extra)),
                            },
                            Some(&mut precondition),
                            &mut w.cg,
                        )
                    };
                    report.pcg_iterations += outcome.iterations;
                    report.phases.solve += ms_since(t);
                    solved = outcome.converged;
                }
                if !solved {
                    if pass == Pass::Irls || !factor.is_valid() {
                        let t = Instant::now();
                        symbolic
                            .factorize(
                                factor,
                                &self.pattern.col_ptr,
                                &self.pattern.row_idx,
                                values,
                                cfg.thread_count(),
                            )
                            .map_err(|e| SolverError(e.0))?;
                        report.factorizations += 1;
                        report.phases.factorization += ms_since(t);
                    }
                    let t = Instant::now();
                    w.solution.copy_from_slice(&w.rhs);
                    symbolic.solve_in_place(factor, &mut w.solution, 2, cfg.thread_count());
                    report.phases.solve += ms_since(t);
                }
            }
            _ => {
                let t = Instant::now();
                let outcome = cg::solve(
                    &self.pattern,
                    values,
                    &w.rhs,
                    &mut w.solution,
                    cg::CgStop {
                        tolerance: cfg.cg_tolerance,
                        max_iterations: cfg.cg_max_iterations,
                        reference: Some(elastic_norm(&w.rhs, &w.extra)),
                    },
                    None,
                    &mut w.cg,
                );
                report.cg_iterations += outcome.iterations;
                report.phases.solve += ms_since(t);
            }
        }
        let measure = cfg
            .measure_residual
            .then_some((&self.pattern, &values[..], &mut w.scratch));
        take_solution(&w.solution, &w.rhs, measure, report, next);
        Ok(())
    }

    /// Pass 1's global step by Cholesky (the default path, `work.diagonal` and `work.extra`
    /// filled): the weighted matrix is filled, then factorised while its right-hand side is
    /// gathered beside it, then solved. The factorisation and the right-hand side read
    /// disjoint data and write their own, so their results do not depend on which thread ran
    /// what, or on one thread running both one after the other; the factorisation's phase
    /// time includes the right-hand side it hides.
    fn solve_irls_factored(
        &mut self,
        next: &mut [DVec2],
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let threads = cfg.thread_count();
        let t = Instant::now();
        let (w, pattern) = (&mut self.work, &self.pattern);
        pattern.fill_values(&w.weights, &w.diagonal, &mut w.values, threads);
        report.phases.assembly += ms_since(t);
        let Some(symbolic) = self.symbolic.as_mut() else {
            return Err(SolverError("no symbolic factorisation".into()));
        };
        let t = Instant::now();
        let factor = &mut self.irls_factor;
        // side by side only where the frame runs on the pool (a split factor): elsewhere a
        // hand-over to the pool per iteration costs more than the right-hand side
        let beside = if symbolic.is_split() { threads } else { 1 };
        let (factored, ()) = chunks::join(
            beside,
            || {
                symbolic.factorize(
                    factor,
                    &pattern.col_ptr,
                    &pattern.row_idx,
                    &w.values,
                    threads,
                )
            },
            || {
                let (rows, rhs) = (&mut w.vertex_rhs, &mut w.rhs);
                pattern.weighted_rhs(&w.weights, &w.targets, &w.extra, rows, rhs, threads);
            },
        );
        factored.map_err(|e| SolverError(e.0))?;
        report.factorizations += 1;
        report.phases.factorization += ms_since(t);
        let t = Instant::now();
        w.solution.clone_from(&w.rhs);
        symbolic.solve_in_place(factor, &mut w.solution, 2, threads);
        report.phases.solve += ms_since(t);
        let measure = cfg
            .measure_residual
            .then_some((pattern, &w.values[..], &mut w.scratch));
        take_solution(&w.solution, &w.rhs, measure, report, next);
        Ok(())
    }

    /// The least-squares global step (unit weights) by Cholesky, with the right-hand side
    /// gathered into and solved in the factor's order
    /// ([`SymbolicFactor::solve_in_factor_order`]): the same numbers as the general path,
    /// without its column copies.
    fn solve_least_squares_ordered(
        &mut self,
        f: &[DVec2],
        next: &mut [DVec2],
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let t = Instant::now();
        let w = &mut self.work;
        let slot = &self.factor_slot;
        let (lambda, mu) = (cfg.handle_weight, cfg.proximal_weight);
        self.ordered.resize(f.len(), [0.0; 2]);
        // Summed in vertex order (where an edge's ends are near each other; the factor's
        // order scatters them), then gathered into the factor's order. Sized first and then
        // written: a push per vertex would check the capacity every time.
        let n = f.len();
        let b = &mut w.vertex_rhs;
        w.diagonal.resize(n, 0.0);
        b.resize(n, DVec2::ZERO);
        let handles = w.handle_count.iter().zip(&w.handle_sum).zip(f);
        for ((d, bi), ((&count, &sum), &p)) in w.diagonal.iter_mut().zip(b.iter_mut()).zip(handles)
        {
            *d = lambda * count + mu;
            *bi = lambda * sum + mu * p;
        }
        if self.pattern.can_gather() {
            let threads = cfg.thread_count();
            self.pattern.gather_rhs(None, &w.targets, b, threads);
        } else {
            for (&[x, y], &t) in self.pattern.ends.iter().zip(&w.targets) {
                let (x, y) = (x as usize, y as usize);
                if x != y {
                    b[x] += t;
                    b[y] -= t;
                }
            }
        }
        let x = &mut self.ordered;
        let order = self.symbolic.as_ref().and_then(|s| s.factor_order());
        for (xi, &v) in x.iter_mut().zip(order.unwrap_or_default()) {
            *xi = b[v].to_array();
        }
        refresh_least_squares(&self.pattern, w, &mut self.l2_factor);
        report.phases.assembly += ms_since(t);
        let Some(symbolic) = self.symbolic.as_mut() else {
            return Err(SolverError("no symbolic factorisation".into()));
        };
        if !self.l2_factor.is_valid() {
            let t = Instant::now();
            symbolic
                .factorize(
                    &mut self.l2_factor,
                    &self.pattern.col_ptr,
                    &self.pattern.row_idx,
                    &w.l2_values,
                    self.config.thread_count(),
                )
                .map_err(|e| SolverError(e.0))?;
            report.factorizations += 1;
            report.phases.factorization += ms_since(t);
        }
        let t = Instant::now();
        if !symbolic.solve_in_factor_order(&self.l2_factor, x, cfg.thread_count()) {
            return Err(SolverError("the factor has no supernodal order".into()));
        }
        report.phases.solve += ms_since(t);
        for (p, &i) in next.iter_mut().zip(slot) {
            *p = DVec2::from(x[i]);
        }
        if cfg.measure_residual {
            // the general path's columns, only to measure (tests)
            let columns = |v: &[DVec2], out: &mut Vec<f64>| {
                out.clear();
                out.extend(v.iter().map(|p| p.x));
                out.extend(v.iter().map(|p| p.y));
            };
            columns(&w.vertex_rhs, &mut w.rhs);
            columns(next, &mut w.solution);
            let r = global::relative_residual(
                &self.pattern,
                &w.l2_values,
                &w.solution,
                &w.rhs,
                &mut w.scratch,
            );
            report.linear_residual = Some(report.linear_residual.map_or(r, |m| m.max(r)));
        }
        Ok(())
    }
}

/// The end of a global step solved into `solution` (every vertex's x, then every y) from
/// `rhs`: with `measure` (the pattern and matrix values: tests ask for it), its relative
/// residual into `report`; then the solution into `next`.
fn take_solution(
    solution: &[f64],
    rhs: &[f64],
    measure: Option<(&Pattern, &[f64], &mut Vec<f64>)>,
    report: &mut FrameReport,
    next: &mut [DVec2],
) {
    if let Some((pattern, values, scratch)) = measure {
        let r = global::relative_residual(pattern, values, solution, rhs, scratch);
        report.linear_residual = Some(report.linear_residual.map_or(r, |m| m.max(r)));
    }
    let n = next.len();
    for (v, p) in next.iter_mut().enumerate() {
        *p = DVec2::new(solution[v], solution[n + v]);
    }
}

/// Brings the least-squares matrix up to date with `w.diagonal`: its values depend only on
/// the handles' vertices, so they, and the factor, are kept while the diagonal stays the same;
/// otherwise refilled, and the factor marked for refactorisation.
fn refresh_least_squares(pattern: &Pattern, w: &mut Work, factor: &mut NumericFactor) {
    if w.l2_diagonal == w.diagonal && !w.l2_values.is_empty() {
        return;
    }
    pattern.fill_unit_values(&w.diagonal, &mut w.l2_values);
    w.l2_diagonal.clone_from(&w.diagonal);
    factor.invalidate();
}

/// Per column, the norm of the right-hand side's edge terms (without the handle and proximal
/// terms in `extra`). CG measures its residual against this: the handle rows, a million times
/// stiffer, would otherwise let a solve stop with the elastic rows far from balanced.
fn elastic_norm(rhs: &[f64], extra: &[DVec2]) -> [f64; 2] {
    let n = extra.len();
    let (mut sx, mut sy) = (0.0, 0.0);
    for (i, e) in extra.iter().enumerate() {
        sx += (rhs[i] - e.x).powi(2);
        sy += (rhs[n + i] - e.y).powi(2);
    }
    [sx.sqrt(), sy.sqrt()]
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Pass {
    Irls,
    LeastSquares,
}
