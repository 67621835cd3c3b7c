"""The ``cloudprox`` command.

``cloudprox demo``
    A piano lowered over a table in a room, at several exact gaps: a table of
    ``P`` and states, and a figure.
``cloudprox collide A B [--sigma S | --sensor ...] [--pose-a P] [--filter STEP]``
    One query between two files: point clouds (PLY, PCD, XYZ/CSV, NPY, LAS/LAZ)
    or meshes (STL, OBJ, OFF, PLY with faces).
``cloudprox view A B [--html FILE] [--rerun FILE.rrd] [--no-open]``
    The query of ``collide``, shown in 3D in the web browser (``collide`` and
    ``robot`` write the same view with ``--html`` / ``--rerun``).
``cloudprox info FILE [--topic T] [--index I]``
    A summary of a point-cloud or mesh file, or the topics of a ROS bag (with
    ``--topic`` / ``--index``, that frame too).
``cloudprox example [DIR]``
    Example files: a depth-camera scan (PCD), a gripper (STL) and two grasp poses.
``cloudprox bench``
    cloudprox against a nearest-neighbour baseline and python-fcl on the same clouds.
``cloudprox reproduce [--quick] [--out DIR] [--workers N] [--ray [ADDRESS]]``
    The paper's experiments against exact ground truth and the baselines: figures,
    a metrics table and the raw per-query results.

Every user error (missing or unreadable file, wrong shape, bad option) prints one
line to stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cloudprox import __version__
from cloudprox._native import (
    CollisionRequest,
    CollisionResult,
    PointCloud,
    collide,
)
from cloudprox.exceptions import CloudproxError

__all__ = ["build_parser", "main", "result_to_dict"]

#: Gaps of the demo, in units of sigma.
DEMO_GAPS_SIGMA = (-3.0, -1.0, 0.0, 1.0, 2.0, 4.0, 8.0, 15.0)
#: The demo's "far" gap (metres).
DEMO_FAR_GAP = 0.25


class CliError(Exception):
    """A user error: reported on one line, exit status 2."""


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


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
                "point": [_finite(float(x)) for x in r.point],
                "normal": [_finite(float(x)) for x in r.normal],
                "separation": _finite(r.separation),
                "probability": r.probability,
                "surface": r.surface,
                "status": r.status,
                "iterations": r.iterations,
            }
            for r in result.patches
        ],
        "stats": {
            k: (_finite(v) if isinstance(v, float) else v)
            for k, v in result.stats.to_dict().items()
        },
    }


def _console(stderr: bool = False) -> Any:
    from rich.console import Console

    console = Console(stderr=stderr, highlight=False)
    if not console.is_terminal:  # files and pipes: do not squeeze tables into 80 columns
        console.width = max(console.width, 120)
    return console


# --------------------------------------------------------------------------- demo


def _cmd_demo(args: argparse.Namespace) -> int:
    from rich.table import Table

    from cloudprox.plots import Panel, plot_collisions, world_points
    from cloudprox.scenes import build_scene

    if not (math.isfinite(args.sigma) and args.sigma > 0.0):
        raise CliError(f"--sigma must be finite and > 0, got {args.sigma}")
    if args.points < 50:
        raise CliError(f"--points must be >= 50, got {args.points}")
    out = Path(args.out)
    console = _console()
    t_start = time.perf_counter()
    s = args.sigma
    scene = build_scene(sigma=s, points=args.points, seed=args.seed)
    piano = PointCloud(scene.piano_points, sigma=s)
    room = PointCloud(scene.room_points, sigma=s)
    console.print(
        f"Piano ({len(piano)} points) lowered over {scene.table} in a room ({len(room)} points), "
        f"noise sigma = {1e3 * s:g} mm, seed {args.seed}."
    )

    table = Table(title="Piano against the room at exact gaps")
    for col in ("gap mm", "gap/sigma", "nearest", "P", "state", "patches", "ms"):
        table.add_column(col, justify="left" if col in ("nearest", "state") else "right")
    gaps = [g * s for g in DEMO_GAPS_SIGMA] + [DEMO_FAR_GAP]
    runs = []
    for gap in gaps:
        pose = scene.piano_pose(gap)
        per_group = scene.gaps(pose)
        nearest = min(per_group, key=per_group.__getitem__)
        exact = per_group[nearest]
        result = collide(piano, room, pose_a=pose)
        runs.append((gap, pose, result))
        style = {"free": "green", "contact": "yellow", "collision": "red"}[result.state]
        table.add_row(
            f"{1e3 * exact:+.1f}",
            f"{exact / s:+.1f}",
            nearest,
            f"{result.probability:.3g}",
            f"[{style}]{result.state}[/{style}]",
            str(len(result.patches)),
            f"{1e3 * result.stats.time_seconds:.1f}",
        )
    console.print(table)
    console.print(
        "P: the probability, under the noise, that the two sampled surfaces cross "
        "(of poses read P = 0.3, about 3 in 10 collide)."
    )

    # The figure: touching, and the first undecided case (else the 4 sigma one).
    touching = next(r for r in runs if r[0] == 0.0)
    undecided = next((r for r in runs if r[2].state == "contact"), runs[DEMO_GAPS_SIGMA.index(4.0)])
    out.mkdir(parents=True, exist_ok=True)
    png = out / "demo.png"
    panels = [
        Panel(
            world_points(scene.piano_points, pose),
            scene.room_points,
            result,
            f"piano {gap / s:+g} sigma ({1e3 * gap:+.1f} mm) above {scene.table}",
        )
        for gap, pose, result in (touching, undecided)
    ]
    plot_collisions(panels, png, bounds="contact", labels=("piano", "room"), elev=25.0)
    console.print(f"Figure written to {png.resolve()}")
    console.print(f"Total time {time.perf_counter() - t_start:.2f} s.")
    return 0


# ------------------------------------------------------------------------ collide


#: The sensor models' parameters with flags of their own on `collide` (the
#: `robot` command has no such flags: they are None there, the model's defaults).
_SENSOR_PARAMETERS = (
    "axial_offset",
    "axial_quadratic",
    "axial_depth0",
    "focal_px",
    "sigma_px",
    "baseline",
    "sigma_disparity_px",
    "sigma_range",
    "sigma_angle",
)


def _sensor_spec(args: argparse.Namespace) -> Any:
    from cloudprox.pipeline import sensor_spec

    params = {k: getattr(args, k) for k in _SENSOR_PARAMETERS}
    return sensor_spec(
        args.sensor,
        sigma=args.sigma,
        params=params,
        preset=args.preset,
        origin=args.origin,
        sensor_pose=args.sensor_pose,
    )


def _cmd_collide(args: argparse.Namespace) -> int:
    from cloudprox.pipeline import PipelineError, load_side, parse_filter, parse_pose

    try:
        sensor = _sensor_spec(args)
        steps = [parse_filter(f) for f in args.filter]
        with _bag_frame(args, args.a, args.b):
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
    request = CollisionRequest(
        model=args.model,
        surface=args.surface,
        aggregation=args.aggregation,
        solver=args.solver,
        decide_only=args.decide_only,
        segmentations=args.segmentations,
        near_context=args.near_context,
    )
    _check_view_arguments(args)
    result = collide(
        sides[0].obj,
        sides[1].obj,
        poses[0],
        poses[1],
        request=request,
        mesh_spacing=args.mesh_spacing,
    )

    def scene() -> Any:
        from cloudprox.view import collision_scene

        return collision_scene(
            result,
            sides[0].obj,
            sides[1].obj,
            poses[0],
            poses[1],
            labels=(f"A {Path(args.a).name}", f"B {Path(args.b).name}"),
            surfaces=args.surfaces,
        )

    if args.json:
        _write_views(args, scene)
        doc = result_to_dict(result) | {"a": sides[0].summary(), "b": sides[1].summary()}
        print(json.dumps(doc, indent=2))
        return 0
    console = _console()
    style = {"free": "green", "contact": "yellow", "collision": "red"}[result.state]
    for name, side in zip("AB", sides, strict=True):
        if side.mesh is not None:
            dropped = f", {side.dropped_faces} degenerate dropped" if side.dropped_faces else ""
            console.print(
                f"{name}: {side.path} (mesh: {len(side.mesh.vertices)} vertices, "
                f"{len(side.mesh.faces)} faces{dropped})"
            )
        else:
            assert side.cloud is not None
            steps_text = "".join(f", {f['filter']} -> {f['after']}" for f in side.filters)
            skipped = f", {side.skipped} non-finite skipped" if side.skipped else ""
            console.print(
                f"{name}: {side.path} ({side.read_points} points{skipped}{steps_text}; "
                f"{len(side.cloud)} queried)"
            )
    console.print(
        f"P = {result.probability:.6g}   state: [{style}]{result.state}[/{style}]   "
        f"patches: {len(result.patches)}   time: {1e3 * result.stats.time_seconds:.2f} ms"
    )
    for k, r in enumerate(result.patches):
        point = ", ".join(f"{x:+.4f}" for x in r.point)
        normal = ", ".join(f"{x:+.3f}" for x in r.normal)
        console.print(
            f"  patch {k}: P = {r.probability:.3g}, separation {1e3 * r.separation:+.2f} mm, "
            f"point ({point}), normal ({normal}), points {len(r.indices_a)}+{len(r.indices_b)}, "
            f"{r.surface} surface, {r.status}"
        )
    stats = ", ".join(
        f"{k} = {v:.3g}" if isinstance(v, float) else f"{k} = {v}"
        for k, v in result.stats.to_dict().items()
    )
    console.print(f"stats: {stats}")
    _write_views(args, scene)
    return 0


@contextlib.contextmanager
def _bag_frame(args: argparse.Namespace, *paths: str) -> Iterator[None]:
    """Read the ``--topic`` / ``--index`` frame of the bags among ``paths`` inside the context."""
    from cloudprox.bags import bag_selection, is_bag

    given = args.topic is not None or args.index is not None
    if given and not any(is_bag(p) for p in paths):
        raise CliError("--topic and --index apply to ROS bags (.bag, .db3, .mcap) only")
    try:
        with bag_selection(args.topic, 0 if args.index is None else args.index):
            yield
    except ModuleNotFoundError as e:
        raise CliError(str(e)) from None


def _add_bag_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--topic`` and ``--index``: which frame of a ROS bag a cloud side is read from."""
    parser.add_argument(
        "--topic",
        default=None,
        help="ROS bags: the sensor_msgs/PointCloud2 topic (default: the bag's only one)",
    )
    parser.add_argument(
        "--index",
        type=int,
        default=None,
        help="ROS bags: the message's index in the topic (default 0; negative: from the end)",
    )


