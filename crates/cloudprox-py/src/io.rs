//! File reading and writing: `CloudFile`, `read_point_cloud`, `write_point_cloud`,
//! `read_mesh`, `write_mesh`.

use std::ffi::CString;
use std::path::PathBuf;
use std::sync::Arc;

use cloudprox::cloud::PointCloud;
use cloudprox::io::pointcloud2::{
    decode_pointcloud2, read_pointcloud2_message, read_pointcloud2_named,
    write_pointcloud2 as write_pc2, MessageEncoding, PointCloud2Layout, PointField,
};
use cloudprox::io::{self, CloudData, CloudFormat, Encoding, Grid, MeshFormat};
use cloudprox::math::Matrix3;
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::cloud::{noise_from, PyPointCloud};
use crate::convert::{matrices3_to_py, points_from, points_to_py, pose_to_py, rows3_to_py};
use crate::error::{invalid_input, run_detached};
use crate::mesh::PyMesh;

fn cloud_format(py: Python<'_>, format: &str) -> PyResult<Option<CloudFormat>> {
    Ok(Some(match format.to_ascii_lowercase().as_str() {
        "auto" => return Ok(None),
        "ply" => CloudFormat::Ply,
        "pcd" => CloudFormat::Pcd,
        "xyz" | "xyzn" | "xyzrgb" | "txt" | "pts" => CloudFormat::Xyz,
        "csv" => CloudFormat::Csv,
        "npy" => CloudFormat::Npy,
        "las" | "laz" => CloudFormat::Las,
        other => {
            return Err(invalid_input(
                py,
                format!(
                    "unknown point cloud format {other:?}; known: auto, ply, pcd, xyz, csv, npy, \
                     las, laz"
                ),
            ))
        }
    }))
}

fn mesh_format(py: Python<'_>, format: &str) -> PyResult<Option<MeshFormat>> {
    Ok(Some(match format.to_ascii_lowercase().as_str() {
        "auto" => return Ok(None),
        "stl" => MeshFormat::Stl,
        "obj" => MeshFormat::Obj,
        "ply" => MeshFormat::Ply,
        "off" => MeshFormat::Off,
        other => {
            return Err(invalid_input(
                py,
                format!("unknown mesh format {other:?}; known: auto, stl, obj, ply, off"),
            ))
        }
    }))
}

/// The encodings a format can be written in, by their Python names (`None`:
/// the format has no choice).
fn encodings_of(format: Option<&str>) -> Option<&'static [&'static str]> {
    match format {
        Some("ply") => Some(&["ascii", "binary", "binary_big_endian"]),
        Some("pcd") => Some(&["ascii", "binary", "binary_compressed"]),
        Some("stl") => Some(&["ascii", "binary"]),
        _ => None,
    }
}

/// Refuses an encoding the format cannot be written in, with the Python names.
fn check_encoding(
    py: Python<'_>,
    path: &std::path::Path,
    format: &str,
    encoding: Option<&str>,
    write_ascii: bool,
    compressed: bool,
) -> PyResult<()> {
    let name = if format.eq_ignore_ascii_case("auto") {
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
    } else {
        Some(format.to_ascii_lowercase())
    };
    let asked = match (encoding, write_ascii, compressed) {
        (Some(e), _, _) => Some(
            e.to_ascii_lowercase()
                .replace("binary_little_endian", "binary"),
        ),
        (None, true, _) => Some("ascii".to_string()),
        (None, false, true) => Some("binary_compressed".to_string()),
        (None, false, false) => None,
    };
    let Some(asked) = asked else { return Ok(()) };
    if !["ascii", "binary", "binary_big_endian", "binary_compressed"].contains(&asked.as_str()) {
        return Ok(()); // an unknown name: `encoding_from` says so
    }
    let fmt = name.clone().unwrap_or_default();
    match encodings_of(name.as_deref()) {
        Some(list) if list.contains(&asked.as_str()) => Ok(()),
        Some(list) => Err(invalid_input(
            py,
            format!(
                "{} cannot be written as {asked}; choose one of: {}",
                fmt.to_uppercase(),
                list.join(", ")
            ),
        )),
        None => Err(invalid_input(
            py,
            format!(
                "{} has a single encoding: do not give encoding, write_ascii or compressed",
                fmt.to_uppercase()
            ),
        )),
    }
}

