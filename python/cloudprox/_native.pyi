"""Type stubs of the compiled module ``cloudprox._native`` (PyO3, ``crates/cloudprox-py``).

Conventions
-----------
Inputs are any numeric array-like, converted to C-contiguous float64: points
``(n, 3)``, covariances ``(n, 3, 3)``, transforms ``(4, 4)``. Outputs are fresh numpy
arrays. Units are SI: metres, and metres squared for covariances. Poses map an
object's own frame to the world; ``None`` means identity.
"""

import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, Final, Literal, final

import numpy as np
import numpy.typing as npt

__version__: Final[str]
__all__ = [
    "SOR_DEFAULT_K",
    "SOR_DEFAULT_STD_RATIO",
    "CloudFile",
    "CloudproxError",
    "CollisionRequest",
    "CollisionResult",
    "ContactPatch",
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
    "Occlusion",
    "PointCloud",
    "Proximity",
    "ProximityBatch",
    "QueryStats",
    "Robot",
    "RobotBatchResult",
    "RobotCollisionResult",
    "RobotRequest",
    "RobotStats",
    "ScanResult",
    "ScanStep",
    "SelfFilter",
    "SolverError",
    "StereoCamera",
    "TargetCollision",
    "Voxels",
    "__version__",
    "_read_mesh_counted",
    "add_noise",
    "check_motion",
    "collide",
    "collide_along",
    "collide_many",
    "collide_robot",
    "collide_robot_many",
    "crop_box",
    "distance",
    "exact_intersects_many",
    "exact_proximity",
    "exact_proximity_many",
    "exact_time_of_impact_many",
    "facing_pairs",
    "parse_mesh",
    "pose_from_quaternion",
    "pose_from_rotation_vector",
    "pose_from_rpy",
    "pose_from_translation",
    "pose_look_at",
    "random_rotations",
    "ray_covariances",
    "read_mesh",
    "read_point_cloud",
    "read_pointcloud2",
    "sample_box_surface",
    "sample_sphere",
    "scan_to_cloud",
    "shadow_filter",
    "statistical_outlier_removal",
    "voxel_downsample",
    "write_mesh",
    "write_point_cloud",
    "write_pointcloud2",
]

_FloatArray = npt.NDArray[np.float64]

#: Default number of neighbours of :func:`statistical_outlier_removal` (the core's).
SOR_DEFAULT_K: Final[int]
#: Default standard-deviation multiplier of :func:`statistical_outlier_removal` (the core's).
SOR_DEFAULT_STD_RATIO: Final[float]
_IntArray = npt.NDArray[np.int64]
#: A robot configuration: an array of one value per entry of ``Robot.joint_names``,
#: or a mapping from joint name to value (the joints it leaves out at their
#: reference value: 0, or the limit nearest 0).
_Configuration = npt.ArrayLike | Mapping[str, float]
_SurfaceName = Literal["linear", "quadric"]
_AggregationName = Literal["surface", "max", "union", "independent"]
_ModelName = Literal["elements", "points"]
_RobustModelName = Literal["gaussian", "chebyshev"]
_SolverName = Literal["primal_dual", "clarabel"]
_StateName = Literal["free", "contact", "collision"]
_MeshSideName = Literal["exact", "sampled"]
_CloudFormatName = Literal[
    "auto", "ply", "pcd", "xyz", "xyzn", "xyzrgb", "txt", "pts", "csv", "npy", "las", "laz"
]
_MeshFormatName = Literal["auto", "stl", "obj", "ply", "off"]
_EncodingName = Literal[
    "ascii", "binary", "binary_little_endian", "binary_big_endian", "binary_compressed"
]
_MergeName = Literal["mean", "independent"]

class CloudproxError(Exception):
    """Base class of every exception raised by cloudprox."""

class InvalidInputError(CloudproxError, ValueError):
    """An input is out of its domain or has the wrong shape or dtype.

    Raised for NaN or infinite coordinates, empty clouds, arrays of the wrong
    shape, negative sigmas, covariances that are not symmetric positive
    semi-definite, poses that are not rigid, thresholds out of order and unknown
    option names.
    """

class FormatError(CloudproxError, ValueError):
    """A file's content is not valid in its format.

    Raised for corrupt, truncated or unsupported files; the message names the
    file and the problem. Missing files raise ``FileNotFoundError`` instead.
    """

class SolverError(CloudproxError, RuntimeError):
    """A solver failed in a way that cannot be reported as data (reserved).

    A solve that does not converge is not an error: it falls back to a plane and
    is reported in ``ContactPatch.status`` and ``CollisionResult.stats``.
    """

@final
class PointCloud:
    """Points with a 3x3 covariance each, in the cloud's own frame.

    It pickles exactly (its root's points and sensor covariances, discretization
    neighbours, noise correlation and moves; the hierarchy is rebuilt on use).
    The covariance of a point is its sensor covariance (from ``sigma``, ``cov``
    or a ``sensor`` model seen from ``origin`` / ``sensor_pose``) plus, with ``discretization=True``, the k-nearest-neighbour
    discretization covariance. The bounding volume hierarchy over the points is
    built on first use and shared by every query on this cloud.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Point positions (metres); ``n >= 1``, all finite. An Open3D or trimesh
        point cloud is accepted too.
    sigma : float or array_like of shape (n,), optional
        Isotropic standard deviation of the sensor noise, one for all points or
        one per point (metres, ``>= 0``).
    cov : array_like, shape (n, 3, 3), optional
        Full sensor covariance per point (metres squared), symmetric positive
        semi-definite. Exclusive with ``sigma``; with neither the sensor noise
        is zero.
    sensor : DepthCamera or StereoCamera or Lidar, optional
        A range sensor's noise model: covariances anisotropic along each point's
        viewing ray. Exclusive with ``sigma`` and ``cov``; needs ``origin`` or
        ``sensor_pose``.
    origin : array_like, shape (3,), optional
        The sensor's origin in the cloud's frame (depth is then taken as range).
    sensor_pose : array_like, shape (4, 4), optional
        The sensor's pose in the cloud's frame; its ``+z`` axis is the optical
        axis (a PCD ``VIEWPOINT``, a ROS optical frame).
    discretization : bool, default False
        Add the discretization covariance estimated from each point's ``k``
        nearest neighbours (Gaussian weights of scale ``2 d_k``).
    k : int, optional
        Number of neighbours for ``discretization`` (``>= 2``; default: the
        core's, ``DiscretizationSettings::default()`` in Rust);
        only allowed with ``discretization=True``.
    noise_correlation : float, optional
        Correlation ``rho`` in ``[0, 1]`` of the sensor noise between the points
        of one surface element (``model="elements"``): the mean of ``m`` points
        has the covariance ``(1 - rho) sum(Sigma_i) / m^2 + rho sum(Sigma_i) / m``.
        Default: the sensor model's (0 for ``sigma`` and ``cov``: independent).

    Raises
    ------
    InvalidInputError
        On a wrong shape or dtype, an empty cloud, a NaN or infinite coordinate,
        a negative or non-finite sigma, a sigma array of the wrong length, a
        covariance that is not symmetric PSD, both ``sigma`` and ``cov``, or ``k``
        without ``discretization``; a sensor without a viewpoint, a point at the
        sensor origin or behind the sensor.
    """

    def __new__(
        cls,
        points: npt.ArrayLike | Any,
        sigma: npt.ArrayLike | None = None,
        cov: npt.ArrayLike | None = None,
        *,
        sensor: DepthCamera | StereoCamera | Lidar | None = None,
        origin: npt.ArrayLike | None = None,
        sensor_pose: npt.ArrayLike | None = None,
        discretization: bool = False,
        k: int | None = None,
        noise_correlation: float | None = None,
    ) -> PointCloud: ...
    @property
    def noise_correlation(self) -> float:
        """Correlation of the sensor noise between the points of one surface element.

        Set by ``noise_correlation=``, else the sensor model's
        (:meth:`DepthCamera.noise_correlation` at the median depth); 0 for ``sigma``
        and ``cov``.
        """
    @property
    def points(self) -> _FloatArray:
        """Point positions, shape ``(n, 3)``, float64 (metres)."""
    @property
    def covariances(self) -> _FloatArray:
        """Per-point total covariances, shape ``(n, 3, 3)``, float64 (metres squared)."""
    @property
    def sigma_max(self) -> _FloatArray:
        """Per-point largest standard deviation over all directions, shape ``(n,)``."""
    @property
    def spacing(self) -> _FloatArray:
        """Per-point sampling spacing ``(n,)``: the distance to the 6th nearest neighbour."""
    @property
    def cell_side(self) -> float:
        """The side of the square of surface each point stands for (metres).

        The median :attr:`spacing` ``d_6`` times ``sqrt(pi / 6)``: a density of
        ``6 / (pi d_6^2)`` points per square metre (a grid of pitch ``h`` gives
        ``h sqrt(2 pi / 6)``).
        """
    def prepare(self, request: CollisionRequest | None = None, **options: Any) -> None:
        """Build now, without the GIL, what a query under ``request`` builds on first use.

        The hierarchy and sampling spacing and, for ``model="elements"``, the
        surface elements (every one of the ``segmentations`` sets, each about as
        large as the cloud's points; ``options`` override the request's fields, as in
        :func:`collide`). Later queries then do not pay for it, the first
        query's ``time_seconds`` included; calling it again costs nothing.
        :func:`collide_many` and the robot queries do it themselves.
        """
    @property
    def sensor_covariances(self) -> _FloatArray:
        """Per-point sensor covariances (without the discretization part), ``(n, 3, 3)``."""
    @staticmethod
    def _from_state(state: tuple[Any, ...]) -> PointCloud:
        """Rebuild a pickled cloud (pickle support; the state comes from ``__reduce__``)."""
    def select_by_index(self, indices: npt.ArrayLike, invert: bool = False) -> PointCloud:
        """Return a new cloud of the points at ``indices`` (with ``invert``, of the others).

        Each point keeps its sensor covariance and the cloud its noise
        correlation; a discretization covariance is estimated again from the kept
        points' neighbours. An index out of range, a boolean mask (pass
        ``numpy.flatnonzero(mask)``) or an empty selection raise
        :class:`InvalidInputError`. :func:`cloudprox.filters.split_box` and
        :func:`cloudprox.filters.split_labels` split a scan into a grasp target
        and the rest with it.
        """
    def transformed(self, transform: npt.ArrayLike) -> PointCloud:
        """Return a copy moved by a rigid transform.

        Parameters
        ----------
        transform : array_like, shape (4, 4)
            Homogeneous rigid transform ``[R t; 0 0 0 1]``.

        Returns
        -------
        PointCloud
            The moved cloud: points ``R x + t``, covariances ``R S R^T``.

        Raises
        ------
        InvalidInputError
            If ``transform`` is not a ``(4, 4)`` rigid transform.
        """
    def __len__(self) -> int: ...

@final
class DistanceResult:
    """The answer of :func:`distance`, in world coordinates."""

    @property
    def distance(self) -> float:
        """The estimated signed separation of the two surface estimates, metres.

        Negative where they interpenetrate; with ``beyond_max_distance``, a
        lower bound on it instead.
        """
    @property
    def std(self) -> float:
        """The standard deviation of ``distance``, metres (0 for a bound)."""
    @property
    def point_a(self) -> _FloatArray:
        """The point of A's surface estimate where the distance is read, shape ``(3,)`` (NaN for a bound)."""
    @property
    def point_b(self) -> _FloatArray:
        """The point of B's surface estimate, shape ``(3,)`` (NaN for a bound)."""
    @property
    def normal(self) -> _FloatArray:
        """The unit direction the distance is measured along, from A towards B, shape ``(3,)`` (NaN for a bound)."""
    @property
    def beyond_max_distance(self) -> bool:
        """Whether the query stopped at ``max_distance``: ``distance`` is a lower bound."""
    @property
    def near_contact(self) -> bool:
        """Whether the reading is one of :func:`collide`'s: two clouds within the noise's reach of each other.

        Always ``False`` with an exact mesh side, whose reading is the cloud's
        nearest element surface to the mesh at any distance.
        """
    @property
    def crossing_probability(self) -> float:
        """``Phi(-distance / std)``: the probability that the surfaces cross at the reading.

        At most :func:`collide`'s ``P``; equal to it when the contact is one
        facing pair of surface elements.
        """

