"""cloudprox.datasets: the MRPT Kinect frame, the Panda gripper, fetching, .deb reading.

The Kinect frame and the gripper wheel are fetched into the cache
(``$CLOUDPROX_CACHE`` or ``~/.cache/cloudprox``) on the first run.
"""

from __future__ import annotations

import gzip
import io
import lzma
import re
import shutil
import struct
import subprocess
import tarfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import datasets

# ------------------------------------------------------------------------- cache


def test_cache_dir_from_env(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CLOUDPROX_CACHE", str(tmp_path / "c" / "d"))
    assert datasets.cache_dir() == tmp_path / "c" / "d"
    assert (tmp_path / "c" / "d").is_dir()


def test_cache_dir_default(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CLOUDPROX_CACHE", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    assert datasets.cache_dir() == tmp_path / ".cache" / "cloudprox"
    assert datasets.cache_dir().is_dir()


def test_run_command_quotes_the_failure(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError, match=r"^get x: `false` failed with exit status 1:\n\nretry$"):
        datasets.run_command(["false"], tmp_path, "get x", "retry")
    missing = str(tmp_path / "no-such-client")
    with pytest.raises(LookupError, match=r"^get x: `.*no-such-client` could not run \(.*\)$"):
        datasets.run_command([missing], tmp_path, "get x", error=LookupError)


# ------------------------------------------------------------------ Kinect frame

N_KINECT_POINTS = 273_225


@pytest.fixture(scope="module")
def frame() -> datasets.DepthFrame:
    return datasets.load_kinect_frame()


@pytest.fixture(scope="module")
def raw_archive() -> bytes:
    """The uncompressed MRPT archive of the frame."""
    return gzip.decompress(datasets.kinect_rawlog_path().read_bytes())


def test_kinect_frame_points(frame: datasets.DepthFrame) -> None:
    assert frame.points.shape == (N_KINECT_POINTS, 3)
    assert frame.points.dtype == np.float64
    assert np.all(np.isfinite(frame.points))
    assert np.all(frame.points[:, 2] > 0)
    # a bookshelf about 1.6-2.6 m in front of the camera
    assert 1.5 < frame.points[:, 2].min() < frame.points[:, 2].max() < 2.7
    np.testing.assert_array_equal(frame.origin, np.zeros(3))
    assert Path(frame.source).name == "tests_rgbd.rawlog"
    assert not frame.points.flags.writeable


def test_kinect_intrinsics_reproject_pixels(frame: datasets.DepthFrame) -> None:
    # agree with the depth camera calibration stored in the file
    np.testing.assert_allclose(
        [frame.fx, frame.fy, frame.cx, frame.cy], [572.883, 542.740, 314.649, 240.160], atol=1e-3
    )
    p = frame.points
    u = frame.cx + frame.fx * p[:, 0] / p[:, 2]
    v = frame.cy + frame.fy * p[:, 1] / p[:, 2]
    assert frame.pixels.shape == (N_KINECT_POINTS, 2)
    assert np.abs(u - frame.pixels[:, 0]).max() < 0.01
    assert np.abs(v - frame.pixels[:, 1]).max() < 0.01
    np.testing.assert_allclose(frame.project(p), frame.pixels, atol=0.01)


def test_kinect_depth_image_matches_points(frame: datasets.DepthFrame) -> None:
    assert frame.depth.shape == (480, 640)
    assert frame.rgb.shape == (480, 640, 3)
    assert frame.rgb.dtype == np.uint8
    u, v = frame.pixels[:, 0], frame.pixels[:, 1]
    np.testing.assert_allclose(frame.depth[v, u], frame.points[:, 2], atol=1e-6)
    # one point per pixel with a return, none elsewhere
    assert np.count_nonzero(frame.depth) == N_KINECT_POINTS
    assert len(np.unique(v * 640 + u)) == N_KINECT_POINTS
    assert frame.depth.min() == 0.0


def test_kinect_fetch_into_cache(frame: datasets.DepthFrame) -> None:
    path = datasets.fetch_kinect_rawlog()  # apt-get download mrpt-common, once
    assert path == datasets.cache_dir() / "mrpt" / "tests_rgbd.rawlog"
    if Path(frame.source) != path:
        assert path.read_bytes() == Path(frame.source).read_bytes()
    assert datasets.load_kinect_frame(path).points.shape == (N_KINECT_POINTS, 3)


def _points_offset(raw: bytes) -> tuple[int, int]:
    """Byte offset of the first x coordinate and the number of points."""
    at = raw.index(b"mrpt::poses::CPose3D") + 20 + 1 + 12 * 8 + 1 + 1  # pose, end, flag
    (n,) = struct.unpack_from("<I", raw, at)
    return at + 4, n


def _corrupt(raw: bytes, at: int, new: bytes) -> bytes:
    return raw[:at] + new + raw[at + len(new) :]


def test_kinect_uncompressed_archive_loads(tmp_path: Path, raw_archive: bytes) -> None:
    path = tmp_path / "plain.rawlog"
    path.write_bytes(raw_archive)
    assert datasets.load_kinect_frame(path).points.shape == (N_KINECT_POINTS, 3)


def test_kinect_truncated_gzip(tmp_path: Path) -> None:
    blob = datasets.kinect_rawlog_path().read_bytes()
    path = tmp_path / "cut.rawlog"
    path.write_bytes(blob[: len(blob) // 2])
    with pytest.raises(ValueError, match=re.escape(str(path)) + ".*corrupt or truncated gzip"):
        datasets.load_kinect_frame(path)


@pytest.mark.parametrize(
    ("where", "problem"),
    [
        ("y", r"truncated: point y coordinates needs 1092900 bytes, 100 are left"),
        ("range", r"truncated: range image needs 614400 bytes, 1000 are left"),
        ("rgb", r"truncated: pixels of the colour image needs 921600 bytes, 10 are left"),
        ("end", r"truncated: has-pixel-labels flag needs 1 bytes, 0 are left"),
    ],
)
def test_kinect_truncated_archive(
    tmp_path: Path, raw_archive: bytes, where: str, problem: str
) -> None:
    at, n = _points_offset(raw_archive)
    range_at = at + 16 * n + 1 + 4 + 8  # points, flag, units, rows and columns
    rgb_at = raw_archive.index(b"mrpt::img::CImage") + 17 + 11  # version, flags, size
    cut = {"y": at + 4 * n + 100, "range": range_at + 1000, "rgb": rgb_at + 10}
    path = tmp_path / "cut.rawlog"
    path.write_bytes(
        gzip.compress(raw_archive[: cut.get(where, len(raw_archive) - 2)], compresslevel=1)
    )
    with pytest.raises(ValueError, match=re.escape(str(path)) + ": " + problem):
        datasets.load_kinect_frame(path)


def test_kinect_wrong_class(tmp_path: Path, raw_archive: bytes) -> None:
    path = tmp_path / "wrong.rawlog"
    path.write_bytes(raw_archive.replace(b"CObservation3DRangeScan", b"CObservation2DRangeScan", 1))
    with pytest.raises(
        ValueError,
        match=r"expected an object of class mrpt::obs::CObservation3DRangeScan, "
        r"found 'mrpt::obs::CObservation2DRangeScan'",
    ):
        datasets.load_kinect_frame(path)


def test_kinect_not_an_archive(tmp_path: Path) -> None:
    path = tmp_path / "text.rawlog"
    path.write_bytes(b"hello world\n")
    with pytest.raises(ValueError, match=r"expected an object of class .*, found 'byte 0x68'"):
        datasets.load_kinect_frame(path)


def test_kinect_wrong_version(tmp_path: Path, raw_archive: bytes) -> None:
    version_at = 1 + len("mrpt::obs::CObservation3DRangeScan")
    assert raw_archive[version_at] == 9
    path = tmp_path / "v7.rawlog"
    path.write_bytes(_corrupt(raw_archive, version_at, b"\x07"))
    with pytest.raises(ValueError, match=r"unsupported serialization version 7 of mrpt::obs::CObs"):
        datasets.load_kinect_frame(path)


def test_kinect_bad_flag_and_end_marker(tmp_path: Path, raw_archive: bytes) -> None:
    at, _ = _points_offset(raw_archive)
    path = tmp_path / "flag.rawlog"
    path.write_bytes(_corrupt(raw_archive, at - 5, b"\x07"))
    with pytest.raises(ValueError, match=r"has-points flag should be a boolean"):
        datasets.load_kinect_frame(path)
    path.write_bytes(_corrupt(raw_archive, len(raw_archive) - 1, b"\x00"))
    with pytest.raises(ValueError, match=r"missing end-of-object marker"):
        datasets.load_kinect_frame(path)


def test_kinect_points_must_match_depth_and_pinhole(tmp_path: Path, raw_archive: bytes) -> None:
    at, n = _points_offset(raw_archive)
    (x0,) = struct.unpack_from("<f", raw_archive, at)
    (y0,) = struct.unpack_from("<f", raw_archive, at + 4 * n)
    path = tmp_path / "moved.rawlog"
    path.write_bytes(_corrupt(raw_archive, at, struct.pack("<f", x0 + 0.01)))
    with pytest.raises(ValueError, match=r"points differ from the depth image by up to 0.01 m"):
        datasets.load_kinect_frame(path)
    path.write_bytes(_corrupt(raw_archive, at + 4 * n, struct.pack("<f", y0 + 0.01)))
    with pytest.raises(ValueError, match=r"not a pinhole projection"):
        datasets.load_kinect_frame(path)


def test_kinect_missing_file(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError, match=r"missing\.rawlog: cannot read.*apt-get install"):
        datasets.load_kinect_frame(tmp_path / "missing.rawlog")


# --------------------------------------------------------------- .deb extraction

MEMBER = "usr/share/mrpt/datasets/tests_rgbd.rawlog"


def _tar(files: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w") as tar:
        for name, content in files.items():
            info = tarfile.TarInfo(name)
            info.size = len(content)
            tar.addfile(info, io.BytesIO(content))
    return buf.getvalue()


def _ar(members: dict[str, bytes]) -> bytes:
    out = [b"!<arch>\n"]
    for name, content in members.items():
        header = f"{name:<16}{0:<12}{0:<6}{0:<6}{100644:<8}{len(content):<10}`\n"
        out += [header.encode(), content, b"\n" * (len(content) % 2)]
    return b"".join(out)


def _deb(path: Path, payload: bytes, compression: str) -> Path:
    data_tar = _tar({"./usr/": b"", "./" + MEMBER: payload})
    compressors: dict[str, Callable[[bytes], bytes]] = {
        "xz": lzma.compress,
        "gz": gzip.compress,
        "": bytes,
    }
    compress = compressors[compression]
    name = "data.tar" + (f".{compression}" if compression else "")
    control = lzma.compress(_tar({"./control": b"Package: mrpt-common\n"}))
    members = {"debian-binary": b"2.0\n", "control.tar.xz": control, name: compress(data_tar)}
    path.write_bytes(_ar(members))
    return path


@pytest.mark.parametrize("compression", ["xz", "gz", ""])
def test_extract_from_deb(tmp_path: Path, compression: str) -> None:
    deb = _deb(tmp_path / "p.deb", b"odd-length payload", compression)
    assert datasets.extract_from_deb(deb, MEMBER) == b"odd-length payload"


@pytest.mark.skipif(
    shutil.which("zstd") is None or shutil.which("dpkg-deb") is None,
    reason="needs the zstd and dpkg-deb programs",
)
def test_extract_from_deb_zstd_via_dpkg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    deb = _deb(tmp_path / "p.deb", b"payload", "")
    members = datasets._ar_members(deb, deb.read_bytes())
    zst = subprocess.run(
        ["zstd", "-q", "-c"], input=members.pop("data.tar"), capture_output=True, check=True
    ).stdout
    deb.write_bytes(_ar({**members, "data.tar.zst": zst}))
    monkeypatch.setattr(datasets, "_zstd_decompressor", lambda: None)  # force dpkg-deb
    assert datasets.extract_from_deb(deb, MEMBER) == b"payload"


def test_extract_from_deb_errors(tmp_path: Path) -> None:
    bad = tmp_path / "bad.deb"
    bad.write_bytes(b"PK\x03\x04 not a deb")
    with pytest.raises(ValueError, match=r"bad\.deb: not a Debian package"):
        datasets.extract_from_deb(bad, MEMBER)
    deb = _deb(tmp_path / "p.deb", b"payload", "xz")
    with pytest.raises(ValueError, match=r"p\.deb: the package has no file usr/share/other"):
        datasets.extract_from_deb(deb, "usr/share/other")
    cut = tmp_path / "cut.deb"
    cut.write_bytes(deb.read_bytes()[:-40])
    with pytest.raises(ValueError, match=r"cut\.deb: ar member 'data\.tar\.xz' is truncated"):
        datasets.extract_from_deb(cut, MEMBER)


def test_fetch_without_apt_get(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CLOUDPROX_CACHE", str(tmp_path))
    monkeypatch.setattr(datasets.shutil, "which", lambda _name: None)
    with pytest.raises(RuntimeError, match=r"apt-get is not available"):
        datasets.fetch_kinect_rawlog()


def test_fetch_failing_apt_get(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fake = tmp_path / "apt-get"
    fake.write_text("#!/bin/sh\necho 'E: Unable to locate package mrpt-common' >&2\nexit 100\n")
    fake.chmod(0o755)
    monkeypatch.setenv("CLOUDPROX_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(datasets.shutil, "which", lambda _name: str(fake))
    with pytest.raises(
        RuntimeError, match=r"(?s)exit status 100.*Unable to locate.*apt-get update"
    ):
        datasets.fetch_kinect_rawlog()
    assert not (tmp_path / "cache" / "mrpt" / "tests_rgbd.rawlog").exists()


# ------------------------------------------------------------------ Panda gripper


@pytest.fixture(scope="module")
def open_parts() -> list[cp.Mesh]:
    return datasets.panda_gripper_parts(0.04)


def _finger_gap(parts: list[cp.Mesh]) -> float:
    """Free space along y between the left (y < 0) and right (y > 0) finger."""
    _, left, right = parts
    return float(right.bounds()[0][1] - left.bounds()[1][1])


def test_gripper_parts(open_parts: list[cp.Mesh]) -> None:
    hand, left, right = open_parts
    assert hand.faces.shape == (7078, 3)
    assert left.faces.shape == right.faces.shape == (624, 3)
    # hand.obj is an open surface, finger.obj a closed but not convex solid
    assert not hand.is_closed
    assert left.is_closed and right.is_closed
    assert not right.is_convex()
    # the left finger is the right one turned half a turn about z
    np.testing.assert_allclose(left.vertices[:, :2], -right.vertices[:, :2])
    np.testing.assert_allclose(left.vertices[:, 2], right.vertices[:, 2])
    assert left.volume == pytest.approx(right.volume) and right.volume > 0


def test_gripper_extents(open_parts: list[cp.Mesh]) -> None:
    gripper = datasets.panda_gripper()
    assert len(gripper.faces) == sum(len(p.faces) for p in open_parts)
    lo, hi = gripper.bounds()
    np.testing.assert_allclose(hi - lo, [0.0630, 0.2045, 0.1382], atol=5e-4)
    # palm behind the flange plane, finger tips just beyond the tool centre point
    assert lo[2] < 0 < datasets.PANDA_FINGER_MOUNT < datasets.PANDA_TCP_OFFSET < hi[2] < 0.12
    np.testing.assert_allclose(gripper.bounds()[1][2], open_parts[2].bounds()[1][2])


def test_gripper_opening_moves_fingers(open_parts: list[cp.Mesh]) -> None:
    closed = datasets.panda_gripper_parts(0.0)
    half = datasets.panda_gripper_parts(0.01)
    gap0 = _finger_gap(closed)
    assert abs(gap0) < 1e-3  # closed fingers touch (the mesh overlaps by 0.17 mm)
    assert _finger_gap(half) - gap0 == pytest.approx(0.02, abs=1e-9)
    assert _finger_gap(open_parts) - gap0 == pytest.approx(0.08, abs=1e-9)
    np.testing.assert_array_equal(closed[0].vertices, open_parts[0].vertices)  # hand fixed


@pytest.mark.parametrize("opening", [-0.001, 0.0401, float("nan"), float("inf")])
def test_gripper_bad_opening(opening: float) -> None:
    with pytest.raises(ValueError, match=r"opening must be in \[0, 0.04\] m"):
        datasets.panda_gripper(opening)


def test_panda_wheel_cached_and_checked(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    wheel = datasets.fetch_panda_wheel()
    assert wheel.parent == datasets.cache_dir() / "pypi"
    fake = tmp_path / "pypi" / wheel.name
    fake.parent.mkdir()
    fake.write_bytes(b"tampered")
    monkeypatch.setenv("CLOUDPROX_CACHE", str(tmp_path))
    with pytest.raises(RuntimeError, match=r"SHA-256 .* differs from the published"):
        datasets.fetch_panda_wheel()
