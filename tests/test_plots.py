from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.plots import Panel, plot_collision, plot_collisions, world_points
from tests.helpers import sphere_gap_pose


def test_plot_writes_a_png(tmp_path, spheres, sphere_points) -> None:
    a, b = spheres
    pose_b = sphere_gap_pose(2.0)
    r = cp.collide(a, b, pose_b=pose_b)
    out = tmp_path / "spheres.png"
    fig = plot_collision(
        sphere_points[0], world_points(sphere_points[1], pose_b), r, out, title="t"
    )
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "P = " in fig.axes[0].get_title() and r.state in fig.axes[0].get_title()


def test_plot_panels_and_bad_shapes(tmp_path, spheres, sphere_points) -> None:
    a, b = spheres
    r = cp.collide(a, b, pose_b=sphere_gap_pose(10.0))
    pb = world_points(sphere_points[1], sphere_gap_pose(10.0))
    fig = plot_collisions(
        [Panel(sphere_points[0], pb, r, "one"), Panel(sphere_points[0], pb, r, "two")],
        tmp_path / "two.png",
        bounds=(np.full(3, -0.05), np.full(3, 0.5)),
    )
    assert len([ax for ax in fig.axes if ax.name == "3d"]) == 2
    with pytest.raises(ValueError, match="do not match"):
        plot_collision(sphere_points[0][:10], pb, r)
    with pytest.raises(ValueError, match="no panels"):
        plot_collisions([])


def test_plotting_leaves_pyplot_alone(tmp_path) -> None:
    code = (
        "import sys, cloudprox as cp; from cloudprox.plots import plot_collision; "
        "a = cp.PointCloud(cp.synthetic.sample_sphere(50, 0.1)); "
        f"plot_collision(a.points, a.points, cp.collide(a, a), {str(tmp_path / 'x.png')!r}); "
        "print('matplotlib.pyplot' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_world_points() -> None:
    p = np.arange(6.0).reshape(2, 3)
    t = cp.pose.from_rpy((0.0, 0.0, np.pi / 2), (1.0, 0.0, 0.0))  # a quarter turn about z
    np.testing.assert_allclose(world_points(p, t), [[0.0, 0.0, 2.0], [-3.0, 3.0, 5.0]], atol=1e-12)
    np.testing.assert_array_equal(world_points(p), p)


def test_contact_bounds_zoom_on_the_probable_points(tmp_path, spheres, sphere_points) -> None:
    from cloudprox.plots import contact_bounds

    a, b = spheres
    pose_b = sphere_gap_pose(0.0)
    r = cp.collide(a, b, pose_b=pose_b)
    pa, pb = sphere_points[0], world_points(sphere_points[1], pose_b)
    lo, hi = contact_bounds(pa, pb, r)
    loud = np.concatenate([pa[r.probabilities_a >= 1e-3], pb[r.probabilities_b >= 1e-3]])
    assert len(loud) and np.all((loud >= lo) & (loud <= hi))
    everything = np.concatenate([pa, pb])
    # Zoomed in along the line of centres, where the spheres touch.
    assert hi[0] - lo[0] < 0.5 * np.ptp(everything[:, 0])
    assert np.prod(hi - lo) < 0.5 * np.prod(np.ptp(everything, axis=0))
    far = cp.collide(a, b, pose_b=sphere_gap_pose(40.0))
    assert contact_bounds(pa, world_points(sphere_points[1], sphere_gap_pose(40.0)), far) is None
    fig = plot_collision(pa, pb, r, tmp_path / "zoom.png", bounds="contact")
    assert fig.axes[0].get_xlim()[1] - fig.axes[0].get_xlim()[0] < np.ptp(everything[:, 0])
    with pytest.raises(ValueError, match="bounds must be"):
        plot_collision(pa, pb, r, bounds="everything")
