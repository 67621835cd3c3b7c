"""Reconstruct-then-collide: a triangle mesh from each cloud, then the exact check.

The two-step approach the paper names first ("reconstructing triangle meshes from
point clouds and then performing exact mesh collision checking"): screened Poisson
surface reconstruction (Kazhdan and Hoppe 2013) as Open3D implements it, on
normals from the points' neighbourhoods, then parry's exact triangle-vs-triangle
test through :class:`cloudprox.ExactShape` with ``solid=False``.

Every parameter comes from the cloud's sampling spacing ``h`` and noise ``sigma``:

* normals from the neighbours within ``max(2 h, 3 sigma)`` (at most 30), oriented
  towards the sensor when its position is known, else consistently along a
  minimum spanning tree (Hoppe et al. 1992);
* octree depth so that the finest cell is no larger than ``max(h, sigma)`` (detail
  finer than both the sampling and the noise is not in the data);
* the Poisson surface extrapolates where there are no points; the parts of it
  farther than ``h + 3 sigma`` from every point are cut away (the data does not
  support them).

The solver runs on one thread: Open3D's multithreaded solver sums in an order that
changes run to run (the Kinect frame's reference surface came out with 665 663,
665 666 or 665 667 triangles), and a reproduction's ground truth must not. One
thread costs about 8 s more on the 273 000-point Kinect frame (23 s against 15 s);
:func:`reconstruct_many` gets the cores back by reconstructing several clouds at
once in a process pool, each on one thread (the same surfaces as one by one).

The result is a surface, not a solid: a single scan sees one side of things and
Poisson's inside/outside is not to be trusted there, so the two reconstructions
intersect iff their triangles cross. Open3D is an optional dependency
(``pip install 'cloudprox[reproduce]'``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from concurrent.futures import Executor

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cloudprox._native import ExactShape, Mesh

__all__ = [
    "ReconstructionUnavailable",
    "available",
    "reconstruct",
    "reconstruct_many",
    "surface_shape",
    "tiles",
]

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
#: One reconstruction's arguments: points, spacing, sigma, sensor origin (or ``None``).
Cloud = tuple[FloatArray, float, float, Sequence[float] | None]

#: Deepest octree allowed (memory grows eightfold per level).
MAX_DEPTH = 10


class ReconstructionUnavailable(RuntimeError):
    """Open3D, which does the reconstruction, is not installed."""


def available() -> bool:
    """Return whether Open3D can be imported."""
    try:
        import open3d  # noqa: F401
    except ImportError:
        return False
    return True


def _open3d():  # type: ignore[no-untyped-def]
    try:
        import open3d
    except ImportError as e:
        raise ReconstructionUnavailable(
            "reconstruct-then-collide needs Open3D: pip install 'cloudprox[reproduce]' "
            f"(open3d-cpu); import failed: {e}"
        ) from e
    return open3d


def reconstruct(
    points: FloatArray,
    spacing: float,
    sigma: float,
    sensor_origin: Sequence[float] | None = None,
) -> Mesh:
    """Return a triangle mesh reconstructed from ``points`` by screened Poisson.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        The cloud (metres), at least 10 finite points.
    spacing : float
        Sampling spacing ``h`` of the cloud (metres, > 0).
    sigma : float
        Typical sensor standard deviation (metres, >= 0).
    sensor_origin : sequence of 3 floats, optional
        Where the sensor was, in the cloud's frame; orients the normals towards it.

    Returns
    -------
    Mesh

    Raises
    ------
    ValueError
        Bad points or parameters, or nothing left after the support cut.
    ReconstructionUnavailable
        Open3D is missing.
    """
    pts = np.array(points, dtype=float)  # a writeable copy, as Open3D wants
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {pts.shape}")
    if len(pts) < 10:
        raise ValueError(f"reconstruction needs at least 10 points, got {len(pts)}")
    if not np.all(np.isfinite(pts)):
        raise ValueError("points contain NaN or infinite coordinates")
    if not (math.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be finite and positive, got {spacing}")
    if not (math.isfinite(sigma) and sigma >= 0.0):
        raise ValueError(f"sigma must be finite and non-negative, got {sigma}")
    o3d = _open3d()
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    radius = max(2.0 * spacing, 3.0 * sigma)
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=radius, max_nn=30))
    if sensor_origin is not None:
        pcd.orient_normals_towards_camera_location(np.asarray(sensor_origin, dtype=float))
    else:
        pcd.orient_normals_consistent_tangent_plane(15)
    extent = float(np.max(pts.max(axis=0) - pts.min(axis=0)))
    cell = max(spacing, sigma)
    depth = int(min(MAX_DEPTH, max(4, math.ceil(math.log2(1.1 * extent / cell)))))
    mesh, _density = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(
        pcd, depth=depth, scale=1.1, n_threads=1
    )
    vertices = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.triangles, dtype=np.int64)
    d, _ = cKDTree(pts).query(vertices)
    supported = d <= spacing + 3.0 * sigma
    keep = supported[faces].all(axis=1)
    faces = faces[keep]
    faces = faces[
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    ]
    if len(faces) == 0:
        raise ValueError("the reconstruction has no triangle near the points")
    used = np.unique(faces)
    remap = np.full(len(vertices), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return Mesh(vertices[used], remap[faces])


def _reconstruction_arrays(
    points: FloatArray, spacing: float, sigma: float, sensor_origin: Sequence[float] | None
) -> tuple[FloatArray, IntArray]:
    """:func:`reconstruct` as vertex and face arrays (a pool's task: arrays cross processes)."""
    mesh = reconstruct(points, spacing, sigma, sensor_origin)
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)


