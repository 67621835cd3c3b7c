"""Real data fetched from package registries: a Kinect depth frame, the Panda gripper.

Shared by the reproduction (:mod:`cloudprox.reproduce`), the tests and the
benchmarks. Nothing here is stored in the repository: the files come from
package registries and are kept in a local cache (:func:`cache_dir`:
``$CLOUDPROX_CACHE``, else ``~/.cache/cloudprox``), fetched on first use.

Public API:

- :func:`cache_dir`: the cache folder; :func:`write_atomically` puts a file in it;
  :func:`run_command` runs a registry client (``apt-get download``, ``pip download``).
- :func:`extract_from_deb`: one file of a Debian package (``ar`` archive holding
  a ``data.tar``, plain or compressed with xz, gzip or Zstandard), read in Python.
- :func:`fetch_kinect_rawlog`, :func:`kinect_rawlog_path`,
  :func:`load_kinect_frame` and :class:`DepthFrame`: the Kinect v1 frame below.
- :func:`fetch_panda_wheel`, :func:`load_obj`, :func:`panda_gripper_parts`,
  :func:`panda_gripper` and the ``PANDA_*`` constants: the gripper below.

Depth frame
    ``tests_rgbd.rawlog`` of the Debian package ``mrpt-common`` (MRPT, the Mobile
    Robot Programming Toolkit; licence BSD-3-Clause), installed at
    ``/usr/share/mrpt/datasets/tests_rgbd.rawlog``. It is a (gzip-compressed)
    MRPT archive holding a single ``mrpt::obs::CObservation3DRangeScan``
    (serialization version 9) recorded with a Kinect v1 through OpenNI2: a
    640x480 depth image (millimetres, 0 where the sensor got no return), the
    273,225 points unprojected from it and the 640x480 colour image. When the
    package is not installed, :func:`load_kinect_frame` runs ``apt-get download
    mrpt-common`` (no root needed, but the apt package lists must be present) and
    extracts the file from the ``.deb`` into ``<cache>/mrpt/``.

    The points come out of MRPT in its camera frame (x forward along the optical
    axis, y left, z up) and are returned in the optical frame (x right, y down,
    z forward): ``optical = (-y, -z, x)``. They are an exact pinhole unprojection
    of the depth image without lens distortion; the intrinsics are fitted to the
    points by least squares (``u = cx + fx * x / z``, ``v = cy + fy * y / z``),
    which reproduces every pixel to about 3e-5 px, and agree with the depth
    camera calibration stored in the file: ``fx = 572.88``, ``fy = 542.74``,
    ``cx = 314.65``, ``cy = 240.16`` (pixels).

Gripper
    ``hand.obj`` and ``finger.obj`` of the PyPI wheel ``dm-robotics-panda==0.4.8``
    (MuJoCo model of the Franka Emika Panda by Jean Elsner; licence Apache-2.0),
    read straight from the wheel (``python -m pip download``, not installed) kept
    in ``<cache>/pypi/``. :func:`panda_gripper_parts` assembles them as the
    wheel's ``panda_hand.xml`` does: hand frame at the flange, z the approach
    axis, both fingers mounted at ``z = 0.0584`` m and sliding along ``+-y`` by
    the opening (0 to 0.04 m each); the tool centre point is at
    ``z = PANDA_TCP_OFFSET``.
"""

from __future__ import annotations

import functools
import gzip
import hashlib
import io
import lzma
import math
import os
import shutil
import struct
import subprocess
import sys
import tarfile
import tempfile
import warnings
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cloudprox._native import Mesh
from cloudprox.exceptions import DegenerateFacesWarning
from cloudprox.io import parse_mesh, read_mesh
from cloudprox.pose import from_translation

