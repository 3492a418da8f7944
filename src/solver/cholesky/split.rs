//! Two independent halves of a factorisation, for two cores: two sets of whole subtrees of
//! the supernodal elimination tree under a top of separators, so neither half writes to the
//! other and both write only to their own subtrees and to the top, which is factorised after
//! both.
//!
//! The split is chosen from the symbolic structure alone, never from the thread count, and
//! the factorisation ([`super::numeric`]) runs it the same way on one thread or two: the
//! second half's updates to the shared ancestors go to a buffer that is added after both, so
//! the factor is the same to the bit whatever the thread count.

use std::ops::Range;

use super::layout::SupernodalLayout;

/// Below this many multiply-adds a factorisation is not split (a thread's start-up, some
/// tens of microseconds, would cost more than half the work saves).
const MIN_WORK: f64 = 400_000.0;

/// The lighter half must have at least this share of the heavier's work.
const MIN_BALANCE: f64 = 0.8;

/// The halves must hold at least this share of the work (the rest, the top, is one thread's).
const MIN_SHARE: f64 = 0.3;

/// The supernodes in three groups: two halves, each a list of whole subtrees (runs of
/// supernodes, in order), and the top: every supernode above them (each a run, in order).
/// No subtree of one half has an ancestor in the other; every ancestor outside a subtree is in
/// the top.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Split {
    pub halves: [Vec<Range<usize>>; 2],
    pub top: Vec<Range<usize>>,
}

/// The multiply-adds of factorising supernode `s`: `w^3 / 3` (its diagonal block), `b w^2`
/// (its rows below) and `b^2 w / 2` (its updates), for `w` columns and `b` rows below.
pub(super) fn work(layout: &SupernodalLayout, s: usize) -> f64 {
    let (_, size, below, _) = layout.supernode(s);
    let (w, b) = (size as f64, below.len() as f64);
    w * w * w / 3.0 + b * w * w + b * b * w / 2.0
}

/// The split of `layout` (`column_supernode[c]`: the supernode of permuted column `c`), or
/// `None` when the tree has no two balanced halves, the work is small, or the supernodes are
/// not in an order where every subtree is a run ending at its root (a postorder).
///
/// From the top (the roots), the heaviest subtree under the top joins the top (its children
/// come under it) until the subtrees under the top divide into two halves (largest first into
/// the lighter half) within [`MIN_BALANCE`] of each other: the top is the separators, the
/// halves the regions they separate.
pub(super) fn find(layout: &SupernodalLayout, column_supernode: &[u32]) -> Option<Split> {
    let count = layout.val_start.len();
    let mut parent = vec![None; count];
    for (s, p) in parent.iter_mut().enumerate() {
        let (_, _, below, _) = layout.supernode(s);
        if let Some(&row) = below.first() {
            // the elimination tree of supernodes: the parent holds the first row below
            let t = *column_supernode.get(row as usize)? as usize;
            if t <= s {
                return None;
            }
            *p = Some(t);
        }
    }
    // subtree work and extent: a subtree is a run iff it holds `s - first[s] + 1` supernodes
    let mut sub: Vec<f64> = (0..count).map(|s| work(layout, s)).collect();
    let mut first: Vec<usize> = (0..count).collect();
    let mut size = vec![1usize; count];
    let mut children = vec![Vec::new(); count];
    let mut under = Vec::new();
    for s in 0..count {
        if s + 1 - first[s] != size[s] {
            return None;
        }
        match parent[s] {
            Some(t) => {
                sub[t] += sub[s];
                first[t] = first[t].min(first[s]);
                size[t] += size[s];
                children[t].push(s);
            }
            None => under.push(s),
        }
    }
    let total: f64 = under.iter().map(|&r| sub[r]).sum();
    if total < MIN_WORK {
        return None;
    }
    let mut in_top = vec![false; count];
    loop {
        let below: f64 = under.iter().map(|&c| sub[c]).sum();
        if below < MIN_SHARE * total {
            return None;
        }
        under.sort_by(|&x, &y| sub[y].total_cmp(&sub[x]).then(x.cmp(&y)));
        let mut halves: [(f64, Vec<usize>); 2] = Default::default();
        for &c in &under {
            let lighter = usize::from(halves[1].0 < halves[0].0);
            halves[lighter].0 += sub[c];
            halves[lighter].1.push(c);
        }
        let (light, heavy) = (halves[0].0.min(halves[1].0), halves[0].0.max(halves[1].0));
        if light >= MIN_BALANCE * heavy {
            let runs = |roots: &mut Vec<usize>| {
                roots.sort_unstable();
                roots.iter().map(|&r| first[r]..r + 1).collect::<Vec<_>>()
            };
            let [(_, mut a), (_, mut b)] = halves;
            let top = (0..count).filter(|&s| in_top[s]).fold(
                Vec::<Range<usize>>::new(),
                |mut runs, s| {
                    match runs.last_mut() {
                        Some(run) if run.end == s => run.end = s + 1,
                        _ => runs.push(s..s + 1),
                    }
                    runs
                },
            );
            return Some(Split {
                halves: [runs(&mut a), runs(&mut b)],
                top,
            });
        }
        // the heaviest (first after the sort) joins the top
        let heaviest = under.remove(0);
        in_top[heaviest] = true;
        under.append(&mut children[heaviest]);
    }
}
