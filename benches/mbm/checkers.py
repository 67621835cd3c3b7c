"""Collision checkers beside cloudprox's: exact primitives and a voxel map (python-fcl).

* :class:`FclChecker`: the robot's exact link meshes (``cloudprox.Robot.link_mesh``:
  the URDF's collision meshes, as python-fcl BVH models, posed by
  ``Robot.link_poses``) against fixed collision objects in one
  ``DynamicAABBTreeCollisionManager``. With the scene's primitives
  (:meth:`mbm.scene.Primitive.fcl_object`: exact ``fcl.Box``, ``Cylinder``,
  ``Sphere``) it is the exact checker, the ground truth no robot has; with
  :func:`voxel_boxes` of a sensor cloud it is the boolean collision map a ROS
  stack builds (each occupied voxel a box).
* Self-collision is the same for every checker: ``Robot.self_collisions``
  (cloudprox's exact link meshes, its own pair list), as
  :class:`cloudprox.planning.ChanceConstraint` checks it, or that with the
  pairs a scene's allowed-collision matrix allows left out
  (:func:`self_collision_check`).
* :class:`MotionBound` and :func:`discrete_motion`: a straight joint-space
  motion is checked at states so close that no link point moves more than
  ``resolution`` between two, with the bound cloudprox's ``check_motion`` uses
  (per link, the sum over the joints above it of ``|dq_j| r_j``, ``r_j`` the
  largest distance of any geometry below joint ``j`` from its origin; 1 per
  metre of a prismatic joint), read from the URDF. The states are checked as
  OMPL's ``DiscreteMotionValidator`` does: the end state first, then the inside
  ones in bisection order, the start (already valid) not again.
"""

from __future__ import annotations

import itertools
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

import cloudprox as cp

__all__ = [
    "DiscreteMotion",
    "FclChecker",
    "MotionBound",
    "bisection_order",
    "dense_states",
    "discrete_motion",
    "fcl_mesh",
    "fcl_robot",
    "first_collision",
    "self_collision_check",
    "voxel_boxes",
    "voxel_centres",
]

FloatArray = npt.NDArray[np.float64]
StateCheck = Callable[[FloatArray], bool]


def self_collision_check(
    robot: cp.Robot, allowed: Collection[frozenset[str]] = frozenset()
) -> StateCheck:
    """Return ``q -> no self-collision``: ``Robot.self_collisions`` but the ``allowed`` pairs.

    Parameters
    ----------
    robot : cloudprox.Robot
        The robot.
    allowed : collection of frozenset of str
        Link pairs that may touch (an allowed-collision matrix's).

    Returns
    -------
    callable
        ``check(q) -> bool``, ``True`` when no reported pair is outside ``allowed``.
    """
    if not allowed:
        return lambda q: not robot.self_collisions(q)
    pairs = frozenset(allowed)
    return lambda q: all(frozenset(p) in pairs for p in robot.self_collisions(q))


def fcl_mesh(mesh: cp.Mesh) -> Any:
    """Return a python-fcl BVH model (OBBRSS) of a mesh."""
    import fcl

    bvh = fcl.BVHModel()
    v = np.asarray(mesh.vertices, dtype=float)
    f = np.asarray(mesh.faces, dtype=np.int64)
    bvh.beginModel(len(v), len(f))
    bvh.addSubModel(v, f)
    bvh.endModel()
    return bvh


def fcl_robot(robot: cp.Robot) -> tuple[dict[str, Any], Any]:
    """Return the robot's links with meshes as python-fcl objects and their set-up manager."""
    import fcl

    links = {
        n: fcl.CollisionObject(fcl_mesh(m), fcl.Transform())
        for n in robot.link_names
        if (m := robot.link_mesh(n)) is not None
    }
    manager = fcl.DynamicAABBTreeCollisionManager()
    manager.registerObjects(list(links.values()))
    manager.setup()
    return links, manager


