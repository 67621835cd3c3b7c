//! ROS `sensor_msgs/PointCloud2`: the message's field layout plus its raw
//! `data` bytes, or the whole serialized message as a bag stores it.
//!
//! Reading ([`read_pointcloud2`]): fields `x y z` are required (any datatype),
//! `normal_x normal_y normal_z` become normals, other fields are named in
//! [`CloudData::fields`] and otherwise ignored. Point `(row, column)` starts at
//! byte `row * row_step + column * point_step`. A cloud with `height > 1` is
//! organized ([`CloudData::grid`]); its no-return points are left out and
//! counted: NaN or infinite points in [`CloudData::skipped`] (REP 117), points
//! at exactly `(0, 0, 0)` in [`CloudData::at_origin`] (drivers write a beam
//! that returned nothing as the origin of the sensor's frame, the frame a raw
//! scan is published in). An unorganized cloud keeps its points at the origin.
//!
//! Serialized messages ([`read_pointcloud2_message`], [`decode_pointcloud2`]):
//! the bytes a rosbag2 (sqlite3 or MCAP) stores, CDR with its 4-byte
//! encapsulation header (little or big endian), or the bytes a ROS 1 `.bag`
//! stores ([`MessageEncoding::Ros1`]). The header and layout are decoded and
//! the points read straight from the message's bytes (nothing is copied
//! before the points are).
//!
//! Writing ([`write_pointcloud2`]): `float32` `x y z` (and `normal_x normal_y
//! normal_z` when the cloud has normals), little endian, dense, `height` 1.

use crate::error::{Error, Result};
use crate::io::{ByteCursor, CloudData, CloudDataBuilder, Grid};
use crate::math::{Point3, Vector3};

const NAME: &str = "PointCloud2";

/// `PointField.datatype` of a signed 8-bit integer.
pub const INT8: u8 = 1;
/// `PointField.datatype` of an unsigned 8-bit integer.
pub const UINT8: u8 = 2;
/// `PointField.datatype` of a signed 16-bit integer.
pub const INT16: u8 = 3;
/// `PointField.datatype` of an unsigned 16-bit integer.
pub const UINT16: u8 = 4;
/// `PointField.datatype` of a signed 32-bit integer.
pub const INT32: u8 = 5;
/// `PointField.datatype` of an unsigned 32-bit integer.
pub const UINT32: u8 = 6;
/// `PointField.datatype` of a 32-bit float.
pub const FLOAT32: u8 = 7;
/// `PointField.datatype` of a 64-bit float.
pub const FLOAT64: u8 = 8;

/// One `sensor_msgs/PointField`: a named value at a byte offset in each point.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointField {
    /// The field's name (`x`, `y`, `z`, `intensity`, `rgb`, ...).
    pub name: String,
    /// Byte offset of the field inside a point record.
    pub offset: u32,
    /// Its type: [`INT8`] .. [`FLOAT64`] (1 to 8).
    pub datatype: u8,
    /// How many values of that type (1 for a scalar).
    pub count: u32,
}

/// The layout fields of a `sensor_msgs/PointCloud2` message (everything but
/// `header`, `data` and `is_dense`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointCloud2Layout {
    /// Rows (1 for an unorganized cloud).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The per-point fields.
    pub fields: Vec<PointField>,
    /// Whether the values are big endian.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
}

/// How a serialized `sensor_msgs/PointCloud2` message is encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MessageEncoding {
    /// ROS 2 (rosbag2, sqlite3 or MCAP): CDR (XCDR1) with its 4-byte
    /// encapsulation header, little or big endian.
    Cdr,
    /// ROS 1 (`.bag`): little endian, no alignment, `Header.seq` first.
    Ros1,
}

/// The `std_msgs/Header` of a message, and its `is_dense` flag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointCloud2Header {
    /// `header.stamp` in nanoseconds since the epoch (ROS 2 `sec` may be
    /// negative; ROS 1 `secs` is unsigned).
    pub stamp_ns: i64,
    /// `header.frame_id`: the frame the points are expressed in.
    pub frame_id: String,
    /// `is_dense`: the message says it holds no invalid point.
    pub is_dense: bool,
}

/// A decoded message: its header, layout, and the `data` bytes (borrowed
/// from the message).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointCloud2Message<'a> {
    /// The header (stamp, frame) and `is_dense`.
    pub header: PointCloud2Header,
    /// The field layout.
    pub layout: PointCloud2Layout,
    /// The `data` bytes, inside the message's bytes.
    pub data: &'a [u8],
}

fn err(name: &str, problem: impl Into<String>) -> Error {
    Error::format(name, NAME, problem)
}

