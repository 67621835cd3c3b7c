//! LAS and LAZ (ASPRS lidar point clouds): read only, through the `las` crate.
//!
//! The points' `x, y, z` are returned in the file's units (metres for projected
//! coordinate systems such as UTM) as `raw * scale + offset`, computed in `f64`:
//! large offsets keep the full precision the file stores. [`CloudData::fields`]
//! lists the attributes the file's point format carries (`x, y, z, intensity,
//! return_number, ..., gps_time, red, green, blue, nir, ...`); only the
//! coordinates are read into the cloud.
//!
//! Before the file is handed to the `las` crate its header is checked here: the
//! signature, finite and non-zero scales, finite offsets, a point count that the
//! data can hold (an uncompressed file must contain every point record its
//! header promises; a compressed one must not end early), and the extended
//! records, the LAZ chunk table and the layer sizes of LAS 1.4 LAZ chunks that
//! the crate would otherwise size its buffers from. Points are then read in batches, so a hostile count never allocates
//! more than the file can hold. Every error of the crate becomes an
//! [`Error::Format`] naming the file, with the format `LAS` or `LAZ` (compressed).
//!
//! The LAZ decoder can still panic on corrupt compressed points (its arithmetic
//! decoder has no way to tell them from valid ones). That panic is caught and
//! becomes an [`Error::Format`] too, and it prints nothing: the first call of
//! [`read_las`] installs, once per process, a panic hook that stays silent for
//! panics raised on a thread while it is inside the decoder and hands every
//! other panic to the hook that was there before. (A hook installed later by
//! the program replaces it; a decoder panic then prints through that hook, and
//! is still returned as an error.)
//!
//! The decoder also recurses without bound on some corrupt GPS time data, and
//! a stack overflow cannot be caught: LAZ is decoded on a thread of its own
//! whose stack use is checked on every read from the file (see
//! `GuardedBytes`), so that the recursion ends in an [`Error::Format`].

use std::cell::Cell;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

use crate::error::{Error, Result};
use crate::io::{ByteCursor, CloudData, CloudDataBuilder};
use crate::math::Point3;

/// Points read per batch.
const BATCH: u64 = 1 << 16;
/// The size of the LAS 1.0-1.2 public header block.
const MIN_HEADER: usize = 227;

/// What the header says, as far as the checks here need it.
struct HeaderFacts {
    compressed: bool,
    format_id: u8,
    count: u64,
    offset_to_points: u64,
}

/// `"LAZ"` when the point format's compression bit is set, or (when the header
/// cannot be read) when the name ends in `.laz`; `"LAS"` otherwise.
fn format_name(bytes: &[u8], name: &str) -> &'static str {
    let compressed = match bytes.get(104) {
        Some(&id) if bytes.starts_with(b"LASF") => id & 0x80 != 0,
        _ => name.to_ascii_lowercase().ends_with(".laz"),
    };
    if compressed {
        "LAZ"
    } else {
        "LAS"
    }
}