class FclChecker:
    """The robot's exact link meshes against fixed python-fcl collision objects.

    Parameters
    ----------
    robot : cloudprox.Robot
        The robot (its link meshes and kinematics).
    objects : sequence
        python-fcl ``CollisionObject`` s, world frame.
    names : sequence of str, optional
        A name per object (for :meth:`nearest`).
    base_pose : array_like, shape (4, 4), optional
        Pose of the robot's root link.
    allowed : collection of frozenset of str, optional
        Link pairs whose contact is not a self-collision (an allowed-collision
        matrix); by default every pair ``Robot.self_collisions`` reports counts.
    """

    def __init__(
        self,
        robot: cp.Robot,
        objects: Sequence[Any],
        names: Sequence[str] | None = None,
        base_pose: npt.ArrayLike | None = None,
        allowed: Collection[frozenset[str]] = frozenset(),
    ) -> None:
        import fcl

        self.robot = robot
        self.self_free = self_collision_check(robot, allowed)
        self.base_pose = None if base_pose is None else np.asarray(base_pose, dtype=float)
        self.links, self.robot_manager = fcl_robot(robot)
        self.objects = list(objects)
        self.names = list(names) if names is not None else [str(i) for i in range(len(objects))]
        self.scene = fcl.DynamicAABBTreeCollisionManager()
        self.scene.registerObjects(self.objects)
        self.scene.setup()
        self.calls = 0

    def pose(self, q: npt.ArrayLike) -> None:
        """Move the link objects to configuration ``q``."""
        import fcl

        poses = self.robot.link_poses(q, self.base_pose)
        for name, obj in self.links.items():
            p = poses[name]
            obj.setTransform(fcl.Transform(p[:3, :3], p[:3, 3]))
        self.robot_manager.update()

    def collides(self, q: npt.ArrayLike) -> bool:
        """Whether some link meets some object at ``q`` (self-collision not included)."""
        import fcl

        self.calls += 1
        self.pose(q)
        data = fcl.CollisionData()
        self.robot_manager.collide(self.scene, data, fcl.defaultCollisionCallback)
        return bool(data.result.is_collision)

    def state_valid(self, q: npt.ArrayLike) -> bool:
        """Free of the objects and of self-collision (:func:`self_collision_check`)."""
        return not self.collides(q) and self.self_free(np.asarray(q, dtype=float))

    def distance(self, q: npt.ArrayLike) -> float:
        """Smallest distance of a link to an object at ``q`` (python-fcl; not signed in contact)."""
        import fcl

        self.pose(q)
        data = fcl.DistanceData()
        self.robot_manager.distance(self.scene, data, fcl.defaultDistanceCallback)
        return float(data.result.min_distance)

    def nearest(self, q: npt.ArrayLike) -> tuple[float, str, str]:
        """Smallest distance of a link to an object at ``q`` (0 in contact), its link and object."""
        import fcl

        self.pose(q)
        best, link, obj = math.inf, "", ""
        for name, lo in self.links.items():
            for other, oname in zip(self.objects, self.names, strict=True):
                r = fcl.DistanceResult()
                d = fcl.distance(lo, other, fcl.DistanceRequest(), r)
                if d < best:
                    best, link, obj = max(float(d), 0.0), name, oname
        return best, link, obj

    def contacts(self, q: npt.ArrayLike) -> FloatArray:
        """Contact points ``(k, 3)`` of the links with the objects at ``q`` (python-fcl)."""
        import fcl

        self.pose(q)
        request = fcl.CollisionRequest(num_max_contacts=16, enable_contact=True)
        out: list[Any] = []
        for lo in self.links.values():
            for other in self.objects:
                r = fcl.CollisionResult()
                fcl.collide(lo, other, request, r)
                out.extend(c.pos for c in r.contacts)
        return np.array(out, dtype=np.float64).reshape(-1, 3)

    def colliding_pairs(self, q: npt.ArrayLike) -> list[tuple[str, str]]:
        """(link, object) pairs in contact at ``q``."""
        import fcl

        self.pose(q)
        out = []
        for name, lo in self.links.items():
            for other, oname in zip(self.objects, self.names, strict=True):
                r = fcl.CollisionResult()
                if fcl.collide(lo, other, fcl.CollisionRequest(), r):
                    out.append((name, oname))
        return out


