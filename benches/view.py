"""Size and opening time of the interactive HTML view of a 100 000-point scene.

Two noisy spheres of 50 000 points each, 0.5 sigma apart (hundreds of points
with a probability), written by :func:`cloudprox.view.write_html`; the file is
opened in headless Chromium, which reports how long after navigation started
plotly had drawn the scene (``performance.now()`` when ``Plotly.newPlot``
resolved), and the wall time of a screenshot run beside that of a blank page.

Usage: python benches/view.py [--points 100000] [--repeat 3] [--out DIR]
"""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import cloudprox as cp
from cloudprox import view

MARK = "cloudprox-drawn-ms="


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return name
    raise SystemExit("no chromium found (scripts/system-deps.sh installs it)")


def drawn_ms(html: Path, png: Path, profile: Path) -> float:
    """Milliseconds from navigation start to the plot drawn, as the page measured it.

    The page logs them to the console when plotly fires ``plotly_afterplot``;
    headless Chromium prints its console to stderr and takes the screenshot
    once the page has loaded and drawn.
    """
    err = subprocess.run(
        [
            _chromium(),
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-logging=stderr",
            f"--user-data-dir={profile}",
            "--window-size=1000,800",
            f"--screenshot={png}",
            html.resolve().as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stderr
    m = re.search(MARK + r"([0-9.]+)", err)
    if not m:
        raise RuntimeError("the page did not report its drawing time")
    return float(m.group(1))


def screenshot_seconds(html: Path, png: Path, profile: Path) -> float:
    """Wall time of one headless screenshot of ``html``."""
    t = time.perf_counter()
    subprocess.run(
        [
            _chromium(),
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            f"--user-data-dir={profile}",
            "--window-size=1000,800",
            f"--screenshot={png}",
            html.resolve().as_uri(),
        ],
        capture_output=True,
        timeout=120,
        check=True,
    )
    return time.perf_counter() - t


def measure(points: int, repeat: int, out: Path) -> dict[str, float]:
    """Write the view of a ``points``-point scene into ``out``; time it in Chromium."""
    out.mkdir(parents=True, exist_ok=True)
    half = points // 2
    sigma = 0.002
    base = cp.sample_sphere(half, 0.1)
    a = cp.PointCloud(cp.add_noise(base, sigma, seed=1), sigma=sigma)
    b = cp.PointCloud(cp.add_noise(base, sigma, seed=2), sigma=sigma)
    pose_b = np.eye(4)
    pose_b[0, 3] = 0.2 + 0.5 * sigma
    result = cp.collide(a, b, pose_b=pose_b)
    t = time.perf_counter()
    scene = view.collision_scene(result)
    html = view.write_html(scene, out / "view.html")
    write_s = time.perf_counter() - t
    # The same figure, logging when plotly has drawn it (two animation frames
    # after Plotly.newPlot resolved: the frame is on screen), for drawn_ms.
    marked = out / "view-timed.html"
    view.to_figure(scene).write_html(
        str(marked),
        include_plotlyjs=True,
        full_html=True,
        post_script="requestAnimationFrame(function(){requestAnimationFrame(function(){"
        f"console.log('{MARK}'+performance.now())}})}})",
    )
    blank = out / "blank.html"
    blank.write_text("<html><body>blank</body></html>")
    profile = out / "chromium-profile"
    drawn = [drawn_ms(marked, out / "timed.png", profile) / 1e3 for _ in range(repeat)]
    shot = [screenshot_seconds(html, out / "view.png", profile) for _ in range(repeat)]
    empty = [screenshot_seconds(blank, out / "blank.png", profile) for _ in range(repeat)]
    loud = sum(int(np.sum(x.probabilities >= scene.quiet_below)) for x in scene.points)
    return {
        "points": len(a) + len(b),
        "loud": loud,
        "mb": html.stat().st_size / 1e6,
        "write_s": write_s,
        "drawn_s": statistics.median(drawn),
        "shot_s": statistics.median(shot),
        "blank_s": statistics.median(empty),
    }


def main() -> None:
    """Run the measurement and print one table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--floor-points", type=int, default=2_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default=None, help="keep the files here")
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="cloudprox-view-bench-"))
    print(
        f"| points | with p >= 1e-3 | HTML MB | written s | drawn s (page) | "
        f"screenshot s (wall) | blank page s | (median of {args.repeat})"
    )
    print("|---|---|---|---|---|---|---|")
    for n in (args.floor_points, args.points):
        r = measure(n, args.repeat, out / str(n))
        print(
            f"| {r['points']} | {r['loud']} | {r['mb']:.2f} | {r['write_s']:.2f} | "
            f"{r['drawn_s']:.2f} | {r['shot_s']:.2f} | {r['blank_s']:.2f} |"
        )
    print(f"files in {out}")


if __name__ == "__main__":
    main()
