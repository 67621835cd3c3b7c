"""Robot links as exact sides (``mesh_side="exact"``, the default) or sampled clouds."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from tests.robots import wall

SIGMA = 0.002


@pytest.fixture(scope="module")
def cloud() -> cp.PointCloud:
    """The plane x = 0.40 in front of the arm's tip (link3's sphere reaches x = 0.33 + j3)."""
    return cp.PointCloud(wall(0.40, 0.3, 0.1, SIGMA, 1), sigma=SIGMA)


@pytest.mark.parametrize("model", ["elements", "points"])
def test_exact_and_sampled_links_agree_where_the_answer_is_clear(
    arm: cp.Robot, cloud: cp.PointCloud, model: str
) -> None:
    # Free (the tip 3.5 cm from the wall, 17 sigma) and pushed 3 cm into it.
    for q, expected in [([0, 0, 0, 0], "free"), ([0, 0, 0.1, 0], "collision")]:
        for side in ("exact", "sampled"):
            r = cp.collide_robot(arm, q, cloud, mesh_side=side, model=model)
            assert r.state == expected, (side, q, r.probability)


def test_exact_links_are_the_default_and_train_nothing(arm: cp.Robot, cloud: cp.PointCloud) -> None:
    q = [0.0, 0.0, 0.1, 0.0]
    default = cp.collide_robot(arm, q, cloud, model="points")
    exact = cp.collide_robot(arm, q, cloud, mesh_side="exact", model="points")
    sampled = cp.collide_robot(arm, q, cloud, mesh_side="sampled", model="points")
    assert default.probability == exact.probability
    assert exact.stats.solver_iterations == 0 and exact.stats.links_queried > 0
    assert sampled.stats.solver_iterations > 0
    # A sampling spacing samples the links, as collide samples a mesh.
    spaced = cp.collide_robot(arm, q, cloud, mesh_spacing=0.002, model="points")
    assert spaced.stats.solver_iterations > 0


def test_each_exact_link_is_collide_on_its_mesh(arm: cp.Robot, cloud: cp.PointCloud) -> None:
    q = [0.05, 0.02, 0.07, 0.0]
    r = cp.collide_robot(arm, q, cloud, broad_phase=False)
    poses = arm.link_poses(q)
    for name, link in r.links.items():
        mesh = arm.link_mesh(name)
        assert mesh is not None
        direct = cp.collide(mesh, cloud, pose_a=poses[name])
        assert direct.probability == link.probability, name
    assert r.probability > 0.0


def test_batches_and_motions_take_the_mesh_side(arm: cp.Robot, cloud: cp.PointCloud) -> None:
    t = np.linspace(0.0, 1.0, 7)
    qs = np.column_stack([np.zeros_like(t), np.zeros_like(t), 0.1 * t, np.zeros_like(t)])
    for side in ("exact", "sampled"):
        many = cp.collide_robot_many(arm, qs, cloud, mesh_side=side)
        for i, q in enumerate(qs):
            one = cp.collide_robot(arm, q, cloud, mesh_side=side)
            assert many.probabilities[i] == one.probability
        assert many.states[0] == "free" and many.states[-1] == "collision"
        m = cp.check_motion(arm, qs[0], qs[-1], cloud, mesh_side=side)
        assert not m.safe
    # Far from the wall (the base 5 m away), no link is queried.
    base = np.eye(4)
    base[0, 3] = 5.0
    far = cp.collide_robot(arm, [0.0, 0.0, 0.0, 0.0], cloud, base_pose=base)
    assert far.stats.links_queried == 0 and far.probability == 0.0


def test_bad_mesh_sides_are_rejected(arm: cp.Robot, cloud: cp.PointCloud) -> None:
    q = [0.0, 0.0, 0.0, 0.0]
    with pytest.raises(cp.InvalidInputError, match=r"mesh_side.*'exact'"):
        cp.collide_robot(arm, q, cloud, mesh_side="voxels")
    with pytest.raises(cp.InvalidInputError, match=r"mesh_spacing"):
        cp.collide_robot(arm, q, cloud, mesh_side="exact", mesh_spacing=0.002)
    with pytest.raises(cp.InvalidInputError, match=r"surface"):
        cp.collide_robot(arm, q, cloud, model="points", aggregation="surface")
    with pytest.raises(cp.InvalidInputError, match=r"must be a str"):
        cp.check_motion(arm, q, q, cloud, mesh_side=1)


def test_cli_mesh_side(arm_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from cloudprox.cli import main

    scan = tmp_path / "wall.xyz"
    np.savetxt(scan, wall(0.40, 0.3, 0.1, SIGMA, 11))
    args = ["robot", str(arm_path), str(scan), "--sigma", str(SIGMA), "--q", "0,0,0.1,0", "--json"]
    states = {}
    for side in ("exact", "sampled"):
        assert main([*args, "--mesh-side", side]) == 0
        doc = json.loads(capsys.readouterr().out)
        states[side] = doc["state"]
    assert states == {"exact": "collision", "sampled": "collision"}
    assert main([*args, "--mesh-side", "exact", "--mesh-spacing", "0.002"]) == 2
    assert "mesh_spacing" in capsys.readouterr().err
