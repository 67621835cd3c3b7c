"""The sensor-cloud filters through the Python API, against analytic answers and Open3D.

Open3D facts these tests rely on (checked here; measured with open3d 0.20):

- ``PointCloud.crop(AxisAlignedBoundingBox)`` keeps ``min <= p <= max`` on every axis,
  bounds included, as :func:`cloudprox.filters.crop_box`.
- ``voxel_down_sample(v)`` anchors its grid at the cloud's minimum **minus v/2**, cloudprox
  (as PCL) at the minimum itself; the two partitions agree only when every point's offset from
  the minimum is, modulo ``v``, in ``[0, v/2)`` on every axis. The lattice below is built so.
- ``remove_statistical_outlier(nb_neighbors, std_ratio)`` counts the query point itself among
  its ``nb_neighbors`` (a zero distance in the mean), PCL and cloudprox do not: Open3D's
  ``nb_neighbors = k + 1`` gives every mean distance scaled by ``k / (k + 1)``, hence the same
  kept set as cloudprox's ``k``. Both use the **sample** standard deviation (divide by
  ``n - 1``, Bessel), as PCL: on small clouds where the population and sample thresholds keep
  different sets, both match the sample one (``test_sor_std_is_sample_std_like_open3d``).
  Open3D keeps ``d < threshold``, cloudprox ``d <= threshold`` (ties have measure zero).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import filters
from cloudprox.pose import from_rotation_vector

o3d = pytest.importorskip("open3d")


# --------------------------------------------------------------------------- helpers


def apply(pose: np.ndarray, points: np.ndarray) -> np.ndarray:
    return points @ pose[:3, :3].T + pose[:3, 3]


def mask(n: int, keep: np.ndarray) -> np.ndarray:
    m = np.zeros(n, dtype=bool)
    m[keep] = True
    return m


def assert_indices(keep: np.ndarray, n: int) -> None:
    assert keep.dtype == np.int64 and keep.ndim == 1
    assert np.all(np.diff(keep) > 0), "indices must be strictly ascending"
    assert keep.size == 0 or (keep[0] >= 0 and keep[-1] < n)


def o3d_cloud(points: np.ndarray) -> Any:  # open3d ships no type stubs
    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))


def cube_lattice(n: int, step: float) -> np.ndarray:
    """``n**3`` points ``step * (i, j, k)``, ``i, j, k in 0..n-1`` (x slowest)."""
    i = np.arange(n) * step
    return np.stack(np.meshgrid(i, i, i, indexing="ij"), -1).reshape(-1, 3)


# Voxel lattice: K voxels per axis of side V. Every voxel (i, j, l) holds the 27 points
# V * ((i, j, l) + (f1, f2, f3)), f in FRACS; one extra point at the corner (0, 0, 0) is the
# cloud's minimum and anchors both grids. Offsets from the minimum are V * (cell + f) with
# f in [0, 0.5): no point on a voxel boundary, in cloudprox's grid or in Open3D's (shifted by
# V / 2), so both make the same K**3 voxels.
V = 0.05
K = 4
FRACS = (0.1, 0.25, 0.4)
OFFSET = np.array([0.31, -1.7, 2.05])


def voxel_lattice() -> tuple[np.ndarray, np.ndarray]:
    """Points ``(27 K**3 + 1, 3)`` and the voxel ``(i, j, l)`` of each point."""
    cells = cube_lattice(K, 1.0)
    fr = np.array(FRACS)
    sub = np.stack(np.meshgrid(fr, fr, fr, indexing="ij"), -1).reshape(-1, 3)
    rel = (cells[:, None, :] + sub[None, :, :]).reshape(-1, 3)
    voxel = np.repeat(cells, len(sub), axis=0)
    rel = np.vstack([[0.0, 0.0, 0.0], rel])
    voxel = np.vstack([[0.0, 0.0, 0.0], voxel]).astype(np.int64)
    return OFFSET + V * rel, voxel


def random_spd(n: int, rng: np.random.Generator) -> np.ndarray:
    a = rng.normal(scale=1e-3, size=(n, 3, 3))
    return a @ np.swapaxes(a, 1, 2) + 1e-7 * np.eye(3)


# --------------------------------------------------------------------------- crop box


def test_crop_box_counts_on_lattice_bounds_included() -> None:
    # Exact binary lattice (step 1/8): box faces pass through lattice planes.
    pts = cube_lattice(10, 0.125)
    keep = filters.crop_box(pts, [0.25, 0.25, 0.25], [0.5, 0.75, 1.0])
    assert_indices(keep, len(pts))
    assert keep.size == 3 * 5 * 7  # bounds included on every axis
    inside = np.all((pts >= [0.25, 0.25, 0.25]) & (pts <= [0.5, 0.75, 1.0]), axis=1)
    np.testing.assert_array_equal(keep, np.flatnonzero(inside))
    out = filters.crop_box(pts, [0.25, 0.25, 0.25], [0.5, 0.75, 1.0], invert=True)
    np.testing.assert_array_equal(out, np.flatnonzero(~inside))
    # A flat box (min == max on z) is allowed: one lattice plane.
    flat = filters.crop_box(pts, [0.0, 0.0, 0.5], [2.0, 2.0, 0.5])
    assert flat.size == 100
    # A box around nothing keeps nothing; inverted, everything.
    assert filters.crop_box(pts, [5.0, 5.0, 5.0], [6.0, 6.0, 6.0]).size == 0
    assert filters.crop_box(pts, [5.0, 5.0, 5.0], [6.0, 6.0, 6.0], invert=True).size == len(pts)


def test_crop_box_rotated_by_pose() -> None:
    # In the box's frame: a lattice at ±0.05, ±0.15, ... ±0.95 (inside [-1, 1]^3) plus a shell
    # of points at ±1.05 on one axis (outside). Placed in the cloud frame by a rotated pose.
    g = np.arange(-0.95, 1.0, 0.1)
    inner = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    shell = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            s = inner[::7].copy()
            s[:, axis] = sign * 1.05
            shell.append(s)
    local = np.vstack([inner, *shell])
    is_inner = np.arange(len(local)) < len(inner)
    pose = from_rotation_vector([0.3, -0.5, 0.8], [2.0, -1.0, 0.5])
    pts = apply(pose, local)
    keep = filters.crop_box(pts, [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], pose=pose)
    np.testing.assert_array_equal(keep, np.flatnonzero(is_inner))
    out = filters.crop_box(pts, [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], pose=pose, invert=True)
    np.testing.assert_array_equal(out, np.flatnonzero(~is_inner))
    # The same box without the pose (axis-aligned at the origin) keeps something else.
    assert not np.array_equal(filters.crop_box(pts, [-1, -1, -1], [1, 1, 1]), keep)


def test_crop_box_invariant_under_rigid_transform() -> None:
    rng = np.random.default_rng(11)
    pts = rng.uniform(-2.0, 2.0, size=(20_000, 3))
    pose = from_rotation_vector([0.0, 0.0, 0.7], [0.2, 0.1, -0.3])
    lo, hi = np.array([-0.8, -0.5, -1.0]), np.array([0.9, 0.6, 0.4])
    keep = filters.crop_box(pts, lo, hi, pose=pose)
    assert 0 < keep.size < len(pts)
    t = from_rotation_vector([1.1, -0.4, 2.0], [10.0, -3.0, 7.0])
    keep_t = filters.crop_box(apply(t, pts), lo, hi, pose=t @ pose)
    np.testing.assert_array_equal(keep_t, keep)


def test_crop_box_agrees_with_open3d() -> None:
    rng = np.random.default_rng(5)
    lattice = cube_lattice(10, 0.125)  # points on the box faces: inclusion rule matters
    pts = np.vstack([lattice, rng.uniform(-0.2, 1.3, size=(5_000, 3))])
    lo, hi = np.array([0.25, 0.125, 0.0]), np.array([0.75, 1.0, 0.5])
    keep = filters.crop_box(pts, lo, hi)
    bbox = o3d.geometry.AxisAlignedBoundingBox(lo, hi)
    ref = np.sort(np.asarray(bbox.get_point_indices_within_bounding_box(o3d_cloud(pts).points)))
    np.testing.assert_array_equal(keep, ref)
    cropped = np.asarray(o3d_cloud(pts).crop(bbox).points)
    np.testing.assert_array_equal(pts[keep], cropped)


# --------------------------------------------------------------------------- voxel


def test_voxel_lattice_count_centroids_counts() -> None:
    pts, voxel = voxel_lattice()
    voxels = filters.voxel_downsample(pts, V)
    assert isinstance(voxels, cp.Voxels)
    centroids, covs, counts = voxels
    assert voxels.points is not None and voxels.covariances is None
    np.testing.assert_array_equal(voxels.counts, counts)
    np.testing.assert_array_equal(voxels[0], centroids)
    assert covs is None
    assert centroids.shape == (K**3, 3) and counts.shape == (K**3,)
    assert counts.dtype == np.int64
    assert counts.sum() == len(pts)
    assert len(voxels) == 3 and repr(voxels) == f"Voxels(points={K**3}, covariances=None)"
    # Ordered by voxel (i, j, l), x slowest: the order of cube_lattice.
    cells = cube_lattice(K, 1.0)
    expected_counts = np.full(K**3, 27)
    expected_counts[0] = 28  # the corner point joins voxel (0, 0, 0)
    np.testing.assert_array_equal(counts, expected_counts)
    expected = OFFSET + V * (cells + np.mean(FRACS))
    expected[0] = OFFSET + V * (27 * np.mean(FRACS) / 28) * np.ones(3)
    np.testing.assert_allclose(centroids, expected, rtol=0, atol=1e-12)
    # Each centroid is the mean of its members (grouped independently of the filter).
    for c in (1, 17, K**3 - 1):
        members = np.all(voxel == cells[c].astype(np.int64), axis=1)
        np.testing.assert_allclose(centroids[c], pts[members].mean(0), rtol=0, atol=1e-12)


def test_voxel_covariance_merging_mean_and_independent() -> None:
    pts, voxel = voxel_lattice()
    rng = np.random.default_rng(2)
    covs = random_spd(len(pts), rng)
    c_mean, s_mean, n_mean = filters.voxel_downsample(pts, V, covs, merge="mean")
    c_ind, s_ind, n_ind = filters.voxel_downsample(pts, V, covs, merge="independent")
    assert s_mean is not None and s_ind is not None
    np.testing.assert_array_equal(c_mean, c_ind)
    np.testing.assert_array_equal(n_mean, n_ind)
    cells = cube_lattice(K, 1.0).astype(np.int64)
    for c in range(K**3):
        members = np.all(voxel == cells[c], axis=1)
        n = int(members.sum())
        assert n == n_mean[c]
        total = covs[members].sum(0)
        np.testing.assert_allclose(s_mean[c], total / n, rtol=1e-12, atol=1e-20)
        np.testing.assert_allclose(s_ind[c], total / n**2, rtol=1e-12, atol=1e-20)
    # "independent" is "mean" over n, so never larger.
    np.testing.assert_allclose(s_ind, s_mean / n_mean[:, None, None], rtol=1e-12, atol=1e-20)
    # A single point in its voxel keeps its own covariance under both rules.
    one = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    _, s1, _ = filters.voxel_downsample(one, 0.1, covs[:2], merge="independent")
    assert s1 is not None
    np.testing.assert_allclose(s1, covs[:2], rtol=1e-15)


def test_voxel_agrees_with_open3d() -> None:
    pts, _ = voxel_lattice()
    centroids, _, _ = filters.voxel_downsample(pts, V)
    down = np.asarray(o3d_cloud(pts).voxel_down_sample(V).points)
    assert len(down) == len(centroids) == K**3
    order = np.lexsort(down.T[::-1])  # x slowest, like cloudprox's output
    np.testing.assert_allclose(down[order], centroids, rtol=0, atol=1e-9)


# --------------------------------------------------------------------------- SOR


def test_sor_removes_far_outliers_from_dense_plane() -> None:
    rng = np.random.default_rng(7)
    g = np.arange(100) * 0.01
    plane = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    plane = np.column_stack([plane, np.zeros(len(plane))]) + rng.normal(0, 0.001, (10_000, 3))
    outliers = rng.uniform([-0.5, -0.5, 0.3], [1.5, 1.5, 1.5], size=(100, 3))  # 1%
    pts = np.vstack([plane, outliers])
    is_plane = np.arange(len(pts)) < len(plane)
    keep = filters.statistical_outlier_removal(pts)  # defaults k = 20, std_ratio = 2
    assert_indices(keep, len(pts))
    kept = mask(len(pts), keep)
    assert not kept[~is_plane].any(), "every far outlier is removed"
    assert kept[is_plane].mean() > 0.99
    assert filters.SOR_DEFAULT_K == 20 and filters.SOR_DEFAULT_STD_RATIO == 2.0
    np.testing.assert_array_equal(filters.statistical_outlier_removal(pts, 20, 2.0), keep)


def _sor_reference(pts: np.ndarray, k: int, std_ratio: float, ddof: int) -> np.ndarray:
    from scipy.spatial import cKDTree  # type: ignore[import-untyped]

    d, _ = cKDTree(pts).query(pts, k + 1)
    mean = d[:, 1:].mean(1)  # k nearest *other* points (PCL)
    return np.flatnonzero(mean <= mean.mean() + std_ratio * mean.std(ddof=ddof))


def test_sor_agrees_with_open3d_on_random_cloud() -> None:
    rng = np.random.default_rng(3)
    pts = np.vstack([rng.random((4000, 3)), rng.uniform(-1.0, 2.0, (40, 3))])
    for k, ratio in ((10, 1.0), (20, 2.0), (8, 0.5)):
        keep = filters.statistical_outlier_removal(pts, k, ratio)
        _, ind = o3d_cloud(pts).remove_statistical_outlier(nb_neighbors=k + 1, std_ratio=ratio)
        np.testing.assert_array_equal(keep, np.sort(np.asarray(ind)))
        np.testing.assert_array_equal(keep, _sor_reference(pts, k, ratio, ddof=1))
        assert 0 < len(pts) - keep.size < len(pts) // 2


def test_sor_std_is_sample_std_like_open3d() -> None:
    # Small clouds where the population (n) and sample (n - 1) thresholds keep different sets.
    k, ratio, found = 5, 1.0, 0
    for seed in range(200):
        pts = np.random.default_rng(seed).random((20, 3))
        pop, sample = (_sor_reference(pts, k, ratio, ddof) for ddof in (0, 1))
        if np.array_equal(pop, sample):
            continue
        found += 1
        keep = filters.statistical_outlier_removal(pts, k, ratio)
        _, ind = o3d_cloud(pts).remove_statistical_outlier(nb_neighbors=k + 1, std_ratio=ratio)
        np.testing.assert_array_equal(keep, sample)
        np.testing.assert_array_equal(np.sort(np.asarray(ind)), sample)
    assert found >= 5


# --------------------------------------------------------------------------- shadow

# Pinhole camera at the origin looking along +z (x right, y down): a wall at z = 2 and the front
# face of a box (half side 0.15 m) at z = 1 on the optical axis. Pixels within BAND pixels outside
# the box's silhouette are mixed pixels: depths interpolated from the box to the wall.
H, W, F, BAND = 240, 320, 300.0, 4


def depth_scene(band: int = BAND) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(H * W, 3)`` (pixel ``i`` is point ``i``) and the veil mask."""
    r, c = np.mgrid[0:H, 0:W]
    x, y = (c + 0.5 - W / 2) / F, (r + 0.5 - H / 2) / F
    half, z_box, z_wall = 0.15, 1.0, 2.0
    inside = (np.abs(x * z_box) <= half) & (np.abs(y * z_box) <= half)
    edge = half / z_box * F  # silhouette half width (pixels)
    out_px = np.maximum(np.maximum(np.abs(x) * F - edge, 0), np.maximum(np.abs(y) * F - edge, 0))
    veil = ~inside & (out_px < band)
    depth = np.where(inside, z_box, z_wall)
    mix = np.clip(np.ceil(out_px) / (band + 1), 0.0, 1.0)
    depth = np.where(veil, z_box + (z_wall - z_box) * mix, depth)
    pts = np.stack([x * depth, y * depth, depth], -1).reshape(-1, 3)
    return pts, veil.ravel()


