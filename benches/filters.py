"""Benchmark of cloudprox's sensor-cloud filters against Open3D's, in one run, on one image.

Usage::

    python3 benches/filters.py [--points N] [--repeat R] [--json]

The scene is one synthetic organized depth image (default 1280 x 960, about 1.2 M points): a
pinhole camera at the origin looking along +z (x right, y down) sees a wall at 3 m, a table
(top 0.6 m below the camera, 1 to 2.2 m away), three boxes on it and a two-link arm above it.
Depth noise is ``1 mm * z`` along the ray (a time-of-flight camera: independent noise well
above the lateral pixel spacing would make the shadow filter's angle rule see veils
everywhere); pixels at depth discontinuities (3 x 3 depth range over 5 cm) are mixed pixels
with a depth drawn between the near and far sides (the veil); 1% of pixels have no return (dropped).

Each filter runs once untimed (warm-up), then ``R`` timed runs; the table reports the median.
Both libraries use every core (cloudprox: rayon; Open3D: OpenMP where it parallelises).
cloudprox takes the NumPy array at every call (its conversion is in its time); Open3D works on
an ``o3d.geometry.PointCloud`` built once, outside the timed runs (that conversion is timed on
its own row). Equivalent calls:

========================  ===============================  =====================================
filter                    cloudprox                        Open3D
========================  ===============================  =====================================
crop box                  ``crop_box(p, lo, hi)``          ``pcd.crop(AxisAlignedBoundingBox)``
voxel 1 cm                ``voxel_downsample(p, 0.01)``    ``pcd.voxel_down_sample(0.01)``
SOR k = 20, 2 sigma       ``statistical_outlier_removal``  ``remove_statistical_outlier(21, 2)``
shadow (organized)        ``shadow_filter(pixels=...)``    none
shadow (unorganized)      ``shadow_filter()``, k = 8       none
self filter               ``SelfFilter.apply``             none
========================  ===============================  =====================================

Open3D's ``nb_neighbors`` counts the point itself, so its 21 is cloudprox's (and PCL's) 20.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

import cloudprox as cp
from cloudprox import filters

#: Default number of points: a 1280 x 960 image.
DEFAULT_POINTS = 1280 * 960
#: Voxel size of the voxel row (metres).
VOXEL = 0.01
#: SOR neighbours (cloudprox / PCL convention) and threshold.
SOR_K, SOR_RATIO = 20, 2.0
#: Crop box around the table and what is on it (camera frame, metres).
CROP_LO, CROP_HI = np.array([-0.9, -0.2, 0.9]), np.array([0.9, 0.7, 2.3])
#: Half extents of the arm's two links (metres).
LINKS_HALF = ((0.25, 0.04, 0.04), (0.04, 0.2, 0.04))


@dataclass(frozen=True)
class Row:
    """One filter: medians (milliseconds) and output sizes of each library."""

    filter: str
    cloudprox_ms: float | None
    open3d_ms: float | None
    cloudprox_out: int | None
    open3d_out: int | None

    @property
    def ratio(self) -> float | None:
        """Open3D median over cloudprox median."""
        if self.cloudprox_ms is None or self.open3d_ms is None or self.cloudprox_ms == 0:
            return None
        return self.open3d_ms / self.cloudprox_ms


@dataclass(frozen=True)
class Scene:
    """The synthetic depth image as an organized cloud."""

    points: np.ndarray
    pixels: np.ndarray
    grid_shape: tuple[int, int]
    veil: np.ndarray
    links: list[tuple[cp.Mesh, np.ndarray]]


def _ray_box(dirs: np.ndarray, pose: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Ray parameter of the first hit of rays from the origin on an oriented box, else inf."""
    r, t = pose[:3, :3], pose[:3, 3]
    d = dirs @ r  # directions in the box frame (R^T d, row-wise)
    o = -(r.T @ t)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (-half - o) / d, (half - o) / d
    near = np.nanmax(np.minimum(t1, t2), axis=1)
    far = np.nanmin(np.maximum(t1, t2), axis=1)
    hit = (far >= np.maximum(near, 0.0)) & (near > 0.0)
    return np.where(hit, near, np.inf)


