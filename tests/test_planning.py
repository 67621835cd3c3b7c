"""OMPL planning with the collision probability as a chance constraint.

Skipped when OMPL's Python bindings cannot be imported, except on CI
(``CI=true``), where the test extra installs them and the test must run.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from tests.robots import ARM_URDF, panda_urdf_or_skip, readme_block

SIGMA = 0.002
BOX_HALF = (0.01, 0.01, 0.05)
BOX_CENTRE = (0.2, 0.0, 0.3)
Q0 = np.array([-0.6, 0.0, 0.0, 0.0])
Q1 = np.array([0.6, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def ompl() -> None:
    try:
        import ompl.geometric  # noqa: F401
    except ImportError as exc:
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI=true: OMPL must be installed (the test extra has it): {exc}")
        pytest.skip(f"OMPL not installed: {exc}")


@pytest.fixture(scope="module")
def arm(tmp_path_factory: pytest.TempPathFactory) -> cp.Robot:
    # The planner's joint space is bounded: the continuous j5 gets limits.
    urdf = ARM_URDF.replace('type="continuous"', 'type="revolute"').replace(
        '<origin xyz="0 0.3 0"/><axis xyz="0 0 1"/>',
        '<origin xyz="0 0.3 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/>',
    )
    path: Path = tmp_path_factory.mktemp("plan") / "arm.urdf"
    path.write_text(urdf)
    return cp.Robot.from_urdf(path)


@pytest.fixture(scope="module")
def cloud() -> cp.PointCloud:
    """A scan of a thin post that the arm's straight sweep from Q0 to Q1 runs into."""
    pts = cp.synthetic.sample_box_surface(BOX_HALF, 0.005, center=BOX_CENTRE)
    return cp.PointCloud(cp.synthetic.add_noise(pts, SIGMA, seed=7), sigma=SIGMA)


def exact_hits(arm: cp.Robot, path: np.ndarray, steps: int = 101) -> list[tuple[str, float]]:
    """(link, t) where a link's exact mesh meets the exact post along the path's segments."""
    box = cp.ExactShape([cp.Mesh.cuboid(*BOX_HALF)])
    box_pose = np.eye(4)
    box_pose[:3, 3] = BOX_CENTRE
    shapes = {n: cp.ExactShape([m]) for n in arm.link_names if (m := arm.link_mesh(n))}
    hits = []
    for a, b in itertools.pairwise(path):
        ts = np.linspace(0.0, 1.0, steps)
        qs = a + ts[:, None] * (b - a)
        for name, shape in shapes.items():
            poses = np.stack([arm.link_poses(q)[name] for q in qs])
            hit = cp.exact_intersects_many(shape, box, poses, box_pose)
            hits.extend((name, float(t)) for t in ts[hit])
    return hits


def test_the_planner_goes_around_an_obstacle_the_straight_motion_hits(
    ompl: None, arm: cp.Robot, cloud: cp.PointCloud
) -> None:
    from cloudprox.planning import plan

    assert not cp.check_motion(arm, Q0, Q1, cloud, max_probability=0.1).safe
    assert exact_hits(arm, np.stack([Q0, Q1]))  # the straight sweep hits the exact post
    result = plan(arm, cloud, Q0, Q1, seed=1, time_limit=20.0, max_probability=0.1)
    assert result.solved and result.path is not None
    path = result.path
    assert len(path) >= 3  # not the straight motion
    np.testing.assert_allclose(path[0], Q0)
    np.testing.assert_allclose(path[-1], Q1)
    assert result.states_checked > 0 and result.motions_checked > 0
    assert np.isfinite(result.length) and result.length > np.linalg.norm(Q1 - Q0)
    lim = arm.joint_limits
    assert np.all(path >= lim[:, 0] - 1e-9) and np.all(path <= lim[:, 1] + 1e-9)
    for a, b in itertools.pairwise(path):
        m = cp.check_motion(arm, a, b, cloud, max_probability=0.1)
        assert m.safe and m.probability <= 0.1
    for q in path:
        assert cp.collide_robot(arm, q, cloud).probability <= 0.1
    # Against the exact scene: no link meets the exact post anywhere along the path.
    assert exact_hits(arm, path) == []


def test_a_tighter_constraint_keeps_the_path_farther_from_the_points(
    ompl: None, arm: cp.Robot, cloud: cp.PointCloud
) -> None:
    from cloudprox.planning import ChanceConstraint

    loose = ChanceConstraint(arm, cloud, max_probability=0.5)
    tight = ChanceConstraint(arm, cloud, max_probability=1e-6)
    # Swing link 2 towards the post's side until the loose constraint rejects it:
    # the tight one has rejected it earlier.
    first = {}
    for name, c in (("loose", loose), ("tight", tight)):
        for a in np.linspace(-0.6, 0.0, 241):
            if not c.state_valid(np.array([a, 0.0, 0.0, 0.0])):
                first[name] = a
                break
    assert first["tight"] < first["loose"]
    assert loose.states_checked > 0 and tight.states_checked > 0
    assert not tight.motion_valid(Q0, Q1) and tight.motions_checked == 1


def test_stopping_at_the_collision_threshold_keeps_the_constraint_answer(
    ompl: None, arm: cp.Robot, cloud: cp.PointCloud
) -> None:
    from cloudprox.planning import ChanceConstraint

    # Link 2 swept through the post and out: free, grazing and deep states.
    qs = [np.array([a, b, 0.0, 0.0]) for a in np.linspace(-0.6, 0.6, 13) for b in (0.0, -0.2)]
    for p in (0.01, 0.1):
        fast = ChanceConstraint(arm, cloud, max_probability=p)
        full = ChanceConstraint(arm, cloud, max_probability=p, decide_only=False)
        assert fast.state_options["decide_only"] and not full.state_options["decide_only"]
        answers = [fast.state_valid(q) for q in qs]
        assert answers == [full.state_valid(q) for q in qs]
        assert any(answers) and not all(answers)


