"""The command line's layout and shared options: the user's commands first in --help, the
query options (thresholds included) on every command that queries, and their checks."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.cli import COMMANDS, DEVELOPMENT, build_parser, main
from cloudprox.pose import from_translation
from tests.robots import wall

SIGMA = 0.002
STATES = ("free", "contact", "collision")
#: The flags of a CollisionRequest that every querying command takes.
REQUEST_FLAGS = {
    "--model",
    "--surface",
    "--aggregation",
    "--solver",
    "--decide-only",
    "--segmentations",
    "--near-context",
    "--threshold-free",
    "--threshold-collision",
}


@pytest.fixture(scope="module")
def spheres(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    """Two noisy samplings of one sphere (radius 0.1 m) as .npy files."""
    d = tmp_path_factory.mktemp("spheres")
    base = cp.synthetic.sample_sphere(600, 0.1)
    paths = []
    for seed in (1, 2):
        path = d / f"s{seed}.npy"
        np.save(path, cp.synthetic.add_noise(base, SIGMA, seed=seed))
        paths.append(str(path))
    return paths[0], paths[1]


@pytest.fixture(scope="module")
def wall_scan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The wall in front of the test arm's tip as a .npy file (read exactly)."""
    path = tmp_path_factory.mktemp("wall") / "wall.npy"
    np.save(path, wall(0.40, 0.3, 0.1, SIGMA, 11))
    return path


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    raise AssertionError("no subcommands")


def _flags(parser: argparse.ArgumentParser) -> set[str]:
    return {flag for action in parser._actions for flag in action.option_strings}


