"""Sensor noise models from Python: formulas, PointCloud(sensor=...), bad input."""

from __future__ import annotations

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation


def test_depth_camera_default_is_khoshelham_on_the_axis() -> None:
    cam = cp.DepthCamera()
    z = np.array([0.5, 1.0, 2.0, 5.0])
    np.testing.assert_allclose(cam.sigma_axial(z), 1.425e-3 * z**2, rtol=1e-12)
    np.testing.assert_allclose(cam.sigma_lateral(z), 0.8 * z / 580.0, rtol=1e-12)
    pts = np.c_[np.zeros_like(z), np.zeros_like(z), z]
    cov = cam.covariances(pts, sensor_pose=np.eye(4))
    np.testing.assert_allclose(cov[:, 2, 2], (1.425e-3 * z**2) ** 2, rtol=1e-12)
    np.testing.assert_allclose(cov[:, 0, 0], (0.8 * z / 580.0) ** 2, rtol=1e-12)


def test_unset_parameters_are_the_cores_defaults() -> None:
    # None (the signature's default) is the Rust Default, written once there.
    kh, cam = cp.DepthCamera.khoshelham_2012(), cp.DepthCamera(focal_px=600.0)
    for name in ("axial_offset", "axial_quadratic", "axial_depth0", "sigma_px", "baseline_m"):
        assert getattr(cam, name) == getattr(kh, name), name
    assert cam.disparity_step_px == kh.disparity_step_px == 0.125 and cam.focal_px == 600.0
    st = cp.StereoCamera(sigma_px=None)
    assert (st.focal_px, st.baseline, st.sigma_disparity_px, st.sigma_px) == (
        430.0,
        0.05,
        0.08,
        0.5,
    )
    assert cp.Lidar().sigma_range == 0.01
    assert cp.Lidar(sigma_range=0.02).sigma_angle == cp.Lidar().sigma_angle


def test_presets_and_stereo_and_lidar_formulas() -> None:
    assert cp.DepthCamera.nguyen_2012().sigma_axial([0.4])[0] == pytest.approx(0.0012)
    st = cp.StereoCamera(focal_px=500.0, baseline=0.1, sigma_disparity_px=0.2)
    assert st.sigma_axial([4.0])[0] == pytest.approx(16.0 * 0.2 / 50.0)
    lidar = cp.Lidar(sigma_range=0.02, sigma_angle=0.001)
    u = np.array([0.0, 0.6, 0.8])
    cov = lidar.covariances([5.0 * u], origin=[0.0, 0.0, 0.0])[0]
    assert u @ cov @ u == pytest.approx(0.02**2)
    v = np.array([1.0, 0.0, 0.0])
    assert v @ cov @ v == pytest.approx((5.0 * 0.001) ** 2)


def test_point_cloud_from_a_sensor_uses_the_model() -> None:
    rng = np.random.default_rng(0)
    pts = rng.uniform(-1.0, 1.0, (200, 3)) + np.array([0.0, 0.0, 3.0])
    cam = cp.DepthCamera.nguyen_2012()
    pose = from_translation((0.1, 0.0, -0.2))
    cloud = cp.PointCloud(pts, sensor=cam, sensor_pose=pose)
    np.testing.assert_allclose(cloud.covariances, cam.covariances(pts, sensor_pose=pose))
    # Covariances are stretched along the viewing ray: the largest axis is the ray.
    ray = pts[0] - pose[:3, 3]
    ray /= np.linalg.norm(ray)
    _, v = np.linalg.eigh(cloud.covariances[0])
    assert abs(v[:, -1] @ ray) == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"sensor": cp.DepthCamera()}, "origin"),
        ({"sensor": cp.DepthCamera(), "sigma": 0.01, "origin": [0, 0, 0]}, "one of sigma"),
        ({"origin": [0, 0, 0]}, "only used with a sensor"),
        ({"sensor": "kinect", "origin": [0, 0, 0]}, "DepthCamera, StereoCamera or Lidar"),
        (
            {"sensor": cp.Lidar(), "origin": [0, 0, 0], "sensor_pose": np.eye(4)},
            "either origin or sensor_pose",
        ),
        ({"sensor": cp.DepthCamera(), "sensor_pose": from_translation((0, 0, 5))}, "not in front"),
    ],
)
def test_bad_sensor_arguments_are_named(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(cp.InvalidInputError, match=match):
        cp.PointCloud([[0.0, 0.0, 1.0], [0.1, 0.0, 1.2]], **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: cp.DepthCamera(focal_px=0.0), "focal_px"),
        (lambda: cp.DepthCamera(axial_quadratic=float("nan")), "axial_quadratic"),
        (lambda: cp.StereoCamera(baseline=-0.1), "baseline"),
        (lambda: cp.Lidar(sigma_range=-1.0), "sigma_range"),
    ],
)
def test_bad_sensor_parameters_are_named(make, name: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(cp.InvalidInputError, match=name):
        make()


def test_point_at_the_origin_is_refused() -> None:
    with pytest.raises(cp.InvalidInputError, match="point 1 lies at the sensor origin"):
        cp.PointCloud([[0, 0, 1.0], [0, 0, 0]], sensor=cp.Lidar(), origin=[0, 0, 0])


def test_open3d_and_trimesh_like_point_objects_are_accepted() -> None:
    pts = np.random.default_rng(1).normal(size=(50, 3))

    class TrimeshLike:  # trimesh.PointCloud exposes .vertices
        vertices = pts

    c = cp.PointCloud(TrimeshLike(), sigma=0.01)
    np.testing.assert_array_equal(c.points, pts)
    o3d = pytest.importorskip("open3d")
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    np.testing.assert_array_equal(cp.PointCloud(pc, sigma=0.01).points, pts)
