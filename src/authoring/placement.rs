//! Docks the compiled model closes. The compiler places one instance of each connected group
//! by its `at`/`rotate` and every other through a dock (the docked site's centre onto the
//! other's, its `out` turned opposite), then requires every docked pair of vertices to meet
//! within 0.1 mm (E032). A drawing can ask for docks that cannot all close (issue 37):
//!
//! - a single shared corner docks by the sites' `out` directions, which need not be how the
//!   two shapes are drawn: docking there turns one away from its place;
//! - regions equal within the tolerance are one piece, drawn in its first region's shape, so a
//!   loop of docks through near-copies need not close;
//! - positions are written to the micrometre and turns to the micro-degree, and a long loop of
//!   turned pieces (a ring of bricks) adds those up.
//!
//! So a dock that would turn or move an instance away from where it is drawn is not made
//! ([`Design::turns_away`]), and the written model is placed here exactly as the compiler
//! places it ([`Design::fit_docks`]): a dock whose vertices would not meet is left out, with a
//! note, and the instances it joined are placed by the other docks or by their own `at`.

use std::collections::{HashMap, HashSet, VecDeque};

use glam::DVec2;

use super::pieces::{Design, round_point, round6};

/// Docked vertices must meet within this after placement (metres): a quarter of the
/// compiler's tolerance (0.1 mm), so that reading the written numbers back cannot tip a dock
/// over it.
const MEET: f64 = 2.5e-5;

/// How the model block is written: the chains, each instance's chain and place in it, and the
/// instance of each connected group that is placed by `at`/`rotate`.
pub(crate) struct Layout {
    pub chains: Vec<Vec<usize>>,
    pub chain_of: HashMap<usize, (usize, usize)>,
    pub anchored: HashSet<usize>,
}

/// One side of a dock: `(instance, site)`.
type Side = (usize, usize);

/// One dock as the compiler reads it: `(instance, site)` on each side, and its index in
/// [`Design::docks`].
struct Read {
    a: Side,
    b: Side,
    dock: usize,
}

/// Rotation as the compiler does it: cosines and sines within 1e-12 of a whole number are
/// snapped to it, so that quarter turns are exact.
fn rotate(v: DVec2, angle: f64) -> DVec2 {
    let snap = |x: f64| {
        let r = x.round();
        if (x - r).abs() < 1e-12 { r } else { x }
    };
    let (sin, cos) = angle.sin_cos();
    DVec2::new(snap(cos), snap(sin)).rotate(v)
}

impl Design {
    /// The layout [`Design::to_syntax`] writes.
    pub(crate) fn layout(&self) -> Layout {
        let chains = self.chains();
        let mut chain_of = HashMap::new();
        for (c, run) in chains.iter().enumerate() {
            for (k, &i) in run.iter().enumerate() {
                chain_of.insert(i, (c, k));
            }
        }
        // One instance per connected group is placed with `at`: a chain's first if the group
        // has a chain, else its first instance.
        let n = self.instances.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for d in &self.docks {
            let (a, b) = (find(&mut parent, d.a.0), find(&mut parent, d.b.0));
            parent[a.max(b)] = a.min(b);
        }
        let mut placed_root: HashMap<usize, usize> = HashMap::new();
        for run in &chains {
            let r = find(&mut parent, run[0]);
            placed_root.entry(r).or_insert(run[0]);
        }
        for i in 0..n {
            let r = find(&mut parent, i);
            placed_root.entry(r).or_insert(i);
        }
        Layout {
            chains,
            chain_of,
            anchored: placed_root.values().copied().collect(),
        }
    }

    /// Whether dock `d` is one a chain implies (element k's `to` site with element k+1's
    /// `from` site), so it is not written.
    pub(crate) fn implied_by_chain(&self, layout: &Layout, d: usize) -> bool {
        let d = &self.docks[d];
        let link = |x: (usize, usize), y: (usize, usize)| match (
            layout.chain_of.get(&x.0),
            layout.chain_of.get(&y.0),
        ) {
            (Some(&(c1, k1)), Some(&(c2, k2))) if c1 == c2 && k2 == k1 + 1 => {
                let piece = &self.pieces[self.instances[x.0].piece];
                piece
                    .stretch
                    .is_some_and(|[from, to]| x.1 == to && y.1 == from)
            }
            _ => false,
        };
        link(d.a, d.b) || link(d.b, d.a)
    }

