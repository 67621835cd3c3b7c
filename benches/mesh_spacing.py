"""How densely to sample a mesh against a cloud: P against the exact gap.

A 10 cm cube (an exact mesh) above a noisy, sampled plane (2 cm grid, 1 m^2),
at exact gaps given in noise sigmas, for mesh sampling spacings of 0.25, 0.5 and
1 times the plane cloud's median spacing (its distance to the 6th nearest
neighbour). Prints P (``max`` aggregation) per gap and the median query time.

    python3 benches/mesh_spacing.py
"""

from __future__ import annotations

import statistics
import time

import numpy as np

import cloudprox as cp

GAPS_SIGMA = (10.0, 5.0, 2.0, 0.0, -5.0)
FACTORS = (0.25, 0.5, 1.0)


def main() -> None:
    """Print P for a cube against a plane cloud at each gap and mesh spacing factor."""
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    g = np.stack(np.meshgrid(np.linspace(-0.5, 0.5, 50), np.linspace(-0.5, 0.5, 50)), -1)
    g = g.reshape(-1, 2)
    rng = np.random.default_rng(1)
    print("sigma  factor  " + "  ".join(f"{x:+5.0f}s" for x in GAPS_SIGMA) + "  median ms")
    for sigma in (0.002, 0.01):
        plane = np.c_[g, np.zeros(len(g))] + rng.normal(0.0, sigma, (len(g), 3))
        cloud = cp.PointCloud(plane, sigma=sigma, discretization=True)
        h = float(np.median(cloud.spacing))
        for f in FACTORS:
            ps, times = [], []
            for gap in GAPS_SIGMA:
                pose = cp.pose.from_translation((0.0, 0.0, 0.05 + gap * sigma))
                start = time.perf_counter()
                r = cp.collide(cube, cloud, pose_a=pose, mesh_spacing=f * h)
                times.append(time.perf_counter() - start)
                ps.append(r.probability)
            cells = "  ".join(f"{p:6.2f}" for p in ps)
            print(f"{sigma:5.3f}  {f:6.2f}  {cells}  {1e3 * statistics.median(times):8.1f}")


if __name__ == "__main__":
    main()
