//! `cargo xtask ssp [--anchor relative|absolute] [--sheets NAME] [--out PATH]`
//!
//! The chain of python/chain.py (sheet B hanging from sheet A's load node)
//! as an SSP 1.0 archive: `SystemStructure.ssd` with one component per
//! sheet, the connections of `chain.LINKS`, and per sheet a parameter set
//! `resources/NAME.ssv` (named [`PARAMETER_SET`]) with the values of
//! `chain.SHEETS` and `chain.COMMON`, and the FMU it runs,
//! `resources/ModalMassSpring[-nxN][-nyN][-modesR].fmu`.
//!
//! The sheets' values are read from python/chain.py itself (in the project's
//! venv), so the archive is the chain the plain master runs. Structural
//! parameters (nx, ny, nModes) are not in the parameter sets: each sheet's
//! grid is baked into its FMU's start values (`cargo xtask fmu --nx --ny
//! --modes`), since an importer that applies parameter sets in
//! Initialization Mode (Ecos) cannot set them there. With `--anchor
//! relative` (the default, as `chain.run_master`) a connection into an
//! anchor subtracts the source's value before initialization, B.anchor =
//! A.loadNode - A.loadNode(0), as an `ssc:LinearTransformation` (offset
//! read from the sheet's FMU through fmpy); `absolute` connects the values
//! as they are, as a container does. docs/usage.md (Co-simulation masters)
//! says what Ecos does with it.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use zip::write::SimpleFileOptions;

use crate::cli::{self, Long, ValueExt};
use crate::generate::{self, Spec};
use crate::setup;

/// The name of every sheet's parameter set (Ecos: `init(parameter_set=...)`).
pub const PARAMETER_SET: &str = "chain";

