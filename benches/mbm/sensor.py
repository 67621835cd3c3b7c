"""Sensor clouds of a MotionBenchMaker scene: a simulated depth camera, and area-sampled surfaces.

Two ways a robot could see the primitives of a :class:`~mbm.scene.Scene`:

* :func:`camera_scan`: a depth camera at a fixed position (by default
  :data:`CAMERA_POSITION`, above and behind the robot's base, as a head
  camera), aimed at the part of the scene within the robot's reach. Its rays
  are cast analytically against the primitives
  (:meth:`~mbm.scene.Scene.ray_distances`: exact boxes, cylinders, spheres; the
  nearest hit) on a pinhole grid whose field of view covers that part and whose
  size gives about ``target`` hits; returns between 0.4 and 4.5 m are kept (a
  Kinect v1's range). The noise is the Kinect v1 model of Nguyen, Izadi and
  Lovell (2012) as the repository's scans use it
  (:func:`cloudprox.reproduce.realscan.kinect_camera`: axial ``0.0012 + 0.0019
  (z - 0.4)^2`` stretched along the ray, lateral 0.8 px of the Kinect's 580 px
  focal length), drawn from each point's covariance; the cloud is made as
  ``benches/tabletop.py`` makes its scan (an organized
  :class:`cloudprox.io.CloudFile` with the sensor pose, then
  ``to_point_cloud(sensor=...)``: the sensor covariance at each noisy point plus
  the discretization part).
* :func:`area_scan`: ``n`` points spread uniformly by area over every
  primitive's surface (those inside another primitive dropped: the surface of
  the union), with isotropic Gaussian noise of ``sigma`` (3 mm by default):
  ``cloudprox.PointCloud(points, sigma=sigma)``.

Both return a :class:`SensorCloud`: the :class:`cloudprox.PointCloud`, the
noisy and the exact points, and what was made (counts, camera intrinsics,
median noise, build seconds).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

import cloudprox as cp
from cloudprox.reproduce.realscan import kinect_camera

from .scene import Scene

__all__ = [
    "CAMERA_POSITION",
    "KINECT_FOCAL",
    "KINECT_RANGE",
    "REACH_BOX",
    "SensorCloud",
    "area_scan",
    "camera_scan",
    "cast",
    "median_sigma",
    "pinhole_rays",
]

FloatArray = npt.NDArray[np.float64]
#: The camera's fixed position (robot base frame, metres): above and behind the base.
CAMERA_POSITION = (-0.5, 0.0, 1.4)
#: The Kinect v1's focal length (px) of its 640 x 480 depth image: the lateral noise's scale.
KINECT_FOCAL = 580.0
#: Depths (m) a Kinect v1 returns.
KINECT_RANGE = (0.4, 4.5)
#: The part of the world the camera is aimed at and frames: (lo, hi) around the base.
REACH_BOX = ((-1.2, -1.2, -0.8), (1.2, 1.2, 1.4))


@dataclass
class SensorCloud:
    """A scene's simulated sensor cloud.

    Attributes
    ----------
    kind : str
        ``"camera"`` or ``"area"``.
    cloud : cloudprox.PointCloud
        The points with their covariances.
    points : numpy.ndarray
        The noisy points ``(n, 3)`` (world frame).
    exact : numpy.ndarray
        The noise-free surface points they were drawn around ``(n, 3)``.
    sensor_pose : numpy.ndarray or None
        The camera's optical frame in the world (``None`` for ``"area"``).
    info : dict
        What was made: counts, intrinsics, median sigma, seconds.
    """

    kind: str
    cloud: cp.PointCloud
    points: FloatArray
    exact: FloatArray
    sensor_pose: FloatArray | None
    info: dict[str, Any] = field(default_factory=dict)


def median_sigma(cloud: cp.PointCloud) -> float:
    """Median over the points of ``sqrt(trace(cov) / 3)`` (m): the cloud's typical noise."""
    cov = np.asarray(cloud.covariances)
    return float(np.median(np.sqrt(np.trace(cov, axis1=1, axis2=2) / 3.0)))


def _aim(scene: Scene, position: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Target point and the corners to frame: the scene's bounds clipped to :data:`REACH_BOX`."""
    lo, hi = scene.bounds()
    rlo, rhi = (np.asarray(v, dtype=float) for v in REACH_BOX)
    lo, hi = np.maximum(lo, rlo), np.minimum(hi, rhi)
    if np.any(lo >= hi):  # nothing within reach: frame the whole scene
        lo, hi = scene.bounds()
    corners = np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )
    target = (lo + hi) / 2
    if np.linalg.norm(target - position) < 1e-6:
        target = target + np.array([1.0, 0.0, 0.0])
    return target, corners


