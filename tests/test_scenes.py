from __future__ import annotations

import numpy as np
import pytest

import cloudprox
from cloudprox.pose import from_translation
from cloudprox.scenes import build_scene, piano, room


def test_meshes_and_exact_queries_from_python() -> None:
    cube = cloudprox.Mesh.cuboid(0.1, 0.1, 0.1)
    assert cube.area == pytest.approx(0.24) and cube.volume == pytest.approx(0.008)
    assert cube.is_closed and cube.is_convex()
    sample = cube.sample(500, seed=1)
    assert isinstance(sample, cloudprox.MeshSample)
    pts, normals, faces = sample
    assert sample.points is not None and sample[0] is not None and len(sample) == 3
    np.testing.assert_array_equal(sample.normals, normals)
    np.testing.assert_array_equal(sample.faces, faces)
    assert pts.shape == (500, 3) and normals.shape == (500, 3) and faces.shape == (500,)
    assert repr(sample) == "MeshSample(points=500)"
    assert np.allclose(np.max(np.abs(pts), axis=1), 0.1)
    shape = cloudprox.ExactShape([cube])
    assert shape.part_kinds == ["convex"]
    r = cloudprox.exact_proximity(shape, shape, None, from_translation((0.5, 0.0, 0.0)))
    assert isinstance(r, cloudprox.Proximity)
    assert not r.intersecting and r.distance == pytest.approx(0.3)
    assert r.penetration_depth is None and r.signed_distance == r.distance
    assert r.to_dict() == {
        "intersecting": False,
        "distance": r.distance,
        "penetration_depth": None,
        "signed_distance": r.distance,
    }
    # (Offset sideways a little: EPA misjudges the depth of two boxes whose faces
    # are exactly coplanar.)
    many = cloudprox.exact_proximity_many(
        shape, shape, np.stack([from_translation((x, 0.001, 0.002)) for x in (0.15, 0.25)])
    )
    assert list(many.intersecting) == [True, False]
    assert many.signed_distance == pytest.approx([-0.05, 0.05])
    assert isinstance(many, cloudprox.ProximityBatch) and len(many) == 2
    assert many.distance.dtype == np.float64 and many.intersecting.dtype == np.bool_
    assert many[1].distance == pytest.approx(0.05) and not many[-1].intersecting
    keys = {"intersecting", "distance", "penetration_depth", "signed_distance"}
    assert set(many.to_dict()) == keys
    with pytest.raises(IndexError, match="out of range for 2 poses"):
        many[2]
    with pytest.raises(cloudprox.InvalidInputError, match="refers to vertex 5"):
        cloudprox.Mesh(np.eye(3), [[0, 1, 5]])
    with pytest.raises(cloudprox.InvalidInputError, match="faces must be integers"):
        cloudprox.Mesh(np.eye(3), [[0.0, 1.0, 2.0]])
    with pytest.raises(cloudprox.InvalidInputError, match="shape \\(m, 3\\)"):
        cloudprox.Mesh(np.eye(3), [0, 1, 2])
    with pytest.raises(cloudprox.InvalidInputError, match="exactly one of n and density"):
        cube.sample()


def test_union_sampling_stays_on_the_union_surface() -> None:
    p = piano()
    pts, normals = p.sample(2000.0, seed=4)
    # No sample lies inside another part (the union's surface only) ...
    for part in p.parts:
        assert not part.contains(pts, margin=1e-6).any(), part.name
    # ... and every sample lies on some part's surface: a tiny probe at it touches the piano.
    probe = cloudprox.ExactShape([cloudprox.Mesh.cuboid(1e-4, 1e-4, 1e-4)])
    poses = np.stack([from_translation(x) for x in pts[::50]])
    assert cloudprox.exact_proximity_many(probe, p.exact, poses).intersecting.all()
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0)
    with pytest.raises(ValueError, match="density"):
        p.sample(0.0)


def test_scene_gaps_are_exact() -> None:
    scene = build_scene(sigma=0.005, points=400, seed=3)
    assert scene.piano_points.shape[1] == 3 and scene.room_points.shape[1] == 3
    assert {"floor", "walls", "table 1", "table 2", "table 3", "table 4"} <= set(scene.room.groups)
    assert 2.5 < scene.piano.diagonal < 3.2
    for gap in (-0.015, 0.0, 0.01, 0.075):
        pose = scene.piano_pose(gap)
        gaps = scene.gaps(pose)
        assert gaps[scene.table] == pytest.approx(gap, abs=1e-9)
        assert scene.exact_gap(pose) == pytest.approx(gap, abs=1e-9)
        assert min(gaps, key=gaps.get) == scene.table
    # The noise has the requested spread.
    clean = build_scene(sigma=0.0, points=400, seed=3)
    noise = scene.piano_points - clean.piano_points
    assert np.std(noise) == pytest.approx(0.005, rel=0.1)
    # The room holds the piano: its parts' boxes span the walls.
    lo, hi = room().bounds()
    assert lo[0] < -3.0 and hi[0] > 3.0 and lo[2] < 0.0
    with pytest.raises(ValueError, match="points must be >= 10"):
        build_scene(points=1)


def test_elements_do_not_read_a_collision_off_a_surface_that_does_not_describe_it() -> None:
    # The demo's scene: a patch's quadric, wrapped around a contact 0.4 m away,
    # ran across the piano's bottom and the table top 20 mm (4 sigma) apart with
    # its normal nearly horizontal, and read P = 1 there. Such a patch is now cut.
    s = 0.005
    scene = build_scene(sigma=s, points=10_000, seed=0)
    pa = cloudprox.PointCloud(scene.piano_points, sigma=s)
    room_cloud = cloudprox.PointCloud(scene.room_points, sigma=s)

    def p(gap_sigmas: float) -> float:
        pose = scene.piano_pose(gap_sigmas * s)
        return cloudprox.collide(pa, room_cloud, pose_a=pose, model="elements").probability

    # 20 mm (4 sigma) is less than half the clouds' sampling spacing (the
    # 6th-neighbour distance: 44 mm on the piano, 53 mm in the room), where
    # sampled surfaces may touch: no collision is read there (it read P = 1),
    # and 8 sigma is free.
    assert p(4.0) < 0.5
    assert p(8.0) <= 0.1
    assert p(15.0) == 0.0
    assert p(-1.0) >= 0.9 and p(-3.0) >= 0.9
