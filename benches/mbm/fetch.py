"""Fetch the MotionBenchMaker problems and robots from the ``vamp-planner`` sdist on PyPI.

The sdist of ``vamp-planner==0.6.4`` ships, under ``resources/<robot>/``, the
MotionBenchMaker (MBM) problems of four robots (``problems.tar.bz2``: MoveIt
planning-scene and motion-plan-request YAML files) and each robot's URDF, SRDF
and collision meshes. Nothing is committed: the sdist is downloaded with pip
into the cache (:func:`cloudprox.datasets.cache_dir`, ``$CLOUDPROX_CACHE`` or
``~/.cache/cloudprox``), under ``mbm/``, its SHA-256 checked, and the robot's
folder extracted beside it.

``pip download`` of an sdist prepares its metadata, which for this package runs
its build backend's metadata hook: scikit-build-core, nanobind, cmake and
typing_extensions must be importable in the downloading environment. The
download therefore runs in a virtual environment of its own, made once under
``<cache>/mbm/venv`` with those four installed; nothing is built.

Layout of the cache::

    <cache>/mbm/venv/                                  the download environment
    <cache>/mbm/vamp_planner-0.6.4.tar.gz              the sdist (SHA-256 checked)
    <cache>/mbm/vamp_planner-0.6.4/<robot>/            resources/<robot>/ extracted
    <cache>/mbm/vamp_planner-0.6.4/<robot>/<robot>.cloudprox.urdf

The last file is the robot's URDF with the fixes :func:`loadable_urdf` lists
(the Panda's URDF declares a ``mimic`` on a fixed finger joint, which
:meth:`cloudprox.Robot.from_urdf` refuses).
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path

from cloudprox.datasets import cache_dir, run_command, write_atomically

__all__ = [
    "BUILD_REQUIREMENTS",
    "ROBOTS",
    "SDIST",
    "SDIST_SHA256",
    "VAMP_REQUIREMENT",
    "MbmUnavailable",
    "RobotFiles",
    "fetch_robot",
    "fetch_sdist",
    "loadable_urdf",
    "mbm_cache",
]

#: The package and version whose sdist holds the problems.
VAMP_REQUIREMENT = "vamp-planner==0.6.4"
#: File name of the sdist and its SHA-256 (PyPI's published digest).
SDIST = "vamp_planner-0.6.4.tar.gz"
SDIST_SHA256 = "d3150c6b67ff941af9ad56480b31d3fb73b12211ea21dc684f7737b059f6daba"
#: What the sdist's metadata step imports (its ``build-system.requires``).
BUILD_REQUIREMENTS = ("scikit-build-core", "nanobind", "cmake", "typing_extensions")
#: Robots of the sdist: name -> URDF file name in ``resources/<name>/``.
ROBOTS = {"panda": "panda.urdf", "ur5": "ur5.urdf", "fetch": "fetch.urdf", "baxter": "baxter.urdf"}
#: Seconds pip may take for one step.
_TIMEOUT = 900.0


class MbmUnavailable(RuntimeError):
    """The MotionBenchMaker data cannot be fetched (no network, pip failing, wrong file)."""


@dataclass(frozen=True)
class RobotFiles:
    """A robot's files, extracted from the sdist.

    Attributes
    ----------
    robot : str
        The robot's name (``"panda"``, ``"ur5"``, ``"fetch"``, ``"baxter"``).
    root : Path
        The extracted ``resources/<robot>/`` folder.
    urdf : Path
        The URDF as shipped.
    loadable_urdf : Path
        The URDF with the fixes of :func:`loadable_urdf` (beside the original, so
        the mesh paths resolve alike).
    fixes : tuple of str
        What was changed in ``loadable_urdf`` (empty when nothing).
    problems : Path
        ``problems.tar.bz2``.
    srdf : Path or None
        The SRDF, when shipped.
    """

    robot: str
    root: Path
    urdf: Path
    loadable_urdf: Path
    fixes: tuple[str, ...]
    problems: Path
    srdf: Path | None


def mbm_cache() -> Path:
    """Return ``<cache>/mbm`` (created on demand)."""
    path = cache_dir() / "mbm"
    path.mkdir(parents=True, exist_ok=True)
    return path


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _howto(folder: Path) -> str:
    return (
        "to fetch it by hand: make a virtual environment with "
        f"`pip install {' '.join(BUILD_REQUIREMENTS)}`, then run its "
        "`pip download --no-deps --no-build-isolation --no-binary vamp-planner "
        f"{VAMP_REQUIREMENT} -d {folder}` (the file's SHA-256 must be {SDIST_SHA256})"
    )


def _venv(folder: Path) -> Path:
    """Return the pip of the download environment, making it on first use."""
    venv = folder / "venv"
    bindir = "Scripts" if os.name == "nt" else "bin"
    pip = venv / bindir / ("pip.exe" if os.name == "nt" else "pip")
    marker = venv / ".cloudprox-ready"
    if pip.is_file() and marker.is_file():
        return pip
    if venv.exists():
        shutil.rmtree(venv)
    howto = _howto(folder)
    run_command(
        [sys.executable, "-m", "venv", str(venv)],
        folder,
        f"cannot make the download environment {venv}",
        howto,
        error=MbmUnavailable,
        timeout=_TIMEOUT,
    )
    run_command(
        [str(pip), "install", "--disable-pip-version-check", "-q", *BUILD_REQUIREMENTS],
        folder,
        f"cannot install the sdist's metadata requirements ({', '.join(BUILD_REQUIREMENTS)}) "
        f"into {venv}",
        howto,
        error=MbmUnavailable,
        timeout=_TIMEOUT,
    )
    marker.write_text("ok\n")
    return pip


def fetch_sdist(folder: Path | None = None) -> Path:
    """Return the cached ``vamp_planner-0.6.4.tar.gz``, downloading it with pip if missing.

    Parameters
    ----------
    folder : Path, optional
        Where the sdist (and the download environment) live; :func:`mbm_cache`
        by default.

    Returns
    -------
    Path
        The sdist, its SHA-256 checked.

    Raises
    ------
    MbmUnavailable
        If the environment cannot be made, pip fails (no network: its output is
        quoted), or the file is not the published one.
    """
    folder = mbm_cache() if folder is None else folder
    folder.mkdir(parents=True, exist_ok=True)
    sdist = folder / SDIST
    if sdist.is_file():
        digest = _sha256(sdist)
        if digest == SDIST_SHA256:
            return sdist
        raise MbmUnavailable(
            f"{sdist}: SHA-256 {digest} differs from the published {SDIST_SHA256}; "
            "delete the file to download it again"
        )
    pip = _venv(folder)
    with tempfile.TemporaryDirectory(dir=folder, prefix="pip-") as tmp:
        cmd = [str(pip), "download", "--no-deps", "--no-build-isolation"]
        cmd += ["--no-binary", "vamp-planner", "--disable-pip-version-check"]
        cmd += [VAMP_REQUIREMENT, "-d", tmp]
        run_command(
            cmd,
            Path(tmp),
            f"cannot download the {VAMP_REQUIREMENT} sdist from PyPI",
            _howto(folder),
            error=MbmUnavailable,
            timeout=_TIMEOUT,
        )
        got = Path(tmp) / SDIST
        if not got.is_file():
            names = ", ".join(p.name for p in Path(tmp).iterdir()) or "nothing"
            raise MbmUnavailable(f"pip download produced {names}, not {SDIST}; {_howto(folder)}")
        digest = _sha256(got)
        if digest != SDIST_SHA256:
            raise MbmUnavailable(
                f"the downloaded {SDIST} has SHA-256 {digest}, not the published "
                f"{SDIST_SHA256}: refusing it"
            )
        os.replace(got, sdist)
    return sdist


_MIMIC = re.compile(r"<mimic\b[^>]*?(?:/>|>\s*</mimic>)")
_JOINT = re.compile(r"<joint\b[^>]*>.*?</joint>", re.DOTALL)


def loadable_urdf(text: str) -> tuple[str, list[str]]:
    """Return the URDF text with what :meth:`cloudprox.Robot.from_urdf` refuses removed.

    One fix: a ``<mimic>`` inside a ``fixed`` joint (the Panda's
    ``panda_finger_joint2`` mimics ``panda_finger_joint1``, both fixed at an
    opening of 6.5 cm) is dropped; a fixed joint follows nothing, so the
    kinematics are unchanged.

    Parameters
    ----------
    text : str
        The URDF.

    Returns
    -------
    tuple of (str, list of str)
        The fixed text and one line per change.
    """
    fixes: list[str] = []

    def fix(match: re.Match[str]) -> str:
        joint = match.group(0)
        head = joint[: joint.index(">") + 1]
        if re.search(r"""type\s*=\s*["']fixed["']""", head) and _MIMIC.search(joint):
            name = re.search(r"""name\s*=\s*["']([^"']*)["']""", head)
            fixes.append(f"dropped the mimic of fixed joint {name.group(1) if name else '?'}")
            return _MIMIC.sub("", joint)
        return joint

    return _JOINT.sub(fix, text), fixes


def _extract(sdist: Path, robot: str, dest: Path) -> None:
    prefix = f"{SDIST.removesuffix('.tar.gz')}/resources/{robot}/"
    tmp = Path(tempfile.mkdtemp(dir=dest.parent, prefix=f".{robot}-"))
    try:
        with tarfile.open(sdist, "r:gz") as tar:
            members = [m for m in tar.getmembers() if m.name.startswith(prefix)]
            if not members:
                raise MbmUnavailable(f"{sdist} holds no resources/{robot}/")
            for m in members:
                m.name = m.name[len(prefix) :]
            tar.extractall(tmp, members=[m for m in members if m.name], filter="data")
        if dest.exists():
            shutil.rmtree(dest)
        os.replace(tmp, dest)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp)


