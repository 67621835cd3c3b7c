"""Side-by-side benchmark of cloudprox and comparison engines on the same clouds.

Two noisy spheres (radius 0.1 m, ``sigma`` = 2 mm) in three configurations: apart
by 10 sigma, near (1 sigma) and interpenetrating (-3 sigma). Engines, all in this
process and on the same points:

``cloudprox``
    :func:`cloudprox.collide` with the default options.
``kdtree``
    Nearest-neighbour gap baseline: ``d`` = smallest distance from a point of A to
    a point of B (``scipy.spatial.cKDTree``), score ``Phi(-(d - 2 sigma) / sigma)``.
``fcl``
    python-fcl: every point a cube of half-size ``sigma`` (12 triangles) in one
    ``fcl.BVHModel`` per cloud, ``fcl.collide`` between the two (a yes/no answer).

Each engine builds its structures once (``prep``), outside the timed queries; the
query time is the median over repeats.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cloudprox._native import PointCloud, collide
from cloudprox.pose import from_translation
from cloudprox.synthetic import add_noise, sample_sphere

__all__ = ["CONFIGS", "BenchRow", "make_spheres", "run_bench"]

#: Configuration name -> surface gap in units of sigma.
CONFIGS: dict[str, float] = {"apart": 10.0, "near": 1.0, "interpenetrating": -3.0}


@dataclass(frozen=True)
class BenchRow:
    """One engine on one configuration.

    Attributes
    ----------
    config : str
        Configuration name (a key of :data:`CONFIGS`).
    engine : str
        Engine name.
    median_ms : float
        Median query time (milliseconds).
    prep_ms : float
        Time to build the engine's structures, once per engine (milliseconds).
    answer : str
        What the engine answered (probability, score or yes/no).
    """

    config: str
    engine: str
    median_ms: float
    prep_ms: float
    answer: str


def make_spheres(
    n: int, sigma: float = 0.002, radius: float = 0.1
) -> tuple[np.ndarray, np.ndarray]:
    """Two noisy samplings of the same sphere (seeds 1 and 2), each ``(n, 3)``."""
    base = sample_sphere(n, radius)
    return add_noise(base, sigma, seed=1), add_noise(base, sigma, seed=2)


def _phi(x: float) -> float:
    return 0.5 * math.erfc(-x / math.sqrt(2.0))


class _Cloudprox:
    name = "cloudprox"

    @staticmethod
    def load() -> None:
        """Import what the engine needs (outside the timed preparation)."""

    def __init__(self, pa: np.ndarray, pb: np.ndarray, sigma: float) -> None:
        self.a = PointCloud(pa, sigma=sigma)
        self.b = PointCloud(pb, sigma=sigma)
        collide(self.a, self.b, pose_b=from_translation((1.0, 0.0, 0.0)))  # builds both hierarchies

    def query(self, offset: float) -> str:
        r = collide(self.a, self.b, pose_b=from_translation((offset, 0.0, 0.0)))
        return f"P={r.probability:.3g} {r.state}"


class _KdTree:
    name = "kdtree"

    @staticmethod
    def load() -> None:
        """Import what the engine needs (outside the timed preparation)."""
        import scipy.spatial  # type: ignore[import-untyped]  # noqa: F401

    def __init__(self, pa: np.ndarray, pb: np.ndarray, sigma: float) -> None:
        from scipy.spatial import cKDTree  # type: ignore[import-untyped]

        self.pa = pa
        self.tree = cKDTree(pb)
        self.sigma = sigma

    def query(self, offset: float) -> str:
        # B is moved by +offset along x: query A in B's frame.
        d, _ = self.tree.query(self.pa - np.array([offset, 0.0, 0.0]), k=1)
        gap = float(np.min(d))
        return f"score={_phi(-(gap - 2.0 * self.sigma) / self.sigma):.3g}"


class _Fcl:
    name = "fcl"

    @staticmethod
    def load() -> None:
        """Import what the engine needs (outside the timed preparation)."""
        import fcl  # type: ignore[import-untyped]  # noqa: F401

    def __init__(self, pa: np.ndarray, pb: np.ndarray, sigma: float) -> None:
        import fcl  # type: ignore[import-untyped]

        self.fcl = fcl
        self.a = fcl.CollisionObject(_cubes_model(fcl, pa, sigma), fcl.Transform())
        self.b = fcl.CollisionObject(_cubes_model(fcl, pb, sigma), fcl.Transform())

    def query(self, offset: float) -> str:
        self.b.setTranslation(np.array([offset, 0.0, 0.0]))
        hit = self.fcl.collide(
            self.a, self.b, self.fcl.CollisionRequest(), self.fcl.CollisionResult()
        )
        return "collision" if hit else "free"


_CUBE_CORNERS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
# Two triangles per face: x = -1, x = +1, y = -1, y = +1, z = -1, z = +1.
_CUBE_TRIANGLES = np.concatenate(
    [
        [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1]],
        [[2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]],
    ]
)


def _cubes_model(fcl: object, points: np.ndarray, half: float) -> object:
    """One BVH mesh of a cube of half-size ``half`` around every point."""
    n = len(points)
    verts = (points[:, None, :] + half * _CUBE_CORNERS[None, :, :]).reshape(-1, 3)
    tris = (_CUBE_TRIANGLES[None, :, :] + 8 * np.arange(n)[:, None, None]).reshape(-1, 3)
    model = fcl.BVHModel()  # type: ignore[attr-defined]
    model.beginModel(len(verts), len(tris))
    model.addSubModel(verts, tris)
    model.endModel()
    return model


def run_bench(
    n: int = 10_000,
    repeat: int = 5,
    sigma: float = 0.002,
    radius: float = 0.1,
    on_step: Callable[[str], None] | None = None,
) -> tuple[list[BenchRow], list[str]]:
    """Run every available engine on every configuration.

    Parameters
    ----------
    n : int, default 10000
        Points per sphere.
    repeat : int, default 5
        Timed queries per engine and configuration.
    sigma : float, default 0.002
        Noise standard deviation (metres).
    radius : float, default 0.1
        Sphere radius (metres).
    on_step : callable, optional
        Called with a description after every timed query (for progress bars).

    Returns
    -------
    rows : list of BenchRow
        One row per available engine and configuration.
    notes : list of str
        Engines that were skipped, and why.
    """
    if n < 10 or repeat < 1:
        raise ValueError(f"need n >= 10 and repeat >= 1, got n = {n}, repeat = {repeat}")
    pa, pb = make_spheres(n, sigma, radius)
    rows: list[BenchRow] = []
    notes: list[str] = []
    for engine_type in (_Cloudprox, _KdTree, _Fcl):
        try:
            engine_type.load()
        except ImportError as e:
            notes.append(f"{engine_type.name} skipped ({e})")
            if on_step is not None:
                for _ in range(repeat * len(CONFIGS)):
                    on_step(f"{engine_type.name} skipped")
            continue
        t0 = time.perf_counter()
        engine = engine_type(pa, pb, sigma)
        prep_ms = 1e3 * (time.perf_counter() - t0)
        for config, gap in CONFIGS.items():
            offset = 2.0 * radius + gap * sigma
            times = []
            answer = ""
            for _ in range(repeat):
                t = time.perf_counter()
                answer = engine.query(offset)
                times.append(1e3 * (time.perf_counter() - t))
                if on_step is not None:
                    on_step(f"{engine_type.name} / {config}")
            rows.append(
                BenchRow(config, engine_type.name, float(np.median(times)), prep_ms, answer)
            )
    order = {c: k for k, c in enumerate(CONFIGS)}
    rows.sort(key=lambda r: order[r.config])  # stable: engines keep their order
    return rows, notes


def engine_names() -> tuple[str, ...]:
    """Names of the engines :func:`run_bench` tries, in order."""
    return (_Cloudprox.name, _KdTree.name, _Fcl.name)
