"""Run the reproduction: scenes, noise draws, poses, every method, metrics, outputs.

Outputs in the chosen directory:

``results.csv``
    One row per (level, pose, draw, method): exact signed distance, label, score,
    state, seconds (``nan`` for the paper's aggregations off the poses timed on
    their own, see :func:`cloudprox.reproduce.methods.cloudprox_answers`).
``summary.md``
    The metrics table (markdown) and the headline claims with their verdicts.
``summary.json``
    The same, machine-readable.
``p_vs_distance.png``, ``flip_rate.png``, ``roc.png``
    The pictures.
"""

from __future__ import annotations

import csv
import json
import math
import multiprocessing
import os
import time
from collections.abc import Callable
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cloudprox.reproduce import figures
from cloudprox.reproduce import methods as m
from cloudprox.reproduce.metrics import NEAR_SIGMA, Metrics, compute_metrics
from cloudprox.reproduce.noise import NoiseModel
from cloudprox.reproduce.poses import QueryPoses, sample_poses
from cloudprox.reproduce.realscan import SCAN_STEPS, run_scan
from cloudprox.reproduce.reconstruct import available as reconstruction_available
from cloudprox.scenes import SceneObject, piano, room

__all__ = [
    "Claim",
    "Config",
    "Scene",
    "Summary",
    "available_cpus",
    "check_claims",
    "config_levels",
    "level_inputs",
    "level_name",
    "run",
    "sample_scene",
]

#: The method whose claims are checked, and the baselines.
OURS = "cloudprox quadric surface"
NN, MAP, SPHERES = m.POINT_BASELINES
RECON = "reconstruct"
#: The surface-element model's row.
ELEMENTS = "cloudprox elements quadric"
#: cloudprox variants: (model, surface family, aggregation).
VARIANTS = (
    ("elements", "quadric", "max"),
    ("points", "quadric", "surface"),
    ("points", "quadric", "max"),
    ("points", "quadric", "union"),
    ("points", "quadric", "independent"),
    ("points", "linear", "surface"),
    ("points", "linear", "max"),
)
#: cloudprox variants run on the real scan.
SCAN_VARIANTS = (
    ("elements", "quadric", "max"),
    ("points", "quadric", "surface"),
    ("points", "quadric", "max"),
    ("points", "linear", "surface"),
)
#: The real scan's level name.
KINECT = "kinect"


@dataclass(frozen=True)
class Config:
    """What to run.

    Attributes
    ----------
    piano_points : int
        Approximate number of piano points; the room is sampled at the same density.
    poses : int
        Query poses per noise level (each answered under ``draws`` noise draws).
    levels : tuple of float
        Isotropic noise levels as shares of the piano's bounding-box diagonal.
    anisotropic_levels : tuple of float
        Levels of the depth-camera-like model (axial sigma, lateral sigma / 3, the
        sensor 3 m in front of and 2 m above each object).
    draws : int
        Noise draws per pose (2 give the flip rate).
    scan_poses : int
        Gripper poses of the real-scan experiment (0: skip it).
    seed : int
        Seed of everything.
    """

    piano_points: int = 10_000
    poses: int = 5000
    levels: tuple[float, ...] = (0.005, 0.01, 0.02)
    anisotropic_levels: tuple[float, ...] = (0.01,)
    draws: int = 2
    scan_poses: int = 5000
    seed: int = 0

    @classmethod
    def quick(cls) -> Config:
        """Return the CI smoke run: 3000 piano points, 100 poses, 0.5% and 2% (under 3 minutes)."""
        return cls(
            piano_points=3000,
            poses=100,
            levels=(0.005, 0.02),
            anisotropic_levels=(),
            scan_poses=100,
        )


@dataclass(frozen=True)
class Claim:
    """One headline claim at one level, with its verdict and the numbers behind it."""

    level: str
    claim: str
    holds: bool
    detail: str


@dataclass
class Summary:
    """Everything measured: metrics per (level, method), claims, timings."""

    config: Config
    metrics: dict[tuple[str, str], Metrics] = field(default_factory=dict)
    sigmas: dict[str, float] = field(default_factory=dict)
    claims: list[Claim] = field(default_factory=list)
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)
    scan_facts: dict[str, float] = field(default_factory=dict)


def level_name(share: float, anisotropic: bool) -> str:
    """Return a noise level's name in the table: ``"0.5%"``, ``"1% aniso"``."""
    return f"{100 * share:g}%" + (" aniso" if anisotropic else "")


