"""The plotly renderer of a view: :func:`to_figure` (needs ``plotly``, in ``cloudprox[view]``).

``write_html(scene, path, renderer="plotly")`` writes its figure as one HTML file.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from cloudprox.view._common import (
    COLORSCALE,
    QUIET_CELLS,
    REGION_COLOR,
    bounds,
    focus,
    loud_order,
    need,
    normal_length,
    padded_bounds,
    patch_text,
    quiet_shown,
)

if TYPE_CHECKING:
    from cloudprox.view.scene import MeshLayer, PointLayer, Scene

__all__ = ["to_figure"]

#: Sets ``window.cloudproxDrawn`` two frames after the figure is drawn (benches, tests).
PLOTLY_DRAWN = (
    "requestAnimationFrame(function(){requestAnimationFrame(function(){"
    "window.cloudproxDrawn=performance.now()})})"
)

#: The probability scale of the drawn points and links.
_SCALE = {"colorscale": COLORSCALE, "cmin": 0.0, "cmax": 1.0}


def to_figure(scene: Scene, *, all_points: bool = True) -> Any:
    """Build the plotly figure of a scene (needs ``plotly``, in ``cloudprox[view]``).

    Parameters
    ----------
    scene : Scene
        From :func:`~cloudprox.view.collision_scene` or :func:`~cloudprox.view.robot_scene`.
    all_points : bool, default True
        Draw every point with ``p < quiet_below``; else thin them as
        :func:`~cloudprox.view.to_k3d` does.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    go = need("plotly.graph_objects", "view")
    fig = go.Figure()
    cell = None if all_points else scene.extent() / QUIET_CELLS
    # The colour bar has a trace of its own (one invisible point inside the
    # scene): it shows even when no point reaches quiet_below.
    fig.add_trace(_colorbar_trace(go, bounds(scene)[0]))
    for layer in scene.points:
        for trace in _point_traces(go, layer, scene.quiet_below, cell):
            fig.add_trace(trace)
    for m in scene.meshes:
        fig.add_trace(_mesh_trace(go, m))
    if scene.regions:
        for trace in _patch_traces(go, scene):
            fig.add_trace(trace)
    fig.update_layout(**_layout(scene))
    return fig


def _hover(name: str) -> str:
    return (
        f"<b>{name}</b><br>p = %{{customdata:.4g}}<br>"
        "(%{x:.4f}, %{y:.4f}, %{z:.4f})<extra></extra>"
    )


def _xyz(points: np.ndarray) -> dict[str, Any]:
    return {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2]}


def _colorbar_trace(go: Any, corner: np.ndarray) -> Any:
    colorbar = {
        "title": {"text": "collision<br>probability p", "side": "top"},
        "len": 0.75,
        "thickness": 18,
        "x": 1.0,
    }
    marker = {"size": 0.1, "opacity": 0.0, "color": [0.0], **_SCALE}
    return go.Scatter3d(
        x=[float(corner[0])],
        y=[float(corner[1])],
        z=[float(corner[2])],
        mode="markers",
        marker={**marker, "showscale": True, "colorbar": colorbar},
        showlegend=False,
        hoverinfo="skip",
        name="colour bar",
    )


def _point_traces(go: Any, layer: PointLayer, quiet_below: float, cell: float | None) -> list[Any]:
    """Trace a side's quiet points in its colour (if drawn), then the others."""
    pts, prob = layer.points, layer.probabilities
    traces = []
    shown = quiet_shown(layer, quiet_below, cell)
    if layer.show_quiet and len(shown):
        quiet = int(np.sum(prob < quiet_below))
        count = f"{len(pts)}" if len(shown) == quiet else f"{len(shown)} of {len(pts)}"
        traces.append(
            go.Scatter3d(
                **_xyz(pts[shown]),
                mode="markers",
                name=f"{layer.name}: {count} points",
                marker={"size": 1.5, "color": layer.color},
                customdata=prob[shown],
                hovertemplate=_hover(layer.name),
            )
        )
    loud = loud_order(prob, quiet_below)
    traces.append(
        go.Scatter3d(
            **_xyz(pts[loud]),
            mode="markers",
            name=f"{layer.name}: {len(loud)} with p ≥ {quiet_below:g}",
            marker={"size": 3.5, "color": prob[loud], **_SCALE},
            customdata=prob[loud],
            hovertemplate=_hover(layer.name),
        )
    )
    return traces


