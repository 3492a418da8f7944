//! The fuzzer of the mesh-asset loaders (issue 37): every asset in the repository (OBJ with its
//! `.mtl`, GLB, glTF with a `.bin` or a data URI) mutated as a user's 3D tool or disk might
//! break it, written to a folder of its own per case and compiled from a grammar that names it
//! (plain, rigid, skinned and mirrored), then exported. Mutations: truncation, bytes flipped
//! and inserted, numbers replaced by huge, negative, non-finite or out-of-range ones (counts,
//! indices, offsets, lengths, component types, modes), binary words overwritten with NaN,
//! infinities and huge values, broken base64 in data URIs, OBJ lines added, and the files an
//! asset refers to missing, renamed, or a folder, a named pipe or a symbolic-link loop.
//!
//! Properties: no panic; no case longer than `HANG`; a refused asset is exactly one error, one
//! of E064-E067, at file:line:col of the grammar; an accepted mesh has finite coordinates and
//! in-range triangles; its export (glTF and OBJ) writes only finite numbers.
//! `CLAY_FUZZ_CASES=N` runs N cases (default [`CASES`]), `CLAY_FUZZ_SEED` another seed; a
//! failure gives the case's input, saved byte for byte.

#[allow(dead_code)] // the engine's plain `fuzz` is the other targets'
mod fuzzing;
#[path = "fuzzing/located.rs"]
mod located;

use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use base64::Engine as _;
use clay::{ExportOptions, scene};
use clay_dsl::compiled::{CompiledGrammar, ProxyShape};
use clay_dsl::{Diagnostics, Severity};
use fuzzing::{fuzz_cases, mutate};
use located::located;
use proptest::prelude::RngExt;
use proptest::test_runner::TestRng;

/// Cases a plain `cargo test` runs: a debug build takes 2-15 s for them on two shared cores
/// (10,000 took 4 s on idle cores and 29 s on busy ones: a case writes, reads and removes
/// its folder).
const CASES: usize = 5_000;

/// Between the files of one input: a case is a bundle of named files, the first the asset the
/// grammar names.
const SEP: &[u8] = b"\n\x1e\x1e";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

// ---- bundles --------------------------------------------------------------------------------

fn encode(files: &[(String, Vec<u8>)]) -> Vec<u8> {
    let mut out = Vec::new();
    for (k, (name, bytes)) in files.iter().enumerate() {
        if k > 0 {
            out.extend_from_slice(SEP);
        }
        out.extend_from_slice(name.as_bytes());
        out.push(b'\n');
        out.extend_from_slice(bytes);
    }
    out
}

