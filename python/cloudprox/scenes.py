"""Procedural scenes with exact geometry: a grand piano in a room with tables.

Every object is a union of closed convex triangle meshes (boxes and cylinders,
:class:`cloudprox.Mesh`), so exact collision, distance and penetration depth
between two objects come from :func:`cloudprox.exact_proximity` (GJK and EPA
through parry). Parts of one object may overlap; :meth:`SceneObject.sample`
samples the surface of the *union* (points of a part that lie inside another part
are dropped), area-weighted at a chosen density.

The piano is given in its own frame: origin at the centre of the underside of the
rectangular front part of its body, z up, keyboard towards -y. The room is in the
world frame: floor top at z = 0, walls at x = +-3 m and y = +-2.5 m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import numpy.typing as npt

from cloudprox._native import ExactShape, Mesh, exact_proximity
from cloudprox.pose import from_rpy, from_translation

__all__ = [
    "Part",
    "Scene",
    "SceneObject",
    "build_scene",
    "piano",
    "room",
]

FloatArray = npt.NDArray[np.float64]

#: Sides of the prisms that stand for cylinders.
CYLINDER_SEGMENTS = 48


@dataclass(frozen=True, eq=False)
class Part:
    """One closed convex piece of an object.

    Attributes
    ----------
    name : str
        E.g. ``"body"`` or ``"table 2 leg 1"``.
    group : str
        The piece of furniture it belongs to, e.g. ``"piano"``, ``"table 2"``, ``"walls"``.
    mesh : Mesh
        Its exact surface, in the object's frame.
    """

    name: str
    group: str
    mesh: Mesh

    @cached_property
    def _planes(self) -> tuple[FloatArray, FloatArray]:
        """Unit outward face normals ``(m, 3)`` and offsets ``(m,)`` (``n . x <= c`` inside)."""
        v, f = self.mesh.vertices, self.mesh.faces
        n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        return n, np.einsum("ij,ij->i", n, v[f[:, 0]])

    def contains(self, points: FloatArray, margin: float = 1e-9) -> npt.NDArray[np.bool_]:
        """Whether each point ``(k, 3)`` is strictly inside (deeper than ``margin``)."""
        n, c = self._planes
        return np.all(points @ n.T < c - margin, axis=1)


def _box(
    name: str,
    group: str,
    center: npt.ArrayLike,
    half: npt.ArrayLike,
    rpy: npt.ArrayLike = (0.0, 0.0, 0.0),
) -> Part:
    h = [float(x) for x in np.asarray(half, dtype=float)]
    return Part(name, group, Mesh.cuboid(*h).transformed(from_rpy(rpy, center)))


def _cylinder(
    name: str, group: str, center: npt.ArrayLike, radius: float, half_height: float
) -> Part:
    mesh = Mesh.cylinder(radius, half_height, CYLINDER_SEGMENTS)
    return Part(name, group, mesh.transformed(from_translation(center)))


@dataclass(frozen=True, eq=False)
class SceneObject:
    """An object made of convex parts, with exact queries and surface sampling.

    Attributes
    ----------
    name : str
        ``"piano"`` or ``"room"``.
    parts : list of Part
        Its parts, in the object's frame.
    """

    name: str
    parts: list[Part] = field(default_factory=list)

    @cached_property
    def exact(self) -> ExactShape:
        """The parts prepared for :func:`cloudprox.exact_proximity`."""
        return ExactShape([p.mesh for p in self.parts])

    @cached_property
    def group_shapes(self) -> dict[str, ExactShape]:
        """Each group's parts prepared for exact queries."""
        return {g: ExactShape([p.mesh for p in self.parts if p.group == g]) for g in self.groups}

    @property
    def groups(self) -> tuple[str, ...]:
        """The groups of the parts, in order of first appearance."""
        return tuple(dict.fromkeys(p.group for p in self.parts))

    def bounds(self) -> tuple[FloatArray, FloatArray]:
        """Lower and upper corners of the bounding box of all parts."""
        lo = np.min([p.mesh.bounds()[0] for p in self.parts], axis=0)
        hi = np.max([p.mesh.bounds()[1] for p in self.parts], axis=0)
        return lo, hi

    @property
    def diagonal(self) -> float:
        """Length of the bounding box's diagonal (metres)."""
        lo, hi = self.bounds()
        return float(np.linalg.norm(hi - lo))

    def sample(self, density: float, seed: int = 0) -> tuple[FloatArray, FloatArray]:
        """Sample the surface of the union of the parts, area-weighted.

        Each part is sampled at ``density`` points per square metre; points inside
        another part of the object are dropped, so the density is uniform over the
        union's surface.

        Parameters
        ----------
        density : float
            Points per square metre (> 0).
        seed : int, default 0
            Seed of the sampling.

        Returns
        -------
        points : ndarray, shape (k, 3)
        normals : ndarray, shape (k, 3)
            Unit outward normals of the points' faces.
        """
        if not (math.isfinite(density) and density > 0.0):
            raise ValueError(f"density must be finite and > 0, got {density}")
        pts, nrm = [], []
        for i, part in enumerate(self.parts):
            p, n, _ = part.mesh.sample(density=density, seed=seed * 100_003 + i)
            keep = np.ones(len(p), dtype=bool)
            for j, other in enumerate(self.parts):
                if j != i:
                    keep &= ~other.contains(p)
            pts.append(p[keep])
            nrm.append(n[keep])
        return np.concatenate(pts), np.concatenate(nrm)

    def distances(self, other: SceneObject, pose: npt.ArrayLike | None = None) -> dict[str, float]:
        """Exact signed distance from this object at ``pose`` to each group of ``other``.

        Parameters
        ----------
        other : SceneObject
            The other object (at the identity pose).
        pose : array_like, shape (4, 4), optional
            Pose of this object.

        Returns
        -------
        dict of str to float
            Group of ``other`` to the signed distance (metres; negative: minus
            the penetration depth).
        """
        return {
            group: exact_proximity(self.exact, shape, pose).signed_distance
            for group, shape in other.group_shapes.items()
        }