def near_veil(veil: np.ndarray, window: int = 1) -> np.ndarray:
    """Pixels with a veil pixel within ``window`` rows and columns."""
    v = veil.reshape(H, W)
    out = np.zeros_like(v)
    for dr in range(-window, window + 1):
        for dc in range(-window, window + 1):
            out |= np.roll(np.roll(v, dr, 0), dc, 1)
    return out.ravel()


def test_shadow_organized_removes_veil() -> None:
    pts, veil = depth_scene()
    assert veil.sum() > 1000
    keep = filters.shadow_filter(pts, np.zeros(3), pixels=np.arange(len(pts)), grid_shape=(H, W))
    assert_indices(keep, len(pts))
    kept = mask(len(pts), keep)
    assert not kept[veil].any()
    # The defaults (None) are the core's ShadowSettings::default(): 10 degrees, 1, 8.
    explicit = filters.shadow_filter(
        pts,
        np.zeros(3),
        pixels=np.arange(len(pts)),
        grid_shape=(H, W),
        min_angle_deg=10.0,
        window=1,
        k=8,
    )
    np.testing.assert_array_equal(explicit, keep)
    assert kept[~veil].mean() > 0.98
    # The real points removed are the veil's immediate neighbours (as in ROS), nothing else.
    assert not (~kept & ~veil & ~near_veil(veil)).any()


