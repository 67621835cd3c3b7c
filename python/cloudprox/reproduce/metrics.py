"""Metrics of one method at one noise level, against the exact ground truth."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.stats import rankdata, spearmanr

__all__ = [
    "Calibration",
    "Metrics",
    "auc",
    "auc_near",
    "calibration",
    "compute_metrics",
    "roc_curve",
]

FloatArray = npt.NDArray[np.float64]

#: Exact separation (in sigma) within which a query counts as near contact.
NEAR_SIGMA = 5.0
#: Exact distance / penetration (in sigma) beyond which a wrong state is a hard error.
HARD_SIGMA = 3.0


def auc(score: FloatArray, label: npt.NDArray[np.bool_]) -> float:
    """ROC AUC (Mann-Whitney, ties count one half); NaN if one class is missing."""
    pos, neg = int(label.sum()), int((~label).sum())
    if pos == 0 or neg == 0:
        return float("nan")
    ranks = rankdata(score)
    return float((ranks[label].sum() - pos * (pos + 1) / 2.0) / (pos * neg))


def auc_near(score: FloatArray, signed_distance: FloatArray, sigma: float) -> float:
    """ROC AUC over the near queries (``|signed_distance| <= NEAR_SIGMA * sigma``).

    ``score`` is ``(draws, poses)`` (the draws pooled) or ``(poses,)``; the
    label is ``signed_distance <= 0``, as in :func:`compute_metrics`.
    """
    d = np.broadcast_to(signed_distance, np.shape(score)).ravel()
    near = np.abs(d) <= NEAR_SIGMA * sigma
    return auc(np.ravel(score)[near], (d <= 0.0)[near])


def roc_curve(score: FloatArray, label: npt.NDArray[np.bool_]) -> tuple[FloatArray, FloatArray]:
    """Return false- and true-positive rates over every threshold (from strictest)."""
    order = np.argsort(-score, kind="stable")
    s, y = score[order], label[order]
    distinct = np.r_[np.nonzero(np.diff(s))[0], len(s) - 1]
    tp = np.cumsum(y)[distinct]
    fp = np.cumsum(~y)[distinct]
    tpr = np.r_[0.0, tp / max(1, int(y.sum()))]
    fpr = np.r_[0.0, fp / max(1, int((~y).sum()))]
    return fpr, tpr


@dataclass(frozen=True)
class Metrics:
    """Every metric of one method at one level (see the module's docs for each).

    Attributes
    ----------
    auc_all, auc_near : float
        ROC AUC against the exact label, over all queries and over the near ones.
    spearman : float
        Spearman correlation of the score with minus the exact signed distance
        (1 = perfect ordering).
    decided_accuracy : float
        Share of correct states among ``free`` and ``collision`` answers.
    undecided : float
        Share of ``contact`` answers.
    hard_flip : float
        Share of poses whose state is ``free`` under one noise draw and
        ``collision`` under the other.
    false_positive_3s : float
        Share of ``collision`` answers among poses farther than 3 sigma.
    false_negative_3s : float
        Share of ``free`` answers among poses penetrating deeper than 3 sigma.
    median_ms : float
        Median time per query (milliseconds), over the timed ones (a time of
        ``nan`` marks a query answered but not timed on its own).
    n : int
        Number of answers (poses times draws).
    ece, brier, log_loss, worst_bin : float
        Expected calibration error, Brier score, log-loss and worst reliability
        bin (holding 20 or more answers, :meth:`Calibration.worst_bin`) of the
        score read as a probability (clipped to ``[0, 1]``; see
        :func:`calibration`), NaN when a score is NaN.
    reliability : tuple
        The reliability table behind them (:attr:`Calibration.table`: one row
        ``(low, high, count, mean P, observed frequency)`` per non-empty bin),
        empty when a score is NaN.
    """

    auc_all: float
    auc_near: float
    spearman: float
    decided_accuracy: float
    undecided: float
    hard_flip: float
    false_positive_3s: float
    false_negative_3s: float
    median_ms: float
    n: int
    ece: float = float("nan")
    brier: float = float("nan")
    log_loss: float = float("nan")
    worst_bin: float = float("nan")
    reliability: tuple[tuple[float, float, int, float, float], ...] = ()


def _share(mask: npt.NDArray[np.bool_], among: npt.NDArray[np.bool_]) -> float:
    k = int(among.sum())
    return float((mask & among).sum() / k) if k else float("nan")


def compute_metrics(
    score: FloatArray,
    state: npt.NDArray[np.str_],
    seconds: FloatArray,
    signed_distance: FloatArray,
    sigma: float,
) -> Metrics:
    """Metrics of answers of shape ``(draws, poses)`` against exact distances ``(poses,)``.

    The label is ``signed_distance <= 0`` (exact contact counts as collision).
    """
    draws = score.shape[0]
    d = np.broadcast_to(signed_distance, score.shape).ravel()
    s, st = score.ravel(), state.ravel()
    label = d <= 0.0
    decided = st != "contact"
    correct = (st == "collision") == label
    rho = spearmanr(s, -d).statistic if np.ptp(s) > 0 else float("nan")
    flips = (
        np.mean(
            ((state[0] == "free") & (state[1] == "collision"))
            | ((state[0] == "collision") & (state[1] == "free"))
        )
        if draws >= 2
        else float("nan")
    )
    return Metrics(
        auc_all=auc(s, label),
        auc_near=auc_near(score, signed_distance, sigma),
        spearman=float(rho),
        decided_accuracy=_share(correct, decided),
        undecided=float(np.mean(~decided)),
        hard_flip=float(flips),
        false_positive_3s=_share(st == "collision", d > HARD_SIGMA * sigma),
        false_negative_3s=_share(st == "free", d < -HARD_SIGMA * sigma),
        median_ms=float(np.nanmedian(seconds) * 1e3),
        n=int(s.size),
        **_calibration_scores(s, label),
    )


def _calibration_scores(score: FloatArray, label: npt.NDArray[np.bool_]) -> dict[str, Any]:
    if not np.all(np.isfinite(score)):
        return {}
    cal = calibration(np.clip(score, 0.0, 1.0), label)
    return {
        "ece": cal.ece,
        "brier": cal.brier,
        "log_loss": cal.log_loss,
        "worst_bin": cal.worst_bin(),
        "reliability": cal.table,
    }


#: The reliability table's bins of ``P``: ten of equal width, as ECE is defined.
RELIABILITY_BINS = 10


@dataclass(frozen=True)
class Calibration:
    """How well a probability matches the observed frequency of collision.

    ``ece`` is the expected calibration error: the mean over ten equal-width
    bins of ``P`` of ``|mean P - observed frequency|``, weighted by the bins'
    counts. ``brier`` is the mean of ``(P - label)^2``, ``log_loss`` the mean
    of ``-log`` of the probability given to what happened (``P`` clipped to
    ``[1e-6, 1 - 1e-6]``). ``table`` holds one row per non-empty bin: ``(low,
    high, count, mean P, observed frequency)``.
    """

    ece: float
    brier: float
    log_loss: float
    table: tuple[tuple[float, float, int, float, float], ...]

    def worst_bin(self, min_count: int = 20) -> float:
        """Return the largest ``|mean P - frequency|`` over bins holding ``min_count`` or more."""
        gaps = [abs(p - f) for _, _, n, p, f in self.table if n >= min_count]
        return max(gaps, default=float("nan"))


def calibration(probability: FloatArray, label: npt.NDArray[np.bool_]) -> Calibration:
    """Return the calibration of ``probability`` against the exact ``label`` (same shape).

    Raises
    ------
    ValueError
        On empty or mismatched arrays, or a probability outside ``[0, 1]`` or NaN.
    """
    p = np.asarray(probability, dtype=np.float64).ravel()
    y = np.asarray(label, dtype=bool).ravel()
    if p.size == 0 or p.shape != y.shape:
        raise ValueError(f"calibration needs two arrays of one size > 0, got {p.size}, {y.size}")
    if not np.all((p >= 0.0) & (p <= 1.0)):
        raise ValueError("calibration: every probability must be in [0, 1] (and not NaN)")
    edges = np.linspace(0.0, 1.0, RELIABILITY_BINS + 1)
    which = np.clip(np.digitize(p, edges[1:-1]), 0, RELIABILITY_BINS - 1)
    rows = []
    ece = 0.0
    for k in range(RELIABILITY_BINS):
        inside = which == k
        n = int(inside.sum())
        if n == 0:
            continue
        mean_p, freq = float(p[inside].mean()), float(y[inside].mean())
        ece += n / p.size * abs(mean_p - freq)
        rows.append((float(edges[k]), float(edges[k + 1]), n, mean_p, freq))
    q = np.clip(p, 1e-6, 1.0 - 1e-6)
    log_loss = float(-np.mean(np.where(y, np.log(q), np.log1p(-q))))
    return Calibration(float(ece), float(np.mean((p - y) ** 2)), log_loss, tuple(rows))
