//! A bounds-checked reader over a file's bytes whose errors name file, format
//! and byte offset.

use crate::error::{Error, Result};

/// Reads numbers and slices from a byte buffer; running past the end is an
/// [`Error::Format`] ("truncated") naming the file, the format and the offset.
#[derive(Debug, Clone)]
pub struct ByteCursor<'a> {
    data: &'a [u8],
    pos: usize,
    name: &'a str,
    format: &'static str,
}

macro_rules! read_num {
    ($le:ident, $t:ty, $n:expr) => {
        /// Reads one little-endian value.
        pub fn $le(&mut self) -> Result<$t> {
            let b = self.take($n)?;
            Ok(<$t>::from_le_bytes(b.try_into().expect("length checked")))
        }
    };
    ($le:ident, $be:ident, $t:ty, $n:expr) => {
        read_num!($le, $t, $n);
        /// Reads one big-endian value.
        pub fn $be(&mut self) -> Result<$t> {
            let b = self.take($n)?;
            Ok(<$t>::from_be_bytes(b.try_into().expect("length checked")))
        }
    };
}

impl<'a> ByteCursor<'a> {
    /// A cursor at the start of `data`; `name` and `format` go into errors.
    pub fn new(data: &'a [u8], name: &'a str, format: &'static str) -> Self {
        Self {
            data,
            pos: 0,
            name,
            format,
        }
    }

    /// The current offset.
    pub fn position(&self) -> usize {
        self.pos
    }

    /// Moves to `pos` (at most the length).
    pub fn seek(&mut self, pos: usize) -> Result<()> {
        if pos > self.data.len() {
            return Err(self.error(format!(
                "truncated: offset {pos} is past the end ({} bytes)",
                self.data.len()
            )));
        }
        self.pos = pos;
        Ok(())
    }

    /// Bytes left.
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.remaining() {
            return Err(self.error(format!(
                "truncated: needed {n} bytes at offset {}, only {} left",
                self.pos,
                self.remaining()
            )));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// The rest of the buffer.
    pub fn rest(&mut self) -> &'a [u8] {
        let s = &self.data[self.pos..];
        self.pos = self.data.len();
        s
    }

    /// The next line (without `\n` or `\r\n`), or `None` at the end.
    pub fn line(&mut self) -> Option<&'a [u8]> {
        if self.pos >= self.data.len() {
            return None;
        }
        let rest = &self.data[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        let line = &rest[..end];
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    }

    /// Reads one byte.
    pub fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    read_num!(u16_le, u16_be, u16, 2);
    read_num!(i16_le, i16_be, i16, 2);
    read_num!(u32_le, u32_be, u32, 4);
    read_num!(i32_le, i32_be, i32, 4);
    // (No reader needs a big-endian u64.)
    read_num!(u64_le, u64, 8);
    read_num!(f32_le, f32_be, f32, 4);
    read_num!(f64_le, f64_be, f64, 8);

    /// An [`Error::Format`] for this cursor's file and format.
    pub fn error(&self, problem: impl Into<String>) -> Error {
        Error::format(self.name, self.format, problem)
    }
}
