"""Sensor noise for the experiments: isotropic, or anisotropic along viewing rays.

A noise model gives each surface point a 3x3 sensor covariance and draws the
noisy positions from it. The anisotropic model mimics a depth camera at a fixed
origin: the standard deviation along the viewing ray is ``sigma`` and across it
``sigma * lateral_ratio`` (structured-light and stereo cameras err mostly in depth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cloudprox._native import ray_covariances

__all__ = ["NoiseModel"]

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class NoiseModel:
    """Gaussian sensor noise of one experiment level.

    Attributes
    ----------
    sigma : float
        Standard deviation (metres): in every direction when isotropic, along the
        viewing ray otherwise.
    origin : tuple of float or None
        Sensor origin in the cloud's own frame; ``None`` means isotropic noise.
    lateral_ratio : float
        Lateral over axial standard deviation of the anisotropic model.
    """

    sigma: float
    origin: tuple[float, float, float] | None = None
    lateral_ratio: float = 1.0 / 3.0

    @property
    def isotropic(self) -> bool:
        """Whether the covariance is ``sigma^2 I``."""
        return self.origin is None

    def covariances(self, points: FloatArray) -> FloatArray:
        """Per-point sensor covariances ``(n, 3, 3)`` for surface points ``(n, 3)``.

        Anisotropic: the core's :func:`cloudprox.ray_covariances` from ``origin``.
        """
        if self.origin is None:
            eye = np.broadcast_to(np.eye(3), (len(points), 3, 3))
            return np.ascontiguousarray(self.sigma**2 * eye)
        return np.asarray(
            ray_covariances(points, self.sigma, self.sigma * self.lateral_ratio, origin=self.origin)
        )

    def draw(self, points: FloatArray, rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
        """Noisy copies of ``points`` and their sensor covariances.

        Returns
        -------
        noisy : ndarray, shape (n, 3)
        covariances : ndarray, shape (n, 3, 3)
        """
        cov = self.covariances(points)
        z = rng.standard_normal(points.shape)
        if self.origin is None:
            return points + self.sigma * z, cov
        chol = np.linalg.cholesky(cov)
        return points + np.einsum("nij,nj->ni", chol, z), cov
