//! No circle of imports between the reference crate's files: the file-level import graph of
//! `reference/src` (every `crate::…`, `super::…` and `self::…` path, and the relative `use` of
//! a child module) has no cycle. Test code is left out: `#[cfg(test)]` items, files only a
//! `#[cfg(test)] mod` declares, and `*_tests.rs` files may reach anywhere. A re-export
//! (`pub use`) is an alias, not a dependency: a path through one counts as a reference to the
//! file that defines the item. A cycle is printed file by file, with a path that makes each
//! step.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path from the crate root (`[]` is lib.rs, `["ndf", "ggx"]` is ndf/ggx.rs).
type Module = Vec<String>;

/// The import graph: for each file's module, the modules it references, each with one path
/// that does.
type Graph = BTreeMap<Module, BTreeMap<Module, String>>;

fn name(m: &Module) -> String {
    if m.is_empty() {
        "lib.rs".to_string()
    } else {
        format!("{}.rs", m.join("/"))
    }
}

#[path = "../../tests/support/rust_source.rs"]
mod rust_source;
use rust_source::*;

/// The crate: each file module's code (comments, literals and test items blanked).
struct Crate {
    files: BTreeMap<Module, String>,
}

impl Crate {
    /// Reads `src`, keeping the files the crate compiles outside tests.
    fn read(src: &Path) -> Crate {
        let mut raw = BTreeMap::new();
        read_dir(src, src, &mut raw);
        Crate::from_sources(raw)
    }

    /// The crate of `(module, source)` pairs, without the files that only a `#[cfg(test)]`
    /// declaration brings in and without `*_tests.rs`.
    fn from_sources(raw: BTreeMap<Module, String>) -> Crate {
        let code: BTreeMap<Module, String> = raw
            .into_iter()
            .map(|(m, text)| (m, without_test_items(&code_only(&text))))
            .collect();
        let mut files = BTreeMap::new();
        for (m, text) in &code {
            let declared = match m.split_last() {
                None => true,
                Some((last, parent)) => code
                    .get(parent)
                    .is_some_and(|p| declared_modules(p).contains(last)),
            };
            if declared {
                files.insert(m.clone(), text.clone());
            }
        }
        // A child of a file left out is left out too.
        let kept: BTreeSet<Module> = files.keys().cloned().collect();
        files.retain(|m, _| (0..m.len()).all(|k| kept.contains(&m[..k])));
        Crate { files }
    }

    /// The file that defines what `path` (from the crate root) names: the longest prefix that
    /// is a file, followed through that file's re-exports.
    fn resolve(&self, path: &[String], depth: usize) -> Module {
        let mut m: Module = Vec::new();
        for (k, seg) in path.iter().enumerate() {
            let mut child = m.clone();
            child.push(seg.clone());
            if self.files.contains_key(&child) {
                m = child;
                continue;
            }
            if depth < 8 {
                if let Some(target) = self.reexport(&m, seg) {
                    let mut next = target;
                    next.extend(path[k + 1..].iter().cloned());
                    return self.resolve(&next, depth + 1);
                }
            }
            break;
        }
        m
    }

    /// Where `file` re-exports `item` from (`pub use a::b::item;`), as a path from the root.
    fn reexport(&self, file: &Module, item: &str) -> Option<Vec<String>> {
        let code = self.files.get(file)?;
        for (tree, public) in use_statements(code) {
            if !public {
                continue;
            }
            for path in expand_use(&tree) {
                if path.last().map(String::as_str) == Some(item) {
                    if let Some(abs) = self.absolute(file, &[], &path) {
                        return Some(abs);
                    }
                }
            }
        }
        None
    }

