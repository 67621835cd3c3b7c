"""Reading and writing point clouds and meshes.

Point clouds: PLY (ascii, binary little/big endian), PCD (ascii, binary,
binary_compressed; organized or not), XYZ/CSV, NPY, and LAS/LAZ (read only).
Meshes: STL (ascii, binary), OBJ, PLY, OFF. ROS ``sensor_msgs/PointCloud2``
messages are read from their raw bytes and field layout, no ROS needed.

The parsers are the Rust core's (``cloudprox::io``); they release the GIL. A
missing file raises ``FileNotFoundError``; a corrupt, truncated or unsupported
file raises :class:`cloudprox.FormatError` naming the file and the problem.
Points with a NaN or infinite coordinate (the holes of an organized depth image)
are skipped and counted in :attr:`CloudFile.skipped`, never dropped silently.

Examples
--------
>>> import cloudprox as cp
>>> scan = cp.io.read_point_cloud("scan.pcd")  # doctest: +SKIP
>>> cloud = scan.to_point_cloud(sensor=cp.DepthCamera())  # noise seen from the file's VIEWPOINT
>>> gripper = cp.io.read_mesh("gripper.stl")  # doctest: +SKIP
>>> cp.collide(gripper, cloud, pose_a=grasp).probability  # doctest: +SKIP
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from cloudprox._native import CloudFile, Mesh, parse_mesh, read_mesh
from cloudprox._native import read_point_cloud as _read_point_cloud
from cloudprox._native import read_pointcloud2 as _read_pointcloud2
from cloudprox._native import write_mesh as _write_mesh
from cloudprox._native import write_point_cloud as _write_point_cloud
from cloudprox._native import write_pointcloud2 as _write_pointcloud2
from cloudprox.exceptions import DegenerateFacesWarning, InvalidInputError
from cloudprox.pose import from_quaternion, from_translation

__all__ = [
    "CloudFile",
    "DegenerateFacesWarning",
    "from_ros_message",
    "parse_mesh",
    "parse_numbers",
    "read_mesh",
    "read_point_cloud",
    "read_pointcloud2",
    "read_pose",
    "write_mesh",
    "write_point_cloud",
    "write_pointcloud2",
]

CloudFormatName = Literal["auto", "ply", "pcd", "xyz", "txt", "pts", "csv", "npy", "las", "laz"]
MeshFormatName = Literal["auto", "stl", "obj", "ply", "off"]
EncodingName = Literal[
    "ascii", "binary", "binary_little_endian", "binary_big_endian", "binary_compressed"
]
PathLike = str | os.PathLike[str]
FloatArray = npt.NDArray[np.float64]


def read_point_cloud(path: PathLike, format: CloudFormatName = "auto") -> CloudFile:
    """Read a point-cloud file.

    Parameters
    ----------
    path : str or path-like
        The file.
    format : str, default "auto"
        ``"auto"`` picks the format from the extension (``.ply .pcd .xyz .txt
        .pts .csv .npy .las .laz``).

    Returns
    -------
    CloudFile
        Points ``(n, 3)`` with finite coordinates, and what else the file holds:
        normals, covariances, the sensor pose (PCD ``VIEWPOINT``), the organized
        layout, the field names and the number of skipped non-finite points.
        ``CloudFile.to_point_cloud(...)`` makes a :class:`cloudprox.PointCloud`.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    cloudprox.FormatError
        If its content is corrupt, truncated or unsupported (the message names
        the file and the problem).
    cloudprox.InvalidInputError
        If the format cannot be told from the extension or is unknown.
    """
    return _read_point_cloud(os.fspath(path), format)


def write_point_cloud(
    path: PathLike,
    cloud: object,
    format: CloudFormatName = "auto",
    *,
    encoding: EncodingName | None = None,
    write_ascii: bool = False,
    compressed: bool = False,
) -> None:
    """Write a point cloud.

    Parameters
    ----------
    path : str or path-like
        The file; its extension gives the format unless ``format`` does.
    cloud : CloudFile, PointCloud or array_like of shape (n, 3)
        What to write. A ``PointCloud`` writes its points and its sensor
        covariances (as ``cov_xx ... cov_zz`` fields in PLY and PCD) when they are
        not zero; a ``CloudFile`` writes everything it holds.
    format : str, default "auto"
        As in :func:`read_point_cloud`; LAS/LAZ cannot be written.
    encoding : {"ascii", "binary", "binary_big_endian", "binary_compressed"}, optional
        PLY: ascii, binary (little endian) or binary_big_endian. PCD: ascii,
        binary or binary_compressed. Default binary.
    write_ascii, compressed : bool
        Open3D's spelling of ``encoding="ascii"`` and
        ``encoding="binary_compressed"``.
    """
    _write_point_cloud(
        os.fspath(path),
        cloud,
        format,
        encoding=encoding,
        write_ascii=write_ascii,
        compressed=compressed,
    )


def write_mesh(
    path: PathLike,
    mesh: Mesh,
    format: MeshFormatName = "auto",
    *,
    encoding: EncodingName | None = None,
    write_ascii: bool = False,
) -> None:
    """Write a triangle mesh (STL and PLY: binary unless ascii is asked for)."""
    _write_mesh(os.fspath(path), mesh, format, encoding=encoding, write_ascii=write_ascii)


def read_pointcloud2(
    data: bytes | bytearray | memoryview,
    fields: Sequence[tuple[str, int, int, int]] | Sequence[Any],
    *,
    height: int,
    width: int,
    point_step: int,
    row_step: int,
    is_bigendian: bool = False,
) -> CloudFile:
    """Read a ROS ``sensor_msgs/PointCloud2`` from its raw bytes and field layout.

    No ROS installation is needed: give the message's ``data`` and layout.

    Parameters
    ----------
    data : bytes-like
        The message's ``data`` (``row_step * height`` bytes at least).
    fields : sequence
        ``(name, offset, datatype, count)`` tuples, or ROS ``PointField`` objects;
        datatypes 1-8 are INT8, UINT8, INT16, UINT16, INT32, UINT32, FLOAT32,
        FLOAT64. ``x``, ``y`` and ``z`` are required; ``normal_x/y/z`` are read as
        normals.
    height, width, point_step, row_step, is_bigendian
        As in the message. ``height > 1`` is an organized cloud.

    Returns
    -------
    CloudFile
        Points with finite coordinates; NaN points (the holes of an organized
        cloud) are skipped and counted in ``skipped``, and ``pixels`` gives each
        kept point's pixel.

    Raises
    ------
    cloudprox.FormatError
        If the layout does not fit the data (a field past ``point_step``, data
        shorter than ``row_step * height``, an unknown datatype, no ``x``).
    """
    return _read_pointcloud2(
        data,
        fields,
        height=height,
        width=width,
        point_step=point_step,
        row_step=row_step,
        is_bigendian=is_bigendian,
    )


def from_ros_message(msg: Any) -> CloudFile:
    """Read a ROS 1 or ROS 2 ``sensor_msgs/PointCloud2`` message object.

    Any object with the message's attributes works (``data``, ``fields`` with
    ``name``/``offset``/``datatype``/``count``, ``height``, ``width``,
    ``point_step``, ``row_step``, ``is_bigendian``); see :func:`read_pointcloud2`.
    """
    return read_pointcloud2(
        bytes(msg.data),
        list(msg.fields),
        height=int(msg.height),
        width=int(msg.width),
        point_step=int(msg.point_step),
        row_step=int(msg.row_step),
        is_bigendian=bool(msg.is_bigendian),
    )


def write_pointcloud2(cloud: object) -> tuple[dict[str, Any], bytes]:
    """Encode a cloud as a dense ``PointCloud2`` (float32 x, y, z; little endian).

    Parameters
    ----------
    cloud : CloudFile, PointCloud or array_like of shape (n, 3)
        The points (and normals of a ``CloudFile`` that has them).

    Returns
    -------
    layout : dict
        ``height`` (1), ``width``, ``fields`` as ``(name, offset, datatype,
        count)`` tuples, ``is_bigendian``, ``point_step``, ``row_step``.
    data : bytes
        The message's ``data``.
    """
    return _write_pointcloud2(cloud)


def parse_numbers(text: str, n: int, what: str = "numbers") -> FloatArray:
    """Parse ``n`` finite numbers separated by commas or spaces."""
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        values = np.array([float(p) for p in parts], dtype=np.float64)
    except ValueError:
        raise InvalidInputError(f"{what}: expected {n} numbers, got {text!r}") from None
    if len(values) != n or not np.all(np.isfinite(values)):
        raise InvalidInputError(f"{what}: expected {n} finite numbers, got {text!r}")
    return values


def read_pose(text: str | os.PathLike[str], what: str = "pose") -> FloatArray:
    """Read a ``(4, 4)`` pose from a file, or parse it from inline numbers.

    Accepted: a ``.npy`` file holding a ``(4, 4)`` array; a text file of 16
    numbers (row-major); inline ``"x,y,z"`` (a translation), ``"x,y,z,qw,qx,qy,qz"``
    (translation and unit quaternion) or 16 numbers (row-major matrix).

    Raises
    ------
    cloudprox.InvalidInputError
        Naming ``what`` and the problem (missing file, wrong count, not numbers).
    """
    path = Path(text)
    text = os.fspath(text)
    if path.suffix.lower() == ".npy" or path.is_file():
        if not path.is_file():
            raise InvalidInputError(f"{what}: no such file: {text}")
        if path.suffix.lower() == ".npy":
            try:
                m = np.load(path, allow_pickle=False)
            except (ValueError, OSError) as e:
                raise InvalidInputError(
                    f"{what}: {text} is not a readable .npy file ({e})"
                ) from None
        else:
            try:
                m = np.loadtxt(path, dtype=np.float64, ndmin=1)
            except ValueError as e:
                raise InvalidInputError(
                    f"{what}: {text} is not a text file of numbers ({e})"
                ) from None
        m = np.asarray(m, dtype=np.float64)
        if m.size != 16:
            raise InvalidInputError(
                f"{what}: {text} must hold a (4, 4) matrix, got shape {m.shape}"
            )
        return m.reshape(4, 4)
    parts = [p for p in text.replace(",", " ").split() if p]
    values = parse_numbers(text, len(parts), what) if parts else np.zeros(0)
    if len(values) == 16:
        return values.reshape(4, 4)
    if len(values) not in (3, 7):
        raise InvalidInputError(
            f"{what}: expected a pose file, or 3 (x,y,z), 7 (x,y,z,qw,qx,qy,qz) or 16 numbers, "
            f"got {text!r}"
        )
    try:  # the core's constructors check the numbers (a zero quaternion, a huge translation)
        if len(values) == 3:
            return from_translation(values)
        return from_quaternion(values[3:], translation=values[:3])
    except InvalidInputError as e:
        raise InvalidInputError(f"{what}: {e}") from None