fn type_size(datatype: u8) -> Option<usize> {
    Some(match datatype {
        INT8 | UINT8 => 1,
        INT16 | UINT16 => 2,
        INT32 | UINT32 | FLOAT32 => 4,
        FLOAT64 => 8,
        _ => return None,
    })
}

#[inline]
fn value(b: &[u8], datatype: u8, big: bool) -> f64 {
    macro_rules! num {
        ($t:ty, $n:expr) => {{
            let mut a = [0u8; $n];
            a.copy_from_slice(&b[..$n]);
            if big {
                <$t>::from_be_bytes(a)
            } else {
                <$t>::from_le_bytes(a)
            }
        }};
    }
    match datatype {
        INT8 => f64::from(i8::from_le_bytes([b[0]])),
        UINT8 => f64::from(b[0]),
        INT16 => f64::from(num!(i16, 2)),
        UINT16 => f64::from(num!(u16, 2)),
        INT32 => f64::from(num!(i32, 4)),
        UINT32 => f64::from(num!(u32, 4)),
        FLOAT32 => f64::from(num!(f32, 4)),
        _ => num!(f64, 8),
    }
}

/// Reads the points of a `sensor_msgs/PointCloud2` message from its layout and
/// `data` bytes.
///
/// # Errors
/// [`Error::Format`] (file name and format `"PointCloud2"`) naming the
/// problem: no `x`/`y`/`z` field (or one of count 0), a field named twice, an
/// unknown datatype, a field reaching past
/// `point_step`, `point_step * width > row_step`, `data` shorter than
/// `row_step * height`.
pub fn read_pointcloud2(layout: &PointCloud2Layout, data: &[u8]) -> Result<CloudData> {
    read_pointcloud2_named(layout, data, NAME)
}

/// [`read_pointcloud2`] with the name its errors give (a bag's file, topic
/// and message, say) instead of `"PointCloud2"`.
///
/// # Errors
/// As [`read_pointcloud2`].
pub fn read_pointcloud2_named(
    layout: &PointCloud2Layout,
    data: &[u8],
    name: &str,
) -> Result<CloudData> {
    let step = layout.point_step as usize;
    let mut sizes = Vec::with_capacity(layout.fields.len());
    for f in &layout.fields {
        let size = type_size(f.datatype).ok_or_else(|| {
            err(
                name,
                format!(
                    "field '{}' has unknown datatype {} (expected 1 to 8)",
                    f.name, f.datatype
                ),
            )
        })?;
        let end = (f.offset as usize).saturating_add(size.saturating_mul(f.count as usize));
        if end > step {
            return Err(err(
                name,
                format!(
                    "field '{}' (offset {}, {} x {size} bytes) reaches past point_step {step}",
                    f.name, f.offset, f.count
                ),
            ));
        }
        sizes.push(size);
    }
    for (i, f) in layout.fields.iter().enumerate() {
        if layout.fields[..i].iter().any(|g| g.name == f.name) {
            return Err(err(name, format!("field '{}' appears twice", f.name)));
        }
    }
    let find = |n: &str| {
        layout
            .fields
            .iter()
            .position(|f| f.name == n && f.count >= 1)
    };
    let mut xyz = [0usize; 3];
    for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = find(axis).ok_or_else(|| {
            if layout.fields.iter().any(|f| f.name == axis) {
                return err(
                    name,
                    format!("field '{axis}' has count 0 (it holds no value)"),
                );
            }
            let names: Vec<&str> = layout.fields.iter().map(|f| f.name.as_str()).collect();
            err(
                name,
                format!("no field '{axis}' (fields: {})", names.join(", ")),
            )
        })?;
    }
    let normals: Option<Vec<usize>> = ["normal_x", "normal_y", "normal_z"]
        .iter()
        .map(|n| find(n))
        .collect();
    let (width, height) = (layout.width as usize, layout.height as usize);
    let row = layout.row_step as usize;
    if step.checked_mul(width).is_none_or(|w| w > row) {
        return Err(err(
            name,
            format!("point_step {step} x width {width} is more than row_step {row}"),
        ));
    }
    match row.checked_mul(height) {
        Some(need) if need <= data.len() => {}
        _ => {
            return Err(err(
                name,
                format!(
                    "truncated: row_step {row} x height {height} bytes needed, data has {}",
                    data.len()
                ),
            ))
        }
    }
    let fields: Vec<String> = layout.fields.iter().map(|f| f.name.clone()).collect();
    let organized = (height > 1).then_some((width, height));
    let n = width * height;
    let big = layout.is_bigendian;
    let offset = |f: usize| layout.fields[f].offset as usize;
    let all_f32 = xyz.iter().all(|&f| layout.fields[f].datatype == FLOAT32);
    if all_f32 && normals.is_none() {
        let offsets = [offset(xyz[0]), offset(xyz[1]), offset(xyz[2])];
        return Ok(read_xyz_f32(
            data, width, height, step, row, offsets, big, fields,
        ));
    }
    let mut b = CloudDataBuilder::new(fields, organized, normals.is_some(), false, n);
    b.set_no_return_origin(Some(Point3::origin()));
    for r in 0..height {
        for c in 0..width {
            let rec = &data[r * row + c * step..r * row + (c + 1) * step];
            let v = |f: usize| {
                let o = offset(f);
                value(&rec[o..o + sizes[f]], layout.fields[f].datatype, big)
            };
            let p = Point3::new(v(xyz[0]), v(xyz[1]), v(xyz[2]));
            let nrm = normals
                .as_ref()
                .map(|k| Vector3::new(v(k[0]), v(k[1]), v(k[2])));
            b.push(r * width + c, p, nrm, None);
        }
    }
    Ok(b.finish())
}