fn check_header(bytes: &[u8], name: &str, format: &'static str) -> Result<HeaderFacts> {
    let err = |problem: String| Error::format(name, format, problem);
    if !bytes.starts_with(b"LASF") {
        let shown: Vec<u8> = bytes.iter().take(4).copied().collect();
        return Err(err(format!(
            "the file does not start with the signature \"LASF\" (found {:?})",
            String::from_utf8_lossy(&shown)
        )));
    }
    if bytes.len() < MIN_HEADER {
        return Err(err(format!(
            "truncated: the public header block needs at least {MIN_HEADER} bytes, the file \
             has {}",
            bytes.len()
        )));
    }
    let mut cur = ByteCursor::new(bytes, name, format);
    cur.seek(24)?;
    let version = (cur.u8()?, cur.u8()?);
    cur.seek(94)?;
    let header_size = cur.u16_le()?;
    let offset_to_points = u64::from(cur.u32_le()?);
    let vlrs = cur.u32_le()?;
    let format_id = cur.u8()?;
    let record_len = u64::from(cur.u16_le()?);
    let legacy_count = u64::from(cur.u32_le()?);
    cur.seek(131)?;
    let mut scale = [0.0; 3];
    let mut offset = [0.0; 3];
    for s in &mut scale {
        *s = cur.f64_le()?;
    }
    for o in &mut offset {
        *o = cur.f64_le()?;
    }
    for (axis, (s, o)) in ["x", "y", "z"].iter().zip(scale.iter().zip(offset.iter())) {
        if !s.is_finite() || *s == 0.0 {
            return Err(err(format!(
                "the {axis} scale factor is {s}: it must be finite and non-zero"
            )));
        }
        if !o.is_finite() {
            return Err(err(format!("the {axis} offset is {o}: it must be finite")));
        }
    }
    let mut count = legacy_count;
    let mut evlrs: Option<(u64, u32)> = None;
    if version >= (1, 4) {
        let needed = 375;
        if bytes.len() < needed {
            return Err(err(format!(
                "truncated: a LAS {}.{} header needs {needed} bytes, the file has {}",
                version.0,
                version.1,
                bytes.len()
            )));
        }
        cur.seek(235)?;
        let start = cur.u64_le()?;
        let n = cur.u32_le()?;
        let count64 = cur.u64_le()?;
        if legacy_count == 0 {
            count = count64;
        }
        if n > 0 {
            evlrs = Some((start, n));
        }
    }
    let len = bytes.len() as u64;
    if u64::from(header_size) > len {
        return Err(err(format!(
            "truncated: the header size is {header_size} bytes, the file has {len}"
        )));
    }
    if offset_to_points > len {
        return Err(err(format!(
            "truncated: the point data starts at offset {offset_to_points}, the file has \
             {len} bytes"
        )));
    }
    let Some(data_len) = count.checked_mul(record_len) else {
        return Err(err(format!(
            "the header promises {count} points of {record_len} bytes: more than any file holds"
        )));
    };
    let compressed = format_id & 0x80 != 0;
    if !compressed
        && offset_to_points
            .checked_add(data_len)
            .is_none_or(|end| end > len)
    {
        return Err(err(format!(
            "truncated: the header promises {count} points of {record_len} bytes ({data_len} \
             bytes from offset {offset_to_points}), but the file has {len} bytes"
        )));
    }
    if let Some((start, n)) = evlrs {
        // The crate reads the first extended record and sizes its buffer from it.
        let header_end = start.checked_add(60).filter(|&e| e <= len).ok_or_else(|| {
            err(format!(
                "truncated: the header promises {n} extended records from offset {start}, the \
                 file has {len} bytes"
            ))
        })?;
        cur.seek(start as usize + 20)?;
        let record = cur.u64_le()?;
        if header_end.checked_add(record).is_none_or(|e| e > len) {
            return Err(err(format!(
                "truncated: the extended record at offset {start} promises {record} bytes, the \
                 file has {len}"
            )));
        }
    }
    if compressed {
        let layers = check_laszip_items(&mut cur, header_size, vlrs, record_len)?;
        check_chunk_table(bytes, &mut cur, offset_to_points)?;
        if let Some(chunks) = layers {
            check_layered_chunks(
                bytes,
                &mut cur,
                offset_to_points,
                record_len,
                count,
                &chunks,
            )?;
        }
    }
    Ok(HeaderFacts {
        compressed,
        format_id,
        count,
        offset_to_points,
    })
}

