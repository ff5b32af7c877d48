//! The harness's layers, checked from its source: data flows one way (cli → commands →
//! charts/distributed → args → pipeline → plan → scene/metrics → builtin/tf → io/reference/dispatch →
//! core), no command imports another,
//! nothing imports `cli`, and files stay small enough to read (issue 16's "must show" 1 and 2).
//!
//! A module's dependencies are the `crate::…` and `super::…` paths in its code (`use` lines and
//! inline paths alike; unit tests after `#[cfg(test)]` are not counted). Modules are the top-level
//! ones, with `commands`, `pipeline` and `charts` split into their files; a group's `mod.rs`
//! declaring and re-exporting its own files is not a dependency.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const GROUPS: [&str; 3] = ["commands", "pipeline", "charts"];

/// Largest file anywhere in `core/src` and `std-harness/src`, unless it says why it stays whole.
const MAX_LINES: usize = 600;
/// Largest command file: a command is a thin adapter.
const MAX_COMMAND_LINES: usize = 300;
/// A module doc line starting with this states why a file over `MAX_LINES` stays whole.
const WHOLE_MARKER: &str = "//! Why one file:";

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable source folder") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rs_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of a file under `src`: `commands/render.rs` → [commands, render],
/// `pipeline/mod.rs` → [pipeline], `lib.rs` → [].
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("file under src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

/// The layer node of an absolute module path (`None` for the crate root's own items).
fn node(path: &[String], files: &BTreeSet<Vec<String>>) -> Option<String> {
    let first = path.first()?;
    if !files.contains(&vec![first.clone()]) {
        return None; // an item of the crate root: CliError, say!
    }
    if GROUPS.contains(&first.as_str()) && path.len() > 1 {
        let sub = vec![first.clone(), path[1].clone()];
        if files.contains(&sub) {
            return Some(format!("{first}/{}", path[1]));
        }
    }
    Some(first.clone())
}

fn rank(node: &str) -> u32 {
    match node.split('/').next().unwrap_or(node) {
        "cli" => 9,
        "commands" => 8,
        "charts" => 7,
        // Scale-out: bricks rendered by the pipeline and composited; commands call it.
        "distributed" => 7,
        // The command line's flags (clap types) and their resolution into inputs and a plan,
        // once (issue 76): above the pipeline, which reads only the typed values.
        "args" => 6,
        "pipeline" => 5,
        // The render plan and inputs: typed values, read by the pipeline.
        "plan" => 4,
        // What is rendered (the scene: source, camera, classification, kernel), typed; and the
        // measures of error.
        "scene" | "metrics" => 3,
        // The built-in volume and the transfer functions.
        "builtin" | "tf" => 2,
        "io" | "reference" => 1,
        // Threads that may fail to start, the one table-size dispatch, and a render's
        // interruption from outside: used by io, the reference and the pipeline alike.
        "threads" | "dispatch" | "cancel" => 0,
        other => panic!("module '{other}' has no layer: add it to tests/layering.rs"),
    }
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Every path that follows `prefix` in `code`, as identifier lists, expanding one level of
/// `{a, b::c}` groups.
fn paths_after(code: &str, prefix: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        let before_ok = rest[..i].chars().next_back().is_none_or(|c| !is_ident(c));
        rest = &rest[i + prefix.len()..];
        if !before_ok {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                out.push(idents(item.trim()));
            }
        } else {
            out.push(idents(rest));
        }
    }
    out.retain(|p| !p.is_empty());
    out
}

/// `a::b::c…` at the start of `s` as [a, b, c].
fn idents(s: &str) -> Vec<String> {
    let mut v = Vec::new();
    let mut s = s;
    loop {
        let end = s.find(|c: char| !is_ident(c)).unwrap_or(s.len());
        if end == 0 {
            break;
        }
        v.push(s[..end].to_string());
        match s[end..].strip_prefix("::") {
            Some(r) if !r.starts_with('{') => s = r,
            Some(r) => {
                // `a::{b, c}`: the module `a` is what matters for the layer.
                let _ = r;
                break;
            }
            None => break,
        }
    }
    v
}

