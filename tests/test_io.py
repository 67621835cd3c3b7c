"""File I/O through ``cloudprox.io``: round trips, independent readers, errors, PointCloud2.

The independent readers are Open3D (PLY, PCD, XYZ, STL, OBJ, OFF), numpy (NPY)
and laspy (LAS/LAZ); their tests skip when the package is missing.
"""

from __future__ import annotations

import array
import re
import struct
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import FormatError, InvalidInputError
from cloudprox.io import DegenerateFacesWarning
from cloudprox.pose import from_rpy

# (extension, encoding) of every point-cloud format and encoding cloudprox writes.
CLOUD_CASES: list[tuple[str, str | None]] = [
    ("ply", "ascii"),
    ("ply", "binary"),
    ("ply", "binary_big_endian"),
    ("pcd", "ascii"),
    ("pcd", "binary"),
    ("pcd", "binary_compressed"),
    ("xyz", None),
    ("csv", None),
    ("npy", None),
]
# Formats that store covariances (cov_xx ... cov_zz).
COV_CASES = [c for c in CLOUD_CASES if c[0] in ("ply", "pcd", "csv")]
MESH_CASES: list[tuple[str, str | None]] = [
    ("stl", "ascii"),
    ("stl", "binary"),
    ("obj", None),
    ("ply", "ascii"),
    ("ply", "binary"),
    ("ply", "binary_big_endian"),
    ("off", None),
]
# What the header says about the encoding, so a test sees the one it asked for.
ENCODING_MARK = {
    ("ply", "ascii"): b"format ascii 1.0\n",
    ("ply", "binary"): b"format binary_little_endian 1.0\n",
    ("ply", "binary_big_endian"): b"format binary_big_endian 1.0\n",
    ("pcd", "ascii"): b"\nDATA ascii\n",
    ("pcd", "binary"): b"\nDATA binary\n",
    ("pcd", "binary_compressed"): b"\nDATA binary_compressed\n",
}
COV_FIELDS = ["cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"]


def case_id(case: tuple[str, str | None]) -> str:
    return case[0] if case[1] is None else f"{case[0]}-{case[1]}"


def f32(a: Any) -> np.ndarray:
    """Values rounded to float32, as float64."""
    return np.asarray(a, dtype=np.float64).astype(np.float32).astype(np.float64)


