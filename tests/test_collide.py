"""The binding contract of ``collide`` and its result: shapes, dtypes, options
passed through, poses, threads. The query's properties (monotone in the gap,
invariances, closed forms, aggregations, models) are tested in Rust
(``crates/cloudprox/tests/collide_*.rs``)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_rotation_vector, from_translation
from tests.helpers import phi, sphere_gap_pose


def test_result_fields(spheres) -> None:
    a, b = spheres
    r = cp.collide(a, b, pose_b=sphere_gap_pose(1.0), model="points")
    assert r.state in ("free", "contact", "collision")
    assert r.probabilities_a.shape == (len(a),) and r.probabilities_a.dtype == np.float64
    assert r.probabilities_b.shape == (len(b),) and r.probabilities_b.dtype == np.float64
    assert r.probability == pytest.approx(
        max(r.probabilities_a.max(), r.probabilities_b.max()), abs=0.0
    )
    # Far apart (decided by the bounds) and deciding only: every point still counted.
    for far in (
        cp.collide(a, b, pose_b=sphere_gap_pose(50.0)),
        cp.collide(a, b, pose_b=sphere_gap_pose(1.0), decide_only=True),
    ):
        assert far.probabilities_a.shape == (len(a),)
        assert far.probabilities_b.shape == (len(b),)
    for (idx, val), dense in ((r.nonzero_a, r.probabilities_a), (r.nonzero_b, r.probabilities_b)):
        assert idx.dtype == np.int64 and val.dtype == np.float64
        np.testing.assert_array_equal(idx, np.flatnonzero(dense))
        np.testing.assert_array_equal(val, dense[idx])
    assert isinstance(r.stats, cp.QueryStats)
    assert set(r.stats.to_dict()) == {
        "node_pairs_visited",
        "leaf_pairs",
        "near_regions",
        "patches",
        "misfit_cuts",
        "patches_beyond_reach",
        "surface_crossings",
        "surface_links",
        "points_classified",
        "solver_iterations",
        "clarabel_fallbacks",
        "solver_fallbacks",
        "pruned_bound",
        "time_seconds",
    }
    assert all(
        isinstance(v, int)
        for k, v in r.stats.to_dict().items()
        if k not in ("pruned_bound", "time_seconds")
    )
    assert r.stats.patches == len(r.patches) > 0
    assert r.stats.points_classified == sum(len(g.indices_a) + len(g.indices_b) for g in r.patches)
    assert "CollisionResult(probability=" in repr(r)
    for region in r.patches:
        assert region.indices_a.dtype == np.int64 and region.indices_b.dtype == np.int64
        assert region.point.shape == (3,) and region.normal.shape == (3,)
        assert np.linalg.norm(region.normal) == pytest.approx(1.0)
        assert region.normal[0] > 0.5  # from A (at the origin) towards B (along +x)
        assert region.surface == "quadric"
        assert region.status in ("solved", "almost_solved", "fallback")
        # The interior-point method takes at least one step to a solution.
        assert region.iterations >= 1 or region.status == "fallback"
        assert 0.0 <= region.probability <= 1.0
        assert isinstance(region.separation, float) and isinstance(region.component, int)
        assert "ContactPatch(" in repr(region)
    # The patches list is fresh, its elements are the same objects.
    assert r.patches is not r.patches and r.patches[0] is r.patches[0]


def test_per_point_probabilities_match_closed_form(spheres, sphere_points) -> None:
    a, b = spheres
    pose_b = sphere_gap_pose(1.0)
    r = cp.collide(a, b, pose_b=pose_b)
    world_a = sphere_points[0]
    world_b = sphere_points[1] + pose_b[:3, 3]
    covs_a, covs_b = a.covariances, b.covariances  # pure translation: unrotated
    seen_a = np.zeros(len(a), dtype=bool)
    for region in r.patches:
        for idx, pts, covs, label, probs, seen in (
            (region.indices_a, world_a, covs_a, 1.0, r.probabilities_a, seen_a),
            (region.indices_b, world_b, covs_b, -1.0, r.probabilities_b, None),
        ):
            f, g = region.evaluate(pts[idx])
            std = np.sqrt(np.einsum("mi,mij,mj->m", g, covs[idx], g))
            expected = phi(-label * f / std)
            np.testing.assert_allclose(probs[idx], expected, rtol=1e-9, atol=1e-15)
            if seen is not None:
                seen[idx] = True
    # Points outside every region get probability 0.
    assert np.all(r.probabilities_a[~seen_a] == 0.0)
    assert seen_a.sum() < len(a)


def test_moving_the_cloud_or_the_pose_is_the_same(spheres) -> None:
    a, b = spheres
    g = from_rotation_vector(np.array([0.3, -0.4, 1.0]), np.array([1.0, 2.0, -0.5]))
    pose_b = sphere_gap_pose(1.0)
    by_pose = cp.collide(a, b, pose_a=g, pose_b=g @ pose_b, model="points")
    by_cloud = cp.collide(a.transformed(g), b.transformed(g @ pose_b), model="points")
    assert by_cloud.probability == pytest.approx(by_pose.probability, abs=1e-6)
    np.testing.assert_allclose(by_cloud.probabilities_a, by_pose.probabilities_a, atol=1e-6)
    # The elements model on the same clouds: moving both poses moves nothing.
    for gap in (-1.0, 0.0, 1.0):
        pose_b = sphere_gap_pose(gap)
        at_rest = cp.collide(a, b, pose_b=pose_b, model="elements")
        moved = cp.collide(a, b, pose_a=g, pose_b=g @ pose_b, model="elements")
        assert moved.probability == pytest.approx(at_rest.probability, abs=1e-9)
        assert moved.state == at_rest.state
    # Moved points are grouped into elements anew, in their own frame: a
    # sphere's principal axes are degenerate, so its top-down splits run
    # elsewhere, and P moves as a new noise draw moves it (near contact by
    # several tenths). Three sigma apart the state is the same.
    pose_far = sphere_gap_pose(3.0)
    by_pose = cp.collide(a, b, pose_a=g, pose_b=g @ pose_far, model="elements")
    by_cloud = cp.collide(a.transformed(g), b.transformed(g @ pose_far), model="elements")
    assert by_cloud.state == by_pose.state
    assert by_cloud.probability == pytest.approx(by_pose.probability, abs=0.05)


def test_collide_many_equals_a_loop(spheres) -> None:
    a, b = spheres
    poses = np.stack([np.linalg.inv(sphere_gap_pose(g)) for g in (-2.0, 0.0, 1.0, 5.0, 12.0)])
    pose_b = from_translation((0.3, -0.1, 0.2))
    poses = pose_b @ poses  # A placed relative to B at each gap
    many = cp.collide_many(a, b, poses, pose_b, aggregation="union")
    assert isinstance(many, list) and len(many) == len(poses)
    for pose, r in zip(poses, many, strict=False):
        one = cp.collide(a, b, pose, pose_b, aggregation="union")
        assert r.probability == one.probability
        assert r.state == one.state
        np.testing.assert_array_equal(r.probabilities_a, one.probabilities_a)
        np.testing.assert_array_equal(r.probabilities_b, one.probabilities_b)
        assert len(r.patches) == len(one.patches)
    assert cp.collide_many(a, b, np.zeros((0, 4, 4))) == []


def test_collide_along_answers_as_collide_many(spheres) -> None:
    # A approaching B from 6 sigma apart to 3 sigma in, quarter-sigma steps: the
    # answers of the warm-started runs are collide_many's to the solver's
    # tolerance, with fewer solver iterations.
    a, b = spheres
    poses = np.stack([np.linalg.inv(sphere_gap_pose(g)) for g in np.arange(6.0, -3.01, -0.25)])
    along = cp.collide_along(a, b, poses)
    many = cp.collide_many(a, b, poses)
    assert len(along) == len(many) == len(poses)
    for r, m in zip(along, many, strict=True):
        assert r.probability == pytest.approx(m.probability, abs=1e-4)
        np.testing.assert_allclose(r.probabilities_b, m.probabilities_b, atol=1e-4)
    iterations = [sum(r.stats.solver_iterations for r in rs) for rs in (along, many)]
    assert 0 < iterations[0] < iterations[1]
    assert cp.collide_along(a, b, np.zeros((0, 4, 4))) == []
    with pytest.raises(cp.InvalidInputError, match="poses_a"):
        cp.collide_along(a, b, np.zeros((3, 4)))


def test_options_take_effect(spheres) -> None:
    a, b = spheres
    pose_b = sphere_gap_pose(4.0)
    default = cp.collide(a, b, pose_b=pose_b)
    explicit = cp.collide(a, b, pose_b=pose_b, **cp.CollisionRequest().to_dict())
    assert explicit.probability == default.probability
    # The paper's model's options (aggregations, patch size).
    base = cp.collide(a, b, pose_b=pose_b, model="points")
    union = cp.collide(a, b, pose_b=pose_b, aggregation="union", model="points")
    independent = cp.collide(a, b, pose_b=pose_b, aggregation="independent", model="points")
    assert base.probability <= independent.probability <= union.probability
    # One points query gives the paper's three aggregates, exactly.
    assert base.point_aggregates == {
        "max": base.probability,
        "union": union.probability,
        "independent": independent.probability,
    }
    assert cp.collide(a, b, pose_b=pose_b, model="elements").point_aggregates is None
    linear = cp.collide(a, b, pose_b=pose_b, surface="linear", model="points")
    assert all(r.surface == "linear" for r in linear.patches)
    strict = cp.collide(
        a, b, pose_b=pose_b, threshold_collision=0.5, threshold_free=0.0, model="points"
    )
    assert strict.probability == base.probability
    assert strict.state == ("collision" if base.probability >= 0.5 else "contact")
    small = cp.collide(a, b, pose_b=pose_b, region_max_points=40, model="points")
    assert len(small.patches) > len(base.patches)

    def mean_size(r: cp.CollisionResult) -> float:
        return float(np.mean([len(g.indices_a) + len(g.indices_b) for g in r.patches]))

    assert mean_size(small) <= 40 < mean_size(base)
    # The brute force tests every point pair with the same near rule: one region,
    # the same points, the same P as the hierarchy (which finds one region here).
    hier = cp.collide(a, b, pose_b=sphere_gap_pose(2.0), model="points")
    brute = cp.collide(a, b, pose_b=sphere_gap_pose(2.0), use_hierarchy=False, model="points")
    assert hier.stats.near_regions == 1
    assert brute.stats.points_classified == hier.stats.points_classified > 0
    assert brute.probability == pytest.approx(hier.probability, abs=1e-9)
    assert brute.stats.node_pairs_visited == 0


def test_queries_run_in_threads_with_the_same_answers(spheres) -> None:
    a, b = spheres
    poses = [sphere_gap_pose(g) for g in (0.0, 2.0, 4.0, 6.0)]
    expected = [cp.collide(a, b, pose_b=p).probability for p in poses]
    got: dict[int, float] = {}

    def work(k: int) -> None:
        got[k] = cp.collide(a, b, pose_b=poses[k]).probability

    threads = [threading.Thread(target=work, args=(k,)) for k in range(len(poses))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [got[k] for k in range(len(poses))] == expected


def test_elements_model_rejects_the_surface_aggregation(spheres) -> None:
    a, b = spheres
    with pytest.raises(cp.InvalidInputError, match="aggregation 'surface'"):
        cp.collide(a, b, model="elements", aggregation="surface")
    with pytest.raises(cp.InvalidInputError, match="unknown model 'surfels'"):
        cp.collide(a, b, model="surfels")


def test_a_batch_of_results_holds_the_contacts_not_the_clouds() -> None:
    # A small sphere touching a 200 000-point floor: each result keeps the
    # probabilities of the points near the contact, not 200 000 zeros.
    import pickle

    rng = np.random.default_rng(3)
    floor = cp.PointCloud(
        np.column_stack([rng.uniform(-2, 2, (200_000, 2)), rng.normal(0, 1e-3, 200_000)]),
        sigma=1e-3,
    )
    d = rng.normal(size=(500, 3))
    ball = cp.PointCloud(0.05 * d / np.linalg.norm(d, axis=1, keepdims=True), sigma=1e-3)
    poses = [from_translation([0.0, 0.0, 0.05 + gap]) for gap in (0.0, 0.001, 0.003)]
    results = cp.collide_many(ball, floor, poses, model="points")
    for r in results:
        idx, val = r.nonzero_b
        assert 0 < len(idx) < 5_000 and np.all(val > 0.0)
        assert r.probabilities_b.shape == (200_000,)
        assert np.count_nonzero(r.probabilities_b) == len(idx)
        assert len(pickle.dumps(r)) < 200_000
