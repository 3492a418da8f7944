//! The local step over fixed chunks of parts, on both cores (paper 4.1-4.3 per part): every
//! part's rotation (and, when switching, its rest-state choice), its edge targets
//! `R_xy (x0 - y0)` and its squared residuals, in one pass over the part's data.
//!
//! **Deterministic whatever the thread count.** The parts are cut into chunks of [`CHUNK`]
//! parts, the same for any thread count; each thread takes a contiguous run of chunks and
//! writes into its own slices of pre-sized outputs (one slot per part or per part-edge), with
//! its own scratch. The only number that crosses parts, the elastic energy, is summed in edge
//! order within a chunk and then over the chunks in order, so it has the same bits on one
//! thread or two. State switches are not applied here: the caller reads the chosen states in
//! part order.

use std::ops::Range;
use std::sync::OnceLock;

use rayon::prelude::*;

use clay_dsl::compiled::Part;
use glam::DVec2;

use super::local::Switching;
use super::rest_cache::RestCache;

/// Parts per chunk (fixed: the chunks, and so every sum, do not depend on the thread count).
pub const CHUNK: usize = 512;

/// Below this many parts the step stays on the calling thread: starting a thread (about
/// 20-50 microseconds here) would cost more than the second core saves.
pub const PARALLEL_MIN_PARTS: usize = 8 * CHUNK;

/// Whether the local step may switch rest states (pass 1) or keeps them (pass 2).
#[derive(Clone, Copy, Debug)]
pub enum Choice<'a> {
    /// Rotations of the active states.
    Keep,
    /// Each part's nearest rest state, with hysteresis (paper 4.3), a stretch part's by its
    /// length ([`super::local::decide_stretch`]).
    Switch(Switching<'a>),
}

/// One evaluation's outputs: per part its rotation, its (chosen) active state and its squared
/// stacked residual; per part-edge its target.
pub struct Outputs<'a> {
    pub rotations: &'a mut [DVec2],
    pub chosen: &'a mut [usize],
    /// Per part: its claim ([`super::local::Chosen::claim`]; 0 when the states are kept).
    pub claims: &'a mut [i32],
    pub residuals: &'a mut [f64],
    pub targets: &'a mut [DVec2],
}

/// Outputs that can be cut at a part (and its first edge) for another thread.
trait Split: Sized + Send {
    fn split(self, parts: usize, edges: usize) -> (Self, Self);
}

impl Split for Outputs<'_> {
    fn split(self, parts: usize, edges: usize) -> (Self, Self) {
        let (r0, r1) = self.rotations.split_at_mut(parts);
        let (c0, c1) = self.chosen.split_at_mut(parts);
        let (k0, k1) = self.claims.split_at_mut(parts);
        let (s0, s1) = self.residuals.split_at_mut(parts);
        let (t0, t1) = self.targets.split_at_mut(edges);
        (
            Outputs {
                rotations: r0,
                chosen: c0,
                claims: k0,
                residuals: s0,
                targets: t0,
            },
            Outputs {
                rotations: r1,
                chosen: c1,
                claims: k1,
                residuals: s1,
                targets: t1,
            },
        )
    }
}

/// The second half of a step within a rotation cone: targets and residuals only.
struct Targets<'a> {
    residuals: &'a mut [f64],
    targets: &'a mut [DVec2],
}

impl Split for Targets<'_> {
    fn split(self, parts: usize, edges: usize) -> (Self, Self) {
        let (s0, s1) = self.residuals.split_at_mut(parts);
        let (t0, t1) = self.targets.split_at_mut(edges);
        (
            Targets {
                residuals: s0,
                targets: t0,
            },
            Targets {
                residuals: s1,
                targets: t1,
            },
        )
    }
}

/// The fixed chunks of a step: chunk `c` holds parts `bounds[c].0..bounds[c + 1].0`, whose
/// edges start at `bounds[c].1`.
struct Chunks {
    bounds: Vec<(usize, usize)>,
}

