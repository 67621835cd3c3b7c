"""A view as a file: :func:`write_html` (one self-contained HTML file) and :func:`show`."""

from __future__ import annotations

import os
import tempfile
import webbrowser
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cloudprox.view.k3d_renderer import k3d_page, to_k3d
from cloudprox.view.plotly_renderer import PLOTLY_DRAWN, to_figure
from cloudprox.view.scene import collision_scene

if TYPE_CHECKING:
    from cloudprox._native import CollisionResult
    from cloudprox.view.scene import Scene

__all__ = ["show", "write_html"]


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
            post_script=PLOTLY_DRAWN,
        )
    else:
        raise ValueError(f"renderer must be 'k3d' or 'plotly', got {renderer!r}")
    return path


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
        os.close(fd)
        path = Path(name)
    out = write_html(scene, path)
    if open_browser:
        webbrowser.open(out.resolve().as_uri())
    return out
