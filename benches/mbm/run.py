"""The MotionBenchMaker planning benchmark: one planner, a chance constraint and two baselines.

For each problem (its own scene, start and goal): the scene's sensor clouds
(:mod:`mbm.sensor`: the simulated Kinect and the area-sampled surfaces), then
one planner, OMPL's RRTConnect through
:func:`cloudprox.planning.plan_joint_space` (the same seed, time limit, motion
resolution and path simplification for every checker), with each checker:

* ``exact``: python-fcl, the robot's link meshes against the exact primitives
  (ground truth, no robot has it);
* ``map S (cloud)``: python-fcl, the link meshes against the cloud's occupied
  voxels of side S as boxes (a boolean collision map);
* ``cloudprox P<=p (cloud)``: :class:`cloudprox.planning.ChanceConstraint` on
  the cloud at ``max_probability=p`` (its own defaults otherwise; the motion
  resolution given).

Self-collision is ``Robot.self_collisions`` for all. Before planning, each
checker judges the start and the goal (cloudprox: the full ``collide_robot``
query's ``P`` at both, which is what is reported; the planner's own check of
both then has to agree); a checker that refuses either does not plan that
problem. Each returned path is checked against the exact scene at
``--validate-resolution`` of link travel (python-fcl). Timings: wall time of
OMPL's solve until the first solution (``planning_time``); per checker the
calls and seconds of its state and motion checks; per cloud the first
``collide_robot`` call (hierarchy, surface estimates, link samples: the build)
against the second; and a probe of ``--probe`` uniformly random configurations
per scene, each checker's single-state cost.

:func:`main` is ``benches/motionbenchmaker.py``.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import platform
import shlex
import sys
import time
import zlib
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

import cloudprox as cp
from cloudprox.planning import ChanceConstraint, plan_joint_space

from .checkers import (
    FclChecker,
    MotionBound,
    discrete_motion,
    first_collision,
    self_collision_check,
    voxel_boxes,
)
from .fetch import ROBOTS, MbmUnavailable, RobotFiles, fetch_robot
from .scene import Problem, load_problems
from .sensor import CAMERA_POSITION, SensorCloud, area_scan, camera_scan

__all__ = ["Checker", "RunRecord", "main", "markdown", "run"]

FloatArray = npt.NDArray[np.float64]


def log(message: str) -> None:
    """Progress on standard error."""
    print(message, file=sys.stderr, flush=True)


class Timed:
    """A callable's calls and seconds, counted around it."""

    def __init__(self, fn: Callable[..., bool]) -> None:
        self.fn = fn
        self.calls = 0
        self.seconds = 0.0

    def __call__(self, *args: Any) -> bool:
        """Call the wrapped function, timing it."""
        t0 = time.perf_counter()
        try:
            return self.fn(*args)
        finally:
            self.seconds += time.perf_counter() - t0
            self.calls += 1


class CountingConstraint(ChanceConstraint):
    """:class:`~cloudprox.planning.ChanceConstraint` that also counts the states its motions check.

    ``motion_valid`` makes the same ``check_motion`` call as the library's and
    adds its ``states_checked`` to :attr:`motion_states`. With ``allowed`` (an
    allowed-collision matrix's pairs) cloudprox's own self-collision check is
    off (``self_collision=False``) and :func:`mbm.checkers.self_collision_check`
    with those pairs is added: at the state, and along a motion at the same
    states a :class:`mbm.checkers.DiscreteMotion` checks (the library takes no
    allowed pairs).
    """

    motion_states: int = 0

    def __init__(
        self,
        robot: cp.Robot,
        cloud: cp.PointCloud,
        *,
        max_probability: float,
        resolution: float,
        bound: MotionBound,
        allowed: frozenset[frozenset[str]] = frozenset(),
    ) -> None:
        options: dict[str, Any] = {"resolution": resolution}
        if allowed:
            options["self_collision"] = False
        super().__init__(robot, cloud, max_probability=max_probability, **options)
        self.allowed = allowed
        self.self_free = self_collision_check(robot, allowed)
        self.self_motion = discrete_motion(self.self_free, bound, resolution)

    def state_valid(self, q: npt.ArrayLike) -> bool:
        """Check the state as the library does, plus the allowed-pair self-collision check."""
        ok = super().state_valid(q)
        return ok and (not self.allowed or self.self_free(np.asarray(q, dtype=float)))

    def motion_valid(self, q0: npt.ArrayLike, q1: npt.ArrayLike) -> bool:
        """Check the straight motion ``q0 -> q1`` (``check_motion``), counting its states."""
        self.motions_checked += 1
        m = cp.check_motion(
            self.robot,
            q0,
            q1,
            self.cloud,
            self.base_pose,
            max_probability=self.max_probability,
            **self.motion_options,
        )
        self.motion_states += int(m.states_checked)
        if not m.safe:
            return False
        if self.allowed:
            return self.self_motion(np.asarray(q0, dtype=float), np.asarray(q1, dtype=float))
        return True


