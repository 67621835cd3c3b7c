"""The development commands: ``cloudprox bench`` and ``cloudprox reproduce``.

They measure the library against other engines and reproduce the paper's
experiments; their code (:mod:`cloudprox.bench`, :mod:`cloudprox.reproduce`) is
imported only when they run, and ``reproduce`` needs the extra
``cloudprox[reproduce]`` for its reconstruction baseline.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from cloudprox.cli._common import CliError, console

__all__ = ["add_parsers"]


# -------------------------------------------------------------------------- bench


def _cmd_bench(args: argparse.Namespace) -> int:
    if args.points < 10 or args.repeat < 1:
        raise CliError("--points must be >= 10 and --repeat >= 1")
    rows, notes = _run_bench(args.points, args.repeat)
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
    _print_bench(args, rows, notes, ref)
    return 0


def _run_bench(points: int, repeat: int) -> tuple[list[Any], list[str]]:
    """Run the benchmark with a progress bar on stderr."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    from cloudprox.bench import CONFIGS, engine_names, run_bench

    total = len(engine_names()) * len(CONFIGS) * repeat
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        console=console(stderr=True),
        transient=True,
    ) as progress:
        task = progress.add_task("benchmark", total=total)

        def step(desc: str) -> None:
            progress.update(task, advance=1, description=desc)

        return run_bench(points, repeat, on_step=step)


def _print_bench(
    args: argparse.Namespace, rows: list[Any], notes: list[str], ref: dict[str, float]
) -> None:
    from rich.table import Table

    out = console()
    table = Table(title=f"Two noisy spheres, {args.points} points each, median of {args.repeat}")
    for col in ("config", "engine", "median ms", "ratio", "prep ms", "answer"):
        right = col in ("median ms", "ratio", "prep ms")
        table.add_column(col, justify="right" if right else "left", no_wrap=True)
    for r in rows:
        ratio = f"{r.median_ms / ref[r.config]:.3g}" if ref[r.config] else "-"
        table.add_row(r.config, r.engine, f"{r.median_ms:.3f}", ratio, f"{r.prep_ms:.1f}", r.answer)
    out.print(table)
    out.print("ratio = engine median / cloudprox median on the same configuration.")
    for note in notes:
        out.print(f"note: {note}")


# ---------------------------------------------------------------------- reproduce


def _cmd_reproduce(args: argparse.Namespace) -> int:
    try:
        from cloudprox.reproduce.run import available_cpus, run, steps
    except ModuleNotFoundError as e:  # scipy: the extra cloudprox[reproduce]
        raise CliError(
            f"cloudprox reproduce needs the '{e.name}' package: pip install 'cloudprox[reproduce]'"
        ) from None
    config = _reproduce_config(args)
    if args.workers is not None and args.workers < 1:
        raise CliError(f"--workers must be >= 1, got {args.workers}")
    out = Path(args.out)
    many = _ray_many(args.ray)
    con = console()
    con.print(_reproduce_intro(config))
    with _progress(con) as bar:
        task = bar.add_task("starting", total=steps(config))
        summary = run(
            config,
            out,
            lambda desc, n: bar.update(task, advance=n, description=desc),
            many,
            args.workers or available_cpus(),
        )
    _print_summary(con, summary)
    con.print(f"Figures, summary.md and results.csv in {out.resolve()} ({summary.seconds:.0f} s).")
    return 0


def _reproduce_config(args: argparse.Namespace) -> Any:
    """Return the run's ``Config``: the full run or ``--quick``, with the overrides given."""
    from dataclasses import replace

    from cloudprox.reproduce.run import Config

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
    return config


def _ray_many(address: str | None) -> Any:
    """Return ``collide_many`` as Ray tasks (``--ray``), or ``None`` (in this process)."""
    if address is None:
        return None
    from functools import partial

    from cloudprox import distributed

    try:
        ray: Any = distributed.ensure_ray(address or None)
    except ImportError as e:
        raise CliError(str(e)) from None
    cpus = ray.cluster_resources().get("CPU", 0)
    console().print(f"cloudprox's queries run as Ray tasks ({cpus:g} CPUs in the cluster).")
    return partial(distributed.collide_many, progress=False)


def _reproduce_intro(config: Any) -> str:
    """Describe the run: the scene, the poses and draws, the noise levels."""
    levels = ", ".join(f"{100 * x:g}%" for x in config.levels)
    text = (
        f"Reproducing on the piano-in-room scene: {config.piano_points} piano points, "
        f"{config.poses} poses x {config.draws} noise draws per level, levels {levels}"
    )
    if config.anisotropic_levels:
        text += f" + anisotropic {', '.join(f'{100 * x:g}%' for x in config.anisotropic_levels)}"
    if config.scan_poses:
        text += f"; real Kinect frame with the Panda gripper at {config.scan_poses} poses"
    return text + "."


def _progress(con: Any) -> Any:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("{task.description:<42}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=con,
        transient=False,
    )


def _print_summary(con: Any, summary: Any) -> None:
    """Print the metrics table and whether each of the paper's claims holds."""
    from rich.table import Table

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
    con.print(table)
    for c in summary.claims:
        mark = "[green]holds[/green]" if c.holds else "[red]does not hold[/red]"
        con.print(f"{c.level}: {c.claim}: {mark} ({c.detail})")


# ------------------------------------------------------------------------ parsers


def add_parsers(sub: Any) -> None:
    """Add ``bench`` and ``reproduce`` to the subcommands ``sub``."""
    bench = sub.add_parser(
        "bench", help="[development] cloudprox against comparison engines on the same clouds"
    )
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
    _add_reproduce_parser(sub)


def _add_reproduce_parser(sub: Any) -> None:
    rep = sub.add_parser(
        "reproduce",
        help="[development] the paper's experiments against exact ground truth and baselines",
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