__all__ = [
    "PANDA_FINGER_MOUNT",
    "PANDA_MAX_OPENING",
    "PANDA_TCP_OFFSET",
    "DegenerateFacesWarning",
    "DepthFrame",
    "cache_dir",
    "extract_from_deb",
    "fetch_kinect_rawlog",
    "fetch_panda_wheel",
    "kinect_rawlog_path",
    "load_kinect_frame",
    "load_obj",
    "panda_gripper",
    "panda_gripper_parts",
    "run_command",
    "write_atomically",
]

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: Distance (metres) from the flange to the tool centre point of the Franka Hand
#: along its z axis: the default end-effector frame of the Franka Control Interface
#: documentation ("Control parameters", https://frankaemika.github.io/docs/), and
#: the ``TCP`` site of ``panda_hand.xml`` in dm-robotics-panda 0.4.8.
PANDA_TCP_OFFSET = 0.1034
#: Height (metres) along z of both finger joints in the hand frame (``panda_hand.xml``).
PANDA_FINGER_MOUNT = 0.0584
#: Largest travel (metres) of each finger: the joint range of ``panda_hand.xml``.
PANDA_MAX_OPENING = 0.04

#: Where Debian's mrpt-common installs the frame, and its path inside the package.
_MRPT_SYSTEM_FILE = Path("/usr/share/mrpt/datasets/tests_rgbd.rawlog")
_MRPT_DEB_MEMBER = "usr/share/mrpt/datasets/tests_rgbd.rawlog"
_MRPT_HOWTO = (
    "install it with `apt-get install mrpt-common`, or run `apt-get update` and retry "
    "(the file is fetched with `apt-get download mrpt-common`), or pass its path"
)

_PANDA_REQUIREMENT = "dm-robotics-panda==0.4.8"
_PANDA_WHEEL = "dm_robotics_panda-0.4.8-py3-none-any.whl"
_PANDA_WHEEL_SHA256 = "320688490d25079f8c576610e025946fddb30415946e751950023e3d83eb6003"
_PANDA_ASSETS = "dm_robotics/panda/assets/panda/"


def cache_dir() -> Path:
    """Return the cache of fetched data, created on demand.

    ``$CLOUDPROX_CACHE`` when set (and not empty), else ``~/.cache/cloudprox``.
    """
    env = os.environ.get("CLOUDPROX_CACHE")
    path = Path(env).expanduser() if env else Path.home() / ".cache" / "cloudprox"
    path.mkdir(parents=True, exist_ok=True)
    return path


def run_command(
    cmd: list[str],
    cwd: Path,
    what: str,
    howto: str = "",
    *,
    error: type[Exception] = RuntimeError,
    timeout: float = 900,
) -> None:
    """Run ``cmd`` (a registry client: ``apt-get``, ``pip``) in ``cwd``.

    On failure (it cannot start, times out or exits non-zero) raise ``error``
    with a message that opens with ``what``, quotes the command and its output
    and closes with ``howto`` when one is given.
    """
    try:
        proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as exc:
        advice = f"; {howto}" if howto else ""
        raise error(f"{what}: `{' '.join(cmd)}` could not run ({exc}){advice}") from exc
    if proc.returncode != 0:
        output = (proc.stderr.strip() or proc.stdout.strip())[-2000:]
        advice = f"\n{howto}" if howto else ""
        raise error(
            f"{what}: `{' '.join(cmd)}` failed with exit status {proc.returncode}:\n"
            f"{output}{advice}"
        )


# --------------------------------------------------------------------------- .deb


def _ar_members(deb: Path, data: bytes) -> dict[str, bytes]:
    """Members of a Unix ``ar`` archive (the container of a ``.deb``)."""
    magic = b"!<arch>\n"
    if not data.startswith(magic):
        raise ValueError(f"{deb}: not a Debian package (no ar archive signature)")
    members: dict[str, bytes] = {}
    pos = len(magic)
    while pos < len(data):
        header = data[pos : pos + 60]
        if len(header) < 60 or header[58:60] != b"`\n":
            raise ValueError(f"{deb}: corrupt ar member header at byte {pos}")
        name = header[:16].decode("ascii", "replace").strip().rstrip("/")
        try:
            size = int(header[48:58].decode("ascii").strip())
        except ValueError:
            raise ValueError(f"{deb}: corrupt ar member size at byte {pos + 48}") from None
        start = pos + 60
        if size < 0 or start + size > len(data):
            raise ValueError(f"{deb}: ar member {name!r} is truncated")
        members[name] = data[start : start + size]
        pos = start + size + (size & 1)  # members are padded to an even length
    return members


