"""Throughput of ``cloudprox.distributed.collide_many`` at 1 and 2 Ray workers.

Two noisy spheres (``--points`` each) and ``--poses`` poses of one of them,
from overlapping to 5 cm apart (every state occurs). For 1 and 2 CPUs (a local
Ray started with ``num_cpus``), the poses run as Ray tasks of the default batch
size; the result is checked equal to the local ``cloudprox.collide_many``. Then,
at 2 CPUs, ``--small`` poses at several batch sizes give the per-task overhead
(time per task at batch size 1 minus the per-pose time of large batches) and the
batch size that hides it.

Usage: python benches/distributed.py [--points 1000] [--poses 10000] [--small 1000]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import cloudprox as cp
from cloudprox import distributed


def scene(points: int, m: int) -> tuple[cp.PointCloud, cp.PointCloud, np.ndarray]:
    """Two spheres of radius 0.1 and ``m`` poses of the first along x and y."""
    base = cp.synthetic.sample_sphere(points, 0.1)
    a = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=1), sigma=0.002)
    b = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=2), sigma=0.002)
    rng = np.random.default_rng(0)
    poses = np.tile(np.eye(4), (m, 1, 1))
    poses[:, 0, 3] = rng.uniform(-0.25, -0.19, m)
    poses[:, 1, 3] = rng.uniform(-0.02, 0.02, m)
    return a, b, poses


def same(r: list[cp.CollisionResult], s: list[cp.CollisionResult]) -> bool:
    """Whether two result lists agree in P, state and every per-point probability."""
    return len(r) == len(s) and all(
        x.probability == y.probability
        and x.state == y.state
        and np.array_equal(x.probabilities_a, y.probabilities_a)
        and np.array_equal(x.probabilities_b, y.probabilities_b)
        for x, y in zip(r, s, strict=False)
    )


def timed(a, b, poses, **kw) -> tuple[float, list[cp.CollisionResult]]:
    """Seconds of one distributed call (after a warm-up that starts the workers)."""
    distributed.collide_many(a, b, poses[:8], progress=False, batch_size=4)
    t = time.perf_counter()
    out = distributed.collide_many(a, b, poses, progress=False, **kw)
    return time.perf_counter() - t, out


def main() -> None:
    """Print the throughput table, the overhead and the batch-size sweep."""
    import ray

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1000)
    parser.add_argument("--poses", type=int, default=10_000)
    parser.add_argument("--small", type=int, default=1000)
    args = parser.parse_args()
    a, b, poses = scene(args.points, args.poses)
    os.environ["RAYON_NUM_THREADS"] = "1"  # the local reference on one thread
    t = time.perf_counter()
    local = cp.collide_many(a, b, poses)
    local_s = time.perf_counter() - t
    states = {s: sum(r.state == s for r in local) for s in ("free", "contact", "collision")}
    print(f"{args.poses} poses of two {args.points}-point spheres: {states}")
    print(f"local collide_many, 1 thread: {local_s:.2f} s, {args.poses / local_s:.0f} poses/s")
    print()
    print("| Ray CPUs | batch | tasks | seconds | poses/s | speed-up | equal to local |")
    print("|---|---|---|---|---|---|---|")
    base = None
    for cpus in (1, 2):
        ray.init(num_cpus=cpus, include_dashboard=False, log_to_driver=False)
        size = distributed.default_batch_size(args.poses, cpus)
        seconds, out = timed(a, b, poses)
        rate = args.poses / seconds
        base = base or rate
        tasks = -(-args.poses // size)
        print(
            f"| {cpus} | {size} | {tasks} | {seconds:.2f} | {rate:.0f} | {rate / base:.2f}x | "
            f"{same(out, local)} |"
        )
        if cpus == 2:
            small = poses[: args.small]
            rows = []
            for size in (1, 4, 16, 64, 256):
                seconds, out = timed(a, b, small, batch_size=size)
                assert same(out, local[: args.small])
                rows.append((size, seconds))
        ray.shutdown()
    print()
    per_pose = min(s for _, s in rows) / args.small
    print(f"2 CPUs, {args.small} poses:")
    print("| batch | tasks | seconds | poses/s | overhead per task (ms) |")
    print("|---|---|---|---|---|")
    for size, seconds in rows:
        tasks = -(-args.small // size)
        over = (seconds - per_pose * args.small) / tasks * 2.0  # two run at once
        print(
            f"| {size} | {tasks} | {seconds:.2f} | {args.small / seconds:.0f} | {1e3 * over:.2f} |"
        )


if __name__ == "__main__":
    main()
