"""Grasp targets: ``collide_robot(..., target=..., allowed_links=...)``.

The test arm (``tests.robots.ARM_URDF``) at ``q = 0`` holds its sphere ``link3``
(radius 0.03) at ``(0.3, 0, 0.3)``: its tip is at ``x = 0.33``. A patch of the plane
``x = 0.325`` is pressed 5 mm into it (the fingers on the object); a patch at
``x = 0.15`` cuts ``link2``'s bar (the arm hitting the object). The scene proper is a
wall far away, so that everything the robot reads comes from the target.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.filters import split_box, split_labels
from cloudprox.pose import from_translation
from tests.robots import wall

SIGMA = 0.002
Q0 = [0.0, 0.0, 0.0, 0.0]
FINGERS = ["link3", "link4", "tool"]


def patch(x0: float, seed: int = 3) -> cp.PointCloud:
    return cp.PointCloud(wall(x0, 0.3, 0.02, SIGMA, seed), sigma=SIGMA)


@pytest.fixture(scope="module")
def scene() -> cp.PointCloud:
    return cp.PointCloud(wall(5.0, 0.3, 0.05, SIGMA, 7), sigma=SIGMA)


def test_fingers_on_the_target_are_free_when_allowed(arm: cp.Robot, scene: cp.PointCloud) -> None:
    r = cp.collide_robot(arm, Q0, scene, target=patch(0.325), allowed_links=FINGERS)
    assert r.state == "free"
    assert r.target is not None
    assert r.target.state == "collision"
    assert r.target.probability > 0.99
    assert r.target.other_probability < 1e-6
    link3 = r.links["link3"]
    assert link3.probability < 1e-6
    assert link3.target is not None and link3.target.probability > 0.99
    assert link3.target.target is None
    assert "TargetCollision(" in repr(r.target)


def test_fingers_on_the_target_collide_when_not_allowed(
    arm: cp.Robot, scene: cp.PointCloud
) -> None:
    r = cp.collide_robot(arm, Q0, scene, target=patch(0.325))
    assert r.state == "collision"
    assert r.links["link3"].probability > 0.99
    assert r.target is not None
    assert r.target.probability == 0.0
    assert r.target.other_probability > 0.99
    plain = cp.collide_robot(arm, Q0, scene)
    assert plain.target is None
    assert plain.links["link3"].target is None


def test_the_arm_hitting_the_target_still_collides(arm: cp.Robot, scene: cp.PointCloud) -> None:
    r = cp.collide_robot(arm, Q0, scene, target=patch(0.15), allowed_links=FINGERS)
    assert r.state == "collision"
    assert r.links["link2"].probability > 0.99
    assert r.target is not None and r.target.other_probability > 0.99


def test_a_mesh_target_at_a_pose(arm: cp.Robot, scene: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.01, 0.01, 0.01)
    pose = from_translation([0.335, 0.0, 0.3])
    r = cp.collide_robot(arm, Q0, scene, target=cube, target_pose=pose, allowed_links=["link3"])
    assert r.state == "free"
    assert r.target is not None and r.target.state == "collision"
    r = cp.collide_robot(arm, Q0, scene, target=cube, target_pose=pose)
    assert r.state == "collision"


def test_batches_and_motions_count_the_target(arm: cp.Robot, scene: cp.PointCloud) -> None:
    away = [1.5, 0.0, 0.0, 0.0]
    target = patch(0.325)
    allowed = cp.collide_robot_many(arm, [Q0, away], scene, target=target, allowed_links=FINGERS)
    denied = cp.collide_robot_many(arm, [Q0, away], scene, target=target)
    assert list(allowed.states) == ["free", "free"]
    assert list(denied.states) == ["collision", "free"]
    assert allowed.target_probabilities is not None
    assert allowed.target_probabilities[0] > 0.99
    assert allowed.target_probabilities[1] < 1e-6
    assert cp.collide_robot_many(arm, [Q0], scene).target_probabilities is None
    again = pickle.loads(pickle.dumps(allowed))
    np.testing.assert_array_equal(again.target_probabilities, allowed.target_probabilities)
    assert cp.check_motion(arm, away, Q0, scene, target=target, allowed_links=FINGERS).safe
    assert not cp.check_motion(arm, away, Q0, scene, target=target).safe


def test_split_box_and_labels_make_target_and_rest(arm: cp.Robot) -> None:
    points = np.vstack([wall(0.325, 0.3, 0.02, SIGMA, 3), wall(0.9, 0.3, 0.05, SIGMA, 4)])
    sigma = np.full(len(points), SIGMA)
    sigma[:10] = 0.003
    scan = cp.PointCloud(points, sigma=sigma, noise_correlation=0.25)
    n_target = len(wall(0.325, 0.3, 0.02, SIGMA, 3))
    target, rest = split_box(scan, [0.3, -0.1, 0.2], [0.4, 0.1, 0.4])
    assert (len(target), len(rest)) == (n_target, len(scan) - n_target)
    np.testing.assert_array_equal(target.points, points[:n_target])
    np.testing.assert_array_equal(target.sensor_covariances, scan.sensor_covariances[:n_target])
    np.testing.assert_array_equal(rest.sensor_covariances, scan.sensor_covariances[n_target:])
    assert target.noise_correlation == rest.noise_correlation == 0.25
    labels = np.r_[np.full(n_target, 7), np.zeros(len(rest), dtype=int)]
    t2, r2 = split_labels(scan, labels, 7)
    np.testing.assert_array_equal(t2.points, target.points)
    np.testing.assert_array_equal(r2.points, rest.points)
    # An oriented box: the same box turned a quarter about its own centre's z.
    turned = np.array([[0.0, -1.0, 0.0, 0.35], [1.0, 0.0, 0.0, 0.0], [0, 0, 1, 0.3], [0, 0, 0, 1]])
    t3, _ = split_box(scan, [-0.1, -0.05, -0.1], [0.1, 0.05, 0.1], pose=turned)
    assert len(t3) == n_target
    r = cp.collide_robot(arm, Q0, rest, target=target, allowed_links=FINGERS)
    assert r.state == "free" and r.target is not None and r.target.state == "collision"


def test_select_by_index_keeps_discretization_and_moves(arm: cp.Robot) -> None:
    cloud = cp.PointCloud(wall(0.5, 0.3, 0.05, SIGMA, 2), sigma=SIGMA, discretization=True)
    moved = cloud.transformed(from_translation([0.0, 0.0, 1.0]))
    sub = moved.select_by_index(np.arange(20))
    np.testing.assert_array_equal(sub.points, moved.points[:20])
    assert sub.covariances[0, 0, 0] > SIGMA**2 * 1.001
    assert len(moved.select_by_index([0, 1], invert=True)) == len(moved) - 2


def test_bad_targets_name_the_problem(arm: cp.Robot, scene: cp.PointCloud) -> None:
    with pytest.raises(cp.InvalidInputError, match="allowed_links names 'finger'"):
        cp.collide_robot(arm, Q0, scene, target=patch(0.325), allowed_links=["finger"])
    with pytest.raises(cp.InvalidInputError, match="need a target"):
        cp.collide_robot(arm, Q0, scene, allowed_links=FINGERS)
    with pytest.raises(cp.InvalidInputError, match="list of link names, got a str"):
        cp.collide_robot(arm, Q0, scene, target=patch(0.325), allowed_links="link3")
    with pytest.raises(cp.InvalidInputError, match="target_pose places a Mesh"):
        cp.collide_robot(arm, Q0, scene, target=patch(0.325), target_pose=np.eye(4))
    with pytest.raises(TypeError, match="PointCloud or a Mesh"):
        cp.collide_robot(arm, Q0, scene, target=np.zeros((3, 3)))
    with pytest.raises(cp.InvalidInputError, match="holds no point"):
        split_box(scene, [0, 0, 0], [0.1, 0.1, 0.1])
    with pytest.raises(cp.InvalidInputError, match="every point"):
        split_box(scene, [-10, -10, -10], [10, 10, 10])
    with pytest.raises(cp.InvalidInputError, match="shape"):
        split_labels(scene, [1, 2, 3], 1)
    with pytest.raises(cp.InvalidInputError, match="integers"):
        split_labels(scene, np.zeros(len(scene)), 0)
    with pytest.raises(cp.InvalidInputError, match="boolean mask"):
        scene.select_by_index(np.ones(len(scene), dtype=bool))
    with pytest.raises(cp.InvalidInputError, match="out of range"):
        scene.select_by_index([len(scene)])
    with pytest.raises(cp.InvalidInputError, match="no point"):
        scene.select_by_index([], invert=False)
