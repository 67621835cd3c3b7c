"""Link padding: ``collide_robot(..., padding=...)``.

The test arm's base (``tests.robots.ARM_URDF``) is a 0.2 x 0.2 x 0.1 box centred at
the origin: its face ``x = 0.1`` faces a patch of the plane ``x = 0.1 + c`` (``|y|``,
``|z| <= 0.03``, nearest the face everywhere), so the base reads at clearance ``c``
and a padding ``d`` reads exactly as a clearance ``c - d``.
"""

from __future__ import annotations

import math

import pytest

import cloudprox as cp
from tests.robots import wall

SIGMA = 0.002
Q0 = [0.0, 0.0, 0.0, 0.0]


def facing(c: float) -> cp.PointCloud:
    return cp.PointCloud(wall(0.1 + c, 0.0, 0.03, SIGMA, 6), sigma=SIGMA)


def test_padding_zero_is_no_padding_exactly(arm: cp.Robot) -> None:
    cloud = facing(0.004)
    plain = cp.collide_robot(arm, Q0, cloud)
    for padding in (0.0, {"base": 0.0}):
        zero = cp.collide_robot(arm, Q0, cloud, padding=padding)
        assert zero.probability == plain.probability
        for name, link in plain.links.items():
            assert zero.links[name].probability == link.probability


@pytest.mark.parametrize("model", ["elements", "points"])
@pytest.mark.parametrize(("c", "d"), [(0.006, 0.004), (0.004, 0.004), (0.008, 0.002)])
def test_padding_d_at_clearance_c_reads_as_clearance_c_minus_d(
    arm: cp.Robot, model: str, c: float, d: float
) -> None:
    def p(clearance: float, **options: object) -> float:
        r = cp.collide_robot(arm, Q0, facing(clearance), model=model, **options)
        return r.links["base"].probability

    padded = p(c, padding=d)
    assert math.isclose(padded, p(c - d), abs_tol=1e-6)
    assert padded > p(c)
    assert math.isclose(p(c, padding={"base": d}), padded, abs_tol=0.0)


def test_padding_by_name_pads_that_link_only(arm: cp.Robot) -> None:
    cloud = facing(0.008)
    plain = cp.collide_robot(arm, Q0, cloud)
    other = cp.collide_robot(arm, Q0, cloud, padding={"link3": 0.05})
    own = cp.collide_robot(arm, Q0, cloud, padding={"base": 0.01})
    assert other.links["base"].probability == plain.links["base"].probability
    assert own.links["base"].probability > plain.links["base"].probability + 0.1
    for name in ("link1", "link2", "link3", "link4", "tool"):
        assert own.links[name].probability == plain.links[name].probability


def test_padding_in_batches_and_motions(arm: cp.Robot) -> None:
    cloud = facing(0.008)
    batch = cp.collide_robot_many(arm, [Q0], cloud, padding=0.01)
    single = cp.collide_robot(arm, Q0, cloud, padding=0.01)
    assert batch.probabilities[0] == single.probability
    away = [1.5, 0.0, 0.0, 0.0]
    assert cp.check_motion(arm, away, Q0, cloud).safe
    assert not cp.check_motion(arm, away, Q0, cloud, padding=0.01).safe


@pytest.mark.parametrize("bad", [-0.01, float("nan"), float("inf")])
def test_bad_padding_names_the_problem(arm: cp.Robot, bad: float) -> None:
    cloud = facing(0.01)
    with pytest.raises(cp.InvalidInputError, match="padding must be finite and >= 0"):
        cp.collide_robot(arm, Q0, cloud, padding=bad)
    with pytest.raises(cp.InvalidInputError, match="padding of link 'link2'"):
        cp.collide_robot(arm, Q0, cloud, padding={"link2": bad})


def test_padding_unknown_link_and_wrong_type(arm: cp.Robot) -> None:
    cloud = facing(0.01)
    with pytest.raises(cp.InvalidInputError, match="'gripper', which robot 'arm' does not have"):
        cp.collide_robot(arm, Q0, cloud, padding={"gripper": 0.01})
    with pytest.raises(cp.InvalidInputError, match="float"):
        cp.collide_robot(arm, Q0, cloud, padding="1cm")


def test_padding_moves_sampled_links_samples(arm: cp.Robot) -> None:
    def p(clearance: float, padding: float) -> float:
        r = cp.collide_robot(
            arm, Q0, facing(clearance), mesh_side="sampled", mesh_spacing=0.005, padding=padding
        )
        return r.links["base"].probability

    # Two sampled sheets read contact only where they meet, and not
    # monotonically within a millimetre of it: compare at touching.
    assert p(0.008, 0.0) < 1e-6
    assert p(0.008, 0.008) > 0.2
    assert p(0.0, 0.0) > 0.2


def test_padding_refuses_attached_objects(arm: cp.Robot) -> None:
    holding = arm.attach("link3", cp.Mesh.cuboid(0.02, 0.02, 0.02), name="box")
    with pytest.raises(cp.InvalidInputError, match="attached objects are not padded"):
        cp.collide_robot(holding, Q0, facing(0.01), padding={"box": 0.01})
    # A float pads the links only: the held box reads as without padding.
    padded = cp.collide_robot(holding, Q0, facing(0.01), padding=0.001)
    plain = cp.collide_robot(holding, Q0, facing(0.01))
    assert padded.links["box"].probability == plain.links["box"].probability