def test_the_constraint_installed_in_an_ompl_setup_of_ones_own(
    ompl: None, arm: cp.Robot, cloud: cp.PointCloud
) -> None:
    import ompl.base as ob
    import ompl.geometric as og

    from cloudprox.planning import ChanceConstraint

    space = ob.RealVectorStateSpace(arm.dof)
    bounds = ob.RealVectorBounds(arm.dof)
    for i, (lo, hi) in enumerate(arm.joint_limits):
        bounds.setLow(i, float(lo))
        bounds.setHigh(i, float(hi))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    info = setup.getSpaceInformation()
    constraint = ChanceConstraint(arm, cloud, max_probability=0.1)
    constraint.install(info)

    def state(q: np.ndarray) -> object:
        s = space.allocState()
        for i, v in enumerate(q):
            s[i] = float(v)
        return s

    through = np.array([0.0, 0.0, 0.0, 0.0])  # link 2 inside the post
    assert info.isValid(state(Q0)) and not info.isValid(state(through))
    assert not info.checkMotion(state(Q0), state(Q1))
    above = np.array([-0.6, -0.5, 0.0, 0.0])
    assert info.checkMotion(state(Q0), state(above))
    assert constraint.states_checked == 2 and constraint.motions_checked == 2


def test_bad_planning_input(ompl: None, arm: cp.Robot, cloud: cp.PointCloud) -> None:
    from cloudprox.planning import ChanceConstraint, plan, plan_joint_space

    with pytest.raises(ValueError, match="q_goal is not valid"):
        plan(arm, cloud, Q0, [0.0, 0, 0, 0], time_limit=1.0)
    with pytest.raises(ValueError, match="unknown OMPL planner"):
        plan(arm, cloud, Q0, Q1, planner="Nope", time_limit=1.0)
    with pytest.raises(ValueError, match="time_limit"):
        plan(arm, cloud, Q0, Q1, time_limit=0.0)
    with pytest.raises(ValueError, match="max_probability"):
        ChanceConstraint(arm, cloud, max_probability=1.5)
    with pytest.raises(ValueError, match="decide_only needs max_probability"):
        ChanceConstraint(arm, cloud, max_probability=0.95, decide_only=True)
    request = cp.CollisionRequest(decide_only=True, threshold_collision=0.6)
    with pytest.raises(ValueError, match=r"threshold_collision \(0.6\)"):
        ChanceConstraint(arm, cloud, max_probability=0.7, request=request)
    # A request's own settings are kept (no automatic decide_only).
    kept = ChanceConstraint(arm, cloud, max_probability=0.05, request=cp.CollisionRequest())
    assert kept.state_options == {"request": cp.CollisionRequest()}
    with pytest.raises(ValueError, match=r"q_start must have shape \(4,\)"):
        plan(arm, cloud, [0.0, 0.0], Q1, time_limit=1.0)
    with pytest.raises(ValueError, match="finite joint limits"):
        plan_joint_space(
            [[0.0, np.inf]], lambda q: True, lambda a, b: True, [0.0], [1.0], time_limit=1.0
        )
    with pytest.raises(cp.InvalidInputError, match="unknown"):
        plan(arm, cloud, Q0, Q1, time_limit=1.0, no_such_option=1)


@pytest.mark.parametrize("planner", ["RRTConnect", "KPIECE1"])
def test_plan_joint_space_with_plain_checks_is_reproducible(ompl: None, planner: str) -> None:
    from cloudprox.planning import plan_joint_space

    # A square with a disc in the middle: the straight motion from left to right
    # crosses the disc; a motion is checked by 200 states on it.
    def state_valid(q: np.ndarray) -> bool:
        return bool(np.hypot(q[0], q[1]) > 0.3)

    def motion_valid(a: np.ndarray, b: np.ndarray) -> bool:
        return all(state_valid(a + t * (b - a)) for t in np.linspace(0.0, 1.0, 200))

    lim = [[-1.0, 1.0], [-1.0, 1.0]]
    runs = [
        plan_joint_space(
            lim, state_valid, motion_valid, [-0.9, 0.0], [0.9, 0.0], seed=3, planner=planner
        )
        for _ in range(2)
    ]
    for r in runs:
        assert r.solved and r.path is not None
        assert all(motion_valid(a, b) for a, b in zip(r.path[:-1], r.path[1:], strict=False))
        assert r.length > 1.8
    np.testing.assert_array_equal(runs[0].path, runs[1].path)


# ------------------------------------------------------------------ README


def test_readme_robot_planning(ompl: None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from cloudprox.examples import write_example_files

    urdf = panda_urdf_or_skip()
    shutil.copytree(urdf.parent, tmp_path / "panda")
    write_example_files(tmp_path / "example")
    monkeypatch.chdir(tmp_path)
    code = readme_block("robot-python") + readme_block("robot-planning")
    namespace: dict[str, object] = {}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), namespace)
    assert out.getvalue().splitlines()[-1] == "True"
    robot, scan, base = namespace["robot"], namespace["scan"], namespace["base"]
    path = namespace["result"].path  # type: ignore[attr-defined]
    q0, q1 = np.asarray(namespace["q0"]), np.asarray(namespace["q1"])
    np.testing.assert_allclose(path[[0, -1]], [q0, q1])
    # The straight motion leaves the constraint (the hand sweeps through the box);
    # every segment of the plan keeps it.
    assert not cp.check_motion(robot, q0, q1, scan, base, max_probability=0.01).safe
    for a, b in itertools.pairwise(path):
        assert cp.check_motion(robot, a, b, scan, base, max_probability=0.01).safe
