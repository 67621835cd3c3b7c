"""Random piano poses with exact signed distances, concentrated around contact.

A pose starts at a random place in the room (random yaw, a small random tilt)
where the piano is farther from everything than the distance wanted; it then
moves along a random direction (downwards or sideways) until the exact signed
distance to the room equals a target drawn from ``[-3, 10]`` sigma (or, for the
far share, from ``[10 sigma, 0.5 m]``, and for the deep share from ``[-8, -3]``
sigma, so that false negatives at penetrations beyond 3 sigma are measured):
:func:`cloudprox.exact_time_of_impact_many` finds the first pose along the line
at the target (shape casting to a gap, or past the first contact to a
penetration depth). The
target is drawn first and the start redrawn until it reaches it, so the targets
keep their designed distribution (rejecting targets instead favours the ones that
are easy to reach: penetrations). The exact signed distance of the final pose
(:func:`cloudprox.exact_proximity_many`: distance, or minus the EPA penetration
depth) is the ground truth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cloudprox._native import exact_proximity_many, exact_time_of_impact_many
from cloudprox.pose import from_rpy
from cloudprox.scenes import SceneObject

__all__ = ["QueryPoses", "draw_target_units", "sample_poses"]

FloatArray = npt.NDArray[np.float64]

#: Length of the line searched for the target distance (metres).
_REACH = 3.0
#: Rounds of fresh starts for the targets not yet reached.
_ROUNDS = 200


@dataclass(frozen=True)
class QueryPoses:
    """Poses of the piano and their exact answers.

    Attributes
    ----------
    poses : ndarray, shape (m, 4, 4)
    signed_distance : ndarray, shape (m,)
        Exact signed distance to the room (metres; negative: penetration depth).
    intersecting : ndarray of bool, shape (m,)
        Exact collision label.
    far : ndarray of bool, shape (m,)
        Whether the pose was drawn from the far share.
    """

    poses: FloatArray
    signed_distance: FloatArray
    intersecting: npt.NDArray[np.bool_]
    far: npt.NDArray[np.bool_]


def _translated(poses: FloatArray, dirs: FloatArray, t: FloatArray) -> FloatArray:
    out = poses.copy()
    out[:, :3, 3] += dirs * t[:, None]
    return out


def draw_target_units(
    n: int,
    rng: np.random.Generator,
    far_high: float,
    far_share: float = 0.2,
    deep_share: float = 0.1,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Target signed distances in units of sigma, and which are far.

    ``far_share`` of them uniform in ``[10, far_high]``, ``deep_share`` in
    ``[-8, -3]``, the rest in ``[-3, 10]``.
    """
    u = rng.random(n)
    far, deep = u < far_share, u >= 1.0 - deep_share
    unit = np.where(
        far,
        rng.uniform(10.0, far_high, n),
        np.where(deep, rng.uniform(-8.0, -3.0, n), rng.uniform(-3.0, 10.0, n)),
    )
    return unit, far


def sample_poses(
    piano: SceneObject,
    room: SceneObject,
    n: int,
    sigma: float,
    rng: np.random.Generator,
    far_share: float = 0.2,
    deep_share: float = 0.1,
    max_tilt_deg: float = 10.0,
) -> QueryPoses:
    """Draw ``n`` piano poses, ``1 - far_share - deep_share`` of them in [-3, 10] sigma.

    Parameters
    ----------
    piano, room : SceneObject
        The moving object (own frame) and the environment (world frame).
    n : int
        Number of poses.
    sigma : float
        The noise level, the unit of the target distances (metres).
    rng : numpy.random.Generator
        Source of randomness.
    far_share : float, default 0.2
        Share of poses with a target distance in ``[10 sigma, 0.5 m]``.
    deep_share : float, default 0.1
        Share of poses with a target penetration in ``[3, 8]`` sigma.
    max_tilt_deg : float, default 10
        Largest roll and pitch (degrees).

    Returns
    -------
    QueryPoses
    """
    lo, hi = room.bounds()
    # Targets first, then starts drawn until each target is reached: redrawing
    # the start (never the target) keeps the targets' distribution as designed.
    unit, far = draw_target_units(
        n, rng, max(0.5 / sigma, 12.0), far_share=far_share, deep_share=deep_share
    )
    target = unit * sigma
    poses = np.empty((n, 4, 4))
    pending = np.arange(n)
    tilt = math.radians(max_tilt_deg)
    for _ in range(_ROUNDS):
        if len(pending) == 0:
            break
        m = len(pending)
        tg = target[pending]
        starts = np.stack(
            [
                # Keywords in this order keep the draws' order (translation first).
                from_rpy(
                    translation=(
                        rng.uniform(lo[0] + 0.5, hi[0] - 0.5),
                        rng.uniform(lo[1] + 0.5, hi[1] - 0.5),
                        rng.uniform(0.65, 2.4),
                    ),
                    rpy=(
                        rng.uniform(-tilt, tilt),
                        rng.uniform(-tilt, tilt),
                        rng.uniform(0, 2 * math.pi),
                    ),
                )
                for _ in range(m)
            ]
        )
        # Directions: polar angle from straight down uniform in [0, 100] degrees.
        polar = np.radians(rng.uniform(0.0, 100.0, m))
        azim = rng.uniform(0.0, 2 * math.pi, m)
        dirs = np.stack(
            [np.sin(polar) * np.cos(azim), np.sin(polar) * np.sin(azim), -np.cos(polar)], 1
        )
        # The first pose along the line at the target (0 where the start is
        # already at or within it, inf where the target is out of reach).
        travel = exact_time_of_impact_many(
            piano.exact, room.exact, starts, dirs, target=tg, max_travel=_REACH
        )
        ok = np.isfinite(travel) & (travel > 0.0)
        poses[pending[ok]] = _translated(starts[ok], dirs[ok], travel[ok])
        pending = pending[~ok]
    if len(pending):
        raise RuntimeError(
            f"could not place {len(pending)} of {n} poses at their target distances "
            f"in {_ROUNDS} rounds (targets {np.round(target[pending], 3).tolist()} m)"
        )
    r = exact_proximity_many(piano.exact, room.exact, poses)
    return QueryPoses(
        poses=poses,
        signed_distance=np.asarray(r.signed_distance, dtype=float),
        intersecting=np.asarray(r.intersecting, dtype=bool),
        far=far,
    )
