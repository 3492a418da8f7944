//! The `clay-editor` binary's arguments and its start without a display: usage and version
//! are printed, not taken for file names; a missing display is one line and exit code 1.

use std::process::Command;

fn editor() -> Command {
    Command::new(env!("CARGO_BIN_EXE_clay-editor"))
}

#[test]
fn help_and_version_print_and_exit_zero() {
    let out = editor().arg("--help").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Usage: clay-editor [OPTIONS] [GRAMMAR]"),
        "{text}"
    );
    assert!(text.contains("--follow"), "{text}");
    assert!(text.contains("F1"), "points at the in-window help: {text}");

    let out = editor().arg("--version").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        text.trim(),
        format!("clay-editor {}", env!("CARGO_PKG_VERSION"))
    );
}

#[test]
fn an_unknown_flag_is_a_usage_error_not_a_file() {
    let out = editor().arg("--frobnicate").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unexpected argument '--frobnicate'"), "{err}");
}

#[cfg(all(unix, not(target_os = "macos")))]
#[test]
fn no_display_is_one_line_and_exit_one() {
    let out = editor()
        .arg("../grammars/wall.clay")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.starts_with("clay-editor: no display"), "{err}");
    assert!(!err.contains("WinitEventLoop"), "{err}");
}
