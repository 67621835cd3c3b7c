"""`CollisionRequest`: the query options as one frozen, validated value."""

from __future__ import annotations

import copy
import json
import pickle
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from tests.helpers import sphere_gap_pose
from tests.robots import ARM_URDF

# Every option set away from its default (a valid request).
CHANGED: dict[str, Any] = {
    "surface": "linear",
    "aggregation": "union",
    "threshold_collision": 0.8,
    "threshold_free": 0.05,
    "prune_epsilon": 1e-4,
    "region_max_points": 500,
    "near_context": 3.0,
    "slack_weight": 50.0,
    "robust_eta": 0.95,
    "robust_model": "chebyshev",
    "solver": "clarabel",
    "use_hierarchy": False,
    "model": "elements",
    "decide_only": True,
    "segmentations": 2,
}


def test_defaults_are_the_rust_defaults() -> None:
    # The values are the Rust `Default`s (`CollisionRequest::default()`), tested
    # there and written nowhere in Python: every option has one, of its type.
    r = cp.CollisionRequest()
    d = r.to_dict()
    assert set(d) == set(CHANGED)
    for name, value in CHANGED.items():
        assert type(d[name]) is type(value), name
    for name, choices in cp.CollisionRequest.choices().items():
        assert d[name] in choices, name
    # None means "not given": the default.
    assert cp.CollisionRequest(surface=None, slack_weight=None) == r
    assert cp.CollisionRequest(**d) == r


def test_every_option_is_read_back() -> None:
    r = cp.CollisionRequest(**CHANGED)
    assert r.to_dict() == CHANGED
    assert list(r.to_dict()) == list(cp.CollisionRequest().to_dict())
    for name, value in CHANGED.items():
        assert getattr(r, name) == value, name
    assert set(CHANGED) == set(cp.CollisionRequest().to_dict())


def test_frozen() -> None:
    r = cp.CollisionRequest()
    with pytest.raises(AttributeError):
        r.surface = "linear"  # type: ignore[misc]
    with pytest.raises(AttributeError):
        r.extra = 1  # type: ignore[attr-defined]
    assert r.surface == "quadric"


def test_replace_returns_a_new_validated_request() -> None:
    r = cp.CollisionRequest(surface="linear")
    s = r.replace(threshold_free=0.2, model="points")
    assert (s.surface, s.threshold_free, s.model) == ("linear", 0.2, "points")
    assert (r.threshold_free, r.model) == (0.1, "elements")
    assert r.replace() == r
    assert r.replace(surface=None) == r  # None leaves an option as it is
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'lambda_'; valid options: "):
        r.replace(lambda_=1.0)
    with pytest.raises(cp.InvalidInputError, match=r"threshold_free"):
        r.replace(threshold_free=0.7)


def test_equality_hash_repr() -> None:
    a = cp.CollisionRequest(surface="linear")
    b = cp.CollisionRequest().replace(surface="linear")
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert a != cp.CollisionRequest()
    zero = cp.CollisionRequest(threshold_free=0.0)
    minus_zero = cp.CollisionRequest(threshold_free=-0.0)
    assert zero == minus_zero and hash(zero) == hash(minus_zero)
    assert a != "CollisionRequest"
    text = repr(a)
    assert text.startswith("CollisionRequest(surface='linear', aggregation='max', ")
    assert "slack_weight=100.0" in text and text.endswith("decide_only=False, segmentations=1)")


def test_pickle_copy_and_json() -> None:
    r = cp.CollisionRequest(**CHANGED)
    for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
        back = pickle.loads(pickle.dumps(r, protocol=protocol))
        assert back == r and back.to_dict() == CHANGED
    assert copy.deepcopy(r) == r and copy.copy(r) == r
    text = json.dumps(r.to_dict())
    assert cp.CollisionRequest(**json.loads(text)) == r