def test_shadow_organized_with_missing_pixels() -> None:
    # A sensor drops pixels (no return): the remaining points keep their own pixel indices.
    pts, veil = depth_scene()
    valid = np.random.default_rng(4).random(len(pts)) > 0.1
    idx = np.flatnonzero(valid)
    keep = filters.shadow_filter(pts[idx], np.zeros(3), pixels=idx, grid_shape=(H, W))
    kept = mask(len(idx), keep)
    sub_veil = veil[idx]
    assert not kept[sub_veil].any()
    assert kept[~sub_veil].mean() > 0.98


def test_shadow_flat_wall_keeps_everything_and_rigid_invariance() -> None:
    pts, veil = depth_scene()
    wall = pts.copy()
    wall *= (2.0 / wall[:, 2])[:, None]  # every pixel on the wall: no discontinuity
    keep = filters.shadow_filter(wall, np.zeros(3), pixels=np.arange(len(wall)), grid_shape=(H, W))
    assert keep.size == len(wall)
    assert filters.shadow_filter(wall, np.zeros(3)).size == len(wall)
    # Moving the sensor and the scene together changes nothing.
    t = from_rotation_vector([0.4, 1.2, -0.3], [1.0, 2.0, -4.0])
    a = filters.shadow_filter(pts, np.zeros(3), pixels=np.arange(len(pts)), grid_shape=(H, W))
    b = filters.shadow_filter(
        apply(t, pts), t[:3, 3], pixels=np.arange(len(pts)), grid_shape=(H, W)
    )
    np.testing.assert_array_equal(a, b)
    assert veil.any()