@dataclass
class Checker:
    """One collision checker of one problem.

    Attributes
    ----------
    name : str
        Its row in the tables (``exact``, ``map 10 mm (camera)``, ``cloudprox P<=0.01 (area)``).
    family : str
        ``"exact"``, ``"map"`` or ``"cloudprox"``.
    cloud : str
        ``"-"``, ``"camera"`` or ``"area"``.
    state_valid, motion_valid : Timed
        The checks the planner calls.
    motion_states : callable
        States checked by its motions so far.
    """

    name: str
    family: str
    cloud: str
    state_valid: Timed
    motion_valid: Timed
    motion_states: Callable[[], int]


@dataclass
class RunRecord:
    """One checker on one problem."""

    problem: str
    scenario: str
    checker: str
    family: str
    cloud: str
    admitted: bool
    refused: str = ""
    p_start: float = float("nan")
    p_goal: float = float("nan")
    goal_link: str = ""
    solved: bool = False
    planning_time: float = float("nan")
    simplify_time: float = float("nan")
    length: float = float("nan")
    waypoints: int = 0
    states_checked: int = 0
    motions_checked: int = 0
    motion_states: int = 0
    state_seconds: float = 0.0
    motion_seconds: float = 0.0
    colliding: bool | None = None
    collision: str = ""
    seen_near_contact: int | None = None
    path: list[list[float]] | None = None
    note: str = ""


@dataclass
class SceneRecord:
    """What one problem's scene cost and held."""

    problem: str
    scenario: str
    objects: int
    exact_start: bool
    exact_goal: bool
    start_clearance: float
    goal_clearance: float
    goal_nearest: str
    clouds: dict[str, dict[str, Any]] = field(default_factory=dict)
    probe: dict[str, dict[str, float]] = field(default_factory=dict)
    phases: dict[str, float] = field(default_factory=dict)


# ---------------------------------------------------------------- setup


