"""Manipulation essentials of ``Robot``: SRDF ``<disable_collisions>``, robots from URDF
text, configurations by joint name.

The robot is the Franka Panda of :mod:`tests.robots` (skipped when PyPI cannot be
reached, except on CI). Self-collision is checked against python-fcl's exact
mesh-mesh test of the same collision meshes at the same link poses.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import fcl
import numpy as np
import pytest

import cloudprox as cp
from tests.robots import panda_urdf_or_skip

#: Configurations of the Panda (7 arm joints, 2 fingers) at which links collide, and
#: python-fcl agrees with cloudprox on every pair. (Elsewhere they may differ where a
#: finger lies wholly inside another link: cloudprox's links are closed solids,
#: fcl's meshes surfaces that must cross.)
FOLDED = [
    [1.21, 1.67, -0.01, -2.95, -0.03, 1.9, 1.68, 0.04, 0.01],
    [0.0, -1.7, 0.0, -3.0, 0.0, 0.5, 0.0, 0.04, 0.04],
    [-1.88, -1.51, -2.47, -2.85, -2.38, 3.13, 0.1, 0.0, 0.02],
    [2.56, -1.14, 2.67, -3.0, -1.97, 2.02, -1.33, 0.03, 0.02],
]
#: Configurations at which no two checked links touch.
CLEAR = [
    [0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.8, 0.04, 0.04],
    [2.0, 1.5, -2.5, -2.9, 2.5, 3.7, 2.0, 0.02, 0.0],
    [0.5, -0.3, 0.2, -2.0, 0.1, 2.0, -0.5, 0.0, 0.0],
]


@pytest.fixture(scope="module")
def panda_path() -> Path:
    return panda_urdf_or_skip()


@pytest.fixture(scope="module")
def panda(panda_path: Path) -> cp.Robot:
    return cp.Robot.from_urdf(panda_path)


def srdf_text(pairs: list[tuple[str, str]], robot: str = "panda") -> str:
    entries = "\n".join(
        f'  <disable_collisions link1="{a}" link2="{b}" reason="Never"/>' for a, b in pairs
    )
    return f"""<?xml version="1.0"?>
