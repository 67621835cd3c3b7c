"""``cloudprox robot URDF SCAN``: a robot at one or many configurations against a scan."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

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
    request_from_args,
    sensor_spec,
    styled_state,
    write_views,
)

__all__ = ["add_parsers", "read_configurations"]

#: Configurations per call of ``collide_robot_many`` (the progress bar's step).
CHUNK = 256


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


def _load(args: argparse.Namespace) -> tuple[Any, Any]:
    """Read the scan (noise, filters) and the robot's base pose."""
    from cloudprox.pipeline import PipelineError, load_side, parse_filter, parse_pose

    try:
        sensor = sensor_spec(args)
        steps = [parse_filter(f) for f in args.filter]
        with bag_frame(args, args.scan):
            side = load_side(args.scan, sensor, steps)
        base = None if args.base_pose is None else parse_pose(args.base_pose, "--base-pose")
    except (PipelineError, FileNotFoundError) as e:
        raise CliError(str(e)) from None
    if side.cloud is None:
        raise CliError(f"{args.scan}: the scan must be a point cloud, not a mesh")
    return side, base


def _cmd_robot(args: argparse.Namespace) -> int:
    from cloudprox import Robot, RobotRequest

    request = request_from_args(args)
    robot = Robot.from_urdf(args.urdf, package_dirs=args.package_dir or None, srdf=args.srdf)
    qs = read_configurations(args.q, args.q_file, robot.dof)
    side, base = _load(args)
    check_view_arguments(args)
    if args.q is None and (args.html is not None or args.rerun is not None):
        raise CliError("--html and --rerun show one configuration: give --q, not --q-file")
    options: dict[str, Any] = {
        "request": RobotRequest(
            collide=request,
            mesh_side=args.mesh_side,
            mesh_spacing=args.mesh_spacing,
            padding=args.padding,
            **_shadow_options(args, side),
        )
    }
    if args.q is not None:
        return _one_configuration(args, robot, qs[0], side, base, options)
    return _many_configurations(args, robot, qs, side, base, options)


def _shadow_options(args: argparse.Namespace, side: Any) -> dict[str, Any]:
    """Return the ``shadow=`` options of ``--shadow`` / ``--shadow-depth`` (none without)."""
    from cloudprox.filters import Occlusion

    if not args.shadow:
        if args.shadow_depth is not None:
            raise CliError("--shadow-depth needs --shadow")
        return {}
    if side.origin is None:
        raise CliError(
            f"--shadow on {args.scan}: the sensor origin is unknown (the file has no "
            "VIEWPOINT): give --origin or --sensor-pose"
        )
    return {"shadow": Occlusion(side.cloud, side.origin), "shadow_depth": args.shadow_depth}


def _one_configuration(
    args: argparse.Namespace, robot: Any, q: np.ndarray, side: Any, base: Any, options: Any
) -> int:
    from cloudprox import collide_robot

    cloud = side.cloud
    result = collide_robot(robot, q, cloud, base, **options)

    def scene() -> Any:
        from cloudprox.view import robot_scene

        label = Path(args.scan).name
        return robot_scene(robot, q, cloud, result, base, label=label, surfaces=args.surfaces)

    if args.json:
        write_views(args, scene)
        print(json.dumps(_result_doc(result), indent=2))
        return 0
    out = console()
    out.print(
        f"{robot.name}: {robot.dof} joints, {len(result.links)} links with geometry; "
        f"{args.scan}: {len(cloud)} points"
    )
    out.print(
        f"P = {result.probability:.6g}   state: {styled_state(result.state)}   "
        f"links queried: {result.stats.links_queried}   "
        f"time: {1e3 * result.stats.time_seconds:.2f} ms"
    )
    for name, link in result.links.items():
        if link.queried or link.shadow > 0:
            shadow = f", in the scan's shadow: {link.shadow:.3g}" if link.shadow > 0 else ""
            out.print(f"  {name}: P = {link.probability:.3g} ({link.state}{shadow})")
    if result.self_collisions:
        pairs = ", ".join(f"{a}-{b}" for a, b in result.self_collisions)
        out.print(f"self-collision: {pairs}")
    write_views(args, scene)
    return 0


def _result_doc(result: Any) -> dict[str, Any]:
    """Return the JSON of one configuration's result."""
    return {
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


def _query_many(
    args: argparse.Namespace, robot: Any, qs: np.ndarray, side: Any, base: Any, options: Any
) -> list[Any]:
    """Query the configurations ``CHUNK`` at a time, with a progress bar on stderr."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    from cloudprox import collide_robot_many

    parts = []
    with Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        console=console(stderr=True),
        transient=True,
        disable=args.json,
    ) as progress:
        task = progress.add_task("configurations", total=len(qs))
        for start in range(0, len(qs), CHUNK):
            part = collide_robot_many(robot, qs[start : start + CHUNK], side.cloud, base, **options)
            parts.append(part)
            progress.update(task, advance=len(part))
    return parts


def _many_configurations(
    args: argparse.Namespace, robot: Any, qs: np.ndarray, side: Any, base: Any, options: Any
) -> int:
    parts = _query_many(args, robot, qs, side, base, options)
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
    out = console()
    counts = {s: int(np.sum(states == s)) for s in ("free", "contact", "collision")}
    out.print(
        f"{len(qs)} configurations: {counts['free']} free, {counts['contact']} contact, "
        f"{counts['collision']} collision, {int(selfc.sum())} self-colliding"
    )
    for i, (p, s) in enumerate(zip(probabilities, states, strict=False)):
        out.print(f"  {i}: P = {p:.6g}  {s}{'  self-collision' if selfc[i] else ''}")
    return 0


def add_parsers(sub: Any) -> None:
    """Add ``robot`` to the subcommands ``sub``."""
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
    add_bag_arguments(rob)
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
        "--srdf",
        default=None,
        metavar="FILE",
        help="an SRDF whose <disable_collisions> pairs leave the self-collision check",
    )
    rob.add_argument(
        "--package-dir",
        action="append",
        default=[],
        metavar="DIR",
        help="folder searched for package:// mesh URIs (repeatable)",
    )
    add_noise_arguments(rob, "the scan")
    add_filter_argument(rob)
    _add_link_arguments(rob)
    add_request_arguments(rob)
    rob.add_argument("--json", action="store_true", help="print the result as JSON")
    add_view_arguments(rob)
    rob.set_defaults(func=_cmd_robot)


def _add_link_arguments(rob: argparse.ArgumentParser) -> None:
    """Add ``--mesh-side``, ``--mesh-spacing``, ``--padding`` and the shadow options."""
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
    rob.add_argument(
        "--padding",
        type=float,
        default=None,
        metavar="M",
        help="grow every link's surface by M metres (a margin for model error; default 0)",
    )
    rob.add_argument(
        "--shadow",
        action="store_true",
        help=(
            "read the scan's shadow: a link reaching behind what the sensor saw reads at "
            "least contact (needs the sensor origin: the file's VIEWPOINT or --origin)"
        ),
    )
    rob.add_argument(
        "--shadow-depth",
        type=float,
        default=None,
        metavar="M",
        help="with --shadow: how far behind a seen surface space counts (m; default 0.05)",
    )