@final
class ContactPatch:
    """One patch of a near region with its own separating surface (world frame).

    The surface ``f`` is positive on cloud A's side and negative on cloud B's.
    """

    @property
    def component(self) -> int:
        """Index of the connected near region the patch belongs to."""
    @property
    def indices_a(self) -> _IntArray:
        """Indices of cloud A's points in the patch, shape ``(k,)``, int64."""
    @property
    def indices_b(self) -> _IntArray:
        """Indices of cloud B's points in the patch, shape ``(l,)``, int64."""
    @property
    def point(self) -> _FloatArray:
        """A point on the surface where the clouds come closest, shape ``(3,)``."""
    @property
    def normal(self) -> _FloatArray:
        """Unit normal of the surface at ``point``, from A towards B, shape ``(3,)``."""
    @property
    def separation(self) -> float:
        """Estimated signed separation along the normal (metres); negative = overlap."""
    @property
    def probability(self) -> float:
        """The patch's aggregated collision probability."""
    @property
    def surface(self) -> _SurfaceName:
        """The surface family."""
    @property
    def status(self) -> Literal["solved", "almost_solved", "fallback"]:
        """How the solve ended (``"fallback"``: did not converge, a plane was used)."""
    @property
    def iterations(self) -> int:
        """Interior-point iterations of the solve."""
    def evaluate(self, x: npt.ArrayLike) -> tuple[_FloatArray, _FloatArray]:
        """Evaluate the separating surface and its gradient.

        Parameters
        ----------
        x : array_like, shape (m, 3)
            Points in the world frame.

        Returns
        -------
        f : ndarray, shape (m,)
            ``f(x)``, positive on A's side.
        grad : ndarray, shape (m, 3)
            ``grad f(x)``.

        Notes
        -----
        The per-point probability of a point ``x`` with covariance ``S`` and label
        ``c`` (+1 for A, -1 for B) is ``Phi(-c f(x) / sqrt(g^T S g))`` with
        ``g = grad f(x)``.
        """

@final
class CollisionResult:
    """The answer of :func:`collide`."""

    @property
    def probability(self) -> float:
        """The pair's collision probability ``P`` in ``[0, 1]``."""
    @property
    def state(self) -> _StateName:
        """``"free"`` (``P <= threshold_free``), ``"collision"`` (``P >= threshold_collision``) or ``"contact"``."""
    @property
    def probabilities_a(self) -> _FloatArray:
        """Per-point probability of A's points being on the wrong side, shape ``(n_a,)``.

        Points outside every near region get 0. The result stores only the
        near regions' points (a batch of results of a large cloud holds memory
        in proportion to its contacts): each read builds a new array.
        """
    @property
    def probabilities_b(self) -> _FloatArray:
        """Per-point probability of B's points being on the wrong side, shape ``(n_b,)``."""
    @property
    def nonzero_a(self) -> tuple[_IntArray, _FloatArray]:
        """A's points with a non-zero probability, by index, and their probabilities.

        ``(indices (m,) int64, probabilities (m,))``: what ``probabilities_a``
        holds without its zeros, without building the ``(n_a,)`` array.
        """
    @property
    def nonzero_b(self) -> tuple[_IntArray, _FloatArray]:
        """The same for B."""
    @property
    def points_a(self) -> _FloatArray | None:
        """Side A's points as queried (a mesh side: its samples), world frame, ``(n_a, 3)``.

        ``None`` when the result does not record them (the per-link results of
        robot queries). The result shares the clouds it was computed on.
        """
    @property
    def points_b(self) -> _FloatArray | None:
        """Side B's points as queried, world frame, shape ``(n_b, 3)``, or ``None``."""
    def show(self, path: str | os.PathLike[str] | None = None, **options: Any) -> Path:
        """Write the interactive HTML view and open it in the web browser.

        Calls :func:`cloudprox.view.show` (needs ``cloudprox[view]``): ``path``
        (default: a new temporary file), ``open_browser`` and the options of
        :func:`cloudprox.view.collision_scene`. Returns the file written.
        """
    @property
    def patches(self) -> list[ContactPatch]:
        """The classified patches of the near regions."""
    @property
    def point_aggregates(self) -> dict[str, float] | None:
        """``P`` under each of the paper's aggregations, with the points model.

        ``{"max": ..., "union": ..., "independent": ...}`` from this query's
        per-point probabilities over the points ``P`` aggregates: a points-model
        query asking for one of them returns it as its ``probability``, exactly,
        so one query gives all three. ``None`` with the elements model (its ``P``
        aggregates surface crossings) and with ``decide_only``.
        """
    @property
    def stats(self) -> QueryStats:
        """Counters and timings of the query."""

@final
class QueryStats:
    """Counters and timings of one :func:`collide` query (``CollisionResult.stats``)."""

    @property
    def node_pairs_visited(self) -> int:
        """Node pairs of the two hierarchies tested during the traversal."""
    @property
    def leaf_pairs(self) -> int:
        """Leaf pairs kept (not pruned)."""
    @property
    def near_regions(self) -> int:
        """Connected near regions."""
    @property
    def patches(self) -> int:
        """Patches classified (``len(result.patches)``)."""
    @property
    def misfit_cuts(self) -> int:
        """Patches cut in two because one surface misfit them."""
    @property
    def patches_beyond_reach(self) -> int:
        """Patches of the elements model pruned because no element faces the other side within the noise's reach."""
    @property
    def surface_crossings(self) -> int:
        """Element surface pairs found crossing, 0 or 1 per segmentation (elements model: before any patch with ``decide_only``, after the patches found no collision in the full query)."""
    @property
    def surface_links(self) -> int:
        """Element pairs whose surfaces face within the noise's reach although no sample of one of them was near the other (a metre-wide element a thin part passes through): each brought both elements into the near set."""
    @property
    def points_classified(self) -> int:
        """Points of both clouds that went into a classifier."""
    @property
    def solver_iterations(self) -> int:
        """Interior-point iterations over all patches."""
    @property
    def clarabel_fallbacks(self) -> int:
        """Patches where the specialized solver gave way to Clarabel."""
    @property
    def solver_fallbacks(self) -> int:
        """Patches whose solve fell back to a plane (``ContactPatch.status == "fallback"``)."""
    @property
    def pruned_bound(self) -> float:
        """Upper bound on the probability that any pruned point is on the wrong side."""
    @property
    def time_seconds(self) -> float:
        """Wall time of the query (seconds)."""
    def to_dict(self) -> dict[str, int | float]:
        """Return the statistics as a dict of ``int`` and ``float``, ready for JSON."""
    def __eq__(self, value: object, /) -> bool: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...
    @staticmethod
    def _from_state(state: tuple[tuple[int, ...], float]) -> QueryStats: ...

@final
class Mesh:
    """A triangle mesh, validated on construction.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        Vertex positions (metres), all finite.
    faces : array_like of int, shape (m, 3)
        Vertex indices of each triangle, counter-clockwise seen from outside
        when the mesh bounds a solid; ``m >= 1``.

    Raises
    ------
    InvalidInputError
        On a wrong shape or dtype, no vertex or face, a non-finite coordinate, an
        index out of range or a face that repeats a vertex.
    """

    def __new__(cls, vertices: npt.ArrayLike, faces: npt.ArrayLike) -> Mesh: ...
    @staticmethod
    def cuboid(hx: float, hy: float, hz: float) -> Mesh:
        """Make a box centred at the origin with half extents ``(hx, hy, hz)`` (each > 0)."""
    @staticmethod
    def cylinder(radius: float, half_height: float, segments: int = 32) -> Mesh:
        """Make a cylinder along z centred at the origin: a prism of ``segments`` (>= 3) sides."""
    @staticmethod
    def merged(meshes: list[Mesh]) -> Mesh:
        """Several meshes as one (faces re-indexed)."""
    @property
    def vertices(self) -> _FloatArray:
        """Vertices, shape ``(n, 3)``, float64 (metres)."""
    @property
    def faces(self) -> _IntArray:
        """Faces, shape ``(m, 3)``, int64."""
    @property
    def area(self) -> float:
        """Surface area (square metres)."""
    @property
    def volume(self) -> float:
        """Enclosed volume (cubic metres; meaningful when the mesh is closed)."""
    @property
    def is_closed(self) -> bool:
        """Whether every edge is shared by exactly two faces, once in each direction."""
    def is_convex(self, tolerance: float = 1e-9) -> bool:
        """Whether the mesh is closed and convex, within ``tolerance`` metres."""
    def bounds(self) -> tuple[_FloatArray, _FloatArray]:
        """Lower and upper corners of the bounding box, each shape ``(3,)``."""
    def transformed(self, transform: npt.ArrayLike) -> Mesh:
        """Return a copy moved by the ``(4, 4)`` rigid transform ``transform``."""
    def sample(
        self, n: int | None = None, *, density: float | None = None, seed: int = 0
    ) -> MeshSample:
        """Sample the surface uniformly (faces chosen with probability proportional to area).

        Parameters
        ----------
        n : int, optional
            Number of points.
        density : float, optional
            Points per square metre instead (``round(density * area)`` points).
        seed : int, default 0
            Seed: the same seed gives the same points.

        Returns
        -------
        MeshSample
            ``points`` ``(k, 3)``, ``normals`` ``(k, 3)`` (unit outward normal of
            each point's face) and ``faces`` ``(k,)`` (face index of each point);
            unpacks as ``points, normals, faces``.

        Raises
        ------
        InvalidInputError
            If not exactly one of ``n`` and ``density`` is given, or the mesh has
            zero area.
        """

@final
class MeshSample:
    """What :meth:`Mesh.sample` returns; unpacks as ``points, normals, faces``."""

    @property
    def points(self) -> _FloatArray:
        """The sampled points, shape ``(k, 3)``."""
    @property
    def normals(self) -> _FloatArray:
        """The unit outward normal of each point's face, shape ``(k, 3)``."""
    @property
    def faces(self) -> _IntArray:
        """The index of the face each point lies on, shape ``(k,)``."""
    def __iter__(self) -> Iterator[Any]: ...
    def __getitem__(self, key: int, /) -> Any: ...
    def __len__(self) -> int: ...

@final
class ExactShape:
    """An object made of mesh parts, prepared for exact queries.

    Closed convex parts become convex polyhedra (exact distance by GJK,
    penetration depth by EPA); other parts triangle meshes (exact distance and
    intersection, containment when closed). Built on parry.

    Parameters
    ----------
    parts : list of Mesh
        The parts, in the object's own frame (at least one).
    solid : bool, default True
        False: every part is a bare surface, closed or not (intersection iff
        triangles cross; no containment, no penetration depth), for meshes whose
        orientation is not to be trusted, such as reconstructions from scans.
    """

    def __new__(cls, parts: list[Mesh], *, solid: bool = True) -> ExactShape: ...
    @property
    def part_kinds(self) -> list[str]:
        """Per part, ``"convex"``, ``"solid"`` (closed mesh) or ``"surface"``."""
    def __len__(self) -> int: ...

@final
class Proximity:
    """What :func:`exact_proximity` returns: whether two shapes intersect, and how far apart or how deep."""

    @property
    def intersecting(self) -> bool:
        """Whether the solids (or surfaces, for open parts) intersect."""
    @property
    def distance(self) -> float:
        """The distance between the shapes (metres); 0 when intersecting."""
    @property
    def penetration_depth(self) -> float | None:
        """The largest depth over intersecting convex part pairs; ``None`` when unknown."""
    @property
    def signed_distance(self) -> float:
        """``distance``, or minus the depth when intersecting (NaN when the depth is unknown)."""
    def to_dict(self) -> dict[str, bool | float | None]:
        """Return the four attributes as a dict."""
    def __eq__(self, value: object, /) -> bool: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...
    @staticmethod
    def _from_state(
        intersecting: bool, distance: float, penetration_depth: float | None
    ) -> Proximity: ...

def exact_proximity(
    a: ExactShape,
    b: ExactShape,
    pose_a: npt.ArrayLike | None = None,
    pose_b: npt.ArrayLike | None = None,
) -> Proximity:
    """Exact proximity of two posed objects (the ground truth of the evaluation).

    Returns
    -------
    Proximity
        ``intersecting``; ``distance`` (0 when intersecting); ``penetration_depth``,
        the largest over intersecting convex part pairs (``None`` when a
        non-convex part intersects); ``signed_distance`` (distance, or minus the
        depth; NaN when the depth is unknown).
    """

def exact_intersects_many(
    a: ExactShape,
    b: ExactShape,
    poses_a: npt.ArrayLike,
    pose_b: npt.ArrayLike | None = None,
) -> npt.NDArray[np.bool_]:
    """Whether ``a`` at each pose ``(m, 4, 4)`` intersects ``b``, in parallel.

    The ``intersecting`` of :func:`exact_proximity_many` without the distances,
    which cost far more for large meshes that are apart.
    """

def exact_proximity_many(
    a: ExactShape,
    b: ExactShape,
    poses_a: npt.ArrayLike,
    pose_b: npt.ArrayLike | None = None,
) -> ProximityBatch:
    """:func:`exact_proximity` for poses ``(m, 4, 4)`` of ``a``, in parallel.

    Returns
    -------
    ProximityBatch
        One :class:`Proximity` per pose, read as arrays of shape ``(m,)``
        (``intersecting``, ``distance``, ``penetration_depth`` (NaN when
        unknown), ``signed_distance``) or pose by pose (``batch[i]``).
    """

