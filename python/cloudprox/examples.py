"""Built-in example files: a depth-camera scan of a table top and a gripper.

``write_example_files(folder)`` writes

* ``scan.pcd``: an organized 320 x 240 depth image (PCD ``binary_compressed``)
  of a table with a box and a mug in front of a wall, seen by a Kinect-like
  camera whose pose is the file's ``VIEWPOINT``. Depth noise follows Nguyen et
  al. (2012) along each ray, 1% of the pixels are dropped (NaN), and the pixels
  at depth edges are mixed pixels (veil points) as real structured-light
  sensors give them;
* ``gripper.stl``: a parallel gripper (palm and two fingers, 10 cm between the
  fingers' inner faces), binary STL, in its own frame: fingertips at ``z = 0``,
  palm above them (the gripper approaches along ``-z``);
* ``grasp-free.txt``: a pose (4 x 4, text) that puts the fingers around the box,
  1 cm from each side and 3 cm below its top: collision-free;
* ``grasp-collision.txt``: the same grasp 5 cm off to the side, so that one
  finger comes down 3 cm into the box's top: in collision.

The scene is exact (boxes and a cylinder), so the true gaps are known: the free
grasp clears the box by 10 mm on each side, about 5 noise sigmas at 1.1 m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from cloudprox import io
from cloudprox._native import DepthCamera, Mesh
from cloudprox.pose import from_translation, look_at

__all__ = ["BOX_CENTRE", "BOX_HALF", "TABLE_TOP", "gripper_mesh", "write_example_files"]

FloatArray = npt.NDArray[np.float64]

#: Height of the table top (m).
TABLE_TOP = 0.75
#: The box on the table: centre of its footprint and half extents (m).
BOX_CENTRE = np.array([0.1, 0.3])
BOX_HALF = np.array([0.04, 0.04, 0.075])
#: The mug: centre of its footprint, radius and height (m).
MUG = (np.array([-0.2, 0.35]), 0.04, 0.1)
#: Camera: position, point looked at (its optical frame is :func:`cloudprox.pose.look_at`'s),
#: image size and focal length (px).
CAMERA_AT = np.array([0.0, -0.55, 1.55])
CAMERA_LOOK = np.array([0.0, 0.3, 0.8])
WIDTH, HEIGHT, FOCAL = 320, 240, 290.0


def _boxes() -> list[tuple[FloatArray, FloatArray]]:
    """Axis-aligned boxes of the scene as (lower, upper) corners."""
    c, h = BOX_CENTRE, BOX_HALF
    return [
        (np.array([-0.6, -0.1, TABLE_TOP - 0.03]), np.array([0.6, 0.8, TABLE_TOP])),  # table top
        (
            np.array([c[0] - h[0], c[1] - h[1], TABLE_TOP]),
            np.array([c[0] + h[0], c[1] + h[1], TABLE_TOP + 2 * h[2]]),
        ),
        (np.array([-3.0, 1.5, 0.0]), np.array([3.0, 1.6, 3.0])),  # wall
        (np.array([-3.0, -3.0, -0.1]), np.array([3.0, 3.0, 0.0])),  # floor
    ]


def _ray_box(o: FloatArray, d: FloatArray, lo: FloatArray, hi: FloatArray) -> FloatArray:
    """Entry distance of rays ``o + t d`` into a box (inf where they miss)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t1 = (lo - o) * inv
        t2 = (hi - o) * inv
    t_near = np.nanmax(np.minimum(t1, t2), axis=1)
    t_far = np.nanmin(np.maximum(t1, t2), axis=1)
    hit = (t_near <= t_far) & (t_far > 0.0)
    return np.where(hit, np.maximum(t_near, 0.0), np.inf)


def _ray_mug(o: FloatArray, d: FloatArray) -> FloatArray:
    """Entry distance of rays into the mug (a closed vertical cylinder)."""
    (cx, cy), r, height = MUG
    z0, z1 = TABLE_TOP, TABLE_TOP + height
    px, py = o[0] - cx, o[1] - cy
    a = d[:, 0] ** 2 + d[:, 1] ** 2
    b = 2.0 * (px * d[:, 0] + py * d[:, 1])
    c = px * px + py * py - r * r
    disc = b * b - 4 * a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        t_side = (-b - np.sqrt(disc)) / (2 * a)
    z_side = o[2] + t_side * d[:, 2]
    side = np.where((disc >= 0) & (t_side > 0) & (z_side >= z0) & (z_side <= z1), t_side, np.inf)
    with np.errstate(divide="ignore"):
        t_top = (z1 - o[2]) / d[:, 2]
    xt, yt = o[0] + t_top * d[:, 0] - cx, o[1] + t_top * d[:, 1] - cy
    top = np.where((t_top > 0) & (xt * xt + yt * yt <= r * r), t_top, np.inf)
    return np.minimum(side, top)


