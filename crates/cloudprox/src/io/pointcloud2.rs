//! PointCloud2 (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "PointCloud2", "reader not written yet")
}

/// Reads a PointCloud2 message body (to be specified by the module's author).
pub fn read_pointcloud2(data: &[u8]) -> Result<CloudData> {
    Err(todo("PointCloud2"))
}
