//! STL (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "STL", "reader not written yet")
}

/// Reads an STL mesh.
pub fn read_stl_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    Err(todo(name))
}
/// Encodes a mesh as STL.
pub fn write_stl_mesh(mesh: &Mesh, encoding: Encoding) -> Result<Vec<u8>> {
    Err(todo(""))
}
