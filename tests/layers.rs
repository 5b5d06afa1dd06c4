//! The physics core and the FMI glue have no import cycles; the physics
//! knows nothing of FMI, and the glue names its model only through
//! `crate::TheModel` (bound in `lib.rs`).
//!
//! Every file under `src/physics/` (and `src/fmi/`) is a module; a module depends on every
//! module a path in its code names (`use` trees, `crate::physics::...`,
//! `super::...`, `self::...` and paths that start at one of its own child
//! modules; re-exports count too). No module may depend, directly or
//! through others, on a module that depends on it, and no module may name
//! `crate::fmi` or `crate::canonical_scenes`. The test prints the module graph it
//! read, so a failure shows the cycle and the edges behind it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path (below the top module) of each file, e.g. `space::modal::cubature`.
fn modules(root: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).unwrap();
                let mut segs: Vec<String> = rel.iter().map(|s| s.to_string_lossy().trim_end_matches(".rs").to_string()).collect();
                if segs.last().is_some_and(|s| s == "mod") {
                    segs.pop();
                }
                out.insert(segs, path);
            }
        }
    }
    out
}

/// The code of a file without comments, string and character literals.
fn code_only(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            '/' if b.get(i + 1) == Some(&'/') => {
                while i < b.len() && b[i] != '\n' {
                    i += 1;
                }
            }
            '/' if b.get(i + 1) == Some(&'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == '*' && b[i + 1] == '/') {
                    i += 1;
                }
                i += 2;
            }
            '"' => {
                i += 1;
                while i < b.len() && b[i] != '"' {
                    i += if b[i] == '\\' { 2 } else { 1 };
                }
                i += 1;
                out.push_str("\"\"");
            }
            // A character literal ('x', '\n'); a lifetime ('a) has no closing quote two or three on.
            '\'' if b.get(i + 2) == Some(&'\'') => i += 3,
            '\'' if b.get(i + 1) == Some(&'\\') && b.get(i + 3) == Some(&'\'') => i += 4,
            c => {
                out.push(c);
                i += 1;
            }
        }
    }
    out
}

/// Every path of a `use` tree: `a::{b, c::{d, e}}` -> a::b, a::c::d, a::c::e.
fn use_paths(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    match tree.find('{') {
        None => vec![tree.split(" as ").next().unwrap().trim().to_string()],
        Some(open) => {
            let prefix = tree[..open].trim_end_matches("::").trim();
            let inner = &tree[open + 1..tree.rfind('}').unwrap()];
            let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
            for (i, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        parts.push(&inner[start..i]);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            parts.push(&inner[start..]);
            parts
                .into_iter()
                .filter(|p| !p.trim().is_empty())
                .flat_map(use_paths)
                .map(|p| {
                    if p == "self" {
                        prefix.to_string()
                    } else if prefix.is_empty() {
                        p
                    } else {
                        format!("{prefix}::{p}")
                    }
                })
                .collect()
        }
    }
}

/// Inline modules (`mod tests { ... }`) of a file: (start, end, name) of each body.
fn inline_modules(code: &str) -> Vec<(usize, usize, String)> {
    let mut out = Vec::new();
    let mut open: Vec<(usize, usize, String)> = Vec::new(); // (start, depth, name)
    let mut depth = 0;
    let bytes = code.as_bytes();
    for (i, c) in code.char_indices() {
        match c {
            '{' => {
                depth += 1;
                // `mod NAME {`: the word before the brace, and `mod` before it.
                let head = code[..i].trim_end();
                let name_start = head.rfind(|c: char| !(c.is_alphanumeric() || c == '_')).map_or(0, |k| k + 1);
                let before = head[..name_start].trim_end();
                if before.ends_with("mod") && (before.len() == 3 || !(bytes[before.len() - 4] as char).is_alphanumeric()) {
                    open.push((i, depth, head[name_start..].to_string()));
                }
            }
            '}' => {
                if open.last().is_some_and(|o| o.1 == depth) {
                    let (start, _, name) = open.pop().unwrap();
                    out.push((start, i, name));
                }
                depth -= 1;
            }
            _ => {}
        }
    }
    out
}

/// The paths a module's code names, each with where it stands: its `use`
/// trees and the qualified paths in its code.
fn named_paths(code: &str) -> Vec<(usize, String)> {
    let mut paths = Vec::new();
    let mut from = 0;
    while let Some(at) = code[from..].find("use ") {
        let at = from + at;
        from = at + 4;
        if code[..at].chars().last().is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        if let Some(end) = code[from..].find(';') {
            paths.extend(use_paths(&code[from..from + end]).into_iter().map(|p| (at, p)));
        }
    }
    for start in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(at) = code[from..].find(start) {
            let at = from + at;
            from = at + start.len();
            if code[..at].chars().last().is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let end = code[at..].find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).map_or(code.len(), |e| at + e);
            paths.push((at, code[at..end].trim_end_matches(':').to_string()));
        }
    }
    paths
}

