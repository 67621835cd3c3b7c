"""Clouds, meshes, robots and results pickle and come back exactly."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation
from tests.robots import ARM_URDF, wall


def roundtrip(obj):
    return pickle.loads(pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


def assert_same_result(r: cp.CollisionResult, s: cp.CollisionResult) -> None:
    assert r.probability == s.probability and r.state == s.state
    assert r.point_aggregates == s.point_aggregates
    np.testing.assert_array_equal(r.probabilities_a, s.probabilities_a)
    np.testing.assert_array_equal(r.probabilities_b, s.probabilities_b)
    assert len(r.patches) == len(s.patches)
    for x, y in zip(r.patches, s.patches, strict=False):
        assert (x.component, x.separation, x.probability, x.surface, x.status, x.iterations) == (
            y.component,
            y.separation,
            y.probability,
            y.surface,
            y.status,
            y.iterations,
        )
        np.testing.assert_array_equal(x.indices_a, y.indices_a)
        np.testing.assert_array_equal(x.indices_b, y.indices_b)
        np.testing.assert_array_equal(x.point, y.point)
        np.testing.assert_array_equal(x.normal, y.normal)


def assert_same_cloud(c: cp.PointCloud, d: cp.PointCloud) -> None:
    assert len(c) == len(d) and c.noise_correlation == d.noise_correlation
    for name in ("points", "covariances", "sensor_covariances", "sigma_max", "spacing"):
        np.testing.assert_array_equal(getattr(c, name), getattr(d, name), err_msg=name)


def _clouds() -> dict[str, cp.PointCloud]:
    base = cp.synthetic.add_noise(cp.synthetic.sample_sphere(800, 0.1), 0.002, seed=4)
    sensor_pose = np.eye(4)
    sensor_pose[2, 3] = -1.0
    rot = cp.pose.from_rpy((0.0, 0.0, np.pi / 2), (0.01, 0.02, 0.03))  # a quarter turn about z
    plain = cp.PointCloud(base, sigma=0.002)
    disc = cp.PointCloud(base, sigma=0.002, discretization=True, k=8, noise_correlation=0.3)
    camera = cp.PointCloud(
        base, sensor=cp.DepthCamera.nguyen_2012(), sensor_pose=sensor_pose, discretization=True
    )
    return {
        "sigma": plain,
        "discretization": disc,
        "depth camera": camera,
        "moved twice": disc.transformed(rot).transformed(from_translation((0.05, 0.0, 0.0))),
        "per-point sigma": cp.PointCloud(base, sigma=np.linspace(0.001, 0.003, len(base))),
    }


@pytest.mark.parametrize("name", list(_clouds()))
def test_point_cloud_roundtrip(name: str) -> None:
    cloud = _clouds()[name]
    back = roundtrip(cloud)
    assert_same_cloud(cloud, back)
    other = cp.PointCloud(
        cp.synthetic.add_noise(cp.synthetic.sample_sphere(800, 0.1), 0.002, seed=5), sigma=0.002
    )
    centre = cloud.points.mean(axis=0)
    pose = from_translation((centre[0] + 0.195, centre[1], centre[2]))
    for model in ("points", "elements"):
        assert_same_result(
            cp.collide(cloud, other, pose_b=pose, model=model),
            cp.collide(back, other, pose_b=pose, model=model),
        )


def test_mesh_roundtrip() -> None:
    mesh = cp.Mesh.merged([cp.Mesh.cuboid(0.05, 0.04, 0.03), cp.Mesh.cylinder(0.02, 0.1, 12)])
    back = roundtrip(mesh)
    np.testing.assert_array_equal(mesh.vertices, back.vertices)
    np.testing.assert_array_equal(mesh.faces, back.faces)
    cloud = cp.PointCloud(cp.synthetic.sample_sphere(600, 0.1), sigma=0.002)
    pose = from_translation((0.14, 0.0, 0.0))
    assert_same_result(cp.collide(mesh, cloud, pose_a=pose), cp.collide(back, cloud, pose_a=pose))


def test_result_and_region_roundtrip() -> None:
    base = cp.synthetic.sample_sphere(800, 0.1)
    a = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=1), sigma=0.002)
    b = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=2), sigma=0.002)
    # The paper's model: its result carries the per-point aggregates too.
    result = cp.collide(a, b, pose_b=from_translation((0.199, 0.0, 0.0)), model="points")
    assert result.patches and result.point_aggregates is not None
    back = roundtrip(result)
    assert_same_result(result, back)
    assert back.stats == result.stats
    assert back.points_a is None and result.points_a is not None
    x = np.random.default_rng(0).normal(0.1, 0.05, (50, 3))
    for r, s in zip(result.patches, back.patches, strict=False):
        f, g = r.evaluate(x)
        f2, g2 = s.evaluate(x)
        np.testing.assert_array_equal(f, f2)
        np.testing.assert_array_equal(g, g2)
    region = roundtrip(result.patches[0])
    np.testing.assert_array_equal(region.evaluate(x)[0], result.patches[0].evaluate(x)[0])


def test_robot_and_batch_roundtrip(tmp_path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM_URDF)
    robot = cp.Robot.from_urdf(path)
    data = pickle.dumps(robot)
    path.unlink()  # the URDF's text travels in the pickle
    back = pickle.loads(data)
    assert back.link_names == robot.link_names and back.joint_names == robot.joint_names
    np.testing.assert_array_equal(back.joint_limits, robot.joint_limits)
    q = np.array([0.3, -0.2, 0.05, 1.0])
    for name, pose in robot.link_poses(q).items():
        np.testing.assert_array_equal(back.link_poses(q)[name], pose)
    cloud = cp.PointCloud(wall(0.36, 0.3, 0.15, 0.002, seed=3), sigma=0.002)
    qs = np.array([[0.0, 0.0, 0.0, 0.0], [0.0, -0.3, 0.1, 0.0], [1.5, 0.0, 0.0, 0.0]])
    local = cp.collide_robot_many(robot, qs, cloud)
    again = cp.collide_robot_many(back, qs, cloud)
    batch = roundtrip(local)
    for r in (again, batch):
        np.testing.assert_array_equal(r.probabilities, local.probabilities)
        np.testing.assert_array_equal(r.states, local.states)
        np.testing.assert_array_equal(r.self_colliding, local.self_colliding)
        np.testing.assert_array_equal(r.link_probabilities, local.link_probabilities)


def test_bad_states_are_refused() -> None:
    with pytest.raises(cp.InvalidInputError, match="state version 99"):
        cp.PointCloud._from_state((99, np.zeros((1, 3)), np.zeros((1, 3, 3)), None, 0.0, []))
    with pytest.raises(cp.InvalidInputError, match="unknown collision state 'maybe'"):
        cp.RobotBatchResult._from_state(([0.5], ["maybe"], [False], [0.5], 1))
    with pytest.raises(cp.InvalidInputError, match="inconsistent lengths"):
        cp.RobotBatchResult._from_state(([0.5], ["free"], [False], [0.5, 0.1], 1))
    # Statistics from an older build (one counter fewer) name what they lack.
    with pytest.raises(cp.InvalidInputError, match=r"holds 12 counters, expected 13 \(node_pairs"):
        cp.QueryStats._from_state(([0] * 12, 0.0))


def test_request_stats_and_proximity_roundtrip() -> None:
    request = cp.CollisionRequest(surface="linear", threshold_free=0.05, decide_only=True)
    assert roundtrip(request) == request
    base = cp.synthetic.sample_sphere(400, 0.1)
    a = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=1), sigma=0.002)
    stats = cp.collide(a, a, pose_b=from_translation((0.199, 0.0, 0.0)), request=request).stats
    assert roundtrip(stats) == stats and roundtrip(stats).to_dict() == stats.to_dict()
    cube = cp.ExactShape([cp.Mesh.cuboid(0.1, 0.1, 0.1)])
    near = cp.exact_proximity(cube, cube, None, from_translation((0.5, 0.0, 0.0)))
    assert roundtrip(near) == near and roundtrip(near).to_dict() == near.to_dict()