<robot name="{robot}">
  <group name="arm"><chain base_link="panda_link0" tip_link="panda_link8"/></group>
{entries}
</robot>
"""


def fcl_collisions(robot: cp.Robot, q: list[float]) -> set[frozenset[str]]:
    """Every pair of links with geometry whose meshes intersect at ``q`` (python-fcl)."""
    poses = robot.link_poses(q)
    objects = {}
    for name in robot.link_names:
        mesh = robot.link_mesh(name)
        if mesh is None:
            continue
        model = fcl.BVHModel()
        model.beginModel(len(mesh.vertices), len(mesh.faces))
        model.addSubModel(mesh.vertices, mesh.faces.astype(np.int32))
        model.endModel()
        pose = poses[name]
        objects[name] = fcl.CollisionObject(model, fcl.Transform(pose[:3, :3], pose[:3, 3]))
    names = list(objects)
    hits = set()
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            result = fcl.CollisionResult()
            if fcl.collide(objects[a], objects[b], fcl.CollisionRequest(), result) > 0:
                hits.add(frozenset((a, b)))
    return hits


def pair_set(pairs: list[tuple[str, str]]) -> set[frozenset[str]]:
    return {frozenset(p) for p in pairs}


# ------------------------------------------------------------------ SRDF


def test_srdf_moves_its_pairs_to_ignored(panda: cp.Robot, panda_path: Path, tmp_path: Path) -> None:
    checked = panda.self_collision_pairs
    disabled = [checked[0], (checked[3][1], checked[3][0])]  # either order in the SRDF
    srdf = tmp_path / "panda.srdf"
    srdf.write_text(srdf_text(disabled))
    robot = cp.Robot.from_urdf(panda_path, srdf=srdf)
    gone = pair_set(disabled)
    assert pair_set(robot.self_collision_pairs) == pair_set(checked) - gone
    assert pair_set(robot.ignored_pairs) == pair_set(panda.ignored_pairs) | gone
    assert len(robot.self_collision_pairs) == len(checked) - 2
    # Text instead of a path: the same robot.
    same = cp.Robot.from_urdf(panda_path, srdf_string=srdf.read_text())
    assert same.self_collision_pairs == robot.self_collision_pairs
    assert same.ignored_pairs == robot.ignored_pairs


def test_srdf_of_ignored_or_geometryless_links_changes_nothing(
    panda: cp.Robot, panda_path: Path
) -> None:
    text = srdf_text([panda.ignored_pairs[0], ("panda_link8", "panda_link1")])
    robot = cp.Robot.from_urdf(panda_path, srdf_string=text)
    assert robot.self_collision_pairs == panda.self_collision_pairs
    assert robot.ignored_pairs == panda.ignored_pairs


def test_self_collisions_agree_with_fcl_minus_disabled_pairs(
    panda: cp.Robot, panda_path: Path
) -> None:
    # Disable every pair that collides at the first folded configuration.
    first = fcl_collisions(panda, FOLDED[0]) & pair_set(panda.self_collision_pairs)
    assert first, "the folded configuration must self-collide"
    disabled = [tuple(sorted(p)) for p in first]
    robot = cp.Robot.from_urdf(panda_path, srdf_string=srdf_text(disabled))
    assert robot.self_collisions(FOLDED[0]) == []
    for q in FOLDED + CLEAR:
        exact = fcl_collisions(robot, q)
        assert pair_set(panda.self_collisions(q)) == exact & pair_set(panda.self_collision_pairs)
        expected = exact & pair_set(robot.self_collision_pairs)
        assert pair_set(robot.self_collisions(q)) == expected, q
        assert not pair_set(robot.self_collisions(q)) & first
    some_colliding = [
        q for q in FOLDED if fcl_collisions(robot, q) & pair_set(robot.self_collision_pairs)
    ]
    assert some_colliding, "a folded configuration must still self-collide on checked pairs"


def test_srdf_reaches_collide_robot(panda: cp.Robot, panda_path: Path) -> None:
    first = fcl_collisions(panda, FOLDED[0]) & pair_set(panda.self_collision_pairs)
    robot = cp.Robot.from_urdf(panda_path, srdf_string=srdf_text([tuple(sorted(p)) for p in first]))
    far = cp.PointCloud(np.array([[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]), sigma=0.002)
    assert pair_set(cp.collide_robot(panda, FOLDED[0], far).self_collisions) == first
    assert cp.collide_robot(robot, FOLDED[0], far).self_collisions == []
    qs = np.array([FOLDED[0], CLEAR[0]])
    assert cp.collide_robot_many(robot, qs, far).self_colliding.tolist() == [False, False]
    assert cp.collide_robot_many(panda, qs, far).self_colliding.tolist() == [True, False]


def test_srdf_survives_pickling(panda_path: Path, panda: cp.Robot) -> None:
    pair = panda.self_collision_pairs[0]
    robot = cp.Robot.from_urdf(panda_path, srdf_string=srdf_text([pair]))
    again = pickle.loads(pickle.dumps(robot))
    assert again.self_collision_pairs == robot.self_collision_pairs
    assert pair not in again.self_collision_pairs


def test_srdf_unknown_link_is_a_format_error(panda_path: Path, tmp_path: Path) -> None:
    srdf = tmp_path / "typo.srdf"
    srdf.write_text(srdf_text([("panda_link1", "panda_link3"), ("panda_link1", "panda_lnk5")]))
    with pytest.raises(cp.FormatError, match=r"typo\.srdf.*'panda_lnk5'"):
        cp.Robot.from_urdf(panda_path, srdf=srdf)
    with pytest.raises(cp.FormatError, match=r"<SRDF string>.*'gripper'"):
        cp.Robot.from_urdf(panda_path, srdf_string=srdf_text([("gripper", "panda_link1")]))


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('<robot><disable_collisions link1="a" link2="b"></robot>', "malformed XML at line 1"),
        ("<robot>", "ends inside"),
        ("", "no <robot>"),
        ('<robot>\n<disable_collisions link2="panda_link1"/></robot>', "line 2.*no link1"),
    ],
)
def test_srdf_malformed_is_a_format_error(panda_path: Path, text: str, match: str) -> None:
    with pytest.raises(cp.FormatError, match=match):
        cp.Robot.from_urdf(panda_path, srdf_string=text)


def test_srdf_bad_arguments(panda_path: Path, tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"missing\.srdf"):
        cp.Robot.from_urdf(panda_path, srdf=tmp_path / "missing.srdf")
    with pytest.raises(cp.InvalidInputError, match="not both"):
        cp.Robot.from_urdf(panda_path, srdf=tmp_path / "x.srdf", srdf_string="<robot/>")


# ------------------------------------------------------------------ URDF text


def test_from_urdf_string_equals_from_urdf(panda: cp.Robot, panda_path: Path) -> None:
    text = panda_path.read_text()
    robot = cp.Robot.from_urdf_string(text, base_dir=panda_path.parent)
    assert robot.name == panda.name
    assert robot.joint_names == panda.joint_names
    assert robot.link_names == panda.link_names
    np.testing.assert_array_equal(robot.joint_limits, panda.joint_limits)
    assert robot.self_collision_pairs == panda.self_collision_pairs
    assert robot.ignored_pairs == panda.ignored_pairs
    for q in FOLDED + CLEAR:
        a, b = robot.link_poses(q), panda.link_poses(q)
        for name in panda.link_names:
            np.testing.assert_array_equal(a[name], b[name])
        assert robot.self_collisions(q) == panda.self_collisions(q)
    for name in panda.link_names:
        ma, mb = robot.link_mesh(name), panda.link_mesh(name)
        assert (ma is None) == (mb is None)
        if ma is not None and mb is not None:
            np.testing.assert_array_equal(ma.vertices, mb.vertices)
    again = pickle.loads(pickle.dumps(robot))
    assert again.self_collision_pairs == robot.self_collision_pairs


def test_from_urdf_string_with_srdf(panda: cp.Robot, panda_path: Path, tmp_path: Path) -> None:
    pair = panda.self_collision_pairs[1]
    srdf = tmp_path / "p.srdf"
    srdf.write_text(srdf_text([pair]))
    text = panda_path.read_text()
    by_path = cp.Robot.from_urdf_string(text, base_dir=panda_path.parent, srdf=srdf)
    by_text = cp.Robot.from_urdf_string(
        text, base_dir=panda_path.parent, srdf_string=srdf_text([pair])
    )
    assert pair not in by_path.self_collision_pairs and pair in by_path.ignored_pairs
    assert by_text.self_collision_pairs == by_path.self_collision_pairs


def test_from_urdf_string_errors(tmp_path: Path, panda_path: Path) -> None:
    with pytest.raises(cp.FormatError, match="<URDF string>"):
        cp.Robot.from_urdf_string("<robot name='x'><link name='a'></robot>")
    # Relative mesh paths need base_dir: without it they are looked for in the
    # current folder.
    with pytest.raises(FileNotFoundError, match="panda_link0"):
        cp.Robot.from_urdf_string(panda_path.read_text(), base_dir=tmp_path)


# ------------------------------------------------------------------ configurations by name


def test_dict_configuration_gives_the_array_poses(panda: cp.Robot) -> None:
    for q in FOLDED + CLEAR:
        by_name = dict(zip(panda.joint_names, q, strict=True))
        a, b = panda.link_poses(by_name), panda.link_poses(q)
        for name in panda.link_names:
            np.testing.assert_array_equal(a[name], b[name])
        assert panda.self_collisions(by_name) == panda.self_collisions(q)
        np.testing.assert_array_equal(panda.clamp(by_name), panda.clamp(q))


def test_dict_configuration_leaves_others_at_reference(panda: cp.Robot) -> None:
    reference = np.zeros(panda.dof)  # every joint of this Panda may be 0
    q = reference.copy()
    q[1] = 0.4
    q[7] = 0.03
    partial = {"panda_joint2": 0.4, panda.joint_names[7]: 0.03}
    a, b = panda.link_poses(partial), panda.link_poses(q)
    for name in panda.link_names:
        np.testing.assert_array_equal(a[name], b[name])
    empty = panda.link_poses({})
    for name, pose in panda.link_poses(reference).items():
        np.testing.assert_array_equal(empty[name], pose)


SLIDER_URDF = """<robot name="slider">
  <link name="base"/><link name="carriage"/><link name="arm"/>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="carriage"/>
    <axis xyz="1 0 0"/><limit lower="0.2" upper="1.0" effort="1" velocity="1"/></joint>
  <joint name="turn" type="revolute"><parent link="carriage"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1.5" upper="-0.5" effort="1" velocity="1"/></joint>
