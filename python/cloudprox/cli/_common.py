"""What the commands share: the user error, the console, and the options of every query.

The commands that query scans (``collide``, ``view``, ``robot``) take the same
noise options (``--sigma``, ``--sensor`` and its parameters, ``--filter``); they
and ``demo`` take the same options of the query (:func:`add_request_arguments`, read back into a
:class:`~cloudprox.CollisionRequest` by :func:`request_from_args`) and the same
view options (``--html``, ``--rerun``).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from cloudprox._native import CollisionRequest

#: The sensor models' parameters, each with a flag of its own (``--axial-offset``, ...).
SENSOR_PARAMETERS = (
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

#: The styles of the three states in the console.
STATE_STYLE = {"free": "green", "contact": "yellow", "collision": "red"}


class CliError(Exception):
    """A user error: reported on one line, exit status 2."""


def finite(x: float) -> float | None:
    """Return ``x``, or ``None`` (JSON's null) if it is not finite."""
    return x if math.isfinite(x) else None


def console(stderr: bool = False) -> Any:
    """Return a rich console (on stderr if asked) that keeps tables wide in files and pipes."""
    from rich.console import Console

    out = Console(stderr=stderr, highlight=False)
    if not out.is_terminal:  # files and pipes: do not squeeze tables into 80 columns
        out.width = max(out.width, 120)
    return out


def styled_state(state: str) -> str:
    """Return ``state`` in its console colour."""
    style = STATE_STYLE[state]
    return f"[{style}]{state}[/{style}]"


# ------------------------------------------------------------------ noise and input


def add_noise_arguments(parser: argparse.ArgumentParser, what: str) -> None:
    """Add ``--sigma`` and the sensor model's options of the point clouds read."""
    parser.add_argument(
        "--sigma", type=float, default=None, help="isotropic noise standard deviation (metres)"
    )
    sensor = parser.add_argument_group("sensor model (per-point noise along the viewing rays)")
    sensor.add_argument("--sensor", choices=["isotropic", "depth-camera", "stereo", "lidar"])
    sensor.add_argument(
        "--preset",
        choices=["khoshelham-2012", "nguyen-2012"],
        help="depth camera: published fit (default: the core's, khoshelham-2012)",
    )
    sensor.add_argument("--origin", metavar="X,Y,Z", help=f"sensor origin in {what}'s frame")
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


def add_filter_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--filter``: the filter steps of the point clouds read, in order."""
    parser.add_argument(
        "--filter",
        action="append",
        default=[],
        metavar="STEP",
        help="filter step for point-cloud sides, in order (repeatable): "
        "crop:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX | voxel:SIZE | outliers[:K[:STD]] | "
        "shadow[:MIN_ANGLE_DEG] | self:MESH[:PADDING[:POSE]]",
    )


def sensor_spec(args: argparse.Namespace) -> Any:
    """Return the noise model the noise options of ``args`` give."""
    from cloudprox.pipeline import sensor_spec as spec

    params = {k: getattr(args, k) for k in SENSOR_PARAMETERS}
    return spec(
        args.sensor,
        sigma=args.sigma,
        params=params,
        preset=args.preset,
        origin=args.origin,
        sensor_pose=args.sensor_pose,
    )


def add_bag_arguments(parser: argparse.ArgumentParser) -> None:
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


@contextlib.contextmanager
def bag_frame(args: argparse.Namespace, *paths: str) -> Iterator[None]:
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


# ------------------------------------------------------------------- the query


def add_request_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of a query: the model, the surface, the thresholds of the states."""
    defaults = CollisionRequest()
    names = CollisionRequest.choices()
    group = parser.add_argument_group("the query (a CollisionRequest; defaults: the core's)")
    group.add_argument(
        "--model",
        choices=names["model"],
        default=None,
        help="what is classified: surface elements fitted to the points, or every point "
        f"(the paper's method) (default: {defaults.model})",
    )
    group.add_argument(
        "--decide-only",
        action="store_true",
        help="return as soon as the state is decided (no per-point probabilities)",
    )
    group.add_argument(
        "--segmentations",
        type=int,
        default=None,
        metavar="K",
        help="with --model elements: average P over K segmentations of the clouds "
        "(1 to 16; better ranking near contact for K times the work; default 1)",
    )
    group.add_argument(
        "--near-context",
        type=float,
        default=None,
        metavar="C",
        help="spacings of surface around the contact that the classifier sees (at least "
        "0.5; fewer is faster near contact, see docs/design/near-context.md; "
        f"default {defaults.near_context:g})",
    )
    _add_choice(group, "--surface", names, f"separating surface (default: {defaults.surface})")
    _add_choice(
        group,
        "--aggregation",
        names,
        f"aggregation of per-point probabilities (default: {defaults.aggregation})",
    )
    _add_choice(group, "--solver", names, f"SOCP solver (default: {defaults.solver})")
    _add_threshold_arguments(group, defaults)


def _add_choice(group: Any, flag: str, names: dict[str, Any], text: str) -> None:
    group.add_argument(flag, choices=names[flag.lstrip("-")], default=None, help=text)


def _add_threshold_arguments(group: Any, defaults: CollisionRequest) -> None:
    """Add ``--threshold-free`` and ``--threshold-collision`` (the request's thresholds)."""
    group.add_argument(
        "--threshold-free",
        type=float,
        default=None,
        metavar="P",
        help="P at or below this reads free (0 to 0.5, at most --threshold-collision; "
        f"default {defaults.threshold_free:g})",
    )
    group.add_argument(
        "--threshold-collision",
        type=float,
        default=None,
        metavar="P",
        help="P at or above this reads collision (0.5 to 1; "
        f"default {defaults.threshold_collision:g})",
    )


def check_thresholds(free: float | None, collision: float | None) -> None:
    """Check ``--threshold-free`` and ``--threshold-collision`` (``None``: the default).

    Raises
    ------
    CliError
        If a threshold is not a number, the two are out of order, or one is
        outside its range (``0 <= free <= 0.5 <= collision <= 1``).
    """
    defaults = CollisionRequest()
    given = {"--threshold-free": free, "--threshold-collision": collision}
    for flag, value in given.items():
        if value is not None and not math.isfinite(value):
            raise CliError(f"{flag} must be a number, got {value}")
    low = defaults.threshold_free if free is None else free
    high = defaults.threshold_collision if collision is None else collision
    if low > high:
        raise CliError(
            f"thresholds out of order: --threshold-free {low:g} is above "
            f"--threshold-collision {high:g} (give 0 <= free <= 0.5 <= collision <= 1)"
        )
    if not 0.0 <= low <= 0.5:
        raise CliError(f"--threshold-free must be in [0, 0.5], got {low:g}")
    if not 0.5 <= high <= 1.0:
        raise CliError(f"--threshold-collision must be in [0.5, 1], got {high:g}")


def request_from_args(args: argparse.Namespace) -> CollisionRequest:
    """Return the :class:`~cloudprox.CollisionRequest` of the query options in ``args``."""
    check_thresholds(args.threshold_free, args.threshold_collision)
    return CollisionRequest(
        model=args.model,
        surface=args.surface,
        aggregation=args.aggregation,
        solver=args.solver,
        decide_only=args.decide_only,
        segmentations=args.segmentations,
        near_context=args.near_context,
        threshold_free=args.threshold_free,
        threshold_collision=args.threshold_collision,
    )


# -------------------------------------------------------------------- the view


def add_view_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--html`` and ``--rerun``: where a command writes its interactive view."""
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


def check_view_arguments(args: argparse.Namespace) -> None:
    """Check the view options before the query: the files' names and the extras they need."""
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
        if path is not None and importlib.util.find_spec(module) is None:
            raise CliError(f"{flag} needs the '{module}' package: pip install 'cloudprox[{extra}]'")


def write_views(args: argparse.Namespace, make_scene: Callable[[], Any]) -> None:
    """Write the ``--html`` and ``--rerun`` views of a scene made by ``make_scene()``."""
    if args.html is None and args.rerun is None:
        return
    from cloudprox import view

    scene = make_scene()
    out = console(stderr=bool(getattr(args, "json", False)))
    if args.html is not None:
        path = view.write_html(
            scene, args.html, all_points=bool(getattr(args, "all_points", False))
        )
        size = path.stat().st_size / 1e6
        out.print(f"view written to {path.resolve()} ({size:.1f} MB; open it in a browser)")
    if args.rerun is not None:
        path = view.write_rerun(scene, args.rerun)
        out.print(f"Rerun recording written to {path.resolve()} (rerun {path})")
