"""The interactive view: HTML rendered by headless Chromium, Rerun read back, the CLI."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import view
from cloudprox.cli import main
from cloudprox.pose import from_translation
from cloudprox.view._common import quiet_shown
from tests.chromium import Chromium, find_chromium
from tests.robots import ARM_URDF, wall


def _browser() -> Chromium:
    if find_chromium() is None:
        if os.environ.get("CI"):
            pytest.fail("no chromium on CI: scripts/system-deps.sh installs it")
        pytest.skip("no chromium here (scripts/system-deps.sh installs it)")
    return Chromium(size=SIZE, settle=0.5)


#: The browser's viewport (CSS pixels).
SIZE = (1000, 800)


def screenshot(html: Path, png: Path) -> np.ndarray:
    """Open ``html`` in headless Chromium, wait until drawn; the screenshot's RGB (0-255)."""
    from matplotlib.image import imread

    with _browser() as browser:
        browser.open(html)
        # Only the file itself and what it carries inline (data:, a blob: worker).
        foreign = [u for u in browser.requests() if not u.startswith(("file:", "data:", "blob:"))]
        assert not foreign, foreign
        browser.screenshot(png)
    return (imread(png)[:, :, :3] * 255.0).round()


def _near(pixels: np.ndarray, rgb: tuple[int, int, int], tol: float = 30.0) -> int:
    return int(np.sum(np.all(np.abs(pixels - np.array(rgb)) <= tol, axis=2)))


def _hex(color: str) -> tuple[int, int, int]:
    c = color.lstrip("#")
    r, g, b = (int(c[i : i + 2], 16) for i in (0, 2, 4))
    return r, g, b


def _plot_area(pixels: np.ndarray) -> np.ndarray:
    """The 3D scene without the legend (top left), panel (top right), colour bar (bottom left)."""
    h, w = pixels.shape[:2]
    return pixels[int(0.20 * h) :, int(0.12 * w) : int(0.88 * w)]


def _color_bar(pixels: np.ndarray) -> np.ndarray:
    h, w = pixels.shape[:2]
    return pixels[int(0.5 * h) :, : int(0.1 * w)]


def hot_mask(pixels: np.ndarray) -> np.ndarray:
    """Pixels of the plasma scale's top (p >~ 0.75: orange to yellow)."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (r > 220) & (g > 120) & (b < 110)


def hot(pixels: np.ndarray) -> int:
    return int(np.sum(hot_mask(pixels)))


def cold(pixels: np.ndarray) -> int:
    """Pixels of the plasma scale's bottom (p <~ 0.3: dark blue to purple)."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return int(np.sum((r < 150) & (g < 40) & (b > 110)))


def external_scripts(text: str) -> list[str]:
    """``src`` of the page's real ``<script>`` tags (not of markup inside script text)."""
    from html.parser import HTMLParser

    found: list[str] = []

    class Scripts(HTMLParser):
        def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
            found.extend(v or "" for k, v in attrs if tag == "script" and k == "src")

    Scripts().feed(text)
    return found


def _k3d_objects(text: str) -> list[dict[str, object]]:
    """The objects a k3d page carries (its msgpack snapshot, base64 in the page)."""
    import base64

    import msgpack

    m = re.search(r'atob\("([A-Za-z0-9+/=]+)"\)', text)
    assert m, "no k3d snapshot in the page"
    objects: list[dict[str, object]] = msgpack.unpackb(base64.b64decode(m.group(1)))["objects"]
    return objects


@pytest.fixture(scope="module")
def spheres_near() -> tuple[cp.PointCloud, cp.PointCloud, np.ndarray]:
    base = cp.synthetic.sample_sphere(1500, 0.1)
    a = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=1), sigma=0.002)
    b = cp.PointCloud(cp.synthetic.add_noise(base, 0.002, seed=2), sigma=0.002)
    return a, b, from_translation((0.19, 0.0, 0.0))