</robot>"""


def test_dict_configuration_reference_is_the_limit_nearest_zero() -> None:
    robot = cp.Robot.from_urdf_string(SLIDER_URDF)
    assert robot.joint_names == ["slide", "turn"]
    for q, expected in [
        ({}, [0.2, -0.5]),
        ({"turn": -1.0}, [0.2, -1.0]),
        ({"slide": 0.7}, [0.7, -0.5]),
    ]:
        got, want = robot.link_poses(q), robot.link_poses(expected)
        for name in robot.link_names:
            np.testing.assert_array_equal(got[name], want[name])
        np.testing.assert_array_equal(robot.clamp(q), expected)


def test_dict_configuration_in_queries(panda: cp.Robot) -> None:
    far = cp.PointCloud(np.array([[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]), sigma=0.002)
    by_name = [dict(zip(panda.joint_names, q, strict=True)) for q in FOLDED]
    one = cp.collide_robot(panda, by_name[0], far)
    assert one.self_collisions == cp.collide_robot(panda, FOLDED[0], far).self_collisions
    many = cp.collide_robot_many(panda, [*by_name, CLEAR[0]], far)
    expected = cp.collide_robot_many(panda, np.array([*FOLDED, CLEAR[0]]), far)
    np.testing.assert_array_equal(many.self_colliding, expected.self_colliding)
    np.testing.assert_array_equal(many.probabilities, expected.probabilities)
    motion = cp.check_motion(panda, {"panda_joint1": -0.2}, {"panda_joint1": 0.2}, far)
    reference = panda.clamp(np.zeros(panda.dof))
    q0, q1 = reference.copy(), reference.copy()
    q0[0], q1[0] = -0.2, 0.2
    ref = cp.check_motion(panda, q0, q1, far)
    assert (motion.safe, motion.states_total) == (ref.safe, ref.states_total)


@pytest.mark.parametrize(
    ("q", "match"),
    [
        ({"panda_joint9": 0.1}, r"'panda_joint9' is not a joint"),
        ({"panda_joint1": 0.1, "elbow": 0.0}, r"'elbow' is not a joint.*panda_joint1"),
        ({"panda_joint1": "wide"}, r"value of joint 'panda_joint1' must be a float"),
        ({1: 0.0}, r"joint names must be str"),
        ({"panda_joint1": 9.0}, r"panda_joint1.*outside its limits"),
        ({"panda_joint1": float("nan")}, r"panda_joint1.*not finite"),
    ],
)
def test_dict_configuration_errors(panda: cp.Robot, q: dict[object, object], match: str) -> None:
    far = cp.PointCloud(np.array([[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]), sigma=0.002)
    with pytest.raises(cp.InvalidInputError, match=match):
        panda.link_poses(q)
    with pytest.raises(cp.InvalidInputError, match=match):
        cp.collide_robot(panda, q, far)
    with pytest.raises(cp.InvalidInputError, match=match):
        cp.collide_robot_many(panda, [CLEAR[0], q], far)
    with pytest.raises(cp.InvalidInputError, match=match):
        cp.check_motion(panda, CLEAR[0], q, far)


def test_dict_configuration_fixed_joint_is_named(panda: cp.Robot) -> None:
    with pytest.raises(cp.InvalidInputError, match=r"^q: 'panda_joint8' is a fixed joint"):
        panda.link_poses({"panda_joint8": 0.0})
    with pytest.raises(cp.InvalidInputError, match=r"^qs\[1\]: 'panda_joint8' is a fixed joint"):
        cp.collide_robot_many(
            panda, [{}, {"panda_joint8": 0.0}], cp.PointCloud(np.eye(3), sigma=0.01)
        )


# ------------------------------------------------------------------ allowed pairs


def test_with_allowed_collisions(panda: cp.Robot) -> None:
    colliding = sorted(tuple(sorted(p)) for p in pair_set(panda.self_collisions(FOLDED[1])))
    assert len(colliding) >= 3
    allowed = [colliding[0], (colliding[1][1], colliding[1][0])]
    robot = panda.with_allowed_collisions(allowed)
    gone = pair_set(allowed)
    assert pair_set(robot.self_collision_pairs) == pair_set(panda.self_collision_pairs) - gone
    assert gone <= pair_set(robot.ignored_pairs)
    assert pair_set(robot.self_collisions(FOLDED[1])) == pair_set(colliding) - gone
    # The original is unchanged; the copy pickles with its pairs.
    assert pair_set(panda.self_collisions(FOLDED[1])) == pair_set(colliding)
    again = pickle.loads(pickle.dumps(robot))
    assert again.self_collision_pairs == robot.self_collision_pairs
    # Allowing more on the copy keeps the pairs allowed before.
    more = again.with_allowed_collisions([colliding[2]])
    assert not pair_set(more.self_collision_pairs) & (gone | {frozenset(colliding[2])})
    assert pair_set(more.self_collisions(FOLDED[1])) == pair_set(colliding[3:])
    far = cp.PointCloud(np.array([[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]), sigma=0.002)
    hit = cp.collide_robot(robot, FOLDED[1], far)
    assert pair_set(hit.self_collisions) == pair_set(colliding) - gone


def test_with_allowed_collisions_errors(panda: cp.Robot) -> None:
    with pytest.raises(cp.InvalidInputError, match="no link named 'panda_link99'"):
        panda.with_allowed_collisions([("panda_link1", "panda_link99")])
    with pytest.raises(cp.InvalidInputError, match="'panda_hand' twice"):
        panda.with_allowed_collisions([("panda_hand", "panda_hand")])
    with pytest.raises(ValueError, match="length 2"):
        panda.with_allowed_collisions([("panda_hand",)])  # type: ignore[list-item]
    assert panda.with_allowed_collisions([]).self_collision_pairs == panda.self_collision_pairs
