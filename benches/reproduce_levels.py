"""One cloudprox variant on the full reproduction's synthetic levels, alone.

The same scene, poses and noise draws as ``cloudprox reproduce`` (5000 poses
per level, two draws, seed 0; the piano and room sampled at 10 000 piano
points), but only the variant asked for (by default the surface elements):
each level takes one to two minutes on 2 cores instead of the full run's
hour, so a change of the elements model can be measured on every level. Prints
each level's metrics (the columns of the reproduction's table) and the missed
collisions deeper than 3 sigma (draw, pose, exact signed distance in sigma).

Usage: ``python3 benches/reproduce_levels.py [--levels '0.5%,1%,2%,1% aniso']
[--variant elements,quadric,max] [--poses 5000] [--piano-points 10000] [--kinect N]
[--save PREFIX]``; ``--kinect N`` also runs the variant on the Kinect frame with
``N`` gripper poses (the reproduction's real-scan experiment, seed 0; its point
baselines run too, and ``--levels ''`` skips the piano); the model may carry the
elements' options (``elements-x3``, ``elements-c1``: see
:func:`cloudprox.reproduce.methods.model_options`);
``--piano-points 3000`` samples the scene as the quick run does; ``--save`` writes each
level's scores, states, times and exact distances to ``PREFIX_<level>.npz``.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from cloudprox.reproduce import methods as m
from cloudprox.reproduce.metrics import Metrics, compute_metrics
from cloudprox.reproduce.realscan import run_scan
from cloudprox.reproduce.run import Config, config_levels, level_inputs, level_name, sample_scene


def main() -> None:
    """Run the variant on the levels asked for and print their metrics."""
    config = Config()
    names = [level_name(s, a) for s, a in config_levels(config)]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--levels",
        default=",".join(names),
        help=f"comma-separated level names among {', '.join(names).replace('%', '%%')}",
    )
    ap.add_argument(
        "--variant",
        default="elements,quadric,max",
        help="model,surface,aggregation (default: elements,quadric,max)",
    )
    ap.add_argument(
        "--poses",
        type=int,
        default=config.poses,
        help=f"poses per level (default {config.poses}, the full run's; others are other poses)",
    )
    ap.add_argument(
        "--piano-points",
        type=int,
        default=config.piano_points,
        help=f"points on the piano (default {config.piano_points}; the quick run's: 3000)",
    )
    ap.add_argument(
        "--kinect",
        type=int,
        default=0,
        metavar="N",
        help="also the Kinect frame with N gripper poses (0, the default: skip it)",
    )
    ap.add_argument("--save", default=None, help="write PREFIX_<level>.npz per level")
    args = ap.parse_args()
    if args.piano_points < 1:
        ap.error(f"--piano-points must be >= 1, got {args.piano_points}")
    config = dataclasses.replace(config, piano_points=args.piano_points)
    asked = [x.strip() for x in args.levels.split(",") if x.strip()]
    unknown = [x for x in asked if x not in names]
    if unknown:
        ap.error(f"unknown level(s) {unknown}; known: {names}")
    parts = tuple(args.variant.split(","))
    if len(parts) != 3:
        ap.error(f"--variant must be model,surface,aggregation, got {args.variant!r}")
    variant = (parts[0], parts[1], parts[2])
    if args.poses < 1:
        ap.error(f"--poses must be >= 1, got {args.poses}")
    if args.kinect < 0:
        ap.error(f"--kinect must be >= 0, got {args.kinect}")
    try:
        m.model_options(variant[0])
    except ValueError as e:
        ap.error(str(e))
    scene = sample_scene(config) if asked else None
    for k, name in enumerate(names):
        if name not in asked:
            continue
        assert scene is not None  # sampled whenever a level is asked for
        sigma, q, draws = level_inputs(config, k, scene, args.poses)
        t0 = time.perf_counter()
        answers = m.variant_answers(draws, q.poses, (variant,), None, lambda *_: None, name)
        ans = answers[m.variant_name(*variant)]
        sc = np.stack([x.score for x in ans])
        st = np.stack([x.state for x in ans])
        sec = np.stack([x.seconds for x in ans])
        mt = compute_metrics(sc, st, sec, q.signed_distance, sigma)
        report(name, time.perf_counter() - t0, mt, q.signed_distance / sigma, st)
        if args.save:
            np.savez(
                f"{args.save}_{name.replace(' ', '-').replace('%', 'pc')}.npz",
                score=sc,
                state=st,
                seconds=sec,
                signed_distance=q.signed_distance,
                sigma=sigma,
            )
    if args.kinect > 0:
        t0 = time.perf_counter()
        scan = run_scan(args.kinect, config.seed, (variant,), lambda *_: None)
        row = m.variant_name(*variant)
        unit = scan.poses.signed_distance / scan.poses.sigma
        report("Kinect", time.perf_counter() - t0, scan.metrics[row], unit, scan.states[row])


def report(name: str, seconds: float, mt: Metrics, unit: np.ndarray, states: np.ndarray) -> None:
    """Print a level's metrics and its missed collisions deeper than 3 sigma.

    ``unit`` holds the poses' exact signed distances in sigma, ``states`` the
    variant's states per draw and pose.
    """
    print(
        f"{name}: {seconds:.0f} s; AUC near {mt.auc_near:.3f}, "
        f"decided {mt.decided_accuracy:.3f}, undecided {100 * mt.undecided:.1f}%, "
        f"flips {100 * mt.hard_flip:.2f}%, FP > 3 sigma {100 * mt.false_positive_3s:.2f}%, "
        f"FN < -3 sigma {100 * mt.false_negative_3s:.2f}%, median {mt.median_ms:.2f} ms",
        flush=True,
    )
    draw, pose = np.nonzero((unit[None, :] < -3.0) & (states == "free"))
    misses = [(int(i), int(j), round(float(unit[j]), 2)) for i, j in zip(draw, pose, strict=True)]
    print(f"  missed deeper than 3 sigma (draw, pose, sigma): {misses}", flush=True)


if __name__ == "__main__":
    main()
