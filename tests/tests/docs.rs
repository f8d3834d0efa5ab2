//! The documentation holds together: every relative link of README.md, ARCHITECTURE.md and
//! docs/*.md reaches an existing file, and every `#anchor` a heading of its target (GitHub's
//! slugs); every doc comment or string of the workspace's Rust files that cites a section of
//! ARCHITECTURE.md (`ARCHITECTURE.md, "Section"`, `ARCHITECTURE.md "A", "B"`, or a record
//! source's `ARCHITECTURE.md model boundary: …`) names one of its headings; every file and code
//! identifier ARCHITECTURE.md names in a code span exists (the rules at [`path_candidate`] and
//! [`identifier_candidate`]); every page of docs/ is linked from the README; and the README
//! stays at most 200 lines (reference material goes to docs/). The checkers are tested on
//! broken input too, so that a pass means they looked.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

#[path = "../support/rust_source.rs"]
mod rust_source;

/// The README's length limit, in lines.
const README_MAX_LINES: usize = 200;

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the workspace")
        .to_path_buf()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// The markdown files whose links are checked: README.md, ARCHITECTURE.md and docs/*.md.
fn checked_markdown(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md"), root.join("ARCHITECTURE.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("docs/ exists")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

/// GitHub's anchor for a heading: lowercase, every character but letters, digits, `-`, `_` and
/// spaces dropped (so backticks, punctuation, `—` and `∈` go), spaces turned into `-`.
fn slug(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The lines of a markdown text outside fenced code blocks.
fn prose_lines(text: &str) -> Vec<&str> {
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push(line);
        }
    }
    out
}

/// The headings' texts of a markdown text (ATX headings outside code blocks).
fn headings(text: &str) -> Vec<String> {
    prose_lines(text)
        .into_iter()
        .filter_map(|line| {
            let hashes = line.chars().take_while(|&c| c == '#').count();
            let rest = &line[hashes..];
            ((1..=6).contains(&hashes) && rest.starts_with(' ')).then(|| rest.trim().to_string())
        })
        .collect()
}

/// The anchors of a markdown text's headings, with GitHub's `-1`, `-2` … for repeated slugs.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    for h in headings(text) {
        let base = slug(&h);
        let mut a = base.clone();
        let mut n = 0;
        while seen.contains(&a) {
            n += 1;
            a = format!("{base}-{n}");
        }
        seen.insert(a);
    }
    seen
}

/// The targets of the inline links and images of a markdown text (`[text](target)`), outside
/// code blocks and code spans, each with its line number.
fn link_targets(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let chars: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            if chars[i] == '`' {
                // A code span: skip to the closing run of as many backticks.
                let run = chars[i..].iter().take_while(|&&c| c == '`').count();
                let mut j = i + run;
                loop {
                    if j >= chars.len() {
                        j = chars.len();
                        break;
                    }
                    let r = chars[j..].iter().take_while(|&&c| c == '`').count();
                    if r == run {
                        j += r;
                        break;
                    }
                    j += r.max(1);
                }
                i = j;
                continue;
            }
            if chars[i] == ']' && chars.get(i + 1) == Some(&'(') {
                let mut depth = 0;
                let mut target = String::new();
                for &c in &chars[i + 2..] {
                    match c {
                        '(' => depth += 1,
                        ')' if depth == 0 => break,
                        ')' => depth -= 1,
                        _ => {}
                    }
                    target.push(c);
                }
                // `[text](target "title")`: the target is the first word.
                let target = target.split_whitespace().next().unwrap_or("").to_string();
                out.push((n + 1, target));
            }
            i += 1;
        }
    }
    out
}

