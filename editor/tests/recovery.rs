//! Crash recovery (issue 37): an editor killed mid-sculpt leaves its work in the recovery file,
//! and the next editor restores it; a save or a clean exit leaves nothing behind.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command as Process, Stdio};
use std::time::Duration;

use clay_editor::EditorApp;
use clay_editor::action::Action;
use clay_editor::recovery::WRITE_EVERY;
use clay_editor::sculpt::Command;
use clay_editor::session;
use glam::DVec2;

/// Set in the child process this test starts and kills.
const CHILD: &str = "CLAY_RECOVERY_TEST_CHILD";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-recovery-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// UI frames of the app's logic (solver, recovery) without a window.
fn frames(app: &mut EditorApp, n: usize) {
    let ctx = egui::Context::default();
    for _ in 0..n {
        app.logic(&ctx);
    }
}

/// Drags the castle's last part down by a metre over 20 frames and lets go.
fn sculpt(app: &mut EditorApp) {
    frames(app, 40);
    let part = app.sculpt.data().parts.len() - 1;
    let at = app.sculpt.assembly().part_centroid(part);
    app.sculpt.apply(Command::Grab { part, at });
    for k in 1..=20 {
        app.sculpt.apply(Command::MoveGrab {
            translation: DVec2::new(0.0, -0.05 * f64::from(k)),
            angle: 0.0,
        });
        frames(app, 1);
    }
    app.sculpt.apply(Command::Release);
    frames(app, 40);
}

/// The child: sculpts with recovery on, goes on a few seconds (the file is kept up to date at
/// most every `WRITE_EVERY` while nothing is undone), writes what it has to `expected`, says
/// so, and waits to be killed.
fn child(recovery: &Path, expected: &Path) -> ! {
    let mut app = EditorApp::bundled();
    app.use_recovery(recovery.to_path_buf());
    sculpt(&mut app);
    assert!(app.sculpt.dirty());
    std::thread::sleep(WRITE_EVERY + Duration::from_millis(100));
    frames(&mut app, 1);
    session::write(expected, &app.session()).unwrap();
    println!("sculpted");
    loop {
        std::thread::sleep(Duration::from_secs(1));
    }
}

/// This test binary running only `test`, as the child editor the test kills.
fn this_test_as_a_child(test: &str) -> Process {
    let mut p = Process::new(std::env::current_exe().unwrap());
    p.args([test, "--exact", "--nocapture"]);
    p
}

/// Starts the child editor, waits until it says it sculpted, then kills it (no clean exit).
fn kill_once_sculpted(mut child: Process) {
    let mut editor = child.stdout(Stdio::piped()).spawn().unwrap();
    let out = BufReader::new(editor.stdout.take().unwrap());
    let said = out
        .lines()
        .map_while(Result::ok)
        .any(|l| l.contains("sculpted"));
    editor.kill().unwrap();
    editor.wait().unwrap();
    assert!(said, "the child editor sculpted");
}

#[test]
fn a_killed_editor_is_restored_by_the_next() {
    if let Some(dir) = std::env::var_os(CHILD) {
        let dir = PathBuf::from(dir);
        child(
            &dir.join("recovery.clay-session"),
            &dir.join("expected.json"),
        );
    }
    let dir = scratch("killed");
    let recovery = dir.join("recovery.clay-session");
    let mut editor = this_test_as_a_child("a_killed_editor_is_restored_by_the_next");
    editor.env(CHILD, &dir);
    kill_once_sculpted(editor);

    let expected = session::read(&dir.join("expected.json")).unwrap();
    let left = std::fs::read(&recovery).expect("the killed editor left its work");
    assert_eq!(
        session::read(&recovery).unwrap(),
        expected,
        "the recovery file holds the sculpt as it was"
    );
    let mut next = EditorApp::bundled();
    next.use_recovery(recovery.clone());
    let offer = next.recovery().and_then(|r| r.offer()).cloned();
    assert!(offer.is_some(), "the next editor finds the work");
    frames(&mut next, 3);
    assert_eq!(
        std::fs::read(&recovery).unwrap(),
        left,
        "nothing is written over the work on offer"
    );
    next.perform(Action::RestoreRecovery);
    assert!(
        next.sculpt.data() == &expected.assembly,
        "the sculpt is restored exactly"
    );
    assert_eq!(next.sculpt.pins(), expected.pins);
    assert!(next.sculpt.dirty(), "restored work is unsaved work");
}

/// Set in the first-time user's child editor: its empty home.
const FIRST: &str = "CLAY_RECOVERY_TEST_FIRST_TIME";

