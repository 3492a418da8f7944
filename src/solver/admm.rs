//! Pass 1 by variable splitting (ADMM) instead of reweighting: the sub-quadratic energy
//! `sum |r_e|^p` over the part-edges' residuals `r_e = f(x) - f(y) - R_xy (x0 - y0)` is split
//! as `sum |z_e|^p` subject to `z_e = r_e`. Each iteration then solves the *least-squares*
//! system with the targets moved by `z - u` (the matrix never changes, so pass 1 reuses pass
//! 2's factor: no numeric factorisation per iteration), shrinks every edge's residual with the
//! proximal map of `|.|^p` (residuals below a threshold snap back to zero: those edges stay
//! rigid; larger ones become free gaps) and accumulates the scaled dual `u`. This is the
//! splitting Bouaziz et al. use for sparse ICP; IRLS and it have the same stationary points.
//! Like IRLS it starts every frame from the displayed pose (no gaps, no duals) and runs until
//! its steps stop: it converges linearly, so it needs far more (cheaper) iterations than IRLS
//! (`docs/solver.md`).
//!
//! This module holds the per-edge variables and the shrink operator; `Solver` drives it.

use glam::DVec2;

/// Per part-edge splitting variables of one frame (kept between frames only as buffers).
#[derive(Clone, Debug, Default)]
pub struct Splitting {
    /// Gaps `z_e`: the part of each residual the sub-quadratic norm leaves open.
    pub z: Vec<DVec2>,
    /// Scaled duals `u_e`.
    pub u: Vec<DVec2>,
    /// The pass-1 pose (of either method).
    pub pose: Vec<DVec2>,
}

impl Splitting {
    /// Starts a frame's pass 1 at `pose`: no gaps, no duals.
    pub fn reset(&mut self, edges: usize, pose: &[DVec2]) {
        self.z.clear();
        self.z.resize(edges, DVec2::ZERO);
        self.u.clear();
        self.u.resize(edges, DVec2::ZERO);
        self.pose.clear();
        self.pose.extend_from_slice(pose);
    }
}

/// The penalty `rho` whose shrink threshold (the residual length below which a gap closes)
/// is `threshold`, for the norm `p`. For `p < 1` the proximal map of `|z|^p / rho` is zero
/// below `C_p rho^(-1 / (2 - p))`; for `p >= 1` we take `rho = threshold^(p - 2)`, which gives
/// the soft threshold `threshold` at `p = 1`.
pub fn penalty(threshold: f64, p: f64) -> f64 {
    let threshold = threshold.max(1e-12);
    let c = if p < 1.0 {
        let a = (2.0 * (1.0 - p)).powf(1.0 / (2.0 - p));
        a + p * a.powf(p - 1.0)
    } else {
        1.0
    };
    // rho = (c / threshold)^(2 - p); at p = 2 any rho works (the norm is the least-squares
    // one), so keep 1 there.
    if p >= 2.0 {
        1.0
    } else {
        (c / threshold).powf(2.0 - p)
    }
}

/// The proximal map of the sub-quadratic norm for one penalty: `argmin_z |z|^p + rho/2
/// |z - v|^2` for a 2D residual `v` (isotropic, so `z` is `v` scaled by `s / |v|` with `s`
/// the 1D solution). The threshold is computed once, not per edge.
#[derive(Clone, Copy, Debug)]
pub struct Shrink {
    rho: f64,
    p: f64,
    /// Residuals no longer than this close to zero (`p < 1`; 0 otherwise).
    threshold: f64,
    /// Lower end of the bracket of the shrunk length (`p < 1`: where the 1D objective's
    /// nonzero branch starts; 0 otherwise).
    lower: f64,
    /// `1 / (2 rho)`, the cubic's coefficient at `p = 1/2`: divided once here rather than
    /// once per open edge.
    half_over_rho: f64,
}

impl Shrink {
    pub fn new(rho: f64, p: f64) -> Self {
        let (threshold, lower) = if p < 1.0 && rho > 0.0 {
            let a = (2.0 * (1.0 - p) / rho).powf(1.0 / (2.0 - p));
            (a + (p / rho) * a.powf(p - 1.0), a)
        } else if p == 1.0 && rho > 0.0 {
            (1.0 / rho, 0.0)
        } else {
            (0.0, 0.0)
        };
        Self {
            rho,
            p,
            threshold,
            lower,
            half_over_rho: 0.5 / rho,
        }
    }

