//! Line and column (1-based, the column in characters) of a byte offset of the scene text, as
//! roxmltree's `Document::text_pos_at` gives them, in time linear in the text over a walk in
//! document order: `text_pos_at` scans the text from its start on every call, so naming every
//! anonymous plugin (`shape@line:column`) of a scene was quadratic in its elements (61 000
//! shapes in a 1 MiB file took 21 s). Hand-written: roxmltree offers only the per-call scan.

use std::cell::Cell;

/// The positions of one text.
pub(super) struct Positions<'t> {
    text: &'t str,
    /// The byte offset at which each line starts (the first is 0).
    line_starts: Vec<usize>,
    /// The last position answered (byte offset, line, column): the next one, later on the same
    /// line, counts characters from there, not from the line's start (a one-line file).
    last: Cell<(usize, usize, usize)>,
}

impl<'t> Positions<'t> {
    /// Indexes the lines of `text`.
    pub(super) fn new(text: &'t str) -> Self {
        let line_starts = std::iter::once(0)
            .chain(
                text.bytes()
                    .enumerate()
                    .filter_map(|(i, b)| (b == b'\n').then_some(i + 1)),
            )
            .collect();
        Self {
            text,
            line_starts,
            last: Cell::new((0, 1, 1)),
        }
    }

    /// (line, column) of byte offset `pos` (clamped to the text, and back to a character
    /// boundary).
    pub(super) fn at(&self, pos: usize) -> (usize, usize) {
        let mut pos = pos.min(self.text.len());
        while !self.text.is_char_boundary(pos) {
            pos -= 1;
        }
        let line = self.line_starts.partition_point(|&s| s <= pos);
        let start = self.line_starts[line - 1];
        let (last_pos, last_line, last_col) = self.last.get();
        let (from, col) = if last_line == line && (start..=pos).contains(&last_pos) {
            (last_pos, last_col)
        } else {
            (start, 1)
        };
        let col = col + self.text[from..pos].chars().count();
        self.last.set((pos, line, col));
        (line, col)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same line and column as roxmltree's scan at every element, in document order and
    /// backwards, over several lines with multi-byte characters.
    #[test]
    fn positions_are_roxmltrees() {
        let text = "<scene>\n  <shape type=\"é\"/><shape/>\n\n<bsdf id=\"ü\">\n<float name=\"alpha\" value=\"0.1\"/></bsdf>  <shape/>\n</scene>";
        let doc = roxmltree::Document::parse(text).unwrap();
        let p = Positions::new(text);
        let starts: Vec<usize> = doc.descendants().map(|n| n.range().start).collect();
        for &s in starts.iter().chain(starts.iter().rev()) {
            let t = doc.text_pos_at(s);
            assert_eq!(p.at(s), (t.row as usize, t.col as usize), "offset {s}");
        }
        assert_eq!(p.at(text.len() + 10), {
            let t = doc.text_pos_at(text.len());
            (t.row as usize, t.col as usize)
        });
    }
}
