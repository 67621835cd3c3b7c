"""Shared fixtures (two noisy spheres with fixed noise) and the suite's marks.

Two marks split the suite (``pyproject.toml`` declares them): ``network``, the
tests that read real files fetched into the cache from package registries
(crates.io, PyPI, Debian), and ``slow``, the full quick reproduction. A
developer's fast run is ``python3 -m pytest -m "not network and not slow"``;
``scripts/test.sh`` (and so CI) runs them all in one run, the slow file first.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from tests.helpers import N_POINTS, RADIUS, SIGMA
from tests.robots import ARM_URDF


@pytest.fixture(scope="module")
def arm_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The test arm's URDF (``tests.robots.ARM_URDF``) in a file."""
    path = tmp_path_factory.mktemp("arm") / "arm.urdf"
    path.write_text(ARM_URDF)
    return path


@pytest.fixture(scope="module")
def arm(arm_path: Path) -> cp.Robot:
    """The test arm, loaded from its file."""
    return cp.Robot.from_urdf(arm_path)


@pytest.fixture(scope="session")
def sphere_points() -> tuple[np.ndarray, np.ndarray]:
    """Two noisy samplings (seeds 1 and 2) of one sphere of radius 0.1 at the origin."""
    base = cp.synthetic.sample_sphere(N_POINTS, RADIUS)
    return cp.synthetic.add_noise(base, SIGMA, seed=1), cp.synthetic.add_noise(base, SIGMA, seed=2)


@pytest.fixture(scope="session")
def spheres(sphere_points: tuple[np.ndarray, np.ndarray]) -> tuple[cp.PointCloud, cp.PointCloud]:
    pa, pb = sphere_points
    return cp.PointCloud(pa, sigma=SIGMA), cp.PointCloud(pb, sigma=SIGMA)


#: Modules whose every test reads real files from the cache.
NETWORK_MODULES = {"test_io_real", "test_datasets"}
#: Fixtures that fetch real files (the Panda URDF and its meshes).
NETWORK_FIXTURES = {"panda", "readme_folder"}
#: Tests that fetch real files themselves.
NETWORK_TESTS = {"test_readme_robot_planning"}
#: Fixtures that run the full quick reproduction.
SLOW_FIXTURES = {"quick_run"}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark the tests that need the network or the full reproduction."""
    for item in items:
        fixtures = set(getattr(item, "fixturenames", ()))
        module = item.module.__name__.rsplit(".", 1)[-1] if item.module else ""
        if (
            module in NETWORK_MODULES
            or fixtures & NETWORK_FIXTURES
            or item.originalname in NETWORK_TESTS
        ):
            item.add_marker(pytest.mark.network)
        if fixtures & SLOW_FIXTURES:
            item.add_marker(pytest.mark.slow)
    # The slow tests' files first: with two workers (one file each) the
    # longest file then runs beside the others instead of after them.
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)