def _collide_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(["collide", *argv, "--sigma", str(SIGMA), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_help_lists_the_users_commands_before_the_development_ones(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["--help"]) == 0
    lines = capsys.readouterr().out.splitlines()
    listed = [line.split()[0] for line in lines if line.startswith("    ") and line.split()]
    order = [name for name in listed if name in COMMANDS + DEVELOPMENT]
    assert order == [*COMMANDS, *DEVELOPMENT]
    assert set(_subcommands(build_parser())) == set(COMMANDS + DEVELOPMENT)
    assert "\n".join(lines).count("[development]") == len(DEVELOPMENT)


@pytest.mark.parametrize("command", ["collide", "view", "robot"])
def test_every_querying_command_takes_the_request_options(command: str) -> None:
    flags = _flags(_subcommands(build_parser())[command])
    assert flags >= REQUEST_FLAGS
    assert flags >= {"--sigma", "--sensor", "--axial-offset", "--sigma-range", "--filter"}


def test_the_demo_takes_the_request_options() -> None:
    assert _flags(_subcommands(build_parser())["demo"]) >= REQUEST_FLAGS


def _demo_states(capsys: pytest.CaptureFixture[str], out: Path, *flags: str) -> list[str]:
    """The state column of ``cloudprox demo --points 2000``'s table."""
    assert main(["demo", "--points", "2000", "--out", str(out), *flags]) == 0
    rows = [line.strip().strip("│").split("│") for line in capsys.readouterr().out.splitlines()]
    return [row[4].strip() for row in rows if len(row) == 7 and row[4].strip() in STATES]


def test_demo_thresholds_and_model_change_the_states_as_the_api_does(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from cloudprox.cli.demo import DEMO_FAR_GAP, DEMO_GAPS_SIGMA
    from cloudprox.scenes import build_scene

    s = 0.005  # the demo's default noise
    scene = build_scene(sigma=s, points=2000, seed=0)
    piano = cp.PointCloud(scene.piano_points, sigma=s)
    room = cp.PointCloud(scene.room_points, sigma=s)
    gaps = [g * s for g in DEMO_GAPS_SIGMA] + [DEMO_FAR_GAP]

    def expected(request: cp.CollisionRequest) -> list[str]:
        return [
            cp.collide(piano, room, pose_a=scene.piano_pose(g), request=request).state for g in gaps
        ]

    default = _demo_states(capsys, tmp_path)
    assert default == expected(cp.CollisionRequest())
    flags = ["--threshold-free", "0.4", "--threshold-collision", "0.5"]
    loose = _demo_states(capsys, tmp_path, *flags)
    assert loose == expected(cp.CollisionRequest(threshold_free=0.4, threshold_collision=0.5))
    assert loose != default  # some contacts of the default thresholds read free or collision
    points = _demo_states(capsys, tmp_path, "--model", "points", *flags)
    request = cp.CollisionRequest(model="points", threshold_free=0.4, threshold_collision=0.5)
    assert points == expected(request)


def test_thresholds_decide_the_state(capsys: pytest.CaptureFixture[str], spheres) -> None:
    a, b = spheres
    # B 2 mm (one sigma) past touching: P between the default thresholds.
    pose = from_translation((0.202, 0.0, 0.0))
    pose_file = Path(b).with_name("pose.npy")
    np.save(pose_file, pose)
    default = _collide_json(capsys, a, b, "--pose-b", str(pose_file))
    p = default["probability"]
    defaults = cp.CollisionRequest()
    assert defaults.threshold_free < p < 0.5 and default["state"] == "contact"

    free = (p + 0.5) / 2.0
    loose = _collide_json(capsys, a, b, "--pose-b", str(pose_file), "--threshold-free", str(free))
    assert loose["state"] == "free"
    assert loose["probability"] == pytest.approx(p, rel=1e-12)  # the same P, read anew

    strict = _collide_json(
        capsys, a, b, "--pose-b", str(pose_file), "--threshold-free", str(p / 2.0)
    )
    assert strict["state"] == "contact"


def test_threshold_collision_turns_contact_into_collision(
    capsys: pytest.CaptureFixture[str], spheres
) -> None:
    a, b = spheres
    pose_file = Path(b).with_name("touching.npy")
    np.save(pose_file, from_translation((0.2, 0.0, 0.0)))
    default = _collide_json(capsys, a, b, "--pose-b", str(pose_file))
    p = default["probability"]
    assert 0.5 < p < cp.CollisionRequest().threshold_collision
    assert default["state"] == "contact"
    low = (p + 0.5) / 2.0
    doc = _collide_json(capsys, a, b, "--pose-b", str(pose_file), "--threshold-collision", str(low))
    assert doc["state"] == "collision"


def test_robot_query_options_reach_the_query(
    capsys: pytest.CaptureFixture[str], arm_path: Path, wall_scan: Path
) -> None:
    q = np.array([0.0, 0.0, 0.05, 0.0])
    options = ["--model", "points", "--threshold-free", "0.2", "--threshold-collision", "0.7"]
    argv = ["robot", str(arm_path), str(wall_scan), "--sigma", str(SIGMA), "--q", "0,0,0.05,0"]
    assert main([*argv, *options, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    request = cp.CollisionRequest(model="points", threshold_free=0.2, threshold_collision=0.7)
    cloud = cp.PointCloud(np.load(wall_scan), sigma=SIGMA)
    expected = cp.collide_robot(cp.Robot.from_urdf(arm_path), q, cloud, request=request)
    assert doc["probability"] == pytest.approx(expected.probability, rel=1e-9, abs=1e-12)
    assert doc["state"] == expected.state
    for name, link in expected.links.items():
        assert doc["links"][name]["state"] == link.state


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (
            ["--threshold-free", "0.4", "--threshold-collision", "0.3"],
            "thresholds out of order: --threshold-free 0.4 is above --threshold-collision 0.3",
        ),
        (["--threshold-free", "0.6"], "--threshold-free must be in [0, 0.5], got 0.6"),
        (["--threshold-free", "-0.1"], "--threshold-free must be in [0, 0.5], got -0.1"),
        (
            ["--threshold-free", "0.95"],
            "--threshold-free 0.95 is above --threshold-collision 0.9",
        ),
        (
            ["--threshold-free", "0.05", "--threshold-collision", "0.45"],
            "--threshold-collision must be in [0.5, 1], got 0.45",
        ),
        (["--threshold-collision", "1.5"], "--threshold-collision must be in [0.5, 1], got 1.5"),
        (["--threshold-collision", "nan"], "--threshold-collision must be a number"),
    ],
)
@pytest.mark.parametrize("command", ["collide", "robot", "demo"])
def test_bad_thresholds_exit_2_with_one_message(
    capsys: pytest.CaptureFixture[str],
    spheres,
    arm_path: Path,
    wall_scan: Path,
    command: str,
    options: list[str],
    message: str,
) -> None:
    if command == "collide":
        argv = ["collide", *spheres, "--sigma", str(SIGMA)]
    elif command == "demo":  # refused before the scene is built or anything written
        argv = ["demo", "--points", "50", "--out", str(wall_scan.parent / "no-demo")]
    else:
        argv = ["robot", str(arm_path), str(wall_scan), "--sigma", str(SIGMA), "--q", "0,0,0,0"]
    assert main([*argv, *options]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (wall_scan.parent / "no-demo").exists()


def test_thresholds_at_their_limits_are_accepted(
    capsys: pytest.CaptureFixture[str], spheres
) -> None:
    # free = collision = 0.5: every P reads free or collision, never contact.
    a, b = spheres
    pose_file = Path(b).with_name("limits.npy")
    np.save(pose_file, from_translation((0.202, 0.0, 0.0)))
    limits = ["--threshold-free", "0.5", "--threshold-collision", "0.5"]
    doc = _collide_json(capsys, a, b, "--pose-b", str(pose_file), *limits)
    assert doc["state"] == ("free" if doc["probability"] <= 0.5 else "collision")


def test_robot_padding_and_shadow_reach_the_query(
    capsys: pytest.CaptureFixture[str], arm_path: Path, wall_scan: Path
) -> None:
    q = np.array([0.0, 0.0, 0.05, 0.0])
    argv = ["robot", str(arm_path), str(wall_scan), "--sigma", str(SIGMA), "--q", "0,0,0.05,0"]
    robot = cp.Robot.from_urdf(arm_path)
    cloud = cp.PointCloud(np.load(wall_scan), sigma=SIGMA)
    origin = [1.0, 0.0, 0.3]
    shadow = cp.filters.Occlusion(cloud, origin)
    for options, kwargs in (
        (["--padding", "0.02"], {"padding": 0.02}),
        (["--shadow", "--origin", "1,0,0.3"], {"shadow": shadow}),
        (
            ["--shadow", "--origin", "1,0,0.3", "--shadow-depth", "0.5"],
            {"shadow": shadow, "shadow_depth": 0.5},
        ),
    ):
        assert main([*argv, *options, "--json"]) == 0
        doc = json.loads(capsys.readouterr().out)
        expected = cp.collide_robot(robot, q, cloud, **kwargs)  # type: ignore[arg-type]
        assert doc["probability"] == pytest.approx(expected.probability, rel=1e-9, abs=1e-12)
    bare = cp.collide_robot(robot, q, cloud).probability
    deep = cp.collide_robot(robot, q, cloud, shadow=shadow, shadow_depth=0.5).probability
    assert deep > bare  # the links behind the wall, seen from x = 1, are in its shadow


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--shadow"], "the sensor origin is unknown"),
        (["--shadow-depth", "0.1"], "--shadow-depth needs --shadow"),
    ],
)
def test_robot_shadow_without_what_it_needs_exits_2(
    capsys: pytest.CaptureFixture[str],
    arm_path: Path,
    wall_scan: Path,
    options: list[str],
    message: str,
) -> None:
    argv = ["robot", str(arm_path), str(wall_scan), "--sigma", str(SIGMA), "--q", "0,0,0,0"]
    assert main([*argv, *options]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
