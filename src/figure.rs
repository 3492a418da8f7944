//! How a number is written for people (the summary, the rule log): one home, so the same
//! energy reads the same wherever it appears.

/// A figure for people: `decimals` places below a million, three significant decimals in
/// scientific notation above (never a 300-digit number), `inf` / `NaN` as such.
pub fn figure(x: f64, decimals: usize) -> String {
    if x.is_finite() && x.abs() >= 1e6 {
        format!("{x:.3e}")
    } else {
        format!("{x:.decimals$}")
    }
}

/// Why a change judged by energy was kept, as the rule log says it: "the model rests better
/// so (energy 2.202 -> 0.000)".
pub fn rests_better(before: f64, after: f64) -> String {
    format!(
        "the model rests better so (energy {} -> {})",
        figure(before, 3),
        figure(after, 3)
    )
}

#[cfg(test)]
mod tests {
    use super::{figure, rests_better};

    #[test]
    fn large_and_odd_figures_stay_short() {
        assert_eq!(figure(1.23456, 3), "1.235");
        assert_eq!(figure(1e300, 3), "1.000e300");
        assert_eq!(figure(f64::INFINITY, 3), "inf");
        assert_eq!(
            rests_better(2.2, 0.0),
            "the model rests better so (energy 2.200 -> 0.000)"
        );
    }
}