def _check_view_arguments(args: argparse.Namespace) -> None:
    if args.surfaces < 0:
        raise CliError(f"--surfaces must be >= 0, got {args.surfaces}")
    for flag, path, suffix in (("--html", args.html, ".html"), ("--rerun", args.rerun, ".rrd")):
        if path is None:
            continue
        if not Path(path).suffix:
            raise CliError(f"{flag} {path}: give a file name ending in {suffix}")
        parent = Path(path).resolve().parent
        if not parent.is_dir():
            raise CliError(f"{flag} {path}: no such folder {parent}")
    modules = [("--html", args.html, "k3d", "view"), ("--rerun", args.rerun, "rerun", "rerun")]
    for flag, path, module, extra in modules:
        if path is None:
            continue
        import importlib.util

        if importlib.util.find_spec(module) is None:
            raise CliError(f"{flag} needs the '{module}' package: pip install 'cloudprox[{extra}]'")


def _write_views(args: argparse.Namespace, make_scene: Any) -> None:
    """Write the ``--html`` and ``--rerun`` views of a scene made by ``make_scene()``."""
    if args.html is None and args.rerun is None:
        return
    from cloudprox import view

    scene = make_scene()
    console = _console(stderr=bool(getattr(args, "json", False)))
    if args.html is not None:
        path = view.write_html(
            scene, args.html, all_points=bool(getattr(args, "all_points", False))
        )
        size = path.stat().st_size / 1e6
        console.print(f"view written to {path.resolve()} ({size:.1f} MB; open it in a browser)")
    if args.rerun is not None:
        path = view.write_rerun(scene, args.rerun)
        console.print(f"Rerun recording written to {path.resolve()} (rerun {path})")