fn decode(input: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    let mut rest = input;
    loop {
        let (entry, next) = match find(rest, SEP) {
            Some(i) => (&rest[..i], Some(&rest[i + SEP.len()..])),
            None => (rest, None),
        };
        let (name, bytes) = match entry.iter().position(|&b| b == b'\n') {
            Some(i) => (&entry[..i], &entry[i + 1..]),
            None => (entry, &[][..]),
        };
        files.push((String::from_utf8_lossy(name).into_owned(), bytes.to_vec()));
        match next {
            Some(n) => rest = n,
            None => return files,
        }
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// A file name that stays in the case's folder and fits in a string literal.
fn safe_name(name: &str, k: usize) -> String {
    let s: String = name
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'))
        .take(40)
        .collect();
    if s.is_empty() || s.chars().all(|c| c == '.') {
        format!("file{k}")
    } else {
        s
    }
}

// ---- the corpus -----------------------------------------------------------------------------

/// The chunks of a GLB: its JSON and its binary chunk, when it has that shape.
fn glb_chunks(bytes: &[u8]) -> Option<(Vec<u8>, Option<Vec<u8>>)> {
    let u32_at = |at: usize| -> Option<usize> {
        let b = bytes.get(at..at + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    if !bytes.starts_with(b"glTF") {
        return None;
    }
    let json_len = u32_at(12)?;
    let json = bytes.get(20..20usize.checked_add(json_len)?)?.to_vec();
    let at = 20 + json_len;
    let bin = u32_at(at).and_then(|n| {
        bytes
            .get(at + 8..(at + 8).checked_add(n)?)
            .map(<[u8]>::to_vec)
    });
    Some((json, bin))
}

/// A GLB of `json` and `bin`, every length right.
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.map(<[u8]>::to_vec);
    if let Some(b) = &mut bin {
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
    }
    let total = 12 + 8 + json.len() + bin.as_ref().map_or(0, |b| 8 + b.len());
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if let Some(b) = bin {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

fn base64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn f32s(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A glTF JSON asset using every part of the format the loader reads: a node tree with a
/// matrix, a translation-rotation-scale and a mirroring scale; triangles, a strip and a fan;
/// 8-, 16- and 32-bit indices; a strided view; two materials; one buffer, embedded.
fn rich_gltf() -> String {
    let cube: Vec<f32> = (0..8)
        .flat_map(|i| {
            [
                (i & 1) as f32,
                ((i >> 1) & 1) as f32 * 2.0,
                -(((i >> 2) & 1) as f32),
            ]
        })
        .collect();
    let tris: Vec<u16> = vec![
        0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6,
        1, 3, 5, 3, 7, 5,
    ];
    let strip: Vec<u8> = vec![0, 1, 2, 3, 6, 7, 4, 5];
    let fan: Vec<u32> = vec![0, 1, 3, 2, 6, 4];
    let mut buf = f32s(&cube); // 96 bytes
    // The cube again, each position followed by 4 bytes of padding (a 16-byte stride).
    for p in cube.chunks(3) {
        buf.extend(f32s(p));
        buf.extend([0u8; 4]);
    }
    let tri_at = buf.len(); // 224
    buf.extend(tris.iter().flat_map(|v| v.to_le_bytes()));
    let strip_at = buf.len();
    buf.extend(&strip);
    while !buf.len().is_multiple_of(4) {
        buf.push(0);
    }
    let fan_at = buf.len();
    buf.extend(fan.iter().flat_map(|v| v.to_le_bytes()));
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,
"scenes":[{{"nodes":[0,3]}}],
"nodes":[{{"children":[1,2],"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0.5,0,0,1]}},
{{"mesh":0,"translation":[0,1,0],"rotation":[0,0.7071068,0,0.7071068],"scale":[0.5,0.5,0.5]}},
{{"mesh":1,"scale":[-1,1,1]}},
{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":2,"material":0}}]}},
{{"primitives":[{{"attributes":{{"POSITION":1}},"indices":3,"mode":5,"material":1}},
{{"attributes":{{"POSITION":0}},"indices":4,"mode":6}},
{{"attributes":{{"POSITION":0}},"mode":4}},
{{"attributes":{{"POSITION":0}},"mode":1}}]}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.2,0.1,1.0]}}}},{{}}],
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":96}},
{{"buffer":0,"byteOffset":96,"byteLength":128,"byteStride":16}},
{{"buffer":0,"byteOffset":{tri_at},"byteLength":72}},
{{"buffer":0,"byteOffset":{strip_at},"byteLength":8}},
{{"buffer":0,"byteOffset":{fan_at},"byteLength":24}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[0,0,-1],"max":[1,2,0]}},
{{"bufferView":1,"componentType":5126,"count":8,"type":"VEC3","min":[0,0,-1],"max":[1,2,0]}},
{{"bufferView":2,"componentType":5123,"count":36,"type":"SCALAR"}},
{{"bufferView":3,"componentType":5121,"count":8,"type":"SCALAR"}},
{{"bufferView":4,"componentType":5125,"count":6,"type":"SCALAR"}}]}}"#,
        len = buf.len(),
        data = base64(&buf),
    )
}

