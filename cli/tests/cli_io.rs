//! `clayc` at its edges (issue 16): a reader that closes the pipe early never makes a subcommand
//! panic, an unreadable file never lets `check` pass, `-o -` writes to standard output for every
//! subcommand that writes a file, `-o` through a symbolic link writes its target and keeps the
//! link, `-o /dev/stdout` writes into the pipe, and script coordinates beyond +/-1e9 (or an empty
//! script) are rejected with the step and its line and column named.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};

fn clayc() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_clayc"));
    c.env("NO_COLOR", "1");
    c
}

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn wall() -> String {
    root().join("grammars/wall.clay").display().to_string()
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-cli-io-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn invalid_fixture() -> PathBuf {
    root().join("tests/fixtures/invalid/E011-unknown-piece.clay")
}

/// Which stream of the child the test reads and then closes.
#[derive(Clone, Copy)]
enum Stream {
    Stdout,
    Stderr,
}

/// Runs clayc with `stream` piped, reads one line of it (when `read_first` is set; otherwise
/// closes it before the child can write) and closes it, then waits. Gives the exit status and
/// what the child wrote on the other stream.
fn close_early(args: &[String], stream: Stream, read_first: bool) -> (ExitStatus, String) {
    let mut child = clayc()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (closed, mut other): (Box<dyn Read + Send>, Box<dyn Read + Send>) = match stream {
        Stream::Stdout => (
            Box::new(child.stdout.take().unwrap()),
            Box::new(child.stderr.take().unwrap()),
        ),
        Stream::Stderr => (
            Box::new(child.stderr.take().unwrap()),
            Box::new(child.stdout.take().unwrap()),
        ),
    };
    // The other stream is drained on its own thread so that the child never blocks on it.
    let drain = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = other.read_to_string(&mut text);
        text
    });
    if read_first {
        let mut line = String::new();
        let mut reader = BufReader::new(closed);
        reader.read_line(&mut line).unwrap();
        assert!(!line.is_empty(), "{args:?}: nothing was written");
    } else {
        drop(closed);
    }
    let status = child.wait().unwrap();
    (status, drain.join().unwrap())
}

/// The arguments of `clayc check` on the invalid fixture `copies` times: a lot of output, more
/// than a pipe holds, so the child is still writing when the reader goes.
fn check_many(json: bool, copies: usize) -> Vec<String> {
    let mut args = vec!["check".to_string()];
    if json {
        args.extend(["--format".to_string(), "json".to_string()]);
    }
    args.extend(std::iter::repeat_n(
        invalid_fixture().display().to_string(),
        copies,
    ));
    args
}

fn assert_quiet_exit(status: ExitStatus, other: &str, expected: i32, what: &str) {
    assert_ne!(status.code(), Some(101), "{what}: panicked: {other}");
    assert_eq!(status.code(), Some(expected), "{what}: {other}");
    assert!(!other.contains("panicked"), "{what}: {other}");
    assert!(!other.contains("Broken pipe"), "{what}: {other}");
}

#[test]
fn a_reader_that_closes_early_never_makes_clayc_panic() {
    // check --format json: a JSON array far larger than a pipe, the reader keeps one line.
    let (status, stderr) = close_early(&check_many(true, 3000), Stream::Stdout, true);
    assert_quiet_exit(status, &stderr, 1, "check --format json | head -1");
    // check (human): the diagnostics are on stderr, so that is the pipe that closes.
    let (status, _) = close_early(&check_many(false, 3000), Stream::Stderr, true);
    assert_ne!(status.code(), Some(101), "check 2>&1 | head -1 panicked");
    assert_eq!(status.code(), Some(1), "check 2>&1 | head -1");
    // run and run --json print a short summary: the reader has gone before it is written.
    let script = scratch("pipe").join("s.json");
    std::fs::write(
        &script,
        r#"{"steps": [{"grab": {"extreme": "east"}}, {"drag": {"by": [0.5, 0], "frames": 3}}]}"#,
    )
    .unwrap();
    let script = script.display().to_string();
    for json in [false, true] {
        let mut args = vec!["run".to_string(), wall(), "--script".into(), script.clone()];
        if json {
            args.push("--json".into());
        }
        let (status, stderr) = close_early(&args, Stream::Stdout, false);
        assert_quiet_exit(status, &stderr, 0, &format!("{args:?}"));
    }
    // Everything else that prints: build, fmt, render and sheet to `-o -`.
    let others = [
        vec!["build".to_string(), wall(), "-o".into(), "-".into()],
        vec!["fmt".to_string(), wall()],
        vec!["render".to_string(), wall(), "-o".into(), "-".into()],
        vec!["sheet".to_string(), wall(), "-o".into(), "-".into()],
    ];
    for args in others {
        let (status, stderr) = close_early(&args, Stream::Stdout, false);
        assert_quiet_exit(status, &stderr, 0, &format!("{args:?}"));
    }
}

