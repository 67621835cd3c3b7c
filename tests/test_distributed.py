"""cloudprox.distributed against a local Ray of 2 CPUs: equal to the local calls."""

from __future__ import annotations

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.pose import from_translation
from tests.robots import ARM_URDF, wall
from tests.test_pickle import assert_same_result

ray = pytest.importorskip("ray")
from cloudprox import distributed  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


@pytest.fixture(scope="module")
def clouds() -> tuple[cp.PointCloud, cp.PointCloud]:
    base = cp.synthetic.sample_sphere(600, 0.1)
    return (
        cp.PointCloud(
            cp.synthetic.add_noise(base, 0.002, seed=1), sigma=0.002, discretization=True
        ),
        cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=2), sigma=0.002),
    )


def _poses(m: int) -> np.ndarray:
    xs, ys = np.linspace(0.18, 0.24, m), np.linspace(-0.02, 0.02, m)
    return np.stack([from_translation((x, y, 0.0)) for x, y in zip(xs, ys, strict=True)])


def test_collide_many_equals_local(clouds) -> None:
    a, b = clouds
    poses = _poses(150)
    pose_b = from_translation((0.0, 0.0, 0.001))
    local = cp.collide_many(a, b, poses, pose_b)
    # Uneven batches (7 tasks, the last short) on 2 workers: the order is the input's.
    remote = distributed.collide_many(a, b, poses, pose_b, batch_size=22, progress=False)
    assert len(remote) == len(local)
    states = {r.state for r in local}
    assert states >= {"free", "collision"}
    for r, s in zip(local, remote, strict=False):
        assert_same_result(r, s)
    # Options travel too.
    linear = distributed.collide_many(a, b, poses[:20], pose_b, surface="linear", progress=False)
    for r, s in zip(
        cp.collide_many(a, b, poses[:20], pose_b, surface="linear"), linear, strict=False
    ):
        assert_same_result(r, s)


def test_mesh_side_and_default_batches(clouds) -> None:
    a, _ = clouds
    box = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    poses = _poses(40)
    poses[:, 0, 3] -= 0.04
    remote = distributed.collide_many(box, a, poses)
    for r, s in zip(cp.collide_many(box, a, poses), remote, strict=False):
        assert_same_result(r, s)


def test_collide_robot_many_equals_local(tmp_path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM_URDF)
    robot = cp.Robot.from_urdf(path)
    cloud = cp.PointCloud(wall(0.36, 0.3, 0.15, 0.002, seed=3), sigma=0.002)
    rng = np.random.default_rng(0)
    qs = np.column_stack(
        [
            rng.uniform(-0.4, 0.4, 60),
            rng.uniform(-0.5, 0.3, 60),
            rng.uniform(0, 0.1, 60),
            np.zeros(60),
        ]
    )
    local = cp.collide_robot_many(robot, qs, cloud)
    remote = distributed.collide_robot_many(robot, qs, cloud, batch_size=16, progress=False)
    assert len(set(local.states)) >= 2
    np.testing.assert_array_equal(remote.probabilities, local.probabilities)
    np.testing.assert_array_equal(remote.states, local.states)
    np.testing.assert_array_equal(remote.self_colliding, local.self_colliding)
    np.testing.assert_array_equal(remote.link_probabilities, local.link_probabilities)


def test_errors(clouds) -> None:
    a, b = clouds
    with pytest.raises(ValueError, match=r"poses_a must have shape \(m, 4, 4\)"):
        distributed.collide_many(a, b, np.eye(4))
    with pytest.raises(TypeError, match="b must be a cloudprox PointCloud or Mesh"):
        distributed.collide_many(a, np.zeros((5, 3)), _poses(2))
    with pytest.raises(ValueError, match="batch_size must be >= 1"):
        distributed.collide_many(a, b, _poses(2), batch_size=0)
    bad = _poses(40)
    bad[23, :3, :3] *= 2.0  # not a rotation: the worker's query refuses it
    with pytest.raises(
        cp.InvalidInputError,
        match=r"poses 20 to 29 .*count from 20.*poses_a\[3\]: .*not a rotation",
    ):
        distributed.collide_many(a, b, bad, batch_size=10, progress=False)


def test_readme_ray_lines(tmp_path, monkeypatch) -> None:
    import contextlib
    import io

    from cloudprox.examples import write_example_files
    from tests.robots import readme_block

    write_example_files(tmp_path / "example")
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {}
    with contextlib.redirect_stdout(io.StringIO()):
        exec(readme_block("python"), namespace)
    block = readme_block("ray-python")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(block, namespace)
    promised = block.split("# ")[-1].strip()
    assert out.getvalue().strip() == promised
    scan, gripper = namespace["scan"], namespace["gripper"]
    poses = [cp.io.read_pose(f"example/grasp-{k}.txt") for k in ("free", "collision")]
    assert str([r.state for r in cp.collide_many(gripper, scan, poses)]) == promised


def test_reproduce_query_loop_on_ray(tmp_path, monkeypatch) -> None:
    import dataclasses
    import importlib

    from cloudprox.cli import main

    run_module = importlib.import_module("cloudprox.reproduce.run")
    monkeypatch.setattr(run_module, "reconstruction_available", lambda: False)
    config = run_module.Config(
        piano_points=600, poses=12, levels=(0.02,), anisotropic_levels=(), scan_poses=0
    )
    local = run_module.run(config, tmp_path / "local")
    remote = run_module.run(
        config,
        tmp_path / "ray",
        many=lambda *a, **k: distributed.collide_many(*a, progress=False, **k),
    )
    cloudprox_rows = [key for key in local.metrics if key[1].startswith("cloudprox")]
    assert cloudprox_rows
    for key in cloudprox_rows:
        x, y = dataclasses.asdict(local.metrics[key]), dataclasses.asdict(remote.metrics[key])
        x.pop("median_ms"), y.pop("median_ms")
        # The same answers: every score equal (nan where a score is
        # undefined, e.g. no reliability bin of 20 poses).
        assert x.keys() == y.keys(), key
        for name in x:
            same = x[name] == y[name] or (
                isinstance(x[name], float) and np.isnan(x[name]) and np.isnan(y[name])
            )
            assert same, (key, name, x[name], y[name])

    # `cloudprox reproduce --ray` hands distributed.collide_many to the run.
    seen = {}

    def fake_run(config, out, progress, many, workers):
        seen["many"], seen["workers"] = many, workers
        return run_module.Summary(config)

    monkeypatch.setattr(run_module, "run", fake_run)
    assert main(["reproduce", "--quick", "--ray", "--out", str(tmp_path / "cli")]) == 0
    assert seen["many"].func is distributed.collide_many
    # The baselines' processes: every CPU by default, or as asked.
    assert seen["workers"] == run_module.available_cpus()
    assert main(["reproduce", "--quick", "--workers", "1", "--out", str(tmp_path / "w")]) == 0
    assert seen["workers"] == 1
