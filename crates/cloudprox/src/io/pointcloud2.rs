//! ROS `sensor_msgs/PointCloud2`: the message's field layout plus its raw
//! `data` bytes (decode the message itself with your ROS client library).
//!
//! Reading ([`read_pointcloud2`]): fields `x y z` are required (any datatype),
//! `normal_x normal_y normal_z` become normals, other fields are named in
//! [`CloudData::fields`] and otherwise ignored. Point `(row, column)` starts at
//! byte `row * row_step + column * point_step`. A cloud with `height > 1` is
//! organized ([`CloudData::grid`]); NaN points are skipped and counted.
//!
//! Writing ([`write_pointcloud2`]): `float32` `x y z` (and `normal_x normal_y
//! normal_z` when the cloud has normals), little endian, dense, `height` 1.

use crate::error::{Error, Result};
use crate::io::{CloudData, CloudDataBuilder};
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

fn err(problem: impl Into<String>) -> Error {
    Error::format(NAME, NAME, problem)
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
    let step = layout.point_step as usize;
    let mut sizes = Vec::with_capacity(layout.fields.len());
    for f in &layout.fields {
        let size = type_size(f.datatype).ok_or_else(|| {
            err(format!(
                "field '{}' has unknown datatype {} (expected 1 to 8)",
                f.name, f.datatype
            ))
        })?;
        let end = (f.offset as usize).saturating_add(size.saturating_mul(f.count as usize));
        if end > step {
            return Err(err(format!(
                "field '{}' (offset {}, {} x {size} bytes) reaches past point_step {step}",
                f.name, f.offset, f.count
            )));
        }
        sizes.push(size);
    }
    for (i, f) in layout.fields.iter().enumerate() {
        if layout.fields[..i].iter().any(|g| g.name == f.name) {
            return Err(err(format!("field '{}' appears twice", f.name)));
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
                return err(format!("field '{axis}' has count 0 (it holds no value)"));
            }
            let names: Vec<&str> = layout.fields.iter().map(|f| f.name.as_str()).collect();
            err(format!("no field '{axis}' (fields: {})", names.join(", ")))
        })?;
    }
    let normals: Option<Vec<usize>> = ["normal_x", "normal_y", "normal_z"]
        .iter()
        .map(|n| find(n))
        .collect();
    let (width, height) = (layout.width as usize, layout.height as usize);
    let row = layout.row_step as usize;
    if step.checked_mul(width).is_none_or(|w| w > row) {
        return Err(err(format!(
            "point_step {step} x width {width} is more than row_step {row}"
        )));
    }
    match row.checked_mul(height) {
        Some(need) if need <= data.len() => {}
        _ => {
            return Err(err(format!(
                "truncated: row_step {row} x height {height} bytes needed, data has {}",
                data.len()
            )))
        }
    }
    let fields = layout.fields.iter().map(|f| f.name.clone()).collect();
    let organized = (height > 1).then_some((width, height));
    let n = width * height;
    let mut b = CloudDataBuilder::new(fields, organized, normals.is_some(), false, n);
    let big = layout.is_bigendian;
    for r in 0..height {
        for c in 0..width {
            let rec = &data[r * row + c * step..r * row + (c + 1) * step];
            let v = |f: usize| {
                let o = layout.fields[f].offset as usize;
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
