"""Where the Kinect frame's deep collisions are: shown by the frame, or only by its reference.

The reproduction's Kinect experiment (:func:`cloudprox.reproduce.realscan.run_scan`,
its poses and its two quarter-resolution clouds, seed 0) labels a pose by the
Poisson surface of the *full* frame, which fills holes of the scan up to its
support cut. This bench takes the poses deeper than 3 sigma by that reference
and asks, for each, whether any point of the full frame lies inside the
gripper's mesh at that pose (the collision is in the data), then answers them
with both models on both clouds: missed collisions (``free``) among the poses
the frame shows and among those only the reference shows.

The poses are placed as the full run places them (11 minutes on 2 idle
cores for 5000, 33 beside other work; the queries take seconds). ``trimesh``
decides which frame points lie inside the gripper (``pip install -e '.[bench]'``).

Usage: ``python3 benches/kinect_deep.py [--poses 5000] [--seed 0]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import trimesh
from scipy.spatial import cKDTree

import cloudprox as cp
from cloudprox.datasets import load_kinect_frame, panda_gripper
from cloudprox.reproduce import methods as m
from cloudprox.reproduce import realscan as rs


class _Captured(Exception):
    """Stops :func:`run_scan` once its poses and clouds are made."""


def scene(n: int, seed: int) -> tuple[rs.ScanPoses, list[m.Draw]]:
    """Return the reproduction's Kinect poses and its two clouds (nothing is queried)."""
    got: dict[str, object] = {}
    place, answer = rs.sample_scan_poses, m.variant_answers

    def placed(*args: object, **kwargs: object) -> rs.ScanPoses:
        got["poses"] = q = place(*args, **kwargs)  # type: ignore[arg-type]
        return q

    def stop(draws: list[m.Draw], *_: object) -> None:
        got["draws"] = draws
        raise _Captured

    rs.sample_scan_poses, m.variant_answers = placed, stop  # type: ignore[assignment]
    try:
        rs.run_scan(n, seed, (("elements", "quadric", "max"),), lambda *_: None)
    except _Captured:
        pass
    finally:
        rs.sample_scan_poses, m.variant_answers = place, answer
    return got["poses"], got["draws"]  # type: ignore[return-value]


def frame_points_inside(poses: np.ndarray) -> np.ndarray:
    """For each gripper pose, how many points of the full frame lie inside its mesh."""
    g = panda_gripper()
    mesh = trimesh.Trimesh(np.asarray(g.vertices), np.asarray(g.faces), process=True)
    lo, hi = mesh.bounds
    centre, radius = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
    full = np.asarray(load_kinect_frame().points)
    tree = cKDTree(full)
    out = np.zeros(len(poses), dtype=int)
    for k, pose in enumerate(poses):
        near = tree.query_ball_point(pose[:3, :3] @ centre + pose[:3, 3], radius)
        inv = np.linalg.inv(pose)
        local = full[near] @ inv[:3, :3].T + inv[:3, 3]
        boxed = local[np.all((local > lo) & (local < hi), axis=1)]
        if len(boxed):
            out[k] = int((trimesh.proximity.signed_distance(mesh, boxed) > 0.0).sum())
    return out


def main() -> None:
    """Place the poses, find the deep ones, and count each model's misses."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    q, draws = scene(args.poses, args.seed)
    unit = q.signed_distance / q.sigma
    deep = np.flatnonzero(unit < -3.0)
    shown = frame_points_inside(q.poses[deep]) > 0
    print(
        f"{len(deep)} of {len(unit)} poses deeper than 3 sigma by the reference; "
        f"the full frame has points inside the gripper at {shown.sum()}, "
        f"none at {(~shown).sum()}: {deep[~shown].tolist()} "
        f"({time.perf_counter() - t0:.0f} s)"
    )
    head = [
        "model",
        "draw",
        "missed, frame shows it",
        "missed, reference only",
        "states there",
        "missed poses (index: depth in sigma, P)",
    ]
    print("| " + " | ".join(head) + " |")
    print("|---|---|---|---|---|---|")
    for model in ("elements", "points"):
        for k, d in enumerate(draws):
            gripper, scan = d.clouds()
            res = cp.collide_many(gripper, scan, q.poses[deep], model=model)
            st = np.array([r.state for r in res])
            only = {s: int((st[~shown] == s).sum()) for s in ("free", "contact", "collision")}
            missed = "; ".join(
                f"{deep[i]}{'' if shown[i] else ' (hole)'}: {-unit[deep[i]]:.1f}, "
                f"{res[i].probability:.2g}"
                for i in np.flatnonzero(st == "free")
            )
            print(
                f"| {model} | {k} | {(st[shown] == 'free').sum()} / {shown.sum()} | "
                f"{(st[~shown] == 'free').sum()} / {(~shown).sum()} | {only} | {missed} |"
            )


if __name__ == "__main__":
    main()