def config_levels(config: Config) -> list[tuple[float, bool]]:
    """Return the levels of ``config`` in the run's order: ``(share, anisotropic)``."""
    return [(s, False) for s in config.levels] + [(s, True) for s in config.anisotropic_levels]


@dataclass(frozen=True)
class Scene:
    """The piano and the room with their noise-free sampled points, as the run samples them.

    Attributes
    ----------
    piano, room : SceneObject
        The two objects (the piano moves, the room stays).
    piano_points, room_points : ndarray, shape (n, 3)
        Their surfaces sampled at one density (``config.piano_points`` on the piano).
    spacing : float
        The sampling spacing of both clouds together (metres).
    """

    piano: SceneObject
    room: SceneObject
    piano_points: np.ndarray
    room_points: np.ndarray
    spacing: float


def sample_scene(config: Config) -> Scene:
    """Sample the piano and the room as :func:`run` does (same density, same seeds)."""
    p_obj, r_obj = piano(), room()
    density = config.piano_points / sum(part.mesh.area for part in p_obj.parts)
    piano_pts, _ = p_obj.sample(density, config.seed)
    room_pts, _ = r_obj.sample(density, config.seed + 1)
    spacing = m.sampling_spacing(np.concatenate([piano_pts, room_pts]))
    return Scene(p_obj, r_obj, piano_pts, room_pts, spacing)


def level_inputs(
    config: Config, k: int, scene: Scene, poses: int
) -> tuple[float, QueryPoses, list[m.Draw]]:
    """Return level ``k``'s sigma, query poses and noise draws, as the run makes them.

    ``scene`` is :func:`sample_scene`'s; ``poses`` query poses (``config.poses``
    in the run). The level's generator is seeded from ``config.seed`` and ``k``,
    so any one level can be made alone with the run's poses and draws
    (``benches/reproduce_levels.py``).
    """
    share, aniso = config_levels(config)[k]
    p_obj, r_obj = scene.piano, scene.room
    piano_pts, room_pts = scene.piano_points, scene.room_points
    sigma = share * p_obj.diagonal
    rng = np.random.default_rng(config.seed * 1000 + k)
    q = sample_poses(p_obj, r_obj, poses, sigma, rng)
    axes = (0.0, -3.0, 2.0) if aniso else None
    noise_p, noise_r = NoiseModel(sigma, axes), NoiseModel(sigma, axes)
    draws = []
    for _ in range(config.draws):
        a, ca = noise_p.draw(piano_pts, rng)
        b, cb = noise_r.draw(room_pts, rng)
        d = m.Draw(a, ca, b, cb)
        d.clouds()
        draws.append(d)
    return sigma, q, draws


def check_claims(summary: Summary) -> list[Claim]:
    """Check the issue's headline claims, per level, on ``summary``'s own metrics.

    Near-contact AUC above every baseline's; decided accuracy above the
    nearest-neighbour baseline's with no larger undecided share; hard-flip rate at
    most a third of the collision map's; false positives beyond 3 sigma below 1%.
    """
    out: list[Claim] = []
    for level in summary.sigmas:
        ours = summary.metrics[(level, OURS)]
        base = {
            k[1]: v
            for k, v in summary.metrics.items()
            if k[0] == level and not k[1].startswith("cloudprox")
        }
        best = max(base, key=lambda k: base[k].auc_near)
        out.append(
            Claim(
                level,
                "near-contact AUC above every baseline's",
                all(ours.auc_near > b.auc_near for b in base.values()),
                f"{ours.auc_near:.3f} vs best baseline {best} {base[best].auc_near:.3f}",
            )
        )
        nn = base[NN]
        out.append(
            Claim(
                level,
                "decided accuracy above nn-gap's with no larger undecided share",
                ours.decided_accuracy > nn.decided_accuracy and ours.undecided <= nn.undecided,
                f"{ours.decided_accuracy:.3f} / {ours.undecided:.1%} undecided vs "
                f"{nn.decided_accuracy:.3f} / {nn.undecided:.1%}",
            )
        )
        cm = base[MAP]
        out.append(
            Claim(
                level,
                "hard-flip rate at most a third of the collision map's",
                ours.hard_flip <= cm.hard_flip / 3.0,
                f"{ours.hard_flip:.3f} vs {cm.hard_flip:.3f}",
            )
        )
        fp = ours.false_positive_3s
        out.append(
            Claim(level, "false positives beyond 3 sigma below 1%", bool(fp < 0.01), f"{fp:.2%}")
        )
    return out


