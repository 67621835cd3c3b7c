from __future__ import annotations

import threading

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cloudprox as cp
from cloudprox.pose import from_rotation_vector, from_translation
from tests.helpers import phi, sphere_gap_pose

GAPS = (-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 15.0)


@pytest.fixture(scope="module")
def sweep(spheres) -> dict[float, cp.CollisionResult]:
    """The paper's per-point model over the gaps (its properties are tested here)."""
    a, b = spheres
    return {g: cp.collide(a, b, pose_b=sphere_gap_pose(g), model="points") for g in GAPS}


@pytest.fixture(scope="module")
def element_sweep(spheres) -> dict[float, cp.CollisionResult]:
    """The surface-element model over the gaps."""
    a, b = spheres
    return {g: cp.collide(a, b, pose_b=sphere_gap_pose(g), model="elements") for g in GAPS}


def assert_non_increasing(sweep, gaps, slack: float = 1e-12) -> None:
    p = [sweep[g].probability for g in gaps]
    assert all(0.0 <= x <= 1.0 for x in p)
    for (g0, p0), (g1, p1) in zip(
        zip(gaps, p, strict=False), zip(gaps[1:], p[1:], strict=False), strict=False
    ):
        assert p1 <= p0 + slack, f"P rose from {p0} at {g0} sigma to {p1} at {g1} sigma"
    assert p[0] > p[-1]


@pytest.mark.parametrize("model", ["points", "elements"])
def test_probability_decreases_with_separation(request, model: str) -> None:
    sweep = request.getfixturevalue("sweep" if model == "points" else "element_sweep")
    # In 2 sigma steps strictly. In 1 sigma steps P may rise by a few hundredths
    # inside the contact band, where the near region (and so the surface and its
    # worst point) changes with the gap: measured 0.532 at 2 sigma, 0.555 at 3.
    assert_non_increasing(sweep, (-3.0, -1.0, 0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 15.0))
    assert_non_increasing(sweep, GAPS, slack=0.05)


@pytest.mark.parametrize("model", ["points", "elements"])
def test_interpenetration_and_clearance(request, model: str) -> None:
    sweep = request.getfixturevalue("sweep" if model == "points" else "element_sweep")
    deep, far = sweep[-3.0], sweep[10.0]
    assert deep.probability > 0.95
    assert deep.state == "collision"
    assert far.probability < 0.01
    assert far.state == "free"
    # Beyond the hierarchy's reach nothing is classified at all.
    assert sweep[15.0].stats.points_classified <= far.stats.points_classified


