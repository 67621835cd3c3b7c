"""MotionBenchMaker planning: cloudprox's chance constraint against exact and voxel checkers.

The MotionBenchMaker problems (MoveIt planning scenes of boxes, cylinders and
spheres; start and goal joint states) and robots come from the
``vamp-planner==0.6.4`` sdist on PyPI, fetched with pip into
``<cache>/mbm`` on first use (``$CLOUDPROX_CACHE`` or ``~/.cache/cloudprox``;
never committed; SHA-256 checked; :mod:`mbm.fetch`). Each problem's scene is
seen by a simulated Kinect v1 from a fixed position and as area-sampled
surfaces with 3 mm noise (:mod:`mbm.sensor`, about 120 000 points each), and
OMPL's RRTConnect plans it with every checker (:mod:`mbm.run`): python-fcl on
the exact primitives, python-fcl on each cloud's 1 cm voxels, and
:class:`cloudprox.planning.ChanceConstraint` on each cloud at
``max_probability`` 0.5 and 0.01. Every returned path is checked against the
exact primitives at 1 mm of link travel.

Needs ``pip install python-fcl ompl pyyaml`` (and yourdfpy for the forward
kinematics cross-check); the download needs network once.

Usage::

    python3 benches/motionbenchmaker.py [--robot panda] [--problems 2] [--first 1]
        [--scenarios box,cage] [--time-limit 5] [--seed 0] [--json results.json]

``RAYON_NUM_THREADS`` defaults to 1 (python-fcl is single-threaded too).
"""

from __future__ import annotations

import os

os.environ.setdefault("RAYON_NUM_THREADS", "1")

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from mbm.run import main

if __name__ == "__main__":
    raise SystemExit(main())