    /// The `rotate` (degrees, as written: to the micro-degree, in (-180, 180]) and `at` of an
    /// instance placed by them.
    pub(crate) fn written_motion(&self, i: usize) -> (f64, DVec2) {
        let inst = &self.instances[i];
        let mut deg = round6(inst.angle.to_degrees());
        if deg <= -180.0 {
            deg += 360.0;
        }
        (deg, round_point(inst.at))
    }

    /// Where docking `(a, sa)`'s site with `(b, sb)`'s puts `b`, given `a`'s motion.
    fn dock_motion(
        &self,
        (a, sa): (usize, usize),
        (b, sb): (usize, usize),
        motion: (f64, DVec2),
    ) -> (f64, DVec2) {
        let (pa, pb) = (
            &self.pieces[self.instances[a].piece],
            &self.pieces[self.instances[b].piece],
        );
        let centre = |pos: &[DVec2], vs: &[usize]| {
            vs.iter().map(|&v| pos[v]).sum::<DVec2>() / vs.len().max(1) as f64
        };
        let (site_a, site_b) = (&pa.sites[sa], &pb.sites[sb]);
        let centre_a = rotate(centre(&pa.positions, &site_a.vertices), motion.0) + motion.1;
        let out_a = rotate(site_a.out, motion.0);
        let angle = (-out_a).to_angle() - site_b.out.to_angle();
        let centre_b = centre(&pb.positions, &site_b.vertices);
        (angle, centre_a - rotate(centre_b, angle))
    }

    /// How far apart the vertices of a stretchable piece's `to` site and the `from` site of a
    /// copy docked to it are, as the compiler places the copy to check a stretch rule (E032).
    pub(crate) fn self_dock_gap(&self, piece: usize, from: usize, to: usize) -> f64 {
        let p = &self.pieces[piece];
        let (sf, st) = (&p.sites[from], &p.sites[to]);
        let n = sf.vertices.len();
        if st.vertices.len() != n {
            return f64::INFINITY;
        }
        let centre = st.vertices.iter().map(|&v| p.positions[v]).sum::<DVec2>() / n.max(1) as f64;
        let angle = (-st.out).to_angle() - sf.out.to_angle();
        let centre_f = sf.vertices.iter().map(|&v| p.positions[v]).sum::<DVec2>() / n.max(1) as f64;
        let shift = centre - rotate(centre_f, angle);
        (0..n)
            .map(|i| {
                let (a, b) = (st.vertices[n - 1 - i], sf.vertices[i]);
                p.positions[a].distance(rotate(p.positions[b], angle) + shift)
            })
            .fold(0.0, f64::max)
    }

    /// Whether a stretchable piece's copies dock end to end from `from` to `to`.
    pub(crate) fn self_docks(&self, piece: usize, from: usize, to: usize) -> bool {
        self.self_dock_gap(piece, from, to) <= MEET
    }

    /// Whether docking `a`'s site with `b`'s would put `b` away from where it is drawn (by
    /// more than `tol` and a little at any of its vertices), with `a` where it is drawn; as in
    /// the other direction. A single shared corner of two pieces drawn at other angles than
    /// their sites' `out` directions say is the usual case.
    pub(crate) fn turns_away(&self, a: (usize, usize), b: (usize, usize), tol: f64) -> bool {
        let drawn = |i: usize| (self.instances[i].angle, self.instances[i].at);
        let off = |x: (usize, usize), y: (usize, usize)| {
            let (angle, shift) = self.dock_motion(x, y, drawn(x.0));
            let (da, dat) = drawn(y.0);
            self.pieces[self.instances[y.0].piece]
                .positions
                .iter()
                .map(|&p| (rotate(p, angle) + shift).distance(rotate(p, da) + dat))
                .fold(0.0, f64::max)
        };
        let limit = 4.0 * tol + 1e-6;
        !(off(a, b) <= limit && off(b, a) <= limit)
    }