/// `%XX` escapes decoded (a link may spell a non-ASCII anchor either way).
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        if let (b'%', Some(b)) = (bytes[i], hex) {
            out.push(b);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// What is wrong with the relative links of the markdown file `file` (text `text`): targets
/// that do not exist, anchors that name no heading of their markdown target.
fn link_problems(file: &Path, text: &str) -> Vec<String> {
    let dir = file.parent().expect("a file has a folder");
    let mut problems = Vec::new();
    for (line, target) in link_targets(text) {
        let at = format!("{}:{line}: ({target})", file.display());
        if target.is_empty() {
            problems.push(format!("{at}: empty link target"));
            continue;
        }
        if target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (path, anchor) = match target.split_once('#') {
            Some((p, a)) => (p, Some(percent_decode(a))),
            None => (target.as_str(), None),
        };
        let resolved = if path.is_empty() {
            file.to_path_buf()
        } else {
            dir.join(percent_decode(path))
        };
        if !path.is_empty() && !resolved.exists() {
            problems.push(format!("{at}: {} does not exist", resolved.display()));
            continue;
        }
        let Some(anchor) = anchor else { continue };
        if resolved.extension().is_none_or(|e| e != "md") {
            problems.push(format!("{at}: an anchor into a file that is not markdown"));
            continue;
        }
        let target_text = if path.is_empty() {
            text.to_string()
        } else {
            read(&resolved)
        };
        if !anchors(&target_text).contains(&anchor) {
            problems.push(format!(
                "{at}: no heading of {} has the anchor #{anchor}",
                resolved.display()
            ));
        }
    }
    problems
}

/// The Rust files of the workspace (not `target/`, not hidden folders).
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable folder") {
        let path = entry.expect("entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                rust_files(&path, out);
            }
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}

/// A Rust text with its comment markers and string continuations joined away, so that a
/// citation wrapped over two doc-comment lines (or a `\`-continued string) reads as one line.
fn joined(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        let t = ["//!", "///", "//"]
            .iter()
            .find_map(|m| t.strip_prefix(m))
            .unwrap_or(t);
        let t = t.trim();
        let t = t.strip_suffix('\\').unwrap_or(t);
        if !out.is_empty() {
            out.push(' ');
        }
        out.push_str(t.trim());
    }
    out
}

/// The sections of ARCHITECTURE.md that a Rust text cites: `ARCHITECTURE.md, "A"`,
/// `ARCHITECTURE.md "A", "B"` (every quoted name in the list), and a record source's unquoted
/// `ARCHITECTURE.md model boundary:` (a few words up to a colon).
fn citations(text: &str) -> Vec<String> {
    const NAME: &str = "ARCHITECTURE.md";
    let text = joined(text);
    let mut out = Vec::new();
    for (i, _) in text.match_indices(NAME) {
        let rest = &text[i + NAME.len()..];
        let after_comma = rest.strip_prefix(',').unwrap_or(rest).trim_start();
        if after_comma.starts_with('"') {
            // One or more quoted sections separated by commas.
            let mut r = after_comma;
            while let Some(body) = r.strip_prefix('"') {
                let Some(end) = body.find('"') else { break };
                out.push(body[..end].split_whitespace().collect::<Vec<_>>().join(" "));
                r = body[end + 1..].trim_start();
                match r.strip_prefix(',') {
                    Some(next) if next.trim_start().starts_with('"') => r = next.trim_start(),
                    _ => break,
                }
            }
        } else if let Some(body) = rest.strip_prefix(' ') {
            // `ARCHITECTURE.md model boundary: …`: lowercase words, then a colon.
            if let Some(end) = body.find(':') {
                let words = &body[..end];
                let n = words.split_whitespace().count();
                if (1..=5).contains(&n) && words.chars().all(|c| c.is_ascii_lowercase() || c == ' ')
                {
                    out.push(words.to_string());
                }
            }
        }
    }
    out
}

/// Whether `cited` names a heading: equal ignoring case, a leading "The " and a trailing "?".
fn names_heading(cited: &str, headings: &[String]) -> bool {
    let norm = |s: &str| {
        let s = s.trim().trim_end_matches('?').to_lowercase();
        s.strip_prefix("the ").map(str::to_string).unwrap_or(s)
    };
    headings.iter().any(|h| norm(h) == norm(cited))
}

/// What is wrong with the ARCHITECTURE.md citations of the Rust file `file` (text `text`).
fn citation_problems(file: &Path, text: &str, architecture: &str) -> Vec<String> {
    let hs = headings(architecture);
    citations(text)
        .into_iter()
        .filter(|c| !names_heading(c, &hs))
        .map(|c| {
            format!(
                "{}: cites ARCHITECTURE.md \"{c}\", which has no such heading",
                file.display()
            )
        })
        .collect()
}

