"""The reproduction's pictures (matplotlib's Agg canvas, no pyplot state)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from cloudprox.reproduce.methods import THRESHOLD_COLLISION, THRESHOLD_FREE
from cloudprox.reproduce.metrics import NEAR_SIGMA, Metrics, roc_curve

__all__ = [
    "plot_flip_rates",
    "plot_probability_vs_distance",
    "plot_reliability",
    "plot_roc",
    "plot_scan_scene",
]

#: Bins of predicted P in the reliability plot.
RELIABILITY_BINS = 10


def _figure(width: float, height: float):  # type: ignore[no-untyped-def]
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def plot_probability_vs_distance(
    panels: list[tuple[str, float, npt.NDArray[np.float64], dict[str, npt.NDArray[np.float64]]]],
    path: Path,
) -> None:
    """Draw the paper's Fig. 2 made real: score against exact signed distance, one panel per level.

    ``panels`` holds ``(title, sigma, signed_distance (m,), {method: score (draws, m)})``.
    """
    fig = _figure(5.0 * len(panels), 4.2)
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for ax, (title, sigma, dist, scores) in zip(axes, panels, strict=False):
        for (name, s), c in zip(scores.items(), colors, strict=False):
            x = np.broadcast_to(dist / sigma, s.shape).ravel()
            ax.scatter(x, s.ravel(), s=7, alpha=0.5, color=c, label=name, linewidths=0)
        ax.axvline(0.0, color="k", lw=0.8)
        lo, hi = THRESHOLD_FREE, THRESHOLD_COLLISION
        ax.axhspan(lo, hi, color="0.9", zorder=0, label=f"contact band ({lo:g}-{hi:g})")
        ax.set_xlabel("exact signed distance / sigma (negative: penetration)")
        ax.set_ylabel("collision probability P")
        ax.set_title(title)
        ax.set_xlim(-9.0, 12.0)
        ax.legend(fontsize=7, loc="upper right")
    fig.savefig(path, dpi=120)


def reliability(
    score: npt.NDArray[np.float64], label: npt.NDArray[np.bool_], bins: int = RELIABILITY_BINS
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Mean predicted ``P``, observed collision frequency and count per bin of ``P``.

    Bins are ``[k / bins, (k + 1) / bins)`` (the last one closed); empty bins give NaN.
    """
    k = np.minimum((score * bins).astype(int), bins - 1)
    count = np.bincount(k, minlength=bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_p = np.bincount(k, weights=score, minlength=bins) / count
        observed = np.bincount(k, weights=label.astype(float), minlength=bins) / count
    return mean_p, observed, count


def plot_reliability(
    panels: list[tuple[str, float, npt.NDArray[np.float64], dict[str, npt.NDArray[np.float64]]]],
    path: Path,
) -> None:
    """Draw predicted ``P`` against the observed frequency of exact collisions, per level.

    ``panels`` holds ``(title, sigma, signed_distance (m,), {method: score (draws, m)})``
    (as :func:`plot_probability_vs_distance`); a calibrated method lies on the
    diagonal. Marker area grows with the number of answers in the bin.
    """
    fig = _figure(4.2 * len(panels), 4.0)
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for ax, (title, _sigma, dist, scores) in zip(axes, panels, strict=False):
        for (name, s), c in zip(scores.items(), colors, strict=False):
            label = np.broadcast_to(dist <= 0.0, s.shape).ravel()
            mean_p, observed, count = reliability(np.clip(s.ravel(), 0.0, 1.0), label)
            ok = count > 0
            ax.plot(mean_p[ok], observed[ok], "-", color=c, lw=1, alpha=0.6)
            ax.scatter(
                mean_p[ok], observed[ok], s=8 + 60 * count[ok] / count.max(), color=c, label=name
            )
        ax.plot([0, 1], [0, 1], "k--", lw=0.8, label="calibrated")
        ax.set_xlabel("predicted P (bin mean)")
        ax.set_ylabel("observed share of exact collisions")
        ax.set_title(title, fontsize=9)
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.legend(fontsize=6, loc="upper left")
    fig.savefig(path, dpi=120)


def plot_flip_rates(levels: list[str], flips: dict[str, list[float]], path: Path) -> None:
    """Hard-flip rate (free <-> collision under fresh noise) against noise level, per method."""
    fig = _figure(6.5, 4.0)
    ax = fig.subplots()
    x = np.arange(len(levels))
    width = 0.8 / max(1, len(flips))
    for k, (name, values) in enumerate(flips.items()):
        ax.bar(x + k * width - 0.4 + width / 2, values, width, label=name)
    ax.set_xticks(x, levels)
    ax.set_xlabel("noise level (share of the piano's bounding-box diagonal) or data set")
    ax.set_ylabel("hard-flip rate")
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=120)