/// An OBJ with texture coordinates, normals, quads, a polygon, groups and two materials.
const RICH_OBJ: &str = "mtllib rich.mtl\no box\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nv 0 2 0\n\
    v 1 2 0\nv 1 2 -1\nv 0 2 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 1 0\nvn 0 -1 0\ng bottom\n\
    usemtl red\nf 1/1/2 4/2/2 3/3/2 2/1/2\ng top\nusemtl blue\nf 5//1 6//1 7//1 8//1\ns off\n\
    f 1/1 2/2 6/3 5/1\nf 2 3 7 6\nf -6 -5 -1 -2\nf 4 1 5 8\nl 1 7\n";
const RICH_MTL: &str = "newmtl red\nKa 0.1 0.1 0.1\nKd 1 0 0\nKs 0.5 0.5 0.5\nd 1.0\nillum 2\n\
    newmtl blue\nKd 0.0 0.2 1.0\nNs 10\n";

/// Every mesh asset of the repository (with the files each refers to), the keep's roof as
/// `.gltf` with a `.bin` and with a data URI, and a few assets using more of each format.
fn corpus() -> Vec<Vec<u8>> {
    let read = |p: &str| std::fs::read(root().join(p)).unwrap();
    let mut found = Vec::new();
    files_under(&root().join("grammars"), &mut found);
    files_under(&root().join("tests/fixtures"), &mut found);
    found.sort();
    let mut bundles: Vec<Vec<(String, Vec<u8>)>> = Vec::new();
    for f in &found {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = std::fs::read(f).unwrap();
        let mut bundle = vec![(name.clone(), bytes.clone())];
        // The files it refers to, from the same folder.
        let text = String::from_utf8_lossy(&bytes);
        for line in text.lines() {
            if let Some(mtl) = line.trim().strip_prefix("mtllib ")
                && let Ok(b) = std::fs::read(f.with_file_name(mtl.trim()))
            {
                bundle.push((mtl.trim().to_string(), b));
            }
        }
        bundles.push(bundle);
    }
    assert!(
        bundles
            .iter()
            .any(|b| b[0].0.ends_with(".obj") && b.len() == 2)
            && bundles.iter().any(|b| b[0].0.ends_with(".glb")),
        "the repository's assets: {found:?}"
    );
    // The spire as glTF JSON beside its .bin, and with its buffer embedded.
    let (json, bin) = glb_chunks(&read("grammars/assets/tower-roof.glb")).unwrap();
    let bin = bin.unwrap();
    let json = String::from_utf8(json).unwrap();
    let json = json.trim_end();
    let external = json.replace(
        r#""buffers":[{"byteLength":216}]"#,
        r#""buffers":[{"byteLength":216,"uri":"tower-roof.bin"}]"#,
    );
    assert_ne!(external, json);
    bundles.push(vec![
        ("tower-roof.gltf".into(), external.into_bytes()),
        ("tower-roof.bin".into(), bin.clone()),
    ]);
    let embedded = json.replace(
        r#""buffers":[{"byteLength":216}]"#,
        &format!(
            r#""buffers":[{{"byteLength":216,"uri":"data:application/octet-stream;base64,{}"}}]"#,
            base64(&bin)
        ),
    );
    bundles.push(vec![("spire.gltf".into(), embedded.into_bytes())]);
    let rich = rich_gltf();
    bundles.push(vec![("rich.gltf".into(), rich.clone().into_bytes())]);
    bundles.push(vec![("rich.glb".into(), glb(rich.as_bytes(), None))]);
    bundles.push(vec![
        ("rich.obj".into(), RICH_OBJ.into()),
        ("rich.mtl".into(), RICH_MTL.into()),
    ]);
    bundles.push(vec![("rich.obj".into(), RICH_OBJ.into())]);
    bundles.iter().map(|b| encode(b)).collect()
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files_under(&p, out);
        } else if p
            .extension()
            .is_some_and(|x| ["obj", "glb", "gltf"].iter().any(|e| x == *e))
        {
            out.push(p);
        }
    }
}

// ---- mutations ------------------------------------------------------------------------------