def exact_time_of_impact_many(
    a: ExactShape,
    b: ExactShape,
    poses_a: npt.ArrayLike,
    directions: npt.ArrayLike,
    target: npt.ArrayLike | None = None,
    max_travel: float = ...,
    pose_b: npt.ArrayLike | None = None,
) -> npt.NDArray[np.float64]:
    """How far ``a`` moves from each start before its signed distance to ``b`` reaches a target.

    Each start ``poses_a[i]`` ``(m, 4, 4)`` is translated (orientation kept)
    along ``directions[i]`` (``(m, 3)``, or one ``(3,)`` for all; normalized).
    ``target`` (metres, a scalar or ``(m,)``, default 0: contact) is the signed
    distance to reach: ``>= 0`` a gap, found by shape casting; ``< 0`` a
    penetration depth (every intersecting part pair convex), found past the
    first contact on :func:`exact_proximity`'s signed distance. Runs in
    parallel, the GIL released.

    Returns
    -------
    ndarray, shape (m,)
        The travel (metres along the unit direction) to the first pose at the
        target: 0 where the start is already at or within it, ``inf`` where it
        is not reached within ``max_travel`` (default: unbounded).

    Raises
    ------
    InvalidInputError
        A pose or direction not finite (or a zero direction), a target not
        finite, ``max_travel`` negative or NaN, shapes that do not match, or a
        negative target where a non-convex part intersects (depth unknown).
    """

@final
class ProximityBatch:
    """What :func:`exact_proximity_many` returns: one :class:`Proximity` per pose."""

    @property
    def intersecting(self) -> npt.NDArray[np.bool_]:
        """Whether the shapes intersect at each pose, bool ``(m,)``."""
    @property
    def distance(self) -> npt.NDArray[np.float64]:
        """Distance between the shapes (0 where they intersect), ``(m,)``."""
    @property
    def penetration_depth(self) -> npt.NDArray[np.float64]:
        """The penetration depth where the shapes intersect (NaN where unknown or apart), ``(m,)``."""
    @property
    def signed_distance(self) -> npt.NDArray[np.float64]:
        """``distance``, or minus the depth where intersecting, ``(m,)``."""
    def to_dict(self) -> dict[str, npt.NDArray[np.float64] | npt.NDArray[np.bool_]]:
        """Return the four arrays as a dict (``tolist()`` them for JSON)."""
    def __len__(self) -> int:
        """Return the number of poses."""
    def __getitem__(self, index: int, /) -> Proximity:
        """Return the :class:`Proximity` at pose ``index`` (negative counts from the end)."""

@final
class CollisionRequest:
    """The options of a collision query, as one immutable value.

    Accepted by :func:`collide`, :func:`collide_many`, :func:`collide_robot`,
    :func:`collide_robot_many` and :func:`check_motion` as ``request=``. Every
    option is keyword-only; one left out (or ``None``) takes the Rust core's
    default (``CollisionRequest::default()``, documented on each field of the
    Rust struct), so ``repr(CollisionRequest())`` and
    ``CollisionRequest().to_dict()`` show the defaults; none is written here. Unknown enum names,
    values out of their domain and thresholds out of order raise
    :class:`InvalidInputError` naming the option (and the valid names).
    Requests are frozen (compare equal option by option, hash and pickle);
    :meth:`replace` gives a modified copy.

    Parameters
    ----------
    surface : {"quadric", "linear"}, optional
        Family of the separating surface.
    aggregation : {"max", "surface", "union", "independent"}, optional
        How per-point probabilities become ``P`` the
        paper's ``max``, ``union`` (``min(1, sum p_i)``) and ``independent``
        (``1 - prod(1 - p_i)``) of the per-point probabilities, or ``surface``:
        the largest probability that the surface around a point (the point and
        its 6 nearest neighbours of its patch, margins averaged) is on the wrong
        side, better near contact on the piano scene but blind to deep crossings
        (see docs/method.md). Only points within the noise's reach of the other
        cloud count.
    threshold_collision : float, optional
        ``P >= threshold_collision`` is ``"collision"``.
    threshold_free : float, optional
        ``P <= threshold_free`` is ``"free"``. Must satisfy
        ``0 <= threshold_free <= 0.5 <= threshold_collision <= 1``.
    prune_epsilon : float, optional
        Node pairs whose crossing bound is below this are pruned.
    region_max_points : int, optional
        Near regions larger than this are split into patches (``>= 8``):
        a bound on the cost of one solve. Regions are also cut where one surface
        misfits (``QueryStats.misfit_cuts``). A cloud too sparse to be cut (a
        handful of points against thousands) is shared by the patches; its
        points keep their largest value.
    near_context : float, optional
        Context kept around the near points, in sampling spacings (each point's
        distance to its 6th nearest neighbour; ``>= 0.5``).
    slack_weight : float, optional
        Weight of the slack term of the classifier against ``|w|^2 / 2``
        (``lambda`` in the formulas; the default is close to a hard margin).
    robust_eta : float, optional
        Confidence of each point's chance constraint, in ``[0.5, 1)``.
    robust_model : {"gaussian", "chebyshev"}, optional
        Distribution assumption of the robustness radius.
    solver : {"primal_dual", "clarabel"}, optional
        SOCP solver: the specialized primal-dual method (falls back to Clarabel if
        it does not converge) or Clarabel alone.
    use_hierarchy : bool, optional
        ``False`` finds the near points by testing every point pair and classifies
        them in one region (the brute-force reference).
    model : {"points", "elements"}, optional
        What is classified: every point (the paper's
        method), or the cloud's *surface elements*: groups of points that fit a
        smooth surface within their noise, built once per cloud, each standing
        for its fitted surface with the covariance of the fit (the default).
        With ``"elements"``, ``P`` is the probability that the two fitted
        surfaces cross at the contact, from the contact's independent facing
        readings (see docs/method.md), and near regions hold tens of samples at
        any noise level; per-point probabilities are still Eq. 3 of each
        point. ``aggregation="surface"`` belongs to ``"points"``.
    decide_only : bool, optional
        Return as soon as the state is decided: no per-point
        probabilities or separation estimates (NaN), and with ``max`` the query
        stops at the first patch that reaches ``threshold_collision``. The state
        is that of the full query.
    segmentations : int, optional
        With ``model="elements"``, how many segmentations of the two clouds
        the query averages over (1 to 16; 1 with ``"points"``): the same
        points grouped into differently placed elements, the query run on
        each, ``P`` and the per-point probabilities their means, the patches
        and counters those of every run. Where the element boundaries fall
        near a contact changes which planes read it, from one noise draw to
        the next more than the planes' own noise; the mean ranks poses near
        contact better, for as many times the work (docs/design/segmentations.md); in a
        query on its own the runs after the first go to the thread pool.
        Deciding only, each run
        still computes its whole ``P``, without the per-point work.

    Examples
    --------
    >>> import cloudprox as cp
    >>> request = cp.CollisionRequest(surface="linear", threshold_free=0.05)
    >>> request.replace(model="elements").model
    'elements'
    """

    def __new__(
        cls,
        *,
        surface: _SurfaceName | None = None,
        aggregation: _AggregationName | None = None,
        threshold_collision: float | None = None,
        threshold_free: float | None = None,
        prune_epsilon: float | None = None,
        region_max_points: int | None = None,
        near_context: float | None = None,
        slack_weight: float | None = None,
        robust_eta: float | None = None,
        robust_model: _RobustModelName | None = None,
        solver: _SolverName | None = None,
        use_hierarchy: bool | None = None,
        model: _ModelName | None = None,
        decide_only: bool | None = None,
        segmentations: int | None = None,
    ) -> CollisionRequest: ...
    @property
    def surface(self) -> _SurfaceName:
        """Family of the separating surface."""
    @property
    def aggregation(self) -> _AggregationName:
        """How per-point probabilities become ``P``."""
    @property
    def threshold_collision(self) -> float:
        """``P`` at or above this reads ``"collision"``."""
    @property
    def threshold_free(self) -> float:
        """``P`` at or below this reads ``"free"``."""
    @property
    def prune_epsilon(self) -> float:
        """Node pairs whose crossing bound is below this are pruned."""
    @property
    def region_max_points(self) -> int:
        """Near regions with more points are split into patches."""
    @property
    def near_context(self) -> float:
        """Context kept around a near region, in sampling spacings."""
    @property
    def slack_weight(self) -> float:
        """Weight of the classifier's slack term (``lambda`` in the formulas)."""
    @property
    def robust_eta(self) -> float:
        """Confidence of each point's chance constraint."""
    @property
    def robust_model(self) -> _RobustModelName:
        """Noise assumption of the chance constraints."""
    @property
    def solver(self) -> _SolverName:
        """Solver of the classifier."""
    @property
    def use_hierarchy(self) -> bool:
        """``False``: every point pair is tested (the brute-force reference)."""
    @property
    def model(self) -> _ModelName:
        """What is classified: points or surface elements."""
    @property
    def decide_only(self) -> bool:
        """Return as soon as the state is decided."""
    @property
    def segmentations(self) -> int:
        """With the elements model, how many segmentations ``P`` averages over."""
    def replace(self, **changes: Any) -> CollisionRequest:
        """Return a copy with the given options changed (``None`` leaves one as it is).

        Raises
        ------
        InvalidInputError
            On an unknown option name or a value out of its domain.
        """
    def to_dict(self) -> dict[str, str | float | int | bool]:
        """Return the options as a dict, ready for JSON; ``CollisionRequest(**d)`` rebuilds it."""
    @staticmethod
    def choices() -> dict[str, tuple[str, ...]]:
        """Return the valid names of the enum options (``surface``, ``aggregation``, ``robust_model``, ``solver``, ``model``)."""
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

def facing_pairs(
    a: PointCloud | Mesh | Any,
    b: PointCloud | Mesh | Any,
    pose_a: npt.ArrayLike | None = None,
    pose_b: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | None = None,
    **options: Any,
) -> dict[str, npt.NDArray[Any]]:
    """Return the elements model's facing pairs of ``collide(a, b, pose_a, pose_b)``, for diagnostics.

    One row per pair of surface elements that face each other in the query's
    patches: ``from_a`` (the probe element is A's), ``element`` and
    ``other_element`` (their indices), ``probe`` and ``facing`` (the two
    surfaces' points, world frame, shape (n, 3)), ``direction`` (the unit
    normal the gap is measured along), ``gap`` and ``std`` (the estimated gap
    and its standard deviation, metres), ``probability`` (its wrong-side
    probability), ``within_reach``, ``beside`` (the probe lies past the other
    element's extent), ``probe_edge``, ``count``, ``other_count``, ``size``,
    ``other_size`` and ``own_std``. ``benches/analytic.py`` and
    ``benches/realmesh.py --residuals`` compare ``gap`` with the exact gap:
    ``(g_true - gap) / std`` should be standard normal.
    """

def distance(
    a: PointCloud | Mesh | Any,
    b: PointCloud | Mesh | Any,
    pose_a: npt.ArrayLike | None = None,
    pose_b: npt.ArrayLike | None = None,
    *,
    max_distance: float | None = None,
    request: CollisionRequest | None = None,
    **options: Any,
) -> DistanceResult:
    """Measure the clearance between two sampled surfaces, with its standard deviation.

    Estimates the signed separation of the *surface estimates* of two clouds
    (each cloud's surface elements), or of an exact mesh and a cloud's, not
    of raw points: negative where they interpenetrate. Near a contact the
    gap and its standard deviation are the readings :func:`collide`'s ``P``
    is made of, so ``Phi(-distance / std)`` (``crossing_probability``) is at
    most ``collide``'s ``P`` and equals it when the contact is one pair of
    surface elements. Farther away, the nearest pair of element surfaces is
    read with the same gap formula.

    Parameters
    ----------
    a, b : PointCloud or mesh
        Two clouds, or one cloud and one mesh (its exact surface).
    pose_a, pose_b : array_like, shape (4, 4), optional
        Rigid poses (own frame to world); ``None`` is the identity.
    max_distance : float, optional
        Stop early, metres, when the surfaces are surely farther apart than
        this: the result is then a lower bound (``beyond_max_distance``).
        Must be ``>= 0``.
    request, **options
        The collision request whose noise model and reach the reading uses,
        as for :func:`collide`.

    Raises
    ------
    InvalidInputError
        A negative or NaN ``max_distance``, a pose that is not a finite
        rigid transform, an unknown option or an invalid request.
    """