/// Code of a file without comments and without its unit tests.
fn code_of(text: &str) -> String {
    let body = text.split("#[cfg(test)]").next().unwrap_or(text);
    body.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

struct Harness {
    /// node → nodes it depends on.
    edges: BTreeMap<String, BTreeSet<String>>,
}

fn harness() -> Harness {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let src = root.join("std-harness/src");
    let mut files = Vec::new();
    rs_files(&src, &mut files);
    let paths: BTreeSet<Vec<String>> = files.iter().map(|f| module_path(&src, f)).collect();
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        if file
            .file_name()
            .is_some_and(|n| n == "main.rs" || n == "lib.rs")
        {
            continue;
        }
        let me_path = module_path(&src, file);
        let Some(me) = node(&me_path, &paths) else {
            continue;
        };
        let is_mod_rs = file.file_name().is_some_and(|n| n == "mod.rs");
        let code = code_of(&std::fs::read_to_string(file).expect("readable file"));
        let mut targets: Vec<Vec<String>> = paths_after(&code, "crate::");
        // `super::x` from `a/b.rs` is `a::x`; from `a/b/mod.rs` it is `a::x` as well.
        let parent: Vec<String> = me_path[..me_path.len().saturating_sub(1)].to_vec();
        for p in paths_after(&code, "super::") {
            let mut abs = parent.clone();
            abs.extend(p);
            targets.push(abs);
        }
        for t in targets {
            let Some(to) = node(&t, &paths) else {
                continue;
            };
            // A group's mod.rs declaring or re-exporting its own files is not a dependency.
            let own_child = is_mod_rs && to.starts_with(&format!("{me}/"));
            if to != me && !own_child {
                edges.entry(me.clone()).or_default().insert(to);
            }
        }
        edges.entry(me).or_default();
    }
    Harness { edges }
}

