//! The user's gestures on the model, as the session defines them: the grab (pressed, moved,
//! released, re-pinning a pinned part where it is dropped), pins, and cuts. Each is applied
//! here and only here, and recorded here as the script step that does the same
//! ([`Sculpt::gesture_script`]).

use std::time::Duration;

use clay::{Grab, HandleKind, Script};
use glam::DVec2;

use super::Sculpt;
use super::frame::solve_frame;
use crate::session::Pin;

impl Sculpt {
    /// The pins, with where they hold their vertices.
    pub fn pins(&self) -> Vec<Pin> {
        let mut pins: Vec<Pin> = self
            .assembly
            .handles()
            .iter()
            .filter(|h| h.kind() == HandleKind::Pin)
            .map(|h| Pin {
                vertices: h.vertices().to_vec(),
                at: (0..h.vertices().len()).map(|k| h.target(k)).collect(),
            })
            .collect();
        if let Some(g) = &self.grab
            && g.was_pinned()
            && let Some(h) = self.assembly.handle(g.handle())
        {
            pins.push(Pin {
                vertices: h.vertices().to_vec(),
                at: (0..h.vertices().len()).map(|k| h.target(k)).collect(),
            });
        }
        pins
    }

    /// The vertices the grab holds, and the pinned ones (the handles-and-pins overlay).
    pub fn held_vertices(&self) -> (Vec<usize>, Vec<usize>) {
        let mut grabbed = Vec::new();
        let mut pinned = Vec::new();
        for h in self.assembly.handles() {
            match h.kind() {
                HandleKind::Grab => grabbed.extend(h.vertices().iter().copied()),
                HandleKind::Pin => pinned.extend(h.vertices().iter().copied()),
            }
        }
        (grabbed, pinned)
    }

    /// Whether an instance of `part` is held by a pin.
    pub fn is_pinned(&self, part: usize) -> bool {
        let asm = &self.assembly;
        (asm.data().part_instances(part).into_iter()).any(|i| clay::pin_of(asm, i).is_some())
            || (self.grab).is_some_and(|g| g.part() == Some(part) && g.was_pinned())
    }

    pub(super) fn grab(&mut self, part: usize, at: DVec2) {
        self.release();
        let Some(instance) = self.assembly.instance_of_part_at(part, at) else {
            return;
        };
        let centre = self.assembly.instance_centroid(instance);
        self.checkpoint();
        self.grab = Grab::at(&mut self.assembly, part, at);
        if self.grab.is_some()
            && let Some(centre) = centre
        {
            self.record.grab(centre);
        }
    }

    /// Moves the grab's target: its start pose moved by `translation` and turned by `angle`.
    pub(super) fn move_grab(&mut self, translation: DVec2, angle: f64) {
        if let Some(g) = self.grab
            && g.move_to(&mut self.assembly, translation, angle)
        {
            self.record.moved(translation, angle);
            self.unsettled = true;
        }
    }

    /// Pins the instance of `part` nearest `at`, or unpins it if pinned.
    pub(super) fn toggle_pin(&mut self, part: usize, at: DVec2) {
        let Some(instance) = self.assembly.instance_of_part_at(part, at) else {
            return;
        };
        self.release();
        self.checkpoint();
        let name = self.assembly.data().instances[instance].name.clone();
        let centre = self.assembly.instance_centroid(instance);
        let pinned = clay::toggle_pin(&mut self.assembly, instance);
        if let Some(centre) = centre {
            self.record.pin(centre, pinned);
        }
        if pinned {
            self.note(format!("pinned {name}"), None);
        } else {
            self.note(format!("unpinned {name}"), None);
        }
        self.unsettled = true;
    }

    /// Ends the gesture: a pinned part stays pinned where it was dropped.
    pub(super) fn release(&mut self) {
        if self.grab.is_none() {
            return;
        }
        if self.moved_while_solving {
            // The last moves came while a background frame ran: solve once more here, so the
            // part is dropped where the pointer let go, not a frame behind it.
            self.moved_while_solving = false;
            self.record.frame_starts();
            let outcome = solve_frame(&mut self.assembly, &mut self.session, Duration::MAX);
            self.integrate(outcome);
        }
        if let Some(g) = self.grab.take() {
            g.release(&mut self.assembly);
            self.record.release();
        }
        self.unsettled = true;
    }

    pub(super) fn cut(&mut self, point: DVec2) {
        self.checkpoint();
        match self.session.cut(&mut self.assembly, point) {
            Ok(e) => {
                self.record.cut(point);
                self.session.clear_rule_log();
                self.revision += 1;
                self.note(
                    format!("{} at ({:.1}, {:.1})", e.detail, e.at.x, e.at.y),
                    Some(e.at),
                );
                self.unsettled = true;
            }
            Err(message) => {
                // Nothing changed: the gesture leaves no undo step.
                self.forget_checkpoint();
                self.note(format!("cut failed: {message}"), Some(point));
            }
        }
    }

    /// The gestures since the grammar's initial model (opened, reset, or rebuilt by a
    /// reload) as a script: replayed on that model by `clayc run` or
    /// [`clay::replay`], it makes this sculpt. Gestures undone are not in it. `Err`
    /// says why there is none (a sculpt opened from a session).
    pub fn gesture_script(&self) -> Result<Script, String> {
        let mut script = self.record.script()?;
        // The parameters the model was made with: the script refuses to replay on others.
        script.params = (self.assembly.grammar().params.iter())
            .map(|p| (p.name.clone(), p.value.clone()))
            .collect();
        Ok(script)
    }

    /// After a rule renumbered the parts, the grabbed part is the one the handle still holds.
    pub(super) fn follow_grab(&mut self) {
        if let Some(g) = &mut self.grab
            && !g.follow(&self.assembly)
        {
            self.grab = None;
        }
    }
}