def piano() -> SceneObject:
    """Make a grand piano: body (a box and a rounded tail), open lid, keyboard, three legs.

    About 1.5 m wide, 2 m deep and 1.4 m tall (bounding-box diagonal 2.9 m).
    """
    g = "piano"
    parts = [
        _box("body front", g, (0.0, -0.15, 0.175), (0.75, 0.45, 0.175)),
        _cylinder("body tail", g, (0.0, 0.3, 0.175), 0.75, 0.175),
        # Lid propped open 25 degrees, its left edge resting on the body.
        _box(
            "lid",
            g,
            (0.0, 0.05, 0.362 + 0.68 * math.sin(math.radians(25.0))),
            (0.68, 0.78, 0.012),
            (0.0, math.radians(-25.0), 0.0),
        ),
        _box("keyboard", g, (0.0, -0.75, 0.12), (0.7, 0.15, 0.06)),
        _cylinder("leg front left", g, (-0.62, -0.45, -0.3), 0.05, 0.3),
        _cylinder("leg front right", g, (0.62, -0.45, -0.3), 0.05, 0.3),
        _cylinder("leg back", g, (0.0, 0.9, -0.3), 0.05, 0.3),
        _box("pedals", g, (0.0, -0.45, -0.5), (0.12, 0.05, 0.04)),
        _box("lyre", g, (0.0, -0.45, -0.23), (0.02, 0.02, 0.23)),
    ]
    return SceneObject("piano", parts)


def _table(
    name: str, xy: tuple[float, float], half_xy: tuple[float, float], height: float
) -> list[Part]:
    """Make a rectangular table: a 4 cm top whose upper face is at ``height``, four round legs."""
    x, y = xy
    hx, hy = half_xy
    parts = [_box(f"{name} top", name, (x, y, height - 0.02), (hx, hy, 0.02))]
    leg = (height - 0.04) / 2.0
    for k, (sx, sy) in enumerate([(-1, -1), (1, -1), (-1, 1), (1, 1)]):
        c = (x + sx * (hx - 0.06), y + sy * (hy - 0.06), leg)
        parts.append(_cylinder(f"{name} leg {k}", name, c, 0.03, leg))
    return parts


def _round_table(name: str, xy: tuple[float, float], radius: float, height: float) -> list[Part]:
    """Make a round table: a 4 cm disc top, a central column and a round foot."""
    x, y = xy
    return [
        _cylinder(f"{name} top", name, (x, y, height - 0.02), radius, 0.02),
        _cylinder(
            f"{name} column", name, (x, y, (height - 0.04) / 2.0), 0.05, (height - 0.04) / 2.0
        ),
        _cylinder(f"{name} foot", name, (x, y, 0.02), 0.3, 0.02),
    ]