def _cmd_view(args: argparse.Namespace) -> int:
    if args.html is None:
        args.html = "cloudprox-view.html"
    status = _cmd_collide(args)
    if status == 0 and not args.no_open:
        import webbrowser

        webbrowser.open(Path(args.html).resolve().as_uri())
    return status


# ------------------------------------------------------------------------ robot


def read_configurations(text: str | None, path: str | None, dof: int) -> np.ndarray:
    """Return the configurations of ``cloudprox robot`` as an ``(m, dof)`` array.

    Parameters
    ----------
    text : str, optional
        One configuration, ``dof`` numbers separated by commas or spaces (``--q``).
    path : str, optional
        A ``.npy`` file of shape ``(m, dof)`` or ``(dof,)``, or a CSV / text file with
        one configuration per line (``--q-file``; ``#`` starts a comment).
    dof : int
        The robot's number of configuration entries.

    Returns
    -------
    numpy.ndarray
        Shape ``(m, dof)``, float64.

    Raises
    ------
    CliError
        If neither or both are given, a file cannot be parsed, or a row has the
        wrong length.
    """
    if (text is None) == (path is None):
        raise CliError("give exactly one of --q and --q-file")
    if text is not None:
        try:
            q = np.array([float(v) for v in text.replace(",", " ").split()], dtype=float)
        except ValueError:
            raise CliError(f"--q: not a list of numbers: {text!r}") from None
        qs = q.reshape(1, -1)
        what = "--q"
    else:
        assert path is not None
        what = f"--q-file {path}"
        if not Path(path).is_file():
            raise CliError(f"{path}: no such file")
        try:
            if path.lower().endswith(".npy"):
                qs = np.load(path, allow_pickle=False)
            else:
                qs = np.loadtxt(path, delimiter=None if "," not in Path(path).read_text() else ",")
        except (ValueError, OSError) as e:
            raise CliError(f"{what}: cannot read configurations: {e}") from None
        qs = np.atleast_2d(np.asarray(qs, dtype=float))
    if qs.ndim != 2 or qs.shape[1] != dof or qs.shape[0] == 0:
        raise CliError(
            f"{what}: expected configurations of {dof} joint values, got shape {qs.shape}"
        )
    return qs