def _zstd_decompressor() -> Callable[[bytes], bytes] | None:
    """Return a Zstandard decompression function, or None if no module provides one."""
    try:  # Python >= 3.14
        from compression import zstd  # type: ignore[import-not-found]

        return zstd.decompress  # type: ignore[no-any-return]
    except ImportError:
        pass
    try:
        import zstandard  # type: ignore[import-not-found]
    except ImportError:
        return None

    def decompress(blob: bytes) -> bytes:
        return zstandard.ZstdDecompressor().decompressobj().decompress(blob)  # type: ignore[no-any-return]

    return decompress


def _data_tar(deb: Path) -> bytes:
    """Return the uncompressed ``data.tar`` of the package ``deb``."""
    members = _ar_members(deb, deb.read_bytes())
    if "debian-binary" not in members:
        raise ValueError(f"{deb}: not a Debian package (no debian-binary member)")
    names = [name for name in members if name.startswith("data.tar")]
    if len(names) != 1:
        raise ValueError(f"{deb}: expected one data.tar member, found {sorted(members)}")
    name = names[0]
    blob = members[name]
    try:
        if name == "data.tar":
            return blob
        if name == "data.tar.xz":
            return lzma.decompress(blob)
        if name == "data.tar.gz":
            return gzip.decompress(blob)
        if name == "data.tar.zst":
            decompress = _zstd_decompressor()
            if decompress is not None:
                return decompress(blob)
            dpkg = shutil.which("dpkg-deb")
            if dpkg is None:
                raise RuntimeError(
                    f"{deb}: {name} is Zstandard-compressed and neither a zstd Python "
                    "module nor dpkg-deb is available; install one (`pip install "
                    "zstandard` or `apt-get install dpkg`)"
                )
            proc = subprocess.run([dpkg, "--fsys-tarfile", str(deb)], capture_output=True)
            if proc.returncode != 0:
                raise RuntimeError(
                    f"{deb}: `dpkg-deb --fsys-tarfile` failed: {proc.stderr.decode()[-1000:]}"
                )
            return proc.stdout
    except (lzma.LZMAError, OSError, EOFError, zlib.error) as exc:
        raise ValueError(f"{deb}: cannot decompress {name}: {exc}") from exc
    raise ValueError(f"{deb}: unsupported package payload {name}")


def _tar_name(name: str) -> str:
    """Member name without a leading ``./`` or ``/`` (how dpkg writes them)."""
    return name[2:] if name.startswith("./") else name.lstrip("/")


def extract_from_deb(deb: Path, member: str) -> bytes:
    """Contents of the regular file ``member`` (e.g. ``usr/share/...``) of the package ``deb``."""
    tar_bytes = _data_tar(deb)
    wanted = _tar_name(member)
    try:
        with tarfile.open(fileobj=io.BytesIO(tar_bytes), mode="r:") as tar:
            for info in tar:
                if _tar_name(info.name) != wanted:
                    continue
                if not info.isfile():
                    raise ValueError(f"{deb}: {member} is not a regular file in the package")
                stream = tar.extractfile(info)
                assert stream is not None  # a regular file always has a stream
                content = stream.read()
                if len(content) != info.size:
                    raise ValueError(f"{deb}: {member} is truncated in the package")
                return content
    except tarfile.TarError as exc:
        raise ValueError(f"{deb}: corrupt data.tar: {exc}") from exc
    raise ValueError(f"{deb}: the package has no file {member}")