def points(n: int = 60, seed: int = 0) -> np.ndarray:
    """Points in front of a sensor at the origin looking along +z, non-round coordinates."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)) * [0.4, 0.3, 0.2] + [0.05, -0.1, 1.7]


@pytest.fixture(scope="module")
def noisy() -> cp.PointCloud:
    """A cloud with anisotropic sensor covariances (all six entries non-zero)."""
    return cp.PointCloud(points(), sensor=cp.DepthCamera(), origin=[0.1, -0.2, 0.0])


def mesh() -> cp.Mesh:
    """A closed 12-sided cylinder in a pose with non-round coordinates."""
    pose = from_rpy((0.7, 0.0, 0.3), (0.123, -0.456, 0.789))
    return cp.Mesh.cylinder(0.05, 0.1, 12).transformed(pose)


def triangles(vertices: Any, faces: Any) -> list[tuple[tuple[float, ...], ...]]:
    """The triangles as corner coordinates, each rotated to start at its smallest corner.

    Independent of vertex order and numbering (welding, Open3D's unwelded STL),
    but not of a triangle's orientation.
    """
    out = []
    for tri in np.asarray(vertices, dtype=np.float64)[np.asarray(faces)].tolist():
        corners = [tuple(c) for c in tri]
        k = corners.index(min(corners))
        out.append(tuple(corners[k:] + corners[:k]))
    return sorted(out)


def signed_volume(vertices: Any, faces: Any) -> float:
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    return float(np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) / 6.0)


def write_cloud(path: Path, cloud: object, encoding: Any) -> bytes:
    cp.io.write_point_cloud(path, cloud, encoding=encoding)
    return path.read_bytes()


# ----------------------------------------------------------------- round trips


@pytest.mark.parametrize("case", CLOUD_CASES, ids=case_id)
def test_points_round_trip(tmp_path: Path, case: tuple[str, str | None]) -> None:
    ext, encoding = case
    pts = points()
    path = tmp_path / f"cloud.{ext}"
    data = write_cloud(path, pts, encoding)
    if case in ENCODING_MARK:
        assert ENCODING_MARK[case] in data
    got = cp.io.read_point_cloud(path)
    # PCD stores x y z as float32 (PCL / Open3D compatibility); the others are exact.
    want = f32(pts) if ext == "pcd" else pts
    assert got.points.dtype == np.float64
    np.testing.assert_array_equal(got.points, want)
    assert len(got) == len(pts)
    assert got.fields == ["x", "y", "z"]
    assert got.normals is None
    assert got.covariances is None
    if ext == "pcd":  # the default VIEWPOINT: the sensor at the origin
        assert got.sensor_pose_is_default
        np.testing.assert_array_equal(got.sensor_pose, np.eye(4))
    else:
        assert got.sensor_pose is None and not got.sensor_pose_is_default
    assert got.grid_shape is None
    assert got.pixels is None
    assert got.skipped == 0
    assert got.path == str(path)


@pytest.mark.parametrize("case", COV_CASES, ids=case_id)
def test_covariances_round_trip(
    tmp_path: Path, case: tuple[str, str | None], noisy: cp.PointCloud
) -> None:
    ext, encoding = case
    path = tmp_path / f"cloud.{ext}"
    write_cloud(path, noisy, encoding)
    got = cp.io.read_point_cloud(path)
    assert got.fields == ["x", "y", "z", *COV_FIELDS]
    want_pts = f32(noisy.points) if ext == "pcd" else noisy.points
    np.testing.assert_array_equal(got.points, want_pts)
    # Covariances are float64 in every format (PCD: F8), so exact.
    assert got.covariances is not None
    assert got.covariances.shape == (len(noisy), 3, 3)
    np.testing.assert_array_equal(got.covariances, noisy.sensor_covariances)
    assert np.all(got.covariances[:, 0, 1] != 0.0)

    # to_point_cloud uses the stored covariances when no noise is given ...
    plain = got.to_point_cloud(discretization=False)
    np.testing.assert_array_equal(plain.covariances, noisy.sensor_covariances)
    # ... and adds the discretization part on top of them by default.
    full = got.to_point_cloud()
    np.testing.assert_array_equal(full.sensor_covariances, noisy.sensor_covariances)
    extra = full.covariances - full.sensor_covariances
    assert np.all(np.linalg.eigvalsh(extra) > -1e-15)
    assert np.all(np.trace(extra, axis1=1, axis2=2) > 0.0)
    # An explicit noise replaces the stored one.
    iso = got.to_point_cloud(sigma=0.003, discretization=False)
    np.testing.assert_allclose(iso.covariances, np.broadcast_to(9e-6 * np.eye(3), (60, 3, 3)))


@pytest.mark.parametrize("ext", ["xyz", "npy"])
def test_formats_without_covariance_columns_drop_them(
    tmp_path: Path, ext: str, noisy: cp.PointCloud
) -> None:
    path = tmp_path / f"cloud.{ext}"
    cp.io.write_point_cloud(path, noisy)
    got = cp.io.read_point_cloud(path)
    np.testing.assert_array_equal(got.points, noisy.points)
    assert got.covariances is None
    with pytest.raises(InvalidInputError, match="stores no covariances"):
        got.to_point_cloud()


def test_zero_sensor_noise_writes_no_covariances(tmp_path: Path) -> None:
    path = tmp_path / "cloud.ply"
    cp.io.write_point_cloud(path, cp.PointCloud(points(), discretization=True))
    assert cp.io.read_point_cloud(path).fields == ["x", "y", "z"]


def test_open3d_spellings_of_the_encoding(tmp_path: Path) -> None:
    pts = points()
    cp.io.write_point_cloud(tmp_path / "a.pcd", pts, write_ascii=True)
    cp.io.write_point_cloud(tmp_path / "c.pcd", pts, compressed=True)
    cp.io.write_point_cloud(tmp_path / "d.pcd", pts)
    cp.io.write_point_cloud(tmp_path / "a.ply", pts, write_ascii=True)
    cp.io.write_point_cloud(tmp_path / "d.ply", pts)
    assert b"\nDATA ascii\n" in (tmp_path / "a.pcd").read_bytes()
    assert b"\nDATA binary_compressed\n" in (tmp_path / "c.pcd").read_bytes()
    assert b"\nDATA binary\n" in (tmp_path / "d.pcd").read_bytes()  # the default
    assert b"format ascii 1.0" in (tmp_path / "a.ply").read_bytes()
    assert b"format binary_little_endian 1.0" in (tmp_path / "d.ply").read_bytes()
    for name in ("a.pcd", "c.pcd", "d.pcd"):
        np.testing.assert_array_equal(cp.io.read_point_cloud(tmp_path / name).points, f32(pts))


@pytest.mark.parametrize(
    ("ext", "encoding", "pattern"),
    [
        ("ply", "binary_compressed", "PLY cannot be written as binary_compressed; choose one of"),
        ("pcd", "binary_big_endian", "PCD cannot be written as binary_big_endian; choose one of"),
        ("xyz", "binary", "XYZ has a single encoding"),
        ("npy", "ascii", "NPY has a single encoding"),
        ("ply", "utf8", 'unknown encoding "utf8"'),
        ("las", None, "writing LAS/LAZ is not supported"),
        ("laz", None, "writing LAS/LAZ is not supported"),
        ("foo", None, 'cannot tell the point cloud format from the extension "foo"'),
    ],
)
def test_write_refuses_what_cannot_be_written(
    tmp_path: Path, ext: str, encoding: str | None, pattern: str
) -> None:
    with pytest.raises(InvalidInputError, match=pattern):
        cp.io.write_point_cloud(
            tmp_path / f"cloud.{ext}",
            points(),
            encoding=encoding,  # type: ignore[arg-type]
        )
    assert not (tmp_path / f"cloud.{ext}").exists()


def test_explicit_format_and_text_extensions(tmp_path: Path) -> None:
    pts = points()
    cp.io.write_point_cloud(tmp_path / "cloud.dat", pts, "ply")
    assert (tmp_path / "cloud.dat").read_bytes().startswith(b"ply\n")
    np.testing.assert_array_equal(cp.io.read_point_cloud(tmp_path / "cloud.dat", "ply").points, pts)
    with pytest.raises(InvalidInputError, match='unknown point cloud format "foo"'):
        cp.io.read_point_cloud(tmp_path / "cloud.dat", "foo")  # type: ignore[arg-type]
    # .txt and .pts are XYZ; the delimiter is found from the first line.
    np.savetxt(tmp_path / "cloud.txt", pts, fmt="%.17g")
    np.savetxt(tmp_path / "cloud.pts", pts, fmt="%.17g", delimiter=";")
    for name in ("cloud.txt", "cloud.pts"):
        np.testing.assert_array_equal(cp.io.read_point_cloud(tmp_path / name).points, pts)


def test_text_columns_header_and_holes(tmp_path: Path) -> None:
    path = tmp_path / "cloud.csv"
    path.write_text(
        "# exported by hand\nX;Y;Z;nx;ny;nz;label\n"
        "1;2;3;0;0;1;7\n\n// comment\n4;5;6;0;1;0;8\nnan;1;2;1;0;0;9\n7;8;inf;1;0;0;9\n"
    )
    got = cp.io.read_point_cloud(path)
    np.testing.assert_array_equal(got.points, [[1, 2, 3], [4, 5, 6]])
    assert got.normals is not None
    np.testing.assert_array_equal(got.normals, [[0, 0, 1], [0, 1, 0]])
    assert got.skipped == 2
    assert [f.lower() for f in got.fields] == ["x", "y", "z", "nx", "ny", "nz", "label"]
    # Without a header the extra columns are col3, col4, ...
    xyz = tmp_path / "cloud.xyz"
    xyz.write_text("1 2 3 9 9\n4\t5 6 9 9\n")
    got = cp.io.read_point_cloud(xyz)
    assert got.fields == ["x", "y", "z", "col3", "col4"]
    np.testing.assert_array_equal(got.points, [[1, 2, 3], [4, 5, 6]])


def test_cloudfile_with_normals_and_organized_grid_round_trips(tmp_path: Path) -> None:
    # A hand-written organized PCD with normals and a VIEWPOINT.
    rng = np.random.default_rng(3)
    pts = f32(points(6, seed=3))
    nrm = f32(rng.normal(size=(6, 3)))
    rows = "\n".join(
        " ".join(repr(float(v)) for v in (*p, *n)) for p, n in zip(pts, nrm, strict=False)
    )
    src = tmp_path / "src.pcd"
    src.write_text(
        "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n"
        "TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH 3\nHEIGHT 2\n"
        "VIEWPOINT 0.5 -0.25 0.125 0 1 0 0\nPOINTS 6\nDATA ascii\n" + rows + "\n"
    )
    cf = cp.io.read_point_cloud(src)
    assert cf.grid_shape == (2, 3)
    assert cf.sensor_pose is not None
    for case in (("pcd", "binary"), ("pcd", "binary_compressed"), ("ply", "binary")):
        out = tmp_path / f"out-{case[1]}.{case[0]}"
        cp.io.write_point_cloud(out, cf, encoding=case[1])
        got = cp.io.read_point_cloud(out)
        np.testing.assert_array_equal(got.points, pts)
        assert got.normals is not None
        np.testing.assert_array_equal(got.normals, nrm)
        if case[0] == "pcd":  # PCD keeps the grid (every pixel holds a point) and viewpoint
            assert got.grid_shape == (2, 3)
            assert got.pixels is not None
            np.testing.assert_array_equal(got.pixels, np.arange(6))
            assert got.sensor_pose is not None
            np.testing.assert_allclose(got.sensor_pose, cf.sensor_pose, atol=1e-15)


@pytest.mark.parametrize("case", MESH_CASES, ids=case_id)
def test_mesh_round_trip(tmp_path: Path, case: tuple[str, str | None]) -> None:
    ext, encoding = case
    m = mesh()
    path = tmp_path / f"mesh.{ext}"
    cp.io.write_mesh(path, m, encoding=encoding)  # type: ignore[arg-type]
    data = path.read_bytes()
    if ext == "stl":
        assert data.startswith(b"solid") == (encoding == "ascii")
    if case in ENCODING_MARK:
        assert ENCODING_MARK[case] in data
    got = cp.io.read_mesh(path)
    assert len(got.faces) == len(m.faces)
    assert len(got.vertices) == len(m.vertices)  # STL: welded back to the shared vertices
    assert got.is_closed
    if ext == "stl":
        # STL has no indices: compare the triangles; binary STL stores float32.
        want = f32(m.vertices) if encoding == "binary" else m.vertices
        assert triangles(got.vertices, got.faces) == triangles(want, m.faces)
        assert got.volume == pytest.approx(m.volume, rel=1e-6)
    else:
        np.testing.assert_array_equal(got.vertices, m.vertices)
        np.testing.assert_array_equal(got.faces, m.faces)
        assert got.volume == m.volume


def test_write_mesh_refuses_unknown_extension_and_encoding(tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="cannot tell the mesh format"):
        cp.io.write_mesh(tmp_path / "mesh.foo", mesh())
    with pytest.raises(InvalidInputError, match="STL cannot be written as binary_big_endian"):
        cp.io.write_mesh(tmp_path / "mesh.stl", mesh(), encoding="binary_big_endian")
    with pytest.raises(InvalidInputError, match="OBJ has a single encoding"):
        cp.io.write_mesh(tmp_path / "mesh.obj", mesh(), encoding="binary")


# ----------------------------------------------------------- independent readers


@pytest.mark.parametrize(
    "case", [c for c in CLOUD_CASES if c[0] in ("ply", "pcd", "xyz")], ids=case_id
)
def test_open3d_reads_what_cloudprox_writes(tmp_path: Path, case: tuple[str, str | None]) -> None:
    o3d = pytest.importorskip("open3d")
    ext, encoding = case
    pts = points()
    path = tmp_path / f"cloud.{ext}"
    write_cloud(path, pts, encoding)
    got = np.asarray(o3d.io.read_point_cloud(str(path)).points)
    if ext == "pcd" and encoding != "ascii":
        np.testing.assert_array_equal(got, f32(pts))
    elif ext == "pcd":  # Open3D parses the float32 decimals as doubles
        np.testing.assert_allclose(got, pts, rtol=2.0**-23, atol=0.0)
    else:
        np.testing.assert_array_equal(got, pts)


@pytest.mark.parametrize(
    ("name", "kwargs"),
    [
        ("ascii.ply", {"write_ascii": True}),
        ("binary.ply", {}),
        ("ascii.pcd", {"write_ascii": True}),
        ("binary.pcd", {}),
        ("compressed.pcd", {"compressed": True}),
        ("cloud.xyz", {}),
    ],
)
def test_cloudprox_reads_what_open3d_writes(
    tmp_path: Path, name: str, kwargs: dict[str, bool]
) -> None:
    o3d = pytest.importorskip("open3d")
    pts = points()
    nrm = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    pcd.normals = o3d.utility.Vector3dVector(nrm)
    path = tmp_path / name
    assert o3d.io.write_point_cloud(str(path), pcd, **kwargs)
    got = cp.io.read_point_cloud(path)
    assert len(got) == len(pts)
    if name.endswith(".pcd"):
        # Open3D writes float32 (ascii: with enough digits to read back the float32).
        np.testing.assert_array_equal(got.points, f32(pts))
        assert got.normals is not None
        np.testing.assert_array_equal(got.normals, f32(nrm))
        assert got.fields == ["x", "y", "z", "normal_x", "normal_y", "normal_z"]
        # Open3D writes the identity VIEWPOINT: PCL's default, the origin.
        assert got.sensor_pose_is_default
        np.testing.assert_array_equal(got.sensor_pose, np.eye(4))
    elif name == "binary.ply":
        np.testing.assert_array_equal(got.points, pts)
        assert got.normals is not None
        np.testing.assert_array_equal(got.normals, nrm)
    elif name == "ascii.ply":  # Open3D writes 6 significant digits: compare with the text
        body = path.read_text().split("end_header\n", 1)[1]
        table = np.loadtxt(body.splitlines(), ndmin=2)
        np.testing.assert_allclose(table[:, :3], pts, atol=5e-6)
        np.testing.assert_array_equal(got.points, table[:, :3])
        assert got.normals is not None
        np.testing.assert_array_equal(got.normals, table[:, 3:6])
    else:  # Open3D writes 10 decimals: compare with the text
        table = np.loadtxt(path, ndmin=2)
        np.testing.assert_allclose(table, pts, rtol=0.0, atol=1e-10)
        np.testing.assert_array_equal(got.points, table)


@pytest.mark.parametrize("case", MESH_CASES, ids=case_id)
def test_open3d_reads_cloudprox_meshes(tmp_path: Path, case: tuple[str, str | None]) -> None:
    o3d = pytest.importorskip("open3d")
    ext, encoding = case
    m = mesh()
    path = tmp_path / f"mesh.{ext}"
    cp.io.write_mesh(path, m, encoding=encoding)  # type: ignore[arg-type]
    tm = o3d.io.read_triangle_mesh(str(path))
    verts, faces = np.asarray(tm.vertices), np.asarray(tm.triangles)
    assert len(faces) == len(m.faces)
    # Open3D reads STL, OBJ and OFF coordinates as float32; binary STL stores float32.
    exact = ext == "ply"
    want = m.vertices if exact else f32(m.vertices)
    got_tris = np.array(triangles(verts, faces))
    want_tris = np.array(triangles(want, m.faces))
    np.testing.assert_allclose(got_tris, want_tris, rtol=0.0, atol=0.0 if exact else 1e-7)
    assert signed_volume(verts, faces) == pytest.approx(m.volume, rel=1e-6)


@pytest.mark.parametrize("ext", ["stl", "obj", "ply", "off"])
def test_cloudprox_reads_open3d_meshes(tmp_path: Path, ext: str) -> None:
    o3d = pytest.importorskip("open3d")
    tm = o3d.geometry.TriangleMesh.create_box(0.1, 0.2, 0.3)
    tm.translate((0.01, -0.02, 0.03))
    tm.compute_triangle_normals()
    tm.compute_vertex_normals()
    path = tmp_path / f"box.{ext}"
    assert o3d.io.write_triangle_mesh(str(path), tm)
    got = cp.io.read_mesh(path)
    verts, faces = np.asarray(tm.vertices), np.asarray(tm.triangles)
    assert len(got.faces) == 12
    assert len(got.vertices) == 8
    assert got.is_closed
    assert got.volume == pytest.approx(0.006, rel=1e-6)
    np.testing.assert_allclose(
        np.array(triangles(got.vertices, got.faces)),
        np.array(triangles(verts, faces)),
        atol=1e-7,
    )


@pytest.mark.parametrize(
    ("array_", "version"),
    [
        (points(), None),
        (points().astype(np.float32), None),
        (np.asfortranarray(points()), None),
        (points().astype(">f8"), None),
        (points().astype(">f4"), (2, 0)),
        (np.hstack([points(), np.ones((60, 2))]), (3, 0)),
    ],
    ids=["f8", "f4", "fortran", "big-endian-f8", "big-endian-f4-v2", "5-columns-v3"],
)
def test_npy_written_by_numpy(
    tmp_path: Path, array_: np.ndarray, version: tuple[int, int] | None
) -> None:
    path = tmp_path / "cloud.npy"
    if version is None:
        np.save(path, array_)
    else:
        with path.open("wb") as fh:
            np.lib.format.write_array(fh, array_, version=version)
    got = cp.io.read_point_cloud(path)
    np.testing.assert_array_equal(got.points, np.asarray(array_[:, :3], dtype=np.float64))
    extra = [f"col{i}" for i in range(3, array_.shape[1])]
    assert got.fields == ["x", "y", "z", *extra]


def test_numpy_reads_cloudprox_npy(tmp_path: Path, noisy: cp.PointCloud) -> None:
    path = tmp_path / "cloud.npy"
    cp.io.write_point_cloud(path, noisy)
    loaded = np.load(path)
    assert loaded.dtype == np.dtype("<f8")
    assert loaded.flags.c_contiguous
    np.testing.assert_array_equal(loaded, noisy.points)
    # The data starts at a multiple of 64 bytes (header padding).
    assert (path.stat().st_size - loaded.nbytes) % 64 == 0


@pytest.mark.parametrize(
    ("array_", "pattern"),
    [
        (np.zeros((4, 3), dtype=np.int64), "unsupported dtype '<i8'"),
        (np.zeros((4, 2)), r"shape \(4, 2\) has fewer than 3 columns"),
        (np.zeros(12), r"is not 2-D"),
        (np.zeros(4, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8")]), "dtype"),
    ],
    ids=["int", "2-columns", "1-D", "structured"],
)
def test_npy_refused(tmp_path: Path, array_: np.ndarray, pattern: str) -> None:
    path = tmp_path / "bad.npy"
    np.save(path, array_)
    with pytest.raises(FormatError, match=pattern) as exc:
        cp.io.read_point_cloud(path)
    assert str(path) in str(exc.value)


@pytest.mark.parametrize("ext", ["las", "laz"])
def test_las_written_by_laspy(tmp_path: Path, ext: str) -> None:
    laspy = pytest.importorskip("laspy")
    if ext == "laz" and not laspy.LazBackend.detect_available():
        pytest.skip("laspy has no LAZ backend")
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales = [0.001, 0.001, 0.0005]
    header.offsets = [512000.0, 5400000.0, 100.0]
    las = laspy.LasData(header)
    rng = np.random.default_rng(7)
    las.x = 512000.0 + rng.uniform(0.0, 50.0, 200)
    las.y = 5400000.0 + rng.uniform(0.0, 50.0, 200)
    las.z = 100.0 + rng.uniform(0.0, 5.0, 200)
    path = tmp_path / f"cloud.{ext}"
    las.write(str(path))
    back = laspy.read(str(path))
    got = cp.io.read_point_cloud(path)
    want = np.column_stack([back.x, back.y, back.z])
    np.testing.assert_array_equal(got.points, want)
    assert got.fields[:4] == ["x", "y", "z", "intensity"]
    assert {"gps_time", "red", "green", "blue"} <= set(got.fields)
    # Every coordinate lies on the file's integer grid.
    steps = (got.points - header.offsets) / header.scales
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)
    data = path.read_bytes()
    for cut in (0, 4, 100, 227, len(data) // 2, len(data) - 1):
        bad = tmp_path / f"cut{cut}.{ext}"
        bad.write_bytes(data[:cut])
        with pytest.raises(FormatError) as exc:
            cp.io.read_point_cloud(bad)
        assert str(bad) in str(exc.value)


# -------------------------------------------------------------- CloudFile fields

ORGANIZED_PCD = """\
# .PCD v0.7 - Point Cloud Data file format
VERSION 0.7
FIELDS x y z intensity
SIZE 4 4 4 4
TYPE F F F F
COUNT 1 1 1 1
WIDTH 3
HEIGHT 2
VIEWPOINT 0.1 0.2 -0.5 0.70710678 0 0 0.70710678
POINTS 6
DATA ascii
0 0 1 5
nan nan nan 0
0.2 0 1 7
0 0.1 1.5 1
0.1 nan 1 2
0.2 0.1 inf 3
"""
# VIEWPOINT tx ty tz qw qx qy qz: a turn of 90 degrees about z, then the translation.
ORGANIZED_POSE = np.array(
    [[0.0, -1.0, 0.0, 0.1], [1.0, 0.0, 0.0, 0.2], [0.0, 0.0, 1.0, -0.5], [0.0, 0.0, 0.0, 1.0]]
)


def test_organized_pcd_with_holes_and_viewpoint(tmp_path: Path) -> None:
    path = tmp_path / "organized.pcd"
    path.write_text(ORGANIZED_PCD)
    cf = cp.io.read_point_cloud(path)
    # F4 values are float32 in ascii data too.
    np.testing.assert_array_equal(cf.points, f32([[0, 0, 1], [0.2, 0, 1], [0, 0.1, 1.5]]))
    assert cf.grid_shape == (2, 3)
    assert cf.pixels is not None
    np.testing.assert_array_equal(cf.pixels, [0, 2, 3])
    assert cf.skipped == 3
    assert cf.fields == ["x", "y", "z", "intensity"]
    assert cf.normals is None
    assert cf.covariances is None
    assert cf.sensor_pose is not None
    np.testing.assert_allclose(cf.sensor_pose, ORGANIZED_POSE, atol=1e-7)

    # The sensor model is seen from the file's VIEWPOINT.
    cam = cp.DepthCamera()
    cloud = cf.to_point_cloud(sensor=cam, discretization=False)
    want = cam.covariances(cf.points, sensor_pose=cf.sensor_pose)
    np.testing.assert_array_equal(cloud.covariances, want)
    # ... which is not the same as a sensor at the origin.
    at_origin = cf.to_point_cloud(sensor=cam, origin=[0.0, 0.0, 0.0], discretization=False)
    assert np.abs(at_origin.covariances - want).max() > 1e-9
    with_disc = cf.to_point_cloud(sensor=cam)
    np.testing.assert_array_equal(with_disc.sensor_covariances, want)

    # Written back, the grid is kept with NaN records for the holes (as PCL writes them).
    for encoding in ("ascii", "binary", "binary_compressed"):
        out = tmp_path / f"out-{encoding}.pcd"
        cp.io.write_point_cloud(out, cf, encoding=encoding)
        assert b"\nWIDTH 3\nHEIGHT 2\n" in out.read_bytes()
        assert b"\nPOINTS 6\n" in out.read_bytes()
        again = cp.io.read_point_cloud(out)
        np.testing.assert_array_equal(again.points, cf.points)
        assert again.grid_shape == (2, 3)
        assert again.pixels is not None
        np.testing.assert_array_equal(again.pixels, cf.pixels)
        assert again.skipped == 3
        assert again.sensor_pose is not None
        np.testing.assert_allclose(again.sensor_pose, cf.sensor_pose, atol=1e-12)


def test_cloudfile_made_for_writing(tmp_path: Path) -> None:
    pose = from_rpy((0.0, 0.0, np.pi / 2), (0.1, 0.2, 0.3))
    pts = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 2.0]])
    cf = cp.io.CloudFile(pts, sensor_pose=pose, grid_shape=(2, 2), pixels=[0, 1, 3])
    assert cf.skipped == 0
    assert cf.grid_shape == (2, 2)
    path = tmp_path / "made.pcd"
    cp.io.write_point_cloud(path, cf)
    got = cp.io.read_point_cloud(path)
    np.testing.assert_array_equal(got.points, pts)
    assert got.pixels is not None
    np.testing.assert_array_equal(got.pixels, [0, 1, 3])
    assert got.skipped == 1
    assert got.sensor_pose is not None
    np.testing.assert_allclose(got.sensor_pose, pose, atol=1e-12)
    with pytest.raises(InvalidInputError, match=r"pixels\[1\] = 2 is outside the 1x2 grid"):
        cp.io.CloudFile(pts[:2], grid_shape=(1, 2), pixels=[0, 2])
    with pytest.raises(InvalidInputError, match="strictly increasing"):
        cp.io.CloudFile(pts[:2], grid_shape=(1, 2), pixels=[1, 0])
    with pytest.raises(InvalidInputError, match="give both grid_shape and pixels"):
        cp.io.CloudFile(pts[:2], pixels=[0, 1])


@pytest.mark.parametrize(
    "viewpoint", ["VIEWPOINT 0 0 0 1 0 0 0\n", ""], ids=["identity-viewpoint", "no-viewpoint"]
)
def test_default_viewpoint_is_the_sensor_at_the_origin(
    tmp_path: Path, viewpoint: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # A raw sensor frame (a VLP-16 scan, a depth image) is written with PCL's
    # default VIEWPOINT, or none: the sensor at the origin, as PCL reads it.
    path = tmp_path / "plain.pcd"
    path.write_text(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
        f"{viewpoint}POINTS 2\nDATA ascii\n0 0 1\n0.5 0 2\n"
    )
    cf = cp.io.read_point_cloud(path)
    assert cf.sensor_pose_is_default
    np.testing.assert_array_equal(cf.sensor_pose, np.eye(4))
    cam = cp.Lidar()
    cloud = cf.to_point_cloud(sensor=cam, discretization=False)
    np.testing.assert_array_equal(cloud.covariances, cam.covariances(cf.points, [0.0, 0.0, 0.0]))
    # `cloudprox info` says the pose is the format's default.
    from cloudprox.cli import main

    assert main(["info", str(path)]) == 0
    assert "the PCD default VIEWPOINT" in capsys.readouterr().out


def test_sensor_without_viewpoint(tmp_path: Path) -> None:
    path = tmp_path / "plain.xyz"
    path.write_text("0 0 1\n0.5 0 2\n")
    cf = cp.io.read_point_cloud(path)
    assert cf.sensor_pose is None and not cf.sensor_pose_is_default
    with pytest.raises(InvalidInputError, match="records no sensor viewpoint") as exc:
        cf.to_point_cloud(sensor=cp.DepthCamera())
    assert str(path) in str(exc.value)
    cam = cp.Lidar()
    cloud = cf.to_point_cloud(sensor=cam, origin=[0.0, 0.0, 0.0], discretization=False)
    np.testing.assert_array_equal(cloud.covariances, cam.covariances(cf.points, [0.0, 0.0, 0.0]))


# ----------------------------------------------------------------------- errors


def test_missing_file(tmp_path: Path) -> None:
    for reader, name in ((cp.io.read_point_cloud, "missing.ply"), (cp.io.read_mesh, "gone.stl")):
        path = tmp_path / name
        with pytest.raises(FileNotFoundError) as exc:
            reader(path)
        assert str(path) in str(exc.value)


@pytest.mark.parametrize("name", ["cloud.foo", "cloud", "cloud.ply.bak"])
def test_unknown_extension(tmp_path: Path, name: str) -> None:
    path = tmp_path / name
    path.write_text("1 2 3\n")
    with pytest.raises(InvalidInputError, match="cannot tell the point cloud format") as exc:
        cp.io.read_point_cloud(path)
    assert str(path) in str(exc.value)
    with pytest.raises(InvalidInputError, match="cannot tell the mesh format"):
        cp.io.read_mesh(path)


def header_end(data: bytes, ext: str) -> int:
    """Offset where a text file's body starts (0 when it has no header)."""
    marks = {"ply": b"end_header\n", "pcd": b"\nDATA ascii\n", "csv": b"\n"}
    mark = marks.get(ext)
    if mark is None:
        return 0
    return data.index(mark) + len(mark)


def mid_row_cuts(data: bytes, start: int, rows: int = 4) -> list[int]:
    """Cuts just after the first delimiter of some body lines: a row left with one value."""
    lines_at = [start]
    while (nl := data.find(b"\n", lines_at[-1])) != -1 and nl + 1 < len(data):
        lines_at.append(nl + 1)
    picks = np.linspace(0, len(lines_at) - 1, rows).round().astype(int)
    cuts = []
    for k in sorted(set(picks.tolist())):
        line = data[lines_at[k] :].split(b"\n", 1)[0]
        first = min(i for i in (line.find(b" ", 1), line.find(b",", 1)) if i > 0)
        cuts.append(lines_at[k] + first + 1)
    return cuts


def cut_points(data: bytes, ext: str, binary: bool) -> list[int]:
    """Where a truncation must be detected.

    A binary body has a size the header fixes, so every cut is. A text file cut at a
    line end (or inside the last number) can be a valid shorter file, so there the
    cuts are in the header and in the middle of rows.
    """
    if binary:
        return sorted({0, 1, *np.linspace(2, len(data) - 1, 25).astype(int).tolist()})
    start = header_end(data, ext)
    head = np.linspace(1, start - 1, 8).astype(int).tolist() if ext in ("ply", "pcd") else []
    return sorted({*head, *mid_row_cuts(data, start)})


@pytest.mark.parametrize("case", CLOUD_CASES, ids=case_id)
def test_truncated_cloud_files(tmp_path: Path, case: tuple[str, str | None]) -> None:
    ext, encoding = case
    data = write_cloud(tmp_path / f"whole.{ext}", cp.PointCloud(points(), sigma=0.01), encoding)
    binary = ext == "npy" or encoding in ("binary", "binary_big_endian", "binary_compressed")
    cuts = cut_points(data, ext, binary)
    assert len(cuts) >= 4
    for cut in cuts:
        path = tmp_path / f"cut{cut}.{ext}"
        path.write_bytes(data[:cut])
        with pytest.raises(FormatError) as exc:
            cp.io.read_point_cloud(path)
        assert str(path) in str(exc.value), f"cut at {cut}"


@pytest.mark.parametrize("case", MESH_CASES, ids=case_id)
def test_truncated_mesh_files(tmp_path: Path, case: tuple[str, str | None]) -> None:
    ext, encoding = case
    path = tmp_path / f"whole.{ext}"
    cp.io.write_mesh(path, mesh(), encoding=encoding)  # type: ignore[arg-type]
    data = path.read_bytes()
    if ext == "stl" and encoding == "ascii":  # anything before 'endsolid' is incomplete
        cuts = np.linspace(0, data.rindex(b"endsolid") - 1, 30).astype(int).tolist()
    elif ext in ("obj", "off"):
        cuts = mid_row_cuts(data, data.index(b"\n") + 1, rows=8)
        if ext == "off":
            cuts += [1, 3, 5, 9]  # inside the 'OFF' line and the counts line
    else:
        cuts = cut_points(data, ext, binary=encoding != "ascii")
    for cut in cuts:
        bad = tmp_path / f"cut{cut}.{ext}"
        bad.write_bytes(data[:cut])
        with pytest.raises(FormatError) as exc:
            cp.io.read_mesh(bad)
        assert str(bad) in str(exc.value), f"cut at {cut}"


CLOUD_EXTS = ["ply", "pcd", "xyz", "csv", "npy", "las", "laz"]
MESH_EXTS = ["stl", "obj", "ply", "off"]


@pytest.mark.parametrize("seed", [0, 1])
def test_garbage_bytes(tmp_path: Path, seed: int) -> None:
    rng = np.random.default_rng(seed)
    garbage = rng.integers(0, 256, 3000, dtype=np.uint8).tobytes()
    for ext in CLOUD_EXTS:
        path = tmp_path / f"garbage.{ext}"
        path.write_bytes(garbage)
        with pytest.raises(FormatError) as exc:
            cp.io.read_point_cloud(path)
        assert str(path) in str(exc.value)
    for ext in MESH_EXTS:
        path = tmp_path / f"garbage_mesh.{ext}"
        path.write_bytes(garbage)
        with pytest.raises(FormatError) as exc:
            cp.io.read_mesh(path)
        assert str(path) in str(exc.value)


def replace(old: bytes, new: bytes) -> Callable[[bytes], bytes]:
    def edit(data: bytes) -> bytes:
        assert old in data
        return data.replace(old, new, 1)

    return edit


def set_u32(offset: int, value: int) -> Callable[[bytes], bytes]:
    return lambda data: data[:offset] + struct.pack("<I", value) + data[offset + 4 :]


def pcd_compressed_sizes(delta_c: int, delta_u: int) -> Callable[[bytes], bytes]:
    def edit(data: bytes) -> bytes:
        at = data.index(b"DATA binary_compressed\n") + len(b"DATA binary_compressed\n")
        c, u = struct.unpack_from("<II", data, at)
        return data[:at] + struct.pack("<II", c + delta_c, u + delta_u) + data[at + 8 :]

    return edit


def pcd_lzf_garbage(data: bytes) -> bytes:
    at = data.index(b"DATA binary_compressed\n") + len(b"DATA binary_compressed\n") + 8
    return data[:at] + b"\xff" * 40 + data[at + 40 :]


# (extension, encoding, edit of a valid file, pattern of the message)
WRONG_HEADERS: list[tuple[str, str | None, Callable[[bytes], bytes], str]] = [
    ("ply", "binary", replace(b"vertex 60", b"vertex 61"), r"truncated"),
    ("ply", "binary", replace(b"binary_little_endian", b"binary_middle_endian"), "unknown format"),
    ("ply", "binary", replace(b" 1.0\n", b" 2.0\n"), "unsupported version '2.0'"),
    ("ply", "binary", replace(b"double x", b"quad x"), "unknown property type 'quad'"),
    ("ply", "ascii", replace(b"property double z\n", b""), "no property 'z'"),
    ("ply", "ascii", replace(b"vertex 60", b"vertex -1"), "element <name> <count>"),
    ("ply", "ascii", replace(b"end_header\n", b"end_header\nabc "), "found 'abc'"),
    ("pcd", "binary", replace(b"POINTS 60", b"POINTS 59"), "POINTS 59 is not WIDTH 60"),
    ("pcd", "binary", replace(b"WIDTH 60", b"WIDTH 61"), "POINTS 60 is not WIDTH 61"),
    ("pcd", "binary", replace(b"DATA binary", b"DATA binaryx"), "unknown DATA 'binaryx'"),
    ("pcd", "binary", replace(b"SIZE 4 4 4", b"SIZE 3 4 4"), "TYPE F with SIZE 3"),
    ("pcd", "binary", replace(b"TYPE F F F", b"TYPE Q F F"), "TYPE must be F, I or U"),
    ("pcd", "ascii", replace(b"FIELDS x y z", b"FIELDS x y w"), "no field 'z'"),
    ("pcd", "ascii", replace(b"DATA ascii\n", b"DATA ascii\n0 0 x "), "value 'x' is not a number"),
    ("pcd", "binary_compressed", pcd_compressed_sizes(0, 4), "uncompressed size"),
    ("pcd", "binary_compressed", pcd_compressed_sizes(1, 0), "compressed size"),
    ("pcd", "binary_compressed", pcd_lzf_garbage, "LZF"),
    ("npy", None, replace(b"(60, 3)", b"(61, 3)"), "truncated"),
    ("npy", None, replace(b"\x93NUMPY\x01", b"\x93NUMPY\x09"), "unsupported NPY version"),
    ("npy", None, replace(b"{'descr'", b"['descr'"), "header dict"),
    ("xyz", None, replace(b"\n", b"\n1 a 2\n"), "'a' is not a number"),
    ("csv", None, replace(b"x,y,z", b"a,y,z"), "no 'x'"),
    ("csv", None, replace(b"\n", b"\n1,,3\n"), "'' is not a number"),
]


@pytest.mark.parametrize(
    ("ext", "encoding", "edit", "pattern"),
    WRONG_HEADERS,
    ids=[f"{e}-{n}" for n, (e, *_) in enumerate(WRONG_HEADERS)],
)
def test_wrong_header_values(
    tmp_path: Path,
    ext: str,
    encoding: str | None,
    edit: Callable[[bytes], bytes],
    pattern: str,
) -> None:
    data = write_cloud(tmp_path / f"whole.{ext}", points(), encoding)
    path = tmp_path / f"bad.{ext}"
    path.write_bytes(edit(data))
    with pytest.raises(FormatError, match=pattern) as exc:
        cp.io.read_point_cloud(path)
    assert str(path) in str(exc.value)


WRONG_MESHES: list[tuple[str, str | None, Callable[[bytes], bytes], str]] = [
    ("stl", "binary", set_u32(80, 49), "promises 49 triangles"),
    ("stl", "binary", set_u32(80, 47), "promises 47 triangles"),
    ("stl", "binary", lambda d: d + b"\0" * 50, "more"),
    ("stl", "ascii", replace(b"endloop", b"endlop"), "endloop"),
    ("stl", "ascii", replace(b"vertex ", b"vertex x"), "expected a number in vertex 1"),
    ("off", None, replace(b"OFF\n26 48 0", b"OFF\n27 48 0"), "promises 48 faces"),
    ("off", None, replace(b"OFF\n26 48 0", b"OFF\n26 47 0"), "after the 47 faces"),
    ("off", None, replace(b"\n3 ", b"\n4 "), "announces 4 vertices"),
    ("off", None, replace(b"\n3 0 ", b"\n3 26 "), "index 26 out of range"),
    ("off", None, replace(b"OFF\n", b"4OFF\n"), 'unsupported OFF variant "4OFF"'),
    ("obj", None, replace(b"\nf 1 ", b"\nf 99 "), "index 99 out of range"),
    ("obj", None, replace(b"\nf 1 ", b"\nf 0 "), "indices start at 1"),
    ("obj", None, replace(b"\nv ", b"\nv 1.x "), 'malformed number "1.x"'),
    ("obj", None, lambda d: d + b"surf 0 1 0 1 1 2 3\n", "free-form surfaces"),
    ("ply", "ascii", replace(b"\n3 0 ", b"\n3 99 "), "refers to vertex 99"),
    ("ply", "binary", replace(b"element face 48", b"element face 49"), "truncated"),
]


@pytest.mark.parametrize(
    ("ext", "encoding", "edit", "pattern"),
    WRONG_MESHES,
    ids=[f"{e}-{n}" for n, (e, *_) in enumerate(WRONG_MESHES)],
)
def test_wrong_mesh_values(
    tmp_path: Path,
    ext: str,
    encoding: str | None,
    edit: Callable[[bytes], bytes],
    pattern: str,
) -> None:
    whole = tmp_path / f"whole.{ext}"
    cp.io.write_mesh(whole, mesh(), encoding=encoding)  # type: ignore[arg-type]
    path = tmp_path / f"bad.{ext}"
    path.write_bytes(edit(whole.read_bytes()))
    with pytest.raises(FormatError, match=re.escape(pattern)) as exc:
        cp.io.read_mesh(path)
    assert str(path) in str(exc.value)


TETRA = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]