def _mesh_trace(go: Any, m: MeshLayer) -> Any:
    """Trace a mesh in its colour, or (a robot link) on the probability scale."""
    common = {
        **_xyz(m.vertices),
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
        return go.Mesh3d(color=m.color, **common)
    intensity = np.full(len(m.vertices), m.probability, dtype=np.float32)
    return go.Mesh3d(intensity=intensity, showscale=False, **_SCALE, **common)


def _patch_traces(go: Any, scene: Scene) -> list[Any]:
    """Trace the patches' normals, markers (hover texts) and hidden surfaces."""
    length = normal_length(scene)
    xs: list[float | None] = []
    ys: list[float | None] = []
    zs: list[float | None] = []
    for r in scene.regions:
        if not (np.all(np.isfinite(r.point)) and np.all(np.isfinite(r.normal))):
            continue
        tip = r.point + length * r.normal
        for arr, k in ((xs, 0), (ys, 1), (zs, 2)):
            arr += [float(r.point[k]), float(tip[k]), None]
    normals = go.Scatter3d(
        x=xs,
        y=ys,
        z=zs,
        mode="lines",
        line={"color": REGION_COLOR, "width": 5},
        name="patch normals (A → B)",
        hoverinfo="skip",
    )
    markers = go.Scatter3d(
        **_xyz(np.array([r.point for r in scene.regions], dtype=np.float64)),
        mode="markers",
        marker={"size": 5, "color": REGION_COLOR, "symbol": "diamond"},
        name=f"contact patches ({len(scene.regions)})",
        hovertext=[patch_text(r) for r in scene.regions],
        hovertemplate="%{hovertext}<extra></extra>",
    )
    return [normals, markers, *_surface_traces(go, scene)]


def _surface_traces(go: Any, scene: Scene) -> list[Any]:
    """Trace the patches' separating surfaces, hidden until shown in the legend."""
    traces = []
    for r in scene.regions:
        if r.surface is None:
            continue
        v, f = r.surface
        traces.append(
            go.Mesh3d(
                **_xyz(v.astype(np.float32)),
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
    return traces


def _camera(scene: Scene, lo: np.ndarray, hi: np.ndarray) -> dict[str, Any]:
    """Look at the contact (the points with p >= quiet_below) from the default direction.

    As close as the contact's size allows; plotly's camera coordinates put the
    scene box's centre at 0 with its largest side 1 long.
    """
    near = focus(scene)
    if near is None:
        return {}
    size = float((hi - lo).max())
    centre = (near[0] - (lo + hi) / 2.0) / size
    distance = 2.165 * min(1.0, max(2.0 * near[1] / size, 0.12))
    eye = centre + distance * np.full(3, 1.0 / math.sqrt(3.0))
    return {
        "center": dict(zip("xyz", centre.tolist(), strict=False)),
        "eye": dict(zip("xyz", eye.tolist(), strict=False)),
    }


def _layout(scene: Scene) -> dict[str, Any]:
    """Lay out the figure's title, axes (the padded box of the scene), camera and legend."""
    lo, hi = padded_bounds(scene)
    size = float((hi - lo).max())
    axis = {"showbackground": True, "backgroundcolor": "#f4f4f4", "gridcolor": "#d0d0d0"}
    return {
        "title": {"text": scene.title, "x": 0.01, "font": {"size": 15}},
        "scene": {
            "aspectmode": "manual",
            "aspectratio": dict(zip("xyz", ((hi - lo) / size).tolist(), strict=False)),
            "camera": _camera(scene, lo, hi),
            "xaxis": {"title": {"text": "x (m)"}, "range": [lo[0], hi[0]], **axis},
            "yaxis": {"title": {"text": "y (m)"}, "range": [lo[1], hi[1]], **axis},
            "zaxis": {"title": {"text": "z (m)"}, "range": [lo[2], hi[2]], **axis},
        },
        "legend": {
            "x": 0.0,
            "y": 0.92,
            "bgcolor": "rgba(255,255,255,0.7)",
            "itemsizing": "constant",
        },
        "margin": {"l": 0, "r": 0, "t": 60, "b": 0},
        "paper_bgcolor": "white",
        "hoverlabel": {"namelength": -1},
    }
