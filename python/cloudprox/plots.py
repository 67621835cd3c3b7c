"""Figures of collision results (matplotlib, imported lazily, drawn with Agg).

Nothing here touches pyplot's global state: figures are made with
``matplotlib.figure.Figure`` and rendered by the Agg canvas, so the module works
headless and does not change the backend of a program that also uses pyplot.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from cloudprox._native import CollisionResult

__all__ = [
    "SIDE_COLORS",
    "Panel",
    "contact_bounds",
    "plot_collision",
    "plot_collisions",
    "world_points",
]

_CMAP = "plasma"
#: Colours of the two clouds' points below ``quiet_below`` (A, B); the same as the
#: interactive view's (:mod:`cloudprox.view`).
SIDE_COLORS = ("#2ca58d", "#8d99ae")


def contact_bounds(
    points_a: npt.ArrayLike,
    points_b: npt.ArrayLike,
    result: CollisionResult,
    quiet_below: float = 1e-3,
    margin: float = 0.5,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Return the box around the contact: the points with ``p_i >= quiet_below``.

    Parameters
    ----------
    points_a, points_b : array_like, shapes (n_a, 3) and (n_b, 3)
        The clouds in the world frame.
    result : CollisionResult
        The query's result.
    quiet_below : float, default 1e-3
        Points below this probability do not count.
    margin : float, default 0.5
        Each side of the box grows by this fraction of its length, plus 3 % of the
        clouds' extent (so a flat contact keeps some depth).

    Returns
    -------
    tuple of two ndarray of shape (3,), or None
        ``(lo, hi)``; ``None`` when no point reaches ``quiet_below``.
    """
    pa = np.asarray(points_a, dtype=float)
    pb = np.asarray(points_b, dtype=float)
    loud = [
        pa[np.asarray(result.probabilities_a) >= quiet_below],
        pb[np.asarray(result.probabilities_b) >= quiet_below],
    ]
    loud += [np.asarray(r.point, dtype=float)[None] for r in result.patches]
    near = np.concatenate([x for x in loud if len(x)] or [np.zeros((0, 3))])
    near = near[np.all(np.isfinite(near), axis=1)]
    if not len(near):
        return None
    everything = np.concatenate([pa, pb])
    floor = 0.03 * float(np.ptp(everything, axis=0).max())
    lo, hi = near.min(axis=0), near.max(axis=0)
    pad = margin * (hi - lo) + floor
    return lo - pad, hi + pad


def world_points(points: npt.ArrayLike, pose: npt.ArrayLike | None = None) -> np.ndarray:
    """Apply a ``(4, 4)`` pose to ``(n, 3)`` points (``None`` = identity).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Points in their own frame.
    pose : array_like, shape (4, 4), optional
        Homogeneous transform to the world.

    Returns
    -------
    ndarray, shape (n, 3)
        The points in the world frame.
    """
    p = np.asarray(points, dtype=float)
    if pose is None:
        return p
    t = np.asarray(pose, dtype=float)
    return p @ t[:3, :3].T + t[:3, 3]


@dataclass(frozen=True)
class Panel:
    """One query to draw: both clouds (world frame) and the result.

    Attributes
    ----------
    points_a, points_b : ndarray, shapes (n_a, 3) and (n_b, 3)
        The clouds in the world frame (apply the query's poses first, see
        :func:`world_points`).
    result : CollisionResult
        The query's result; its per-point probabilities colour the points.
    title : str, optional
        First title line; a second line gives ``P`` and the state.
    """

    points_a: npt.ArrayLike
    points_b: npt.ArrayLike
    result: CollisionResult
    title: str | None = None