def test_html_screenshot_shows_the_probabilities(tmp_path, spheres_near) -> None:
    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b)
    assert result.state == "collision"
    scene = view.collision_scene(result, labels=("left", "right"))
    html = view.write_html(scene, tmp_path / "near.html")
    text = html.read_text()
    # Self-contained: k3d (three.js) inlined, nothing fetched from elsewhere (also
    # checked in the browser by screenshot()).
    assert text.count("<script") > 3 and not external_scripts(text)
    assert 'define("k3d"' in text and 2_000_000 < len(text) < 10_000_000
    assert "<title>left vs right: P = 1, state: collision" in text
    names = [str(o["name"]) for o in _k3d_objects(text)]
    assert "left: 1500 of 1500 points with p < 0.001" not in names  # some are hot
    assert any(n.startswith("left: ") and "with p ≥ 0.001" in n for n in names)
    assert any(n.startswith("contact patches (") for n in names)
    pixels = screenshot(html, tmp_path / "near.png")
    area = _plot_area(pixels)
    # The colliding caps are hot, their rims cold; both spheres keep their colours.
    assert hot(area) > 200, hot(area)
    assert cold(area) > 50, cold(area)
    assert _near(area, _hex(view.SIDE_COLORS[0])) > 200
    assert _near(area, _hex(view.SIDE_COLORS[1])) > 200
    # The contact zoom: the camera looks at the contact, the hot pixels are in
    # the middle of the view (not a speck in a corner).
    rows, cols = np.nonzero(hot_mask(pixels))
    h, w = pixels.shape[:2]
    assert abs(np.median(rows) / h - 0.5) < 0.2 and abs(np.median(cols) / w - 0.5) < 0.2
    assert np.ptp(cols) > 0.05 * w, np.ptp(cols)

    # The same spheres far apart: no hot pixel at all, the colour bar aside.
    far = cp.collide(a, b, pose_b=from_translation((0.3, 0.0, 0.0)))
    assert far.state == "free"
    html = view.write_html(view.collision_scene(far), tmp_path / "far.html")
    pixels = screenshot(html, tmp_path / "far.png")
    assert hot(_plot_area(pixels)) == 0
    assert _near(_plot_area(pixels), _hex(view.SIDE_COLORS[0])) > 200
    # ... while the colour bar (bottom left) does show the hot end.
    assert hot(_color_bar(pixels)) > 50


def test_html_turns_zooms_and_hovers(tmp_path, spheres_near) -> None:
    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b)
    html = view.write_html(
        view.collision_scene(result, labels=("left", "right")), tmp_path / "v.html"
    )
    camera = "cloudproxK3D.getWorld().camera.position.toArray()"
    with _browser() as browser:
        browser.open(html)
        before = browser.screenshot(tmp_path / "before.png")
        from matplotlib.image import imread

        pixels = (imread(before)[:, :, :3] * 255.0).round()
        # Hover the hot pixels one by one: a point's tooltip says its probability.
        rows, cols = np.nonzero(hot_mask(pixels))
        order = np.argsort(np.hypot(rows - np.median(rows), cols - np.median(cols)))
        shown = None
        for k in order[:40]:
            browser.mouse("mouseMoved", float(cols[k]), float(rows[k]))
            shown = browser.eval("window.cloudproxHovered || null")
            if shown and "p = " in shown["html"]:
                break
        assert shown and "p = " in shown["html"], shown
        p = float(re.search(r"p = ([0-9.e+-]+)", shown["html"]).group(1))
        assert p > 0.5 and shown["name"].split(":")[0] in ("left", "right"), shown
        assert browser.eval("document.getElementById('cloudprox-hover').style.display") == "block"
        # A region marker's tooltip: P, separation, normal.
        region = browser.eval(
            "(function(){var w=cloudproxK3D.getWorld(),c=w.camera,o=Object.values(w.ObjectsById)"
            ".find(function(x){return (w.ObjectsListJson[x.K3DIdentifier]||{}).name"
            "&&w.ObjectsListJson[x.K3DIdentifier].name.indexOf('contact patches')===0});"
            "var p=o.geometry.attributes.position,v=o.position.clone();"
            "v.set(p.getX(0),p.getY(0),p.getZ(0)).applyMatrix4(o.matrixWorld).project(c);"
            "var r=w.targetDOMNode.getBoundingClientRect();"
            "return [(v.x+1)/2*r.width+r.left,(1-v.y)/2*r.height+r.top]})()"
        )
        browser.mouse("mouseMoved", region[0] + 1, region[1])
        browser.mouse("mouseMoved", region[0], region[1])
        text = browser.eval("window.cloudproxHovered.html")
        assert "separation" in text and " mm" in text and "normal (" in text, text
        # Turn: drag with the left button; the camera moves, the picture changes.
        start = browser.eval(camera)
        browser.drag((500.0, 500.0), (700.0, 520.0))
        turned = browser.eval(camera)
        assert np.linalg.norm(np.subtract(turned, start)) > 1e-3
        after = browser.screenshot(tmp_path / "after.png")
        assert np.mean(np.abs(imread(after)[:, :, :3] - imread(before)[:, :, :3])) > 0.005
        # Zoom: the wheel brings the camera closer to what it looks at.
        target = browser.eval("cloudproxK3D.getWorld().controls.target.toArray()")
        browser.mouse("mouseWheel", 500.0, 400.0, deltaX=0, deltaY=-500)
        browser.eval("new Promise(function(r){setTimeout(r, 300)})")
        zoomed = browser.eval(camera)
        assert np.linalg.norm(np.subtract(zoomed, target)) < np.linalg.norm(
            np.subtract(turned, target)
        )


