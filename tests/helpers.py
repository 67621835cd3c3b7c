"""Helpers shared by the tests: the sphere setup's constants, poses, the normal cdf."""

from __future__ import annotations

import math

import numpy as np

from cloudprox.pose import from_translation

SIGMA = 0.002
RADIUS = 0.1
N_POINTS = 1500


def sphere_gap_pose(gap_sigmas: float) -> np.ndarray:
    """Pose of sphere B so that the two sphere surfaces are `gap_sigmas` sigma apart."""
    return from_translation((2.0 * RADIUS + gap_sigmas * SIGMA, 0.0, 0.0))


def phi(x: np.ndarray) -> np.ndarray:
    """Standard normal cdf, elementwise."""
    return np.array([0.5 * math.erfc(-v / math.sqrt(2.0)) for v in np.ravel(x)]).reshape(
        np.shape(x)
    )
