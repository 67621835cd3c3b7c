//! Reading and writing point clouds and meshes: one file per format.
//!
//! | format | read | write | module |
//! |---|---|---|---|
//! | PLY (ascii, binary little/big endian; points and meshes) | yes | yes | [`ply`] |
//! | PCD (ascii, binary, binary_compressed; organized or not) | yes | yes | [`pcd`] |
//! | XYZ / CSV (text, one point per line) | yes | yes | [`xyz`] |
//! | NPY (an `(n, 3)` float array) | yes | yes | [`npy`] |
//! | LAS / LAZ | yes | no | [`las`] |
//! | STL (ascii, binary) | yes | yes | [`stl`] |
//! | OBJ | yes | yes | [`obj`] |
//! | OFF | yes | yes | [`off`] |
//! | ROS `sensor_msgs/PointCloud2` (raw bytes + field layout) | yes | encode to bytes | [`pointcloud2`] |
//!
//! Readers parse bytes already in memory (`read_*(bytes, name)`; `name` is the
//! file name used in errors) and return plain data: [`CloudData`] for point
//! clouds, [`MeshData`] for meshes. [`read_point_cloud`] and [`read_mesh`] open a
//! file and pick the format from its extension (or the one given).
//!
//! Points with a NaN or infinite coordinate (the holes of an organized depth
//! image) are never kept and never dropped silently: they are counted in
//! [`CloudData::skipped`], and an organized cloud keeps the pixel of every point
//! it kept ([`Grid`]). Every corrupt, truncated or unsupported file gives
//! [`Error::Format`](crate::Error::Format) naming the file and the problem;
//! a file that cannot be opened gives [`Error::Io`](crate::Error::Io).

mod cloud_data;
mod cursor;
mod format;
pub mod las;
mod lzf;
mod mesh_text;
pub mod npy;
pub mod obj;
pub mod off;
pub mod pcd;
pub mod ply;
pub mod pointcloud2;
pub mod stl;
mod text;
pub mod xyz;

pub use cloud_data::{CloudData, CloudDataBuilder, Grid, MeshData, COV_FIELDS};
pub(crate) use cursor::ByteCursor;
pub use format::{
    read_mesh, read_mesh_bytes, read_point_cloud, read_point_cloud_bytes, write_mesh,
    write_mesh_bytes, write_point_cloud, write_point_cloud_bytes, CloudFormat, Encoding,
    MeshFormat,
};