/// Numbers that break assumptions: counts and indices out of range, every component type and
/// mode, lengths past a buffer, non-finite and beyond-f32 values, negative zero, subnormals.
const ODD_NUMBERS: &[&str] = &[
    "0",
    "1",
    "2",
    "3",
    "4",
    "5",
    "6",
    "7",
    "8",
    "-1",
    "-2",
    "12",
    "255",
    "256",
    "65535",
    "65536",
    "2147483647",
    "-2147483648",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "99999999999999999999999",
    "1e39",
    "-1e39",
    "3.4028235e38",
    "3.5e38",
    "1e30",
    "-1e30",
    "1e308",
    "-1e308",
    "1e9",
    "1e10",
    "1e-45",
    "1e-30",
    "1e-320",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "-0",
    "0.5",
    "-0.5",
    "5120",
    "5121",
    "5122",
    "5123",
    "5125",
    "5126",
    "34962",
    "34963",
    "0x10",
    "1.5.5",
    "",
];

/// f32 or u32 words for binary data.
const ODD_WORDS: &[u32] = &[
    0x7fc0_0000, // NaN
    0x7f80_0000, // inf
    0xff80_0000, // -inf
    0x7f7f_ffff, // f32::MAX
    0xff7f_ffff, // f32::MIN
    0x7149_f2ca, // 1e30
    0x0da2_4260, // 1e-30
    0x0000_0001, // the least subnormal (or index 1)
    0x8000_0000, // -0
    0xffff_ffff,
    0x7fff_ffff,
    0x0000_ffff,
    0x0000_00ff,
    0,
    2,
    7,
    8,
    9,
];

const OBJ_LINES: &[&str] = &[
    "f 1 2 3",
    "f 1 2 99",
    "f 0 0 0",
    "f -1 -2 -3",
    "f -100 1 2",
    "f 1/1/1 2/2/2 3/3/3",
    "f 1//1 2//1 3//1",
    "f 1 2",
    "f 1",
    "f",
    "f 4294967296 1 2",
    "v 1e39 0 0",
    "v nan 0 0",
    "v inf -inf 0",
    "v 3.4e38 3.4e38 -3.4e38",
    "v 1e-45 1e-45 1e-45",
    "v 1e30 0 1e30",
    "v 1 2",
    "v",
    "vt 0.5",
    "vn 0 0",
    "vn nan nan nan",
    "mtllib missing.mtl",
    "mtllib rich.mtl",
    "mtllib .",
    "mtllib ",
    "usemtl",
    "usemtl nowhere",
    "o",
    "g",
    "s 1",
    "l 1 2 3",
    "p 1",
    "Kd 1 0",
    "Kd",
    "Ka nan nan nan",
    "Kd 1e39 -1 2",
    "newmtl",
    "newmtl red",
    "map_Kd -bm",
    "d",
    "Ns nan",
];

/// Rewrites a file's bytes as a mutation of one of these kinds (a GLB's JSON mutated inside
/// a GLB whose lengths are right).
fn mutate_file(rng: &mut TestRng, name: &str, bytes: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    if bytes.starts_with(b"glTF")
        && rng.random_bool(0.8)
        && let Some((json, bin)) = glb_chunks(bytes)
    {
        let (json, bin) = if bin.is_some() && rng.random_bool(0.4) {
            (json, bin.map(|b| overwrite_word(rng, &b)))
        } else {
            (mutate_text(rng, &json, corpus), bin)
        };
        return glb(&json, bin.as_deref());
    }
    if name.ends_with(".bin") || (bytes.starts_with(b"glTF") && rng.random_bool(0.5)) {
        return match rng.random_range(0..3) {
            0 => overwrite_word(rng, bytes),
            1 => truncate(rng, bytes),
            _ => mutate(rng, bytes, corpus),
        };
    }
    mutate_text(rng, bytes, corpus)
}

