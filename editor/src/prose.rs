//! Sentences with names in backticks (the rule log's, the status line's, the inspector's:
//! "`wall[5]` and `wall[6]` became three bricks") as the editor shows them: each name in the
//! monospace font, the backticks gone (issue 48: labels showed markdown's backticks). The text
//! a label reads out (its accessible name) is the sentence without them.

use egui::text::LayoutJob;
use egui::{Align, Color32, FontSelection, RichText, Style};

/// `text` laid out with every `` `name` `` in the monospace font, without its backticks; a
/// backtick with no partner stays as it is. In `colour` when given.
pub fn prose(text: &str, style: &Style, colour: Option<Color32>) -> LayoutJob {
    styled(text, style, |rich| match colour {
        Some(c) => rich.color(c),
        None => rich,
    })
}

/// [`prose`] with every piece given `look` (small, weak, a colour).
pub fn styled(text: &str, style: &Style, look: impl Fn(RichText) -> RichText) -> LayoutJob {
    let mut job = LayoutJob::default();
    let pieces: Vec<&str> = text.split('`').collect();
    // An odd count of pieces: every backtick has its partner; else the last one has none.
    let paired = if pieces.len() % 2 == 1 {
        pieces.len()
    } else {
        pieces.len() - 1
    };
    let mut push = |s: &str, code: bool| {
        if s.is_empty() {
            return;
        }
        let mut rich = look(RichText::new(s));
        if code {
            // The family only: the size stays the sentence's (a small note's names are small).
            rich = rich.family(egui::FontFamily::Monospace);
        }
        rich.append_to(&mut job, style, FontSelection::Default, Align::Center);
    };
    for (k, piece) in pieces[..paired].iter().enumerate() {
        push(piece, k % 2 == 1);
    }
    if paired < pieces.len() {
        push(&format!("`{}", pieces[paired..].join("`")), false);
    }
    job
}

/// A label of [`prose`].
pub fn label(ui: &mut egui::Ui, text: &str) -> egui::Response {
    let job = prose(text, ui.style(), None);
    ui.label(job)
}

/// A one-line label of [`prose`] cut with an ellipsis where it does not fit (the status line:
/// issue 48, messages ran past the window's edge); the whole sentence shows on hover.
pub fn line_label(ui: &mut egui::Ui, text: &str) -> egui::Response {
    let job = prose(text, ui.style(), None);
    ui.add(egui::Label::new(job).truncate())
}

/// A coloured label of [`prose`].
pub fn coloured_label(ui: &mut egui::Ui, colour: Color32, text: &str) -> egui::Response {
    let job = prose(text, ui.style(), Some(colour));
    ui.label(job)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_lose_their_backticks_and_take_the_monospace_font() {
        let style = Style::default();
        let job = prose("`wall[5]` and `wall[6]` became three", &style, None);
        assert_eq!(job.text, "wall[5] and wall[6] became three");
        let mono = |k: usize| job.sections[k].format.font_id.family == egui::FontFamily::Monospace;
        assert_eq!(job.sections.len(), 4);
        assert!(mono(0) && !mono(1) && mono(2) && !mono(3));
        // A backtick without its partner is shown.
        assert_eq!(prose("a `b` c `d", &style, None).text, "a b c `d");
        assert_eq!(prose("no names", &style, None).text, "no names");
    }
}
