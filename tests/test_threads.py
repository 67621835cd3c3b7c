"""The binding's thread contract: queries release the GIL and share clouds safely.

``collide`` called from eight Python threads at once, on fresh clouds whose
hierarchies are built on first use (so the lazy builds race), returns exactly
what serial calls return.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import pose, synthetic

SIGMA = 0.002


def clouds() -> tuple[cp.PointCloud, cp.PointCloud]:
    """Two noisy spheres of radius 0.1 m, built fresh (nothing cached yet)."""
    ball = synthetic.sample_sphere(2000, radius=0.1)
    a = cp.PointCloud(synthetic.add_noise(ball, SIGMA, seed=1), sigma=SIGMA)
    b = cp.PointCloud(synthetic.add_noise(ball, SIGMA, seed=2), sigma=SIGMA)
    return a, b


POSES = [pose.from_translation((0.2 + k * SIGMA, 0.0, 0.0)) for k in (-6, -2, 0, 1, 3, 8)]


def same(r: cp.CollisionResult, s: cp.CollisionResult) -> bool:
    """Equal answers: probability, state, per-point probabilities, counters."""
    counters = {k: v for k, v in r.stats.to_dict().items() if k != "time_seconds"}
    others = {k: v for k, v in s.stats.to_dict().items() if k != "time_seconds"}
    return (
        r.probability == s.probability
        and r.state == s.state
        and np.array_equal(r.probabilities_a, s.probabilities_a)
        and np.array_equal(r.probabilities_b, s.probabilities_b)
        and counters == others
    )


@pytest.mark.parametrize("model", ["points", "elements"])
def test_eight_threads_on_shared_fresh_clouds_get_the_serial_answers(model: str) -> None:
    request = cp.CollisionRequest(model=model)
    a, b = clouds()
    serial = [cp.collide(a, b, pose_b=p, request=request) for p in POSES]
    a, b = clouds()
    jobs = [k % len(POSES) for k in range(8 * len(POSES))]
    with ThreadPoolExecutor(max_workers=8) as pool:
        results = list(pool.map(lambda k: cp.collide(a, b, pose_b=POSES[k], request=request), jobs))
    for k, r in zip(jobs, results, strict=True):
        assert same(r, serial[k]), (model, k)


def test_collide_many_from_threads_matches_collide() -> None:
    a, b = clouds()
    poses = np.stack(POSES)
    single = [cp.collide(b, a, pose_a=p) for p in POSES]
    with ThreadPoolExecutor(max_workers=4) as pool:
        batches = list(pool.map(lambda _: cp.collide_many(b, a, poses), range(4)))
    for batch in batches:
        assert all(same(r, s) for r, s in zip(batch, single, strict=True))


@pytest.mark.parametrize("model", ["points", "elements"])
def test_prepared_clouds_answer_as_clouds_built_on_first_use(model: str) -> None:
    a, b = clouds()
    lazy = [cp.collide(a, b, pose_b=p, model=model) for p in POSES]
    a, b = clouds()
    a.prepare(model=model)
    b.prepare(cp.CollisionRequest(model=model))
    b.prepare(model=model)  # again: nothing left to build
    with ThreadPoolExecutor(max_workers=4) as pool:
        prepared = list(pool.map(lambda p: cp.collide(a, b, pose_b=p, model=model), POSES))
    assert all(same(r, s) for r, s in zip(prepared, lazy, strict=True))


def test_prepare_refuses_what_a_query_refuses() -> None:
    a, _ = clouds()
    with pytest.raises(cp.InvalidInputError, match="model"):
        a.prepare(model="voxels")
    with pytest.raises(cp.InvalidInputError, match="mesh_spacing"):
        a.prepare(mesh_spacing=0.01)
