//! LAS (to be written).

#![allow(unused_variables)]

use crate::error::{Error, Result};
#[allow(unused_imports)]
use crate::io::{CloudData, Encoding, MeshData};
#[allow(unused_imports)]
use crate::shape::Mesh;

fn todo(name: &str) -> Error {
    Error::format(name, "LAS", "reader not written yet")
}

/// Reads a LAS or LAZ file.
pub fn read_las(bytes: &[u8], name: &str) -> Result<CloudData> {
    Err(todo(name))
}