def write_atomically(path: Path, content: bytes) -> None:
    """Write ``content`` to ``path`` (parents created) through a temporary file.

    The temporary file is in the same folder and replaces ``path`` at once, so
    that a reader never sees a partial file.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(content)
        os.chmod(tmp, 0o644)  # mkstemp creates the file private
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def fetch_kinect_rawlog() -> Path:
    """Return ``<cache>/mrpt/tests_rgbd.rawlog``, downloading it first if missing.

    Runs ``apt-get download mrpt-common`` in a temporary directory of the cache
    and extracts the one file from the package; the ``.deb`` is then deleted.

    Raises
    ------
    RuntimeError
        If ``apt-get`` is missing or the download fails.
    ValueError
        If the package is not in the expected format.
    """
    dest = cache_dir() / "mrpt" / "tests_rgbd.rawlog"
    if dest.is_file():
        return dest
    what = f"cannot fetch {_MRPT_SYSTEM_FILE.name} (Debian package mrpt-common)"
    apt_get = shutil.which("apt-get")
    if apt_get is None:
        raise RuntimeError(
            f"{what}: apt-get is not available; copy {_MRPT_SYSTEM_FILE.name} from a "
            f"Debian or Ubuntu package mrpt-common to {dest}, or pass its path"
        )
    with tempfile.TemporaryDirectory(dir=cache_dir(), prefix="apt-") as tmp:
        run_command([apt_get, "download", "mrpt-common"], Path(tmp), what, _MRPT_HOWTO)
        debs = sorted(Path(tmp).glob("mrpt-common_*.deb"))
        if len(debs) != 1:
            raise RuntimeError(
                f"{what}: expected one mrpt-common_*.deb from apt-get download, "
                f"found {[deb.name for deb in debs]}"
            )
        try:
            content = extract_from_deb(debs[0], _MRPT_DEB_MEMBER)
        except ValueError as exc:
            raise ValueError(f"{what}: {exc}; {_MRPT_HOWTO}") from exc
    write_atomically(dest, content)
    return dest


def kinect_rawlog_path() -> Path:
    """Path of ``tests_rgbd.rawlog``: the installed package's, else the cache's (fetched)."""
    if _MRPT_SYSTEM_FILE.is_file():
        return _MRPT_SYSTEM_FILE
    return fetch_kinect_rawlog()


# ------------------------------------------------------------------ MRPT archive

#: Byte closing every serialized object in an MRPT archive.
_END_OF_OBJECT = 0x88


class _Reader:
    """Sequential little-endian reader of an MRPT archive, checking every size."""

    def __init__(self, data: bytes, source: str) -> None:
        self.data = data
        self.source = source
        self.pos = 0

    def fail(self, problem: str) -> ValueError:
        return ValueError(
            f"{self.source}: {problem} (at byte {self.pos} of the uncompressed archive); "
            f"the file is corrupt or not the MRPT Kinect frame - {_MRPT_HOWTO}"
        )

    def take(self, n: int, what: str) -> bytes:
        if n < 0 or self.pos + n > len(self.data):
            raise self.fail(
                f"truncated: {what} needs {n} bytes, {len(self.data) - self.pos} are left"
            )
        out = self.data[self.pos : self.pos + n]
        self.pos += n
        return out

    def scalar(self, fmt: str, what: str) -> float | int:
        size = struct.calcsize("<" + fmt)
        value: float | int = struct.unpack("<" + fmt, self.take(size, what))[0]
        return value

    def u8(self, what: str) -> int:
        return int(self.scalar("B", what))

    def u32(self, what: str) -> int:
        return int(self.scalar("I", what))

    def i32(self, what: str) -> int:
        return int(self.scalar("i", what))

    def f32(self, what: str) -> float:
        return float(self.scalar("f", what))

    def flag(self, what: str) -> bool:
        value = self.u8(what)
        if value > 1:
            self.pos -= 1
            raise self.fail(f"{what} should be a boolean (0 or 1), found {value}")
        return value == 1

    def string(self, what: str) -> str:
        n = self.u32(f"length of {what}")
        return self.take(n, what).decode("utf-8", "replace")

    def array(self, dtype: str, n: int, what: str) -> np.ndarray:
        itemsize = np.dtype(dtype).itemsize
        return np.frombuffer(self.take(n * itemsize, what), dtype=dtype)

    def begin(self, class_name: str, versions: tuple[int, ...]) -> int:
        """Read an object header ``0x80 | len, class name, version``; return the version."""
        start = self.pos
        tag = self.u8(f"header of {class_name}")
        name = self.take(tag & 0x7F, f"class name of {class_name}") if tag & 0x80 else b""
        if not tag & 0x80 or name != class_name.encode():
            self.pos = start
            found = name.decode("ascii", "replace") if name else f"byte {tag:#04x}"
            raise self.fail(f"expected an object of class {class_name}, found {found!r}")
        version = self.u8(f"serialization version of {class_name}")
        if version not in versions:
            self.pos -= 1
            raise self.fail(
                f"unsupported serialization version {version} of {class_name} "
                f"(supported: {', '.join(map(str, versions))})"
            )
        return version

    def end(self, class_name: str) -> None:
        if self.u8(f"end of {class_name}") != _END_OF_OBJECT:
            self.pos -= 1
            raise self.fail(f"missing end-of-object marker 0x88 after {class_name}")


def _skip_pose3d(r: _Reader, what: str) -> None:
    """Read past a ``CPose3D`` (v3: translation and rotation matrix, 12 doubles)."""
    r.begin("mrpt::poses::CPose3D", (3,))
    if not np.all(np.isfinite(r.array("<f8", 12, what))):
        raise r.fail(f"{what} is not finite")
    r.end("mrpt::poses::CPose3D")


def _read_camera(r: _Reader, what: str) -> tuple[float, float, float, float, int, int]:
    """Read a ``TCamera`` (v4-v6): ``(fx, fy, cx, cy, rows, cols)``."""
    version = r.begin("mrpt::img::TCamera", (4, 5, 6))
    r.array("<f8", 9, f"focal length and distortion of {what}")
    fx, fy, cx, cy = (float(x) for x in r.array("<f8", 4, f"intrinsics of {what}"))
    rows, cols = r.u32(f"rows of {what}"), r.u32(f"columns of {what}")
    if version >= 5:
        r.string(f"name of {what}")
    if version >= 6:
        r.u8(f"distortion model of {what}")
    r.end("mrpt::img::TCamera")
    return fx, fy, cx, cy, rows, cols


def _read_color_image(r: _Reader, what: str) -> npt.NDArray[np.uint8]:
    """Read a ``CImage`` (v8-v9) holding an uncompressed colour image, as RGB."""
    r.begin("mrpt::img::CImage", (8, 9))
    if r.flag(f"external-storage flag of the {what}"):
        raise r.fail(f"the {what} is stored in an external file, not in the archive")
    if not r.flag(f"colour flag of the {what}"):
        raise r.fail(f"the {what} is grey-scale, a colour image was expected")
    width, height = r.i32(f"width of the {what}"), r.i32(f"height of the {what}")
    if width >= 0 or height >= 0:
        raise r.fail(
            f"the {what} is JPEG-compressed or empty (size {width} x {height}); "
            "only raw images (negative sizes) are supported"
        )
    width, height = -width, -height
    bgr = r.array("u1", width * height * 3, f"pixels of the {what}").reshape(height, width, 3)
    r.end("mrpt::img::CImage")
    return np.ascontiguousarray(bgr[:, :, ::-1])  # OpenCV stores BGR


@dataclass(frozen=True)
class _RangeScan:
    """The fields of a ``CObservation3DRangeScan`` that the frame needs."""

    mrpt_points: npt.NDArray[np.float32]  # (N, 3), MRPT camera frame
    cols: npt.NDArray[np.uint16]
    rows: npt.NDArray[np.uint16]
    range_image: npt.NDArray[np.uint16]  # (H, W)
    range_unit: float
    rgb: npt.NDArray[np.uint8]
    depth_camera: tuple[float, float, float, float, int, int]


def _parse_range_scan(data: bytes, source: str) -> _RangeScan:
    """Parse an archive whose first object is a ``CObservation3DRangeScan`` (v9-v10)."""
    r = _Reader(data, source)
    cls = "mrpt::obs::CObservation3DRangeScan"
    version = r.begin(cls, (9, 10))
    r.f32("maximum range")
    _skip_pose3d(r, "sensor pose")
    if not r.flag("has-points flag"):
        raise r.fail("the observation holds no 3D points")
    n = r.u32("number of points")
    if n == 0:
        raise r.fail("the observation holds no 3D points")
    xyz = np.stack([r.array("<f4", n, f"point {axis} coordinates") for axis in "xyz"], axis=1)
    cols = r.array("<u2", n, "point pixel columns")
    rows = r.array("<u2", n, "point pixel rows")
    if not r.flag("has-range-image flag"):
        raise r.fail("the observation holds no range image")
    unit = r.f32("range units")
    if not (math.isfinite(unit) and unit > 0):
        raise r.fail(f"invalid range unit {unit}")
    height, width = r.u32("range image rows"), r.u32("range image columns")
    if not (0 < height <= 1 << 14 and 0 < width <= 1 << 14):
        raise r.fail(f"implausible range image size {width} x {height}")
    range_image = r.array("<u2", height * width, "range image").reshape(height, width)
    if not r.flag("has-intensity-image flag"):
        raise r.fail("the observation holds no colour image")
    rgb = _read_color_image(r, "colour image")
    if r.flag("has-confidence-image flag"):
        raise r.fail("confidence images are not supported")
    depth_camera = _read_camera(r, "depth camera")
    _read_camera(r, "colour camera")
    _skip_pose3d(r, "colour camera pose")
    r.f32("standard error")
    r.take(8, "time stamp")
    r.string("sensor label")
    for what in ("points", "range image"):
        if r.flag(f"external-storage flag of the {what}"):
            raise r.fail(f"the {what} is stored in an external file, not in the archive")
        r.string(f"external file of the {what}")
    if not r.flag("range-is-depth flag"):
        raise r.fail("ranges are distances along rays, depths along the optical axis expected")
    r.u8("intensity channel")
    if r.flag("has-pixel-labels flag"):
        raise r.fail("pixel labels are not supported")
    if version >= 10:
        for _ in range(r.u8("number of extra range layers")):
            r.string("layer name")
            layer_size = r.u32("layer size") * r.u32("layer size")
            r.take(2 * layer_size, "extra range layer")
    r.end(cls)
    if rgb.shape[:2] != range_image.shape:
        raise r.fail(f"colour image {rgb.shape[:2]} and range image {range_image.shape} differ")
    if depth_camera[4:] != (height, width):
        raise r.fail(f"depth camera size {depth_camera[4:]} differs from the range image")
    return _RangeScan(xyz, cols, rows, range_image, unit, rgb, depth_camera)


# ------------------------------------------------------------------ depth frame


@dataclass(frozen=True)
class DepthFrame:
    """One depth camera frame, in the camera's optical frame (arrays read-only).

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        The measured points (metres; x right, y down, z forward along the optical
        axis; the sensor at the origin).
    pixels : ndarray of int64, shape (n, 2)
        Pixel of each point: column ``u`` and row ``v``.
    depth : ndarray, shape (h, w)
        Depth image (metres along the optical axis; 0 where there is no return).
    fx, fy, cx, cy : float
        Pinhole intrinsics (pixels): ``u = cx + fx * x / z``, ``v = cy + fy * y / z``.
    rgb : ndarray of uint8, shape (h, w, 3)
        Colour image (registered by the driver to the depth image's size).
    source : str
        File the frame was read from.
    """

    points: FloatArray
    pixels: IntArray
    depth: FloatArray
    fx: float
    fy: float
    cx: float
    cy: float
    rgb: npt.NDArray[np.uint8]
    source: str

    @property
    def origin(self) -> FloatArray:
        """Sensor origin in this frame (the origin)."""
        return np.zeros(3)

    def project(self, points: npt.ArrayLike) -> FloatArray:
        """Pixel coordinates ``(u, v)`` of points in this frame (shape ``(n, 2)``)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return np.stack(
            [self.cx + self.fx * p[:, 0] / p[:, 2], self.cy + self.fy * p[:, 1] / p[:, 2]], axis=1
        )


#: Largest accepted pinhole residual (pixels) and depth mismatch (metres).
_MAX_REPROJECTION_PX = 0.01
_MAX_DEPTH_MISMATCH = 1e-5


def _fit_axis(ratio: FloatArray, pixel: FloatArray) -> tuple[float, float, float]:
    """Least squares ``pixel = c + f * ratio``: ``(f, c, largest residual)``."""
    design = np.stack([ratio, np.ones_like(ratio)], axis=1)
    (f, c), *_ = np.linalg.lstsq(design, pixel, rcond=None)
    return float(f), float(c), float(np.max(np.abs(c + f * ratio - pixel)))


def _read_archive(path: Path) -> bytes:
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise RuntimeError(f"{path}: cannot read the Kinect frame ({exc}); {_MRPT_HOWTO}") from exc
    if not raw.startswith(b"\x1f\x8b"):
        return raw  # MRPT archives may also be stored uncompressed
    try:
        return gzip.decompress(raw)
    except (OSError, EOFError, zlib.error) as exc:
        raise ValueError(
            f"{path}: corrupt or truncated gzip stream ({exc}); {_MRPT_HOWTO}"
        ) from exc


def load_kinect_frame(path: str | os.PathLike[str] | None = None) -> DepthFrame:
    """Load the Kinect v1 frame of MRPT's ``tests_rgbd.rawlog``.

    Parameters
    ----------
    path : str or Path, optional
        An MRPT archive (gzip-compressed or not) whose first object is a
        ``CObservation3DRangeScan``. By default the installed
        ``/usr/share/mrpt/datasets/tests_rgbd.rawlog``, else the cached copy,
        fetched with ``apt-get download mrpt-common`` when missing.

    Returns
    -------
    DepthFrame

    Raises
    ------
    RuntimeError
        If the file cannot be read or fetched.
    ValueError
        If the file is not the expected archive (wrong class or version, a size
        or flag out of place, truncated), or its points are not a pinhole
        unprojection of its depth image.
    """
    source = Path(path) if path is not None else kinect_rawlog_path()
    scan = _parse_range_scan(_read_archive(source), str(source))
    height, width = scan.range_image.shape

    def fail(problem: str) -> ValueError:
        return ValueError(
            f"{source}: {problem}; the file is corrupt or not the MRPT Kinect frame - "
            + _MRPT_HOWTO
        )

    mrpt = scan.mrpt_points.astype(np.float64)
    points = np.stack([-mrpt[:, 1], -mrpt[:, 2], mrpt[:, 0]], axis=1)
    if not np.all(np.isfinite(points)) or not np.all(points[:, 2] > 0):
        raise fail("some points are not finite or not in front of the camera")
    u = scan.cols.astype(np.int64)
    v = scan.rows.astype(np.int64)
    if u.max() >= width or v.max() >= height:
        raise fail(f"point pixels outside the {width} x {height} image")

    depth = scan.range_image.astype(np.float64) * scan.range_unit
    mismatch = np.abs(depth[v, u] - points[:, 2])
    if mismatch.max() > _MAX_DEPTH_MISMATCH:
        raise fail(f"points differ from the depth image by up to {mismatch.max():.3g} m")
    if np.count_nonzero(depth) != len(points):
        raise fail(f"{np.count_nonzero(depth)} depth pixels but {len(points)} points")

    fx, cx, res_u = _fit_axis(points[:, 0] / points[:, 2], u.astype(np.float64))
    fy, cy, res_v = _fit_axis(points[:, 1] / points[:, 2], v.astype(np.float64))
    residual = max(res_u, res_v)
    if residual > _MAX_REPROJECTION_PX:
        raise fail(f"the points are not a pinhole projection (residual up to {residual:.3g} px)")
    # The fit must agree with the depth camera calibration stored in the file.
    sfx, sfy, scx, scy = scan.depth_camera[:4]
    gap = max(
        abs(fx - sfx) * width / sfx + abs(cx - scx),
        abs(fy - sfy) * height / sfy + abs(cy - scy),
    )
    if gap > _MAX_REPROJECTION_PX:
        raise fail(f"fitted intrinsics differ from the stored calibration by {gap:.3g} px")

    pixels = np.stack([u, v], axis=1)
    for array in (points, pixels, depth, scan.rgb):
        array.setflags(write=False)
    return DepthFrame(points, pixels, depth, fx, fy, cx, cy, scan.rgb, str(source))


# ------------------------------------------------------------------ Wavefront OBJ


def load_obj(path: str | os.PathLike[str]) -> Mesh:
    """Read a triangle mesh from a Wavefront OBJ file (:func:`cloudprox.io.read_mesh`)."""
    return read_mesh(path, "obj")


# ------------------------------------------------------------------ Panda gripper


def fetch_panda_wheel() -> Path:
    """Return the cached wheel of ``dm-robotics-panda==0.4.8``, downloading it if missing.

    Runs ``python -m pip download dm-robotics-panda==0.4.8 --no-deps`` into
    ``<cache>/pypi`` and checks the wheel's SHA-256.

    Raises
    ------
    RuntimeError
        If pip fails (no network, no pip) or the wheel's checksum differs.
    """
    folder = cache_dir() / "pypi"
    wheel = folder / _PANDA_WHEEL
    if not wheel.is_file():
        howto = (
            f"download it yourself with `python3 -m pip download {_PANDA_REQUIREMENT} "
            f"--no-deps -d {folder}`"
        )
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=folder, prefix="pip-") as tmp:
            cmd = [sys.executable, "-m", "pip", "download", _PANDA_REQUIREMENT, "--no-deps"]
            # The wheel declares Python < 3.13 (for its dependencies); only its data is used.
            cmd += ["--only-binary=:all:", "--ignore-requires-python", "-d", tmp]
            cmd += ["--disable-pip-version-check"]
            run_command(
                cmd, Path(tmp), f"cannot fetch the Panda gripper meshes ({_PANDA_WHEEL})", howto
            )
            got = Path(tmp) / _PANDA_WHEEL
            if not got.is_file():
                raise RuntimeError(f"pip download did not produce {_PANDA_WHEEL}; {howto}")
            _check_wheel(got)
            os.replace(got, wheel)
    else:
        _check_wheel(wheel)
    return wheel


