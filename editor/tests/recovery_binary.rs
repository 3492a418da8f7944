//! Crash recovery on the real `clay-editor` binary from an empty home (issue 47): under Xvfb,
//! with `HOME` a fresh folder and no `XDG_STATE_HOME`, `XDG_CONFIG_HOME` or
//! `CLAY_RECOVERY_FILE`, the editor opens a grammar, a real pointer drag (XTEST events, as a
//! mouse would send them) pulls a brick, the editor makes `~/.local/state/clay/` and keeps the
//! work there, and after `SIGKILL` the file is a session holding the change.
//!
//! Xvfb is required: without it the test fails (it does not pass having tested nothing);
//! `.ci/run` installs it.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use x11rb::connection::Connection;
use x11rb::protocol::xproto::{ConnectionExt as _, ImageFormat, MapState, Window};
use x11rb::protocol::xtest::ConnectionExt as _;
use x11rb::rust_connection::RustConnection;

/// The whole test's budget: the window, the drag and the write take a few seconds.
const PATIENCE: Duration = Duration::from_secs(25);

/// The brick fill of `grammars/wall.clay` (`fill #b5651d`), as the editor paints it.
const BRICK: [u8; 3] = [0xb5, 0x65, 0x1d];

/// A child process killed (SIGKILL) and reaped when dropped, so that a failing assertion
/// leaves no editor or X server behind.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// An empty folder for this run: the user's home.
fn empty_home() -> PathBuf {
    let home = std::env::temp_dir().join(format!("clay-recovery-binary-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&home);
    std::fs::create_dir_all(&home).unwrap();
    home
}

/// Starts Xvfb on a display it chooses (`-displayfd`: it writes the number once it accepts
/// connections) and returns it with the display's name.
fn xvfb() -> (Killed, String) {
    let started = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "1280x800x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn();
    let mut server = match started {
        Ok(child) => Killed(child),
        Err(e) => panic!(
            "cannot start Xvfb ({e}): this test runs the real editor under it; install it \
             (apt-get install xvfb)"
        ),
    };
    let mut line = String::new();
    BufReader::new(server.0.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let number: u32 = line
        .trim()
        .parse()
        .unwrap_or_else(|_| panic!("Xvfb gave no display number: {line:?}"));
    (server, format!(":{number}"))
}

/// Waits for the editor's top-level window to be mapped; its bounds on the screen.
fn editor_window(
    x: &RustConnection,
    root: Window,
    editor: &mut Killed,
    stderr: impl Fn() -> String,
) -> (i16, i16, u16, u16) {
    let start = Instant::now();
    loop {
        if let Some(status) = editor.0.try_wait().unwrap() {
            panic!(
                "the editor exited before its window showed ({status}); its stderr:\n{}",
                stderr()
            );
        }
        for w in x.query_tree(root).unwrap().reply().unwrap().children {
            let mapped = x
                .get_window_attributes(w)
                .unwrap()
                .reply()
                .unwrap()
                .map_state;
            let g = x.get_geometry(w).unwrap().reply().unwrap();
            if mapped == MapState::VIEWABLE && g.width > 200 && g.height > 200 {
                return (g.x, g.y, g.width, g.height);
            }
        }
        assert!(
            start.elapsed() < PATIENCE,
            "no editor window appeared; its stderr:\n{}",
            stderr()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The screen's pixels, `[r, g, b]` per pixel, row by row.
fn screenshot(x: &RustConnection, root: Window, width: u16, height: u16) -> Vec<[u8; 3]> {
    let image = x
        .get_image(ImageFormat::Z_PIXMAP, root, 0, 0, width, height, !0)
        .unwrap()
        .reply()
        .unwrap();
    assert_eq!(image.depth, 24, "a 24-bit screen, 32 bits a pixel");
    // Xvfb's 24-bit visual: blue, green, red and a pad byte, little-endian.
    image
        .data
        .chunks_exact(4)
        .map(|p| [p[2], p[1], p[0]])
        .collect()
}

/// A point well inside the rightmost brick on screen (every pixel within 4 of it has the
/// brick's fill), or `None` while no brick is drawn.
fn inside_a_brick(
    pixels: &[[u8; 3]],
    width: usize,
    bounds: (i16, i16, u16, u16),
) -> Option<(i16, i16)> {
    let brick = |x: usize, y: usize| {
        let p = pixels[y * width + x];
        (0..3).all(|c| p[c].abs_diff(BRICK[c]) <= 6)
    };
    let (left, top, w, h) = (
        bounds.0.max(0) as usize,
        bounds.1.max(0) as usize,
        bounds.2 as usize,
        bounds.3 as usize,
    );
    let height = pixels.len() / width;
    let mut best: Option<(usize, usize)> = None;
    for y in (top + 4)..(top + h).min(height).saturating_sub(4) {
        for x in (left + 4)..(left + w).min(width).saturating_sub(4) {
            if best.is_some_and(|(bx, _)| bx >= x) || !brick(x, y) {
                continue;
            }
            if (y - 4..=y + 4).all(|yy| (x - 4..=x + 4).all(|xx| brick(xx, yy))) {
                best = Some((x, y));
            }
        }
    }
    best.map(|(x, y)| (x as i16, y as i16))
}

/// Sends one XTEST event and waits a little, as a hand would, so the editor sees each.
fn fake(x: &RustConnection, root: Window, kind: u8, detail: u8, at: (i16, i16)) {
    x.xtest_fake_input(kind, detail, 0, root, at.0, at.1, 0)
        .unwrap();
    x.flush().unwrap();
    std::thread::sleep(Duration::from_millis(30));
}

/// Drags with the left button from `from` by `by`, in steps.
fn drag(x: &RustConnection, root: Window, from: (i16, i16), by: (i16, i16)) {
    const MOTION: u8 = 6;
    const PRESS: u8 = 4;
    const RELEASE: u8 = 5;
    fake(x, root, MOTION, 0, (from.0 - 3, from.1));
    fake(x, root, MOTION, 0, from);
    fake(x, root, PRESS, 1, from);
    let steps = 20;
    for k in 1..=steps {
        let at = (from.0 + by.0 * k / steps, from.1 + by.1 * k / steps);
        fake(x, root, MOTION, 0, at);
    }
    std::thread::sleep(Duration::from_millis(200));
    fake(x, root, RELEASE, 1, (from.0 + by.0, from.1 + by.1));
}

#[test]
fn a_killed_editor_binary_leaves_its_work_in_a_new_home() {
    let home = empty_home();
    let grammar = repository().join("grammars/wall.clay");
    let grammar = std::fs::canonicalize(grammar).unwrap();
    let (_xvfb, display) = xvfb();
    let log = format!("clay-recovery-binary-{}.log", std::process::id());
    let log = std::env::temp_dir().join(log);
    let mut editor = Killed(
        Command::new(env!("CARGO_BIN_EXE_clay-editor"))
            .arg(&grammar)
            .env("HOME", &home)
            .env("DISPLAY", &display)
            .env_remove("XDG_STATE_HOME")
            .env_remove("XDG_CONFIG_HOME")
            .env_remove("CLAY_RECOVERY_FILE")
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("XAUTHORITY")
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .expect("the editor binary starts"),
    );
    let started = Instant::now();
    let stderr = || {
        let mut s = String::new();
        let _ = std::fs::File::open(&log).and_then(|mut f| f.read_to_string(&mut s));
        s
    };

    let (x, screen) = x11rb::connect(Some(&display)).expect("the test reaches Xvfb");
    let root = x.setup().roots[screen].root;
    let (width, height) = {
        let s = &x.setup().roots[screen];
        (s.width_in_pixels, s.height_in_pixels)
    };
    let window = editor_window(&x, root, &mut editor, stderr);

    // The wall drawn: a point inside its rightmost brick.
    let brick = loop {
        let pixels = screenshot(&x, root, width, height);
        if let Some(at) = inside_a_brick(&pixels, usize::from(width), window) {
            break at;
        }
        assert!(
            started.elapsed() < PATIENCE,
            "no brick drawn in the editor's window {window:?}; its stderr:\n{}",
            stderr()
        );
        std::thread::sleep(Duration::from_millis(200));
    };

    let state = home.join(".local/state");
    let recovery = state.join("clay/recovery.clay-session");
    assert!(
        !state.exists(),
        "the home had no state folder before the change (an unchanged model writes nothing)"
    );

    // What the wall was when opened, to tell the dragged one from it.
    let source = std::fs::read_to_string(&grammar).unwrap();
    let shown = grammar.display().to_string();
    let options = clay_dsl::CompileOptions::default();
    let initial = clay_dsl::compile(&source, &shown, &options)
        .unwrap()
        .grammar
        .assembly;
    // The most any vertex moved from the wall as opened (infinite when the drag stretched the
    // wall: bricks were added).
    let moved = |saved: &clay::session_file::SavedSession| {
        let now = &saved.assembly.positions;
        if now.len() != initial.positions.len() {
            return f64::INFINITY;
        }
        (now.iter().zip(&initial.positions))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max)
    };

    // Pull the brick right and down, then wait for the editor to keep the dragged wall: the
    // first write may come with the grab, before the brick moved, and the next within
    // `recovery::WRITE_EVERY` while it moves.
    drag(&x, root, brick, (90, 60));
    loop {
        let kept = clay::session_file::read(&recovery).ok();
        if kept.as_ref().is_some_and(|s| moved(s) > 0.05) {
            break;
        }
        assert!(
            started.elapsed() < PATIENCE,
            "no recovery file at {} holding the drag (read: {:?}); the editor's stderr:\n{}",
            recovery.display(),
            kept.as_ref().map(moved),
            stderr()
        );
        if let Some(status) = editor.0.try_wait().unwrap() {
            panic!("the editor exited ({status}); its stderr:\n{}", stderr());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    // Killed as a crash would (`Child::kill` is SIGKILL), with no chance to clean up.
    editor.0.kill().unwrap();
    let status = editor.0.wait().unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(
            status.signal(),
            Some(9),
            "killed, not a clean exit: {status}"
        );
        let mode = std::fs::metadata(state.join("clay"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(
            mode & 0o777,
            0o700,
            "the state folder it made is this user's only"
        );
    }
    // Written atomically (a rename), the file survives the kill whole.
    let saved = clay::session_file::read(&recovery)
        .unwrap_or_else(|e| panic!("the recovery file left after the kill is a session: {e}"));
    assert_eq!(saved.grammar, shown);
    assert!(
        moved(&saved) > 0.05,
        "the saved model is the wall as dragged, not as opened (moved {} m)",
        moved(&saved)
    );
    let _ = std::fs::remove_dir_all(&home);
    let _ = std::fs::remove_file(&log);
}