def test_result_fields(sweep, spheres) -> None:
    a, b = spheres
    r = sweep[1.0]
    assert r.state in ("free", "contact", "collision")
    assert r.probabilities_a.shape == (len(a),) and r.probabilities_a.dtype == np.float64
    assert r.probabilities_b.shape == (len(b),) and r.probabilities_b.dtype == np.float64
    assert r.probability == pytest.approx(
        max(r.probabilities_a.max(), r.probabilities_b.max()), abs=0.0
    )
    assert isinstance(r.stats, cp.QueryStats)
    assert set(r.stats.to_dict()) == {
        "node_pairs_visited",
        "leaf_pairs",
        "near_regions",
        "patches",
        "misfit_cuts",
        "patches_beyond_reach",
        "surface_crossings",
        "points_classified",
        "solver_iterations",
        "barrier_fallbacks",
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
        # The barrier method takes at least one step to a solution.
        assert region.iterations >= 1 or region.status == "fallback"
        assert 0.0 <= region.probability <= 1.0
        assert isinstance(region.separation, float) and isinstance(region.component, int)
        assert "ContactPatch(" in repr(region)
    # The patches list is fresh, its elements are the same objects.
    assert r.patches is not r.patches and r.patches[0] is r.patches[0]


def min_separation(r: cp.CollisionResult) -> float:
    return min(g.separation for g in r.patches)


def test_separation_has_the_sign_of_the_gap(sweep) -> None:
    assert min_separation(sweep[-3.0]) < 0.0 < min_separation(sweep[4.0])
    assert min_separation(sweep[-3.0]) < min_separation(sweep[0.0]) < min_separation(sweep[8.0])


def test_separation_grows_with_the_gap(sweep) -> None:
    assert min_separation(sweep[4.0]) < min_separation(sweep[10.0])


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


def test_closed_form_with_anisotropic_covariances() -> None:
    # Two plates facing each other along z, noisier across the gap than along it.
    g = np.stack(np.meshgrid(np.arange(12), np.arange(12), indexing="ij"), -1).reshape(-1, 2)
    plate = np.column_stack([0.01 * g, np.zeros(len(g))])
    rng = np.random.default_rng(0)
    cov = np.diag([4e-6, 1e-6, 9e-6])
    a = cp.PointCloud(
        plate + rng.normal(0.0, 1e-3, plate.shape), cov=np.broadcast_to(cov, (144, 3, 3))
    )
    b = cp.PointCloud(plate + rng.normal(0.0, 1e-3, plate.shape), sigma=0.002)
    r = cp.collide(a, b, pose_b=from_translation((0.0, 0.0, 0.006)), surface="linear")
    pa, pb = a.points, b.points + np.array([0.0, 0.0, 0.006])
    for region in r.patches:
        f, g = region.evaluate(pa[region.indices_a])
        std = np.sqrt(np.einsum("mi,ij,mj->m", g, cov, g))
        np.testing.assert_allclose(
            r.probabilities_a[region.indices_a], phi(-f / std), rtol=1e-9, atol=1e-15
        )
        f, g = region.evaluate(pb[region.indices_b])
        std = 0.002 * np.linalg.norm(g, axis=1)
        np.testing.assert_allclose(
            r.probabilities_b[region.indices_b], phi(f / std), rtol=1e-9, atol=1e-15
        )


def test_swapping_a_and_b(spheres) -> None:
    a, b = spheres
    pose_b = sphere_gap_pose(2.0)
    ab = cp.collide(a, b, pose_b=pose_b)
    ba = cp.collide(b, a, pose_a=pose_b)
    assert ba.probability == pytest.approx(ab.probability, abs=1e-6)
    assert ba.state == ab.state
    np.testing.assert_allclose(ba.probabilities_a, ab.probabilities_b, atol=1e-6)
    np.testing.assert_allclose(ba.probabilities_b, ab.probabilities_a, atol=1e-6)


@settings(
    max_examples=15,
    deadline=None,
    database=None,
    derandomize=True,  # reproducible in CI
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    rotvec=st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
    t=st.lists(st.floats(-5.0, 5.0), min_size=3, max_size=3),
    gap=st.sampled_from([-2.0, 0.0, 1.0, 3.0, 6.0]),
)
def test_rigid_motion_of_both_clouds_leaves_p_unchanged(spheres, rotvec, t, gap) -> None:
    a, b = spheres
    pose_b = sphere_gap_pose(gap)
    ref = cp.collide(a, b, pose_b=pose_b)
    g = from_rotation_vector(np.array(rotvec), np.array(t))
    moved = cp.collide(a, b, pose_a=g, pose_b=g @ pose_b)
    assert moved.probability == pytest.approx(ref.probability, abs=1e-6)
    assert moved.state == ref.state
    # The interior-point solver stops at a relative gap of 1e-7: per-point
    # probabilities agree to about that.
    np.testing.assert_allclose(moved.probabilities_a, ref.probabilities_a, atol=1e-5)
    np.testing.assert_allclose(moved.probabilities_b, ref.probabilities_b, atol=1e-5)


def test_moving_the_cloud_or_the_pose_is_the_same(spheres) -> None:
    a, b = spheres
    g = from_rotation_vector(np.array([0.3, -0.4, 1.0]), np.array([1.0, 2.0, -0.5]))
    pose_b = sphere_gap_pose(1.0)
    by_pose = cp.collide(a, b, pose_a=g, pose_b=g @ pose_b, model="points")
    by_cloud = cp.collide(a.transformed(g), b.transformed(g @ pose_b), model="points")
    assert by_cloud.probability == pytest.approx(by_pose.probability, abs=1e-6)
    np.testing.assert_allclose(by_cloud.probabilities_a, by_pose.probabilities_a, atol=1e-6)
    # The elements of moved points are grouped anew (median splits and merges in
    # another frame need not fall on the same points): the same state, P close.
    by_pose = cp.collide(a, b, pose_a=g, pose_b=g @ pose_b, model="elements")
    by_cloud = cp.collide(a.transformed(g), b.transformed(g @ pose_b), model="elements")
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


def test_request_defaults_match_documented_defaults() -> None:
    assert cp.CollisionRequest().to_dict() == {
        "surface": "quadric",
        "aggregation": "max",
        "threshold_collision": 0.9,
        "threshold_free": 0.1,
        "prune_epsilon": 1e-3,
        "region_max_points": 2000,
        "near_context": 2.0,
        "slack_weight": 100.0,
        "robust_eta": 0.9,
        "robust_model": "gaussian",
        "solver": "barrier",
        "use_hierarchy": True,
        "model": "points",
        "decide_only": False,
    }
    names = cp.CollisionRequest.choices()
    assert names["model"] == ("elements", "points")
    assert names["surface"] == ("linear", "quadric")
    assert names["aggregation"] == ("surface", "max", "union", "independent")
    assert names["robust_model"] == ("gaussian", "chebyshev")
    assert names["solver"] == ("barrier", "clarabel")


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


def test_zero_noise_clouds_are_decided_exactly() -> None:
    pts = cp.synthetic.sample_sphere(300, 0.1)
    a = cp.PointCloud(pts)
    b = cp.PointCloud(pts)
    far = cp.collide(a, b, pose_b=from_translation((0.25, 0.0, 0.0)))
    assert far.probability == 0.0 and far.state == "free"
    deep = cp.collide(a, b, pose_b=from_translation((0.1, 0.0, 0.0)))
    assert deep.probability == 1.0 and deep.state == "collision"


def test_surface_aggregation_sees_deep_interpenetration() -> None:
    # Two 10 cm spheres overlapping by half, 1 mm noise: the neighbourhood means
    # cancel at the crossing; the crossing test sees the surfaces cross.
    pts = cp.synthetic.sample_sphere(2000, 0.1)
    a = cp.PointCloud(cp.synthetic.add_noise(pts, 0.001, seed=1), sigma=0.001)
    b = cp.PointCloud(cp.synthetic.add_noise(pts, 0.001, seed=2), sigma=0.001)
    for options in ({"aggregation": "max"}, {"aggregation": "surface"}, {"model": "elements"}):
        model = options.get("model", "points")
        r = cp.collide(
            a, b, pose_b=from_translation((0.1, 0.0, 0.0)), **{"model": model, **options}
        )
        assert r.state == "collision", options


@pytest.mark.parametrize("model", ["elements", "points"])
def test_decide_only_gives_the_full_state(spheres, model: str) -> None:
    a, b = spheres
    for gap in (-4.0, -1.0, 0.0, 1.0, 3.0, 8.0, 20.0):
        full = cp.collide(a, b, pose_b=sphere_gap_pose(gap), model=model)
        quick = cp.collide(a, b, pose_b=sphere_gap_pose(gap), model=model, decide_only=True)
        assert quick.state == full.state, (model, gap, full.probability, quick.probability)
        assert not quick.probabilities_a.any()


def test_elements_model_classifies_tens_of_samples_and_reports_every_point(spheres) -> None:
    a, b = spheres
    pose_b = sphere_gap_pose(1.0)
    el = cp.collide(a, b, pose_b=pose_b, model="elements")
    pts = cp.collide(a, b, pose_b=pose_b, model="points")
    assert 0 < el.stats.points_classified < pts.stats.points_classified
    # Per-point probabilities are Eq. 3 of every point of the elements in the
    # region, against the region's surface: the same points the region lists.
    region = el.patches[0]
    assert len(region.indices_a) > 0
    assert el.probabilities_a[region.indices_a].max() > 0.0
    outside = np.setdiff1d(np.arange(len(el.probabilities_a)), region.indices_a)
    assert not el.probabilities_a[outside].any()
    # Deep is collision, far is free, whatever the model.
    deep = cp.collide(a, b, pose_b=sphere_gap_pose(-4.0), model="elements")
    far = cp.collide(a, b, pose_b=sphere_gap_pose(10.0), model="elements")
    assert (deep.state, far.state) == ("collision", "free")


def test_elements_model_rejects_the_surface_aggregation(spheres) -> None:
    a, b = spheres
    with pytest.raises(cp.InvalidInputError, match="aggregation 'surface'"):
        cp.collide(a, b, model="elements", aggregation="surface")
    with pytest.raises(cp.InvalidInputError, match="unknown model 'surfels'"):
        cp.collide(a, b, model="surfels")
