"""The table-top scene of the robot benchmarks, its simulated scan and python-fcl checkers.

A table top (0.7 x 1.2 m, its surface at the robot base's height, z = 0) with
three meshes that registry packages ship standing on it (fetched into the cache
by ``tests/realfiles.py``, SHA-256 checked): the Stanford bunny (a 99-face
decimation of the scan, ``stl_io`` crate), Spot (``meshx`` crate) and geomview's
mushroom (Debian), each scaled to 0.18-0.22 m. A simulated Kinect v1 (320 x 240,
focal 290 px, times ``scale``; 1.1-1.6 m away) ray-casts them (Open3D) and adds
the Nguyen et al. (2012) noise (axial ``0.0012 + 0.0019 (z - 0.4)^2``, lateral
0.8 px, drawn from each point's covariance). The Franka Panda comes from the
``gym-ignition-models`` wheel (``tests/robots.py``), its base at the origin.

Used by ``benches/planning.py`` and ``benches/robot.py``; needs python-fcl and
Open3D (``pip install -e '.[bench]'``).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benches.mbm.checkers import fcl_mesh, fcl_robot
from tests.realfiles import real_file

import cloudprox as cp
from cloudprox.reproduce.realscan import kinect_camera

#: Table top: x, y extents and thickness (its surface at z = 0, the robot's base).
TABLE = ((0.3, 1.0), (-0.6, 0.6), 0.04)
#: Objects: (real file, up axis, height m, (x, y) on the table, yaw rad).
OBJECTS = (
    ("stl_binary_bunny", 1, 0.2, (0.5, -0.22), 0.6),
    ("obj_spot", 1, 0.22, (0.62, 0.12), 2.0),
    ("off_mushroom", 2, 0.18, (0.45, 0.3), 0.0),
)
CAMERA_AT = np.array([1.5, -0.3, 0.8])
CAMERA_LOOK = np.array([0.55, 0.0, 0.05])
WIDTH, HEIGHT, FOCAL = 320, 240, 290.0
#: Upper bound of the distance of any Panda link point to a joint axis above it (m).
REACH = 1.2


def scene_meshes() -> dict[str, cp.Mesh]:
    """Return the exact scene: the table top and the objects on it, world frame."""
    (x0, x1), (y0, y1), t = TABLE
    table = cp.Mesh.cuboid((x1 - x0) / 2, (y1 - y0) / 2, t / 2)
    pose = cp.pose.from_translation(((x0 + x1) / 2, (y0 + y1) / 2, -t / 2))
    out = {"table": table.transformed(pose)}
    for name, up, height, (x, y), yaw in OBJECTS:
        mesh = cp.io.read_mesh(real_file(name))
        v = np.asarray(mesh.vertices, dtype=float)
        if up == 1:  # y up -> z up
            v = v @ cp.pose.from_rpy((math.pi / 2, 0.0, 0.0))[:3, :3].T
        lo, hi = v.min(axis=0), v.max(axis=0)
        v = (v - [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]]) * (height / (hi[2] - lo[2]))
        v = v @ cp.pose.from_rpy((0.0, 0.0, yaw))[:3, :3].T + [x, y, 0.0]
        out[name] = cp.Mesh(v, mesh.faces)
    return out


def scan(
    meshes: dict[str, cp.Mesh],
    seed: int,
    scale: float = 1.0,
    camera: tuple[np.ndarray, np.ndarray] = (CAMERA_AT, CAMERA_LOOK),
) -> tuple[cp.PointCloud, float]:
    """Ray-cast the scene from the camera, add Kinect noise.

    ``scale`` multiplies the image size and the focal length (the same view,
    ``scale^2`` as many points); ``camera`` is where the camera is and the point
    it looks at. Returns the cloud and the sensor's resolution: a pixel's
    footprint at the median depth.
    """
    import open3d as o3d

    rc = o3d.t.geometry.RaycastingScene()
    for mesh in meshes.values():
        rc.add_triangles(
            np.asarray(mesh.vertices, dtype=np.float32), np.asarray(mesh.faces, dtype=np.uint32)
        )
    pose = cp.pose.look_at(*camera)  # optical frame: x right, y down, z forward
    width, height, focal = round(WIDTH * scale), round(HEIGHT * scale), FOCAL * scale
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    cam = np.stack(
        [(u - (width - 1) / 2) / focal, (v - (height - 1) / 2) / focal, np.ones(u.shape)], -1
    ).reshape(-1, 3)
    d = cam @ pose[:3, :3].T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    rays = np.hstack([np.broadcast_to(pose[:3, 3], d.shape), d]).astype(np.float32)
    t = rc.cast_rays(o3d.core.Tensor(rays))["t_hit"].numpy().astype(float)
    hit = np.flatnonzero(np.isfinite(t))
    exact = pose[:3, 3] + t[hit, None] * d[hit]
    sensor = kinect_camera(focal)
    cov = np.asarray(sensor.covariances(exact, sensor_pose=pose))
    rng = np.random.default_rng(seed)
    noisy = exact + np.einsum(
        "nij,nj->ni", np.linalg.cholesky(cov), rng.standard_normal(exact.shape)
    )
    cloud = cp.io.CloudFile(
        noisy, sensor_pose=pose, grid_shape=(height, width), pixels=hit.tolist()
    ).to_point_cloud(sensor=sensor)
    depth = (exact - pose[:3, 3]) @ pose[:3, 2]
    return cloud, float(np.median(depth)) / focal


# ---------------------------------------------------------------- python-fcl checkers


class FclChecker:
    """The robot's exact link meshes against fixed collision objects (python-fcl managers)."""

    def __init__(self, robot: cp.Robot, objects: list[Any]) -> None:
        import fcl

        self.robot = robot
        self.links, self.robot_manager = fcl_robot(robot)
        self.scene = fcl.DynamicAABBTreeCollisionManager()
        self.scene.registerObjects(objects)
        self.scene.setup()
        self.objects = objects

    def pose(self, q: np.ndarray) -> None:
        """Move the link objects to configuration ``q``."""
        import fcl

        poses = self.robot.link_poses(q)
        for name, obj in self.links.items():
            p = poses[name]
            obj.setTransform(fcl.Transform(p[:3, :3], p[:3, 3]))
        self.robot_manager.update()

    def collides(self, q: np.ndarray) -> bool:
        """Whether some link meets some object at ``q``."""
        import fcl

        self.pose(q)
        data = fcl.CollisionData()
        self.robot_manager.collide(self.scene, data, fcl.defaultCollisionCallback)
        return bool(data.result.is_collision)

    def collide_call(self) -> bool:
        """Whether the links, as posed last, meet some object (the python-fcl call alone)."""
        import fcl

        data = fcl.CollisionData()
        self.robot_manager.collide(self.scene, data, fcl.defaultCollisionCallback)
        return bool(data.result.is_collision)

    def contacts(self, q: np.ndarray) -> np.ndarray:
        """Contact points ``(k, 3)`` of the links with the objects at ``q`` (python-fcl)."""
        import fcl

        self.pose(q)
        out = []
        for obj in self.links.values():
            for other in self.objects:
                r = fcl.CollisionResult()
                fcl.collide(
                    obj, other, fcl.CollisionRequest(num_max_contacts=16, enable_contact=True), r
                )
                out.extend(c.pos for c in r.contacts)
        return np.array(out, dtype=float).reshape(-1, 3)

    def distance(self, q: np.ndarray) -> float:
        """Smallest distance of a link to an object at ``q`` (<= 0 in contact)."""
        import fcl

        self.pose(q)
        data = fcl.DistanceData()
        self.robot_manager.distance(self.scene, data, fcl.defaultDistanceCallback)
        return float(data.result.min_distance)

    def clearance(self, q: np.ndarray) -> tuple[float, str]:
        """Smallest distance of a link to an object at ``q`` (0 in contact), and that link."""
        import fcl

        self.pose(q)
        best, link = math.inf, ""
        for name, obj in self.links.items():
            for other in self.objects:
                r = fcl.DistanceResult()
                d = fcl.distance(obj, other, fcl.DistanceRequest(), r)
                if d < best:
                    best, link = max(d, 0.0), name
        return best, link

    def state_valid(self, q: np.ndarray) -> bool:
        """Free of the objects and of self-collision."""
        return not self.collides(q) and not self.robot.self_collisions(q)