#[test]
fn data_flows_one_way() {
    let h = harness();
    let mut wrong = Vec::new();
    for (from, tos) in &h.edges {
        for to in tos {
            let same_group = from.split('/').next() == to.split('/').next();
            let ok = if same_group {
                // Within a group (pipeline's files, io's formats) only commands are barred from
                // each other; cycles are caught below.
                !from.starts_with("commands/")
            } else {
                rank(to) < rank(from)
            };
            if !ok {
                wrong.push(format!("{from} → {to}"));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "imports against the layers (cli → commands → charts → args → pipeline → plan → scene/metrics → builtin/tf → io/…):\n{}",
        wrong.join("\n")
    );
    assert!(
        h.edges.contains_key("pipeline/ends") && h.edges.contains_key("commands/render"),
        "the scan found the harness's modules: {:?}",
        h.edges.keys().collect::<Vec<_>>()
    );
}

/// The pipeline's folders are its stages (issue 41): `stages` (load → prepare → bands) import
/// neither `ends` (what draws a frame) nor `quality` (what chooses and measures plans), and
/// `ends` import no `quality`.
#[test]
fn the_pipelines_folders_flow_one_way() {
    let h = harness();
    let order = |n: &str| match n {
        "pipeline/stages" => Some(0),
        "pipeline/ends" => Some(1),
        "pipeline/quality" => Some(2),
        _ => None,
    };
    for group in ["pipeline/stages", "pipeline/ends", "pipeline/quality"] {
        assert!(h.edges.contains_key(group), "{group} scanned");
    }
    for (from, tos) in &h.edges {
        let Some(f) = order(from) else { continue };
        for to in tos {
            if let Some(t) = order(to) {
                assert!(t <= f, "{from} imports {to}: against the pipeline's flow");
            }
        }
    }
}

#[test]
fn no_import_cycle() {
    let h = harness();
    // Depth-first search with colours; report the first cycle found.
    fn visit(
        n: &str,
        h: &Harness,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(n) {
            Some(2) => return None,
            Some(1) => {
                let at = stack.iter().position(|s| s == n).unwrap_or(0);
                let mut cycle = stack[at..].to_vec();
                cycle.push(n.to_string());
                return Some(cycle);
            }
            _ => {}
        }
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in h.edges.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, h, state, stack) {
                return Some(c);
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in h.edges.keys() {
        let mut stack = Vec::new();
        if let Some(cycle) = visit(n, &h, &mut state, &mut stack) {
            panic!("import cycle: {}", cycle.join(" → "));
        }
    }
}

#[test]
fn nothing_imports_the_command_line_or_another_command() {
    let h = harness();
    for (from, tos) in &h.edges {
        assert!(!tos.contains("cli"), "{from} imports cli");
        if from.starts_with("commands/") {
            let others: Vec<&String> = tos.iter().filter(|t| t.starts_with("commands")).collect();
            assert!(others.is_empty(), "{from} imports {others:?}");
        }
    }
}

/// The pipeline renders `(&Prepared, &Plan)` and prepares from `Scene` (issue 41): the
/// command-line struct is resolved into those once, in `plan.rs`, and no file of `pipeline/`
/// names it (in code; comments may).
#[test]
fn the_pipeline_never_reads_the_command_line_struct() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("std-harness/src/pipeline");
    let mut files = Vec::new();
    rs_files(&dir, &mut files);
    assert!(files.len() > 10, "the pipeline's files: {files:?}");
    let named: Vec<String> = files
        .iter()
        .filter(|f| {
            let code = code_of(&std::fs::read_to_string(f).unwrap());
            names_render_args(&code)
        })
        .map(|f| f.display().to_string())
        .collect();
    assert!(named.is_empty(), "RenderArgs named in {named:?}");
    // The checker sees the name where it is code, and only there.
    assert!(names_render_args(&code_of(
        "fn f(a: &crate::args::RenderArgs) {}"
    )));
    assert!(!names_render_args(&code_of(
        "// RenderArgs\nfn f(a: &MyRenderArgs) {}"
    )));
}

/// No clap type below the command line (issue 76): no file of `pipeline/`, `plan/` or `scene.rs` imports
/// `crate::args` (in code; comments may name it), so the pipeline reads only the typed inputs
/// and plan that `args::resolve` makes once.
#[test]
fn the_pipeline_and_the_plan_import_no_command_line_module() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("std-harness/src");
    let mut files = vec![src.join("plan.rs"), src.join("scene.rs")];
    rs_files(&src.join("pipeline"), &mut files);
    rs_files(&src.join("plan"), &mut files);
    assert!(
        files.len() > 20,
        "the pipeline's and plan's files: {files:?}"
    );
    let importing: Vec<String> = files
        .iter()
        .filter(|f| imports_args(&code_of(&std::fs::read_to_string(f).unwrap())))
        .map(|f| f.display().to_string())
        .collect();
    assert!(
        importing.is_empty(),
        "crate::args imported in {importing:?}"
    );
    // The checker sees an import or an inline path in code, and only there.
    assert!(imports_args(&code_of("use crate::args::Lod;")));
    assert!(imports_args(&code_of("fn f() { crate::args::plan(a) }")));
    assert!(imports_args(&code_of("use crate::{args::Lod, io};")));
    assert!(!imports_args(&code_of(
        "// crate::args::Lod\nuse crate::argsx::A;"
    )));
}

/// Whether `code` names the `args` module from the crate root.
fn imports_args(code: &str) -> bool {
    paths_after(code, "crate::")
        .iter()
        .any(|p| p.first().is_some_and(|m| m == "args"))
}

/// Whether `code` has the identifier `RenderArgs` (not as part of a longer one).
fn names_render_args(code: &str) -> bool {
    code.split(|c: char| !is_ident(c))
        .any(|t| t == "RenderArgs")
}

/// A runtime table size becomes a const generic in one place (`dispatch::with_size`, issue 41):
/// every other site writes its work once, generic over N (`dispatch::TableSize`), instead of
/// expanding a match over every size where it stands.
#[test]
fn table_sizes_are_dispatched_in_one_place() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["std-harness/src", "python/src", "tests", "benches"] {
        rs_files(&root.join(dir), &mut files);
    }
    let sites: Vec<String> = files
        .iter()
        .filter(|f| !f.ends_with("dispatch.rs") && !f.ends_with("layering.rs"))
        .filter(|f| {
            let code = code_of(&std::fs::read_to_string(f).unwrap_or_default());
            code.contains("with_table_size!")
        })
        .map(|f| f.display().to_string())
        .collect();
    assert!(sites.is_empty(), "the size match expanded at {sites:?}");
}