def test_shadow_unorganized_default_k_removes_veil() -> None:
    # Without the pixel grid the neighbours are the k points nearest in viewing direction
    # (the angular neighbours an image would give): a veil point's neighbours lie along its
    # ray, as in the organized path.
    pts, veil = depth_scene()
    keep = filters.shadow_filter(pts, np.zeros(3))
    kept = mask(len(pts), keep)
    assert not kept[veil].any()
    assert kept[~veil].mean() > 0.98


def test_shadow_unorganized_dense_veil() -> None:
    # A dense veil (16 mixing levels) is removed whole with the default k too.
    pts, veil = depth_scene(band=16)
    keep = filters.shadow_filter(pts, np.zeros(3))
    kept = mask(len(pts), keep)
    assert veil.sum() > 5000
    assert not kept[veil].any()
    assert kept[~veil].mean() > 0.98


# --------------------------------------------------------------------------- self filter

LINK_HALF = (0.1, 0.05, 0.04)
SIGMA = 0.002


def table_and_link(pose: np.ndarray) -> tuple[np.ndarray, np.ndarray, cp.Mesh]:
    """Noisy table points (z = 0, 1 m x 1 m) and noisy points sampled on the link at ``pose``."""
    rng = np.random.default_rng(9)
    table = np.column_stack([rng.uniform(-0.5, 0.5, (20_000, 2)), np.zeros(20_000)])
    table += rng.normal(0.0, SIGMA, table.shape)
    link = cp.Mesh.cuboid(*LINK_HALF)
    local, _, _ = link.sample(density=30_000.0, seed=1)
    on_link = apply(pose, local) + rng.normal(0.0, SIGMA, local.shape)
    return table, on_link, link


