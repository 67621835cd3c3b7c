"""Robots for the robot tests: a hand-written arm with analytic kinematics, and the
Franka Panda URDF with its collision meshes from a pinned PyPI wheel.

The Panda comes from ``gym-ignition-models==1.1.1`` (the wheel that
:mod:`tests.realfiles` already pins for two of its meshes): ``panda/panda.urdf``
(9 joints: 7 revolute, 2 prismatic fingers on a tree; mesh URIs
``file://meshes/collision/*.stl``, relative to the URDF) and its ten collision
STLs, extracted into ``<cache>/realfiles/pypi/gym-ignition-models-1.1.1/panda/``,
every file checked against its SHA-256.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import zipfile
from pathlib import Path

import numpy as np

from cloudprox.datasets import cache_dir, write_atomically
from cloudprox.pose import from_rpy, from_translation
from tests.realfiles import Package, RealFileMismatch, RealFileUnavailable, fetch_archive

GYM_IGNITION_MODELS = Package(
    "pypi",
    "gym-ignition-models",
    "1.1.1",
    "gym_ignition_models-1.1.1-py3-none-any.whl",
    "946d2a26197285a7f0de09edde030ebdbc143ccda04d0b2d598273afa99c54fb",
    15079949,
)

#: Files of the Panda model: path under ``gym_ignition_models/panda/`` -> (SHA-256, size).
PANDA_FILES: dict[str, tuple[str, int]] = {
    "panda.urdf": ("2b08b2ef9803d93762eb1b19fa126bb56e5c42e0cc80812ae632b01a80048383", 11640),
    "meshes/collision/finger.stl": (
        "2d07a740392f3b9b0816f65d64fff9927d3d57c897870fc4b6ff9c56fff3a0c8",
        1684,
    ),
    "meshes/collision/hand.stl": (
        "94493e94f30fe940f2c8ca2f155c3bbe67bbff406d3edf5e261670d2f0f6e2ed",
        10084,
    ),
    "meshes/collision/link0.stl": (
        "dfc6d94330de8ddb005b311bfdba9f3b8e1aa7c256b71592ee7ff32cb9a9a5aa",
        10084,
    ),
    "meshes/collision/link1.stl": (
        "e41a39a94108fcf56aacff603fc91ec80541f4c1af17b51a0de5617f5566e6d2",
        15084,
    ),
    "meshes/collision/link2.stl": (
        "370f7605a0fae3529db169ded50f52f171024aa792d4d773bc84197301f6a039",
        15084,
    ),
    "meshes/collision/link3.stl": (
        "0a8d638b9349c6c0eefc4e888636ac4838c4b27170f18a51699321118af709c1",
        15084,
    ),
    "meshes/collision/link4.stl": (
        "0180ebb5772ec9840cb049750cffb29a9ddc90311752a16ea34757782ef9e48d",
        15084,
    ),
    "meshes/collision/link5.stl": (
        "dd17e688c7870e722283525879643d53a74c0024d328b0e14b034b54c8b6c31a",
        15084,
    ),
    "meshes/collision/link6.stl": (
        "20b768e99a0e0440b5754dcca108016434e57937cc356acd9c352ccd3cb27f77",
        10084,
    ),
    "meshes/collision/link7.stl": (
        "92ac6afcf7574c034d3170d8a68e95ac9048ab9d0dd5bbd8311b86e551b9ab1c",
        10084,
    ),
}


def _ok(path: Path, sha256: str, size: int) -> bool:
    if not path.is_file() or path.stat().st_size != size:
        return False
    return hashlib.sha256(path.read_bytes()).hexdigest() == sha256


def panda_urdf() -> Path:
    """Return the path of the Panda's URDF, its collision meshes beside it.

    Raises
    ------
    tests.realfiles.RealFileUnavailable
        If the wheel is not cached and PyPI cannot be reached.
    tests.realfiles.RealFileMismatch
        If the wheel or a file differs from the pinned one.
    """
    pkg = GYM_IGNITION_MODELS
    root = cache_dir() / "realfiles" / "pypi" / f"{pkg.name}-{pkg.version}" / "panda"
    if all(_ok(root / rel, sha, size) for rel, (sha, size) in PANDA_FILES.items()):
        return root / "panda.urdf"
    wheel = fetch_archive(pkg)
    with zipfile.ZipFile(wheel) as zf:
        for rel, (sha, size) in PANDA_FILES.items():
            content = zf.read(f"gym_ignition_models/panda/{rel}")
            digest = hashlib.sha256(content).hexdigest()
            if digest != sha or len(content) != size:
                raise RealFileMismatch(
                    f"{wheel}!panda/{rel}: SHA-256 {digest} ({len(content)} bytes), "
                    f"expected {sha} ({size} bytes)"
                )
            write_atomically(root / rel, content)
    return root / "panda.urdf"


def panda_urdf_or_skip() -> Path:
    """:func:`panda_urdf`, or skip the test when PyPI cannot be reached (fail on CI)."""
    import pytest

    try:
        return panda_urdf()
    except RealFileUnavailable as exc:
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI=true: the Panda URDF must be fetched, but {exc}")
        pytest.skip(f"Panda URDF unavailable: {exc}")


def readme_block(tag: str) -> str:
    """Return the README's fenced code block that follows ``<!-- readme-test: TAG -->``."""
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    m = re.search(rf"<!-- readme-test: {tag} -->\n```\w+\n(.*?)```", text, re.S)
    assert m, f"README has no block tagged readme-test: {tag}"
    return m.group(1)


