"""Procedural test scenes with exact geometry: a grand piano above a table in a room.

Every part is an axis-aligned box, so the exact surface gap between any two parts
is known in closed form (:func:`box_distance`). The point clouds are the boxes'
surfaces sampled area-weighted with a seeded numpy generator, plus Gaussian noise
of a chosen standard deviation. The piano is given in its own frame (origin at
the centre of the underside of its body, z up); :meth:`Scene.piano_pose` places it
centred above the main table with an exact gap between the body's underside and
the table top, which is then the smallest gap between the piano and the room.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

__all__ = ["Box", "Scene", "box_distance", "build_scene", "sample_boxes"]

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Box:
    """An axis-aligned box.

    Parameters
    ----------
    name : str
        Name of the part, e.g. ``"body"`` or ``"table 1 top"``.
    group : str
        Object the part belongs to, e.g. ``"piano"``, ``"table 1"``, ``"walls"``.
    center : tuple of float
        Centre ``(x, y, z)`` (metres).
    half : tuple of float
        Half extents ``(hx, hy, hz)`` (metres, each > 0).
    """

    name: str
    group: str
    center: tuple[float, float, float]
    half: tuple[float, float, float]

    @property
    def lo(self) -> FloatArray:
        """Lower corner, shape ``(3,)``."""
        return np.asarray(self.center) - np.asarray(self.half)

    @property
    def hi(self) -> FloatArray:
        """Upper corner, shape ``(3,)``."""
        return np.asarray(self.center) + np.asarray(self.half)

    @property
    def area(self) -> float:
        """Surface area (square metres)."""
        hx, hy, hz = self.half
        return 8.0 * (hx * hy + hx * hz + hy * hz)

    def translated(self, offset: npt.ArrayLike) -> Box:
        """Return the box moved by ``offset`` ``(3,)``."""
        c = np.asarray(self.center, dtype=float) + np.asarray(offset, dtype=float)
        return Box(self.name, self.group, (float(c[0]), float(c[1]), float(c[2])), self.half)

    def sample_surface(self, n: int, rng: np.random.Generator) -> FloatArray:
        """Sample the surface uniformly (each face with probability proportional to its area).

        Parameters
        ----------
        n : int
            Number of points.
        rng : numpy.random.Generator
            Source of randomness.

        Returns
        -------
        ndarray, shape (n, 3)
            Points on the surface.
        """
        half = np.asarray(self.half, dtype=float)
        # Faces: axis k at -h_k or +h_k; area of a face normal to k is 4 h_u h_v.
        face_area = np.array([4.0 * half[(k + 1) % 3] * half[(k + 2) % 3] for k in range(3)])
        probs = np.repeat(face_area, 2) / (2.0 * face_area.sum())
        face = rng.choice(6, size=n, p=probs)
        axis, sign = face // 2, np.where(face % 2 == 0, -1.0, 1.0)
        u = rng.uniform(-1.0, 1.0, size=(n, 3)) * half
        u[np.arange(n), axis] = sign * half[axis]
        return np.asarray(self.center, dtype=float) + u


def box_distance(a: Box, b: Box) -> float:
    """Signed distance between the surfaces of two axis-aligned boxes.

    Parameters
    ----------
    a, b : Box
        The boxes.

    Returns
    -------
    float
        The Euclidean distance between the boxes if they are disjoint; otherwise
        minus the penetration depth (the smallest translation along an axis that
        separates them), so 0 means touching.
    """
    d = np.abs(np.asarray(a.center) - np.asarray(b.center)) - (
        np.asarray(a.half) + np.asarray(b.half)
    )
    if np.any(d > 0.0):
        return float(np.linalg.norm(np.maximum(d, 0.0)))
    return float(np.max(d))


def sample_boxes(
    boxes: list[Box], density: float | list[float], rng: np.random.Generator
) -> FloatArray:
    """Sample the surfaces of several boxes at a given density.

    Parameters
    ----------
    boxes : list of Box
        The boxes.
    density : float or list of float
        Points per square metre, one for all boxes or one per box. Each box gets
        ``round(density * area)`` points (at least one).
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    ndarray, shape (n, 3)
        The points, box after box.
    """
    if isinstance(density, (int, float)):
        dens = [float(density)] * len(boxes)
    else:
        dens = [float(d) for d in density]
    if len(dens) != len(boxes):
        raise ValueError(f"{len(dens)} densities for {len(boxes)} boxes")
    parts = [b.sample_surface(max(1, round(d * b.area)), rng) for b, d in zip(boxes, dens)]
    return np.concatenate(parts, axis=0)


def _piano_boxes() -> list[Box]:
    """Make the parts of a grand piano, in its own frame (origin under the body's centre)."""
    return [
        Box("body", "piano", (0.0, 0.0, 0.175), (0.80, 0.75, 0.175)),
        Box("lid", "piano", (0.0, 0.0, 0.36), (0.81, 0.76, 0.01)),
        Box("keyboard", "piano", (0.0, -0.90, 0.10), (0.60, 0.15, 0.05)),
        Box("leg front left", "piano", (-0.70, -0.65, -0.25), (0.04, 0.04, 0.25)),
        Box("leg front right", "piano", (0.70, -0.65, -0.25), (0.04, 0.04, 0.25)),
        Box("leg back", "piano", (0.0, 0.65, -0.25), (0.04, 0.04, 0.25)),
    ]


def _table_boxes(
    name: str, center_xy: tuple[float, float], half_xy: tuple[float, float], height: float
) -> list[Box]:
    """Make a table: a 4 cm top whose upper face is at ``height``, and four 5 cm legs."""
    x, y = center_xy
    hx, hy = half_xy
    top = Box(f"{name} top", name, (x, y, height - 0.02), (hx, hy, 0.02))
    leg_h = (height - 0.04) / 2.0
    legs = [
        Box(
            f"{name} leg {k}",
            name,
            (x + sx * (hx - 0.05), y + sy * (hy - 0.05), leg_h),
            (0.025, 0.025, leg_h),
        )
        for k, (sx, sy) in enumerate([(-1, -1), (1, -1), (-1, 1), (1, 1)])
    ]
    return [top, *legs]


def _room_boxes() -> list[Box]:
    """Make a 6 m x 5 m x 2.6 m room (floor, four 10 cm walls) with three tables."""
    hx, hy, h, t = 3.0, 2.5, 2.6, 0.05
    shell = [
        Box("floor", "floor", (0.0, 0.0, -t), (hx + 2 * t, hy + 2 * t, t)),
        Box("wall north", "walls", (0.0, hy + t, h / 2), (hx + 2 * t, t, h / 2)),
        Box("wall south", "walls", (0.0, -hy - t, h / 2), (hx + 2 * t, t, h / 2)),
        Box("wall east", "walls", (hx + t, 0.0, h / 2), (t, hy, h / 2)),
        Box("wall west", "walls", (-hx - t, 0.0, h / 2), (t, hy, h / 2)),
    ]
    tables = [
        *_table_boxes("table 1", (0.0, 0.0), (0.25, 0.20), 0.75),
        *_table_boxes("table 2", (1.9, 1.5), (0.60, 0.40), 0.75),
        *_table_boxes("table 3", (-1.8, -1.4), (0.45, 0.45), 0.45),
    ]
    return shell + tables


@dataclass(frozen=True, eq=False)
class Scene:
    """A piano and a room, as noisy point clouds and exact boxes.

    Attributes
    ----------
    piano_points : ndarray, shape (n, 3)
        Noisy piano surface points in the piano's own frame.
    room_points : ndarray, shape (m, 3)
        Noisy room surface points in the world frame.
    piano_boxes : list of Box
        The piano's parts in its own frame.
    room_boxes : list of Box
        The room's parts (floor, walls, tables) in the world frame.
    sigma : float
        Standard deviation of the noise that was added (metres).
    table : str
        Group name of the table the piano is placed above.
    """

    piano_points: FloatArray
    room_points: FloatArray
    piano_boxes: list[Box]
    room_boxes: list[Box]
    sigma: float
    table: str = "table 1"
    groups: tuple[str, ...] = field(default=())

    def piano_pose(self, gap: float) -> FloatArray:
        """Pose that puts the piano's underside ``gap`` metres above the table top.

        Parameters
        ----------
        gap : float
            Exact gap between the body's underside and the table top (metres);
            negative values sink the piano into the table.

        Returns
        -------
        ndarray, shape (4, 4)
            Homogeneous transform from the piano's frame to the world.
        """
        top = next(b for b in self.room_boxes if b.name == f"{self.table} top")
        pose = np.eye(4)
        pose[:3, 3] = (top.center[0], top.center[1], float(top.hi[2]) + gap)
        return pose

    def gaps(self, pose: npt.ArrayLike) -> dict[str, float]:
        """Exact signed gap between the piano at ``pose`` and each room group.

        Parameters
        ----------
        pose : array_like, shape (4, 4)
            Pose of the piano; must be a pure translation (the boxes stay
            axis-aligned).

        Returns
        -------
        dict of str to float
            Group name (``"floor"``, ``"walls"``, ``"table 1"``, ...) to the
            smallest signed box distance (metres; negative = interpenetration).
        """
        pose = np.asarray(pose, dtype=float)
        if not np.allclose(pose[:3, :3], np.eye(3)):
            raise ValueError("exact gaps need a pose without rotation")
        moved = [b.translated(pose[:3, 3]) for b in self.piano_boxes]
        out: dict[str, float] = {}
        for r in self.room_boxes:
            d = min(box_distance(p, r) for p in moved)
            out[r.group] = min(out.get(r.group, np.inf), d)
        return out

    def exact_gap(self, pose: npt.ArrayLike) -> float:
        """Smallest exact signed gap between the piano at ``pose`` and the room (metres)."""
        return min(self.gaps(pose).values())


def build_scene(
    sigma: float = 0.005, points: int = 3000, seed: int = 0, shell_ratio: float = 30.0
) -> Scene:
    """Build the piano-in-a-room scene.

    Parameters
    ----------
    sigma : float, default 0.005
        Standard deviation of the isotropic Gaussian noise added to every point
        (metres).
    points : int, default 3000
        Approximate number of piano points. The piano and the tables are sampled
        at the density this gives; the floor and walls at ``shell_ratio`` times
        less (the room has about as many points as the piano).
    seed : int, default 0
        Seed of the numpy generator (sampling and noise).
    shell_ratio : float, default 30
        How much sparser the floor and walls are sampled than the furniture.

    Returns
    -------
    Scene
        The clouds and the exact geometry.
    """
    if points < 10:
        raise ValueError(f"points must be >= 10, got {points}")
    if not (np.isfinite(sigma) and sigma >= 0.0):
        raise ValueError(f"sigma must be finite and >= 0, got {sigma}")
    rng = np.random.default_rng(seed)
    piano = _piano_boxes()
    room = _room_boxes()
    density = points / sum(b.area for b in piano)
    room_density = [
        density / shell_ratio if b.group in ("floor", "walls") else density for b in room
    ]
    piano_pts = sample_boxes(piano, density, rng)
    room_pts = sample_boxes(room, room_density, rng)
    piano_pts = piano_pts + rng.normal(0.0, sigma, size=piano_pts.shape)
    room_pts = room_pts + rng.normal(0.0, sigma, size=room_pts.shape)
    groups = tuple(dict.fromkeys(b.group for b in room))
    return Scene(piano_pts, room_pts, piano, room, float(sigma), "table 1", groups)