def collide(
    a: PointCloud | Mesh | Any,
    b: PointCloud | Mesh | Any,
    pose_a: npt.ArrayLike | None = None,
    pose_b: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | None = None,
    mesh_side: str | None = None,
    mesh_spacing: float | None = None,
    **options: Any,
) -> CollisionResult:
    """Probabilistic collision query between two noisy point clouds.

    The options are ``request`` (a :class:`CollisionRequest`; default: the Rust
    defaults). Keyword options named as :class:`CollisionRequest`'s are a
    shortcut: ``collide(a, b, surface="linear")`` is
    ``collide(a, b, request=CollisionRequest(surface="linear"))``, and given
    with ``request`` they override its fields. The GIL is released during the
    query.

    Either side may be a mesh (``Mesh``, a trimesh ``Trimesh`` or an Open3D
    ``TriangleMesh``). By default (``mesh_side="exact"``) its surface is the
    separating surface and nothing is trained: each cloud point's probability
    is Eq. 3 against it, ``Phi(-sd(x) / sqrt(n^T Sigma n))`` with ``sd`` the
    signed distance to the mesh and ``n`` its gradient, and ``P`` reads the
    cloud's surface elements against it (the elements model's ``P``; with
    ``model="points"``, the aggregation of the per-point probabilities). The
    result has no patches, and the mesh side no points (``points_a`` or
    ``points_b`` is ``None``, its probabilities empty). A ``Mesh`` keeps its
    signed distance, so repeated queries do not build it again. With
    ``mesh_side="sampled"`` (or a ``mesh_spacing``) the mesh is sampled every
    ``mesh_spacing`` metres into a cloud without sensor noise whose covariance
    is its own discretization (``spacing^2 / 12`` across each sample's face,
    none along its normal), and the two clouds are collided.

    Parameters
    ----------
    a, b : PointCloud or mesh
        The two clouds, or one cloud and one mesh.
    pose_a, pose_b : array_like, shape (4, 4), optional
        Rigid poses of the clouds (own frame to world); ``None`` is the identity.
    request : CollisionRequest, optional
        The options of the query (default ``CollisionRequest()``).
    mesh_side : {"exact", "sampled"}, optional
        How a mesh side is read (default ``"exact"``, or ``"sampled"`` when
        ``mesh_spacing`` is given).
    mesh_spacing : float, optional
        Sampling spacing of a sampled mesh side (metres; default: half the
        cloud's median spacing, its distance to the 6th nearest neighbour). A
        ``Mesh`` keeps its last samplings, so repeated queries do not sample it
        again. Given with ``mesh_side="exact"``, an error.
    **options
        Options of :class:`CollisionRequest`, overriding ``request``'s.

    Returns
    -------
    CollisionResult
        ``P``, the state, per-point probabilities, patches and statistics.

    Raises
    ------
    InvalidInputError
        On a bad pose, an unknown option name or an option out of its domain, or
        two meshes.
    TypeError
        If a side is neither a cloud nor a mesh, or ``request`` is not a
        :class:`CollisionRequest`.
    """

def collide_many(
    a: PointCloud | Mesh | Any,
    b: PointCloud | Mesh | Any,
    poses_a: npt.ArrayLike,
    pose_b: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | None = None,
    mesh_side: str | None = None,
    mesh_spacing: float | None = None,
    **options: Any,
) -> list[CollisionResult]:
    """Run :func:`collide` for many poses of ``a``, in parallel.

    Parameters
    ----------
    a, b : PointCloud or mesh
        The two clouds, or one cloud and one mesh (see :func:`collide`).
    poses_a : array_like, shape (m, 4, 4)
        Poses of ``a``.
    pose_b : array_like, shape (4, 4), optional
        Pose of ``b``; ``None`` is the identity.
    request, mesh_side, mesh_spacing, **options
        As in :func:`collide`.

    Returns
    -------
    list of CollisionResult
        One result per pose, in the order of ``poses_a``; identical to calling
        :func:`collide` in a loop.
    """

def collide_along(
    a: PointCloud | Mesh | Any,
    b: PointCloud | Mesh | Any,
    poses_a: npt.ArrayLike,
    pose_b: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | None = None,
    mesh_side: str | None = None,
    mesh_spacing: float | None = None,
    **options: Any,
) -> list[CollisionResult]:
    """Run :func:`collide` for the poses of a motion of ``a`` (consecutive poses near each other).

    The poses are taken in runs of 16 (``ceil(m / 16)`` parallel tasks), the runs in
    parallel; each run's first pose is queried cold, each later one's classifier
    starts from the samples that supported the previous pose's separating surfaces.
    The working set still adds every violated constraint, so the surfaces are
    :func:`collide_many`'s to the solver's tolerance (``P`` within about 1e-5: a
    state can differ only where ``P`` lies that close to a threshold), with fewer
    solver iterations where consecutive poses see the same contact. The runs depend
    on the poses' order alone, not on the number of threads.

    Parameters
    ----------
    a, b : PointCloud or mesh
        The two clouds, or one cloud and one mesh (see :func:`collide`).
    poses_a : array_like, shape (m, 4, 4)
        Poses of ``a``, in the motion's order.
    pose_b : array_like, shape (4, 4), optional
        Pose of ``b``; ``None`` is the identity.
    request, mesh_side, mesh_spacing, **options
        As in :func:`collide` (with an exact mesh side, the queries are
        :func:`collide_many`'s: nothing is trained, so nothing is warm-started).

    Returns
    -------
    list of CollisionResult
        One result per pose, in the order of ``poses_a``.
    """

def pose_from_translation(translation: npt.ArrayLike) -> _FloatArray:
    """Make the pure translation by ``translation``.

    Parameters
    ----------
    translation : array_like, shape (3,)
        Translation (metres).

    Returns
    -------
    ndarray, shape (4, 4)
        The homogeneous matrix, float64.

    Raises
    ------
    cloudprox.InvalidInputError
        Naming ``translation`` if its shape is wrong or an entry is NaN, infinite
        or beyond 1e9 m.
    """

def pose_from_quaternion(
    quaternion: npt.ArrayLike, translation: npt.ArrayLike | None = None
) -> _FloatArray:
    """Make a pose from a quaternion ``(w, x, y, z)`` and a translation.

    Parameters
    ----------
    quaternion : array_like, shape (4,)
        ``(w, x, y, z)``, scalar first; normalised here (need not be unit).
    translation : array_like, shape (3,), optional
        Translation (metres) applied after the rotation; zero by default.

    Returns
    -------
    ndarray, shape (4, 4)
        The homogeneous matrix, float64.

    Raises
    ------
    cloudprox.InvalidInputError
        Naming ``quaternion`` if it is zero, not finite or not of shape (4,), or
        ``translation``.
    """

def pose_from_rpy(rpy: npt.ArrayLike, translation: npt.ArrayLike | None = None) -> _FloatArray:
    """Make a pose from roll-pitch-yaw angles and a translation.

    The convention is ROS/URDF's: roll about the fixed x axis, then pitch about
    the fixed y axis, then yaw about the fixed z axis,
    ``R = Rz(yaw) Ry(pitch) Rx(roll)``.

    Parameters
    ----------
    rpy : array_like, shape (3,)
        Roll, pitch, yaw (radians).
    translation : array_like, shape (3,), optional
        Translation (metres) applied after the rotation; zero by default.

    Returns
    -------
    ndarray, shape (4, 4)
        The homogeneous matrix, float64.

    Raises
    ------
    cloudprox.InvalidInputError
        Naming ``rpy`` or ``translation`` (wrong shape, NaN or infinite).
    """

def pose_from_rotation_vector(
    rotation_vector: npt.ArrayLike, translation: npt.ArrayLike | None = None
) -> _FloatArray:
    """Make a pose from a rotation vector and a translation.

    Parameters
    ----------
    rotation_vector : array_like, shape (3,)
        The rotation axis times the angle (radians), right-handed.
    translation : array_like, shape (3,), optional
        Translation (metres) applied after the rotation; zero by default.

    Returns
    -------
    ndarray, shape (4, 4)
        The homogeneous matrix, float64.

    Raises
    ------
    cloudprox.InvalidInputError
        Naming ``rotation_vector`` or ``translation`` (wrong shape, NaN or infinite).
    """

def pose_look_at(
    eye: npt.ArrayLike, target: npt.ArrayLike, up: npt.ArrayLike | None = None
) -> _FloatArray:
    """Make the pose of a camera at ``eye`` looking at ``target``.

    The result is the camera's optical frame in the world (ROS
    ``*_optical_frame``, OpenCV, :class:`DepthCamera`): z forward, from ``eye``
    towards ``target``; x to the image's right (``z x up``); y down in the image.

    Parameters
    ----------
    eye : array_like, shape (3,)
        The camera's position (metres).
    target : array_like, shape (3,)
        The point on the optical axis.
    up : array_like, shape (3,), optional
        The world's up direction; ``(0, 0, 1)`` by default.

    Returns
    -------
    ndarray, shape (4, 4)
        The homogeneous matrix, float64.

    Raises
    ------
    cloudprox.InvalidInputError
        Naming the argument: a wrong shape, NaN, ``target`` equal to ``eye``, a
        zero ``up`` or one parallel to the viewing direction.
    """

def random_rotations(n: int, seed: int = 0) -> npt.NDArray[np.float64]:
    """Draw ``n`` uniformly random rotations (seeded, deterministic).

    Unit quaternions of four standard normals from the core's generator: the same
    ``seed`` gives the same rotations on every platform.

    Parameters
    ----------
    n : int
        Number of rotations, in ``[0, 1e8]``.
    seed : int, default 0
        Seed of the generator.

    Returns
    -------
    ndarray, shape (n, 4, 4)
        Poses with the rotations and zero translation, float64.
    """

def sample_sphere(n: int, radius: float = 1.0, center: npt.ArrayLike | None = None) -> _FloatArray:
    """Spread points evenly over a sphere (Fibonacci lattice).

    Parameters
    ----------
    n : int
        Number of points.
    radius : float, default 1.0
        Sphere radius (metres).
    center : array_like, shape (3,), optional
        Sphere centre; the origin by default.

    Returns
    -------
    ndarray, shape (n, 3)
        The points.
    """

def sample_box_surface(
    half_extents: npt.ArrayLike, spacing: float, center: npt.ArrayLike | None = None
) -> _FloatArray:
    """Sample the surface of an axis-aligned box on a grid.

    Parameters
    ----------
    half_extents : array_like, shape (3,)
        Half the box's size along x, y and z (metres, each > 0).
    spacing : float
        Approximate grid spacing on each face (metres).
    center : array_like, shape (3,), optional
        Box centre; the origin by default.

    Returns
    -------
    ndarray, shape (m, 3)
        The points.
    """

def add_noise(points: npt.ArrayLike, sigma: float, seed: int = 0) -> _FloatArray:
    """Add seeded isotropic Gaussian noise.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The points.
    sigma : float
        Standard deviation of the noise (metres, ``>= 0``).
    seed : int, default 0
        Seed of the core's generator: the same seed gives the same noise.

    Returns
    -------
    ndarray, shape (n, 3)
        The noisy points.
    """

@final
class DepthCamera:
    """Structured-light depth camera (Kinect v1-like) noise model.

    Axial (depth) standard deviation ``axial_offset + axial_quadratic (z -
    axial_depth0)^2``, stretched along the viewing ray by ``range / depth``;
    lateral ``sigma_px z / focal_px``.

    Every parameter left ``None`` takes the core's default
    (``DepthCamera::default()`` in Rust: Khoshelham & Elberink, Sensors 2012, for
    the axial law, Nguyen et al. 2012 for the lateral one, a Kinect v1's
    baseline and disparity step); the properties read the values.

    Parameters
    ----------
    axial_offset, axial_quadratic, axial_depth0 : float, optional
        Coefficients of the axial law (metres, 1/metre, metres; ``>= 0``).
    focal_px : float
        Focal length in pixels (``> 0``).
    sigma_px : float
        Lateral standard deviation in pixels (``>= 0``).
    baseline_m : float
        Projector-camera baseline in metres (``> 0``).
    disparity_step_px : float
        Resolution of the measured disparity in pixels (``>= 0``).
        Depth comes in steps of ``z^2 disparity_step_px / (focal_px baseline_m)``;
        that share of the error (variance ``step^2 / 12``) is common to
        neighbouring points of a surface and does not average away: a cloud seen
        by this camera builds its surface elements with the noise correlation
        :meth:`noise_correlation` at its median depth.
    """

    def __new__(
        cls,
        *,
        axial_offset: float | None = None,
        axial_quadratic: float | None = None,
        axial_depth0: float | None = None,
        focal_px: float | None = None,
        sigma_px: float | None = None,
        baseline_m: float | None = None,
        disparity_step_px: float | None = None,
    ) -> DepthCamera: ...
    @staticmethod
    def nguyen_2012() -> DepthCamera:
        """Nguyen, Izadi & Lovell (2012): ``sigma_z = 0.0012 + 0.0019 (z - 0.4)^2``."""
    @staticmethod
    def khoshelham_2012() -> DepthCamera:
        """Khoshelham & Elberink (2012): ``sigma_z = 1.425e-3 z^2`` (the default)."""
    @property
    def axial_offset(self) -> float: ...
    @property
    def axial_quadratic(self) -> float: ...
    @property
    def axial_depth0(self) -> float: ...
    @property
    def focal_px(self) -> float: ...
    @property
    def sigma_px(self) -> float: ...
    @property
    def baseline_m(self) -> float: ...
    @property
    def disparity_step_px(self) -> float: ...
    def depth_step(self, depth: npt.ArrayLike) -> _FloatArray:
        """Depth step (one disparity step) at each depth (metres), flattened."""
    def noise_correlation(self, depth: npt.ArrayLike) -> _FloatArray:
        """Share of the axial variance common to one surface's points at each depth."""
    def sigma_axial(self, depth: npt.ArrayLike) -> _FloatArray:
        """Axial (depth) standard deviation at each depth (metres), flattened."""
    def sigma_lateral(self, depth: npt.ArrayLike) -> _FloatArray:
        """Lateral standard deviation at each depth (metres), flattened."""
    def covariances(
        self,
        points: npt.ArrayLike,
        origin: npt.ArrayLike | None = None,
        sensor_pose: npt.ArrayLike | None = None,
    ) -> _FloatArray:
        """Sensor covariances ``(n, 3, 3)`` of ``points`` seen from ``origin`` or ``sensor_pose``."""