def _render(rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
    """Depth image ``(HEIGHT, WIDTH)`` (NaN where nothing is seen) and the rays."""
    pose = look_at(CAMERA_AT, CAMERA_LOOK)
    u, v = np.meshgrid(np.arange(WIDTH), np.arange(HEIGHT))
    rays_cam = np.stack(
        [(u - (WIDTH - 1) / 2) / FOCAL, (v - (HEIGHT - 1) / 2) / FOCAL, np.ones_like(u, float)],
        axis=-1,
    ).reshape(-1, 3)
    d = rays_cam @ pose[:3, :3].T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = pose[:3, 3]
    t = np.full(len(d), np.inf)
    for lo, hi in _boxes():
        t = np.minimum(t, _ray_box(o, d, lo, hi))
    t = np.minimum(t, _ray_mug(o, d))
    # depth along the optical axis
    depth = t * (d @ pose[:3, 2])
    depth = depth.reshape(HEIGHT, WIDTH)
    depth[~np.isfinite(depth)] = np.nan
    return depth, rays_cam.reshape(HEIGHT, WIDTH, 3)


def _mixed_pixels(depth: FloatArray, rng: np.random.Generator) -> FloatArray:
    """Veil points: at depth edges (> 5 cm between 4-neighbours), a depth in between."""
    out = depth.copy()
    for axis in (0, 1):
        for shift in (1, -1):
            nb = np.roll(depth, shift, axis=axis)
            edge = np.abs(nb - depth) > 0.05
            if axis == 0:
                edge[0 if shift == 1 else -1, :] = False
            else:
                edge[:, 0 if shift == 1 else -1] = False
            mix = edge & (rng.random(depth.shape) < 0.6)
            w = rng.uniform(0.2, 0.8, depth.shape)
            out = np.where(mix & (depth < nb), w * depth + (1 - w) * nb, out)
    return out


def gripper_mesh() -> Mesh:
    """Return the example gripper: fingertips at ``z = 0``, palm above (approach ``-z``)."""
    palm = Mesh.cuboid(0.03, 0.09, 0.02).transformed(from_translation((0.0, 0.0, 0.07)))
    fingers = [
        Mesh.cuboid(0.01, 0.01, 0.025).transformed(from_translation((0.0, s * 0.06, 0.025)))
        for s in (-1.0, 1.0)
    ]
    return Mesh.merged([palm, *fingers])


def _grasp(offset: float, tip_height: float) -> FloatArray:
    """Gripper pose: fingertips at ``tip_height``, ``offset`` from the box's centre along y."""
    return from_translation((BOX_CENTRE[0], BOX_CENTRE[1] + offset, tip_height))


def write_example_files(folder: str | Path, seed: int = 0) -> dict[str, Path]:
    """Write the example files into ``folder`` (created); return their paths by name."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    depth, rays = _render(rng)
    cam = DepthCamera.nguyen_2012()
    finite = np.isfinite(depth)
    noisy = depth.copy()
    noisy[finite] += np.asarray(cam.sigma_axial(depth[finite])) * rng.standard_normal(
        int(finite.sum())
    )
    noisy = _mixed_pixels(noisy, rng)
    noisy[rng.random(noisy.shape) < 0.01] = np.nan  # dropouts
    pose = look_at(CAMERA_AT, CAMERA_LOOK)
    pts_cam = rays * noisy[..., None]
    pts = pts_cam.reshape(-1, 3) @ pose[:3, :3].T + pose[:3, 3]
    keep = np.flatnonzero(np.isfinite(pts).all(axis=1))
    scan = io.CloudFile(
        pts[keep], sensor_pose=pose, grid_shape=(HEIGHT, WIDTH), pixels=keep.tolist()
    )
    box_top = TABLE_TOP + 2 * BOX_HALF[2]
    paths = {
        "scan": out / "scan.pcd",
        "gripper": out / "gripper.stl",
        "grasp-free": out / "grasp-free.txt",
        "grasp-collision": out / "grasp-collision.txt",
    }
    io.write_point_cloud(paths["scan"], scan, encoding="binary_compressed")
    io.write_mesh(paths["gripper"], gripper_mesh())
    header = "gripper pose (4 x 4, gripper frame to world, metres)"
    np.savetxt(paths["grasp-free"], _grasp(0.0, box_top - 0.03), header=header)
    np.savetxt(paths["grasp-collision"], _grasp(0.05, box_top - 0.03), header=header)
    return paths