fn encoding_from(
    py: Python<'_>,
    encoding: Option<&str>,
    write_ascii: bool,
    compressed: bool,
) -> PyResult<Encoding> {
    let named = match encoding {
        None => None,
        Some(e) => Some(match e.to_ascii_lowercase().as_str() {
            "ascii" => Encoding::Ascii,
            "binary" | "binary_little_endian" => Encoding::BinaryLittleEndian,
            "binary_big_endian" => Encoding::BinaryBigEndian,
            "binary_compressed" => Encoding::BinaryCompressed,
            other => {
                return Err(invalid_input(
                    py,
                    format!(
                        "unknown encoding {other:?}; known: ascii, binary, binary_big_endian, \
                         binary_compressed"
                    ),
                ))
            }
        }),
    };
    match (named, write_ascii, compressed) {
        (Some(_), true, _) | (Some(_), _, true) => Err(invalid_input(
            py,
            "give encoding, or write_ascii / compressed, not both",
        )),
        (Some(e), false, false) => Ok(e),
        (None, true, true) => Err(invalid_input(
            py,
            "write_ascii and compressed exclude each other",
        )),
        (None, true, false) => Ok(Encoding::Ascii),
        (None, false, true) => Ok(Encoding::BinaryCompressed),
        (None, false, false) => Ok(Encoding::BinaryLittleEndian),
    }
}

/// A point cloud as read from a file: points and whatever else the file holds.
#[pyclass(name = "CloudFile", frozen, module = "cloudprox._native")]
pub struct PyCloudFile {
    pub(crate) data: Arc<CloudData>,
    path: String,
    message: Option<MessageSource>,
}

/// Where a cloud read from a bag came from.
#[derive(Debug, Clone)]
struct MessageSource {
    topic: Option<String>,
    index: Option<usize>,
    /// The message's `header.frame_id` (the sensor's frame).
    sensor_frame: String,
    /// The frame the points are expressed in.
    frame_id: String,
    stamp_ns: i64,
}

impl PyCloudFile {
    pub(crate) fn new(data: CloudData, path: String) -> Self {
        Self {
            data: Arc::new(data),
            path,
            message: None,
        }
    }
}

/// The encoding of a serialized message by its Python name.
fn message_encoding(py: Python<'_>, encoding: &str) -> PyResult<MessageEncoding> {
    match encoding.to_ascii_lowercase().as_str() {
        "cdr" | "ros2" => Ok(MessageEncoding::Cdr),
        "ros1" => Ok(MessageEncoding::Ros1),
        other => Err(invalid_input(
            py,
            format!("unknown message encoding {other:?}; known: cdr (ROS 2), ros1"),
        )),
    }
}

/// The bytes of a bytes-like object: `bytes` borrowed (immutable, so it can
/// be read with the GIL released), anything else copied.
enum MessageBytes<'py> {
    Borrowed(Bound<'py, PyBytes>),
    Owned(Vec<u8>),
}

impl MessageBytes<'_> {
    fn as_slice(&self) -> &[u8] {
        match self {
            MessageBytes::Borrowed(b) => b.as_bytes(),
            MessageBytes::Owned(v) => v,
        }
    }
}

fn message_bytes<'py>(data: &Bound<'py, PyAny>, what: &str) -> PyResult<MessageBytes<'py>> {
    let py = data.py();
    if let Ok(b) = data.cast::<PyBytes>() {
        return Ok(MessageBytes::Borrowed(b.clone()));
    }
    // bytearray, memoryview, array.array('B'), numpy uint8 arrays, lists of ints
    let copied = py
        .import("builtins")?
        .getattr("bytes")?
        .call1((data,))
        .map_err(|e| invalid_input(py, format!("{what} must be bytes-like: {}", e.value(py))))?
        .cast_into::<PyBytes>()?
        .as_bytes()
        .to_vec();
    Ok(MessageBytes::Owned(copied))
}

