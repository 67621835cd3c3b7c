//! NumPy `.npy` files holding an `(n, k)` float array, `k >= 3`.
//!
//! Reading: versions 1.0, 2.0 and 3.0; dtypes `<f8 >f8 <f4 >f4`; C or Fortran
//! order. Columns 0, 1, 2 are `x y z`; further columns are ignored but named
//! `col3`, `col4`, ... in [`CloudData::fields`]. Structured dtypes and arrays
//! of more than 65536 columns are refused.
//!
//! Writing ([`write_npy`]): version 1.0, `<f8`, shape `(n, 3)`, C order, the
//! header padded so the data starts at a multiple of 64 bytes.

use crate::error::{Error, Result};
use crate::io::text::show;
use crate::io::{ByteCursor, CloudData, CloudDataBuilder};
use crate::math::Point3;

const FORMAT: &str = "NPY";
const MAGIC: &[u8] = b"\x93NUMPY";
/// More columns than this is not a point array (and each would get a name).
const MAX_COLUMNS: u64 = 1 << 16;

fn err(name: &str, problem: impl Into<String>) -> Error {
    Error::format(name, FORMAT, problem)
}

/// A value of the header's Python literal dict.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Str(String),
    Bool(bool),
    Int(u64),
    Tuple(Vec<Value>),
    List,
}

/// A small parser for the header dict: strings, `True`/`False`, integers,
/// tuples; lists are recognised (structured dtypes) but not kept.
struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    name: &'a str,
}

