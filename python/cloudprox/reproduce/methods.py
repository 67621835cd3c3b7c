"""The methods compared on the same noisy clouds: cloudprox and the baselines.

Every method answers a batch of piano poses against one draw of the two clouds
with a score (higher = more likely in collision), a state (``"free"``,
``"contact"``, ``"collision"``) and a time per query (seconds; ``nan`` for a query
answered but not timed on its own, see :func:`cloudprox_answers`). Preparation
that a user does once per cloud (trees, hierarchies, reconstructions) is not
timed per query.

Baselines, each with parameters set from the data, not tuned to the scene:

``nn-gap``
    ``P = max_i Phi(-(d_i - 2 s_i) / s_i)`` over the piano's points, ``d_i`` the
    distance to the nearest room point and ``s_i = sqrt(s_a^2 + s_b^2)`` the two
    points' largest sensor standard deviations; the same thresholds as cloudprox.
``collision-map``
    ODE-style, as ROS's collision map: every point an axis-aligned cube of the
    map resolution ``r`` (world frame); collision iff two cubes overlap
    (Chebyshev distance below ``r``). ``r`` is the sampling spacing (see
    :func:`sampling_spacing`).
``spheres``
    Every point a sphere of one fixed radius ``r / sqrt(2)`` (the disc that covers
    a square cell of the sampling); collision iff two spheres overlap.
``reconstruct``
    A triangle mesh reconstructed from each cloud (screened Poisson, parameters
    from spacing and noise), then the exact triangle-vs-triangle check
    (:mod:`cloudprox.reproduce.reconstruct`). Score: ``1`` when the surfaces
    cross, else minus their distance; the reconstructions are made once per draw
    and not timed per query.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree
from scipy.special import ndtr

from cloudprox._native import (
    CollisionRequest,
    CollisionResult,
    ExactShape,
    PointCloud,
    collide_many,
    exact_proximity,
    exact_proximity_many,
)
from cloudprox.reproduce.reconstruct import reconstruct_many, surface_shape

__all__ = [
    "AGGREGATIONS",
    "PAPER_AGGREGATIONS",
    "POINT_BASELINES",
    "Draw",
    "MethodAnswer",
    "PointClusters",
    "cloudprox_answer",
    "cloudprox_answers",
    "collision_map_answer",
    "nn_gap_answer",
    "point_baseline_answers",
    "query_groups",
    "reconstruct_answer",
    "sampling_spacing",
    "sphere_union_answer",
    "states_from",
    "timed_subset",
    "variant_answers",
    "variant_name",
]

FloatArray = npt.NDArray[np.float64]

#: cloudprox's default thresholds (P >= A: collision, P <= B: free), read from the
#: core's defaults (``CollisionRequest()``).
THRESHOLD_COLLISION = CollisionRequest().threshold_collision
THRESHOLD_FREE = CollisionRequest().threshold_free
#: Queries of the reconstruction baseline timed one by one.
TIMED_QUERIES = 30
#: Share of the poses whose queries :func:`timed_subset` times (one in this
#: many), and the fewest it times (all of fewer poses).
TIMED_SHARE, TIMED_LEAST = 8, 200
#: Cells of :class:`PointClusters` along a cloud's longest side.
CLUSTER_CELLS = 8
#: The baselines on the points themselves (:func:`point_baseline_answers`).
POINT_BASELINES = ("nn-gap", "collision-map", "spheres")
#: The points model's aggregations: the surface one and the paper's three.
AGGREGATIONS = ("surface", "max", "union", "independent")
#: The paper's aggregations: one points-model query gives all three
#: (``CollisionResult.point_aggregates``).
PAPER_AGGREGATIONS = ("max", "union", "independent")


@dataclass(frozen=True)
class MethodAnswer:
    """A method's answers for a batch of poses.

    Attributes
    ----------
    score : ndarray, shape (m,)
        Higher means more likely in collision (a probability where the method has one).
    state : ndarray of str, shape (m,)
        ``"free"``, ``"contact"`` or ``"collision"``.
    seconds : ndarray, shape (m,)
        Time per query (``nan`` where a query was answered but not timed on
        its own).
    """

    score: FloatArray
    state: npt.NDArray[np.str_]
    seconds: FloatArray


def states_from(p: FloatArray) -> npt.NDArray[np.str_]:
    """States from probabilities with the default thresholds."""
    return np.where(
        p >= THRESHOLD_COLLISION, "collision", np.where(p <= THRESHOLD_FREE, "free", "contact")
    )


@dataclass(frozen=True)
class PointClusters:
    """Points grouped into the cubes of a grid, each with its centre and radius.

    A point ``p`` of a cluster (centre ``c``, radius ``rho``: the largest
    Euclidean distance of its points to ``c``) within ``reach`` of a point ``q``
    has ``|c - q| <= rho + reach`` (the triangle inequality; in the max norm too,
    which is at most the Euclidean). So the clusters whose centres have no room
    point within that hold no point within ``reach``, and the point baselines
    query only the points of the others: the same answers, in a fraction of the
    time where a small part of the piano is near the room. The grid has
    :data:`CLUSTER_CELLS` cells along the cloud's longest side (rigid motions
    change no distance, so the clusters are made once per cloud).
    """

    centres: FloatArray
    radius: FloatArray
    #: Cluster of each point.
    label: npt.NDArray[np.intp]

    @classmethod
    def of(cls, points: FloatArray) -> PointClusters:
        """Cluster ``points`` (shape ``(n, 3)``, at least one)."""
        lo = points.min(axis=0)
        extent = float(np.max(points.max(axis=0) - lo))
        cell = extent / CLUSTER_CELLS if extent > 0.0 else 1.0
        keys = np.floor((points - lo) / cell).astype(np.int64)
        _, label = np.unique(keys, axis=0, return_inverse=True)
        label = label.ravel()
        k = int(label.max()) + 1
        counts = np.bincount(label, minlength=k).astype(float)
        centres = np.stack(
            [np.bincount(label, weights=points[:, i], minlength=k) for i in range(3)], axis=1
        )
        centres /= counts[:, None]
        radius = np.zeros(k)
        np.maximum.at(radius, label, np.linalg.norm(points - centres[label], axis=1))
        return cls(centres, radius, label)


@dataclass
class Draw:
    """One draw of the noise on both clouds, with everything prepared from it.

    Attributes
    ----------
    piano_points, room_points : ndarray
        Noisy points (piano frame, world frame).
    piano_sensor_cov, room_sensor_cov : ndarray, shape (n, 3, 3)
        Sensor covariances.
    room_noise_correlation : float
        Correlation of the room's sensor noise within a surface element (0:
        independent; a depth camera's from its model).
    """

    piano_points: FloatArray
    piano_sensor_cov: FloatArray
    room_points: FloatArray
    room_sensor_cov: FloatArray
    room_noise_correlation: float = 0.0
    _cache: dict[str, object] = field(default_factory=dict, repr=False)

    def clouds(self) -> tuple[PointCloud, PointCloud]:
        """Cloudprox clouds: sensor covariance plus estimated discretization error."""
        if "clouds" not in self._cache:
            self._cache["clouds"] = (
                PointCloud(self.piano_points, cov=self.piano_sensor_cov, discretization=True),
                PointCloud(
                    self.room_points,
                    cov=self.room_sensor_cov,
                    discretization=True,
                    noise_correlation=self.room_noise_correlation,
                ),
            )
        return self._cache["clouds"]  # type: ignore[return-value]

    def room_tree(self) -> cKDTree:
        """k-d tree of the room's points."""
        if "tree" not in self._cache:
            self._cache["tree"] = cKDTree(self.room_points)
        return self._cache["tree"]  # type: ignore[return-value]

    def piano_clusters(self) -> PointClusters:
        """Return the piano's points grouped into cubes (own frame; :class:`PointClusters`)."""
        if "clusters" not in self._cache:
            self._cache["clusters"] = PointClusters.of(self.piano_points)
        return self._cache["clusters"]  # type: ignore[return-value]

    def near_piano_points(
        self, pose: FloatArray, reach: float, norm: float = 2.0
    ) -> npt.NDArray[np.intp]:
        """Return the piano points (indices, ascending) that may have a room point in ``reach``.

        Every piano point with a room point closer than ``reach`` (``norm``-distance,
        2 or infinity) at ``pose`` is among them: exact, not an approximation
        (see :class:`PointClusters`).
        """
        if not np.isfinite(reach):
            return np.arange(len(self.piano_points))
        cl = self.piano_clusters()
        centres = _world(cl.centres, pose)
        # Margins for the rounding of the distances (relative) and of the
        # coordinates (a few ulps of the largest, for far-off origins).
        tree = self.room_tree()
        scale = max(float(np.abs(centres).max()), float(np.abs([tree.maxes, tree.mins]).max()), 1.0)
        bound = (reach + cl.radius) * (1.0 + 1e-9) + 16.0 * np.finfo(float).eps * scale
        d, _ = tree.query(centres, p=norm, distance_upper_bound=float(bound.max()))
        return np.flatnonzero((d <= bound)[cl.label])

    def sensor_std(self) -> tuple[FloatArray, FloatArray]:
        """Largest sensor standard deviation per point, piano and room (core: ``sigma_max``)."""
        if "std" not in self._cache:
            self._cache["std"] = tuple(
                np.asarray(PointCloud(p, cov=c).sigma_max)
                for p, c in (
                    (self.piano_points, self.piano_sensor_cov),
                    (self.room_points, self.room_sensor_cov),
                )
            )
        return self._cache["std"]  # type: ignore[return-value]


