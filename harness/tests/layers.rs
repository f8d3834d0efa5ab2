//! The layering of ARCHITECTURE.md, enforced: data flows models → oracles → checks → records →
//! sinks, and no module imports a layer above its own. Also: every module named here exists and
//! every module has a layer; no circle of imports between top-level modules or between the
//! sinks of `report/`; only the CLI knows clap; checks and oracles do no file I/O; only the CLI
//! prints.
//!
//! Every non-test line of every file is read: comments, literals and `#[cfg(test)]` items are
//! blanked by `tests/support/rust_source.rs`, nothing else; `use` groups are expanded.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of ARCHITECTURE.md ("Data flows one way"), lowest first.
const LAYERS: &[(u32, &[&str])] = &[
    (
        0,
        &[
            "record",
            "record_serde",
            "record_text",
            "tolerance",
            "random",
            "messages",
            "precision",
            "deadline",
        ],
    ),
    (1, &["oracle"]),
    (2, &["check", "subject"]),
    (3, &["scene", "scene_file", "mitsuba", "plan", "estimate"]),
    (
        4,
        &[
            "audit",
            "run",
            "external",
            "shard",
            "merge",
            "record_trust",
            "baseline",
            "cost",
            "sampler_chi2",
            "readback",
            "selftest",
        ],
    ),
    (5, &["report"]),
    (6, &["cli", "eval", "main", "lib"]),
];

/// The layer of a top-level module of the harness.
fn layer(module: &str) -> Option<u32> {
    LAYERS
        .iter()
        .find(|(_, modules)| modules.contains(&module))
        .map(|(l, _)| *l)
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable source tree") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The non-test source files (test modules kept in their own files may reach anywhere).
fn source_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.retain(|f| {
        let name = f.file_name().and_then(|n| n.to_str()).unwrap_or("");
        name != "tests.rs" && !name.ends_with("_tests.rs")
    });
    files.sort();
    files
}

/// The top-level module a source file belongs to.
fn module_of(file: &Path) -> String {
    let rel = file.strip_prefix(src()).expect("under src");
    let first = rel.components().next().expect("non-empty");
    first
        .as_os_str()
        .to_string_lossy()
        .trim_end_matches(".rs")
        .to_string()
}

#[path = "../../tests/support/rust_source.rs"]
mod rust_source;

/// The code of a file: comments, literals and `#[cfg(test)]` items blanked
/// (`tests/support/rust_source.rs`, the reader the reference crate's layering test uses too).
fn code(text: &str) -> String {
    rust_source::without_test_items(&rust_source::code_only(text))
}

