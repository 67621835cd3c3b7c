"""Meshes as query objects: collide(mesh, cloud) against exact distances."""

from __future__ import annotations

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


def test_mesh_against_cloud_follows_the_exact_gap(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    states = {
        g: cp.collide(cube, sphere_cloud, pose_a=cube_pose(g * SIGMA)).state
        for g in (20.0, 10.0, -5.0, -10.0)
    }
    assert states == {20.0: "free", 10.0: "free", -5.0: "collision", -10.0: "collision"}


def test_mesh_on_either_side_gives_the_same_probability(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    for g in (4.0, 0.0):
        ab = cp.collide(cube, sphere_cloud, pose_a=cube_pose(g * SIGMA))
        ba = cp.collide(sphere_cloud, cube, pose_b=cube_pose(g * SIGMA))
        assert ab.probability == pytest.approx(ba.probability, abs=1e-6)


def test_meshes_of_other_libraries_are_accepted(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)

    class TrimeshLike:  # trimesh.Trimesh exposes .vertices and .faces
        vertices = cube.vertices
        faces = cube.faces

    ref = cp.collide(cube, sphere_cloud, pose_a=cube_pose(0.0))
    got = cp.collide(TrimeshLike(), sphere_cloud, pose_a=cube_pose(0.0))
    assert got.probability == pytest.approx(ref.probability)
    o3d = pytest.importorskip("open3d")
    box = o3d.geometry.TriangleMesh.create_box(0.1, 0.1, 0.1)  # corner at the origin
    r = cp.collide(box, sphere_cloud, pose_a=from_translation((-0.05, -0.05, RADIUS + 20 * SIGMA)))
    assert r.state == "free"
    r = cp.collide(box, sphere_cloud, pose_a=from_translation((-0.05, -0.05, RADIUS - 10 * SIGMA)))
    assert r.state == "collision"


def test_collide_many_accepts_a_mesh(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    poses = np.stack([cube_pose(g * SIGMA) for g in (20.0, -10.0)])
    states = [r.state for r in cp.collide_many(cube, sphere_cloud, poses)]
    assert states == ["free", "collision"]


def test_bad_sides_are_named(sphere_cloud: cp.PointCloud) -> None:
    cube = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    with pytest.raises(cp.InvalidInputError, match="both sides are meshes"):
        cp.collide(cube, cube)
    with pytest.raises(TypeError, match="must be a PointCloud or a mesh"):
        cp.collide(np.zeros((3, 3)), sphere_cloud)  # type: ignore[arg-type]
    with pytest.raises(cp.InvalidInputError, match="mesh_spacing is only used"):
        cp.collide(sphere_cloud, sphere_cloud, mesh_spacing=0.01)
    with pytest.raises(cp.InvalidInputError, match="spacing"):
        cp.collide(cube, sphere_cloud, mesh_spacing=-1.0)