def _table(summary: Summary) -> str:
    head = (
        "| level | method | ECE | Brier | worst bin | AUC all | AUC near | Spearman | "
        "decided acc. | undecided | hard flips | FP > 3σ | FN < -3σ | median ms |"
    )
    lines = [head, "|" + "---|" * 14]
    fmt = lambda x, p=".3f": "–" if not math.isfinite(x) else format(x, p)  # noqa: E731
    for (level, name), mt in summary.metrics.items():
        lines.append(
            f"| {level} | {name} | {fmt(mt.ece)} | {fmt(mt.brier)} | {fmt(mt.worst_bin)} | "
            f"{fmt(mt.auc_all)} | "
            f"{fmt(mt.auc_near)} | {fmt(mt.spearman)} | "
            f"{fmt(mt.decided_accuracy)} | {fmt(mt.undecided, '.1%')} | "
            f"{fmt(mt.hard_flip, '.1%')} | "
            f"{fmt(mt.false_positive_3s, '.1%')} | {fmt(mt.false_negative_3s, '.1%')} | "
            f"{fmt(mt.median_ms, '.2f')} |"
        )
    return "\n".join(lines)


def _scan_text(summary: Summary) -> str:
    f = summary.scan_facts
    if not f:
        return ""
    return (
        f"Level `{KINECT}`: the real Kinect v1 frame of Debian's mrpt-common "
        f"({f['frame_points']:.0f} points) and the Franka Panda gripper "
        f"({f['gripper_points']:.0f} surface points, σ 1 mm) at {summary.config.scan_poses} "
        f"poses; the methods see every 4th pixel ({f['cloud_points']:.0f} points, spacing "
        f"{1e3 * f['cloud_spacing_m']:.1f} mm, Kinect noise model), the two draws are the "
        "two disjoint pixel grids. **Approximate** ground truth: the exact gripper mesh "
        "against the surface reconstructed from the full frame "
        f"({f['reference_triangles']:.0f} triangles). Distances in units of each pose's σ "
        f"({1e3 * f['sigma_min_m']:.1f}–{1e3 * f['sigma_max_m']:.1f} mm).\n\n"
    )


def _reliability_text(summary: Summary, level: str) -> str:
    """Return the reliability tables of ``level``'s methods side by side ("" without any)."""
    rows = {name: mt.reliability for (lv, name), mt in summary.metrics.items() if lv == level}
    rows = {k: v for k, v in rows.items() if v}
    if not rows:
        return ""
    bins = sorted({(lo, hi) for table in rows.values() for lo, hi, *_ in table})
    cells = {k: {(lo, hi): (n, p, f) for lo, hi, n, p, f in v} for k, v in rows.items()}
    lines = [
        f"## Reliability on `{level}`\n",
        "Per bin of the score read as P: answers, mean P / share that truly collides "
        "(worst bin: the largest difference over bins of 20 or more answers).\n",
        "| P | " + " | ".join(rows) + " |",
        "|" + "---|" * (len(rows) + 1),
    ]
    for b in bins:
        row = ["{}: {:.2f} / {:.2f}".format(*cells[k][b]) if b in cells[k] else "" for k in rows]
        lines.append(f"| [{b[0]:.1f}, {b[1]:.1f}) | " + " | ".join(row) + " |")
    return "\n".join(lines) + "\n\n"


def _markdown(summary: Summary) -> str:
    c = summary.config
    sig = ", ".join(f"{k}: σ = {1e3 * v:.1f} mm" for k, v in summary.sigmas.items())
    claims = "\n".join(
        f"| {x.level} | {x.claim} | {'yes' if x.holds else '**no**'} | {x.detail} |"
        for x in summary.claims
    )
    return (
        "# cloudprox reproduce\n\n"
        f"Piano ({c.piano_points} points requested) in a room sampled at the same density; "
        f"{c.poses} poses per level, {c.draws} noise draws each; seed {c.seed}; {sig}. "
        f"Near = exact |signed distance| <= {NEAR_SIGMA:g} σ. Run time {summary.seconds:.0f} s.\n\n"
        + _scan_text(summary)
        + "".join(f"Note: {x}.\n\n" for x in summary.notes)
        + f"{_table(summary)}\n\n"
        + _reliability_text(summary, KINECT)
        + "## Headline claims\n\n"
        f"| level | claim | holds | measured |\n|---|---|---|---|\n{claims}\n"
    )


