"""The paper's Kinect experiment on a real depth frame: a robot gripper near a scanned shelf.

Data (fetched into the cache by :mod:`cloudprox.datasets`, never committed):
the one real Kinect v1 frame that Debian's ``mrpt-common`` ships (273,225 points of
a bookshelf with objects in front of a wall, 1.6 m to 2.6 m away) and the Franka
Emika Panda hand with its two fingers (``dm-robotics-panda`` on PyPI), opened 4 cm
per finger.

**Approximate ground truth**, as in the paper: the surface reconstructed from the
*full* frame (screened Poisson, :mod:`cloudprox.reproduce.reconstruct`), checked
exactly against the gripper's own mesh. It is a reconstruction, not the real
shelf; it is the best reference a single scan allows, and it is approximate.

The reconstruct-then-collide baseline checks the gripper's own mesh (a robot
knows its shape) against the Poisson surface of the cloud the methods see: the
reference's method on fewer points, so its errors partly line up with the
reference's and its scores are favourable.

**What the methods see**: a quarter-resolution cloud, every 4th pixel in both
directions (as a planner would use, 17k points), with per-point Kinect noise
covariances. The two "draws" of the flip rate are the two disjoint pixel grids
offset by two pixels: real, independent measurements of the same surfaces.

Kinect v1 noise (Nguyen, Izadi and Lovell, "Modeling Kinect sensor noise for
improved 3D reconstruction and tracking", 3DIMPVT 2012): axial standard deviation
``sigma_z(z) = 0.0012 + 0.0019 (z - 0.4)^2`` metres at depth ``z`` and lateral
``sigma_L = 0.8 px * z / f`` (surfaces seen at less than 60 degrees); the covariance
is ``sigma_L^2 (I - r r^T) + (sigma_z |p| / z)^2 r r^T`` with ``r`` the unit viewing
ray (the depth error stretched along the ray).

**Poses**: a random scan point, a uniformly random gripper orientation, the gripper's
centre moving along the viewing ray through that point (away from the camera, as
an arm reaching into the shelf) to a target signed distance in ``[-3, 10]`` sigma
(20% far: ``[10, 20]`` sigma; 10% deep: ``[-8, -3]`` sigma), sigma the Kinect's
axial standard deviation at that point's depth combined with the gripper's. The
gripper is cast along the ray to the target gap
(:func:`cloudprox.exact_time_of_impact_many`: exact triangle geometry, to about
1e-7 of the travel); past the first contact (a surface has no depth) the signed
distance is minus the travel beyond that contact. Distances are reported in
units of each pose's sigma.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial import ConvexHull

from cloudprox._native import (
    DepthCamera,
    ExactShape,
    Mesh,
    PointCloud,
    exact_intersects_many,
    exact_time_of_impact_many,
)
from cloudprox.datasets import (
    DepthFrame,
    load_kinect_frame,
    panda_gripper,
    panda_gripper_parts,
)
from cloudprox.pose import random_rotations
from cloudprox.reproduce import methods as m
from cloudprox.reproduce.metrics import Metrics, compute_metrics
from cloudprox.reproduce.poses import draw_target_units
from cloudprox.reproduce.reconstruct import available as reconstruction_available
from cloudprox.reproduce.reconstruct import reconstruct, reconstruct_many, surface_shape

__all__ = [
    "GRIPPER_SIGMA",
    "ScanPoses",
    "ScanResult",
    "convex_hull",
    "kinect_axial_sigma",
    "kinect_camera",
    "kinect_covariances",
    "run_scan",
    "sample_scan_poses",
]

FloatArray = npt.NDArray[np.float64]

#: Pixel stride of the clouds the methods see.
STRIDE = 4
#: Gripper: standard deviation of its pose (calibration, metres) and its sampling spacing.
GRIPPER_SIGMA, GRIPPER_SPACING = 0.001, 0.005
#: Approach: reach (metres) of the hulls' travel, and of the gripper's beyond it.
_REACH, _GRIPPER_REACH = 0.8, 0.2
#: How far before the anchor the gripper's centre starts (about its size, metres).
_START = 0.2
#: Rounds of fresh starts for the targets not yet reached.
_ROUNDS = 200


def kinect_camera(focal: float = 580.0) -> DepthCamera:
    """Return the Kinect v1 noise model of Nguyen et al. (2012) with this focal length (px).

    ``sigma_z = 0.0012 + 0.0019 (z - 0.4)^2`` along the optical axis (stretched by
    ``|p| / z`` along the viewing ray), 0.8 px laterally: the core's
    :meth:`cloudprox.DepthCamera.nguyen_2012` with the frame's own focal length.
    """
    base = DepthCamera.nguyen_2012()
    return DepthCamera(
        axial_offset=base.axial_offset,
        axial_quadratic=base.axial_quadratic,
        axial_depth0=base.axial_depth0,
        focal_px=focal,
        sigma_px=base.sigma_px,
    )


def kinect_axial_sigma(depth: FloatArray) -> FloatArray:
    """Kinect v1 axial standard deviation (metres) at ``depth`` (Nguyen et al. 2012)."""
    z = np.asarray(depth, dtype=float)
    return np.asarray(kinect_camera().sigma_axial(z.ravel())).reshape(z.shape)


def kinect_covariances(points: FloatArray, focal: float) -> FloatArray:
    """Kinect v1 sensor covariances ``(n, 3, 3)`` of points in the optical frame (sensor at 0)."""
    return np.asarray(kinect_camera(focal).covariances(points, sensor_pose=np.eye(4)))


def convex_hull(mesh: Mesh) -> Mesh:
    """Return the convex hull of ``mesh``'s vertices, faces oriented outwards."""
    hull = ConvexHull(np.asarray(mesh.vertices))
    used, f = np.unique(hull.simplices, return_inverse=True)
    v = hull.points[used]
    f = f.reshape(-1, 3)
    tri = v[f]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    inward = np.einsum("ij,ij->i", normal, tri[:, 0] - v.mean(axis=0)) < 0.0
    f[inward] = f[inward][:, ::-1]
    return Mesh(v, f)