@pytest.mark.parametrize(
    ("option", "value", "pattern"),
    [
        ("surface", "cubic", r"unknown surface 'cubic'; valid names: 'linear', 'quadric'"),
        (
            "aggregation",
            "mean",
            r"unknown aggregation 'mean'; valid names: 'surface', 'max', 'union', 'independent'",
        ),
        ("model", "voxels", r"unknown model 'voxels'; valid names: 'elements', 'points'"),
        ("robust_model", "student", r"unknown robust_model 'student'; valid names: 'gaussian'"),
        ("solver", "ecos", r"unknown solver 'ecos'; valid names: 'primal_dual', 'clarabel'"),
        ("surface", "Linear", r"unknown surface 'Linear'"),
        ("slack_weight", 0.0, r"slack_weight must be finite and > 0, got 0"),
        ("slack_weight", float("nan"), r"slack_weight must be finite"),
        ("robust_eta", 1.0, r"robust_eta must be in \[0.5, 1\)"),
        ("threshold_free", 0.6, r"threshold_free"),
        ("threshold_collision", 0.4, r"threshold_collision"),
        ("prune_epsilon", -0.1, r"prune_epsilon must be in \[0, 1\)"),
        ("near_context", 0.1, r"near_context must be finite and >= 0.5"),
        ("region_max_points", 4, r"region_max_points must be >= 8"),
        ("region_max_points", -3, r"region_max_points must be a non-negative integer"),
    ],
)
def test_bad_values_name_the_option(option: str, value: Any, pattern: str) -> None:
    with pytest.raises(cp.InvalidInputError, match=pattern):
        cp.CollisionRequest(**{option: value})
    with pytest.raises(cp.InvalidInputError, match=pattern):
        cp.CollisionRequest().replace(**{option: value})


def test_the_model_and_aggregation_must_agree() -> None:
    with pytest.raises(cp.InvalidInputError, match=r"aggregation 'surface' belongs to model"):
        cp.CollisionRequest(model="elements", aggregation="surface")


def test_wrong_types_and_unknown_keywords() -> None:
    with pytest.raises(TypeError):
        cp.CollisionRequest(surface=3)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        cp.CollisionRequest(threshold_free="low")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        cp.CollisionRequest(lambda_=1.0)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        cp.CollisionRequest("linear")  # type: ignore[misc]


def test_choices_come_from_the_rust_enums() -> None:
    choices = cp.CollisionRequest.choices()
    assert set(choices) == {"surface", "aggregation", "robust_model", "solver", "model"}
    for option, names in choices.items():
        for name in names:
            # aggregations other than max belong to the paper's per-point model
            model = {"model": "points"} if option == "aggregation" else {}
            assert getattr(cp.CollisionRequest(**model, **{option: name}), option) == name


def _same(r: cp.CollisionResult, s: cp.CollisionResult) -> None:
    assert r.probability == s.probability and r.state == s.state
    np.testing.assert_array_equal(r.probabilities_a, s.probabilities_a)
    np.testing.assert_array_equal(r.probabilities_b, s.probabilities_b)
    assert len(r.patches) == len(s.patches)


def test_collide_with_a_request_equals_the_keywords(spheres) -> None:
    a, b = spheres
    pose = sphere_gap_pose(3.0)
    options = {"surface": "linear", "aggregation": "union", "region_max_points": 60}
    request = cp.CollisionRequest(**options)
    by_request = cp.collide(a, b, pose_b=pose, request=request)
    _same(by_request, cp.collide(a, b, pose_b=pose, **options))
    assert all(g.surface == "linear" for g in by_request.patches)
    # Keywords override the request's fields.
    _same(
        cp.collide(a, b, pose_b=pose, request=request.replace(surface="quadric"), surface="linear"),
        by_request,
    )
    # The default request is the default query.
    _same(
        cp.collide(a, b, pose_b=pose, request=cp.CollisionRequest()), cp.collide(a, b, pose_b=pose)
    )
    many = cp.collide_many(a, b, np.stack([np.eye(4), pose]), request=request)
    _same(many[1], cp.collide(a, b, pose_a=pose, **options))


