"""Rigid poses as ``(4, 4)`` float64 homogeneous matrices, built in the Rust core.

One set of constructors for the whole package (scenes, readers, the
reproduction, tests and benchmarks use these):

- :func:`from_translation`: a pure translation;
- :func:`from_quaternion`: a unit quaternion **(w, x, y, z)**, scalar first,
  normalised (a zero quaternion is an error);
- :func:`from_rpy`: roll-pitch-yaw in ROS/URDF's convention, rotations about the
  **fixed x, then y, then z** axes: ``R = Rz(yaw) Ry(pitch) Rx(roll)``;
- :func:`from_rotation_vector`: axis times angle (radians);
- :func:`look_at`: a camera's optical frame (**x right, y down, z forward**, as
  ROS ``*_optical_frame`` and OpenCV, the frame of :class:`cloudprox.DepthCamera`);
- :func:`random_rotations`: seeded, uniformly random rotations.

Each pose rotates first, then translates: ``p_world = R p + t``. Bad input (NaN,
a wrong shape, a zero quaternion, a camera looking at itself) raises
:class:`cloudprox.InvalidInputError` naming the argument.

Examples
--------
>>> import numpy as np
>>> from cloudprox import pose
>>> quarter = pose.from_rpy((0.0, 0.0, np.pi / 2), translation=(1.0, 0.0, 0.0))
>>> np.round(quarter @ [1.0, 0.0, 0.0, 1.0], 12).tolist()
[1.0, 1.0, 0.0, 1.0]
>>> s = np.sqrt(0.5)
>>> bool(np.allclose(pose.from_quaternion((s, 0.0, 0.0, s)), pose.from_rpy((0, 0, np.pi / 2))))
True
"""

from __future__ import annotations

from cloudprox._native import pose_from_quaternion as from_quaternion
from cloudprox._native import pose_from_rotation_vector as from_rotation_vector
from cloudprox._native import pose_from_rpy as from_rpy
from cloudprox._native import pose_from_translation as from_translation
from cloudprox._native import pose_look_at as look_at
from cloudprox._native import random_rotations

__all__ = [
    "from_quaternion",
    "from_rotation_vector",
    "from_rpy",
    "from_translation",
    "look_at",
    "random_rotations",
]
