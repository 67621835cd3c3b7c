"""Sensor noise models from Python: outputs, defaults from the core, PointCloud(sensor=...),
bad input (the formulas are tested in Rust, ``uncertainty_sensor.rs``)."""

from __future__ import annotations

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation


def test_model_outputs_are_float64_arrays_of_the_documented_shapes() -> None:
    # The formulas and the defaults' values are tested in Rust
    # (crates/cloudprox/tests/uncertainty_sensor.rs); here: what crosses the binding.
    z = np.array([0.5, 1.0, 2.0, 5.0])
    pts = np.c_[np.zeros_like(z), np.zeros_like(z), z]
    for model in (cp.DepthCamera(), cp.StereoCamera(), cp.Lidar()):
        cov = model.covariances(pts, sensor_pose=np.eye(4))
        assert cov.shape == (4, 3, 3) and cov.dtype == np.float64, model
        assert cov.flags.c_contiguous
        # The same covariances seen from the origin point as from the identity pose.
        np.testing.assert_array_equal(cov, model.covariances(pts, origin=[0.0, 0.0, 0.0]))
    for model in (cp.DepthCamera(), cp.StereoCamera()):
        for law in (model.sigma_axial, model.sigma_lateral):
            out = law(z.reshape(2, 2))  # flattened
            assert out.shape == (4,) and out.dtype == np.float64
            np.testing.assert_array_equal(out, law(list(z)))
    cam = cp.DepthCamera()
    assert cam.depth_step(z).shape == cam.noise_correlation(z).shape == (4,)


def test_unset_parameters_are_the_cores_defaults() -> None:
    # None (the signature's default) is the Rust Default, written once there:
    # setting one parameter leaves every other at the default model's value.
    fields = {
        cp.DepthCamera: (
            "axial_offset",
            "axial_quadratic",
            "axial_depth0",
            "focal_px",
            "sigma_px",
            "baseline_m",
            "disparity_step_px",
        ),
        cp.StereoCamera: ("focal_px", "baseline", "sigma_disparity_px", "sigma_px"),
        cp.Lidar: ("sigma_range", "sigma_angle"),
    }
    for cls, names in fields.items():
        default = cls()
        for name in names:
            value = 2.0 * getattr(default, name) + 1.0
            one = cls(**{name: value})
            assert getattr(one, name) == value, (cls, name)
            for other in names:
                if other != name:
                    assert getattr(one, other) == getattr(default, other), (cls, name, other)
            assert getattr(cls(**{name: None}), name) == getattr(default, name)
    # The documented default depth camera is the Khoshelham preset.
    kh = cp.DepthCamera.khoshelham_2012()
    assert all(getattr(kh, n) == getattr(cp.DepthCamera(), n) for n in fields[cp.DepthCamera])
    assert cp.DepthCamera.nguyen_2012().axial_offset != kh.axial_offset


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