def run(
    config: Config,
    out: Path,
    progress: Callable[[str, int], None] | None = None,
    many: Callable[..., Any] | None = None,
    workers: int = 1,
) -> Summary:
    """Run every method at every level and write the outputs into ``out``.

    Parameters
    ----------
    config : Config
        What to run.
    out : Path
        Output directory (created).
    progress : callable, optional
        Called as ``progress(description, advance)`` after each step; the total
        number of steps is :func:`steps`.
    many : callable, optional
        Replaces :func:`cloudprox.collide_many` in cloudprox's queries (e.g.
        :func:`cloudprox.distributed.collide_many`, the same answers as Ray tasks).
    workers : int, optional
        Processes for the Python baselines (default 1: in this process;
        ``cloudprox reproduce`` uses :func:`available_cpus`). The answers do not
        depend on it. More than one spawns processes, which re-import the
        calling script: call it under ``if __name__ == "__main__":``.

    Returns
    -------
    Summary
    """
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    if workers == 1:
        return _run(config, out, progress, many, None, 1)
    # Spawned, not forked: the parent's Rust thread pools do not survive a fork.
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
    try:
        summary = _run(config, out, progress, many, pool, workers)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    return summary


def available_cpus() -> int:
    """Return the number of CPUs this process may use (all of the machine's where unknown)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def _run(
    config: Config,
    out: Path,
    progress: Callable[[str, int], None] | None,
    many: Callable[..., Any] | None,
    pool: Executor | None,
    workers: int,
) -> Summary:
    """:func:`run` with the baselines' process ``pool`` (``None``: in this process)."""
    t0 = time.perf_counter()
    tick = progress or (lambda _d, _n: None)
    out.mkdir(parents=True, exist_ok=True)
    scene = sample_scene(config)
    spacing = scene.spacing
    tick("sampled the scene", 1)
    summary = Summary(config)
    with_reconstruction = reconstruction_available()
    if not with_reconstruction:
        summary.notes.append(
            "reconstruct-then-collide skipped: Open3D is not installed "
            "(pip install 'cloudprox[reproduce]')"
        )
    rows: list[tuple[object, ...]] = []
    fig_p: list[tuple[str, float, np.ndarray, dict[str, np.ndarray]]] = []
    fig_roc: list[tuple[str, np.ndarray, dict[str, np.ndarray]]] = []
    for k, (share, aniso) in enumerate(config_levels(config)):
        name = level_name(share, aniso)
        sigma, q, draws = level_inputs(config, k, scene, config.poses)
        summary.sigmas[name] = sigma
        tick(f"{name}: poses", 1)
        tick(f"{name}: noise draws", 1)
        answers = m.variant_answers(draws, q.poses, VARIANTS, many, tick, name)
        answers.update(m.point_baseline_answers(draws, q.poses, spacing, pool, workers))
        if with_reconstruction:
            m.reconstruct_draws(draws, spacing, sigma, pool)
            answers[RECON] = [m.reconstruct_answer(d, q.poses, spacing, sigma) for d in draws]
        tick(f"{name}: baselines", 1)
        scores: dict[str, np.ndarray] = {}
        for method, ans in answers.items():
            sc = np.stack([x.score for x in ans])
            st = np.stack([x.state for x in ans])
            sec = np.stack([x.seconds for x in ans])
            scores[method] = sc
            summary.metrics[(name, method)] = compute_metrics(sc, st, sec, q.signed_distance, sigma)
            rows.extend(
                _rows(name, np.full(len(q.poses), sigma), q.signed_distance, method, sc, st, sec)
            )
        shown = {k2: scores[k2] for k2 in (ELEMENTS, OURS, "cloudprox quadric max", NN)}
        fig_p.append((f"noise {name} (σ = {1e3 * sigma:.1f} mm)", sigma, q.signed_distance, shown))
        near = np.abs(q.signed_distance) <= NEAR_SIGMA * sigma
        fig_roc.append(
            (
                name,
                q.signed_distance[near] <= 0.0,
                {
                    k2: v[:, near]
                    for k2, v in scores.items()
                    if k2 in (ELEMENTS, OURS, "cloudprox linear surface", NN, MAP, SPHERES, RECON)
                },
            )
        )
    if config.scan_poses > 0 and not with_reconstruction:
        summary.notes.append(
            "real-scan experiment skipped: its reference surface is a reconstruction, "
            "which needs Open3D"
        )
    if config.scan_poses > 0 and with_reconstruction:
        scan = run_scan(config.scan_poses, config.seed, SCAN_VARIANTS, tick, many, pool, workers)
        summary.scan_facts = scan.facts
        unit = scan.poses.signed_distance / scan.poses.sigma
        for method, sc in scan.scores.items():
            summary.metrics[(KINECT, method)] = scan.metrics[method]
            rows.extend(
                _rows(
                    KINECT,
                    scan.poses.sigma,
                    scan.poses.signed_distance,
                    method,
                    sc,
                    scan.states[method],
                    scan.seconds[method],
                )
            )
        figures.plot_scan_scene(
            scan.cloud,
            scan.gripper_points,
            scan.poses.poses,
            scan.scores[OURS][0],
            out / "kinect_scene.png",
        )
        shown = {k2: scan.scores[k2] for k2 in (ELEMENTS, OURS, "cloudprox quadric max", NN)}
        fig_p.append(("real Kinect frame, Panda gripper (approx. truth)", 1.0, unit, shown))
        near = np.abs(unit) <= NEAR_SIGMA
        fig_roc.append(
            (
                KINECT,
                unit[near] <= 0.0,
                {
                    k2: v[:, near]
                    for k2, v in scan.scores.items()
                    if k2 in (ELEMENTS, OURS, "cloudprox linear surface", NN, MAP, SPHERES, RECON)
                },
            )
        )
    summary.seconds = time.perf_counter() - t0
    summary.claims = check_claims(summary)
    with (out / "results.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(
            [
                "level",
                "sigma_m",
                "pose",
                "draw",
                "method",
                "exact_signed_distance_m",
                "exact_collision",
                "score",
                "state",
                "seconds",
            ]
        )
        w.writerows(rows)
    figures.plot_probability_vs_distance(fig_p, out / "p_vs_distance.png")
    methods_shown = [
        ELEMENTS,
        OURS,
        "cloudprox quadric max",
        "cloudprox linear surface",
        NN,
        MAP,
        SPHERES,
    ]
    methods_shown += [RECON] if with_reconstruction else []
    flip_levels = list(summary.sigmas) + ([KINECT] if summary.scan_facts else [])
    figures.plot_flip_rates(
        flip_levels,
        {
            k2: [
                summary.metrics[(lv, k2)].hard_flip if (lv, k2) in summary.metrics else np.nan
                for lv in flip_levels
            ]
            for k2 in methods_shown
        },
        out / "flip_rate.png",
    )
    figures.plot_roc(fig_roc, summary.metrics, out / "roc.png")
    figures.plot_reliability(fig_p, out / "reliability.png")
    (out / "summary.md").write_text(_markdown(summary))
    (out / "summary.json").write_text(
        json.dumps(
            {
                "config": asdict(config),
                "sigmas_m": summary.sigmas,
                "metrics": [
                    {"level": lv, "method": mt, **asdict(x)}
                    for (lv, mt), x in summary.metrics.items()
                ],
                "claims": [asdict(c) for c in summary.claims],
                "notes": summary.notes,
                "kinect": summary.scan_facts,
                "seconds": summary.seconds,
            },
            indent=1,
        )
    )
    tick("wrote the outputs", 1)
    return summary


def steps(config: Config) -> int:
    """Return the number of progress steps :func:`run` reports."""
    n_levels = len(config.levels) + len(config.anisotropic_levels)
    with_scan = config.scan_poses > 0 and reconstruction_available()
    scan = SCAN_STEPS + len(SCAN_VARIANTS) if with_scan else 0
    return 2 + n_levels * (3 + len(VARIANTS)) + scan


def _rows(
    level: str,
    sigma: np.ndarray,
    signed: np.ndarray,
    method: str,
    score: np.ndarray,
    state: np.ndarray,
    seconds: np.ndarray,
) -> list[tuple[object, ...]]:
    """CSV rows of one method at one level: one per (pose, draw)."""
    return [
        (
            level,
            sigma[j],
            j,
            r,
            method,
            signed[j],
            bool(signed[j] <= 0.0),
            score[r, j],
            state[r, j],
            seconds[r, j],
        )
        for j in range(score.shape[1])
        for r in range(score.shape[0])
    ]
