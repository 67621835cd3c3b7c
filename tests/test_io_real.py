"""Real files from other projects (fetched from crates.io, PyPI, Debian) read by cloudprox.

Each file of :data:`tests.realfiles.REAL_FILES` is checked against its ground truth
:data:`tests.realfiles.EXPECTED`, established with readers independent of
cloudprox. When a registry cannot be reached the test is skipped, except on CI
(``CI=true``) where it fails: CI must prove that the real files are read.

A file that exposes a reader bug is marked ``xfail(strict=True)`` in
:data:`KNOWN_BUGS` with what goes wrong, rather than weakening its checks.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_quaternion
from tests.realfiles import EXPECTED, REAL_FILES, RealFileUnavailable, real_file

#: Real files cloudprox reads wrongly: name -> precise description. None known.
KNOWN_BUGS: dict[str, str] = {}

IDENTITY_VIEWPOINT = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)


def fetch(name: str) -> Path:
    """The real file's path; skip (fail on CI) when its registry cannot be reached."""
    try:
        return real_file(name)
    except RealFileUnavailable as exc:
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI=true: the real file {name!r} must be read, but {exc}")
        pytest.skip(f"real file {name!r} unavailable: {exc}")


def cases(*formats: str) -> list[Any]:
    """The names of EXPECTED of these formats, with the xfail marks of KNOWN_BUGS."""
    out = []
    for name, truth in EXPECTED.items():
        if truth["format"] not in formats:
            continue
        marks = (
            [pytest.mark.xfail(strict=True, reason=KNOWN_BUGS[name])] if name in KNOWN_BUGS else []
        )
        out.append(pytest.param(name, marks=marks, id=name))
    return out


def assert_bounds(xyz: np.ndarray, truth: dict[str, object]) -> None:
    lo, hi = np.asarray(truth["bounds"], dtype=np.float64)
    np.testing.assert_allclose(xyz.min(axis=0), lo, rtol=0.0, atol=1e-6)
    np.testing.assert_allclose(xyz.max(axis=0), hi, rtol=0.0, atol=1e-6)


def test_every_real_file_has_its_ground_truth() -> None:
    assert set(REAL_FILES) == set(EXPECTED)
    assert {t["format"] for t in EXPECTED.values()} == {
        "pcd",
        "ply",
        "las",
        "laz",
        "stl",
        "obj",
        "off",
    }


def test_ci_policy_fails_instead_of_skipping(monkeypatch: pytest.MonkeyPatch) -> None:
    def unreachable(name: str) -> Path:
        raise RealFileUnavailable(f"no network for {name}")

    monkeypatch.setattr("tests.test_io_real.real_file", unreachable)
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="CI=true: the real file 'pcd_ascii'"):
        fetch("pcd_ascii")
    monkeypatch.setenv("CI", "false")
    with pytest.raises(pytest.skip.Exception, match="no network for pcd_ascii"):
        fetch("pcd_ascii")


@pytest.mark.parametrize("name", cases("pcd"))
def test_pcd(name: str) -> None:
    truth = EXPECTED[name]
    cf = cp.io.read_point_cloud(fetch(name))
    n_finite = int(truth["points"]) - int(truth["nonfinite"])  # type: ignore[call-overload]
    # An organized scan's points at exactly the origin are its no-returns: left out, counted.
    assert len(cf) + cf.at_origin == n_finite
    assert cf.at_origin == 0 or truth["height"] != 1
    n_kept = len(cf)
    assert cf.points.shape == (n_kept, 3)
    assert cf.skipped == truth["nonfinite"]
    assert cf.fields == list(truth["fields"])  # type: ignore[call-overload]
    assert cf.normals is None
    assert cf.covariances is None
    assert_bounds(cf.points, truth)
    height, width = truth["height"], truth["width"]
    if height == 1:
        assert cf.grid_shape is None
        assert cf.pixels is None
    else:
        assert cf.grid_shape == (height, width)
        assert cf.pixels is not None
        assert len(cf.pixels) == n_kept
        if truth["nonfinite"] == 0 and cf.at_origin == 0:
            np.testing.assert_array_equal(cf.pixels, np.arange(n_finite))
    viewpoint: tuple[float, ...] | None = truth["viewpoint"]  # type: ignore[assignment]
    # PCL reads a VIEWPOINT, the default identity included (written or left
    # out), as the sensor pose.
    assert cf.sensor_pose is not None
    default = viewpoint is None or tuple(viewpoint) == IDENTITY_VIEWPOINT
    assert cf.sensor_pose_is_default == default
    want = (
        np.eye(4)
        if viewpoint is None
        else from_quaternion(viewpoint[3:], translation=viewpoint[:3])
    )
    np.testing.assert_allclose(cf.sensor_pose, want, atol=1e-12)


@pytest.mark.parametrize("name", cases("pcd"))
def test_pcd_points_match_open3d(name: str) -> None:
    o3d = pytest.importorskip("open3d")
    path = fetch(name)
    theirs = np.asarray(o3d.io.read_point_cloud(str(path)).points)
    cf = cp.io.read_point_cloud(path)
    ours = cf.points
    if cf.grid_shape is not None:  # an organized scan's no-returns (at the origin) left out
        theirs = theirs[np.any(theirs != 0.0, axis=1)]
    # Open3D keeps ascii decimals as float64; cloudprox reads an F4 field as float32.
    np.testing.assert_array_equal(ours, theirs.astype(np.float32).astype(np.float64))


