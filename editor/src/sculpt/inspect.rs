//! Why a part is in the state it is in, in the grammar's names, for the inspector.

use clay_dsl::compiled::PartKind;

use super::{PartReport, Sculpt};

impl Sculpt {
    /// Why `part` is in the state it is in.
    pub fn inspect(&self, part: usize) -> Option<PartReport> {
        let data = &self.assembly.data();
        let grammar = self.assembly.grammar();
        let p = data.parts.get(part)?;
        let name = |i: usize| data.instances.get(i).map_or("?", |x| x.name.as_str());
        let (piece, covers) = match p.kind {
            PartKind::Piece { instance } => {
                let piece = data
                    .instances
                    .get(instance)
                    .and_then(|x| grammar.pieces.get(x.piece))
                    .map_or("?".to_string(), |pc| pc.name.clone());
                (piece, format!("`{}`", name(instance)))
            }
            PartKind::Stretch { chain, first } => {
                let c = data.chains.get(chain)?;
                let piece = grammar
                    .stretch_rules
                    .get(c.rule)
                    .and_then(|r| grammar.pieces.get(r.piece))
                    .map_or("?".to_string(), |pc| pc.name.clone());
                let a = c.instances.get(first).copied().map_or("?", name);
                let b = c.instances.get(first + 1).copied().map_or("?", name);
                (piece, format!("`{a}` and `{b}`"))
            }
        };
        // The distances and the switch threshold are the session's (the solver's own rule).
        let why = self.session.inspect(&self.assembly, part)?;
        Some(PartReport {
            piece,
            covers,
            pinned: self.is_pinned(part),
            why,
        })
    }
}
