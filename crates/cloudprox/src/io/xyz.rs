//! XYZ (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "XYZ", "reader not written yet")
}

/// Reads an XYZ/CSV file.
pub fn read_xyz(bytes: &[u8], name: &str) -> Result<CloudData> {
    Err(todo(name))
}
/// Encodes a point cloud as text with this delimiter.
pub fn write_xyz(cloud: &CloudData, delimiter: u8) -> Result<Vec<u8>> {
    Err(todo(""))
}
