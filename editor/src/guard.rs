//! The editor's guard against its own bugs: a panic in compiling, solving or drawing is
//! caught at the call and becomes an error message, so the editor, the last good model and
//! the user's unsaved sculpt survive it (issue 37).

use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `f`; a panic becomes `Err` with the panic's message. The caller decides what stays
/// (the state `f` touched may be half updated: `AssertUnwindSafe` is the caller's promise to
/// throw that away or check it).
pub fn catching<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|panic| message(panic.as_ref()))
}

/// The message a panic carried (`panic!` with a string or a format), or a stand-in.
fn message(panic: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = panic.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = panic.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_its_message_and_a_value_passes() {
        assert_eq!(catching(|| 7), Ok(7));
        assert_eq!(
            catching(|| -> u8 { panic!("index {} out of range", 9) }),
            Err("index 9 out of range".to_string())
        );
        assert_eq!(
            catching(|| -> u8 { panic!("plain") }),
            Err("plain".to_string())
        );
        let odd = catching(|| -> u8 { std::panic::panic_any(3_i32) });
        assert_eq!(odd, Err("a panic without a message".to_string()));
    }
}