def voxel_centres(points: npt.ArrayLike, size: float) -> FloatArray:
    """Centres of the occupied voxels of side ``size`` (a grid through the origin)."""
    keys = np.unique(np.floor(np.asarray(points, dtype=float) / size).astype(np.int64), axis=0)
    return np.asarray((keys + 0.5) * size, dtype=np.float64)


def voxel_boxes(points: npt.ArrayLike, size: float) -> list[Any]:
    """Return the occupied voxels of side ``size`` as python-fcl boxes (the collision map)."""
    import fcl

    return [
        fcl.CollisionObject(fcl.Box(size, size, size), fcl.Transform(c))
        for c in voxel_centres(points, size)
    ]


# ----------------------------------------------------------------- motions


@dataclass(frozen=True)
class _Joint:
    name: str
    kind: str
    parent: str
    child: str
    offset: float
    lower: float
    upper: float
    mimic: tuple[str, float] | None


def _urdf_joints(urdf: Path) -> list[_Joint]:
    root = ET.parse(urdf).getroot()
    out = []
    for j in root.iter("joint"):
        origin = j.find("origin")
        xyz = [0.0, 0.0, 0.0]
        if origin is not None and origin.get("xyz"):
            xyz = [float(v) for v in str(origin.get("xyz")).split()]
        limit = j.find("limit")
        lower = float(limit.get("lower", 0.0)) if limit is not None else 0.0
        upper = float(limit.get("upper", 0.0)) if limit is not None else 0.0
        mimic_el = j.find("mimic")
        mimic = None
        if mimic_el is not None:
            mimic = (str(mimic_el.get("joint")), float(mimic_el.get("multiplier", 1.0)))
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            raise ValueError(f"{urdf}: joint {j.get('name')} lacks its parent or child")
        out.append(
            _Joint(
                str(j.get("name")),
                str(j.get("type")),
                str(parent.get("link")),
                str(child.get("link")),
                float(np.linalg.norm(xyz)),
                lower,
                upper,
                mimic,
            )
        )
    return out


class MotionBound:
    """The largest travel of any link point along a straight joint-space motion (upper bound).

    Built from the URDF's tree and the robot's link meshes as cloudprox's
    ``Robot::displacement_bound`` (see the module), so both checkers divide a
    motion into the same states.

    Parameters
    ----------
    robot : cloudprox.Robot
        The robot (its joint order and link meshes).
    urdf : Path
        The robot's URDF (the tree and the joint origins).
    """

    def __init__(self, robot: cp.Robot, urdf: Path) -> None:
        joints = _urdf_joints(Path(urdf))
        dof = {n: i for i, n in enumerate(robot.joint_names)}
        radius = {
            n: float(np.max(np.linalg.norm(np.asarray(m.vertices), axis=1)))
            for n in robot.link_names
            if (m := robot.link_mesh(n)) is not None
        }
        children: dict[str, list[_Joint]] = {}
        parent_of: dict[str, _Joint] = {}
        for j in joints:
            children.setdefault(j.parent, []).append(j)
            parent_of[j.child] = j
        by_name = {j.name: j for j in joints}
        reach: dict[str, float] = {}

        def subtree(link: str) -> float:
            if link not in reach:
                r = radius.get(link, 0.0)
                for j in children.get(link, []):
                    travel = max(abs(j.lower), abs(j.upper)) if j.kind == "prismatic" else 0.0
                    r = max(r, j.offset + travel + subtree(j.child))
                reach[link] = r
            return reach[link]

        self.weights: dict[str, list[tuple[int, float]]] = {}
        for link in radius:
            w: list[tuple[int, float]] = []
            cur = link
            while cur in parent_of:
                j = parent_of[cur]
                per_unit = {"revolute": subtree(j.child), "continuous": subtree(j.child)}.get(
                    j.kind, 1.0 if j.kind == "prismatic" else 0.0
                )
                if per_unit > 0.0:
                    if j.name in dof:
                        w.append((dof[j.name], per_unit))
                    elif j.mimic is not None and j.mimic[0] in dof:
                        master = by_name.get(j.mimic[0])
                        if master is not None:
                            w.append((dof[j.mimic[0]], per_unit * abs(j.mimic[1])))
                cur = j.parent
            self.weights[link] = w

    def travel(self, q0: npt.ArrayLike, q1: npt.ArrayLike) -> float:
        """Upper bound (m) on how far a link point moves from ``q0`` to ``q1``."""
        dq = np.abs(np.asarray(q1, dtype=float) - np.asarray(q0, dtype=float))
        return max((sum(r * dq[d] for d, r in w) for w in self.weights.values()), default=0.0)

    def steps(self, q0: npt.ArrayLike, q1: npt.ArrayLike, resolution: float) -> int:
        """Segments of the motion so that no link point moves more than ``resolution`` in one."""
        return max(1, math.ceil(self.travel(q0, q1) / resolution))


