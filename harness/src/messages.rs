//! Messages for users: serde_json's errors and our own, without 300-digit numbers or Rust type
//! names ("Bad input").

/// A serde_json error as a message for a user: serde's text (which names the key and the
/// position) with long numbers shortened ([`compact_numbers`]).
pub fn json_error_message(e: &serde_json::Error) -> String {
    plain_types(&compact_numbers(&e.to_string()))
}

/// `text` with the Rust type names serde prints (`expected f64`, `expected u32`) in words: the
/// user wrote JSON, not Rust.
pub fn plain_types(text: &str) -> String {
    let words: Vec<&str> = text.split(' ').collect();
    words
        .iter()
        .map(|w| {
            let core = w.trim_end_matches([',', ';', ')']);
            let tail = &w[core.len()..];
            let plain = match core {
                "f64" | "f32" => "a number",
                "u8" | "u16" | "u32" | "u64" | "usize" => "a non-negative integer",
                "i8" | "i16" | "i32" | "i64" | "isize" => "an integer",
                _ => return (*w).to_string(),
            };
            format!("{plain}{tail}")
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// `text` with every decimal number of more than 17 significant digits (Rust prints f64 such as
/// 1e300 with all 301 digits) rewritten in the shortest scientific form, e.g. `1e300`.
/// Hand-written: a dozen lines, no crate does this one thing.
pub fn compact_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let len = tail
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(tail.len());
        let token = &tail[..len];
        let digits = token.bytes().filter(u8::is_ascii_digit).count();
        match token.parse::<f64>() {
            Ok(x) if digits > 17 => out.push_str(&format!("{x:e}")),
            _ => out.push_str(token),
        }
        rest = &tail[len..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_and_type_names_are_rewritten() {
        let long = format!("got {}", 1e300);
        assert!(long.len() > 300);
        assert_eq!(compact_numbers(&long), "got 1e300");
        assert_eq!(
            compact_numbers("got 0.25 at line 1 column 7"),
            "got 0.25 at line 1 column 7"
        );
        assert_eq!(
            plain_types("invalid type: string \"x\", expected f64 at line 1"),
            "invalid type: string \"x\", expected a number at line 1"
        );
        let e = serde_json::from_str::<f64>("\"x\"").unwrap_err();
        let m = json_error_message(&e);
        assert!(m.contains("a number") && !m.contains("f64"), "{m}");
    }
}