@pytest.mark.parametrize("name", cases("ply"))
def test_ply(name: str) -> None:
    truth = EXPECTED[name]
    path = fetch(name)
    mesh = cp.io.read_mesh(path)  # warnings are errors: no face may be dropped
    assert len(mesh.vertices) == truth["vertices"]
    assert len(mesh.faces) == truth["triangles"]
    assert mesh.faces.min() >= 0
    assert mesh.faces.max() < len(mesh.vertices)
    assert_bounds(mesh.vertices, truth)
    cloud = cp.io.read_point_cloud(path)
    assert len(cloud) == truth["vertices"]
    np.testing.assert_array_equal(cloud.points, mesh.vertices)
    assert cloud.fields[:3] == ["x", "y", "z"]
    if name.endswith("tetrahedron"):
        assert mesh.is_closed
        # The regular tetrahedron inscribed in the cube [-1, 1]^3 has volume 8/3.
        assert abs(mesh.volume) == pytest.approx(8.0 / 3.0, rel=1e-12)
    if name == "ply_binary_le_frame":  # normals and colours written by Open3D
        assert cloud.fields == ["x", "y", "z", "nx", "ny", "nz", "red", "green", "blue"]
        assert cloud.normals is not None
        np.testing.assert_allclose(np.linalg.norm(cloud.normals, axis=1), 1.0, atol=1e-6)


@pytest.mark.parametrize("name", cases("ply"))
def test_ply_matches_open3d(name: str) -> None:
    o3d = pytest.importorskip("open3d")
    path = fetch(name)
    theirs = o3d.io.read_triangle_mesh(str(path))
    mesh = cp.io.read_mesh(path)
    np.testing.assert_array_equal(mesh.vertices, np.asarray(theirs.vertices))
    np.testing.assert_array_equal(mesh.faces, np.asarray(theirs.triangles))


@pytest.mark.parametrize("name", cases("las", "laz"))
def test_las(name: str) -> None:
    truth = EXPECTED[name]
    cf = cp.io.read_point_cloud(fetch(name))
    assert len(cf) == truth["points"]
    assert cf.skipped == 0
    assert cf.grid_shape is None
    assert cf.sensor_pose is None
    assert_bounds(cf.points, truth)
    # Coordinates are raw * scale + offset: on the file's integer grid.
    scale = np.asarray(truth["scale"], dtype=np.float64)
    offset = np.asarray(truth["offset"], dtype=np.float64)
    steps = (cf.points - offset) / scale
    # f64 rounding of coordinates ~1e6 over steps ~1e-6 leaves ~1e-3 of a step.
    np.testing.assert_allclose(steps, np.round(steps), rtol=0.0, atol=2e-3)
    assert cf.fields[:4] == ["x", "y", "z", "intensity"]
    point_format = truth["point_format"]
    assert ("gps_time" in cf.fields) == (point_format in (1, 3, 6))
    assert ("red" in cf.fields) == (point_format == 3)
    assert ("scanner_channel" in cf.fields) == (point_format >= 6)  # type: ignore[operator]


@pytest.mark.parametrize("name", cases("las", "laz"))
def test_las_matches_laspy(name: str) -> None:
    laspy = pytest.importorskip("laspy")
    path = fetch(name)
    if name.startswith("laz") and not laspy.LazBackend.detect_available():
        pytest.skip("laspy has no LAZ backend")
    las = laspy.read(str(path))
    assert str(las.header.version) == EXPECTED[name]["version"]
    ours = cp.io.read_point_cloud(path).points
    np.testing.assert_array_equal(ours, np.column_stack([las.x, las.y, las.z]))


@pytest.mark.parametrize("name", cases("stl"))
def test_stl(name: str) -> None:
    truth = EXPECTED[name]
    path = fetch(name)
    assert path.read_bytes().startswith(b"solid") == (truth["encoding"] == "ascii")
    mesh = cp.io.read_mesh(path)  # warnings are errors: no facet may be dropped
    # STL repeats each corner per facet; cloudprox welds exactly equal positions.
    assert len(mesh.vertices) == truth["unique_vertices"]
    assert len(mesh.faces) == truth["facets"]
    assert len(np.unique(mesh.vertices, axis=0)) == len(mesh.vertices)
    assert_bounds(mesh.vertices, truth)
    assert mesh.is_closed == truth["watertight"]
    if truth["signed_volume"] is not None:  # the closed robot links and the cone
        assert mesh.volume == pytest.approx(truth["signed_volume"], rel=1e-6)


def test_stl_ascii_and_binary_bunny_agree() -> None:
    ascii_ = cp.io.read_mesh(fetch("stl_ascii_bunny"))
    binary = cp.io.read_mesh(fetch("stl_binary_bunny"))
    np.testing.assert_allclose(ascii_.vertices, binary.vertices, rtol=0.0, atol=1e-6)
    np.testing.assert_array_equal(ascii_.faces, binary.faces)


@pytest.mark.parametrize("name", cases("obj"))
def test_obj(name: str) -> None:
    truth = EXPECTED[name]
    mesh = cp.io.read_mesh(fetch(name))
    # One vertex per 'v' statement: not split by texture coordinate as Open3D does.
    assert len(mesh.vertices) == truth["vertices"]
    assert len(mesh.faces) == truth["triangles"]
    assert mesh.faces.max() < len(mesh.vertices)
    assert_bounds(mesh.vertices, truth)


@pytest.mark.parametrize("name", cases("off"))
def test_off(name: str) -> None:
    truth = EXPECTED[name]
    mesh = cp.io.read_mesh(fetch(name))
    assert len(mesh.vertices) == truth["vertices"]
    sizes: dict[int, int] = truth["face_sizes"]  # type: ignore[assignment]
    assert sum(sizes.values()) == truth["faces"]
    # Fans: a k-gon gives k - 2 triangles.
    assert len(mesh.faces) == truth["triangles"] == sum((k - 2) * c for k, c in sizes.items())
    assert_bounds(mesh.vertices, truth)
    assert mesh.is_closed
