//! Anderson acceleration of pass 2's local/global iteration (Peng et al., "Anderson
//! Acceleration for Geometry Optimization and Physics Simulation", 2018): the iteration is a
//! fixed-point map `G` (a local step at `x`, then the global solve), and instead of taking
//! `G(x_k)` the next iterate mixes the last few `G(x_j)` with the coefficients that make the
//! mixed fixed-point residual `G(x) - x` smallest. The caller keeps the guard that makes it
//! safe: an accelerated iterate that does not lower the objective is dropped for the plain
//! `G(x_k)` and the history starts over.
//!
//! Everything here is serial and in a fixed order, so the result does not depend on the thread
//! count.

use std::collections::VecDeque;

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use glam::DVec2;

/// The mixing history: the last `window` differences of the residuals `F(x) = G(x) - x` and
/// of the values `G(x)`, in at most `window` pairs of buffers: the newest iterate's `F` and `G`
/// go into the buffers of the difference they displace, so the history costs `2 window`
/// position vectors.
#[derive(Clone, Debug, Default)]
pub struct Anderson {
    window: usize,
    /// Buffer pairs `[F, G]`: a difference's, or the last iterate's.
    pairs: Vec<[Vec<DVec2>; 2]>,
    /// The pairs holding differences, oldest first.
    steps: VecDeque<usize>,
    /// The pair holding the last iterate's `F` and `G`.
    last: Option<usize>,
}

impl Anderson {
    /// Starts a pass with a history of `window` differences (0: no acceleration); keeps the
    /// buffers.
    pub fn start(&mut self, window: usize) {
        self.window = window;
        self.pairs.truncate(window);
        self.steps.clear();
        self.last = None;
    }

    /// Forgets the differences (after a dropped iterate) but keeps the last iterate, so the
    /// plain step taken instead starts the next history.
    pub fn reset(&mut self) {
        self.steps.clear();
    }

    /// Mixes `next`, the plain successor `G(x)` of the iterate `x`, in place into the
    /// accelerated iterate `G(x) - sum gamma_j dG_j`, `gamma` the least-squares fit of `F(x)`
    /// by the past differences `dF_j`. Returns whether it changed `next` (not while the
    /// history is empty); [`Anderson::plain`] puts `G(x)` back.
    pub fn mix(&mut self, x: &[DVec2], next: &mut [DVec2]) -> bool {
        if self.window == 0 {
            return false;
        }
        // the last iterate's pair becomes the newest difference
        if let Some(k) = self.last.take() {
            let [df, dg] = &mut self.pairs[k];
            if df.len() == x.len() {
                for (((d, v), &x), &g) in df.iter_mut().zip(dg.iter_mut()).zip(x).zip(&*next) {
                    *d = (g - x) - *d;
                    *v = g - *v;
                }
                self.steps.push_back(k);
            }
        }
        let gamma = self.coefficients(x, next);
        // This iterate's pair goes into a free pair while the history is short, else into
        // the oldest difference's, overwritten in the same pass that mixes it in.
        let displaces = self.steps.len() == self.window;
        let slot = if displaces {
            self.steps.pop_front().unwrap_or_default()
        } else {
            let free = (0..).find(|i| !self.steps.contains(i)).unwrap_or_default();
            if free == self.pairs.len() {
                self.pairs.push([Vec::new(), Vec::new()]);
            }
            free
        };
        let [mut f_new, mut g_new] = std::mem::take(&mut self.pairs[slot]);
        if !displaces {
            f_new.resize(x.len(), DVec2::ZERO);
            g_new.resize(x.len(), DVec2::ZERO);
        }
        let coefficient = |j: usize| gamma.as_ref().map_or(0.0, |g| g[j]);
        // the displaced difference is the first coefficient's; the kept ones follow
        let oldest = if displaces { coefficient(0) } else { 0.0 };
        let kept: Vec<(&[DVec2], f64)> = (self.steps.iter().enumerate())
            .map(|(j, &k)| (&self.pairs[k][1][..], coefficient(j + displaces as usize)))
            .collect();
        let mixing = gamma.is_some();
        for (i, (&x, out)) in x.iter().zip(next.iter_mut()).enumerate() {
            let g = *out;
            if mixing {
                let mut mixed = g - oldest * g_new[i];
                for &(dg, c) in &kept {
                    mixed -= c * dg[i];
                }
                *out = mixed;
            }
            f_new[i] = g - x;
            g_new[i] = g;
        }
        drop(kept);
        self.pairs[slot] = [f_new, g_new];
        self.last = Some(slot);
        if mixing && !next.iter().all(|p| p.is_finite()) {
            self.plain(next);
            self.reset();
            return false;
        }
        mixing
    }