    /// The factor the shrink scales a residual of squared length `n2` by (in [0, 1]): the
    /// same map for a stacked residual (a part's edges) as for one edge.
    pub fn factor(&self, n2: f64) -> f64 {
        let n = n2.sqrt();
        if n > 0.0 {
            (self.apply(DVec2::new(n, 0.0)).x / n).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// `s^(p - 1)` and `s^(p - 2)`, with p = 0.5 spelled out (powf would dominate).
    fn powers(&self, s: f64) -> (f64, f64) {
        if self.p == 0.5 {
            let r = 1.0 / s.sqrt();
            (r, r / s)
        } else {
            let a = s.powf(self.p - 1.0);
            (a, a / s)
        }
    }

    /// The shrunk residual: zero for a closed gap (most edges, decided inline in the
    /// caller's loop), else [`Shrink::open`].
    #[inline]
    pub fn apply(&self, v: DVec2) -> DVec2 {
        let n2 = v.length_squared();
        // NaN fails every comparison: a NaN residual or penalty closes the gap
        let open = n2 > self.threshold * self.threshold && n2.is_finite() && self.rho > 0.0;
        if !open {
            return DVec2::ZERO;
        }
        self.open(v, n2)
    }

    /// [`Shrink::apply`] for a residual `v` (squared length `n2`) above the threshold.
    #[inline(never)]
    fn open(&self, v: DVec2, n2: f64) -> DVec2 {
        let n = n2.sqrt();
        let (rho, p) = (self.rho, self.p);
        if p >= 2.0 {
            // |z|^2: z = rho v / (rho + 2)
            return v * (rho / (rho + 2.0));
        }
        if p == 1.0 {
            return v * ((n - self.threshold) / n);
        }
        if p == 0.5 {
            // s + c / sqrt(s) = n with c = 1 / (2 rho). With s = n h^2 this is the cubic
            // h^3 - h + e = 0, e = c / n^(3/2); above the threshold its largest root lies in
            // (1 / sqrt 3, 1). Its series h = 1 - e/2 - 3e^2/8 - e^3/2 - 105e^4/128 - ... has
            // only negative terms, so four of them start Newton above the root (by 2e-5 at
            // e = 0.1, 5e-3 at 0.27), where the cubic is positive and convex: the steps
            // descend to it monotonically, and once one is below 1e-9 the next error is below
            // 1e-17 (quadratic convergence) and the loop stops. Two to four divisions, where
            // the trigonometric formula took an acos and a cos per open edge.
            let e = self.half_over_rho / (n * n2).sqrt();
            let mut h = 1.0 - e * (0.5 + e * (0.375 + e * (0.5 + e * (105.0 / 128.0))));
            for _ in 0..64 {
                let step = (h * h * h - h + e) / (3.0 * h * h - 1.0);
                h -= step;
                // converged (or NaN)
                if step.is_nan() || step <= 1e-9 * h {
                    break;
                }
            }
            let scale = h * h;
            if scale.is_finite() {
                return v * scale.clamp(0.0, 1.0);
            }
        }
        // Stationarity for s > 0: phi(s) = s + (p / rho) s^(p - 1) - n = 0, with the root
        // bracketed: for p < 1 between the stationary point of the 1D objective's second
        // branch (`lower`) and n, for 1 < p < 2 between 0 and n. Newton, falling back to
        // bisection whenever a step leaves the bracket.
        let (mut lo, mut hi) = (self.lower, n);
        let mut s = n;
        for _ in 0..60 {
            let (a, b) = self.powers(s);
            let phi = s + (p / rho) * a - n;
            if phi > 0.0 {
                hi = s;
            } else {
                lo = s;
            }
            let dphi = 1.0 + (p * (p - 1.0) / rho) * b;
            let newton = s - phi / dphi;
            let next = if dphi > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - s).abs() <= 1e-12 * n || hi - lo <= 1e-12 * n {
                s = next;
                break;
            }
            s = next;
        }
        v * (s.clamp(0.0, n) / n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shrink(v: DVec2, rho: f64, p: f64) -> DVec2 {
        Shrink::new(rho, p).apply(v)
    }

    /// Brute-force 1D minimiser of `s^p + rho/2 (s - n)^2` over `[0, n]`.
    fn brute(n: f64, rho: f64, p: f64) -> f64 {
        let cost = |s: f64| s.powf(p) + 0.5 * rho * (s - n) * (s - n);
        let mut best = (0.0, cost(0.0));
        let steps = 200_000;
        for k in 1..=steps {
            let s = n * k as f64 / steps as f64;
            let c = cost(s);
            if c < best.1 {
                best = (s, c);
            }
        }
        best.0
    }

    #[test]
    fn shrink_minimises_the_proximal_objective() {
        for &p in &[0.5, 0.8, 1.0, 1.5, 2.0] {
            for &rho in &[0.3, 2.0, 50.0] {
                for &n in &[0.01, 0.3, 1.0, 2.5, 10.0] {
                    let v = DVec2::new(0.6, -0.8) * n;
                    let z = shrink(v, rho, p);
                    let s = z.length();
                    let expected = brute(n, rho, p);
                    assert!(
                        (s - expected).abs() <= 1e-4 * n.max(1.0),
                        "p {p} rho {rho} n {n}: {s} vs {expected}"
                    );
                    // same direction as v (or zero)
                    assert!(s == 0.0 || (z / s - v / n).length() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn the_closed_form_for_p_one_half_is_a_stationary_point() {
        for &rho in &[0.01, 1.0, 164.0, 1e4] {
            let shrink = Shrink::new(rho, 0.5);
            for k in 0..200 {
                let n = shrink.threshold * (1.0 + 1e-9 + 0.05 * k as f64);
                let s = shrink.apply(DVec2::new(0.0, n)).length();
                let phi = s + 0.5 / rho / s.sqrt() - n;
                assert!(phi.abs() <= 1e-10 * n, "rho {rho} n {n}: s {s}, phi {phi}");
                // the open branch beats closing the gap
                assert!(s.sqrt() + 0.5 * rho * (s - n).powi(2) <= 0.5 * rho * n * n + 1e-12);
            }
        }
    }

    #[test]
    fn penalty_puts_the_threshold_where_asked() {
        for &p in &[0.3, 0.5, 0.9] {
            for &t in &[0.01, 0.2, 3.0] {
                let rho = penalty(t, p);
                let v = DVec2::X * t;
                assert_eq!(shrink(v * 0.99, rho, p), DVec2::ZERO, "p {p} t {t}");
                assert!(shrink(v * 1.01, rho, p).length() > 0.0, "p {p} t {t}");
            }
        }
    }

    #[test]
    fn degenerate_input_gives_zero_not_nan() {
        assert_eq!(shrink(DVec2::ZERO, 1.0, 0.5), DVec2::ZERO);
        assert_eq!(shrink(DVec2::NAN, 1.0, 0.5), DVec2::ZERO);
        assert_eq!(shrink(DVec2::X, 0.0, 0.5), DVec2::ZERO);
    }
}
