"""The k3d renderer of a view: :func:`to_k3d` and :func:`k3d_page` (needs ``cloudprox[view]``).

The HTML file of :func:`~cloudprox.view.write_html` is this renderer's page: k3d
(three.js) with its JavaScript inlined, so it opens without a server or the
internet, fast even without a GPU (every point is one WebGL point).
"""

from __future__ import annotations

import base64
import html
import json
import math
import re
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cloudprox.view._common import (
    POINT_PIXELS,
    QUIET_CELLS,
    REGION_COLOR,
    REGION_LABELS,
    finite_marks,
    focus,
    hex_rgb,
    loud_order,
    need,
    normal_length,
    padded_bounds,
    patch_text,
    quiet_shown,
    rgb,
)

if TYPE_CHECKING:
    from cloudprox.view.scene import PointLayer, RegionMark, Scene

__all__ = ["k3d_page", "to_k3d"]

#: The vertical field of view of the k3d camera (degrees).
FOV = 45.0


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
        From :func:`~cloudprox.view.collision_scene` or :func:`~cloudprox.view.robot_scene`.
    all_points : bool, default False
        Draw every quiet point too.

    Returns
    -------
    k3d.plot.Plot
        :func:`k3d_page` makes it the HTML that :func:`~cloudprox.view.write_html` writes.
    """
    k3d = need("k3d", "view")
    lo, hi = padded_bounds(scene)
    build = _Build(k3d, _k3d_plot(k3d, scene, lo, hi), scene)
    build.legend.append(f"<b>{scene.title}</b>")
    cell = None if all_points else scene.extent() / QUIET_CELLS
    for layer in scene.points:
        if layer.show_quiet:
            build.quiet_points(layer, cell)
        build.loud_points(layer)
    for m in scene.meshes:
        color = m.color if m.probability is None else f"#{_plasma_packed(m.probability):06x}"
        build.mesh(
            m.vertices,
            m.faces,
            m.name,
            m.hover or m.name,
            color=_packed(color),
            opacity=m.opacity,
            flat_shading=True,
        )
    marks = finite_marks(scene)
    if marks:
        build.patches(marks)
    build.surfaces()
    build.finish(lo)
    return build.plot


def _k3d_plot(k3d: Any, scene: Scene, lo: np.ndarray, hi: np.ndarray) -> Any:
    """Make an empty plot: the grid on the scene's box, the camera on its contact."""
    plot = k3d.plot(
        antialias=0,  # multisampling doubles the time software WebGL takes to draw
        camera_auto_fit=False,
        grid_auto_fit=False,
        grid=(*lo.tolist(), *hi.tolist()),
        grid_color=0xD0D0D0,
        background_color=0xFFFFFF,
        camera_fov=FOV,
        menu_visibility=True,
        mode="callback",  # hovering an object fires OBJECT_HOVERED (the tooltips)
        axes=["x (m)", "y (m)", "z (m)"],
    )
    plot.camera = _k3d_camera(scene, lo, hi, FOV)
    return plot


def _hovered(*_: Any) -> None:
    """Mark an object as hoverable in the browser (k3d's ``hover_callback``)."""
    return None