#[test]
fn the_checker_sees_a_planted_cycle() {
    // The scan itself: a command that imported another, and an upward import, would be seen.
    let code = "use crate::commands::render::run;\nuse super::{prepare::Prepared, load};\nfn f() { crate::io::read_file(p); }";
    let found = paths_after(code, "crate::");
    assert_eq!(found[0], ["commands", "render", "run"]);
    assert_eq!(found[1], ["io", "read_file"]);
    let sup = paths_after(code, "super::");
    assert_eq!(sup, [vec!["prepare", "Prepared"], vec!["load"]]);
}

#[test]
fn files_stay_readable() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut long = Vec::new();
    for dir in ["core/src", "std-harness/src"] {
        let mut files = Vec::new();
        rs_files(&root.join(dir), &mut files);
        assert!(!files.is_empty(), "{dir} has Rust files");
        for f in files {
            let text = std::fs::read_to_string(&f).expect("readable file");
            let lines = text.lines().count();
            let rel = f
                .strip_prefix(root)
                .expect("under the root")
                .display()
                .to_string();
            let command = rel.starts_with("std-harness/src/commands/");
            if command && lines > MAX_COMMAND_LINES {
                long.push(format!(
                    "{rel}: {lines} lines (a command file may have {MAX_COMMAND_LINES})"
                ));
            }
            let states_why = text.lines().take(40).any(|l| l.starts_with(WHOLE_MARKER));
            if lines > MAX_LINES && !states_why {
                long.push(format!(
                    "{rel}: {lines} lines (over {MAX_LINES} without a '{WHOLE_MARKER}' line)"
                ));
            }
        }
    }
    assert!(long.is_empty(), "{}", long.join("\n"));
}

/// Longest function in the harness and the core, lines from its `fn` line to its closing brace
/// (issue 41: a function a reader takes in whole).
const MAX_FN_LINES: usize = 120;

/// The functions of `text` longer than `max` lines, as `name (lines, from line L)`. A function
/// starts at a line whose code begins with `fn` (after `pub`, `pub(…)`, `const`, `unsafe`) and
/// ends at the first later line that is its indentation followed by `}` (rustfmt's layout).
fn long_functions(text: &str, max: usize) -> Vec<String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut long = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let code = line.trim_start();
        let indent = &line[..line.len() - code.len()];
        let mut rest = code;
        for prefix in ["pub(crate) ", "pub(super) ", "pub ", "const ", "unsafe "] {
            rest = rest.strip_prefix(prefix).unwrap_or(rest);
        }
        let Some(sig) = rest.strip_prefix("fn ") else {
            continue;
        };
        let name: String = sig.chars().take_while(|&c| is_ident(c)).collect();
        // The body opens where the signature ends with `{`; a `;` first is a declaration.
        let Some(open) = (i..lines.len()).find(|&j| {
            let l = lines[j].trim_end();
            l.ends_with('{') || l.ends_with(';')
        }) else {
            continue;
        };
        if lines[open].trim_end().ends_with(';') {
            continue;
        }
        let close = format!("{indent}}}");
        if lines[open].trim_end().ends_with("{}") || lines[open] == close {
            continue;
        }
        if let Some(end) = (open + 1..lines.len()).find(|&j| lines[j] == close) {
            let n = end - i + 1;
            if n > max {
                long.push(format!("{name} ({n} lines, from line {})", i + 1));
            }
        }
    }
    long
}