def make_scene(n_points: int, seed: int = 0) -> Scene:
    """Render the depth image with about ``n_points`` pixels (aspect 4:3)."""
    w = max(8, round(math.sqrt(n_points * 4 / 3)))
    h = max(6, round(n_points / w))
    f = 0.78 * w  # about 65 degrees horizontal field of view
    rows, cols = np.mgrid[0:h, 0:w]
    dirs = np.stack(
        [(cols + 0.5 - w / 2) / f, (rows + 0.5 - h / 2) / f, np.ones((h, w))], -1
    ).reshape(-1, 3)  # z component 1: the ray parameter is the depth z
    depth = np.full(len(dirs), 3.0)  # the wall
    # Poses: a yaw about the camera frame's y axis (vertical), then a translation.
    table = (cp.pose.from_rpy((0.0, 0.0, 0.0), (0.0, 0.62, 1.6)), np.array([0.8, 0.02, 0.6]))
    boxes = [
        (cp.pose.from_rpy((0.0, 0.3, 0.0), (-0.4, 0.5, 1.4)), np.array([0.1, 0.1, 0.08])),
        (cp.pose.from_rpy((0.0, -0.5, 0.0), (0.1, 0.45, 1.8)), np.array([0.08, 0.15, 0.08])),
        (cp.pose.from_rpy((0.0, 0.0, 0.0), (0.5, 0.54, 1.2)), np.array([0.12, 0.06, 0.1])),
    ]
    link_poses = [
        cp.pose.from_rpy((0.0, 0.4, 0.0), (0.1, 0.1, 1.5)),
        cp.pose.from_rpy((0.0, 0.4, 0.0), (0.33, 0.26, 1.4)),
    ]
    links = [
        (cp.Mesh.cuboid(*half), pose) for half, pose in zip(LINKS_HALF, link_poses, strict=False)
    ]
    solids = [
        table,
        *boxes,
        *((p, np.array(hx)) for hx, p in zip(LINKS_HALF, link_poses, strict=False)),
    ]
    for pose, half in solids:
        depth = np.minimum(depth, _ray_box(dirs, pose, half))
    rng = np.random.default_rng(seed)
    image = depth.reshape(h, w)
    lo, hi = image.copy(), image.copy()
    padded = np.pad(image, 1, mode="edge")
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            shifted = padded[dr : dr + h, dc : dc + w]
            lo, hi = np.minimum(lo, shifted), np.maximum(hi, shifted)
    veil = ((hi - lo) > 0.05).ravel() & (rng.random(h * w) < 0.7)
    mixed = lo.ravel() + rng.uniform(0.1, 0.9, h * w) * (hi - lo).ravel()
    depth = np.where(veil, mixed, depth)
    depth = depth + rng.normal(0.0, 1.0, len(depth)) * 0.001 * depth
    valid = rng.random(h * w) >= 0.01
    pixels = np.flatnonzero(valid)
    points = np.ascontiguousarray(dirs[valid] * depth[valid, None])
    return Scene(points, pixels.astype(np.int64), (h, w), veil[valid], links)


def _median_ms(fn: Callable[[], Any], repeat: int, step: Callable[[], None]) -> tuple[float, Any]:
    out = fn()  # warm-up, untimed
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(1e3 * (time.perf_counter() - t))
        step()
    return statistics.median(times), out