def fetch_robot(robot: str = "panda", folder: Path | None = None) -> RobotFiles:
    """Return a robot's MBM files, fetching and extracting the sdist first when needed.

    Parameters
    ----------
    robot : str
        One of :data:`ROBOTS`.
    folder : Path, optional
        The cache folder (:func:`mbm_cache` by default).

    Returns
    -------
    RobotFiles
        The extracted files.

    Raises
    ------
    ValueError
        If ``robot`` is not one of the sdist's robots.
    MbmUnavailable
        If the sdist cannot be fetched, or lacks the robot's files.
    """
    if robot not in ROBOTS:
        raise ValueError(f"unknown robot {robot!r}: the sdist has {', '.join(ROBOTS)}")
    folder = mbm_cache() if folder is None else folder
    base = folder / SDIST.removesuffix(".tar.gz")
    root = base / robot
    marker = root / ".cloudprox-extracted"
    if not (marker.is_file() and marker.read_text().strip() == SDIST_SHA256):
        sdist = fetch_sdist(folder)
        base.mkdir(parents=True, exist_ok=True)
        _extract(sdist, robot, root)
        marker.write_text(SDIST_SHA256 + "\n")
    urdf = root / ROBOTS[robot]
    problems = root / "problems.tar.bz2"
    for path in (urdf, problems):
        if not path.is_file():
            raise MbmUnavailable(f"{path} is missing from the extracted sdist; delete {root}")
    text, fixes = loadable_urdf(urdf.read_text())
    fixed = root / f"{robot}.cloudprox.urdf"
    if not fixed.is_file() or fixed.read_text() != text:
        write_atomically(fixed, text.encode())
    srdf = root / f"{robot}.srdf"
    return RobotFiles(
        robot, root, urdf, fixed, tuple(fixes), problems, srdf if srdf.is_file() else None
    )
