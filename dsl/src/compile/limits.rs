//! The compiler's limits and tolerances: what a grammar may declare and how close two places
//! must be to count as one. Every pass reads them; they import nothing.

/// Largest absolute coordinate accepted, in metres; keeps every later computation finite.
pub const MAX_COORDINATE: f64 = 1e9;
/// Most known names the "did you mean" search compares misspelt names against in one
/// compilation (about 0.2 s): the first few hundred unknown names among thousands get a
/// suggestion, and a file of thousands of misspellings is still checked in linear time.
pub const MAX_SUGGESTION_WORK: usize = 1_000_000;
/// Largest `extrude` height or base, in metres (the tallest building is under 1 km).
pub const MAX_HEIGHT: f64 = 10_000.0;
/// Most instances a model may grow to while it is sculpted (the stretch rule inserts no more).
pub const MAX_INSTANCES: usize = 1_000_000;
/// Most instances a grammar's model may declare (E014, chains included): what `clayc check`,
/// `run` and `build` handle in seconds (a 100,000-element chain: check 0.3 s, build 2.1 s and
/// 300 MB of JSON, a solver frame 0.2 s). A million took 3.7 s to check, 36 s and 4.5 GB to
/// build.
pub const MAX_MODEL_INSTANCES: usize = 100_000;
/// Distance below which two positions count as the same place.
pub const COINCIDENT_EPS: f64 = 1e-9;
/// Tolerance for docked vertices meeting after placement, in metres.
pub const DOCK_TOLERANCE: f64 = 1e-4;
