"""The scene model of a view: what one view draws, in the world frame.

:func:`collision_scene` makes the :class:`Scene` of a :func:`cloudprox.collide`
result, :func:`robot_scene` that of a :func:`cloudprox.collide_robot` result;
every renderer (:mod:`cloudprox.view.k3d_renderer`,
:mod:`cloudprox.view.plotly_renderer`, :mod:`cloudprox.view.rerun_renderer`)
draws a :class:`Scene`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from cloudprox._native import Mesh, PointCloud
from cloudprox.view._common import SIDE_COLORS

if TYPE_CHECKING:
    from cloudprox._native import CollisionResult, ContactPatch, Robot, RobotCollisionResult

__all__ = [
    "MeshLayer",
    "PointLayer",
    "RegionMark",
    "Scene",
    "collision_scene",
    "robot_scene",
    "separating_surface",
]


@dataclass(frozen=True)
class PointLayer:
    """Points of one side, world frame, with their collision probabilities.

    Attributes
    ----------
    name : str
        The side's name (legend, hover).
    points : ndarray, shape (n, 3), float32
        Positions (metres).
    probabilities : ndarray, shape (n,), float32
        Per-point collision probability.
    color : str
        Colour of the points below the view's ``quiet_below``.
    show_quiet : bool
        Whether the points below ``quiet_below`` are drawn (a mesh side's samples
        are not: the mesh is).
    contact : ndarray of int
        Indices of the points in a contact patch: drawn even when thinned.
    """

    name: str
    points: np.ndarray
    probabilities: np.ndarray
    color: str
    show_quiet: bool = True
    contact: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


@dataclass(frozen=True)
class MeshLayer:
    """A triangle mesh in the world frame: a mesh side, or a robot link.

    ``probability`` (a robot link's) colours it on the probability scale; else it
    is drawn in ``color``.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    color: str
    opacity: float = 1.0
    probability: float | None = None
    hover: str = ""


@dataclass(frozen=True)
class RegionMark:
    """One contact patch: where, which way, how far apart, how probable.

    ``surface`` is the region's separating surface as a small triangle mesh
    ``(vertices, faces)`` around ``point``, or ``None``.
    """

    label: str
    point: np.ndarray
    normal: np.ndarray
    separation: float
    probability: float
    points: tuple[int, int]
    surface: tuple[np.ndarray, np.ndarray] | None = None


@dataclass(frozen=True)
class Scene:
    """Everything one view draws (see :func:`collision_scene`, :func:`robot_scene`)."""

    title: str
    points: list[PointLayer] = field(default_factory=list)
    meshes: list[MeshLayer] = field(default_factory=list)
    regions: list[RegionMark] = field(default_factory=list)
    quiet_below: float = 1e-3

    def extent(self) -> float:
        """Largest side of the box around everything drawn (metres, > 0)."""
        parts = [layer.points for layer in self.points if len(layer.points)]
        parts += [m.vertices for m in self.meshes]
        if not parts:
            return 1.0
        allp = np.concatenate([np.asarray(p, dtype=np.float64) for p in parts])
        return float(np.ptp(allp, axis=0).max()) or 1.0


def _world(points: npt.ArrayLike, pose: npt.ArrayLike | None) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if pose is None:
        return p
    t = np.asarray(pose, dtype=np.float64)
    if t.shape != (4, 4):
        raise ValueError(f"a pose must have shape (4, 4), got {t.shape}")
    return p @ t[:3, :3].T + t[:3, 3]


def separating_surface(
    region: ContactPatch,
    half_size: float,
    resolution: int = 16,
) -> tuple[np.ndarray, np.ndarray]:
    """Mesh the separating surface ``f = 0`` of a region around its ``point``.

    A square grid of side ``2 half_size`` on the tangent plane at ``point`` is
    projected onto ``f = 0`` by Newton steps along the gradient of ``f``; the
    vertices where that does not converge stay on the plane.

    Parameters
    ----------
    region : ContactPatch
        The region.
    half_size : float
        Half the side of the square (metres, > 0).
    resolution : int, default 16
        Grid vertices per side (>= 2).

    Returns
    -------
    vertices : ndarray, shape (resolution**2, 3)
    faces : ndarray of int, shape (2 (resolution - 1)**2, 3)
    """
    if not (math.isfinite(half_size) and half_size > 0.0):
        raise ValueError(f"half_size must be finite and > 0, got {half_size}")
    if resolution < 2:
        raise ValueError(f"resolution must be >= 2, got {resolution}")
    point = np.asarray(region.point, dtype=np.float64)
    normal = np.asarray(region.normal, dtype=np.float64)
    normal = normal / (np.linalg.norm(normal) or 1.0)
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    u = np.linspace(-half_size, half_size, resolution)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    plane = point + uu.reshape(-1, 1) * e1 + vv.reshape(-1, 1) * e2
    x = plane.copy()
    for _ in range(12):
        f, g = region.evaluate(x)
        g2 = np.einsum("ij,ij->i", g, g)
        ok = np.isfinite(f) & (g2 > 0.0)
        step = np.zeros_like(x)
        step[ok] = (f[ok] / g2[ok])[:, None] * g[ok]
        x = x - step
    f, _ = region.evaluate(x)
    bad = (
        ~np.isfinite(f)
        | (np.abs(f) > 1e-6 * half_size)
        | (np.linalg.norm(x - plane, axis=1) > 2.0 * half_size)
    )
    x[bad] = plane[bad]
    idx = np.arange(resolution * resolution).reshape(resolution, resolution)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return x, faces


def _surface_half_size(
    r: ContactPatch, world_a: np.ndarray | None, world_b: np.ndarray | None, extent: float
) -> float:
    """Half the side of a patch's drawn surface: as far as its points reach along it."""
    patch = []
    if world_a is not None and len(r.indices_a):
        patch.append(world_a[np.asarray(r.indices_a)])
    if world_b is not None and len(r.indices_b):
        patch.append(world_b[np.asarray(r.indices_b)])
    if not patch:
        return 0.05 * extent
    normal = np.asarray(r.normal, dtype=np.float64)
    d = np.concatenate(patch) - np.asarray(r.point, dtype=np.float64)
    d -= np.outer(d @ normal, normal)
    return max(float(np.linalg.norm(d, axis=1).max()), 0.01 * extent)


def _region_mark(
    label: str, r: ContactPatch, surface: tuple[np.ndarray, np.ndarray] | None
) -> RegionMark:
    return RegionMark(
        label=label,
        point=np.asarray(r.point, dtype=np.float64),
        normal=np.asarray(r.normal, dtype=np.float64),
        separation=float(r.separation),
        probability=float(r.probability),
        points=(len(r.indices_a), len(r.indices_b)),
        surface=surface,
    )


def _region_marks(
    regions: Sequence[tuple[str, ContactPatch]],
    world_a: np.ndarray | None,
    world_b: np.ndarray | None,
    surfaces: int,
    extent: float,
) -> list[RegionMark]:
    """Mark the patches, most probable first; the first ``surfaces`` carry their surface."""
    order = sorted(range(len(regions)), key=lambda k: -regions[k][1].probability)
    marks = []
    for rank, k in enumerate(order):
        label, r = regions[k]
        surface = None
        finite = np.all(np.isfinite(r.point)) and np.all(np.isfinite(r.normal))
        if rank < surfaces and finite:
            half = _surface_half_size(r, world_a, world_b, extent)
            surface = separating_surface(r, half)
        marks.append(_region_mark(label, r, surface))
    return marks


def _contact_indices(regions: Sequence[ContactPatch], side: str, n: int) -> np.ndarray:
    """Collect the indices (sorted, unique, < n) of one side's points in ``regions``."""
    parts = [np.asarray(getattr(r, f"indices_{side}"), dtype=np.int64) for r in regions]
    idx = np.unique(np.concatenate(parts)) if parts else np.zeros(0, dtype=np.int64)
    return idx[(idx >= 0) & (idx < n)]


def _side_points(
    which: str,
    obj: Any,
    pose: npt.ArrayLike | None,
    given: npt.ArrayLike | None,
    result: CollisionResult,
    n: int,
) -> np.ndarray:
    if given is not None:
        pts = np.asarray(given, dtype=np.float64)
    else:
        queried = getattr(result, f"points_{which}", None)
        if queried is not None:
            pts = np.asarray(queried, dtype=np.float64)
        elif isinstance(obj, PointCloud):
            pts = _world(obj.points, pose)
        elif n == 0:
            # An exact mesh side: no points (the mesh itself is drawn).
            pts = np.zeros((0, 3))
        else:
            raise ValueError(
                f"side {which.upper()}: the result does not record its points; give "
                f"the PointCloud as {which}= or the world-frame points as points_{which}="
            )
    if pts.shape != (n, 3):
        raise ValueError(
            f"side {which.upper()}: points of shape {pts.shape} do not match the result's "
            f"{n} probabilities"
        )
    return pts


def _mesh_layer(mesh: Mesh, pose: npt.ArrayLike | None, name: str, color: str) -> MeshLayer:
    vertices = _world(mesh.vertices, pose)
    return MeshLayer(
        name=f"{name} (mesh)",
        vertices=vertices.astype(np.float32),
        faces=np.asarray(mesh.faces, dtype=np.int32),
        color=color,
        opacity=0.35,
        hover=f"{name}: mesh, {len(mesh.faces)} faces",
    )


def collision_scene(
    result: CollisionResult,
    a: PointCloud | Mesh | None = None,
    b: PointCloud | Mesh | None = None,
    pose_a: npt.ArrayLike | None = None,
    pose_b: npt.ArrayLike | None = None,
    *,
    points_a: npt.ArrayLike | None = None,
    points_b: npt.ArrayLike | None = None,
    labels: tuple[str, str] = ("A", "B"),
    surfaces: int = 5,
    quiet_below: float = 1e-3,
    title: str | None = None,
) -> Scene:
    """Make the view of one :func:`cloudprox.collide` result.

    The points come from the result itself (``result.points_a``, the points as
    queried, a mesh side's samples included, in the world frame), else from the
    clouds ``a`` and ``b`` at their poses, else from ``points_a`` / ``points_b``
    (world frame).

    Parameters
    ----------
    result : CollisionResult
        The result to show.
    a, b : PointCloud or Mesh, optional
        The sides as queried; a :class:`Mesh` side is drawn as a surface too.
    pose_a, pose_b : array_like, shape (4, 4), optional
        Their poses (as given to ``collide``).
    points_a, points_b : array_like, shape (n, 3), optional
        World-frame points instead (they take precedence).
    labels : tuple of str, default ("A", "B")
        Names of the two sides.
    surfaces : int, default 5
        How many patches (the most probable) carry their separating surface.
    quiet_below : float, default 1e-3
        Points with a smaller probability are drawn small, in their side's colour.
    title : str, optional
        First title line (a second gives ``P`` and the state).

    Returns
    -------
    Scene
        Hand it to :func:`write_html`, :func:`write_rerun` or :func:`to_figure`.

    Raises
    ------
    ValueError
        If a side's points are not known or do not match the result.
    """
    prob = (np.asarray(result.probabilities_a), np.asarray(result.probabilities_b))
    world = [
        _side_points(w, obj, pose, given, result, len(p))
        for w, obj, pose, given, p in (
            ("a", a, pose_a, points_a, prob[0]),
            ("b", b, pose_b, points_b, prob[1]),
        )
    ]
    layers, meshes = [], []
    for k, (obj, pose) in enumerate(((a, pose_a), (b, pose_b))):
        is_mesh = isinstance(obj, Mesh)
        if isinstance(obj, Mesh):
            meshes.append(_mesh_layer(obj, pose, labels[k], SIDE_COLORS[k]))
        layers.append(
            PointLayer(
                name=labels[k],
                points=world[k].astype(np.float32),
                probabilities=np.nan_to_num(prob[k]).astype(np.float32),
                color=SIDE_COLORS[k],
                show_quiet=not is_mesh,
                contact=_contact_indices(result.patches, "ab"[k], len(prob[k])),
            )
        )
    head = f"{title}<br>" if title else ""
    scene = Scene(
        title=f"{head}{labels[0]} vs {labels[1]}: P = {result.probability:.4g}, "
        f"state: {result.state}, {len(result.patches)} patches",
        points=layers,
        meshes=meshes,
        quiet_below=quiet_below,
    )
    marks = _region_marks(
        [(f"patch {k}", r) for k, r in enumerate(result.patches)],
        world[0],
        world[1],
        surfaces,
        scene.extent(),
    )
    return Scene(scene.title, layers, meshes, marks, quiet_below)


def robot_scene(
    robot: Robot,
    q: npt.ArrayLike,
    cloud: PointCloud,
    result: RobotCollisionResult,
    base_pose: npt.ArrayLike | None = None,
    *,
    label: str = "scene",
    surfaces: int = 5,
    quiet_below: float = 1e-3,
    title: str | None = None,
) -> Scene:
    """Make the view of one :func:`cloudprox.collide_robot` result.

    The links are drawn at ``q`` and coloured by their collision probability
    (grey when the broad phase skipped them), the cloud's points by the largest
    probability any link gave them.

    Parameters
    ----------
    robot : Robot
        The robot.
    q : array_like, shape (dof,)
        The configuration queried.
    cloud : PointCloud
        The scene (its own frame is the world).
    result : RobotCollisionResult
        ``collide_robot(robot, q, cloud, base_pose)``.
    base_pose : array_like, shape (4, 4), optional
        The robot's root in the cloud's frame.
    label : str, default "scene"
        Name of the cloud.
    surfaces, quiet_below, title
        As in :func:`collision_scene`.

    Returns
    -------
    Scene
    """
    meshes = _link_layers(robot, robot.link_poses(q, base_pose), result)
    n = len(cloud)
    layers = [
        PointLayer(
            name=label,
            points=np.asarray(cloud.points, dtype=np.float32),
            probabilities=_worst_scene_probabilities(result, meshes, n).astype(np.float32),
            color=SIDE_COLORS[1],
            contact=_contact_indices([r for _, r in result.patches], "b", n),
        )
    ]
    selfc = (
        f", self-collision: {', '.join(f'{x}-{y}' for x, y in result.self_collisions)}"
        if result.self_collisions
        else ""
    )
    head = f"{title}<br>" if title else ""
    scene = Scene(
        title=f"{head}{robot.name} vs {label}: P = {result.probability:.4g}, "
        f"state: {result.state}{selfc}",
        points=layers,
        meshes=meshes,
        quiet_below=quiet_below,
    )
    cloud_points = np.asarray(cloud.points, dtype=np.float64)
    marks = _region_marks(
        [(name, r) for name, r in result.patches], None, cloud_points, surfaces, scene.extent()
    )
    return Scene(scene.title, layers, meshes, marks, quiet_below)


def _link_layers(
    robot: Robot, poses: dict[str, Any], result: RobotCollisionResult
) -> list[MeshLayer]:
    """Lay out the robot's links with geometry at their poses, coloured by their probability."""
    meshes = []
    for name, link in result.links.items():
        mesh = robot.link_mesh(name)
        if mesh is None:
            continue
        queried = link.queried and math.isfinite(link.probability)
        meshes.append(
            MeshLayer(
                name=name,
                vertices=_world(mesh.vertices, poses[name]).astype(np.float32),
                faces=np.asarray(mesh.faces, dtype=np.int32),
                color="#b0b0b0",
                probability=float(link.probability) if queried else None,
                hover=f"{name}: P = {link.probability:.4g} ({link.state})"
                if queried
                else f"{name}: not queried (beyond reach)",
            )
        )
    return meshes


def _worst_scene_probabilities(
    result: RobotCollisionResult, drawn: list[MeshLayer], n: int
) -> np.ndarray:
    """Each scene point's largest probability over the queries of the ``drawn`` links."""
    worst = np.zeros(n)
    names = {m.name for m in drawn}
    for name, link in result.links.items():
        sub = link.result
        if sub is None or name not in names:
            continue
        pb = np.nan_to_num(np.asarray(sub.probabilities_b))
        if len(pb) != n:
            raise ValueError(
                f"link {name}: the result has {len(pb)} scene probabilities, the cloud "
                f"{n} points: is this the result of this cloud?"
            )
        np.maximum(worst, pb, out=worst)
    return worst
