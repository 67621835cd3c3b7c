//! OBJ (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "OBJ", "reader not written yet")
}

/// Reads an OBJ mesh.
pub fn read_obj_mesh(bytes: &[u8], name: &str) -> Result<MeshData> {
    Err(todo(name))
}
/// Encodes a mesh as OBJ.
pub fn write_obj_mesh(mesh: &Mesh) -> Result<Vec<u8>> {
    Err(todo(""))
}
