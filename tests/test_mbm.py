"""The MotionBenchMaker harness (``benches/mbm``) on a tiny synthetic problem.

No network and no planning: the parsing of MoveIt scenes and requests (from
an archive made here), the primitives' geometry (areas, samples, inside
tests, ray casting), both sensor clouds, the URDF fix, the motion bound
against cloudprox's ``check_motion``, the python-fcl checkers and the tables.
"""

from __future__ import annotations

import io
import json
import math
import sys
import tarfile
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))

pytest.importorskip("yaml")

from mbm import checkers, fetch, run, scene, sensor

SCENE_YAML = """
robot_model_name: tiny
world:
  collision_objects:
    - id: table
      primitives:
        - type: box
          dimensions: [1.0, 0.8, 0.04]
      primitive_poses:
        - position: [0.8, 0.0, 0.2]
          orientation: [0, 0, 0, 1]
    - primitive_poses:
        - orientation: [0, 0, 0.7071067811865476, 0.7071067811865476]
          position: [0.1, 0.0, 0.0]
        - position: [-0.1, 0.0, 0.0]
          orientation: [0, 0, 0, 1]
      pose:
        position: [0.7, 0.1, 0.3]
        orientation: [0, 0, 0, 1]
      id: cans
      primitives:
        - dimensions: [0.12, 0.03]
          type: cylinder
        - type: sphere
          dimensions: [0.04]
allowed_collision_matrix:
  entry_names: [base, link1, link2]
  entry_values:
    - [false, true, false]
    - [true, false, false]
    - [false, false, false]
"""

REQUEST_YAML = """
start_state:
  joint_state:
    name: [j1, j2, j3, finger]
    position: [0.1, -0.2, 0.05, 0.04]
goal_constraints:
  - joint_constraints:
      - joint_name: j1
        position: 1.0
      - position: 0.5
        joint_name: j2
planner_id: RRTConnect
"""

TINY_URDF = """<?xml version="1.0"?>
<robot name="tiny">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="link1"><collision><origin xyz="0 0 0.15"/>
    <geometry><box size="0.05 0.05 0.3"/></geometry></collision></link>
  <link name="link2"><collision><origin xyz="0.2 0 0"/>
    <geometry><box size="0.4 0.04 0.04"/></geometry></collision></link>
  <link name="link3"><collision><geometry><box size="0.04 0.04 0.04"/></geometry></collision></link>
  <link name="finger"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j3" type="prismatic"><parent link="link2"/><child link="link3"/>
    <origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="fix" type="fixed"><parent link="link3"/><child link="finger"/>
    <origin xyz="0 0 0.02"/><mimic joint="j1"/></joint>
</robot>
"""

JOINTS = ["j1", "j2", "j3"]