    /// Puts the last iterate's plain successor `G(x)` back into `next` (after
    /// [`Anderson::mix`] changed it).
    pub fn plain(&self, next: &mut [DVec2]) {
        if let Some(k) = self.last {
            next.copy_from_slice(&self.pairs[k][1]);
        }
    }

    /// `argmin |F(x) - dF gamma|` over the held differences, by the normal equations (a few
    /// unknowns, symmetric positive definite with the ridge: faer's dense Cholesky); `None`
    /// without differences, or when the equations are not positive definite or not finite.
    fn coefficients(&self, x: &[DVec2], g: &[DVec2]) -> Option<Vec<f64>> {
        let m = self.steps.len();
        if m == 0 {
            return None;
        }
        let df = |j: usize| &self.pairs[self.steps[j]][0];
        let dot =
            |a: &[DVec2], b: &[DVec2]| -> f64 { a.iter().zip(b).map(|(p, q)| p.dot(*q)).sum() };
        let mut normal =
            Mat::<f64>::from_fn(m, m, |i, j| if j <= i { dot(df(i), df(j)) } else { 0.0 });
        let mut rhs = Mat::<f64>::from_fn(m, 1, |i, _| {
            (df(i).iter().zip(x.iter().zip(g)))
                .map(|(d, (&x, &g))| d.dot(g - x))
                .sum()
        });
        // a relative ridge keeps nearly dependent differences from blowing the mix up
        let trace: f64 = (0..m).map(|i| normal[(i, i)]).sum();
        if !(trace > 0.0 && trace.is_finite()) {
            return None;
        }
        for i in 0..m {
            normal[(i, i)] += 1e-10 * trace;
        }
        normal.llt(Side::Lower).ok()?.solve_in_place(rhs.as_mut());
        let gamma: Vec<f64> = (0..m).map(|i| rhs[(i, 0)]).collect();
        gamma.iter().all(|v| v.is_finite()).then_some(gamma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear contraction `G(x) = A x + b` (per coordinate): Anderson with a window of two
    /// reaches its fixed point far sooner than the plain iteration.
    #[test]
    fn mixing_accelerates_a_slow_linear_contraction() {
        let g = |x: &[DVec2]| -> Vec<DVec2> {
            // a slow mode (0.95) and a fast one (0.2), coupled
            vec![
                DVec2::new(0.95 * x[0].x + 0.05 * x[1].x + 1.0, 0.2 * x[0].y + 0.5),
                DVec2::new(0.03 * x[0].x + 0.9 * x[1].x - 1.0, 0.5 * x[1].y),
            ]
        };
        let run = |window: usize| -> usize {
            let mut aa = Anderson::default();
            aa.start(window);
            let mut x = vec![DVec2::ZERO; 2];
            for k in 1..=2000 {
                let mut gx = g(&x);
                let moved = (x.iter().zip(&gx))
                    .map(|(a, b)| (*a - *b).length())
                    .fold(0.0, f64::max);
                if moved < 1e-10 {
                    return k;
                }
                aa.mix(&x, &mut gx);
                x = gx;
            }
            2000
        };
        let (plain, mixed) = (run(0), run(2));
        assert!(plain > 200, "plain iteration took {plain}");
        assert!(10 * mixed < plain, "Anderson took {mixed}, plain {plain}");
    }

    #[test]
    fn without_history_the_plain_step_is_taken_and_plain_restores_it() {
        let mut aa = Anderson::default();
        aa.start(2);
        let x = vec![DVec2::ZERO; 3];
        let mut g = vec![DVec2::ONE; 3];
        assert!(!aa.mix(&x, &mut g));
        assert_eq!(g, vec![DVec2::ONE; 3]);
        // a second iterate has a difference to mix with
        let x2 = g.clone();
        let mut g2 = vec![DVec2::new(1.5, 1.25); 3];
        let plain = g2.clone();
        assert!(aa.mix(&x2, &mut g2));
        assert_ne!(g2, plain);
        aa.plain(&mut g2);
        assert_eq!(g2, plain);
        // after a reset the next iterate mixes with the newest difference only, and the
        // history never holds more than `window` pairs
        aa.reset();
        let mut g3 = vec![DVec2::splat(1.7); 3];
        aa.mix(&g2, &mut g3);
        assert_eq!(aa.steps.len(), 1);
        assert!(aa.pairs.len() <= 2);
    }

    #[test]
    fn the_history_holds_window_pairs_and_mixes_the_same_as_a_full_copy() {
        // the in-place ring against a straightforward Anderson with explicit history
        let g = |x: &[DVec2]| -> Vec<DVec2> {
            x.iter()
                .enumerate()
                .map(|(i, p)| {
                    DVec2::new(
                        0.9 * p.x + 0.1 * p.y.sin() + i as f64,
                        0.7 * p.y + 0.2 * p.x.cos(),
                    )
                })
                .collect()
        };
        let window = 3;
        let mut aa = Anderson::default();
        aa.start(window);
        let mut x = vec![DVec2::new(0.3, -0.2); 4];
        let (mut fs, mut gs): (Vec<Vec<DVec2>>, Vec<Vec<DVec2>>) = (Vec::new(), Vec::new());
        for _ in 0..12 {
            let plain = g(&x);
            let f: Vec<DVec2> = plain.iter().zip(&x).map(|(&g, &x)| g - x).collect();
            fs.push(f.clone());
            gs.push(plain.clone());
            // reference: differences of the last window + 1 iterates
            let k = fs.len();
            let d = (k - 1).min(window);
            let mut want = plain.clone();
            if d > 0 {
                let dfs: Vec<Vec<DVec2>> = (k - 1 - d..k - 1)
                    .map(|j| fs[j + 1].iter().zip(&fs[j]).map(|(a, b)| *a - *b).collect())
                    .collect();
                let dgs: Vec<Vec<DVec2>> = (k - 1 - d..k - 1)
                    .map(|j| gs[j + 1].iter().zip(&gs[j]).map(|(a, b)| *a - *b).collect())
                    .collect();
                let dot = |a: &[DVec2], b: &[DVec2]| -> f64 {
                    a.iter().zip(b).map(|(p, q)| p.dot(*q)).sum()
                };
                let mut a = vec![vec![0.0; d + 1]; d];
                for i in 0..d {
                    for j in 0..d {
                        a[i][j] = dot(&dfs[i], &dfs[j]);
                    }
                    a[i][d] = dot(&dfs[i], &f);
                }
                let trace: f64 = (0..d).map(|i| a[i][i]).sum();
                for (i, row) in a.iter_mut().enumerate() {
                    row[i] += 1e-10 * trace;
                }
                let normal = Mat::<f64>::from_fn(d, d, |i, j| a[i][j]);
                let mut gamma = Mat::<f64>::from_fn(d, 1, |i, _| a[i][d]);
                normal
                    .llt(Side::Lower)
                    .unwrap()
                    .solve_in_place(gamma.as_mut());
                let gamma: Vec<f64> = (0..d).map(|i| gamma[(i, 0)]).collect();
                for (j, c) in gamma.iter().enumerate() {
                    for (w, dg) in want.iter_mut().zip(&dgs[j]) {
                        *w -= *c * *dg;
                    }
                }
            }
            let mut got = plain.clone();
            aa.mix(&x, &mut got);
            for (a, b) in got.iter().zip(&want) {
                assert!(
                    (*a - *b).length() <= 1e-9 * (1.0 + b.length()),
                    "{a} vs {b}"
                );
            }
            assert!(aa.pairs.len() <= window);
            x = got;
        }
    }
}
