from __future__ import annotations

import numpy as np
import pytest

from cloudprox.scenes import Box, box_distance, build_scene, sample_boxes


def test_box_distance_cases() -> None:
    a = Box("a", "g", (0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    # Face to face along x, 0.5 apart.
    assert box_distance(a, Box("b", "g", (2.5, 0.0, 0.0), (1.0, 1.0, 1.0))) == pytest.approx(0.5)
    # Edge to edge: 3-4-5 triangle.
    b = Box("b", "g", (2.0 + 0.3, 2.0 + 0.4, 0.0), (1.0, 1.0, 1.0))
    assert box_distance(a, b) == pytest.approx(0.5)
    # Touching and overlapping: minus the smallest overlap along an axis.
    assert box_distance(a, Box("b", "g", (2.0, 0.0, 0.0), (1.0, 1.0, 1.0))) == pytest.approx(0.0)
    assert box_distance(a, Box("b", "g", (1.9, 0.5, 0.0), (1.0, 1.0, 1.0))) == pytest.approx(-0.1)
    assert box_distance(a, Box("b", "g", (0.0, 0.0, 0.0), (0.5, 0.5, 0.5))) == pytest.approx(-1.5)
    assert box_distance(a, b) == box_distance(b, a)


def test_box_sampling_is_on_the_surface_and_area_weighted() -> None:
    box = Box("slab", "g", (1.0, 2.0, 3.0), (0.5, 0.25, 0.01))
    rng = np.random.default_rng(0)
    pts = box.sample_surface(4000, rng)
    d = np.abs(pts - box.center)
    assert np.all(d <= np.asarray(box.half) + 1e-12)
    on = np.isclose(d, box.half)
    assert np.all(on.any(axis=1))
    # The two big faces hold 0.5 * 0.25 / (0.5 * 0.25 + 0.5 * 0.01 + 0.25 * 0.01) of the area.
    big = on[:, 2].mean()
    assert big == pytest.approx(0.125 / 0.1325, abs=0.02)
    assert box.area == pytest.approx(8 * 0.1325)
    both = sample_boxes([box, box.translated([1.0, 0.0, 0.0])], 1000.0, rng)
    assert len(both) == 2 * round(1000.0 * box.area)


def test_scene_gaps_are_exact() -> None:
    scene = build_scene(sigma=0.005, points=400, seed=3)
    assert scene.piano_points.shape[1] == 3 and scene.room_points.shape[1] == 3
    assert {"floor", "walls", "table 1", "table 2", "table 3"} <= set(scene.groups)
    for gap in (-0.015, 0.0, 0.01, 0.075):
        pose = scene.piano_pose(gap)
        gaps = scene.gaps(pose)
        assert gaps[scene.table] == pytest.approx(gap, abs=1e-12)
        assert scene.exact_gap(pose) == pytest.approx(gap, abs=1e-12)
        assert min(gaps, key=gaps.get) == scene.table
    # The noise has the requested spread: distance of the points to their box surface.
    clean = build_scene(sigma=0.0, points=400, seed=3)
    noise = scene.piano_points - clean.piano_points
    assert np.std(noise) == pytest.approx(0.005, rel=0.1)
    with pytest.raises(ValueError, match="rotation"):
        scene.gaps(np.diag([1.0, -1.0, -1.0, 1.0]))
    with pytest.raises(ValueError, match="points must be >= 10"):
        build_scene(points=1)