/// The common layout (float32 `x y z`, no normals), read in one tight loop:
/// the values are checked in `f32` and the points built straight into the
/// cloud (what [`CloudDataBuilder`] does, without its per-point options).
#[allow(clippy::too_many_arguments)]
fn read_xyz_f32(
    data: &[u8],
    width: usize,
    height: usize,
    step: usize,
    row: usize,
    [ox, oy, oz]: [usize; 3],
    big: bool,
    fields: Vec<String>,
) -> CloudData {
    let organized = height > 1;
    let n = width * height;
    let mut points = Vec::with_capacity(n);
    let mut pixels: Vec<u32> = Vec::with_capacity(if organized { n } else { 0 });
    let (mut skipped, mut at_origin) = (0usize, 0usize);
    let read = |rec: &[u8], o: usize| -> f32 {
        let a = [rec[o], rec[o + 1], rec[o + 2], rec[o + 3]];
        if big {
            f32::from_be_bytes(a)
        } else {
            f32::from_le_bytes(a)
        }
    };
    for r in 0..height {
        let row_bytes = &data[r * row..r * row + width * step];
        for (c, rec) in row_bytes.chunks_exact(step).enumerate() {
            let (x, y, z) = (read(rec, ox), read(rec, oy), read(rec, oz));
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                skipped += 1;
                continue;
            }
            if organized && x == 0.0 && y == 0.0 && z == 0.0 {
                at_origin += 1;
                continue;
            }
            points.push(Point3::new(f64::from(x), f64::from(y), f64::from(z)));
            if organized {
                pixels.push((r * width + c) as u32);
            }
        }
    }
    CloudData {
        points,
        grid: organized.then_some(Grid {
            width,
            height,
            pixels,
        }),
        fields,
        skipped,
        at_origin,
        ..CloudData::default()
    }
}

/// Reads a serialized message field by field: CDR aligns each value to its
/// size (from the end of the encapsulation header), ROS 1 does not.
struct MessageReader<'a> {
    cur: ByteCursor<'a>,
    big: bool,
    /// Where CDR alignment counts from (`None`: ROS 1, no alignment).
    origin: Option<usize>,
}

impl<'a> MessageReader<'a> {
    fn new(bytes: &'a [u8], encoding: MessageEncoding, name: &'a str) -> Result<Self> {
        let mut cur = ByteCursor::new(bytes, name, NAME);
        match encoding {
            MessageEncoding::Ros1 => Ok(Self {
                cur,
                big: false,
                origin: None,
            }),
            MessageEncoding::Cdr => {
                let head = cur.take(4).map_err(|_| {
                    err(
                        name,
                        format!(
                            "truncated: a CDR message starts with a 4-byte encapsulation header, \
                             the message has {} bytes",
                            bytes.len()
                        ),
                    )
                })?;
                let big = match (head[0], head[1]) {
                    (0, 0) => true,
                    (0, 1) => false,
                    (a, b) => {
                        return Err(err(
                            name,
                            format!(
                                "unsupported CDR encapsulation 0x{a:02x}{b:02x} (expected \
                                 0x0000 CDR big endian or 0x0001 CDR little endian)"
                            ),
                        ))
                    }
                };
                Ok(Self {
                    cur,
                    big,
                    origin: Some(4),
                })
            }
        }
    }

    fn align(&mut self, n: usize) -> Result<()> {
        if let Some(origin) = self.origin {
            let rel = self.cur.position() - origin;
            let pad = (n - rel % n) % n;
            let _ = self.cur.take(pad)?;
        }
        Ok(())
    }

