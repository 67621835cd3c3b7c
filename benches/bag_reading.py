"""Streaming PointCloud2 frames out of a rosbag2: frames per second and peak memory.

Usage::

    python3 benches/bag_reading.py [--frames N] [--points P] [--storage sqlite3|mcap|ros1]
                                   [--keep DIR] [--json]

Writes a bag with ``rosbags`` (its own CDR serializer) into a temporary folder:
``N`` (default 100) frames on one ``sensor_msgs/PointCloud2`` topic, each an
organized 64-row lidar sweep of about ``P`` (default 300 000) points laid out as
an Ouster/Velodyne driver publishes them (``x y z`` float32, ``intensity``
float32, ``ring`` uint16, ``time`` float32; 32 bytes per point, so 9.6 MB a
frame), 10 % of them no-returns at ``(0, 0, 0)``, plus a ``/tf_static`` mount.

Then a fresh process pinned to one core (``sched_setaffinity``) reads it with
:func:`cloudprox.io.iter_point_clouds` and reports, for the first ``N // 10``
frames and for all ``N``:

* ``stream/s``: frames per second end to end (the bag storage's read, the Rust
  PointCloud2 reader on the message's bytes, the TF transform of the points);
  the last row also takes each frame's points as a NumPy array;
* ``storage/s``: frames per second of the storage alone (``rosbags`` yielding
  the messages' bytes, nothing parsed);
* ``parse/s``: frames per second of the parsing alone
  (:func:`cloudprox.io.read_pointcloud2_message` on each message's bytes, as
  they come out of the storage);
* the process's peak resident memory (``ru_maxrss``): flat in the number of
  frames when the runs' peaks agree.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROWS = 64
POINT_STEP = 32
TOPIC = "/os_cloud_node/points"


def frame_records(width: int, seed: int) -> np.ndarray:
    """One organized sweep: ``ROWS x width`` records, 10 % no-returns at the origin."""
    rng = np.random.default_rng(seed)
    rec = np.zeros(
        ROWS * width,
        dtype=np.dtype(
            {
                "names": ["x", "y", "z", "intensity", "ring", "time"],
                "formats": ["<f4", "<f4", "<f4", "<f4", "<u2", "<f4"],
                "offsets": [0, 4, 8, 16, 20, 24],
                "itemsize": POINT_STEP,
            }
        ),
    )
    az = np.tile(np.linspace(0.0, 2.0 * np.pi, width, endpoint=False), ROWS)
    el = np.repeat(np.linspace(-0.39, 0.39, ROWS), width)
    r = rng.uniform(1.0, 40.0, size=ROWS * width)
    rec["x"] = r * np.cos(el) * np.cos(az)
    rec["y"] = r * np.cos(el) * np.sin(az)
    rec["z"] = r * np.sin(el)
    rec["intensity"] = rng.uniform(0, 255, size=ROWS * width)
    rec["ring"] = np.repeat(np.arange(ROWS), width)
    rec["time"] = np.tile(np.linspace(0.0, 0.1, width), ROWS)
    miss = rng.random(ROWS * width) < 0.1
    for axis in "xyz":
        rec[axis][miss] = 0.0
    return rec


def write_bag(path: Path, frames: int, points: int, storage: str) -> Path:
    """Write the benchmark bag; return the path to read."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ros1 = storage == "ros1"
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if "tf2_msgs/msg/TFMessage" not in ts.types:
        ts.register(
            get_types_from_msg(
                "geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"
            )
        )
    t = ts.types
    width = max(1, points // ROWS)
    header_kw = {"seq": 0} if ros1 else {}

    def header(stamp: int, frame: str) -> Any:
        return t["std_msgs/msg/Header"](
            **header_kw,
            stamp=t["builtin_interfaces/msg/Time"](sec=stamp // 10**9, nanosec=stamp % 10**9),
            frame_id=frame,
        )

    fields = [
        t["sensor_msgs/msg/PointField"](name=n, offset=o, datatype=d, count=1)
        for n, o, d in [
            ("x", 0, 7),
            ("y", 4, 7),
            ("z", 8, 7),
            ("intensity", 16, 7),
            ("ring", 20, 4),
            ("time", 24, 7),
        ]
    ]
    serialize = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    target = path.with_suffix(".bag") if ros1 else path
    if ros1:
        writer: Any = Writer1(target)
    else:
        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer = Writer2(target, version=9, storage_plugin=plugin)
    records = [frame_records(width, seed) for seed in range(4)]  # reused: writing is not timed
    with writer:
        tf = writer.add_connection("/tf_static", "tf2_msgs/msg/TFMessage", typestore=ts)
        mount = t["geometry_msgs/msg/TransformStamped"](
            header=header(0, "base_link"),
            child_frame_id="os_sensor",
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=0.1, y=0.0, z=1.8),
                rotation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
        writer.write(
            tf, 1, bytes(serialize(t["tf2_msgs/msg/TFMessage"](transforms=[mount]), tf.msgtype))
        )
        conn = writer.add_connection(TOPIC, "sensor_msgs/msg/PointCloud2", typestore=ts)
        for i in range(frames):
            stamp = 1_700_000_000 * 10**9 + i * 100_000_000
            msg = t["sensor_msgs/msg/PointCloud2"](
                header=header(stamp, "os_sensor"),
                height=ROWS,
                width=width,
                fields=fields,
                is_bigendian=False,
                point_step=POINT_STEP,
                row_step=POINT_STEP * width,
                data=records[i % len(records)].view(np.uint8),
                is_dense=False,
            )
            writer.write(conn, stamp, bytes(serialize(msg, conn.msgtype)))
    return target


def read(path: str, frames: int, as_numpy: bool) -> dict[str, Any]:
    """Read the first ``frames`` frames in this process (one core): rates and peak RSS.

    Two passes over the same frames: the storage alone (``rosbags`` yielding each
    message's bytes), then :func:`cloudprox.io.iter_point_clouds` (storage, parsing,
    TF), inside which the time of the Rust reader on each message's bytes
    (``read_pointcloud2_message``, the parsing) is taken on its own.
    """
    import cloudprox as cp
    from cloudprox import bags

    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    with bags._Bag(path) as bag:
        start = time.perf_counter()
        for n, _ in enumerate(bag.messages(TOPIC), 1):
            if n == frames:
                break
        storage = time.perf_counter() - start
    n = points = no_returns = 0
    parse = 0.0
    start = time.perf_counter()
    for cloud in cp.io.iter_point_clouds(path):
        if as_numpy:
            points += int(np.asarray(cloud.points).shape[0])
        else:
            points += len(cloud)
        no_returns += cloud.no_returns
        n += 1
        if n == frames:
            break
    seconds = time.perf_counter() - start
    with bags._Bag(path) as bag:
        for i, (_, raw) in enumerate(bag.messages(TOPIC)):
            if i == n:
                break
            t0 = time.perf_counter()
            cp.io.read_pointcloud2_message(raw, bag.encoding)
            parse += time.perf_counter() - t0
    return {
        "frames": n,
        "seconds": seconds,
        "frames_per_second": n / seconds,
        "storage_frames_per_second": n / storage,
        "parse_frames_per_second": n / parse,
        "points_per_frame": points / max(n, 1),
        "no_returns_per_frame": no_returns / max(n, 1),
        "points_as_numpy": as_numpy,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def measure(path: Path, frames: int, as_numpy: bool) -> dict[str, Any]:
    """Run :func:`read` in a fresh process, so that its peak memory is the reading's own."""
    cmd = [sys.executable, __file__, "--read", str(path), "--frames", str(frames)]
    if as_numpy:
        cmd.append("--numpy")
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main() -> int:
    """Write the bag, read it in child processes, print the table (or JSON)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--points", type=int, default=300_000)
    parser.add_argument("--storage", choices=["sqlite3", "mcap", "ros1"], default="sqlite3")
    parser.add_argument("--keep", default=None, help="write the bag into DIR and keep it")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--read", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--numpy", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.read is not None:
        print(json.dumps(read(args.read, args.frames, args.numpy)))
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(args.keep) if args.keep else Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        t0 = time.perf_counter()
        bag = write_bag(folder / "bench", args.frames, args.points, args.storage)
        written = time.perf_counter() - t0
        size = sum(p.stat().st_size for p in (bag.rglob("*") if bag.is_dir() else [bag]))
        few = max(1, args.frames // 10)
        rows = [
            measure(bag, few, False),
            measure(bag, args.frames, False),
            measure(bag, args.frames, True),
        ]
    doc = {
        "storage": args.storage,
        "bag_mb": size / 1e6,
        "write_seconds": written,
        "runs": rows,
    }
    if args.json:
        print(json.dumps(doc, indent=2))
        return 0
    print(
        f"{args.storage} bag: {args.frames} frames of {rows[1]['points_per_frame']:.0f} valid "
        f"points (+{rows[1]['no_returns_per_frame']:.0f} no-returns), {size / 1e6:.0f} MB, "
        f"written in {written:.1f} s"
    )
    print(
        f"{'frames':>7} {'numpy':>6} {'stream/s':>9} {'storage/s':>10} {'parse/s':>8} "
        f"{'peak RSS MB':>12}"
    )
    for r in rows:
        print(
            f"{r['frames']:>7} {'yes' if r['points_as_numpy'] else 'no':>6} "
            f"{r['frames_per_second']:>9.1f} {r['storage_frames_per_second']:>10.1f} "
            f"{r['parse_frames_per_second']:>8.1f} {r['peak_rss_mb']:>12.1f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