def _draw(
    ax: Any,
    panel: Panel,
    bounds: tuple[npt.ArrayLike, npt.ArrayLike] | str | None,
    labels: tuple[str, str],
    quiet_below: float,
) -> None:
    from matplotlib.colors import Normalize
    from matplotlib.ticker import MaxNLocator

    result = panel.result
    pa = np.asarray(panel.points_a, dtype=float)
    pb = np.asarray(panel.points_b, dtype=float)
    prob_a = np.asarray(result.probabilities_a)
    prob_b = np.asarray(result.probabilities_b)
    if pa.shape != (len(prob_a), 3) or pb.shape != (len(prob_b), 3):
        raise ValueError(
            f"points of shapes {pa.shape} and {pb.shape} do not match the result's "
            f"{len(prob_a)} and {len(prob_b)} probabilities"
        )
    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    if isinstance(bounds, str):
        if bounds != "contact":
            raise ValueError(f"bounds must be (lo, hi), 'contact' or None, got {bounds!r}")
        bounds = contact_bounds(pa, pb, result, quiet_below)
    if bounds is not None:
        lo, hi = (np.asarray(b, dtype=float) for b in bounds)
        keep_a = np.all((pa >= lo) & (pa <= hi), axis=1)
        keep_b = np.all((pb >= lo) & (pb <= hi), axis=1)
        pa, prob_a, pb, prob_b = pa[keep_a], prob_a[keep_a], pb[keep_b], prob_b[keep_b]

    norm = Normalize(vmin=0.0, vmax=1.0)
    clouds = (
        (pa, prob_a, "o", labels[0], SIDE_COLORS[0]),
        (pb, prob_b, "^", labels[1], SIDE_COLORS[1]),
    )
    for pts, prob, marker, label, grey in clouds:
        # Points safely on their side are small, in their cloud's colour; the
        # doubtful ones are coloured by p_i, larger, and drawn last so they stay on top.
        quiet = prob < quiet_below
        if np.any(quiet):
            ax.scatter(
                *pts[quiet].T,
                color=grey,
                s=3.0,
                alpha=0.45,
                marker=marker,
                depthshade=False,
                label=f"{label}: {len(pts)} points",
            )
        loud = np.flatnonzero(~quiet)
        loud = loud[np.argsort(prob[loud])]
        if len(loud):
            ax.scatter(
                *pts[loud].T,
                c=prob[loud],
                cmap=_CMAP,
                norm=norm,
                s=12.0 + 40.0 * prob[loud],
                marker=marker,
                depthshade=False,
                edgecolors="k",
                linewidths=0.3,
                label=f"{label}: {len(loud)} with $p_i \\geq$ {quiet_below:g}",
            )
    for region in result.patches:
        if np.any(region.point < lo) or np.any(region.point > hi):
            continue
        ax.quiver(*region.point, *(0.1 * region.normal), color="tab:green", linewidth=1.0)
    everything = np.concatenate([pa, pb]) if len(pa) + len(pb) else np.zeros((1, 3))
    extent = everything.max(axis=0) - everything.min(axis=0)
    ax.set_box_aspect(np.maximum(extent, 0.05 * (float(extent.max()) or 1.0)))
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(4))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.legend(loc="upper left", fontsize="x-small")
    head = f"{panel.title}\n" if panel.title else ""
    ax.set_title(f"{head}P = {result.probability:.4g}, state: {result.state}", fontsize="medium")


def plot_collisions(
    panels: Sequence[Panel],
    path: str | Path | None = None,
    *,
    bounds: tuple[npt.ArrayLike, npt.ArrayLike] | str | None = None,
    labels: tuple[str, str] = ("A", "B"),
    quiet_below: float = 1e-3,
    elev: float = 12.0,
    azim: float = -60.0,
    dpi: int = 110,
) -> Figure:
    """Draw several queries side by side in 3D, coloured by per-point probability.

    Parameters
    ----------
    panels : sequence of Panel
        The queries, one panel each, in a row.
    path : str or Path, optional
        Where to write the figure (format from the suffix, e.g. ``.png``).
    bounds : tuple of two array_like of shape (3,), or "contact", optional
        Only points inside this axis-aligned box ``(lo, hi)`` are drawn;
        ``"contact"``: the box around each panel's points with ``p_i >=
        quiet_below`` (see :func:`contact_bounds`), everything when there are none.
    labels : tuple of str, default ("A", "B")
        Names of the two clouds in the legends.
    quiet_below : float, default 1e-3
        Points with a smaller probability are drawn small and grey.
    elev, azim : float, default 12 and -60
        Viewing angles (degrees).
    dpi : int, default 110
        Resolution of the written file.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (attached to an Agg canvas), with one colour bar for all panels.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    if not panels:
        raise ValueError("nothing to plot: no panels")
    fig = Figure(figsize=(1.0 + 6.0 * len(panels), 5.5))
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(1, len(panels), k + 1, projection="3d") for k in range(len(panels))]
    for ax, panel in zip(axes, panels, strict=False):
        _draw(ax, panel, bounds, labels, quiet_below)
        ax.view_init(elev=elev, azim=azim)
    fig.colorbar(
        ScalarMappable(norm=Normalize(vmin=0.0, vmax=1.0), cmap=_CMAP),
        ax=axes,
        shrink=0.6,
        pad=0.08,
        label="per-point collision probability $p_i$",
    )
    if path is not None:
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
    return fig


def plot_collision(
    points_a: npt.ArrayLike,
    points_b: npt.ArrayLike,
    result: CollisionResult,
    path: str | Path | None = None,
    *,
    title: str | None = None,
    **options: Any,
) -> Figure:
    """Draw both clouds of one query in 3D, coloured by each point's collision probability.

    Parameters
    ----------
    points_a, points_b : array_like, shapes (n_a, 3) and (n_b, 3)
        The clouds in the world frame (apply the query's poses first, see
        :func:`world_points`).
    result : CollisionResult
        The query's result; its ``probabilities_a`` and ``probabilities_b`` colour
        the points.
    path : str or Path, optional
        Where to write the figure (format from the suffix, e.g. ``.png``).
    title : str, optional
        First title line; a second line gives ``P`` and the state.
    **options
        ``bounds``, ``labels``, ``quiet_below``, ``elev``, ``azim`` and ``dpi``, as in
        :func:`plot_collisions`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (attached to an Agg canvas).
    """
    return plot_collisions([Panel(points_a, points_b, result, title)], path, **options)
