//! PCD (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "PCD", "reader not written yet")
}

/// Reads a PCD file.
pub fn read_pcd(bytes: &[u8], name: &str) -> Result<CloudData> {
    Err(todo(name))
}
/// Encodes a point cloud as PCD.
pub fn write_pcd(cloud: &CloudData, encoding: Encoding) -> Result<Vec<u8>> {
    Err(todo(""))
}
