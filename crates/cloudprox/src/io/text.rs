//! Helpers shared by the text readers and writers: a whitespace tokenizer that
//! knows its line, number parsing and formatting, tokens quoted in messages.

use std::fmt::Write as _;

/// Whitespace-separated tokens of a byte buffer, with the 1-based line of each.
#[derive(Debug, Clone)]
pub(crate) struct Tokens<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Tokens<'a> {
    /// Tokens of `data`, whose first byte is on line `first_line`.
    pub(crate) fn new(data: &'a [u8], first_line: usize) -> Self {
        Self {
            data,
            pos: 0,
            line: first_line,
        }
    }

    /// The line of the next token (or of the end).
    pub(crate) fn line(&mut self) -> usize {
        self.skip_space();
        self.line
    }

    /// The line reached so far (at the end of the data: its last line).
    pub(crate) fn current_line(&self) -> usize {
        self.line
    }

    fn skip_space(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if b == b'\n' {
                self.line += 1;
            } else if !b.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
    }

    /// The next token and its line, or `None` at the end.
    pub(crate) fn next_token(&mut self) -> Option<(&'a [u8], usize)> {
        self.skip_space();
        if self.pos >= self.data.len() {
            return None;
        }
        let start = self.pos;
        while self
            .data
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        Some((&self.data[start..self.pos], self.line))
    }

    /// Skips the rest of the current line (e.g. an STL solid's name).
    pub(crate) fn skip_line(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if b == b'\n' {
                break;
            }
            self.pos += 1;
        }
    }
}

/// At most this many characters of a bad token are shown in an error.
const SHOW_MAX: usize = 40;

/// A token as it is quoted in an error message (lossy UTF-8, shortened, in
/// double quotes).
pub(crate) fn quote(token: &[u8]) -> String {
    let text = String::from_utf8_lossy(token);
    if text.chars().count() > SHOW_MAX {
        let short: String = text.chars().take(SHOW_MAX).collect();
        format!("{short:?}...")
    } else {
        format!("{text:?}")
    }
}

/// Formats a coordinate so that it reads back to exactly the same `f64`.
pub(crate) fn push_real(out: &mut String, x: f64) {
    let a = x.abs();
    if x == 0.0 || (1e-5..1e15).contains(&a) {
        let _ = write!(out, "{x}");
    } else {
        let _ = write!(out, "{x:e}");
    }
}

/// A token as text for messages (lossy, shortened).
pub(crate) fn show(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    if s.chars().count() > SHOW_MAX {
        format!("{}...", s.chars().take(SHOW_MAX).collect::<String>())
    } else {
        s.into_owned()
    }
}

/// Parses a float token (`nan`, `inf` accepted).
pub(crate) fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.trim().parse().ok()
}

/// Parses a float token as `f32` (the nearest `f32` to the decimal value).
pub(crate) fn parse_f32(token: &[u8]) -> Option<f32> {
    std::str::from_utf8(token).ok()?.trim().parse().ok()
}

/// Parses an integer token.
pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
    std::str::from_utf8(token).ok()?.trim().parse().ok()
}

/// Appends `values` separated by `sep`, then `\n`. Each is written in its
/// shortest form that reads back as the same `f64` (`{:?}`: `0.1`, `1.0`,
/// `1e-300`), so text files round-trip exactly.
pub(crate) fn push_row(out: &mut String, values: &[f64], sep: char) {
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            out.push(sep);
        }
        let _ = write!(out, "{v:?}");
    }
    out.push('\n');
}