/// The LAZ items (in the `laszip encoded` record) must add up to the point
/// record length, or the decoder writes past its buffer. Returns how the
/// chunks are laid out when the points are compressed in layers (LAS 1.4
/// point formats), `None` otherwise.
fn check_laszip_items(
    cur: &mut ByteCursor,
    header_size: u16,
    vlrs: u32,
    record_len: u64,
) -> Result<Option<LayeredChunks>> {
    cur.seek(usize::from(header_size))?;
    // Variable length records: a 54-byte header, then `length` bytes.
    for _ in 0..vlrs {
        if cur.remaining() < 54 {
            break;
        }
        let start = cur.position();
        let _reserved = cur.u16_le()?;
        let user_id = cur.take(16)?;
        let record_id = cur.u16_le()?;
        let length = usize::from(cur.u16_le()?);
        let _description = cur.take(32)?;
        if user_id.starts_with(b"laszip encoded") && record_id == 22204 {
            let data = cur.take(length)?;
            let mut items = ByteCursor::new(data, "", "LAZ");
            let compressor = items
                .u16_le()
                .map_err(|_| cur.error("the laszip record is too short"))?;
            items
                .seek(32)
                .map_err(|_| cur.error("the laszip record is too short"))?;
            let n = items
                .u16_le()
                .map_err(|_| cur.error("the laszip record is too short"))?;
            let mut total = 0u64;
            let mut layers = 0u64;
            for _ in 0..n {
                let kind = items.u16_le().unwrap_or(0);
                let size = items.u16_le().map_err(|_| {
                    cur.error(format!(
                        "the laszip record at offset {start} lists {n} items but is only {length} bytes"
                    ))
                })?;
                let _version = items.u16_le();
                // The decoder reads each item's fixed size from the record's
                // bytes without checking it (unchecked reads in release builds).
                let fixed = match kind {
                    6 => Some(20),
                    7 | 12 => Some(8),
                    8 | 11 => Some(6),
                    9 | 13 => Some(29),
                    10 => Some(30),
                    _ => None,
                };
                if fixed.is_some_and(|f| f != size) {
                    return Err(cur.error(format!(
                        "the laszip record's item of type {kind} is {size} bytes, not {}",
                        fixed.unwrap_or(0)
                    )));
                }
                total += u64::from(size);
                // Layers per item in laz 0.13: point 14 has 9, RGB 1, RGB+NIR 2,
                // wave packet 1, extra bytes one per byte.
                layers += match kind {
                    10 => 9,
                    11 | 13 => 1,
                    12 => 2,
                    14 => u64::from(size),
                    _ => 0,
                };
            }
            if total != record_len {
                return Err(cur.error(format!(
                    "the laszip items add up to {total} bytes per point but the header's point \
                     records are {record_len} bytes"
                )));
            }
            // The decoder compresses in layers whenever the items are the
            // LAS 1.4 ones, whatever the compressor field says.
            return Ok((layers > 0).then_some(LayeredChunks {
                layers,
                // Compressor 1 (point-wise, one chunk) has no chunk table offset.
                table_offset: compressor != 1,
                // Offset 12: the number of points in a chunk (u32::MAX: variable).
                chunk_size: u32::from_le_bytes(
                    data.get(12..16)
                        .and_then(|b| b.try_into().ok())
                        .unwrap_or([0; 4]),
                ),
            }));
        }
        if cur.take(length).is_err() {
            break;
        }
    }
    // No laszip record: the las crate reports it.
    Ok(None)
}

/// How a file compressed in layers lays out its chunks (from its `laszip`
/// record).
struct LayeredChunks {
    /// Layers per chunk.
    layers: u64,
    /// Whether the point data starts with the 8-byte chunk table offset.
    table_offset: bool,
    /// Points per chunk (`u32::MAX`: each chunk says how many it holds).
    chunk_size: u32,
}

/// A layered chunk is its first point (uncompressed), its number of points,
/// the byte size of each of its layers, then the layers. The decoder
/// allocates (and zeroes) each layer at the size it reads, up to 4 GiB, before
/// it reads the layer, so every chunk's sizes must fit in the file. The
/// chunks are walked in order until they hold the header's point count.
fn check_layered_chunks(
    bytes: &[u8],
    cur: &mut ByteCursor,
    data_start: u64,
    record_len: u64,
    count: u64,
    chunks: &LayeredChunks,
) -> Result<()> {
    let len = bytes.len() as u64;
    let mut pos = data_start + if chunks.table_offset { 8 } else { 0 };
    let mut points = 0u64;
    let mut chunk = 0u64;
    while points < count {
        let sizes_at = pos
            .checked_add(record_len + 4)
            .filter(|&p| p.checked_add(4 * chunks.layers).is_some_and(|e| e <= len))
            .ok_or_else(|| {
                cur.error(format!(
                    "truncated: chunk {chunk} (from offset {pos}) and its {} layer sizes do \
                     not fit in the file ({len} bytes)",
                    chunks.layers
                ))
            })?;
        cur.seek(sizes_at as usize - 4)?;
        let in_chunk = u64::from(cur.u32_le()?);
        let mut total = 0u64;
        for _ in 0..chunks.layers {
            total += u64::from(cur.u32_le()?);
        }
        let left = cur.remaining() as u64;
        if total > left {
            return Err(cur.error(format!(
                "truncated: the layers of chunk {chunk} (from offset {pos}) add up to {total} \
                 bytes, only {left} are left"
            )));
        }
        let held = if chunks.chunk_size == u32::MAX {
            in_chunk
        } else {
            u64::from(chunks.chunk_size)
        };
        if held == 0 {
            return Err(cur.error(format!("chunk {chunk} (from offset {pos}) holds no point")));
        }
        points = points.saturating_add(held);
        pos = (cur.position() as u64) + total;
        chunk += 1;
    }
    Ok(())
}

