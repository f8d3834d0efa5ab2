//! The documentation holds together: every relative link of README.md, ARCHITECTURE.md and
//! docs/*.md reaches an existing file, and every `#anchor` a heading of its target (GitHub's
//! slugs); every doc comment or string of the workspace's Rust files that cites a section of
//! ARCHITECTURE.md (`ARCHITECTURE.md, "Section"`, `ARCHITECTURE.md "A", "B"`, or a record
//! source's `ARCHITECTURE.md model boundary: …`) names one of its headings; every page of docs/
//! is linked from the README; and the README stays at most 200 lines (issue 24: reference
//! material goes to docs/). The checkers are tested on broken input too, so that a pass means
//! they looked.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

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
        slug("Seed 004 — Deriving G1 for γ ∈ (0, 4] (Dimov, GTR)"),
        "seed-004--deriving-g1-for-γ--0-4-dimov-gtr"
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
