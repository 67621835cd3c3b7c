"""What the view's renderers share: colours, sizes, the box and the focus of a scene."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from cloudprox.view.scene import PointLayer, RegionMark, Scene

#: The colour scale of probabilities (matplotlib's and plotly's "plasma").
COLORSCALE = "Plasma"
#: Colours of the two sides' points below ``quiet_below`` (side A, side B).
SIDE_COLORS = ("#2ca58d", "#8d99ae")
#: Colour of the contact patches' points and normals.
REGION_COLOR = "#d62728"
#: Quiet points are thinned to one a cubic cell of ``extent / QUIET_CELLS``: the
#: size of one drawn quiet point (2 pixels) when the whole scene fills a view
#: about 800 pixels across.
QUIET_CELLS = 400
#: Pixel sizes of the drawn points (below and above ``quiet_below``, regions).
POINT_PIXELS = (2.0, 5.0, 11.0)
#: How many contact patches (the most probable) carry a text label in the view.
REGION_LABELS = 3


def need(module: str, extra: str) -> Any:
    """Import ``module``, or say which extra of cloudprox installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"this view needs the '{module.split('.')[0]}' package: "
            f"pip install 'cloudprox[{extra}]'"
        ) from None


def rgb(probabilities: np.ndarray) -> np.ndarray:
    """Return the plasma colours of ``probabilities`` as ``(n, 3)`` bytes."""
    from matplotlib import colormaps

    rgba = colormaps["plasma"](np.clip(probabilities, 0.0, 1.0))
    return (rgba[:, :3] * 255.0).round().astype(np.uint8)


def hex_rgb(color: str) -> np.ndarray:
    """Return ``"#rrggbb"`` as three bytes."""
    c = color.lstrip("#")
    return np.array([int(c[i : i + 2], 16) for i in (0, 2, 4)], dtype=np.uint8)


def bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Return the corners of the box around everything the scene draws."""
    parts = [np.asarray(x.points, dtype=np.float64) for x in scene.points if len(x.points)]
    parts += [np.asarray(m.vertices, dtype=np.float64) for m in scene.meshes]
    allp = np.concatenate(parts) if parts else np.zeros((1, 3))
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    if not len(allp):
        return np.zeros(3), np.ones(3)
    return allp.min(axis=0), allp.max(axis=0)


def padded_bounds(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Return :func:`bounds` grown by 2 % of its largest side."""
    lo, hi = bounds(scene)
    pad = 0.02 * float((hi - lo).max()) + 1e-9
    return lo - pad, hi + pad


def focus(scene: Scene) -> tuple[np.ndarray, float] | None:
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


def normal_length(scene: Scene) -> float:
    """Length of the drawn patch normals: a share of the contact's size."""
    extent = scene.extent()
    near = focus(scene)
    return 0.08 * extent if near is None else max(0.4 * near[1], 0.005 * extent)


def finite_marks(scene: Scene) -> list[RegionMark]:
    """Return the scene's patches with a finite point and normal (those drawn)."""
    return [
        r for r in scene.regions if np.all(np.isfinite(r.point)) and np.all(np.isfinite(r.normal))
    ]


def patch_text(mark: RegionMark) -> str:
    """Return the HTML hover text of one contact patch."""
    n = mark.normal
    return (
        f"<b>{mark.label}</b><br>P = {mark.probability:.4g}<br>separation "
        f"{1e3 * mark.separation:+.2f} mm<br>normal ({n[0]:+.3f}, "
        f"{n[1]:+.3f}, {n[2]:+.3f})<br>points {mark.points[0]} + {mark.points[1]}"
    )


def quiet_shown(layer: PointLayer, quiet_below: float, cell: float | None) -> np.ndarray:
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


def loud_order(probabilities: np.ndarray, quiet_below: float) -> np.ndarray:
    """Return the indices of the points with ``p >= quiet_below``, least probable first."""
    loud = np.flatnonzero(probabilities >= quiet_below)
    return loud[np.argsort(probabilities[loud], kind="stable")]