/// The 120-line rule holds for the core and the harness alike (issue 76), and the core's front
/// door example stays at most 40 lines.
#[test]
fn functions_stay_readable() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rs_files(&root.join("std-harness/src"), &mut files);
    rs_files(&root.join("core/src"), &mut files);
    let example = std::fs::read_to_string(root.join("core/examples/in_memory.rs")).unwrap();
    assert!(
        example.lines().count() <= 40,
        "core/examples/in_memory.rs has {} lines, more than 40",
        example.lines().count()
    );
    let mut long = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).expect("readable file");
        for l in long_functions(&text, MAX_FN_LINES) {
            long.push(format!("{}: {l}", f.display()));
        }
    }
    assert!(
        long.is_empty(),
        "over {MAX_FN_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn the_function_measure_sees_a_long_function() {
    let body = "    let x = 1;\n".repeat(5);
    let text = format!("pub fn a(\n    x: u8,\n) -> u8 {{\n{body}}}\n\nfn b() {{}}\nfn c();\n");
    assert_eq!(long_functions(&text, 8), ["a (9 lines, from line 1)"]);
    assert!(long_functions(&text, 9).is_empty());
    let nested = format!("impl A {{\n    fn m(&self) {{\n{body}    }}\n}}\n");
    assert_eq!(long_functions(&nested, 6), ["m (7 lines, from line 2)"]);
}

/// The core's layers, bottom up: a module imports only modules of lower layers (issue 41: no
/// circle and no upward import in either crate). Within a folder module, files that name each
/// other through `super::` form no circle either.
fn core_rank(module: &str) -> u32 {
    match module {
        "math" | "composite" | "refine" => 0,
        "kernel" | "output" => 1,
        "geometry" => 2,
        "table" => 3,
        "splat" => 4,
        "stencil" | "frame" => 5,
        "shade" | "fixed" => 6,
        "render" => 7,
        "source" => 8,
        "volume" | "lod" => 9,
        "quick" => 10,
        "prelude" => 11,
        other => panic!("core module '{other}' has no layer: add it to tests/layering.rs"),
    }
}

#[test]
fn the_core_imports_downward_only_and_without_circles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("core/src");
    let mut files = Vec::new();
    rs_files(&src, &mut files);
    let mut upward = Vec::new();
    // Sibling edges inside each folder module: (folder, file) -> files it names via `super::`.
    let mut siblings: BTreeMap<(String, String), BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let rel: Vec<String> = file
            .strip_prefix(&src)
            .unwrap()
            .iter()
            .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
            .collect();
        if rel[0] == "lib" {
            continue;
        }
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let top = rel[0].clone();
        for path in paths_after(&code, "crate::") {
            let to = &path[0];
            let module = to != &top && to.chars().next().is_some_and(|c| c.is_ascii_lowercase());
            if module && core_rank(to) >= core_rank(&top) {
                upward.push(format!("{} -> crate::{to}", rel.join("/")));
            }
            // An item through the crate root's re-exports hides which layer it comes from
            // (issue 76: `fixed/compact/setup.rs` took `crate::Sampler`): name its module.
            // The prelude exists to re-export; `Error` is defined at the root.
            let reexported = to.chars().next().is_some_and(|c| c.is_ascii_uppercase());
            if reexported && to != "Error" && top != "prelude" {
                upward.push(format!(
                    "{} -> crate::{to} (name its module)",
                    rel.join("/")
                ));
            }
        }
        if rel.len() == 2 {
            let folder = src.join(&rel[0]);
            for path in paths_after(&code, "super::") {
                if folder.join(format!("{}.rs", path[0])).exists() && path[0] != rel[1] {
                    siblings
                        .entry((rel[0].clone(), rel[1].clone()))
                        .or_default()
                        .insert(path[0].clone());
                }
            }
        }
    }
    assert!(
        upward.is_empty(),
        "imports at or above their own layer: {upward:#?}"
    );
    for ((folder, file), names) in &siblings {
        for other in names {
            let back = siblings.get(&(folder.clone(), other.clone()));
            assert!(
                !back.is_some_and(|b| b.contains(file)),
                "import circle in core/src/{folder}: {file}.rs <-> {other}.rs"
            );
        }
    }
}
