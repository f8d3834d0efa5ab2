//! The layering of ARCHITECTURE.md, enforced: data flows models → oracles → checks → records →
//! sinks, and no module imports a layer above its own. Also: only the CLI knows clap, and
//! checks and oracles do no file I/O.

use std::path::{Path, PathBuf};

/// The layer of each top-level module of the harness (lower imports nothing higher).
fn layer(module: &str) -> Option<u32> {
    Some(match module {
        "record" | "record_serde" | "tolerance" | "random" | "messages" => 0,
        "oracle" => 1,
        "check" | "subject" | "scene" | "mitsuba" => 2,
        "plan" | "plan_table" => 3,
        "audit" | "gate" | "external" | "shard" | "merge" | "baseline" | "cost" | "chi2_run"
        | "readback" | "selftest" => 4,
        "report" | "heatmap" => 5,
        "cli" | "chi2_command" | "eval" | "main" | "lib" => 6,
        _ => return None,
    })
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

/// The top-level module a source file belongs to.
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).expect("under src");
    let first = rel.components().next().expect("non-empty");
    first
        .as_os_str()
        .to_string_lossy()
        .trim_end_matches(".rs")
        .to_string()
}

/// The source without `#[cfg(test)]` modules (tests may reach anywhere) and comments.
fn code(text: &str) -> String {
    let cut = text.find("#[cfg(test)]").unwrap_or(text.len());
    text[..cut]
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn no_module_imports_a_layer_above_its_own() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut violations = Vec::new();
    for file in &files {
        // Test modules kept in their own files may reach anywhere, like `#[cfg(test)]` ones.
        let name = file.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name == "tests.rs" || name.ends_with("_tests.rs") {
            continue;
        }
        let module = module_of(&src, file);
        let Some(own) = layer(&module) else {
            violations.push(format!(
                "{}: module `{module}` has no layer",
                file.display()
            ));
            continue;
        };
        let text = code(&std::fs::read_to_string(file).expect("readable"));
        for (i, _) in text.match_indices("crate::") {
            let rest = &text[i + "crate::".len()..];
            let target: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if let Some(t) = layer(&target) {
                if t > own {
                    violations.push(format!(
                        "{}: `{module}` (layer {own}) imports `{target}` (layer {t})",
                        file.display()
                    ));
                }
            }
        }
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
