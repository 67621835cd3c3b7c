"""``exact_time_of_impact_many`` and the reproduction's pieces that now run in the core.

The reproduction places its poses with the core's time of impact and takes its
noise covariances, sampling spacing and standard deviations from the core; the
tests below check the binding on closed-form cases and bad input, that the
poses land at the signed distances asked for (measured by
``exact_proximity_many``), and that the core's values equal the formulas the
reproduction computed itself before (kept here as the reference).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import numpy.typing as npt
import pytest
from scipy.spatial import cKDTree

import cloudprox as cp
from cloudprox.pose import from_translation
from cloudprox.reproduce.methods import Draw, sampling_spacing
from cloudprox.reproduce.noise import NoiseModel
from cloudprox.reproduce.poses import draw_target_units, sample_poses
from cloudprox.reproduce.realscan import sample_scan_poses
from cloudprox.scenes import piano, room

FloatArray = npt.NDArray[np.float64]


def _cube_and_wall() -> tuple[cp.ExactShape, cp.ExactShape, FloatArray]:
    """A 0.1 m half-side cube at the origin, a wall's near face 0.8 m away along x."""
    cube = cp.ExactShape([cp.Mesh.cuboid(0.1, 0.1, 0.1)])
    wall = cp.ExactShape([cp.Mesh.cuboid(0.1, 5.0, 5.0)])
    return cube, wall, from_translation((1.0, 0.0, 0.0))


def test_time_of_impact_has_the_closed_form_travel() -> None:
    cube, wall, at_wall = _cube_and_wall()
    starts = np.stack([np.eye(4)] * 5)
    starts[4] = from_translation((0.85, 0.0, 0.0))  # 0.05 into the wall
    dirs = np.array(
        [[2.0, 0.0, 0.0], [0.6, 0.8, 0.0], [0.6, 0.8, 0.0], [-1.0, 0.0, 0.0], [1.0, 0, 0]]
    )
    target = np.array([0.0, 0.25, -0.05, 0.0, 0.0])
    t = cp.exact_time_of_impact_many(cube, wall, starts, dirs, target=target, pose_b=at_wall)
    assert t.shape == (5,) and t.dtype == np.float64
    # Head-on 0.8; at cosine 0.6 a 0.25 gap after 0.55 / 0.6 and a 0.05 depth
    # after 0.85 / 0.6; moving away never; intersecting at the start: 0.
    assert t[:3] == pytest.approx([0.8, 0.55 / 0.6, 0.85 / 0.6], abs=1e-7)
    assert t[3] == math.inf and t[4] == 0.0
    # The poses reached are at their targets, as exact_proximity measures them.
    unit = dirs[:3] / np.linalg.norm(dirs[:3], axis=1, keepdims=True)
    reached = starts[:3].copy()
    reached[:, :3, 3] += unit * t[:3, None]
    s = cp.exact_proximity_many(cube, wall, reached, pose_b=at_wall).signed_distance
    assert s == pytest.approx(target[:3], abs=1e-7)
    # One direction and one target for every start; a reach short of the wall.
    one = cp.exact_time_of_impact_many(cube, wall, starts[:2], [1.0, 0.0, 0.0], pose_b=at_wall)
    assert one == pytest.approx([0.8, 0.8])
    short = cp.exact_time_of_impact_many(
        cube, wall, starts[:1], [1.0, 0.0, 0.0], max_travel=0.5, pose_b=at_wall
    )
    assert short[0] == math.inf


def test_time_of_impact_refuses_bad_input() -> None:
    cube, wall, at_wall = _cube_and_wall()
    starts = np.stack([np.eye(4)] * 2)
    x = [1.0, 0.0, 0.0]

    def toi(**kw: object) -> object:
        args: dict[str, object] = {"poses_a": starts, "directions": x, "pose_b": at_wall}
        args.update(kw)
        return cp.exact_time_of_impact_many(cube, wall, **args)  # type: ignore[arg-type]

    with pytest.raises(cp.InvalidInputError, match="direction"):
        toi(directions=[0.0, 0.0, 0.0])
    with pytest.raises(cp.InvalidInputError, match="direction"):
        toi(directions=[[1.0, 0.0, math.nan], [1.0, 0.0, 0.0]])
    with pytest.raises(cp.InvalidInputError, match="directions"):
        toi(directions=np.ones((3, 3)))
    with pytest.raises(cp.InvalidInputError, match="target"):
        toi(target=[0.0, 0.1, 0.2])
    with pytest.raises(cp.InvalidInputError, match="target"):
        toi(target=math.inf)
    with pytest.raises(cp.InvalidInputError, match="max_travel"):
        toi(max_travel=-1.0)
    with pytest.raises(cp.InvalidInputError, match="max_travel"):
        toi(max_travel=math.nan)
    with pytest.raises(cp.InvalidInputError, match="poses_a"):
        toi(poses_a=np.ones((2, 4, 4)))
    # A depth target between surfaces, whose depth is unknown.
    surface = cp.ExactShape([cp.Mesh.cuboid(0.1, 0.1, 0.1)], solid=False)
    with pytest.raises(cp.InvalidInputError, match="penetration depths"):
        cp.exact_time_of_impact_many(surface, wall, starts, x, target=-0.01, pose_b=at_wall)


