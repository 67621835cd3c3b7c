"""The scan pipeline in the core (``scan_to_cloud``) against the Python composition
it replaced: the same public functions called step by step give the same cloud."""

from __future__ import annotations

import pickle
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import filters
from cloudprox._native import ScanStep, scan_to_cloud
from cloudprox.pipeline import (
    PipelineError,
    SensorSpec,
    load_side,
    parse_filter,
    parse_pose,
    parse_vector,
    read_mesh_file,
)


@pytest.fixture(scope="module")
def example(tmp_path_factory) -> dict[str, str]:
    from cloudprox.examples import write_example_files

    paths = write_example_files(tmp_path_factory.mktemp("example"))
    return {k: str(v) for k, v in paths.items()}


@pytest.fixture(scope="module")
def files(tmp_path_factory, example) -> dict[str, str]:
    """A PLY with stored covariances, an unorganized XYZ, and a link mesh."""
    d = tmp_path_factory.mktemp("scan")
    scan = cp.io.read_point_cloud(example["scan"])
    pts = np.asarray(scan.points)[::7]
    rng = np.random.default_rng(3)
    a = rng.normal(size=(len(pts), 3, 3)) * 1e-3
    covs = a @ a.transpose(0, 2, 1) + np.eye(3) * 1e-6
    ply = d / "stored.ply"
    cp.io.write_point_cloud(ply, cp.io.CloudFile(pts, covariances=covs))
    xyz = d / "plain.xyz"
    cp.io.write_point_cloud(xyz, pts)
    stl = d / "box.stl"
    cp.io.write_mesh(stl, cp.Mesh.cuboid(0.045, 0.045, 0.08))
    return {"ply": str(ply), "xyz": str(xyz), "stl": str(stl)}


def previous_composition(path: str, spec: SensorSpec, steps: list[str]) -> dict[str, Any]:
    """What ``load_side`` did in Python before the pipeline moved to the core."""
    scan = cp.io.read_point_cloud(path)
    points = np.asarray(scan.points)
    pose = spec.sensor_pose if spec.sensor_pose is not None else scan.sensor_pose
    where: dict[str, Any] = (
        {"origin": spec.origin} if spec.origin is not None else {"sensor_pose": pose}
    )
    if spec.model is not None:
        covs = spec.model.covariances(points, **where)
    elif spec.sigma is None:
        covs = np.asarray(scan.covariances)
    else:
        covs = None
    origin = spec.origin if spec.origin is not None else (None if pose is None else pose[:3, 3])
    pixels = None if scan.pixels is None else np.asarray(scan.pixels)
    counts = []
    for text in steps:
        step = parse_filter(text)
        before = len(points)
        if step.name == "voxel":
            v = filters.voxel_downsample(points, float(step.args[0]), covariances=covs)
            points, covs, pixels = v.points, v.covariances, None
        else:
            if step.name == "crop":
                box = parse_vector(step.args[0], 6, "crop")
                keep = filters.crop_box(points, box[:3], box[3:])
            elif step.name == "outliers":
                k = int(step.args[0]) if step.args else None
                std = float(step.args[1]) if len(step.args) > 1 else None
                keep = filters.statistical_outlier_removal(points, k=k, std_ratio=std)
            elif step.name == "shadow":
                angle = float(step.args[0]) if step.args else None
                grid = scan.grid_shape if pixels is not None else None
                keep = filters.shadow_filter(
                    points, origin, pixels=pixels, grid_shape=grid, min_angle_deg=angle
                )
            else:
                mesh, _ = read_mesh_file(step.args[0])
                padding = float(step.args[1]) if len(step.args) > 1 else None
                link = parse_pose(step.args[2], "pose") if len(step.args) > 2 else np.eye(4)
                keep = filters.SelfFilter([(mesh, link)], padding).apply(points)
            points = points[keep]
            covs = None if covs is None else covs[keep]
            pixels = None if pixels is None else pixels[keep]
        counts.append((before, len(points)))
    if covs is not None:
        rho = (
            None
            if spec.model is None
            else cp.PointCloud(points, sensor=spec.model, **where).noise_correlation
        )
        cloud = cp.PointCloud(points, cov=covs, discretization=True, noise_correlation=rho)
    else:
        cloud = cp.PointCloud(points, sigma=spec.sigma, discretization=True)
    return {"cloud": cloud, "counts": counts}


def assert_same_cloud(new: cp.PointCloud, old: cp.PointCloud) -> None:
    """Bit for bit: the same core functions on the same numbers."""
    np.testing.assert_array_equal(new.points, old.points)
    np.testing.assert_array_equal(new.sensor_covariances, old.sensor_covariances)
    np.testing.assert_array_equal(new.covariances, old.covariances)
    assert new.noise_correlation == old.noise_correlation


