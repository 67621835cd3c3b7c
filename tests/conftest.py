"""Shared fixtures: two noisy spheres with fixed noise."""

from __future__ import annotations

import numpy as np
import pytest

import cloudprox as cp
from tests.helpers import N_POINTS, RADIUS, SIGMA


@pytest.fixture(scope="session")
def sphere_points() -> tuple[np.ndarray, np.ndarray]:
    """Two noisy samplings (seeds 1 and 2) of one sphere of radius 0.1 at the origin."""
    base = cp.synthetic.sample_sphere(N_POINTS, RADIUS)
    return cp.synthetic.add_noise(base, SIGMA, seed=1), cp.synthetic.add_noise(base, SIGMA, seed=2)


@pytest.fixture(scope="session")
def spheres(sphere_points: tuple[np.ndarray, np.ndarray]) -> tuple[cp.PointCloud, cp.PointCloud]:
    pa, pb = sphere_points
    return cp.PointCloud(pa, sigma=SIGMA), cp.PointCloud(pb, sigma=SIGMA)