    /// `path` as written in `file` (inside its inline modules `inline`) from the crate root;
    /// `None` for a path outside the crate.
    fn absolute(&self, file: &Module, inline: &[String], path: &[String]) -> Option<Vec<String>> {
        let mut here: Vec<String> = file.iter().chain(inline).cloned().collect();
        let mut segs = path.iter().peekable();
        match segs.peek().map(|s| s.as_str()) {
            Some("crate") => {
                segs.next();
                here.clear();
            }
            Some("super") => {
                while segs.peek().map(|s| s.as_str()) == Some("super") {
                    segs.next();
                    here.pop()?;
                }
            }
            Some("self") => {
                segs.next();
            }
            Some(first) => {
                let mut child = file.clone();
                child.push(first.to_string());
                if !inline.is_empty() || !self.files.contains_key(&child) {
                    return None;
                }
            }
            None => return None,
        }
        here.extend(segs.cloned());
        Some(here)
    }

    /// The import graph.
    fn graph(&self) -> Graph {
        let mut graph = Graph::new();
        for (file, code) in &self.files {
            let edges = graph.entry(file.clone()).or_default();
            let inline = inline_modules(code);
            let inline_at = |pos: usize| -> Vec<String> {
                inline
                    .iter()
                    .filter(|(_, s, e)| *s <= pos && pos < *e)
                    .map(|(n, _, _)| n.clone())
                    .collect()
            };
            let mut add = |pos: usize, path: &[String]| {
                if let Some(abs) = self.absolute(file, &inline_at(pos), path) {
                    let target = self.resolve(&abs, 0);
                    if &target != file {
                        edges.entry(target).or_insert_with(|| path.join("::"));
                    }
                }
            };
            // `use` statements (re-exports are aliases, not dependencies).
            let mut uses = Vec::new();
            for (pos, tree, public) in use_statements_at(code) {
                uses.push((pos, pos + tree.len() + 4));
                if !public {
                    for path in expand_use(&tree) {
                        add(pos, &path);
                    }
                }
            }
            // Paths in code: crate::…, super::…, self::…
            let b = code.as_bytes();
            for start in ["crate", "super", "self"] {
                for (i, _) in code.match_indices(start) {
                    let before_ok = i == 0
                        || !(b[i - 1].is_ascii_alphanumeric()
                            || b[i - 1] == b'_'
                            || b[i - 1] == b':');
                    if !before_ok || uses.iter().any(|(s, e)| *s <= i && i < *e) {
                        continue;
                    }
                    let path = path_at(&code[i..]);
                    if path[0] != start {
                        continue;
                    }
                    if path.len() >= 2 || start == "super" {
                        add(i, &path);
                    }
                }
            }
        }
        graph
    }
}

fn read_dir(src: &Path, dir: &Path, out: &mut BTreeMap<Module, String>) {
    for entry in std::fs::read_dir(dir).expect("readable source tree") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            read_dir(src, &path, out);
            continue;
        }
        let Some(stem) = path
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_suffix(".rs"))
        else {
            continue;
        };
        if stem.ends_with("_tests") {
            continue;
        }
        let rel = path.strip_prefix(src).expect("under src");
        let mut module: Module = rel
            .parent()
            .into_iter()
            .flat_map(|p| p.components())
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if stem != "mod" && stem != "lib" {
            module.push(stem.to_string());
        }
        out.insert(module, std::fs::read_to_string(&path).expect("readable"));
    }
}