def pinhole_rays(
    pose: FloatArray, width: int, height: int, focal: float
) -> tuple[FloatArray, FloatArray]:
    """Return the unit rays (world) of a ``width x height`` pinhole grid and their depth factors.

    The optical frame is ``pose`` (x right, y down, z forward); pixel ``(u, v)``
    looks along ``((u - cx) / f, (v - cy) / f, 1)``, the centre ``((w - 1) / 2,
    (h - 1) / 2)``. Returns the directions ``(h w, 3)`` row by row and the
    depth per unit distance along each (``z`` of the unit ray).
    """
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    cam = np.stack(
        [(u - (width - 1) / 2) / focal, (v - (height - 1) / 2) / focal, np.ones(u.shape)], -1
    ).reshape(-1, 3)
    cam /= np.linalg.norm(cam, axis=1, keepdims=True)
    return cam @ pose[:3, :3].T, cam[:, 2]


def cast(
    scene: Scene, pose: FloatArray, width: int, height: int, focal: float, dirs: FloatArray
) -> FloatArray:
    """Distance along each pixel's ray to the first primitive it hits (``inf`` when none).

    Each primitive is intersected only with the rays of the pixel rectangle its
    bounding box projects to (every ray when the box reaches behind the camera).
    """
    eye = pose[:3, 3]
    out = np.full(len(dirs), np.inf)
    for o in scene.objects:
        h = o.half_extents
        corners = np.array(
            [[x, y, z] for x in (-h[0], h[0]) for y in (-h[1], h[1]) for z in (-h[2], h[2])]
        )
        local = (o.to_world(corners) - eye) @ pose[:3, :3]
        if np.all(local[:, 2] > 1e-6):
            u = local[:, 0] / local[:, 2] * focal + (width - 1) / 2
            v = local[:, 1] / local[:, 2] * focal + (height - 1) / 2
            u0, u1 = max(0, math.floor(u.min())), min(width - 1, math.ceil(u.max()))
            v0, v1 = max(0, math.floor(v.min())), min(height - 1, math.ceil(v.max()))
            if u0 > u1 or v0 > v1:
                continue
            rows = np.arange(v0, v1 + 1)[:, None] * width
            idx = (rows + np.arange(u0, u1 + 1)[None, :]).ravel()
        else:
            idx = np.arange(len(dirs))
        t = o.ray_distances(eye, dirs[idx])
        out[idx] = np.minimum(out[idx], t)
    return out


def _intrinsics(pose: FloatArray, corners: FloatArray, max_fov: float) -> tuple[float, float]:
    """Half-angle tangents (x, y) that frame the corners in front of the camera, capped."""
    local = (corners - pose[:3, 3]) @ pose[:3, :3]
    z = np.maximum(local[:, 2], 1e-3)
    cap = math.tan(math.radians(max_fov) / 2)
    tx = float(min(np.max(np.abs(local[:, 0]) / z), cap))
    ty = float(min(np.max(np.abs(local[:, 1]) / z), cap))
    floor = math.tan(math.radians(20.0))
    return max(tx, floor), max(ty, floor)


