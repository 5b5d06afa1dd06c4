//! The FMI layer (`src/fmi/`) is generic: outside the generated variable
//! table (`src/fmi/variables.rs`) it names no variable of the model, neither
//! as a string nor as an identifier (camelCase, snake_case or a `vr::`
//! constant), so adding a port touches the model (`src/model/`) and the
//! table, never the glue.

use std::path::{Path, PathBuf};

/// Variable names that are also generic FMI words the glue may use.
const GENERIC: &[&str] = &[
    // The independent variable: the FMU's time, start time and stop time are the glue's.
    "time",
];

/// Names of every variable of `modelDescription/variables.toml`.
fn variable_names() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("modelDescription/variables.toml")).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let names: Vec<String> = table["variables"].as_array().unwrap().iter().map(|v| v.get("name").and_then(|n| n.as_str()).unwrap().to_string()).collect();
    assert!(names.len() > 30, "{} variables read", names.len());
    names
}

/// Every Rust file under `dir`, recursively (directory modules such as `exports/` too).
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for p in std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()) {
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
    out
}

/// The glue's sources, but the generated table.
fn glue_sources() -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/fmi");
    let mut files: Vec<_> = rust_files(&dir)
        .into_iter()
        .filter(|p| p != &dir.join("variables.rs"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p.strip_prefix(&dir).unwrap().to_path_buf(), text)
        })
        .collect();
    files.sort();
    assert!(files.len() >= 10, "{} glue files", files.len());
    assert!(files.iter().any(|(p, _)| p.starts_with("exports")), "the exports module is read");
    files
}

/// The words of a camelCase name, lower case: `loadNodeVX` -> load, node, v, x.
fn words(name: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for c in name.chars() {
        if c.is_uppercase() || out.is_empty() {
            out.push(String::new());
        }
        out.last_mut().unwrap().extend(c.to_lowercase());
    }
    out
}

/// Identifier-like tokens of `text` (also those inside strings and comments), with their lines.
fn tokens(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        out.extend(line.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|t| !t.is_empty()).map(|t| (n + 1, t)));
    }
    out
}

/// `token` names the variable of camelCase `name` with `words`: it is the
/// name, or its words follow each other among the token's `_`-separated
/// parts (`load_column_chosen`, `LOAD_COLUMN`).
fn names(token: &str, name: &str, words: &[String]) -> bool {
    if token == name {
        return true;
    }
    let parts: Vec<String> = token.split('_').filter(|p| !p.is_empty()).map(str::to_lowercase).collect();
    parts.windows(words.len()).any(|w| w == words)
}

/// Every place the glue names a model variable.
fn hits() -> Vec<String> {
    let names_ = variable_names();
    let mut found = Vec::new();
    for (path, text) in glue_sources() {
        let file = path.display().to_string();
        for (line, token) in tokens(&text) {
            for name in names_.iter().filter(|n| !GENERIC.contains(&n.as_str())) {
                if names(token, name, &words(name)) {
                    found.push(format!("src/fmi/{file}:{line}: {token} names {name}"));
                }
            }
        }
        for (n, l) in text.lines().enumerate() {
            if l.contains("vr::") {
                found.push(format!("src/fmi/{file}:{}: a value reference constant: {}", n + 1, l.trim()));
            }
        }
    }
    found
}

#[test]
fn the_glue_names_no_model_variable() {
    let found = hits();
    assert!(found.is_empty(), "the FMI layer names variables of the model (move the rule to src/model/):\n{}", found.join("\n"));
}

#[test]
fn the_matcher_finds_names_in_every_form() {
    let w = words("loadColumn");
    assert_eq!(w, ["load", "column"]);
    for t in ["loadColumn", "load_column_chosen", "LOAD_COLUMN", "chosen_load_column"] {
        assert!(names(t, "loadColumn", &w), "{t}");
    }
    for t in ["load", "column", "loadcolumns", "load_node"] {
        assert!(!names(t, "loadColumn", &w), "{t}");
    }
    let text = "let x = vr::NX; log(\"forceResidual passed\");";
    let toks: Vec<&str> = tokens(text).into_iter().map(|(_, t)| t).collect();
    assert!(toks.iter().any(|t| names(t, "nx", &words("nx"))));
    assert!(toks.iter().any(|t| names(t, "forceResidual", &words("forceResidual"))));
}
