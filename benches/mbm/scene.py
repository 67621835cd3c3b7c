"""MotionBenchMaker problems: MoveIt planning scenes of primitives, start and goal states.

``problems.tar.bz2`` holds, per scenario (``problems/<scenario>_<robot>/``),
``sceneNNNN.yaml`` (a ``moveit_msgs/PlanningScene``) and ``requestNNNN.yaml``
(a ``moveit_msgs/MotionPlanRequest``) with the same number: one problem.

A scene's ``world.collision_objects`` are solid primitives, each with an
``id``, ``primitives`` (``type`` box, cylinder or sphere and ``dimensions``:
a box's three side lengths, a cylinder's height and radius with its axis along
its own z, a sphere's radius), ``primitive_poses`` (``position`` and
``orientation`` as a quaternion ``x, y, z, w``) and optionally an object
``pose`` that the primitive poses are relative to. Its
``allowed_collision_matrix`` (``entry_names``, ``entry_values``) names the
robot link pairs that may touch (self-collision). A request's
``start_state.joint_state`` gives the start (``name``, ``position``; the
names may be absent, the order then the robot's) and its first
``goal_constraints`` entry's ``joint_constraints`` the goal by joint name;
joints of the request that the robot model does not move (the Panda's fixed
fingers, the Fetch's wheels and head) are dropped, and a robot joint the
goal leaves out keeps its start value.

:class:`Primitive` answers what the benchmark asks of a solid: its surface
area and uniform surface samples, an inside test, analytic ray intersection
(the simulated camera), and its python-fcl collision object (the exact
checker).
"""

from __future__ import annotations

import bz2
import gzip
import io
import math
import re
import tarfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

__all__ = [
    "Kind",
    "Primitive",
    "Problem",
    "Scene",
    "load_problems",
    "parse_pose",
    "parse_request",
    "parse_scene",
    "problem_files",
]

FloatArray = npt.NDArray[np.float64]
Kind = Literal["box", "cylinder", "sphere"]
#: Tolerance (m) of the inside test: points this close to a surface are not inside.
INSIDE_TOLERANCE = 1e-9


def _yaml_load(text: str | bytes) -> Any:
    import yaml

    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    return yaml.load(text, Loader=loader)  # a safe loader


