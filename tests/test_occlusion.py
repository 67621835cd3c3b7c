"""`filters.Occlusion`: what a single view did not see, against exact geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.filters import Occlusion
from cloudprox.pose import from_rpy, from_translation

SIGMA = 0.002


@pytest.fixture(scope="module")
def wall() -> cp.PointCloud:
    """A 1 m wall at x = 1 m seen from the origin, 1 cm grid, 2 mm isotropic noise."""
    g = np.linspace(-0.5, 0.5, 101)
    y, z = np.meshgrid(g, g)
    pts = np.column_stack([np.ones(y.size), y.ravel(), z.ravel()])
    return cp.PointCloud(cp.synthetic.add_noise(pts, SIGMA, seed=3), sigma=SIGMA)


def test_behind_is_hidden_in_front_is_seen_beside_is_unobserved(wall: cp.PointCloud) -> None:
    occ = Occlusion(wall, [0.0, 0.0, 0.0])
    assert 0.01 < occ.cell < 0.04
    pts = np.array([[1.3, 0.1, 0.0], [0.6, -0.2, 0.1], [1.0, 3.0, 0.0], [-1.0, 0.0, 0.0]])
    assert occ.visibility(pts) == ["hidden", "seen", "unobserved", "unobserved"]
    p = occ.hidden_probability(pts)
    assert p[0] > 0.999 and p[1] < 1e-9 and p[2] == 0.0


def test_the_hidden_probability_follows_the_range_noise(wall: cp.PointCloud) -> None:
    # Behind the wall by t along the ray: Phi(t / sigma) about the nearest
    # return of the neighbourhood (the least of a few noisy ranges, so a
    # little in front of the wall).
    occ = Occlusion(wall, [0.0, 0.0, 0.0])
    t = np.array([-6.0, -3.0, 3.0, 6.0]) * SIGMA
    p = occ.hidden_probability(np.column_stack([1.0 + t, np.zeros(4), np.zeros(4)]))
    assert p[0] < 1e-4 and p[1] < 0.5 < p[2] and p[3] > 1 - 1e-6
    assert np.all(np.diff(p) >= 0)


def test_a_box_behind_the_wall_is_in_its_shadow(wall: cp.PointCloud) -> None:
    occ = Occlusion(wall, [0.0, 0.0, 0.0])
    box = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    samples = np.asarray(box.sample(density=1e4).points)
    hidden = occ.visibility(samples + np.array([1.2, 0.0, 0.0]))
    seen = occ.visibility(samples + np.array([0.5, 0.0, 0.0]))
    assert set(hidden) == {"hidden"} and set(seen) == {"seen"}


def test_a_rigid_motion_of_everything_changes_nothing(wall: cp.PointCloud) -> None:
    motion = from_translation((0.4, -1.0, 2.0)) @ from_rpy((0.3, -0.6, 1.2))
    moved = wall.transformed(motion)
    # Points clear of the wall and of its edges (the cube map's cells turn with
    # the frame, so a point within a cell of the silhouette may change cell).
    pts = np.array([[1.3, 0.1, 0.0], [0.6, -0.2, 0.1], [0.95, 0.3, 0.4], [1.0, 3.0, 0.0]])
    a = Occlusion(wall, [0.0, 0.0, 0.0], cell=0.02)
    b = Occlusion(moved, motion[:3, 3], cell=0.02)
    moved_pts = pts @ motion[:3, :3].T + motion[:3, 3]
    assert a.visibility(pts) == b.visibility(moved_pts)


@pytest.mark.parametrize(
    ("args", "kwargs", "words"),
    [
        ((np.zeros((3, 3)), [0, 0, 0]), {}, "PointCloud"),
        (("wall", [math.nan, 0, 0]), {}, "origin"),
        (("wall", [0, 0, 0]), {"cell": 0.0}, "cell"),
        (("wall", [0, 0]), {}, "origin"),
    ],
)
def test_bad_inputs_are_named(
    wall: cp.PointCloud, args: tuple[object, ...], kwargs: dict[str, float], words: str
) -> None:
    args = tuple(wall if isinstance(a, str) else a for a in args)
    with pytest.raises((cp.InvalidInputError, ValueError, TypeError), match=words):
        Occlusion(*args, **kwargs)  # type: ignore[arg-type]


def test_bad_query_points_are_named(wall: cp.PointCloud) -> None:
    occ = Occlusion(wall, [0.0, 0.0, 0.0])
    with pytest.raises(cp.InvalidInputError, match="point 1"):
        occ.hidden_probability([[1.0, 0.0, 0.0], [math.nan, 0.0, 0.0]])
    on_sensor = cp.PointCloud(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), sigma=SIGMA)
    with pytest.raises(cp.InvalidInputError, match="point 0"):
        Occlusion(on_sensor, [0.0, 0.0, 0.0])


def test_a_stated_thickness_bounds_the_shadow(wall: cp.PointCloud) -> None:
    occ = Occlusion(wall, [0.0, 0.0, 0.0])
    pts = np.array([[1.03, 0.0, 0.0], [1.2, 0.0, 0.0], [0.9, 0.0, 0.0]])
    p = occ.hidden_probability(pts, depth=0.05)
    assert p[0] > 0.999 and p[1] < 1e-9 and p[2] < 1e-9
    everywhere = occ.hidden_probability(pts)
    assert np.all(p <= everywhere + 1e-15)
    with pytest.raises(cp.InvalidInputError, match="depth"):
        occ.hidden_probability(pts, depth=-0.01)


def test_a_robot_link_in_the_shadow_reads_contact_not_free(arm: cp.Robot) -> None:
    # The arm's link3 sphere (radius 0.03, centre (0.3, 0, 0.3) at q = 0) lies
    # 3 cm before a wall at x = 0.36: free. Seen from x = 1 it is 3-9 cm behind
    # the wall, in its shadow; seen from x = -1 it is in front of it.
    from tests.robots import wall as wall_points

    scan = cp.PointCloud(wall_points(0.36, 0.3, 0.2, SIGMA, 11), sigma=SIGMA)
    q = np.zeros(arm.dof)
    bare = cp.collide_robot(arm, q, scan, self_collision=False)
    assert bare.state == "free"
    behind = Occlusion(scan, [1.0, 0.0, 0.3])
    r = cp.collide_robot(arm, q, scan, self_collision=False, shadow=behind)
    assert r.links["link3"].shadow == pytest.approx(0.5, abs=1e-6)
    assert r.state == "contact"
    thin = cp.collide_robot(
        arm, q, scan, self_collision=False, shadow=behind, shadow_depth=0.01, shadow_prior=0.9
    )
    assert thin.links["link3"].shadow < 1e-9 and thin.state == "free"
    front = cp.collide_robot(
        arm, q, scan, self_collision=False, shadow=Occlusion(scan, [-1.0, 0.0, 0.3])
    )
    assert front.state == "free"
    many = cp.collide_robot_many(arm, [q, q], scan, self_collision=False, shadow=behind)
    assert np.allclose(many.probabilities, r.probability)


def test_bad_shadow_options_are_named(arm: cp.Robot, wall: cp.PointCloud) -> None:
    q = np.zeros(arm.dof)
    occ = Occlusion(wall, [0.0, 0.0, 0.0])
    for kwargs, words in (
        ({"shadow": "not an occlusion"}, "Occlusion"),
        ({"shadow_depth": 0.05}, "need a shadow"),
        ({"shadow": occ, "shadow_prior": 2.0}, "prior"),
        ({"shadow": occ, "shadow_depth": 0.0}, "depth"),
    ):
        with pytest.raises(cp.InvalidInputError, match=words):
            cp.collide_robot(arm, q, wall, **kwargs)
