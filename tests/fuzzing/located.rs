//! The diagnostic property every fuzz target that compiles a grammar checks
//! (`tests/fuzz.rs`, `tests/fuzz_assets.rs`): each diagnostic located on its file.

/// Every diagnostic lies on char boundaries of its file, has a 1-based line and column, and
/// the whole list renders.
pub fn located(diagnostics: &clay_dsl::Diagnostics, text: &str, path: &str) -> Result<(), String> {
    for d in diagnostics.iter() {
        for span in std::iter::once(&d.primary)
            .chain(&d.secondary)
            .map(|l| l.span)
        {
            let at = diagnostics.sources.locate(text, path, span);
            let ok = at.start <= at.end
                && at.end <= at.text.len()
                && at.text.is_char_boundary(at.start)
                && at.text.is_char_boundary(at.end);
            if !ok {
                return Err(format!(
                    "{} {:?}: span {:?} off its file",
                    d.code, d.message, span
                ));
            }
            let (line, col) = clay_dsl::line_col(at.text, at.start);
            if line == 0 || col == 0 {
                return Err(format!("{} at {line}:{col}", d.code));
            }
        }
    }
    let _ = clay_dsl::render(diagnostics, text, path, false);
    Ok(())
}