def stl_ascii(tris: list[tuple[str, str, str]]) -> str:
    body = "".join(
        "facet normal 0 0 0\n outer loop\n"
        + "".join(f"  vertex {v}\n" for v in tri)
        + " endloop\nendfacet\n"
        for tri in tris
    )
    return f"solid t\n{body}endsolid t\n"


def stl_binary(tris: list[tuple[tuple[float, ...], ...]]) -> bytes:
    out = bytearray(b"\0" * 80) + struct.pack("<I", len(tris))
    for tri in tris:
        out += struct.pack("<3f", 0, 0, 0) + struct.pack("<9f", *np.ravel(tri)) + b"\0\0"
    return bytes(out)


DEGENERATE: list[tuple[str, str | bytes, int, int]] = [
    (
        "obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
        "f 1 3 2\nf 1 2 4\nf 1 1 2\nf 2 3 3\nf 1 4 3\nf 2 3 4\nf -4 -3 -3\n",
        3,
        4,
    ),
    ("obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 2 3 4\n", 1, 2),
    ("off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 0 1\n4 0 1 3 3\n3 1 1 1\n", 3, 2),
    (
        "ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 3\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 0 1\n3 1 2 3\n",
        1,
        2,
    ),
    # Welding makes -0 equal to 0, so the second facet repeats a corner.
    ("stl", stl_ascii([("0 0 0", "0 1 0", "1 0 0"), ("0 0 0", "1 0 0", "-0 0 0")]), 1, 1),
    (
        "stl",
        stl_binary([(TETRA[0], TETRA[2], TETRA[1]), (TETRA[1], TETRA[1], TETRA[3])] * 2),
        2,
        2,
    ),
]


