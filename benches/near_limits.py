"""What bounds the near-contact AUC on the piano: the noise, or the sampling.

Runs cloudprox variants on one of the reproduction's synthetic levels with the
noise scaled by a factor (the poses, and so the near band of 5 sigma, stay the
level's) and with the piano sampled at other densities. With the noise scaled
far down, what is left of the AUC loss is the sampling's: where the sampled
surfaces end and how they run between samples. Each factor's draws start from
the same generator state, so the factors see the same underlying normals
scaled, and factor 1 gives ``benches/reproduce_levels.py``'s draws (same
``--poses`` and ``--piano-points``) wherever it is in the list.

Also printed, per row: the near-contact AUC the same scores reach when every
pose farther than 1 sigma from contact is ranked perfectly (collisions above
every score, free poses below), which shows how much is lost among the poses
within 1 sigma; and, per density, the AUC of a score that ranks every pose
beyond ``w`` sigma perfectly and is blind within (``w`` = 0.5, 1 and half the
sampling spacing), a property of the poses alone.

Usage: ``python3 benches/near_limits.py [--level 0.5%] [--poses 1000]
[--noise 1,0.3,0.03] [--piano-points 10000]
[--variants 'elements,quadric,max;points,quadric,max']``. Each variant, noise
factor and density takes 5-20 s at 1000 poses on 2 cores (the scene at 40 000
piano points takes a minute to sample).
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from cloudprox.reproduce import methods as m
from cloudprox.reproduce.metrics import NEAR_SIGMA, auc_near, compute_metrics
from cloudprox.reproduce.noise import NoiseModel
from cloudprox.reproduce.poses import sample_poses
from cloudprox.reproduce.run import Config, config_levels, level_name, sample_scene


def _numbers(text: str, what: str, ap: argparse.ArgumentParser) -> list[float]:
    try:
        values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        ap.error(f"{what} must be comma-separated numbers, got {text!r}")
    if not values or not all(np.isfinite(v) and v > 0.0 for v in values):
        ap.error(f"{what} must be finite and > 0, got {text!r}")
    return values


def ranked_beyond(
    score: np.ndarray, signed_distance: np.ndarray, sigma: float, w: float
) -> np.ndarray:
    """``score`` (draws, poses) with every pose beyond ``w`` sigma of contact ranked perfectly.

    Collisions deeper than ``w`` sigma score above every score (2), free poses
    farther than ``w`` sigma below every score (-1), so no tie with a real
    score of 0 or 1 is left.
    """
    out = np.array(score, dtype=float, copy=True)
    unit = signed_distance / sigma
    out[:, unit < -w] = 2.0
    out[:, unit > w] = -1.0
    return out


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
    factors = _numbers(args.noise, "--noise", ap)
    densities = []
    for x in _numbers(args.piano_points, "--piano-points", ap):
        if x != int(x):
            ap.error(f"--piano-points must be whole numbers, got {args.piano_points!r}")
        densities.append(int(x))
    variants = []
    for v in args.variants.split(";"):
        parts = tuple(x.strip() for x in v.split(","))
        if (
            len(parts) != 3
            or parts[0] not in ("points", "elements")
            or parts[1] not in ("quadric", "linear")
            or parts[2] not in m.AGGREGATIONS
        ):
            ap.error(
                f"a variant is model,surface,aggregation (points|elements, quadric|linear, "
                f"{'|'.join(m.AGGREGATIONS)}), got {v!r}"
            )
        variants.append((parts[0], parts[1], parts[2]))
    k = names.index(args.level)
    share, aniso = config_levels(config)[k]
    axes = (0.0, -3.0, 2.0) if aniso else None
    for density in densities:
        scene = sample_scene(dataclasses.replace(config, piano_points=density))
        sigma = share * scene.piano.diagonal
        rng = np.random.default_rng(config.seed * 1000 + k)
        q = sample_poses(scene.piano, scene.room, args.poses, sigma, rng)
        d = q.signed_distance
        near = np.abs(d) <= NEAR_SIGMA * sigma
        print(
            f"{args.level}, {density} piano points: sigma {1e3 * sigma:.1f} mm, spacing "
            f"{1e3 * scene.spacing:.1f} mm ({scene.spacing / sigma:.2f} sigma), "
            f"{int(near.sum())} near poses",
            flush=True,
        )
        blind = []
        for w in (0.5, 1.0, 0.5 * scene.spacing / sigma):
            s = ranked_beyond(np.full((1, len(d)), 0.5), d, sigma, w)
            blind.append(f"{auc_near(s, d, sigma):.3f} at w = {w:.2f}")
        print(f"  perfect beyond w sigma, blind within: {', '.join(blind)}", flush=True)
        start = rng.bit_generator.state
        for factor in factors:
            rng.bit_generator.state = start
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
                mt = compute_metrics(score, state, seconds, d, sigma)
                bound = auc_near(ranked_beyond(score, d, sigma, 1.0), d, sigma)
                print(
                    f"  noise x{factor:g}, {m.variant_name(*variant)}: AUC near {mt.auc_near:.3f} "
                    f"(beyond 1 sigma perfect: {bound:.3f}), decided {mt.decided_accuracy:.3f}, "
                    f"undecided {100 * mt.undecided:.1f}%, flips {100 * mt.hard_flip:.2f}%",
                    flush=True,
                )


if __name__ == "__main__":
    main()