const USAGE: &str = "\
usage: cargo xtask ssp [--anchor relative|absolute] [--sheets NAME] [--out PATH]

  --anchor WHICH  relative (default, as chain.run_master): B.anchor = A.loadNode - A.loadNode(0),
                  an ssc:LinearTransformation on the anchor's connections; absolute: A.loadNode as
                  it is (B starts at rest hanging from A's load node, as in a container)
  --sheets NAME   the pair of python/chain.py (a key of SHEET_SETS; default: default)
  --out PATH      where the archive goes (default target/ssp/chain[-NAME][-absolute].ssp)";

struct Options {
    relative: bool,
    sheets: String,
    out: Option<PathBuf>,
}

fn parse(args: &[String]) -> Result<Option<Options>, cli::Error> {
    let mut o = Options { relative: true, sheets: "default".into(), out: None };
    let mut p = cli::parser(args);
    while let Some(arg) = p.next()? {
        match arg {
            Long("anchor") => {
                o.relative = match p.value()?.string()?.as_str() {
                    "relative" => true,
                    "absolute" => false,
                    other => return Err(format!("--anchor: {other} is neither relative nor absolute").into()),
                }
            }
            Long("sheets") => o.sheets = p.value()?.string()?,
            Long("out") => o.out = Some(PathBuf::from(p.value()?)),
            arg if cli::is_help(&arg) => return Ok(None),
            arg => return Err(arg.unexpected()),
        }
    }
    Ok(Some(o))
}

/// The chain as python/chain.py has it: each sheet's parameters (its own
/// and the common ones, in chain.py's order) and the links (source sheet,
/// output, sink sheet, input).
struct Chain {
    sheets: BTreeMap<String, Vec<(String, f64)>>,
    links: Vec<[String; 4]>,
}

/// Prints the pair's parameters and the links, one per line.
const READ_CHAIN: &str = "
import sys
sys.path.insert(0, 'python')
import chain
for s, p in chain.SHEET_SETS[sys.argv[1]].items():
    for k, v in {**p, **chain.COMMON}.items():
        print('param', s, k, repr(v))
for link in chain.LINKS:
    print('link', *link)
";

/// Prints the values of the named outputs of sheet NAME before
/// initialization, its parameters set as `chain.run_master` sets them
/// (where it reads A.loadNode(0)). Arguments: FMU, NAME, SHEETS, outputs.
const READ_START: &str = "
import shutil
import sys
sys.path.insert(0, 'python')
import chain
from fmpy import extract, read_model_description
fmu, name, sheets, names = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
unzipdir = extract(fmu)
sheet = chain.Sheet(fmu, unzipdir, read_model_description(fmu), name, chain.SHEET_SETS[sheets][name])
try:
    print(*map(repr, sheet.get(*names)))
finally:
    sheet.slave.freeInstance()  # never initialized: no fmi3Terminate
    shutil.rmtree(unzipdir, ignore_errors=True)
";

/// Runs a script of the project's Python (from the repository's root) and returns what it printed.
fn python(script: &str, args: &[&str]) -> Result<String, String> {
    let python = setup::python();
    if !python.exists() {
        return Err("no .venv: run `cargo xtask setup` first (the chain is read from python/chain.py)".into());
    }
    let out = Command::new(python).current_dir(setup::root()).arg("-c").arg(script).args(args).output().map_err(|e| format!("cannot run python: {e}"))?;
    if !out.status.success() {
        return Err(format!("python failed: {}", String::from_utf8_lossy(&out.stderr)));
    }
    String::from_utf8(out.stdout).map_err(|e| e.to_string())
}

fn read_chain(sheets: &str) -> Result<Chain, String> {
    let mut chain = Chain { sheets: BTreeMap::new(), links: Vec::new() };
    for line in python(READ_CHAIN, &[sheets])?.lines() {
        match line.split_whitespace().collect::<Vec<_>>()[..] {
            ["param", s, k, v] => {
                let v: f64 = v.parse().map_err(|_| format!("chain.py: {s}.{k} = {v} is not a number"))?;
                chain.sheets.entry(s.into()).or_default().push((k.into(), v));
            }
            ["link", s, o, d, i] => chain.links.push([s.into(), o.into(), d.into(), i.into()]),
            _ => return Err(format!("unexpected line from chain.py: {line}")),
        }
    }
    Ok(chain)
}

/// The structural parameters `cargo xtask fmu` bakes, and its options for them.
const FMU_OPTIONS: [(&str, &str); 3] = [("nx", "nx"), ("ny", "ny"), ("nModes", "modes")];

/// One component: its FMU (built by `cargo xtask fmu` with the sheet's
/// grid) and the parameters of its parameter set.
struct Component {
    fmu: PathBuf,
    parameters: Vec<(String, f64)>,
}

fn component(spec: &Spec, target: &Path, sheet: &str, values: &[(String, f64)]) -> Result<Component, String> {
    let (mut structural, mut parameters) = (BTreeMap::new(), Vec::new());
    for (k, v) in values {
        let var = spec.variable(k).ok_or(format!("chain.py: sheet {sheet} sets {k}, which the FMU does not have"))?;
        if var.causality == "structuralParameter" {
            structural.insert(k.as_str(), *v);
        } else if var.holds_value() {
            parameters.push((k.clone(), *v));
        } else {
            return Err(format!("sheet {sheet}: {k} is a {}, not a parameter", var.causality));
        }
    }
    if let Some(k) = structural.keys().find(|k| !FMU_OPTIONS.iter().any(|(name, _)| name == *k)) {
        return Err(format!("sheet {sheet}: the structural parameter {k} cannot be baked by cargo xtask fmu"));
    }
    // The options and the file name of `cargo xtask fmu`, in its order.
    let (mut fmu_args, mut name) = (Vec::new(), spec.model_identifier.clone());
    for (k, option) in FMU_OPTIONS {
        if let Some(v) = structural.get(k) {
            fmu_args.extend([format!("--{option}"), format!("{v}")]);
            name.push_str(&format!("-{option}{v}"));
        }
    }
    let fmu = target.join("fmu").join(format!("{name}.fmu"));
    fmu_args.extend(["--out".to_string(), fmu.display().to_string()]);
    crate::fmu::main(&fmu_args)?;
    Ok(Component { fmu, parameters })
}

/// An XML attribute value.
fn attr(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('"', "&quot;")
}

/// The parameter set of one sheet (SSV 1.0), typed as the model description types them.
fn ssv(spec: &Spec, sheet: &str, parameters: &[(String, f64)]) -> Result<String, String> {
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(&format!(
        "<ssv:ParameterSet xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" version=\"1.0\" name=\"{PARAMETER_SET}\" \
         description=\"Sheet {sheet} of python/chain.py (its structural parameters are the start values of its FMU)\">\n  <ssv:Parameters>\n"
    ));
    for (name, v) in parameters {
        let var = spec.variable(name).unwrap();
        let value = match var.ty.as_str() {
            "Float64" => format!("<ssv:Real value=\"{v}\"/>"),
            "UInt64" if v.fract() == 0.0 && (0.0..=i32::MAX as f64).contains(v) => format!("<ssv:Integer value=\"{v}\"/>"),
            "Boolean" => format!("<ssv:Boolean value=\"{}\"/>", *v != 0.0),
            "Enumeration" => {
                let t = var.declared_type.as_deref().unwrap_or_default();
                let item = spec.enumerations.iter().find(|e| e.name == t).and_then(|e| e.items.iter().find(|i| i.value as f64 == *v));
                format!("<ssv:Enumeration value=\"{}\"/>", attr(&item.ok_or(format!("sheet {sheet}: {name} = {v} is no item of {t}"))?.name))
            }
            ty => return Err(format!("sheet {sheet}: {name} = {v} cannot be a {ty} parameter of SSV 1.0")),
        };
        x.push_str(&format!("    <ssv:Parameter name=\"{}\">{value}</ssv:Parameter>\n", attr(name)));
    }
    x.push_str("  </ssv:Parameters>\n</ssv:ParameterSet>\n");
    Ok(x)
}

/// The connectors of a component: every scalar Float64 input and output of the FMU.
fn connectors(spec: &Spec) -> String {
    let mut x = String::new();
    for v in spec.variables.iter().filter(|v| v.ty == "Float64" && v.dimensions.is_empty() && matches!(v.causality.as_str(), "input" | "output")) {
        x.push_str(&format!("          <ssd:Connector name=\"{}\" kind=\"{}\"><ssc:Real/></ssd:Connector>\n", attr(&v.name), v.causality));
    }
    x
}

/// SystemStructure.ssd: the components (FMU and parameter set of each
/// sheet) and the connections, with their offsets (sink -> offset).
fn ssd(spec: &Spec, components: &BTreeMap<String, (String, String)>, chain: &Chain, offsets: &BTreeMap<String, f64>, relative: bool) -> String {
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(
        "<ssd:SystemStructureDescription xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\" \
         xmlns:ssd=\"http://ssp-standard.org/SSP1/SystemStructureDescription\" \
         xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" \
         name=\"ModalMassSpringChain\" version=\"1.0\" generationTool=\"cargo xtask ssp\">\n",
    );
    let anchor = if relative { "B.anchor = A.loadNode - A.loadNode(0)" } else { "B.anchor = A.loadNode" };
    x.push_str(&format!(
        "  <ssd:System name=\"chain\" description=\"python/chain.py: sheet B hangs from the load node of sheet A ({anchor}, A.load = B.anchorForce)\">\n    <ssd:Elements>\n"
    ));
    for (name, (fmu, ssv)) in components {
        x.push_str(&format!(
            "      <ssd:Component name=\"{}\" type=\"application/x-fmu-sharedlibrary\" source=\"{}\" implementation=\"CoSimulation\">\n        <ssd:Connectors>\n{}        </ssd:Connectors>\n",
            attr(name),
            attr(fmu),
            connectors(spec)
        ));
        x.push_str(&format!("        <ssd:ParameterBindings>\n          <ssd:ParameterBinding source=\"{}\"/>\n        </ssd:ParameterBindings>\n", attr(ssv)));
        x.push_str("      </ssd:Component>\n");
    }
    x.push_str("    </ssd:Elements>\n    <ssd:Connections>\n");
    for [s, o, d, i] in &chain.links {
        let open = format!(
            "      <ssd:Connection startElement=\"{}\" startConnector=\"{}\" endElement=\"{}\" endConnector=\"{}\"",
            attr(s),
            attr(o),
            attr(d),
            attr(i)
        );
        match offsets.get(&format!("{d}.{i}")) {
            Some(offset) => x.push_str(&format!("{open}>\n        <ssc:LinearTransformation factor=\"1\" offset=\"{offset}\"/>\n      </ssd:Connection>\n")),
            None => x.push_str(&format!("{open}/>\n")),
        }
    }
    x.push_str("    </ssd:Connections>\n  </ssd:System>\n</ssd:SystemStructureDescription>\n");
    x
}

pub fn main(args: &[String]) -> Result<(), String> {
    let Some(o) = cli::options(parse(args), USAGE)? else { return Ok(()) };
    let root = setup::root();
    let spec = generate::load(&root.join("modelDescription/variables.toml"))?;
    let target = setup::target_dir(&root);
    let chain = read_chain(&o.sheets)?;
    if chain.sheets.is_empty() {
        return Err(format!("chain.py's pair {} has no sheet", o.sheets));
    }

    let mut built = BTreeMap::new();
    for (sheet, values) in &chain.sheets {
        built.insert(sheet.clone(), component(&spec, &target, sheet, values)?);
    }
    for [s, o_, d, i] in &chain.links {
        for (sheet, name, causality) in [(s, o_, "output"), (d, i, "input")] {
            if !built.contains_key(sheet) || spec.variable(name).is_none_or(|v| v.causality != causality || v.ty != "Float64") {
                return Err(format!("chain.py links {s}.{o_} to {d}.{i}: {sheet}.{name} is not a Float64 {causality} of a sheet"));
            }
        }
    }
    // The relative anchor: a connection into an anchor subtracts the source's value before initialization.
    let mut offsets = BTreeMap::new();
    if o.relative {
        for [s, o_, d, i] in chain.links.iter().filter(|l| l[3].starts_with("anchor")) {
            let fmu = built[s].fmu.display().to_string();
            let start = python(READ_START, &[&fmu, s, &o.sheets, o_])?;
            let start: f64 = start.trim().parse().map_err(|_| format!("{s}.{o_} before initialization: {start}"))?;
            offsets.insert(format!("{d}.{i}"), -start);
        }
    }

    // The archive's files: one FMU per grid, one parameter set per sheet.
    let mut files: BTreeMap<String, Vec<u8>> = BTreeMap::new();
    let mut components = BTreeMap::new();
    for (sheet, c) in &built {
        let fmu = format!("resources/{}", c.fmu.file_name().unwrap().to_string_lossy());
        files.insert(fmu.clone(), std::fs::read(&c.fmu).map_err(|e| format!("{}: {e}", c.fmu.display()))?);
        let ssv_name = format!("resources/{sheet}.ssv");
        files.insert(ssv_name.clone(), ssv(&spec, sheet, &c.parameters)?.into_bytes());
        components.insert(sheet.clone(), (fmu, ssv_name));
    }
    files.insert("SystemStructure.ssd".into(), ssd(&spec, &components, &chain, &offsets, o.relative).into_bytes());

    let out = o.out.clone().unwrap_or_else(|| {
        let mut name = String::from("chain");
        if o.sheets != "default" {
            name.push_str(&format!("-{}", o.sheets));
        }
        if !o.relative {
            name.push_str("-absolute");
        }
        target.join("ssp").join(format!("{name}.ssp"))
    });
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    // Written next to the target and renamed, so a reader never sees half an archive.
    let tmp = out.with_extension("ssp.part");
    let file = std::fs::File::create(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    // SystemStructure.ssd first; the FMUs are zip archives already.
    let ssd_first = files.remove_entry("SystemStructure.ssd").into_iter().chain(files);
    for (name, data) in ssd_first {
        let method = if name.ends_with(".fmu") { zip::CompressionMethod::Stored } else { zip::CompressionMethod::Deflated };
        zip.start_file(name.as_str(), SimpleFileOptions::default().compression_method(method)).map_err(|e| e.to_string())?;
        zip.write_all(&data).map_err(|e| e.to_string())?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    std::fs::rename(&tmp, &out).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("{}", out.display());
    Ok(())
}