fn mutate_text(rng: &mut TestRng, bytes: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    // glTF JSON mostly keeps its syntax (so the mutation reaches the loader, not the JSON
    // parser); OBJ and MTL get lines.
    if bytes.trim_ascii_start().starts_with(b"{") {
        match rng.random_range(0..13) {
            0 => truncate(rng, bytes),
            1..=6 => {
                let json = rng.random_bool(0.9);
                replace_number(rng, bytes, json)
            }
            7 | 8 => replace_word(rng, bytes),
            9 => break_data_uri(rng, bytes),
            10 => data_uri_words(rng, bytes),
            _ => mutate(rng, bytes, corpus),
        }
    } else {
        match rng.random_range(0..10) {
            0 => truncate(rng, bytes),
            1..=3 => replace_number(rng, bytes, false),
            4..=6 => insert_line(rng, bytes),
            _ => mutate(rng, bytes, corpus),
        }
    }
}

fn truncate(rng: &mut TestRng, bytes: &[u8]) -> Vec<u8> {
    bytes[..rng.random_range(0..=bytes.len())].to_vec()
}

/// Numbers of a text replaced by odd ones (by ones JSON can hold when `json`).
fn replace_number(rng: &mut TestRng, bytes: &[u8], json: bool) -> Vec<u8> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (matches!(bytes[i], b'-' | b'.')
                && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric()) {
            let start = i;
            i += 1;
            while i < bytes.len()
                && (bytes[i].is_ascii_digit()
                    || matches!(bytes[i], b'.' | b'e' | b'E')
                    || (matches!(bytes[i], b'-' | b'+') && matches!(bytes[i - 1], b'e' | b'E')))
            {
                i += 1;
            }
            spans.push((start, i));
        }
        i += 1;
    }
    if spans.is_empty() {
        return bytes.to_vec();
    }
    let mut out = bytes.to_vec();
    for _ in 0..rng.random_range(1..=3) {
        let (a, b) = spans[rng.random_range(0..spans.len())];
        if b > out.len() {
            continue;
        }
        let odd = loop {
            let odd = if rng.random_bool(0.2) {
                rng.random_range(0..2000u32).to_string()
            } else {
                ODD_NUMBERS[rng.random_range(0..ODD_NUMBERS.len())].to_string()
            };
            if !json || serde_json::from_str::<serde_json::Number>(&odd).is_ok() {
                break odd;
            }
        };
        out.splice(a..b, odd.bytes());
    }
    out
}

/// A glTF keyword or name replaced by another of its kind.
fn replace_word(rng: &mut TestRng, bytes: &[u8]) -> Vec<u8> {
    const WORDS: &[&str] = &[
        "\"VEC3\"",
        "\"VEC2\"",
        "\"VEC4\"",
        "\"SCALAR\"",
        "\"MAT4\"",
        "\"POSITION\"",
        "\"NORMAL\"",
        "\"TEXCOORD_0\"",
        "\"indices\"",
        "\"byteStride\"",
        "\"byteOffset\"",
        "\"byteLength\"",
        "\"count\"",
        "\"bufferView\"",
        "\"buffer\"",
        "\"mode\"",
        "\"mesh\"",
        "\"children\"",
        "\"nodes\"",
        "\"scene\"",
        "\"uri\"",
        "\"matrix\"",
        "\"scale\"",
        "\"sparse\"",
        "\"material\"",
        "null",
        "[]",
        "{}",
        "true",
        "\"\"",
    ];
    let text = String::from_utf8_lossy(bytes);
    let present: Vec<(usize, &str)> = WORDS
        .iter()
        .flat_map(|w| text.match_indices(w).collect::<Vec<_>>())
        .collect();
    if present.is_empty() {
        return bytes.to_vec();
    }
    let (at, word) = present[rng.random_range(0..present.len())];
    let with = WORDS[rng.random_range(0..WORDS.len())];
    let mut out = text.to_string();
    out.replace_range(at..at + word.len(), with);
    out.into_bytes()
}