/// The code spans of a markdown text outside fenced code blocks, each with the line it starts
/// on: a run of n backticks up to the next run of exactly n within the paragraph (a span may
/// wrap over lines; its line breaks read as spaces), its content trimmed. A run with no closing
/// run is literal text.
fn code_spans(text: &str) -> Vec<(usize, String)> {
    let mut fenced = false;
    let mut chars: Vec<(usize, char)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let fence = line.trim_start().starts_with("```");
        if fence {
            fenced = !fenced;
        }
        // Fences, fenced lines and blank lines all read as an empty line: a paragraph break.
        if !fence && !fenced && !line.trim().is_empty() {
            chars.extend(line.chars().map(|c| (n + 1, c)));
        }
        chars.push((n + 1, '\n'));
    }
    let run_at = |i: usize| chars[i..].iter().take_while(|&&(_, c)| c == '`').count();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        if chars[i].1 != '`' {
            i += 1;
            continue;
        }
        let run = run_at(i);
        let mut j = i + run;
        let mut close = None;
        while j < chars.len() {
            match chars[j].1 {
                '\n' if chars.get(j + 1).is_some_and(|&(_, c)| c == '\n') => break,
                '`' => {
                    let r = run_at(j);
                    if r == run {
                        close = Some(j);
                        break;
                    }
                    j += r;
                }
                _ => j += 1,
            }
        }
        match close {
            Some(j) => {
                let body: String = chars[i + run..j]
                    .iter()
                    .map(|&(_, c)| if c == '\n' { ' ' } else { c })
                    .collect();
                out.push((chars[i].0, body.trim().to_string()));
                i = j + run;
            }
            None => i += run,
        }
    }
    out
}

/// The extensions that make a code span a file of the repository even without a folder.
/// Outputs of mfh (`report.json`, `junit.xml`, `report.html`, …) are not among them: a span
/// names one of those without being a file of the repository.
const FILE_EXTENSIONS: &[&str] = &["rs", "md", "toml", "py", "hpp", "cpp"];

/// Whether a code span names a file or folder of the repository, and which: a span of letters,
/// digits and `_ - . / < >` only that either ends in one of [`FILE_EXTENSIONS`] (`Cargo.toml`,
/// `ks.rs`) or has a `/` and begins with the name of a folder of the workspace
/// (`harness/src/check/run.rs`, `check/bsdf/chi2.rs`, `oracle/chi2/`). A component with
/// `<placeholder>` or `NNN` in it stands for any name (`reference/src/ndf/<family>.rs`,
/// `documentNNN.rs`). Not paths: `family/quantity/route` (no folder is called `family`),
/// `report.json` (an output, not a source extension).
fn path_candidate(span: &str, folders: &BTreeSet<String>) -> Option<String> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || "_-./<>".contains(c);
    if span.is_empty() || !span.chars().all(allowed) || span.starts_with('/') {
        return None;
    }
    let path = span.trim_end_matches('/');
    let has_extension = !span.ends_with('/')
        && path
            .rsplit_once('.')
            .is_some_and(|(_, e)| FILE_EXTENSIONS.contains(&e));
    let first = path.split('/').next().unwrap_or("");
    let rooted = span.contains('/') && folders.contains(first);
    (has_extension || rooted).then(|| path.to_string())
}