@dataclass(frozen=True)
class ScanPoses:
    """Gripper poses near the scan, with their approximate ground truth.

    Attributes
    ----------
    poses : ndarray, shape (m, 4, 4)
        Gripper poses in the camera's optical frame.
    signed_distance : ndarray, shape (m,)
        Signed distance to the reference surface (metres; negative: travel past contact).
    sigma : ndarray, shape (m,)
        Each pose's noise unit (metres).
    """

    poses: FloatArray
    signed_distance: FloatArray
    sigma: FloatArray


def sample_scan_poses(
    gripper: ExactShape,
    bound: ExactShape,
    reference: ExactShape,
    anchors: FloatArray,
    anchor_sigma: FloatArray,
    centre: FloatArray,
    n: int,
    rng: np.random.Generator,
) -> ScanPoses:
    """Draw ``n`` gripper poses at target signed distances from the reference surface.

    Parameters
    ----------
    gripper, reference : ExactShape
        The gripper (own frame) and the reference surface (camera frame).
    bound : ExactShape
        Convex parts enclosing the gripper (own frame): their distance bounds the
        gripper's from below.
    anchors : ndarray, shape (k, 3)
        Scan points to approach (along their viewing rays).
    anchor_sigma : ndarray, shape (k,)
        Noise unit at each anchor (metres).
    centre : ndarray, shape (3,)
        The gripper's centre in its own frame (put on the viewing ray).
    n : int
        Number of poses.
    rng : numpy.random.Generator
        Source of randomness.
    """
    unit, _ = draw_target_units(n, rng, 20.0)
    poses = np.empty((n, 4, 4))
    signed = np.empty(n)
    sigmas = np.empty(n)
    pending = np.arange(n)
    for _ in range(_ROUNDS):
        if len(pending) == 0:
            break
        k = len(pending)
        pick = rng.integers(0, len(anchors), k)
        a, s = anchors[pick], anchor_sigma[pick]
        target = unit[pending] * s
        ray = a / np.linalg.norm(a, axis=1, keepdims=True)
        rot = random_rotations(k, seed=int(rng.integers(2**63)))[:, :3, :3]
        start = np.zeros((k, 4, 4))
        start[:, :3, :3] = rot
        start[:, 3, 3] = 1.0
        start[:, :3, 3] = a - _START * ray - np.einsum("kij,j->ki", rot, centre)

        def at(
            t: FloatArray, idx: npt.NDArray[np.intp], st: FloatArray = start, ry: FloatArray = ray
        ) -> FloatArray:
            out = st[idx].copy()
            out[:, :3, 3] += ry[idx] * t[:, None]
            return out

        # A gap target is reached by the gripper itself; a depth target from its
        # first contact (a surface has no depth: the travel past it).
        gap = np.maximum(target, 0.0)
        # 1. The convex hulls' travel to the target: cheap, and no more than the
        # gripper's (it lies inside them). Starts already there are redrawn.
        hull = exact_time_of_impact_many(
            bound, reference, start, ray, target=gap, max_travel=_REACH
        )
        near = np.flatnonzero(np.isfinite(hull) & (hull > 0.0))
        # 2. The gripper's own travel from there (shape casting of its triangles).
        rest = exact_time_of_impact_many(
            gripper,
            reference,
            at(hull[near], near),
            ray[near],
            target=gap[near],
            max_travel=_GRIPPER_REACH,
        )
        reached = np.isfinite(rest)
        ok = near[reached]
        hit = hull[ok] + rest[reached]
        # 3. Past contact, |target| further (the gripper must still cross the
        # surface there); a gap target is where the cast stopped (the gripper
        # must be clear). The gap is the cast's: parry's distance along the
        # move, to about 1e-7 of the travel (exact_proximity there agrees,
        # tests/test_time_of_impact.py), at a fraction of its cost.
        tg = target[ok]
        final = at(np.where(tg < 0.0, hit - tg, hit), ok)
        crossing = exact_intersects_many(gripper, reference, final)
        keep = np.where(tg < 0.0, crossing, ~crossing)
        signed_ok = tg
        placed = ok[keep]
        poses[pending[placed]] = final[keep]
        signed[pending[placed]] = signed_ok[keep]
        sigmas[pending[placed]] = s[placed]
        pending = np.delete(pending, placed)
    if len(pending):
        raise RuntimeError(
            f"could not place {len(pending)} of {n} gripper poses near the scan in {_ROUNDS} "
            "rounds (no contact within reach, or the pose past or before it not as required); "
            f"targets {np.round(target[pending], 4).tolist()} m"
        )
    return ScanPoses(poses, signed, sigmas)