def machine_info() -> dict[str, Any]:
    """Host, CPU, cores, Python and the packages' versions."""
    import importlib.metadata as md

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    versions = {}
    for pkg in ("cloudprox", "ompl", "python-fcl", "numpy", "PyYAML", "yourdfpy"):
        try:
            versions[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            versions[pkg] = "-"
    return {
        "host": platform.node(),
        "cpu": cpu,
        "cores": os.cpu_count(),
        "rayon_threads": os.environ.get("RAYON_NUM_THREADS", "default"),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "versions": versions,
    }


def fk_check(robot: cp.Robot, urdf: Path, n: int, seed: int) -> float | None:
    """Largest difference (m, rotation entries alike) of cloudprox's link poses from yourdfpy's.

    ``None`` when yourdfpy is not installed.
    """
    try:
        import yourdfpy
    except ImportError:
        return None
    model = yourdfpy.URDF.load(str(urdf), load_meshes=False, build_collision_scene_graph=False)
    rng = np.random.default_rng(seed)
    lim = robot.joint_limits
    worst = 0.0
    names = list(robot.joint_names)
    for _ in range(n):
        q = rng.uniform(lim[:, 0], lim[:, 1])
        model.update_cfg({j: float(v) for j, v in zip(names, q, strict=True)})
        poses = robot.link_poses(q)
        for link, pose in poses.items():
            other = model.get_transform(frame_to=link, frame_from=model.base_link)
            worst = max(worst, float(np.max(np.abs(other - pose))))
    return worst


def acm_differences(robot: cp.Robot, problem: Problem) -> dict[str, list[list[str]]]:
    """Link pairs where the scene's allowed-collision matrix and the robot's pair list differ."""
    checked = {frozenset(p) for p in robot.self_collision_pairs}
    names = set(problem.scene.acm_names)
    allowed_but_checked = sorted(
        sorted(p) for p in problem.scene.allowed if p in checked and p <= names
    )
    ignored = {frozenset(p) for p in robot.ignored_pairs}
    checked_by_acm_but_ignored = sorted(
        sorted(p) for p in ignored if p <= names and p not in problem.scene.allowed
    )
    return {
        "acm_allows_cloudprox_checks": allowed_but_checked,
        "acm_checks_cloudprox_ignores": checked_by_acm_but_ignored,
    }


# ---------------------------------------------------------------- per problem


def _top_link(result: Any) -> str:
    best, name = -1.0, ""
    for link, lc in result.links.items():
        p = lc.probability
        if p == p and p > best:
            best, name = p, link
    return name


def build_cloud_timing(robot: cp.Robot, cloud: cp.PointCloud, q: FloatArray) -> dict[str, float]:
    """Seconds of the first ``collide_robot`` call on a fresh cloud (the build) and of a second."""
    t0 = time.perf_counter()
    cp.collide_robot(robot, q, cloud, self_collision=False)
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    cp.collide_robot(robot, q, cloud, self_collision=False)
    second = time.perf_counter() - t0
    return {"first_check_seconds": first, "second_check_seconds": second}


def probe(
    robot: cp.Robot,
    exact: FclChecker,
    maps: dict[str, FclChecker],
    clouds: dict[str, SensorCloud],
    n: int,
    rng: np.random.Generator,
) -> dict[str, dict[str, float]]:
    """Median single-state cost of each checker on ``n`` uniformly random configurations."""
    if n <= 0:
        return {}
    lim = robot.joint_limits
    qs = rng.uniform(lim[:, 0], lim[:, 1], (n, robot.dof))
    out: dict[str, dict[str, float]] = {}

    def wall(fn: Callable[[FloatArray], Any]) -> list[float]:
        t = []
        for q in qs:
            t0 = time.perf_counter()
            fn(q)
            t.append(time.perf_counter() - t0)
        return t

    out["exact (python-fcl)"] = {"median_seconds": float(np.median(wall(exact.collides)))}
    out["self-collision (Robot.self_collisions)"] = {
        "median_seconds": float(np.median(wall(robot.self_collisions)))
    }
    for name, m in maps.items():
        out[name] = {
            "median_seconds": float(np.median(wall(m.collides))),
            "boxes": float(len(m.objects)),
        }
    for kind, sc in clouds.items():
        for decide in (False, True):
            own, walls = [], []
            for q in qs:
                t0 = time.perf_counter()
                options: dict[str, Any] = {"self_collision": False}
                if decide:
                    options.update(decide_only=True, threshold_collision=0.5)
                r = cp.collide_robot(robot, q, sc.cloud, **options)
                walls.append(time.perf_counter() - t0)
                own.append(r.stats.time_seconds)
            label = f"cloudprox {'decide-only' if decide else 'full'} ({kind})"
            out[label] = {
                "median_seconds": float(np.median(walls)),
                "p90_seconds": float(np.quantile(walls, 0.9)),
                "max_seconds": float(np.max(walls)),
                "median_query_seconds": float(np.median(own)),
            }
    return out


def _reader(obj: object, attr: str) -> Callable[[], int]:
    """Return a function reading ``obj.attr`` as an int."""
    return lambda: int(getattr(obj, attr))


def make_checkers(
    robot: cp.Robot,
    bound: MotionBound,
    exact: FclChecker,
    maps: dict[str, tuple[str, FclChecker]],
    clouds: dict[str, SensorCloud],
    thresholds: Sequence[float],
    resolution: float,
    allowed: frozenset[frozenset[str]] = frozenset(),
) -> list[Checker]:
    """Return the checkers of one problem, exact first."""
    out = []
    ex_motion = discrete_motion(exact.state_valid, bound, resolution)
    out.append(
        Checker(
            "exact (python-fcl, primitives)",
            "exact",
            "-",
            Timed(exact.state_valid),
            Timed(ex_motion),
            _reader(ex_motion, "states"),
        )
    )
    for kind, sc in clouds.items():
        for name, (mkind, m) in maps.items():
            if mkind != kind:
                continue
            mv = discrete_motion(m.state_valid, bound, resolution)
            out.append(
                Checker(
                    name,
                    "map",
                    kind,
                    Timed(m.state_valid),
                    Timed(mv),
                    _reader(mv, "states"),
                )
            )
        for p in thresholds:
            c = CountingConstraint(
                robot,
                sc.cloud,
                max_probability=p,
                resolution=resolution,
                bound=bound,
                allowed=allowed,
            )
            out.append(
                Checker(
                    f"cloudprox P<={p:g} ({kind})",
                    "cloudprox",
                    kind,
                    Timed(c.state_valid),
                    Timed(c.motion_valid),
                    _reader(c, "motion_states"),
                )
            )
    return out


def validate_path(
    exact: FclChecker, bound: MotionBound, path: FloatArray, resolution: float
) -> tuple[bool, str, FloatArray]:
    """Whether the path meets the exact scene (to ``resolution`` of link travel), where, contacts.

    :func:`mbm.checkers.first_collision`: conservative advancement with the
    exact clearance, states at most ``resolution`` apart near the scene.
    """
    hit = first_collision(exact, bound, path, resolution)
    if hit is None:
        return False, "", np.empty((0, 3))
    k, t, _ = hit
    q = path[k] + t * (path[k + 1] - path[k])
    where = ", ".join(f"{a}-{b}" for a, b in exact.colliding_pairs(q)[:3])
    return True, f"segment {k + 1}/{len(path) - 1} at t={t:.3f}: {where}", exact.contacts(q)


def problem_seed(seed: int, problem: Problem) -> int:
    """Return the seed of one problem's noise and planner: ``--seed`` and the problem's name.

    The same problem gets the same seed whatever else is selected.
    """
    return (seed * 1_000_003 + zlib.crc32(problem.name.encode())) % (2**31 - 1)


def run_problem(
    problem: Problem,
    robot: cp.Robot,
    bound: MotionBound,
    args: argparse.Namespace,
    seed: int,
) -> tuple[SceneRecord, list[RunRecord]]:
    """Build the problem's clouds and checkers, plan with each, validate the paths."""
    scene = problem.scene
    names = [o.name for o in scene.objects]
    allowed = scene.allowed if args.self_collision == "acm" else frozenset()
    self_free = self_collision_check(robot, allowed)
    exact = FclChecker(robot, [o.fcl_object() for o in scene.objects], names, allowed=allowed)
    s_clear, _, _ = exact.nearest(problem.start)
    g_clear, g_link, g_obj = exact.nearest(problem.goal)
    srec = SceneRecord(
        problem.name,
        problem.scenario,
        len(scene.objects),
        exact.collides(problem.start),
        exact.collides(problem.goal),
        s_clear,
        g_clear,
        f"{g_link}-{g_obj}",
    )
    clock = time.perf_counter()

    def phase(name: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        srec.phases[name] = srec.phases.get(name, 0.0) + now - clock
        clock = now

    phase("exact scene")
    clouds: dict[str, SensorCloud] = {}
    for kind in args.clouds:
        if kind == "camera":
            sc = camera_scan(scene, target=args.points, seed=seed, position=args.camera)
        else:
            sc = area_scan(scene, n=args.points, sigma=args.sigma, seed=seed)
        info = dict(sc.info)
        info.update(build_cloud_timing(robot, sc.cloud, problem.start))
        clouds[kind] = sc
        srec.clouds[kind] = info
    phase("clouds and first checks")
    maps: dict[str, tuple[str, FclChecker]] = {}
    for kind, sc in clouds.items():
        for size in args.voxel:
            t0 = time.perf_counter()
            boxes = voxel_boxes(sc.points, size)
            m = FclChecker(robot, boxes, allowed=allowed)
            maps[f"map {size * 1e3:g} mm ({kind})"] = (kind, m)
            srec.clouds[kind][f"map_{size * 1e3:g}mm_boxes"] = len(boxes)
            srec.clouds[kind][f"map_{size * 1e3:g}mm_build_seconds"] = time.perf_counter() - t0
    phase("voxel maps")
    srec.probe = probe(
        robot,
        exact,
        {k: v[1] for k, v in maps.items()},
        clouds,
        args.probe,
        np.random.default_rng(seed + 7),
    )
    phase("probe")
    # P at the start and goal: the full query, once per cloud
    p_at: dict[str, tuple[float, float, str, bool, bool]] = {}
    for kind, sc in clouds.items():
        rs = cp.collide_robot(robot, problem.start, sc.cloud)
        rg = cp.collide_robot(robot, problem.goal, sc.cloud)
        p_at[kind] = (
            float(rs.probability),
            float(rg.probability),
            _top_link(rg),
            bool(rs.self_collisions),
            bool(rg.self_collisions),
        )
        srec.clouds[kind]["p_start"] = float(rs.probability)
        srec.clouds[kind]["p_goal"] = float(rg.probability)
        srec.clouds[kind]["goal_link"] = _top_link(rg)
    phase("start and goal")
    checkers = make_checkers(
        robot, bound, exact, maps, clouds, args.thresholds, args.resolution, allowed
    )
    records = []
    trees: dict[str, Any] = {}
    for ch in checkers:
        rec = RunRecord(problem.name, problem.scenario, ch.name, ch.family, ch.cloud, True)
        self_s = not self_free(problem.start)
        self_g = not self_free(problem.goal)
        if ch.family == "cloudprox":
            ps, pg, link, _, _ = p_at[ch.cloud]
            rec.p_start, rec.p_goal, rec.goal_link = ps, pg, link
            limit = float(ch.name.split("P<=")[1].split()[0])
            bad_s, bad_g = ps > limit, pg > limit
        elif ch.family == "map":
            m = maps[ch.name][1]
            bad_s, bad_g = m.collides(problem.start), m.collides(problem.goal)
        else:
            bad_s, bad_g = srec.exact_start, srec.exact_goal
        reasons = []
        if self_s or self_g:
            reasons.append(
                "self-collision at "
                + "/".join(w for w, b in (("start", self_s), ("goal", self_g)) if b)
            )
        if bad_s:
            reasons.append("start")
        if bad_g:
            reasons.append("goal")
        if reasons:
            rec.admitted, rec.refused = False, ", ".join(reasons)
            records.append(rec)
            log(f"  {problem.name} {ch.name}: refused ({rec.refused})")
            continue
        try:
            r = plan_joint_space(
                robot.joint_limits,
                ch.state_valid,
                ch.motion_valid,
                problem.start,
                problem.goal,
                time_limit=args.time_limit,
                seed=seed,
                simplify=args.simplify_time > 0,
                simplify_time=args.simplify_time or None,
            )
        except ValueError as exc:  # its own check of the start or goal refused it
            rec.admitted, rec.refused, rec.note = False, "planner's own check", str(exc)
            records.append(rec)
            log(f"  {problem.name} {ch.name}: refused by its state check ({exc})")
            continue
        phase("planning")
        rec.solved = r.solved
        rec.planning_time = r.planning_time
        rec.simplify_time = r.simplify_time
        rec.states_checked = ch.state_valid.calls
        rec.motions_checked = ch.motion_valid.calls
        rec.motion_states = ch.motion_states()
        rec.state_seconds = ch.state_valid.seconds
        rec.motion_seconds = ch.motion_valid.seconds
        if r.path is not None:
            rec.length = r.length
            rec.waypoints = len(r.path)
            rec.colliding, rec.collision, contacts = validate_path(
                exact, bound, r.path, args.validate_resolution
            )
            if rec.colliding:
                rec.path = r.path.tolist()
                if ch.cloud in clouds and len(contacts):
                    # did the sensor see the surface there? cloud points within 1 cm
                    tree = trees.setdefault(ch.cloud, cKDTree(clouds[ch.cloud].points))
                    near = tree.query_ball_point(contacts, 0.01)
                    rec.seen_near_contact = len({j for js in near for j in js})
                    rec.collision += f" ({rec.seen_near_contact} cloud points within 1 cm)"
            phase("validation")
        records.append(rec)
        log(
            f"  {problem.name} {ch.name}: solved {r.solved} in {r.planning_time:.2f} s "
            f"({rec.states_checked} states, {rec.motions_checked} motions, "
            f"{rec.motion_states} motion states)"
            + (f", colliding: {rec.collision}" if rec.colliding else "")
        )
    return srec, records


# ---------------------------------------------------------------- output


def _median(x: Sequence[float]) -> float:
    return float(np.median(x)) if len(x) else float("nan")


def _fmt(x: float, digits: int = 2) -> str:
    return "-" if not math.isfinite(x) else f"{x:.{digits}f}"


def _us(x: float) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{x * 1e6:.0f} us" if x < 1e-3 else f"{x * 1e3:.1f} ms"


def summary(records: list[RunRecord]) -> list[dict[str, Any]]:
    """Per checker: admitted, solved, the exact checker on the same problems, times, collisions."""
    exact = {r.problem: r for r in records if r.family == "exact"}
    out = []
    for name in dict.fromkeys(r.checker for r in records):
        rows = [r for r in records if r.checker == name]
        adm = [r for r in rows if r.admitted]
        solved = [r for r in adm if r.solved]
        ex_same = [exact[r.problem] for r in adm if r.problem in exact]
        ex_solved = [e for e in ex_same if e.solved]
        both = [
            (r.planning_time, exact[r.problem].planning_time)
            for r in solved
            if r.problem in exact and exact[r.problem].solved
        ]
        refused: dict[str, int] = {}
        for r in rows:
            if not r.admitted:
                refused[r.refused] = refused.get(r.refused, 0) + 1
        checks = sum(r.states_checked + r.motion_states for r in adm)
        seconds = sum(r.state_seconds + r.motion_seconds for r in adm)
        out.append(
            {
                "checker": name,
                "problems": len(rows),
                "admitted": len(adm),
                "solved": len(solved),
                "exact_solved_same": len(ex_solved),
                "exact_on_same": len(ex_same),
                "median_planning_time": _median([r.planning_time for r in solved]),
                "exact_median_same": _median([e.planning_time for e in ex_solved]),
                "median_ratio_both_solved": _median([a / b for a, b in both if b > 0]),
                "colliding": sum(bool(r.colliding) for r in solved),
                "refused": refused,
                "seconds_per_checked_state": seconds / checks if checks else float("nan"),
                "states_per_motion": (
                    sum(r.motion_states for r in adm) / sum(r.motions_checked for r in adm)
                    if any(r.motions_checked for r in adm)
                    else float("nan")
                ),
            }
        )
    return out


def markdown(result: dict[str, Any]) -> str:
    """Return the run's tables as markdown."""
    a = result["args"]
    m = result["machine"]
    lines = [
        f"MotionBenchMaker ({result['source']}), robot {a['robot']}, "
        f"{result['n_problems']} problems ({a['problems']} per scenario"
        + (f" from number {a['first']}" if a["first"] > 1 else "")
        + f"), OMPL RRTConnect, {a['time_limit']:g} s limit, seed {a['seed']}, "
        f"motion resolution {a['resolution'] * 1e3:g} mm, paths validated at "
        f"{a['validate_resolution'] * 1e3:g} mm against the exact primitives.",
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores (RAYON_NUM_THREADS={m['rayon_threads']}), "
        f"Python {m['python']}, cloudprox {m['versions']['cloudprox']}, "
        f"OMPL {m['versions']['ompl']}, python-fcl {m['versions']['python-fcl']}; "
        f"{result['date']}.",
        "",
        f"Command: `{result['command']}`",
        "",
        "| checker | admitted | solved within the limit | exact, same problems "
        "| median planning time (s) | exact's median, same problems (s) "
        "| median ratio to exact (both solved) | paths colliding with the exact scene "
        "| refused (why) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for s in result["summary"]:
        refused = "; ".join(f"{k}: {v}" for k, v in s["refused"].items()) or "-"
        share = s["solved"] / s["admitted"] if s["admitted"] else float("nan")
        ratio = s["median_ratio_both_solved"]
        ex_share = s["exact_solved_same"] / s["exact_on_same"] if s["exact_on_same"] else math.nan
        lines.append(
            f"| {s['checker']} | {s['admitted']}/{s['problems']} | "
            f"{s['solved']}/{s['admitted']} ({_fmt(100 * share, 0)} %) | "
            f"{s['exact_solved_same']}/{s['exact_on_same']} ({_fmt(100 * ex_share, 0)} %) | "
            f"{_fmt(s['median_planning_time'])} | {_fmt(s['exact_median_same'])} | "
            f"{_fmt(s['median_ratio_both_solved'], 1)}{'x' if math.isfinite(ratio) else ''} | "
            f"{s['colliding']}/{s['solved']} | {refused} |"
        )
    # per scenario
    records = [RunRecord(**r) for r in result["runs"]]
    scenarios = list(dict.fromkeys(r.scenario for r in records))
    names = [s["checker"] for s in result["summary"]]
    lines += [
        "",
        "Solved / admitted per scenario:",
        "",
        "| checker | " + " | ".join(scenarios) + " |",
        "|---|" + "---|" * len(scenarios),
    ]
    for name in names:
        cells = []
        for sc in scenarios:
            rows = [r for r in records if r.checker == name and r.scenario == sc]
            cells.append(f"{sum(r.solved for r in rows)}/{sum(r.admitted for r in rows)}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    colliding = [r for r in records if r.colliding]
    if colliding:
        lines += ["", "Paths colliding with the exact scene (first contact):", ""]
        lines += [f"- {r.checker}, {r.problem}: {r.collision}" for r in colliding]
    # start / goal probabilities
    scenes = result["scenes"]
    kinds = list(a["clouds"])
    lines += [
        "",
        "Start and goal: exact clearance (python-fcl distance, nearest link and object) and "
        "cloudprox's P (full query; the link with the largest P at the goal):",
        "",
        "| problem | start clearance (mm) | goal clearance (mm) | nearest at goal | "
        + " | ".join(f"P start / goal ({k})" for k in kinds)
        + " |",
        "|---|---|---|---|" + "---|" * len(kinds),
    ]
    shown = (
        scenes
        if len(scenes) <= 60
        else [
            s for s in scenes if any(s["clouds"][k]["p_goal"] > min(a["thresholds"]) for k in kinds)
        ][:60]
    )
    for s in shown:
        cells = [
            f"{s['clouds'][k]['p_start']:.2g} / {s['clouds'][k]['p_goal']:.2g}"
            + (f" ({s['clouds'][k]['goal_link']})" if s["clouds"][k]["p_goal"] > 0 else "")
            for k in kinds
        ]
        lines.append(
            f"| {s['problem']} | {s['start_clearance'] * 1e3:.1f} | "
            f"{s['goal_clearance'] * 1e3:.1f} | {s['goal_nearest']} | " + " | ".join(cells) + " |"
        )
    if len(shown) < len(scenes):
        lines.append(
            f"\n({len(shown)} of {len(scenes)} problems shown: those with a goal P above "
            f"{min(a['thresholds']):g}.)"
        )
    # timings
    lines += [
        "",
        "Where the time goes (medians over the scenes; per-state costs one thread):",
        "",
        "| cloud | points | median sigma (mm) | cloud made (s) | first check, the build (ms) "
        "| second check (ms) | map boxes |",
        "|---|---|---|---|---|---|---|",
    ]
    for k in kinds:
        info = [s["clouds"][k] for s in scenes]
        made = [
            i.get("cast_seconds", i.get("sample_seconds", 0.0)) + i["cloud_seconds"] for i in info
        ]
        boxes = [v for i in info for kk, v in i.items() if kk.endswith("_boxes")]
        lines.append(
            f"| {k} | {_median([i['points'] for i in info]):.0f} | "
            f"{_median([i['median_sigma'] for i in info]) * 1e3:.1f} | {_median(made):.2f} | "
            f"{_median([i['first_check_seconds'] for i in info]) * 1e3:.0f} "
            f"({min(i['first_check_seconds'] for i in info) * 1e3:.0f}-"
            f"{max(i['first_check_seconds'] for i in info) * 1e3:.0f}) | "
            f"{_median([i['second_check_seconds'] for i in info]) * 1e3:.2f} | "
            f"{_median(boxes):.0f} |"
        )
    lines += [
        "",
        "| checker | in planning: time per checked state | states per motion "
        "| uniform random states: median (p90, max) |",
        "|---|---|---|---|",
    ]
    probe_of = {
        "exact (python-fcl, primitives)": "exact (python-fcl)",
        **{n: n for n in names if n.startswith("map")},
    }
    for s in result["summary"]:
        key = probe_of.get(s["checker"])
        if s["checker"].startswith("cloudprox"):
            kind = s["checker"].split("(")[-1].rstrip(")")
            limit = float(s["checker"].split("P<=")[1].split()[0])
            key = f"cloudprox {'decide-only' if limit < 0.5 else 'full'} ({kind})"
        pr = [sc["probe"][key] for sc in scenes if key in sc["probe"]]
        med = _median([p["median_seconds"] for p in pr])
        extra = ""
        if pr and "p90_seconds" in pr[0]:
            extra = (
                f" ({_us(_median([p['p90_seconds'] for p in pr]))}, "
                f"{_us(max(p['max_seconds'] for p in pr))})"
            )
        lines.append(
            f"| {s['checker']} | {_us(s['seconds_per_checked_state'])} | "
            f"{_fmt(s['states_per_motion'], 1)} | {_us(med)}{extra} |"
        )
    if any("self-collision (Robot.self_collisions)" in s["probe"] for s in scenes):
        sc_med = _median(
            [s["probe"]["self-collision (Robot.self_collisions)"]["median_seconds"] for s in scenes]
        )
        lines.append(
            f"\nThe exact and map checkers' state time includes `Robot.self_collisions` "
            f"({_us(sc_med)} median per state); the probe's python-fcl times do not."
        )
    notes = result.get("notes") or []
    if notes:
        lines += ["", *[f"- {n}" for n in notes]]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- main


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """Parse the command line."""
    ap = argparse.ArgumentParser(
        prog="benches/motionbenchmaker.py",
        description="Plan MotionBenchMaker problems with cloudprox's chance constraint, "
        "an exact checker and a voxel map (OMPL RRTConnect).",
    )
    ap.add_argument("--robot", default="panda", help=f"one of {', '.join(ROBOTS)} (panda)")
    ap.add_argument("--problems", type=int, default=2, help="problems per scenario (2)")
    ap.add_argument("--first", type=int, default=1, help="first problem number (1)")
    ap.add_argument("--scenarios", default="", help="comma-separated (all by default)")
    ap.add_argument("--time-limit", type=float, default=5.0, help="planning seconds (5)")
    ap.add_argument(
        "--simplify-time",
        type=float,
        default=0.0,
        help="seconds of OMPL's path simplification (0: none, the default)",
    )
    ap.add_argument("--seed", type=int, default=0, help="OMPL's and the noise's seed (0)")
    ap.add_argument("--thresholds", default="0.5,0.01", help="cloudprox max_probability values")
    ap.add_argument("--clouds", default="camera,area", help="sensor clouds: camera, area")
    ap.add_argument("--points", type=int, default=120_000, help="points per cloud (120000)")
    ap.add_argument("--sigma", type=float, default=0.003, help="area cloud noise (m, 0.003)")
    ap.add_argument("--voxel", default="0.01", help="collision map voxel sides (m, 0.01)")
    ap.add_argument(
        "--camera",
        default=",".join(f"{v:g}" for v in CAMERA_POSITION),
        help="camera position x,y,z in the robot's base frame (m)",
    )
    ap.add_argument("--resolution", type=float, default=0.005, help="motion check (m, 0.005)")
    ap.add_argument(
        "--validate-resolution", type=float, default=0.001, help="path validation (m, 0.001)"
    )
    ap.add_argument("--probe", type=int, default=20, help="random states per scene timed (20)")
    ap.add_argument(
        "--self-collision",
        choices=("auto", "robot", "acm"),
        default="auto",
        help="self-collision pairs: the robot model's (cloudprox's own), the scene's "
        "allowed-collision matrix applied to them, or auto: acm when a chosen start or goal "
        "self-collides only in pairs the matrix allows (the default)",
    )
    ap.add_argument("--json", type=Path, default=None, help="write the results here")
    args = ap.parse_args(argv)
    args.thresholds = [float(x) for x in str(args.thresholds).split(",") if x]
    args.clouds = [c for c in str(args.clouds).split(",") if c]
    args.voxel = [float(x) for x in str(args.voxel).split(",") if x]
    args.camera = [float(x) for x in str(args.camera).split(",")]
    args.scenarios = [s for s in str(args.scenarios).split(",") if s]
    bad = [c for c in args.clouds if c not in ("camera", "area")]
    if bad:
        ap.error(f"unknown cloud kinds {bad}: camera, area")
    if len(args.camera) != 3:
        ap.error("--camera needs x,y,z")
    if args.problems < 1 or args.first < 1:
        ap.error("--problems and --first must be at least 1")
    if not all(0.0 <= t < 1.0 for t in args.thresholds):
        ap.error("--thresholds must be in [0, 1)")
    return args


def unsupported(robot: cp.Robot, problems: list[Problem]) -> list[str]:
    """Why the planner cannot run this robot's problems (empty when it can)."""
    out = []
    lim = robot.joint_limits
    if not np.all(np.isfinite(lim)):
        inf = [
            j
            for j, (lo, hi) in zip(robot.joint_names, lim, strict=True)
            if not (math.isfinite(lo) and math.isfinite(hi))
        ]
        out.append(f"joints without finite limits (the bounded joint space needs them): {inf}")
    for p in problems:
        for what, q in (("start", p.start), ("goal", p.goal)):
            if np.any(q < lim[:, 0] - 1e-9) or np.any(q > lim[:, 1] + 1e-9):
                out.append(f"{p.name}: the {what} is outside the joint limits")
    return out


def run(args: argparse.Namespace, command: str) -> dict[str, Any]:
    """Fetch, parse, plan, validate; return the results (as written by ``--json``)."""
    t_all = time.perf_counter()
    files: RobotFiles = fetch_robot(args.robot)
    notes = [f"URDF fix: {f}" for f in files.fixes]
    robot = cp.Robot.from_urdf(files.loadable_urdf)
    bound = MotionBound(robot, files.loadable_urdf)
    fk = fk_check(robot, files.loadable_urdf, 20, args.seed)
    if fk is not None:
        notes.append(f"cloudprox's link poses agree with yourdfpy's to {fk:.1e} (20 random q)")
    # numbers are the files' own: the first chosen is --first
    per = args.problems + args.first - 1
    problems = load_problems(
        files.problems,
        args.robot,
        robot.joint_names,
        scenarios=args.scenarios or None,
        per_scenario=per,
    )
    problems = [p for p in problems if p.index >= args.first]
    dropped = sorted({j for p in problems for j in p.dropped_joints})
    if dropped:
        notes.append(f"request joints the robot model does not move (ignored): {dropped}")
    if args.self_collision == "auto":
        args.self_collision = "robot"
        allowed_only = [
            p.name
            for p in problems
            for q in (p.start, p.goal)
            if (pairs := robot.self_collisions(q)) and all(p.scene.allows(a, b) for a, b in pairs)
        ]
        if allowed_only:
            args.self_collision = "acm"
            notes.append(
                f"self-collision: the scenes' allowed-collision matrix ({len(allowed_only)} "
                f"starts/goals, e.g. {allowed_only[0]}, self-collide under the robot model's "
                "pairs only in pairs the matrix allows); cloudprox's own self-check is off and "
                "the same allowed-pair check is added to every checker"
            )
        else:
            notes.append("self-collision: the robot model's pairs (Robot.self_collisions)")
    blockers = unsupported(robot, problems)
    result: dict[str, Any] = {
        "source": f"vamp-planner 0.6.4 sdist, resources/{args.robot}/problems.tar.bz2",
        "date": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "command": command,
        "machine": machine_info(),
        "args": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()},
        "robot": {
            "name": robot.name,
            "dof": robot.dof,
            "joints": list(robot.joint_names),
            "urdf": str(files.urdf),
        },
        "n_problems": len(problems),
        "notes": notes,
        "acm": acm_differences(robot, problems[0]) if problems else {},
        "scenes": [],
        "runs": [],
        "summary": [],
    }
    if blockers:
        result["unsupported"] = blockers
        return result
    log(
        f"{args.robot}: {robot.dof} joints, {len(problems)} problems "
        f"({', '.join(dict.fromkeys(p.scenario for p in problems))})"
    )
    records: list[RunRecord] = []
    for i, p in enumerate(problems):
        t0 = time.perf_counter()
        log(f"[{i + 1}/{len(problems)}] {p.name} ({len(p.scene.objects)} primitives)")
        srec, recs = run_problem(p, robot, bound, args, problem_seed(args.seed, p))
        result["scenes"].append(asdict(srec))
        records += recs
        log(f"  ({time.perf_counter() - t0:.0f} s)")
    result["runs"] = [asdict(r) for r in records]
    result["summary"] = summary(records)
    result["seconds"] = time.perf_counter() - t_all
    return result


def _json_default(x: Any) -> Any:
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return str(x)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark from the command line; print the tables; return the exit status."""
    args = parse_args(argv)
    command = shlex.join([Path(sys.argv[0]).name, *(sys.argv[1:] if argv is None else argv)])
    if args.robot not in ROBOTS:
        print(
            f"error: unknown robot {args.robot!r}; the MotionBenchMaker problems of the "
            f"vamp-planner sdist are for {', '.join(ROBOTS)}",
            file=sys.stderr,
        )
        return 2
    try:
        result = run(args, command)
    except MbmUnavailable as exc:
        print(f"error: the MotionBenchMaker data is unavailable: {exc}", file=sys.stderr)
        return 3
    if result.get("unsupported"):
        print(
            f"{args.robot}: parsed {result['n_problems']} problems, but they cannot be "
            "planned here:\n" + "\n".join(f"- {b}" for b in result["unsupported"])
        )
        status = 4
    else:
        print(markdown(result))
        status = 0
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(result, indent=1, default=_json_default) + "\n")
        log(f"wrote {args.json}")
    return status