def _check_wheel(wheel: Path) -> None:
    digest = hashlib.sha256(wheel.read_bytes()).hexdigest()
    if digest != _PANDA_WHEEL_SHA256:
        raise RuntimeError(
            f"{wheel}: SHA-256 {digest} differs from the published {_PANDA_WHEEL_SHA256}; "
            "delete the file to download it again"
        )


@functools.lru_cache(maxsize=4)
def _panda_meshes(wheel: Path) -> tuple[Mesh, Mesh]:
    """Hand and finger meshes read from the wheel (each in its own frame)."""
    meshes = []
    with zipfile.ZipFile(wheel) as archive:
        for name in ("hand.obj", "finger.obj"):
            member = _PANDA_ASSETS + name
            with warnings.catch_warnings():
                warnings.simplefilter("error", DegenerateFacesWarning)
                meshes.append(parse_mesh(archive.read(member), "obj", f"{wheel}!{member}"))
    return meshes[0], meshes[1]


def panda_gripper_parts(opening: float = PANDA_MAX_OPENING) -> list[Mesh]:
    """Franka Panda hand and fingers in the hand frame: ``[hand, left, right]``.

    The hand frame is the flange's: z is the approach axis (the tool centre point
    at ``z = PANDA_TCP_OFFSET``) and the fingers close along y. The right finger
    is the finger mesh moved to ``(0, opening, PANDA_FINGER_MOUNT)``; the left
    one is turned half a turn about z and moved to ``(0, -opening,
    PANDA_FINGER_MOUNT)``, so the gap between the fingers grows by twice the
    opening.

    Parameters
    ----------
    opening : float, default 0.04
        Travel of each finger from closed (metres, in ``[0, 0.04]``).

    Raises
    ------
    ValueError
        If ``opening`` is outside ``[0, 0.04]`` or not finite.
    """
    opening = float(opening)
    if not (math.isfinite(opening) and 0.0 <= opening <= PANDA_MAX_OPENING):
        raise ValueError(
            f"opening must be in [0, {PANDA_MAX_OPENING}] m (travel of each finger), got {opening}"
        )
    hand, finger = _panda_meshes(fetch_panda_wheel())
    half_turn = np.diag([-1.0, -1.0, 1.0, 1.0])
    left = finger.transformed(from_translation((0.0, -opening, PANDA_FINGER_MOUNT)) @ half_turn)
    right = finger.transformed(from_translation((0.0, opening, PANDA_FINGER_MOUNT)))
    return [hand, left, right]


def panda_gripper(opening: float = PANDA_MAX_OPENING) -> Mesh:
    """Return the Panda hand and both fingers as one mesh (see :func:`panda_gripper_parts`)."""
    return Mesh.merged(panda_gripper_parts(opening))