def test_segmentations_average_the_elements_model(spheres) -> None:
    # The mean of one query per segmentation: the clouds' own segmentation s
    # is the first of a query's (the Rust tests check every field; here the
    # option's way through the binding).
    a, b = spheres
    pose = sphere_gap_pose(0.5)
    mean = cp.collide(a, b, pose_b=pose, model="elements", segmentations=3)
    one = cp.collide(a, b, pose_b=pose, model="elements")
    assert mean.stats.patches == len(mean.patches) >= 3 * min(1, len(one.patches))
    assert mean.stats.points_classified > one.stats.points_classified
    # The first run is the cloud's own segmentation: its patches come first.
    first = mean.patches[: len(one.patches)]
    assert [p.probability for p in first] == [p.probability for p in one.patches]
    q = cp.collide(a, b, pose_b=pose, model="elements", segmentations=3, decide_only=True)
    assert q.state == mean.state and q.probability == pytest.approx(mean.probability, abs=1e-12)
    with pytest.raises(cp.InvalidInputError, match=r"segmentations must be in 1..=16, got 17"):
        cp.CollisionRequest(model="elements", segmentations=17)
    with pytest.raises(cp.InvalidInputError, match=r"needs model 'elements'"):
        cp.CollisionRequest(model="elements", segmentations=3).replace(model="points")
    with pytest.raises(cp.InvalidInputError, match=r"segmentations must be in 1..=16, got 0"):
        cp.CollisionRequest(model="elements", segmentations=0)
    with pytest.raises(cp.InvalidInputError, match=r"segmentations must be in 1..=16, got -1"):
        cp.CollisionRequest(model="elements", segmentations=-1)
    with pytest.raises(cp.InvalidInputError, match=r"needs model 'elements'"):
        cp.CollisionRequest(model="points", segmentations=2)


def test_collide_rejects_bad_requests_and_options(spheres) -> None:
    a, b = spheres
    with pytest.raises(TypeError):
        cp.collide(a, b, request={"surface": "linear"})  # type: ignore[arg-type]
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'lambda_'.*mesh_spacing"):
        cp.collide(a, b, lambda_=1.0)
    with pytest.raises(cp.InvalidInputError, match=r"unknown surface 'cubic'"):
        cp.collide(a, b, request=cp.CollisionRequest(), surface="cubic")
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'nope'"):
        cp.collide_many(a, b, np.eye(4)[None], nope=True)


def test_robot_queries_take_a_request(tmp_path: Path) -> None:
    (tmp_path / "arm.urdf").write_text(ARM_URDF)
    arm = cp.Robot.from_urdf(tmp_path / "arm.urdf")
    pts = cp.synthetic.sample_box_surface((0.01, 0.01, 0.05), 0.005, center=(0.2, 0.0, 0.3))
    cloud = cp.PointCloud(cp.synthetic.add_noise(pts, 0.002, seed=7), sigma=0.002)
    q = np.zeros(arm.dof)
    request = cp.CollisionRequest(surface="linear", decide_only=True)
    by_request = cp.collide_robot(arm, q, cloud, request=request)
    by_keywords = cp.collide_robot(arm, q, cloud, surface="linear", decide_only=True)
    assert by_request.probability == by_keywords.probability
    assert by_request.state == by_keywords.state
    batch = cp.collide_robot_many(arm, q[None], cloud, request=request)
    assert batch.probabilities[0] == by_request.probability
    motion = cp.check_motion(arm, q, q, cloud, request=request, resolution=0.01)
    assert motion.states_total >= 1
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'nope'.*broad_phase"):
        cp.collide_robot(arm, q, cloud, request=request, nope=1)
    stats = by_request.stats
    assert isinstance(stats, cp.RobotStats) and stats.links_with_geometry > 0
    assert json.loads(json.dumps(stats.to_dict())) == stats.to_dict()
    assert stats.time_seconds > 0.0
    again = pickle.loads(pickle.dumps(stats))
    assert again == stats and again.to_dict() == stats.to_dict()
    assert repr(stats).startswith("RobotStats(links_with_geometry=")


def test_query_stats_are_typed(spheres) -> None:
    a, b = spheres
    r = cp.collide(a, b, pose_b=sphere_gap_pose(2.0))
    stats = r.stats
    assert isinstance(stats, cp.QueryStats) and stats == r.stats
    assert stats.patches == len(r.patches) and stats.time_seconds > 0.0
    assert isinstance(stats.points_classified, int) and isinstance(stats.pruned_bound, float)
    d = stats.to_dict()
    assert json.loads(json.dumps(d)) == d
    assert all(d[name] == getattr(stats, name) for name in d)
    assert repr(stats).startswith("QueryStats(near_regions=")
    again = pickle.loads(pickle.dumps(stats))
    assert again == stats and again.to_dict() == d