@pytest.mark.parametrize(
    ("ext", "content", "dropped", "kept"),
    DEGENERATE,
    ids=["obj", "obj-polygon", "off", "ply", "stl-ascii", "stl-binary"],
)
def test_degenerate_faces_warn_with_their_count(
    tmp_path: Path, ext: str, content: str | bytes, dropped: int, kept: int
) -> None:
    path = tmp_path / f"degenerate.{ext}"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    with pytest.warns(DegenerateFacesWarning) as record:
        got = cp.io.read_mesh(path)
    assert len(record) == 1
    message = str(record[0].message)
    assert message.startswith(str(path))
    assert f"dropped {dropped} degenerate face(s)" in message
    assert record[0].filename == __file__  # attributed to the caller of read_mesh
    assert len(got.faces) == kept
    assert np.all(np.diff(np.sort(got.faces, axis=1), axis=1) > 0)  # no repeated corner
    assert issubclass(DegenerateFacesWarning, UserWarning)
    assert cp.io.DegenerateFacesWarning is cp.exceptions.DegenerateFacesWarning


def test_mesh_of_only_degenerate_faces_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "flat.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nf 1 2 2\nf 1 1 1\n")
    with pytest.raises(FormatError, match="all 2 triangles repeat a vertex") as exc:
        cp.io.read_mesh(path)
    assert str(path) in str(exc.value)


