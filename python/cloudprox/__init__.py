"""Probabilistic collision queries between noisy point clouds.

Two clouds are collision-free iff a surface separates them. Every point carries a
3x3 covariance; a robust classifier finds the separating surface that tolerates
that noise, every point gets the probability of lying on the wrong side of it, and
the pair gets an aggregated probability ``P`` and a state (``"free"``,
``"contact"`` or ``"collision"``).

Examples
--------
>>> import cloudprox
>>> from cloudprox import pose, synthetic
>>> pts = synthetic.sample_sphere(500, radius=0.1)
>>> a = cloudprox.PointCloud(synthetic.add_noise(pts, 0.002, seed=1), sigma=0.002)
>>> b = cloudprox.PointCloud(synthetic.add_noise(pts, 0.002, seed=2), sigma=0.002)
>>> pose_b = pose.from_translation((0.25, 0.0, 0.0))  # 5 cm (25 sigma) apart
>>> cloudprox.collide(a, b, pose_b=pose_b).state
'free'
"""

from cloudprox import filters, io, pose, synthetic
from cloudprox._native import (
    CollisionRequest,
    CollisionResult,
    ContactPatch,
    DepthCamera,
    DistanceField,
    DistanceResult,
    ExactShape,
    Lidar,
    LinkCollision,
    Mesh,
    MeshDistance,
    MeshSample,
    MotionRequest,
    MotionResult,
    PointCloud,
    Proximity,
    ProximityBatch,
    QueryStats,
    Robot,
    RobotBatchResult,
    RobotCollisionResult,
    RobotRequest,
    RobotStats,
    StereoCamera,
    TargetCollision,
    Voxels,
    __version__,
    check_motion,
    collide,
    collide_along,
    collide_many,
    collide_robot,
    collide_robot_many,
    distance,
    exact_intersects_many,
    exact_proximity,
    exact_proximity_many,
    exact_time_of_impact_many,
    ray_covariances,
)
from cloudprox.exceptions import (
    CloudproxError,
    DegenerateFacesWarning,
    FormatError,
    InvalidInputError,
    SolverError,
)

__all__ = [
    "CloudproxError",
    "CollisionRequest",
    "CollisionResult",
    "ContactPatch",
    "DegenerateFacesWarning",
    "DepthCamera",
    "DistanceField",
    "DistanceResult",
    "ExactShape",
    "FormatError",
    "InvalidInputError",
    "Lidar",
    "LinkCollision",
    "Mesh",
    "MeshDistance",
    "MeshSample",
    "MotionRequest",
    "MotionResult",
    "PointCloud",
    "Proximity",
    "ProximityBatch",
    "QueryStats",
    "Robot",
    "RobotBatchResult",
    "RobotCollisionResult",
    "RobotRequest",
    "RobotStats",
    "SolverError",
    "StereoCamera",
    "TargetCollision",
    "Voxels",
    "__version__",
    "check_motion",
    "collide",
    "collide_along",
    "collide_many",
    "collide_robot",
    "collide_robot_many",
    "distance",
    "exact_intersects_many",
    "exact_proximity",
    "exact_proximity_many",
    "exact_time_of_impact_many",
    "filters",
    "io",
    "pose",
    "ray_covariances",
    "synthetic",
]