def bisection_order(n: int) -> list[int]:
    """Return the inside states ``1 .. n-1`` of ``n`` segments in bisection order."""
    order: list[int] = []
    queue = [(1, n - 1)]
    while queue:
        nxt = []
        for lo, hi in queue:
            if lo > hi:
                continue
            mid = (lo + hi) // 2
            order.append(mid)
            nxt += [(lo, mid - 1), (mid + 1, hi)]
        queue = nxt
    return order


class DiscreteMotion:
    """A motion check: the end state, then the inside states by bisection; early exit.

    Parameters
    ----------
    state_valid : callable
        ``state_valid(q) -> bool``.
    bound : MotionBound
        The robot's displacement bound.
    resolution : float
        Largest link-point travel (m) between two checked states.

    Attributes
    ----------
    states : int
        States checked so far.
    """

    def __init__(self, state_valid: StateCheck, bound: MotionBound, resolution: float) -> None:
        self.state_valid = state_valid
        self.bound = bound
        self.resolution = resolution
        self.states = 0

    def __call__(self, q0: FloatArray, q1: FloatArray) -> bool:
        """Whether every checked state of the straight motion ``q0 -> q1`` is valid."""
        n = self.bound.steps(q0, q1, self.resolution)
        self.states += 1
        if not self.state_valid(q1):
            return False
        for i in bisection_order(n):
            self.states += 1
            if not self.state_valid(q0 + (i / n) * (q1 - q0)):
                return False
        return True


def discrete_motion(
    state_valid: StateCheck, bound: MotionBound, resolution: float
) -> DiscreteMotion:
    """Return the :class:`DiscreteMotion` check of ``state_valid`` at ``resolution``."""
    return DiscreteMotion(state_valid, bound, resolution)


def first_collision(
    checker: FclChecker, bound: MotionBound, path: FloatArray, resolution: float
) -> tuple[int, float, int] | None:
    """Where a path first meets the checker's objects, checked to ``resolution`` of link travel.

    Conservative advancement along each segment: at a free state whose
    clearance is ``d`` (python-fcl distance), no link point can reach an
    object before it has travelled ``d`` (:class:`MotionBound` bounds the
    travel), so the next state checked is ``max(d, resolution)`` of travel on.
    A collision is missed only where it is shorter than ``resolution``, as with
    states ``resolution`` apart, at a fraction of their checks.

    Returns
    -------
    tuple of (int, float, int) or None
        ``(segment, t, checks)`` of the first colliding state (``t`` in ``[0, 1]``
        along the segment, ``checks`` the states checked so far), or ``None``
        when the path is free.
    """
    checks = 0
    for k, (a, b) in enumerate(itertools.pairwise(path)):
        travel = bound.travel(a, b)
        t = 0.0
        while True:
            q = a + t * (b - a)
            checks += 1
            if checker.collides(q):
                return k, t, checks
            if t >= 1.0:
                break
            d = checker.distance(q)
            step = max(d, resolution) / travel if travel > 0 else 1.0
            t = min(1.0, t + step)
    return None


def dense_states(path: FloatArray, bound: MotionBound, resolution: float) -> FloatArray:
    """Every state along a path's segments, ``resolution`` of link travel apart, ends included."""
    out = [path[:1]]
    for a, b in itertools.pairwise(path):
        n = bound.steps(a, b, resolution)
        t = np.arange(1, n + 1, dtype=float)[:, None] / n
        out.append(a + t * (b - a))
    return np.concatenate(out)