/// The segment after `prefix` of every path in `code` that starts with it: in `use` trees
/// (groups such as `crate::{a, b}` expanded) and in paths written inline (`crate::a::f()`).
fn targets(code: &str, prefix: &[&str]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (_, tree, _) in rust_source::use_statements_at(code) {
        for path in rust_source::expand_use(&tree) {
            if path.len() > prefix.len() && path.iter().zip(prefix).all(|(a, b)| a == b) {
                out.insert(path[prefix.len()].clone());
            }
        }
    }
    let written = format!("{}::", prefix.join("::"));
    for (i, _) in code.match_indices(&written) {
        let ident: String = code[i + written.len()..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !ident.is_empty() {
            out.insert(ident);
        }
    }
    out
}

/// The top-level modules a file imports (through `crate::`), its own excluded.
fn imports(file: &Path) -> BTreeSet<String> {
    let own = module_of(file);
    let text = code(&std::fs::read_to_string(file).expect("readable"));
    targets(&text, &["crate"])
        .into_iter()
        .filter(|t| *t != own)
        .collect()
}

/// A circle in a directed graph, if there is one (depth-first search).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_string(), 1);
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == next).expect("on the path");
                    let mut circle = path[start..].to_vec();
                    circle.push(next.clone());
                    return Some(circle);
                }
                0 => {
                    if let Some(c) = visit(next, graph, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node.as_str()).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(node, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn no_module_imports_a_layer_above_its_own() {
    let mut violations = Vec::new();
    for file in &source_files() {
        let module = module_of(file);
        let Some(own) = layer(&module) else {
            violations.push(format!(
                "{}: module `{module}` has no layer",
                file.display()
            ));
            continue;
        };
        for target in imports(file) {
            if let Some(t) = layer(&target) {
                if t > own {
                    violations.push(format!(
                        "{}: `{module}` (layer {own}) imports `{target}` (layer {t})",
                        file.display()
                    ));
                }
            }
        }
        let text = code(&std::fs::read_to_string(file).expect("readable"));
        if own < 6 && text.contains("clap") {
            violations.push(format!("{}: only the CLI may use clap", file.display()));
        }
        let checks_or_oracles = matches!(module.as_str(), "check" | "oracle" | "subject");
        if checks_or_oracles && (text.contains("std::fs") || text.contains("File::")) {
            violations.push(format!(
                "{}: checks and oracles do no file I/O",
                file.display()
            ));
        }
    }
    violations.sort();
    violations.dedup();
    assert!(violations.is_empty(), "{violations:#?}");
}

/// The printing a library must not do: the standard-stream macros and handles. Only the CLI
/// (`cli/`, `main.rs`) writes to the terminal; the library tells it what happens through
/// callbacks (`run::RunControl`, progress functions).
const PRINTS: &[&str] = &[
    "print!",
    "println!",
    "eprint!",
    "eprintln!",
    "dbg!",
    "io::stdout",
    "io::stderr",
];

/// Where `code` uses one of [`PRINTS`] as a whole token (`fingerprint!` would not count).
fn prints(code: &str) -> Vec<&'static str> {
    PRINTS
        .iter()
        .filter(|p| {
            code.match_indices(*p).any(|(i, _)| {
                !code[..i]
                    .chars()
                    .next_back()
                    .is_some_and(|c| c.is_alphanumeric() || c == '_')
            })
        })
        .copied()
        .collect()
}

#[test]
fn the_library_prints_nothing() {
    let mut violations = Vec::new();
    for file in &source_files() {
        if matches!(module_of(file).as_str(), "cli" | "main") {
            continue;
        }
        let text = code(&std::fs::read_to_string(file).expect("readable"));
        for p in prints(&text) {
            violations.push(format!(
                "{}: `{p}` outside the CLI (the library prints nothing)",
                file.display()
            ));
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
    assert_eq!(prints("eprintln!(\"x\")"), ["eprintln!"]);
    assert_eq!(prints("std::io::stderr()"), ["io::stderr"]);
    assert!(prints("fingerprint!(x); my_dbg!(y)").is_empty());
}

#[test]
fn every_module_of_the_table_exists_and_every_module_has_a_layer() {
    let src = src();
    for (_, modules) in LAYERS {
        for m in *modules {
            assert!(
                src.join(format!("{m}.rs")).is_file() || src.join(m).is_dir(),
                "the layer table names `{m}`, which is not a module of the harness"
            );
        }
    }
    for entry in std::fs::read_dir(&src).expect("src") {
        let path = entry.expect("entry").path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if path.is_dir() || name.ends_with(".rs") {
            let m = name.trim_end_matches(".rs");
            assert!(layer(m).is_some(), "module `{m}` has no layer in layers.rs");
        }
    }
}

#[test]
fn no_circle_of_imports_between_top_level_modules() {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &source_files() {
        let module = module_of(file);
        let entry = graph.entry(module).or_default();
        entry.extend(imports(file).into_iter().filter(|t| layer(t).is_some()));
    }
    assert_eq!(
        find_cycle(&graph),
        None,
        "a circle of imports between modules"
    );
}

#[test]
fn no_circle_of_imports_between_the_sinks() {
    let report = src().join("report");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut files = Vec::new();
    rust_files(&report, &mut files);
    let names: BTreeSet<String> = files
        .iter()
        .map(|f| f.file_stem().unwrap().to_string_lossy().to_string())
        .collect();
    for file in &files {
        let name = file.file_stem().unwrap().to_string_lossy().to_string();
        if name == "mod" || name == "tests" || name.ends_with("_tests") {
            continue;
        }
        let text = code(&std::fs::read_to_string(file).expect("readable"));
        let used: BTreeSet<String> = targets(&text, &["super"])
            .into_iter()
            .chain(targets(&text, &["crate", "report"]))
            .filter(|t| *t != name && t != "mod" && names.contains(t))
            .collect();
        graph.entry(name).or_default().extend(used);
    }
    assert_eq!(
        find_cycle(&graph),
        None,
        "a circle of imports inside report/"
    );
}

#[test]
fn the_reader_drops_test_items_and_comments_only() {
    let text = "use crate::a;\n#[cfg(test)]\nmod tests {\n    fn f() { let s = \"}\"; }\n    \
                use crate::b;\n}\n// crate::c\nuse crate::d;\n#[cfg(test)]\nuse crate::e;\n\
                /* crate::f */ fn g() { let r = r#\"{ crate::h\"#; crate::i::j(); }\n\
                use crate::{k, l::m};\n";
    let c = code(text);
    let found = targets(&c, &["crate"]);
    let expected: BTreeSet<String> = ["a", "d", "i", "k", "l"].map(String::from).into();
    assert_eq!(found, expected, "in:\n{c}");
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("a".into());
    assert_eq!(
        find_cycle(&g),
        Some(vec!["a".to_string(), "b".into(), "a".into()])
    );
}