@final
class StereoCamera:
    """Stereo camera noise model.

    Depth standard deviation ``z^2 sigma_disparity_px / (focal_px baseline)``
    (first-order propagation of ``z = f B / d``), stretched along the ray;
    lateral ``sigma_px z / focal_px``. Every parameter left ``None`` takes the
    core's ``StereoCamera::default()`` (a RealSense D435-like camera); the
    properties read the values.
    """

    def __new__(
        cls,
        *,
        focal_px: float | None = None,
        baseline: float | None = None,
        sigma_disparity_px: float | None = None,
        sigma_px: float | None = None,
    ) -> StereoCamera: ...
    @property
    def focal_px(self) -> float: ...
    @property
    def baseline(self) -> float: ...
    @property
    def sigma_disparity_px(self) -> float: ...
    @property
    def sigma_px(self) -> float: ...
    def sigma_axial(self, depth: npt.ArrayLike) -> _FloatArray:
        """Depth standard deviation at each depth (metres), flattened."""
    def sigma_lateral(self, depth: npt.ArrayLike) -> _FloatArray:
        """Lateral standard deviation at each depth (metres), flattened."""
    def covariances(
        self,
        points: npt.ArrayLike,
        origin: npt.ArrayLike | None = None,
        sensor_pose: npt.ArrayLike | None = None,
    ) -> _FloatArray:
        """Sensor covariances ``(n, 3, 3)`` of ``points`` seen from ``origin`` or ``sensor_pose``."""

@final
class Lidar:
    """Laser range finder noise model.

    ``sigma_range`` along the ray, ``range * sigma_angle`` across it. A
    parameter left ``None`` takes the core's ``Lidar::default()`` (a Hokuyo
    UTM-30LX: its accuracy taken as 3 sigma, its angular resolution's
    quantization); the properties read the values.
    """

    def __new__(
        cls, *, sigma_range: float | None = None, sigma_angle: float | None = None
    ) -> Lidar: ...
    @property
    def sigma_range(self) -> float: ...
    @property
    def sigma_angle(self) -> float: ...
    def covariances(
        self,
        points: npt.ArrayLike,
        origin: npt.ArrayLike | None = None,
        sensor_pose: npt.ArrayLike | None = None,
    ) -> _FloatArray:
        """Sensor covariances ``(n, 3, 3)`` of ``points`` seen from ``origin`` or ``sensor_pose``."""

def ray_covariances(
    points: npt.ArrayLike,
    sigma_ray: float,
    sigma_lateral: float,
    *,
    origin: npt.ArrayLike | None = None,
    sensor_pose: npt.ArrayLike | None = None,
) -> _FloatArray:
    """Covariances ``(n, 3, 3)`` with fixed standard deviations along and across each viewing ray.

    ``sigma_ray^2 u u^T + sigma_lateral^2 (I - u u^T)`` for the unit ray ``u``
    from ``origin`` (or ``sensor_pose``) to each point: the form every sensor
    model gives, with a noise level set by hand instead of a sensor's laws.

    Raises
    ------
    InvalidInputError
        A negative or non-finite standard deviation, neither or both of
        ``origin`` and ``sensor_pose``, a non-finite point, a point at the
        origin (or behind a ``sensor_pose``).
    """

@final
class CloudFile:
    """A point cloud as read from a file: points and whatever else the file holds.

    Returned by :func:`cloudprox.io.read_point_cloud`; made directly to write
    data with a sensor pose or an organized layout (missing pixels are written
    as NaN records).
    """

    def __new__(
        cls,
        points: npt.ArrayLike,
        *,
        normals: npt.ArrayLike | None = None,
        covariances: npt.ArrayLike | None = None,
        sensor_pose: npt.ArrayLike | None = None,
        grid_shape: tuple[int, int] | None = None,
        pixels: Sequence[int] | None = None,
    ) -> CloudFile: ...
    @property
    def points(self) -> _FloatArray:
        """Points with finite coordinates, shape ``(n, 3)`` (metres)."""
    @property
    def normals(self) -> _FloatArray | None:
        """Per-point normals ``(n, 3)``, or ``None`` when the file has none."""
    @property
    def covariances(self) -> _FloatArray | None:
        """Per-point covariances ``(n, 3, 3)`` stored in the file, or ``None``."""
    @property
    def sensor_pose(self) -> _FloatArray | None:
        """The sensor's pose ``(4, 4)`` recorded in the file (PCD ``VIEWPOINT``), or ``None``.

        A PCD that leaves ``VIEWPOINT`` at the format's default reads as the identity.
        """
    @property
    def sensor_pose_is_default(self) -> bool:
        """Whether ``sensor_pose`` is the PCD default ``VIEWPOINT`` (the identity).

        Written or left out, it is the sensor at the origin looking along +z.
        """
    @property
    def grid_shape(self) -> tuple[int, int] | None:
        """``(height, width)`` of an organized cloud, or ``None``."""
    @property
    def pixels(self) -> _IntArray | None:
        """For an organized cloud, the pixel ``row * width + column`` of each point."""
    @property
    def fields(self) -> list[str]:
        """Names of all per-point fields in the file, in file order."""
    @property
    def skipped(self) -> int:
        """Points skipped because a coordinate was NaN or infinite."""
    @property
    def at_origin(self) -> int:
        """Points of an organized scan left out for lying at exactly the sensor origin.

        The driver's no-return points; 0 for an unorganized cloud, which keeps them.
        """
    @property
    def no_returns(self) -> int:
        """The no-returns of an organized scan: ``at_origin`` plus ``skipped``.

        None of them is in ``points``; the organized layout keeps their pixels
        (``pixels`` skips them). 0 for an unorganized cloud.
        """
    @property
    def topic(self) -> str | None:
        """For a cloud read from a bag: its topic, else ``None``."""
    @property
    def index(self) -> int | None:
        """For a cloud read from a bag: the message's index in its topic, else ``None``."""
    @property
    def frame_id(self) -> str | None:
        """For a cloud read from a message: the frame its points are expressed in.

        The TF frame they were moved to, else the message's ``frame_id``; ``None``
        for a file.
        """
    @property
    def sensor_frame(self) -> str | None:
        """For a cloud read from a message: its ``header.frame_id``, else ``None``."""
    @property
    def stamp(self) -> int | None:
        """For a cloud read from a message: ``header.stamp`` in nanoseconds, else ``None``."""
    @property
    def path(self) -> str:
        """The file it was read from."""
    @staticmethod
    def _from_message(
        message: object,
        encoding: str,
        *,
        name: str,
        path: str,
        pose: npt.ArrayLike | None = None,
        frame_id: str | None = None,
        topic: str | None = None,
        index: int | None = None,
    ) -> CloudFile:
        """Read a serialized PointCloud2 message (``"cdr"`` or ``"ros1"``) in place.

        The sensor sits at the origin of the message's frame; ``pose`` moves the
        points and the sensor into ``frame_id``. ``name`` goes into errors.
        """
    @staticmethod
    def _message_header(message: object, encoding: str, *, name: str) -> tuple[str, int]:
        """Return the ``(frame_id, stamp)`` of a serialized PointCloud2 message."""
    def to_point_cloud(
        self,
        sigma: npt.ArrayLike | None = None,
        cov: npt.ArrayLike | None = None,
        *,
        sensor: DepthCamera | StereoCamera | Lidar | None = None,
        origin: npt.ArrayLike | None = None,
        sensor_pose: npt.ArrayLike | None = None,
        discretization: bool = True,
    ) -> PointCloud:
        """Make a :class:`PointCloud` of the points.

        The noise is ``sigma``, ``cov``, or a ``sensor`` model seen from
        ``origin`` / ``sensor_pose`` (default: the file's ``sensor_pose``); with
        none of them, the covariances stored in the file. ``discretization`` adds
        the k-nearest-neighbour discretization part (default ``True``).

        Raises
        ------
        InvalidInputError
            If the noise is not given and the file stores none, or a sensor is
            given and neither the call nor the file gives its viewpoint.
        """
    def __len__(self) -> int: ...

def read_point_cloud(path: str, format: _CloudFormatName = "auto") -> CloudFile:
    """Read a point-cloud file (see :func:`cloudprox.io.read_point_cloud`)."""

def write_point_cloud(
    path: str,
    cloud: object,
    format: _CloudFormatName = "auto",
    *,
    encoding: _EncodingName | None = None,
    write_ascii: bool = False,
    compressed: bool = False,
) -> None:
    """Write a point cloud (see :func:`cloudprox.io.write_point_cloud`)."""

def read_mesh(path: str | os.PathLike[str], format: _MeshFormatName = "auto") -> Mesh:
    """Read a triangle mesh (STL ascii/binary, OBJ, PLY, OFF).

    Polygons are split into fans of triangles and STL vertices are welded.
    Triangles that repeat a vertex are dropped with a
    :class:`~cloudprox.DegenerateFacesWarning` giving their number.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    cloudprox.FormatError
        If its content is corrupt, truncated or unsupported.
    """

def _read_mesh_counted(
    path: str | os.PathLike[str], format: _MeshFormatName = "auto"
) -> tuple[Mesh, int]:
    """:func:`read_mesh` without the warning: the mesh and the number of faces dropped."""

def write_mesh(
    path: str,
    mesh: Mesh,
    format: _MeshFormatName = "auto",
    *,
    encoding: _EncodingName | None = None,
    write_ascii: bool = False,
) -> None:
    """Write a mesh file (see :func:`cloudprox.io.write_mesh`)."""

def read_pointcloud2(
    data: object,
    fields: object,
    *,
    height: int,
    width: int,
    point_step: int,
    row_step: int,
    is_bigendian: bool = False,
) -> CloudFile:
    """Read a ROS PointCloud2 from raw bytes (see :func:`cloudprox.io.read_pointcloud2`)."""

def write_pointcloud2(cloud: object) -> tuple[dict[str, Any], bytes]:
    """Encode a cloud as a PointCloud2 (see :func:`cloudprox.io.write_pointcloud2`)."""

def crop_box(
    points: npt.ArrayLike,
    min: npt.ArrayLike,
    max: npt.ArrayLike,
    pose: npt.ArrayLike | None = None,
    invert: bool = False,
) -> _IntArray:
    """Return the indices (ascending) of the points inside the box (see :mod:`cloudprox.filters`)."""

def voxel_downsample(
    points: npt.ArrayLike,
    voxel_size: float,
    covariances: npt.ArrayLike | None = None,
    merge: _MergeName = "mean",
) -> Voxels:
    """One point per occupied voxel (see :mod:`cloudprox.filters`)."""

@final
class Voxels:
    """What :func:`voxel_downsample` returns; unpacks as ``points, covariances, counts``."""

    @property
    def points(self) -> _FloatArray:
        """The centroid of each voxel's members, shape ``(m, 3)``."""
    @property
    def covariances(self) -> npt.NDArray[np.float64] | None:
        """The merged covariance of each voxel, ``(m, 3, 3)``; ``None`` without input covariances."""
    @property
    def counts(self) -> _IntArray:
        """The number of input points in each voxel, shape ``(m,)``."""
    def __iter__(self) -> Iterator[Any]: ...
    def __getitem__(self, key: int, /) -> Any: ...
    def __len__(self) -> int: ...

def statistical_outlier_removal(
    points: npt.ArrayLike, k: int | None = None, std_ratio: float | None = None
) -> _IntArray:
    """Return the indices (ascending) of the points kept (see :mod:`cloudprox.filters`)."""