/// `name` matched against `pattern`, where `*` stands for any run of characters.
fn glob(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    let (mut i, mut j) = (0, 0);
    let mut back: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && p[i] == '*' {
            back = Some((i, j));
            i += 1;
        } else if i < p.len() && p[i] == n[j] {
            i += 1;
            j += 1;
        } else if let Some((bi, bj)) = back {
            i = bi + 1;
            j = bj + 1;
            back = Some((bi, bj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// A path component of a code span as a [`glob`] pattern: `<…>` and `NNN` stand for any name.
fn component_pattern(component: &str) -> String {
    let mut out = String::new();
    let mut rest = component;
    while let Some(open) = rest.find('<') {
        out.push_str(&rest[..open]);
        out.push('*');
        rest = rest[open..]
            .find('>')
            .map_or("", |close| &rest[open + close + 1..]);
    }
    out.push_str(rest);
    out.replace("NNN", "*")
}

/// Whether `path` (components separated by `/`) is the end of some entry's path, component by
/// component: `check/bsdf/chi2.rs` is `harness/src/check/bsdf/chi2.rs`.
fn path_resolves(path: &str, entries: &[Vec<String>]) -> bool {
    let want: Vec<String> = path.split('/').map(component_pattern).collect();
    entries.iter().any(|e| {
        e.len() >= want.len()
            && e[e.len() - want.len()..]
                .iter()
                .zip(&want)
                .all(|(name, pattern)| glob(pattern, name))
    })
}

/// Every file and folder of the workspace as its path's components (not `target/`, not
/// `.git`), and the names of its folders.
fn workspace_entries(root: &Path) -> (Vec<Vec<String>>, BTreeSet<String>) {
    fn walk(
        dir: &Path,
        prefix: &[String],
        out: &mut Vec<Vec<String>>,
        folders: &mut BTreeSet<String>,
    ) {
        for entry in std::fs::read_dir(dir).expect("readable folder") {
            let path = entry.expect("entry").path();
            let name = path
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("")
                .to_string();
            if name == "target" || name == ".git" {
                continue;
            }
            let mut components = prefix.to_vec();
            components.push(name.clone());
            if path.is_dir() {
                folders.insert(name);
                walk(&path, &components, out, folders);
            }
            out.push(components);
        }
    }
    let (mut entries, mut folders) = (Vec::new(), BTreeSet::new());
    walk(root, &[], &mut entries, &mut folders);
    (entries, folders)
}

/// How a code span names code: a Rust path as written, a call `name()` or a macro `name!`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Naming {
    Path,
    Function,
    Macro,
}

/// Whether a code span names a code identifier that must exist, and its segments: a Rust path
/// (`Check`, `Audit::of`, `sphere_chi2::draw_chunks`), optionally followed by `()` (a function)
/// or `!` (a macro), that has a `::`, or a capital letter (types, traits, variants, constants:
/// `PlannedCheck`, `FamilyInfo`, `MEASURED`), or the `()` or `!`. A lone lowercase word (`d`,
/// `seed`, `case`) is prose about a method, a field or a JSON key, and is not checked; nor is
/// anything with spaces or punctuation (`Check::new(id, …)`, `bsdf.chi2`).
fn identifier_candidate(span: &str) -> Option<(Vec<String>, Naming)> {
    let (body, naming) = if let Some(b) = span.strip_suffix("()") {
        (b, Naming::Function)
    } else if let Some(b) = span.strip_suffix('!') {
        (b, Naming::Macro)
    } else {
        (span, Naming::Path)
    };
    let segments: Vec<String> = body.split("::").map(str::to_string).collect();
    let identifier = |s: &String| {
        s.chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
    };
    if !segments.iter().all(identifier) {
        return None;
    }
    let named = segments.len() > 1
        || naming != Naming::Path
        || body.chars().any(|c| c.is_ascii_uppercase());
    named.then_some((segments, naming))
}

/// What the workspace's Rust code names: its identifier tokens outside comments and literals,
/// the names it declares (after `fn`, `struct`, `enum`, `trait`, `type`, `const`, `static`,
/// `mod`, `union`, `macro_rules!`), its code with the literals blanked, and its raw text (for
/// environment variables, named only in string literals).
struct RustIndex {
    tokens: BTreeSet<String>,
    declared: BTreeMap<String, BTreeSet<String>>,
    code: String,
    raw: String,
}

impl RustIndex {
    fn of<'t>(texts: impl IntoIterator<Item = &'t str>) -> RustIndex {
        const KEYWORDS: &[&str] = &[
            "fn",
            "struct",
            "enum",
            "trait",
            "type",
            "const",
            "static",
            "mod",
            "union",
            "macro_rules",
        ];
        let mut index = RustIndex {
            tokens: BTreeSet::new(),
            declared: BTreeMap::new(),
            code: String::new(),
            raw: String::new(),
        };
        for text in texts {
            let code = rust_source::code_only(text);
            let words: Vec<&str> = code
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .filter(|w| !w.is_empty())
                .collect();
            for pair in words.windows(2) {
                if KEYWORDS.contains(&pair[0]) {
                    index
                        .declared
                        .entry(pair[1].to_string())
                        .or_default()
                        .insert(pair[0].to_string());
                }
            }
            index.tokens.extend(words.iter().map(|w| w.to_string()));
            index.code.push_str(&code);
            index.code.push('\n');
            index.raw.push_str(text);
            index.raw.push('\n');
        }
        index
    }

    /// Whether the code has what a span names: a macro is declared by `macro_rules!`, a function
    /// by `fn`; a path of several segments ends in a declared name or occurs as written; a
    /// single name occurs as a token of the code, or — all in capitals — as a whole string
    /// literal (an environment variable the code reads).
    fn has(&self, segments: &[String], naming: Naming) -> bool {
        let last = segments.last().expect("a path has a segment");
        let declared = |kw: &str| self.declared.get(last).is_some_and(|k| k.contains(kw));
        match naming {
            Naming::Macro => declared("macro_rules"),
            Naming::Function => declared("fn"),
            Naming::Path if segments.len() > 1 => {
                self.declared.contains_key(last) || self.code.contains(&segments.join("::"))
            }
            Naming::Path => {
                self.tokens.contains(last)
                    || (!last.chars().any(|c| c.is_ascii_lowercase())
                        && self.raw.contains(&format!("\"{last}\"")))
            }
        }
    }
}

/// What is wrong with the files and identifiers the markdown text `text` (of `file`) names in
/// code spans, and how many spans it checked as (paths, identifiers).
fn named_code_problems(
    file: &str,
    text: &str,
    entries: &[Vec<String>],
    folders: &BTreeSet<String>,
    index: &RustIndex,
) -> ((usize, usize), Vec<String>) {
    let (mut paths, mut identifiers) = (0, 0);
    let mut problems = Vec::new();
    for (line, span) in code_spans(text) {
        if let Some(path) = path_candidate(&span, folders) {
            paths += 1;
            if !path_resolves(&path, entries) {
                problems.push(format!("{file}:{line}: `{span}`: no such file or folder"));
            }
        } else if let Some((segments, naming)) = identifier_candidate(&span) {
            identifiers += 1;
            if !index.has(&segments, naming) {
                problems.push(format!(
                    "{file}:{line}: `{span}`: named nowhere in the workspace's Rust code"
                ));
            }
        }
    }
    ((paths, identifiers), problems)
}

#[test]
fn every_relative_link_and_anchor_resolves() {
    let root = root();
    let mut problems = Vec::new();
    let mut links = 0;
    for file in checked_markdown(&root) {
        let text = read(&file);
        links += link_targets(&text).len();
        problems.extend(link_problems(&file, &text));
    }
    assert!(links > 50, "only {links} links found: is the parser blind?");
    assert!(
        problems.is_empty(),
        "broken links:\n{}",
        problems.join("\n")
    );
}

#[test]
fn every_architecture_citation_in_rust_names_a_section() {
    let root = root();
    let architecture = read(&root.join("ARCHITECTURE.md"));
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    files.sort();
    let mut problems = Vec::new();
    let mut cited = 0;
    // This file cites made-up sections on purpose (its checkers' own test).
    for file in files.iter().filter(|f| !f.ends_with(file!())) {
        let text = read(file);
        cited += citations(&text).len();
        problems.extend(citation_problems(file, &text, &architecture));
    }
    assert!(
        cited >= 8,
        "only {cited} citations found: is the parser blind?"
    );
    assert!(
        problems.is_empty(),
        "citations of missing sections:\n{}",
        problems.join("\n")
    );
}

#[test]
fn every_file_and_identifier_architecture_names_exists() {
    let root = root();
    let text = read(&root.join("ARCHITECTURE.md"));
    let (entries, folders) = workspace_entries(&root);
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    // This file names made-up identifiers on purpose (its checkers' own test).
    let texts: Vec<String> = files
        .iter()
        .filter(|f| !f.ends_with(file!()))
        .map(|f| read(f))
        .collect();
    let index = RustIndex::of(texts.iter().map(String::as_str));
    let ((paths, identifiers), problems) =
        named_code_problems("ARCHITECTURE.md", &text, &entries, &folders, &index);
    assert!(
        paths > 100 && identifiers > 40,
        "only {paths} paths and {identifiers} identifiers checked: is the parser blind?"
    );
    assert!(
        problems.is_empty(),
        "ARCHITECTURE.md names what does not exist:\n{}",
        problems.join("\n")
    );
}

#[test]
fn every_docs_page_is_linked_from_the_readme() {
    let root = root();
    let readme = read(&root.join("README.md"));
    let linked: BTreeSet<PathBuf> = link_targets(&readme)
        .into_iter()
        .map(|(_, t)| root.join(t.split('#').next().unwrap_or("")))
        .collect();
    let missing: Vec<String> = checked_markdown(&root)
        .into_iter()
        .filter(|p| p.starts_with(root.join("docs")) && !linked.contains(p))
        .map(|p| p.display().to_string())
        .collect();
    assert!(missing.is_empty(), "not linked from README.md: {missing:?}");
}

#[test]
fn the_readme_is_at_most_200_lines() {
    let lines = read(&root().join("README.md")).lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines (at most {README_MAX_LINES}: reference material goes to docs/)"
    );
}

/// The checkers see what they must: a missing file, a missing anchor, a link hidden in code
/// (ignored), a citation of a missing section in each of its forms.
#[test]
fn the_checkers_catch_broken_links_and_citations() {
    assert_eq!(slug("Where does X go?"), "where-does-x-go");
    assert_eq!(slug("An `mfh eval` quantity"), "an-mfh-eval-quantity");
    assert_eq!(
        slug("Document 004 — Deriving G1 for γ ∈ (0, 4] (Dimov, GTR)"),
        "document-004--deriving-g1-for-γ--0-4-dimov-gtr"
    );
    assert_eq!(
        anchors("# A\n## A\n```\n# not a heading\n```\n"),
        BTreeSet::from(["a".to_string(), "a-1".to_string()])
    );

    let dir = std::env::temp_dir().join(format!("mfh-docs-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("docs")).expect("temp folder");
    std::fs::write(dir.join("docs/page.md"), "# Page\n\n## Its section\n").expect("write");
    let md = dir.join("README.md");
    let good = "[p](docs/page.md) [s](docs/page.md#its-section) [self](#top) `[x](nowhere.md)`\n\
                ```\n[y](nowhere.md)\n```\n# Top\n";
    assert_eq!(link_problems(&md, good), Vec::<String>::new());
    let bad = "[p](docs/missing.md) and [s](docs/page.md#no-such-section) and [a](#nope)\n";
    let problems = link_problems(&md, bad);
    assert_eq!(problems.len(), 3, "{problems:?}");
    assert!(problems[0].contains("does not exist"), "{problems:?}");
    assert!(problems[1].contains("#no-such-section"), "{problems:?}");
    assert!(problems[2].contains("#nope"), "{problems:?}");
    std::fs::remove_dir_all(&dir).expect("clean up");

    let architecture = "# Map\n## Checks and records\n## Scenes\n## The model boundary\n";
    let rust =
        "//! (ARCHITECTURE.md, \"Checks\n//! and records\") and ARCHITECTURE.md \"Scenes\", \
                \"Gone\".\nconst S: &str = \"ARCHITECTURE.md model boundary: D finite\";\n\
                /// (ARCHITECTURE.md, \"Evaluating closed forms\")\n";
    assert_eq!(
        citations(rust),
        [
            "Checks and records",
            "Scenes",
            "Gone",
            "model boundary",
            "Evaluating closed forms"
        ]
    );
    let problems = citation_problems(Path::new("x.rs"), rust, architecture);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems[0].contains("\"Gone\""), "{problems:?}");
    assert!(
        problems[1].contains("\"Evaluating closed forms\""),
        "{problems:?}"
    );
}

/// The checker of named files and identifiers sees what it must: spans over two lines, spans in
/// code blocks (ignored), paths by suffix and with placeholders, outputs and ids that are not
/// paths, declared and undeclared names, environment variables.
#[test]
fn the_checker_catches_missing_files_and_identifiers() {
    assert_eq!(
        code_spans("a `x` and ``y ` z`` and `wrapped\nspan` `open\n\n`\n```\n`fenced`\n```\n"),
        [
            (1, "x".to_string()),
            (1, "y ` z".to_string()),
            (1, "wrapped span".to_string())
        ]
    );
    assert!(glob("document*.rs", "document004.rs") && glob("*", "") && !glob("a*b", "ac"));
    assert_eq!(component_pattern("<family>.rs"), "*.rs");
    assert_eq!(component_pattern("documentNNN.rs"), "document*.rs");

    let entries: Vec<Vec<String>> = [
        "harness/src/check/bsdf/chi2.rs",
        "harness/src/check/bsdf",
        "harness/src/check",
        "harness/src",
        "harness",
        "reference/src/ndf/ggx.rs",
        "reference/src/ndf",
        "reference/src",
        "reference",
        "reference/src/errata/document001.rs",
        "reference/src/errata",
        "Cargo.toml",
    ]
    .iter()
    .map(|p| p.split('/').map(str::to_string).collect())
    .collect();
    let folders: BTreeSet<String> = [
        "harness",
        "src",
        "check",
        "bsdf",
        "reference",
        "ndf",
        "errata",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let rust = [
        "pub struct PlannedCheck;\npub fn of() {}\nmacro_rules! registry { () => {} }\n\
         const MEASURED: u8 = 0;\nimpl Audit { fn of_bsdf() {} }\n\
         fn f() { let _ = std::env::var(\"MFH_SEED\"); let v = Precision::F32; }\n\
         // struct InAComment;\nconst S: &str = \"NotCode\";\n",
    ];
    let index = RustIndex::of(rust);
    let markdown = "\
`harness/src/check/bsdf/chi2.rs` `check/bsdf/chi2.rs` `check/bsdf/` `Cargo.toml`
`reference/src/ndf/<family>.rs` `reference/src/errata/documentNNN.rs`
`family/quantity/route` `report.json` `bsdf.chi2` `d` `seed` `Check::new(id, model)`
`PlannedCheck` `Audit::of` `Audit::of_bsdf` `Precision::F32` `registry!` `of()` `MEASURED`
`MFH_SEED`
```
`harness/src/fenced.rs` `Fenced`
```
`harness/src/nowhere.rs` `check/bsdf/missing.rs` `ndf/<family>/deep.rs` `src/NNN/x.rs` `Cargo.lock`
`NoSuchType` `Audit::gone` `model_spec!` `PlannedCheck()` `InAComment` `NotCode` `MFH_UNREAD`
";
    let ((paths, identifiers), problems) =
        named_code_problems("A.md", markdown, &entries, &folders, &index);
    let named: Vec<&str> = problems
        .iter()
        .map(|p| p.split('`').nth(1).expect("the span is quoted"))
        .collect();
    assert_eq!(
        named,
        [
            "harness/src/nowhere.rs",
            "check/bsdf/missing.rs",
            "ndf/<family>/deep.rs",
            "src/NNN/x.rs",
            "NoSuchType",
            "Audit::gone",
            "model_spec!",
            "PlannedCheck()",
            "InAComment",
            "NotCode",
            "MFH_UNREAD",
        ],
        "{problems:?}"
    );
    assert!(problems[0].starts_with("A.md:9: "), "{problems:?}");
    // `Cargo.lock` is neither a source extension nor under a folder: not checked.
    assert_eq!((paths, identifiers), (6 + 4, 8 + 7));
}

/// The places in `text` that cite a tracker issue by number (the word, a space, digits):
/// the repository holds no tracker, so a reason is written out, never referred to by number.
fn issue_numbers(text: &str) -> Vec<usize> {
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let lower = line.to_lowercase();
        let cites = ["issue ", "issues "].iter().any(|word| {
            lower.match_indices(word).any(|(at, w)| {
                let before_ok = at == 0
                    || !lower[..at]
                        .chars()
                        .next_back()
                        .is_some_and(|c| c.is_alphanumeric() || c == '_');
                before_ok
                    && lower[at + w.len()..]
                        .chars()
                        .next()
                        .is_some_and(|c| c.is_ascii_digit())
            })
        });
        if cites {
            lines.push(i + 1);
        }
    }
    lines
}

#[test]
fn no_rust_source_cites_a_tracker_issue_by_number() {
    let root = root();
    let mut found = Vec::new();
    let mut scanned = 0;
    let mut stack = vec![
        root.join("reference"),
        root.join("harness"),
        root.join("tests"),
        root.join("python/src"),
    ];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries {
            let path = e.expect("entry").path();
            if path.is_dir() {
                if !path.ends_with("target") {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|x| x == "rs") {
                scanned += 1;
                // This file's own examples below are deliberate.
                if path.ends_with("tests/docs.rs") {
                    continue;
                }
                for line in issue_numbers(&read(&path)) {
                    found.push(format!("{}:{line}", path.display()));
                }
            }
        }
    }
    assert!(scanned > 100, "only {scanned} Rust files scanned");
    assert!(
        found.is_empty(),
        "tracker issue numbers cited:\n{}",
        found.join("\n")
    );
    assert_eq!(
        // Built from parts, so that this file does not cite what it forbids.
        issue_numbers(
            &[
                "a (issue",
                " 27)\nthe_issue_example\nIssues",
                " 15 and 26\nissue tracker"
            ]
            .concat()
        ),
        [1, 3]
    );
}