def test_separating_surface_shows_from_the_panel(tmp_path, spheres_near) -> None:
    from matplotlib.image import imread

    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b)
    html = view.write_html(view.collision_scene(result), tmp_path / "s.html")
    # The surface's entry in the K3D panel (Objects), its "visible" box.
    toggle = (
        "(function(){var t=Array.from(document.querySelectorAll('button.lil-title'))"
        ".find(function(b){return b.textContent.indexOf('separating surface')===0});"
        "var c=Array.from(t.parentElement.querySelectorAll('.lil-controller.lil-boolean'))"
        ".find(function(r){return r.textContent.trim()==='visible'});"
        "var box=c.querySelector('input');var before=box.checked;box.click();"
        "return [before, box.checked]})()"
    )
    with _browser() as browser:
        browser.open(html)
        hidden = (imread(browser.screenshot(tmp_path / "hidden.png"))[:, :, :3] * 255).round()
        assert browser.eval(toggle) == [False, True]
        browser.eval(
            "new Promise(function(r){requestAnimationFrame(function(){setTimeout(r,200)})})"
        )
        shown = (imread(browser.screenshot(tmp_path / "surface.png"))[:, :, :3] * 255).round()

    # Half-transparent blue over white and grey: a bluish patch appears.
    def bluish(px: np.ndarray) -> int:
        r, g, bl = px[..., 0], px[..., 1], px[..., 2]
        return int(np.sum((bl > r + 40) & (bl > g + 15) & (r < 200)))

    assert bluish(_plot_area(shown)) > bluish(_plot_area(hidden)) + 2000, (
        bluish(_plot_area(hidden)),
        bluish(_plot_area(shown)),
    )


def test_quiet_points_are_thinned_to_the_screen(tmp_path) -> None:
    # A dense wall of 200 000 points with p = 0 and a patch of 400 with p > 0.
    rng = np.random.default_rng(5)
    wall = np.column_stack(
        [rng.uniform(0, 1, 200_000), rng.uniform(0, 1, 200_000), np.zeros(200_000)]
    )
    prob = np.zeros(len(wall), dtype=np.float32)
    prob[:400] = rng.uniform(0.01, 1.0, 400)
    layer = view.PointLayer("wall", wall.astype(np.float32), prob, view.SIDE_COLORS[1])
    scene = view.Scene("wall", points=[layer])
    cell = scene.extent() / view.QUIET_CELLS
    shown = quiet_shown(layer, scene.quiet_below, cell)
    # Every shown point is quiet, one in each cell that holds quiet points.
    quiet = np.flatnonzero(prob < scene.quiet_below)
    pts = layer.points.astype(np.float64)
    cells = np.floor((pts - pts[quiet].min(axis=0)) / cell).astype(int)
    assert np.all(prob[shown] < scene.quiet_below)
    assert len(np.unique(cells[shown], axis=0)) == len(shown)
    assert len(np.unique(cells[quiet], axis=0)) == len(shown)
    assert 0.5 * view.QUIET_CELLS**2 < len(shown) < 0.6 * len(wall)
    # The points of a contact patch are drawn even where the cell has another.
    dropped = np.setdiff1d(quiet, shown)[:50]
    with_contact = view.PointLayer(
        "wall", layer.points, prob, layer.color, contact=np.concatenate([dropped, [3]])
    )
    kept = quiet_shown(with_contact, scene.quiet_below, cell)
    assert len(kept) == len(shown) + 50 and np.all(np.isin(dropped, kept)) and 3 not in kept
    objects = {o.name: o for o in view.to_k3d(scene).objects}
    assert f"wall: {len(shown)} of {len(wall) - 400} points with p < 0.001" in objects
    assert len(objects["wall: 400 with p ≥ 0.001"].positions) == 400
    legend = objects["legend"].text
    assert f"{len(shown)} of {len(wall) - 400} points with p &lt; 0.001 drawn" in legend
    everything = {o.name for o in view.to_k3d(scene, all_points=True).objects}
    assert f"wall: {len(wall) - 400} of {len(wall) - 400} points with p < 0.001" in everything
    # The plotly figure thins the same way on request.
    fig = view.to_figure(scene, all_points=False)
    assert len(fig.data[1].x) == len(shown)


