"""Synthetic shapes and seeded noise for demos, tests and benchmarks.

These are not part of the query API: they make clouds to try it on. Each runs
in the Rust core and is deterministic (the same arguments give the same points
on every platform).

- :func:`sample_sphere`: points spread evenly over a sphere (Fibonacci lattice);
- :func:`sample_box_surface`: an axis-aligned box's surface on a grid;
- :func:`add_noise`: seeded isotropic Gaussian noise.

Examples
--------
>>> from cloudprox import synthetic
>>> ball = synthetic.sample_sphere(500, radius=0.1)
>>> ball.shape
(500, 3)
>>> noisy = synthetic.add_noise(ball, 0.002, seed=1)
>>> bool((noisy != ball).any())
True
"""

from __future__ import annotations

from cloudprox._native import add_noise, sample_box_surface, sample_sphere

__all__ = ["add_noise", "sample_box_surface", "sample_sphere"]