#[pymethods]
impl PyCloudFile {
    /// Data to write: points `(n, 3)` and optionally normals `(n, 3)`,
    /// covariances `(n, 3, 3)`, the sensor pose `(4, 4)` (written as a PCD
    /// `VIEWPOINT`) and an organized layout (`grid_shape = (height, width)` with
    /// the pixel of each point; missing pixels are written as NaN records).
    #[new]
    #[pyo3(signature = (points, *, normals=None, covariances=None, sensor_pose=None, grid_shape=None, pixels=None))]
    fn py_new(
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        normals: Option<&Bound<'_, PyAny>>,
        covariances: Option<&Bound<'_, PyAny>>,
        sensor_pose: Option<&Bound<'_, PyAny>>,
        grid_shape: Option<(usize, usize)>,
        pixels: Option<Vec<i64>>,
    ) -> PyResult<Self> {
        let points = points_from(points, "points")?;
        let n = points.len();
        if let Some((i, p)) = points
            .iter()
            .enumerate()
            .find(|(_, p)| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(invalid_input(
                py,
                format!(
                    "point {i} has a non-finite coordinate: {:?}",
                    p.coords.as_slice()
                ),
            ));
        }
        let mut data = CloudData::from_points(points);
        if let Some(nr) = normals {
            let nr = points_from(nr, "normals")?;
            if nr.len() != n {
                return Err(invalid_input(
                    py,
                    format!("{} normals for {n} points", nr.len()),
                ));
            }
            data.normals = Some(nr.into_iter().map(|p| p.coords).collect());
            data.fields.extend(["nx", "ny", "nz"].map(String::from));
        }
        if let Some(c) = covariances {
            let c = crate::convert::matrices3_from(c, "covariances")?;
            if c.len() != n {
                return Err(invalid_input(
                    py,
                    format!("{} covariances for {n} points", c.len()),
                ));
            }
            data.covariances = Some(c);
            data.fields.extend(io::COV_FIELDS.map(String::from));
        }
        if sensor_pose.is_some() {
            data.sensor = Some(crate::convert::pose_from(py, sensor_pose, "sensor_pose")?);
        }
        match (grid_shape, pixels) {
            (None, None) => {}
            (Some((height, width)), Some(px)) => {
                if px.len() != n {
                    return Err(invalid_input(
                        py,
                        format!("{} pixels for {n} points", px.len()),
                    ));
                }
                let total = height.saturating_mul(width);
                let mut out = Vec::with_capacity(n);
                for (i, &p) in px.iter().enumerate() {
                    let ok = u32::try_from(p).ok().filter(|&q| (q as usize) < total);
                    let Some(q) = ok else {
                        return Err(invalid_input(
                            py,
                            format!("pixels[{i}] = {p} is outside the {height}x{width} grid"),
                        ));
                    };
                    if out.last().is_some_and(|&last| last >= q) {
                        return Err(invalid_input(
                            py,
                            format!("pixels must be strictly increasing; pixels[{i}] = {p}"),
                        ));
                    }
                    out.push(q);
                }
                data.grid = Some(Grid {
                    width,
                    height,
                    pixels: out,
                });
            }
            _ => {
                return Err(invalid_input(
                    py,
                    "give both grid_shape and pixels (an organized cloud), or neither",
                ))
            }
        }
        Ok(Self::new(data, "<memory>".to_string()))
    }

