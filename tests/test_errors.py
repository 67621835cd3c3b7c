from __future__ import annotations

import re
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import CloudproxError, InvalidInputError, SolverError
from cloudprox.pose import from_translation


@pytest.fixture(scope="module")
def small() -> cp.PointCloud:
    return cp.PointCloud(cp.synthetic.sample_sphere(100, 0.1), sigma=0.002)


def test_hierarchy() -> None:
    assert issubclass(CloudproxError, Exception)
    assert issubclass(InvalidInputError, CloudproxError)
    assert issubclass(InvalidInputError, ValueError)
    assert issubclass(SolverError, CloudproxError)
    assert issubclass(SolverError, RuntimeError)
    assert not issubclass(InvalidInputError, RuntimeError)
    for e in (CloudproxError, InvalidInputError, SolverError):
        assert e.__module__ == "cloudprox._native"
        assert e.__doc__
    assert cp.exceptions.InvalidInputError is cp.InvalidInputError


GOOD = np.zeros((4, 3)) + np.arange(4)[:, None]


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"points": [[np.nan, 0.0, 0.0], [1.0, 2.0, 3.0]]}, r"point 0 .*NaN or infinite"),
        ({"points": [[0.0, 0.0, 0.0], [1.0, np.inf, 3.0]]}, r"point 1 .*NaN or infinite"),
        ({"points": np.zeros((0, 3))}, r"empty"),
        ({"points": np.zeros((5, 2))}, r"points must have shape \(n, 3\), got shape \(5, 2\)"),
        ({"points": np.zeros(3)}, r"points must have shape \(n, 3\), got shape \(3,\)"),
        ({"points": np.zeros((2, 3, 1))}, r"got shape \(2, 3, 1\)"),
        ({"points": [["a", "b", "c"]]}, r"points must be numeric, got an array of dtype <U1"),
        ({"points": np.ones((2, 3), dtype=bool)}, r"points must be numeric.*bool"),
        ({"points": np.ones((2, 3), dtype=complex)}, r"points must be numeric.*complex"),
        ({"points": [[1.0, 2.0, 3.0], [1.0, 2.0]]}, r"points must be a numeric array-like"),
        ({"points": [[1.0, None, 3.0]]}, r"point 0 .*NaN"),
        ({"points": GOOD, "sigma": -0.001}, r"sigma must be finite and >= 0, got -0.001"),
        ({"points": GOOD, "sigma": np.nan}, r"sigma must be finite"),
        ({"points": GOOD, "sigma": [0.001, 0.001, -1.0, 0.0]}, r"sigma of point 2 must be"),
        ({"points": GOOD, "sigma": [0.001, 0.002]}, r"per-point sigmas: expected 4, got 2"),
        (
            {"points": GOOD, "sigma": np.ones((4, 1))},
            r"sigma must be a scalar or .*\(n,\).*\(4, 1\)",
        ),
        ({"points": GOOD, "sigma": "big"}, r"sigma must be numeric"),
        (
            {"points": GOOD, "cov": np.broadcast_to(-np.eye(3), (4, 3, 3))},
            r"point 0: covariance is not positive semi-definite",
        ),
        (
            {"points": GOOD, "cov": np.broadcast_to(np.triu(np.ones((3, 3))), (4, 3, 3))},
            r"point 0: covariance is not symmetric",
        ),
        ({"points": GOOD, "cov": np.zeros((3, 3, 3))}, r"per-point covariances: expected 4, got 3"),
        ({"points": GOOD, "cov": np.zeros((4, 3))}, r"cov must have shape \(n, 3, 3\)"),
        ({"points": GOOD, "sigma": 0.001, "cov": np.zeros((4, 3, 3))}, r"either sigma or cov"),
        ({"points": GOOD, "discretization": True, "k": 1}, r"k must be >= 2, got 1"),
        ({"points": GOOD, "discretization": True, "k": -3}, r"k must be >= 2, got -3"),
    ],
)
def test_bad_point_cloud_input(kwargs: dict, pattern: str) -> None:
    with pytest.raises(InvalidInputError, match=pattern):
        cp.PointCloud(**kwargs)


def test_errors_are_value_errors_and_cloudprox_errors() -> None:
    with pytest.raises(ValueError, match="empty"):
        cp.PointCloud(np.zeros((0, 3)))
    with pytest.raises(CloudproxError):
        cp.PointCloud(np.zeros((0, 3)))


def scaled() -> np.ndarray:
    t = np.eye(4)
    t[0, 0] = 2.0
    return t


def reflected() -> np.ndarray:
    t = np.eye(4)
    t[2, 2] = -1.0
    return t


