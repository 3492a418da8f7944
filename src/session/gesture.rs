//! The sculpting gestures, one definition each: grab a part where the pointer is (or an
//! instance a script names), move and turn the grab, let go (a part that was pinned is pinned
//! again where it was dropped), pin and unpin. Scripts ([`super::Session::step`]), the editor
//! and the bindings call these; none writes a handle itself.
//!
//! A [`Grab`] is a value apart from the [`super::Session`]: the editor moves its grab on the
//! model it shows while a copy of the model and its session solve on another thread.

use glam::DVec2;

use crate::assembly::{Assembly, HandleId, HandleKind};

/// A grab in progress: the handle moving one instance, and whether that instance was pinned
/// (the pin gives way to the grab and comes back where the instance is dropped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grab {
    handle: HandleId,
    /// The part the grab was made on (followed across rewrites by [`Grab::follow`]).
    part: Option<usize>,
    was_pinned: bool,
}

impl Grab {
    /// Grabs the instance of `part` nearest `at` (a stretch part covers two): where the
    /// pointer went down. `None` if the part does not exist or holds no instance.
    pub fn at(asm: &mut Assembly, part: usize, at: DVec2) -> Option<Self> {
        let instance = asm.instance_of_part_at(part, at)?;
        let mut grab = Self::instance(asm, instance)?;
        grab.part = Some(part);
        Some(grab)
    }

    /// Grabs `instance`, taking over its pin if it has one. `None` if it has no vertices.
    pub fn instance(asm: &mut Assembly, instance: usize) -> Option<Self> {
        asm.data().instances.get(instance)?;
        let was_pinned = match pin_of(asm, instance) {
            Some(id) => asm.release(id),
            None => false,
        };
        let Some(handle) = asm.hold_instance(instance, HandleKind::Grab) else {
            if was_pinned {
                asm.hold_instance(instance, HandleKind::Pin);
            }
            return None;
        };
        let part = asm.handle(handle).and_then(|h| h.part);
        Some(Self {
            handle,
            part,
            was_pinned,
        })
    }

    /// The grab's handle.
    pub fn handle(&self) -> HandleId {
        self.handle
    }

    /// The part the grab holds (after [`Grab::follow`], its index after the last rewrite).
    pub fn part(&self) -> Option<usize> {
        self.part
    }

    /// Whether the grabbed instance was pinned (and is pinned again when let go).
    pub fn was_pinned(&self) -> bool {
        self.was_pinned
    }

    /// Moves the grab's target: its start pose moved by `translation` and turned by `angle`
    /// radians about its centre. Returns whether anything changed; a non-finite move changes
    /// nothing.
    pub fn move_to(&self, asm: &mut Assembly, translation: DVec2, angle: f64) -> bool {
        asm.move_handle(self.handle, translation, angle)
    }

    /// Where the grab is taking its instance: the target's centre and angle.
    pub fn target(&self, asm: &Assembly) -> Option<(DVec2, f64)> {
        let h = asm.handle(self.handle)?;
        Some((h.target_centre(), h.angle))
    }

    /// Lets go: the handle goes, or becomes the pin again where the instance was dropped.
    /// Returns whether the handle was still there.
    pub fn release(self, asm: &mut Assembly) -> bool {
        match asm.handle_mut(self.handle) {
            Some(h) if self.was_pinned => {
                h.kind = HandleKind::Pin;
                true
            }
            Some(_) => asm.release(self.handle),
            None => false,
        }
    }

    /// After a rule renumbered the parts: the part holding the most of the grabbed vertices,
    /// nearest the grab (the one a pointer on the grabbed instance would be over).
    /// Returns `false` when the handle is gone (the grab is over).
    pub fn follow(&mut self, asm: &Assembly) -> bool {
        let Some(h) = asm.handle(self.handle) else {
            return false;
        };
        // The part that holds the most of the grabbed vertices, and of those the one nearest
        // the grab: a chain element lies in two pair parts, and a part wholly held need not
        // exist. Issue 48: only a part wholly held was looked for, none was found for a chain
        // element, and the index from before the rewrite pointed at a pair mid-wall.
        let held: std::collections::HashSet<usize> = h.vertices.iter().copied().collect();
        let centre = h.target_centre();
        let best = (asm.data().parts.iter().enumerate())
            .map(|(p, part)| (p, part.vertices.iter().filter(|v| held.contains(v)).count()))
            .filter(|&(_, shared)| shared > 0)
            .map(|(p, shared)| (p, shared, (asm.part_centroid(p) - centre).length()))
            .max_by(|a, b| a.1.cmp(&b.1).then(b.2.total_cmp(&a.2)));
        if let Some((p, _, _)) = best {
            self.part = Some(p);
        }
        true
    }
}

/// Pins `instance` where it is (a pinned one stays as it is). `None` if it has no vertices.
pub fn pin(asm: &mut Assembly, instance: usize) -> Option<HandleId> {
    pin_of(asm, instance).or_else(|| asm.hold_instance(instance, HandleKind::Pin))
}

/// Unpins `instance`. Returns whether it was pinned.
pub fn unpin(asm: &mut Assembly, instance: usize) -> bool {
    match pin_of(asm, instance) {
        Some(id) => asm.release(id),
        None => false,
    }
}

/// Pins `instance`, or unpins it when it is pinned. Returns whether it is pinned now.
pub fn toggle_pin(asm: &mut Assembly, instance: usize) -> bool {
    if unpin(asm, instance) {
        return false;
    }
    pin(asm, instance).is_some()
}

/// The pin holding `instance`, found by its stable id (its vertices change when rules
/// rewrite the chain around it).
pub fn pin_of(asm: &Assembly, instance: usize) -> Option<HandleId> {
    let id = asm.data().instances.get(instance)?.id;
    asm.handles()
        .iter()
        .find(|h| h.kind == HandleKind::Pin && h.held.as_ref().is_some_and(|x| x.id == id))
        .map(|h| h.id)
}

/// Pins `vertices` with their targets at `at` (one per vertex; a saved sculpt's pin): an
/// instance's vertices exactly are held as that instance, so the pin follows it through
/// rules; any other set as it is. Where `at` is not one finite point per vertex, they are
/// pinned where they are. `None` if a vertex does not exist.
pub fn pin_at(asm: &mut Assembly, vertices: Vec<usize>, at: &[DVec2]) -> Option<HandleId> {
    let instance = (asm.data().instances.iter()).position(|i| i.vertices == vertices);
    let id = match instance {
        Some(i) => asm.hold_instance(i, HandleKind::Pin),
        None => asm.hold_vertices(vertices, HandleKind::Pin),
    }?;
    if at.iter().all(|p| p.is_finite())
        && let Some(h) = asm.handle_mut(id)
    {
        h.place(at);
    }
    Some(id)
}