    /// Points with finite coordinates, shape `(n, 3)` (metres).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_to_py(py, &self.data.points)
    }

    /// Per-point normals `(n, 3)`, or `None`.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.data
            .normals
            .as_ref()
            .map(|n| rows3_to_py(py, n.iter().copied()))
            .transpose()
    }

    /// Per-point covariances `(n, 3, 3)` stored in the file, or `None`.
    #[getter]
    fn covariances<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray3<f64>>>> {
        self.data
            .covariances
            .as_ref()
            .map(|c| matrices3_to_py(py, c))
            .transpose()
    }

    /// The sensor's pose `(4, 4)` recorded in the file (PCD `VIEWPOINT`, the
    /// identity when the file leaves it at the format's default), or `None`.
    #[getter]
    fn sensor_pose<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.data
            .sensor
            .as_ref()
            .map(|p| pose_to_py(py, p))
            .transpose()
    }

    /// Whether `sensor_pose` is the PCD format's default `VIEWPOINT` (the
    /// identity, written or left out): the sensor at the origin looking along +z.
    #[getter]
    fn sensor_pose_is_default(&self) -> bool {
        self.data.sensor_is_default
    }

    /// `(height, width)` of an organized cloud, or `None`.
    #[getter]
    fn grid_shape(&self) -> Option<(usize, usize)> {
        self.data.grid.as_ref().map(|g| (g.height, g.width))
    }

    /// For an organized cloud, the pixel `row * width + column` of every point, or `None`.
    #[getter]
    fn pixels<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<i64>>> {
        self.data
            .grid
            .as_ref()
            .map(|g| PyArray1::from_vec(py, g.pixels.iter().map(|&p| i64::from(p)).collect()))
    }

    /// Names of all per-point fields in the file, in file order.
    #[getter]
    fn fields(&self) -> Vec<String> {
        self.data.fields.clone()
    }

    /// Points skipped because a coordinate was NaN or infinite.
    #[getter]
    fn skipped(&self) -> usize {
        self.data.skipped
    }

    /// Points of an organized scan left out because they lie at exactly the
    /// sensor origin: the driver's no-return points (0 for an unorganized
    /// cloud, which keeps such points).
    #[getter]
    fn at_origin(&self) -> usize {
        self.data.at_origin
    }

    /// The no-return points of an organized scan: `at_origin` plus the NaN or
    /// infinite ones (`skipped`). None of them is in `points`; the organized
    /// layout keeps their pixels (`pixels` skips them). 0 when unorganized.
    #[getter]
    fn no_returns(&self) -> usize {
        self.data.no_returns()
    }

    /// For a cloud read from a bag: its topic, else `None`.
    #[getter]
    fn topic(&self) -> Option<String> {
        self.message.as_ref().and_then(|m| m.topic.clone())
    }

    /// For a cloud read from a bag: the message's index in its topic, else `None`.
    #[getter]
    fn index(&self) -> Option<usize> {
        self.message.as_ref().and_then(|m| m.index)
    }

    /// For a cloud read from a message: the frame its points are expressed in
    /// (the TF frame they were moved to, else the message's `frame_id`);
    /// `None` for a file.
    #[getter]
    fn frame_id(&self) -> Option<String> {
        self.message.as_ref().map(|m| m.frame_id.clone())
    }

    /// For a cloud read from a message: the message's `header.frame_id`, the
    /// sensor's frame; `None` for a file.
    #[getter]
    fn sensor_frame(&self) -> Option<String> {
        self.message.as_ref().map(|m| m.sensor_frame.clone())
    }

    /// For a cloud read from a message: `header.stamp` in nanoseconds since
    /// the epoch; `None` for a file.
    #[getter]
    fn stamp(&self) -> Option<i64> {
        self.message.as_ref().map(|m| m.stamp_ns)
    }

    /// Reads a serialized `sensor_msgs/PointCloud2` message, as a bag stores
    /// it (`encoding` `"cdr"` for rosbag2, `"ros1"` for a ROS 1 bag), straight
    /// from its bytes. The sensor sits at the origin of the message's frame;
    /// `pose` (the frame's pose in `frame_id`, a `(4, 4)`) moves the points
    /// and the sensor there. `name` goes into errors, `path` is the file.
    #[staticmethod]
    #[pyo3(signature = (message, encoding, *, name, path, pose=None, frame_id=None, topic=None, index=None))]
    #[allow(clippy::too_many_arguments)]
    fn _from_message(
        py: Python<'_>,
        message: &Bound<'_, PyAny>,
        encoding: &str,
        name: &str,
        path: String,
        pose: Option<&Bound<'_, PyAny>>,
        frame_id: Option<String>,
        topic: Option<String>,
        index: Option<usize>,
    ) -> PyResult<Self> {
        let encoding = message_encoding(py, encoding)?;
        let pose = pose
            .map(|p| crate::convert::pose_from(py, Some(p), "pose"))
            .transpose()?;
        let bytes = message_bytes(message, "message")?;
        let slice = bytes.as_slice();
        let (data, header) = run_detached(py, move || {
            let (mut data, header) = read_pointcloud2_message(slice, encoding, name)?;
            data.sensor = Some(cloudprox::math::Pose::identity());
            data.sensor_is_default = true;
            if let Some(p) = &pose {
                data.transform(p);
            }
            Ok((data, header))
        })?;
        let frame_id = frame_id.unwrap_or_else(|| header.frame_id.clone());
        Ok(Self {
            data: Arc::new(data),
            path,
            message: Some(MessageSource {
                topic,
                index,
                sensor_frame: header.frame_id,
                frame_id,
                stamp_ns: header.stamp_ns,
            }),
        })
    }

    /// The `(frame_id, stamp)` of a serialized `sensor_msgs/PointCloud2`
    /// message (stamp in nanoseconds), as `_from_message` decodes it.
    #[staticmethod]
    #[pyo3(signature = (message, encoding, *, name))]
    fn _message_header(
        py: Python<'_>,
        message: &Bound<'_, PyAny>,
        encoding: &str,
        name: &str,
    ) -> PyResult<(String, i64)> {
        let encoding = message_encoding(py, encoding)?;
        let bytes = message_bytes(message, "message")?;
        let slice = bytes.as_slice();
        let header = run_detached(py, move || {
            decode_pointcloud2(slice, encoding, name).map(|m| m.header)
        })?;
        Ok((header.frame_id, header.stamp_ns))
    }

    /// The file it was read from.
    #[getter]
    fn path(&self) -> &str {
        &self.path
    }

    /// The points as a `PointCloud` with noise: `sigma`, `cov`, or a `sensor`
    /// model seen from `origin` / `sensor_pose` (default: the file's
    /// `sensor_pose`). With none of them, the file's covariances are used if it
    /// has them. `discretization` adds the k-nearest-neighbour discretization part.
    #[pyo3(signature = (
        sigma=None, cov=None, *, sensor=None, origin=None, sensor_pose=None,
        discretization=true
    ))]
    fn to_point_cloud(
        &self,
        py: Python<'_>,
        sigma: Option<&Bound<'_, PyAny>>,
        cov: Option<&Bound<'_, PyAny>>,
        sensor: Option<&Bound<'_, PyAny>>,
        origin: Option<&Bound<'_, PyAny>>,
        sensor_pose: Option<&Bound<'_, PyAny>>,
        discretization: bool,
    ) -> PyResult<PyPointCloud> {
        let file_pose = if sensor.is_some() && origin.is_none() && sensor_pose.is_none() {
            match self.data.sensor.as_ref() {
                Some(p) => Some(pose_to_py(py, p)?.into_any()),
                None => {
                    return Err(invalid_input(
                        py,
                        format!(
                            "{} records no sensor viewpoint: give origin= or sensor_pose=",
                            self.path
                        ),
                    ))
                }
            }
        } else {
            None
        };
        let sensor_pose = sensor_pose.or(file_pose.as_ref());
        // A laser scanner has no optical axis (a spinning lidar sees all around):
        // its model takes the pose's origin only, so that the points behind the
        // pose's +z are not refused as "not in front of the sensor".
        let lidar = sensor.is_some_and(|s| s.cast::<crate::sensor::PyLidar>().is_ok());
        let lidar_origin = match (lidar, origin, sensor_pose) {
            (true, None, Some(p)) => {
                let pose = crate::convert::pose_from(py, Some(p), "sensor_pose")?;
                Some(
                    points_to_py(
                        py,
                        &[cloudprox::math::Point3::from(pose.translation.vector)],
                    )?
                    .call_method1("reshape", (3,))?,
                )
            }
            _ => None,
        };
        let (origin, sensor_pose) = match &lidar_origin {
            Some(o) => (Some(o), None),
            None => (origin, sensor_pose),
        };
        let noise = if sigma.is_none() && cov.is_none() && sensor.is_none() {
            match self.data.covariances.as_ref() {
                Some(c) => crate::cloud::Noise::Covariances(c.clone()),
                None => {
                    return Err(invalid_input(
                        py,
                        format!(
                            "{} stores no covariances: give sigma=, cov= or sensor= to say how \
                             noisy the points are",
                            self.path
                        ),
                    ))
                }
            }
        } else {
            noise_from(py, sigma, cov, sensor, origin, sensor_pose)?
        };
        PyPointCloud::build(
            py,
            self.data.points.clone(),
            noise,
            discretization,
            None,
            None,
        )
    }

    fn __len__(&self) -> usize {
        self.data.points.len()
    }

    fn __repr__(&self) -> String {
        let grid = self.data.grid.as_ref().map_or(String::new(), |g| {
            format!(", organized {}x{}", g.width, g.height)
        });
        let source = self.message.as_ref().map_or(String::new(), |m| {
            let topic = m
                .topic
                .as_deref()
                .map_or(String::new(), |t| format!(" {t}"));
            let index = m.index.map_or(String::new(), |i| format!(" #{i}"));
            format!("{topic}{index} in {}", m.frame_id)
        });
        let no_returns = if self.data.grid.is_some() {
            format!(", {} no-returns", self.data.no_returns())
        } else {
            String::new()
        };
        format!(
            "CloudFile({:?}{source}: {} points{grid}, {} skipped{no_returns}, fields {:?})",
            self.path,
            self.data.points.len(),
            self.data.skipped,
            self.data.fields
        )
    }
}