/// A data URI's base64 broken: cut, padded wrongly, a character outside the alphabet, another
/// encoding named, or emptied.
fn break_data_uri(rng: &mut TestRng, bytes: &[u8]) -> Vec<u8> {
    let Some(at) = find(bytes, b"base64,") else {
        return bytes.to_vec();
    };
    let start = at + "base64,".len();
    let end = bytes[start..]
        .iter()
        .position(|&b| b == b'"')
        .map_or(bytes.len(), |e| start + e);
    let mut out = bytes.to_vec();
    let pick = rng.random_range(start..=end);
    let (range, with): (std::ops::Range<usize>, &[u8]) = match rng.random_range(0..7) {
        0 => (pick..end, b""),
        1 => (pick..pick, b"="),
        2 => (pick..pick, b"!"),
        3 => (at..at + 6, b"base32"),
        4 => (start..end, b""),
        5 => (pick..pick, b"\\u0041"),
        _ => (pick..pick, b"AAAA"),
    };
    out.splice(range, with.iter().copied());
    out
}

/// Words of the binary data in a data URI overwritten (its base64 kept valid).
fn data_uri_words(rng: &mut TestRng, bytes: &[u8]) -> Vec<u8> {
    let Some(at) = find(bytes, b"base64,") else {
        return bytes.to_vec();
    };
    let start = at + "base64,".len();
    let end = bytes[start..]
        .iter()
        .position(|&b| b == b'"')
        .map_or(bytes.len(), |e| start + e);
    let Ok(data) = base64::engine::general_purpose::STANDARD.decode(&bytes[start..end]) else {
        return bytes.to_vec();
    };
    let mut out = bytes.to_vec();
    out.splice(start..end, base64(&overwrite_word(rng, &data)).into_bytes());
    out
}

