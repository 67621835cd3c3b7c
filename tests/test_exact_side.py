"""An exact mesh side: its surface is the separating surface (the default)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation
from tests.helpers import RADIUS, SIGMA


@pytest.fixture(scope="module")
def sphere_cloud(sphere_points: tuple[np.ndarray, np.ndarray]) -> cp.PointCloud:
    return cp.PointCloud(sphere_points[0], sigma=SIGMA, discretization=True)


def cube_pose(gap: float) -> np.ndarray:
    """A 10 cm cube whose bottom face is `gap` above the sphere's top (exact distance)."""
    return from_translation((0.0, 0.0, RADIUS + 0.05 + gap))


def test_per_point_probabilities_are_eq_3() -> None:
    # Scattered points under the unit cube's bottom face, sigma_z = 1.5 mm:
    # the gradient is -z there, so p = Phi(-d / sigma_z).
    d = np.array([0.001, 0.002, 0.0005, -0.001, 0.003])
    pts = np.column_stack([0.1 * np.arange(5) - 0.2, np.full(5, 0.05), -0.5 - d])
    cov = np.broadcast_to(np.diag([4e-6, 9e-6, 0.0015**2]), (5, 3, 3)).copy()
    cloud = cp.PointCloud(pts, cov=cov)
    r = cp.collide(cp.Mesh.cuboid(0.5, 0.5, 0.5), cloud)
    want = [0.5 * math.erfc(x / 0.0015 / math.sqrt(2.0)) for x in d]
    np.testing.assert_allclose(r.probabilities_b, want, atol=1e-12)
    assert len(r.probabilities_a) == 0
    assert r.points_a is None and r.points_b is not None
    assert r.patches == []


def test_exact_and_sampled_agree_at_clear_gaps(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    for g, want in ((20.0, "free"), (10.0, "free"), (-5.0, "collision"), (-10.0, "collision")):
        pose = cube_pose(g * SIGMA)
        exact = cp.collide(cube, sphere_cloud, pose_a=pose)
        sampled = cp.collide(cube, sphere_cloud, pose_a=pose, mesh_side="sampled")
        assert (exact.state, sampled.state) == (want, want), g
        assert exact.stats.patches == 0


def test_either_order_and_many_poses_agree(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    poses = np.stack([cube_pose(g * SIGMA) for g in (20.0, 2.0, 0.0, -3.0)])
    many = cp.collide_many(cube, sphere_cloud, poses)
    along = cp.collide_along(cube, sphere_cloud, poses)
    for pose, m, a in zip(poses, many, along, strict=True):
        one = cp.collide(cube, sphere_cloud, pose_a=pose)
        ba = cp.collide(sphere_cloud, cube, pose_b=pose)
        assert m.probability == one.probability == a.probability
        assert ba.probability == pytest.approx(one.probability, abs=1e-12)
        np.testing.assert_allclose(ba.probabilities_a, one.probabilities_b, atol=1e-12)
    # The cloud moving against a fixed mesh: the same relative poses.
    inverse = np.stack([np.linalg.inv(p) for p in poses])
    moved = cp.collide_many(sphere_cloud, cube, inverse)
    for m, b in zip(many, moved, strict=True):
        assert b.probability == pytest.approx(m.probability, abs=1e-9)


def test_invariant_under_a_rigid_motion_of_both(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    motion = cp.pose.random_rotations(1, seed=3)[0]
    motion[:3, 3] = (0.4, -1.2, 0.7)
    for g in (3.0, 0.0, -2.0):
        pose = cube_pose(g * SIGMA)
        a = cp.collide(cube, sphere_cloud, pose_a=pose)
        b = cp.collide(cube, sphere_cloud, pose_a=motion @ pose, pose_b=motion)
        assert b.probability == pytest.approx(a.probability, abs=1e-9)
        assert a.state == b.state


def test_bad_mesh_side_options_are_named(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    with pytest.raises(cp.InvalidInputError, match="mesh_side"):
        cp.collide(cube, sphere_cloud, mesh_side="exactly")
    with pytest.raises(cp.InvalidInputError, match="mesh_spacing"):
        cp.collide(cube, sphere_cloud, mesh_side="exact", mesh_spacing=0.01)
    with pytest.raises(cp.InvalidInputError, match="pose_a"):
        cp.collide(cube, sphere_cloud, pose_a=np.full((4, 4), np.nan))
    with pytest.raises(cp.InvalidInputError, match="surface"):
        cp.collide(cube, sphere_cloud, model="points", aggregation="surface")