/// Reads a point-cloud file (PLY, PCD, XYZ/CSV, NPY, LAS/LAZ; the format from the
/// extension unless given). The GIL is released while reading.
#[pyfunction]
#[pyo3(signature = (path, format="auto"))]
pub fn read_point_cloud(py: Python<'_>, path: PathBuf, format: &str) -> PyResult<PyCloudFile> {
    let format = cloud_format(py, format)?;
    let name = path.display().to_string();
    let data = run_detached(py, move || io::read_point_cloud(&path, format))?;
    Ok(PyCloudFile::new(data, name))
}

/// What `write_point_cloud` accepts: a `CloudFile`, a `PointCloud` (its points and
/// sensor covariances) or an `(n, 3)` array-like.
fn cloud_data_from(obj: &Bound<'_, PyAny>) -> PyResult<CloudData> {
    if let Ok(f) = obj.cast::<PyCloudFile>() {
        return Ok((*f.get().data).clone());
    }
    if let Ok(c) = obj.cast::<PyPointCloud>() {
        let inner: &PointCloud = &c.get().inner;
        let mut data = CloudData::from_points(inner.points().to_vec());
        let sensor = inner.sensor_covariances();
        if sensor.iter().any(|m| *m != Matrix3::zeros()) {
            data.covariances = Some(sensor.to_vec());
            data.fields.extend(io::COV_FIELDS.map(String::from));
        }
        return Ok(data);
    }
    Ok(CloudData::from_points(points_from(obj, "cloud")?))
}

