"""Helpers shared by the tests: the sphere setup's constants, poses, the normal cdf."""

from __future__ import annotations

import math

import numpy as np

SIGMA = 0.002
RADIUS = 0.1
N_POINTS = 1500


def translation(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def sphere_gap_pose(gap_sigmas: float) -> np.ndarray:
    """Pose of sphere B so that the two sphere surfaces are `gap_sigmas` sigma apart."""
    return translation(2.0 * RADIUS + gap_sigmas * SIGMA)


def phi(x: np.ndarray) -> np.ndarray:
    """Standard normal cdf, elementwise."""
    return np.array([0.5 * math.erfc(-v / math.sqrt(2.0)) for v in np.ravel(x)]).reshape(
        np.shape(x)
    )