def reconstruct_draws(
    draws: list[Draw], spacing: float, sigma: float, pool: Executor | None = None
) -> None:
    """Reconstruct both clouds of every draw not yet reconstructed (kept in its cache).

    With ``pool`` (a process pool), all of them at once: each reconstruction runs on
    one thread, so the surfaces are those of one by one
    (:func:`cloudprox.reproduce.reconstruct.reconstruct_many`).
    """
    todo = [d for d in draws if "meshes" not in d._cache]
    clouds = [(p, spacing, sigma, None) for d in todo for p in (d.piano_points, d.room_points)]
    meshes = reconstruct_many(clouds, pool)
    for k, d in enumerate(todo):
        d._cache["meshes"] = (surface_shape(meshes[2 * k]), surface_shape(meshes[2 * k + 1]))


def reconstruct_answer(
    draw: Draw,
    poses: FloatArray,
    spacing: float,
    sigma: float,
    shapes: tuple[ExactShape, ExactShape] | None = None,
) -> MethodAnswer:
    """Reconstruct both clouds (once per draw), then the exact surface check per pose.

    ``shapes`` replaces the reconstructions (the moving object's, the other's)
    where the caller has them, e.g. a robot's own mesh. The answers come from
    :func:`cloudprox.exact_proximity_many` (in parallel); the time per query is
    the median of :data:`TIMED_QUERIES` of them run one by one (every query gets
    that median).
    """
    if shapes is None:
        reconstruct_draws([draw], spacing, sigma)
        shapes = draw._cache["meshes"]  # type: ignore[assignment]
    piano, room = shapes
    r = exact_proximity_many(piano, room, poses)
    hit = np.asarray(r.intersecting, dtype=bool)
    scores = np.where(hit, 1.0, -np.asarray(r.distance, dtype=float))
    timed = []
    for pose in poses[:: max(1, len(poses) // TIMED_QUERIES)][:TIMED_QUERIES]:
        t0 = time.perf_counter()
        exact_proximity(piano, room, pose)
        timed.append(time.perf_counter() - t0)
    seconds = np.full(len(poses), float(np.median(timed)))
    return MethodAnswer(scores, np.where(hit, "collision", "free"), seconds)


def sampling_spacing(points: FloatArray) -> float:
    """Return the side of the square cell each point stands for on the surface.

    The core's :attr:`cloudprox.PointCloud.cell_side`: from the median distance
    ``d_6`` to the 6th nearest neighbour, a surface density of ``6 / (pi d_6^2)``
    points per square metre gives cells of side ``d_6 sqrt(pi / 6)``.
    """
    return float(PointCloud(points).cell_side)


def _world(points: FloatArray, pose: FloatArray) -> FloatArray:
    return points @ pose[:3, :3].T + pose[:3, 3]


def cloudprox_answer(
    draw: Draw,
    poses: FloatArray,
    surface: str,
    aggregation: str,
    model: str = "points",
    many: Callable[..., list[CollisionResult]] | None = None,
) -> MethodAnswer:
    """Answer every pose with cloudprox (``collide_many``, in parallel).

    Default settings but for the surface family, the aggregation and the model
    (``"points"``, the paper's, or ``"elements"``, the surface elements).
    ``many`` replaces :func:`cloudprox.collide_many` (e.g.
    :func:`cloudprox.distributed.collide_many`: the same answers, as Ray tasks).
    """
    return cloudprox_answers(draw, poses, surface, (aggregation,), model, many)[aggregation]


def cloudprox_answers(
    draw: Draw,
    poses: FloatArray,
    surface: str,
    aggregations: tuple[str, ...],
    model: str = "points",
    many: Callable[..., list[CollisionResult]] | None = None,
) -> dict[str, MethodAnswer]:
    """Answer every pose under several aggregations with one query per pose.

    The query asks for ``aggregations[0]``; the others must be the paper's
    (``"max"``, ``"union"``, ``"independent"``, points model) and are read from
    its ``point_aggregates``: exactly what a query asking for them returns (the
    points model trains the same surfaces under every aggregation). They share
    its time when it asks for ``max``; when it asks for ``surface`` (which
    costs more), their time is that of their own ``max`` query on the
    :func:`timed_subset` poses (``nan`` for the others). See
    :func:`cloudprox_answer`.
    """
    first, *rest = aggregations
    if rest and (model != "points" or not set(rest) <= set(PAPER_AGGREGATIONS)):
        raise ValueError(
            f"only the points model's {PAPER_AGGREGATIONS} can be read from one query, "
            f"not {rest} with model {model!r}"
        )
    piano, room = draw.clouds()
    options = model_options(model)
    request = CollisionRequest(
        surface=surface,
        aggregation=first,
        model=options.model,
        segmentations=options.segmentations,
        near_context=options.near_context,
    )
    results = (many or collide_many)(piano, room, poses, request=request)
    seconds = np.array([r.stats.time_seconds for r in results])
    out = {
        first: MethodAnswer(
            np.array([r.probability for r in results]),
            np.array([r.state for r in results]),
            seconds,
        )
    }
    if rest and first not in PAPER_AGGREGATIONS:
        timed = timed_subset(seconds)
        own = (many or collide_many)(
            piano,
            room,
            poses[timed],
            request=CollisionRequest(surface=surface, aggregation="max", model=model),
        )
        seconds = np.full(len(poses), np.nan)
        seconds[timed] = [r.stats.time_seconds for r in own]
    for agg in rest:
        scores = np.array([(r.point_aggregates or {})[agg] for r in results])
        out[agg] = MethodAnswer(scores, states_from(scores), seconds)
    return out


def timed_subset(seconds: FloatArray) -> npt.NDArray[np.intp]:
    """Return the poses whose queries are timed on their own, given another query's times.

    ``seconds`` are the times of a query that does the same work and more (the
    points model's ``surface`` query for its ``max``). The poses are ranked by
    them and every :data:`TIMED_SHARE`-th is taken from the middle of its run
    of ranks, at least :data:`TIMED_LEAST` (all of fewer): a systematic sample
    over a correlated time, whose median follows the median of all. Query
    times spread over three decades, and the median of every 8th pose in
    index order was 25% below to 19% above the median of all in the full
    run's levels (of the ``surface`` query's own times); ranked by the other
    surface family's times, within 5%. The full run's 5000 poses time 625
    per draw.
    """
    n = len(seconds)
    step = max(1, min(TIMED_SHARE, n // TIMED_LEAST))
    ranks = np.arange(step // 2, n, step)
    return np.sort(np.argsort(seconds, kind="stable")[ranks])


def query_groups(
    variants: tuple[tuple[str, str, str], ...],
) -> list[tuple[tuple[str, str], tuple[str, ...]]]:
    """Group ``variants`` into queries, one per (model, surface, asked aggregation).

    One points-model query per surface family gives every aggregation: it asks
    for ``surface`` (else ``max``, else the first given), and the paper's ``max``, ``union`` and
    ``independent`` are its ``point_aggregates`` (the same numbers as their own
    queries; see :func:`cloudprox_answers` for their times).
    """
    groups: dict[tuple[str, str, str], list[str]] = {}
    for model, surface, agg in variants:
        key = (model, surface, "one" if model == "points" else agg)
        groups.setdefault(key, []).append(agg)
    out = []
    for (model, surface, _), aggs in groups.items():
        # The query asks for `surface` when it is among them, else `max`.
        aggs.sort(key=lambda a: (a != "surface", a != "max"))
        out.append(((model, surface), tuple(aggs)))
    return out


def variant_answers(
    draws: list[Draw],
    poses: FloatArray,
    variants: tuple[tuple[str, str, str], ...],
    many: Callable[..., list[CollisionResult]] | None,
    tick: Callable[[str, int], None],
    label: str,
) -> dict[str, list[MethodAnswer]]:
    """Answer every (model, surface, aggregation) of ``variants`` for every draw.

    One query per :func:`query_groups` group and draw; keyed by
    :func:`variant_name`, in the order of ``variants``. ``tick(description,
    advance)`` reports each group (one step per variant), ``label`` starting
    its description.
    """
    answers: dict[str, list[MethodAnswer]] = {}
    for (model, surface), aggs in query_groups(variants):
        per_draw = [cloudprox_answers(d, poses, surface, aggs, model, many) for d in draws]
        for agg in aggs:
            answers[variant_name(model, surface, agg)] = [x[agg] for x in per_draw]
        tick(f"{label}: cloudprox {model} {surface} {'/'.join(aggs)}", len(aggs))
    return {variant_name(*v): answers[variant_name(*v)] for v in variants}


@dataclass(frozen=True)
class ModelOptions:
    """A variant's model name read as the query's model and its options.

    Attributes
    ----------
    model : str
        ``"points"`` or ``"elements"``.
    segmentations : int
        ``CollisionRequest(segmentations=...)``: 1 unless the name asks for more.
    near_context : float or None
        ``CollisionRequest(near_context=...)``; ``None`` keeps the core's default.
    """

    model: str
    segmentations: int = 1
    near_context: float | None = None


#: The most segmentations a query averages over (the core's ``MAX_SEGMENTATIONS``).
MAX_SEGMENTATIONS = 16
#: The least context a query takes (``CollisionRequest(near_context=...)``).
MIN_NEAR_CONTEXT = 0.5
_SEGMENTATIONS = re.compile(r"x([0-9]+)")
_CONTEXT = re.compile(r"c([0-9]+(?:\.[0-9]+)?)")


def model_options(model: str) -> ModelOptions:
    """Read a variant's model name: ``"points"``, or ``"elements"`` with suffixes.

    ``"-xK"`` averages the elements over ``K`` segmentations (1 to
    :data:`MAX_SEGMENTATIONS`; ``CollisionRequest(segmentations=K)``); ``"-cC"``
    gives the classifier ``C`` spacings of context (at least
    :data:`MIN_NEAR_CONTEXT`; ``CollisionRequest(near_context=C)``), each at most
    once: ``"elements-x3"``, ``"elements-c1"``, ``"elements-x3-c1"``. Raises
    ``ValueError`` naming the model on anything else.
    """
    base, *suffixes = model.split("-")
    if base != "elements":
        if suffixes:
            raise ValueError(f"model {model!r}: only the elements take -xK or -cC")
        return ModelOptions(base)
    segmentations: int | None = None
    near_context: float | None = None
    for suffix in suffixes:
        if (k := _SEGMENTATIONS.fullmatch(suffix)) and segmentations is None:
            segmentations = int(k.group(1))
            if not 1 <= segmentations <= MAX_SEGMENTATIONS:
                raise ValueError(
                    f"model {model!r}: K must be in 1..={MAX_SEGMENTATIONS}, got {segmentations}"
                )
        elif (c := _CONTEXT.fullmatch(suffix)) and near_context is None:
            near_context = float(c.group(1))
            if near_context < MIN_NEAR_CONTEXT:
                raise ValueError(
                    f"model {model!r}: C must be at least {MIN_NEAR_CONTEXT}, got {near_context:g}"
                )
        else:
            raise ValueError(
                f"model {model!r}: expected elements[-xK][-cC] (each at most once, K an "
                f"integer, C a decimal number), got {suffix!r}"
            )
    return ModelOptions(base, segmentations or 1, near_context)


def variant_name(model: str, surface: str, aggregation: str) -> str:
    """Return the row name of a cloudprox variant.

    ``"cloudprox quadric max"`` for the points model (the paper's, with its
    aggregation), ``"cloudprox elements quadric"`` for the surface elements
    (``"cloudprox elements quadric x3"`` averaged over 3 segmentations,
    ``"... c1"`` with 1 spacing of context).
    """
    options = model_options(model)
    if options.model == "elements":
        suffix = f" x{options.segmentations}" if options.segmentations > 1 else ""
        if options.near_context is not None:
            suffix += f" c{options.near_context:g}"
        return f"cloudprox elements {surface}{suffix}"
    return f"cloudprox {surface} {aggregation}"


def nn_gap_answer(draw: Draw, poses: FloatArray) -> MethodAnswer:
    """Score by the nearest-neighbour gap ``max_i Phi(-(d_i - 2 s_i) / s_i)``.

    ``d_i`` is piano point ``i``'s distance to its nearest room point ``j`` and
    ``s_i = sqrt(s_a_i^2 + s_b_j^2)`` the two points' largest sensor standard
    deviations. Exact, without every point's nearest neighbour: the points'
    neighbours are first searched within ``R = 4 s_max`` only (``s_max`` the
    largest ``s_i`` can be). A point without one there has ``(2 s_i - d_i) /
    s_i < 2 - R / s_max``, so once a found point reaches that, the maximum is
    among the found ones; else ``R`` doubles. (A full search per pose took
    120-175 ms at 10 000 points; this one 5-27 ms, the same scores.) Each search
    reads only the points :meth:`Draw.near_piano_points` keeps for its reach.
    """
    tree, _ = draw.room_tree(), draw.piano_clusters()  # prepared once, not timed
    std_a, std_b = draw.sensor_std()
    s_max = float(np.sqrt(std_a.max() ** 2 + std_b.max() ** 2))
    scores, seconds = np.empty(len(poses)), np.empty(len(poses))
    for i, pose in enumerate(poses):
        t0 = time.perf_counter()
        x = _world(draw.piano_points, pose)
        # (Without noise, every neighbour at once.)
        reach = 4.0 * s_max if s_max > 0.0 else np.inf
        while True:
            # Only the points that may have a neighbour within the reach.
            near = draw.near_piano_points(pose, reach)
            d, j = tree.query(x[near], distance_upper_bound=reach)
            found = np.isfinite(d)
            if found.any():
                s = np.sqrt(std_a[near[found]] ** 2 + std_b[j[found]] ** 2)
                best = float(np.max(2.0 - d[found] / s))
                if reach == np.inf or best >= 2.0 - reach / s_max:
                    break
            reach *= 2.0
        scores[i] = float(ndtr(best))
        seconds[i] = time.perf_counter() - t0
    return MethodAnswer(scores, states_from(scores), seconds)


def _overlap_answer(draw: Draw, poses: FloatArray, reach: float, norm: float) -> MethodAnswer:
    """Collision iff some piano point is within ``reach`` of a room point (``norm``-distance)."""
    tree, _ = draw.room_tree(), draw.piano_clusters()  # prepared once, not timed
    hit, seconds = np.empty(len(poses), dtype=bool), np.empty(len(poses))
    for i, pose in enumerate(poses):
        t0 = time.perf_counter()
        near = draw.near_piano_points(pose, reach, norm)
        d, _ = tree.query(_world(draw.piano_points, pose)[near], p=norm, distance_upper_bound=reach)
        hit[i] = bool(np.any(d < reach))
        seconds[i] = time.perf_counter() - t0
    return MethodAnswer(hit.astype(float), np.where(hit, "collision", "free"), seconds)


def collision_map_answer(draw: Draw, poses: FloatArray, resolution: float) -> MethodAnswer:
    """Axis-aligned cubes of side ``resolution`` on every point; collision iff two overlap.

    Two such cubes overlap iff their centres are closer than ``resolution`` in the
    Chebyshev (max) norm.
    """
    return _overlap_answer(draw, poses, resolution, np.inf)


def sphere_union_answer(draw: Draw, poses: FloatArray, radius: float) -> MethodAnswer:
    """Spheres of one ``radius`` on every point; collision iff two overlap."""
    return _overlap_answer(draw, poses, 2.0 * radius, 2.0)


def _point_baseline(method: str, draw: Draw, poses: FloatArray, spacing: float) -> MethodAnswer:
    """One of :data:`POINT_BASELINES` on ``poses`` (a pool's task)."""
    if method == "nn-gap":
        return nn_gap_answer(draw, poses)
    if method == "collision-map":
        return collision_map_answer(draw, poses, spacing)
    if method == "spheres":
        return sphere_union_answer(draw, poses, spacing / np.sqrt(2.0))
    raise ValueError(f"unknown baseline {method!r}; expected one of {POINT_BASELINES}")


def point_baseline_answers(
    draws: list[Draw],
    poses: FloatArray,
    spacing: float,
    pool: Executor | None = None,
    workers: int = 1,
) -> dict[str, list[MethodAnswer]]:
    """nn-gap, collision map and spheres (cell side ``spacing``) for every draw.

    With ``pool`` (e.g. a process pool of ``workers``), each draw's poses are
    split into ``workers`` runs of consecutive poses, each a task: every pose
    is answered and timed on its own, so the answers are those of one process
    (the times are each worker's). Returns per method one answer per draw.
    """
    if pool is None or workers <= 1 or len(poses) == 0:
        return {b: [_point_baseline(b, d, poses, spacing) for d in draws] for b in POINT_BASELINES}
    chunks = [c for c in np.array_split(np.arange(len(poses)), workers) if len(c)]
    # A draw's own arrays only (its cache of trees is rebuilt by each task).
    bare = [replace(d, _cache={}) for d in draws]
    futures = {
        (b, k, i): pool.submit(_point_baseline, b, d, poses[c], spacing)
        for b in POINT_BASELINES
        for k, d in enumerate(bare)
        for i, c in enumerate(chunks)
    }
    out: dict[str, list[MethodAnswer]] = {}
    try:
        for b in POINT_BASELINES:
            out[b] = []
            for k in range(len(draws)):
                parts = [futures[(b, k, i)].result() for i in range(len(chunks))]
                out[b].append(
                    MethodAnswer(
                        np.concatenate([x.score for x in parts]),
                        np.concatenate([x.state for x in parts]),
                        np.concatenate([x.seconds for x in parts]),
                    )
                )
    except BaseException:
        # A failed task (or Ctrl-C) ends the others not yet started.
        for f in futures.values():
            f.cancel()
        raise
    return out
