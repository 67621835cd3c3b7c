"""Reading and writing point clouds and meshes.

Point clouds: PLY (ascii, binary little/big endian), PCD (ascii, binary,
binary_compressed; organized or not), XYZ/CSV, NPY, and LAS/LAZ (read only).
Meshes: STL (ascii, binary), OBJ, PLY, OFF. ROS ``sensor_msgs/PointCloud2``
messages are read from their raw bytes and field layout, from a serialized
message, or from ROS bags (rosbag2 sqlite3 ``.db3`` and MCAP, ROS 1 ``.bag``;
see :mod:`cloudprox.bags`), no ROS needed.

The parsers are the Rust core's (``cloudprox::io``); they release the GIL. A
missing file raises ``FileNotFoundError``; a corrupt, truncated or unsupported
file raises :class:`cloudprox.FormatError` naming the file and the problem.
Points with a NaN or infinite coordinate (the holes of an organized depth image)
are skipped and counted in :attr:`CloudFile.skipped`, never dropped silently.
In an organized scan the points at exactly the sensor origin are no-returns
too: left out and counted in :attr:`CloudFile.at_origin` (``no_returns`` is
both counts), their pixels kept in the organized layout.

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
from collections.abc import Iterator, Sequence
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
    "iter_point_clouds",
    "parse_mesh",
    "parse_numbers",
    "read_mesh",
    "read_point_cloud",
    "read_pointcloud2",
    "read_pointcloud2_message",
    "read_pose",
    "write_mesh",
    "write_point_cloud",
    "write_pointcloud2",
]

CloudFormatName = Literal[
    "auto", "ply", "pcd", "xyz", "xyzn", "xyzrgb", "txt", "pts", "csv", "npy", "las", "laz"
]
MeshFormatName = Literal["auto", "stl", "obj", "ply", "off"]
EncodingName = Literal[
    "ascii", "binary", "binary_little_endian", "binary_big_endian", "binary_compressed"
]
PathLike = str | os.PathLike[str]
FloatArray = npt.NDArray[np.float64]


def read_point_cloud(
    path: PathLike,
    format: CloudFormatName = "auto",
    *,
    topic: str | None = None,
    index: int | None = None,
    frame: str | None = None,
) -> CloudFile:
    """Read a point-cloud file, or one frame of a ROS bag.

    Parameters
    ----------
    path : str or path-like
        The file. A ROS 1 ``.bag``, a rosbag2 ``.db3`` or ``.mcap`` file, or a
        rosbag2 folder (with its ``metadata.yaml``) is read as a bag.
    format : str, default "auto"
        ``"auto"`` picks the format from the extension (``.ply .pcd .xyz .xyzn
        .xyzrgb .txt .pts .csv .npy .las .laz``, and the bags').
    topic : str, optional
        Bags only: the ``sensor_msgs/PointCloud2`` topic; ``None`` picks the
        bag's only one (an error lists them when there are several).
    index : int, optional
        Bags only: the message's index in the topic (default 0; negative counts
        from the end).
    frame : str, optional
        Bags only: the TF frame to express the points in (default: the root of
        the sensor frame's TF tree; see :mod:`cloudprox.bags`).

    Returns
    -------
    CloudFile
        Points ``(n, 3)`` with finite coordinates, and what else the file holds:
        normals, covariances, the sensor pose (PCD ``VIEWPOINT``; a bag's TF),
        the organized layout, the field names, the number of skipped non-finite
        points and of no-returns at the sensor origin (``at_origin``).
        ``CloudFile.to_point_cloud(...)`` makes a :class:`cloudprox.PointCloud`.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    cloudprox.FormatError
        If its content is corrupt, truncated or unsupported (the message names
        the file and the problem; for a bag also the topic, message and field).
    cloudprox.InvalidInputError
        If the format cannot be told from the extension or is unknown; for a
        bag, if the topic is unknown, ambiguous or not a PointCloud2, or the
        index is out of range; ``topic``, ``index`` or ``frame`` given for a
        file that is not a bag.
    """
    from cloudprox import bags

    if format == "auto" and bags.is_bag(path):
        default_topic, default_index = bags.selected()
        return bags.read_point_cloud(
            path,
            default_topic if topic is None else topic,
            default_index if index is None else index,
            frame=frame,
        )
    if topic is not None or index is not None or frame is not None:
        raise InvalidInputError(
            f"{os.fspath(path)}: topic=, index= and frame= apply to ROS bags (.bag, .db3, "
            ".mcap or a rosbag2 folder) only"
        )
    return _read_point_cloud(os.fspath(path), format)


def iter_point_clouds(
    path: PathLike, topic: str | None = None, *, frame: str | None = None
) -> Iterator[CloudFile]:
    """Yield the frames of a bag's ``sensor_msgs/PointCloud2`` topic, one at a time.

    A generator: memory stays flat in the number of frames. See
    :func:`cloudprox.bags.iter_point_clouds`.

    Parameters
    ----------
    path : str or path-like
        A ROS 1 ``.bag``, a rosbag2 ``.db3`` or ``.mcap`` file, or a rosbag2 folder.
    topic : str, optional
        The PointCloud2 topic (``None``: the bag's only one).
    frame : str, optional
        The TF frame to express the points in (default: the TF root).

    Yields
    ------
    CloudFile
        One per message, in the bag's order.
    """
    from cloudprox import bags

    return bags.iter_point_clouds(path, topic, frame=frame)


def read_pointcloud2_message(
    message: bytes | bytearray | memoryview,
    encoding: Literal["cdr", "ros1"] = "cdr",
    *,
    name: str = "PointCloud2 message",
) -> CloudFile:
    """Read a serialized ``sensor_msgs/PointCloud2`` message, as a bag stores it.

    Parameters
    ----------
    message : bytes-like
        The message: CDR with its 4-byte encapsulation header (rosbag2, ROS 2
        middleware), or the ROS 1 serialization (``.bag``). ``bytes`` are read in
        place, without a copy.
    encoding : {"cdr", "ros1"}, default "cdr"
        Which of the two.
    name : str, default "PointCloud2 message"
        What errors call the message.

    Returns
    -------
    CloudFile
        As :func:`read_pointcloud2`, with ``stamp``, ``frame_id`` and
        ``sensor_frame`` from the message's header and the sensor at the origin
        of its frame.

    Raises
    ------
    cloudprox.FormatError
        If the message is truncated, its layout does not fit its data, or ``x``,
        ``y`` or ``z`` is missing.
    """
    return CloudFile._from_message(message, encoding, name=name, path=name)


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
