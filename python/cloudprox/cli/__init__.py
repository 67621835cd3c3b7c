"""The ``cloudprox`` command.

The user's commands:

``cloudprox demo``
    A piano lowered over a table in a room, at several exact gaps: a table of
    ``P`` and states, and a figure.
``cloudprox collide A B [--sigma S | --sensor ...] [--pose-a P] [--filter STEP]``
    One query between two files: point clouds (PLY, PCD, XYZ/CSV, NPY, LAS/LAZ)
    or meshes (STL, OBJ, OFF, PLY with faces).
``cloudprox view A B [--html FILE] [--rerun FILE.rrd] [--no-open]``
    The query of ``collide``, shown in 3D in the web browser (``collide`` and
    ``robot`` write the same view with ``--html`` / ``--rerun``).
``cloudprox robot URDF SCAN (--q Q | --q-file FILE)``
    A URDF robot at one or many configurations against a scan.
``cloudprox info FILE [--topic T] [--index I]``
    A summary of a point-cloud or mesh file, or the topics of a ROS bag (with
    ``--topic`` / ``--index``, that frame too).
``cloudprox example [DIR]``
    Example files: a depth-camera scan (PCD), a gripper (STL) and two grasp poses.

The commands that query (``demo``, ``collide``, ``view``, ``robot``) take the same options
of the query: ``--model``, ``--surface``, ``--aggregation``, ``--solver``,
``--decide-only``, ``--segmentations``, ``--near-context`` and the thresholds of
the states, ``--threshold-free`` and ``--threshold-collision``
(``0 <= free <= 0.5 <= collision <= 1``; see :class:`~cloudprox.CollisionRequest`).

The development commands (listed last):

``cloudprox bench``
    cloudprox against a nearest-neighbour baseline and python-fcl on the same clouds.
``cloudprox reproduce [--quick] [--out DIR] [--workers N] [--ray [ADDRESS]]``
    The paper's experiments against exact ground truth and the baselines: figures,
    a metrics table and the raw per-query results.

Every user error (missing or unreadable file, wrong shape, bad option) prints one
line to stderr and exits with status 2.

One module a job: :mod:`cloudprox.cli.demo` (``demo``, ``example``),
:mod:`cloudprox.cli.collide` (``collide``, ``view``), :mod:`cloudprox.cli.robot`,
:mod:`cloudprox.cli.info` and :mod:`cloudprox.cli.dev` (``bench``, ``reproduce``).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from cloudprox import __version__
from cloudprox.cli import collide, demo, dev, info, robot
from cloudprox.cli._common import CliError
from cloudprox.cli.collide import result_to_dict
from cloudprox.cli.demo import DEMO_FAR_GAP, DEMO_GAPS_SIGMA
from cloudprox.cli.info import file_info
from cloudprox.cli.robot import read_configurations
from cloudprox.exceptions import CloudproxError

__all__ = [
    "DEMO_FAR_GAP",
    "DEMO_GAPS_SIGMA",
    "CliError",
    "build_parser",
    "file_info",
    "main",
    "read_configurations",
    "result_to_dict",
]

#: The user's commands, in the order of ``cloudprox --help``; then :data:`DEVELOPMENT`.
COMMANDS = ("demo", "collide", "view", "robot", "info", "example")
#: The development commands, listed after the user's.
DEVELOPMENT = ("bench", "reproduce")


def build_parser() -> argparse.ArgumentParser:
    """Build the ``cloudprox`` command's argument parser, with every subcommand.

    The user's commands come first (:data:`COMMANDS`), the development commands
    last (:data:`DEVELOPMENT`). The documentation's command-line reference is
    generated from it.

    Returns
    -------
    argparse.ArgumentParser
        The parser :func:`main` uses.
    """
    parser = argparse.ArgumentParser(
        prog="cloudprox",
        description="Probabilistic collision queries between noisy point clouds.",
        epilog="bench and reproduce are development commands: they measure cloudprox "
        "against other engines and reproduce the paper's experiments.",
    )
    parser.add_argument("--version", action="version", version=f"cloudprox {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")
    demo.add_demo_parser(sub)
    collide.add_parsers(sub)
    robot.add_parsers(sub)
    info.add_parsers(sub)
    demo.add_example_parser(sub)
    dev.add_parsers(sub)
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
            f"cloudprox: error: a command is required "
            f"({', '.join(COMMANDS + DEVELOPMENT[:-1])} or {DEVELOPMENT[-1]})",
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
