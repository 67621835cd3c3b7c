from __future__ import annotations

import json

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.cli import main
from tests.helpers import translation


@pytest.fixture(scope="module")
def npy_files(tmp_path_factory) -> dict[str, str]:
    d = tmp_path_factory.mktemp("npy")
    base = cp.sample_sphere(600, 0.1)
    files = {
        "a": cp.add_noise(base, 0.002, seed=1),
        "b_far": cp.add_noise(base, 0.002, seed=2) + np.array([0.25, 0.0, 0.0]),
        "b_deep": cp.add_noise(base, 0.002, seed=2) + np.array([0.19, 0.0, 0.0]),
        "b": cp.add_noise(base, 0.002, seed=2),
        "shift": translation(0.25),
        "flat": np.zeros((5, 2)),
    }
    out = {}
    for name, arr in files.items():
        path = d / f"{name}.npy"
        np.save(path, arr)
        out[name] = str(path)
    (d / "text.npy").write_text("not an array\n")
    out["text"] = str(d / "text.npy")
    np.savez(d / "arch.npz", x=np.eye(4))
    out["npz"] = str(d / "arch.npz")
    out["dir"] = str(d)
    return out


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_demo_writes_a_png(tmp_path, capsys) -> None:
    code, out, err = run(capsys, "demo", "--out", str(tmp_path / "demo"), "--points", "300")
    assert code == 0, err
    png = tmp_path / "demo" / "demo.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert str(png.resolve()) in out.replace("\n", "")
    assert "collision" in out and "free" in out
    assert "table 1" in out


@pytest.mark.parametrize(("b", "state"), [("b_far", "free"), ("b_deep", "collision")])
def test_collide_json(capsys, npy_files, b: str, state: str) -> None:
    code, out, err = run(
        capsys, "collide", npy_files["a"], npy_files[b], "--sigma", "0.002", "--json"
    )
    assert code == 0, err
    doc = json.loads(out)
    assert doc["state"] == state
    assert 0.0 <= doc["probability"] <= 1.0
    assert set(doc["stats"]) >= {"points_classified", "time_seconds", "patches"}
    for region in doc["regions"]:
        assert len(region["point"]) == 3 and len(region["normal"]) == 3
        assert isinstance(region["separation"], float)


def test_collide_with_pose_and_options(capsys, npy_files) -> None:
    args = ("collide", npy_files["a"], npy_files["b"], "--sigma", "0.002", "--sigma-b", "0.003")
    code, out, _ = run(
        capsys, *args, "--pose-b", npy_files["shift"], "--json", "--surface", "linear"
    )
    assert code == 0
    doc = json.loads(out)
    assert doc["state"] == "free"
    assert all(r["surface"] == "linear" for r in doc["regions"])
    code, out, _ = run(
        capsys,
        *args,
        "--pose-b",
        npy_files["shift"],
        "--aggregation",
        "union",
        "--solver",
        "clarabel",
    )
    assert code == 0
    assert "state: free" in out and "P = " in out and "stats:" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["collide", "{a}", "{dir}/missing.npy", "--sigma", "0.002"], "no such file"),
        (["collide", "{a}", "{text}", "--sigma", "0.002"], "not a valid NPY file: wrong magic"),
        (["collide", "{a}", "{npz}", "--sigma", "0.002"], 'from the extension "npz"'),
        (["collide", "{a}", "{dir}", "--sigma", "0.002"], "is a directory"),
        (
            ["collide", "{a}", "{flat}", "--sigma", "0.002"],
            "shape (5, 2) has fewer than 3 columns",
        ),
        (["collide", "{a}", "{b}", "--sigma", "-1"], "sigma must be finite and >= 0"),
        (
            ["collide", "{a}", "{b}", "--sigma", "0.002", "--pose-a", "{a}"],
            "must hold a (4, 4) matrix",
        ),
        (["collide", "{a}", "{b}", "--sigma", "0.002", "--surface", "cubic"], "invalid choice"),
        (["collide", "{a}", "{b}"], "--sigma"),
        (["demo", "--sigma", "0"], "--sigma must be finite and > 0"),
        (["bench", "--repeat", "0"], "--repeat"),
        (["frobnicate"], "invalid choice"),
        ([], "a command is required"),
    ],
)
def test_user_errors_exit_2_with_one_message(capsys, npy_files, argv, message) -> None:
    code, out, err = run(capsys, *(a.format(**npy_files) for a in argv))
    assert code == 2
    assert message in err
    assert "Traceback" not in err and "Traceback" not in out
    assert err.strip().splitlines()[-1].startswith(("cloudprox", "usage"))


def test_help_and_version(capsys) -> None:
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "demo" in out and "collide" in out and "bench" in out
    code, out, _ = run(capsys, "--version")
    assert code == 0 and cp.__version__ in out


def test_bench_json(capsys) -> None:
    code, out, err = run(capsys, "bench", "--points", "300", "--repeat", "1", "--json")
    assert code == 0, err
    doc = json.loads(out)
    engines = {r["engine"] for r in doc["rows"]}
    assert {"cloudprox", "kdtree"} <= engines
    assert "fcl" in engines or any("fcl" in n for n in doc["notes"])
    configs = {r["config"] for r in doc["rows"]}
    assert configs == {"apart", "near", "interpenetrating"}
    for r in doc["rows"]:
        assert r["median_ms"] >= 0.0
        if r["engine"] == "cloudprox":
            assert r["ratio_to_cloudprox"] == pytest.approx(1.0)


def test_bench_table(capsys) -> None:
    code, out, _ = run(capsys, "bench", "--points", "200", "--repeat", "1")
    assert code == 0
    assert "cloudprox" in out and "kdtree" in out and "ratio" in out
