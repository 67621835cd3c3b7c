"""`distance`: the clearance between sampled surfaces, with its standard deviation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_rpy, from_translation
from tests.helpers import RADIUS, SIGMA, phi


def cube_pose(gap: float) -> np.ndarray:
    """A 10 cm cube whose bottom face is `gap` above the sphere's top (exact distance)."""
    return from_translation((0.0, 0.0, RADIUS + 0.05 + gap))


@pytest.fixture(scope="module")
def cube() -> cp.Mesh:
    return cp.Mesh.cuboid(0.05, 0.05, 0.05)


@pytest.fixture(scope="module")
def dense() -> tuple[cp.PointCloud, cp.PointCloud]:
    """Two 10 000-point noisy spheres (spacing 3.5 mm, under twice the noise)."""
    base = cp.synthetic.sample_sphere(10_000, RADIUS)
    return tuple(  # type: ignore[return-value]
        cp.PointCloud(cp.synthetic.add_noise(base, SIGMA, seed=s), sigma=SIGMA) for s in (5, 6)
    )


def test_mesh_and_cloud_read_the_exact_gap(
    spheres: tuple[cp.PointCloud, cp.PointCloud], cube: cp.Mesh
) -> None:
    sphere, _ = spheres
    d = cp.distance(cube, sphere, cube_pose(0.010))
    assert 0.0 < d.std < 2.5 * SIGMA
    assert abs(d.distance - 0.010) < 3.0 * d.std
    # The witnesses: the cube's bottom face and the sphere's top, along z.
    assert abs(d.point_a[2] - (RADIUS + 0.010)) < 1e-6
    assert abs(np.hypot(d.point_a[0], d.point_a[1])) < 0.02
    assert abs(np.linalg.norm(d.point_b) - RADIUS) < 3.0 * SIGMA
    assert abs(abs(d.normal[2]) - 1.0) < 0.05
    assert not d.beyond_max_distance


def test_two_clouds_read_the_exact_gap(dense: tuple[cp.PointCloud, cp.PointCloud]) -> None:
    a, b = dense
    gap = 0.010
    d = cp.distance(a, b, pose_b=from_translation((2.0 * RADIUS + gap, 0.0, 0.0)))
    assert 0.0 < d.std < 2.5 * SIGMA
    assert abs(d.distance - gap) < 4.0 * d.std
    assert d.point_a[0] == pytest.approx(RADIUS, abs=3.0 * SIGMA)
    assert d.point_b[0] == pytest.approx(RADIUS + gap, abs=3.0 * SIGMA)
    assert d.normal[0] > 0.95


def test_swapping_the_sides_swaps_the_witnesses(
    spheres: tuple[cp.PointCloud, cp.PointCloud], cube: cp.Mesh
) -> None:
    sphere, other = spheres
    for a, b in ((cube, sphere), (other, sphere)):
        pose = cube_pose(0.006) if a is cube else from_translation((2.0 * RADIUS + 0.006, 0, 0))
        ab = cp.distance(a, b, pose)
        ba = cp.distance(b, a, None, pose)
        assert ba.distance == pytest.approx(ab.distance, rel=1e-9, abs=1e-12)
        assert ba.std == pytest.approx(ab.std, rel=1e-9, abs=1e-12)
        np.testing.assert_allclose(ba.point_a, ab.point_b, atol=1e-9)
        np.testing.assert_allclose(ba.point_b, ab.point_a, atol=1e-9)
        np.testing.assert_allclose(ba.normal, -ab.normal, atol=1e-9)


def test_a_rigid_motion_moves_the_witnesses_only(
    spheres: tuple[cp.PointCloud, cp.PointCloud], cube: cp.Mesh
) -> None:
    sphere, _ = spheres
    here = cp.distance(cube, sphere, cube_pose(0.004))
    motion = from_translation((0.3, -0.2, 1.1)) @ from_rpy((0.4, -0.7, 1.9))
    moved = cp.distance(cube, sphere, motion @ cube_pose(0.004), motion)
    assert moved.distance == pytest.approx(here.distance, abs=1e-9)
    assert moved.std == pytest.approx(here.std, abs=1e-9)
    rot, shift = motion[:3, :3], motion[:3, 3]
    np.testing.assert_allclose(moved.point_a, rot @ here.point_a + shift, atol=1e-9)
    np.testing.assert_allclose(moved.normal, rot @ here.normal, atol=1e-9)


@pytest.mark.parametrize("gap_sigmas", [-1.0, 0.5, 2.0])
def test_the_crossing_probability_is_collides_reading(
    spheres: tuple[cp.PointCloud, cp.PointCloud], cube: cp.Mesh, gap_sigmas: float
) -> None:
    sphere, other = spheres
    pose = cube_pose(gap_sigmas * SIGMA)
    d = cp.distance(cube, sphere, pose)
    assert d.crossing_probability == pytest.approx(
        float(phi(np.array(-d.distance / d.std))), abs=1e-12
    )
    assert d.crossing_probability <= cp.collide(cube, sphere, pose).probability + 1e-12
    # Two clouds near contact: the reading is one of collide's.
    pose = from_translation((2.0 * RADIUS + gap_sigmas * SIGMA, 0.0, 0.0))
    d = cp.distance(other, sphere, pose)
    assert d.near_contact
    assert d.crossing_probability <= cp.collide(other, sphere, pose).probability + 1e-12


def test_max_distance_stops_with_a_lower_bound(
    dense: tuple[cp.PointCloud, cp.PointCloud],
) -> None:
    a, b = dense
    gap = 0.5
    d = cp.distance(a, b, pose_b=from_translation((2.0 * RADIUS + gap, 0, 0)), max_distance=0.05)
    assert d.beyond_max_distance
    assert 0.05 < d.distance <= gap + 3.0 * SIGMA
    assert d.std == 0.0
    assert all(math.isnan(v) for v in d.point_a)
    assert d.crossing_probability == 0.0
    full = cp.distance(a, b, pose_b=from_translation((2.0 * RADIUS + gap, 0, 0)))
    assert not full.beyond_max_distance
    assert d.distance <= full.distance + 1e-9
    assert abs(full.distance - gap) < 4.0 * full.std + 1e-3


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"max_distance": -0.1}, "max_distance"),
        ({"max_distance": float("nan")}, "max_distance"),
        ({"no_such_option": 1}, "no_such_option"),
        ({"pose_a": np.full((4, 4), np.nan)}, "pose_a"),
        ({"pose_b": np.eye(3)}, "pose_b"),
    ],
)
def test_bad_inputs_are_named(
    spheres: tuple[cp.PointCloud, cp.PointCloud], kwargs: dict[str, object], words: str
) -> None:
    a, b = spheres
    with pytest.raises((cp.InvalidInputError, TypeError, ValueError), match=words):
        cp.distance(a, b, **kwargs)  # type: ignore[arg-type]
