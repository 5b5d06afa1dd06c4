//! `cargo xtask fmu [--scene NAME] [--nx N] [--ny N] [--modes R] [--set NAME=VALUE]... [--bake] [--out PATH]`
//!
//! Builds the cdylib in release mode and packs the FMU: modelDescription.xml
//! (generated from modelDescription/variables.toml with the chosen start
//! values), terminalsAndIcons/terminalsAndIcons.xml (the holders and the load
//! node as terminals, from the same table: modelDescription/generate/terminals.rs),
//! binaries/x86_64-linux/ModalMassSpring.so, documentation/index.html
//! and resources/startValues.txt (the same start values, read by the binary).
//! With `--bake`, also resources/setup.bin: the modal or adaptive set-up of
//! those start values (basis, equilibrium, cubature sets, and what the
//! adaptive set-up chose), computed once here by the `bake` example so that
//! instantiation skips it while the parameters match.

use crate::cli::{self, Long, ValueExt};
use crate::generate;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use zip::write::SimpleFileOptions;

const PLATFORM: &str = "x86_64-linux";

struct Options {
    scene: Option<String>,
    nx: Option<u64>,
    ny: Option<u64>,
    modes: Option<u64>,
    /// Other scalar start values, `--set NAME=VALUE` (VALUE as given: a number or an enumeration item's name).
    set: Vec<(String, String)>,
    bake: bool,
    out: Option<PathBuf>,
}

const USAGE: &str = "\
usage: cargo xtask fmu [--scene NAME] [--nx N] [--ny N] [--modes R] [--set NAME=VALUE]... [--bake] [--out PATH]

  --scene NAME  start values of a canonical scene (modelDescription/variables.toml)
  --nx N        nodes per row (the load column follows the middle of the row)
  --ny N        rows of nodes
  --modes R     modes kept (nModes)
  --set NAME=VALUE  the start value of another scalar parameter or input; an
                enumeration by item name or value, e.g. --set nHolders=2
                --set fixedNodes=2 --set reduction=adaptive; repeatable
  --bake        also resources/setup.bin: the modal or adaptive set-up of these start values
  --out PATH    where the FMU goes (default target/fmu/NAME.fmu, NAME the scene or
                ModalMassSpring, with -nxN, -nyN, -modesR appended when given)";

fn parse(args: &[String]) -> Result<Option<Options>, cli::Error> {
    let mut o = Options { scene: None, nx: None, ny: None, modes: None, set: Vec::new(), bake: false, out: None };
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Long("scene") => o.scene = Some(p.value()?.string()?),
            Long("nx") => o.nx = Some(p.value()?.parse()?),
            Long("ny") => o.ny = Some(p.value()?.parse()?),
            Long("modes") => o.modes = Some(p.value()?.parse()?),
            Long("set") => {
                let pair = p.value()?.string()?;
                let (name, value) = pair.split_once('=').ok_or_else(|| cli::Error::from(format!("--set {pair}: expected NAME=VALUE")))?;
                o.set.push((name.trim().to_string(), value.trim().to_string()));
            }
            Long("out") => o.out = Some(PathBuf::from(p.value()?)),
            Long("bake") => o.bake = true,
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(o))
}

/// Set (by `cargo xtask test`): [`build_library`] builds the library
/// together with the `bake` example. An example's dev-dependencies turn on
/// features of the library's own dependencies (fmi-sys, log, serde_core,
/// zerocopy, ...), so the library alone and the library under an example are
/// two builds of it, each overwriting the other's shared library: in a run of
/// the whole suite, which builds examples between FMUs, the library was
/// compiled anew at each switch (about 45 s each).
pub const WITH_EXAMPLES: &str = "MMS_LIBRARY_WITH_EXAMPLES";

