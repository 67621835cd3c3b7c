"""Point clouds from ROS bags, no ROS installation needed.

Reads ``sensor_msgs/PointCloud2`` messages from rosbag2 (a folder with its
``metadata.yaml``, or one of its sqlite3 ``.db3`` or ``.mcap`` files) and from
ROS 1 ``.bag`` files. The bag is opened with the pure-Python ``rosbags``
package (``pip install 'cloudprox[bags]'``); each message's bytes go through
the Rust core's PointCloud2 reader as they are stored (CDR for rosbag2, the
ROS 1 serialization for ``.bag``), so nothing but the points is copied.

Sensor pose
    When the bag's ``/tf`` and ``/tf_static`` connect the message's
    ``header.frame_id`` (the sensor's frame) to a parent frame, the points are
    moved into the root of that tree (or into ``frame=``) and
    ``CloudFile.sensor_pose`` is the sensor frame's pose there. Transforms are
    composed along the chain from the sensor frame up to the root at the
    message's ``header.stamp`` (the bag's receive time when the stamp is 0):
    ``/tf_static`` edges are fixed; a ``/tf`` edge is *interpolated* between
    its two samples around the stamp (linearly in translation, spherically in
    rotation) and, for a stamp before its first or after its last sample, its
    *nearest* sample. Without TF for the frame the points stay in the message's
    frame and the sensor sits at its origin (``sensor_pose_is_default``).
No-return points
    In an organized cloud (``height > 1``) points at exactly ``(0, 0, 0)`` of
    the sensor's frame, and NaN points, are the driver's no-returns: left out
    of ``points``, counted (``CloudFile.at_origin``, ``skipped``,
    ``no_returns``), their pixels kept in the organized layout.
Errors
    A missing bag raises ``FileNotFoundError``; a bag that cannot be read
    (truncated, corrupt, an unsupported storage) and a message that is not a
    valid PointCloud2 (truncated, a field missing) raise
    :class:`cloudprox.FormatError` naming the file, and the topic, message
    index and field where they apply; a topic that does not exist, is not a
    PointCloud2 (its type is named) or an index out of range raise
    :class:`cloudprox.InvalidInputError`.

Memory is flat in the number of frames: :func:`iter_point_clouds` holds one
message at a time (plus the bag's TF samples, read once).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
from collections.abc import Generator, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cloudprox._native import CloudFile
from cloudprox.exceptions import CloudproxError, FormatError, InvalidInputError

__all__ = [
    "BAG_SUFFIXES",
    "POINTCLOUD2_TYPES",
    "BagTopic",
    "TransformTree",
    "bag_selection",
    "is_bag",
    "iter_point_clouds",
    "read_point_cloud",
    "topics",
]

PathLike = str | os.PathLike[str]
FloatArray = npt.NDArray[np.float64]

#: File suffixes read as bags: ROS 1, rosbag2 sqlite3, rosbag2 MCAP.
BAG_SUFFIXES = frozenset({".bag", ".db3", ".mcap"})
#: The message type names of ``sensor_msgs/PointCloud2`` (as rosbags spells them).
POINTCLOUD2_TYPES = frozenset({"sensor_msgs/msg/PointCloud2", "sensor_msgs/PointCloud2"})
#: The message type of ``/tf`` and ``/tf_static``.
TF_TYPES = frozenset({"tf2_msgs/msg/TFMessage", "tf2_msgs/TFMessage", "tf/msg/tfMessage"})
#: The topics TF is read from (ROS 1 bags sometimes drop the slash).
TF_TOPICS = frozenset({"/tf", "tf"})
TF_STATIC_TOPICS = frozenset({"/tf_static", "tf_static"})

_SELECTION: contextvars.ContextVar[tuple[str | None, int]] = contextvars.ContextVar(
    "cloudprox_bag_selection", default=(None, 0)
)


@dataclass(frozen=True)
class BagTopic:
    """One topic of a bag.

    Attributes
    ----------
    name : str
        The topic (``/velodyne_points``).
    msgtype : str
        Its message type as stored (``sensor_msgs/msg/PointCloud2``).
    count : int
        Its number of messages.
    """

    name: str
    msgtype: str
    count: int

    @property
    def is_pointcloud2(self) -> bool:
        """Whether the topic holds ``sensor_msgs/PointCloud2`` messages."""
        return self.msgtype in POINTCLOUD2_TYPES


def is_bag(path: PathLike) -> bool:
    """Tell whether ``path`` is read as a bag.

    A ``.bag``, ``.db3`` or ``.mcap`` file, or a folder holding a rosbag2
    ``metadata.yaml``.
    """
    p = Path(path)
    if p.suffix.lower() in BAG_SUFFIXES:
        return True
    return p.is_dir() and (p / "metadata.yaml").is_file()


@contextlib.contextmanager
def bag_selection(topic: str | None = None, index: int = 0) -> Iterator[None]:
    """Set the topic and index :func:`cloudprox.io.read_point_cloud` reads from a bag.

    They apply while the context is open, when the call does not give them: for
    code that reads a path it is handed, as the command line's ``--topic`` and
    ``--index`` do.

    Parameters
    ----------
    topic : str, optional
        The PointCloud2 topic (``None``: the bag's only one).
    index : int, default 0
        The message index in that topic (negative: from the end).
    """
    token = _SELECTION.set((topic, index))
    try:
        yield
    finally:
        _SELECTION.reset(token)


def selected() -> tuple[str | None, int]:
    """Return the ``(topic, index)`` set by :func:`bag_selection` (``(None, 0)`` outside it)."""
    return _SELECTION.get()


# ---------------------------------------------------------------------- opening


def _rosbags() -> Any:
    try:
        import rosbags  # noqa: F401
    except ImportError:
        raise ModuleNotFoundError(
            "reading ROS bags needs the 'rosbags' package: pip install 'cloudprox[bags]' "
            "(or pip install rosbags)"
        ) from None
    from rosbags import rosbag1, rosbag2

    return rosbag1, rosbag2


def _describe(err: BaseException) -> str:
    text = str(err).strip() or type(err).__name__
    return text if len(text) <= 300 else text[:300] + "..."


@contextlib.contextmanager
def _bag_errors(path: PathLike, what: str = "") -> Iterator[None]:
    """Turn whatever a bag reader raises into cloudprox's errors, naming the file."""
    try:
        yield
    except (CloudproxError, FileNotFoundError, MemoryError, ModuleNotFoundError):
        raise
    except Exception as err:
        where = f" ({what})" if what else ""
        raise FormatError(
            f"{os.fspath(path)}{where}: not a readable bag: {type(err).__name__}: {_describe(err)}"
        ) from err


class _Bag:
    """An open bag: its reader, whether it is ROS 1, its topics."""

    def __init__(self, path: PathLike) -> None:
        self.path = Path(path)
        if not self.path.exists():
            raise FileNotFoundError(f"{os.fspath(path)}: no such file or folder")
        rosbag1, rosbag2 = _rosbags()
        self.ros1 = self.path.is_file() and self.path.suffix.lower() == ".bag"
        if not self.ros1 and not is_bag(self.path):
            raise InvalidInputError(
                f"{os.fspath(path)}: not a bag (expected a .bag, .db3 or .mcap file, or a "
                "rosbag2 folder with metadata.yaml)"
            )
        self._stack = contextlib.ExitStack()
        with _bag_errors(self.path):
            reader = rosbag1.Reader(self.path) if self.ros1 else rosbag2.Reader(self.path)
            self.reader = self._stack.enter_context(reader)
            self.connections = list(self.reader.connections)
        self.encoding = "ros1" if self.ros1 else "cdr"

    def __enter__(self) -> _Bag:
        return self

    def __exit__(self, *exc: object) -> None:
        with contextlib.suppress(Exception):
            self._stack.close()

    def topics(self) -> list[BagTopic]:
        counts: dict[str, int] = {}
        types: dict[str, set[str]] = {}
        for c in self.connections:
            counts[c.topic] = counts.get(c.topic, 0) + int(c.msgcount)
            types.setdefault(c.topic, set()).add(c.msgtype)
        return [
            BagTopic(name, " | ".join(sorted(types[name])), counts[name]) for name in sorted(counts)
        ]

    def cloud_topic(self, topic: str | None) -> BagTopic:
        """Return the PointCloud2 topic asked for (the only one when ``None``)."""
        all_topics = self.topics()
        listing = ", ".join(f"{t.name} ({t.msgtype}, {t.count})" for t in all_topics) or "none"
        if topic is None:
            clouds = [t for t in all_topics if t.is_pointcloud2]
            if len(clouds) == 1:
                return clouds[0]
            if not clouds:
                raise FormatError(
                    f"{self.path}: the bag has no sensor_msgs/PointCloud2 topic; its topics: "
                    f"{listing}"
                )
            names = ", ".join(f"{t.name} ({t.count} messages)" for t in clouds)
            raise InvalidInputError(
                f"{self.path}: the bag has {len(clouds)} PointCloud2 topics, give one "
                f"(topic= or --topic): {names}"
            )
        found = [t for t in all_topics if t.name == topic]
        if not found:
            raise InvalidInputError(f"{self.path}: no topic {topic!r}; its topics: {listing}")
        if not found[0].is_pointcloud2:
            raise InvalidInputError(
                f"{self.path}: topic {topic} holds {found[0].msgtype} messages, not "
                "sensor_msgs/msg/PointCloud2"
            )
        return found[0]

    def messages(self, topic: str) -> Iterator[tuple[int, bytes]]:
        """``(bag timestamp, raw bytes)`` of a topic's messages, in order."""
        conns = [c for c in self.connections if c.topic == topic]
        with _bag_errors(self.path, f"topic {topic}"):
            for _, timestamp, raw in self.reader.messages(connections=conns):
                yield timestamp, raw

    def transform_tree(self) -> TransformTree:
        """Read the bag's ``/tf`` and ``/tf_static``."""
        tree = TransformTree()
        names = TF_TOPICS | TF_STATIC_TOPICS
        conns = [c for c in self.connections if c.topic in names and c.msgtype in TF_TYPES]
        if not conns:
            return tree
        from rosbags.interfaces import MessageDefinitionFormat
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore

        store = get_typestore(Stores.ROS1_NOETIC if self.ros1 else Stores.ROS2_HUMBLE)
        deserialize = store.deserialize_ros1 if self.ros1 else store.deserialize_cdr
        with _bag_errors(self.path, "topic /tf"):
            for conn in conns:  # the bag's own definition where it has one (ROS 1 always)
                if conn.msgdef.format == MessageDefinitionFormat.MSG and conn.msgdef.data:
                    # a definition that clashes with the store's: keep the store's
                    with contextlib.suppress(Exception):
                        store.register(get_types_from_msg(conn.msgdef.data, conn.msgtype))
            for conn, _, raw in self.reader.messages(connections=conns):
                msg: Any = deserialize(raw, conn.msgtype)
                static = conn.topic in TF_STATIC_TOPICS
                for t in msg.transforms:
                    stamp = int(t.header.stamp.sec) * 1_000_000_000 + int(t.header.stamp.nanosec)
                    tr, q = t.transform.translation, t.transform.rotation
                    tree.add(
                        t.header.frame_id,
                        t.child_frame_id,
                        stamp,
                        (tr.x, tr.y, tr.z),
                        (q.w, q.x, q.y, q.z),
                        static=static,
                    )
        return tree


# ------------------------------------------------------------------------ TF


def _frame(name: str) -> str:
    return name.strip().lstrip("/")


def _quat_matrix(q: FloatArray) -> FloatArray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _slerp(q0: FloatArray, q1: FloatArray, s: float) -> FloatArray:
    d = float(np.dot(q0, q1))
    if d < 0.0:
        q1, d = -q1, -d
    if d > 0.9995:
        q = q0 + s * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(min(d, 1.0))
    return (np.sin((1 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


def _pose(t: FloatArray, q: FloatArray) -> FloatArray:
    m = np.eye(4)
    m[:3, :3] = _quat_matrix(q)
    m[:3, 3] = t
    return m


class TransformTree:
    """The transforms of a bag's ``/tf`` (time-stamped) and ``/tf_static`` (fixed).

    Each frame has one parent: the parent of its first transform (later ones from
    another parent are ignored, as tf2 would refuse them). See the module docs for
    how a transform at a stamp is found (interpolated, or nearest outside the samples).
    """

    def __init__(self) -> None:
        self._static: dict[str, tuple[str, FloatArray]] = {}
        self._samples: dict[str, tuple[str, list[tuple[int, FloatArray, FloatArray]]]] = {}
        self._dynamic: dict[str, tuple[str, np.ndarray, FloatArray, FloatArray]] = {}

    def add(
        self,
        parent: str,
        child: str,
        stamp: int,
        translation: tuple[float, float, float],
        rotation_wxyz: tuple[float, float, float, float],
        *,
        static: bool = False,
    ) -> None:
        """Add the transform of ``child`` in ``parent`` (stamp in nanoseconds)."""
        parent, child = _frame(parent), _frame(child)
        t = np.asarray(translation, dtype=np.float64)
        q = np.asarray(rotation_wxyz, dtype=np.float64)
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q)) and np.linalg.norm(q) > 0):
            return
        if static:
            if child not in self._static or self._static[child][0] == parent:
                self._static[child] = (parent, _pose(t, q))
            return
        known = self._samples.setdefault(child, (parent, []))
        if known[0] == parent:
            known[1].append((stamp, t, q))
            self._dynamic.pop(child, None)

    def __len__(self) -> int:
        """Return the number of frames that have a parent."""
        return len(set(self._static) | set(self._samples))

    def parent(self, frame: str) -> str | None:
        """Return the parent of ``frame``, or ``None`` for a root or an unknown frame."""
        frame = _frame(frame)
        if frame in self._static:
            return self._static[frame][0]
        if frame in self._samples:
            return self._samples[frame][0]
        return None

    def _edge(self, child: str, stamp: int) -> FloatArray:
        if child in self._static:
            return self._static[child][1]
        if child not in self._dynamic:
            parent, samples = self._samples[child]
            samples.sort(key=lambda s: s[0])
            times = np.array([s[0] for s in samples], dtype=np.int64)
            ts = np.array([s[1] for s in samples])
            qs = np.array([s[2] / np.linalg.norm(s[2]) for s in samples])
            self._dynamic[child] = (parent, times, ts, qs)
        _, times, ts, qs = self._dynamic[child]
        k = int(np.searchsorted(times, stamp))
        if k == 0:
            return _pose(ts[0], qs[0])
        if k >= len(times):
            return _pose(ts[-1], qs[-1])
        t0, t1 = int(times[k - 1]), int(times[k])
        s = 0.0 if t1 == t0 else (stamp - t0) / (t1 - t0)
        return _pose(ts[k - 1] + s * (ts[k] - ts[k - 1]), _slerp(qs[k - 1], qs[k], s))

    def to_root(self, frame: str, stamp: int) -> tuple[str, FloatArray]:
        """Return the root of ``frame``'s tree and ``frame``'s pose in it at ``stamp``."""
        frame = _frame(frame)
        pose = np.eye(4)
        seen = {frame}
        while (parent := self.parent(frame)) is not None:
            pose = self._edge(frame, stamp) @ pose
            frame = parent
            if frame in seen:
                raise FormatError(f"TF: the frames form a loop through {frame!r}")
            seen.add(frame)
        return frame, pose

    def lookup(self, target: str | None, source: str, stamp: int) -> tuple[str, FloatArray]:
        """Return the frame ``source`` is expressed in and its pose there at ``stamp``.

        ``target=None`` is the root of ``source``'s tree. Raises
        :class:`cloudprox.InvalidInputError` when ``target`` is not in that tree.
        """
        root, pose = self.to_root(source, stamp)
        if target is None or _frame(target) == root:
            return root, pose
        target_root, target_pose = self.to_root(target, stamp)
        if target_root != root:
            raise InvalidInputError(
                f"frame {target!r} is not connected to {source!r} by the bag's TF "
                f"({source!r} is under {root!r}, {target!r} under {target_root!r})"
            )
        return _frame(target), np.linalg.inv(target_pose) @ pose


# ---------------------------------------------------------------------- reading


def topics(path: PathLike) -> list[BagTopic]:
    """Return the topics of a bag with their message types and counts, sorted by name.

    Raises
    ------
    FileNotFoundError
        If the bag does not exist.
    cloudprox.FormatError
        If it cannot be read (naming the file and what the reader said).
    """
    with _Bag(path) as bag:
        return bag.topics()


def _frames(
    bag: _Bag, topic: BagTopic, frame: str | None, start: int = 0, stop: int | None = None
) -> Generator[CloudFile, None, None]:
    tree = bag.transform_tree()
    for i, (timestamp, raw) in enumerate(bag.messages(topic.name)):
        if i < start:
            continue
        if stop is not None and i >= stop:
            return
        name = f"{bag.path} (topic {topic.name}, message {i})"
        pose = None
        target = None
        if len(tree) or frame is not None:
            sensor_frame, stamp = CloudFile._message_header(raw, bag.encoding, name=name)
            stamp = stamp if stamp != 0 else int(timestamp)
            if frame is not None and _frame(frame) == _frame(sensor_frame):
                target = frame
            elif tree.parent(sensor_frame) is not None or frame is not None:
                try:
                    target, pose = tree.lookup(frame, sensor_frame, stamp)
                except InvalidInputError as err:
                    raise InvalidInputError(f"{name}: {err}") from None
        yield CloudFile._from_message(
            raw,
            bag.encoding,
            name=name,
            path=os.fspath(bag.path),
            pose=pose,
            frame_id=target,
            topic=topic.name,
            index=i,
        )


def read_point_cloud(
    path: PathLike, topic: str | None = None, index: int = 0, *, frame: str | None = None
) -> CloudFile:
    """Read one ``sensor_msgs/PointCloud2`` frame of a bag.

    Parameters
    ----------
    path : str or path-like
        A ROS 1 ``.bag``, a rosbag2 ``.db3`` or ``.mcap`` file, or a rosbag2 folder.
    topic : str, optional
        The PointCloud2 topic; ``None`` picks the bag's only one (an error lists
        them when there are several).
    index : int, default 0
        The message's index in the topic; negative counts from the end.
    frame : str, optional
        The TF frame to express the points in (default: the root of the sensor
        frame's tree when the bag's TF knows the frame, else the message's frame).

    Returns
    -------
    CloudFile
        The points, the sensor pose (from TF, see the module docs), the organized
        layout and the no-return counts; ``topic``, ``index``, ``stamp``,
        ``frame_id`` and ``sensor_frame`` say where it came from.

    Raises
    ------
    FileNotFoundError
        If the bag does not exist.
    cloudprox.FormatError
        If the bag or the message cannot be read (naming file, topic, message, field).
    cloudprox.InvalidInputError
        If the topic is unknown, ambiguous or not a PointCloud2, or the index is out of
        range.
    """
    with _Bag(path) as bag:
        chosen = bag.cloud_topic(topic)
        i = index + chosen.count if index < 0 else index
        if not 0 <= i < chosen.count:
            raise InvalidInputError(
                f"{bag.path}: index {index} is out of range: topic {chosen.name} has "
                f"{chosen.count} messages"
            )
        frames = _frames(bag, chosen, frame, start=i, stop=i + 1)
        try:
            for cloud in frames:
                return cloud
        finally:
            frames.close()
        raise FormatError(
            f"{bag.path} (topic {chosen.name}): message {i} is missing: the bag holds fewer "
            f"messages than its index says ({chosen.count})"
        )


def iter_point_clouds(
    path: PathLike, topic: str | None = None, *, frame: str | None = None
) -> Iterator[CloudFile]:
    """Yield every frame of a bag's PointCloud2 topic in order, one at a time.

    Memory stays flat in the number of frames: one message is held at a time (and
    the bag's TF samples, read once before the first frame). Parameters, errors and
    what each :class:`CloudFile` holds are as in :func:`read_point_cloud`.
    """
    with _Bag(path) as bag:
        chosen = bag.cloud_topic(topic)
        yield from _frames(bag, chosen, frame)
