"""The pose constructors' binding contract: shapes, dtype, conventions, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import pose

S = math.sqrt(0.5)


def assert_rigid(m: np.ndarray) -> None:
    assert m.shape == (4, 4) and m.dtype == np.float64
    np.testing.assert_allclose(m[:3, :3] @ m[:3, :3].T, np.eye(3), atol=1e-12)
    assert np.linalg.det(m[:3, :3]) == pytest.approx(1.0)
    np.testing.assert_array_equal(m[3], [0.0, 0.0, 0.0, 1.0])


def test_every_constructor_returns_a_rigid_float64_4x4() -> None:
    for m in (
        pose.from_translation((1, 2, 3)),  # integers are accepted
        pose.from_quaternion((1.0, 2.0, 3.0, 4.0)),  # normalised
        pose.from_rpy((0.3, -0.2, 1.1), translation=(1.0, 2.0, 3.0)),
        pose.from_rotation_vector(np.array([0.3, -0.2, 1.1])),
        pose.look_at((0.0, -0.55, 1.55), (0.0, 0.3, 0.8)),
    ):
        assert_rigid(m)
    many = pose.random_rotations(5, seed=3)
    assert many.shape == (5, 4, 4) and many.dtype == np.float64
    for m in many:
        assert_rigid(m)
    assert pose.random_rotations(0).shape == (0, 4, 4)


def test_translation_and_defaults() -> None:
    t = pose.from_translation([0.1, -0.2, 0.3])
    np.testing.assert_array_equal(t[:3, :3], np.eye(3))
    np.testing.assert_array_equal(t[:3, 3], [0.1, -0.2, 0.3])
    for rotate in (pose.from_rpy, pose.from_rotation_vector):
        np.testing.assert_array_equal(rotate((0.0, 0.0, 0.0)), np.eye(4))
    np.testing.assert_array_equal(pose.from_quaternion((1.0, 0.0, 0.0, 0.0)), np.eye(4))


def test_a_quarter_turn_about_z_maps_x_to_y_in_every_form() -> None:
    x = np.array([1.0, 0.0, 0.0, 1.0])
    for m in (
        pose.from_quaternion((S, 0.0, 0.0, S)),  # (w, x, y, z): scalar first
        pose.from_rpy((0.0, 0.0, math.pi / 2)),
        pose.from_rotation_vector((0.0, 0.0, math.pi / 2)),
    ):
        np.testing.assert_allclose(m @ x, [0.0, 1.0, 0.0, 1.0], atol=1e-12)


def test_look_at_takes_eye_target_and_up() -> None:
    # The camera convention (z forward, y down) is tested in Rust
    # (cloud/pose.rs); here: the arguments arrive in their places.
    eye, target = np.array([0.2, -0.5, 1.5]), np.array([0.0, 0.3, 0.8])
    m = pose.look_at(eye, target)
    np.testing.assert_array_equal(m[:3, 3], eye)
    forward = (target - eye) / np.linalg.norm(target - eye)
    np.testing.assert_allclose(m[:3, 2], forward, atol=1e-12)
    down = pose.look_at((0, 0, 2), (0, 0, 0), up=(0, 1, 0))
    np.testing.assert_allclose(down[:3, 1], [0.0, -1.0, 0.0], atol=1e-12)


def test_random_rotations_are_seeded() -> None:
    a = pose.random_rotations(50, seed=11)
    np.testing.assert_array_equal(a, pose.random_rotations(50, seed=11))
    assert not np.array_equal(a, pose.random_rotations(50, seed=12))
    np.testing.assert_array_equal(a[:, :3, 3], 0.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: pose.from_translation((1.0, 2.0)), r"translation must have shape \(3,\)"),
        (lambda: pose.from_translation((np.nan, 0.0, 0.0)), "translation"),
        (lambda: pose.from_translation((2e9, 0.0, 0.0)), "translation"),
        (lambda: pose.from_translation("abc"), "translation"),
        (lambda: pose.from_quaternion((0.0, 0.0, 0.0, 0.0)), "quaternion .* zero"),
        (lambda: pose.from_quaternion((1.0, 0.0, 0.0)), r"quaternion must have shape \(4,\)"),
        (lambda: pose.from_quaternion((1.0, np.inf, 0.0, 0.0)), "quaternion"),
        (lambda: pose.from_quaternion((1, 0, 0, 0), translation=(0, 0)), "translation"),
        (lambda: pose.from_rpy((0.0, np.nan, 0.0)), "rpy"),
        (lambda: pose.from_rpy(np.zeros((3, 1))), "rpy"),
        (lambda: pose.from_rotation_vector((np.nan, 0.0, 0.0)), "rotation_vector"),
        (lambda: pose.look_at((0, 0, 0), (0, 0, 0)), "target"),
        (lambda: pose.look_at((0, 0, 0), (0, 0, 1)), "parallel"),
        (lambda: pose.look_at((0, 0, 0), (1, 0, 0), up=(0, 0, 0)), "up"),
        (lambda: pose.look_at((0, 0, np.nan), (1, 0, 0)), "eye"),
        (lambda: pose.random_rotations(-1), "n must be"),
    ],
)
def test_bad_input_raises_invalid_input_naming_the_argument(call, match: str) -> None:
    with pytest.raises(cp.InvalidInputError, match=match):
        call()


def test_io_reads_an_inline_quaternion_pose_through_the_core() -> None:
    m = cp.io.read_pose(f"1,2,3,{S},0,0,{S}")
    np.testing.assert_allclose(m, pose.from_quaternion((S, 0, 0, S), translation=(1, 2, 3)))
    with pytest.raises(cp.InvalidInputError, match=r"grasp: quaternion .* zero"):
        cp.io.read_pose("1,2,3,0,0,0,0", what="grasp")


def test_agrees_with_scipy() -> None:
    rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    rng = np.random.default_rng(5)
    for _ in range(20):
        rpy, rotvec = rng.uniform(-3.0, 3.0, 3), rng.uniform(-2.0, 2.0, 3)
        q = rng.normal(size=4)
        # ROS rpy = scipy's extrinsic "xyz"; scipy's quaternions are scalar last.
        np.testing.assert_allclose(
            pose.from_rpy(rpy)[:3, :3], rotation.from_euler("xyz", rpy).as_matrix(), atol=1e-12
        )
        np.testing.assert_allclose(
            pose.from_rotation_vector(rotvec)[:3, :3],
            rotation.from_rotvec(rotvec).as_matrix(),
            atol=1e-12,
        )
        np.testing.assert_allclose(
            pose.from_quaternion(q)[:3, :3],
            rotation.from_quat(np.roll(q, -1)).as_matrix(),
            atol=1e-12,
        )
