//! Names an engine keeps as they are: node and mesh names of letters, digits and single
//! underscores, at most 63 bytes, unique in the file.
//!
//! Importers rewrite names they do not like, and two different names can come out the same:
//! three.js (`PropertyBinding.sanitizeNodeName`) drops `[ ] . : /` and turns whitespace into
//! `_`, so `wall[10]` and `wall1[0]` both become `wall10`; Blender cuts names at 63 bytes and
//! numbers repeats (`.001`); Godot refuses `. : @ / " %`. A name made only of letters, digits
//! and `_` passes all of them unchanged. Stretch-chain elements are named by their chain and
//! their place in it (`wall_n_4`, the fifth brick of `wall_n` in chain order), other instances by
//! their assembly name with every other character an underscore (`gate[0]` -> `gate_0`); a name
//! already taken gets `_2`, `_3`, ... Mesh names hold a double underscore (`brick__rest`),
//! which no node name has, so three.js's numbering of instanced copies (`brick__rest_1`) never
//! takes a node's name.

use std::collections::HashSet;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar};

use super::model::{ChainPlace, Scene};

/// Blender's limit for object and mesh names, in bytes.
pub const MAX_NAME_BYTES: usize = 63;

/// `name` with every character but letters, digits and `_` made `_`, runs of `_` made one,
/// no `_` at either end, at most [`MAX_NAME_BYTES`] bytes; `fallback` when nothing is left.
pub fn sanitise(name: &str, fallback: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        let c = if c.is_alphanumeric() { c } else { '_' };
        if c == '_' && (out.is_empty() || out.ends_with('_')) {
            continue;
        }
        out.push(c);
    }
    while out.ends_with('_') {
        out.pop();
    }
    let out = truncate(&out, MAX_NAME_BYTES);
    if out.is_empty() {
        fallback.to_string()
    } else {
        out
    }
}

/// The longest prefix of `s` of at most `max` bytes that ends on a character boundary, without
/// a trailing `_`.
fn truncate(s: &str, max: usize) -> String {
    let mut end = s.len().min(max);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    s[..end].trim_end_matches('_').to_string()
}

/// `wanted` if no name in `taken` is, else `wanted_2`, `wanted_3`, ... (cut to fit the limit);
/// the name is added to `taken`.
pub fn unique(wanted: &str, taken: &mut HashSet<String>) -> String {
    if taken.insert(wanted.to_string()) {
        return wanted.to_string();
    }
    for k in 2usize.. {
        let suffix = format!("_{k}");
        let name = format!(
            "{}{suffix}",
            truncate(wanted, MAX_NAME_BYTES - suffix.len())
        );
        if taken.insert(name.clone()) {
            return name;
        }
    }
    unreachable!("some suffix is free")
}

/// Each instance's stretch chain and its place in it (chain order, from the chain's `from` end),
/// `None` for instances in no chain. A chain is called by its model name (`wall_n` of
/// `wall_n[3]`, or of `wall_n#12` for an element a rule inserted); a second chain of that name
/// is `wall_n_2`, and so on.
pub fn chain_places(assembly: &AssemblyData) -> Vec<Option<ChainPlace>> {
    let mut places = vec![None; assembly.instances.len()];
    let mut taken = HashSet::new();
    for (c, chain) in assembly.chains.iter().enumerate() {
        let first = chain
            .instances
            .first()
            .and_then(|&i| assembly.instances.get(i))
            .map_or("", |i| i.name.as_str());
        let stem = first.split(['[', '#']).next().unwrap_or(first);
        let name = unique(&sanitise(stem, &format!("chain{c}")), &mut taken);
        for (index, &i) in chain.instances.iter().enumerate() {
            if let Some(p) = places.get_mut(i) {
                *p = Some(ChainPlace {
                    name: name.clone(),
                    index,
                });
            }
        }
    }
    places
}

/// Names the root (the grammar's file name without extension, `castle`), every node and every
/// mesh, all different.
pub fn name_scene(scene: &mut Scene, grammar: &CompiledGrammar) {
    let stem = std::path::Path::new(&grammar.source)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    scene.name = sanitise(&stem, "model");
    let mut taken = HashSet::from([scene.name.clone()]);
    for node in &mut scene.nodes {
        let wanted = match &node.chain {
            Some(c) => sanitise(&format!("{}_{}", c.name, c.index), "element"),
            None => sanitise(&node.instance, "instance"),
        };
        node.name = unique(&wanted, &mut taken);
    }
    let mut count: std::collections::HashMap<String, usize> = Default::default();
    for mesh in &mut scene.meshes {
        let node = &scene.nodes[mesh.node];
        let base = truncate(
            &format!(
                "{}__{}",
                sanitise(&node.piece, "piece"),
                sanitise(&node.state, "state")
            ),
            MAX_NAME_BYTES - 6,
        );
        let k = count.entry(base.clone()).or_default();
        *k += 1;
        let wanted = if *k == 1 {
            base
        } else {
            format!("{base}__{k}")
        };
        mesh.name = unique(&wanted, &mut taken);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// three.js's `PropertyBinding.sanitizeNodeName`.
    fn three_js(name: &str) -> String {
        name.chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .filter(|c| !"[].:/".contains(*c))
            .collect()
    }

    #[test]
    fn names_survive_three_js_and_stay_apart() {
        let mut taken = HashSet::new();
        let a = unique(&sanitise("wall[10]", "x"), &mut taken);
        let b = unique(&sanitise("wall1[0]", "x"), &mut taken);
        assert_eq!((a.as_str(), b.as_str()), ("wall_10", "wall1_0"));
        for n in [&a, &b] {
            assert_eq!(&three_js(n), n);
        }
        assert_eq!(sanitise("wall#17", "x"), "wall_17");
        assert_eq!(sanitise("a b.c:d/e", "x"), "a_b_c_d_e");
        assert_eq!(sanitise("[]", "node"), "node");
        assert_eq!(unique("wall_10", &mut taken), "wall_10_2");
        assert_eq!(unique("wall_10", &mut taken), "wall_10_3");
    }

    #[test]
    fn long_names_are_cut_at_a_character_boundary() {
        let long = "é".repeat(40);
        let s = sanitise(&long, "x");
        assert!(s.len() <= MAX_NAME_BYTES);
        assert!(long.starts_with(&s));
        let mut taken = HashSet::from([s.clone()]);
        let t = unique(&s, &mut taken);
        assert!(t.len() <= MAX_NAME_BYTES && t.ends_with("_2"), "{t}");
    }
}
