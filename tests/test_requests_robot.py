"""``RobotRequest`` and ``MotionRequest``: the typed options of the robot queries.

A request and the same keyword options give the same answer (one parser reads
both), keywords given beside a request override it, bad values raise naming the
option on both paths, and requests repr, replace and pickle.

The test arm's base (``tests.robots.ARM_URDF``) is a 0.2 x 0.2 x 0.1 box centred
at the origin; a patch of the plane ``x = 0.1 + c`` faces it at clearance ``c``.
"""

from __future__ import annotations

import pickle
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from tests.robots import wall

SIGMA = 0.002
Q0 = [0.0, 0.0, 0.0, 0.0]
Q1 = [0.0, 0.3, 0.0, 0.0]
FINGERS = ["link3", "link4", "tool"]


def facing(c: float) -> cp.PointCloud:
    return cp.PointCloud(wall(0.1 + c, 0.0, 0.03, SIGMA, 6), sigma=SIGMA)


def target_patch() -> cp.PointCloud:
    """A patch pressed 5 mm into the arm's sphere ``link3`` at ``q = 0``."""
    return cp.PointCloud(wall(0.325, 0.3, 0.02, SIGMA, 3), sigma=SIGMA)


#: Robot options and collision options that change the answer at clearance 4 mm.
KEYWORDS: dict[str, Any] = {"model": "points", "threshold_free": 0.2, "padding": 0.002}


def keyword_request() -> cp.RobotRequest:
    return cp.RobotRequest(
        collide=cp.CollisionRequest(model="points", threshold_free=0.2), padding=0.002
    )


def link_probabilities(r: cp.RobotCollisionResult) -> dict[str, float]:
    return {name: link.probability for name, link in r.links.items()}


def test_defaults_are_the_cores() -> None:
    r = cp.RobotRequest()
    assert r.collide == cp.CollisionRequest()
    assert (r.mesh_side, r.mesh_spacing, r.broad_phase, r.self_collision) == (
        "exact",
        None,
        True,
        True,
    )
    assert r.padding == 0.0
    assert (r.target, r.target_pose, r.allowed_links, r.shadow) == (None, None, None, None)
    assert (r.shadow_depth, r.shadow_prior) == (None, None)
    m = cp.MotionRequest()
    assert (m.resolution, m.max_probability, m.warm_start) == (None, None, True)
    assert m.robot.to_dict() == r.to_dict()
    # A spacing alone samples the links, as the keyword does.
    assert cp.RobotRequest(mesh_spacing=0.005).mesh_side == "sampled"