def hover_pose(x: float = 0.0, y: float = 0.0) -> np.ndarray:
    # Bottom face 3 cm above the table (the pose keeps z vertical).
    return from_rotation_vector([0.0, 0.0, 0.5], [x, y, 0.03 + LINK_HALF[2]])


def test_self_filter_removes_link_keeps_table() -> None:
    pose = hover_pose()
    table, on_link, link = table_and_link(pose)
    pts = np.vstack([table, on_link])
    is_table = np.arange(len(pts)) < len(table)
    f = filters.SelfFilter([(link, pose)], padding=0.01)
    assert filters.SelfFilter([(link, pose)]).padding == f.padding  # the core's default
    assert f.padding == 0.01
    keep = f.apply(pts)
    assert_indices(keep, len(pts))
    np.testing.assert_array_equal(keep, np.flatnonzero(is_table))
    # A point inside the closed link is removed; one 2 cm above its top face is kept.
    centre, above = pose[:3, 3], pose[:3, 3] + [0.0, 0.0, LINK_HALF[2] + 0.02]
    assert f.apply(np.array([centre, above])).tolist() == [1]
    # Padding 5 cm reaches the table under the link (3 cm below it).
    wide = filters.SelfFilter([(link, pose)], padding=0.05).apply(table)
    assert wide.size < len(table)