/// The LAZ chunk table: the crate sizes a buffer from its chunk count.
fn check_chunk_table(bytes: &[u8], cur: &mut ByteCursor, data_start: u64) -> Result<()> {
    let len = bytes.len() as u64;
    let start = usize::try_from(data_start).map_err(|_| cur.error("offset too large"))?;
    cur.seek(start)?;
    let mut table = i64::from_le_bytes(cur.take(8)?.try_into().unwrap_or([0; 8]));
    let table_data = data_start + 8;
    // As the crate does: an offset at or before the point data (-1 from a
    // streaming writer, or any other) sends it to the file's last 8 bytes.
    if u64::try_from(table).map_or(true, |t| t <= data_start) {
        if len < table_data + 8 {
            return Ok(()); // the crate fails to read it: a format error
        }
        cur.seek((len - 8) as usize)?;
        table = i64::from_le_bytes(cur.take(8)?.try_into().unwrap_or([0; 8]));
        if u64::try_from(table).map_or(true, |t| t <= data_start) {
            return Ok(()); // no chunk table: the crate reads the points sequentially
        }
    }
    let table = table.unsigned_abs();
    if table.checked_add(8).is_none_or(|e| e > len) {
        return Err(cur.error(format!(
            "truncated: the chunk table is at offset {table}, the file has {len} bytes"
        )));
    }
    cur.seek(table as usize + 4)?;
    let chunks = u64::from(cur.u32_le()?);
    // Every chunk holds at least one byte of compressed points before the
    // table (a file without points lists one empty chunk).
    let data = table.saturating_sub(table_data);
    if chunks > data.max(1) {
        return Err(cur.error(format!(
            "the chunk table lists {chunks} chunks but there are only {data} bytes of point data"
        )));
    }
    Ok(())
}

/// The names of the attributes of a LAS point format.
fn field_names(format: las::point::Format) -> Vec<String> {
    let mut f: Vec<&str> = vec![
        "x",
        "y",
        "z",
        "intensity",
        "return_number",
        "number_of_returns",
    ];
    if format.is_extended {
        f.push("scanner_channel");
    }
    f.extend([
        "scan_direction_flag",
        "edge_of_flight_line",
        "classification",
    ]);
    f.extend(["synthetic", "key_point", "withheld"]);
    if format.is_extended {
        f.push("overlap");
    }
    f.extend(["scan_angle", "user_data", "point_source_id"]);
    if format.has_gps_time {
        f.push("gps_time");
    }
    if format.has_color {
        f.extend(["red", "green", "blue"]);
    }
    if format.has_nir {
        f.push("nir");
    }
    if format.has_waveform {
        f.extend([
            "wave_packet_descriptor_index",
            "byte_offset_to_waveform_data",
            "waveform_packet_size",
            "return_point_waveform_location",
            "x_t",
            "y_t",
            "z_t",
        ]);
    }
    let mut names: Vec<String> = f.into_iter().map(String::from).collect();
    if format.extra_bytes > 0 {
        names.push(format!("extra_bytes_{}", format.extra_bytes));
    }
    names
}

thread_local! {
    /// Whether this thread is inside the `las`/`laz` decoder (see [`quietly`]).
    static IN_DECODER: Cell<bool> = const { Cell::new(false) };
}

static QUIET_HOOK: Once = Once::new();

/// Clears [`IN_DECODER`] when the decoder call ends, by return or by unwind.
struct DecoderScope(bool);

impl Drop for DecoderScope {
    fn drop(&mut self) {
        IN_DECODER.with(|f| f.set(self.0));
    }
}

