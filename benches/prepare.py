"""What a new cloud costs before its first query: covariances, spacing, elements.

A planner on live sensor data makes a new cloud per frame, so this is paid per
frame. Times, on large clouds of the repository's own scenes (median of
``--repeat`` runs, seconds):

- ``cloud``: ``PointCloud(points, cov=..., discretization=True)`` (the
  discretization covariances from each point's 10 nearest neighbours; the
  hierarchy);
- ``elements``: what the elements model builds on first use (the spacing, the
  surface elements, their hulls and samples), through ``collide_many`` with
  one pose far away, which builds them before its queries.

Clouds: the reproduction's room (123 536 points of the piano scene's walls,
floor and furniture) at 0.5% and 2% isotropic noise, and the real Kinect
frame (quarter resolution as the methods see it, 17 000 points, and full,
273 000, with the Kinect noise model).

    python3 benches/prepare.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np

import cloudprox as cp
from cloudprox.datasets import load_kinect_frame
from cloudprox.reproduce.realscan import STRIDE, kinect_camera
from cloudprox.reproduce.run import Config, level_inputs, sample_scene

FAR = cp.pose.from_translation((1e3, 0.0, 0.0))


def clouds() -> list[tuple[str, Callable[[], cp.PointCloud]]]:
    """Each test cloud by name, as a function making it anew."""
    config = Config(poses=1, scan_poses=0)
    scene = sample_scene(config)
    out: list[tuple[str, Callable[[], cp.PointCloud]]] = []
    for k, name in ((0, "room, 0.5%"), (2, "room, 2%")):
        d = level_inputs(config, k, scene, 1)[2][0]
        room_points, room_cov = d.room_points, d.room_sensor_cov
        out.append(
            (
                name,
                lambda p=room_points, c=room_cov: cp.PointCloud(p, cov=c, discretization=True),
            )
        )
    frame = load_kinect_frame()
    full = np.asarray(frame.points)
    u, v = frame.pixels[:, 0], frame.pixels[:, 1]
    quarter = full[(u % STRIDE == 0) & (v % STRIDE == 0)]
    camera = kinect_camera(0.5 * (frame.fx + frame.fy))
    for name, p in (("Kinect, quarter", quarter), ("Kinect, full", full)):
        out.append(
            (
                name,
                lambda p=p: cp.PointCloud(
                    p, sensor=camera, sensor_pose=np.eye(4), discretization=True
                ),
            )
        )
    return out


def main() -> None:
    """Print the median preparation times of each cloud."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs per cloud (median)")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1, got {args.repeat}")
    request = cp.CollisionRequest(model="elements")
    print(f"{'cloud':18s} {'points':>8s} {'cloud s':>8s} {'elements s':>10s}")
    for name, make in clouds():
        t_cloud, t_elements = [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            cloud = make()
            t1 = time.perf_counter()
            cp.collide_many(cloud, cloud, FAR[None], request=request)
            t_elements.append(time.perf_counter() - t1)
            t_cloud.append(t1 - t0)
        print(
            f"{name:18s} {len(cloud):8d} {statistics.median(t_cloud):8.3f} "
            f"{statistics.median(t_elements):10.3f}"
        )


if __name__ == "__main__":
    main()
