"""The real-scan experiment's pieces: Kinect noise, hulls, reconstruction, gripper poses."""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation
from cloudprox.reproduce.realscan import (
    convex_hull,
    kinect_axial_sigma,
    kinect_covariances,
    sample_scan_poses,
)
from cloudprox.reproduce.reconstruct import reconstruct, reconstruct_many, surface_shape, tiles


def test_kinect_noise_follows_nguyen_et_al() -> None:
    # sigma_z = 0.0012 + 0.0019 (z - 0.4)^2: 1.2 mm at 0.4 m, 5.8 mm at 2 m.
    assert kinect_axial_sigma(np.array([0.4, 2.0])) == pytest.approx(
        [0.0012, 0.0012 + 0.0019 * 2.56]
    )
    pts = np.array([[0.0, 0.0, 2.0], [1.0, -0.5, 1.5]])
    cov = kinect_covariances(pts, 575.0)
    for p, c in zip(pts, cov, strict=False):
        ray = p / np.linalg.norm(p)
        assert np.allclose(c, c.T)
        stretch = np.linalg.norm(p) / p[2]
        assert ray @ c @ ray == pytest.approx((kinect_axial_sigma(p[2]) * stretch) ** 2)
        across = np.cross(ray, [0.0, 1.0, 0.0])
        across /= np.linalg.norm(across)
        assert across @ c @ across == pytest.approx((0.8 * p[2] / 575.0) ** 2)


def test_convex_hull_of_a_non_convex_mesh_is_convex_and_encloses_it() -> None:
    two = cp.Mesh.merged(
        [
            cp.Mesh.cuboid(0.1, 0.1, 0.1),
            cp.Mesh.cuboid(0.1, 0.1, 0.1).transformed(from_translation((0.5, 0, 0))),
        ]
    )
    hull = convex_hull(two)
    assert hull.is_closed and hull.is_convex
    assert hull.volume == pytest.approx(0.7 * 0.2 * 0.2)
    assert cp.ExactShape([hull]).part_kinds == ["convex"]


def test_intersection_only_query_agrees_with_the_full_one() -> None:
    rng = np.random.default_rng(0)
    a = cp.ExactShape([cp.Mesh.cylinder(0.1, 0.2, 16)], solid=False)
    b = cp.ExactShape([cp.Mesh.cuboid(0.3, 0.2, 0.05), cp.Mesh.cuboid(0.05, 0.05, 0.3)])
    poses = np.stack([from_translation(rng.uniform(-0.5, 0.5, 3)) for _ in range(200)])
    full = cp.exact_proximity_many(a, b, poses)
    fast = cp.exact_intersects_many(a, b, poses)
    assert fast.dtype == bool and fast.shape == (200,)
    assert np.array_equal(fast, full.intersecting)
    assert 20 < fast.sum() < 180