def motion_states(q0: np.ndarray, q1: np.ndarray, resolution: float) -> np.ndarray:
    """Return the states inside ``q0 -> q1`` (bisection order), link travel below ``resolution``.

    A link point at most ``REACH`` from each joint axis above it moves at most
    ``sum |dq_j| REACH`` along the motion (prismatic travel counted alike).
    """
    n = max(1, math.ceil(float(np.abs(q1 - q0).sum()) * REACH / resolution))
    order, seen = [], set()
    k = 1
    while len(order) < n - 1:
        k *= 2
        for i in range(1, k, 2):
            j = round(i * n / k)
            if 0 < j < n and j not in seen:
                seen.add(j)
                order.append(j)
    for j in range(1, n):  # any the bisection rounding skipped
        if j not in seen:
            order.append(j)
    return q0 + (np.array(order, dtype=float)[:, None] / n) * (q1 - q0)


def discrete_motion(state_valid: Callable[[np.ndarray], bool], resolution: float) -> Callable:
    """Return a motion check by states ``resolution`` of link travel apart, early exit."""

    def valid(q0: np.ndarray, q1: np.ndarray) -> bool:
        return all(state_valid(q) for q in motion_states(q0, q1, resolution))

    return valid


def voxel_boxes(points: np.ndarray, size: float) -> list[Any]:
    """Return the occupied voxels of side ``size`` as python-fcl boxes (the collision map)."""
    import fcl

    keys = np.unique(np.floor(points / size).astype(np.int64), axis=0)
    centres = (keys + 0.5) * size
    return [fcl.CollisionObject(fcl.Box(size, size, size), fcl.Transform(c)) for c in centres]


# ---------------------------------------------------------------- the run


def fcl_object(mesh: cp.Mesh) -> Any:
    """Return a python-fcl collision object of a mesh, at the identity."""
    import fcl

    return fcl.CollisionObject(fcl_mesh(mesh), fcl.Transform())


def log(message: str) -> None:
    """Progress on standard error."""
    print(message, file=sys.stderr, flush=True)
