"""``cloudprox collide A B`` and ``cloudprox view A B``: one query between two files."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from cloudprox._native import CollisionResult, collide
from cloudprox.cli._common import (
    CliError,
    add_bag_arguments,
    add_filter_argument,
    add_noise_arguments,
    add_request_arguments,
    add_view_arguments,
    bag_frame,
    check_view_arguments,
    console,
    finite,
    request_from_args,
    sensor_spec,
    styled_state,
    write_views,
)

__all__ = ["add_parsers", "result_to_dict"]


def result_to_dict(result: CollisionResult) -> dict[str, Any]:
    """Plain-JSON form of a result (non-finite numbers become ``None``).

    Parameters
    ----------
    result : CollisionResult
        A query's result.

    Returns
    -------
    dict
        ``probability``, ``state``, ``patches`` (each with ``component``,
        ``points_a``, ``points_b``, ``point``, ``normal``, ``separation``,
        ``probability``, ``surface``, ``status``, ``iterations``) and ``stats``.
    """
    return {
        "probability": result.probability,
        "state": result.state,
        "patches": [
            {
                "component": r.component,
                "points_a": len(r.indices_a),
                "points_b": len(r.indices_b),
                "point": [finite(float(x)) for x in r.point],
                "normal": [finite(float(x)) for x in r.normal],
                "separation": finite(r.separation),
                "probability": r.probability,
                "surface": r.surface,
                "status": r.status,
                "iterations": r.iterations,
            }
            for r in result.patches
        ],
        "stats": {
            k: (finite(v) if isinstance(v, float) else v) for k, v in result.stats.to_dict().items()
        },
    }


def _load(args: argparse.Namespace) -> tuple[list[Any], list[Any]]:
    """Read the two sides (noise, filters) and their poses."""
    from cloudprox.pipeline import PipelineError, load_side, parse_filter, parse_pose

    try:
        sensor = sensor_spec(args)
        steps = [parse_filter(f) for f in args.filter]
        with bag_frame(args, args.a, args.b):
            sides = [
                load_side(args.a, sensor, steps),
                load_side(args.b, sensor, steps, sigma_override=args.sigma_b),
            ]
        poses = [
            None if text is None else parse_pose(text, what)
            for text, what in ((args.pose_a, "--pose-a"), (args.pose_b, "--pose-b"))
        ]
    except (PipelineError, FileNotFoundError) as e:
        raise CliError(str(e)) from None
    return sides, poses


def _cmd_collide(args: argparse.Namespace) -> int:
    request = request_from_args(args)
    sides, poses = _load(args)
    check_view_arguments(args)
    a, b = sides[0].obj, sides[1].obj
    result = collide(a, b, poses[0], poses[1], request=request, mesh_spacing=args.mesh_spacing)

    def scene() -> Any:
        from cloudprox.view import collision_scene

        labels = (f"A {Path(args.a).name}", f"B {Path(args.b).name}")
        return collision_scene(
            result, a, b, poses[0], poses[1], labels=labels, surfaces=args.surfaces
        )

    if args.json:
        write_views(args, scene)
        doc = result_to_dict(result) | {"a": sides[0].summary(), "b": sides[1].summary()}
        print(json.dumps(doc, indent=2))
        return 0
    _print_result(result, sides)
    write_views(args, scene)
    return 0


def _print_result(result: CollisionResult, sides: list[Any]) -> None:
    """Print the sides as read, ``P`` and the state, the patches and the counters."""
    out = console()
    for name, side in zip("AB", sides, strict=True):
        out.print(f"{name}: {_side_text(side)}")
    out.print(
        f"P = {result.probability:.6g}   state: {styled_state(result.state)}   "
        f"patches: {len(result.patches)}   time: {1e3 * result.stats.time_seconds:.2f} ms"
    )
    for k, r in enumerate(result.patches):
        point = ", ".join(f"{x:+.4f}" for x in r.point)
        normal = ", ".join(f"{x:+.3f}" for x in r.normal)
        out.print(
            f"  patch {k}: P = {r.probability:.3g}, separation {1e3 * r.separation:+.2f} mm, "
            f"point ({point}), normal ({normal}), points {len(r.indices_a)}+{len(r.indices_b)}, "
            f"{r.surface} surface, {r.status}"
        )
    stats = ", ".join(
        f"{k} = {v:.3g}" if isinstance(v, float) else f"{k} = {v}"
        for k, v in result.stats.to_dict().items()
    )
    out.print(f"stats: {stats}")


def _side_text(side: Any) -> str:
    """Describe one side as read: a mesh's size, or a cloud's points through the filters."""
    if side.mesh is not None:
        dropped = f", {side.dropped_faces} degenerate dropped" if side.dropped_faces else ""
        return (
            f"{side.path} (mesh: {len(side.mesh.vertices)} vertices, "
            f"{len(side.mesh.faces)} faces{dropped})"
        )
    assert side.cloud is not None
    steps_text = "".join(f", {f['filter']} -> {f['after']}" for f in side.filters)
    skipped = f", {side.skipped} non-finite skipped" if side.skipped else ""
    return (
        f"{side.path} ({side.read_points} points{skipped}{steps_text}; {len(side.cloud)} queried)"
    )


def _cmd_view(args: argparse.Namespace) -> int:
    if args.html is None:
        args.html = "cloudprox-view.html"
    status = _cmd_collide(args)
    if status == 0 and not args.no_open:
        import webbrowser

        webbrowser.open(Path(args.html).resolve().as_uri())
    return status


def _add_query_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the arguments of one query between two files (``collide`` and ``view``)."""
    parser.add_argument("a", metavar="A", help="point-cloud, mesh or ROS bag file of side A")
    parser.add_argument("b", metavar="B", help="point-cloud, mesh or ROS bag file of side B")
    add_bag_arguments(parser)
    add_noise_arguments(parser, "the cloud")
    parser.add_argument(
        "--sigma-b", type=float, default=None, help="isotropic noise of B (overrides for B)"
    )
    parser.add_argument(
        "--pose-a",
        default=None,
        metavar="POSE",
        help="pose of A: a .npy (4, 4) or text file, or x,y,z or x,y,z,qw,qx,qy,qz",
    )
    parser.add_argument("--pose-b", default=None, metavar="POSE", help="pose of B (as --pose-a)")
    add_filter_argument(parser)
    parser.add_argument(
        "--mesh-spacing",
        type=float,
        default=None,
        help="sampling spacing of a mesh side (m; default half the cloud's spacing)",
    )
    add_request_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    add_view_arguments(parser)


def add_parsers(sub: Any) -> None:
    """Add ``collide`` and ``view`` to the subcommands ``sub``."""
    col = sub.add_parser(
        "collide",
        help="one query between two files (point clouds or meshes)",
        description=(
            "One query between A and B. Each is a point-cloud file (PLY, PCD, XYZ/CSV, NPY, "
            "LAS/LAZ) or a mesh file (STL, OBJ, OFF, PLY with faces). Cloud sides get their "
            "noise from --sigma, --sensor, or the covariances stored in the file, then go "
            "through the --filter steps in order."
        ),
    )
    _add_query_arguments(col)
    col.set_defaults(func=_cmd_collide)

    vw = sub.add_parser(
        "view",
        help="one query between two files, shown in 3D in the web browser",
        description=(
            "The query of `cloudprox collide A B` (same options), written as an interactive "
            "3D view (--html, default cloudprox-view.html: one file that opens without a "
            "server or the internet) and opened in the web browser."
        ),
    )
    _add_query_arguments(vw)
    vw.add_argument(
        "--no-open", action="store_true", help="write the view but do not open the browser"
    )
    vw.set_defaults(func=_cmd_view)