def run(
    n_points: int, repeat: int, on_step: Callable[[str], None] | None = None
) -> tuple[list[Row], dict[str, Any]]:
    """Build the scene and time every filter; return the rows and the scene/machine facts."""
    import open3d as o3d  # type: ignore[import-untyped]

    scene = make_scene(n_points)
    p = scene.points
    origin = np.zeros(3)
    rows: list[Row] = []

    def stepper(desc: str) -> Callable[[], None]:
        return lambda: on_step(desc) if on_step is not None else None

    def both(
        name: str,
        ours: Callable[[], Any],
        theirs: Callable[[], Any] | None,
        size_ours: Callable[[Any], int],
        size_theirs: Callable[[Any], int],
    ) -> tuple[Any, Any]:
        ms_c, out_c = _median_ms(ours, repeat, stepper(f"cloudprox {name}"))
        ms_o: float | None = None
        n_o: int | None = None
        out_o = None
        if theirs is not None:
            ms_o, out_o = _median_ms(theirs, repeat, stepper(f"open3d {name}"))
            n_o = size_theirs(out_o)
        rows.append(Row(name, ms_c, ms_o, size_ours(out_c), n_o))
        return out_c, out_o

    def to_o3d() -> Any:
        return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))

    ms_conv, pcd = _median_ms(to_o3d, repeat, stepper("numpy -> open3d"))
    rows.append(Row("numpy -> o3d.PointCloud", None, ms_conv, None, len(pcd.points)))
    aabb = o3d.geometry.AxisAlignedBoundingBox(CROP_LO, CROP_HI)
    both(
        "crop box",
        lambda: filters.crop_box(p, CROP_LO, CROP_HI),
        lambda: pcd.crop(aabb),
        len,
        lambda c: len(c.points),
    )
    both(
        f"voxel {VOXEL * 100:g} cm",
        lambda: filters.voxel_downsample(p, VOXEL),
        lambda: pcd.voxel_down_sample(VOXEL),
        lambda v: len(v[0]),
        lambda c: len(c.points),
    )
    sor_c, sor_o = both(
        f"SOR k={SOR_K}, {SOR_RATIO:g} std",
        lambda: filters.statistical_outlier_removal(p, SOR_K, SOR_RATIO),
        lambda: pcd.remove_statistical_outlier(SOR_K + 1, SOR_RATIO),
        len,
        lambda r: len(r[1]),
    )
    both(
        "shadow, organized",
        lambda: filters.shadow_filter(p, origin, pixels=scene.pixels, grid_shape=scene.grid_shape),
        None,
        len,
        len,
    )
    both("shadow, unorganized k=8", lambda: filters.shadow_filter(p, origin), None, len, len)
    t0 = time.perf_counter()
    self_filter = filters.SelfFilter(scene.links, padding=0.01)
    build_ms = 1e3 * (time.perf_counter() - t0)
    both("self filter (2 links)", lambda: self_filter.apply(p), None, len, len)
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            names = [ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    sor_differ = int(np.setxor1d(sor_c, np.asarray(sor_o[1])).size)
    facts = {
        "points": len(p),
        "sor_kept_sets_differ_by": sor_differ,
        "image": f"{scene.grid_shape[1]} x {scene.grid_shape[0]}",
        "veil_points": int(scene.veil.sum()),
        "repeat": repeat,
        "self_filter_build_ms": build_ms,
        "cpu_count": os.cpu_count(),
        "cpu": cpu,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "open3d": o3d.__version__,
        "cloudprox": getattr(cp, "__version__", "?"),
        "platform": platform.platform(),
    }
    return rows, facts


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print a rich table (or JSON)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=DEFAULT_POINTS, help="image pixels")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per filter")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    if args.points < 1000 or args.repeat < 1:
        parser.error("--points must be >= 1000 and --repeat >= 1")

    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn
    from rich.table import Table

    # numpy -> open3d, 3 filters x 2 libraries, 3 cloudprox-only filters.
    total = args.repeat * (1 + 3 * 2 + 3)
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        console=Console(stderr=True),
        transient=True,
    ) as progress:
        task = progress.add_task("building the scene", total=total)

        def step(desc: str) -> None:
            progress.update(task, advance=1, description=desc)

        rows, facts = run(args.points, args.repeat, on_step=step)

    if args.json:
        doc = {
            **facts,
            "rows": [{**asdict(r), "ratio_open3d_over_cloudprox": r.ratio} for r in rows],
        }
        print(json.dumps(doc, indent=2))
        return 0

    def ms(v: float | None) -> str:
        return "-" if v is None else f"{v:.1f}"

    def size(v: int | None) -> str:
        return "-" if v is None else f"{v:,}"

    table = Table(
        title=(
            f"Filters on one {facts['image']} depth image ({facts['points']:,} points, "
            f"{facts['veil_points']:,} veil), median of {args.repeat}"
        )
    )
    for col in (
        "filter",
        "cloudprox ms",
        "open3d ms",
        "open3d / cloudprox",
        "out (cp)",
        "out (o3d)",
    ):
        table.add_column(col, justify="left" if col == "filter" else "right", no_wrap=True)
    for r in rows:
        ratio = "-" if r.ratio is None else f"{r.ratio:.2f}"
        table.add_row(
            r.filter,
            ms(r.cloudprox_ms),
            ms(r.open3d_ms),
            ratio,
            size(r.cloudprox_out),
            size(r.open3d_out),
        )
    console = Console(width=max(Console().width, 110))
    console.print(table)
    console.print(
        f"machine: {facts['cpu_count']} CPUs ({facts['cpu']}), {facts['platform']}; "
        f"python {facts['python']}, numpy {facts['numpy']}, open3d {facts['open3d']}, "
        f"cloudprox {facts['cloudprox']}"
    )
    console.print(
        f"SelfFilter build (once): {facts['self_filter_build_ms']:.1f} ms. "
        "out = points kept (voxels for the voxel row). "
        f"SOR kept sets differ by {facts['sor_kept_sets_differ_by']} points."
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