/// Runs `f` (a call into the `las` crate) with its panics caught and silent:
/// a panic is returned as its message, and the panic hook prints nothing for
/// it. Panics elsewhere, on this thread or others, reach the previous hook.
fn quietly<T>(f: impl FnOnce() -> T) -> std::result::Result<T, String> {
    QUIET_HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !IN_DECODER.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let _scope = DecoderScope(IN_DECODER.with(|flag| flag.replace(true)));
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default()
    })
}

/// Reads a LAS or LAZ file from its bytes; `name` is used in errors.
///
/// # Errors
/// [`Error::Format`] (format `LAS` or `LAZ`) naming the problem: a bad signature
/// or header field, a truncated file (with the count the header promises and
/// the bytes there are), or what the `las` crate reported.
pub fn read_las(bytes: &[u8], name: &str) -> Result<CloudData> {
    let format = format_name(bytes, name);
    let facts = check_header(bytes, name, format)?;
    // The crate is not ours: a panic inside it on a corrupt file becomes a
    // format error rather than unwinding into the caller, and prints nothing.
    let decode = || match quietly(|| read_points(bytes, name, format, &facts)) {
        Ok(result) => result,
        Err(what) => Err(Error::format(
            name,
            format,
            format!("corrupt point data: the LAS/LAZ decoder failed ({what})"),
        )),
    };
    if !facts.compressed {
        return decode();
    }
    // LAZ: on a thread of its own, whose stack the decoder's recursion is
    // measured against (see `GuardedBytes`).
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("cloudprox-laz".into())
            .stack_size(DECODER_STACK)
            .spawn_scoped(scope, decode)
            .map_err(|e| {
                Error::format(
                    name,
                    format,
                    format!("could not start the LAZ decoder's thread: {e}"),
                )
            })?
            .join()
            .unwrap_or_else(|_| {
                Err(Error::format(
                    name,
                    format,
                    "corrupt point data: the LAZ decoder failed",
                ))
            })
    })
}

/// The stack of the LAZ decoder's thread (reserved address space; only the
/// pages a decode touches are used).
const DECODER_STACK: usize = 256 << 20;

/// How much of [`DECODER_STACK`] the decoder may use before a read from the
/// file is refused: the rest is the margin below.
const DECODER_STACK_LIMIT: usize = 64 << 20;

thread_local! {
    /// The address of a local at the top of the decoder's frames, when this
    /// thread is inside [`read_points`] (0 otherwise).
    static STACK_BASE: Cell<usize> = const { Cell::new(0) };
}

/// The address of a local of the caller's frame: how deep the stack is.
#[inline(never)]
fn stack_position() -> usize {
    let marker = 0u8;
    std::ptr::from_ref(std::hint::black_box(&marker)).addr()
}

/// The file's bytes as the `las` crate reads them, with a check of the stack
/// on every read.
///
/// The `laz` decoder (0.13, the latest release) decodes a GPS time that
/// switches to another of its four sequences by calling itself
/// (`las/gps.rs`, `decompress_with`, as LASzip does), as often as the
/// arithmetic-coded data says: on corrupt data without bound, until the stack
/// overflows, which aborts the process and cannot be caught. Its arithmetic
/// decoder reads a byte from the file at least every 36 400 symbols (a
/// symbol's probability is at most `1 - 5 / 2^15` in its adaptive models, and
/// it reads a byte whenever the interval has shrunk by `2^8`), one symbol per
/// level of that recursion. So a read that finds more than
/// [`DECODER_STACK_LIMIT`] of the decoder thread's stack in use fails (an
/// `io::Error` the decoder passes up, which unwinds the recursion), and the
/// recursion cannot grow by more than 36 400 frames (192 MiB at 5 KiB a
/// frame) before the next read checks again.
#[derive(Debug)]
struct GuardedBytes(Cursor<Vec<u8>>);

impl std::io::Read for GuardedBytes {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let base = STACK_BASE.with(Cell::get);
        if base != 0 && base.abs_diff(stack_position()) > DECODER_STACK_LIMIT {
            return Err(std::io::Error::other(format!(
                "the LAZ decoder recursed past {} MiB of stack (corrupt GPS time data)",
                DECODER_STACK_LIMIT >> 20
            )));
        }
        self.0.read(buf)
    }
}

impl std::io::Seek for GuardedBytes {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.0.seek(pos)
    }
}