def _cmd_robot(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    from cloudprox import Robot, collide_robot, collide_robot_many
    from cloudprox.pipeline import PipelineError, load_side, parse_filter, parse_pose

    robot = Robot.from_urdf(args.urdf, package_dirs=args.package_dir or None)
    qs = read_configurations(args.q, args.q_file, robot.dof)
    try:
        sensor = _sensor_spec(args)
        steps = [parse_filter(f) for f in args.filter]
        with _bag_frame(args, args.scan):
            side = load_side(args.scan, sensor, steps)
        base = None if args.base_pose is None else parse_pose(args.base_pose, "--base-pose")
    except (PipelineError, FileNotFoundError) as e:
        raise CliError(str(e)) from None
    if side.cloud is None:
        raise CliError(f"{args.scan}: the scan must be a point cloud, not a mesh")
    options: dict[str, Any] = {"mesh_side": args.mesh_side, "mesh_spacing": args.mesh_spacing}
    _check_view_arguments(args)
    if args.q is None and (args.html is not None or args.rerun is not None):
        raise CliError("--html and --rerun show one configuration: give --q, not --q-file")
    if args.q is not None:
        result = collide_robot(robot, qs[0], side.cloud, base, **options)
        cloud = side.cloud

        def scene() -> Any:
            from cloudprox.view import robot_scene

            return robot_scene(
                robot,
                qs[0],
                cloud,
                result,
                base,
                label=Path(args.scan).name,
                surfaces=args.surfaces,
            )

        if args.json:
            _write_views(args, scene)
            doc = {
                "probability": result.probability,
                "state": result.state,
                "links": {
                    name: {
                        "probability": link.probability,
                        "state": link.state,
                        "queried": link.queried,
                    }
                    for name, link in result.links.items()
                },
                "self_collisions": [list(p) for p in result.self_collisions],
                "stats": result.stats.to_dict(),
            }
            print(json.dumps(doc, indent=2))
            return 0
        console = _console()
        style = {"free": "green", "contact": "yellow", "collision": "red"}[result.state]
        console.print(
            f"{robot.name}: {robot.dof} joints, {len(result.links)} links with geometry; "
            f"{args.scan}: {len(side.cloud)} points"
        )
        console.print(
            f"P = {result.probability:.6g}   state: [{style}]{result.state}[/{style}]   "
            f"links queried: {result.stats.links_queried}   "
            f"time: {1e3 * result.stats.time_seconds:.2f} ms"
        )
        for name, link in result.links.items():
            if link.queried:
                console.print(f"  {name}: P = {link.probability:.3g} ({link.state})")
        if result.self_collisions:
            pairs = ", ".join(f"{a}-{b}" for a, b in result.self_collisions)
            console.print(f"self-collision: {pairs}")
        _write_views(args, scene)
        return 0
    chunk = 256
    parts = []
    with Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        console=_console(stderr=True),
        transient=True,
        disable=args.json,
    ) as progress:
        task = progress.add_task("configurations", total=len(qs))
        for start in range(0, len(qs), chunk):
            parts.append(
                collide_robot_many(robot, qs[start : start + chunk], side.cloud, base, **options)
            )
            progress.update(task, advance=len(parts[-1]))
    probabilities = np.concatenate([p.probabilities for p in parts])
    states = np.concatenate([p.states for p in parts])
    links = np.vstack([p.link_probabilities for p in parts])
    selfc = np.concatenate([p.self_colliding for p in parts])
    if args.json:
        doc = {
            "configurations": len(qs),
            "probabilities": probabilities.tolist(),
            "states": states.tolist(),
            "self_colliding": selfc.tolist(),
            "link_names": robot.link_names,
            "link_probabilities": links.tolist(),
        }
        print(json.dumps(doc, indent=2))
        return 0
    console = _console()
    counts = {s: int(np.sum(states == s)) for s in ("free", "contact", "collision")}
    console.print(
        f"{len(qs)} configurations: {counts['free']} free, {counts['contact']} contact, "
        f"{counts['collision']} collision, {int(selfc.sum())} self-colliding"
    )
    for i, (p, s) in enumerate(zip(probabilities, states, strict=False)):
        console.print(f"  {i}: P = {p:.6g}  {s}{'  self-collision' if selfc[i] else ''}")
    return 0


# ------------------------------------------------------------------------ example


def _cmd_example(args: argparse.Namespace) -> int:
    from cloudprox.examples import write_example_files

    paths = write_example_files(args.out, seed=args.seed)
    console = _console()
    console.print(f"wrote the example files to {Path(args.out).resolve()}:")
    for name, path in paths.items():
        console.print(f"  {name}: {path.name}")
    console.print(
        "try: cloudprox collide "
        f"{paths['gripper']} {paths['scan']} --pose-a {paths['grasp-free']} "
        "--sensor depth-camera --preset nguyen-2012 --filter shadow"
    )
    return 0