# ------------------------------------------------------------------ PointCloud2

F32 = 7
PC2_FIELDS = [("x", 0, F32, 1), ("y", 4, F32, 1), ("z", 8, F32, 1), ("intensity", 16, F32, 1)]
PC2_H, PC2_W, PC2_STEP, PC2_ROW = 2, 3, 32, 3 * 32 + 8  # padded points and rows
PC2_GRID = np.array(
    [
        [[0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [1.0, 0.0, 1.0]],
        [[0.0, 0.5, 2.0], [np.nan, np.nan, np.nan], [1.0, 0.5, 2.0]],
    ]
)


def organized_message(big_endian: bool) -> bytes:
    """The 3x2 cloud: x y z at 0, padding, intensity at 16, padding; 0xAB in the padding."""
    e = ">" if big_endian else "<"
    buf = bytearray(b"\xab" * (PC2_ROW * PC2_H))
    for r in range(PC2_H):
        for c in range(PC2_W):
            at = r * PC2_ROW + c * PC2_STEP
            struct.pack_into(f"{e}3f", buf, at, *PC2_GRID[r, c])
            struct.pack_into(f"{e}f", buf, at + 16, 10.0 * (r * PC2_W + c))
    return bytes(buf)


def read_organized(data: bytes, fields: Any = PC2_FIELDS, **layout: Any) -> cp.io.CloudFile:
    kw: dict[str, Any] = {
        "height": PC2_H,
        "width": PC2_W,
        "point_step": PC2_STEP,
        "row_step": PC2_ROW,
    }
    kw.update(layout)
    return cp.io.read_pointcloud2(data, fields, **kw)


def test_pointcloud2_round_trip(noisy: cp.PointCloud) -> None:
    layout, data = cp.io.write_pointcloud2(noisy)
    n = len(noisy)
    assert layout == {
        "height": 1,
        "width": n,
        "fields": [("x", 0, F32, 1), ("y", 4, F32, 1), ("z", 8, F32, 1)],
        "is_bigendian": False,
        "point_step": 12,
        "row_step": 12 * n,
    }
    assert isinstance(data, bytes)
    # Independent decoding: little-endian float32 triples.
    np.testing.assert_array_equal(
        np.frombuffer(data, dtype="<f4").reshape(n, 3), noisy.points.astype(np.float32)
    )
    got = cp.io.read_pointcloud2(
        data, layout["fields"], height=1, width=n, point_step=12, row_step=12 * n
    )
    np.testing.assert_array_equal(got.points, f32(noisy.points))
    assert got.grid_shape is None
    assert got.skipped == 0


def test_pointcloud2_round_trip_with_normals(tmp_path: Path) -> None:
    path = tmp_path / "normals.ply"
    path.write_text(
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
        "property double z\nproperty float nx\nproperty float ny\nproperty float nz\n"
        "end_header\n0.1 0.2 0.3 0 0 1\n-1 2.5 3 0.6 0.8 0\n"
    )
    cf = cp.io.read_point_cloud(path)
    layout, data = cp.io.write_pointcloud2(cf)
    assert [f[0] for f in layout["fields"]] == ["x", "y", "z", "normal_x", "normal_y", "normal_z"]
    assert layout["point_step"] == 24
    got = cp.io.read_pointcloud2(
        data, layout["fields"], height=1, width=2, point_step=24, row_step=48
    )
    np.testing.assert_array_equal(got.points, f32([[0.1, 0.2, 0.3], [-1, 2.5, 3]]))
    assert got.normals is not None
    np.testing.assert_array_equal(got.normals, f32([[0, 0, 1], [0.6, 0.8, 0]]))


@pytest.mark.parametrize("big_endian", [False, True], ids=["little-endian", "big-endian"])
def test_pointcloud2_organized_with_padding_and_a_hole(big_endian: bool) -> None:
    got = read_organized(organized_message(big_endian), is_bigendian=big_endian)
    np.testing.assert_array_equal(
        got.points, [[0, 0, 1], [0.5, 0, 1], [1, 0, 1], [0, 0.5, 2], [1, 0.5, 2]]
    )
    assert got.grid_shape == (2, 3)
    assert got.pixels is not None
    np.testing.assert_array_equal(got.pixels, [0, 1, 2, 3, 5])
    assert got.skipped == 1
    assert got.fields == ["x", "y", "z", "intensity"]
    assert got.normals is None


def test_pointcloud2_wrong_endianness_is_not_the_cloud() -> None:
    got = read_organized(organized_message(True), is_bigendian=False)
    assert not np.array_equal(got.points[:1], [[0.0, 0.0, 1.0]])


def test_pointcloud2_float64_and_integer_fields() -> None:
    # x float64, y int16, z uint8 (datatypes 8, 3, 2), point_step 11.
    rows = [(0.25, -3, 7), (1e-3, 300, 255)]
    data = b"".join(struct.pack("<dhB", *r) for r in rows)
    got = cp.io.read_pointcloud2(
        data,
        [("x", 0, 8, 1), ("y", 8, 3, 1), ("z", 10, 2, 1)],
        height=1,
        width=2,
        point_step=11,
        row_step=22,
    )
    np.testing.assert_array_equal(got.points, np.array(rows, dtype=np.float64))


@pytest.mark.parametrize(
    "as_data", [lambda b: array.array("B", b), list, bytearray], ids=["array", "list", "bytearray"]
)
def test_from_ros_message(as_data: Callable[[bytes], Any]) -> None:
    msg = SimpleNamespace(
        header=SimpleNamespace(frame_id="camera_depth_optical_frame"),
        height=PC2_H,
        width=PC2_W,
        fields=[
            SimpleNamespace(name=n, offset=o, datatype=d, count=c) for n, o, d, c in PC2_FIELDS
        ],
        is_bigendian=False,
        point_step=PC2_STEP,
        row_step=PC2_ROW,
        data=as_data(organized_message(False)),
        is_dense=False,
    )
    got = cp.io.from_ros_message(msg)
    assert got.grid_shape == (2, 3)
    assert got.pixels is not None
    np.testing.assert_array_equal(got.pixels, [0, 1, 2, 3, 5])
    np.testing.assert_array_equal(got.points[4], [1.0, 0.5, 2.0])
    assert got.skipped == 1


@pytest.mark.parametrize(
    ("data", "fields", "layout", "pattern"),
    [
        (-1, PC2_FIELDS, {}, r"truncated: row_step 104 x height 2 bytes needed, data has 207"),
        (
            0,
            [*PC2_FIELDS[:3], ("intensity", 30, F32, 1)],
            {},
            r"'intensity' \(offset 30.*past point_step 32",
        ),
        (0, [("x", 28, 8, 1), *PC2_FIELDS[1:]], {}, r"'x' \(offset 28, 1 x 8 bytes\) reaches past"),
        (0, [*PC2_FIELDS[:3], ("intensity", 16, 9, 1)], {}, r"'intensity' has unknown datatype 9"),
        (0, [("x", 0, 0, 1), *PC2_FIELDS[1:]], {}, r"'x' has unknown datatype 0"),
        (0, PC2_FIELDS[1:], {}, r"no field 'x'"),
        (0, PC2_FIELDS[:2], {}, r"no field 'z'"),
        (0, PC2_FIELDS, {"row_step": 64}, r"point_step 32 x width 3 is more than row_step 64"),
        (0, PC2_FIELDS, {"point_step": 0}, r"past point_step 0"),
    ],
    ids=[
        "short-data",
        "field-past-step",
        "f64-past-step",
        "datatype-9",
        "datatype-0",
        "no-x",
        "no-z",
        "row-step-small",
        "point-step-0",
    ],
)
def test_pointcloud2_bad_layouts(
    data: int, fields: Any, layout: dict[str, int], pattern: str
) -> None:
    msg = organized_message(False)
    with pytest.raises(FormatError, match=pattern):
        read_organized(msg[: len(msg) + data] if data else msg, fields, **layout)


def test_pointcloud2_malformed_field_tuples() -> None:
    with pytest.raises(InvalidInputError, match=r"fields\[0\] must be \(name, offset"):
        read_organized(organized_message(False), [("x", 0, F32), *PC2_FIELDS[1:]])


# ------------------------------------------------------ no-returns, XYZ columns


def test_organized_no_returns_at_the_sensor_origin(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A raw lidar frame: the driver writes beams that returned nothing as (0, 0, 0).
    path = tmp_path / "frame.pcd"
    path.write_text(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 2\n"
        "POINTS 6\nDATA ascii\n0 0 0\n1 0 2\nnan nan nan\n0 0 0\n0.5 0.5 1\n2 -1 0.5\n"
    )
    cf = cp.io.read_point_cloud(path)
    np.testing.assert_array_equal(cf.points, [[1, 0, 2], [0.5, 0.5, 1], [2, -1, 0.5]])
    np.testing.assert_array_equal(cf.pixels, [1, 4, 5])
    assert (cf.skipped, cf.at_origin, cf.no_returns) == (1, 2, 3)
    assert "3 no-returns" in repr(cf)
    assert cf.topic is None and cf.frame_id is None and cf.stamp is None
    # The sensor model takes the frame: no point lies at its origin any more.
    cloud = cf.to_point_cloud(sensor=cp.Lidar(), discretization=False)
    assert len(cloud) == 3
    from cloudprox.cli import main

    assert main(["info", str(path), "--json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    assert (doc["skipped_non_finite"], doc["no_returns"]) == (1, 3)
    assert doc["no_returns_at_sensor_origin"] == 2
    # Written back, the no-returns become NaN records of the same layout.
    out = tmp_path / "out.pcd"
    cp.io.write_point_cloud(out, cf)
    again = cp.io.read_point_cloud(out)
    np.testing.assert_array_equal(again.pixels, [1, 4, 5])
    assert (again.skipped, again.at_origin) == (3, 0)


def unit_normals(n: int, seed: int = 0) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


@pytest.mark.parametrize(
    ("layout", "fields"),
    [
        ("x y z nx ny nz", ["x", "y", "z", "nx", "ny", "nz"]),  # CGAL kitten.xyz, Open3D .xyzn
        ("x y z r g b", ["x", "y", "z", "r", "g", "b"]),  # Open3D .xyzrgb, CloudCompare
        ("x y z r g b nx ny nz", ["x", "y", "z", "r", "g", "b", "nx", "ny", "nz"]),  # CloudCompare
        ("x y z nx ny nz r g b", ["x", "y", "z", "nx", "ny", "nz", "r", "g", "b"]),
    ],
    ids=["normals", "colours", "cloudcompare", "normals-colours"],
)
def test_xyz_six_and_nine_columns(tmp_path: Path, layout: str, fields: list[str]) -> None:
    n = 40
    pts = points(n)
    nrm = unit_normals(n)
    rgb = np.random.default_rng(1).integers(0, 256, size=(n, 3)).astype(float)
    cols = {"x y z": pts, "nx ny nz": nrm, "r g b": rgb}
    parts = [cols[" ".join(layout.split()[i : i + 3])] for i in range(0, len(fields), 3)]
    path = tmp_path / "cloud.xyz"
    np.savetxt(path, np.hstack(parts), fmt="%.6g")  # as CGAL and CloudCompare print them
    got = cp.io.read_point_cloud(path)
    assert got.fields == fields
    np.testing.assert_allclose(got.points, pts, atol=1e-5)
    if "nx" in fields:
        assert got.normals is not None
        np.testing.assert_allclose(got.normals, nrm, atol=1e-5)
    else:
        assert got.normals is None