def reconstruct_many(clouds: Sequence[Cloud], pool: Executor | None = None) -> list[Mesh]:
    """Return :func:`reconstruct` of each ``(points, spacing, sigma, sensor_origin)``.

    With ``pool`` (a process pool), the clouds are reconstructed at once, one per
    process: each reconstruction runs on one thread, so the meshes are those of
    one by one, in a fraction of the time. An error cancels the tasks not yet
    started and is raised.
    """
    if pool is None:
        return [reconstruct(*c) for c in clouds]
    futures = [pool.submit(_reconstruction_arrays, *c) for c in clouds]
    try:
        return [Mesh(*f.result()) for f in futures]
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def tiles(mesh: Mesh, cell: float) -> list[Mesh]:
    """Split ``mesh`` into the triangles whose centroids fall in each cube of side ``cell``.

    Exact distances between large triangle meshes are slow when they are apart;
    tiles let :func:`cloudprox.exact_proximity` skip every tile whose box is
    farther than the best distance found so far.
    """
    if not (math.isfinite(cell) and cell > 0.0):
        raise ValueError(f"cell must be finite and positive, got {cell}")
    v = np.asarray(mesh.vertices)
    f = np.asarray(mesh.faces, dtype=np.int64)
    key = np.floor(v[f].mean(axis=1) / cell).astype(np.int64)
    _, which = np.unique(key, axis=0, return_inverse=True)
    order = np.argsort(which.ravel(), kind="stable")
    bounds = np.flatnonzero(np.diff(which.ravel()[order])) + 1
    out = []
    for group in np.split(order, bounds):
        ff = f[group]
        used, local = np.unique(ff, return_inverse=True)
        out.append(Mesh(v[used], local.reshape(ff.shape)))
    return out


def surface_shape(mesh: Mesh, cell: float | None = None) -> ExactShape:
    """Prepare a reconstruction for exact queries as a bare surface.

    With ``cell``, the surface is split into :func:`tiles` of that size first.
    """
    parts = [mesh] if cell is None else tiles(mesh, cell)
    return ExactShape(parts, solid=False)
