"""One planner, four collision checkers: a Panda among scanned objects on a table.

The scene: a table top (0.7 x 1.2 m, its surface at the robot base's height)
with three meshes that registry packages ship standing on it (fetched into the
cache by ``tests/realfiles.py``, SHA-256 checked): the Stanford bunny (a 99-face
decimation of the scan, ``stl_io`` crate), Spot (``meshx`` crate) and
geomview's mushroom (Debian), each scaled to 0.18-0.25 m. A simulated Kinect v1
(320 x 240, focal 290 px, 1.1-1.6 m away) ray-casts them (Open3D) with the
Nguyen et al. (2012) noise (axial ``0.0012 + 0.0019 (z - 0.4)^2``, lateral 0.8
px): the scan. The Franka Panda (``gym-ignition-models`` wheel, as
``benches/robot.py``) stands at the table's edge.

Problems: a start with every link at least 5 cm from the exact scene, and a goal
whose exact clearance (python-fcl ``distance()``, links against the scene's
meshes) is between 0.5 and 3 cm, the hand nearest: reaching in beside an object.
Every planner is OMPL's RRTConnect (``cloudprox.planning.plan_joint_space``),
the same seeds, time limit and motion resolution (no link point moves more than
``--resolution`` between two checked states), path simplification included:

* ``exact``: python-fcl on the exact meshes (ground truth, not available to a robot);
* ``map S``: the scan's occupied voxels of side S as boxes (python-fcl), the
  boolean collision map a ROS stack builds; S the sensor's resolution (a
  pixel's footprint at the median depth) and 2 cm;
* ``cloudprox P``: :class:`cloudprox.planning.ChanceConstraint` at thresholds P.

Self-collision is the robot's exact check (``Robot.self_collisions``) for all.
Each returned path is checked densely against the exact scene (python-fcl,
states at most 1 mm of link travel apart): the share of paths that collide.
Grasps: Panda hand poses around the objects (fingers open, approach from above
or the side, exact signed distance -1 to 3 cm), ranked by cloudprox's collision
probability and by the collision map's boolean against the exact label (AUC).

Needs ``pip install python-fcl ompl open3d-cpu`` (``pip install -e '.[bench]'``).

Usage: ``python3 benches/planning.py [--quick] [--out DIR]``
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import itertools

from tabletop import (
    FclChecker,
    discrete_motion,
    fcl_object,
    log,
    motion_states,
    scan,
    scene_meshes,
    voxel_boxes,
)
from tests.robots import panda_urdf

import cloudprox as cp
from cloudprox.planning import ChanceConstraint, PlanResult, plan_joint_space


@dataclass
class Row:
    """One planner's runs."""

    solved: list[bool] = field(default_factory=list)
    rejected: int = 0
    lengths: list[float] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    simplify: list[float] = field(default_factory=list)
    colliding: list[bool] = field(default_factory=list)


def problems(
    robot: cp.Robot, exact: FclChecker, n: int, rng: np.random.Generator
) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """``n`` (start, goal, goal clearance): starts >= 5 cm free, goals 0.5-3 cm, hand nearest."""
    lim = robot.joint_limits
    hand = {"panda_hand", "panda_leftfinger", "panda_rightfinger"}
    starts: list[np.ndarray] = []
    goals: list[tuple[np.ndarray, float]] = []
    while len(starts) < n or len(goals) < n:
        q = rng.uniform(lim[:, 0], lim[:, 1])
        q[7:] = 0.04
        if robot.self_collisions(q):
            continue
        tip = robot.link_poses(q)["panda_hand"][:3, 3]
        if tip[2] < 0.02 or tip[0] < 0.25:
            continue
        d, link = exact.clearance(q)
        if d >= 0.05 and len(starts) < n:
            starts.append(q)
        elif 0.005 <= d <= 0.03 and link in hand and len(goals) < n:
            goals.append((q, d))
    return [(s, g, d) for s, (g, d) in zip(starts, goals, strict=False)]