impl Chunks {
    fn new(cache: &RestCache, parts: usize) -> Self {
        let mut bounds: Vec<(usize, usize)> = (0..parts)
            .step_by(CHUNK)
            .map(|p| (p, cache.first_edge(p)))
            .collect();
        bounds.push((parts, cache.edges()));
        Self { bounds }
    }

    fn count(&self) -> usize {
        self.bounds.len() - 1
    }

    fn parts(&self, c: usize) -> Range<usize> {
        self.bounds[c].0..self.bounds[c + 1].0
    }

    /// Runs `work` once per chunk, each chunk with its own piece of `out` (whose slot 0 is
    /// the chunk's first part and edge): on the calling thread alone when `threads` is 1, else
    /// as tasks of a work-stealing pool (a chunk nobody else takes, the caller runs itself, so
    /// a core another process holds delays nothing). The results come back in chunk order
    /// whichever thread computed them.
    fn run<O: Split, R: Send>(
        &self,
        threads: usize,
        out: O,
        work: &(dyn Fn(usize, O) -> R + Sync),
    ) -> Vec<R> {
        let count = self.count();
        let mut pieces = Vec::with_capacity(count);
        let mut rest = out;
        for c in 1..count {
            let (parts, edges) = (
                self.bounds[c].0 - self.bounds[c - 1].0,
                self.bounds[c].1 - self.bounds[c - 1].1,
            );
            let (head, tail) = rest.split(parts, edges);
            pieces.push(head);
            rest = tail;
        }
        pieces.push(rest);
        let threads = threads.clamp(1, count.max(1));
        if threads == 1 {
            let run = pieces.into_iter().enumerate();
            return run.map(|(c, piece)| work(c, piece)).take(count).collect();
        }
        // one task per chunk; `collect` keeps the chunk order whichever thread ran a task
        let run = || {
            let tasks = pieces.into_par_iter().enumerate().with_max_len(1);
            tasks.map(|(c, piece)| work(c, piece)).collect()
        };
        on_pool(run)
    }
}

/// Rows (vertices) per task of a gathered right-hand side ([`rows`]).
const ROW_CHUNK: usize = 4096;

/// Below this many rows (vertices) a right-hand side or a matrix fill stays on the calling
/// thread ([`rows`], [`columns`]).
pub const PARALLEL_MIN_ROWS: usize = 4 * ROW_CHUNK;

/// Runs `work(first, rows)` over consecutive pieces of `rows` (each row computed on its own,
/// so any cut gives the same rows): on the pool when `threads > 1` and there are at least
/// four pieces, else on the calling thread.
pub fn rows(threads: usize, rows: &mut [DVec2], work: &(dyn Fn(usize, &mut [DVec2]) + Sync)) {
    if threads <= 1 || rows.len() < PARALLEL_MIN_ROWS {
        work(0, rows);
        return;
    }
    let run = move || {
        let pieces = rows.par_chunks_mut(ROW_CHUNK).enumerate();
        pieces.for_each(|(c, piece)| work(c * ROW_CHUNK, piece));
    };
    on_pool(run);
}

/// Runs `work(columns, values)` over consecutive runs of [`ROW_CHUNK`] columns of a
/// compressed-column matrix (`col_ptr`), each with its columns' slice of `values` (each
/// column computed on its own, so any cut gives the same values): on the pool when
/// `threads > 1` and there are at least four runs, else on the calling thread.
pub fn columns(
    threads: usize,
    col_ptr: &[usize],
    values: &mut [f64],
    work: &(dyn Fn(Range<usize>, &mut [f64]) + Sync),
) {
    let n = col_ptr.len().saturating_sub(1);
    if threads <= 1 || n < PARALLEL_MIN_ROWS {
        work(0..n, values);
        return;
    }
    let mut pieces = Vec::with_capacity(n.div_ceil(ROW_CHUNK));
    let mut rest = values;
    for first in (0..n).step_by(ROW_CHUNK) {
        let end = (first + ROW_CHUNK).min(n);
        let (piece, tail) = rest.split_at_mut(col_ptr[end] - col_ptr[first]);
        pieces.push((first..end, piece));
        rest = tail;
    }
    let run = move || {
        pieces
            .into_par_iter()
            .for_each(|(columns, piece)| work(columns, piece));
    };
    on_pool(run);
}

