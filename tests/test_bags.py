"""ROS bags: rosbag2 (sqlite3, MCAP) and ROS 1 bags written with rosbags, read by cloudprox.

Every bag here is written by the ``rosbags`` package (its own serializers, not
cloudprox's), so the reader is checked against an independent writer. The real
VLP-16 frame (the pcd-rs test file, organized 16 x 1809) goes through a PCD, a
rosbag2 and a ROS 1 bag and must give the same 16 849 valid points each time.
"""

from __future__ import annotations

import inspect
import json
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import cloudprox as cp
from cloudprox import FormatError, InvalidInputError, bags
from cloudprox.bags import TransformTree
from cloudprox.cli import main
from cloudprox.pose import from_quaternion, from_rpy

rosbags = pytest.importorskip("rosbags")
from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_types_from_msg, get_typestore  # noqa: E402

PC2 = "sensor_msgs/msg/PointCloud2"
TF = "tf2_msgs/msg/TFMessage"
THING = "my_msgs/msg/Thing"
FLOAT32, UINT32 = 7, 6

#: The VLP-16 frame: valid points and no-returns at the origin (pcd-rs binary.pcd).
VLP16_VALID, VLP16_AT_ORIGIN, VLP16_H, VLP16_W = 16849, 12095, 16, 1809


def store(ros1: bool) -> Any:
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    ts.register(get_types_from_msg("int32 value\nstring note", THING))
    if TF not in ts.types:  # the ROS 1 store has no tf2_msgs
        ts.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF))
    return ts


def cloud_message(
    ts: Any,
    records: np.ndarray,
    *,
    height: int,
    width: int,
    fields: list[tuple[str, int, int]],
    frame_id: str = "velodyne",
    stamp: int = 1_700_000_000_000_000_000,
) -> Any:
    """A PointCloud2 of ``records`` (bytes, ``height * width`` records of equal size)."""
    t = ts.types
    data = np.frombuffer(records.tobytes(), dtype=np.uint8)
    step = data.size // (height * width) if height * width else 0
    return t[PC2](
        header=t["std_msgs/msg/Header"](
            **({"seq": 0} if "seq" in t["std_msgs/msg/Header"].__dataclass_fields__ else {}),
            stamp=t["builtin_interfaces/msg/Time"](
                sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000
            ),
            frame_id=frame_id,
        ),
        height=height,
        width=width,
        fields=[
            t["sensor_msgs/msg/PointField"](name=n, offset=o, datatype=d, count=1)
            for n, o, d in fields
        ],
        is_bigendian=False,
        point_step=step,
        row_step=step * width,
        data=data,
        is_dense=False,
    )


XYZ = [("x", 0, FLOAT32), ("y", 4, FLOAT32), ("z", 8, FLOAT32)]