def test_plotly_renderer_still_draws(tmp_path, spheres_near) -> None:
    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b)
    html = view.write_html(view.collision_scene(result), tmp_path / "p.html", renderer="plotly")
    text = html.read_text()
    assert "Plotly.newPlot" in text and len(text) > 3_000_000
    assert not external_scripts(text)
    pixels = screenshot(html, tmp_path / "plotly.png")
    h, w = pixels.shape[:2]
    area = pixels[int(0.40 * h) : int(0.95 * h), int(0.05 * w) : int(0.86 * w)]
    assert hot(area) > 100 and cold(area) > 30
    with pytest.raises(ValueError, match="renderer must be"):
        view.write_html(view.collision_scene(result), tmp_path / "x.html", renderer="vtk")


def test_scene_of_a_result(spheres_near) -> None:
    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b)
    # The result records its points, in the world frame.
    np.testing.assert_array_equal(result.points_a, a.points)
    np.testing.assert_allclose(result.points_b, b.points + pose_b[:3, 3], rtol=0, atol=1e-15)
    scene = view.collision_scene(result, surfaces=2)
    assert [len(x.points) for x in scene.points] == [len(a), len(b)]
    np.testing.assert_array_equal(
        scene.points[0].probabilities, result.probabilities_a.astype(np.float32)
    )
    assert len(scene.regions) == len(result.patches) >= 1
    assert sorted(r.probability for r in scene.regions)[-1] == max(
        r.probability for r in result.patches
    )
    with_surface = [r for r in scene.regions if r.surface is not None]
    assert 1 <= len(with_surface) <= 2
    # The separating surface passes through f = 0 (it is where f vanishes).
    best = max(result.patches, key=lambda r: r.probability)
    vertices, faces = view.separating_surface(best, 0.02)
    f, _ = best.evaluate(vertices)
    assert np.max(np.abs(f)) < 1e-6 and faces.max() == len(vertices) - 1
    # The same view from the clouds and poses, and from world points.
    again = view.collision_scene(result, a, b, None, pose_b, points_a=a.points)
    np.testing.assert_allclose(again.points[1].points, scene.points[1].points, atol=1e-6)


def test_mesh_side_is_drawn_with_its_samples(tmp_path, spheres_near) -> None:
    a, _, _ = spheres_near
    box = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    pose = from_translation((0.14, 0.0, 0.0))
    result = cp.collide(box, a, pose_a=pose, mesh_side="sampled")
    assert result.points_a.shape == (len(result.probabilities_a), 3)
    assert np.all(np.abs(result.points_a[:, 0] - 0.14) <= 0.05 + 1e-12)
    scene = view.collision_scene(result, box, a, pose)
    assert len(scene.meshes) == 1 and not scene.points[0].show_quiet
    np.testing.assert_allclose(
        scene.meshes[0].vertices, box.vertices + np.array([0.14, 0.0, 0.0]), atol=1e-6
    )
    fig = view.to_figure(scene)
    assert any(t.type == "mesh3d" for t in fig.data)
    # An exact mesh side (the default) has no points: the mesh alone is drawn.
    exact = view.collision_scene(cp.collide(box, a, pose_a=pose), box, a, pose)
    assert len(exact.meshes) == 1 and len(exact.points[0].points) == 0


def test_bad_inputs_give_clear_errors(spheres_near, monkeypatch) -> None:
    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b)
    with pytest.raises(ValueError, match=r"side A: points of shape \(10, 3\) do not match"):
        view.collision_scene(result, points_a=a.points[:10])
    with pytest.raises(ValueError, match="half_size must be finite and > 0"):
        view.separating_surface(result.patches[0], 0.0)
    box = cp.Mesh.cuboid(0.05, 0.05, 0.05)
    with_mesh = cp.collide(box, a, pose_a=from_translation((0.14, 0.0, 0.0)))
    with pytest.raises(ValueError, match=r"a pose must have shape \(4, 4\)"):
        view.collision_scene(with_mesh, box, a, np.eye(3))
    monkeypatch.setitem(sys.modules, "plotly", None)
    monkeypatch.setitem(sys.modules, "plotly.graph_objects", None)
    with pytest.raises(ImportError, match=r"pip install 'cloudprox\[view\]'"):
        view.to_figure(view.collision_scene(result))