/// Writes a point cloud (`CloudFile`, `PointCloud` or `(n, 3)` array-like).
#[pyfunction]
#[pyo3(signature = (path, cloud, format="auto", *, encoding=None, write_ascii=false, compressed=false))]
pub fn write_point_cloud(
    py: Python<'_>,
    path: PathBuf,
    cloud: &Bound<'_, PyAny>,
    format: &str,
    encoding: Option<&str>,
    write_ascii: bool,
    compressed: bool,
) -> PyResult<()> {
    check_encoding(py, &path, format, encoding, write_ascii, compressed)?;
    let format = cloud_format(py, format)?;
    let encoding = encoding_from(py, encoding, write_ascii, compressed)?;
    let data = cloud_data_from(cloud)?;
    run_detached(py, move || {
        io::write_point_cloud(&path, &data, format, encoding)
    })
}

/// Emits `DegenerateFacesWarning` (from `cloudprox.exceptions`) when faces
/// were dropped, attributed to the caller's line.
fn warn_dropped(py: Python<'_>, source: &str, dropped: usize) -> PyResult<()> {
    if dropped == 0 {
        return Ok(());
    }
    let category = py
        .import("cloudprox.exceptions")?
        .getattr("DegenerateFacesWarning")?;
    let msg = format!("{source}: dropped {dropped} degenerate face(s) that repeat a vertex");
    let msg = CString::new(msg.replace('\0', "")).unwrap_or_default();
    PyErr::warn(py, &category, &msg, 1)
}

