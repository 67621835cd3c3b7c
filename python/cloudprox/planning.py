"""Motion planning with OMPL under a chance constraint on the collision probability.

A state is valid when the robot there collides with the scanned environment with
probability at most ``max_probability`` (:func:`cloudprox.collide_robot`) and its
links do not collide with each other; a straight joint-space motion is valid when
:func:`cloudprox.check_motion` finds every state along it valid at its own
resolution (no link point moves more than ``resolution`` between two checked
states). OMPL (``pip install ompl``, the Open Motion Planning Library's Python
bindings) plans in the robot's joint space within its limits.

:class:`ChanceConstraint` is the checker on its own (``state_valid``,
``motion_valid``, and :meth:`ChanceConstraint.install` for an OMPL
``SpaceInformation`` of one's own); :func:`plan` plans with it;
:func:`plan_joint_space` plans with any pair of state and motion checks, which is
how ``benches/planning.py`` runs the same planner against exact meshes and a
collision map.

Examples
--------
>>> from cloudprox.planning import plan  # doctest: +SKIP
>>> result = plan(robot, scan, q_start, q_goal, max_probability=0.05)  # doctest: +SKIP
>>> result.path.shape  # doctest: +SKIP
(12, 9)
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from cloudprox._native import (
    CollisionRequest,
    PointCloud,
    Robot,
    RobotRequest,
    check_motion,
    collide_robot,
)

__all__ = ["ChanceConstraint", "PlanResult", "plan", "plan_joint_space"]

FloatArray = npt.NDArray[np.float64]
#: A state check: configuration -> valid.
StateCheck = Callable[[FloatArray], bool]
#: A motion check: (from, to) -> the straight joint-space motion is valid.
MotionCheck = Callable[[FloatArray, FloatArray], bool]


@dataclass
class PlanResult:
    """What :func:`plan` and :func:`plan_joint_space` return.

    Attributes
    ----------
    solved : bool
        Whether an exact solution was found within the time limit.
    path : numpy.ndarray or None
        The solution's waypoints, shape ``(k, dof)``, start first and goal last
        (``None`` when not solved). Consecutive waypoints are joined by straight
        joint-space motions that the motion check accepted.
    planning_time : float
        Wall time of the planner until the first solution or the time limit (seconds).
    simplify_time : float
        Wall time of the path's simplification (seconds; 0 without it).
    states_checked : int
        Calls of the state validity checker.
    motions_checked : int
        Calls of the motion validator.
    """

    solved: bool
    path: FloatArray | None
    planning_time: float
    simplify_time: float
    states_checked: int
    motions_checked: int

    @property
    def length(self) -> float:
        """Joint-space length of the path (sum of the segments' Euclidean norms; nan unsolved)."""
        if self.path is None:
            return float("nan")
        return float(np.linalg.norm(np.diff(self.path, axis=0), axis=1).sum())


class ChanceConstraint:
    """State and motion validity of a robot among a cloud's points, under a chance constraint.

    Parameters
    ----------
    robot : Robot
        The robot.
    cloud : PointCloud
        The environment, in the frame of ``base_pose``.
    base_pose : array_like, shape (4, 4), optional
        Pose of the robot's root link (identity by default).
    max_probability : float
        The chance constraint, in ``[0, 1)``: a valid state has a collision
        probability at most this (and no self-collision).
    **options
        Options of :func:`cloudprox.collide_robot` (``request=`` a
        :class:`cloudprox.RobotRequest` or a :class:`cloudprox.CollisionRequest`,
        and keyword options), plus
        ``resolution`` of :func:`cloudprox.check_motion`. Unless a ``request``
        or ``decide_only`` is given, ``decide_only`` is on
        when ``max_probability`` is below 0.5, with ``threshold_collision`` 0.5
        unless given: a query may then stop at the first patch that reaches
        that threshold, which is above the constraint anyway, so its answer for
        the constraint does not change.

    Raises
    ------
    ValueError
        If ``max_probability`` is not in ``[0, 1)``, or ``decide_only`` is on and
        ``max_probability`` is not below ``threshold_collision``.
    """

    def __init__(
        self,
        robot: Robot,
        cloud: PointCloud,
        base_pose: npt.ArrayLike | None = None,
        *,
        max_probability: float = 0.1,
        **options: Any,
    ) -> None:
        if not (np.isfinite(max_probability) and 0.0 <= max_probability < 1.0):
            raise ValueError(f"max_probability must be in [0, 1), got {max_probability}")
        request: CollisionRequest | RobotRequest | None = options.get("request")
        if max_probability < 0.5 and "decide_only" not in options and request is None:
            # A query may stop at the first patch whose probability reaches the
            # collision threshold: 0.5 (its lowest) unless given, above the constraint.
            options.setdefault("threshold_collision", 0.5)
            options["decide_only"] = True
        collision = request.collide if isinstance(request, RobotRequest) else request
        effective = (collision or CollisionRequest()).replace(
            **{k: options[k] for k in ("threshold_collision", "decide_only") if k in options}
        )
        threshold = effective.threshold_collision
        if effective.decide_only and max_probability >= threshold:
            raise ValueError(
                f"decide_only needs max_probability ({max_probability}) below "
                f"threshold_collision ({threshold}): a query may stop at that probability"
            )
        self.robot = robot
        self.cloud = cloud
        self.base_pose = None if base_pose is None else np.asarray(base_pose, dtype=float)
        self.max_probability = float(max_probability)
        self.motion_options = dict(options)
        self.state_options = {k: v for k, v in options.items() if k != "resolution"}
        self.states_checked = 0
        self.motions_checked = 0

    def state_valid(self, q: npt.ArrayLike) -> bool:
        """Whether the robot at ``q`` meets the constraint and is free of self-collision."""
        self.states_checked += 1
        r = collide_robot(self.robot, q, self.cloud, self.base_pose, **self.state_options)
        return r.probability <= self.max_probability and not r.self_collisions

    def motion_valid(self, q0: npt.ArrayLike, q1: npt.ArrayLike) -> bool:
        """Whether every state of the straight motion ``q0 -> q1`` is valid (``check_motion``)."""
        self.motions_checked += 1
        m = check_motion(
            self.robot,
            q0,
            q1,
            self.cloud,
            self.base_pose,
            max_probability=self.max_probability,
            **self.motion_options,
        )
        return bool(m.safe)

    def install(self, space_information: Any) -> None:
        """Make this the state validity checker and motion validator of an OMPL space.

        ``space_information`` is an ``ompl.base.SpaceInformation`` over a
        ``RealVectorStateSpace`` of the robot's dimension.
        """
        _install(space_information, self.robot.dof, self.state_valid, self.motion_valid)


def _values(state: Any, dof: int) -> FloatArray:
    return np.array([state[i] for i in range(dof)], dtype=float)


def _install(info: Any, dof: int, state_valid: StateCheck, motion_valid: MotionCheck) -> None:
    import ompl.base as ob

    def checker(state: Any) -> bool:
        return bool(state_valid(_values(state, dof)))

    class _Motion(ob.MotionValidator):  # type: ignore[misc]
        def checkMotion(self, s1: Any, s2: Any, *rest: Any) -> bool:
            return bool(motion_valid(_values(s1, dof), _values(s2, dof)))

    info.setStateValidityChecker(checker)
    info.setMotionValidator(_Motion(info))


def plan_joint_space(
    limits: npt.ArrayLike,
    state_valid: StateCheck,
    motion_valid: MotionCheck,
    q_start: npt.ArrayLike,
    q_goal: npt.ArrayLike,
    *,
    time_limit: float = 10.0,
    planner: str = "RRTConnect",
    seed: int | None = None,
    simplify: bool = True,
    simplify_time: float | None = None,
) -> PlanResult:
    """Plan a path in a box of joint space with OMPL, given a state and a motion check.

    Parameters
    ----------
    limits : array_like, shape (dof, 2)
        Lower and upper limit of each coordinate (finite).
    state_valid, motion_valid : callable
        ``state_valid(q) -> bool`` and ``motion_valid(q0, q1) -> bool`` (the
        straight motion between two valid states).
    q_start, q_goal : array_like, shape (dof,)
        Start and goal; both must pass ``state_valid``.
    time_limit : float
        Seconds the planner may use.
    planner : str
        An OMPL geometric planner's class name (``"RRTConnect"``, ``"RRT"``, ...).
    seed : int, optional
        Seed of OMPL's random number generator, set before the planner and its
        samplers are made (reproducible plans within the time limit).
    simplify : bool
        Shorten the solution with OMPL's path simplifier (its motions checked by
        ``motion_valid`` too).
    simplify_time : float, optional
        Seconds the simplifier may use (default ``time_limit``); OMPL checks its
        budget between its steps, so one step may run past it.

    Returns
    -------
    PlanResult
        The path and counters (``states_checked`` and ``motions_checked`` count
        the calls OMPL made).

    Raises
    ------
    ImportError
        If OMPL's Python bindings are not installed.
    ValueError
        If the limits are not finite intervals, a configuration has the wrong
        length or is invalid, ``time_limit`` is not positive, or the planner name
        is unknown.
    """
    import ompl.base as ob
    import ompl.geometric as og
    import ompl.util as ou

    lim = np.asarray(limits, dtype=float)
    if lim.ndim != 2 or lim.shape[1] != 2 or len(lim) == 0:
        raise ValueError(f"limits must have shape (dof, 2), got {lim.shape}")
    if not (np.all(np.isfinite(lim)) and np.all(lim[:, 0] <= lim[:, 1])):
        raise ValueError(
            "plan needs finite joint limits, lower <= upper (continuous joints are unbounded)"
        )
    if not (np.isfinite(time_limit) and time_limit > 0.0):
        raise ValueError(f"time_limit must be positive, got {time_limit}")
    try:
        planner_class = getattr(og, planner)
    except AttributeError:
        raise ValueError(f"unknown OMPL planner {planner!r}") from None
    dof = len(lim)
    q0 = np.asarray(q_start, dtype=float)
    q1 = np.asarray(q_goal, dtype=float)
    for name, q in (("q_start", q0), ("q_goal", q1)):
        if q.shape != (dof,):
            raise ValueError(f"{name} must have shape ({dof},), got {q.shape}")
        if not state_valid(q):
            raise ValueError(f"{name} is not valid (collision, self-collision or out of limits)")
    counters = {"states": 0, "motions": 0}

    def counted_state(q: FloatArray) -> bool:
        counters["states"] += 1
        return state_valid(q)

    def counted_motion(a: FloatArray, b: FloatArray) -> bool:
        counters["motions"] += 1
        return motion_valid(a, b)

    if seed is not None:
        # OMPL reseeds the generator of the seeds of the RNGs made from now on (the
        # planner's and its samplers'); after a first plan in the process it also
        # logs an error about the RNGs made before, which this plan does not use.
        ou.setLogLevel(ou.LogLevel.LOG_NONE)
        ou.RNG.setSeed(int(seed))
    ou.setLogLevel(ou.LogLevel.LOG_WARN)
    space = ob.RealVectorStateSpace(dof)
    bounds = ob.RealVectorBounds(dof)
    for i in range(dof):
        bounds.setLow(i, float(lim[i, 0]))
        bounds.setHigh(i, float(lim[i, 1]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    info = setup.getSpaceInformation()
    _install(info, dof, counted_state, counted_motion)
    start, goal = space.allocState(), space.allocState()
    for i in range(dof):
        start[i] = float(q0[i])
        goal[i] = float(q1[i])
    setup.setStartAndGoalStates(start, goal)
    setup.setPlanner(planner_class(info))
    t0 = time.perf_counter()
    setup.solve(float(time_limit))
    elapsed = time.perf_counter() - t0
    solved = bool(setup.haveExactSolutionPath())
    path = None
    simplified = 0.0
    if solved:
        if simplify:
            t1 = time.perf_counter()
            setup.simplifySolution(float(time_limit if simplify_time is None else simplify_time))
            simplified = time.perf_counter() - t1
        p = setup.getSolutionPath()
        path = np.array([_values(p.getState(i), dof) for i in range(p.getStateCount())])
    return PlanResult(solved, path, elapsed, simplified, counters["states"], counters["motions"])


def plan(
    robot: Robot,
    cloud: PointCloud,
    q_start: npt.ArrayLike,
    q_goal: npt.ArrayLike,
    *,
    base_pose: npt.ArrayLike | None = None,
    max_probability: float = 0.1,
    time_limit: float = 10.0,
    planner: str = "RRTConnect",
    seed: int | None = None,
    simplify: bool = True,
    simplify_time: float | None = None,
    **options: Any,
) -> PlanResult:
    """Plan a joint-space path for ``robot`` among a cloud's points under a chance constraint.

    Every waypoint has a collision probability at most ``max_probability`` and no
    self-collision, and so has every state :func:`cloudprox.check_motion` checks
    between two waypoints (see :class:`ChanceConstraint`).

    Parameters
    ----------
    robot : Robot
        The robot; every joint needs finite limits (continuous joints are not
        supported by the bounded joint space).
    cloud : PointCloud
        The environment, in the frame of ``base_pose``.
    q_start, q_goal : array_like, shape (dof,)
        Start and goal configurations (valid, within the limits).
    base_pose : array_like, shape (4, 4), optional
        Pose of the robot's root link (identity by default).
    max_probability : float
        The chance constraint: the largest collision probability of a valid state.
    time_limit, planner, seed, simplify, simplify_time
        As in :func:`plan_joint_space`.
    **options
        Options of :func:`cloudprox.collide_robot` (and ``resolution`` of
        :func:`cloudprox.check_motion`).

    Returns
    -------
    PlanResult
        The path and counters.

    Raises
    ------
    ImportError
        If OMPL's Python bindings are not installed.
    ValueError
        If a joint has infinite limits, a configuration is invalid, or the planner
        name is unknown.
    """
    constraint = ChanceConstraint(
        robot, cloud, base_pose, max_probability=max_probability, **options
    )
    return plan_joint_space(
        robot.joint_limits,
        constraint.state_valid,
        constraint.motion_valid,
        q_start,
        q_goal,
        time_limit=time_limit,
        planner=planner,
        seed=seed,
        simplify=simplify,
        simplify_time=simplify_time,
    )