def test_show_writes_and_opens(tmp_path, spheres_near, monkeypatch) -> None:
    a, b, pose_b = spheres_near
    opened: list[str] = []
    monkeypatch.setattr("webbrowser.open", lambda url: opened.append(url) or True)
    result = cp.collide(a, b, pose_b=pose_b)
    path = result.show(tmp_path / "shown.html", labels=("one", "two"))
    assert path == tmp_path / "shown.html" and path.stat().st_size > 2_000_000
    assert opened == [path.resolve().as_uri()]
    assert "one vs two" in path.read_text()
    quiet = result.show(open_browser=False)
    assert quiet.is_file() and len(opened) == 1
    quiet.unlink()


def test_rerun_recording_reads_back(tmp_path, spheres_near) -> None:
    rr = pytest.importorskip("rerun")
    a, b, pose_b = spheres_near
    result = cp.collide(a, b, pose_b=pose_b, model="points")
    scene = view.collision_scene(result, labels=("left", "right"))
    path = view.write_rerun(scene, tmp_path / "near.rrd")
    columns: dict[str, dict[str, object]] = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        batch = chunk.to_record_batch()
        columns.setdefault(chunk.entity_path, {}).update(
            {name: batch.column(name) for name in batch.schema.names}
        )
    assert {"/summary", "/points/0_left", "/points/1_right", "/regions"} <= set(columns)
    for k, name in ((0, "/points/0_left"), (1, "/points/1_right")):
        positions = np.array(columns[name]["Points3D:positions"][0].as_py(), dtype=np.float32)
        np.testing.assert_array_equal(positions, scene.points[k].points)
        prob = np.array(columns[name]["probability"][0].as_py())
        np.testing.assert_array_equal(prob, scene.points[k].probabilities.astype(np.float64))
        colors = np.array(columns[name]["Points3D:colors"][0].as_py(), dtype=np.uint64)
        top = int(np.argmax(prob))
        # Packed 0xRRGGBBAA: the most probable point is drawn in plasma's yellow end.
        r, g, bl = (int(colors[top]) >> s & 0xFF for s in (24, 16, 8))
        assert r > 200 and g > 150 and bl < 120, (r, g, bl)
    origins = np.array(columns["/regions"]["Arrows3D:origins"][0].as_py())
    assert len(origins) == len(result.patches)
    text = columns["/summary"]["TextDocument:text"][0].as_py()
    assert f"state: {result.state}" in str(text)


@pytest.fixture(scope="module")
def arm_files(tmp_path_factory) -> dict[str, str]:
    d = tmp_path_factory.mktemp("arm-view")
    (d / "arm.urdf").write_text(ARM_URDF)
    np.save(d / "wall.npy", wall(0.36, 0.3, 0.15, 0.002, seed=3))
    return {"urdf": str(d / "arm.urdf"), "scan": str(d / "wall.npy"), "dir": str(d)}


