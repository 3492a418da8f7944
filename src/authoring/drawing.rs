//! Authoring's input and its error: a drawing of polylines in metres (y up), and why a
//! drawing could not become a grammar. Every step of authoring reads these, so they live
//! apart from `mod.rs`, which imports the steps.

use glam::DVec2;

/// One stroke of a drawing, in metres with y up.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    pub points: Vec<DVec2>,
    /// The last point joins the first.
    pub closed: bool,
    /// Fill colour as drawn (`#rrggbb`), if any.
    pub fill: Option<[u8; 3]>,
    /// The drawing's name for it (an SVG `id`), used to name pieces.
    pub name: Option<String>,
}

impl Polyline {
    /// A closed polygon without colour or name.
    pub fn polygon(points: Vec<DVec2>) -> Self {
        Self {
            points,
            closed: true,
            fill: None,
            name: None,
        }
    }
}

/// A drawing: the input of authoring.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawing {
    pub polylines: Vec<Polyline>,
}

/// Why a drawing could not become a grammar.
#[derive(Clone, Debug, PartialEq)]
pub struct AuthorError(pub String);

impl std::fmt::Display for AuthorError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for AuthorError {}