    fn u32(&mut self) -> Result<u32> {
        self.align(4)?;
        if self.big {
            self.cur.u32_be()
        } else {
            self.cur.u32_le()
        }
    }

    fn i32(&mut self) -> Result<i32> {
        self.align(4)?;
        if self.big {
            self.cur.i32_be()
        } else {
            self.cur.i32_le()
        }
    }

    fn u8(&mut self) -> Result<u8> {
        self.cur.u8()
    }

    /// A `string`: a `uint32` length then the bytes (CDR counts and writes
    /// a terminating NUL, ROS 1 does neither).
    fn string(&mut self, what: &str) -> Result<String> {
        let len = self.u32()? as usize;
        let at = self.cur.position();
        let bytes = self.cur.take(len).map_err(|_| {
            self.cur.error(format!(
                "truncated: {what} of {len} bytes at offset {at}, only {} left",
                self.cur.remaining()
            ))
        })?;
        let text = match (self.origin, bytes.split_last()) {
            (Some(_), Some((0, head))) => head,
            _ => bytes,
        };
        Ok(String::from_utf8_lossy(text).into_owned())
    }

    /// A `uint8[]`: a `uint32` length then the bytes.
    fn bytes(&mut self, what: &str) -> Result<&'a [u8]> {
        let len = self.u32()? as usize;
        let at = self.cur.position();
        if len > self.cur.remaining() {
            return Err(self.cur.error(format!(
                "truncated: {what} of {len} bytes at offset {at}, only {} left",
                self.cur.remaining()
            )));
        }
        self.cur.take(len)
    }
}

/// Decodes a serialized `sensor_msgs/PointCloud2` message: header, layout
/// and the `data` bytes (borrowed). `name` goes into errors (a bag's file,
/// topic and message index).
///
/// # Errors
/// [`Error::Format`] naming the problem: an unknown CDR encapsulation, a
/// message that ends inside a field (truncated, naming what was being read),
/// more fields than the message could hold.
pub fn decode_pointcloud2<'a>(
    bytes: &'a [u8],
    encoding: MessageEncoding,
    name: &'a str,
) -> Result<PointCloud2Message<'a>> {
    let mut m = MessageReader::new(bytes, encoding, name)?;
    if encoding == MessageEncoding::Ros1 {
        let _seq = m.u32()?;
    }
    let stamp_ns = match encoding {
        MessageEncoding::Cdr => {
            let sec = m.i32()?;
            let nsec = m.u32()?;
            i64::from(sec) * 1_000_000_000 + i64::from(nsec)
        }
        MessageEncoding::Ros1 => {
            let sec = m.u32()?;
            let nsec = m.u32()?;
            i64::from(sec) * 1_000_000_000 + i64::from(nsec)
        }
    };
    let frame_id = m.string("header.frame_id")?;
    let height = m.u32()?;
    let width = m.u32()?;
    let count = m.u32()? as usize;
    // A field takes at least 13 bytes: do not trust a count the bytes cannot hold.
    if count > m.cur.remaining() / 13 {
        return Err(err(
            name,
            format!(
                "truncated: {count} fields announced, the message has {} bytes left",
                m.cur.remaining()
            ),
        ));
    }
    let mut fields = Vec::with_capacity(count);
    for i in 0..count {
        let fname = m.string(&format!("the name of field {i}"))?;
        let offset = m.u32()?;
        let datatype = m.u8()?;
        let fcount = m.u32()?;
        fields.push(PointField {
            name: fname,
            offset,
            datatype,
            count: fcount,
        });
    }
    let is_bigendian = m.u8()? != 0;
    let point_step = m.u32()?;
    let row_step = m.u32()?;
    let data = m.bytes("data")?;
    // `is_dense` is the last byte; a message cut right before it is refused
    // like any other truncation.
    let is_dense = m.u8()? != 0;
    Ok(PointCloud2Message {
        header: PointCloud2Header {
            stamp_ns,
            frame_id,
            is_dense,
        },
        layout: PointCloud2Layout {
            height,
            width,
            fields,
            is_bigendian,
            point_step,
            row_step,
        },
        data,
    })
}

/// Reads the points of a serialized `sensor_msgs/PointCloud2` message (as a
/// rosbag2 or ROS 1 bag stores it; see [`decode_pointcloud2`]) straight from
/// its bytes, and returns them with the message's header.
///
/// # Errors
/// [`Error::Format`] naming `name` and the problem: as
/// [`decode_pointcloud2`], then as [`read_pointcloud2`] (a missing field,
/// `data` shorter than the layout says, ...).
pub fn read_pointcloud2_message(
    bytes: &[u8],
    encoding: MessageEncoding,
    name: &str,
) -> Result<(CloudData, PointCloud2Header)> {
    let msg = decode_pointcloud2(bytes, encoding, name)?;
    let cloud = read_pointcloud2_named(&msg.layout, msg.data, name)?;
    Ok((cloud, msg.header))
}