def _quaternion_xyzw(q: Sequence[float]) -> FloatArray:
    x, y, z, w = (float(v) for v in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not (n > 0.0 and math.isfinite(n)):
        raise ValueError(f"degenerate quaternion {list(q)}")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def parse_pose(data: Mapping[str, Any] | None) -> FloatArray:
    """Return the ``(4, 4)`` pose of a ``geometry_msgs/Pose`` mapping (identity if ``None``).

    Parameters
    ----------
    data : mapping or None
        ``position`` (three numbers, default zero) and ``orientation`` (a
        quaternion ``x, y, z, w``, default the identity; normalised).

    Returns
    -------
    numpy.ndarray
        The pose, shape ``(4, 4)``.
    """
    pose = np.eye(4)
    if data is None:
        return pose
    pose[:3, :3] = _quaternion_xyzw(data.get("orientation", (0.0, 0.0, 0.0, 1.0)))
    pose[:3, 3] = np.asarray(data.get("position", (0.0, 0.0, 0.0)), dtype=float)
    return pose


@dataclass(frozen=True, eq=False)
class Primitive:
    """One solid primitive of a scene, in the world frame.

    Parameters
    ----------
    name : str
        The collision object's ``id`` (``id/k`` for its k-th primitive when it has several).
    kind : {"box", "cylinder", "sphere"}
        The shape.
    dimensions : tuple of float
        As MoveIt's ``shape_msgs/SolidPrimitive``: a box's side lengths ``(x, y,
        z)``, a cylinder's ``(height, radius)`` (axis along its z, centred), a
        sphere's ``(radius,)``.
    pose : numpy.ndarray
        Pose of the primitive's centre frame in the world, shape ``(4, 4)``.
    """

    name: str
    kind: Kind
    dimensions: tuple[float, ...]
    pose: FloatArray = field(repr=False)

    def __post_init__(self) -> None:
        """Check the dimensions' count and sign."""
        need = {"box": 3, "cylinder": 2, "sphere": 1}.get(self.kind)
        if need is None:
            raise ValueError(f"{self.name}: unknown primitive type {self.kind!r}")
        if len(self.dimensions) < need:
            raise ValueError(
                f"{self.name}: a {self.kind} needs {need} dimensions, got {list(self.dimensions)}"
            )
        if not all(math.isfinite(d) and d > 0 for d in self.dimensions[:need]):
            raise ValueError(f"{self.name}: dimensions must be positive, got {self.dimensions}")

    # ---------------------------------------------------------------- geometry

    @property
    def half_extents(self) -> FloatArray:
        """Half the side lengths of the primitive's own bounding box (its frame)."""
        d = self.dimensions
        if self.kind == "box":
            return np.array(d[:3], dtype=float) / 2
        if self.kind == "cylinder":
            return np.array([d[1], d[1], d[0] / 2])
        return np.full(3, d[0])

    @property
    def area(self) -> float:
        """Surface area (m^2)."""
        d = self.dimensions
        if self.kind == "box":
            return 2.0 * (d[0] * d[1] + d[1] * d[2] + d[0] * d[2])
        if self.kind == "cylinder":
            h, r = d[0], d[1]
            return 2.0 * math.pi * r * h + 2.0 * math.pi * r * r
        return 4.0 * math.pi * d[0] ** 2

    def bounds(self) -> tuple[FloatArray, FloatArray]:
        """World axis-aligned bounds ``(lo, hi)`` of the primitive's own box."""
        r, t = self.pose[:3, :3], self.pose[:3, 3]
        reach = np.abs(r) @ self.half_extents
        return t - reach, t + reach

    def to_local(self, points: npt.ArrayLike) -> FloatArray:
        """Express world points ``(n, 3)`` in the primitive's frame."""
        p = np.asarray(points, dtype=float)
        return (p - self.pose[:3, 3]) @ self.pose[:3, :3]

    def to_world(self, points: npt.ArrayLike) -> FloatArray:
        """Express points ``(n, 3)`` of the primitive's frame in the world."""
        p = np.asarray(points, dtype=float)
        return p @ self.pose[:3, :3].T + self.pose[:3, 3]

    def contains(self, points: npt.ArrayLike, tolerance: float = INSIDE_TOLERANCE) -> np.ndarray:
        """Whether each world point is strictly inside (deeper than ``tolerance``)."""
        p = self.to_local(points)
        d = self.dimensions
        if self.kind == "box":
            return np.all(np.abs(p) < np.array(d[:3]) / 2 - tolerance, axis=1)
        if self.kind == "cylinder":
            radial = np.hypot(p[:, 0], p[:, 1])
            return (radial < d[1] - tolerance) & (np.abs(p[:, 2]) < d[0] / 2 - tolerance)
        return np.linalg.norm(p, axis=1) < d[0] - tolerance

    def signed_distance(self, points: npt.ArrayLike) -> FloatArray:
        """Exact signed distance of world points to the surface (negative inside)."""
        p = self.to_local(points)
        d = self.dimensions
        if self.kind == "sphere":
            return np.linalg.norm(p, axis=1) - d[0]
        if self.kind == "box":
            q = np.abs(p) - np.array(d[:3]) / 2
        else:
            q = np.stack([np.hypot(p[:, 0], p[:, 1]) - d[1], np.abs(p[:, 2]) - d[0] / 2], 1)
        outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
        inside = np.minimum(q.max(axis=1), 0.0)
        return outside + inside

    def sample_surface(self, n: int, rng: np.random.Generator) -> FloatArray:
        """``n`` points uniformly distributed over the surface (by area), world frame."""
        d = self.dimensions
        if n <= 0:
            return np.empty((0, 3))
        if self.kind == "box":
            h = np.array(d[:3]) / 2
            faces = np.array([h[1] * h[2], h[0] * h[2], h[0] * h[1]])
            axis = rng.choice(3, size=n, p=faces / faces.sum())
            p = rng.uniform(-1.0, 1.0, (n, 3)) * h
            sign = rng.choice((-1.0, 1.0), size=n)
            p[np.arange(n), axis] = sign * h[axis]
        elif self.kind == "cylinder":
            height, r = d[0], d[1]
            side = rng.random(n) < (height / (height + r))  # 2 pi r h against 2 pi r^2
            p = np.empty((n, 3))
            phi = rng.uniform(0.0, 2.0 * math.pi, n)
            rad = np.where(side, r, r * np.sqrt(rng.random(n)))
            p[:, 0], p[:, 1] = rad * np.cos(phi), rad * np.sin(phi)
            cap = rng.choice((-height / 2, height / 2), size=n)
            p[:, 2] = np.where(side, rng.uniform(-height / 2, height / 2, n), cap)
        else:
            v = rng.standard_normal((n, 3))
            p = d[0] * v / np.linalg.norm(v, axis=1, keepdims=True)
        return self.to_world(p)

    def ray_distances(self, origin: npt.ArrayLike, directions: npt.ArrayLike) -> FloatArray:
        """Distance along each ray ``origin + t d`` (``d`` unit, world) to its first hit, or inf.

        Rays starting inside the solid report ``inf`` (a camera is never inside one).
        """
        o = self.to_local(np.asarray(origin, dtype=float).reshape(1, 3))[0]
        dv = np.asarray(directions, dtype=float) @ self.pose[:3, :3]
        d = self.dimensions
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.kind == "box":
                h = np.array(d[:3]) / 2
                t1 = (-h - o) / dv
                t2 = (h - o) / dv
                near = np.nanmax(np.minimum(t1, t2), axis=1)
                far = np.nanmin(np.maximum(t1, t2), axis=1)
                hit = (near <= far) & (near > 0.0)
                return np.where(hit, near, np.inf)
            if self.kind == "sphere":
                return _sphere_hits(o, dv, d[0])
            return _cylinder_hits(o, dv, d[0], d[1])

    def fcl_object(self) -> Any:
        """Return the primitive as a python-fcl object (``fcl.Box``, ``Cylinder``, ``Sphere``)."""
        import fcl

        d = self.dimensions
        if self.kind == "box":
            geom = fcl.Box(*d[:3])
        elif self.kind == "cylinder":
            geom = fcl.Cylinder(d[1], d[0])
        else:
            geom = fcl.Sphere(d[0])
        return fcl.CollisionObject(geom, fcl.Transform(self.pose[:3, :3], self.pose[:3, 3]))


def _sphere_hits(o: FloatArray, dv: FloatArray, r: float) -> FloatArray:
    b = dv @ o
    c = float(o @ o) - r * r
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t = -b - root
    return np.where((disc >= 0.0) & (t > 0.0) & (c > 0.0), t, np.inf)


def _cylinder_hits(o: FloatArray, dv: FloatArray, height: float, r: float) -> FloatArray:
    half = height / 2
    best = np.full(len(dv), np.inf)
    # side: (o + t d)_xy on the circle, |z| <= half
    a = dv[:, 0] ** 2 + dv[:, 1] ** 2
    b = o[0] * dv[:, 0] + o[1] * dv[:, 1]
    c = o[0] ** 2 + o[1] ** 2 - r * r
    disc = b * b - a * c
    ok = (a > 1e-15) & (disc >= 0.0)
    t = np.where(ok, (-b - np.sqrt(np.maximum(disc, 0.0))) / np.where(ok, a, 1.0), np.inf)
    z = o[2] + t * dv[:, 2]
    side = ok & (t > 0.0) & (np.abs(z) <= half)
    best = np.where(side, t, best)
    # caps: z = +-half, within the radius
    for zc in (-half, half):
        with np.errstate(divide="ignore", invalid="ignore"):
            tc = (zc - o[2]) / dv[:, 2]
        x = o[0] + tc * dv[:, 0]
        y = o[1] + tc * dv[:, 1]
        cap = np.isfinite(tc) & (tc > 0.0) & (x * x + y * y <= r * r)
        best = np.where(cap & (tc < best), tc, best)
    inside = (c < 0.0) and abs(o[2]) < half
    return np.full(len(dv), np.inf) if inside else best


@dataclass(eq=False)
class Scene:
    """A planning scene: primitives in the world frame (the robot's root at the origin).

    Attributes
    ----------
    scenario : str
        The scenario (``"bookshelf_small"``, ...).
    index : int
        The problem number within the scenario.
    objects : list of Primitive
        The solids.
    acm_names : list of str
        Link names of the allowed-collision matrix (empty when it has none).
    allowed : frozenset of frozenset of str
        Link pairs the matrix allows to touch (self-collision not checked).
    """

    scenario: str
    index: int
    objects: list[Primitive]
    acm_names: list[str] = field(default_factory=list)
    allowed: frozenset[frozenset[str]] = frozenset()

    def bounds(self) -> tuple[FloatArray, FloatArray]:
        """World axis-aligned bounds ``(lo, hi)`` of every primitive."""
        if not self.objects:
            return np.zeros(3), np.zeros(3)
        lo, hi = zip(*(o.bounds() for o in self.objects), strict=True)
        return np.min(lo, axis=0), np.max(hi, axis=0)

    @property
    def area(self) -> float:
        """Total surface area of the primitives (m^2), overlaps counted twice."""
        return float(sum(o.area for o in self.objects))

    def contains(self, points: npt.ArrayLike, skip: int | None = None) -> np.ndarray:
        """Whether each world point is strictly inside some primitive (but ``objects[skip]``)."""
        p = np.asarray(points, dtype=float)
        inside = np.zeros(len(p), dtype=bool)
        for i, o in enumerate(self.objects):
            if i != skip:
                inside |= o.contains(p)
        return inside

    def signed_distance(self, points: npt.ArrayLike) -> FloatArray:
        """Smallest signed distance of each world point to a primitive's surface."""
        p = np.asarray(points, dtype=float)
        out = np.full(len(p), np.inf)
        for o in self.objects:
            out = np.minimum(out, o.signed_distance(p))
        return out

    def ray_distances(self, origin: npt.ArrayLike, directions: npt.ArrayLike) -> FloatArray:
        """First hit of each ray over the primitives (``inf`` when none)."""
        d = np.asarray(directions, dtype=float)
        out = np.full(len(d), np.inf)
        for o in self.objects:
            out = np.minimum(out, o.ray_distances(origin, d))
        return out

    def allows(self, a: str, b: str) -> bool:
        """Whether the allowed-collision matrix lets links ``a`` and ``b`` touch."""
        return frozenset((a, b)) in self.allowed


def parse_scene(data: Mapping[str, Any], scenario: str = "", index: int = 0) -> Scene:
    """Return the :class:`Scene` of a MoveIt ``PlanningScene`` mapping.

    Parameters
    ----------
    data : mapping
        The parsed YAML (``world.collision_objects``, optionally
        ``allowed_collision_matrix``).
    scenario : str
        The scenario's name, kept on the scene.
    index : int
        The problem number, kept on the scene.

    Returns
    -------
    Scene
        Its primitives and allowed pairs.

    Raises
    ------
    ValueError
        On a primitive type other than box, cylinder and sphere, a mesh or
        plane object (MBM's scenes have none), or primitives and poses of
        different counts.
    """
    objects: list[Primitive] = []
    world = data.get("world") or {}
    for co in world.get("collision_objects") or []:
        name = str(co.get("id", f"object{len(objects)}"))
        for unsupported in ("meshes", "planes"):
            if co.get(unsupported):
                raise ValueError(f"{name}: collision object {unsupported} are not supported")
        base = parse_pose(co.get("pose"))
        prims = co.get("primitives") or []
        poses = co.get("primitive_poses") or []
        if len(prims) != len(poses):
            raise ValueError(f"{name}: {len(prims)} primitives but {len(poses)} primitive poses")
        for k, (prim, pose) in enumerate(zip(prims, poses, strict=True)):
            kind = str(prim.get("type", "")).lower()
            if kind not in ("box", "cylinder", "sphere"):
                raise ValueError(f"{name}: unsupported primitive type {prim.get('type')!r}")
            dims = tuple(float(v) for v in prim.get("dimensions") or ())
            label = name if len(prims) == 1 else f"{name}/{k}"
            objects.append(Primitive(label, kind, dims, base @ parse_pose(pose)))  # type: ignore[arg-type]
    acm = data.get("allowed_collision_matrix") or {}
    names = [str(n) for n in acm.get("entry_names") or []]
    values = acm.get("entry_values") or []
    allowed: set[frozenset[str]] = set()
    if len(values) != len(names):
        raise ValueError(
            f"allowed_collision_matrix: {len(names)} names but {len(values)} rows of values"
        )
    for i, row in enumerate(values):
        if row is None or len(row) != len(names):
            raise ValueError(f"allowed_collision_matrix: row {i} has not {len(names)} values")
        for j, v in enumerate(row):
            if v and i != j:
                allowed.add(frozenset((names[i], names[j])))
    return Scene(scenario, index, objects, names, frozenset(allowed))


def parse_request(
    data: Mapping[str, Any], joint_names: Sequence[str]
) -> tuple[FloatArray, FloatArray, list[str]]:
    """Return the start and goal of a MoveIt ``MotionPlanRequest`` mapping.

    Parameters
    ----------
    data : mapping
        The parsed YAML (``start_state.joint_state``, ``goal_constraints``).
    joint_names : sequence of str
        The robot model's joints, in configuration order.

    Returns
    -------
    start, goal : numpy.ndarray
        Configurations in the order of ``joint_names``.
    dropped : list of str
        Joints of the request that are not in ``joint_names`` (ignored).

    Raises
    ------
    ValueError
        If there is no goal constraint, the start leaves out one of
        ``joint_names``, or its names and positions differ in count.
    """
    js = (data.get("start_state") or {}).get("joint_state") or {}
    positions = [float(v) for v in js.get("position") or []]
    names = [str(n) for n in js.get("name") or []]
    if not names:  # positions in the robot's own order
        names = list(joint_names[: len(positions)])
    if len(names) != len(positions):
        raise ValueError(f"start_state: {len(names)} joint names but {len(positions)} positions")
    start_map = dict(zip(names, positions, strict=True))
    missing = [j for j in joint_names if j not in start_map]
    if missing:
        raise ValueError(f"start_state lacks the robot's joints {missing}")
    goals = data.get("goal_constraints") or []
    if not goals or not goals[0].get("joint_constraints"):
        raise ValueError("the request has no joint goal constraint")
    goal_map = {str(c["joint_name"]): float(c["position"]) for c in goals[0]["joint_constraints"]}
    start = np.array([start_map[j] for j in joint_names])
    goal = np.array([goal_map.get(j, start_map[j]) for j in joint_names])
    known = set(joint_names)
    dropped = sorted({*names, *goal_map} - known)
    return start, goal, dropped


@dataclass(eq=False)
class Problem:
    """One MBM problem: its scene, start and goal.

    Attributes
    ----------
    scenario : str
        The scenario.
    index : int
        The number of its files (``scene0001.yaml`` and ``request0001.yaml``: 1).
    scene : Scene
        The planning scene.
    start, goal : numpy.ndarray
        Configurations, in the robot's joint order.
    dropped_joints : list of str
        Request joints the robot model does not move.
    """

    scenario: str
    index: int
    scene: Scene
    start: FloatArray
    goal: FloatArray
    dropped_joints: list[str] = field(default_factory=list)

    @property
    def name(self) -> str:
        """``scenario/NNNN``."""
        return f"{self.scenario}/{self.index:04d}"


def problem_files(names: Iterable[str], robot: str) -> dict[str, dict[int, dict[str, str]]]:
    """Group archive member names by scenario and problem number.

    Parameters
    ----------
    names : iterable of str
        Member names (``problems/<scenario>_<robot>/sceneNNNN.yaml``, ...).
    robot : str
        The robot suffix of the scenario folders.

    Returns
    -------
    dict
        ``{scenario: {index: {"scene": member, "request": member}}}``, the
        scenarios sorted, and only problems with both files.
    """
    pattern = re.compile(rf"(?:^|/)([^/]+)_{re.escape(robot)}/(scene|request)(\d+)\.ya?ml$")
    found: dict[str, dict[int, dict[str, str]]] = {}
    for name in names:
        m = pattern.search(name)
        if m is None:
            continue
        scenario, kind, number = m.group(1), m.group(2), int(m.group(3))
        found.setdefault(scenario, {}).setdefault(number, {})[kind] = name
    return {s: {i: f for i, f in sorted(found[s].items()) if len(f) == 2} for s in sorted(found)}


def load_problems(
    archive: Path | str | bytes,
    robot: str,
    joint_names: Sequence[str],
    *,
    scenarios: Sequence[str] | None = None,
    per_scenario: int | None = None,
) -> list[Problem]:
    """Read MBM problems from ``problems.tar.bz2``.

    Parameters
    ----------
    archive : path or bytes
        The archive (a path, or its bytes).
    robot : str
        The robot's name (the scenario folders' suffix).
    joint_names : sequence of str
        The robot model's joints (configuration order).
    scenarios : sequence of str, optional
        Keep these scenarios only (all by default); an unknown name raises.
    per_scenario : int, optional
        Keep the first ``per_scenario`` problems (by number) of each scenario.

    Returns
    -------
    list of Problem
        Scenario by scenario (sorted), problems by number.

    Raises
    ------
    ValueError
        If a requested scenario is not in the archive, or a file does not parse.
    """
    # Decompressed once into memory (a few MB): a compressed tar stream is read
    # again from its start whenever a member before the current one is asked for.
    raw = archive if isinstance(archive, bytes) else Path(archive).read_bytes()
    if raw[:3] == b"BZh":
        raw = bz2.decompress(raw)
    elif raw[:2] == b"\x1f\x8b":
        raw = gzip.decompress(raw)
    with tarfile.open(fileobj=io.BytesIO(raw), mode="r:") as tar:
        files = problem_files(tar.getnames(), robot)
        if scenarios is not None:
            unknown = [s for s in scenarios if s not in files]
            if unknown:
                raise ValueError(
                    f"scenarios {unknown} are not in the archive (it has {', '.join(files)})"
                )
            files = {s: files[s] for s in scenarios}
        out: list[Problem] = []
        for scenario, problems in files.items():
            chosen = list(problems.items())
            if per_scenario is not None:
                chosen = chosen[:per_scenario]
            for index, members in chosen:
                texts = {}
                for kind, member in members.items():
                    f = tar.extractfile(member)
                    if f is None:
                        raise ValueError(f"{member} is not a file")
                    texts[kind] = f.read()
                try:
                    scene = parse_scene(_yaml_load(texts["scene"]), scenario, index)
                    start, goal, dropped = parse_request(_yaml_load(texts["request"]), joint_names)
                except (ValueError, KeyError, TypeError) as exc:
                    raise ValueError(f"{scenario}/{index:04d}: {exc}") from exc
                out.append(Problem(scenario, index, scene, start, goal, dropped))
    return out