def plot_roc(
    panels: list[tuple[str, npt.NDArray[np.float64], dict[str, npt.NDArray[np.float64]]]],
    metrics: dict[tuple[str, str], Metrics],
    path: Path,
) -> None:
    """ROC curves over the near queries (|exact distance| <= 5 sigma), one panel per level.

    ``panels`` holds ``(level, near-query labels (m,), {method: score (draws, m)})``.
    """
    fig = _figure(5.0 * len(panels), 4.5)
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, (level, label, scores) in zip(axes, panels, strict=False):
        for name, s in scores.items():
            y = np.broadcast_to(label, s.shape).ravel()
            fpr, tpr = roc_curve(s.ravel(), y)
            ax.plot(fpr, tpr, label=f"{name} (AUC {metrics[(level, name)].auc_near:.3f})")
        ax.plot([0, 1], [0, 1], color="0.6", lw=0.8, ls="--")
        ax.set_xlabel("false-positive rate")
        ax.set_ylabel("true-positive rate")
        ax.set_title(f"near queries (|d| <= {NEAR_SIGMA:g} sigma), noise {level}")
        ax.legend(fontsize=7, loc="lower right")
    fig.savefig(path, dpi=120)


def plot_scan_scene(
    scan: npt.NDArray[np.float64],
    gripper: npt.NDArray[np.float64],
    poses: npt.NDArray[np.float64],
    probability: npt.NDArray[np.float64],
    path: Path,
    shown: int = 40,
) -> None:
    """Draw the real scan (front and side views) with gripper poses coloured by ``P``.

    ``scan`` and the posed ``gripper`` points are in the camera's optical frame
    (x right, y down, z forward); ``shown`` poses are drawn, the first ones.
    """
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable

    fig = _figure(11.0, 5.2)
    front, side = fig.subplots(1, 2, width_ratios=[2.4, 1.0])
    z = scan[:, 2]
    front.scatter(
        scan[:, 0],
        -scan[:, 1],
        s=1.0,
        c=z,
        cmap="Greys_r",
        vmin=z.min() - 0.3,
        vmax=z.max() + 0.6,
        linewidths=0,
    )
    side.scatter(z, -scan[:, 1], s=1.0, color="0.55", linewidths=0)
    cmap = colormaps["coolwarm"]
    for pose, p in zip(poses[:shown], probability[:shown], strict=False):
        g = gripper @ pose[:3, :3].T + pose[:3, 3]
        front.scatter(g[:, 0], -g[:, 1], s=0.4, color=cmap(float(p)), linewidths=0)
        side.scatter(g[:, 2], -g[:, 1], s=0.4, color=cmap(float(p)), linewidths=0)
    front.set_title("real Kinect frame (grey by depth), gripper poses coloured by P")
    front.set_xlabel("x (m, right)")
    front.set_ylabel("up (m)")
    side.set_title("side view")
    side.set_xlabel("depth z (m)")
    for ax in (front, side):
        ax.set_aspect("equal")
    sm = ScalarMappable(cmap=cmap)
    sm.set_clim(0.0, 1.0)
    fig.colorbar(sm, ax=side, label="collision probability P (cloudprox)")
    fig.savefig(path, dpi=110)