def shadow_filter(
    points: npt.ArrayLike,
    origin: npt.ArrayLike,
    *,
    pixels: npt.ArrayLike | None = None,
    grid_shape: tuple[int, int] | None = None,
    min_angle_deg: float | None = None,
    window: int | None = None,
    k: int | None = None,
) -> _IntArray:
    """Return the indices of the points kept by the veil filter (see :mod:`cloudprox.filters`)."""

@final
class Occlusion:
    """What a scan did not see: the space behind its observed surfaces.

    A single view observes the first surface along each ray from the sensor;
    space in front of it is seen to be free, space behind it is unknown, not
    free (a collision there leaves no point in the scan). ``Occlusion`` keeps
    the nearest return per viewing direction (a cube map of the rays, cells
    of twice the scan's median angular spacing unless ``cell`` is given) and
    tells where any point lies as the scan saw it.

    Parameters
    ----------
    scan : PointCloud
        The scan; its sensor covariances give the range noise along each ray.
    origin : array_like, shape (3,)
        The sensor's origin, in the scan's frame.
    cell : float, optional
        The angular cell in radians (> 0).

    Raises
    ------
    InvalidInputError
        A scan that is not a ``PointCloud``, a non-finite origin, a scan point
        at the origin (a no-return point) or a cell that is not positive.
    """

    def __new__(
        cls, scan: PointCloud, origin: npt.ArrayLike, *, cell: float | None = None
    ) -> Occlusion: ...
    @property
    def cell(self) -> float:
        """The angular cell in radians."""
    def hidden_probability(self, points: npt.ArrayLike, depth: float | None = None) -> _FloatArray:
        """Return, per point (``(n, 3)``, the scan's frame), the probability that it lies behind the observed surface.

        ``Phi((|x - o| - r) / s)``, with ``r`` the nearest return of the
        point's direction's cell and ``s`` that
        range's standard deviation; 0 along a direction without a return.
        With ``depth`` (metres, > 0): behind it by at most ``depth``, inside
        an object seen from the front whose thickness is at most ``depth``
        (``Phi((d - r) / s) - Phi((d - r - depth) / s)``).
        """
    def visibility(self, points: npt.ArrayLike) -> list[Literal["seen", "hidden", "unobserved"]]:
        """Return each point as the scan saw it: ``"seen"``, ``"hidden"`` or ``"unobserved"``.

        ``"seen"``: in front of the observed surface along its ray (seen to be
        free); ``"hidden"``: behind it (``hidden_probability > 0.5``);
        ``"unobserved"``: no return along its direction (outside the field of
        view, beyond the sensor's range, no-return pixels).
        """

@final
class SelfFilter:
    """Removes the points on the robot (see :mod:`cloudprox.filters`)."""

    def __new__(cls, links: object, padding: float | None = None) -> SelfFilter: ...
    def set_poses(self, poses: npt.ArrayLike) -> None:
        """Move the links: ``(m, 4, 4)``, one pose per link."""
    @property
    def padding(self) -> float:
        """The padding (metres)."""
    def apply(self, points: npt.ArrayLike) -> _IntArray:
        """Return the indices (ascending) of the points not on the robot."""

@final
class ScanStep:
    """One filter step of :func:`scan_to_cloud`, made by its static methods.

    Parameters left ``None`` take the core's defaults (as in :mod:`cloudprox.filters`).
    """

    @staticmethod
    def crop(
        min: npt.ArrayLike,
        max: npt.ArrayLike,
        pose: npt.ArrayLike | None = None,
        invert: bool = False,
    ) -> ScanStep:
        """Keep the points inside the box ``[min, max]`` (outside with ``invert``)."""
    @staticmethod
    def voxel(size: float, merge: _MergeName = "mean") -> ScanStep:
        """One point per occupied voxel of side ``size``, covariances merged."""
    @staticmethod
    def outliers(k: int | None = None, std_ratio: float | None = None) -> ScanStep:
        """Statistical outlier removal."""
    @staticmethod
    def shadow(
        min_angle_deg: float | None = None, window: int | None = None, k: int | None = None
    ) -> ScanStep:
        """Remove the shadow (veil) points, seen from the sensor origin."""
    @staticmethod
    def self_filter(filter: SelfFilter) -> ScanStep:
        """Remove the points on the robot (a copy of ``filter`` as it is now)."""
    @property
    def name(self) -> str:
        """``"crop"``, ``"voxel"``, ``"outliers"``, ``"shadow"`` or ``"self"``."""

@final
class ScanResult:
    """What :func:`scan_to_cloud` returns: the cloud and what each step did."""

    @property
    def cloud(self) -> PointCloud:
        """The cloud; raises :class:`InvalidInputError` when a step removed every point."""
    @property
    def steps(self) -> list[tuple[str, int, int]]:
        """``(name, before, after)`` for each step that ran, in order."""
    @property
    def emptied_by(self) -> int | None:
        """The index of the step that left no point (the last one run), or ``None``."""

def scan_to_cloud(
    scan: CloudFile,
    steps: Sequence[ScanStep] = ...,
    *,
    sigma: float | None = None,
    sensor: DepthCamera | StereoCamera | Lidar | None = None,
    origin: npt.ArrayLike | None = None,
    sensor_pose: npt.ArrayLike | None = None,
    discretization: bool = True,
    k: int | None = None,
) -> ScanResult:
    """Run the core's scan pipeline on ``scan``: sensor covariances, ``steps``, ``PointCloud``.

    The noise is ``sigma``, or ``sensor`` seen from ``origin`` / ``sensor_pose``
    (default: the file's ``VIEWPOINT``), or with neither the covariances stored
    in the file. The shadow step uses the same sensor origin. The
    discretization part is added with ``k`` neighbours unless
    ``discretization=False``. The GIL is released while it runs.
    """

def parse_mesh(
    data: bytes, format: Literal["stl", "obj", "ply", "off"], name: str = "<bytes>"
) -> Mesh:
    """Read a triangle mesh from bytes in memory (e.g. a member of a zip archive).

    As :func:`read_mesh`; ``format`` must be given (``"stl"``, ``"obj"``,
    ``"ply"`` or ``"off"``) and ``name`` is used in messages.
    """

# ---------------------------------------------------------------- robots (issue 11)

@final
class Robot:
    """A robot loaded from a URDF file, prepared once for many queries.

    It pickles as its URDF text: the mesh files it names are read again on
    unpickling, at the same paths.

    A configuration ``q`` holds one value per independent moving joint (revolute,
    continuous, prismatic; mimic joints follow their master), in the order of
    :attr:`joint_names`; or it is a mapping from joint name to value, wherever a
    configuration is taken (``{"panda_joint4": -1.5}``): the joints it leaves out
    take their reference value (0, or the limit nearest 0), and a name that is not
    in :attr:`joint_names` raises :class:`InvalidInputError` naming it. A configuration outside the joint limits, of the wrong
    length or with a NaN raises :class:`InvalidInputError` naming the joint; it is
    never clamped silently (:meth:`clamp` clamps on request).
    """

    @staticmethod
    def from_urdf(
        path: str | os.PathLike[str],
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
        srdf: str | os.PathLike[str] | None = None,
        *,
        srdf_string: str | None = None,
    ) -> Robot:
        """Load a URDF file, and optionally the link pairs an SRDF disables.

        ``package://NAME/PATH`` mesh URIs are looked for as ``DIR/NAME/PATH`` (or
        ``DIR/PATH`` when ``DIR`` is named ``NAME``) for each of ``package_dirs``,
        then in the URDF's own folders; ``file://`` and plain paths are absolute or
        relative to the URDF's folder. Meshes: STL, OBJ, PLY, OFF (COLLADA raises
        :class:`FormatError`); ``box``, ``cylinder``, ``sphere`` and ``capsule``
        become closed meshes. A missing file raises ``FileNotFoundError`` naming
        the link and the paths tried; a malformed URDF raises :class:`FormatError`
        naming the joint or link.

        ``srdf`` is the path of an SRDF file (as MoveIt writes), ``srdf_string``
        the text of one (give at most one of them): the link pairs of its
        ``<disable_collisions link1=... link2=.../>`` entries are taken out of
        :attr:`self_collision_pairs` and listed in :attr:`ignored_pairs`; the rest
        of the SRDF is not read. Malformed XML, or an entry naming a link the
        robot does not have, raises :class:`FormatError` naming the SRDF file and
        the link.
        """
    @staticmethod
    def from_urdf_string(
        text: str,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
        base_dir: str | os.PathLike[str] | None = None,
        srdf: str | os.PathLike[str] | None = None,
        *,
        srdf_string: str | None = None,
    ) -> Robot:
        """Load a robot from URDF text, as :meth:`from_urdf` loads a file.

        Relative and ``file://`` mesh paths are resolved against ``base_dir``
        (``None``: the current folder), ``package://`` URIs in ``package_dirs``
        and then ``base_dir``. ``srdf`` is the *path* of an SRDF file,
        ``srdf_string`` the SRDF *text*, as in :meth:`from_urdf`. Errors name the
        URDF ``<URDF string>`` (and an SRDF text ``<SRDF string>``).
        """
    @property
    def name(self) -> str:
        """The robot's name."""
    @property
    def dof(self) -> int:
        """Number of configuration entries."""
    @property
    def joint_names(self) -> list[str]:
        """Names of the joints of the configuration entries, in order."""
    @property
    def link_names(self) -> list[str]:
        """Names of the links, in URDF order."""
    @property
    def joint_limits(self) -> _FloatArray:
        """Lower and upper limits, shape ``(dof, 2)`` (infinite for continuous joints)."""
    @property
    def self_collision_pairs(self) -> list[tuple[str, str]]:
        """Link pairs checked for self-collision."""
    @property
    def ignored_pairs(self) -> list[tuple[str, str]]:
        """Link pairs never checked: adjacent, touching at the reference configuration, or disabled by the SRDF."""
    def with_allowed_collisions(self, pairs: Sequence[tuple[str, str]]) -> Robot:
        """Return a copy of the robot that does not check ``pairs`` for self-collision.

        Each pair names two links (either order); it leaves
        :attr:`self_collision_pairs` and joins :attr:`ignored_pairs`, as an SRDF's
        ``<disable_collisions>`` does (a pair already ignored changes nothing).
        The robot itself is unchanged; the copy pickles with its allowed pairs.
        An unknown link, or a link paired with itself, raises
        :class:`InvalidInputError` naming it.
        """
    def attach(
        self,
        link: str,
        obj: Mesh | PointCloud,
        pose: npt.ArrayLike | None = None,
        *,
        name: str,
        touch_links: Sequence[str] | None = None,
    ) -> Robot:
        """Return a copy of the robot holding ``obj`` on ``link``.

        Parameters
        ----------
        link : str
            The link that holds the object; the object moves with it.
        obj : Mesh or PointCloud
            The object in its own frame. A mesh stands in queries as a link does
            (its exact surface, or its sample with ``mesh_side="sampled"``); a
            cloud is collided as a cloud, and its convex hull stands for it in
            self-collision and the self-filter.
        pose : (4, 4) float, optional
            The object's frame in the link's frame (``None``: identity).
        name : str
            The object's name: its key in :attr:`RobotCollisionResult.links` and
            :attr:`RobotCollisionResult.self_collisions`.
        touch_links : sequence of str, optional
            Links allowed to touch the object besides ``link`` (MoveIt's touch
            links, e.g. the fingers that grasp it).

        Returns
        -------
        Robot
            The copy; the robot itself is unchanged. The copy's queries read the
            object against the environment, its :meth:`self_filter` removes the
            points on it, and its self-collision checks it against every link
            with geometry but ``link`` and ``touch_links``. Attached objects are
            not checked against each other. It pickles with its objects.

        Raises
        ------
        InvalidInputError
            Naming the problem: an unknown link or touch link, a name already
            used by an attached object or a link, a non-finite pose, a mesh
            rejected as a link's would be, or a flat cloud.
        TypeError
            If ``obj`` is neither a :class:`Mesh` nor a :class:`PointCloud`.
        """
    def detach(self, name: str) -> Robot:
        """Return a copy of the robot without the attached object ``name``.

        An unknown name raises :class:`InvalidInputError` listing the objects held.
        """
    @property
    def attached_objects(self) -> list[str]:
        """Names of the attached objects, in the order attached."""
    def attached_poses(
        self, q: _Configuration, base_pose: npt.ArrayLike | None = None
    ) -> dict[str, _FloatArray]:
        """Every attached object's ``(4, 4)`` pose (object frame to world) at ``q``, by name.

        The holding link's pose (:meth:`link_poses`) composed with the object's
        pose in the link.
        """
    def link_poses(
        self, q: _Configuration, base_pose: npt.ArrayLike | None = None
    ) -> dict[str, _FloatArray]:
        """Every link's ``(4, 4)`` pose (link frame to world) at ``q``, the root at ``base_pose``."""
    def clamp(self, q: _Configuration) -> _FloatArray:
        """Return ``q`` clamped into the joint limits."""
    def link_mesh(self, link: str) -> Mesh | None:
        """Return the collision mesh of ``link`` in its own frame (``None`` without geometry)."""
    def self_collisions(self, q: _Configuration) -> list[tuple[str, str]]:
        """Return the pairs of non-adjacent links whose exact meshes intersect at ``q``.

        Then the ``(link, object)`` pairs of attached objects that intersect a
        link other than their holder and touch links.
        """
    def self_filter(
        self,
        q: _Configuration,
        padding: float | None = None,
        base_pose: npt.ArrayLike | None = None,
    ) -> SelfFilter:
        """Return the :class:`SelfFilter` of the robot's links at ``q`` (root at ``base_pose``, cloud frame).

        Attached objects are filtered too (a cloud object by its convex hull),
        after the links with geometry, in the order attached (the order
        :meth:`SelfFilter.set_poses` reads).

        ``padding=None`` is the core's ``SELF_FILTER_DEFAULT_PADDING``.
        """

