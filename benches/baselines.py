"""The reproduction's slowest baselines, timed on its own scene at full size.

The piano and the room of ``cloudprox reproduce`` sampled at 10 000 points
(its full run's size), one noise draw at ``--level`` of the piano's diagonal,
``--poses`` poses from its pose sampler (around contact, some far):

* reconstruct-then-collide: both clouds' Poisson surfaces (Open3D, the
  ``cloudprox[reproduce]`` extra), then :func:`cloudprox.exact_proximity` per
  pose on the bare surfaces (tens of thousands against hundreds of thousands of
  triangles);
* the nn-gap baseline (:func:`cloudprox.reproduce.methods.nn_gap_answer`);
* cloudprox's own query (elements model, then the points model's ``max``), for
  scale, on the same draw and poses.

Prints the median and mean milliseconds per query of each. Run it with two
builds (two virtual environments) to compare them.

    python3 benches/baselines.py [--poses 40] [--level 0.005]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import cloudprox as cp
from cloudprox.reproduce import methods as m
from cloudprox.reproduce.noise import NoiseModel
from cloudprox.reproduce.poses import sample_poses
from cloudprox.reproduce.reconstruct import available, reconstruct, surface_shape
from cloudprox.reproduce.run import Config, sample_scene


def _row(name: str, seconds: np.ndarray) -> None:
    print(
        f"| {name} | {1e3 * float(np.median(seconds)):.2f} | {1e3 * float(np.mean(seconds)):.2f} |"
    )


def main() -> None:
    """Time the baselines and cloudprox on one draw of the full-size scene."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=40)
    ap.add_argument("--level", type=float, default=0.005, help="noise, share of the diagonal")
    ap.add_argument("--points", type=int, default=10_000)
    args = ap.parse_args()
    scene = sample_scene(Config(piano_points=args.points, seed=0))
    p_obj, r_obj, pp, rp = scene.piano, scene.room, scene.piano_points, scene.room_points
    spacing = scene.spacing
    sigma = args.level * p_obj.diagonal
    rng = np.random.default_rng(0)
    q = sample_poses(p_obj, r_obj, args.poses, sigma, rng)
    noise = NoiseModel(sigma, None)
    a, ca = noise.draw(pp, rng)
    b, cb = noise.draw(rp, rng)
    draw = m.Draw(a, ca, b, cb)
    print(
        f"{len(a)} piano and {len(b)} room points, sigma {1e3 * sigma:.1f} mm, "
        f"{len(q.poses)} poses ({int(np.sum(q.signed_distance < 0))} in collision)"
    )
    print("| method | median ms | mean ms |")
    print("|---|---|---|")
    if available():
        t0 = time.perf_counter()
        sa = surface_shape(reconstruct(a, spacing, sigma))
        sb = surface_shape(reconstruct(b, spacing, sigma))
        built = time.perf_counter() - t0
        seconds = []
        for pose in q.poses:
            t0 = time.perf_counter()
            cp.exact_proximity(sa, sb, pose)
            seconds.append(time.perf_counter() - t0)
        _row(
            f"reconstruct-then-collide, exact_proximity (reconstruction {built:.0f} s)",
            np.array(seconds),
        )
    else:
        print("| reconstruct-then-collide | skipped: Open3D is not installed | |")
    _row("nn-gap", m.nn_gap_answer(draw, q.poses).seconds)
    for model, aggregation in (("elements", "max"), ("points", "max")):
        ans = m.cloudprox_answer(draw, q.poses, "quadric", aggregation, model)
        _row(f"cloudprox {model} (one query's own time)", ans.seconds)


if __name__ == "__main__":
    main()
