"""From files to query sides: parse poses, sensors and filter steps; load a side.

This is the glue of ``cloudprox collide A B``: a side is a mesh file (STL, OBJ,
OFF, or a PLY with faces) or a point-cloud file (PLY, PCD, XYZ/CSV, NPY, LAS/LAZ).
A cloud side goes through

1. reading (:func:`cloudprox.io.read_point_cloud`; non-finite points skipped and
   counted);
2. the sensor covariances of every point (a sensor model seen from the file's
   ``VIEWPOINT`` or the given origin / sensor pose, an isotropic sigma, or the
   covariances stored in the file);
3. the filter steps, in order (each one subsets the points, their covariances
   and pixels; voxel downsampling merges covariances);
4. a :class:`cloudprox.PointCloud` with the discretization part added.

Steps 2-4 run in the Rust core (``cloudprox::scan::ScanPipeline``, here
:func:`cloudprox._native.scan_to_cloud`); this module parses the command line's
poses, sensors and filter steps into its arguments.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cloudprox import filters, io
from cloudprox._native import (
    DepthCamera,
    Lidar,
    Mesh,
    PointCloud,
    ScanStep,
    StereoCamera,
    _read_mesh_counted,
    scan_to_cloud,
)

__all__ = [
    "MESH_EXTENSIONS",
    "FilterStep",
    "LoadedSide",
    "PipelineError",
    "SensorSpec",
    "is_mesh_file",
    "load_side",
    "parse_filter",
    "parse_pose",
    "parse_vector",
    "read_mesh_file",
    "scan_step",
    "sensor_spec",
]

FloatArray = npt.NDArray[np.float64]

#: Extensions always read as meshes (``.ply`` is a mesh when it has faces).
MESH_EXTENSIONS = frozenset({".stl", ".obj", ".off"})

SENSORS = ("isotropic", "depth-camera", "stereo", "lidar")
FILTERS = ("crop", "voxel", "outliers", "shadow", "self")


class PipelineError(ValueError):
    """A user error in a pose, a sensor or a filter step (the message says which)."""


def parse_pose(text: str, what: str) -> FloatArray:
    """Parse a ``(4, 4)`` pose (see :func:`cloudprox.io.read_pose`)."""
    return io.read_pose(text, what)


def parse_vector(text: str, n: int, what: str) -> FloatArray:
    """Parse ``n`` numbers separated by commas or spaces."""
    return io.parse_numbers(text, n, what)


@dataclass(frozen=True)
class SensorSpec:
    """How noisy a cloud side is: a sensor model and where it sits, or a sigma."""

    kind: str = "isotropic"
    sigma: float | None = None
    model: DepthCamera | StereoCamera | Lidar | None = None
    origin: FloatArray | None = None
    sensor_pose: FloatArray | None = None

    def noise_arguments(self, scan: io.CloudFile) -> dict[str, Any]:
        """Return the noise arguments of :func:`cloudprox._native.scan_to_cloud` for ``scan``.

        ``sigma``; or ``sensor`` with ``origin`` or ``sensor_pose`` (the one given,
        else the file's ``VIEWPOINT``); or nothing: the covariances stored in the
        file. Raises :class:`PipelineError` when the noise is not known.
        """
        if self.model is None:
            if self.sigma is None:
                if scan.covariances is None:
                    raise PipelineError(
                        f"{scan.path}: no noise given and the file stores no covariances: "
                        "give --sigma or --sensor"
                    )
                return self._placement()
            return {"sigma": self.sigma} | self._placement()
        if self.origin is None and self._pose(scan) is None:
            raise PipelineError(
                f"{scan.path} records no sensor viewpoint: give --origin or --sensor-pose "
                f"for --sensor {self.kind}"
            )
        return {"sensor": self.model} | self._placement()

    def _placement(self) -> dict[str, Any]:
        """Where the sensor sits, as given (the core falls back to the file's ``VIEWPOINT``)."""
        if self.origin is not None:
            return {"origin": self.origin}
        if self.sensor_pose is not None:
            return {"sensor_pose": self.sensor_pose}
        return {}

    def sensor_origin(self, scan: io.CloudFile) -> FloatArray | None:
        """Return where the sensor sits (for the shadow filter), if known."""
        if self.origin is not None:
            return self.origin
        pose = self._pose(scan)
        return None if pose is None else np.asarray(pose)[:3, 3]

    def _pose(self, scan: io.CloudFile) -> FloatArray | None:
        """Return the sensor pose given, else the file's ``VIEWPOINT``, else ``None``."""
        return self.sensor_pose if self.sensor_pose is not None else scan.sensor_pose


@dataclass(frozen=True)
class FilterStep:
    """One ``--filter`` step: its name and arguments."""

    name: str
    args: tuple[str, ...] = ()

    def describe(self) -> str:
        """Return the step as written on the command line."""
        return self.name + "".join(f":{a}" for a in self.args)


def parse_filter(text: str) -> FilterStep:
    """Parse a filter step ``NAME[:ARG[:ARG...]]``.

    ``crop:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX``, ``voxel:SIZE``, ``outliers[:K[:STD]]``,
    ``shadow[:MIN_ANGLE_DEG]``, ``self:MESH_FILE[:PADDING[:POSE]]``.
    """
    name, *args = text.split(":", 2) if text.startswith("self:") else text.split(":")
    if name not in FILTERS:
        raise PipelineError(f"unknown filter {name!r} in {text!r}; known: {', '.join(FILTERS)}")
    step = FilterStep(name, tuple(args))
    if name == "crop" and len(args) != 1:
        raise PipelineError(f"crop needs 6 numbers: crop:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX ({text!r})")
    if name == "voxel" and len(args) != 1:
        raise PipelineError(f"voxel needs a size in metres: voxel:SIZE ({text!r})")
    if name == "outliers" and len(args) > 2:
        raise PipelineError(f"outliers takes at most K and STD: outliers:K:STD ({text!r})")
    if name == "shadow" and len(args) > 1:
        raise PipelineError(f"shadow takes at most an angle: shadow:MIN_ANGLE_DEG ({text!r})")
    if name == "self" and not args:
        raise PipelineError(f"self needs a mesh file: self:MESH[:PADDING[:POSE]] ({text!r})")
    if name == "self" and len(args) == 2 and ":" in args[1]:
        padding, pose = args[1].split(":", 1)
        step = FilterStep(name, (args[0], padding, pose))
    return step


def _float(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise PipelineError(f"{what}: expected a number, got {text!r}") from None
    return value


def _int(text: str, what: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise PipelineError(f"{what}: expected an integer, got {text!r}") from None


@dataclass
class LoadedSide:
    """A query side read from a file: a cloud or a mesh, and what happened to it."""

    path: str
    kind: str  # "cloud" or "mesh"
    cloud: PointCloud | None = None
    mesh: Mesh | None = None
    read_points: int = 0
    dropped_faces: int = 0
    skipped: int = 0
    filters: list[dict[str, Any]] = field(default_factory=list)
    fields: list[str] = field(default_factory=list)
    #: The sensor's origin in the cloud's frame (given, or the file's
    #: ``VIEWPOINT``), or ``None`` where it is unknown.
    origin: FloatArray | None = None

    @property
    def obj(self) -> PointCloud | Mesh:
        """What goes into ``collide``."""
        obj = self.cloud if self.cloud is not None else self.mesh
        assert obj is not None
        return obj

    def summary(self) -> dict[str, Any]:
        """Plain-JSON description."""
        out: dict[str, Any] = {"path": self.path, "kind": self.kind}
        if self.mesh is not None:
            out |= {
                "vertices": len(self.mesh.vertices),
                "faces": len(self.mesh.faces),
                "dropped_faces": self.dropped_faces,
            }
        if self.cloud is not None:
            out |= {
                "points_read": self.read_points,
                "skipped_non_finite": self.skipped,
                "filters": self.filters,
                "points": len(self.cloud),
                "fields": self.fields,
            }
        return out


def is_mesh_file(path: str) -> bool:
    """Whether ``path`` is read as a mesh: STL, OBJ, OFF, or a PLY with faces."""
    suffix = Path(path).suffix.lower()
    if suffix in MESH_EXTENSIONS:
        return True
    if suffix != ".ply":
        return False
    with open(path, "rb") as f:
        head = f.read(4096)
    return b"\nelement face " in head.split(b"end_header", 1)[0]


def read_mesh_file(path: str) -> tuple[Mesh, int]:
    """Read a mesh file; also return the number of degenerate faces dropped (no warning)."""
    return _read_mesh_counted(path)


def scan_step(step: FilterStep) -> ScanStep:
    """Parse the arguments of a ``--filter`` step into the core's :class:`ScanStep`.

    Arguments left out are ``None``: the core's defaults. ``self`` reads its mesh.
    """
    if step.name == "crop":
        box = parse_vector(step.args[0], 6, "crop")
        return ScanStep.crop(box[:3], box[3:])
    if step.name == "voxel":
        return ScanStep.voxel(_float(step.args[0], "voxel size"))
    if step.name == "outliers":
        k = _int(step.args[0], "outliers K") if step.args else None
        std = _float(step.args[1], "outliers STD") if len(step.args) > 1 else None
        return ScanStep.outliers(k, std)
    if step.name == "shadow":
        angle = _float(step.args[0], "shadow angle") if step.args else None
        return ScanStep.shadow(angle)
    mesh, _ = read_mesh_file(step.args[0])
    padding = _float(step.args[1], "self padding") if len(step.args) > 1 else None
    pose = parse_pose(step.args[2], "self pose") if len(step.args) > 2 else np.eye(4)
    return ScanStep.self_filter(filters.SelfFilter([(mesh, pose)], padding))


def load_side(
    path: str,
    sensor: SensorSpec,
    steps: list[FilterStep],
    *,
    sigma_override: float | None = None,
) -> LoadedSide:
    """Read one side of a query from ``path`` (see the module docs)."""
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    if os.path.isdir(path):
        raise PipelineError(f"{path} is a directory, expected a point-cloud or mesh file")
    if is_mesh_file(path):
        mesh, dropped = read_mesh_file(path)
        return LoadedSide(path, "mesh", mesh=mesh, dropped_faces=dropped)
    scan = io.read_point_cloud(path)
    side = LoadedSide(path, "cloud", read_points=len(scan) + scan.skipped, skipped=scan.skipped)
    side.fields = scan.fields
    if len(scan) == 0:
        raise PipelineError(f"{path}: no point with finite coordinates ({scan.skipped} skipped)")
    spec = sensor if sigma_override is None else SensorSpec(sigma=sigma_override)
    noise = spec.noise_arguments(scan)
    native_steps = [scan_step(step) for step in steps]
    if any(step.name == "shadow" for step in steps) and spec.sensor_origin(scan) is None:
        raise PipelineError(
            f"shadow filter on {scan.path}: the sensor origin is unknown (the file has no "
            "VIEWPOINT): give --origin or --sensor-pose"
        )
    result = scan_to_cloud(scan, native_steps, **noise)
    for step, (_, before, after) in zip(steps, result.steps, strict=False):
        side.filters.append({"filter": step.describe(), "before": before, "after": after})
    if result.emptied_by is not None:
        emptied = steps[result.emptied_by].describe()
        raise PipelineError(f"{path}: filter {emptied} removed every point")
    side.cloud = result.cloud
    side.origin = spec.sensor_origin(scan)
    return side


def sensor_spec(
    kind: str | None,
    *,
    sigma: float | None,
    params: dict[str, float | None],
    preset: str | None,
    origin: str | None,
    sensor_pose: str | None,
) -> SensorSpec:
    """Build the noise of the cloud sides from the CLI's options."""
    o = None if origin is None else parse_vector(origin, 3, "--origin")
    sp = None if sensor_pose is None else parse_pose(sensor_pose, "--sensor-pose")
    if kind is None:
        kind = "isotropic"
    if kind == "isotropic":
        if preset is not None or any(v is not None for v in params.values()):
            raise PipelineError("sensor parameters need --sensor depth-camera, stereo or lidar")
        return SensorSpec(kind, sigma=sigma, origin=o, sensor_pose=sp)
    if sigma is not None:
        raise PipelineError(f"--sigma is for --sensor isotropic, not {kind}")
    given = {k: v for k, v in params.items() if v is not None}
    allowed: dict[str, tuple[str, ...]] = {
        "depth-camera": (
            "axial_offset",
            "axial_quadratic",
            "axial_depth0",
            "focal_px",
            "sigma_px",
        ),
        "stereo": ("focal_px", "baseline", "sigma_disparity_px", "sigma_px"),
        "lidar": ("sigma_range", "sigma_angle"),
    }
    extra = sorted(set(given) - set(allowed[kind]))
    if extra:
        flags = ", ".join("--" + e.replace("_", "-") for e in extra)
        raise PipelineError(f"{flags} do not apply to --sensor {kind}")
    model: DepthCamera | StereoCamera | Lidar
    if kind == "depth-camera":
        base = DepthCamera.nguyen_2012() if preset == "nguyen-2012" else DepthCamera()
        values = {
            "axial_offset": base.axial_offset,
            "axial_quadratic": base.axial_quadratic,
            "axial_depth0": base.axial_depth0,
            "focal_px": base.focal_px,
            "sigma_px": base.sigma_px,
        } | given
        model = DepthCamera(**values)
    elif preset is not None:
        raise PipelineError("--preset applies to --sensor depth-camera only")
    elif kind == "stereo":
        model = StereoCamera(**given)
    else:
        model = Lidar(**given)
    return SensorSpec(kind, model=model, origin=o, sensor_pose=sp)