    /// The docks in the order the compiler reads them: a chain's own docks where the chain is
    /// declared, then the written `dock` lines.
    fn read_docks(&self, layout: &Layout) -> Vec<Read> {
        let mut index: HashMap<(Side, Side), usize> = HashMap::new();
        for (k, d) in self.docks.iter().enumerate() {
            index.insert((d.a, d.b), k);
            index.insert((d.b, d.a), k);
        }
        let mut read = Vec::new();
        let mut written_chains = HashSet::new();
        for i in 0..self.instances.len() {
            let Some(&(c, 0)) = layout.chain_of.get(&i) else {
                continue;
            };
            if !written_chains.insert(c) {
                continue;
            }
            let run = &layout.chains[c];
            let Some([from, to]) = self.pieces[self.instances[run[0]].piece].stretch else {
                continue;
            };
            for w in run.windows(2) {
                let (a, b) = ((w[0], to), (w[1], from));
                if let Some(&dock) = index.get(&(a, b)) {
                    read.push(Read { a, b, dock });
                }
            }
        }
        for (k, d) in self.docks.iter().enumerate() {
            if !self.implied_by_chain(layout, k) {
                read.push(Read {
                    a: d.a,
                    b: d.b,
                    dock: k,
                });
            }
        }
        read
    }

    /// Places the written model as the compiler does and returns the docks whose vertices do
    /// not meet, each with how far apart they are.
    fn unmet_docks(&self) -> Vec<(usize, f64)> {
        let layout = self.layout();
        let n = self.instances.len();
        // The compiler's instance order: chains expanded where they are declared.
        let mut order = Vec::with_capacity(n);
        for i in 0..n {
            match layout.chain_of.get(&i) {
                Some(&(c, 0)) => order.extend(layout.chains[c].iter().copied()),
                Some(_) => {}
                None => order.push(i),
            }
        }
        let read = self.read_docks(&layout);
        let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, r) in read.iter().enumerate() {
            adjacent[r.a.0].push(k);
            adjacent[r.b.0].push(k);
        }
        let mut motion: Vec<Option<(f64, DVec2)>> = vec![None; n];
        let mut queue = VecDeque::new();
        for &i in &order {
            if layout.anchored.contains(&i) {
                let (deg, at) = self.written_motion(i);
                motion[i] = Some((deg.to_radians(), at));
                queue.push_back(i);
            }
        }
        while let Some(i) = queue.pop_front() {
            let Some(m) = motion[i] else { continue };
            for &k in &adjacent[i] {
                let r = &read[k];
                let (mine, other) = if r.a.0 == i { (r.a, r.b) } else { (r.b, r.a) };
                if motion[other.0].is_none() {
                    motion[other.0] = Some(self.dock_motion(mine, other, m));
                    queue.push_back(other.0);
                }
            }
        }
        let world = |(i, s): (usize, usize), k: usize| {
            let piece = &self.pieces[self.instances[i].piece];
            let (angle, shift) = motion[i].unwrap_or((0.0, DVec2::ZERO));
            rotate(piece.positions[piece.sites[s].vertices[k]], angle) + shift
        };
        let mut unmet = Vec::new();
        for r in &read {
            let count = |(i, s): (usize, usize)| {
                self.pieces[self.instances[i].piece].sites[s].vertices.len()
            };
            let m = count(r.a);
            if count(r.b) != m {
                continue;
            }
            let gap = (0..m)
                .map(|k| world(r.a, k).distance(world(r.b, m - 1 - k)))
                .fold(0.0, f64::max);
            if gap > MEET {
                unmet.push((r.dock, gap));
            }
        }
        unmet
    }

    /// Leaves out every dock whose vertices would not meet in the compiled model (E032), with
    /// a note for each, until all that are left meet. A dock left out can change how others
    /// are placed (and which instances form a chain), so the model is placed again each time.
    pub fn fit_docks(&mut self) {
        loop {
            let unmet = self.unmet_docks();
            if unmet.is_empty() {
                return;
            }
            let mut gone = vec![false; self.docks.len()];
            for (d, gap) in unmet {
                let dock = self.docks[d];
                let name = |(i, _): (usize, usize)| self.instances[i].name.clone();
                self.notes.push(format!(
                    "`{}` and `{}` are left undocked: placed through the other docks, their docked vertices would be {} m apart (shapes equal only within the tolerance, or a loop of turned pieces)",
                    name(dock.a),
                    name(dock.b),
                    round6(gap)
                ));
                gone[d] = true;
            }
            let mut keep = gone.iter().map(|g| !g);
            self.docks.retain(|_| keep.next().unwrap_or(true));
        }
    }
}