/// Runs `a` and `b`, side by side on the pool when `threads > 1` (the caller makes the
/// result independent of which ran where).
pub fn join<A, B, RA, RB>(threads: usize, a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA + Send,
    B: FnOnce() -> RB + Send,
    RA: Send,
    RB: Send,
{
    if threads <= 1 {
        return (a(), b());
    }
    on_pool(|| rayon::join(a, b))
}

/// Runs `run` on the pool ([`pool`]), or on rayon's global pool when it could not start; the
/// calling thread blocks until it is done. Called from a thread of the pool, `run` runs at
/// once on that thread: a frame run as one task of the pool hands each parallel step to the
/// pool from inside it (a step handed over from outside put the caller to sleep and woke a
/// pool thread about 90 times a frame at 10k parts). A pool thread with nothing to do
/// blocks in rayon's sleep: no core is spun while a frame runs serial work, nor between
/// frames.
pub fn on_pool<R: Send>(run: impl FnOnce() -> R + Send) -> R {
    match pool() {
        Some(pool) => pool.install(run),
        None => run(),
    }
}

/// The local step's thread pool (every core), started at the first parallel step; `None`
/// when it cannot be started (rayon's global pool then runs the tasks).
fn pool() -> Option<&'static rayon::ThreadPool> {
    static POOL: OnceLock<Option<rayon::ThreadPool>> = OnceLock::new();
    POOL.get_or_init(|| {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let builder = rayon::ThreadPoolBuilder::new().num_threads(cores.max(2));
        builder
            .thread_name(|i| format!("clay-local-{i}"))
            .build()
            .ok()
    })
    .as_ref()
}

/// Evaluates the local step at `positions` for every part of `parts` (which `cache` was built
/// for) into `out` (one slot per part and per part-edge, in the solver's order); returns the
/// elastic energy `sum |t - (f_x - f_y)|^2`. With a rotation cone (`cos_cone < 1`) an edge's
/// rotation averages its neighbours', so all rotations come first, then the targets.
pub fn evaluate(
    cache: &RestCache,
    parts: &[Part],
    positions: &[DVec2],
    choice: Choice,
    cos_cone: f64,
    threads: usize,
    out: Outputs,
) -> f64 {
    let chunks = Chunks::new(cache, parts.len());
    let threads = if parts.len() < PARALLEL_MIN_PARTS {
        1
    } else {
        threads
    };
    let scratch = cache.largest_part();
    let partials = if cos_cone >= 1.0 {
        let work = |c: usize, o: Outputs| {
            let (p0, e0) = chunks.bounds[c];
            let (mut small, mut large) = ([DVec2::ZERO; SMALL], Vec::new());
            let pose = scratch_of(&mut small, &mut large, scratch);
            let mut elastic = 0.0;
            for pi in chunks.parts(c) {
                let part = &parts[pi];
                let (active, own, claim) = rotate(cache, pi, part, positions, choice, pose);
                o.rotations[pi - p0] = own;
                o.chosen[pi - p0] = active;
                o.claims[pi - p0] = claim;
                let first = cache.first_edge(pi) - e0;
                let t = &mut o.targets[first..][..cache.part_edges(pi)];
                cache.targets_with(pi, active, own, &[], cos_cone, t, pose);
                o.residuals[pi - p0] = cache.residual_of(pi, t, positions, &mut elastic);
            }
            elastic
        };
        chunks.run(threads, out, &work)
    } else {
        within_cone(
            cache, &chunks, parts, positions, choice, cos_cone, threads, out,
        )
    };
    // over the chunks in order (one chunk: the chunk's own sum, since +0 + x is x)
    let mut elastic = 0.0;
    for e in partials {
        elastic += e;
    }
    elastic
}