def test_self_filter_set_poses_moves_link() -> None:
    pose = hover_pose()
    table, on_link, link = table_and_link(pose)
    moved_pose = hover_pose(x=0.3, y=-0.2)
    moved = apply(moved_pose @ np.linalg.inv(pose), on_link)
    pts = np.vstack([table, on_link, moved])
    f = filters.SelfFilter([(link, pose)], padding=0.01)
    labels = np.repeat([0, 1, 2], [len(table), len(on_link), len(moved)])
    np.testing.assert_array_equal(f.apply(pts), np.flatnonzero(labels != 1))
    f.set_poses(moved_pose[None])
    np.testing.assert_array_equal(f.apply(pts), np.flatnonzero(labels != 2))
    # A bare Mesh is a link at the identity pose.
    g = filters.SelfFilter([link.transformed(moved_pose)], padding=0.01)
    np.testing.assert_array_equal(g.apply(pts), np.flatnonzero(labels != 2))


def test_self_filter_invariant_under_rigid_transform() -> None:
    pose = hover_pose()
    table, on_link, link = table_and_link(pose)
    rng = np.random.default_rng(1)
    pts = np.vstack([table, on_link, rng.uniform(-0.3, 0.3, (5_000, 3))])
    keep = filters.SelfFilter([(link, pose)], padding=0.01).apply(pts)
    t = from_rotation_vector([2.0, -0.7, 0.4], [5.0, -2.0, 1.0])
    keep_t = filters.SelfFilter([(link, t @ pose)], padding=0.01).apply(apply(t, pts))
    np.testing.assert_array_equal(keep_t, keep)


# --------------------------------------------------------------------------- bad inputs


def _pts() -> np.ndarray:
    return np.random.default_rng(0).random((50, 3))


def _nan_pts() -> np.ndarray:
    p = _pts()
    p[3, 1] = np.nan
    return p


