"""``cloudprox info FILE``: a summary of a point-cloud, mesh or ROS bag file."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from cloudprox._native import PointCloud
from cloudprox.cli._common import CliError, add_bag_arguments, console

__all__ = ["add_parsers", "file_info"]


def file_info(path: str, topic: str | None = None, index: int | None = None) -> dict[str, Any]:
    """Summarize a point-cloud, mesh or ROS bag file as plain JSON.

    Point clouds: format, points, non-finite points skipped, the no-returns of an
    organized scan (at the sensor origin, and NaN), organized layout, fields,
    bounds, sensor pose and the estimated sampling spacing (median and 5th/95th
    percentiles of each point's distance to its 6th nearest neighbour).
    Meshes: vertices, faces (dropped degenerate ones), bounds, area, volume,
    whether closed. Bags: the topics with their message types and counts; with
    ``topic`` or ``index``, that PointCloud2 frame as a point cloud too.
    """
    from cloudprox import bags, io
    from cloudprox.pipeline import is_mesh_file

    p = Path(path)
    if not p.exists():
        raise CliError(f"{path}: no such file")
    is_bag = bags.is_bag(path)
    if p.is_dir() and not is_bag:
        raise CliError(f"{path} is a directory, expected a point-cloud or mesh file")
    if (topic is not None or index is not None) and not is_bag:
        raise CliError("--topic and --index apply to ROS bags (.bag, .db3, .mcap) only")
    info: dict[str, Any] = {"path": path, "format": p.suffix.lower().lstrip(".")}
    if is_bag:
        try:
            return _bag_info(info, path, topic, index)
        except ModuleNotFoundError as e:
            raise CliError(str(e)) from None
    if is_mesh_file(path):
        return info | _mesh_info(path)
    return info | _cloud_info(io.read_point_cloud(path))


def _bag_info(
    info: dict[str, Any], path: str, topic: str | None, index: int | None
) -> dict[str, Any]:
    """Return :func:`file_info` of a bag: its topics, and the frame asked for."""
    from cloudprox import bags

    topics = bags.topics(path)
    info |= {
        "format": info["format"] or "rosbag2",
        "kind": "ROS bag",
        "topics": [{"name": t.name, "type": t.msgtype, "messages": t.count} for t in topics],
    }
    if topic is None and index is None:
        return info
    scan = bags.read_point_cloud(path, topic, 0 if index is None else index)
    info["frame"] = {
        "topic": scan.topic,
        "index": scan.index,
        "stamp_ns": scan.stamp,
        "sensor_frame": scan.sensor_frame,
        "frame_id": scan.frame_id,
    } | _cloud_info(scan)
    return info


def _mesh_info(path: str) -> dict[str, Any]:
    """Return the mesh part of :func:`file_info`."""
    from cloudprox.pipeline import read_mesh_file

    mesh, dropped = read_mesh_file(path)
    lo, hi = mesh.bounds()
    return {
        "kind": "mesh",
        "vertices": len(mesh.vertices),
        "faces": len(mesh.faces),
        "warnings": (
            [f"{path}: dropped {dropped} degenerate face(s) that repeat a vertex"]
            if dropped
            else []
        ),
        "bounds": [lo.tolist(), hi.tolist()],
        "area_m2": mesh.area,
        "closed": mesh.is_closed,
        "volume_m3": mesh.volume if mesh.is_closed else None,
    }


def _cloud_info(scan: Any) -> dict[str, Any]:
    """Return the point-cloud part of :func:`file_info` for a ``CloudFile``."""
    pts = np.asarray(scan.points)
    info: dict[str, Any] = {
        "kind": "point cloud",
        "points": len(pts),
        "skipped_non_finite": scan.skipped,
    }
    if scan.grid_shape is not None:
        info |= {"no_returns": scan.no_returns, "no_returns_at_sensor_origin": scan.at_origin}
    info |= {
        "organized": None if scan.grid_shape is None else list(scan.grid_shape),
        "fields": scan.fields,
        "has_normals": scan.normals is not None,
        "has_covariances": scan.covariances is not None,
        "sensor_pose": None if scan.sensor_pose is None else np.asarray(scan.sensor_pose).tolist(),
        "sensor_pose_is_default": scan.sensor_pose_is_default,
    }
    if len(pts):
        info["bounds"] = [pts.min(axis=0).tolist(), pts.max(axis=0).tolist()]
    if len(pts) >= 7:
        spacing = np.asarray(PointCloud(pts, sigma=0.0).spacing)
        q05, q50, q95 = np.percentile(spacing, [5, 50, 95])
        info["spacing_m"] = {"median": q50, "p05": q05, "p95": q95}
    return info


def _print_info(out: Any, info: dict[str, Any], indent: str = "  ") -> None:
    """Print the items of a :func:`file_info` summary, one per line."""
    for key, value in info.items():
        if key in ("path", "kind", "format") or (key == "warnings" and not value):
            continue
        if key == "topics":
            out.print(f"{indent}topics: {len(value)}")
            for t in value:
                out.print(f"{indent}  {t['name']}: {t['type']}, {t['messages']} messages")
            continue
        if key == "frame":
            out.print(f"{indent}frame {value['index']} of {value['topic']}:")
            _print_info(out, value, indent + "  ")
            continue
        if key in ("no_returns_at_sensor_origin", "sensor_pose_is_default"):
            continue
        out.print(f"{indent}{key.replace('_', ' ')}: {_value_text(key, value, info)}")


def _value_text(key: str, value: Any, info: dict[str, Any]) -> Any:
    """Return one item of a :func:`file_info` summary as printed."""
    if key == "no_returns":
        at = info["no_returns_at_sensor_origin"]
        return f"{value} ({at} at the sensor origin, {value - at} non-finite)"
    if key == "bounds":
        lo, hi = value
        return (
            "["
            + ", ".join(f"{x:.4g}" for x in lo)
            + "] .. ["
            + ", ".join(f"{x:.4g}" for x in hi)
            + "]"
        )
    if key == "spacing_m":
        return (
            f"median {1e3 * value['median']:.3g} mm "
            f"(5%: {1e3 * value['p05']:.3g}, 95%: {1e3 * value['p95']:.3g})"
        )
    if key == "sensor_pose" and value is not None:
        text = "origin (" + ", ".join(f"{row[3]:.4g}" for row in value[:3]) + ")"
        if info.get("sensor_pose_is_default"):
            text += (
                ", the origin of the message's frame (no TF for it)"
                if "sensor_frame" in info
                else ", the PCD default VIEWPOINT (identity)"
            )
        return text
    if key == "fields":
        return " ".join(value)
    if isinstance(value, float):
        return f"{value:.4g}"
    return value


def _cmd_info(args: argparse.Namespace) -> int:
    info = file_info(args.file, args.topic, args.index)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    out = console()
    out.print(f"[bold]{info['path']}[/bold]: {info['kind']} ({info['format'].upper()})")
    _print_info(out, info)
    return 0


def add_parsers(sub: Any) -> None:
    """Add ``info`` to the subcommands ``sub``."""
    info = sub.add_parser(
        "info",
        help="summarize a point-cloud, mesh or ROS bag file (points, bounds, fields, topics)",
    )
    info.add_argument("file", metavar="FILE", help="point-cloud, mesh or ROS bag file")
    add_bag_arguments(info)
    info.add_argument("--json", action="store_true", help="print the summary as JSON")
    info.set_defaults(func=_cmd_info)
