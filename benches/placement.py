"""What placing the gripper near the real Kinect frame costs (the reproduction's scan poses).

The reproduction's Kinect experiment draws gripper poses at target gaps and
depths from a surface reconstructed from the frame
(:func:`cloudprox.reproduce.realscan.sample_scan_poses`): per round, the
gripper's convex hulls are cast along viewing rays to the target (``hull``),
then the gripper's own triangles from there (``gripper``, a mesh against the
surface's 666 000 triangles), then an intersection test confirms each pose's
side (``check``). Prints the seconds of each stage over all rounds, the
rounds, and the whole placement, for ``--poses`` poses (500: a tenth of a full
run's). ``--save`` writes the poses (``.npz``) to compare two builds (the
reconstruction itself varies by a few triangles between runs: Open3D's
Poisson solver is multithreaded).

    python3 benches/placement.py [--poses 500] [--seed 0] [--save poses.npz]
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

import cloudprox.reproduce.realscan as rs
from cloudprox import ExactShape
from cloudprox.datasets import load_kinect_frame, panda_gripper, panda_gripper_parts
from cloudprox.reproduce import methods
from cloudprox.reproduce.reconstruct import reconstruct, surface_shape


def main() -> None:
    """Place ``--poses`` gripper poses, timing each stage."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--save", type=Path, default=None)
    args = parser.parse_args()
    if args.poses < 1:
        parser.error("--poses must be at least 1")

    t0 = time.perf_counter()
    frame = load_kinect_frame()
    full = np.asarray(frame.points)
    full_sigma = rs.kinect_axial_sigma(full[:, 2])
    h = methods.sampling_spacing(full)
    surface = reconstruct(full, h, float(np.median(full_sigma)), frame.origin)
    reference = surface_shape(surface)
    gripper_mesh = panda_gripper()
    gripper = ExactShape([gripper_mesh], solid=False)
    bound = ExactShape([rs.convex_hull(x) for x in panda_gripper_parts()])
    lo, hi = gripper_mesh.bounds()
    centre = 0.5 * (np.asarray(lo) + np.asarray(hi))
    anchor_sigma = np.sqrt(full_sigma**2 + rs.GRIPPER_SIGMA**2)
    print(f"reference surface: {len(surface.faces)} triangles, {time.perf_counter() - t0:.1f} s")

    # Each stage's seconds, by wrapping the module's two exact queries.
    seconds: dict[str, float] = defaultdict(float)
    rounds = 0
    cast, check = rs.exact_time_of_impact_many, rs.exact_intersects_many

    def timed_cast(shape: ExactShape, *rest: Any, **options: Any) -> Any:
        nonlocal rounds
        stage = "hull" if shape is bound else "gripper"
        rounds += stage == "hull"
        t = time.perf_counter()
        out = cast(shape, *rest, **options)
        seconds[stage] += time.perf_counter() - t
        return out

    def timed_check(*a: Any, **options: Any) -> Any:
        t = time.perf_counter()
        out = check(*a, **options)
        seconds["check"] += time.perf_counter() - t
        return out

    rs.exact_time_of_impact_many = timed_cast  # type: ignore[assignment]
    rs.exact_intersects_many = timed_check  # type: ignore[assignment]
    rng = np.random.default_rng(args.seed)
    t1 = time.perf_counter()
    poses = rs.sample_scan_poses(
        gripper, bound, reference, full, anchor_sigma, centre, args.poses, rng
    )
    total = time.perf_counter() - t1
    print(f"{args.poses} poses in {rounds} rounds: {total:.1f} s")
    for stage in ("hull", "gripper", "check"):
        print(f"  {stage:8s} {seconds[stage]:7.1f} s")
    if args.save is not None:
        np.savez(args.save, poses=poses.poses, signed_distance=poses.signed_distance)


if __name__ == "__main__":
    main()
