"""Exceptions raised by cloudprox.

The classes are created by the compiled module (``cloudprox._native``) and
re-exported here::

    Exception
    └── CloudproxError            base of everything cloudprox raises
        ├── InvalidInputError     also a ValueError: bad shapes, dtypes, values, options
        ├── FormatError           also a ValueError: a corrupt, truncated or unsupported file
        └── SolverError           also a RuntimeError: reserved for solver failures

A solve that does not converge is *not* an error: it falls back to a plane and is
reported as data (``ContactPatch.status == "fallback"`` and
``CollisionResult.stats.solver_fallbacks``). Missing files raise the builtin
``FileNotFoundError``.

Warnings: :class:`DegenerateFacesWarning` when a mesh file's faces that repeat a
vertex are dropped (their number is in the message).
"""

from cloudprox._native import CloudproxError, FormatError, InvalidInputError, SolverError

__all__ = [
    "CloudproxError",
    "DegenerateFacesWarning",
    "FormatError",
    "InvalidInputError",
    "SolverError",
]


class DegenerateFacesWarning(UserWarning):
    """Faces repeating a vertex were dropped while reading a mesh file."""