/// Every cycle of the graph, one per strongly connected component of more than one file,
/// printed as `a.rs → b.rs (path) → … → a.rs (path)`, each step with a path that makes it.
fn cycles(graph: &Graph) -> Vec<String> {
    // Tarjan's strongly connected components.
    struct State<'g> {
        graph: &'g Graph,
        index: BTreeMap<&'g Module, usize>,
        low: BTreeMap<&'g Module, usize>,
        stack: Vec<&'g Module>,
        on_stack: BTreeSet<&'g Module>,
        components: Vec<Vec<&'g Module>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g Module) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph.get(v).into_iter().flat_map(|e| e.keys()) {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.components.push(component);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        components: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    // One concrete cycle through each component: the shortest path back to its first file.
    s.components
        .iter()
        .map(|component| {
            let members: BTreeSet<&Module> = component.iter().copied().collect();
            let start = *members.iter().next().expect("non-empty");
            let mut previous: BTreeMap<&Module, &Module> = BTreeMap::new();
            let mut queue = std::collections::VecDeque::from([start]);
            let mut back = None;
            while let Some(v) = queue.pop_front() {
                for w in graph[v].keys().filter(|w| members.contains(w)) {
                    if w == start {
                        back = Some(v);
                        break;
                    }
                    if !previous.contains_key(w) {
                        previous.insert(w, v);
                        queue.push_back(w);
                    }
                }
                if back.is_some() {
                    break;
                }
            }
            let mut chain = vec![start];
            let mut v = back.expect("a component has a cycle through each member");
            while v != start {
                chain.push(v);
                v = previous[v];
            }
            chain[1..].reverse();
            chain.push(start);
            let mut text = name(start);
            for pair in chain.windows(2) {
                text += &format!(" → {} ({})", name(pair[1]), graph[pair[0]][pair[1]]);
            }
            format!("import cycle among {} files: {text}", members.len())
        })
        .collect()
}

#[test]
fn the_reference_crate_has_no_import_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = Crate::read(&src).graph();
    // The reader sees the imports (a blind reader would find no cycle anywhere).
    let edge = |from: &[&str], to: &[&str]| {
        let f: Module = from.iter().map(|s| s.to_string()).collect();
        let t: Module = to.iter().map(|s| s.to_string()).collect();
        graph.get(&f).is_some_and(|e| e.contains_key(&t))
    };
    assert!(edge(&["registry"], &["spec"]), "{graph:#?}");
    assert!(edge(&["model"], &["spec"]), "{graph:#?}");
    assert!(
        edge(&["ndf", "student"], &["ndf", "beckmann"]),
        "{graph:#?}"
    );
    assert!(edge(&["sg", "asg"], &["sg", "isotropic"]), "{graph:#?}");
    // Test-only files are not part of the graph.
    assert!(!graph.contains_key(&vec!["test_support".to_string()]));
    let found = cycles(&graph);
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// The reader on a small crate: paths of every kind make edges, re-exports are followed to
/// the defining file, test code is left out, and a cycle is found and printed.
#[test]
fn the_reader_finds_a_planted_cycle() {
    let module = |p: &str| -> Module {
        if p.is_empty() {
            Vec::new()
        } else {
            p.split('/').map(String::from).collect()
        }
    };
    let sources = [
        ("", "pub mod a;\npub mod b;\npub mod c;\n#[cfg(test)]\nmod t;\npub use a::A;\n"),
        (
            "a",
            "use crate::b::{self, B};\n// use crate::c::C;\nconst S: &str = \"crate::c::C\";\npub struct A;\n",
        ),
        (
            "b",
            "pub struct B;\n#[cfg(test)]\nmod tests {\n    use crate::c::C;\n}\nfn f() -> crate::A { crate::A }\n",
        ),
        ("c", "pub struct C;\nfn g() -> char { '\\'' }\n"),
        ("t", "use crate::c::C;\npub struct T;\n"),
    ];
    let krate = Crate::from_sources(
        sources
            .iter()
            .map(|(m, s)| (module(m), s.to_string()))
            .collect(),
    );
    assert!(
        !krate.files.contains_key(&module("t")),
        "test-only file kept"
    );
    let graph = krate.graph();
    assert_eq!(
        graph[&module("a")].keys().collect::<Vec<_>>(),
        [&module("b")],
        "comments and strings are not imports"
    );
    assert_eq!(
        graph[&module("b")].keys().collect::<Vec<_>>(),
        [&module("a")],
        "crate::A is a.rs through lib.rs's re-export; test items are left out"
    );
    let found = cycles(&graph);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        found[0],
        "import cycle among 2 files: a.rs → b.rs (crate::b) → a.rs (crate::A)"
    );
}