/// Encodes a layout and `data` as a serialized `sensor_msgs/PointCloud2`
/// message (the inverse of [`decode_pointcloud2`]): CDR little endian with
/// its encapsulation header, or ROS 1 (`seq` 0).
pub fn encode_pointcloud2(
    header: &PointCloud2Header,
    layout: &PointCloud2Layout,
    data: &[u8],
    encoding: MessageEncoding,
) -> Vec<u8> {
    let cdr = encoding == MessageEncoding::Cdr;
    let mut out: Vec<u8> = Vec::with_capacity(data.len() + 256);
    if cdr {
        out.extend_from_slice(&[0, 1, 0, 0]);
    }
    let align = |out: &mut Vec<u8>, n: usize| {
        if cdr {
            while (out.len() - 4) % n != 0 {
                out.push(0);
            }
        }
    };
    let put_u32 = |out: &mut Vec<u8>, v: u32| {
        align(out, 4);
        out.extend_from_slice(&v.to_le_bytes());
    };
    let put_str = |out: &mut Vec<u8>, s: &str| {
        let extra = usize::from(cdr);
        put_u32(out, (s.len() + extra) as u32);
        out.extend_from_slice(s.as_bytes());
        if cdr {
            out.push(0);
        }
    };
    let secs = header.stamp_ns.div_euclid(1_000_000_000);
    let nsec = header.stamp_ns.rem_euclid(1_000_000_000) as u32;
    if !cdr {
        put_u32(&mut out, 0);
    }
    put_u32(&mut out, secs as u32);
    put_u32(&mut out, nsec);
    put_str(&mut out, &header.frame_id);
    put_u32(&mut out, layout.height);
    put_u32(&mut out, layout.width);
    put_u32(&mut out, layout.fields.len() as u32);
    for f in &layout.fields {
        put_str(&mut out, &f.name);
        put_u32(&mut out, f.offset);
        out.push(f.datatype);
        put_u32(&mut out, f.count);
    }
    out.push(u8::from(layout.is_bigendian));
    put_u32(&mut out, layout.point_step);
    put_u32(&mut out, layout.row_step);
    put_u32(&mut out, data.len() as u32);
    out.extend_from_slice(data);
    out.push(u8::from(header.is_dense));
    out
}

/// Encodes a cloud as a dense, unorganized (`height` 1), little-endian
/// PointCloud2: `float32` `x y z`, plus `normal_x normal_y normal_z` when the
/// cloud has normals. Returns the layout and the `data` bytes.
///
/// # Errors
/// [`Error::InvalidInput`] when the cloud is too large for the message's
/// 32-bit sizes or has a different number of normals than points.
pub fn write_pointcloud2(cloud: &CloudData) -> Result<(PointCloud2Layout, Vec<u8>)> {
    let n = cloud.points.len();
    if let Some(normals) = &cloud.normals {
        if normals.len() != n {
            return Err(Error::invalid(format!(
                "cloud has {n} points but {} normals",
                normals.len()
            )));
        }
    }
    let mut names = vec!["x", "y", "z"];
    if cloud.normals.is_some() {
        names.extend_from_slice(&["normal_x", "normal_y", "normal_z"]);
    }
    let fields: Vec<PointField> = names
        .iter()
        .enumerate()
        .map(|(i, name)| PointField {
            name: (*name).to_string(),
            offset: 4 * i as u32,
            datatype: FLOAT32,
            count: 1,
        })
        .collect();
    let step = 4 * names.len();
    let too_big = || Error::invalid(format!("cloud of {n} points is too large for PointCloud2"));
    let width = u32::try_from(n).map_err(|_| too_big())?;
    let row_step = n
        .checked_mul(step)
        .and_then(|r| u32::try_from(r).ok())
        .ok_or_else(too_big)?;
    let mut data = Vec::with_capacity(n * step);
    for i in 0..n {
        for c in cloud.points[i].coords.iter() {
            data.extend_from_slice(&(*c as f32).to_le_bytes());
        }
        if let Some(normals) = &cloud.normals {
            for c in normals[i].iter() {
                data.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
    }
    let layout = PointCloud2Layout {
        height: 1,
        width,
        fields,
        is_bigendian: false,
        point_step: step as u32,
        row_step,
    };
    Ok((layout, data))
}
