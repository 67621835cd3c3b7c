"""A bin whose far wall the camera cannot see: what the scan's shadow catches.

An open bin (inside 0.4 x 0.3 m, walls 0.15 m high and 1 cm thick, on the
floor z = 0) seen by the simulated Kinect of ``benches/tabletop.py`` from low
in front (``CAMERA``): the near wall hides the bin's lower half and the foot of
the far wall. A finger (a 1 x 1 x 4 cm box) is placed at exact clearances to
the bin's surfaces, in five places:

- ``far wall, foot``: into the far wall's inner face low down (hidden);
- ``far wall, top``: into its inner face near the top (seen over the near wall);
- ``near wall, outside``: into the near wall's outer face (seen);
- ``bin, low, free``: inside the bin 2 cm from everything (hidden, free);
- ``above the bin``: 5 cm above the near wall's top (seen, free).

For each place and exact signed clearance (``--gaps``, mm; negative: into
the wall), over ``--draws`` noise draws: the median of ``collide(finger,
scan)``'s P and the share of draws reading free, and the same with the
scan's shadow read as ``filters.Occlusion`` reads it for a robot's link
(``shadow=``): P raised to ``prior * hidden``, with the default prior 0.5,
within the default depth (5 cm) and at any depth.

    python3 benches/shadow_bin.py [--draws 5] [--gaps -10,-3,5]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from tabletop import scan

import cloudprox as cp

CAMERA = (np.array([0.9, 0.0, 0.25]), np.array([0.0, 0.0, 0.05]))
INNER = (0.2, 0.15)  # half extents of the inside (x, y)
HEIGHT, WALL = 0.15, 0.01
FINGER = (0.005, 0.005, 0.02)  # half extents
PRIOR, DEPTH = 0.5, 0.05


def bin_meshes() -> dict[str, cp.Mesh]:
    """Return the floor and the four walls as boxes."""
    hx, hy = INNER
    t, h = WALL, HEIGHT

    def box(c: tuple[float, float, float], e: tuple[float, float, float]) -> cp.Mesh:
        m = cp.Mesh.cuboid(*e)
        return cp.Mesh(np.asarray(m.vertices) + c, m.faces)

    return {
        "floor": box((0.0, 0.0, -t / 2), (hx + t, hy + t, t / 2)),
        "far": box((-hx - t / 2, 0.0, h / 2), (t / 2, hy + t, h / 2)),
        "near": box((hx + t / 2, 0.0, h / 2), (t / 2, hy + t, h / 2)),
        "left": box((0.0, -hy - t / 2, h / 2), (hx, t / 2, h / 2)),
        "right": box((0.0, hy + t / 2, h / 2), (hx, t / 2, h / 2)),
    }


def finger_centre(place: str, gap: float) -> np.ndarray:
    """Return the finger's centre at exact clearance ``gap`` in ``place``."""
    hx, _ = INNER
    fx, _, fz = FINGER
    if place == "far wall, foot":
        return np.array([-hx + fx + gap, 0.0, 0.04])
    if place == "far wall, top":
        return np.array([-hx + fx + gap, 0.0, HEIGHT - fz - 0.005])
    if place == "near wall, outside":
        return np.array([hx + WALL + fx + gap, 0.0, 0.08])
    if place == "bin, low, free":
        return np.array([-hx + fx + 0.02, 0.0, fz + 0.02])
    return np.array([hx + WALL / 2, 0.0, HEIGHT + fz + 0.05])


PLACES = ("far wall, foot", "far wall, top", "near wall, outside", "bin, low, free", "above")


def main() -> None:
    """Print the table: each place and clearance, without and with the shadow."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=5)
    ap.add_argument("--gaps", default="-10,-3,5", help="exact clearances, mm")
    args = ap.parse_args()
    gaps = [float(g) * 1e-3 for g in args.gaps.split(",")]
    meshes = bin_meshes()
    finger = cp.Mesh.cuboid(*FINGER)
    samples = np.asarray(finger.sample(density=4e5).points)
    rows: dict[tuple[str, float], list[tuple[float, float]]] = {}
    for draw in range(args.draws):
        cloud, _ = scan(meshes, seed=draw, scale=2.0, camera=CAMERA)
        occ = cp.filters.Occlusion(cloud, CAMERA[0])
        for place in PLACES:
            for gap in gaps if "free" not in place and place != "above" else [np.nan]:
                c = finger_centre(place, 0.0 if np.isnan(gap) else gap)
                p = cp.collide(finger, cloud, cp.pose.from_translation(c)).probability
                pts = samples + c
                near = float(occ.hidden_probability(pts, DEPTH).max())
                anywhere = float(occ.hidden_probability(pts).max())
                rows.setdefault((place, gap), []).append(
                    (p, max(p, PRIOR * near), max(p, PRIOR * anywhere))
                )
    print(f"{cloud.points.shape[0]} scan points; {args.draws} draws; shadow prior {PRIOR}\n")
    print(
        "| finger | exact clearance | P: median, share free | shadow within 5 cm "
        "| shadow at any depth |\n|---|---|---|---|---|"
    )
    for (place, gap), v in rows.items():
        a = np.asarray(v)
        free = (a < 0.01).mean(axis=0)
        g = "free" if np.isnan(gap) else f"{gap * 1e3:+.0f} mm"
        cells = " | ".join(f"{np.median(a[:, k]):.3g}, {free[k]:.0%}" for k in range(3))
        print(f"| {place} | {g} | {cells} |")


if __name__ == "__main__":
    main()
