from __future__ import annotations

import json

import numpy as np
import pytest

import cloudprox as cp
from cloudprox.cli import main
from cloudprox.pose import from_translation


@pytest.fixture(scope="module")
def npy_files(tmp_path_factory) -> dict[str, str]:
    d = tmp_path_factory.mktemp("npy")
    base = cp.synthetic.sample_sphere(600, 0.1)
    files = {
        "a": cp.synthetic.add_noise(base, 0.002, seed=1),
        "b_far": cp.synthetic.add_noise(base, 0.002, seed=2) + np.array([0.25, 0.0, 0.0]),
        "b_deep": cp.synthetic.add_noise(base, 0.002, seed=2) + np.array([0.19, 0.0, 0.0]),
        "b": cp.synthetic.add_noise(base, 0.002, seed=2),
        "shift": from_translation((0.25, 0.0, 0.0)),
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
    for patch in doc["patches"]:
        assert len(patch["point"]) == 3 and len(patch["normal"]) == 3
        assert isinstance(patch["separation"], float)


def test_collide_with_pose_and_options(capsys, npy_files) -> None:
    args = ("collide", npy_files["a"], npy_files["b"], "--sigma", "0.002", "--sigma-b", "0.003")
    code, out, _ = run(
        capsys, *args, "--pose-b", npy_files["shift"], "--json", "--surface", "linear"
    )
    assert code == 0
    doc = json.loads(out)
    assert doc["state"] == "free"
    assert all(r["surface"] == "linear" for r in doc["patches"])
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


def test_collide_with_segmentations(capsys, npy_files) -> None:
    args = ("collide", npy_files["a"], npy_files["b_deep"], "--sigma", "0.002", "--json")
    code, out, err = run(capsys, *args, "--model", "elements", "--segmentations", "3")
    assert code == 0, err
    doc = json.loads(out)
    code, out, err = run(capsys, *args, "--model", "elements")
    assert code == 0, err
    one = json.loads(out)
    assert doc["state"] == "collision"
    assert doc["stats"]["patches"] >= len(one["patches"]) and len(doc["patches"]) > len(
        one["patches"]
    )
    code, _, err = run(capsys, *args, "--model", "points", "--segmentations", "3")
    assert code != 0 and "needs model 'elements'" in err


def test_collide_with_near_context(capsys, npy_files) -> None:
    args = ("collide", npy_files["a"], npy_files["b_deep"], "--sigma", "0.002", "--json")
    classified = []
    for context in ("2", "0.5"):
        code, out, err = run(capsys, *args, "--model", "elements", "--near-context", context)
        assert code == 0, err
        doc = json.loads(out)
        assert doc["state"] == "collision"
        classified.append(doc["stats"]["points_classified"])
    # Less context around the contact: fewer samples for the classifier.
    assert 0 < classified[1] < classified[0]
    code, _, err = run(capsys, *args, "--near-context", "0.2")
    assert code != 0 and "near_context must be finite and >= 0.5" in err


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
        (["reproduce", "--workers", "0"], "--workers must be >= 1, got 0"),
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
        assert 0.0 < r["median_ms"] < 60e3
        if r["engine"] == "cloudprox":
            assert r["ratio_to_cloudprox"] == pytest.approx(1.0)


def test_bench_table(capsys) -> None:
    code, out, _ = run(capsys, "bench", "--points", "200", "--repeat", "1")
    assert code == 0
    assert "cloudprox" in out and "kdtree" in out and "ratio" in out


# ------------------------------------------------------------ files of any format


@pytest.fixture(scope="module")
def example(tmp_path_factory) -> dict[str, str]:
    from cloudprox.examples import write_example_files

    paths = write_example_files(tmp_path_factory.mktemp("example"))
    return {k: str(v) for k, v in paths.items()}


def _collide(capsys, example, *extra: str) -> tuple[int, dict, str]:
    code, out, err = run(
        capsys,
        "collide",
        example["gripper"],
        example["scan"],
        "--sensor",
        "depth-camera",
        "--preset",
        "nguyen-2012",
        *extra,
        "--json",
    )
    return code, (json.loads(out) if code == 0 else {}), err


def test_collide_gripper_stl_against_pcd_scan(capsys, example) -> None:
    code, doc, err = _collide(
        capsys, example, "--pose-a", example["grasp-free"], "--filter", "shadow"
    )
    assert code == 0, err
    assert doc["state"] == "free"
    assert doc["a"]["kind"] == "mesh" and doc["a"]["faces"] == 36
    b = doc["b"]
    assert b["kind"] == "cloud" and b["points_read"] == 320 * 240
    assert b["skipped_non_finite"] > 0
    assert b["filters"][0]["filter"] == "shadow"
    assert b["filters"][0]["after"] < b["filters"][0]["before"]
    code, doc, err = _collide(capsys, example, "--pose-a", example["grasp-collision"])
    assert code == 0, err
    assert doc["state"] == "collision"


def test_collide_inline_pose_and_filter_chain(capsys, example) -> None:
    # The free grasp written inline (translation only), through crop and voxel steps.
    pose = np.loadtxt(example["grasp-free"])
    inline = ",".join(str(x) for x in pose[:3, 3])
    code, doc, err = _collide(
        capsys,
        example,
        "--pose-a",
        inline,
        "--filter",
        "shadow",
        "--filter",
        "crop:-0.5,0,0.7,0.5,0.8,1.2",
        "--filter",
        "voxel:0.004",
    )
    assert code == 0, err
    steps = [f["filter"] for f in doc["b"]["filters"]]
    assert steps == ["shadow", "crop:-0.5,0,0.7,0.5,0.8,1.2", "voxel:0.004"]
    counts = [f["after"] for f in doc["b"]["filters"]]
    assert counts[0] > counts[1] > counts[2] > 0
    assert doc["state"] == "free"


def test_self_filter_step_removes_the_robot(capsys, example, tmp_path) -> None:
    # The gripper mesh placed where the box is: the self-filter removes the box's
    # points, so the colliding grasp becomes free.
    box = cp.Mesh.cuboid(0.045, 0.045, 0.08)
    stl = tmp_path / "box.stl"
    cp.io.write_mesh(stl, box)
    where = "0.1,0.3,0.825"
    code, doc, err = _collide(
        capsys,
        example,
        "--pose-a",
        example["grasp-collision"],
        "--filter",
        "shadow",
        "--filter",
        f"self:{stl}:0.01:{where}",
    )
    assert code == 0, err
    assert doc["state"] == "free"
    assert doc["b"]["filters"][1]["after"] < doc["b"]["filters"][1]["before"]


def test_collide_point_cloud_formats(capsys, npy_files, tmp_path) -> None:
    a = np.load(npy_files["a"])
    b = np.load(npy_files["b_far"])
    for ext in ("ply", "pcd", "xyz", "csv"):
        pa, pb = tmp_path / f"a.{ext}", tmp_path / f"b.{ext}"
        cp.io.write_point_cloud(pa, a)
        cp.io.write_point_cloud(pb, b)
        code, out, err = run(capsys, "collide", str(pa), str(pb), "--sigma", "0.002", "--json")
        assert code == 0, f"{ext}: {err}"
        assert json.loads(out)["state"] == "free", ext


def test_lidar_sensor_with_origin(capsys, npy_files) -> None:
    code, out, err = run(
        capsys,
        "collide",
        npy_files["a"],
        npy_files["b_deep"],
        "--sensor",
        "lidar",
        "--sigma-range",
        "0.002",
        "--origin",
        "0,0,2",
        "--json",
    )
    assert code == 0, err
    assert json.loads(out)["state"] == "collision"


def test_info_point_cloud_and_mesh(capsys, example) -> None:
    code, out, err = run(capsys, "info", example["scan"], "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["kind"] == "point cloud"
    assert info["organized"] == [240, 320]
    assert info["points"] + info["skipped_non_finite"] == 320 * 240
    assert info["sensor_pose"][0][3] == pytest.approx(0.0)
    assert 0.001 < info["spacing_m"]["median"] < 0.05
    code, out, err = run(capsys, "info", example["gripper"], "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["kind"] == "mesh" and info["closed"]
    assert info["volume_m3"] == pytest.approx(0.06 * 0.18 * 0.04 + 2 * 0.02 * 0.02 * 0.05, rel=1e-6)
    code, out, _ = run(capsys, "info", example["scan"])
    assert "organized: [240, 320]" in out and "spacing" in out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--filter", "blur"], "unknown filter 'blur'"),
        (["--filter", "voxel"], "voxel needs a size"),
        (["--filter", "voxel:0"], "voxel"),
        (["--pose-a", "1,2"], "expected a pose file, or 3"),
        (["--pose-a", "nofile.npy"], "no such file"),
        (["--sigma", "0.01"], "--sigma is for --sensor isotropic"),
        (["--baseline", "0.1"], "--baseline do not apply to --sensor depth-camera"),
    ],
)
def test_file_collide_user_errors(capsys, example, extra: list[str], message: str) -> None:
    code, _, err = _collide(capsys, example, *extra)
    assert code == 2
    assert message in err, err
    assert "Traceback" not in err


def test_sensor_without_viewpoint_and_corrupt_file(capsys, npy_files, tmp_path) -> None:
    code, _, err = run(capsys, "collide", npy_files["a"], npy_files["b"], "--sensor", "stereo")
    assert code == 2
    assert "records no sensor viewpoint" in err
    bad = tmp_path / "bad.pcd"
    bad.write_bytes(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n")
    code, _, err = run(capsys, "collide", str(bad), npy_files["b"], "--sigma", "0.01")
    assert code == 2
    assert str(bad) in err and "PCD" in err
    code, _, err = run(capsys, "info", str(tmp_path / "missing.ply"))
    assert code == 2 and "no such file" in err


def test_gripper_stl_against_a_las_scan(capsys, example, tmp_path) -> None:
    # The "LAS file and an STL gripper" path: a laser scan has no sensor pose,
    # so the noise is given (isotropic here, or --sensor lidar --origin ...).
    laspy = pytest.importorskip("laspy")
    pts = cp.io.read_point_cloud(example["scan"]).points
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales = np.array([1e-4, 1e-4, 1e-4])
    header.offsets = pts.min(axis=0)
    las = laspy.LasData(header)
    las.x, las.y, las.z = pts[:, 0], pts[:, 1], pts[:, 2]
    path = tmp_path / "scan.laz"
    las.write(str(path))
    code, out, err = run(
        capsys,
        "collide",
        example["gripper"],
        str(path),
        "--pose-a",
        example["grasp-collision"],
        "--sigma",
        "0.002",
        "--json",
    )
    assert code == 0, err
    doc = json.loads(out)
    assert doc["state"] == "collision"
    assert doc["b"]["points_read"] == len(pts)
    assert "classification" in doc["b"]["fields"]


def test_dropped_mesh_faces_are_reported(capsys, npy_files, tmp_path) -> None:
    obj = tmp_path / "tet.obj"
    obj.write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 1 2\n"
    )
    code, out, err = run(capsys, "collide", str(obj), npy_files["a"], "--sigma", "0.002", "--json")
    assert code == 0, err
    assert json.loads(out)["a"]["dropped_faces"] == 1
    code, out, err = run(capsys, "info", str(obj), "--json")
    assert code == 0, err
    assert "dropped 1 degenerate face" in json.loads(out)["warnings"][0]