def archive(robot: str = "tiny", scenarios: tuple[str, ...] = ("shelf", "table")) -> bytes:
    """A problems.tar.bz2 of two problems per scenario."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:bz2") as tar:
        for s in scenarios:
            for i in (2, 1):
                for kind, text in (("scene", SCENE_YAML), ("request", REQUEST_YAML)):
                    data = text.encode()
                    info = tarfile.TarInfo(f"problems/{s}_{robot}/{kind}{i:04d}.yaml")
                    info.size = len(data)
                    tar.addfile(info, io.BytesIO(data))
        info = tarfile.TarInfo("problems/README")
        info.size = 2
        tar.addfile(info, io.BytesIO(b"hi"))
    return buf.getvalue()


@pytest.fixture(scope="module")
def tiny_scene() -> scene.Scene:
    import yaml

    return scene.parse_scene(yaml.safe_load(SCENE_YAML), "table", 1)


@pytest.fixture(scope="module")
def tiny_robot(tmp_path_factory: pytest.TempPathFactory) -> tuple[cp.Robot, Path]:
    text, fixes = fetch.loadable_urdf(TINY_URDF)
    assert fixes == ["dropped the mimic of fixed joint fix"]
    path = tmp_path_factory.mktemp("mbm") / "tiny.urdf"
    path.write_text(text)
    return cp.Robot.from_urdf(path), path


# ---------------------------------------------------------------- parsing


def test_parse_pose_quaternion_xyzw() -> None:
    p = scene.parse_pose(
        {"position": [1, 2, 3], "orientation": [0, 0, math.sqrt(0.5), math.sqrt(0.5)]}
    )
    np.testing.assert_allclose(p[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    np.testing.assert_allclose(p[:3, 3], [1, 2, 3])
    np.testing.assert_allclose(scene.parse_pose(None), np.eye(4))
    with pytest.raises(ValueError, match="degenerate"):
        scene.parse_pose({"orientation": [0, 0, 0, 0]})


def test_parse_scene(tiny_scene: scene.Scene) -> None:
    names = [o.name for o in tiny_scene.objects]
    assert names == ["table", "cans/0", "cans/1"]
    table, can, ball = tiny_scene.objects
    assert table.kind == "box" and table.dimensions == (1.0, 0.8, 0.04)
    # the object pose composes with the primitive pose
    np.testing.assert_allclose(can.pose[:3, 3], [0.8, 0.1, 0.3])
    np.testing.assert_allclose(ball.pose[:3, 3], [0.6, 0.1, 0.3])
    np.testing.assert_allclose(can.pose[:3, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(can.half_extents, [0.03, 0.03, 0.06])
    assert tiny_scene.allows("base", "link1") and tiny_scene.allows("link1", "base")
    assert not tiny_scene.allows("base", "link2")
    lo, hi = tiny_scene.bounds()
    np.testing.assert_allclose(lo, [0.3, -0.4, 0.18])
    np.testing.assert_allclose(hi, [1.3, 0.4, 0.36])


def test_parse_scene_rejects_what_it_cannot_hold() -> None:
    base = {"id": "x", "primitive_poses": [{}]}
    with pytest.raises(ValueError, match="unsupported primitive type 'cone'"):
        scene.parse_scene(
            {
                "world": {
                    "collision_objects": [
                        {**base, "primitives": [{"type": "cone", "dimensions": [1, 1]}]}
                    ]
                }
            }
        )
    with pytest.raises(ValueError, match="meshes"):
        scene.parse_scene(
            {"world": {"collision_objects": [{**base, "meshes": [{}], "primitives": []}]}}
        )
    with pytest.raises(ValueError, match="needs 3 dimensions"):
        scene.parse_scene(
            {
                "world": {
                    "collision_objects": [
                        {**base, "primitives": [{"type": "box", "dimensions": [1]}]}
                    ]
                }
            }
        )
    with pytest.raises(ValueError, match="2 primitives but 1"):
        scene.parse_scene(
            {
                "world": {
                    "collision_objects": [
                        {**base, "primitives": [{"type": "sphere", "dimensions": [1]}] * 2}
                    ]
                }
            }
        )
    empty = scene.parse_scene({})
    assert empty.objects == [] and empty.allowed == frozenset()


def test_parse_request() -> None:
    import yaml

    start, goal, dropped = scene.parse_request(yaml.safe_load(REQUEST_YAML), JOINTS)
    np.testing.assert_allclose(start, [0.1, -0.2, 0.05])
    np.testing.assert_allclose(goal, [1.0, 0.5, 0.05])  # j3 keeps its start value
    assert dropped == ["finger"]
    unnamed = {
        "start_state": {"joint_state": {"position": [1, 2, 3]}},
        "goal_constraints": [{"joint_constraints": [{"joint_name": "j3", "position": 9}]}],
    }
    start, goal, dropped = scene.parse_request(unnamed, JOINTS)
    np.testing.assert_allclose(goal, [1, 2, 9])
    assert dropped == []
    with pytest.raises(ValueError, match="lacks the robot's joints"):
        scene.parse_request(
            {"start_state": {"joint_state": {"name": ["j1"], "position": [0]}}}, JOINTS
        )
    with pytest.raises(ValueError, match="no joint goal"):
        scene.parse_request({"start_state": {"joint_state": {"position": [1, 2, 3]}}}, JOINTS)


def test_load_problems_from_archive(tmp_path: Path) -> None:
    data = archive()
    names = tarfile.open(fileobj=io.BytesIO(data)).getnames()
    files = scene.problem_files(names, "tiny")
    assert list(files) == ["shelf", "table"] and list(files["shelf"]) == [1, 2]
    problems = scene.load_problems(data, "tiny", JOINTS)
    assert [p.name for p in problems] == ["shelf/0001", "shelf/0002", "table/0001", "table/0002"]
    path = tmp_path / "problems.tar.bz2"
    path.write_bytes(data)
    one = scene.load_problems(path, "tiny", JOINTS, scenarios=["table"], per_scenario=1)
    assert [p.name for p in one] == ["table/0001"]
    assert len(one[0].scene.objects) == 3 and one[0].dropped_joints == ["finger"]
    with pytest.raises(ValueError, match=r"\['desk'\] are not in the archive"):
        scene.load_problems(data, "tiny", JOINTS, scenarios=["desk"])
    assert scene.load_problems(data, "other", JOINTS) == []


# ---------------------------------------------------------------- geometry


@pytest.mark.parametrize("which", [0, 1, 2])
def test_primitive_area_samples_and_inside(tiny_scene: scene.Scene, which: int) -> None:
    prim = tiny_scene.objects[which]
    expected = {
        0: 2 * (0.8 + 0.032 + 0.04),
        1: 2 * math.pi * 0.03 * 0.12 + 2 * math.pi * 0.03**2,
        2: 4 * math.pi * 0.04**2,
    }[which]
    assert prim.area == pytest.approx(expected)
    rng = np.random.default_rng(1)
    pts = prim.sample_surface(4000, rng)
    np.testing.assert_allclose(prim.signed_distance(pts), 0.0, atol=1e-12)
    assert not prim.contains(pts).any()
    lo, hi = prim.bounds()
    assert np.all(pts >= lo - 1e-12) and np.all(pts <= hi + 1e-12)
    # points pushed inward along the signed distance's gradient are inside
    centre = prim.pose[:3, 3]
    assert prim.contains(centre[None])[0]
    assert prim.signed_distance(centre[None])[0] < 0


def test_box_sampling_is_uniform_by_area() -> None:
    box = scene.Primitive("b", "box", (0.4, 0.2, 0.1), np.eye(4))
    pts = box.sample_surface(60_000, np.random.default_rng(0))
    on_z = np.isclose(np.abs(pts[:, 2]), 0.05).mean()
    assert on_z == pytest.approx(2 * 0.4 * 0.2 / box.area, abs=0.01)


def test_ray_distances_match_the_signed_distance(tiny_scene: scene.Scene) -> None:
    rng = np.random.default_rng(2)
    origin = np.array([0.0, 0.0, 1.0])
    for prim in tiny_scene.objects:
        # rays towards points of the surface and beside it
        targets = prim.sample_surface(300, rng) + rng.normal(0.0, 0.01, (300, 3))
        d = targets - origin
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        t = prim.ray_distances(origin, d)
        hit = np.isfinite(t)
        assert hit.mean() > 0.3
        np.testing.assert_allclose(
            prim.signed_distance(origin + t[hit, None] * d[hit]), 0.0, atol=1e-9
        )
        # nothing of the solid before the first hit: sample along the rays
        for frac in (0.25, 0.5, 0.9, 0.999):
            before = origin + (frac * t[hit])[:, None] * d[hit]
            assert np.all(prim.signed_distance(before) > -1e-12)
        # misses: the ray never enters the solid
        miss = ~hit
        for s in np.linspace(0.0, 3.0, 61):
            assert not prim.contains(origin + s * d[miss]).any()


def test_cast_agrees_with_brute_force(tiny_scene: scene.Scene) -> None:
    pose = cp.pose.look_at(np.array([-0.3, 0.2, 1.2]), np.array([0.8, 0.0, 0.25]))
    dirs, _ = sensor.pinhole_rays(pose, 64, 48, 50.0)
    a = sensor.cast(tiny_scene, pose, 64, 48, 50.0, dirs)
    b = tiny_scene.ray_distances(pose[:3, 3], dirs)
    assert np.isfinite(a).sum() > 100
    np.testing.assert_array_equal(a, b)


def test_camera_scan(tiny_scene: scene.Scene) -> None:
    sc = sensor.camera_scan(tiny_scene, target=3000, seed=3, position=(-0.3, 0.0, 1.2))
    n = len(sc.points)
    assert sc.kind == "camera" and 2000 <= n <= 4500 and len(sc.cloud) == n
    np.testing.assert_allclose(tiny_scene.signed_distance(sc.exact), 0.0, atol=1e-9)
    cov = np.asarray(sc.cloud.covariances)
    assert cov.shape == (n, 3, 3)
    # Kinect axial noise at ~1.1 m: 0.0012 + 0.0019 (z - 0.4)^2, about 2 mm
    depth = (sc.exact - sc.sensor_pose[:3, 3]) @ sc.sensor_pose[:3, 2]
    axial = 0.0012 + 0.0019 * (depth - 0.4) ** 2
    err = (sc.points - sc.exact) @ sc.sensor_pose[:3, 2]
    assert np.std(err / axial) == pytest.approx(1.0, abs=0.15)
    assert sc.info["points"] == n and sc.info["median_sigma"] > 0.001
    again = sensor.camera_scan(tiny_scene, target=3000, seed=3, position=(-0.3, 0.0, 1.2))
    np.testing.assert_array_equal(again.points, sc.points)


def test_camera_that_sees_nothing_says_so(tiny_scene: scene.Scene) -> None:
    far = scene.Scene("x", 1, [scene.Primitive("b", "box", (0.1, 0.1, 0.1), np.eye(4))])
    with pytest.raises(ValueError, match="no return within the Kinect's range"):
        sensor.camera_scan(far, target=500, position=(0.0, 0.0, 0.3))


def test_area_scan_drops_hidden_surface() -> None:
    outer = scene.Primitive("outer", "box", (0.4, 0.4, 0.4), np.eye(4))
    inner = scene.Primitive("inner", "sphere", (0.1,), np.eye(4))  # wholly inside
    sc = sensor.area_scan(scene.Scene("s", 1, [outer, inner]), n=5000, sigma=0.002, seed=4)
    assert len(sc.points) == 5000
    np.testing.assert_allclose(outer.signed_distance(sc.exact), 0.0, atol=1e-12)
    assert sc.info["hidden_share"] == pytest.approx(
        inner.area / (inner.area + outer.area), abs=0.02
    )
    assert np.std(sc.points - sc.exact) == pytest.approx(0.002, rel=0.05)
    np.testing.assert_allclose(np.asarray(sc.cloud.covariances)[0], 0.002**2 * np.eye(3))


# ---------------------------------------------------------------- fetch


def test_loadable_urdf_keeps_mimics_of_moving_joints() -> None:
    text = (
        '<robot name="r"><joint name="a" type="revolute"><mimic joint="b"/></joint>'
        '<joint name="f" type="fixed"><mimic joint="a"></mimic></joint></robot>'
    )
    fixed, fixes = fetch.loadable_urdf(text)
    assert fixes == ["dropped the mimic of fixed joint f"]
    assert '<mimic joint="b"/>' in fixed and '<mimic joint="a">' not in fixed
    assert fetch.loadable_urdf(fixed) == (fixed, [])


def test_sdist_with_wrong_digest_is_refused(tmp_path: Path) -> None:
    (tmp_path / fetch.SDIST).write_bytes(b"not the sdist")
    with pytest.raises(fetch.MbmUnavailable, match="differs from the published"):
        fetch.fetch_sdist(tmp_path)


def test_failing_download_says_how_to_fetch_by_hand(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pip = tmp_path / "pip"
    pip.write_text("#!/bin/sh\necho 'ERROR: Could not find a version (no network)' >&2\nexit 1\n")
    pip.chmod(0o755)
    monkeypatch.setattr(fetch, "_venv", lambda folder: pip)
    with pytest.raises(fetch.MbmUnavailable) as info:
        fetch.fetch_sdist(tmp_path)
    msg = str(info.value)
    assert "cannot download the vamp-planner==0.6.4 sdist" in msg
    assert "no network" in msg and "--no-build-isolation" in msg and fetch.SDIST_SHA256 in msg
    with pytest.raises(ValueError, match="unknown robot 'kuka'"):
        fetch.fetch_robot("kuka", tmp_path)


# ---------------------------------------------------------------- checkers


def test_motion_bound_matches_check_motion(tiny_robot: tuple[cp.Robot, Path]) -> None:
    robot, path = tiny_robot
    bound = checkers.MotionBound(robot, path)
    cloud = cp.PointCloud(np.array([[2.0, 2.0, 2.0], [2.1, 2.0, 2.0]]), sigma=0.001)
    rng = np.random.default_rng(5)
    lim = robot.joint_limits
    for _ in range(5):
        q0, q1 = rng.uniform(lim[:, 0], lim[:, 1]), rng.uniform(lim[:, 0], lim[:, 1])
        m = cp.check_motion(robot, q0, q1, cloud, resolution=0.01, max_probability=1.0)
        assert m.states_total == bound.steps(q0, q1, 0.01) + 1


@pytest.mark.parametrize("n", [1, 2, 3, 8, 13])
def test_bisection_order(n: int) -> None:
    order = checkers.bisection_order(n)
    assert sorted(order) == list(range(1, n))
    if n > 2:
        assert order[0] == n // 2


def test_discrete_motion_checks_the_end_first(tiny_robot: tuple[cp.Robot, Path]) -> None:
    robot, path = tiny_robot
    bound = checkers.MotionBound(robot, path)
    seen: list[float] = []

    def state(q: np.ndarray) -> bool:
        seen.append(float(q[0]))
        return True

    valid = checkers.discrete_motion(state, bound, 0.05)
    q0, q1 = np.zeros(3), np.array([1.0, 0.0, 0.0])
    assert valid(q0, q1)
    n = bound.steps(q0, q1, 0.05)
    assert seen[0] == 1.0 and len(seen) == n == valid.states
    assert 0.0 not in seen


def test_fcl_checkers(tiny_robot: tuple[cp.Robot, Path], tiny_scene: scene.Scene) -> None:
    pytest.importorskip("fcl")
    robot, path = tiny_robot
    # link2 (0.4 m along x at 0.35 m height when j2 = 0) against a box above the base
    block = scene.Primitive(
        "block", "box", (0.1, 0.1, 0.1), scene.parse_pose({"position": [0.3, 0, 0.35]})
    )
    exact = checkers.FclChecker(robot, [block.fcl_object()], ["block"])
    assert exact.collides(np.zeros(3))
    assert exact.colliding_pairs(np.zeros(3)) == [("link2", "block")]
    up = np.array([0.0, -1.2, 0.0])  # link2 raised
    assert not exact.collides(up)
    d, _, obj = exact.nearest(up)
    assert d > 0.0 and obj == "block" and exact.distance(up) == pytest.approx(d, abs=1e-6)
    bound = checkers.MotionBound(robot, path)
    hit = checkers.first_collision(exact, bound, np.array([up, np.zeros(3)]), 0.002)
    assert hit is not None and hit[0] == 0 and 0.0 < hit[1] <= 1.0
    assert (
        checkers.first_collision(exact, bound, np.array([up, up + np.array([0.5, 0, 0])]), 0.002)
        is None
    )
    contacts = exact.contacts(np.zeros(3))
    assert len(contacts) > 0 and np.all(block.signed_distance(contacts) < 1e-6)
    colliding, where, at = run.validate_path(exact, bound, np.array([up, np.zeros(3)]), 0.002)
    assert colliding and "link2-block" in where and where.startswith("segment 1/1")
    assert len(at) > 0
    assert run.validate_path(exact, bound, np.array([up, up]), 0.002)[0] is False
    # the collision map of a sampled block collides where the block does
    pts = block.sample_surface(3000, np.random.default_rng(0))
    centres = checkers.voxel_centres(pts, 0.02)
    assert np.all(np.abs(centres - block.pose[:3, 3]) <= 0.05 + 0.02)
    cmap = checkers.FclChecker(robot, checkers.voxel_boxes(pts, 0.02))
    assert cmap.collides(np.zeros(3)) and not cmap.collides(up)


# ---------------------------------------------------------------- tables


def test_summary_and_markdown() -> None:
    runs = []
    for i, (ok_exact, t_exact) in enumerate([(True, 1.0), (True, 2.0), (False, 5.0)]):
        prob = f"table/{i + 1:04d}"
        runs.append(
            run.RunRecord(
                prob,
                "table",
                "exact (python-fcl, primitives)",
                "exact",
                "-",
                True,
                solved=ok_exact,
                planning_time=t_exact,
                colliding=False if ok_exact else None,
            )
        )
        refused = i == 2
        runs.append(
            run.RunRecord(
                prob,
                "table",
                "cloudprox P<=0.01 (area)",
                "cloudprox",
                "area",
                not refused,
                refused="goal" if refused else "",
                p_goal=0.2 if refused else 0.0,
                solved=not refused,
                planning_time=2.0 * t_exact if not refused else math.nan,
                colliding=False if not refused else None,
                states_checked=10,
                motion_states=90,
                motions_checked=3,
                state_seconds=0.01,
                motion_seconds=0.09,
            )
        )
    s = {row["checker"]: row for row in run.summary(runs)}
    cpx = s["cloudprox P<=0.01 (area)"]
    assert (cpx["admitted"], cpx["solved"], cpx["exact_solved_same"], cpx["exact_on_same"]) == (
        2,
        2,
        2,
        2,
    )
    assert cpx["median_planning_time"] == pytest.approx(3.0)
    assert cpx["exact_median_same"] == pytest.approx(1.5)
    assert cpx["median_ratio_both_solved"] == pytest.approx(2.0)
    assert cpx["refused"] == {"goal": 1}
    assert cpx["seconds_per_checked_state"] == pytest.approx(0.2 / 200)
    assert s["exact (python-fcl, primitives)"]["solved"] == 2
    args = vars(run.parse_args(["--problems", "1", "--clouds", "area"]))
    scenes = [
        {
            "problem": f"table/{i:04d}",
            "start_clearance": 0.1,
            "goal_clearance": 0.01,
            "goal_nearest": "hand-can",
            "probe": {},
            "clouds": {
                "area": {
                    "p_start": 0.0,
                    "p_goal": 0.2,
                    "goal_link": "hand",
                    "points": 100,
                    "median_sigma": 0.003,
                    "sample_seconds": 0.1,
                    "cloud_seconds": 0.1,
                    "first_check_seconds": 0.2,
                    "second_check_seconds": 0.001,
                    "map_10mm_boxes": 50,
                }
            },
        }
        for i in (1, 2, 3)
    ]
    result = {
        "source": "test",
        "args": args,
        "n_problems": 3,
        "date": "today",
        "command": "cmd",
        "machine": {
            "cpu": "cpu",
            "cores": 2,
            "rayon_threads": "1",
            "python": "3",
            "versions": {"cloudprox": "0", "ompl": "0", "python-fcl": "0"},
        },
        "summary": run.summary(runs),
        "runs": [run.asdict(r) for r in runs],
        "scenes": scenes,
        "notes": ["a note"],
    }
    md = run.markdown(json.loads(json.dumps(result)))
    row = "| cloudprox P<=0.01 (area) | 2/3 | 2/2 (100 %) | 2/2 (100 %) | 3.00 | 1.50 | 2.0x |"
    assert row + " 0/2 | goal: 1 |" in md
    assert "| table/0001 | 100.0 | 10.0 | hand-can | 0 / 0.2 (hand) |" in md
    assert "- a note" in md


def test_parse_args_checks() -> None:
    a = run.parse_args(["--thresholds", "0.5,0.01", "--voxel", "0.01,0.02", "--camera", "1,2,3"])
    assert a.thresholds == [0.5, 0.01] and a.voxel == [0.01, 0.02] and a.camera == [1.0, 2.0, 3.0]
    for bad in (
        ["--clouds", "lidar"],
        ["--camera", "1,2"],
        ["--thresholds", "1.0"],
        ["--problems", "0"],
    ):
        with pytest.raises(SystemExit):
            run.parse_args(bad)


class _FakeRobot:
    def self_collisions(self, q: np.ndarray) -> list[tuple[str, str]]:
        return [("a", "b")] if q[0] > 0 else []


def test_self_collision_check_leaves_out_allowed_pairs() -> None:
    robot = _FakeRobot()
    strict = checkers.self_collision_check(robot)  # type: ignore[arg-type]
    lenient = checkers.self_collision_check(robot, {frozenset(("b", "a"))})  # type: ignore[arg-type]
    assert strict(np.zeros(1)) and not strict(np.ones(1))
    assert lenient(np.ones(1))