/// Part `pi`'s active state after the step, its rotation onto `positions` and its claim.
#[inline]
fn rotate(
    cache: &RestCache,
    pi: usize,
    part: &Part,
    positions: &[DVec2],
    choice: Choice,
    pose: &mut [DVec2],
) -> (usize, DVec2, i32) {
    match choice {
        Choice::Keep => (part.active, cache.rotation_of(pi, part, positions), 0),
        Choice::Switch(how) => {
            let c = cache.choose_with(pi, part, positions, how, pose);
            (c.state, c.rotation, c.claim)
        }
    }
}

/// [`evaluate`] within a rotation cone: every part's rotation and state first, then the
/// targets (which read the rotations of the parts around each vertex); returns the chunks'
/// energies in order.
#[allow(clippy::too_many_arguments)]
fn within_cone(
    cache: &RestCache,
    chunks: &Chunks,
    parts: &[Part],
    positions: &[DVec2],
    choice: Choice,
    cos_cone: f64,
    threads: usize,
    out: Outputs,
) -> Vec<f64> {
    let scratch = cache.largest_part();
    let Outputs {
        rotations,
        chosen,
        claims,
        residuals,
        targets,
    } = out;
    let states = |c: usize, o: Outputs| {
        let p0 = chunks.bounds[c].0;
        let (mut small, mut large) = ([DVec2::ZERO; SMALL], Vec::new());
        let pose = scratch_of(&mut small, &mut large, scratch);
        for pi in chunks.parts(c) {
            let (active, own, claim) = rotate(cache, pi, &parts[pi], positions, choice, pose);
            o.rotations[pi - p0] = own;
            o.chosen[pi - p0] = active;
            o.claims[pi - p0] = claim;
        }
    };
    let no_targets = Outputs {
        rotations: &mut *rotations,
        chosen: &mut *chosen,
        claims,
        residuals: &mut [],
        targets: &mut [],
    };
    // only the parts' slots are cut in the first half
    chunks.run(threads, PartsOnly(no_targets), &|c, o: PartsOnly| {
        states(c, o.0)
    });
    let (rotations, chosen) = (&*rotations, &*chosen);
    let work = |c: usize, o: Targets| {
        let (p0, e0) = chunks.bounds[c];
        let (mut small, mut large) = ([DVec2::ZERO; SMALL], Vec::new());
        let sums = scratch_of(&mut small, &mut large, scratch);
        let mut elastic = 0.0;
        for pi in chunks.parts(c) {
            let at = cache.first_edge(pi) - e0;
            let t = &mut o.targets[at..][..cache.part_edges(pi)];
            let own = rotations[pi];
            cache.targets_with(pi, chosen[pi], own, rotations, cos_cone, t, sums);
            o.residuals[pi - p0] = cache.residual_of(pi, t, positions, &mut elastic);
        }
        elastic
    };
    chunks.run(threads, Targets { residuals, targets }, &work)
}

/// [`Outputs`] whose per-edge slices are empty (the first half of a step within a cone).
struct PartsOnly<'a>(Outputs<'a>);

impl Split for PartsOnly<'_> {
    fn split(self, parts: usize, _edges: usize) -> (Self, Self) {
        let o = self.0;
        let (r0, r1) = o.rotations.split_at_mut(parts);
        let (c0, c1) = o.chosen.split_at_mut(parts);
        let (k0, k1) = o.claims.split_at_mut(parts);
        let empty = || Outputs {
            rotations: &mut [],
            chosen: &mut [],
            claims: &mut [],
            residuals: &mut [],
            targets: &mut [],
        };
        let (mut a, mut b) = (empty(), empty());
        (a.rotations, a.chosen, b.rotations, b.chosen) = (r0, c0, r1, c1);
        (a.claims, b.claims) = (k0, k1);
        (PartsOnly(a), PartsOnly(b))
    }
}

/// Parts up to this many vertices take their scratch from the stack.
const SMALL: usize = 32;