/// Sets [`STACK_BASE`] for the duration of a decode.
struct StackScope(usize);

impl StackScope {
    fn enter() -> Self {
        StackScope(STACK_BASE.with(|b| b.replace(stack_position())))
    }
}

impl Drop for StackScope {
    fn drop(&mut self) {
        STACK_BASE.with(|b| b.set(self.0));
    }
}

fn read_points(
    bytes: &[u8],
    name: &str,
    format: &'static str,
    facts: &HeaderFacts,
) -> Result<CloudData> {
    let crate_err =
        |what: &str, e: &las::Error| Error::format(name, format, format!("{what}: {e}"));
    let _stack = StackScope::enter();
    let mut reader = las::Reader::new(GuardedBytes(Cursor::new(bytes.to_vec()))).map_err(|e| {
        crate_err(
            "cannot read the header, its records or the LAZ chunk table",
            &e,
        )
    })?;
    let header = reader.header();
    if header.point_format().is_compressed != facts.compressed {
        return Err(Error::format(
            name,
            format,
            format!("point format id {} is inconsistent", facts.format_id),
        ));
    }
    let count = header.number_of_points();
    if count != facts.count {
        return Err(Error::format(
            name,
            format,
            format!(
                "the header's point counts disagree ({count} and {})",
                facts.count
            ),
        ));
    }
    let fields = field_names(*header.point_format());
    let capacity = usize::try_from(count)
        .unwrap_or(usize::MAX)
        .min(bytes.len() / 20);
    let mut builder = CloudDataBuilder::new(fields, None, false, false, capacity);
    let mut done: u64 = 0;
    while done < count {
        let want = (count - done).min(BATCH);
        let batch = reader.read_points(want).map_err(|e| {
            Error::format(
                name,
                format,
                format!(
                    "truncated or corrupt point data: the header promises {count} points from \
                     offset {}, reading points {done} to {} failed: {e}",
                    facts.offset_to_points,
                    done + want - 1
                ),
            )
        })?;
        let got = batch.len() as u64;
        if got != want {
            return Err(Error::format(
                name,
                format,
                format!(
                    "truncated: the header promises {count} points, the file holds {}",
                    done + got
                ),
            ));
        }
        for (k, ((x, y), z)) in batch.x().zip(batch.y()).zip(batch.z()).enumerate() {
            builder.push(done as usize + k, Point3::new(x, y, z), None, None);
        }
        done += got;
    }
    Ok(builder.finish())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn a_runaway_recursion_fails_its_read_before_the_stack_overflows() {
        // Without the guard this overflows the stack and aborts the test run.
        let depth = std::thread::Builder::new()
            .stack_size(DECODER_STACK)
            .spawn(|| {
                let _stack = StackScope::enter();
                let mut src = GuardedBytes(Cursor::new(vec![0u8; 1 << 20]));
                let mut reached = 0;
                let err = recurse_counting(&mut src, 0, &mut reached).unwrap_err();
                assert!(err.to_string().contains("recursed past 64 MiB"), "{err}");
                reached
            })
            .unwrap()
            .join()
            .unwrap();
        // Stopped at the first read past the limit: 64 MiB of frames of at
        // least 4 KiB is at most 16 384 levels (at least 8 000 if the compiler
        // doubles the frame).
        assert!((8_000..=17_000).contains(&depth), "{depth}");
        // Outside a decode (no stack scope) reads are never refused.
        let mut plain = GuardedBytes(Cursor::new(vec![7u8; 4]));
        let mut b = [0u8; 4];
        plain.read_exact(&mut b).unwrap();
        assert_eq!(b, [7; 4]);
    }

    /// A recursion like the decoder's: a 4 KiB frame a level, a byte read
    /// from the file every 1000 levels, no end but a failed read.
    fn recurse_counting(
        src: &mut GuardedBytes,
        depth: usize,
        reached: &mut usize,
    ) -> std::io::Result<usize> {
        *reached = depth;
        let frame = std::hint::black_box([depth as u8; 4096]);
        if depth % 1000 == 0 {
            let mut b = [0u8; 1];
            src.read_exact(&mut b)?;
        }
        let deeper = recurse_counting(src, depth + 1, reached)?;
        Ok(deeper + usize::from(frame[depth % 4096] == 0))
    }
}
