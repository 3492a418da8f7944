//! `clayc check` on a grammar whose mesh asset is broken: the diagnostic (E066) at the
//! asset's path in the grammar, `file:line:col`, and exit 1. Mesh assets in the live model and
//! the exports are the clay crate's `tests/mesh_assets.rs`.

use std::path::PathBuf;
use std::process::Command;

/// A folder with a grammar and its assets.
fn scratch(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-mesh-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

/// A wall piece with a skinned OBJ box (the clay crate's `tests/mesh_assets.rs` sculpts it).
const WALL: &str = "site type s\npiece wall {\n    vertex sw (0, -0.4)\n    vertex se (1, -0.4)\n    \
                    vertex ne (1, 0.4)\n    vertex nw (0, 0.4)\n    edges sw-se-ne-nw-sw, sw-ne\n    \
                    site west: s [nw, sw] out (-1, 0)\n    site east: s [se, ne] out (1, 0)\n    \
                    axis west -> east\n    polygon skinned fill #111111 {\n        \
                    (0, -0.4) (1, -0.4) (1, 0.4) (0, 0.4)\n    }\n    mesh skinned \"box.obj\" fill #222222\n}\n\
                    model {\n    w = wall\n}\n";

#[test]
fn clayc_check_reports_a_broken_asset_at_its_path_and_fails() {
    let source = WALL.replace("box.obj", "box.glb");
    let dir = scratch("check", &[("wall.clay", &source)]);
    std::fs::write(dir.join("box.glb"), b"glTF\x02\0\0\0\x10\0\0\0junk").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_clayc"))
        .arg("check")
        .arg(dir.join("wall.clay"))
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let line = source.lines().position(|l| l.contains("box.glb")).unwrap() + 1;
    let col = source.lines().nth(line - 1).unwrap().find('"').unwrap() + 1;
    let at = format!("{}:{line}:{col}", dir.join("wall.clay").display());
    assert!(stderr.contains("error[E066]"), "{stderr}");
    assert!(stderr.contains(&at), "{at} in {stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    std::fs::remove_dir_all(dir).unwrap();
}
