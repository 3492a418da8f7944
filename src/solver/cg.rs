//! Conjugate gradients on the global step's two-column system, each column with its own step
//! lengths but sharing the matrix products. Unpreconditioned, it is the paper's own solver
//! (the `SolverKind::Cg` baseline); preconditioned by a stale Cholesky factor it solves systems
//! whose weights changed a little since that factor was computed.

use super::global::Pattern;

/// Scratch vectors reused across solves (no allocation on the per-frame path once sized).
#[derive(Clone, Debug, Default)]
pub struct CgWork {
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    ap: Vec<f64>,
}

/// Outcome of one CG solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgOutcome {
    pub iterations: usize,
    pub converged: bool,
}

/// Replaces its argument (two columns) by `M^-1` times it.
pub type Preconditioner<'a> = dyn FnMut(&mut [f64]) + 'a;

/// When a solve stops: relative residual reached, or iteration cap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgStop {
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Per column, the norm the residual is measured against; `None` uses the right-hand
    /// side's own norm.
    pub reference: Option<[f64; 2]>,
}

fn col(n: usize, c: usize) -> std::ops::Range<usize> {
    c * n..(c + 1) * n
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves `A X = B` (two columns, column-major) starting from `x`, until every column's
/// residual is below `stop.tolerance` times its right-hand side's norm or
/// `stop.max_iterations` pass.
/// `precondition`, if given, replaces its argument (two columns) by `M^-1` times it.
pub fn solve(
    pattern: &Pattern,
    values: &[f64],
    b: &[f64],
    x: &mut [f64],
    stop: CgStop,
    mut precondition: Option<&mut Preconditioner<'_>>,
    work: &mut CgWork,
) -> CgOutcome {
    let n = pattern.n;
    for v in [&mut work.r, &mut work.z, &mut work.p, &mut work.ap] {
        v.clear();
        v.resize(2 * n, 0.0);
    }
    pattern.multiply(values, x, &mut work.ap, 2);
    for ((r, bi), ax) in work.r.iter_mut().zip(b).zip(&work.ap) {
        *r = bi - ax;
    }
    let mut goal = [0.0; 2];
    let mut done = [false; 2];
    for (c, (g, d)) in goal.iter_mut().zip(&mut done).enumerate() {
        let bn = match stop.reference {
            Some(r) => r[c],
            None => dot(&b[col(n, c)], &b[col(n, c)]).sqrt(),
        };
        *g = stop.tolerance * bn.max(1e-300);
        *d = dot(&work.r[col(n, c)], &work.r[col(n, c)]).sqrt() <= *g;
    }
    if done[0] && done[1] {
        return CgOutcome {
            iterations: 0,
            converged: true,
        };
    }
    work.z.copy_from_slice(&work.r);
    if let Some(m) = precondition.as_mut() {
        m(&mut work.z);
    }
    work.p.copy_from_slice(&work.z);
    let mut rz = [0.0; 2];
    for (c, v) in rz.iter_mut().enumerate() {
        *v = dot(&work.r[col(n, c)], &work.z[col(n, c)]);
    }
    let mut iterations = 0;
    while iterations < stop.max_iterations && !(done[0] && done[1]) {
        iterations += 1;
        pattern.multiply(values, &work.p, &mut work.ap, 2);
        for c in 0..2 {
            if done[c] {
                continue;
            }
            let range = col(n, c);
            let pap = dot(&work.p[range.clone()], &work.ap[range.clone()]);
            if pap.is_nan() || pap <= 0.0 || !pap.is_finite() {
                // breakdown: the direction carries no curvature; nothing more to gain.
                done[c] = true;
                continue;
            }
            let alpha = rz[c] / pap;
            for i in range.clone() {
                x[i] += alpha * work.p[i];
                work.r[i] -= alpha * work.ap[i];
            }
            if dot(&work.r[range.clone()], &work.r[range]).sqrt() <= goal[c] {
                done[c] = true;
            }
        }
        if done[0] && done[1] {
            break;
        }
        work.z.copy_from_slice(&work.r);
        if let Some(m) = precondition.as_mut() {
            m(&mut work.z);
        }
        for c in 0..2 {
            if done[c] {
                continue;
            }
            let range = col(n, c);
            let rz_new = dot(&work.r[range.clone()], &work.z[range.clone()]);
            let beta = if rz[c] != 0.0 { rz_new / rz[c] } else { 0.0 };
            rz[c] = rz_new;
            for i in range {
                work.p[i] = work.z[i] + beta * work.p[i];
            }
        }
    }
    // Recheck with the true residual's bookkeeping: breakdown columns count as converged only
    // if their residual really is small.
    let converged =
        (0..2).all(|c| dot(&work.r[col(n, c)], &work.r[col(n, c)]).sqrt() <= goal[c] * 1.0001);
    CgOutcome {
        iterations,
        converged,
    }
}
