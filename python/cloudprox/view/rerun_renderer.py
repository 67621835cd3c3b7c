"""The Rerun renderer of a view: :func:`write_rerun` (needs ``cloudprox[rerun]``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cloudprox.view._common import REGION_COLOR, hex_rgb, need, rgb

if TYPE_CHECKING:
    from cloudprox.view.scene import Scene

__all__ = ["write_rerun"]


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
        From :func:`~cloudprox.view.collision_scene` or :func:`~cloudprox.view.robot_scene`.
    path : str or Path
        The ``.rrd`` file to write.
    application_id : str, default "cloudprox"
        The recording's application id.

    Returns
    -------
    Path
        ``path``.
    """
    rr = need("rerun", "rerun")
    path = Path(path)
    rec = rr.RecordingStream(application_id)
    rec.save(str(path))
    rec.log("summary", rr.TextDocument(scene.title.replace("<br>", "\n")), static=True)
    _log_points(rr, rec, scene)
    _log_meshes(rr, rec, scene)
    if scene.regions:
        _log_patches(rr, rec, scene)
    rec.flush()
    rec.disconnect()
    return path


def _entity(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name) or "_"


def _log_points(rr: Any, rec: Any, scene: Scene) -> None:
    """Log each side's points, the quiet ones small in the side's colour."""
    radius = 0.002 * scene.extent()
    for k, layer in enumerate(scene.points):
        prob = layer.probabilities
        colors = rgb(prob)
        quiet = prob < scene.quiet_below
        colors[quiet] = hex_rgb(layer.color)
        keep = np.ones(len(prob), dtype=bool) if layer.show_quiet else ~quiet
        radii = np.where(quiet, radius, 2.0 * radius).astype(np.float32)
        rec.log(
            f"points/{k}_{_entity(layer.name)}",
            rr.Points3D(layer.points[keep], colors=colors[keep], radii=radii[keep]),
            rr.AnyValues(probability=prob[keep].astype(np.float64)),
            static=True,
        )


def _log_meshes(rr: Any, rec: Any, scene: Scene) -> None:
    """Log the mesh sides in their colour, the robot's links on the probability scale."""
    for m in scene.meshes:
        if m.probability is None:
            color = np.append(hex_rgb(m.color), int(255 * m.opacity)).astype(np.uint8)
        else:
            color = np.append(rgb(np.array([m.probability]))[0], 255).astype(np.uint8)
        rec.log(
            f"meshes/{_entity(m.name)}",
            rr.Mesh3D(
                vertex_positions=m.vertices,
                triangle_indices=m.faces.astype(np.uint32),
                albedo_factor=color,
            ),
            static=True,
        )


def _log_patches(rr: Any, rec: Any, scene: Scene) -> None:
    """Log the patches' normals as labelled arrows, and their separating surfaces."""
    length = 0.08 * scene.extent()
    rec.log(
        "regions",
        rr.Arrows3D(
            origins=np.array([r.point for r in scene.regions], dtype=np.float32),
            vectors=np.array([length * r.normal for r in scene.regions], dtype=np.float32),
            colors=hex_rgb(REGION_COLOR),
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
