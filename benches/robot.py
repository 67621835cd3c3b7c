"""Per-configuration cost of a URDF robot against a depth-camera scan.

The Franka Panda of the PyPI wheel ``gym-ignition-models==1.1.1`` (fetched into
the cache by ``tests/robots.py``, SHA-256 checked) beside the table of
``cloudprox example`` (76 021 points, Nguyen et al. 2012 depth noise), its base
at ``(0, -0.35, 0.75)`` facing the table. Uniformly random configurations within
the joint limits; each is timed by the query itself (``stats["time_seconds"]``),
one at a time, then all of them through ``collide_robot_many``.

Usage: ``python3 benches/robot.py [--configurations 2000] [--seed 0]``
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.robots import panda_urdf

import cloudprox as cp
from cloudprox.examples import write_example_files

BASE = "0,-0.35,0.75,0.7071068,0,0,0.7071068"


def main() -> None:
    """Run the measurement and print medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configurations", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    robot = cp.Robot.from_urdf(panda_urdf())
    with tempfile.TemporaryDirectory() as tmp:
        write_example_files(Path(tmp))
        scan = cp.io.read_point_cloud(Path(tmp) / "scan.pcd").to_point_cloud(
            sensor=cp.DepthCamera.nguyen_2012()
        )
    base = cp.io.read_pose(BASE)
    lim = robot.joint_limits
    qs = np.random.default_rng(args.seed).uniform(
        lim[:, 0], lim[:, 1], (args.configurations, robot.dof)
    )
    cp.collide_robot(robot, qs[0], scan, base_pose=base)  # link samples, scan hierarchy
    results = [cp.collide_robot(robot, q, scan, base_pose=base, self_collision=False) for q in qs]
    t = np.array([r.stats["time_seconds"] for r in results])
    far = np.array([r.stats["links_queried"] == 0 for r in results])
    print(f"{len(qs)} random configurations, {len(scan)} scan points")
    print(f"  every link beyond the noise's reach: {far.sum()}")
    print(f"  median, every link skipped: {1e6 * np.median(t[far]):.1f} us")
    if (~far).any():
        print(f"  median, some link queried ({(~far).sum()}): {1e3 * np.median(t[~far]):.2f} ms")
    with_self = [
        cp.collide_robot(robot, q, scan, base_pose=base).stats["time_seconds"] for q in qs[far]
    ]
    print(f"  median with self-collision, every link skipped: {1e6 * np.median(with_self):.1f} us")
    start = time.perf_counter()
    cp.collide_robot_many(robot, qs, scan, base_pose=base)
    dt = time.perf_counter() - start
    print(f"  collide_robot_many: {dt:.2f} s ({1e3 * dt / len(qs):.2f} ms per configuration)")


if __name__ == "__main__":
    main()