fn insert_line(rng: &mut TestRng, bytes: &[u8]) -> Vec<u8> {
    let lines: Vec<usize> = std::iter::once(0)
        .chain(
            bytes
                .iter()
                .enumerate()
                .filter(|(_, b)| **b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .collect();
    let at = lines[rng.random_range(0..lines.len())];
    let line = format!("{}\n", OBJ_LINES[rng.random_range(0..OBJ_LINES.len())]);
    let mut out = bytes.to_vec();
    out.splice(at..at, line.bytes());
    out
}

/// A 4-byte word of binary data overwritten (at a multiple of 4, where floats and indices are).
fn overwrite_word(rng: &mut TestRng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    if out.len() < 4 {
        return out;
    }
    for _ in 0..rng.random_range(1..=3) {
        let at = rng.random_range(0..out.len() / 4) * 4;
        let w = if rng.random_bool(0.2) {
            rng.random()
        } else {
            ODD_WORDS[rng.random_range(0..ODD_WORDS.len())]
        };
        let w = if rng.random_bool(0.3) {
            // a 16-bit index pair
            w & 0xffff | (w << 16)
        } else {
            w
        };
        out[at..at + 4].copy_from_slice(&w.to_le_bytes());
    }
    out
}

/// What a file may be instead of one: a folder, a named pipe, a link to itself.
const SPECIALS: &[&[u8]] = &[b"@dir", b"@fifo", b"@loop"];

/// One case: most often a file of the bundle mutated as its format breaks, else the files
/// themselves changed (one missing, renamed, special), or the bundle's bytes mutated whole.
fn mutate_bundle(rng: &mut TestRng, base: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    if rng.random_bool(0.1) {
        return mutate(rng, base, corpus);
    }
    let mut files = decode(base);
    for _ in 0..rng.random_range(1..=2) {
        if files.is_empty() {
            break;
        }
        let k = rng.random_range(0..files.len());
        match rng.random_range(0..20) {
            0 => {
                files.remove(k);
            }
            1 => files[k].1 = SPECIALS[rng.random_range(0..SPECIALS.len())].to_vec(),
            2 => {
                let other = &files[rng.random_range(0..files.len())].0;
                files[k].0 = if rng.random_bool(0.5) {
                    other.clone()
                } else {
                    format!("{}x", files[k].0)
                };
            }
            3 => {
                // Another asset's companion beside this one.
                let other = decode(&corpus[rng.random_range(0..corpus.len())]);
                files.extend(other.into_iter().skip(1));
            }
            _ => {
                let (name, bytes) = files[k].clone();
                files[k].1 = mutate_file(rng, &name, &bytes, corpus);
            }
        }
    }
    encode(&files)
}

// ---- the properties -------------------------------------------------------------------------

/// Grammars naming the asset `ASSET`: plain on a triangle, rigid with a fill, skinned along a
/// wall (a polygon skinned too), skinned with a mirrored state.
const GRAMMARS: &[&str] = &[
    "piece hut {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    \
     edges a-b-c-a\n    mesh \"ASSET\"\n}\nmodel {\n    h = hut\n}\n",
    "piece hut {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    \
     edges a-b-c-a\n    mesh rigid \"ASSET\" fill #336699\n}\nmodel {\n    h = hut\n    \
     k = hut at (4, 0)\n}\n",
    "site type s\npiece wall {\n    vertex sw (0, -0.4)\n    vertex se (1, -0.4)\n    \
     vertex ne (1, 0.4)\n    vertex nw (0, 0.4)\n    edges sw-se-ne-nw-sw, sw-ne\n    \
     site west: s [nw, sw] out (-1, 0)\n    site east: s [se, ne] out (1, 0)\n    \
     axis west -> east\n    polygon skinned fill #111111 {\n        \
     (0, -0.4) (1, -0.4) (1, 0.4) (0, 0.4)\n    }\n    mesh skinned \"ASSET\" fill #222222\n}\n\
     model {\n    w = wall\n}\n",
    "site type s\npiece road {\n    vertex w (0, 0)\n    vertex e (2, 0)\n    vertex n (1, 1)\n    \
     vertex s (1, -1)\n    edges w-e-n-w, w-s-e\n    site west: s [w] out (-1, 0)\n    \
     site east: s [e] out (1, 0)\n    axis west -> east\n    mesh skinned \"ASSET\"\n    \
     state up {\n        w (0, 0)\n        e (2, 0)\n        n (1, 1.5)\n        s (1, -1.5)\n    }\n    \
     state down mirror up\n}\nmodel {\n    r = road\n    q = road at (0, 5) rotate 180\n}\n",
];

/// A fresh folder per case (cases run one at a time, but test binaries may share the machine).
fn case_dir() -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "clay-fuzz-assets-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes the bundle's files into `dir`; the name of the first (the asset).
fn write_files(dir: &Path, files: &[(String, Vec<u8>)]) -> String {
    for (k, (name, bytes)) in files.iter().enumerate() {
        let path = dir.join(safe_name(name, k));
        if path.symlink_metadata().is_ok() {
            continue; // the first of two files of one name is the one there
        }
        match bytes.as_slice() {
            b"@dir" => std::fs::create_dir(&path).unwrap(),
            b"@fifo" => {
                // Where `mkfifo` is missing the name is simply absent.
                let _ = std::process::Command::new("mkfifo").arg(&path).status();
            }
            b"@loop" => std::os::unix::fs::symlink(&path, &path).unwrap(),
            _ => std::fs::write(&path, bytes).unwrap(),
        }
    }
    files
        .first()
        .map_or_else(|| "gone.glb".to_string(), |f| safe_name(&f.0, 0))
}

/// A refused asset is one error, E064-E067, at the path string.
fn refused(d: &Diagnostics, text: &str, path: &str) -> Result<(), String> {
    located(d, text, path)?;
    let errors: Vec<_> = d.iter().filter(|e| e.severity == Severity::Error).collect();
    let codes: Vec<&str> = errors.iter().map(|e| e.code).collect();
    if errors.len() != 1 || !["E064", "E065", "E066", "E067"].contains(&codes[0]) {
        return Err(format!(
            "not one asset error: {:?}",
            errors
                .iter()
                .map(|e| format!("{}: {}", e.code, e.message))
                .collect::<Vec<_>>()
        ));
    }
    let e = errors[0];
    let quoted = &text[e.primary.span.start.min(text.len())..e.primary.span.end.min(text.len())];
    if !quoted.starts_with('"') || e.hints.is_empty() {
        return Err(format!(
            "{} not at the path, or without help: {quoted:?}",
            e.code
        ));
    }
    Ok(())
}

/// An accepted mesh is finite and its triangles index its points; its export is finite too.
fn accepted(g: &CompiledGrammar) -> Result<(), String> {
    let mut meshes = 0;
    for piece in &g.pieces {
        for state in &piece.states {
            for proxy in &state.geometry {
                let ProxyShape::Mesh {
                    points,
                    heights,
                    triangles,
                } = &proxy.shape
                else {
                    continue;
                };
                meshes += 1;
                if points.len() != heights.len() || triangles.is_empty() {
                    return Err(format!(
                        "{} points, {} heights, {} triangles",
                        points.len(),
                        heights.len(),
                        triangles.len()
                    ));
                }
                if let Some(p) = points.iter().find(|p| !p.is_finite()) {
                    return Err(format!("a mesh point {p}"));
                }
                if let Some(h) = heights.iter().find(|h| !h.is_finite()) {
                    return Err(format!("a mesh height {h}"));
                }
                if let Some(t) = triangles
                    .iter()
                    .find(|t| t.iter().any(|&i| i as usize >= points.len()))
                {
                    return Err(format!("triangle {t:?} of {} points", points.len()));
                }
            }
        }
    }
    if meshes == 0 {
        return Err("the grammar compiled without its mesh".into());
    }
    if serde_json::to_string(g)
        .ok()
        .and_then(|j| serde_json::from_str::<CompiledGrammar>(&j).ok())
        .is_none()
    {
        return Err("the compiled grammar does not round-trip through JSON".into());
    }
    let s = scene(g, &g.assembly, &ExportOptions::default());
    for n in &s.nodes {
        for p in &n.primitives {
            let bad = p
                .positions
                .iter()
                .chain(&p.normals)
                .find(|v| !v.iter().all(|x| x.is_finite()));
            if let Some(v) = bad {
                return Err(format!("the export of {} has {v:?}", n.name));
            }
        }
    }
    clay::testing::to_glb(&s).map_err(|e| format!("the glTF export failed: {e}"))?;
    let (text, _) = clay::testing::to_obj(&s, "fuzz.mtl");
    let lower = text.to_ascii_lowercase();
    if lower.contains("nan") || lower.contains("inf") {
        return Err("the OBJ export writes a non-finite number".into());
    }
    Ok(())
}

fn asset_case(input: &[u8]) -> Result<(), String> {
    let files = decode(input);
    let dir = case_dir();
    let asset = write_files(&dir, &files);
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    input.hash(&mut hasher);
    let text =
        GRAMMARS[(hasher.finish() % GRAMMARS.len() as u64) as usize].replace("ASSET", &asset);
    let path = dir.join("g.clay").to_string_lossy().into_owned();
    let outcome = match clay_dsl::compile(&text, &path, &clay_dsl::CompileOptions::default()) {
        Ok(c) => located(&c.warnings, &text, &path).and_then(|()| accepted(&c.grammar)),
        Err(d) => refused(&d, &text, &path),
    };
    let _ = std::fs::remove_dir_all(&dir);
    outcome.map_err(|why| format!("{why}\ngrammar:\n{text}"))
}

#[test]
fn mesh_assets_mutated_never_panic_hang_or_load_non_finite_geometry() {
    let corpus = corpus();
    // The corpus itself compiles (the fixtures meant to fail, fail as they should).
    for c in &corpus {
        asset_case(c).unwrap_or_else(|e| panic!("{:?}: {e}", decode(c)[0].0));
    }
    fuzz_cases(
        "assets",
        fuzzing::cases_or(CASES),
        corpus,
        mutate_bundle,
        asset_case,
    );
}
