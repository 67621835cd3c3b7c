"""Size and opening time of the interactive HTML view, plotly against k3d.

Two noisy spheres, 0.5 sigma apart (hundreds of points with a probability),
written by :func:`cloudprox.view.write_html` with each renderer and opened in
headless Chromium (``--disable-gpu``: WebGL in software, SwiftShader), driven
over the DevTools protocol (``tests/chromium.py``). Each run starts a new
Chromium (no cache), waits until it has settled, then loads the file; the page
reports, in milliseconds after navigation started:

- library: its renderer's JavaScript parsed and run (plotly.js, or k3d's bundle),
- scene: the data decoded and the scene built (``Plotly.newPlot`` resolved, or
  k3d's snapshot loaded),
- drawn: two animation frames after that, the first picture on screen
  (``window.cloudproxDrawn``, which the view sets; the wall time to see it
  changes is the same within the polling step of 20 ms).

Chromium's own start-up (launch to its first DevTools answer) and a blank
page's load are reported apart. Runs are interleaved and medians printed; the
machine is shared, so the load average before and after is printed too.

Usage: python benches/view.py [--points 100000] [--floor-points 2000] [--repeat 5] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.chromium import Chromium

import cloudprox as cp
from cloudprox import view

#: (label, renderer, all_points) of the configurations measured.
CONFIGS = (
    ("plotly (before)", "plotly", True),
    ("k3d, all points", "k3d", True),
    ("k3d (default)", "k3d", False),
)


def spheres(points: int) -> view.Scene:
    """Make the view of two noisy spheres of ``points // 2`` points each, 0.5 sigma apart."""
    half = max(points // 2, 1)
    sigma = 0.002
    base = cp.synthetic.sample_sphere(half, 0.1)
    a = cp.PointCloud(cp.synthetic.add_noise(base, sigma, seed=1), sigma=sigma)
    b = cp.PointCloud(cp.synthetic.add_noise(base, sigma, seed=2), sigma=sigma)
    pose_b = cp.pose.from_translation((0.2 + 0.5 * sigma, 0.0, 0.0))
    return view.collision_scene(cp.collide(a, b, pose_b=pose_b))


def marked(html: Path, renderer: str) -> Path:
    """Copy ``html`` into a page that also records when its library ran and its scene loaded."""
    text = html.read_text(encoding="utf-8")
    lib = "<script>window.cloudproxLib=performance.now()</script>"
    if renderer == "k3d":
        anchors = [
            ("<script>\nvar K3DInstance = (function () {", lib + "\n"),
            (
                "K3DInstance.then(function (K3DInstance) {\n",
                "window.cloudproxLoaded=performance.now();\n",
            ),
        ]
        first, second = anchors
        text = text.replace(first[0], first[1] + first[0], 1)
        text = text.replace(second[0], second[0] + second[1], 1)
    else:
        start = text.index("<script>/**\n* plotly.js")
        end = text.index("</script>", start) + len("</script>")
        text = text[:end] + lib + text[end:]
        text = text.replace(
            "requestAnimationFrame(function(){requestAnimationFrame(",
            "window.cloudproxLoaded=performance.now();"
            "requestAnimationFrame(function(){requestAnimationFrame(",
            1,
        )
    if "cloudproxLib" not in text or "cloudproxLoaded" not in text:
        raise RuntimeError(f"{html}: the page's layout changed; update benches/view.py")
    out = html.with_name(html.stem + "-timed.html")
    out.write_text(text, encoding="utf-8")
    return out


def one_run(page: Path) -> dict[str, float]:
    """Open ``page`` in a new Chromium; its phases in seconds."""
    with Chromium() as browser:
        drawn = browser.open(page)
        marks = browser.eval("[window.cloudproxLib || 0, window.cloudproxLoaded || 0]")
        return {
            "startup": browser.startup_s,
            "library": marks[0] / 1e3,
            "scene": (marks[1] - marks[0]) / 1e3,
            "draw": drawn - marks[1] / 1e3,
            "drawn": drawn,
        }


def main() -> None:
    """Write the files, time them in Chromium, print one table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--floor-points", type=int, default=2_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--out", default=None, help="keep the files here")
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="cloudprox-view-bench-"))
    out.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()[0]

    pages: dict[tuple[str, int], tuple[Path, dict[str, float]]] = {}
    for n in (args.floor_points, args.points):
        scene = spheres(n)
        loud = sum(int(np.sum(x.probabilities >= scene.quiet_below)) for x in scene.points)
        for label, renderer, all_points in CONFIGS:
            path = out / f"{n}-{renderer}-{'all' if all_points else 'thinned'}.html"
            t = time.perf_counter()
            view.write_html(scene, path, renderer=renderer, all_points=all_points)
            written = time.perf_counter() - t
            if renderer == "k3d":
                objects = view.to_k3d(scene, all_points=all_points).objects
                drawn = sum(len(o.positions) for o in objects if o.name.split(":")[0] in ("A", "B"))
            else:
                drawn = sum(len(x.points) for x in scene.points)
            info = {"n": n, "loud": loud, "drawn_points": drawn, "mb": path.stat().st_size / 1e6}
            info["written"] = written
            pages[(label, n)] = (marked(path, renderer), info)
    blank = out / "blank.html"
    blank.write_text("<html><body><script>window.cloudproxDrawn=performance.now()</script>")

    runs: dict[tuple[str, int] | str, list[dict[str, float]]] = {k: [] for k in pages}
    runs["blank"] = []
    for _ in range(args.repeat):
        for key, (page, _info) in pages.items():
            runs[key].append(one_run(page))
        runs["blank"].append(one_run_blank(blank))

    def med(rows: list[dict[str, float]], key: str) -> float:
        return statistics.median(r[key] for r in rows)

    print(
        f"| renderer | points | with p >= 1e-3 | points drawn | HTML MB | written s | "
        f"library s | scene s | draw s | **drawn s** | (median of {args.repeat})"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for (label, n), (_page, info) in pages.items():
        rows = runs[(label, n)]
        print(
            f"| {label} | {n} | {info['loud']} | {info['drawn_points']} | {info['mb']:.2f} | "
            f"{info['written']:.2f} | {med(rows, 'library'):.2f} | {med(rows, 'scene'):.2f} | "
            f"{med(rows, 'draw'):.2f} | **{med(rows, 'drawn'):.2f}** |"
        )
    every = [r for k, rows in runs.items() if k != "blank" for r in rows]
    print(
        "\nChromium start-up (launch to its first DevTools answer): "
        f"{med(every, 'startup'):.2f} s; a blank page drawn after "
        f"{med(runs['blank'], 'drawn'):.3f} s"
    )
    print(f"load average (1 min): {load_before:.2f} before, {os.getloadavg()[0]:.2f} after")
    print(f"files in {out}")


def one_run_blank(page: Path) -> dict[str, float]:
    """Open the blank page in a new Chromium."""
    with Chromium() as browser:
        return {"startup": browser.startup_s, "drawn": browser.open(page)}


if __name__ == "__main__":
    main()
