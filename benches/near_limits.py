"""What bounds the near-contact AUC on the piano: the noise, or the sampling.

Runs cloudprox variants on one of the reproduction's synthetic levels with the
noise scaled by a factor (the poses, and so the near band of 5 sigma, stay the
level's) and with the piano sampled at other densities. With the noise scaled
far down, what is left of the AUC loss is the sampling's: where the sampled
surfaces end and how they run between samples. Also printed: the AUC the
same scores would reach if every pose farther than one sigma from contact
were ranked perfectly (collisions first), which shows how much of the loss
lies within one sigma of contact.

Usage: ``python3 benches/near_limits.py [--level 0.5%] [--poses 1000]
[--noise 1,0.3,0.03] [--piano-points 10000,40000]
[--variants 'elements,quadric,max;points,quadric,max']``. Each variant, noise
factor and density takes 5-20 s at 1000 poses on 2 cores (the denser
piano's scene takes a minute to sample).
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from cloudprox.reproduce import methods as m
from cloudprox.reproduce.metrics import NEAR_SIGMA, auc, compute_metrics
from cloudprox.reproduce.noise import NoiseModel
from cloudprox.reproduce.poses import sample_poses
from cloudprox.reproduce.run import Config, config_levels, level_name, sample_scene


def _floats(text: str) -> list[float]:
    return [float(x) for x in text.split(",") if x.strip()]


def main() -> None:
    """Run the variants at each density and noise factor and print their near-contact metrics."""
    config = Config()
    names = [level_name(s, a) for s, a in config_levels(config)]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    known = ", ".join(names).replace("%", "%%")
    ap.add_argument("--level", default=names[0], help=f"one of {known}")
    ap.add_argument("--poses", type=int, default=1000, help="poses (default 1000)")
    ap.add_argument("--noise", default="1,0.3,0.03", help="noise factors (default 1,0.3,0.03)")
    ap.add_argument("--piano-points", default="10000", help="piano densities (default 10000)")
    ap.add_argument(
        "--variants",
        default="elements,quadric,max;points,quadric,max",
        help="model,surface,aggregation triples separated by ';'",
    )
    args = ap.parse_args()
    if args.level not in names:
        ap.error(f"unknown level {args.level!r}; known: {names}")
    if args.poses < 1:
        ap.error(f"--poses must be >= 1, got {args.poses}")
    factors = _floats(args.noise)
    if not factors or any(not (f > 0.0) for f in factors):
        ap.error(f"--noise must be positive factors, got {args.noise!r}")
    densities = [int(x) for x in _floats(args.piano_points)]
    if not densities or any(n < 1 for n in densities):
        ap.error(f"--piano-points must be positive, got {args.piano_points!r}")
    variants = []
    for v in args.variants.split(";"):
        parts = tuple(x.strip() for x in v.split(","))
        if len(parts) != 3:
            ap.error(f"a variant is model,surface,aggregation, got {v!r}")
        variants.append((parts[0], parts[1], parts[2]))
    k = names.index(args.level)
    share, aniso = config_levels(config)[k]
    axes = (0.0, -3.0, 2.0) if aniso else None
    for density in densities:
        scene = sample_scene(dataclasses.replace(config, piano_points=density))
        sigma = share * scene.piano.diagonal
        rng = np.random.default_rng(config.seed * 1000 + k)
        q = sample_poses(scene.piano, scene.room, args.poses, sigma, rng)
        unit = q.signed_distance / sigma
        near = np.abs(unit) <= NEAR_SIGMA
        label = unit < 0.0
        print(
            f"{args.level}, {density} piano points: sigma {1e3 * sigma:.1f} mm, spacing "
            f"{1e3 * scene.spacing:.1f} mm ({scene.spacing / sigma:.2f} sigma), "
            f"{int(near.sum())} near poses",
            flush=True,
        )
        for factor in factors:
            noise = NoiseModel(factor * sigma, axes)
            draws = []
            for _ in range(config.draws):
                a, ca = noise.draw(scene.piano_points, rng)
                b, cb = noise.draw(scene.room_points, rng)
                draw = m.Draw(a, ca, b, cb)
                draw.clouds()
                draws.append(draw)
            for variant in variants:
                answers = m.variant_answers(
                    draws, q.poses, (variant,), None, lambda *_: None, args.level
                )[m.variant_name(*variant)]
                score = np.stack([x.score for x in answers])
                state = np.stack([x.state for x in answers])
                seconds = np.stack([x.seconds for x in answers])
                mt = compute_metrics(score, state, seconds, q.signed_distance, sigma)
                ideal = score.copy()
                ideal[:, unit < -1.0] = 1.0
                ideal[:, unit > 1.0] = 0.0
                bound = np.mean([auc(s[near], label[near]) for s in ideal])
                print(
                    f"  noise x{factor:g}, {variant[0]} {variant[2]}: AUC near {mt.auc_near:.3f} "
                    f"(beyond 1 sigma perfect: {bound:.3f}), decided {mt.decided_accuracy:.3f}, "
                    f"undecided {100 * mt.undecided:.1f}%, flips {100 * mt.hard_flip:.2f}%",
                    flush=True,
                )


if __name__ == "__main__":
    main()