/// A chunk's scratch of `len` points: `small` when it fits, else `large` grown to it (a
/// worker then allocates nothing for the usual parts).
fn scratch_of<'a>(
    small: &'a mut [DVec2; SMALL],
    large: &'a mut Vec<DVec2>,
    len: usize,
) -> &'a mut [DVec2] {
    if len <= SMALL {
        &mut small[..len]
    } else {
        large.resize(len, DVec2::ZERO);
        large
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::local::VertexParts;
    use crate::solver::rest_cache::RestCache;

    fn same(a: DVec2, b: DVec2) -> bool {
        a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
    }

    /// A frame run on the pool returns what it computed, runs its halves on the pool, and
    /// ends, with its panic, when it unwinds.
    #[test]
    fn a_pooled_frame_returns_and_unwinds() {
        let (a, b) = on_pool(|| join(2, || 20 + 1, || 2 * 10 + 1));
        assert_eq!((a, b), (21, 21));
        let sum: u64 = on_pool(|| (0..10_000u64).into_par_iter().sum());
        assert_eq!(sum, 49_995_000);
        let (sender, receiver) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let unwound = std::panic::catch_unwind(|| on_pool(|| -> u32 { panic!("frame") }));
            sender.send(unwound.is_err()).unwrap();
        });
        let unwound = receiver.recv_timeout(std::time::Duration::from_secs(60));
        assert_eq!(
            unwound,
            Ok(true),
            "a frame that unwinds must end, with its panic"
        );
        // the pool still serves frames afterwards
        assert_eq!(on_pool(|| 7), 7);
    }

    /// The chunked step gives the reference step's states, rotations, targets and (for one
    /// chunk) energy bit for bit, with and without a rotation cone, on a deformed city.
    #[test]
    fn chunked_step_matches_the_reference_step() {
        let data = crate::synthetic::city(400).assembly;
        let n = data.positions.len();
        // a shear and a wave, so parts are rotated, strained and some switch
        let positions: Vec<DVec2> = (data.positions.iter())
            .map(|p| DVec2::new(p.x + 0.3 * p.y, p.y + (0.7 * p.x).sin()))
            .collect();
        for cos_cone in [1.0, 20f64.to_radians().cos()] {
            for choice in [Choice::Keep, Choice::Switch(Switching::plain(0.15))] {
                let mut parts = data.parts.clone();
                let vp = VertexParts::build(&parts, n);
                let mut cache = RestCache::build(&parts, &vp).unwrap();
                assert!(
                    parts.len() <= CHUNK,
                    "one chunk: the energy is one running sum"
                );
                let (count, edges) = (parts.len(), cache.edges());
                let (mut rotations, mut chosen) = (vec![DVec2::X; count], vec![0; count]);
                let (mut residuals, mut targets) = (vec![0.0; count], vec![DVec2::ZERO; edges]);
                let mut claims = vec![0; count];
                let out = Outputs {
                    rotations: &mut rotations,
                    chosen: &mut chosen,
                    claims: &mut claims,
                    residuals: &mut residuals,
                    targets: &mut targets,
                };
                let elastic = evaluate(&cache, &parts, &positions, choice, cos_cone, 2, out);
                // the reference: state by state, then the targets, then the energy
                let mut want_rotations = Vec::new();
                for (pi, part) in parts.iter_mut().enumerate() {
                    let (state, r) = match choice {
                        Choice::Keep => (part.active, cache.part_rotation(pi, part, &positions)),
                        Choice::Switch(how) => {
                            let c = cache.choose_state(pi, part, &positions, how);
                            (c.state, c.rotation)
                        }
                    };
                    assert_eq!(chosen[pi], state, "part {pi}");
                    part.active = state;
                    want_rotations.push(r);
                }
                let mut want = Vec::new();
                cache.edge_targets(&parts, &want_rotations, cos_cone, &mut want);
                assert!(
                    rotations
                        .iter()
                        .zip(&want_rotations)
                        .all(|(a, b)| same(*a, *b))
                );
                assert_eq!(targets.len(), want.len());
                assert!(targets.iter().zip(&want).all(|(a, b)| same(*a, *b)));
                let energy = cache.elastic(&want, &positions).unwrap();
                assert_eq!(elastic.to_bits(), energy.to_bits());
            }
        }
    }
}