def camera_scan(
    scene: Scene,
    *,
    target: int = 120_000,
    seed: int = 0,
    position: npt.ArrayLike = CAMERA_POSITION,
    max_fov_deg: float = 100.0,
) -> SensorCloud:
    """Simulate a Kinect v1 scan of the scene's primitives from a fixed position.

    Parameters
    ----------
    scene : Scene
        The primitives.
    target : int
        About how many points (hits) the scan should have; the image size is
        chosen from a coarse cast's hit share.
    seed : int
        Seed of the noise.
    position : array_like, shape (3,)
        The camera's position (world); it is aimed at the centre of the scene's
        bounds within :data:`REACH_BOX`.
    max_fov_deg : float
        Largest field of view along either image axis (degrees).

    Returns
    -------
    SensorCloud
        ``kind="camera"``; ``info`` has ``width``, ``height``, ``focal_px`` (of
        the ray grid), ``fov_deg``, ``points``, ``median_depth``,
        ``median_sigma``, ``cast_seconds`` and ``cloud_seconds``.

    Raises
    ------
    ValueError
        If no ray hits the scene.
    """
    t0 = time.perf_counter()
    eye = np.asarray(position, dtype=float)
    aim, corners = _aim(scene, eye)
    view = (aim - eye) / np.linalg.norm(aim - eye)
    up = (0.0, 0.0, 1.0) if abs(view[2]) < 0.99 else (1.0, 0.0, 0.0)
    pose = cp.pose.look_at(eye, aim, up)
    tx, ty = _intrinsics(pose, corners, max_fov_deg)
    # coarse cast: the share of pixels that hit, to size the image
    coarse_w = 160
    coarse_h = max(8, round(coarse_w * ty / tx))
    coarse_f = (coarse_w - 1) / 2 / tx
    dirs, _ = pinhole_rays(pose, coarse_w, coarse_h, coarse_f)
    t = cast(scene, pose, coarse_w, coarse_h, coarse_f, dirs)
    share = float(np.mean(np.isfinite(t)))
    if share == 0.0:
        raise ValueError(f"{scene.scenario}/{scene.index:04d}: the camera at {eye} sees nothing")
    pixels = target / share
    width = max(16, round(math.sqrt(pixels * tx / ty)))
    height = max(16, round(pixels / width))
    focal = (width - 1) / 2 / tx
    dirs, zfactor = pinhole_rays(pose, width, height, focal)
    t = cast(scene, pose, width, height, focal, dirs)
    depth = t * zfactor
    keep = np.flatnonzero(np.isfinite(t) & (depth >= KINECT_RANGE[0]) & (depth <= KINECT_RANGE[1]))
    if len(keep) == 0:
        raise ValueError(f"{scene.scenario}/{scene.index:04d}: no return within the Kinect's range")
    exact = eye + t[keep, None] * dirs[keep]
    cast_seconds = time.perf_counter() - t0
    t1 = time.perf_counter()
    sensor = kinect_camera(KINECT_FOCAL)
    cov = np.asarray(sensor.covariances(exact, sensor_pose=pose))
    rng = np.random.default_rng(seed)
    noisy = exact + np.einsum(
        "nij,nj->ni", np.linalg.cholesky(cov), rng.standard_normal(exact.shape)
    )
    cloud = cp.io.CloudFile(
        noisy, sensor_pose=pose, grid_shape=(height, width), pixels=keep.tolist()
    ).to_point_cloud(sensor=sensor)
    info = {
        "width": width,
        "height": height,
        "focal_px": focal,
        "fov_deg": [math.degrees(2 * math.atan(tx)), math.degrees(2 * math.atan(ty))],
        "position": eye.tolist(),
        "aim": aim.tolist(),
        "points": len(keep),
        "median_depth": float(np.median(depth[keep])),
        "median_sigma": median_sigma(cloud),
        "cast_seconds": cast_seconds,
        "cloud_seconds": time.perf_counter() - t1,
    }
    return SensorCloud("camera", cloud, noisy, exact, pose, info)


def area_scan(
    scene: Scene, *, n: int = 120_000, sigma: float = 0.003, seed: int = 0
) -> SensorCloud:
    """Sample the primitives' surfaces uniformly by area, with isotropic noise.

    Parameters
    ----------
    scene : Scene
        The primitives.
    n : int
        Number of points.
    sigma : float
        Standard deviation of the isotropic Gaussian noise (m).
    seed : int
        Seed of the samples and the noise.

    Returns
    -------
    SensorCloud
        ``kind="area"``; ``info`` has ``points``, ``sigma``, ``hidden_share`` (the
        share of area samples that fell inside another primitive and were
        dropped), ``spacing`` (``sqrt(area / n)``), ``sample_seconds`` and
        ``cloud_seconds``.

    Raises
    ------
    ValueError
        If the scene has no primitive or ``n`` is not positive.
    """
    if not scene.objects or n <= 0:
        raise ValueError("area_scan needs primitives and n > 0")
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    areas = np.array([o.area for o in scene.objects])
    kept: list[FloatArray] = []
    have, drawn, dropped = 0, 0, 0
    while have < n:
        m = max(1024, int(1.2 * (n - have)))
        counts = rng.multinomial(m, areas / areas.sum())
        for i, (o, c) in enumerate(zip(scene.objects, counts, strict=True)):
            p = o.sample_surface(int(c), rng)
            hidden = scene.contains(p, skip=i)
            dropped += int(hidden.sum())
            kept.append(p[~hidden])
            have += int((~hidden).sum())
        drawn += m
        if have == 0 and drawn > 10 * n:
            raise ValueError("every surface sample is inside another primitive")
    exact = np.concatenate(kept)
    exact = exact[rng.permutation(len(exact))[:n]]
    noisy = exact + rng.normal(0.0, sigma, exact.shape)
    sample = time.perf_counter() - t0
    t1 = time.perf_counter()
    cloud = cp.PointCloud(noisy, sigma=sigma)
    info = {
        "points": n,
        "sigma": sigma,
        "hidden_share": dropped / drawn,
        "area": float(areas.sum()),
        "spacing": math.sqrt(float(areas.sum()) * (1 - dropped / drawn) / n),
        "median_sigma": sigma,
        "sample_seconds": sample,
        "cloud_seconds": time.perf_counter() - t1,
    }
    return SensorCloud("area", cloud, noisy, exact, None, info)