@dataclass
class _Build:
    """A k3d plot being filled: its objects, their hover texts, the legend's lines."""

    k3d: Any
    plot: Any
    scene: Scene
    #: The hover data of the objects by name, read by the page's script (``_K3D_JS``).
    info: dict[str, dict[str, Any]] = field(default_factory=dict)
    legend: list[str] = field(default_factory=list)
    #: The object whose colour map the colour bar shows (-1: none yet).
    bar_id: int = -1

    def points(self, pts: np.ndarray, name: str, **options: Any) -> Any:
        obj = self.k3d.points(pts, shader="dot", name=name, **options)
        self.plot += obj
        return obj

    def quiet_points(self, layer: PointLayer, cell: float | None) -> None:
        """Draw the side's points below ``quiet_below``, thinned to one a ``cell``."""
        below = self.scene.quiet_below
        pts = np.asarray(layer.points, dtype=np.float32)
        prob = np.asarray(layer.probabilities, dtype=np.float32)
        shown = quiet_shown(layer, below, cell)
        total = int(np.sum(prob < below))
        if len(shown):
            name = f"{layer.name}: {len(shown)} of {total} points with p < {below:g}"
            self.points(
                pts[shown],
                name,
                attribute=prob[shown],
                color_map=_flat_map(layer.color),
                color_range=[0.0, 1.0],
                point_size=POINT_PIXELS[0],
                hover_callback=_hovered,
            )
            self.info[name] = {"side": layer.name}
        thinned = ""
        if cell is not None and len(shown) < total:
            thinned = f" (one a {1e3 * cell:.2g} mm cell)"
        self.legend.append(
            f"<span style='color:{layer.color}'>&#9632;</span> {layer.name}: "
            f"{len(shown)} of {total} points with p &lt; {below:g} drawn{thinned}"
        )

    def loud_points(self, layer: PointLayer) -> None:
        """Draw the side's points at or above ``quiet_below``, all, on the plasma scale."""
        below = self.scene.quiet_below
        pts = np.asarray(layer.points, dtype=np.float32)
        prob = np.asarray(layer.probabilities, dtype=np.float32)
        loud = loud_order(prob, below)
        if len(loud):
            name = f"{layer.name}: {len(loud)} with p ≥ {below:g}"
            obj = self.points(
                pts[loud],
                name,
                attribute=prob[loud],
                color_map=self.k3d.colormaps.matplotlib_color_maps.plasma,
                color_range=[0.0, 1.0],
                point_size=POINT_PIXELS[1],
                hover_callback=_hovered,
            )
            self.bar_id = obj.id if self.bar_id < 0 else self.bar_id
            self.info[name] = {"side": layer.name}
        self.legend.append(f"{layer.name}: {len(loud)} points with p ≥ {below:g}, all drawn")

    def mesh(
        self, vertices: np.ndarray, faces: np.ndarray, name: str, text: str, **options: Any
    ) -> None:
        self.plot += self.k3d.mesh(
            np.asarray(vertices, dtype=np.float32),
            np.asarray(faces, dtype=np.uint32),
            side="double",
            name=name,
            hover_callback=_hovered,
            **options,
        )
        self.info[name] = {"text": text}

    def patches(self, marks: list[RegionMark]) -> None:
        """Draw the patches' markers (hover texts), normals and top labels."""
        length = normal_length(self.scene)
        at = np.array([r.point for r in marks], dtype=np.float32)
        name = f"contact patches ({len(marks)})"
        red = _packed(REGION_COLOR)
        self.points(at, name, color=red, point_size=POINT_PIXELS[2], hover_callback=_hovered)
        texts = [patch_text(r) for r in marks]
        self.info[name] = {"texts": texts}
        points = [r.point.tolist() for r in marks]
        self.info["__regions__"] = {"name": name, "points": points, "texts": texts}
        self.plot += self.k3d.vectors(
            at,
            np.array([length * r.normal for r in marks], dtype=np.float32),
            color=red,
            head_size=length,  # k3d's arrow head: a cone 0.2 head_size long
            line_width=0.06 * length,
            name="patch normals (A → B)",
        )
        # The most probable regions carry a label (all of them a hover text).
        for r in sorted(marks, key=lambda r: -r.probability)[:REGION_LABELS]:
            self.plot += self.k3d.label(
                f"{r.label}: P = {r.probability:.3g}, {1e3 * r.separation:+.2f} mm",
                position=(r.point + length * r.normal).astype(np.float32),
                color=red,
                is_html=True,
                size=0.8,
                mode="local",
                name=f"label of {r.label}",
            )
        self.legend.append(
            f"<span style='color:{REGION_COLOR}'>&#9670;</span> {len(marks)} contact patches "
            "with normals (A → B) and separations: hover a marker"
        )

    def surfaces(self) -> None:
        """Draw the patches' separating surfaces, hidden at first."""
        drawn = [r for r in self.scene.regions if r.surface is not None]
        for r in drawn:
            assert r.surface is not None
            name = f"separating surface, {r.label} (P = {r.probability:.3g})"
            v, f = r.surface
            text = f"separating surface of {r.label}"
            self.mesh(v, f, name, text, color=0x1F77B4, opacity=0.5, visible=False)
        if drawn:
            self.legend.append("separating surfaces: K3D panel, Objects (hidden at first)")

    def finish(self, corner: np.ndarray) -> None:
        """Add the colour bar, the legend and the page's script."""
        if self.bar_id < 0:
            # The colour bar shows one object's map: with no loud point, a carrier
            # of two points drawn fully transparent.
            obj = self.points(
                np.repeat(corner[None].astype(np.float32), 2, axis=0),
                "colour bar",
                attribute=np.array([0.0, 1.0], dtype=np.float32),
                color_map=self.k3d.colormaps.matplotlib_color_maps.plasma,
                color_range=[0.0, 1.0],
                point_size=1.0,
                opacity=0.0,
            )
            self.bar_id = obj.id
        self.plot.colorbar_object_id = self.bar_id
        self.plot += self.k3d.text2d(
            "<br>".join(self.legend),
            position=(0.005, 0.005),
            reference_point="lt",
            is_html=True,
            size=0.8,
            color=0x333333,
            label_box=True,
            name="legend",
        )
        info = json.dumps(self.info).replace("</", "<\\/")
        self.plot.additional_js_code = _K3D_JS.replace("__INFO__", info)


def _packed(color: str) -> int:
    return int(color.lstrip("#"), 16)


def _plasma_packed(p: float) -> int:
    r, g, b = (int(x) for x in rgb(np.array([p]))[0])
    return (r << 16) | (g << 8) | b


def _flat_map(color: str) -> list[float]:
    """Make a k3d colour map of one colour (the probabilities ride along as the attribute)."""
    r, g, b = (float(x) / 255.0 for x in hex_rgb(color))
    return [0.0, r, g, b, 1.0, r, g, b]


def _k3d_camera(scene: Scene, lo: np.ndarray, hi: np.ndarray, fov: float) -> list[float]:
    """Look at the contact from the (1, 1, 1) direction, as the plotly figure does."""
    size = float((hi - lo).max())
    near = focus(scene)
    if near is None:
        centre, distance = (lo + hi) / 2.0, 2.165 * size
    else:
        centre = near[0]
        distance = 2.165 * size * min(1.0, max(2.0 * near[1] / size, 0.12))
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
    k3d = need("k3d", "view")
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
