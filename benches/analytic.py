"""Calibration of P on analytic shapes against the noise model, larger than the tests.

The scenes of ``tests/test_calibration_analytic.py`` (its module docs give the
derivations): parallel plates (two 0.2 m slabs whose facing ``k x k`` grids are
``g`` apart), two spheres of radius 0.1 m with area-uniform samples (four
disjoint contacts per pair of clouds), and two 0.2 m cubes face to face
(grid-sampled on every face). Isotropic noise ``sigma``; true gaps uniform
within +-3 standard errors of the estimated gap (``unit`` in the table:
``sigma sqrt(2 / n)``, ``n`` the points of a face or of the sphere's cap that
is flat to within ``sigma``); label ``g < 0``. One fresh noise draw per gap
(per four gaps for the spheres).

Columns: draws; the prior's unit (mm); ECE and the ECE a calibrated P with the
same values stays below by chance (99.9 %, labels drawn as Bernoulli(P), plus
the bounded prior's own 0.003); Brier score; log-loss; the worst bin holding 20
or more draws (|mean P - observed frequency|); mean P minus the share that
collides (calibration in the large: > 0 leans to collision, < 0 to free);
mean P at the draws within 0.5 unit of contact (0.5 for a calibrated P); the
standardized residuals ``(g_true - gap) / std`` of the elements' facing pairs
within reach, pooled over the first ``--residual-draws`` draws (mean, sd:
0 and 1 when the gaps and their variances are right; bias and over-confidence
show as either off) and the pairs' median std in units; median query time
(clouds prepared) and median time to build both clouds' elements.

Usage: ``python3 benches/analytic.py [--draws 400] [--residual-draws 100]
[--scenes plates,plates41,spheres2000,spheres10000,boxes] [--sigmas 1,5]
[--model elements] [--seed 0] [--reliability]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.test_calibration_analytic import (
    Scene,
    boxes,
    ece_tolerance,
    plates,
    prior_gaps,
    run_draws,
    spheres,
)

import cloudprox as cp
from cloudprox.reproduce.metrics import calibration

#: Scene names of ``--scenes`` and how to make each at a noise sigma (metres).
SCENES = {
    "plates": lambda s: plates(s, k=21),
    "plates41": lambda s: plates(s, k=41),
    "spheres2000": lambda s: spheres(2000, s),
    "spheres10000": lambda s: spheres(10_000, s),
    "boxes": lambda s: boxes(s),
}


def row(scene: Scene, draws: int, residual_draws: int, seed: int, request: cp.CollisionRequest):
    """Run ``scene`` and return its table cells and calibration."""
    d = run_draws(
        scene,
        prior_gaps(scene, draws, seed),
        seed + 1,
        residuals=residual_draws,
        request=request,
    )
    label = d.gap < 0.0
    cal = calibration(d.p, label)
    near = np.abs(d.gap) <= 0.5 * scene.sigma_gap
    kept = [r for r in d.residuals if len(r)]
    z = np.concatenate(kept) if kept else np.zeros(0)
    beside = np.concatenate([b for b in d.beside if len(b)]) if kept else np.zeros(0, bool)
    std = np.concatenate([s for s in d.pair_std if len(s)]) if kept else np.zeros(0)
    cell = lambda x: f"{np.mean(x):+.2f} / {np.std(x):.2f}" if len(x) else "-"  # noqa: E731
    cells = [
        scene.name,
        f"{draws}",
        f"{1e3 * scene.sigma_gap:.3f}",
        f"{cal.ece:.3f}",
        f"{ece_tolerance(d.p):.3f}",
        f"{cal.brier:.3f}",
        f"{cal.log_loss:.3f}",
        f"{cal.worst_bin():.3f}",
        f"{np.mean(d.p) - np.mean(label):+.3f}",
        f"{np.mean(d.p[near]):.2f} ({int(near.sum())})" if near.any() else "-",
        f"{cell(z)} ({len(z)} in {len(kept)})",
        cell(z[~beside]),
        cell(z[beside]),
        f"{np.median(std) / scene.sigma_gap:.2f}" if len(std) else "-",
        f"{1e3 * np.median(d.seconds):.2f}",
        f"{1e3 * np.median(d.build_seconds):.1f}",
    ]
    return cells, cal


HEAD = (
    "| scene | draws | unit mm | ECE | ECE tol. | Brier | log-loss | worst bin | mean P - freq "
    "| mean P near 0 (draws) | residual mean / sd (pairs in draws) | over | beside "
    "| pair std / unit | query ms | build ms |"
)


def main() -> None:
    """Run the scenes at every sigma and print one table (and the reliability tables)."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--draws", type=int, default=400, help="noise draws (true gaps) per scene")
    ap.add_argument(
        "--residual-draws", type=int, default=100, help="draws whose facing pairs are read"
    )
    ap.add_argument("--scenes", default=",".join(SCENES), help=f"among {', '.join(SCENES)}")
    ap.add_argument("--sigmas", default="1,5", help="noise sigmas in mm, comma-separated")
    ap.add_argument("--model", default=None, help="the request's model (default: the default)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--reliability", action="store_true", help="also print each scene's reliability table"
    )
    args = ap.parse_args()
    names = [x.strip() for x in args.scenes.split(",") if x.strip()]
    unknown = [x for x in names if x not in SCENES]
    if unknown or not names:
        ap.error(f"unknown or no scenes {unknown}; known: {', '.join(SCENES)}")
    if args.draws < 10 or args.residual_draws < 0:
        ap.error("--draws must be >= 10 and --residual-draws >= 0")
    sigmas = [float(x) * 1e-3 for x in args.sigmas.split(",") if x.strip()]
    request = cp.CollisionRequest(model=args.model) if args.model else cp.CollisionRequest()
    print(f"model {request.model}\n")
    print(HEAD)
    print("|" + "---|" * (HEAD.count("|") - 1))
    tables = []
    for k, name in enumerate(names):
        for j, sigma in enumerate(sigmas):
            scene = SCENES[name](sigma)
            t0 = time.perf_counter()
            seed = args.seed * 10_000 + 100 * k + j
            cells, cal = row(scene, args.draws, min(args.residual_draws, args.draws), seed, request)
            print("| " + " | ".join(cells) + " |", flush=True)
            print(f"{scene.name}: {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
            tables.append((scene.name, cal))
    if args.reliability:
        for name, cal in tables:
            print(f"\n{name}: P bin | draws | mean P | share colliding")
            for lo, hi, n, p, f in cal.table:
                print(f"  [{lo:.1f}, {hi:.1f}) | {n} | {p:.3f} | {f:.3f}")


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"\n({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
