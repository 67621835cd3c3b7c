"""Batches of queries as Ray tasks, on one machine or a cluster (``cloudprox[ray]``).

:func:`collide_many` and :func:`collide_robot_many` split their poses or
configurations into batches and run each batch as a Ray task on the current
cluster (``ray.init()`` is called when Ray is not initialized yet: it joins the
cluster started on this machine by ``ray start``, the one ``RAY_ADDRESS`` names,
or starts a local one). The clouds, meshes and robots go once into Ray's object
store (``ray.put``); each worker process unpickles them once and keeps them for
the following tasks (the hierarchy of a cloud is built once per worker). The
results come back in input order, equal to the local call's, with a progress bar.

Within a task the batch runs on ``cpus_per_task`` threads (``RAYON_NUM_THREADS``),
so Ray's CPU accounting is the machine's.

Examples
--------
>>> import numpy as np, ray, cloudprox as cp
>>> from cloudprox import distributed
>>> _ = ray.init(num_cpus=2, include_dashboard=False)  # doctest: +SKIP
>>> a = cp.PointCloud(cp.synthetic.sample_sphere(500, 0.1), sigma=0.002)
>>> poses = np.tile(np.eye(4), (100, 1, 1)); poses[:, 0, 3] = np.linspace(0.18, 0.3, 100)
>>> results = distributed.collide_many(a, a, poses)  # doctest: +SKIP
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from cloudprox._native import (
    CollisionResult,
    Mesh,
    PointCloud,
    Robot,
    RobotBatchResult,
)
from cloudprox._native import collide_many as _collide_many
from cloudprox._native import collide_robot_many as _collide_robot_many

if TYPE_CHECKING:
    import ray as ray_module

__all__ = ["collide_many", "collide_robot_many", "default_batch_size", "ensure_ray"]

#: Objects a worker process keeps unpickled, by object id (least recently used out).
_CACHE_SIZE = 8
_cache: OrderedDict[str, Any] = OrderedDict()


def ensure_ray(address: str | None = None) -> ray_module:
    """Return the ``ray`` module, initialized.

    Parameters
    ----------
    address : str, optional
        A cluster to join (``"auto"``, ``"HOST:6379"``, ``"ray://HOST:10001"``);
        by default the running one, else a new local one (``ray.init()``).

    Raises
    ------
    ImportError
        Without Ray: the message names the extra ``cloudprox[ray]``.
    """
    try:
        import ray
    except ImportError:
        raise ImportError("cloudprox.distributed needs Ray: pip install 'cloudprox[ray]'") from None
    if not ray.is_initialized():
        ray.init(address=address, ignore_reinit_error=True)
    return ray


def default_batch_size(m: int, cpus: float) -> int:
    """Return the items per task: about 4 tasks per CPU, at least 64 and at most 2048.

    Fewer, larger tasks hide Ray's per-task overhead (see BENCHMARKS.md); 4 tasks
    per CPU keep the CPUs busy to the end and the progress bar moving.
    """
    if m <= 0:
        return 1
    per = math.ceil(m / max(4.0 * cpus, 1.0))
    return max(1, min(m, max(64, min(per, 2048))))


def _local(ref_box: list[Any]) -> Any:
    """Return the object behind an object ref, unpickled once per worker process."""
    import ray

    ref = ref_box[0]
    key = ref.hex()
    if key in _cache:
        _cache.move_to_end(key)
        return _cache[key]
    obj = ray.get(ref)
    _cache[key] = obj
    while len(_cache) > _CACHE_SIZE:
        _cache.popitem(last=False)
    return obj


def _collide_batch(
    a_box: list[Any],
    b_box: list[Any],
    poses_a: np.ndarray,
    pose_b: np.ndarray | None,
    options: dict[str, Any],
) -> list[CollisionResult]:
    return _collide_many(_local(a_box), _local(b_box), poses_a, pose_b, **options)


def _robot_batch(
    robot_box: list[Any],
    cloud_box: list[Any],
    qs: np.ndarray,
    base_pose: np.ndarray | None,
    options: dict[str, Any],
) -> RobotBatchResult:
    return _collide_robot_many(_local(robot_box), qs, _local(cloud_box), base_pose, **options)


def _run(
    ray: Any,
    function: Any,
    shared: Sequence[Any],
    items: np.ndarray,
    extra: tuple[Any, ...],
    batch_size: int | None,
    cpus_per_task: int,
    progress: bool,
    what: str,
) -> list[Any]:
    """Run ``function(*boxes, items[k:k+n], *extra)`` as tasks; results in order."""
    if cpus_per_task < 1:
        raise ValueError(f"cpus_per_task must be >= 1, got {cpus_per_task}")
    m = len(items)
    cpus = float(ray.cluster_resources().get("CPU", 1.0))
    size = default_batch_size(m, cpus / cpus_per_task) if batch_size is None else batch_size
    if size < 1:
        raise ValueError(f"batch_size must be >= 1, got {size}")
    boxes = [[ray.put(obj)] for obj in shared]
    task = ray.remote(function).options(
        num_cpus=cpus_per_task,
        runtime_env={"env_vars": {"RAYON_NUM_THREADS": str(cpus_per_task)}},
    )
    starts = list(range(0, m, size))
    refs = [task.remote(*boxes, items[s : s + size], *extra) for s in starts]
    order = {ref: k for k, ref in enumerate(refs)}
    out: list[Any] = [None] * len(refs)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    with Progress(
        TextColumn(f"{what} on Ray"),
        BarColumn(),
        MofNCompleteColumn(),
        console=Console(stderr=True),
        transient=True,
        disable=not progress,
    ) as bar:
        job = bar.add_task(what, total=m)
        pending = list(refs)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                k = order[ref]
                try:
                    out[k] = ray.get(ref)
                except ray.exceptions.RayTaskError as e:
                    for r in pending:
                        ray.cancel(r)
                    cause = getattr(e, "cause", None)
                    if not isinstance(cause, Exception):
                        raise
                    end = min(starts[k] + size, m)
                    # Indices in the cause's message count from the batch's start.
                    raise type(cause)(
                        f"{what} {starts[k]} to {end - 1} (indices below count from "
                        f"{starts[k]}): {cause}"
                    ) from None
                bar.update(job, advance=min(size, m - starts[k]))
    return out


def _check_side(obj: Any, what: str) -> None:
    if not isinstance(obj, (PointCloud, Mesh)):
        raise TypeError(
            f"{what} must be a cloudprox PointCloud or Mesh to travel to Ray workers, got "
            f"{type(obj).__name__}"
        )


def collide_many(
    a: PointCloud | Mesh,
    b: PointCloud | Mesh,
    poses_a: npt.ArrayLike,
    pose_b: npt.ArrayLike | None = None,
    *,
    batch_size: int | None = None,
    cpus_per_task: int = 1,
    address: str | None = None,
    progress: bool = True,
    **options: Any,
) -> list[CollisionResult]:
    """:func:`cloudprox.collide_many` as Ray tasks: ``a`` at each of ``poses_a`` against ``b``.

    Parameters
    ----------
    a, b : PointCloud or Mesh
        The sides (sent once to the object store).
    poses_a : array_like, shape (m, 4, 4)
        Poses of ``a``.
    pose_b : array_like, shape (4, 4), optional
        Pose of ``b``.
    batch_size : int, optional
        Poses per task (default :func:`default_batch_size`).
    cpus_per_task : int, default 1
        CPUs (and threads) of each task.
    address : str, optional
        The cluster to join when Ray is not initialized (see :func:`ensure_ray`).
    progress : bool, default True
        Show a progress bar on stderr.
    **options
        The options of :func:`cloudprox.collide`.

    Returns
    -------
    list of CollisionResult
        In the order of ``poses_a``, equal to the local call's (they travel back
        pickled, without the clouds: ``points_a`` and ``points_b`` are ``None``).
    """
    _check_side(a, "a")
    _check_side(b, "b")
    poses = np.ascontiguousarray(poses_a, dtype=np.float64)
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or len(poses) == 0:
        raise ValueError(f"poses_a must have shape (m, 4, 4) with m >= 1, got {poses.shape}")
    pb = None if pose_b is None else np.ascontiguousarray(pose_b, dtype=np.float64)
    ray = ensure_ray(address)
    parts = _run(
        ray,
        _collide_batch,
        (a, b),
        poses,
        (pb, options),
        batch_size,
        cpus_per_task,
        progress,
        "poses",
    )
    return [r for part in parts for r in part]


def collide_robot_many(
    robot: Robot,
    qs: npt.ArrayLike,
    cloud: PointCloud,
    base_pose: npt.ArrayLike | None = None,
    *,
    batch_size: int | None = None,
    cpus_per_task: int = 1,
    address: str | None = None,
    progress: bool = True,
    **options: Any,
) -> RobotBatchResult:
    """:func:`cloudprox.collide_robot_many` as Ray tasks, one batch of configurations each.

    The robot travels as its URDF text: its mesh files must be readable at the
    same paths on every machine (primitives need no file).

    Parameters
    ----------
    robot : Robot
        The robot.
    qs : array_like, shape (m, dof)
        The configurations.
    cloud : PointCloud
        The scene.
    base_pose : array_like, shape (4, 4), optional
        The robot's root in the cloud's frame.
    batch_size, cpus_per_task, address, progress
        As in :func:`collide_many`.
    **options
        The options of :func:`cloudprox.collide_robot`.

    Returns
    -------
    RobotBatchResult
        Over all configurations, in order, equal to the local call's.
    """
    if not isinstance(robot, Robot):
        raise TypeError(f"robot must be a cloudprox Robot, got {type(robot).__name__}")
    if not isinstance(cloud, PointCloud):
        raise TypeError(f"cloud must be a cloudprox PointCloud, got {type(cloud).__name__}")
    q = np.ascontiguousarray(qs, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != robot.dof or len(q) == 0:
        raise ValueError(
            f"qs must have shape (m, {robot.dof}) with m >= 1 (the robot's dof), got {q.shape}"
        )
    base = None if base_pose is None else np.ascontiguousarray(base_pose, dtype=np.float64)
    ray = ensure_ray(address)
    parts: list[RobotBatchResult] = _run(
        ray,
        _robot_batch,
        (robot, cloud),
        q,
        (base, options),
        batch_size,
        cpus_per_task,
        progress,
        "configurations",
    )
    n_links = parts[0].link_probabilities.shape[1]
    state = (
        np.concatenate([p.probabilities for p in parts]).tolist(),
        np.concatenate([p.states for p in parts]).tolist(),
        np.concatenate([p.self_colliding for p in parts]).tolist(),
        np.concatenate([p.link_probabilities.ravel() for p in parts]).tolist(),
        n_links,
    )
    return RobotBatchResult._from_state(state)