# --------------------------------------------------------------------------- info


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
    from cloudprox.pipeline import is_mesh_file, read_mesh_file

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
            topics = bags.topics(path)
            info |= {
                "format": info["format"] or "rosbag2",
                "kind": "ROS bag",
                "topics": [
                    {"name": t.name, "type": t.msgtype, "messages": t.count} for t in topics
                ],
            }
            if topic is None and index is None:
                return info
            scan = bags.read_point_cloud(path, topic, 0 if index is None else index)
        except ModuleNotFoundError as e:
            raise CliError(str(e)) from None
        info["frame"] = {
            "topic": scan.topic,
            "index": scan.index,
            "stamp_ns": scan.stamp,
            "sensor_frame": scan.sensor_frame,
            "frame_id": scan.frame_id,
        } | _cloud_info(scan)
        return info
    if is_mesh_file(path):
        mesh, dropped = read_mesh_file(path)
        lo, hi = mesh.bounds()
        info |= {
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
        return info
    return info | _cloud_info(io.read_point_cloud(path))


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


def _print_info(console: Any, info: dict[str, Any], indent: str = "  ") -> None:
    """Print the items of a :func:`file_info` summary, one per line."""
    from_bag = "sensor_frame" in info
    for key, value in info.items():
        if key in ("path", "kind", "format") or (key == "warnings" and not value):
            continue
        if key == "topics":
            console.print(f"{indent}topics: {len(value)}")
            for t in value:
                console.print(f"{indent}  {t['name']}: {t['type']}, {t['messages']} messages")
            continue
        if key == "frame":
            console.print(f"{indent}frame {value['index']} of {value['topic']}:")
            _print_info(console, value, indent + "  ")
            continue
        if key in ("no_returns_at_sensor_origin", "sensor_pose_is_default"):
            continue
        if key == "no_returns":
            at = info["no_returns_at_sensor_origin"]
            value = f"{value} ({at} at the sensor origin, {value - at} non-finite)"
        elif key == "bounds":
            lo, hi = value
            value = (
                "["
                + ", ".join(f"{x:.4g}" for x in lo)
                + "] .. ["
                + ", ".join(f"{x:.4g}" for x in hi)
                + "]"
            )
        elif key == "spacing_m":
            value = (
                f"median {1e3 * value['median']:.3g} mm "
                f"(5%: {1e3 * value['p05']:.3g}, 95%: {1e3 * value['p95']:.3g})"
            )
        elif key == "sensor_pose" and value is not None:
            value = "origin (" + ", ".join(f"{row[3]:.4g}" for row in value[:3]) + ")"
            if info.get("sensor_pose_is_default"):
                value += (
                    ", the origin of the message's frame (no TF for it)"
                    if from_bag
                    else ", the PCD default VIEWPOINT (identity)"
                )
        elif key == "fields":
            value = " ".join(value)
        elif isinstance(value, float):
            value = f"{value:.4g}"
        console.print(f"{indent}{key.replace('_', ' ')}: {value}")


def _cmd_info(args: argparse.Namespace) -> int:
    info = file_info(args.file, args.topic, args.index)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    console = _console()
    console.print(f"[bold]{info['path']}[/bold]: {info['kind']} ({info['format'].upper()})")
    _print_info(console, info)
    return 0


# -------------------------------------------------------------------------- bench


def _cmd_bench(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn
    from rich.table import Table

    from cloudprox.bench import CONFIGS, engine_names, run_bench

    if args.points < 10 or args.repeat < 1:
        raise CliError("--points must be >= 10 and --repeat >= 1")
    total = len(engine_names()) * len(CONFIGS) * args.repeat
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        console=_console(stderr=True),
        transient=True,
    ) as progress:
        task = progress.add_task("benchmark", total=total)

        def step(desc: str) -> None:
            progress.update(task, advance=1, description=desc)

        rows, notes = run_bench(args.points, args.repeat, on_step=step)
    ref = {r.config: r.median_ms for r in rows if r.engine == "cloudprox"}
    if args.json:
        doc = {
            "points": args.points,
            "repeat": args.repeat,
            "rows": [
                {
                    "config": r.config,
                    "engine": r.engine,
                    "median_ms": r.median_ms,
                    "prep_ms": r.prep_ms,
                    "ratio_to_cloudprox": r.median_ms / ref[r.config] if ref[r.config] else None,
                    "answer": r.answer,
                }
                for r in rows
            ],
            "notes": notes,
        }
        print(json.dumps(doc, indent=2))
        return 0
    console = _console()
    table = Table(title=f"Two noisy spheres, {args.points} points each, median of {args.repeat}")
    for col in ("config", "engine", "median ms", "ratio", "prep ms", "answer"):
        right = col in ("median ms", "ratio", "prep ms")
        table.add_column(col, justify="right" if right else "left", no_wrap=True)
    for r in rows:
        ratio = f"{r.median_ms / ref[r.config]:.3g}" if ref[r.config] else "-"
        table.add_row(r.config, r.engine, f"{r.median_ms:.3f}", ratio, f"{r.prep_ms:.1f}", r.answer)
    console.print(table)
    console.print("ratio = engine median / cloudprox median on the same configuration.")
    for note in notes:
        console.print(f"note: {note}")
    return 0


# ---------------------------------------------------------------------- reproduce


def _cmd_reproduce(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    from cloudprox.reproduce.run import Config, available_cpus, run, steps

    config = Config.quick() if args.quick else Config()
    if args.poses is not None:
        if args.poses < 10:
            raise CliError(f"--poses must be >= 10, got {args.poses}")
        config = replace(config, poses=args.poses)
    if args.scan_poses is not None:
        if args.scan_poses < 0:
            raise CliError(f"--scan-poses must be >= 0, got {args.scan_poses}")
        config = replace(config, scan_poses=args.scan_poses)
    if args.points is not None:
        if args.points < 500:
            raise CliError(f"--points must be >= 500, got {args.points}")
        config = replace(config, piano_points=args.points)
    if args.workers is not None and args.workers < 1:
        raise CliError(f"--workers must be >= 1, got {args.workers}")
    out = Path(args.out)
    many = None
    if args.ray is not None:
        from functools import partial

        from cloudprox import distributed

        try:
            ray = distributed.ensure_ray(args.ray or None)
        except ImportError as e:
            raise CliError(str(e)) from None
        many = partial(distributed.collide_many, progress=False)
        cpus = ray.cluster_resources().get("CPU", 0)
        _console().print(f"cloudprox's queries run as Ray tasks ({cpus:g} CPUs in the cluster).")
    console = _console()
    console.print(
        f"Reproducing on the piano-in-room scene: {config.piano_points} piano points, "
        f"{config.poses} poses x {config.draws} noise draws per level, levels "
        f"{', '.join(f'{100 * x:g}%' for x in config.levels)}"
        + (
            f" + anisotropic {', '.join(f'{100 * x:g}%' for x in config.anisotropic_levels)}"
            if config.anisotropic_levels
            else ""
        )
        + (
            f"; real Kinect frame with the Panda gripper at {config.scan_poses} poses"
            if config.scan_poses
            else ""
        )
        + "."
    )
    with Progress(
        TextColumn("{task.description:<42}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=console,
        transient=False,
    ) as bar:
        task = bar.add_task("starting", total=steps(config))
        summary = run(
            config,
            out,
            lambda desc, n: bar.update(task, advance=n, description=desc),
            many,
            args.workers or available_cpus(),
        )
    table = Table(
        title="Near-contact AUC / decided accuracy / undecided / hard flips / FP > 3 sigma / "
        "FN < -3 sigma"
    )
    cols = ("level", "method", "AUC near", "decided", "undecided", "flips", "FP>3s", "FN<-3s", "ms")
    for col in cols:
        table.add_column(col, justify="left" if col in ("level", "method") else "right")
    for (level, method), mt in summary.metrics.items():
        table.add_row(
            level,
            method,
            f"{mt.auc_near:.3f}",
            f"{mt.decided_accuracy:.3f}",
            f"{mt.undecided:.1%}",
            f"{mt.hard_flip:.1%}",
            f"{mt.false_positive_3s:.1%}",
            f"{mt.false_negative_3s:.1%}",
            f"{mt.median_ms:.2f}",
        )
    console.print(table)
    for c in summary.claims:
        mark = "[green]holds[/green]" if c.holds else "[red]does not hold[/red]"
        console.print(f"{c.level}: {c.claim}: {mark} ({c.detail})")
    console.print(
        f"Figures, summary.md and results.csv in {out.resolve()} ({summary.seconds:.0f} s)."
    )
    return 0


# --------------------------------------------------------------------------- main


def _add_query_arguments(
    col: argparse.ArgumentParser, defaults: CollisionRequest, names: dict[str, tuple[str, ...]]
) -> None:
    """Add the arguments of one query between two files (``collide`` and ``view``)."""
    col.add_argument("a", metavar="A", help="point-cloud, mesh or ROS bag file of side A")
    col.add_argument("b", metavar="B", help="point-cloud, mesh or ROS bag file of side B")
    _add_bag_arguments(col)
    col.add_argument(
        "--sigma", type=float, default=None, help="isotropic noise standard deviation (metres)"
    )
    col.add_argument(
        "--sigma-b", type=float, default=None, help="isotropic noise of B (overrides for B)"
    )
    sensor = col.add_argument_group("sensor model (per-point noise along the viewing rays)")
    sensor.add_argument("--sensor", choices=["isotropic", "depth-camera", "stereo", "lidar"])
    sensor.add_argument(
        "--preset",
        choices=["khoshelham-2012", "nguyen-2012"],
        help="depth camera: published fit (default: the core's, khoshelham-2012)",
    )
    sensor.add_argument("--origin", metavar="X,Y,Z", help="sensor origin in the cloud's frame")
    sensor.add_argument(
        "--sensor-pose",
        metavar="POSE",
        help="sensor pose (optical axis +z); default: the file's VIEWPOINT",
    )
    for flag, text in (
        ("--axial-offset", "depth camera: constant axial std (m)"),
        ("--axial-quadratic", "depth camera: quadratic axial coefficient (1/m)"),
        ("--axial-depth0", "depth camera: depth where the quadratic term vanishes (m)"),
        ("--focal-px", "depth/stereo camera: focal length (px)"),
        ("--sigma-px", "depth/stereo camera: lateral std (px)"),
        ("--baseline", "stereo: baseline (m)"),
        ("--sigma-disparity-px", "stereo: disparity std (px)"),
        ("--sigma-range", "lidar: range std (m)"),
        ("--sigma-angle", "lidar: angular std (rad)"),
    ):
        sensor.add_argument(flag, type=float, default=None, help=text)
    col.add_argument(
        "--pose-a",
        default=None,
        metavar="POSE",
        help="pose of A: a .npy (4, 4) or text file, or x,y,z or x,y,z,qw,qx,qy,qz",
    )
    col.add_argument("--pose-b", default=None, metavar="POSE", help="pose of B (as --pose-a)")
    col.add_argument(
        "--filter",
        action="append",
        default=[],
        metavar="STEP",
        help="filter step for point-cloud sides, in order (repeatable): "
        "crop:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX | voxel:SIZE | outliers[:K[:STD]] | "
        "shadow[:MIN_ANGLE_DEG] | self:MESH[:PADDING[:POSE]]",
    )
    col.add_argument(
        "--mesh-spacing",
        type=float,
        default=None,
        help="sampling spacing of a mesh side (m; default half the cloud's spacing)",
    )
    col.add_argument(
        "--model",
        choices=names["model"],
        default=None,
        help="what is classified: surface elements fitted to the points, or every point "
        f"(the paper's method) (default: {defaults.model})",
    )
    col.add_argument(
        "--decide-only",
        action="store_true",
        help="return as soon as the state is decided (no per-point probabilities)",
    )
    col.add_argument(
        "--segmentations",
        type=int,
        default=None,
        metavar="K",
        help="with --model elements: average P over K segmentations of the clouds "
        "(1 to 16; better ranking near contact for K times the work; default 1)",
    )
    col.add_argument(
        "--near-context",
        type=float,
        default=None,
        metavar="C",
        help="spacings of surface around the contact that the classifier sees (at least "
        "0.5; fewer is faster near contact, see docs/design/near-context.md; "
        f"default {defaults.near_context:g})",
    )
    col.add_argument(
        "--surface",
        choices=names["surface"],
        default=None,
        help=f"separating surface (default: {defaults.surface})",
    )
    col.add_argument(
        "--aggregation",
        choices=names["aggregation"],
        default=None,
        help=f"aggregation of per-point probabilities (default: {defaults.aggregation})",
    )
    col.add_argument(
        "--solver",
        choices=names["solver"],
        default=None,
        help=f"SOCP solver (default: {defaults.solver})",
    )
    col.add_argument("--json", action="store_true", help="print the result as JSON")
    _add_view_arguments(col)


def _add_view_arguments(parser: argparse.ArgumentParser) -> None:
    """``--html`` and ``--rerun``: where a command writes its interactive view."""
    group = parser.add_argument_group("interactive view")
    group.add_argument(
        "--html",
        metavar="FILE",
        default=None,
        help="write the interactive 3D view: one HTML file that opens without a server "
        "(needs cloudprox[view])",
    )
    group.add_argument(
        "--rerun",
        metavar="FILE.rrd",
        default=None,
        help="log the same scene to a Rerun recording (needs cloudprox[rerun])",
    )
    group.add_argument(
        "--surfaces",
        type=int,
        default=5,
        metavar="N",
        help="separating surfaces of the N most probable patches in the view, hidden until "
        "shown in the view's panel (default: %(default)s)",
    )
    group.add_argument(
        "--all-points",
        action="store_true",
        help="draw every point with p < 1e-3 in the HTML view too (by default they are thinned "
        "to the density a screen shows of the whole scene; the legend says how many)",
    )


def build_parser() -> argparse.ArgumentParser:
    """Build the ``cloudprox`` command's argument parser, with every subcommand.

    The documentation's command-line reference is generated from it.

    Returns
    -------
    argparse.ArgumentParser
        The parser :func:`main` uses.
    """
    defaults = CollisionRequest()
    names = CollisionRequest.choices()
    parser = argparse.ArgumentParser(
        prog="cloudprox",
        description="Probabilistic collision queries between noisy point clouds.",
    )
    parser.add_argument("--version", action="version", version=f"cloudprox {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    demo = sub.add_parser("demo", help="piano over a table in a room, at several exact gaps")
    demo.add_argument(
        "--out", default="cloudprox-demo", help="directory for demo.png (default: %(default)s)"
    )
    demo.add_argument(
        "--sigma",
        type=float,
        default=0.005,
        help="noise standard deviation in metres (default: %(default)s)",
    )
    demo.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    demo.add_argument(
        "--points",
        type=int,
        default=10_000,
        help="approximate number of piano points (default: %(default)s)",
    )
    demo.set_defaults(func=_cmd_demo)

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
    _add_query_arguments(col, defaults, names)
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
    _add_query_arguments(vw, defaults, names)
    vw.add_argument(
        "--no-open", action="store_true", help="write the view but do not open the browser"
    )
    vw.set_defaults(func=_cmd_view)

    rob = sub.add_parser(
        "robot",
        help="a URDF robot at one or many configurations against a scan",
        description=(
            "The robot of URDF at the configuration --q (or each row of --q-file) against "
            "the point-cloud file SCAN, with the scan's noise from --sigma, --sensor or the "
            "file's covariances, after the --filter steps."
        ),
    )
    rob.add_argument("urdf", metavar="URDF", help="the robot's URDF file")
    rob.add_argument("scan", metavar="SCAN", help="point-cloud or ROS bag file of the environment")
    _add_bag_arguments(rob)
    rob.add_argument(
        "--q", default=None, help="one configuration: joint values separated by commas"
    )
    rob.add_argument(
        "--q-file",
        default=None,
        metavar="FILE",
        help="many configurations: .npy (m, dof) or CSV/text, one per line",
    )
    rob.add_argument(
        "--base-pose",
        default=None,
        metavar="POSE",
        help="pose of the robot's root link in the scan's frame (as --pose-a of collide)",
    )
    rob.add_argument(
        "--package-dir",
        action="append",
        default=[],
        metavar="DIR",
        help="folder searched for package:// mesh URIs (repeatable)",
    )
    rob.add_argument(
        "--sigma", type=float, default=None, help="isotropic noise standard deviation (metres)"
    )
    rob.add_argument("--sensor", choices=["isotropic", "depth-camera", "stereo", "lidar"])
    rob.add_argument("--preset", choices=["khoshelham-2012", "nguyen-2012"])
    rob.add_argument("--origin", metavar="X,Y,Z", help="sensor origin in the scan's frame")
    rob.add_argument("--sensor-pose", metavar="POSE", help="sensor pose (default: VIEWPOINT)")
    rob.add_argument(
        "--filter", action="append", default=[], metavar="STEP", help="filter step (as collide)"
    )
    rob.add_argument(
        "--mesh-side",
        choices=["exact", "sampled"],
        default=None,
        help=(
            "how the links stand: their exact surfaces (the default) or their meshes "
            "sampled into clouds (the default with --mesh-spacing)"
        ),
    )
    rob.add_argument(
        "--mesh-spacing",
        type=float,
        default=None,
        help="sampling spacing of sampled links (m; default half the scan's spacing)",
    )
    rob.add_argument("--json", action="store_true", help="print the result as JSON")
    _add_view_arguments(rob)
    rob.set_defaults(
        func=_cmd_robot,
        **dict.fromkeys(_SENSOR_PARAMETERS),
    )

    ex = sub.add_parser(
        "example",
        help="write example files: a depth-camera scan (PCD), a gripper (STL), two grasp poses",
    )
    ex.add_argument(
        "out", nargs="?", default="cloudprox-example", help="folder (default: %(default)s)"
    )
    ex.add_argument("--seed", type=int, default=0, help="noise seed (default: %(default)s)")
    ex.set_defaults(func=_cmd_example)

    info = sub.add_parser(
        "info",
        help="summarize a point-cloud, mesh or ROS bag file (points, bounds, fields, topics)",
    )
    info.add_argument("file", metavar="FILE", help="point-cloud, mesh or ROS bag file")
    _add_bag_arguments(info)
    info.add_argument("--json", action="store_true", help="print the summary as JSON")
    info.set_defaults(func=_cmd_info)

    bench = sub.add_parser("bench", help="cloudprox against comparison engines")
    bench.add_argument(
        "--points", type=int, default=10_000, help="points per sphere (default: %(default)s)"
    )
    bench.add_argument(
        "--repeat",
        type=int,
        default=5,
        help="timed queries per engine and configuration (default: %(default)s)",
    )
    bench.add_argument("--json", action="store_true", help="print the results as JSON")
    bench.set_defaults(func=_cmd_bench)

    rep = sub.add_parser(
        "reproduce", help="the paper's experiments against exact ground truth and baselines"
    )
    rep.add_argument(
        "--quick",
        action="store_true",
        help="the CI smoke run: 3000 piano points, 100 poses, 0.5%% and 2%% noise, "
        "100 poses on the real scan",
    )
    rep.add_argument(
        "--out", default="cloudprox-reproduce", help="output directory (default: %(default)s)"
    )
    rep.add_argument("--poses", type=int, default=None, help="poses per noise level (overrides)")
    rep.add_argument(
        "--points", type=int, default=None, help="approximate number of piano points (overrides)"
    )
    rep.add_argument(
        "--scan-poses",
        type=int,
        default=None,
        help="gripper poses on the real Kinect frame (overrides; 0 skips the experiment)",
    )
    rep.add_argument(
        "--workers",
        type=int,
        default=None,
        help="processes for the Python baselines (default: the CPUs available; "
        "1: in this process); the answers do not depend on it",
    )
    rep.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        metavar="ADDRESS",
        help="run cloudprox's queries as Ray tasks: on the cluster at ADDRESS, else the "
        "running one, else a local one (needs cloudprox[ray])",
    )
    rep.set_defaults(func=_cmd_reproduce)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``cloudprox`` command.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` by default.

    Returns
    -------
    int
        Exit status: 0 on success, 2 on a user error.
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # --help, --version, or a usage error already printed
        return e.code if isinstance(e.code, int) else 2
    if args.command is None:
        parser.print_usage(sys.stderr)
        print(
            "cloudprox: error: a command is required "
            "(demo, collide, view, robot, info, example, bench or reproduce)",
            file=sys.stderr,
        )
        return 2
    try:
        return int(args.func(args))
    except (CliError, CloudproxError) as e:
        print(f"cloudprox {args.command}: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"cloudprox {args.command}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cloudprox: interrupted", file=sys.stderr)
        return 130