def test_piano_poses_land_at_their_target_signed_distances() -> None:
    p, r = piano(), room()
    sigma, n = 0.02, 30
    rng = np.random.default_rng(5)
    # sample_poses draws its targets first: the same draw, from a copy.
    unit, _ = draw_target_units(
        n, copy.deepcopy(rng), max(0.5 / sigma, 12.0), far_share=0.25, deep_share=0.2
    )
    q = sample_poses(p, r, n, sigma, rng, far_share=0.25, deep_share=0.2)
    exact = cp.exact_proximity_many(p.exact, r.exact, q.poses).signed_distance
    assert np.allclose(exact, unit * sigma, atol=1e-7)
    assert np.allclose(q.signed_distance, exact)
    assert (unit < -3.0).any() and (unit > 10.0).any()


def test_scan_poses_land_at_their_target_gaps() -> None:
    # A wall 2 m in front of the camera, a 4 cm cube as the gripper.
    wall = cp.Mesh.cuboid(1.0, 1.0, 0.01).transformed(from_translation((0.0, 0.0, 2.01)))
    reference = cp.ExactShape([wall], solid=False)
    cube = cp.Mesh.cuboid(0.02, 0.02, 0.02)
    gripper = cp.ExactShape([cube], solid=False)
    rng = np.random.default_rng(4)
    anchors = np.column_stack([rng.uniform(-0.3, 0.3, (50, 2)), np.full(50, 2.0)])
    unit, _ = draw_target_units(30, copy.deepcopy(rng), 20.0)
    q = sample_scan_poses(
        gripper, cp.ExactShape([cube]), reference, anchors, np.full(50, 0.005), np.zeros(3), 30, rng
    )
    assert np.allclose(q.signed_distance, unit * 0.005, atol=1e-7)
    full = cp.exact_proximity_many(gripper, reference, q.poses)
    apart = q.signed_distance > 0.0
    assert np.allclose(full.distance[apart], q.signed_distance[apart], atol=1e-9)
    assert np.all(full.intersecting[~apart])


def _former_covariances(model: NoiseModel, points: FloatArray) -> FloatArray:
    """``NoiseModel.covariances`` as the reproduction computed it in numpy."""
    n = len(points)
    eye = np.broadcast_to(np.eye(3), (n, 3, 3))
    if model.origin is None:
        return model.sigma**2 * eye
    ray = points - np.asarray(model.origin, dtype=float)
    ray /= np.linalg.norm(ray, axis=1, keepdims=True)
    outer = ray[:, :, None] * ray[:, None, :]
    lat = (model.sigma * model.lateral_ratio) ** 2
    return lat * (eye - outer) + model.sigma**2 * outer


def _former_spacing(points: FloatArray, k: int = 6) -> float:
    """``sampling_spacing`` as the reproduction computed it with scipy."""
    d, _ = cKDTree(points).query(points, k=k + 1)
    return float(np.median(d[:, k]) * math.sqrt(math.pi / k))


@pytest.mark.parametrize("n", [1000, 9000])
def test_core_noise_spacing_and_sigma_equal_the_former_formulas(n: int) -> None:
    rng = np.random.default_rng(n)
    # A noisy, unevenly sampled surface (the core's spacing switches from the
    # tree to the hashed grid above 4096 points).
    xy = rng.random((n, 2)) ** 1.5
    pts = np.column_stack([xy, 0.1 * np.sin(3.0 * xy[:, 0]) + 1e-3 * rng.standard_normal(n)])
    assert sampling_spacing(pts) == pytest.approx(_former_spacing(pts), rel=1e-12)
    for model in (
        NoiseModel(0.01),
        NoiseModel(0.02, origin=(0.0, -3.0, 2.0)),
        NoiseModel(0.03, origin=(0.5, 0.5, 2.0), lateral_ratio=0.25),
    ):
        former = _former_covariances(model, pts)
        assert np.allclose(model.covariances(pts), former, rtol=1e-12, atol=1e-18)
    cov_a = NoiseModel(0.02, origin=(0.0, -3.0, 2.0)).covariances(pts)
    cov_b = NoiseModel(0.01).covariances(pts[:100])
    draw = Draw(pts, cov_a, pts[:100], cov_b)
    std_a, std_b = draw.sensor_std()
    assert np.allclose(std_a, np.sqrt(np.linalg.eigvalsh(cov_a)[:, -1]), rtol=1e-12)
    assert np.allclose(std_b, 0.01, rtol=1e-12)


def test_ray_covariances_refuse_bad_input() -> None:
    pts = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0]])
    c = cp.ray_covariances(pts, 0.02, 0.005, origin=[0.0, 0.0, 0.0])
    assert c.shape == (2, 3, 3)
    assert c[0] == pytest.approx(np.diag([0.005**2, 0.005**2, 0.02**2]))
    with pytest.raises(cp.InvalidInputError, match="sigma_ray"):
        cp.ray_covariances(pts, -1.0, 0.005, origin=[0.0, 0.0, 0.0])
    with pytest.raises(cp.InvalidInputError, match="sigma_lat"):
        cp.ray_covariances(pts, 0.01, math.nan, origin=[0.0, 0.0, 0.0])
    with pytest.raises(cp.InvalidInputError, match="origin"):
        cp.ray_covariances(pts, 0.01, 0.01, origin=[0.0, 0.0, 1.0])
    with pytest.raises(cp.InvalidInputError, match="origin"):
        cp.ray_covariances(pts, 0.01, 0.01)