/// Reads a triangle mesh (STL ascii/binary, OBJ, PLY, OFF; `format` `"auto"`
/// guesses from the extension).
///
/// Polygons are split into fans of triangles and STL vertices are welded.
/// Triangles that repeat a vertex are dropped with a `DegenerateFacesWarning`
/// giving their number. A missing file raises `FileNotFoundError`; a corrupt,
/// truncated or unsupported one `cloudprox.FormatError`.
#[pyfunction]
#[pyo3(signature = (path, format="auto"))]
pub fn read_mesh(py: Python<'_>, path: PathBuf, format: &str) -> PyResult<PyMesh> {
    let source = path.to_string_lossy().into_owned();
    let (mesh, dropped) = read_mesh_counted(py, path, format)?;
    warn_dropped(py, &source, dropped)?;
    Ok(mesh)
}

/// `read_mesh` without the warning: the mesh and the number of degenerate faces
/// dropped (for the command line, which reports them itself).
#[pyfunction]
#[pyo3(name = "_read_mesh_counted", signature = (path, format="auto"))]
pub fn read_mesh_counted(py: Python<'_>, path: PathBuf, format: &str) -> PyResult<(PyMesh, usize)> {
    let format = mesh_format(py, format)?;
    let data = run_detached(py, move || io::read_mesh(&path, format))?;
    Ok((PyMesh::wrap(data.mesh), data.dropped_faces))
}

/// Writes a mesh (STL ascii/binary, OBJ, PLY ascii/binary, OFF).
#[pyfunction]
#[pyo3(signature = (path, mesh, format="auto", *, encoding=None, write_ascii=false))]
pub fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    mesh: &Bound<'_, PyMesh>,
    format: &str,
    encoding: Option<&str>,
    write_ascii: bool,
) -> PyResult<()> {
    check_encoding(py, &path, format, encoding, write_ascii, false)?;
    let format = mesh_format(py, format)?;
    let encoding = encoding_from(py, encoding, write_ascii, false)?;
    let mesh = Arc::clone(&mesh.get().inner);
    run_detached(py, move || io::write_mesh(&path, &mesh, format, encoding))
}

/// One field of a PointCloud2 layout from a `(name, offset, datatype, count)`
/// tuple or an object with those attributes (a ROS `PointField`).
fn point_field_from(obj: &Bound<'_, PyAny>, i: usize) -> PyResult<PointField> {
    let py = obj.py();
    let bad = |e: PyErr| {
        invalid_input(
            py,
            format!(
                "fields[{i}] must be (name, offset, datatype, count) or have those attributes: {}",
                e.value(py)
            ),
        )
    };
    let (name, offset, datatype, count): (String, u32, u8, u32) = if obj.hasattr("name")? {
        (
            obj.getattr("name")?.extract().map_err(bad)?,
            obj.getattr("offset")?.extract().map_err(bad)?,
            obj.getattr("datatype")?.extract().map_err(bad)?,
            obj.getattr("count")?.extract().map_err(bad)?,
        )
    } else {
        obj.extract().map_err(bad)?
    };
    Ok(PointField {
        name,
        offset,
        datatype,
        count,
    })
}

