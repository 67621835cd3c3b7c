"""The calibration scores of the benchmarks: ECE, Brier score, log-loss, reliability table."""

from __future__ import annotations

import numpy as np
import pytest

from cloudprox.reproduce.metrics import calibration


def test_a_calibrated_forecast_scores_near_zero_ece() -> None:
    rng = np.random.default_rng(0)
    p = rng.uniform(size=200_000)
    y = rng.uniform(size=p.size) < p
    cal = calibration(p, y)
    assert cal.ece < 0.01
    # Brier of a calibrated uniform forecast: E[p(1-p)] = 1/6.
    assert cal.brier == pytest.approx(1.0 / 6.0, abs=0.005)
    assert cal.worst_bin() < 0.02
    assert [row[2] for row in cal.table] == pytest.approx([20_000] * 10, rel=0.05)


def test_a_confident_wrong_forecast_scores_one() -> None:
    cal = calibration(np.ones(50), np.zeros(50, dtype=bool))
    assert (cal.ece, cal.brier) == (1.0, 1.0)
    assert cal.log_loss == pytest.approx(-np.log(1e-6))
    assert cal.table == ((0.9, 1.0, 50, 1.0, 0.0),)


def test_an_over_confident_forecast_is_seen_in_its_bins() -> None:
    # P = 0.2 where the truth collides half the time: ECE 0.3 in that bin.
    p = np.full(1000, 0.2)
    y = np.arange(1000) % 2 == 0
    cal = calibration(p, y)
    assert cal.ece == pytest.approx(0.3)
    (low, high, n, mean_p, freq) = cal.table[0]
    assert (n, mean_p, freq) == (1000, pytest.approx(0.2), 0.5) and low <= 0.2 < high


def test_bad_inputs_name_the_problem() -> None:
    with pytest.raises(ValueError, match="one size"):
        calibration(np.zeros(3), np.zeros(2, dtype=bool))
    with pytest.raises(ValueError, match="one size"):
        calibration(np.zeros(0), np.zeros(0, dtype=bool))
    with pytest.raises(ValueError, match=r"in \[0, 1\]"):
        calibration(np.array([0.5, np.nan]), np.zeros(2, dtype=bool))
    with pytest.raises(ValueError, match=r"in \[0, 1\]"):
        calibration(np.array([1.5]), np.zeros(1, dtype=bool))