def test_request_and_keywords_give_the_same_answer(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    by_keywords = cp.collide_robot(arm, Q0, cloud, **KEYWORDS)
    by_request = cp.collide_robot(arm, Q0, cloud, request=keyword_request())
    assert by_request.probability == by_keywords.probability
    assert by_request.state == by_keywords.state
    assert link_probabilities(by_request) == link_probabilities(by_keywords)
    # The options matter here: without them the answer differs.
    plain = cp.collide_robot(arm, Q0, cloud)
    assert plain.links["base"].probability != by_request.links["base"].probability


def test_request_and_keywords_in_batches(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    qs = np.array([Q0, Q1, [0.2, 0.0, 0.05, 0.0]])
    by_keywords = cp.collide_robot_many(arm, qs, cloud, **KEYWORDS)
    by_request = cp.collide_robot_many(arm, qs, cloud, request=keyword_request())
    np.testing.assert_array_equal(by_request.probabilities, by_keywords.probabilities)
    np.testing.assert_array_equal(by_request.states, by_keywords.states)
    np.testing.assert_array_equal(by_request.link_probabilities, by_keywords.link_probabilities)


def test_motion_request_and_keywords_give_the_same_answer(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    keywords = KEYWORDS | {"resolution": 0.01, "max_probability": 0.3, "warm_start": False}
    by_keywords = cp.check_motion(arm, Q0, Q1, cloud, **keywords)
    request = cp.MotionRequest(
        robot=keyword_request(), resolution=0.01, max_probability=0.3, warm_start=False
    )
    by_request = cp.check_motion(arm, Q0, Q1, cloud, request=request)
    for field in ("safe", "probability", "first_unsafe", "state", "states_checked"):
        assert getattr(by_request, field) == getattr(by_keywords, field), field
    assert by_request.states_total == by_keywords.states_total
    # A coarser resolution divides the motion into fewer states.
    coarse = cp.check_motion(arm, Q0, Q1, cloud, request=request.replace(resolution=0.05))
    assert coarse.states_total < by_request.states_total
    # A RobotRequest or a CollisionRequest stands for every state's query.
    robot_only = cp.check_motion(arm, Q0, Q1, cloud, request=keyword_request(), resolution=0.01)
    same = cp.check_motion(arm, Q0, Q1, cloud, resolution=0.01, **KEYWORDS)
    assert (robot_only.probability, robot_only.states_total) == (
        same.probability,
        same.states_total,
    )


def test_keywords_override_the_request(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    request = keyword_request()
    overridden = cp.collide_robot(arm, Q0, cloud, request=request, padding=0.0, model="elements")
    plain = cp.collide_robot(arm, Q0, cloud, threshold_free=0.2)
    assert link_probabilities(overridden) == link_probabilities(plain)
    replaced = request.replace(padding=0.0, model="elements")
    assert replaced.padding == 0.0 and replaced.collide.model == "elements"
    assert replaced.collide.threshold_free == 0.2
    # The request itself is unchanged (frozen).
    assert request.padding == 0.002 and request.collide.model == "points"
    with pytest.raises(AttributeError):
        request.padding = 0.0  # type: ignore[misc]


def test_a_collision_request_is_still_accepted(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    collision = cp.CollisionRequest(model="points", threshold_free=0.2)
    old = cp.collide_robot(arm, Q0, cloud, request=collision, padding=0.002)
    new = cp.collide_robot(
        arm, Q0, cloud, request=cp.RobotRequest(collide=collision), padding=0.002
    )
    assert link_probabilities(old) == link_probabilities(new)


def test_target_and_shadow_in_a_request(arm: cp.Robot) -> None:
    scene = cp.PointCloud(wall(5.0, 0.3, 0.05, SIGMA, 7), sigma=SIGMA)
    target = target_patch()
    request = cp.RobotRequest(target=target, allowed_links=FINGERS)
    assert request.target is target and list(request.allowed_links or []) == FINGERS
    by_request = cp.collide_robot(arm, Q0, scene, request=request)
    by_keywords = cp.collide_robot(arm, Q0, scene, target=target, allowed_links=FINGERS)
    assert by_request.state == by_keywords.state == "free"
    assert by_request.target is not None and by_keywords.target is not None
    assert by_request.target.probability == by_keywords.target.probability
    shadow = cp.filters.Occlusion(facing(0.004), [1.0, 0.0, 0.0])
    shadowed = cp.RobotRequest(shadow=shadow, shadow_depth=0.1)
    assert shadowed.shadow is shadow
    assert (shadowed.shadow_depth, shadowed.shadow_prior) == (0.1, 0.5)
    cloud = facing(0.004)
    a = cp.collide_robot(arm, Q0, cloud, request=shadowed)
    b = cp.collide_robot(arm, Q0, cloud, shadow=shadow, shadow_depth=0.1)
    assert {n: link.shadow for n, link in a.links.items()} == {
        n: link.shadow for n, link in b.links.items()
    }


#: Bad robot options: the keyword, its value, the error and what its message says.
BAD_ROBOT = [
    ({"broad_phase": "yes"}, cp.InvalidInputError, "option broad_phase must be a bool"),
    ({"self_collision": 1.5}, cp.InvalidInputError, "option self_collision must be a bool"),
    ({"mesh_side": "hollow"}, cp.InvalidInputError, "unknown mesh_side 'hollow'"),
    ({"mesh_spacing": -0.01}, cp.InvalidInputError, "mesh_spacing must be finite and > 0"),
    ({"padding": "wide"}, cp.InvalidInputError, "option padding must be a float"),
    ({"padding": -0.01}, cp.InvalidInputError, "padding"),
    ({"padding": {"base": "x"}}, cp.InvalidInputError, "padding of link 'base'"),
    ({"allowed_links": "link3"}, cp.InvalidInputError, "allowed_links must be a list"),
    ({"allowed_links": ["link3"]}, cp.InvalidInputError, "need a target"),
    ({"shadow_depth": 0.1}, cp.InvalidInputError, "need a shadow"),
    ({"shadow": 3}, cp.InvalidInputError, "option shadow must be a filters.Occlusion"),
    ({"target": 3}, TypeError, "target must be a PointCloud or a Mesh"),
]


@pytest.mark.parametrize(("options", "error", "message"), BAD_ROBOT)
def test_bad_robot_options_name_the_problem_on_both_paths(
    arm: cp.Robot, options: dict[str, Any], error: type[Exception], message: str
) -> None:
    with pytest.raises(error, match=message):
        cp.RobotRequest(**options)
    with pytest.raises(error, match=message):
        cp.collide_robot(arm, Q0, facing(0.004), **options)
    with pytest.raises(error, match=message):
        cp.RobotRequest().replace(**options)
    assert issubclass(cp.InvalidInputError, ValueError)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"resolution": -1.0}, "motion resolution must be finite and > 0"),
        ({"resolution": "fine"}, "option resolution must be a float"),
        ({"max_probability": 2.0}, r"max_probability must be in \[0, 1\]"),
        ({"warm_start": "no"}, "option warm_start must be a bool"),
    ],
)
def test_bad_motion_options_name_the_problem_on_both_paths(
    arm: cp.Robot, options: dict[str, Any], message: str
) -> None:
    with pytest.raises(cp.InvalidInputError, match=message):
        cp.MotionRequest(**options)
    with pytest.raises(cp.InvalidInputError, match=message):
        cp.check_motion(arm, Q0, Q1, facing(0.004), **options)


def test_unknown_names_and_wrong_request_types(arm: cp.Robot) -> None:
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'paddin'; valid options: .*"):
        cp.RobotRequest().replace(paddin=0.1)
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'resolutio'.*warm_start"):
        cp.MotionRequest().replace(resolutio=0.1)
    # A motion option is not one of collide_robot's.
    with pytest.raises(cp.InvalidInputError, match=r"unknown option 'resolution'"):
        cp.collide_robot(arm, Q0, facing(0.004), resolution=0.01)
    with pytest.raises(TypeError, match="request must be a CollisionRequest or a RobotRequest"):
        cp.collide_robot(arm, Q0, facing(0.004), request=cp.MotionRequest())
    with pytest.raises(TypeError, match="request must be a CollisionRequest, a RobotRequest or"):
        cp.check_motion(arm, Q0, Q1, facing(0.004), request="points")
    with pytest.raises(TypeError):
        cp.RobotRequest(collide="points")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        cp.MotionRequest(robot=cp.CollisionRequest())  # type: ignore[arg-type]


def test_requests_pickle(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    request = cp.RobotRequest(
        collide=cp.CollisionRequest(model="points"),
        padding={"base": 0.002},
        target=target_patch(),
        allowed_links=FINGERS,
        mesh_spacing=0.004,
    )
    back = pickle.loads(pickle.dumps(request))
    assert isinstance(back, cp.RobotRequest)
    assert back.collide == request.collide
    assert back.padding == {"base": 0.002}
    assert (back.mesh_side, back.mesh_spacing) == ("sampled", 0.004)
    assert list(back.allowed_links or []) == FINGERS
    assert isinstance(back.target, cp.PointCloud) and len(back.target) == len(target_patch())
    a = cp.collide_robot(arm, Q0, cloud, request=request)
    b = cp.collide_robot(arm, Q0, cloud, request=back)
    assert link_probabilities(a) == link_probabilities(b)
    motion = cp.MotionRequest(robot=keyword_request(), resolution=0.01, warm_start=False)
    motion_back = pickle.loads(pickle.dumps(motion))
    assert isinstance(motion_back, cp.MotionRequest)
    assert (motion_back.resolution, motion_back.max_probability, motion_back.warm_start) == (
        0.01,
        None,
        False,
    )
    assert motion_back.robot.to_dict() == motion.robot.to_dict()
    assert repr(motion_back) == repr(motion)


def test_repr_and_to_dict() -> None:
    request = keyword_request()
    text = repr(request)
    assert text.startswith("RobotRequest(collide=CollisionRequest(")
    assert "model='points'" in text and "padding=0.002" in text and "mesh_side='exact'" in text
    assert cp.RobotRequest(**request.to_dict()).to_dict() == request.to_dict()
    motion = cp.MotionRequest(robot=request, resolution=0.005)
    text = repr(motion)
    assert text.startswith("MotionRequest(robot=RobotRequest(")
    assert "resolution=0.005" in text and "warm_start=True" in text
    assert repr(cp.MotionRequest(**motion.to_dict())) == repr(motion)
    assert motion.replace(threshold_free=0.1).robot.collide.threshold_free == 0.1


def test_a_chance_constraint_takes_a_robot_request(arm: cp.Robot) -> None:
    from cloudprox.planning import ChanceConstraint

    cloud = facing(0.004)
    request = cp.RobotRequest(
        collide=cp.CollisionRequest(decide_only=True, threshold_collision=0.6), padding=0.002
    )
    # The request's collision options are read: decide_only stops at 0.6, below 0.7.
    with pytest.raises(ValueError, match=r"threshold_collision \(0.6\)"):
        ChanceConstraint(arm, cloud, max_probability=0.7, request=request)
    typed = ChanceConstraint(arm, cloud, max_probability=0.3, request=keyword_request())
    keywords = ChanceConstraint(arm, cloud, max_probability=0.3, **KEYWORDS)
    for q in (Q0, Q1):
        assert typed.state_valid(q) == keywords.state_valid(q)
    assert typed.motion_valid(Q0, Q1) == keywords.motion_valid(Q0, Q1)
