"""Interactive 3D views of results: one self-contained HTML file, or a Rerun recording.

A view holds both sides of a query (clouds, or a mesh and a cloud, or a robot at
its configuration and a scene), every point coloured by its collision probability
on a colour bar, the contact patches with their normals and separations, and the
separating surface of the most probable regions (hidden at first). The HTML file
(:func:`write_html`) is drawn by k3d (three.js, its JavaScript inlined: it opens
without a server or the internet, fast even without a GPU: every point is one
WebGL point); turn, zoom, and hover a point for its probability. The points
below ``quiet_below`` are thinned to the density a screen shows of the whole
scene unless ``all_points``. :func:`to_figure` makes the same scene a plotly
figure (``write_html(..., renderer="plotly")``).

k3d and plotly are the optional extra ``cloudprox[view]``, rerun-sdk
``cloudprox[rerun]``.

Examples
--------
>>> import cloudprox as cp
>>> from cloudprox import view
>>> a = cp.PointCloud(cp.synthetic.sample_sphere(300, radius=0.1), sigma=0.002)
>>> result = cp.collide(a, a, pose_b=[[1, 0, 0, 0.19], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
>>> scene = view.collision_scene(result, labels=("left", "right"))
>>> [layer.name for layer in scene.points]
['left', 'right']
"""

from __future__ import annotations

import base64
import html
import json
import math
import re
import tempfile
import webbrowser
import zlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from cloudprox._native import Mesh, PointCloud

if TYPE_CHECKING:
    from cloudprox._native import CollisionResult, ContactPatch, Robot, RobotCollisionResult

__all__ = [
    "MeshLayer",
    "PointLayer",
    "RegionMark",
    "Scene",
    "collision_scene",
    "k3d_page",
    "robot_scene",
    "separating_surface",
    "show",
    "to_figure",
    "to_k3d",
    "write_html",
    "write_rerun",
]

#: The colour scale of probabilities (matplotlib's and plotly's "plasma").
COLORSCALE = "Plasma"
#: Colours of the two sides' points below ``quiet_below`` (side A, side B).
SIDE_COLORS = ("#2ca58d", "#8d99ae")
#: Colour of the contact patches' points and normals.
REGION_COLOR = "#d62728"


def _need(module: str, extra: str) -> Any:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"this view needs the '{module.split('.')[0]}' package: "
            f"pip install 'cloudprox[{extra}]'"
        ) from None


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