@final
class LinkCollision:
    """One link's part of a :class:`RobotCollisionResult`."""

    @property
    def link(self) -> str:
        """The link's name."""
    @property
    def probability(self) -> float:
        """The link's collision probability (0 when the broad phase skipped it; NaN when a ``decide_only`` query was decided before it)."""
    @property
    def state(self) -> _StateName:
        """The link's state."""
    @property
    def shadow(self) -> float:
        """With ``shadow=``, the link's shadow probability (already in ``probability``); 0 without."""
    @property
    def queried(self) -> bool:
        """Whether the link was queried (it passed the broad phase, before any decision)."""
    @property
    def result(self) -> CollisionResult | None:
        """The link's full query result, ``None`` when skipped.

        Side A is the link: its exact surface (no points) for exact links, its
        sample for sampled ones.
        """
    @property
    def target(self) -> LinkCollision | None:
        """With a grasp target (``target=``), the link's query against it; else ``None``.

        A link not in ``allowed_links`` has it in :attr:`probability` and
        :attr:`state`; an allowed link's :attr:`probability` is the environment's alone.
        """

@final
class TargetCollision:
    """The grasp target's part of a :class:`RobotCollisionResult` (``result.target``)."""

    @property
    def probability(self) -> float:
        """The allowed links' contact probability with the target (not in the robot's ``probability``)."""
    @property
    def state(self) -> _StateName:
        """The state from :attr:`probability` and the thresholds (``"collision"``: the fingers are on it)."""
    @property
    def other_probability(self) -> float:
        """The other links' collision probability with the target (in the robot's ``probability``)."""

@final
class RobotCollisionResult:
    """The answer of :func:`collide_robot`."""

    @property
    def probability(self) -> float:
        """The robot's collision probability with the environment (links aggregated as points are)."""
    @property
    def state(self) -> _StateName:
        """The state from ``probability`` and the thresholds."""
    @property
    def links(self) -> dict[str, LinkCollision]:
        """Per link with geometry, by name (URDF order), then per attached object, by its name."""
    @property
    def target(self) -> TargetCollision | None:
        """With a grasp target (``target=``): the allowed links' contact with it and the others' collision with it; else ``None``."""
    @property
    def patches(self) -> list[tuple[str, ContactPatch]]:
        """Contact patches of every queried link, as ``(link name, patch)``."""
    @property
    def self_collisions(self) -> list[tuple[str, str]]:
        """Pairs of non-adjacent links that intersect; not part of ``probability``."""
    @property
    def stats(self) -> RobotStats:
        """Counters and timings of the query."""

@final
class RobotStats:
    """Counters and timings of one :func:`collide_robot` query (``RobotCollisionResult.stats``)."""

    @property
    def links_with_geometry(self) -> int:
        """Links with geometry, and attached objects."""
    @property
    def links_queried(self) -> int:
        """Links queried against the cloud (the others skipped by the broad phase or the decision), plus, with a grasp target, those queried against it."""
    @property
    def links_after_decision(self) -> int:
        """With ``decide_only``, the links left once one reached the collision threshold."""
    @property
    def broad_phase_nodes(self) -> int:
        """Hierarchy nodes of the cloud visited by the broad phase."""
    @property
    def self_pairs_checked(self) -> int:
        """Link pairs tested for self-collision."""
    @property
    def node_pairs_visited(self) -> int:
        """Node pairs visited by the per-link queries, summed."""
    @property
    def solver_iterations(self) -> int:
        """Interior-point iterations of the per-link queries' classifiers, summed (0 for exact links)."""
    @property
    def time_seconds(self) -> float:
        """Wall time of the query (seconds)."""
    def to_dict(self) -> dict[str, int | float]:
        """Return the statistics as a dict of ``int`` and ``float``, ready for JSON."""
    def __eq__(self, value: object, /) -> bool: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...
    @staticmethod
    def _from_state(state: tuple[tuple[int, ...], float]) -> RobotStats: ...

@final
class RobotBatchResult:
    """The answer of :func:`collide_robot_many`: arrays over the configurations."""

    @property
    def probabilities(self) -> _FloatArray:
        """Collision probabilities, shape ``(m,)``."""
    @property
    def states(self) -> npt.NDArray[np.str_]:
        """States, shape ``(m,)``."""
    @property
    def self_colliding(self) -> npt.NDArray[np.bool_]:
        """Whether non-adjacent links intersect, shape ``(m,)``."""
    @property
    def link_probabilities(self) -> _FloatArray:
        """Per-link probabilities, shape ``(m, n_links)``, links in ``Robot.link_names`` order (attached objects enter ``probabilities`` only)."""
    @property
    def target_probabilities(self) -> _FloatArray | None:
        """With a grasp target (``target=``): the allowed links' contact probability with it, shape ``(m,)``; else ``None``."""
    @staticmethod
    def _from_state(
        state: tuple[list[float], list[str], list[bool], list[float], int]
        | tuple[list[float], list[str], list[bool], list[float], int, list[float] | None],
    ) -> RobotBatchResult:
        """Rebuild from ``(probabilities, states, self_colliding, link_probabilities (flat), n_links[, target_probabilities])``."""
    def __len__(self) -> int: ...

@final
class MotionResult:
    """The answer of :func:`check_motion`."""

    @property
    def safe(self) -> bool:
        """Whether every checked state is safe."""
    @property
    def probability(self) -> float:
        """The largest collision probability of the states checked."""
    @property
    def first_unsafe(self) -> float | None:
        """Fraction along the motion of the first unsafe state, or ``None``."""
    @property
    def state(self) -> _StateName:
        """The state at the first unsafe state, or the worst state's when safe."""
    @property
    def states_checked(self) -> int:
        """States checked (the check stops at the first unsafe one)."""
    @property
    def states_total(self) -> int:
        """States the motion was divided into, both ends included."""
    @property
    def resolution(self) -> float:
        """The largest displacement (metres) of a link point between two states."""
    @property
    def solver_iterations(self) -> int:
        """Interior-point iterations of the classifiers of every state checked, summed."""

@final
class RobotRequest:
    """The options of a robot query, as one immutable value.

    Accepted by :func:`collide_robot`, :func:`collide_robot_many` (and, as every
    state's query, :func:`check_motion`) as ``request=``, where a keyword option
    given beside it overrides its value: ``collide_robot(robot, q, cloud,
    request=r, padding=0.01)`` is ``collide_robot(robot, q, cloud,
    request=r.replace(padding=0.01))``. Each option is parsed and checked as the
    same keyword option of :func:`collide_robot` is (the same code): one left
    out (or ``None``) takes the core's default, and a value of the wrong type or
    out of its domain raises :class:`InvalidInputError` (a ``ValueError``)
    naming the option; a ``target`` of another type raises ``TypeError``.
    Requests are frozen and pickle (with their target and shadow objects);
    :meth:`replace` gives a modified copy.

    Parameters
    ----------
    collide : CollisionRequest, optional
        The options of each link's query (default ``CollisionRequest()``).
    mesh_side : {"exact", "sampled"}, optional
        How each link stands: its exact surface (the default), or its mesh
        sampled into a cloud (the default when ``mesh_spacing`` is given).
    mesh_spacing : float, optional
        Sampling spacing of sampled links (metres; default half the cloud's
        median spacing).
    broad_phase : bool, optional
        Skip links that cannot reach the cloud (default ``True``).
    self_collision : bool, optional
        Check self-collision between non-adjacent links (default ``True``).
    padding : float or dict of str to float, optional
        Safety margin (metres) of every link, or of the links a dict names.
    target : PointCloud or Mesh, optional
        An object about to be grasped, still in the scene.
    target_pose : array_like, shape (4, 4), optional
        Pose of a :class:`Mesh` target.
    allowed_links : list of str, optional
        The links that may touch ``target``.
    shadow : cloudprox.filters.Occlusion, optional
        The scan's occlusion, whose shadow the links read.
    shadow_depth : float, optional
        With ``shadow``: the thickness (metres) behind the observed surface that
        counts (default 0.05).
    shadow_prior : float, optional
        With ``shadow``: the prior probability of a shadowed sample, in
        ``[0, 1]`` (default 0.5).

    Examples
    --------
    >>> import cloudprox as cp
    >>> request = cp.RobotRequest(collide=cp.CollisionRequest(model="points"), padding=0.01)
    >>> request.replace(threshold_free=0.05).collide.threshold_free
    0.05
    """

    def __new__(
        cls,
        *,
        collide: CollisionRequest | None = None,
        mesh_side: _MeshSideName | None = None,
        mesh_spacing: float | None = None,
        broad_phase: bool | None = None,
        self_collision: bool | None = None,
        padding: float | Mapping[str, float] | None = None,
        target: PointCloud | Mesh | None = None,
        target_pose: npt.ArrayLike | None = None,
        allowed_links: Sequence[str] | None = None,
        shadow: Occlusion | None = None,
        shadow_depth: float | None = None,
        shadow_prior: float | None = None,
    ) -> RobotRequest: ...
    @property
    def collide(self) -> CollisionRequest:
        """The options of each link's query."""
    @property
    def mesh_side(self) -> _MeshSideName:
        """How each link stands: its exact surface or its mesh sampled."""
    @property
    def mesh_spacing(self) -> float | None:
        """Sampling spacing of sampled links (metres), or ``None``: from the cloud."""
    @property
    def broad_phase(self) -> bool:
        """Whether links that cannot reach the cloud are skipped."""
    @property
    def self_collision(self) -> bool:
        """Whether self-collision between non-adjacent links is checked."""
    @property
    def padding(self) -> float | dict[str, float]:
        """The links' safety margin (metres): one for every link, or by link name."""
    @property
    def target(self) -> PointCloud | Mesh | None:
        """The object about to be grasped, or ``None``."""
    @property
    def target_pose(self) -> Any | None:
        """The pose of a :class:`Mesh` target, as given, or ``None``."""
    @property
    def allowed_links(self) -> Sequence[str] | None:
        """The links that may touch the target, as given, or ``None``."""
    @property
    def shadow(self) -> Occlusion | None:
        """The scan's occlusion whose shadow the links read, or ``None``."""
    @property
    def shadow_depth(self) -> float | None:
        """With a shadow: the thickness behind the observed surface that counts."""
    @property
    def shadow_prior(self) -> float | None:
        """With a shadow: the prior probability of a shadowed sample."""
    def replace(self, **changes: Any) -> RobotRequest:
        """Return a copy with the given options changed (``None`` leaves one as it is).

        ``changes`` are the options of :class:`RobotRequest` and of
        :class:`CollisionRequest` (applied to :attr:`collide`).

        Raises
        ------
        InvalidInputError
            On an unknown option name or a value out of its domain.
        """
    def to_dict(self) -> dict[str, Any]:
        """Return every option as a dict; ``RobotRequest(**d)`` rebuilds the request."""
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class MotionRequest:
    """The options of :func:`check_motion`, as one immutable value.

    Accepted by :func:`check_motion` as ``request=``, keyword options given
    beside it overriding its values, as :class:`RobotRequest` is by
    :func:`collide_robot`; each option is parsed and checked as the same keyword
    option of :func:`check_motion` is. Requests are frozen and pickle;
    :meth:`replace` gives a modified copy.

    Parameters
    ----------
    robot : RobotRequest, optional
        Every state's query (default ``RobotRequest()``).
    resolution : float, optional
        The largest distance (metres) a link point may move between two checked
        states (default: the cloud's median noise standard deviation, or half its
        median spacing without noise).
    max_probability : float, optional
        A state is unsafe above this probability, in ``[0, 1]`` (default: the
        free threshold).
    warm_start : bool, optional
        Start each state's classifier from the previous state's samples
        (default ``True``).

    Examples
    --------
    >>> import cloudprox as cp
    >>> request = cp.MotionRequest(robot=cp.RobotRequest(padding=0.01), resolution=0.005)
    >>> request.replace(warm_start=False).warm_start
    False
    """

    def __new__(
        cls,
        *,
        robot: RobotRequest | None = None,
        resolution: float | None = None,
        max_probability: float | None = None,
        warm_start: bool | None = None,
    ) -> MotionRequest: ...
    @property
    def robot(self) -> RobotRequest:
        """Every state's query."""
    @property
    def resolution(self) -> float | None:
        """The largest displacement of a link point between two states, or ``None``."""
    @property
    def max_probability(self) -> float | None:
        """A state is unsafe above this probability, or ``None``: the free threshold."""
    @property
    def warm_start(self) -> bool:
        """Whether each state's classifier starts from the previous state's samples."""
    def replace(self, **changes: Any) -> MotionRequest:
        """Return a copy with the given options changed (``None`` leaves one as it is).

        ``changes`` are the options of :class:`MotionRequest`, of
        :class:`RobotRequest` and of :class:`CollisionRequest`.

        Raises
        ------
        InvalidInputError
            On an unknown option name or a value out of its domain.
        """
    def to_dict(self) -> dict[str, Any]:
        """Return every option as a dict; ``MotionRequest(**d)`` rebuilds the request."""
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

