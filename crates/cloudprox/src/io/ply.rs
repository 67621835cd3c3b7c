//! PLY (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "PLY", "reader not written yet")
}

/// Reads the vertices of a PLY file as a point cloud.
pub fn read_ply(bytes: &[u8], name: &str) -> Result<CloudData> {
    Err(todo(name))
}
/// Encodes a point cloud as PLY.
pub fn write_ply(cloud: &CloudData, encoding: Encoding) -> Result<Vec<u8>> {
    Err(todo(""))
}
/// Reads a PLY mesh.
pub fn read_ply_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    Err(todo(name))
}
/// Encodes a mesh as PLY.
pub fn write_ply_mesh(mesh: &Mesh, encoding: Encoding) -> Result<Vec<u8>> {
    Err(todo(""))
}