def dense_collides(exact: FclChecker, path: np.ndarray) -> bool:
    """Whether the exact robot meets the exact scene anywhere along the path (1 mm travel)."""
    for a, b in itertools.pairwise(path):
        if exact.collides(a) or any(exact.collides(q) for q in motion_states(a, b, 0.001)):
            return True
    return exact.collides(path[-1])


def main() -> None:
    """Build the scene, plan every problem with every checker, print and save the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="4 problems, 1 seed, 3 s, 100 grasps")
    ap.add_argument("--problems", type=int, default=10)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--time-limit", type=float, default=5.0)
    ap.add_argument("--resolution", type=float, default=0.005, help="motion check (m)")
    ap.add_argument("--thresholds", default="0.01,0.1")
    ap.add_argument("--grasps", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=Path("planning-bench"))
    args = ap.parse_args()
    if args.quick:
        args.problems, args.seeds, args.time_limit, args.grasps = 4, 1, 3.0, 100
    args.out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    robot = cp.Robot.from_urdf(panda_urdf())
    meshes = scene_meshes()
    cloud, spacing = scan(meshes, args.seed)
    points = np.asarray(cloud.points)
    sigma = float(np.median(np.sqrt(np.trace(np.asarray(cloud.covariances), axis1=1, axis2=2) / 3)))
    exact = FclChecker(robot, [fcl_object(m) for m in meshes.values()])
    log(
        f"scan: {len(cloud)} points, pixel footprint {spacing * 1e3:.1f} mm, "
        f"sigma {sigma * 1e3:.1f} mm"
    )
    probs = problems(robot, exact, args.problems, rng)
    log(f"{len(probs)} problems, goal clearances {[round(p[2] * 100, 1) for p in probs]} cm")

    checkers: dict[str, tuple[Callable, Callable]] = {}
    checkers["exact (python-fcl, meshes)"] = (
        exact.state_valid,
        discrete_motion(exact.state_valid, args.resolution),
    )
    for size in (spacing, 0.02):
        cmap = FclChecker(robot, voxel_boxes(points, size))
        checkers[f"map {size * 1e3:.0f} mm (python-fcl, boxes)"] = (
            cmap.state_valid,
            discrete_motion(cmap.state_valid, args.resolution),
        )
    for p in (float(x) for x in args.thresholds.split(",")):
        c = ChanceConstraint(robot, cloud, max_probability=p, resolution=args.resolution)
        checkers[f"cloudprox P <= {p:g}"] = (c.state_valid, c.motion_valid)

    rows = {name: Row() for name in checkers}
    for i, (q0, q1, _) in enumerate(probs):
        for seed in range(1, args.seeds + 1):
            for name, (state_valid, motion_valid) in checkers.items():
                row = rows[name]
                try:
                    r: PlanResult = plan_joint_space(
                        robot.joint_limits,
                        state_valid,
                        motion_valid,
                        q0,
                        q1,
                        time_limit=args.time_limit,
                        seed=seed,
                        simplify_time=1.0,
                    )
                except ValueError:  # start or goal invalid for this checker
                    row.rejected += 1
                    row.solved.append(False)
                    continue
                row.solved.append(r.solved)
                row.times.append(r.planning_time)
                if r.path is not None:
                    row.simplify.append(r.simplify_time)
                    row.lengths.append(r.length)
                    row.colliding.append(dense_collides(exact, r.path))
                log(
                    f"problem {i} seed {seed} {name}: solved {r.solved} in "
                    f"{r.planning_time:.2f} s ({r.states_checked} states, "
                    f"{r.motions_checked} motions)"
                    + (f", colliding {row.colliding[-1]}" if r.path is not None else "")
                )
    grasp_rows = grasps(robot, meshes, cloud, spacing, args.grasps, rng)
    table = markdown(rows, grasp_rows, args, len(cloud), spacing, sigma)
    print(table)
    (args.out / "planning.md").write_text(table)
    figure(rows, args.out / "planning.png")
    log(f"wrote {args.out / 'planning.md'} and {args.out / 'planning.png'}")
    log(f"({time.perf_counter() - t_start:.0f} s)")


# ---------------------------------------------------------------- grasps


def grasps(
    robot: cp.Robot,
    meshes: dict[str, cp.Mesh],
    cloud: cp.PointCloud,
    spacing: float,
    n: int,
    rng: np.random.Generator,
) -> list[tuple[str, float, float]]:
    """Hand poses around the objects: (method, AUC, share decided wrong at > 3 sigma)."""
    from scipy.spatial import cKDTree

    q = np.zeros(robot.dof)
    q[7:] = 0.04
    poses = robot.link_poses(q)
    inv = np.linalg.inv(poses["panda_hand"])
    parts = [
        robot.link_mesh(n).transformed(inv @ poses[n])  # type: ignore[union-attr]
        for n in ("panda_hand", "panda_leftfinger", "panda_rightfinger")
    ]
    gripper = cp.Mesh.merged(parts)
    shape = cp.ExactShape(parts)
    objects = [m for k, m in meshes.items() if k != "table"]
    scene = cp.ExactShape([*objects, meshes["table"]])
    out_poses, dist = [], []
    while len(out_poses) < n:
        obj = objects[rng.integers(len(objects))]
        lo, hi = (np.asarray(b) for b in obj.bounds())
        centre = (lo + hi) / 2
        # approach along the hand's z, from above or from the side, yawed at random
        tilt = rng.uniform(math.pi / 2, math.pi)
        yaw = rng.uniform(-math.pi, math.pi)
        pose = (
            cp.pose.from_rotation_vector((0.0, 0.0, yaw))
            @ cp.pose.from_rotation_vector((0.0, tilt, 0.0))
            @ cp.pose.from_rotation_vector((0.0, 0.0, rng.uniform(0, math.pi)))
        )
        approach = pose[:3, 2]
        target = rng.uniform(-0.01, 0.03)

        def at(
            s: float,
            pose: np.ndarray = pose,
            approach: np.ndarray = approach,
            centre: np.ndarray = centre,
        ) -> cp.Proximity:
            pose[:3, 3] = centre - s * approach
            return cp.exact_proximity(shape, scene, pose)

        lo_s, hi_s = 0.0, 0.5
        if at(hi_s).intersecting:
            continue
        for _ in range(30):  # first contact coming in along the approach
            mid = 0.5 * (lo_s + hi_s)
            lo_s, hi_s = (lo_s, mid) if not at(mid).intersecting else (mid, hi_s)
        s = hi_s + target
        r = at(s)
        if bool(r.intersecting) != (target < 0):
            continue
        # free: the exact distance; in contact: the travel past first contact (the
        # meshes are not convex: the depth is that travel, as in benches/realmesh.py)
        out_poses.append(pose.copy())
        dist.append(target if target < 0 else float(r.distance))
    poses_a = np.array(out_poses)
    d = np.array(dist)
    p_cp = np.array([r.probability for r in cp.collide_many(gripper, cloud, poses_a)])
    pts = np.asarray(cloud.points)
    samples = np.asarray(gripper.sample(4000, seed=1)[0])
    rows = []
    for size in (spacing, 0.02):
        tree = cKDTree((np.floor(pts / size) + 0.5) * size)
        hit = np.array(
            [
                bool(
                    np.any(
                        np.isfinite(
                            tree.query(
                                samples @ p[:3, :3].T + p[:3, 3],
                                p=np.inf,
                                distance_upper_bound=size / 2,
                            )[0]
                        )
                    )
                )
                for p in poses_a
            ]
        )
        rows.append((f"map {size * 1e3:.0f} mm", hit.astype(float)))
    rows.insert(0, ("cloudprox P", p_cp))
    sigma = float(np.median(np.sqrt(np.trace(np.asarray(cloud.covariances), axis1=1, axis2=2) / 3)))
    label = d <= 0.0
    out = []
    for name, score in rows:
        far = np.abs(d) > 3 * sigma
        wrong = (score >= 0.5) != label
        out.append((name, auc(score, label), float(np.mean(wrong[far]))))
    out.append(("(poses, colliding, within 3 sigma)", float(len(d)), float(label.mean())))
    return out


def auc(score: np.ndarray, label: np.ndarray) -> float:
    """Area under the ROC curve of ``score`` for ``label`` (ties count half)."""
    pos, neg = score[label], score[~label]
    if len(pos) == 0 or len(neg) == 0:
        return float("nan")
    greater = (pos[:, None] > neg[None, :]).mean()
    ties = (pos[:, None] == neg[None, :]).mean()
    return float(greater + 0.5 * ties)


# ---------------------------------------------------------------- output


def markdown(
    rows: dict[str, Row],
    grasp_rows: list[tuple[str, float, float]],
    args: argparse.Namespace,
    n_points: int,
    spacing: float,
    sigma: float,
) -> str:
    """Return the tables as markdown."""
    runs = args.problems * args.seeds
    lines = [
        f"Panda, RRTConnect, {args.problems} problems x {args.seeds} seeds, "
        f"{args.time_limit:g} s limit, motion resolution {args.resolution * 1e3:g} mm; "
        f"scan {n_points} points, pixel footprint {spacing * 1e3:.1f} mm, "
        f"median sigma {sigma * 1e3:.1f} mm.",
        "",
        "| checker | solved | start/goal rejected | median path length (rad) "
        "| median planning time (s) | median simplification (s) "
        "| paths colliding with the exact scene |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in rows.items():
        solved = sum(r.solved)
        coll = sum(r.colliding)
        length = f"{np.median(r.lengths):.2f}" if r.lengths else "-"
        t = f"{np.median(r.times):.2f}" if r.times else "-"
        simp = f"{np.median(r.simplify):.2f}" if r.simplify else "-"
        lines.append(
            f"| {name} | {solved}/{runs} | {r.rejected} | {length} | {t} | {simp} | "
            f"{coll}/{len(r.colliding)} |"
        )
    lines += [
        "",
        "| grasp ranking | AUC (exact collision) | wrong at > 3 sigma |",
        "|---|---|---|",
    ]
    for name, a, w in grasp_rows[:-1]:
        lines.append(f"| {name} | {a:.3f} | {w:.1%} |")
    n, share = grasp_rows[-1][1], grasp_rows[-1][2]
    lines.append(f"\n{int(n)} grasp poses, {share:.0%} in exact collision.")
    return "\n".join(lines) + "\n"


def figure(rows: dict[str, Row], path: Path) -> None:
    """Outcome of every run per checker (stacked bars), and success against colliding paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(rows)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [3, 2]})
    parts = {
        "solved, free of the exact scene": [
            sum(not c for c in r.colliding) / len(r.solved) for r in rows.values()
        ],
        "solved, colliding with it": [sum(r.colliding) / len(r.solved) for r in rows.values()],
        "not solved in time": [
            (len(r.solved) - sum(r.solved) - r.rejected) / len(r.solved) for r in rows.values()
        ],
        "start or goal rejected": [r.rejected / len(r.solved) for r in rows.values()],
    }
    colours = ["#4c9a5b", "#c8423b", "#9a9a9a", "#d9c27a"]
    left = np.zeros(len(names))
    for (label, share), colour in zip(parts.items(), colours, strict=False):
        ax.barh(names, share, left=left, color=colour, label=label)
        left += np.asarray(share)
    ax.invert_yaxis()
    ax.set_xlim(0, 1)
    ax.set_xlabel("share of runs")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    ax.set_title("RRTConnect, Panda among scanned objects", fontsize=10)
    for k, (name, r) in enumerate(rows.items()):
        x = float(np.mean(r.solved)) if r.solved else 0.0
        y = float(np.mean(r.colliding)) if r.colliding else 0.0
        bx.scatter([x], [y], s=60, marker="osD^v"[k % 5], label=name)
    bx.set_xlabel("success rate")
    bx.set_ylabel("returned paths colliding with the exact scene")
    bx.set_xlim(-0.05, 1.05)
    bx.set_ylim(-0.02, 0.5)
    bx.grid(alpha=0.3)
    bx.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