def _region_marks(
    regions: Sequence[tuple[str, ContactPatch]],
    world_a: np.ndarray | None,
    world_b: np.ndarray | None,
    surfaces: int,
    extent: float,
) -> list[RegionMark]:
    order = sorted(range(len(regions)), key=lambda k: -regions[k][1].probability)
    marks = []
    for rank, k in enumerate(order):
        label, r = regions[k]
        surface = None
        if rank < surfaces:
            patch = []
            if world_a is not None and len(r.indices_a):
                patch.append(world_a[np.asarray(r.indices_a)])
            if world_b is not None and len(r.indices_b):
                patch.append(world_b[np.asarray(r.indices_b)])
            point = np.asarray(r.point, dtype=np.float64)
            normal = np.asarray(r.normal, dtype=np.float64)
            half = 0.05 * extent
            if patch:
                d = np.concatenate(patch) - point
                d -= np.outer(d @ normal, normal)
                half = max(float(np.linalg.norm(d, axis=1).max()), 0.01 * extent)
            if np.all(np.isfinite(point)) and np.all(np.isfinite(normal)):
                surface = separating_surface(r, half)
        marks.append(
            RegionMark(
                label=label,
                point=np.asarray(r.point, dtype=np.float64),
                normal=np.asarray(r.normal, dtype=np.float64),
                separation=float(r.separation),
                probability=float(r.probability),
                points=(len(r.indices_a), len(r.indices_b)),
                surface=surface,
            )
        )
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
        if is_mesh:
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
    poses = robot.link_poses(q, base_pose)
    n = len(cloud)
    worst = np.zeros(n)
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
        sub = link.result
        if sub is not None:
            pb = np.nan_to_num(np.asarray(sub.probabilities_b))
            if len(pb) != n:
                raise ValueError(
                    f"link {name}: the result has {len(pb)} scene probabilities, the cloud "
                    f"{n} points: is this the result of this cloud?"
                )
            np.maximum(worst, pb, out=worst)
    layers = [
        PointLayer(
            name=label,
            points=np.asarray(cloud.points, dtype=np.float32),
            probabilities=worst.astype(np.float32),
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


# ------------------------------------------------------------------------- plotly


def _hover(name: str) -> str:
    return (
        f"<b>{name}</b><br>p = %{{customdata:.4g}}<br>"
        "(%{x:.4f}, %{y:.4f}, %{z:.4f})<extra></extra>"
    )


def _bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    parts = [np.asarray(x.points, dtype=np.float64) for x in scene.points if len(x.points)]
    parts += [np.asarray(m.vertices, dtype=np.float64) for m in scene.meshes]
    allp = np.concatenate(parts) if parts else np.zeros((1, 3))
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    if not len(allp):
        return np.zeros(3), np.ones(3)
    return allp.min(axis=0), allp.max(axis=0)


def _focus(scene: Scene) -> tuple[np.ndarray, float] | None:
    """Centre and size of the contact: the points with p >= quiet_below, regions."""
    parts = [x.points[x.probabilities >= scene.quiet_below] for x in scene.points]
    parts += [r.point[None] for r in scene.regions]
    parts += [
        m.vertices
        for m in scene.meshes
        if m.probability is not None and m.probability >= scene.quiet_below
    ]
    near = np.concatenate(
        [np.asarray(p, dtype=np.float64) for p in parts if len(p)] or [np.zeros((0, 3))]
    )
    near = near[np.all(np.isfinite(near), axis=1)]
    if not len(near):
        return None
    lo, hi = near.min(axis=0), near.max(axis=0)
    return (lo + hi) / 2.0, max(float((hi - lo).max()), 0.02 * scene.extent())


def to_figure(scene: Scene, *, all_points: bool = True) -> Any:
    """Build the plotly figure of a scene (needs ``plotly``, in ``cloudprox[view]``).

    Parameters
    ----------
    scene : Scene
        From :func:`collision_scene` or :func:`robot_scene`.
    all_points : bool, default True
        Draw every point with ``p < quiet_below``; else thin them as
        :func:`to_k3d` does.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    go = _need("plotly.graph_objects", "view")
    fig = go.Figure()
    extent = scene.extent()
    cell = extent / QUIET_CELLS
    focus = _focus(scene)
    colorbar = {
        "title": {"text": "collision<br>probability p", "side": "top"},
        "len": 0.75,
        "thickness": 18,
        "x": 1.0,
    }
    # The colour bar has a trace of its own (one invisible point inside the
    # scene): it shows even when no point reaches quiet_below.
    lo, hi = _bounds(scene)
    fig.add_trace(
        go.Scatter3d(
            x=[float(lo[0])],
            y=[float(lo[1])],
            z=[float(lo[2])],
            mode="markers",
            marker={
                "size": 0.1,
                "opacity": 0.0,
                "color": [0.0],
                "colorscale": COLORSCALE,
                "cmin": 0.0,
                "cmax": 1.0,
                "showscale": True,
                "colorbar": colorbar,
            },
            showlegend=False,
            hoverinfo="skip",
            name="colour bar",
        )
    )
    for layer in scene.points:
        pts, prob = layer.points, layer.probabilities
        quiet = prob < scene.quiet_below
        shown = _quiet_shown(layer, scene.quiet_below, None if all_points else cell)
        if layer.show_quiet and len(shown):
            q = pts[shown]
            count = f"{len(pts)}" if len(shown) == np.sum(quiet) else f"{len(shown)} of {len(pts)}"
            fig.add_trace(
                go.Scatter3d(
                    x=q[:, 0],
                    y=q[:, 1],
                    z=q[:, 2],
                    mode="markers",
                    name=f"{layer.name}: {count} points",
                    marker={"size": 1.5, "color": layer.color},
                    customdata=prob[shown],
                    hovertemplate=_hover(layer.name),
                )
            )
        loud = np.flatnonzero(~quiet)
        loud = loud[np.argsort(prob[loud], kind="stable")]
        l_pts = pts[loud]
        fig.add_trace(
            go.Scatter3d(
                x=l_pts[:, 0],
                y=l_pts[:, 1],
                z=l_pts[:, 2],
                mode="markers",
                name=f"{layer.name}: {len(loud)} with p ≥ {scene.quiet_below:g}",
                marker={
                    "size": 3.5,
                    "color": prob[loud],
                    "colorscale": COLORSCALE,
                    "cmin": 0.0,
                    "cmax": 1.0,
                },
                customdata=prob[loud],
                hovertemplate=_hover(layer.name),
            )
        )
    for m in scene.meshes:
        common = {
            "x": m.vertices[:, 0],
            "y": m.vertices[:, 1],
            "z": m.vertices[:, 2],
            "i": m.faces[:, 0],
            "j": m.faces[:, 1],
            "k": m.faces[:, 2],
            "name": m.name,
            "opacity": m.opacity,
            "showlegend": True,
            "hovertemplate": f"{m.hover or m.name}<extra></extra>",
            "flatshading": True,
        }
        if m.probability is None:
            fig.add_trace(go.Mesh3d(color=m.color, **common))
        else:
            fig.add_trace(
                go.Mesh3d(
                    intensity=np.full(len(m.vertices), m.probability, dtype=np.float32),
                    colorscale=COLORSCALE,
                    cmin=0.0,
                    cmax=1.0,
                    showscale=False,
                    **common,
                )
            )
    if scene.regions:
        length = 0.08 * extent if focus is None else max(0.4 * focus[1], 0.005 * extent)
        xs: list[float | None] = []
        ys: list[float | None] = []
        zs: list[float | None] = []
        for r in scene.regions:
            if not (np.all(np.isfinite(r.point)) and np.all(np.isfinite(r.normal))):
                continue
            tip = r.point + length * r.normal
            for arr, k in ((xs, 0), (ys, 1), (zs, 2)):
                arr += [float(r.point[k]), float(tip[k]), None]
        fig.add_trace(
            go.Scatter3d(
                x=xs,
                y=ys,
                z=zs,
                mode="lines",
                line={"color": REGION_COLOR, "width": 5},
                name="patch normals (A → B)",
                hoverinfo="skip",
            )
        )
        pts = np.array([r.point for r in scene.regions], dtype=np.float64)
        text = [
            f"<b>{r.label}</b><br>P = {r.probability:.4g}<br>separation "
            f"{1e3 * r.separation:+.2f} mm<br>normal ({r.normal[0]:+.3f}, "
            f"{r.normal[1]:+.3f}, {r.normal[2]:+.3f})<br>points {r.points[0]} + {r.points[1]}"
            for r in scene.regions
        ]
        fig.add_trace(
            go.Scatter3d(
                x=pts[:, 0],
                y=pts[:, 1],
                z=pts[:, 2],
                mode="markers",
                marker={"size": 5, "color": REGION_COLOR, "symbol": "diamond"},
                name=f"contact patches ({len(scene.regions)})",
                hovertext=text,
                hovertemplate="%{hovertext}<extra></extra>",
            )
        )
        for r in scene.regions:
            if r.surface is None:
                continue
            v, f = r.surface
            fig.add_trace(
                go.Mesh3d(
                    x=v[:, 0].astype(np.float32),
                    y=v[:, 1].astype(np.float32),
                    z=v[:, 2].astype(np.float32),
                    i=f[:, 0].astype(np.int32),
                    j=f[:, 1].astype(np.int32),
                    k=f[:, 2].astype(np.int32),
                    color="#1f77b4",
                    opacity=0.5,
                    name=f"separating surface, {r.label} (P = {r.probability:.3g})",
                    showlegend=True,
                    visible="legendonly",
                    hovertemplate=f"separating surface of {r.label}<extra></extra>",
                )
            )
    axis = {"showbackground": True, "backgroundcolor": "#f4f4f4", "gridcolor": "#d0d0d0"}
    pad = 0.02 * float((hi - lo).max()) + 1e-9
    lo, hi = lo - pad, hi + pad
    size = float((hi - lo).max())
    # The camera looks at the contact (the points with p >= quiet_below) from the
    # default direction, as close as its size allows; plotly's camera coordinates
    # put the scene box's centre at 0 with its largest side 1 long.
    camera: dict[str, Any] = {}
    if focus is not None:
        centre = (focus[0] - (lo + hi) / 2.0) / size
        distance = 2.165 * min(1.0, max(2.0 * focus[1] / size, 0.12))
        eye = centre + distance * np.full(3, 1.0 / math.sqrt(3.0))
        camera = {
            "center": dict(zip("xyz", centre.tolist(), strict=False)),
            "eye": dict(zip("xyz", eye.tolist(), strict=False)),
        }
    fig.update_layout(
        title={"text": scene.title, "x": 0.01, "font": {"size": 15}},
        scene={
            "aspectmode": "manual",
            "aspectratio": dict(zip("xyz", ((hi - lo) / size).tolist(), strict=False)),
            "camera": camera,
            "xaxis": {"title": {"text": "x (m)"}, "range": [lo[0], hi[0]], **axis},
            "yaxis": {"title": {"text": "y (m)"}, "range": [lo[1], hi[1]], **axis},
            "zaxis": {"title": {"text": "z (m)"}, "range": [lo[2], hi[2]], **axis},
        },
        legend={"x": 0.0, "y": 0.92, "bgcolor": "rgba(255,255,255,0.7)", "itemsizing": "constant"},
        margin={"l": 0, "r": 0, "t": 60, "b": 0},
        paper_bgcolor="white",
        hoverlabel={"namelength": -1},
    )
    return fig


def write_html(
    scene: Scene,
    path: str | Path,
    *,
    renderer: str = "k3d",
    all_points: bool = False,
) -> Path:
    """Write the scene as one self-contained HTML file (its renderer embedded).

    The file opens in a browser without a server or the internet: turn with the
    left button, zoom with the wheel, hover a point for its probability.

    ``renderer="k3d"`` (the default) draws with three.js (k3d): every point is
    one WebGL point, so it opens fast even without a GPU; the K3D panel's Objects
    folder shows and hides each part (the separating surfaces start hidden).
    ``renderer="plotly"`` writes :func:`to_figure` (plotly.js embedded, axes with
    ticks, a clickable legend), several times slower to open with many points.

    Parameters
    ----------
    scene : Scene
        From :func:`collision_scene` or :func:`robot_scene`.
    path : str or Path
        The file to write.
    renderer : {"k3d", "plotly"}, default "k3d"
        Which library draws the scene.
    all_points : bool, default False
        Draw every point with ``p < quiet_below`` too, instead of one a cell of
        the density the screen shows of the whole scene (the legend says how
        many are drawn); points with ``p >= quiet_below`` are always all drawn.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    if renderer == "k3d":
        path.write_text(
            k3d_page(to_k3d(scene, all_points=all_points), scene.title), encoding="utf-8"
        )
    elif renderer == "plotly":
        fig = to_figure(scene, all_points=all_points)
        fig.write_html(
            str(path),
            include_plotlyjs=True,
            full_html=True,
            config={"displaylogo": False, "responsive": True},
            post_script=_PLOTLY_DRAWN,
        )
    else:
        raise ValueError(f"renderer must be 'k3d' or 'plotly', got {renderer!r}")
    return path


_PLOTLY_DRAWN = (
    "requestAnimationFrame(function(){requestAnimationFrame(function(){"
    "window.cloudproxDrawn=performance.now()})})"
)


# --------------------------------------------------------------------------- k3d

#: Quiet points are thinned to one a cubic cell of ``extent / QUIET_CELLS``: the
#: size of one drawn quiet point (2 pixels) when the whole scene fills a view
#: about 800 pixels across.
QUIET_CELLS = 400
#: Pixel sizes of the drawn points (below and above ``quiet_below``, regions).
POINT_PIXELS = (2.0, 5.0, 11.0)
#: How many contact patches (the most probable) carry a text label in the view.
REGION_LABELS = 3


def _quiet_shown(layer: PointLayer, quiet_below: float, cell: float | None) -> np.ndarray:
    """Pick the quiet points drawn: all, or one a cell of side ``cell`` (indices).

    The first point (in the layer's order) of each occupied cell is kept, so the
    choice is deterministic and the drawn density is at most one a cell; the
    points of the contact patches (``layer.contact``) are kept besides.
    """
    is_quiet = np.asarray(layer.probabilities) < quiet_below
    quiet = np.flatnonzero(is_quiet)
    if cell is None or not len(quiet):
        return quiet
    pts = np.asarray(layer.points, dtype=np.float64)[quiet]
    ok = np.all(np.isfinite(pts), axis=1)
    if not np.any(ok):
        return quiet[:0]
    key = np.floor((pts[ok] - pts[ok].min(axis=0)) / cell).astype(np.int64)
    span = key.max(axis=0) + 1
    flat = (key[:, 0] * span[1] + key[:, 1]) * span[2] + key[:, 2]
    _, first = np.unique(flat, return_index=True)
    contact = np.asarray(layer.contact, dtype=np.int64)
    contact = contact[(contact >= 0) & (contact < len(is_quiet))]
    return np.union1d(quiet[ok][first], contact[is_quiet[contact]])


def _packed(color: str) -> int:
    return int(color.lstrip("#"), 16)


def _plasma_packed(p: float) -> int:
    r, g, b = (int(x) for x in _rgb(np.array([p]))[0])
    return (r << 16) | (g << 8) | b


def _flat_map(color: str) -> list[float]:
    """Make a k3d colour map of one colour (the probabilities ride along as the attribute)."""
    r, g, b = (float(x) / 255.0 for x in _hex_rgb(color))
    return [0.0, r, g, b, 1.0, r, g, b]


def _k3d_camera(scene: Scene, lo: np.ndarray, hi: np.ndarray, fov: float) -> list[float]:
    """Look at the contact from the (1, 1, 1) direction, as :func:`to_figure` does."""
    size = float((hi - lo).max())
    focus = _focus(scene)
    if focus is None:
        centre, distance = (lo + hi) / 2.0, 2.165 * size
    else:
        centre = focus[0]
        distance = 2.165 * size * min(1.0, max(2.0 * focus[1] / size, 0.12))
    # plotly's camera sees 45 degrees vertically, k3d's ``fov``.
    distance *= math.tan(math.radians(22.5)) / math.tan(math.radians(fov / 2.0))
    eye = centre + distance * np.full(3, 1.0 / math.sqrt(3.0))
    return [*eye.tolist(), *centre.tolist(), 0.0, 0.0, 1.0]


_K3D_JS = r"""
(function () {
  var info = __INFO__;
  var k3d = K3DInstance, world = k3d.getWorld(), target = world.targetDOMNode;
  window.cloudproxK3D = k3d;
  function fmt(v) { return Number(v.toPrecision(4)).toString(); }
  var tip = document.createElement('div');
  tip.id = 'cloudprox-hover';
  tip.style.cssText = 'position:absolute;display:none;pointer-events:none;z-index:30;' +
    'background:rgba(255,255,255,0.93);border:1px solid #777;border-radius:3px;' +
    'padding:3px 6px;font:12px sans-serif;color:#222;white-space:nowrap';
  target.appendChild(tip);
  var bar = document.createElement('div');
  bar.id = 'cloudprox-colorbar-title';
  bar.innerHTML = 'collision<br>probability p';
  bar.style.cssText = 'position:absolute;left:12px;bottom:230px;z-index:20;' +
    'pointer-events:none;font:13px sans-serif;color:#333';
  target.appendChild(bar);
  // Above k3d's colour bar (an SVG bottom left, its height a share of the view's).
  function placeBarTitle() {
    var rects = target.querySelectorAll('svg rect'), t = target.getBoundingClientRect();
    for (var k = 0; k < rects.length; k++) {
      var r = rects[k].getBoundingClientRect();
      if (r.left - t.left < 100 && r.height > 50) {
        bar.style.bottom = (t.bottom - r.top + 16) + 'px';
        return;
      }
    }
  }
  k3d.on(k3d.events.RESIZED, placeBarTitle);
  var mouse = {x: 0, y: 0}, hit = false, onRegion = false;
  function show(html, name, index) {
    tip.innerHTML = html;
    tip.style.left = (mouse.x + 14) + 'px';
    tip.style.top = (mouse.y + 14) + 'px';
    tip.style.display = 'block';
    hit = true;
    window.cloudproxHovered = {name: name, index: index, html: html};
  }
  // The region markers win over the points around them: the nearest one within
  // 9 pixels of the pointer, found on the screen.
  function region() {
    var r = info.__regions__;
    if (!r) return false;
    var V = world.camera.position.constructor, best = -1, bestD = 81;
    var w = target.clientWidth, h = target.clientHeight;
    for (var k = 0; k < r.points.length; k++) {
      var v = new V(r.points[k][0], r.points[k][1], r.points[k][2]).project(world.camera);
      if (v.z < -1 || v.z > 1) continue;
      var dx = (v.x + 1) / 2 * w - mouse.x, dy = (1 - v.y) / 2 * h - mouse.y;
      if (dx * dx + dy * dy < bestD) { bestD = dx * dx + dy * dy; best = k; }
    }
    if (best < 0) return false;
    show(r.texts[best], r.name, best);
    return true;
  }
  // Capture: runs before k3d's own pointermove (which casts the ray, then fires
  // OBJECT_HOVERED and MOUSE_MOVE).
  target.addEventListener('pointermove', function (e) {
    var r = target.getBoundingClientRect();
    mouse.x = e.clientX - r.left; mouse.y = e.clientY - r.top; hit = false;
    onRegion = region();
  }, true);
  k3d.on(k3d.events.OBJECT_HOVERED, function (e) {
    var json = world.ObjectsListJson[e.K3DIdentifier];
    var entry = json && info[json.name];
    if (!entry || onRegion) return;
    var html = entry.text;
    if (entry.texts) {
      html = entry.texts[e.index];
    } else if (entry.side) {
      var i = e.index, xyz = json.positions.data;
      html = '<b>' + entry.side + '</b><br>p = ' + fmt(json.attribute.data[i]) + '<br>(' +
        [xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]].map(function (v) {
          return v.toFixed(4);
        }).join(', ') + ')';
    }
    if (html !== undefined) show(html, json.name, e.index);
  });
  k3d.on(k3d.events.MOUSE_MOVE, function () { if (!hit) tip.style.display = 'none'; });
  k3d.on(k3d.events.MOUSE_LEAVE, function () { tip.style.display = 'none'; });
  // Drawn: two frames after the scene was loaded and rendered (the frame is on
  // screen); the benches and tests wait for this.
  requestAnimationFrame(function () {
    placeBarTitle();
    requestAnimationFrame(function () { window.cloudproxDrawn = performance.now(); });
  });
})();
"""


def _hover_texts(scene: Scene) -> list[str]:
    return [
        f"<b>{r.label}</b><br>P = {r.probability:.4g}<br>separation "
        f"{1e3 * r.separation:+.2f} mm<br>normal ({r.normal[0]:+.3f}, "
        f"{r.normal[1]:+.3f}, {r.normal[2]:+.3f})<br>points {r.points[0]} + {r.points[1]}"
        for r in scene.regions
    ]


def to_k3d(scene: Scene, *, all_points: bool = False) -> Any:
    """Build the k3d plot of a scene (needs ``cloudprox[view]``).

    Every point with ``p >= quiet_below`` is drawn, coloured on the plasma scale
    and larger; the others in their side's colour, thinned (unless
    ``all_points``) to one a cell of ``extent / QUIET_CELLS`` (the density a
    screen shows of the whole scene), the points of contact patches kept; the
    legend says how many are drawn. The
    contact patches are red markers with their normals (hover a marker for P,
    separation, normal), the separating surfaces start hidden (the panel's
    Objects folder shows them), mesh sides and robot links are surfaces.

    Parameters
    ----------
    scene : Scene
        From :func:`collision_scene` or :func:`robot_scene`.
    all_points : bool, default False
        Draw every quiet point too.

    Returns
    -------
    k3d.plot.Plot
        :func:`k3d_page` makes it the HTML that :func:`write_html` writes.
    """
    k3d = _need("k3d", "view")
    extent = scene.extent()
    lo, hi = _bounds(scene)
    pad = 0.02 * float((hi - lo).max()) + 1e-9
    lo, hi = lo - pad, hi + pad
    fov = 45.0
    plot = k3d.plot(
        antialias=0,  # multisampling doubles the time software WebGL takes to draw
        camera_auto_fit=False,
        grid_auto_fit=False,
        grid=(*lo.tolist(), *hi.tolist()),
        grid_color=0xD0D0D0,
        background_color=0xFFFFFF,
        camera_fov=fov,
        menu_visibility=True,
        mode="callback",  # hovering an object fires OBJECT_HOVERED (the tooltips)
        axes=["x (m)", "y (m)", "z (m)"],
    )
    plot.camera = _k3d_camera(scene, lo, hi, fov)

    def hovered(*_: Any) -> None:  # marks an object as hoverable in the browser
        return None

    info: dict[str, dict[str, Any]] = {}
    bar_id = -1
    legend = [f"<b>{scene.title}</b>"]
    cell = None if all_points else extent / QUIET_CELLS
    for layer in scene.points:
        pts = np.asarray(layer.points, dtype=np.float32)
        prob = np.asarray(layer.probabilities, dtype=np.float32)
        if layer.show_quiet:
            shown = _quiet_shown(layer, scene.quiet_below, cell)
            total = int(np.sum(prob < scene.quiet_below))
            if len(shown):
                name = (
                    f"{layer.name}: {len(shown)} of {total} points with p < {scene.quiet_below:g}"
                )
                plot += k3d.points(
                    pts[shown],
                    attribute=prob[shown],
                    color_map=_flat_map(layer.color),
                    color_range=[0.0, 1.0],
                    shader="dot",
                    point_size=POINT_PIXELS[0],
                    name=name,
                    hover_callback=hovered,
                )
                info[name] = {"side": layer.name}
            thinned = ""
            if cell is not None and len(shown) < total:
                thinned = f" (one a {1e3 * cell:.2g} mm cell)"
            legend.append(
                f"<span style='color:{layer.color}'>&#9632;</span> {layer.name}: "
                f"{len(shown)} of {total} points with p &lt; {scene.quiet_below:g} drawn{thinned}"
            )
        loud = np.flatnonzero(prob >= scene.quiet_below)
        loud = loud[np.argsort(prob[loud], kind="stable")]
        if len(loud):
            name = f"{layer.name}: {len(loud)} with p ≥ {scene.quiet_below:g}"
            obj = k3d.points(
                pts[loud],
                attribute=prob[loud],
                color_map=k3d.colormaps.matplotlib_color_maps.plasma,
                color_range=[0.0, 1.0],
                shader="dot",
                point_size=POINT_PIXELS[1],
                name=name,
                hover_callback=hovered,
            )
            plot += obj
            bar_id = obj.id if bar_id < 0 else bar_id
            info[name] = {"side": layer.name}
        legend.append(f"{layer.name}: {len(loud)} points with p ≥ {scene.quiet_below:g}, all drawn")
    for m in scene.meshes:
        color = m.color if m.probability is None else f"#{_plasma_packed(m.probability):06x}"
        plot += k3d.mesh(
            np.asarray(m.vertices, dtype=np.float32),
            np.asarray(m.faces, dtype=np.uint32),
            color=_packed(color),
            opacity=m.opacity,
            flat_shading=True,
            side="double",
            name=m.name,
            hover_callback=hovered,
        )
        info[m.name] = {"text": m.hover or m.name}
    marks = [
        r for r in scene.regions if np.all(np.isfinite(r.point)) and np.all(np.isfinite(r.normal))
    ]
    if marks:
        focus = _focus(scene)
        length = 0.08 * extent if focus is None else max(0.4 * focus[1], 0.005 * extent)
        name = f"contact patches ({len(marks)})"
        plot += k3d.points(
            np.array([r.point for r in marks], dtype=np.float32),
            color=_packed(REGION_COLOR),
            shader="dot",
            point_size=POINT_PIXELS[2],
            name=name,
            hover_callback=hovered,
        )
        info[name] = {"texts": _hover_texts(Scene(scene.title, regions=marks))}
        info["__regions__"] = {
            "name": name,
            "points": [r.point.tolist() for r in marks],
            "texts": info[name]["texts"],
        }
        plot += k3d.vectors(
            np.array([r.point for r in marks], dtype=np.float32),
            np.array([length * r.normal for r in marks], dtype=np.float32),
            color=_packed(REGION_COLOR),
            head_size=length,  # k3d's arrow head: a cone 0.2 head_size long
            line_width=0.06 * length,
            name="patch normals (A → B)",
        )
        # The most probable regions carry a label (all of them a hover text).
        for r in sorted(marks, key=lambda r: -r.probability)[:REGION_LABELS]:
            plot += k3d.label(
                f"{r.label}: P = {r.probability:.3g}, {1e3 * r.separation:+.2f} mm",
                position=(r.point + length * r.normal).astype(np.float32),
                color=_packed(REGION_COLOR),
                is_html=True,
                size=0.8,
                mode="local",
                name=f"label of {r.label}",
            )
        legend.append(
            f"<span style='color:{REGION_COLOR}'>&#9670;</span> {len(marks)} contact patches "
            "with normals (A → B) and separations: hover a marker"
        )
    for r in scene.regions:
        if r.surface is None:
            continue
        v, f = r.surface
        name = f"separating surface, {r.label} (P = {r.probability:.3g})"
        plot += k3d.mesh(
            np.asarray(v, dtype=np.float32),
            np.asarray(f, dtype=np.uint32),
            color=0x1F77B4,
            opacity=0.5,
            side="double",
            visible=False,
            name=name,
            hover_callback=hovered,
        )
        info[name] = {"text": f"separating surface of {r.label}"}
    if any(r.surface is not None for r in scene.regions):
        legend.append("separating surfaces: K3D panel, Objects (hidden at first)")
    if bar_id < 0:
        # The colour bar shows one object's map: with no loud point, a carrier
        # of two points drawn fully transparent.
        obj = k3d.points(
            np.repeat(lo[None].astype(np.float32), 2, axis=0),
            attribute=np.array([0.0, 1.0], dtype=np.float32),
            color_map=k3d.colormaps.matplotlib_color_maps.plasma,
            color_range=[0.0, 1.0],
            shader="dot",
            point_size=1.0,
            opacity=0.0,
            name="colour bar",
        )
        plot += obj
        bar_id = obj.id
    plot.colorbar_object_id = bar_id
    plot += k3d.text2d(
        "<br>".join(legend),
        position=(0.005, 0.005),
        reference_point="lt",
        is_html=True,
        size=0.8,
        color=0x333333,
        label_box=True,
        name="legend",
    )
    plot.additional_js_code = _K3D_JS.replace("__INFO__", json.dumps(info).replace("</", "<\\/"))
    return plot


_K3D_PAGE = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>__TITLE__</title>
<style>
html, body { margin: 0; padding: 0; overflow: hidden; background: #ffffff; }
#canvasTarget { width: 100%; height: 100%; position: absolute; }
</style>
</head>
<body>
<div id="canvasTarget"></div>
<script>
// k3d's bundle registers itself with an AMD define("k3d", [], factory).
var cloudproxK3DLib = null;
function define(name, deps, factory) { cloudproxK3DLib = factory(); }
</script>
<script>__K3D_JS__</script>
<script>
var K3DInstance = (function () {
  var lib = cloudproxK3DLib;
  var text = atob("__DATA__"), bytes = new Uint8Array(text.length);
  for (var i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  var snapshot = lib.msgpackDecode(bytes);
  var k3d = new lib.K3D(lib.ThreeJsProvider, document.getElementById('canvasTarget'),
                        Object.assign({}, snapshot.plot, {standaloneGUI: true}));
  // One draw an animation frame: k3d asks for a draw on every object loaded and
  // every setting applied, and with many points each costs a lot in software WebGL.
  var world = k3d.getWorld(), draw = world.render, queued = null, forced = false;
  world.render = function (force) {
    forced = forced || !!force;
    if (queued === null) {
      queued = new Promise(function (resolve) {
        requestAnimationFrame(function () {
          var f = forced;
          queued = null;
          forced = false;
          resolve(draw.call(world, f));
        });
      });
    }
    return queued;
  };
  return k3d.setSnapshot(snapshot).then(function () {
    if (snapshot.plot.camera.length > 0) k3d.setCamera(snapshot.plot.camera);
    k3d.render();
    return k3d;
  });
})();
K3DInstance.then(function (K3DInstance) {
__ADDITIONAL__
});
</script>
</body>
</html>
"""


def k3d_page(plot: Any, title: str = "cloudprox view") -> str:
    """Write a k3d plot as one self-contained HTML page (k3d's JavaScript inlined).

    k3d's own ``plot.get_snapshot()`` ships its 2.6 MB bundle zlib-compressed in
    base64 and runs it through ``eval`` and require.js; here it is a plain script
    (parsed as the page loads), the plot's data plain msgpack in base64, and k3d
    draws at most once an animation frame while the scene loads (it asks for a
    draw on every object and setting, each one costly in software WebGL). The
    plot's ``additional_js_code`` runs once it is loaded, with ``K3DInstance``.

    Parameters
    ----------
    plot : k3d.plot.Plot
        The plot (from :func:`to_k3d`, or any).
    title : str
        The page's title (``<br>`` becomes " | ").

    Returns
    -------
    str
        The HTML text.
    """
    k3d = _need("k3d", "view")
    source = Path(k3d.__file__).parent / "static" / "standalone.js"
    code = source.read_text(encoding="utf-8") if source.is_file() else ""
    if not code.lstrip().split("*/", 1)[-1].lstrip().startswith('define("k3d"') or re.search(
        r"</script|<!--", code, re.IGNORECASE
    ):
        # Another k3d layout: its own page, which embeds the same.
        page: str = plot.get_snapshot()
        return re.sub(
            r"<title>.*?</title>",
            lambda _: f"<title>{html.escape(title.replace('<br>', ' | '))}</title>",
            page,
            count=1,
        )
    data = zlib.decompress(plot.get_binary_snapshot(compression_level=0))
    return (
        _K3D_PAGE.replace("__TITLE__", html.escape(title.replace("<br>", " | ")))
        .replace("__ADDITIONAL__", plot.additional_js_code)
        .replace("__DATA__", base64.b64encode(data).decode("ascii"))
        .replace("__K3D_JS__", code)
    )


# ------------------------------------------------------------------------- rerun


def _rgb(probabilities: np.ndarray) -> np.ndarray:
    from matplotlib import colormaps

    rgba = colormaps["plasma"](np.clip(probabilities, 0.0, 1.0))
    return (rgba[:, :3] * 255.0).round().astype(np.uint8)


def _hex_rgb(color: str) -> np.ndarray:
    c = color.lstrip("#")
    return np.array([int(c[i : i + 2], 16) for i in (0, 2, 4)], dtype=np.uint8)


def write_rerun(scene: Scene, path: str | Path, application_id: str = "cloudprox") -> Path:
    """Write the scene as a Rerun recording (``.rrd``; needs ``cloudprox[rerun]``).

    Entities: ``points/<side>`` (``Points3D`` coloured by probability, with the
    probabilities as the ``probability`` component), ``meshes/<name>``
    (``Mesh3D``), ``regions`` (``Arrows3D`` along the normals, labelled with P and
    the separation), ``surfaces/<region>`` (``Mesh3D``) and ``summary``
    (``TextDocument``). Open with ``rerun FILE.rrd``.

    Parameters
    ----------
    scene : Scene
        From :func:`collision_scene` or :func:`robot_scene`.
    path : str or Path
        The ``.rrd`` file to write.
    application_id : str, default "cloudprox"
        The recording's application id.

    Returns
    -------
    Path
        ``path``.
    """
    rr = _need("rerun", "rerun")
    path = Path(path)
    rec = rr.RecordingStream(application_id)
    rec.save(str(path))
    rec.log("summary", rr.TextDocument(scene.title.replace("<br>", "\n")), static=True)
    for k, layer in enumerate(scene.points):
        prob = layer.probabilities
        colors = _rgb(prob)
        quiet = prob < scene.quiet_below
        colors[quiet] = _hex_rgb(layer.color)
        keep = np.ones(len(prob), dtype=bool) if layer.show_quiet else ~quiet
        radius = 0.002 * scene.extent()
        radii = np.where(quiet, radius, 2.0 * radius).astype(np.float32)
        rec.log(
            f"points/{k}_{_entity(layer.name)}",
            rr.Points3D(layer.points[keep], colors=colors[keep], radii=radii[keep]),
            rr.AnyValues(probability=prob[keep].astype(np.float64)),
            static=True,
        )
    for m in scene.meshes:
        if m.probability is None:
            color = np.append(_hex_rgb(m.color), int(255 * m.opacity)).astype(np.uint8)
        else:
            color = np.append(_rgb(np.array([m.probability]))[0], 255).astype(np.uint8)
        rec.log(
            f"meshes/{_entity(m.name)}",
            rr.Mesh3D(
                vertex_positions=m.vertices,
                triangle_indices=m.faces.astype(np.uint32),
                albedo_factor=color,
            ),
            static=True,
        )
    if scene.regions:
        length = 0.08 * scene.extent()
        rec.log(
            "regions",
            rr.Arrows3D(
                origins=np.array([r.point for r in scene.regions], dtype=np.float32),
                vectors=np.array([length * r.normal for r in scene.regions], dtype=np.float32),
                colors=_hex_rgb(REGION_COLOR),
                labels=[
                    f"{r.label}: P = {r.probability:.3g}, {1e3 * r.separation:+.1f} mm"
                    for r in scene.regions
                ],
            ),
            static=True,
        )
        for k, r in enumerate(scene.regions):
            if r.surface is None:
                continue
            v, f = r.surface
            rec.log(
                f"surfaces/{k}_{_entity(r.label)}",
                rr.Mesh3D(
                    vertex_positions=v.astype(np.float32),
                    triangle_indices=f.astype(np.uint32),
                    albedo_factor=np.array([31, 119, 180, 128], dtype=np.uint8),
                ),
                static=True,
            )
    rec.flush()
    rec.disconnect()
    return path


def _entity(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name) or "_"


# -------------------------------------------------------------------------- show


def show(
    result: CollisionResult,
    path: str | Path | None = None,
    *,
    open_browser: bool = True,
    **options: Any,
) -> Path:
    """Write the HTML view of a :func:`cloudprox.collide` result and open it.

    Parameters
    ----------
    result : CollisionResult
        The result (``result.show()`` calls this).
    path : str or Path, optional
        Where to write the HTML file (default: a new file in the temporary folder).
    open_browser : bool, default True
        Open the file in the default web browser.
    **options
        Passed to :func:`collision_scene` (``a``, ``b``, ``pose_a``, ``pose_b``,
        ``labels``, ``surfaces``, ``quiet_below``, ``title``).

    Returns
    -------
    Path
        The HTML file.
    """
    scene = collision_scene(result, **options)
    if path is None:
        fd, name = tempfile.mkstemp(prefix="cloudprox-view-", suffix=".html")
        import os

        os.close(fd)
        path = Path(name)
    out = write_html(scene, path)
    if open_browser:
        webbrowser.open(out.resolve().as_uri())
    return out