def test_robot_scene(arm_files) -> None:
    robot = cp.Robot.from_urdf(arm_files["urdf"])
    cloud = cp.PointCloud(np.load(arm_files["scan"]), sigma=0.002)
    q = np.array([0.0, 0.0, 0.08, 0.0])  # link3 into the wall
    result = cp.collide_robot(robot, q, cloud)
    assert result.state == "collision" and result.links["link3"].state == "collision"
    scene = view.robot_scene(robot, q, cloud, result, label="wall")
    names = [m.name for m in scene.meshes]
    assert names == [n for n in robot.link_names if robot.link_mesh(n) is not None]
    by_name = {m.name: m for m in scene.meshes}
    for name, link in result.links.items():
        expected = link.probability if link.queried else None
        assert by_name[name].probability == expected
    worst = np.zeros(len(cloud))
    for link in result.links.values():
        if link.result is not None:
            worst = np.maximum(worst, link.result.probabilities_b)
    np.testing.assert_array_equal(scene.points[0].probabilities, worst.astype(np.float32))
    poses = robot.link_poses(q)
    v = robot.link_mesh("link2").vertices
    np.testing.assert_allclose(
        by_name["link2"].vertices, v @ poses["link2"][:3, :3].T + poses["link2"][:3, 3], atol=1e-6
    )
    assert result.state in scene.title


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_collide_and_robot_write_views(capsys, tmp_path, arm_files) -> None:
    from cloudprox.examples import write_example_files

    ex = write_example_files(tmp_path / "ex")
    html, rrd = tmp_path / "grasp.html", tmp_path / "grasp.rrd"
    argv = [
        "collide",
        str(ex["gripper"]),
        str(ex["scan"]),
        "--pose-a",
        str(ex["grasp-collision"]),
        "--sensor",
        "depth-camera",
        "--preset",
        "nguyen-2012",
    ]
    code, out, err = run(capsys, *argv, "--html", str(html), "--rerun", str(rrd), "--json")
    assert code == 0, err
    assert '"state": "collision"' in out and str(html.resolve()) in err.replace("\n", "")
    assert 2_000_000 < html.stat().st_size < 10_000_000 and rrd.stat().st_size > 0
    # The mesh side is drawn as a mesh, with its samples coloured.
    types = [o["type"] for o in _k3d_objects(html.read_text())]
    assert "Mesh" in types and "Points" in types

    opened: list[str] = []
    import webbrowser

    orig = webbrowser.open
    webbrowser.open = lambda url: opened.append(url) or True  # type: ignore[assignment]
    try:
        out_html = tmp_path / "v.html"
        code, out, err = run(capsys, "view", *argv[1:], "--html", str(out_html))
        assert code == 0, err
        assert opened == [out_html.resolve().as_uri()] and out_html.is_file()
        code, out, err = run(
            capsys, "view", *argv[1:], "--html", str(tmp_path / "w.html"), "--no-open"
        )
        assert code == 0 and len(opened) == 1
        # --all-points: every quiet point of the scan drawn ("N of N").
        code, out, err = run(
            capsys,
            "view",
            *argv[1:],
            "--html",
            str(tmp_path / "all.html"),
            "--no-open",
            "--all-points",
        )
        assert code == 0, err
        counts = [
            re.match(r".+: (\d+) of (\d+) points", str(o["name"]))
            for o in _k3d_objects((tmp_path / "all.html").read_text())
        ]
        assert [m.group(1) == m.group(2) for m in counts if m] == [True]
    finally:
        webbrowser.open = orig  # type: ignore[assignment]

    robot_html = tmp_path / "arm.html"
    code, out, err = run(
        capsys,
        "robot",
        arm_files["urdf"],
        arm_files["scan"],
        "--sigma",
        "0.002",
        "--q",
        "0,0,0.08,0",
        "--html",
        str(robot_html),
    )
    assert code == 0, err
    names = [o["name"] for o in _k3d_objects(robot_html.read_text())]
    assert "link2" in names


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--surfaces", "-1"], "--surfaces must be >= 0"),
        (["--html", "/no/such/folder/x.html"], "no such folder"),
        (["--html", "noext"], "ending in .html"),
    ],
)
def test_cli_view_errors(capsys, tmp_path, arm_files, extra, message) -> None:
    a = tmp_path / "a.npy"
    np.save(a, cp.synthetic.sample_sphere(200, 0.1))
    code, _, err = run(capsys, "collide", str(a), str(a), "--sigma", "0.002", *extra)
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_cli_robot_html_needs_one_configuration(capsys, tmp_path, arm_files) -> None:
    qs = tmp_path / "qs.csv"
    qs.write_text("0,0,0,0\n0.1,0,0,0\n")
    code, _, err = run(
        capsys,
        "robot",
        arm_files["urdf"],
        arm_files["scan"],
        "--sigma",
        "0.002",
        "--q-file",
        str(qs),
        "--html",
        str(tmp_path / "x.html"),
    )
    assert code == 2 and "give --q, not --q-file" in err


def test_readme_view_line(tmp_path) -> None:
    from tests.robots import readme_block

    line = readme_block("view-cli").strip()
    assert "\n" not in line, "the README promises one command line"
    # The command installed beside this Python (a virtualenv's), else on PATH.
    beside = Path(sys.executable).parent / "cloudprox"
    script = str(beside) if beside.is_file() else shutil.which("cloudprox")
    launcher = [script] if script else [sys.executable, "-m", "cloudprox"]
    for command in line.split("&&"):
        argv = command.split()
        assert argv[0] == "cloudprox"
        done = subprocess.run(
            [*launcher, *argv[1:]], cwd=tmp_path, capture_output=True, text=True, check=False
        )
        assert done.returncode == 0, done.stderr
    html = tmp_path / "grasp.html"
    assert "state: collision" in done.stdout and str(html.resolve()) in done.stdout.replace(
        "\n", ""
    )
    text = html.read_text()
    assert not external_scripts(text) and "state: collision" in text
