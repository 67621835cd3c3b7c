//! File formats, their detection from a path, and the dispatch to each reader
//! and writer.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::{las, npy, obj, off, pcd, ply, stl, xyz, CloudData, MeshData};
use crate::shape::Mesh;

/// A point-cloud file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CloudFormat {
    /// Stanford PLY (`.ply`).
    Ply,
    /// Point Cloud Library PCD (`.pcd`).
    Pcd,
    /// Whitespace-separated text, one point per line (`.xyz`, `.xyzn`, `.xyzrgb`,
    /// `.txt`, `.pts`).
    Xyz,
    /// Comma-separated text, with or without a header line (`.csv`).
    Csv,
    /// NumPy array file (`.npy`).
    Npy,
    /// ASPRS LAS, or LAZ (its compressed form) (`.las`, `.laz`); read only.
    Las,
}

/// A triangle-mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// STL, ascii or binary (`.stl`).
    Stl,
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Stanford PLY with a `face` element (`.ply`).
    Ply,
    /// Object File Format (`.off`).
    Off,
}

/// How a file is written, where the format has a choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    /// Text (PLY ascii, PCD ascii, STL ascii).
    Ascii,
    /// Binary, little endian (PLY, PCD `binary`, STL binary).
    #[default]
    BinaryLittleEndian,
    /// Binary, big endian (PLY only).
    BinaryBigEndian,
    /// LZF-compressed binary (PCD `binary_compressed` only).
    BinaryCompressed,
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

impl CloudFormat {
    /// The format a path's extension names, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        Some(match extension(path).as_str() {
            "ply" => Self::Ply,
            "pcd" => Self::Pcd,
            "xyz" | "xyzn" | "xyzrgb" | "txt" | "pts" => Self::Xyz,
            "csv" => Self::Csv,
            "npy" => Self::Npy,
            "las" | "laz" => Self::Las,
            _ => return None,
        })
    }

    /// The format's name as used in messages (`"PLY"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Self::Ply => "PLY",
            Self::Pcd => "PCD",
            Self::Xyz => "XYZ",
            Self::Csv => "CSV",
            Self::Npy => "NPY",
            Self::Las => "LAS",
        }
    }
}

impl MeshFormat {
    /// The format a path's extension names, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        Some(match extension(path).as_str() {
            "stl" => Self::Stl,
            "obj" => Self::Obj,
            "ply" => Self::Ply,
            "off" => Self::Off,
            _ => return None,
        })
    }

    /// The format's name as used in messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Stl => "STL",
            Self::Obj => "OBJ",
            Self::Ply => "PLY",
            Self::Off => "OFF",
        }
    }
}

fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(path, &e))
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| Error::io(path, &e))
}

fn unknown_extension(path: &Path, what: &str, known: &str) -> Error {
    Error::invalid(format!(
        "{}: cannot tell the {what} format from the extension {:?}; known: {known}",
        path.display(),
        extension(path)
    ))
}

const CLOUD_EXTENSIONS: &str = ".ply .pcd .xyz .xyzn .xyzrgb .txt .pts .csv .npy .las .laz";
const MESH_EXTENSIONS: &str = ".stl .obj .ply .off";

/// Reads a point cloud from `bytes`; `name` is used in errors.
pub fn read_point_cloud_bytes(bytes: &[u8], name: &str, format: CloudFormat) -> Result<CloudData> {
    match format {
        CloudFormat::Ply => ply::read_ply(bytes, name),
        CloudFormat::Pcd => pcd::read_pcd(bytes, name),
        CloudFormat::Xyz | CloudFormat::Csv => xyz::read_xyz(bytes, name),
        CloudFormat::Npy => npy::read_npy(bytes, name),
        CloudFormat::Las => las::read_las(bytes, name),
    }
}

/// Reads a point cloud file; the format comes from the extension unless given.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read, [`Error::Format`] when its content
/// is invalid, [`Error::InvalidInput`] when the format cannot be told.
pub fn read_point_cloud(path: &Path, format: Option<CloudFormat>) -> Result<CloudData> {
    let format = format
        .or_else(|| CloudFormat::from_path(path))
        .ok_or_else(|| unknown_extension(path, "point cloud", CLOUD_EXTENSIONS))?;
    let bytes = read_file(path)?;
    read_point_cloud_bytes(&bytes, &path.display().to_string(), format)
}

/// Encodes a point cloud in `format` (`encoding` where the format has a choice).
pub fn write_point_cloud_bytes(
    cloud: &CloudData,
    format: CloudFormat,
    encoding: Encoding,
) -> Result<Vec<u8>> {
    match format {
        CloudFormat::Ply => ply::write_ply(cloud, encoding),
        CloudFormat::Pcd => pcd::write_pcd(cloud, encoding),
        CloudFormat::Xyz => xyz::write_xyz(cloud, b' '),
        CloudFormat::Csv => xyz::write_xyz(cloud, b','),
        CloudFormat::Npy => npy::write_npy(cloud),
        CloudFormat::Las => Err(Error::invalid(
            "writing LAS/LAZ is not supported; write PLY or PCD instead",
        )),
    }
}

/// Writes a point cloud file; the format comes from the extension unless given.
pub fn write_point_cloud(
    path: &Path,
    cloud: &CloudData,
    format: Option<CloudFormat>,
    encoding: Encoding,
) -> Result<()> {
    let format = format
        .or_else(|| CloudFormat::from_path(path))
        .ok_or_else(|| unknown_extension(path, "point cloud", CLOUD_EXTENSIONS))?;
    let bytes = write_point_cloud_bytes(cloud, format, encoding)?;
    write_file(path, &bytes)
}

/// Reads a mesh from `bytes`; `name` is used in errors.
pub fn read_mesh_bytes(bytes: &[u8], name: &str, format: MeshFormat) -> Result<MeshData> {
    match format {
        MeshFormat::Stl => stl::read_stl_mesh(bytes, name),
        MeshFormat::Obj => obj::read_obj_mesh(bytes, name),
        MeshFormat::Ply => ply::read_ply_mesh(bytes, name),
        MeshFormat::Off => off::read_off_mesh(bytes, name),
    }
}

/// Reads a mesh file; the format comes from the extension unless given.
pub fn read_mesh(path: &Path, format: Option<MeshFormat>) -> Result<MeshData> {
    let format = format
        .or_else(|| MeshFormat::from_path(path))
        .ok_or_else(|| unknown_extension(path, "mesh", MESH_EXTENSIONS))?;
    let bytes = read_file(path)?;
    read_mesh_bytes(&bytes, &path.display().to_string(), format)
}

/// Encodes a mesh in `format` (`encoding` for STL and PLY).
pub fn write_mesh_bytes(mesh: &Mesh, format: MeshFormat, encoding: Encoding) -> Result<Vec<u8>> {
    match format {
        MeshFormat::Stl => stl::write_stl_mesh(mesh, encoding),
        MeshFormat::Obj => obj::write_obj_mesh(mesh),
        MeshFormat::Ply => ply::write_ply_mesh(mesh, encoding),
        MeshFormat::Off => off::write_off_mesh(mesh),
    }
}

/// Writes a mesh file; the format comes from the extension unless given.
pub fn write_mesh(
    path: &Path,
    mesh: &Mesh,
    format: Option<MeshFormat>,
    encoding: Encoding,
) -> Result<()> {
    let format = format
        .or_else(|| MeshFormat::from_path(path))
        .ok_or_else(|| unknown_extension(path, "mesh", MESH_EXTENSIONS))?;
    let bytes = write_mesh_bytes(mesh, format, encoding)?;
    write_file(path, &bytes)
}