def test_reconstruction_of_a_noisy_sphere_lies_on_it() -> None:
    rng = np.random.default_rng(1)
    v = rng.standard_normal((6000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    sigma = 0.002
    pts = 0.5 * v + sigma * rng.standard_normal((6000, 3))
    mesh = reconstruct(pts, 0.02, sigma)
    r = np.linalg.norm(np.asarray(mesh.vertices), axis=1)
    assert np.abs(r - 0.5).max() < 0.02 + 3 * sigma
    assert mesh.area == pytest.approx(4 * np.pi * 0.25, rel=0.05)
    # As a bare surface: a probe inside the sphere does not touch it.
    shape = surface_shape(mesh)
    probe = cp.ExactShape([cp.Mesh.cuboid(0.05, 0.05, 0.05)])
    inside = cp.exact_proximity(probe, shape)
    assert not inside.intersecting and inside.distance > 0.4
    across = cp.exact_proximity(probe, shape, from_translation((0.5, 0.0, 0.0)))
    assert across.intersecting
    # The same cloud gives the same surface, run after run (a reproduction's
    # ground truth): Open3D's multithreaded solver varied here by a few triangles.
    for _ in range(3):
        again = reconstruct(pts, 0.02, sigma)
        assert np.array_equal(np.asarray(again.faces), np.asarray(mesh.faces))
        assert np.array_equal(np.asarray(again.vertices), np.asarray(mesh.vertices))


def test_reconstruction_asks_open3d_for_one_thread(monkeypatch: pytest.MonkeyPatch) -> None:
    # On a one-core machine the repeats above cannot differ: the solver's
    # thread count is what makes the surface reproducible.
    o3d = pytest.importorskip("open3d")
    solver = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson
    calls: list[dict[str, object]] = []

    def spy(pcd: object, **kwargs: object) -> object:
        calls.append(kwargs)
        return solver(pcd, **kwargs)

    monkeypatch.setattr(o3d.geometry.TriangleMesh, "create_from_point_cloud_poisson", spy)
    rng = np.random.default_rng(2)
    v = rng.standard_normal((2000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    reconstruct(0.5 * v, 0.04, 0.001)
    assert len(calls) == 1 and calls[0].get("n_threads") == 1


def test_reconstructions_in_a_process_pool_are_those_of_one_by_one() -> None:
    # The reproduction reconstructs a level's clouds at once, one per process:
    # the surfaces (its baseline's answers) must not depend on it.
    pytest.importorskip("open3d")
    rng = np.random.default_rng(3)
    clouds = []
    for k, radius in enumerate((0.5, 0.3, 0.4)):
        v = rng.standard_normal((1500, 3))
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        origin = None if k < 2 else (0.0, 0.0, 3.0)
        clouds.append((radius * v + 0.001 * rng.standard_normal((1500, 3)), 0.05, 0.001, origin))
    alone = reconstruct_many(clouds)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(2, mp_context=ctx) as pool:
        pooled = reconstruct_many(clouds, pool)
        with pytest.raises(ValueError, match="at least 10 points"):
            reconstruct_many([clouds[0], (clouds[1][0][:5], 0.05, 0.001, None)], pool)
    assert len(pooled) == 3
    for a, b in zip(alone, pooled, strict=True):
        assert len(a.faces) > 100
        assert np.array_equal(np.asarray(a.faces), np.asarray(b.faces))
        assert np.array_equal(np.asarray(a.vertices), np.asarray(b.vertices))


def test_tiles_partition_the_triangles() -> None:
    mesh = cp.Mesh.cylinder(0.3, 0.5, 64)
    parts = tiles(mesh, 0.1)
    assert len(parts) > 10
    assert sum(len(p.faces) for p in parts) == len(mesh.faces)
    assert sum(p.area for p in parts) == pytest.approx(mesh.area)
    with pytest.raises(ValueError, match="cell"):
        tiles(mesh, 0.0)


def test_reconstruction_rejects_bad_input() -> None:
    good = np.random.default_rng(0).random((50, 3))
    with pytest.raises(ValueError, match="shape"):
        reconstruct(good[:, :2], 0.1, 0.01)
    with pytest.raises(ValueError, match="at least 10"):
        reconstruct(good[:5], 0.1, 0.01)
    bad = good.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        reconstruct(bad, 0.1, 0.01)
    with pytest.raises(ValueError, match="spacing"):
        reconstruct(good, -1.0, 0.01)
    with pytest.raises(ValueError, match="sigma"):
        reconstruct(good, 0.1, float("inf"))


def test_scan_poses_reach_their_targets_against_a_wall() -> None:
    # A wall 2 m in front of the camera (z = 2), seen through its front face; a
    # 4 cm cube as the gripper. Exact distance along the ray: the cube's face.
    wall = cp.Mesh.cuboid(1.0, 1.0, 0.01).transformed(from_translation((0.0, 0.0, 2.01)))
    reference = cp.ExactShape([wall], solid=False)
    cube = cp.Mesh.cuboid(0.02, 0.02, 0.02)
    gripper = cp.ExactShape([cube], solid=False)
    bound = cp.ExactShape([cube])
    rng = np.random.default_rng(2)
    anchors = np.column_stack([rng.uniform(-0.3, 0.3, (50, 2)), np.full(50, 2.0)])
    sigma = np.full(50, 0.005)
    q = sample_scan_poses(gripper, bound, reference, anchors, sigma, np.zeros(3), 40, rng)
    assert q.poses.shape == (40, 4, 4)
    assert np.all(q.sigma == 0.005)
    unit = q.signed_distance / q.sigma
    assert unit.min() >= -8.0 - 1e-9 and unit.max() <= 20.0 + 1e-9
    assert (unit < -3.0).any() and (unit > 10.0).any()
    full = cp.exact_proximity_many(gripper, reference, q.poses)
    apart = q.signed_distance > 0.0
    assert np.allclose(full.distance[apart], q.signed_distance[apart], atol=1e-9)
    # Past contact: the cube's front (nearest-the-wall) corner is |d| beyond the face.
    assert np.all(full.intersecting[~apart])