/// A first-time user (issue 47): an empty home, no state folder, no setting. The editor
/// finds its recovery file where `recovery::default_path` says, makes the folders it needs
/// (for this user only), keeps the work there, and after a kill the next editor offers it.
#[test]
fn a_first_time_user_with_an_empty_home_is_restored() {
    if let Some(home) = std::env::var_os(FIRST) {
        let path = clay_editor::recovery::default_path().expect("a recovery file under HOME");
        assert!(
            path.starts_with(&home),
            "{} is not under the home",
            path.display()
        );
        child(&path, &PathBuf::from(home).join("expected.json"));
    }
    let home = scratch("first-time");
    let mut editor = this_test_as_a_child("a_first_time_user_with_an_empty_home_is_restored");
    editor
        .env(FIRST, &home)
        .env("HOME", &home)
        .env_remove("XDG_STATE_HOME")
        .env_remove("CLAY_RECOVERY_FILE");
    kill_once_sculpted(editor);
    let folder = home.join(".local/state/clay");
    let recovery = folder.join("recovery.clay-session");
    let expected = session::read(&home.join("expected.json")).unwrap();
    assert_eq!(
        session::read(&recovery).expect("the killed editor left its work in the new folder"),
        expected
    );
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&folder).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700, "the state folder is this user's only");
    }
    let mut next = EditorApp::bundled();
    next.use_recovery(recovery);
    assert!(next.recovery().and_then(|r| r.offer()).is_some());
    next.perform(Action::RestoreRecovery);
    assert!(next.sculpt.data() == &expected.assembly);
}

/// Where the recovery file cannot be written (its folder is a file), the editor says so for
/// as long as it cannot, not once in a status line that the next message replaces.
#[test]
fn a_recovery_file_that_cannot_be_written_is_said_until_it_can() {
    let dir = scratch("unwritable");
    std::fs::write(dir.join("blocked"), b"a file where the folder would be").unwrap();
    let mut app = EditorApp::bundled();
    app.use_recovery(dir.join("blocked").join("recovery.clay-session"));
    sculpt(&mut app);
    let why = app.recovery().and_then(|r| r.failure()).map(str::to_string);
    assert!(
        why.as_deref()
            .is_some_and(|w| w.contains("crash recovery is off") && w.contains("blocked")),
        "{why:?}"
    );
    sculpt(&mut app);
    assert!(
        app.recovery().and_then(|r| r.failure()).is_some(),
        "still said after more work"
    );
    std::fs::remove_file(dir.join("blocked")).unwrap();
    sculpt(&mut app);
    assert!(
        app.recovery().and_then(|r| r.failure()).is_none(),
        "kept again: nothing to say"
    );
    assert!(dir.join("blocked").join("recovery.clay-session").exists());
}

#[test]
fn the_recovery_file_follows_the_sculpt_and_leaves_on_save_and_quit() {
    let dir = scratch("follows");
    let recovery = dir.join("recovery.clay-session");
    let mut app = EditorApp::bundled();
    app.use_recovery(recovery.clone());
    assert!(app.recovery().unwrap().offer().is_none());
    frames(&mut app, 40);
    assert!(!recovery.exists(), "nothing unsaved, nothing kept");
    sculpt(&mut app);
    let kept = session::read(&recovery).expect("the unsaved sculpt is kept");
    // the drag was one undo step; the file has the model after it settled or a few
    // seconds before (it is written after each undo step and then every few seconds)
    assert_eq!(kept.pins, app.sculpt.pins());
    app.save_session(&dir.join("saved.json")).unwrap();
    frames(&mut app, 1);
    assert!(!recovery.exists(), "a save leaves nothing to recover");

    // Two gestures, one undone: still unsaved, and the undo step is kept at once.
    sculpt(&mut app);
    sculpt(&mut app);
    assert!(recovery.exists());
    app.sculpt.apply(Command::Undo);
    frames(&mut app, 1);
    let undone = session::read(&recovery).unwrap();
    assert!(
        &undone.assembly == app.sculpt.data(),
        "an undo step is kept at once"
    );
    // Both undone: the model is the saved one, nothing is left to recover.
    app.sculpt.apply(Command::Undo);
    frames(&mut app, 1);
    assert!(!app.sculpt.dirty());
    assert!(
        !recovery.exists(),
        "back at the saved model, nothing to recover"
    );
    app.sculpt.apply(Command::Redo);
    frames(&mut app, 1);
    assert!(recovery.exists());
    app.perform(Action::Quit);
    // the unsaved prompt: discard, and the clean exit removes the file
    assert!(app.confirming());
    app.sculpt.mark_saved();
    frames(&mut app, 1);
    assert!(
        !recovery.exists(),
        "discarded work leaves nothing to recover"
    );
}
