"""The full reproduction's Python baselines on one level, alone, timed as the run times them.

The same scene, poses and noise draws as ``cloudprox reproduce`` (its
``level_inputs``), a process pool of 2 spawned workers (the run's), then the
point baselines (nn-gap, collision map, spheres: ``point_baseline_answers``)
and reconstruct-then-collide (the level's reconstructions, then the exact
checks), each stage's wall time printed with the baselines' median ms; the
scores are saved to compare two builds (``np.array_equal``).

Usage: ``python3 benches/reproduce_baselines.py LEVEL_INDEX OUT.npz [POSES]``
(level 0 = 0.5%, 1 = 1%, 2 = 2%, 3 = 1% aniso; poses default the run's 5000).
"""

from __future__ import annotations

import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from cloudprox.reproduce import methods as m
from cloudprox.reproduce.run import Config, config_levels, level_inputs, level_name, sample_scene


def main() -> None:
    """Time one level's baselines and save their scores."""
    if len(sys.argv) not in (3, 4):
        raise SystemExit(__doc__)
    k, out = int(sys.argv[1]), sys.argv[2]
    config = Config()
    n = int(sys.argv[3]) if len(sys.argv) > 3 else config.poses
    scene = sample_scene(config)
    spacing = scene.spacing
    share, aniso = config_levels(config)[k]
    sigma, q, draws = level_inputs(config, k, scene, n)
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        list(pool.map(int, [0, 0]))  # workers started before the clock
        t = time.perf_counter()
        answers = m.point_baseline_answers(draws, q.poses, spacing, pool, 2)
        t_baselines = time.perf_counter() - t
        t = time.perf_counter()
        m.reconstruct_draws(draws, spacing, sigma, pool)
        recon = [m.reconstruct_answer(d, q.poses, spacing, sigma) for d in draws]
        t_recon = time.perf_counter() - t
    save = {"reconstruct_score": np.stack([x.score for x in recon])}
    medians = {}
    for name, ans in answers.items():
        save[f"{name}_score"] = np.stack([x.score for x in ans])
        medians[name] = round(float(np.median(np.stack([x.seconds for x in ans]))) * 1e3, 2)
    np.savez(out, **save)
    print(
        f"{level_name(share, aniso)}: {n} poses x {len(draws)} draws; point baselines "
        f"{t_baselines:.1f} s (median ms {medians}), reconstructions + exact checks {t_recon:.1f} s"
    )


if __name__ == "__main__":
    main()
