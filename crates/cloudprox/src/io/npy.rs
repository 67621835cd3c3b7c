//! NPY (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "NPY", "reader not written yet")
}

/// Reads an NPY file.
pub fn read_npy(bytes: &[u8], name: &str) -> Result<CloudData> {
    Err(todo(name))
}
/// Encodes a point cloud as NPY.
pub fn write_npy(cloud: &CloudData) -> Result<Vec<u8>> {
    Err(todo(""))
}
