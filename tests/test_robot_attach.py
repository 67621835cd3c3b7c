"""Objects attached to a robot's link: ``Robot.attach``, ``Robot.detach``.

The test arm (``tests.robots.ARM_URDF``) at ``q = 0`` holds its sphere ``link3``
at ``(0.3, 0, 0.3)``; a box held 0.1 m beyond it spans ``x`` in ``[0.36, 0.44]``,
so the wall at ``x = 0.4`` touches the box and not the bare arm (whose nearest
point, on ``link3``, is at ``x = 0.33``).
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_rotation_vector, from_translation
from tests.robots import wall

SIGMA = 0.002
HALF = 0.04
#: The held box's frame in ``link3``'s frame.
HOLD = from_translation([0.1, 0.0, 0.0])
Q0 = [0.0, 0.0, 0.0, 0.0]
#: Turned a quarter about the base's z: everything away from the wall.
Q_AWAY = [1.5, 0.0, 0.0, 0.0]


def wall_cloud(x0: float = 0.40) -> cp.PointCloud:
    return cp.PointCloud(wall(x0, 0.3, 0.1, SIGMA, 1), sigma=SIGMA)


@pytest.fixture(scope="module")
def holding(arm: cp.Robot) -> cp.Robot:
    """The arm holding a 8 cm box on ``link3``."""
    return arm.attach("link3", cp.Mesh.cuboid(HALF, HALF, HALF), HOLD, name="box")


def box_cloud(seed: int = 3) -> cp.PointCloud:
    points = cp.Mesh.cuboid(HALF, HALF, HALF).sample(3000, seed=seed).points
    return cp.PointCloud(points, sigma=0.001)


def test_attach_returns_a_copy(arm: cp.Robot, holding: cp.Robot) -> None:
    assert arm.attached_objects == []
    assert holding.attached_objects == ["box"]
    assert "attached=1" in repr(holding)
    assert holding.detach("box").attached_objects == []
    assert holding.attached_objects == ["box"]


@pytest.mark.parametrize("q", [Q0, [0.7, -0.4, 0.05, 2.0], [-2.5, 1.9, 0.1, -7.0]])
def test_held_object_moves_with_its_link(holding: cp.Robot, q: list[float]) -> None:
    base = from_rotation_vector([0.0, 0.0, 0.3], [0.1, -0.2, 0.05])
    link = holding.link_poses(q, base)["link3"]
    pose = holding.attached_poses(q, base)["box"]
    np.testing.assert_allclose(pose, link @ HOLD, atol=1e-12)


@pytest.mark.parametrize("mesh_side", ["exact", "sampled"])
def test_held_box_collides_where_the_bare_arm_is_free(
    arm: cp.Robot, holding: cp.Robot, mesh_side: str
) -> None:
    cloud = wall_cloud()
    bare = cp.collide_robot(arm, Q0, cloud, mesh_side=mesh_side)
    assert bare.probability < 1e-6
    held = cp.collide_robot(holding, Q0, cloud, mesh_side=mesh_side)
    assert held.probability > 0.99
    assert list(held.links)[-1] == "box"
    assert held.links["box"].probability > 0.99
    assert held.links["link3"].probability < 1e-6
    assert cp.collide_robot(holding, Q_AWAY, cloud, mesh_side=mesh_side).probability < 1e-6
    again = cp.collide_robot(holding.detach("box"), Q0, cloud, mesh_side=mesh_side)
    assert again.probability == bare.probability
    assert list(again.links) == list(bare.links)


def test_held_cloud_collides(arm: cp.Robot) -> None:
    scan = arm.attach("link3", box_cloud(), HOLD, name="scan")
    cloud = wall_cloud()
    assert cp.collide_robot(scan, Q0, cloud).links["scan"].probability > 0.99
    assert cp.collide_robot(scan, Q_AWAY, cloud).probability < 1e-6
    # The self-filter removes the points inside the cloud's convex hull.
    points = np.array([[0.4, 0.0, 0.3], [0.4, 0.3, 0.3]])
    np.testing.assert_array_equal(scan.self_filter(Q0, padding=0.01).apply(points), [1])


def test_batch_and_motion_see_the_held_object(arm: cp.Robot, holding: cp.Robot) -> None:
    cloud = wall_cloud()
    batch = cp.collide_robot_many(holding, [Q0, Q_AWAY], cloud)
    assert batch.probabilities[0] > 0.99 and batch.probabilities[1] < 1e-6
    assert batch.link_probabilities.shape == (2, len(arm.link_names))
    assert not cp.check_motion(holding, Q_AWAY, Q0, cloud).safe
    assert cp.check_motion(arm, Q_AWAY, Q0, cloud).safe


def test_self_filter_removes_the_held_object(arm: cp.Robot, holding: cp.Robot) -> None:
    points = np.array([[0.4, 0.0, 0.3], [0.4, 0.3, 0.3]])
    np.testing.assert_array_equal(holding.self_filter(Q0, padding=0.01).apply(points), [1])
    np.testing.assert_array_equal(arm.self_filter(Q0, padding=0.01).apply(points), [0, 1])


def test_self_collision_skips_the_holder_and_touch_links(arm: cp.Robot) -> None:
    # A bar from x = 0.12 to 0.27 (world) at q = 0: inside link2's bar, touching link3.
    bar = cp.Mesh.cuboid(0.075, 0.005, 0.005)
    back = from_translation([-0.105, 0.0, 0.0])
    held = arm.attach("link3", bar, back, name="bar")
    assert held.self_collisions(Q0) == [("link2", "bar")]
    result = cp.collide_robot(held, Q0, wall_cloud(2.0))
    assert result.self_collisions == [("link2", "bar")]
    touching = arm.attach("link3", bar, back, name="bar", touch_links=["link2"])
    assert touching.self_collisions(Q0) == []
    # Held beyond link3, clear of link2.
    assert arm.attach("link3", bar, HOLD, name="bar").self_collisions(Q0) == []


@pytest.mark.parametrize("obj", ["mesh", "cloud"])
def test_pickling_keeps_attached_objects(arm: cp.Robot, obj: str) -> None:
    thing = cp.Mesh.cuboid(HALF, HALF, HALF) if obj == "mesh" else box_cloud()
    held = arm.with_allowed_collisions([("base", "link3")]).attach(
        "link3", thing, HOLD, name="thing", touch_links=["link2"]
    )
    back = pickle.loads(pickle.dumps(held))
    assert back.attached_objects == ["thing"]
    assert back.ignored_pairs == held.ignored_pairs
    np.testing.assert_array_equal(
        back.attached_poses(Q0)["thing"], held.attached_poses(Q0)["thing"]
    )
    cloud = wall_cloud()
    assert (
        cp.collide_robot(back, Q0, cloud).probability
        == cp.collide_robot(held, Q0, cloud).probability
    )
    assert pickle.loads(pickle.dumps(back.detach("thing"))).attached_objects == []


def test_attach_errors_name_the_problem(arm: cp.Robot, holding: cp.Robot) -> None:
    box = cp.Mesh.cuboid(0.01, 0.01, 0.01)
    with pytest.raises(cp.InvalidInputError, match=r"'hand'.*no link of that name"):
        arm.attach("hand", box, name="x")
    with pytest.raises(cp.InvalidInputError, match="already holds an object named 'box'"):
        holding.attach("link2", box, name="box")
    with pytest.raises(cp.InvalidInputError, match="'tool' is a link"):
        arm.attach("link2", box, name="tool")
    with pytest.raises(cp.InvalidInputError, match="cannot touch 'palm'"):
        arm.attach("link2", box, name="x", touch_links=["palm"])
    nan = np.eye(4)
    nan[0, 3] = np.nan
    with pytest.raises(cp.InvalidInputError, match="pose"):
        arm.attach("link2", box, nan, name="x")
    with pytest.raises(cp.InvalidInputError, match=r"pose.*\(4, 4\)"):
        arm.attach("link2", box, np.eye(3), name="x")
    flat = cp.PointCloud(np.column_stack([np.arange(10.0), np.zeros(10), np.zeros(10)]), sigma=0.01)
    with pytest.raises(cp.InvalidInputError, match="degenerate"):
        arm.attach("link2", flat, name="x")
    with pytest.raises(cp.InvalidInputError, match="empty"):
        cp.PointCloud(np.zeros((0, 3)), sigma=0.01)
    with pytest.raises(TypeError, match=r"Mesh or a cloudprox\.PointCloud"):
        arm.attach("link2", np.zeros((4, 3)), name="x")  # type: ignore[arg-type]
    with pytest.raises(cp.InvalidInputError, match=r"no object named 'cup'.*box"):
        holding.detach("cup")
    with pytest.raises(cp.InvalidInputError, match="holds: nothing"):
        arm.detach("box")


@pytest.mark.parametrize(("gap", "intersecting"), [(-0.01, True), (0.015, False)])
def test_held_box_agrees_with_fcl(
    arm: cp.Robot, holding: cp.Robot, gap: float, intersecting: bool
) -> None:
    fcl = pytest.importorskip("fcl")
    held_pose = holding.attached_poses(Q0)["box"]
    # An 8 cm box beside the held one along x, `gap` apart (negative: overlapping).
    centre = held_pose[:3, 3] + [2 * HALF + gap, 0.0, 0.0]
    other = cp.Mesh.cuboid(HALF, HALF, HALF).transformed(from_translation(centre))
    points = other.sample(density=4e4, seed=5).points
    points = points + np.random.default_rng(7).normal(0.0, 0.001, points.shape)
    cloud = cp.PointCloud(points, sigma=0.001)

    def fcl_box(pose: np.ndarray) -> fcl.CollisionObject:
        return fcl.CollisionObject(
            fcl.Box(2 * HALF, 2 * HALF, 2 * HALF), fcl.Transform(pose[:3, :3], pose[:3, 3])
        )

    request, result = fcl.CollisionRequest(), fcl.CollisionResult()
    fcl.collide(fcl_box(held_pose), fcl_box(from_translation(centre)), request, result)
    assert result.is_collision == intersecting
    p = cp.collide_robot(holding, Q0, cloud).links["box"].probability
    assert (p > 0.95) if intersecting else (p < 0.01), p
    # The bare arm is far from the other box either way.
    assert cp.collide_robot(arm, Q0, cloud).probability < 1e-6