/// The module of `top` (`physics`, `fmi`) a path names from module `here`,
/// if any; a path to another top module of the crate is `<crate::NAME>`.
fn resolve_in(top: &str, path: &str, here: &[String], known: &BTreeSet<Vec<String>>) -> Option<Vec<String>> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let mut abs: Vec<String> = match segs.first()? {
        &"crate" => {
            if segs.get(1) != Some(&top) {
                return Some(vec![format!("<crate::{}>", segs.get(1).unwrap_or(&""))]);
            }
            segs[2..].iter().map(|s| s.to_string()).collect()
        }
        &"super" | &"self" => {
            let mut base: Vec<String> = here.to_vec();
            let mut k = 0;
            while segs.get(k) == Some(&"super") {
                base.pop();
                k += 1;
            }
            if segs.get(k) == Some(&"self") {
                k += 1;
            }
            base.extend(segs[k..].iter().map(|s| s.to_string()));
            base
        }
        first => {
            let mut child = here.to_vec();
            child.push(first.to_string());
            if !known.contains(&child) {
                return None;
            }
            let mut abs = here.to_vec();
            abs.extend(segs.iter().map(|s| s.to_string()));
            abs
        }
    };
    while !abs.is_empty() && !known.contains(&abs) {
        abs.pop();
    }
    Some(abs)
}

fn resolve(path: &str, here: &[String], known: &BTreeSet<Vec<String>>) -> Option<Vec<String>> {
    resolve_in("physics", path, here, known)
}

#[test]
fn the_physics_modules_form_no_cycle_and_name_no_fmi() {
    check_layers("physics", &["fmi", "canonical_scenes", "model", "TheModel"]);
}

#[test]
fn the_fmi_modules_form_no_cycle_and_name_the_model_only_through_its_binding() {
    check_layers("fmi", &["model", "physics", "canonical_scenes"]);
}

/// Prints the module graph of `src/TOP/` and fails on a cycle or on a path
/// to one of the crate's `forbidden` top modules.
fn check_layers(top: &str, forbidden: &[&str]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(top);
    let files = modules(&root);
    let known: BTreeSet<Vec<String>> = files.keys().cloned().collect();
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    let mut outside = Vec::new();
    for (module, path) in &files {
        let code = code_only(&std::fs::read_to_string(path).unwrap());
        let inline = inline_modules(&code);
        let deps = edges.entry(module.clone()).or_default();
        for (at, p) in named_paths(&code) {
            // Inside `mod tests { ... }` the path starts one module further down.
            let mut here = module.clone();
            here.extend(inline.iter().filter(|(s, e, _)| *s < at && at < *e).map(|(_, _, n)| n.clone()));
            match resolve_in(top, &p, &here, &known) {
                Some(target) if target.first().is_some_and(|t| t.starts_with("<crate::")) => {
                    let t = &target[0];
                    if forbidden.iter().any(|f| *t == format!("<crate::{f}>")) {
                        outside.push(format!("{} names {p}", path.display()));
                    }
                }
                Some(target) if target != *module => {
                    deps.insert(target);
                }
                _ => {}
            }
        }
    }
    let name = |m: &Vec<String>| if m.is_empty() { top.to_string() } else { m.join("::") };
    for (m, deps) in &edges {
        println!("{} -> {}", name(m), deps.iter().map(name).collect::<Vec<_>>().join(", "));
    }
    assert!(outside.is_empty(), "src/{top} names a module it must not know: {outside:#?}");
    // Depth-first search for a back edge.
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    let mut mark: BTreeMap<&Vec<String>, Mark> = edges.keys().map(|k| (k, Mark::New)).collect();
    fn visit<'a>(
        m: &'a Vec<String>,
        edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        mark: &mut BTreeMap<&'a Vec<String>, Mark>,
        path: &mut Vec<&'a Vec<String>>,
    ) -> Option<Vec<&'a Vec<String>>> {
        mark.insert(m, Mark::Open);
        path.push(m);
        for d in edges.get(m).into_iter().flatten() {
            match mark.get(d).copied().unwrap_or(Mark::Done) {
                Mark::Open => {
                    let from = path.iter().position(|p| *p == d).unwrap();
                    let mut cycle = path[from..].to_vec();
                    cycle.push(d);
                    return Some(cycle);
                }
                Mark::New => {
                    if let Some(c) = visit(d, edges, mark, path) {
                        return Some(c);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        mark.insert(m, Mark::Done);
        None
    }
    for m in edges.keys() {
        if mark[m] == Mark::New {
            if let Some(cycle) = visit(m, &edges, &mut mark, &mut Vec::new()) {
                panic!("import cycle in src/{top}: {}", cycle.iter().map(|m| name(m)).collect::<Vec<_>>().join(" -> "));
            }
        }
    }
}

/// The reader above finds the cycles it is meant to find.
#[test]
fn the_reader_sees_use_trees_and_relative_paths() {
    let known: BTreeSet<Vec<String>> =
        [vec![], vec!["space".to_string()], vec!["space".to_string(), "full".to_string()], vec!["engine".to_string()]].into_iter().collect();
    let here = vec!["space".to_string()];
    let code = code_only("use super::engine::{self, Stepper};\npub use full::Full; // use crate::fmi::x;\nlet s = \"use crate::fmi\";");
    let paths: Vec<String> = named_paths(&code).into_iter().map(|(_, p)| p).collect();
    let targets: BTreeSet<Vec<String>> = paths.iter().filter_map(|p| resolve(p, &here, &known)).collect();
    assert_eq!(inline_modules("fn f() { }\nmod tests {\n fn g() { }\n}"), vec![(21, 35, "tests".to_string())]);
    assert!(targets.contains(&vec!["engine".to_string()]), "{paths:?}");
    assert!(targets.contains(&vec!["space".to_string(), "full".to_string()]), "{paths:?}");
    assert!(!paths.iter().any(|p| p.contains("fmi")), "comments and strings are not code: {paths:?}");
}
