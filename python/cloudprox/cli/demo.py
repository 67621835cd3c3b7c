"""``cloudprox demo`` and ``cloudprox example``: the first things to run."""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path
from typing import Any

from cloudprox._native import CollisionRequest, PointCloud, collide
from cloudprox.cli._common import (
    CliError,
    add_request_arguments,
    console,
    request_from_args,
    styled_state,
)

__all__ = ["DEMO_FAR_GAP", "DEMO_GAPS_SIGMA", "add_demo_parser", "add_example_parser"]

#: Gaps of the demo, in units of sigma.
DEMO_GAPS_SIGMA = (-3.0, -1.0, 0.0, 1.0, 2.0, 4.0, 8.0, 15.0)
#: The demo's "far" gap (metres).
DEMO_FAR_GAP = 0.25


def _cmd_demo(args: argparse.Namespace) -> int:
    from cloudprox.scenes import build_scene

    if not (math.isfinite(args.sigma) and args.sigma > 0.0):
        raise CliError(f"--sigma must be finite and > 0, got {args.sigma}")
    if args.points < 50:
        raise CliError(f"--points must be >= 50, got {args.points}")
    request = request_from_args(args)
    out = console()
    t_start = time.perf_counter()
    s = args.sigma
    scene = build_scene(sigma=s, points=args.points, seed=args.seed)
    piano = PointCloud(scene.piano_points, sigma=s)
    room = PointCloud(scene.room_points, sigma=s)
    out.print(
        f"Piano ({len(piano)} points) lowered over {scene.table} in a room ({len(room)} points), "
        f"noise sigma = {1e3 * s:g} mm, seed {args.seed}."
    )
    runs = _demo_runs(out, scene, piano, room, s, request)
    out.print(
        "P: the probability, under the noise, that the two sampled surfaces cross "
        "(of poses read P = 0.3, about 3 in 10 collide)."
    )
    png = _demo_figure(scene, runs, s, Path(args.out))
    out.print(f"Figure written to {png.resolve()}")
    out.print(f"Total time {time.perf_counter() - t_start:.2f} s.")
    return 0


def _demo_runs(
    out: Any, scene: Any, piano: PointCloud, room: PointCloud, s: float, request: CollisionRequest
) -> list[Any]:
    """Query the piano at every gap of the demo; print the table; return (gap, pose, result)."""
    from rich.table import Table

    table = Table(title="Piano against the room at exact gaps")
    for col in ("gap mm", "gap/sigma", "nearest", "P", "state", "patches", "ms"):
        table.add_column(col, justify="left" if col in ("nearest", "state") else "right")
    runs = []
    for gap in [g * s for g in DEMO_GAPS_SIGMA] + [DEMO_FAR_GAP]:
        pose = scene.piano_pose(gap)
        per_group = scene.gaps(pose)
        nearest = min(per_group, key=per_group.__getitem__)
        exact = per_group[nearest]
        result = collide(piano, room, pose_a=pose, request=request)
        runs.append((gap, pose, result))
        table.add_row(
            f"{1e3 * exact:+.1f}",
            f"{exact / s:+.1f}",
            nearest,
            f"{result.probability:.3g}",
            styled_state(result.state),
            str(len(result.patches)),
            f"{1e3 * result.stats.time_seconds:.1f}",
        )
    out.print(table)
    return runs


def _demo_figure(scene: Any, runs: list[Any], s: float, out: Path) -> Path:
    """Draw touching, and pressed 1 sigma into the table, into demo.png."""
    from cloudprox.plots import Panel, plot_collisions, world_points

    touching = next(r for r in runs if r[0] == 0.0)
    pressed = runs[DEMO_GAPS_SIGMA.index(-1.0)]
    out.mkdir(parents=True, exist_ok=True)
    png = out / "demo.png"
    panels = [
        Panel(
            world_points(scene.piano_points, pose),
            scene.room_points,
            result,
            f"piano {gap / s:+g} sigma ({1e3 * gap:+.1f} mm) above {scene.table}",
        )
        for gap, pose, result in (touching, pressed)
    ]
    plot_collisions(panels, png, bounds="contact", labels=("piano", "room"), elev=25.0)
    return png


def _cmd_example(args: argparse.Namespace) -> int:
    from cloudprox.examples import write_example_files

    paths = write_example_files(args.out, seed=args.seed)
    out = console()
    out.print(f"wrote the example files to {Path(args.out).resolve()}:")
    for name, path in paths.items():
        out.print(f"  {name}: {path.name}")
    out.print(
        "try: cloudprox collide "
        f"{paths['gripper']} {paths['scan']} --pose-a {paths['grasp-free']} "
        "--sensor depth-camera --preset nguyen-2012 --filter shadow"
    )
    return 0


def add_demo_parser(sub: Any) -> None:
    """Add ``demo`` to the subcommands ``sub``."""
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
    add_request_arguments(demo)
    demo.set_defaults(func=_cmd_demo)


def add_example_parser(sub: Any) -> None:
    """Add ``example`` to the subcommands ``sub``."""
    ex = sub.add_parser(
        "example",
        help="write example files: a depth-camera scan (PCD), a gripper (STL), two grasp poses",
    )
    ex.add_argument(
        "out", nargs="?", default="cloudprox-example", help="folder (default: %(default)s)"
    )
    ex.add_argument("--seed", type=int, default=0, help="noise seed (default: %(default)s)")
    ex.set_defaults(func=_cmd_example)
