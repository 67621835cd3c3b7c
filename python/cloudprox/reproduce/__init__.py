"""Reproduction of the paper's experiments against exact ground truth (``cloudprox reproduce``).

The piano-in-room scene (:mod:`cloudprox.scenes`) is sampled at one density, noise
is drawn at several levels (a share of the piano's bounding-box diagonal), and
random piano poses near contact (:mod:`.poses`) are answered by cloudprox (per
surface family and aggregation) and by the baselines (:mod:`.methods`) on the same
clouds, twice per pose with fresh noise. The exact signed distances come from
mesh-vs-mesh queries on the original meshes. :mod:`.metrics` scores every method,
:mod:`.figures` draws the pictures and :mod:`.run` writes everything out.
"""

from cloudprox.reproduce.run import Config, check_claims, run

__all__ = ["Config", "check_claims", "run"]
