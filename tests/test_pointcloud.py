from __future__ import annotations

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation


def random_points(n: int = 50, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, 3))


def test_points_round_trip_as_float64_c_contiguous() -> None:
    pts = random_points()
    cloud = cp.PointCloud(pts)
    out = cloud.points
    assert out.dtype == np.float64 and out.shape == (50, 3) and out.flags.c_contiguous
    np.testing.assert_array_equal(out, pts)
    assert len(cloud) == 50
    assert repr(cloud) == "PointCloud with 50 points."


@pytest.mark.parametrize(
    "convert",
    [
        lambda p: p.tolist(),
        lambda p: np.asfortranarray(p),
        lambda p: p.astype(np.float32),
        lambda p: np.round(p * 1000).astype(np.int64),
        lambda p: p[::-1],  # negative strides
        lambda p: np.asarray(p, dtype=object),
    ],
    ids=["list", "fortran", "float32", "int64", "reversed", "object"],
)
def test_any_numeric_array_like_is_accepted(convert) -> None:
    pts = random_points()
    given = convert(pts)
    cloud = cp.PointCloud(given)
    np.testing.assert_allclose(cloud.points, np.asarray(given, dtype=np.float64))


def test_no_noise_gives_zero_covariances() -> None:
    cloud = cp.PointCloud(random_points())
    assert cloud.covariances.shape == (50, 3, 3)
    assert np.all(cloud.covariances == 0.0)
    assert np.all(cloud.sigma_max == 0.0)


def test_scalar_sigma() -> None:
    cloud = cp.PointCloud(random_points(), sigma=0.003)
    np.testing.assert_allclose(cloud.covariances, np.broadcast_to(0.003**2 * np.eye(3), (50, 3, 3)))
    np.testing.assert_allclose(cloud.sigma_max, 0.003)
    # A 0-d array is a scalar too.
    np.testing.assert_allclose(
        cp.PointCloud(random_points(), sigma=np.float64(0.003)).sigma_max, 0.003
    )


def test_per_point_sigma() -> None:
    sig = np.linspace(0.001, 0.005, 50)
    cloud = cp.PointCloud(random_points(), sigma=sig)
    np.testing.assert_allclose(cloud.sigma_max, sig)
    np.testing.assert_allclose(cloud.covariances[:, 0, 0], sig**2)
    np.testing.assert_allclose(cloud.covariances[:, 0, 1], 0.0)


def test_full_covariances_are_kept() -> None:
    rng = np.random.default_rng(3)
    m = rng.normal(size=(50, 3, 3)) * 0.01
    cov = m @ m.transpose(0, 2, 1)
    cloud = cp.PointCloud(random_points(), cov=cov)
    np.testing.assert_allclose(cloud.covariances, cov, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(cloud.sigma_max, np.sqrt(np.linalg.eigvalsh(cov)[:, -1]))


def test_discretization_and_its_k_take_effect() -> None:
    g = np.stack(np.meshgrid(np.arange(20), np.arange(20), indexing="ij"), -1).reshape(-1, 2)
    pts = np.column_stack([0.01 * g, np.zeros(len(g))])
    plain = cp.PointCloud(pts, sigma=0.001)
    disc = cp.PointCloud(pts, sigma=0.001, discretization=True)
    disc_k4 = cp.PointCloud(pts, sigma=0.001, discretization=True, k=4)
    # Where the spread goes is tested in Rust (uncertainty_discretization.rs);
    # here: the option and its k take effect, the sensor part is kept apart.
    assert np.all(disc.sigma_max > plain.sigma_max)
    np.testing.assert_array_equal(disc.sensor_covariances, plain.covariances)
    assert not np.allclose(disc.covariances, disc_k4.covariances)
    # k belongs to the discretization.
    with pytest.raises(cp.InvalidInputError, match="only used with discretization=True"):
        cp.PointCloud(pts, sigma=0.001, k=4)


def test_transformed_moves_points_and_rotates_covariances() -> None:
    pts = random_points()
    cov = np.diag([1e-6, 4e-6, 9e-6])
    cloud = cp.PointCloud(pts, cov=np.broadcast_to(cov, (50, 3, 3)))
    t = from_translation((0.1, -0.2, 0.3)) @ cp.pose.random_rotations(1, seed=5)[0]
    q = t[:3, :3]
    moved = cloud.transformed(t)
    assert isinstance(moved, cp.PointCloud) and len(moved) == 50
    np.testing.assert_allclose(moved.points, pts @ q.T + t[:3, 3], atol=1e-12)
    np.testing.assert_allclose(
        moved.covariances, np.broadcast_to(q @ cov @ q.T, (50, 3, 3)), atol=1e-18
    )
    np.testing.assert_array_equal(cloud.points, pts)  # the original is untouched


def test_transformed_refuses_a_pose_that_moves_points_out_of_range() -> None:
    # Points and translation each within the 1e9 m bound, their sum beyond it.
    cloud = cp.PointCloud(random_points() + 9e8)
    with pytest.raises(cp.InvalidInputError, match="moves the cloud out of range"):
        cloud.transformed(from_translation((5e8, 0.0, 0.0)))


def test_pointcloud_is_frozen() -> None:
    cloud = cp.PointCloud(random_points())
    with pytest.raises(AttributeError):
        cloud.points = np.zeros((3, 3))  # type: ignore[misc]


def test_samplers() -> None:
    s = cp.synthetic.sample_sphere(200, radius=0.5, center=[1.0, 2.0, 3.0])
    assert s.shape == (200, 3)
    np.testing.assert_allclose(np.linalg.norm(s - [1.0, 2.0, 3.0], axis=1), 0.5)
    box = cp.synthetic.sample_box_surface([0.1, 0.2, 0.3], 0.05)
    on_face = np.isclose(np.abs(box), [0.1, 0.2, 0.3]).any(axis=1)
    assert box.shape[1] == 3 and on_face.all()
    assert np.all(np.abs(box) <= [0.1 + 1e-12, 0.2 + 1e-12, 0.3 + 1e-12])
    noisy = cp.synthetic.add_noise(s, 0.01, seed=7)
    np.testing.assert_array_equal(noisy, cp.synthetic.add_noise(s, 0.01, seed=7))
    assert not np.array_equal(noisy, cp.synthetic.add_noise(s, 0.01, seed=8))
    assert 0.005 < np.std(noisy - s) < 0.015


def test_version_and_exports() -> None:
    assert isinstance(cp.__version__, str) and cp.__version__.count(".") == 2
    for name in cp.__all__:
        assert hasattr(cp, name), name
    assert cp.PointCloud.__module__ == "cloudprox._native"