@dataclass
class ScanResult:
    """What the scan experiment measured.

    Attributes
    ----------
    metrics : dict
        Metrics per method (distances in units of each pose's sigma).
    poses : ScanPoses
    scores : dict
        Per method, scores of shape ``(draws, m)``.
    states : dict
        Per method, states of shape ``(draws, m)``.
    seconds : dict
        Per method, seconds per query of shape ``(draws, m)``.
    facts : dict
        Numbers describing the setup (points, spacing, sigma range, reference size).
    cloud, gripper_points : ndarray
        The first draw's scan cloud and the gripper's points (own frame), for pictures.
    """

    metrics: dict[str, Metrics]
    poses: ScanPoses
    scores: dict[str, FloatArray]
    states: dict[str, npt.NDArray[np.str_]]
    seconds: dict[str, FloatArray]
    facts: dict[str, float]
    cloud: FloatArray
    gripper_points: FloatArray


def _grid(frame: DepthFrame, offset: int) -> npt.NDArray[np.bool_]:
    u, v = frame.pixels[:, 0], frame.pixels[:, 1]
    return (u % STRIDE == offset) & (v % STRIDE == offset)


def run_scan(
    n_poses: int,
    seed: int,
    variants: tuple[tuple[str, str, str], ...],
    tick: Callable[[str, int], None],
    many: Callable[..., Any] | None = None,
    pool: Executor | None = None,
    workers: int = 1,
) -> ScanResult:
    """Run every method on the Kinect frame with ``n_poses`` gripper poses.

    ``tick(description, advance)`` reports progress (:data:`SCAN_STEPS` steps);
    ``many`` replaces ``cloudprox.collide_many`` in cloudprox's queries;
    ``pool`` (of ``workers`` processes) runs the point baselines
    (:func:`cloudprox.reproduce.methods.point_baseline_answers`).
    """
    rng = np.random.default_rng(seed)
    frame = load_kinect_frame()
    full = np.asarray(frame.points)
    full_sigma = kinect_axial_sigma(full[:, 2])
    focal = 0.5 * (frame.fx + frame.fy)
    h_full = m.sampling_spacing(full)
    ref_mesh = reconstruct(full, h_full, float(np.median(full_sigma)), frame.origin)
    reference = surface_shape(ref_mesh)
    gripper_mesh = panda_gripper()
    gripper = ExactShape([gripper_mesh], solid=False)
    tick("kinect: reference surface", 1)
    lo, hi = gripper_mesh.bounds()
    centre = 0.5 * (np.asarray(lo) + np.asarray(hi))
    anchor_sigma = np.sqrt(full_sigma**2 + GRIPPER_SIGMA**2)
    bound = ExactShape([convex_hull(x) for x in panda_gripper_parts()])
    q = sample_scan_poses(gripper, bound, reference, full, anchor_sigma, centre, n_poses, rng)
    tick("kinect: poses", 1)
    density = 1.0 / GRIPPER_SPACING**2
    g_pts, _, _ = gripper_mesh.sample(density=density, seed=seed)
    g_pts = np.asarray(g_pts)
    g_cov = np.broadcast_to(GRIPPER_SIGMA**2 * np.eye(3), (len(g_pts), 3, 3)).copy()
    draws = []
    for offset in (0, STRIDE // 2):
        pts = full[_grid(frame, offset)]
        # The core's Kinect model gives the covariances and how much of the
        # noise the points of one surface share (the depth quantization).
        seen = PointCloud(pts, sensor=kinect_camera(focal), sensor_pose=np.eye(4))
        draws.append(
            m.Draw(
                g_pts,
                g_cov,
                pts,
                np.asarray(seen.sensor_covariances),
                room_noise_correlation=seen.noise_correlation,
            )
        )
    spacing = m.sampling_spacing(draws[0].room_points)
    answers = m.variant_answers(draws, q.poses, variants, many, tick, "kinect")
    answers.update(m.point_baseline_answers(draws, q.poses, spacing, pool, workers))
    if reconstruction_available():
        # Each draw's scan on its own (the gripper is its own mesh), both at once.
        sig = [float(np.median(kinect_axial_sigma(d.room_points[:, 2]))) for d in draws]
        scans = reconstruct_many(
            [(d.room_points, spacing, s, frame.origin) for d, s in zip(draws, sig, strict=True)],
            pool,
        )
        answers["reconstruct"] = [
            m.reconstruct_answer(d, q.poses, spacing, s, shapes=(gripper, surface_shape(mesh)))
            for d, s, mesh in zip(draws, sig, scans, strict=True)
        ]
    tick("kinect: baselines", 1)
    unit_distance = q.signed_distance / q.sigma
    out = ScanResult({}, q, {}, {}, {}, {}, draws[0].room_points, g_pts)
    for name, ans in answers.items():
        sc = np.stack([x.score for x in ans])
        st = np.stack([x.state for x in ans])
        sec = np.stack([x.seconds for x in ans])
        out.scores[name], out.states[name], out.seconds[name] = sc, st, sec
        out.metrics[name] = compute_metrics(sc, st, sec, unit_distance, 1.0)
    out.facts = {
        "frame_points": float(len(full)),
        "cloud_points": float(len(draws[0].room_points)),
        "gripper_points": float(len(g_pts)),
        "cloud_spacing_m": spacing,
        "reference_triangles": float(len(ref_mesh.faces)),
        "sigma_min_m": float(q.sigma.min()),
        "sigma_max_m": float(q.sigma.max()),
    }
    return out


#: Progress steps of :func:`run_scan` besides one per cloudprox variant.
SCAN_STEPS = 3