/// Builds the FMU's shared library (release, the product's features only;
/// with [`WITH_EXAMPLES`] set, as the examples build it) and returns its path.
pub fn build_library(root: &Path) -> Result<PathBuf, String> {
    let target = crate::setup::target_dir(root);
    let with_examples: &[&str] = if std::env::var_os(WITH_EXAMPLES).is_some() { &["--example", "bake"] } else { &[] };
    let status = Command::new(crate::setup::cargo())
        .current_dir(root)
        .args(["build", "--release", "--lib", "--package", "modal_mass_spring"])
        .args(with_examples)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --release --lib failed".into());
    }
    Ok(target.join("release/libmodal_mass_spring.so"))
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(o) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf();
    let spec = generate::load(&root.join("modelDescription/variables.toml"))?;

    let mut overrides: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    if let Some(s) = &o.scene {
        overrides = spec.scene(s).ok_or(format!("unknown scene {s}; known: {}", spec.scene_names().join(", ")))?;
    }
    for (name, v) in [("nx", o.nx), ("ny", o.ny), ("nModes", o.modes)] {
        if let Some(v) = v {
            overrides.insert(name.into(), vec![v as f64]);
        }
    }
    // The load node's column follows the middle of the row (variables.toml, loadColumn).
    if let (Some(nx), false) = (overrides.get("nx").map(|v| v[0]), overrides.contains_key("loadColumn")) {
        overrides.insert("loadColumn".into(), vec![(nx / 2.0).floor()]);
    }
    for (name, value) in &o.set {
        let var = spec.variable(name).ok_or(format!("--set {name}: no such variable"))?;
        if !var.dimensions.is_empty() || !matches!(var.causality.as_str(), "parameter" | "structuralParameter" | "input") {
            return Err(format!("--set {name}: only scalar parameters and inputs take a start value here"));
        }
        overrides.insert(name.clone(), vec![set_value(&spec, var, value)?]);
    }
    let check = |name: &str| -> Result<(), String> {
        let var = spec.variable(name).unwrap();
        let x = overrides.get(name).map(|v| v[0]);
        match (x, var.min, var.max) {
            (Some(x), Some(lo), _) if x < lo => Err(format!("{name} = {x} is below its minimum {lo}")),
            (Some(x), _, Some(hi)) if x > hi => Err(format!("{name} = {x} is above its maximum {hi}")),
            _ => Ok(()),
        }
    };
    for name in ["nx", "ny", "nModes"].into_iter().chain(o.set.iter().map(|(n, _)| n.as_str())) {
        check(name)?;
    }

    let xml = spec.model_description_xml(&overrides)?;
    let terminals = spec.terminals_and_icons_xml()?;
    let title = match &o.scene {
        Some(s) => format!("{} ({s})", spec.model_name),
        None => spec.model_name.clone(),
    };
    let html = spec.documentation_html(&overrides, &title)?;
    let starts = spec.start_values_text(&overrides)?;

    let lib = build_library(&root)?;
    let target = crate::setup::target_dir(&root);
    let binary = std::fs::read(&lib).map_err(|e| format!("{}: {e}", lib.display()))?;

    let out = o.out.clone().unwrap_or_else(|| {
        let mut name = o.scene.clone().unwrap_or_else(|| spec.model_identifier.clone());
        for (tag, v) in [("nx", o.nx), ("ny", o.ny), ("modes", o.modes)] {
            if let Some(v) = v {
                name.push_str(&format!("-{tag}{v}"));
            }
        }
        for (tag, v) in &o.set {
            name.push_str(&format!("-{tag}{v}"));
        }
        target.join("fmu").join(format!("{name}.fmu"))
    });
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    // Written next to the target and renamed, so a reader never sees half an FMU.
    let tmp = out.with_extension("fmu.part");
    let file = std::fs::File::create(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let opts = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let baked = if o.bake { bake(&root, &target, &starts)? } else { None };
    let mut entries: Vec<(String, &[u8])> = vec![
        ("modelDescription.xml".into(), xml.as_bytes()),
        ("terminalsAndIcons/terminalsAndIcons.xml".into(), terminals.as_bytes()),
        (format!("binaries/{PLATFORM}/{}.so", spec.model_identifier), &binary),
        ("documentation/index.html".into(), html.as_bytes()),
        ("resources/startValues.txt".into(), starts.as_bytes()),
    ];
    if let Some(b) = &baked {
        entries.push(("resources/setup.bin".into(), b));
    }
    for (name, data) in entries {
        zip.start_file(name.as_str(), opts).map_err(|e| e.to_string())?;
        zip.write_all(data).map_err(|e| e.to_string())?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    std::fs::rename(&tmp, &out).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("{}", out.display());
    Ok(())
}

/// The number `--set NAME=VALUE` gives `var`: an enumeration's item by
/// name or by value (one of its items), else the number VALUE.
fn set_value(spec: &generate::Spec, var: &generate::Variable, value: &str) -> Result<f64, String> {
    let items = var.declared_type.as_ref().and_then(|t| spec.enumerations.iter().find(|e| &e.name == t)).map(|e| &e.items);
    if let Some(item) = items.and_then(|items| items.iter().find(|i| i.name == value)) {
        return Ok(item.value as f64);
    }
    let x: f64 = value.parse().map_err(|_| match items {
        Some(items) => format!(
            "--set {}={value}: not an item of {} ({})",
            var.name,
            var.declared_type.as_deref().unwrap_or(""),
            items.iter().map(|i| format!("{} = {}", i.name, i.value)).collect::<Vec<_>>().join(", ")
        ),
        None => format!("--set {}={value}: {value} is not a number", var.name),
    })?;
    if items.is_some_and(|items| !items.iter().any(|i| i.value as f64 == x)) {
        return Err(format!("--set {}={value}: no item of {} has the value {value}", var.name, var.declared_type.as_deref().unwrap_or("")));
    }
    Ok(x)
}

/// Runs the `bake` example on the start values; the bytes of setup.bin, or
/// `None` where there is nothing to bake (full space).
fn bake(root: &Path, target: &Path, starts: &str) -> Result<Option<Vec<u8>>, String> {
    let status = Command::new(crate::setup::cargo())
        .current_dir(root)
        .args(["build", "--release", "--example", "bake"])
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --example bake failed".into());
    }
    let dir = target.join("bake");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let (start_file, out) = (dir.join("startValues.txt"), dir.join("setup.bin"));
    let _ = std::fs::remove_file(&out);
    std::fs::write(&start_file, starts).map_err(|e| format!("{}: {e}", start_file.display()))?;
    let status = Command::new(target.join("release/examples/bake")).arg(&start_file).arg(&out).status().map_err(|e| format!("cannot run the bake: {e}"))?;
    if !status.success() {
        return Err("the bake failed".into());
    }
    Ok(std::fs::read(&out).ok())
}