_EMPTY = np.empty((0, 3))
_O = np.zeros(3)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: filters.crop_box(_nan_pts(), _O, [1, 1, 1]), r"crop_box: point 3 .*non-finite"),
        (lambda: filters.voxel_downsample(_nan_pts(), 0.1), r"voxel_downsample: point 3"),
        (lambda: filters.statistical_outlier_removal(_nan_pts()), r"outlier_removal: point 3"),
        (lambda: filters.shadow_filter(_nan_pts(), _O), r"shadow_filter: point 3"),
        (lambda: filters.crop_box(_EMPTY, _O, [1, 1, 1]), r"crop_box: the cloud is empty"),
        (lambda: filters.voxel_downsample(_EMPTY, 0.1), r"the cloud is empty"),
        (lambda: filters.statistical_outlier_removal(_EMPTY), r"the cloud is empty"),
        (lambda: filters.shadow_filter(_EMPTY, _O), r"the cloud is empty"),
        (lambda: filters.voxel_downsample(_pts(), 0.0), r"voxel_size must be finite and > 0"),
        (lambda: filters.voxel_downsample(_pts(), np.nan), r"voxel_size"),
        (lambda: filters.voxel_downsample(_pts(), 0.1, merge="sum"), r"merge must be"),
        (lambda: filters.statistical_outlier_removal(_pts(), 0), r"k must be >= 1"),
        (lambda: filters.statistical_outlier_removal(_pts(), 50), r"k must be in 1\.\.50"),
        (lambda: filters.statistical_outlier_removal(_pts(), 5, np.inf), r"std_ratio"),
        (lambda: filters.shadow_filter(_pts(), _O, k=0), r"k must be >= 1"),
        (lambda: filters.shadow_filter(_pts(), _O, window=0), r"window must be >= 1"),
        (lambda: filters.shadow_filter(_pts(), _O, min_angle_deg=90.0), r"min_angle"),
        (lambda: filters.shadow_filter(_pts(), [np.nan, 0, 0]), r"origin"),
        (lambda: filters.crop_box(_pts(), [0, 0.5, 0], [1, 0.4, 1]), r"min corner is above max"),
        (lambda: filters.crop_box(_pts(), _O, [1, np.inf, 1]), r"max corner .* not finite"),
        (
            lambda: filters.crop_box(_pts(), _O, [1, 1, 1], pose=np.diag([2.0, 1, 1, 1])),
            r"pose.*not a rotation",
        ),
        (
            lambda: filters.shadow_filter(_pts(), _O, pixels=np.arange(50)),
            r"give both pixels and grid_shape",
        ),
        (
            lambda: filters.shadow_filter(_pts(), _O, grid_shape=(5, 10)),
            r"give both pixels and grid_shape",
        ),
        (
            lambda: filters.shadow_filter(_pts(), _O, pixels=np.arange(50) + 1, grid_shape=(5, 10)),
            r"pixels\[49\] = 50 is outside",
        ),
        (
            lambda: filters.shadow_filter(_pts(), _O, pixels=np.zeros(50), grid_shape=(5, 10)),
            r"pixel 0 is given to points 0 and 1",
        ),
        (
            lambda: filters.SelfFilter([cp.Mesh.cuboid(1, 1, 1)], padding=-0.01),
            r"padding must be finite and >= 0",
        ),
        (lambda: filters.SelfFilter([np.eye(4)]), r"links\[0\] must be a Mesh"),
        (lambda: filters.SelfFilter([("box", np.eye(4))]), r"links\[0\].*must be a Mesh"),
        (lambda: filters.SelfFilter([]), r"no link given"),
        (
            lambda: filters.SelfFilter([cp.Mesh.cuboid(1, 1, 1)]).set_poses(
                np.tile(np.eye(4), (2, 1, 1))
            ),
            r"set_poses: poses \(one per link\)",
        ),
    ],
)
def test_bad_inputs_raise_invalid_input_naming_the_parameter(
    call: Callable[[], object], match: str
) -> None:
    with pytest.raises(cp.InvalidInputError, match=match):
        call()