/// Reads a ROS `sensor_msgs/PointCloud2` from its raw `data` bytes and layout
/// (no ROS needed). `fields` are `(name, offset, datatype, count)` tuples or ROS
/// `PointField` objects. NaN points (holes of organized clouds) are skipped and
/// counted in `CloudFile.skipped`; in an organized cloud, points at exactly
/// `(0, 0, 0)` (no-returns) in `CloudFile.at_origin`. `bytes` are read in
/// place, other bytes-like objects copied.
#[pyfunction]
#[pyo3(signature = (data, fields, *, height, width, point_step, row_step, is_bigendian=false))]
pub fn read_pointcloud2(
    py: Python<'_>,
    data: &Bound<'_, PyAny>,
    fields: &Bound<'_, PyAny>,
    height: u32,
    width: u32,
    point_step: u32,
    row_step: u32,
    is_bigendian: bool,
) -> PyResult<PyCloudFile> {
    let bytes = message_bytes(data, "data")?;
    let fields = fields
        .try_iter()?
        .enumerate()
        .map(|(i, f)| point_field_from(&f?, i))
        .collect::<PyResult<Vec<_>>>()?;
    let layout = PointCloud2Layout {
        height,
        width,
        fields,
        is_bigendian,
        point_step,
        row_step,
    };
    let slice = bytes.as_slice();
    let data = run_detached(py, move || {
        read_pointcloud2_named(&layout, slice, "PointCloud2")
    })?;
    Ok(PyCloudFile::new(data, "PointCloud2".to_string()))
}

/// The layout of `write_pointcloud2`'s message as a dict.
type Pc2Out<'py> = (Bound<'py, PyDict>, Bound<'py, PyBytes>);

/// Encodes a cloud (`CloudFile`, `PointCloud` or `(n, 3)` array-like) as a dense
/// PointCloud2 (float32 x, y, z, little endian, height 1): returns the layout
/// (`height`, `width`, `fields` as `(name, offset, datatype, count)` tuples,
/// `is_bigendian`, `point_step`, `row_step`) and the data bytes.
#[pyfunction]
pub fn write_pointcloud2<'py>(py: Python<'py>, cloud: &Bound<'py, PyAny>) -> PyResult<Pc2Out<'py>> {
    let data = cloud_data_from(cloud)?;
    let (layout, bytes) = run_detached(py, move || write_pc2(&data))?;
    let d = PyDict::new(py);
    d.set_item("height", layout.height)?;
    d.set_item("width", layout.width)?;
    let fields: Vec<(String, u32, u8, u32)> = layout
        .fields
        .iter()
        .map(|f| (f.name.clone(), f.offset, f.datatype, f.count))
        .collect();
    d.set_item("fields", fields)?;
    d.set_item("is_bigendian", layout.is_bigendian)?;
    d.set_item("point_step", layout.point_step)?;
    d.set_item("row_step", layout.row_step)?;
    Ok((d, PyBytes::new(py, &bytes)))
}

/// Reads a triangle mesh from bytes in memory (e.g. a member of a zip archive),
/// as `read_mesh`; `format` must be given (`"stl"`, `"obj"`, `"ply"` or
/// `"off"`) and `name` is used in messages.
#[pyfunction]
#[pyo3(signature = (data, format, name="<bytes>"))]
pub fn parse_mesh(
    py: Python<'_>,
    data: &Bound<'_, PyBytes>,
    format: &str,
    name: &str,
) -> PyResult<PyMesh> {
    let Some(format) = mesh_format(py, format)? else {
        return Err(invalid_input(
            py,
            "parse_mesh needs the format (stl, obj, ply or off), not auto",
        ));
    };
    let bytes = data.as_bytes().to_vec();
    let source = name.to_string();
    let data = run_detached(py, move || io::read_mesh_bytes(&bytes, &source, format))?;
    warn_dropped(py, name, data.dropped_faces)?;
    Ok(PyMesh::wrap(data.mesh))
}