def bad_last_row() -> np.ndarray:
    t = np.eye(4)
    t[3, 0] = 0.5
    return t


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        (
            {"threshold_collision": 0.3, "threshold_free": 0.6},
            r"threshold_free <= 0.5 <= threshold_collision",
        ),
        ({"threshold_free": -0.1}, r"threshold_free = -0.1"),
        ({"threshold_collision": 1.5}, r"threshold_collision = 1.5"),
        ({"surface": "cubic"}, r"unknown surface 'cubic'; valid names: 'linear', 'quadric'"),
        (
            {"aggregation": "mean"},
            r"unknown aggregation 'mean'; valid names: 'surface', 'max', 'union', 'independent'",
        ),
        (
            {"robust_model": "student"},
            r"unknown robust_model 'student'; valid names: 'gaussian', 'chebyshev'",
        ),
        ({"solver": "ecos"}, r"unknown solver 'ecos'; valid names: 'primal_dual', 'clarabel'"),
        ({"robust_eta": 1.0}, r"robust_eta must be in \[0.5, 1\), got 1"),
        ({"slack_weight": 0.0}, r"slack_weight must be finite and > 0"),
        ({"prune_epsilon": 1.0}, r"prune_epsilon must be in \[0, 1\)"),
        ({"region_max_points": 4}, r"region_max_points must be >= 8"),
        ({"region_max_points": -1}, r"region_max_points must be a non-negative integer, got -1"),
        ({"pose_a": scaled()}, r"pose_a: pose's upper-left 3x3 block is not a rotation"),
        ({"pose_b": reflected()}, r"pose_b: .*not a rotation"),
        ({"pose_a": bad_last_row()}, r"pose_a: pose's last row must be \[0, 0, 0, 1\]"),
        ({"pose_a": np.eye(3)}, r"pose_a must have shape \(4, 4\), got shape \(3, 3\)"),
        ({"pose_b": np.eye(4)[None]}, r"pose_b must have shape \(4, 4\), got shape \(1, 4, 4\)"),
        ({"pose_a": np.full((4, 4), np.nan)}, r"pose_a: pose has a NaN or infinite entry"),
        ({"pose_a": [["x"] * 4] * 4}, r"pose_a must be numeric"),
    ],
)
def test_bad_query_input(small: cp.PointCloud, kwargs: dict, pattern: str) -> None:
    with pytest.raises(InvalidInputError, match=pattern):
        cp.collide(small, small, **kwargs)


@pytest.mark.parametrize("many", [cp.collide_many, cp.collide_along])
def test_bad_collide_many_input(small: cp.PointCloud, many: Any) -> None:
    with pytest.raises(
        InvalidInputError, match=r"poses_a must have shape \(m, 4, 4\), got shape \(4, 4\)"
    ):
        many(small, small, np.eye(4))
    poses = np.stack([np.eye(4), scaled()])
    with pytest.raises(InvalidInputError, match=re.escape("poses_a[1]: pose's upper-left")):
        many(small, small, poses)
    with pytest.raises(InvalidInputError, match="unknown surface"):
        many(small, small, np.eye(4)[None], surface="plane")
    with pytest.raises(InvalidInputError, match="unknown option"):
        many(small, small, np.eye(4)[None], no_such_option=1)
    with pytest.raises(InvalidInputError, match=r"pose_b must have shape \(4, 4\)"):
        many(small, small, np.eye(4)[None], np.eye(4)[None])


def test_wrong_types_raise_type_error(small: cp.PointCloud) -> None:
    with pytest.raises(TypeError):
        cp.collide(np.zeros((3, 3)), small)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        cp.collide(small, small, surface=1)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        cp.collide(small, small, None, None, "quadric")  # type: ignore[misc]


def test_bad_sampler_input() -> None:
    with pytest.raises(InvalidInputError, match="radius must be finite and > 0"):
        cp.synthetic.sample_sphere(10, radius=-1.0)
    with pytest.raises(InvalidInputError, match="n must be in"):
        cp.synthetic.sample_sphere(-1)
    with pytest.raises(InvalidInputError, match="spacing must be finite and > 0"):
        cp.synthetic.sample_box_surface([1.0, 1.0, 1.0], 0.0)
    with pytest.raises(InvalidInputError, match="more than 1e8"):
        cp.synthetic.sample_box_surface([1.0, 1.0, 1.0], 1e-6)
    with pytest.raises(InvalidInputError, match=r"half_extents must have shape \(3,\)"):
        cp.synthetic.sample_box_surface([1.0, 1.0], 0.1)
    with pytest.raises(InvalidInputError, match="sigma must be finite and >= 0"):
        cp.synthetic.add_noise(np.zeros((2, 3)), -1.0)


def test_evaluate_rejects_bad_points(spheres) -> None:
    a, b = spheres
    r = cp.collide(a, b, pose_b=from_translation((0.2, 0.0, 0.0)))
    region = r.patches[0]
    with pytest.raises(InvalidInputError, match=r"x must have shape \(n, 3\)"):
        region.evaluate(np.zeros((4, 2)))
    f, g = region.evaluate(np.zeros((0, 3)))
    assert f.shape == (0,) and g.shape == (0, 3)
