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
  range noise) or along a direction with no return.

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

from cloudprox._native import (
    SOR_DEFAULT_K,
    SOR_DEFAULT_STD_RATIO,
    Occlusion,
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
    "statistical_outlier_removal",
    "voxel_downsample",
]