CASES = [
    # (file, sensor spec, steps)
    pytest.param(
        "scan",
        {"kind": "depth-camera", "model": cp.DepthCamera.nguyen_2012()},
        ["shadow", "crop:-0.5,0,0.7,0.5,0.8,1.2", "outliers", "voxel:0.004"],
        id="pcd-viewpoint-depth-camera-organized",
    ),
    pytest.param(
        "scan",
        {"kind": "lidar", "model": cp.Lidar(), "origin": np.array([0.0, 0.0, 0.0])},
        ["voxel:0.006", "shadow:12", "outliers:10:1.5"],
        id="pcd-lidar-origin-unorganized-shadow",
    ),
    pytest.param(
        "scan",
        {"kind": "isotropic", "sigma": 0.002},
        ["shadow", "self:{stl}:0.01:0.1,0.3,0.825"],
        id="pcd-isotropic-self",
    ),
    pytest.param("ply", {}, ["outliers:12:1.0", "voxel:0.01"], id="ply-stored-covariances"),
    pytest.param(
        "xyz",
        {
            "kind": "stereo",
            "model": cp.StereoCamera(),
            "sensor_pose": cp.pose.from_translation((0.0, 0.0, -0.1)),
        },
        ["crop:-1,-1,0,1,1,2", "shadow:8"],
        id="xyz-stereo-sensor-pose",
    ),
]


@pytest.mark.parametrize(("name", "spec", "steps"), CASES)
def test_load_side_equals_the_previous_python_composition(
    example, files, name: str, spec: dict[str, Any], steps: list[str]
) -> None:
    path = example.get(name) or files[name]
    steps = [s.format(stl=files["stl"]) for s in steps]
    sensor = SensorSpec(**spec)
    side = load_side(path, sensor, [parse_filter(s) for s in steps])
    old = previous_composition(path, sensor, steps)
    assert [(f["before"], f["after"]) for f in side.filters] == old["counts"]
    assert [f["filter"] for f in side.filters] == steps
    assert all(after < before for before, after in old["counts"]), old["counts"]
    assert side.cloud is not None
    assert_same_cloud(side.cloud, old["cloud"])


def test_scan_to_cloud_steps_and_noise(example) -> None:
    scan = cp.io.read_point_cloud(example["scan"])
    result = scan_to_cloud(
        scan, [ScanStep.voxel(0.01), ScanStep.outliers(k=8)], sigma=0.001, discretization=False
    )
    assert [s[0] for s in result.steps] == ["voxel", "outliers"]
    assert result.steps[0][1] == len(scan)
    assert result.emptied_by is None
    voxels = filters.voxel_downsample(scan.points, 0.01)
    keep = filters.statistical_outlier_removal(voxels.points, k=8)
    expected = cp.PointCloud(voxels.points[keep], sigma=0.001)
    assert_same_cloud(result.cloud, expected)
    assert len(result.cloud) == result.steps[1][2]
    # The stored sensor pose is the fallback of a sensor model.
    viewpoint = scan_to_cloud(scan, sensor=cp.Lidar(), discretization=False).cloud
    given = scan_to_cloud(
        scan, sensor=cp.Lidar(), sensor_pose=scan.sensor_pose, discretization=False
    ).cloud
    np.testing.assert_array_equal(viewpoint.covariances, given.covariances)
    # A pipeline's cloud pickles like any other: rebuilt bit for bit.
    cloud = scan_to_cloud(scan, [ScanStep.voxel(0.01)], sensor=cp.DepthCamera()).cloud
    assert_same_cloud(pickle.loads(pickle.dumps(cloud)), cloud)


def test_scan_to_cloud_errors(example, files) -> None:
    scan = cp.io.read_point_cloud(example["scan"])
    far = ScanStep.crop([5, 5, 5], [6, 6, 6])
    result = scan_to_cloud(scan, [far, ScanStep.voxel(0.01)], sigma=0.001)
    assert result.emptied_by == 0 and result.steps == [("crop", len(scan), 0)]
    with pytest.raises(cp.InvalidInputError, match=r"step 0 \(crop\) removed every point"):
        _ = result.cloud
    plain = cp.io.read_point_cloud(files["xyz"])
    with pytest.raises(cp.InvalidInputError, match="stores no covariances"):
        scan_to_cloud(plain)
    with pytest.raises(cp.InvalidInputError, match="records no sensor viewpoint"):
        scan_to_cloud(plain, sensor=cp.Lidar())
    with pytest.raises(cp.InvalidInputError, match="needs the sensor origin"):
        scan_to_cloud(plain, [ScanStep.shadow()], sigma=0.001)
    with pytest.raises(cp.InvalidInputError, match="either sigma or sensor"):
        scan_to_cloud(plain, sigma=0.001, sensor=cp.Lidar())
    with pytest.raises(cp.InvalidInputError, match="voxel_size"):
        scan_to_cloud(plain, [ScanStep.voxel(-1.0)], sigma=0.001)
    with pytest.raises(cp.InvalidInputError, match="k must be >= 1"):
        ScanStep.outliers(k=0)
    with pytest.raises(cp.InvalidInputError, match="merge"):
        ScanStep.voxel(0.01, merge="median")


def test_load_side_messages_are_the_command_lines(example, files) -> None:
    steps = [parse_filter("crop:5,5,5,6,6,6"), parse_filter("voxel:0.01")]
    with pytest.raises(PipelineError, match=r"filter crop:5,5,5,6,6,6 removed every point"):
        load_side(example["scan"], SensorSpec(sigma=0.001), steps)
    with pytest.raises(PipelineError, match="give --sigma or --sensor"):
        load_side(files["xyz"], SensorSpec(), [])
    with pytest.raises(PipelineError, match="give --origin or --sensor-pose for --sensor lidar"):
        load_side(files["xyz"], SensorSpec("lidar", model=cp.Lidar()), [])
    with pytest.raises(PipelineError, match=r"shadow filter on .*sensor origin is unknown"):
        load_side(files["xyz"], SensorSpec(sigma=0.001), [parse_filter("shadow")])
