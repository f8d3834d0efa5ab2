//! A reader of Rust source for the layering tests (`harness/tests/layers.rs`,
//! `reference/tests/layers.rs`, which include this file by `#[path]`): comments and literals
//! blanked, `#[cfg(test)]` items blanked, `use` trees expanded. Text positions and line breaks
//! are kept, so what the tests report can point into the file. Written by hand: no crate reads
//! Rust's import structure without compiling it (`syn` parses, but knows no `cfg(test)` or
//! re-export resolution either, and would pull a proc-macro toolchain into two test builds for
//! a few hundred lines of lexing).

#![allow(dead_code)] // each test uses the part it needs

use std::collections::BTreeSet;

/// The source with comments, string and character literals blanked (lengths and line breaks
/// kept), so that only code is read.
pub fn code_only(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !ident_char_before(&b, i)
        {
            // A raw string r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            for &ch in &b[i..j.min(b.len())] {
                out.push(blank(ch));
            }
            i = j;
        } else if c == '"' {
            out.push(' ');
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < b.len() {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if c == '\'' {
            // A character literal ('a', '\n', '\''), not a lifetime ('a without a closing ').
            let end = if next == Some('\\') {
                (i + 3..b.len().min(i + 12)).find(|&j| b[j] == '\'')
            } else if b.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match end {
                Some(e) => {
                    out.extend(std::iter::repeat_n(' ', e + 1 - i));
                    i = e + 1;
                }
                None => {
                    out.push(c);
                    i += 1;
                }
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

pub fn ident_char_before(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// The end (exclusive) of the bracketed group opening at `open` (`(`, `[` or `{`).
pub fn group_end(b: &[u8], open: usize) -> usize {
    let mut depth = 0i32;
    for (j, &c) in b.iter().enumerate().skip(open) {
        match c {
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => {
                depth -= 1;
                if depth == 0 {
                    return j + 1;
                }
            }
            _ => {}
        }
    }
    b.len()
}

/// `code` with every `#[cfg(test)]` item blanked: the attribute, any attributes after it, and
/// the item up to its `;` or through its braces.
pub fn without_test_items(code: &str) -> String {
    let mut b = code.as_bytes().to_vec();
    let pattern = b"#[cfg(test)]";
    let mut i = 0;
    while i + pattern.len() <= b.len() {
        if &b[i..i + pattern.len()] != pattern {
            i += 1;
            continue;
        }
        let mut j = i + pattern.len();
        loop {
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if b.get(j) == Some(&b'#') && b.get(j + 1) == Some(&b'[') {
                j = group_end(&b, j + 1);
            } else {
                break;
            }
        }
        let mut end = b.len();
        while j < b.len() {
            match b[j] {
                b';' => {
                    end = j + 1;
                    break;
                }
                b'{' => {
                    end = group_end(&b, j);
                    break;
                }
                b'(' | b'[' => j = group_end(&b, j),
                _ => j += 1,
            }
        }
        for c in &mut b[i..end] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
        i = end;
    }
    String::from_utf8(b).expect("blanking keeps UTF-8: only ASCII bytes are replaced")
}

/// The inline modules (`mod name { … }`) of `code`: (name, start, end) byte spans.
pub fn inline_modules(code: &str) -> Vec<(String, usize, usize)> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    for (i, _) in code.match_indices("mod ") {
        if i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_') {
            continue;
        }
        let rest = &code[i + 4..];
        let ident: String = rest
            .trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let after = rest.trim_start()[ident.len()..].trim_start();
        if !ident.is_empty() && after.starts_with('{') {
            let open = i + 4 + (rest.len() - after.len());
            out.push((ident, open, group_end(b, open)));
        }
    }
    out
}

/// The `mod name;` declarations of `code` (file modules it declares).
pub fn declared_modules(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("mod ") {
        let b = code.as_bytes();
        if i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_') {
            continue;
        }
        let rest = code[i + 4..].trim_start();
        let ident: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !ident.is_empty() && rest[ident.len()..].trim_start().starts_with(';') {
            out.insert(ident);
        }
    }
    out
}

/// The paths a `use` tree names, each as segments (`a::{b, c::d}` → `[a, b]`, `[a, c, d]`);
/// `self` inside braces names the prefix, `*` the prefix too (a glob depends on the module).
pub fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn parse(s: &str, prefix: &[String], out: &mut Vec<Vec<String>>) {
        let s = s.trim();
        if let Some(open) = s.find('{') {
            let head: Vec<String> = s[..open]
                .split("::")
                .map(str::trim)
                .filter(|x| !x.is_empty())
                .map(String::from)
                .collect();
            let mut base = prefix.to_vec();
            base.extend(head);
            let inner = &s[open + 1..s.rfind('}').unwrap_or(s.len())];
            let mut depth = 0;
            let mut start = 0;
            for (k, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        parse(&inner[start..k], &base, out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            parse(&inner[start..], &base, out);
        } else {
            let s = s.split(" as ").next().unwrap_or(s);
            let mut path = prefix.to_vec();
            for seg in s.split("::").map(str::trim) {
                if !seg.is_empty() && seg != "*" && seg != "self" {
                    path.push(seg.to_string());
                }
            }
            if !path.is_empty() {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    parse(tree, &[], &mut out);
    out
}

/// The path written at the start of `text` (`crate :: a :: b` → `[crate, a, b]`).
pub fn path_at(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    loop {
        let ident: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if ident.is_empty() {
            break;
        }
        rest = &rest[ident.len()..];
        out.push(ident);
        let trimmed = rest.trim_start();
        if let Some(after) = trimmed.strip_prefix("::") {
            rest = after.trim_start();
        } else {
            break;
        }
    }
    out
}

/// Every `use` statement of `code`: its tree and whether it is a re-export (`pub`, `pub(…)`).
pub fn use_statements(code: &str) -> Vec<(String, bool)> {
    use_statements_at(code)
        .into_iter()
        .map(|(_, t, p)| (t, p))
        .collect()
}

/// Every `use` statement of `code` with the position of its tree (after `use `).
pub fn use_statements_at(code: &str) -> Vec<(usize, String, bool)> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    for (i, _) in code.match_indices("use ") {
        if i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_') {
            continue;
        }
        let Some(len) = code[i..].find(';') else {
            continue;
        };
        let before = code[..i].trim_end();
        let public = before.ends_with("pub")
            || (before.ends_with(')') && {
                let open = before.rfind('(').unwrap_or(0);
                before[..open].trim_end().ends_with("pub")
            });
        out.push((i + 4, code[i + 4..i + len].to_string(), public));
    }
    out
}