impl Parser<'_> {
    fn fail(&self, what: &str) -> Error {
        err(
            self.name,
            format!(
                "header dict: {what} at character {} of '{}'",
                self.i,
                show(self.s)
            ),
        )
    }

    fn ws(&mut self) {
        while self.s.get(self.i).is_some_and(u8::is_ascii_whitespace) {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> bool {
        self.ws();
        if self.s.get(self.i) == Some(&c) {
            self.i += 1;
            true
        } else {
            false
        }
    }

    fn value(&mut self, depth: usize) -> Result<Value> {
        if depth > 16 {
            return Err(self.fail("nesting too deep"));
        }
        self.ws();
        match self.s.get(self.i).copied() {
            Some(q @ (b'\'' | b'"')) => {
                let start = self.i + 1;
                let len = self.s[start..]
                    .iter()
                    .position(|&b| b == q)
                    .ok_or_else(|| self.fail("unterminated string"))?;
                self.i = start + len + 1;
                Ok(Value::Str(
                    String::from_utf8_lossy(&self.s[start..start + len]).into_owned(),
                ))
            }
            Some(b'(' | b'[') => {
                let list = self.s[self.i] == b'[';
                let close = if list { b']' } else { b')' };
                self.i += 1;
                let mut items = Vec::new();
                loop {
                    if self.eat(close) {
                        break;
                    }
                    items.push(self.value(depth + 1)?);
                    if self.eat(close) {
                        break;
                    }
                    if !self.eat(b',') {
                        return Err(self.fail("expected ',' or a closing bracket"));
                    }
                }
                Ok(if list {
                    Value::List
                } else {
                    Value::Tuple(items)
                })
            }
            Some(b'0'..=b'9') => {
                let start = self.i;
                while self.s.get(self.i).is_some_and(u8::is_ascii_digit) {
                    self.i += 1;
                }
                // Python 2 headers may write `3L`.
                if self.s.get(self.i) == Some(&b'L') {
                    self.i += 1;
                }
                std::str::from_utf8(&self.s[start..self.i])
                    .ok()
                    .and_then(|t| t.trim_end_matches('L').parse().ok())
                    .map(Value::Int)
                    .ok_or_else(|| self.fail("integer too large"))
            }
            _ if self.s[self.i..].starts_with(b"True") => {
                self.i += 4;
                Ok(Value::Bool(true))
            }
            _ if self.s[self.i..].starts_with(b"False") => {
                self.i += 5;
                Ok(Value::Bool(false))
            }
            _ => Err(self.fail("expected a string, number, True, False or tuple")),
        }
    }

    fn dict(&mut self) -> Result<Vec<(String, Value)>> {
        if !self.eat(b'{') {
            return Err(self.fail("expected '{'"));
        }
        let mut out = Vec::new();
        loop {
            if self.eat(b'}') {
                break;
            }
            let Value::Str(key) = self.value(0)? else {
                return Err(self.fail("expected a string key"));
            };
            if !self.eat(b':') {
                return Err(self.fail("expected ':'"));
            }
            let v = self.value(0)?;
            out.push((key, v));
            if self.eat(b'}') {
                break;
            }
            if !self.eat(b',') {
                return Err(self.fail("expected ',' or '}'"));
            }
        }
        Ok(out)
    }
}

/// Reads an NPY file.
///
/// # Errors
/// [`Error::Format`] naming the problem: wrong magic, unsupported version, a
/// header that is not the expected dict (naming the key), a dtype other than
/// `<f8 >f8 <f4 >f4` (structured dtypes included), a shape that is not `(n, k)`
/// with `k >= 3`, data shorter than the shape needs.
pub fn read_npy(bytes: &[u8], name: &str) -> Result<CloudData> {
    let mut cur = ByteCursor::new(bytes, name, FORMAT);
    let magic = cur.take(MAGIC.len()).ok();
    if magic != Some(MAGIC) {
        return Err(err(name, "wrong magic: an NPY file starts with \\x93NUMPY"));
    }
    let (major, minor) = (cur.u8()?, cur.u8()?);
    let header_len = match major {
        1 => usize::from(cur.u16_le()?),
        2 | 3 => cur.u32_le()? as usize,
        _ => {
            return Err(err(
                name,
                format!("unsupported NPY version {major}.{minor} (expected 1.0, 2.0 or 3.0)"),
            ))
        }
    };
    let header_start = cur.position();
    let header = cur.take(header_len).map_err(|_| {
        err(
            name,
            format!(
                "truncated: the header is {header_len} bytes, only {} left at offset {header_start}",
                bytes.len() - header_start
            ),
        )
    })?;
    let mut p = Parser {
        s: header,
        i: 0,
        name,
    };
    let dict = p.dict()?;
    let get = |k: &str| {
        dict.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v)
            .ok_or_else(|| err(name, format!("header dict has no '{k}' key")))
    };
    let (size, big) = match get("descr")? {
        Value::Str(d) => match d.as_str() {
            "<f8" => (8, false),
            ">f8" => (8, true),
            "<f4" => (4, false),
            ">f4" => (4, true),
            other => {
                return Err(err(
                    name,
                    format!("unsupported dtype '{other}' (expected <f8, >f8, <f4 or >f4)"),
                ))
            }
        },
        Value::List => {
            return Err(err(
                name,
                "structured dtypes are not supported; save a plain (n, 3) float array",
            ))
        }
        other => return Err(err(name, format!("'descr' is not a string: {other:?}"))),
    };
    let Value::Bool(fortran) = *get("fortran_order")? else {
        return Err(err(name, "'fortran_order' is not True or False"));
    };
    let shape: Vec<u64> = match get("shape")? {
        Value::Tuple(items) => items
            .iter()
            .map(|v| match v {
                Value::Int(i) => Ok(*i),
                _ => Err(err(name, "'shape' holds a value that is not an integer")),
            })
            .collect::<Result<_>>()?,
        _ => return Err(err(name, "'shape' is not a tuple")),
    };
    let [n, k] = shape[..] else {
        return Err(err(
            name,
            format!("shape {shape:?} is not 2-D; expected (n, 3) or (n, k) with k >= 3"),
        ));
    };
    if k > MAX_COLUMNS {
        return Err(err(
            name,
            format!("shape ({n}, {k}) has more than {MAX_COLUMNS} columns; not a point array"),
        ));
    }
    if k < 3 {
        return Err(err(
            name,
            format!("shape ({n}, {k}) has fewer than 3 columns"),
        ));
    }
    let data = cur.rest();
    let need = usize::try_from(n)
        .ok()
        .zip(usize::try_from(k).ok())
        .and_then(|(n, k)| n.checked_mul(k)?.checked_mul(size));
    let Some(need) = need.filter(|&need| need <= data.len()) else {
        return Err(err(
            name,
            format!(
                "truncated: shape ({n}, {k}) of {size}-byte floats needs {} bytes of data, found {}",
                u128::from(n) * u128::from(k) * size as u128,
                data.len()
            ),
        ));
    };
    let _ = need;
    let (n, k) = (n as usize, k as usize);
    let at = |i: usize, j: usize| -> f64 {
        let e = if fortran { j * n + i } else { i * k + j } * size;
        let b = &data[e..e + size];
        match (size, big) {
            (8, false) => f64::from_le_bytes(b.try_into().unwrap_or_default()),
            (8, true) => f64::from_be_bytes(b.try_into().unwrap_or_default()),
            (_, false) => f64::from(f32::from_le_bytes(b.try_into().unwrap_or_default())),
            (_, true) => f64::from(f32::from_be_bytes(b.try_into().unwrap_or_default())),
        }
    };
    let mut fields: Vec<String> = vec!["x".into(), "y".into(), "z".into()];
    fields.extend((3..k).map(|i| format!("col{i}")));
    let mut b = CloudDataBuilder::new(fields, None, false, false, n);
    for i in 0..n {
        b.push(i, Point3::new(at(i, 0), at(i, 1), at(i, 2)), None, None);
    }
    Ok(b.finish())
}

/// Encodes the points as NPY version 1.0: `<f8`, shape `(n, 3)`, C order,
/// data starting at a multiple of 64 bytes.
///
/// # Errors
/// None in practice (kept for symmetry with the other writers).
pub fn write_npy(cloud: &CloudData) -> Result<Vec<u8>> {
    let n = cloud.points.len();
    let mut dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({n}, 3), }}");
    // magic (6) + version (2) + length (2) + dict + '\n' must be a multiple of 64.
    let unpadded = MAGIC.len() + 4 + dict.len() + 1;
    dict.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    dict.push('\n');
    let len = u16::try_from(dict.len())
        .map_err(|_| Error::invalid("NPY header longer than 65535 bytes"))?;
    let mut out = Vec::with_capacity(10 + dict.len() + n * 24);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    for p in &cloud.points {
        for c in p.coords.iter() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    Ok(out)
}