def xyz_message(ts: Any, points: np.ndarray, height: int = 1, **kw: Any) -> Any:
    pts = np.ascontiguousarray(points, dtype="<f4")
    return cloud_message(ts, pts, height=height, width=len(pts) // height, fields=XYZ, **kw)


def tf_message(ts: Any, edges: list[tuple[str, str, int, Any, Any]]) -> Any:
    """``(parent, child, stamp, translation, quaternion wxyz)`` transforms."""
    t = ts.types
    header_fields = t["std_msgs/msg/Header"].__dataclass_fields__
    out = []
    for parent, child, stamp, tr, q in edges:
        out.append(
            t["geometry_msgs/msg/TransformStamped"](
                header=t["std_msgs/msg/Header"](
                    **({"seq": 0} if "seq" in header_fields else {}),
                    stamp=t["builtin_interfaces/msg/Time"](
                        sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000
                    ),
                    frame_id=parent,
                ),
                child_frame_id=child,
                transform=t["geometry_msgs/msg/Transform"](
                    translation=t["geometry_msgs/msg/Vector3"](x=tr[0], y=tr[1], z=tr[2]),
                    rotation=t["geometry_msgs/msg/Quaternion"](x=q[1], y=q[2], z=q[3], w=q[0]),
                ),
            )
        )
    return t[TF](transforms=out)


Message = tuple[str, str, Any, int]  # topic, type, message object (or raw bytes), bag time


def write_bag(path: Path, kind: str, messages: list[Message]) -> Path:
    """Write a bag (``sqlite3``, ``mcap`` or ``ros1``); return what to read (folder or file)."""
    ros1 = kind == "ros1"
    ts = store(ros1)
    if ros1:
        writer: Any = Writer1(path)
    else:
        plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
        writer = Writer2(path, version=9, storage_plugin=plugin)
    with writer:
        conns: dict[tuple[str, str], Any] = {}
        for topic, msgtype, msg, stamp in messages:
            if (topic, msgtype) not in conns:
                conns[topic, msgtype] = writer.add_connection(topic, msgtype, typestore=ts)
            raw = msg
            if not isinstance(msg, bytes | bytearray):
                raw = ts.serialize_ros1(msg, msgtype) if ros1 else ts.serialize_cdr(msg, msgtype)
            writer.write(conns[topic, msgtype], stamp, bytes(raw))
    return path


def bag_file(folder: Path) -> Path:
    """The storage file inside a rosbag2 folder."""
    (found,) = [p for p in folder.iterdir() if p.suffix in (".db3", ".mcap")]
    return found


KINDS = ["sqlite3", "mcap", "ros1"]


def bag_name(tmp_path: Path, kind: str, stem: str = "bag") -> Path:
    return tmp_path / (f"{stem}.bag" if kind == "ros1" else stem)


# ------------------------------------------------------------------ VLP-16


@pytest.fixture(scope="module")
def vlp16_pcd() -> Path:
    from tests.test_io_real import fetch

    return fetch("pcd_binary_organized")


@pytest.fixture(scope="module")
def vlp16_records(vlp16_pcd: Path) -> np.ndarray:
    """The frame's 16 x 1809 records (x y z float32, rgb uint32), no-returns included."""
    raw = vlp16_pcd.read_bytes()
    body = raw.index(b"DATA binary\n") + len(b"DATA binary\n")
    rec = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
    return np.frombuffer(raw, dtype=rec, count=VLP16_H * VLP16_W, offset=body).copy()


VLP16_FIELDS = [*XYZ, ("rgb", 12, UINT32)]


def box_stl(tmp_path: Path) -> Path:
    corners = [[x, y, z] for x in (0, 0.1) for y in (0, 0.1) for z in (0, 0.1)]
    v = np.array(corners) + np.array([3.0, 3.0, 0.0])
    f = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1]]
    f += [[2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    path = tmp_path / "box.stl"
    cp.io.write_mesh(path, cp.Mesh(v.astype(float), np.array(f)))
    return path


@pytest.mark.network
@pytest.mark.parametrize("kind", ["pcd", *KINDS])
def test_vlp16_frame_through_pcd_and_bags(
    tmp_path: Path,
    kind: str,
    vlp16_pcd: Path,
    vlp16_records: np.ndarray,
    capsys: pytest.CaptureFixture[str],
) -> None:
    reference = cp.io.read_point_cloud(vlp16_pcd)
    if kind == "pcd":
        path = vlp16_pcd
    else:
        msg = cloud_message(
            store(kind == "ros1"),
            vlp16_records,
            height=VLP16_H,
            width=VLP16_W,
            fields=VLP16_FIELDS,
        )
        path = write_bag(bag_name(tmp_path, kind), kind, [("/velodyne_points", PC2, msg, 1)])
    got = cp.io.read_point_cloud(path)
    assert (len(got), got.at_origin, got.skipped) == (VLP16_VALID, VLP16_AT_ORIGIN, 0)
    assert got.no_returns == VLP16_AT_ORIGIN
    assert got.grid_shape == (VLP16_H, VLP16_W)
    np.testing.assert_array_equal(got.points, reference.points)
    np.testing.assert_array_equal(got.pixels, reference.pixels)
    # The kept pixels are exactly the records that are not (0, 0, 0).
    xyz = np.stack([vlp16_records[a] for a in "xyz"], axis=1)
    np.testing.assert_array_equal(got.pixels, np.flatnonzero(np.any(xyz != 0, axis=1)))
    np.testing.assert_array_equal(got.sensor_pose, np.eye(4))
    # `collide --sensor lidar` takes the frame (it used to stop at "point 34 lies at the
    # sensor origin"); the command line reads a rosbag2's storage file, not its folder.
    side = path if kind in ("pcd", "ros1") else bag_file(path)
    argv = ["collide", str(box_stl(tmp_path)), str(side), "--sensor", "lidar", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["b"]["points"] == VLP16_VALID
    assert doc["state"] == "free"
    # `info` reports the no-returns beside the skipped non-finite points.
    info_argv = ["info", str(path)] + ([] if kind == "pcd" else ["--index", "0"])
    assert main(info_argv) == 0
    out = capsys.readouterr().out
    assert "skipped non finite: 0" in out
    assert f"no returns: {VLP16_AT_ORIGIN} ({VLP16_AT_ORIGIN} at the sensor origin" in out


# -------------------------------------------------------------- small bags


def scan_points(seed: int = 0, n: int = 6) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(-2.0, 2.0, size=(n, 3)).astype("<f4")


@pytest.mark.parametrize("kind", KINDS)
def test_frames_topics_and_indices(tmp_path: Path, kind: str) -> None:
    ts = store(kind == "ros1")
    frames = [scan_points(i) for i in range(3)]
    stamps = [1_000_000_000 * (10 + i) for i in range(3)]
    messages: list[Message] = [
        ("/lidar", PC2, xyz_message(ts, f, stamp=s), s) for f, s in zip(frames, stamps, strict=True)
    ]
    messages.append(("/thing", THING, ts.types[THING](value=3, note="x"), 5))
    path = write_bag(bag_name(tmp_path, kind), kind, messages)
    topics = {t.name: t for t in bags.topics(path)}
    assert topics["/lidar"].count == 3 and topics["/lidar"].is_pointcloud2
    assert topics["/thing"].msgtype == THING and topics["/thing"].count == 1
    for index in (0, 2, -1):
        got = cp.io.read_point_cloud(path, index=index)
        np.testing.assert_array_equal(got.points, frames[index])
        assert got.topic == "/lidar"
        assert got.index == index % 3
        assert got.stamp == stamps[index]
        assert got.frame_id == got.sensor_frame == "velodyne"
        assert got.sensor_pose_is_default and got.grid_shape is None
    it = cp.io.iter_point_clouds(path)
    assert inspect.isgenerator(it)
    got_all = list(it)
    assert [c.index for c in got_all] == [0, 1, 2]
    for c, f in zip(got_all, frames, strict=True):
        np.testing.assert_array_equal(c.points, f)
    with pytest.raises(InvalidInputError, match="index 3 is out of range: topic /lidar has 3"):
        cp.io.read_point_cloud(path, index=3)
    with pytest.raises(InvalidInputError, match=r"no topic '/nope'; its topics: /lidar") as e:
        cp.io.read_point_cloud(path, topic="/nope")
    assert str(path) in str(e.value)
    # A message type cloudprox does not know is named, not deserialized.
    with pytest.raises(InvalidInputError, match=f"topic /thing holds {THING} messages") as e:
        cp.io.read_point_cloud(path, topic="/thing")
    assert str(path) in str(e.value)
    with pytest.raises(InvalidInputError, match="apply to ROS bags"):
        cp.io.read_point_cloud(tmp_path / "x.pcd", topic="/lidar")


@pytest.mark.parametrize("kind", KINDS)
def test_several_or_no_cloud_topics(tmp_path: Path, kind: str) -> None:
    ts = store(kind == "ros1")
    two = write_bag(
        bag_name(tmp_path, kind, "two"),
        kind,
        [
            ("/front", PC2, xyz_message(ts, scan_points(1)), 1),
            ("/back", PC2, xyz_message(ts, scan_points(2)), 2),
            ("/back", PC2, xyz_message(ts, scan_points(3)), 3),
        ],
    )
    with pytest.raises(
        InvalidInputError, match=r"2 PointCloud2 topics.*/back \(2 messages\), /front \(1"
    ):
        cp.io.read_point_cloud(two)
    got = cp.io.read_point_cloud(two, topic="/back", index=1)
    np.testing.assert_array_equal(got.points, scan_points(3))
    assert [len(c) for c in cp.io.iter_point_clouds(two, "/front")] == [6]
    none = write_bag(
        bag_name(tmp_path, kind, "none"),
        kind,
        [("/thing", THING, ts.types[THING](value=1, note=""), 1)],
    )
    with pytest.raises(FormatError, match="no sensor_msgs/PointCloud2 topic; its topics: /thing"):
        cp.io.read_point_cloud(none)


def test_rosbag2_folder_and_its_file(tmp_path: Path) -> None:
    ts = store(False)
    for kind in ("sqlite3", "mcap"):
        folder = write_bag(tmp_path / kind, kind, [("/p", PC2, xyz_message(ts, scan_points()), 1)])
        for path in (folder, bag_file(folder)):
            assert bags.is_bag(path)
            np.testing.assert_array_equal(cp.io.read_point_cloud(path).points, scan_points())
    assert not bags.is_bag(tmp_path)


@pytest.mark.parametrize("kind", KINDS)
def test_organized_no_returns_and_holes(tmp_path: Path, kind: str) -> None:
    ts = store(kind == "ros1")
    grid = np.array(
        [
            [[0, 0, 0], [1, 0, 2], [np.nan, np.nan, np.nan]],
            [[0.5, 0.5, 1], [0, 0, 0], [-1, 2, 3]],
        ],
        dtype="<f4",
    ).reshape(-1, 3)
    path = write_bag(bag_name(tmp_path, kind), kind, [("/d", PC2, xyz_message(ts, grid, 2), 1)])
    got = cp.io.read_point_cloud(path)
    assert got.grid_shape == (2, 3)
    np.testing.assert_array_equal(got.pixels, [1, 3, 5])
    assert (got.at_origin, got.skipped, got.no_returns) == (2, 1, 3)
    # An unorganized cloud keeps a point at the origin: it may be a real one.
    flat = write_bag(
        bag_name(tmp_path, kind, "flat"), kind, [("/d", PC2, xyz_message(ts, grid), 1)]
    )
    got = cp.io.read_point_cloud(flat)
    assert (len(got), got.at_origin, got.skipped, got.no_returns) == (5, 0, 1, 0)


# ----------------------------------------------------------------------- TF


def quat(pose: np.ndarray) -> np.ndarray:
    """wxyz of a rotation matrix (trace > 0 here)."""
    m = pose[:3, :3]
    w = np.sqrt(1.0 + np.trace(m)) / 2.0
    return np.array(
        [
            w,
            (m[2, 1] - m[1, 2]) / (4 * w),
            (m[0, 2] - m[2, 0]) / (4 * w),
            (m[1, 0] - m[0, 1]) / (4 * w),
        ]
    )


@pytest.mark.parametrize("kind", KINDS)
def test_sensor_pose_from_tf(tmp_path: Path, kind: str) -> None:
    ts = store(kind == "ros1")
    mount = from_rpy((0.0, 0.1, np.pi / 2), (0.2, 0.0, 1.5))  # base_link -> velodyne
    t0, t1 = 100 * 10**9, 102 * 10**9
    start = from_rpy((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # map -> base_link at t0
    end = from_rpy((0.0, 0.0, 0.4), (2.0, -1.0, 0.0))  # ... at t1
    stamp = t0 + (t1 - t0) // 4  # the cloud: a quarter of the way
    pts = scan_points(4, 8)
    messages: list[Message] = [
        (
            "/tf_static",
            TF,
            tf_message(ts, [("base_link", "velodyne", 0, mount[:3, 3], quat(mount))]),
            1,
        ),
        ("/tf", TF, tf_message(ts, [("map", "base_link", t0, start[:3, 3], quat(start))]), t0),
        ("/tf", TF, tf_message(ts, [("/map", "/base_link", t1, end[:3, 3], quat(end))]), t1),
        ("/points", PC2, xyz_message(ts, pts, stamp=stamp, frame_id="velodyne"), stamp),
    ]
    path = write_bag(bag_name(tmp_path, kind), kind, messages)
    got = cp.io.read_point_cloud(path)
    # Interpolated: translation a quarter of the way, yaw 0.1 rad.
    base = from_rpy((0.0, 0.0, 0.1), (0.5, -0.25, 0.0))
    want = base @ mount
    assert got.frame_id == "map" and got.sensor_frame == "velodyne"
    assert not got.sensor_pose_is_default
    np.testing.assert_allclose(got.sensor_pose, want, atol=1e-9)
    moved = pts.astype(np.float64) @ want[:3, :3].T + want[:3, 3]
    np.testing.assert_allclose(got.points, moved, atol=1e-9)
    # frame= picks another frame of the tree, or the message's own.
    in_base = cp.io.read_point_cloud(path, frame="base_link")
    np.testing.assert_allclose(in_base.sensor_pose, mount, atol=1e-9)
    assert in_base.frame_id == "base_link"
    own = cp.io.read_point_cloud(path, frame="velodyne")
    np.testing.assert_array_equal(own.points, pts)
    np.testing.assert_array_equal(own.sensor_pose, np.eye(4))
    with pytest.raises(InvalidInputError, match="frame 'odom' is not connected") as e:
        cp.io.read_point_cloud(path, frame="odom")
    assert "topic /points, message 0" in str(e.value)


def test_transform_tree_nearest_outside_the_samples() -> None:
    tree = TransformTree()
    tree.add("map", "base", 10, (1.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    tree.add("map", "base", 20, (3.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    tree.add("base", "cam", 0, (0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 0.0), static=True)
    for stamp, x in ((0, 1.0), (10, 1.0), (15, 2.0), (20, 3.0), (99, 3.0)):
        root, pose = tree.lookup(None, "cam", stamp)
        assert root == "map"
        np.testing.assert_allclose(pose[:3, 3], [x, 0.0, 1.0])
    frame, pose = tree.lookup("base", "cam", 15)
    assert frame == "base"
    np.testing.assert_allclose(pose, from_quaternion([1, 0, 0, 0], translation=[0, 0, 1]))
    tree.add("cam", "map", 0, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), static=True)
    with pytest.raises(FormatError, match="loop"):
        tree.to_root("cam", 0)


# ---------------------------------------------------------------------- CLI


def test_cli_info_and_topic_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ts = store(False)
    grid = np.array([[0, 0, 0], [1, 0, 2], [1, 1, 2], [0, 1, 2]], dtype="<f4")
    folder = write_bag(
        tmp_path / "bag",
        "sqlite3",
        [
            ("/front", PC2, xyz_message(ts, grid, 2), 1),
            ("/front", PC2, xyz_message(ts, grid[::-1].copy(), 2), 2),
            ("/back", PC2, xyz_message(ts, scan_points(5, 30)), 3),
            ("/thing", THING, ts.types[THING](value=1, note=""), 4),
        ],
    )
    assert main(["info", str(folder)]) == 0
    out = capsys.readouterr().out
    assert "ROS bag" in out and "topics: 3" in out
    assert "/front: sensor_msgs/msg/PointCloud2, 2 messages" in out
    assert f"/thing: {THING}, 1 messages" in out
    assert main(["info", str(folder), "--topic", "/front", "--index", "1", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [t["name"] for t in doc["topics"]] == ["/back", "/front", "/thing"]
    frame = doc["frame"]
    assert (frame["topic"], frame["index"], frame["points"]) == ("/front", 1, 3)
    assert (frame["no_returns"], frame["no_returns_at_sensor_origin"]) == (1, 1)
    # Cloud-reading commands take --topic and --index.
    box = box_stl(tmp_path)
    argv = ["collide", str(box), str(bag_file(folder)), "--sigma", "0.001", "--json"]
    assert main([*argv, "--topic", "/back"]) == 0
    assert json.loads(capsys.readouterr().out)["b"]["points"] == 30
    assert main([*argv, "--topic", "/front", "--index", "-1"]) == 0
    assert json.loads(capsys.readouterr().out)["b"]["points"] == 3
    assert main(argv) == 2
    assert "2 PointCloud2 topics" in capsys.readouterr().err
    assert main(["collide", str(box), str(box), "--topic", "/front"]) == 2
    assert "--topic and --index apply to ROS bags" in capsys.readouterr().err
    assert main([*argv, "--topic", "/thing"]) == 2
    assert f"holds {THING} messages" in capsys.readouterr().err


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("kind", KINDS)
def test_truncated_and_garbage_bags(tmp_path: Path, kind: str) -> None:
    ts = store(kind == "ros1")
    messages: list[Message] = [
        ("/p", PC2, xyz_message(ts, scan_points(i, 2000)), i + 1) for i in range(4)
    ]
    path = write_bag(bag_name(tmp_path, kind), kind, messages)
    target = path if kind == "ros1" else bag_file(path)
    data = target.read_bytes()
    for cut in (len(data) // 2, len(data) - 10, 40):
        cut_path = tmp_path / f"cut-{cut}{target.suffix}"
        cut_path.write_bytes(data[:cut])
        with pytest.raises(FormatError) as e:
            list(cp.io.iter_point_clouds(cut_path))
        assert str(cut_path) in str(e.value)
    garbage = tmp_path / f"garbage{target.suffix}"
    garbage.write_bytes(os.urandom(5000))
    with pytest.raises(FormatError, match="not a readable bag") as e:
        cp.io.read_point_cloud(garbage)
    assert str(garbage) in str(e.value)
    with pytest.raises(FileNotFoundError):
        cp.io.read_point_cloud(tmp_path / f"missing{target.suffix}")


@pytest.mark.parametrize("kind", KINDS)
def test_bad_messages_name_file_topic_and_field(tmp_path: Path, kind: str) -> None:
    ts = store(kind == "ros1")
    ros1 = kind == "ros1"
    good = xyz_message(ts, scan_points(1))
    raw = bytes(ts.serialize_ros1(good, PC2) if ros1 else ts.serialize_cdr(good, PC2))
    no_z = cloud_message(ts, scan_points(2)[:, :2].copy(), height=1, width=6, fields=XYZ[:2])
    path = write_bag(
        bag_name(tmp_path, kind),
        kind,
        [("/ok", PC2, good, 1), ("/cut", PC2, raw[: len(raw) - 30], 2), ("/no_z", PC2, no_z, 3)],
    )
    np.testing.assert_array_equal(cp.io.read_point_cloud(path, topic="/ok").points, scan_points(1))
    with pytest.raises(FormatError, match=r"\(topic /cut, message 0\).*truncated") as e:
        cp.io.read_point_cloud(path, topic="/cut")
    assert str(path) in str(e.value)
    with pytest.raises(FormatError, match=r"\(topic /no_z, message 0\).*no field 'z'") as e:
        cp.io.read_point_cloud(path, topic="/no_z")
    assert "fields: x, y" in str(e.value) and str(path) in str(e.value)


def test_cdr_message_read_in_place_and_encodings() -> None:
    ts = store(False)
    msg = xyz_message(ts, scan_points(7), stamp=5 * 10**9 + 7, frame_id="cam")
    raw = bytes(ts.serialize_cdr(msg, PC2))
    got = cp.io.read_pointcloud2_message(raw)
    np.testing.assert_array_equal(got.points, scan_points(7))
    assert (got.stamp, got.frame_id) == (5 * 10**9 + 7, "cam")
    np.testing.assert_array_equal(
        cp.io.read_pointcloud2_message(memoryview(raw)).points, got.points
    )
    ts1 = store(True)
    raw1 = bytes(ts1.serialize_ros1(xyz_message(ts1, scan_points(7)), PC2))
    np.testing.assert_array_equal(cp.io.read_pointcloud2_message(raw1, "ros1").points, got.points)
    with pytest.raises(FormatError, match="unsupported CDR encapsulation 0x0007"):
        cp.io.read_pointcloud2_message(b"\x00\x07" + raw[2:])
    with pytest.raises(InvalidInputError, match="unknown message encoding"):
        cp.io.read_pointcloud2_message(raw, "json")  # type: ignore[arg-type]


def test_missing_rosbags_is_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "x.bag"
    path.write_bytes(b"#ROSBAG V2.0\n")
    monkeypatch.setitem(sys.modules, "rosbags", None)
    with pytest.raises(ModuleNotFoundError, match=r"pip install 'cloudprox\[bags\]'"):
        cp.io.read_point_cloud(path)