def room() -> SceneObject:
    """Make a 6 m x 5 m room (floor, four walls 2.6 m high) with four tables.

    ``table 1`` is a small side table (50 x 40 cm, 75 cm high) at the origin, which
    fits between the piano's legs; ``table 2`` a desk, ``table 3`` a round table,
    ``table 4`` a low coffee table.
    """
    hx, hy, h, t = 3.0, 2.5, 2.6, 0.05
    parts = [
        _box("floor", "floor", (0.0, 0.0, -t), (hx + 2 * t, hy + 2 * t, t)),
        _box("wall north", "walls", (0.0, hy + t, h / 2), (hx + 2 * t, t, h / 2)),
        _box("wall south", "walls", (0.0, -hy - t, h / 2), (hx + 2 * t, t, h / 2)),
        _box("wall east", "walls", (hx + t, 0.0, h / 2), (t, hy, h / 2)),
        _box("wall west", "walls", (-hx - t, 0.0, h / 2), (t, hy, h / 2)),
        *_table("table 1", (0.0, 0.0), (0.25, 0.20), 0.75),
        *_table("table 2", (1.9, 1.5), (0.60, 0.40), 0.75),
        *_round_table("table 3", (-1.8, -1.3), 0.45, 0.72),
        *_table("table 4", (1.6, -1.5), (0.50, 0.30), 0.45),
    ]
    return SceneObject("room", parts)


@dataclass(frozen=True, eq=False)
class Scene:
    """The piano and the room, with one noisy sampling of each.

    Attributes
    ----------
    piano, room : SceneObject
        Exact geometry (piano in its own frame, room in the world frame).
    piano_points, room_points : ndarray, shapes (n, 3) and (m, 3)
        Noisy surface samples (piano frame, world frame).
    sigma : float
        Standard deviation of the isotropic noise that was added (metres).
    table : str
        The group of the table :meth:`piano_pose` places the piano above.
    """

    piano: SceneObject
    room: SceneObject
    piano_points: FloatArray
    room_points: FloatArray
    sigma: float
    table: str = "table 1"

    def table_top(self) -> Part:
        """Return the top of :attr:`table`."""
        return next(p for p in self.room.parts if p.name == f"{self.table} top")

    def piano_pose(self, gap: float) -> FloatArray:
        """Pose putting the piano's underside ``gap`` metres above :attr:`table`'s top.

        Parameters
        ----------
        gap : float
            Exact gap between the body's underside and the table top (metres);
            negative values sink the piano into the table.

        Returns
        -------
        ndarray, shape (4, 4)
        """
        lo, hi = self.table_top().mesh.bounds()
        return from_translation(((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, hi[2] + gap))

    def gaps(self, pose: npt.ArrayLike) -> dict[str, float]:
        """Exact signed distance between the piano at ``pose`` and each room group."""
        return self.piano.distances(self.room, pose)

    def exact_gap(self, pose: npt.ArrayLike) -> float:
        """Exact signed distance between the piano at ``pose`` and the room (metres)."""
        return exact_proximity(self.piano.exact, self.room.exact, pose).signed_distance


def build_scene(sigma: float = 0.005, points: int = 3000, seed: int = 0) -> Scene:
    """Sample the piano and the room at one density and add isotropic noise.

    Parameters
    ----------
    sigma : float, default 0.005
        Standard deviation of the Gaussian noise added to every coordinate (metres).
    points : int, default 3000
        Approximate number of piano points; the room is sampled at the same density
        (about 11 times as many points).
    seed : int, default 0
        Seed of the sampling and the noise.

    Returns
    -------
    Scene
    """
    if points < 10:
        raise ValueError(f"points must be >= 10, got {points}")
    if not (math.isfinite(sigma) and sigma >= 0.0):
        raise ValueError(f"sigma must be finite and >= 0, got {sigma}")
    p, r = piano(), room()
    density = points / sum(part.mesh.area for part in p.parts)
    piano_pts, _ = p.sample(density, seed)
    room_pts, _ = r.sample(density, seed + 1)
    rng = np.random.default_rng(seed)
    piano_pts = piano_pts + rng.normal(0.0, sigma, size=piano_pts.shape)
    room_pts = room_pts + rng.normal(0.0, sigma, size=room_pts.shape)
    return Scene(p, r, piano_pts, room_pts, float(sigma))
