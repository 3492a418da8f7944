//! "Did you mean": the known name closest to a misspelt one, shared by the parser (keywords)
//! and the compiler (pieces, sites, vertices, site types).

/// The closest candidate by edit distance, if it is close enough to be a likely typo. The
/// distance is optimal string alignment (Levenshtein plus swapping two neighbours as one edit),
/// so `stpe` finds `step` and `sdie` finds `side`.
pub(crate) fn closest<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1) + usize::from(name.len() > 5);
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| (strsim::osa_distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::closest;

    #[test]
    fn swapped_letters_are_one_typo() {
        assert_eq!(closest("stpe", ["step", "stop_x", "site"]), Some("step"));
        assert_eq!(closest("sdie", ["side", "slide"]), Some("side"));
        assert_eq!(closest("brik", ["brick", "tower"]), Some("brick"));
    }

    #[test]
    fn far_names_and_the_name_itself_are_no_suggestion() {
        assert_eq!(closest("tower", ["brick", "wall"]), None);
        assert_eq!(closest("wall", ["wall"]), None);
    }
}