def collide_robot(
    robot: Robot,
    q: _Configuration,
    cloud: PointCloud,
    base_pose: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | RobotRequest | None = None,
    **options: Any,
) -> RobotCollisionResult:
    """Query the robot at configuration ``q`` (root at ``base_pose``) against a cloud.

    Each link with geometry stands, by default (``mesh_side="exact"``), as its exact
    surface: its signed distance, built when the robot was loaded, is the separating
    surface, as :func:`collide` reads a mesh (nothing sampled, nothing trained;
    ``solver_iterations`` stays 0). With ``mesh_side="sampled"`` (the default when a
    ``mesh_spacing`` is given) each link is sampled once per spacing (``mesh_spacing``,
    default half the cloud's median spacing) into a cloud without sensor noise. A
    broad phase (``broad_phase=True``) skips links that cannot reach the cloud,
    before any signed distance or sample is read: for exact links, the link's
    bounding box is beyond the noise's reach of every leaf of the cloud's hierarchy
    (over its points with the points model, over its element hulls with the
    elements model); for sampled links, with the points model, the link's bounding
    box is beyond the noise's reach of every node of the cloud's hierarchy, with the
    elements model, no element surface of the link comes within the noise's reach
    of one of the cloud (the hierarchies over both clouds' element hulls). Their
    query would read 0. Every other link is queried as :func:`collide` does (the
    link as side ``a``); with ``decide_only=True`` the
    links after the first whose probability reaches ``threshold_collision`` are
    left (probability NaN, ``stats.links_after_decision``): the state is
    collision whatever they hold. Self-collision between non-adjacent links
    (exact meshes, ``self_collision=True``) is reported apart.
    ``request`` is a :class:`RobotRequest` (every option typed), or a
    :class:`CollisionRequest` (the link queries' options, the robot's at their
    defaults); ``options`` are the keyword options of :class:`CollisionRequest`
    and :class:`RobotRequest` (overriding ``request``'s, as
    ``request.replace(**options)`` does): ``mesh_side`` (``"exact"`` or ``"sampled"``),
    ``mesh_spacing`` (with sampled links only), ``broad_phase``,
    ``self_collision``, ``padding``, ``target``, ``target_pose``,
    ``allowed_links``, ``shadow``, ``shadow_depth`` and ``shadow_prior``;
    unknown names raise :class:`InvalidInputError`. The GIL is released.

    ``padding`` (metres, default 0) grows each link's surface by a safety margin
    (an exact link's signed distance less it; a sampled link's samples moved
    along their faces' normals): a float for every link, or a dict from link name
    to metres for the links it names (the others unpadded); attached objects are
    not padded.

    ``target`` is an object about to be grasped, still in the scene: a
    :class:`PointCloud` (in the cloud's frame) or a :class:`Mesh` at
    ``target_pose`` (sampled at the links' sampling spacing). The links (or
    attached objects) named in ``allowed_links`` may touch it: their contacts
    are reported apart (:attr:`RobotCollisionResult.target`,
    :attr:`LinkCollision.target`); every other link is queried against it as
    against the cloud, and counts. Unknown link names, a negative or NaN
    padding, ``allowed_links`` without a ``target`` raise
    :class:`InvalidInputError`.

    ``shadow`` (a :class:`cloudprox.filters.Occlusion` of the scan, from its
    sensor's origin) reads what the sensor did not see: each link's surface,
    sampled at the occlusion's footprint, has a shadow probability,
    ``shadow_prior`` (default 0.5) times the largest probability of a sample
    lying behind the observed surface by at most ``shadow_depth`` (metres,
    default 0.05: the thickness of the objects seen from the front), and the
    link's probability is the aggregation of its query's and that
    (:attr:`LinkCollision.shadow`). A link reaching into the scan's shadow
    then reads ``contact`` rather than ``free``.
    """

def collide_robot_many(
    robot: Robot,
    qs: npt.ArrayLike | Sequence[_Configuration],
    cloud: PointCloud,
    base_pose: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | RobotRequest | None = None,
    **options: Any,
) -> RobotBatchResult:
    """:func:`collide_robot` for each row of the ``(m, dof)`` array ``qs`` (or each configuration of a list, arrays or joint-name mappings), in parallel, GIL released."""

def check_motion(
    robot: Robot,
    q0: _Configuration,
    q1: _Configuration,
    cloud: PointCloud,
    base_pose: npt.ArrayLike | None = None,
    *,
    request: CollisionRequest | RobotRequest | MotionRequest | None = None,
    **options: Any,
) -> MotionResult:
    """Check the straight joint-space motion from ``q0`` to ``q1`` against the cloud.

    States ``q0 + t (q1 - q0)`` at ``t = i / n`` are checked in order, ``n`` the
    smallest count for which no link point moves more than ``resolution`` metres
    between two states (default: the cloud's median noise standard deviation, or half
    its median spacing without noise); the check stops at the first unsafe state
    (probability above ``max_probability``, default ``threshold_free``, or
    self-collision). ``request`` is a :class:`MotionRequest`, or the
    :class:`RobotRequest` or :class:`CollisionRequest` of every state (the
    motion's own options at their defaults). ``options``: those of
    :func:`collide_robot` plus ``resolution``, ``max_probability`` and
    ``warm_start`` (the options of :class:`MotionRequest`; default ``True``: each
    state's classifier starts from the samples that supported the previous state's
    surfaces (sampled links only: exact links train nothing), which saves solver iterations (``solver_iterations``) and finds the
    same surfaces to the solver's tolerance, ``P`` within about 1e-5, so only a
    state that close to ``max_probability`` can be judged otherwise; ``False``
    makes each state's answer exactly :func:`collide_robot`'s).
    """

_SignMethodName = Literal["auto", "pseudo_normal", "winding_number"]

@final
class MeshDistance:
    """A triangle mesh prepared for exact signed-distance queries in its own frame.

    Vertices with equal coordinates are welded, faces re-oriented to agree with their
    neighbours and inward-facing shells turned outwards (``topology`` reports what was
    done). The sign is then read by the angle-weighted pseudo-normal of the closest
    feature when the mesh is closed, without degenerate faces, self-intersections or
    overlapping shells, and by the generalized winding number otherwise (inside when
    it exceeds 1/2; for an open mesh, roughly the solid its holes would enclose if
    closed).

    Parameters
    ----------
    mesh : Mesh
        The mesh, in its own frame.
    sign_method : {"auto", "pseudo_normal", "winding_number"}, default "auto"
        Force a sign method instead of choosing it from the topology.

    Raises
    ------
    InvalidInputError
        If every face is degenerate (zero area), or ``sign_method`` is unknown.

    Notes
    -----
    Query points are ``(n, 3)`` array-likes of finite coordinates in metres; a
    non-finite coordinate raises ``InvalidInputError``. The GIL is released during
    the queries, which run in parallel for large batches.
    """

    def __new__(cls, mesh: Mesh, *, sign_method: _SignMethodName = "auto") -> MeshDistance: ...
    @property
    def sign_method(self) -> Literal["pseudo_normal", "winding_number"]:
        """How the sign is read: ``"pseudo_normal"`` or ``"winding_number"``."""
    @property
    def topology(self) -> dict[str, int | bool | None]:
        """What welding and re-orientation found.

        Keys ``vertices`` (after welding), ``shells``, ``boundary_edges``,
        ``non_manifold_edges``, ``degenerate_faces``, ``reoriented_faces``,
        ``closed`` and ``self_intersecting`` (``None`` when not checked).
        """
    @property
    def num_faces(self) -> int:
        """The number of faces of the mesh."""
    def signed_distance(self, points: npt.ArrayLike) -> _FloatArray:
        """Return the signed distance of each point, shape ``(n,)``, negative inside."""
    def distance(self, points: npt.ArrayLike) -> _FloatArray:
        """Return the unsigned distance of each point to the surface, shape ``(n,)``."""
    def closest(self, points: npt.ArrayLike) -> tuple[_FloatArray, _FloatArray, _FloatArray]:
        """Return the closest surface point of each query point.

        Parameters
        ----------
        points : array_like, shape (n, 3)
            Query points (metres), finite.

        Returns
        -------
        distances : ndarray, shape (n,)
            Signed distances, negative inside.
        points : ndarray, shape (n, 3)
            The closest points on the surface.
        normals : ndarray, shape (n, 3)
            Unit gradients of the signed distance (the outward normal: from the
            closest point towards an outside query point).
        """
    def closest_within(
        self, points: npt.ArrayLike, max_distance: float
    ) -> tuple[_FloatArray, _FloatArray, _FloatArray]:
        """Return :meth:`closest` for points within ``max_distance`` of the surface.

        Rows of points farther away are NaN, found without searching farther (for
        broad phases). ``max_distance`` must be >= 0.
        """
    def winding_number(self, points: npt.ArrayLike) -> _FloatArray:
        """Return the generalized winding number of each point, shape ``(n,)`` (exact)."""
    def contains(self, points: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Return whether each point is inside, shape ``(n,)``, per :attr:`sign_method`."""
    def field(self, resolution: float, band: float) -> DistanceField:
        """Build the :class:`DistanceField` of this mesh (see there)."""

@final
class DistanceField:
    """A signed-distance grid in a mesh's own frame, with an error bound per query.

    Nodes every ``resolution`` metres over the mesh's box grown by ``band``; nodes
    within ``band`` of the surface hold the exact signed distance. Queries
    interpolate trilinearly and return a rigorous bound ``|exact - distance| <=
    bound``, from the 1-Lipschitz property of the signed distance: with ``s_i`` the
    corners' values and ``r_i`` their distances to the point, the exact value lies in
    ``[max(s_i - r_i), min(s_i + r_i)]`` (at most half a cell diagonal from the
    interpolant). Points outside the grid, in cells with a corner beyond the band or
    near a hole of an open mesh get the exact query (bound 0).

    Parameters
    ----------
    mesh_distance : MeshDistance
        The mesh.
    resolution : float
        Node spacing (metres), > 0.
    band : float
        Distance from the surface within which nodes are exact (metres), > 0.

    Raises
    ------
    InvalidInputError
        If ``resolution`` or ``band`` is not finite and positive, or the grid would
        have more than 2**25 nodes.
    """

    def __new__(
        cls, mesh_distance: MeshDistance, resolution: float, band: float
    ) -> DistanceField: ...
    def evaluate(self, points: npt.ArrayLike) -> tuple[_FloatArray, _FloatArray, _FloatArray]:
        """Evaluate the field at points in the mesh's frame.

        Parameters
        ----------
        points : array_like, shape (n, 3)
            Query points (metres), finite.

        Returns
        -------
        distances : ndarray, shape (n,)
            Signed distances, negative inside.
        gradients : ndarray, shape (n, 3)
            Gradient of the interpolant (of the exact signed distance, unit, where the
            exact query answered).
        bounds : ndarray, shape (n,)
            Error bounds: ``|exact - distance| <= bound`` (0 where exact).
        """
    @property
    def resolution(self) -> float:
        """Node spacing (metres)."""
    @property
    def band(self) -> float:
        """Distance from the surface within which nodes are exact (metres)."""
    @property
    def shape(self) -> tuple[int, int, int]:
        """Nodes per axis."""
    @property
    def origin(self) -> _FloatArray:
        """Position of node ``(0, 0, 0)``, shape ``(3,)``."""
    @property
    def nbytes(self) -> int:
        """Bytes held by the grid."""
    @property
    def stats(self) -> dict[str, int]:
        """What the build found, counted.

        Keys: ``nodes``, ``nodes_in_band``, ``cells_interpolated``,
        ``cells_sign_agnostic``, ``cells_exact``, ``cells_beyond``, ``exact_sign_nodes``.
        """
    @property
    def mesh_distance(self) -> MeshDistance:
        """The exact queries the field falls back to."""