#: A three-joint arm on a box base (the same as the Rust tests'):
#: ``j1`` revolute about z, ``j2`` revolute about y, ``j3`` prismatic along x,
#: ``j4`` prismatic along y mimicking ``j3`` (x 2, + 0.01), a fixed tool and a
#: continuous ``j5`` carrying a link without geometry.
ARM_URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="link1">
    <collision><origin xyz="0 0 0.1"/>
      <geometry><cylinder radius="0.03" length="0.2"/></geometry></collision>
  </link>
  <link name="link2">
    <collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry></collision>
  </link>
  <link name="link3">
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="link4">
    <collision><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <link name="tool">
    <collision><geometry><capsule radius="0.01" length="0.04"/></geometry></collision>
  </link>
  <link name="wheel"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="j3" type="prismatic">
    <parent link="link2"/><child link="link3"/>
    <origin xyz="0.3 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/>
  </joint>
  <joint name="j4" type="prismatic">
    <parent link="link2"/><child link="link4"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.3" effort="1" velocity="1"/>
    <mimic joint="j3" multiplier="2" offset="0.01"/>
  </joint>
  <joint name="tool_joint" type="fixed">
    <parent link="link2"/><child link="tool"/>
    <origin xyz="0.3 0 0.05" rpy="0 0 1.5707963267948966"/>
  </joint>
  <joint name="j5" type="continuous">
    <parent link="base"/><child link="wheel"/>
    <origin xyz="0 0.3 0"/><axis xyz="0 0 1"/>
  </joint>
</robot>
"""


def arm_poses(q: np.ndarray) -> dict[str, np.ndarray]:
    """Hand-computed link poses of the arm at ``q = [j1, j2, j3, j5]``, root at identity.

    Composed from the joints' frames by hand (yaw ``a`` then pitch ``b`` at the
    shoulder, the prismatic ``c`` along x, the tool turned a quarter about z).
    """
    a, b, c, w = (float(v) for v in q)
    shoulder = from_rpy((0.0, b, a), (0.0, 0.0, 0.3))  # Rz(a) Ry(b), at o2
    return {
        "base": np.eye(4),
        "link1": from_rpy((0.0, 0.0, a), (0.0, 0.0, 0.1)),
        "link2": shoulder,
        "link3": shoulder @ from_translation((0.3 + c, 0.0, 0.0)),
        "link4": shoulder @ from_translation((0.3, 2.0 * c + 0.01, 0.0)),
        "tool": shoulder @ from_rpy((0.0, 0.0, math.pi / 2), (0.3, 0.0, 0.05)),
        "wheel": from_rpy((0.0, 0.0, w), (0.0, 0.3, 0.0)),
    }


def wall(x0: float, z0: float, half: float, sigma: float, seed: int) -> np.ndarray:
    """Noisy points of the square patch of the plane ``x = x0`` around ``(x0, 0, z0)``."""
    g = np.arange(-half, half + 1e-9, 0.01)
    yy, zz = np.meshgrid(g, g + z0, indexing="ij")
    pts = np.column_stack([np.full(yy.size, x0), yy.ravel(), zz.ravel()])
    return pts + np.random.default_rng(seed).normal(0.0, sigma, pts.shape)
