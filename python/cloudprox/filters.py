"""Filters that clean a sensor cloud before queries (the pipeline's first step).

Each runs in the Rust core, in parallel, with the GIL released. On 2M points
the crop, voxel, shadow and self filters take 30-560 ms and the outlier filter
about 0.9 s on two cores (see BENCHMARKS.md).

- :class:`SelfFilter`: points on the robot's links (meshes and poses), as ROS
  ``robot_self_filter``;
- :func:`shadow_filter`: veil (mixed) pixels at depth discontinuities, as ROS
  ``laser_filters``' ``ScanShadowsFilter``;
- :func:`crop_box`: points outside (or inside) a box, as PCL ``CropBox``;
- :func:`voxel_downsample`: one point per voxel, covariances merged, as PCL
  ``VoxelGrid``;
- :func:`statistical_outlier_removal`: isolated points, as PCL
  ``StatisticalOutlierRemoval``;
- :class:`Occlusion`: not a filter but its complement, what the scan did not
  see: whether a point lies in front of the observed surface along its
  viewing ray, behind it (in its shadow, with the probability under the
  range noise) or along a direction with no return;
- :func:`split_box` and :func:`split_labels`: a grasp target and the rest of
  the scene, as two :class:`~cloudprox.PointCloud` objects (for
  ``collide_robot(..., target=...)``).

Filters that remove points return the **indices of the kept points** (int64,
ascending), so that points, covariances and pixels can be subset alike::

    keep = cloudprox.filters.shadow_filter(points, origin, pixels=scan.pixels,
                                           grid_shape=scan.grid_shape)
    points, covs = points[keep], covs[keep]

Parameters left ``None`` take the Rust core's defaults (written once, there):
``SOR_DEFAULT_K`` and ``SOR_DEFAULT_STD_RATIO`` (exported here) for the outlier
filter, ``ShadowSettings::default()`` for the shadow filter and
``SELF_FILTER_DEFAULT_PADDING`` for the self filter. Bad parameters raise
:class:`cloudprox.InvalidInputError` naming them.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cloudprox._native import (
    SOR_DEFAULT_K,
    SOR_DEFAULT_STD_RATIO,
    InvalidInputError,
    Occlusion,
    PointCloud,
    SelfFilter,
    crop_box,
    shadow_filter,
    statistical_outlier_removal,
    voxel_downsample,
)

__all__ = [
    "SOR_DEFAULT_K",
    "SOR_DEFAULT_STD_RATIO",
    "Occlusion",
    "SelfFilter",
    "crop_box",
    "shadow_filter",
    "split_box",
    "split_labels",
    "statistical_outlier_removal",
    "voxel_downsample",
]


def _split(
    cloud: PointCloud, inside: npt.NDArray[np.int64], what: str
) -> tuple[PointCloud, PointCloud]:
    if not isinstance(cloud, PointCloud):
        raise TypeError(f"cloud must be a PointCloud, got {type(cloud).__name__}")
    if inside.size == 0:
        raise InvalidInputError(f"{what} holds no point of the cloud: the target would be empty")
    if inside.size == len(cloud):
        raise InvalidInputError(
            f"{what} holds every point of the cloud: nothing would be left of the scene"
        )
    return cloud.select_by_index(inside), cloud.select_by_index(inside, invert=True)


def split_box(
    cloud: PointCloud,
    min: npt.ArrayLike,
    max: npt.ArrayLike,
    pose: npt.ArrayLike | None = None,
) -> tuple[PointCloud, PointCloud]:
    """Split a cloud into the points inside a box (a grasp target) and the rest.

    Parameters
    ----------
    cloud : PointCloud
        The scan, in its own frame.
    min, max : array_like, shape (3,)
        The box's corners in its own frame (as :func:`crop_box` takes them).
    pose : array_like, shape (4, 4), optional
        The box's pose in the cloud's frame (``None``: axis-aligned, identity);
        an oriented box is a rotated pose.

    Returns
    -------
    tuple of PointCloud
        ``(target, rest)``: each point keeps its sensor covariance and the
        clouds the scan's noise correlation (see
        :meth:`PointCloud.select_by_index`), in the scan's frame.

    Raises
    ------
    InvalidInputError
        A box that holds no point (the target would be empty) or every point;
        bad corners or pose, as :func:`crop_box`.
    """
    inside = crop_box(cloud.points, min, max, pose)
    return _split(cloud, inside, "the box")


def split_labels(
    cloud: PointCloud, labels: npt.ArrayLike, label: int
) -> tuple[PointCloud, PointCloud]:
    """Split a cloud into the points labelled ``label`` (a grasp target) and the rest.

    Parameters
    ----------
    cloud : PointCloud
        The scan.
    labels : array_like of int, shape (n,)
        One label per point of ``cloud`` (an instance segmentation's).
    label : int
        The target's label: ``labels == label`` selects it.

    Returns
    -------
    tuple of PointCloud
        ``(target, rest)``, as :func:`split_box` returns them.

    Raises
    ------
    InvalidInputError
        Labels of the wrong shape or not integers; a label that no point, or
        every point, carries.
    """
    arr = np.asarray(labels)
    if arr.shape != (len(cloud),):
        raise InvalidInputError(
            f"labels must have shape ({len(cloud)},), one per point, got {arr.shape}"
        )
    if arr.dtype.kind not in "iu":
        raise InvalidInputError(f"labels must be integers, got dtype {arr.dtype}")
    return _split(cloud, np.flatnonzero(arr == label).astype(np.int64), f"label {label}")
