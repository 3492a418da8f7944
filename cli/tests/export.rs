//! `clayc export` (issue 20): each format written where `-o` says, the OBJ's material file
//! beside it, and an unknown extension refused with exit 2 and nothing written. What the
//! exported scenes hold is `clay`'s export's, tested in the clay crate's `tests/export.rs`.

#[test]
fn clayc_export_writes_each_format_and_rejects_an_unknown_one() {
    let dir = std::env::temp_dir().join(format!("clay-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let wall = format!("{}/../grammars/wall.clay", env!("CARGO_MANIFEST_DIR"));
    let script = format!(
        "{}/../grammars/wall.script.json",
        env!("CARGO_MANIFEST_DIR")
    );
    for ext in ["glb", "gltf", "obj", "usda"] {
        let out = dir.join(format!("wall.{ext}"));
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_clayc"))
            .args(["export", &wall, "--script", &script, "-o"])
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success(), "{ext}");
        assert!(std::fs::metadata(&out).unwrap().len() > 100);
    }
    assert!(dir.join("wall.mtl").exists());
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(["export", &wall, "-o"])
        .arg(dir.join("wall.fbx"))
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains(".glb, .gltf, .obj or .usda"));
    assert!(!dir.join("wall.fbx").exists());
    // USD's binary form is not written without `usdcat` on the PATH; the refusal says how to
    // make it from the text form.
    let usdc = std::process::Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(["export", &wall, "-o"])
        .arg(dir.join("wall.usdc"))
        .env("PATH", &dir)
        .output()
        .unwrap();
    assert_eq!(usdc.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&usdc.stderr).contains("usdcat MODEL.usda -o MODEL.usdc"));
    assert!(!dir.join("wall.usdc").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 48: with `usdcat` on the PATH, `-o MODEL.usdc` writes the `.usda` beside it, has
/// `usdcat IN -o OUT` convert it, and leaves only the output. (A stand-in `usdcat` that marks
/// what it was given: CI has no USD installation.)
#[cfg(unix)]
#[test]
fn a_usdc_export_goes_through_usdcat_on_the_path() {
    use std::os::unix::fs::PermissionsExt;
    let dir = std::env::temp_dir().join(format!("clay-usdcat-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("bin")).unwrap();
    let usdcat = dir.join("bin/usdcat");
    std::fs::write(
        &usdcat,
        "#!/bin/sh\n[ \"$2\" = -o ] || exit 3\n{ printf 'PXR-USDC\\n'; cat \"$1\"; } > \"$3\"\n",
    )
    .unwrap();
    std::fs::set_permissions(&usdcat, std::fs::Permissions::from_mode(0o755)).unwrap();
    let wall = format!("{}/../grammars/wall.clay", env!("CARGO_MANIFEST_DIR"));
    let export = || {
        std::process::Command::new(env!("CARGO_BIN_EXE_clayc"))
            .args(["export", &wall, "-o"])
            .arg(dir.join("wall.usdc"))
            .env(
                "PATH",
                format!("{}:/usr/bin:/bin", dir.join("bin").display()),
            )
            .output()
            .unwrap()
    };
    let out = export();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let written = std::fs::read_to_string(dir.join("wall.usdc")).unwrap();
    assert!(
        written.starts_with("PXR-USDC\n#usda 1.0"),
        "{}",
        &written[..40]
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "the .usda went: {left:?}");
    // A converter that fails: its message, exit 2, no output.
    std::fs::write(&usdcat, "#!/bin/sh\necho 'cannot read it' >&2\nexit 1\n").unwrap();
    std::fs::remove_file(dir.join("wall.usdc")).unwrap();
    let out = export();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read it"));
    assert!(!dir.join("wall.usdc").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 47: an OBJ export that failed (its .obj could not be written) still replaced the
/// .mtl beside it. The .obj is written first; when it fails, the .mtl stays as it was.
#[test]
fn a_failed_obj_export_leaves_its_mtl_as_it_was() {
    let dir = std::env::temp_dir().join(format!("clay-export-mtl-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // a folder where the .obj should go: it cannot be replaced by a file
    std::fs::create_dir_all(dir.join("model.obj")).unwrap();
    std::fs::write(dir.join("model.mtl"), "the user's materials\n").unwrap();
    let wall = format!("{}/../grammars/wall.clay", env!("CARGO_MANIFEST_DIR"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(["export", &wall, "-o"])
        .arg(dir.join("model.obj"))
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("model.mtl")).unwrap(),
        "the user's materials\n"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