#[test]
fn check_never_passes_a_file_it_could_not_read() {
    let out = clayc().args(["check", "nosuch.clay"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("passed"), "{stderr}");
    assert!(
        stderr.contains("error[E004]: cannot read `nosuch.clay`: no such file"),
        "{stderr}"
    );
    assert!(stderr.contains("help:"), "{stderr}");
    assert!(
        stderr.contains("check failed: 1 of 1 file could not be read"),
        "{stderr}"
    );
    // With a readable file besides, the unreadable one still fails the check.
    let out = clayc()
        .arg("check")
        .arg(wall())
        .arg("nosuch.clay")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("check failed: 1 of 2 files could not be read"),
        "{stderr}"
    );
    // JSON: the I/O error is a diagnostic object naming the file, not `[]`.
    let out = clayc()
        .args(["check", "--format", "json", "nosuch.clay"])
        .arg(wall())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let diags: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(diags.len(), 1, "{diags:?}");
    let d = &diags[0];
    assert_eq!(d["code"], "E004");
    assert_eq!(d["severity"], "error");
    assert_eq!(d["file"], "nosuch.clay");
    assert_eq!(
        (d["line"].as_u64(), d["column"].as_u64()),
        (Some(1), Some(1))
    );
    assert!(
        d["message"].as_str().unwrap().contains("no such file"),
        "{d}"
    );
    assert!(!d["hints"].as_array().unwrap().is_empty(), "{d}");
    // A directory is not a grammar file either.
    let dir = scratch("dir");
    let out = clayc()
        .args(["check", "--format", "json"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let diags: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(diags.len(), 1, "{diags:?}");
    assert_eq!(diags[0]["code"], "E004");
}

/// Runs clayc in `dir` and gives its exit code, stdout and stderr.
fn run_in(dir: &Path, args: &[&str]) -> (Option<i32>, Vec<u8>, String) {
    let out = clayc().args(args).current_dir(dir).output().unwrap();
    (
        out.status.code(),
        out.stdout,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

#[test]
fn dash_output_writes_to_stdout_and_creates_no_file() {
    let dir = scratch("dash");
    let g = wall();
    let (code, png, err) = run_in(&dir, &["render", &g, "-o", "-", "--size", "320x200"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        png.starts_with(PNG_SIGNATURE),
        "{:?}",
        &png[..png.len().min(16)]
    );
    let picture = tiny_skia::Pixmap::decode_png(&png).unwrap();
    assert_eq!((picture.width(), picture.height()), (320, 200));
    let (code, svg, err) = run_in(&dir, &["render", &g, "-o", "-", "--svg"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(String::from_utf8_lossy(&svg).contains("<svg"), "not SVG");
    let (code, sheet, err) = run_in(&dir, &["sheet", &g, "--output", "-"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(sheet.starts_with(PNG_SIGNATURE));
    let (code, json, err) = run_in(&dir, &["build", &g, "-o", "-"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(serde_json::from_slice::<serde_json::Value>(&json).is_ok());
    assert!(!dir.join("-").exists(), "a file named `-` was written");
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "files appeared"
    );
}

#[cfg(unix)]
#[test]
fn output_through_a_symbolic_link_writes_its_target_and_keeps_the_link() {
    use std::os::unix::fs::symlink;
    let dir = scratch("link");
    let g = wall();
    std::fs::create_dir(dir.join("out")).unwrap();
    std::fs::write(dir.join("out/wall.json"), "stale").unwrap();
    symlink("out/wall.json", dir.join("wall.json")).unwrap();
    symlink("out/wall.png", dir.join("wall.png")).unwrap(); // dangling until written
    let (code, _, err) = run_in(&dir, &["build", &g, "-o", "wall.json"]);
    assert_eq!(code, Some(0), "{err}");
    let (code, _, err) = run_in(&dir, &["render", &g, "-o", "wall.png", "--size", "64x48"]);
    assert_eq!(code, Some(0), "{err}");
    for link in ["wall.json", "wall.png"] {
        let meta = std::fs::symlink_metadata(dir.join(link)).unwrap();
        assert!(
            meta.file_type().is_symlink(),
            "{link} was replaced by a file"
        );
    }
    let json = std::fs::read(dir.join("out/wall.json")).unwrap();
    assert!(serde_json::from_slice::<serde_json::Value>(&json).is_ok());
    let png = std::fs::read(dir.join("out/wall.png")).unwrap();
    assert!(png.starts_with(PNG_SIGNATURE));
    let mut written: Vec<_> = std::fs::read_dir(dir.join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    written.sort();
    assert_eq!(written, ["wall.json", "wall.png"], "no temporary left");
}

#[cfg(unix)]
#[test]
fn output_to_dev_stdout_writes_into_the_pipe() {
    let dir = scratch("devstdout");
    let (code, json, err) = run_in(&dir, &["build", &wall(), "-o", "/dev/stdout"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(serde_json::from_slice::<serde_json::Value>(&json).is_ok());
    assert!(
        std::fs::symlink_metadata("/dev/stdout")
            .unwrap()
            .file_type()
            .is_symlink(),
        "/dev/stdout was replaced"
    );
}

/// `clayc run` of wall.clay with this script; gives the exit code and stderr.
fn run_script(name: &str, script: &str) -> (Option<i32>, String) {
    let path = scratch(name).join("huge.json");
    std::fs::write(&path, script).unwrap();
    let out = clayc()
        .arg("run")
        .arg(wall())
        .arg("--script")
        .arg(&path)
        .arg("--json")
        .output()
        .unwrap();
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (
        out.status.code(),
        stderr.replace(&path.display().to_string(), "huge.json"),
    )
}

#[test]
fn huge_script_coordinates_are_rejected_naming_the_step_and_its_line() {
    let (code, err) = run_script(
        "drag",
        "{\"steps\": [\n  {\"grab\": {\"extreme\": \"east\"}},\n  {\"drag\": {\"to\": [1e150, -1e150], \"frames\": 4}}\n]}\n",
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains(
            "error: huge.json:3:3: step 1: drag: \"to\": coordinate 1e150 is outside +/-1e9 m"
        ),
        "{err}"
    );
    assert!(err.contains("help:") && err.contains("E013"), "{err}");
    assert!(!err.contains("merge"), "{err}");
    let (code, err) = run_script(
        "grab",
        r#"{"steps": [{"grab": {"at": [1e200, 1e200]}}, {"drag": {"by": [1, 0], "frames": 2}}]}"#,
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("huge.json:1:12: step 0: grab: \"at\": coordinate 1e200 is outside"),
        "{err}"
    );
    assert!(!err.contains("the model is empty"), "{err}");
    // By offsets and cut points are coordinates too; the bound itself is allowed.
    for (script, needle) in [
        (
            r#"{"steps": [{"drag": {"by": [0, -2e9], "frames": 1}}]}"#,
            "step 0: drag: \"by\"",
        ),
        (
            r#"{"steps": [{"hold": {"frames": 1}}, {"cut": {"at": [1e10, 0]}}]}"#,
            "step 1: cut: \"at\"",
        ),
    ] {
        let (code, err) = run_script("by", script);
        assert_eq!(code, Some(1), "{script}: {err}");
        assert!(err.contains(needle), "{script}: {err}");
    }
    let script = clay::Script::parse(
        r#"{"steps": [{"pin": {"at": [1e9, -1e9]}}, {"drag": {"to": [-1e9, 1e9], "frames": 0}}]}"#,
    );
    assert!(script.is_ok(), "{script:?}");
}

#[test]
fn an_empty_script_is_reported_at_line_1_column_1() {
    for (name, text) in [("empty", ""), ("blank", " \n\n")] {
        let (code, err) = run_script(name, text);
        assert_eq!(code, Some(1), "{err}");
        assert!(
            err.contains("error: huge.json:1:1: the script is empty: expected {\"steps\": [...]}"),
            "{name}: {err}"
        );
    }
}

#[test]
fn script_errors_carry_the_steps_position() {
    let e = clay::Script::parse(
        "{\"steps\": [\n    {\"hold\": {\"frames\": 1}},\n    {\"pin\": {\"at\": [\"x\", 0]}}\n]}",
    )
    .unwrap_err();
    assert_eq!(e.step, Some(1));
    assert_eq!(e.position, Some((3, 5)));
    assert!(e.hint.is_none(), "{e:?}");
    let e = clay::Script::parse("{\"steps\": [\n  {\"hold\": }\n]}").unwrap_err();
    assert_eq!(e.step, None);
    assert_eq!(e.position.map(|p| p.0), Some(2), "{e:?}");
}

/// Runs clayc with `args` in `dir`, and kills it if it has not ended within 60 s (a read that
/// waits on a named pipe or never ends): the exit code (none when killed) and standard error.
fn run_or_kill(dir: &Path, args: &[&str]) -> (Option<i32>, String) {
    let mut child = clayc()
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = stderr.read_to_string(&mut text);
        text
    });
    let start = std::time::Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    (code, reader.join().unwrap())
}

/// Issue 47: `clayc check /dev/zero` reached 11.5 GB in 8 s, and a grammar, script or session
/// that is a named pipe blocked for ever. Every top-level input of every subcommand is read
/// through one reader that refuses what is not a regular file, before opening it, and says so.
#[cfg(unix)]
#[test]
fn dev_zero_and_a_named_pipe_are_refused_by_every_subcommand() {
    let dir = scratch("special");
    let fifo = dir.join("pipe.clay");
    let made = Command::new("mkfifo").arg(&fifo).status();
    let mut inputs = vec![("/dev/zero".to_string(), "a device")];
    if made.is_ok_and(|s| s.success()) {
        inputs.push((fifo.display().to_string(), "named pipe"));
    }
    let wall = wall();
    for (input, kind) in &inputs {
        let i = input.as_str();
        let cases: Vec<Vec<&str>> = vec![
            vec!["check", i],
            vec!["fmt", i],
            vec!["build", i, "-o", "out.json"],
            vec!["render", i, "-o", "out.png"],
            vec!["export", i, "-o", "out.glb"],
            vec!["sheet", i, "-o", "sheet.png"],
            vec!["run", i],
            vec!["run", &wall, "--script", i],
            vec!["render", "--session", i, "-o", "out.png"],
            vec!["author", i, "-o", "out.clay"],
        ];
        for args in cases {
            let (code, stderr) = run_or_kill(&dir, &args);
            assert!(code.is_some(), "{args:?} did not end within 60 s");
            assert_eq!(code, Some(2), "{args:?}: an I/O error: {stderr}");
            assert!(stderr.contains(kind), "{args:?} says what it is: {stderr}");
            assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        }
    }
    for out in ["out.json", "out.png", "out.glb", "sheet.png", "out.clay"] {
        assert!(!dir.join(out).exists(), "{out} written");
    }
}

/// The reader's limit: a grammar on standard input past 32 MiB is refused, not read on.
#[test]
fn fmt_of_standard_input_stops_at_the_limit() {
    let mut child = clayc()
        .args(["fmt", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        use std::io::Write;
        let block = vec![b' '; 1 << 20];
        // 40 MiB, or until clayc stops reading and closes the pipe
        for _ in 0..40 {
            if stdin.write_all(&block).is_err() {
                break;
            }
        }
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("more than 32 MiB"), "{stderr}");
}
