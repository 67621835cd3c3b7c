"""Per-configuration cost and accuracy of a Panda against a 100 000-point scan, beside python-fcl.

The scene of ``benches/tabletop.py`` (a table with the bunny, Spot and the
mushroom) seen by the simulated Kinect at 1.63 times its image size (522 x 391:
about 100 000 points, Nguyen et al. 2012 noise). In one run:

* **Cost per configuration**, one thread (``RAYON_NUM_THREADS=1``): cloudprox's
  ``collide_robot`` with each model (surface elements, the default, and points)
  and each mesh side (``--mesh-side``: the links' exact surfaces, the default,
  and their sampled clouds; both unless one is named), its own
  ``stats.time_seconds`` (forward kinematics, broad phase and queries,
  self-collision off), against python-fcl's ``collide()`` of
  the robot's exact link meshes (a ``DynamicAABBTreeCollisionManager``) against
  the exact scene meshes (the anchor) and against the collision map's occupied
  voxels as boxes (sensor resolution and 2 cm), the links posed beforehand (not
  timed). Each model also with ``decide_only=True`` (what a planner's chance
  constraint asks). Uniform: every uniformly random configuration; far: those
  whose exact clearance exceeds 5 sigma (the scan's median sigma); near contact: the agreement set
  below, free and within 5 sigma; penetrating: the agreement set's colliding
  configurations. With ``--repeat N`` each configuration is queried N times
  and its fastest call kept (the median is then over the configurations'
  minima: a shared host's slow phases, which last seconds, otherwise move
  single-call medians by 20-40% between runs).
* **collide_robot_many** on 10 000 random configurations with 1 and 2 threads
  (separate processes).
* **Short motions near the scene** (``--motions``, default 60): through each
  of the first near-contact configurations (the agreement set below), a
  straight joint-space motion along a random arm direction, its links
  travelling 10 sigma either side; ``check_motion`` at its default resolution
  (sigma) checks every state (``max_probability=1``), with the previous
  state's classifier hint (``warm_start``, the default) and without, the two
  alternated motion by motion; total seconds, the ratio, and the largest
  difference of the motions' worst ``P``.
* **Agreement with the exact scene** over ``--near`` configurations near it: from
  a random free configuration along a random joint-space direction to first
  contact (python-fcl), then back to an exact clearance uniform in [0, 10] sigma
  (10% in [10, 30] sigma) or on past contact by a link-point travel in [0, 6]
  sigma (the meshes are not convex: the depth is that travel, as in
  ``benches/realmesh.py``). Decided accuracy (free or collision, against the
  exact label), undecided share, false collisions beyond 3 sigma, missed
  collisions deeper than 3 sigma, for both models; the collision maps' booleans
  alike.

The time to build the links' signed distances (the exact sides, built when the
robot is loaded) is printed first.

Usage: ``python3 benches/robot.py [--configurations 2000] [--near 1000] [--motions 60]
[--repeat 1] [--mesh-side both|exact|sampled] [--seed 0]``
"""

from __future__ import annotations

import os

os.environ.setdefault("RAYON_NUM_THREADS", "1")

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from tabletop import CAMERA_AT, FclChecker, fcl_object, log, scan, scene_meshes, voxel_boxes
from tests.robots import panda_urdf

import cloudprox as cp

#: Image scale of the simulated camera: 1.63^2 x the 37 539 points of the planning scan.
SCALE = 1.63
ARM = slice(0, 7)
#: cloudprox's query models: the surface elements first (the default), then the points model.
MODELS = ("elements", "points")
#: How the links stand in cloudprox's queries: their exact surfaces (the default) or samples.
MESH_SIDES = ("exact", "sampled")


def variants(sides: tuple[str, ...]) -> list[tuple[str, str]]:
    """Return the ``(model, mesh_side)`` pairs measured, the elements model first."""
    return [(model, side) for side in sides for model in MODELS]


def label(model: str, side: str) -> str:
    """Return a variant's name in the tables."""
    return f"{model}, {side}"


def distance_build_seconds(robot: cp.Robot) -> tuple[float, float, int]:
    """Seconds to build every link's signed distance (total, largest) and the faces."""
    total, largest, faces = 0.0, 0.0, 0
    for n in robot.link_names:
        mesh = robot.link_mesh(n)
        if mesh is None:
            continue
        t = time.perf_counter()
        d = cp.MeshDistance(mesh)
        dt = time.perf_counter() - t
        total, largest, faces = total + dt, max(largest, dt), faces + d.num_faces
    return total, largest, faces


def setup(seed: int) -> tuple[cp.Robot, dict[str, cp.Mesh], cp.PointCloud, float, float]:
    """Return the robot, the exact scene, the scan, the sensor's resolution and the median sigma."""
    robot = cp.Robot.from_urdf(panda_urdf())
    meshes = scene_meshes()
    cloud, resolution = scan(meshes, seed, SCALE)
    cov = np.asarray(cloud.covariances)
    sigma = float(np.median(np.sqrt(np.trace(cov, axis1=1, axis2=2) / 3)))
    return robot, meshes, cloud, resolution, sigma


def random_configurations(robot: cp.Robot, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` uniformly random configurations, fingers open."""
    lim = robot.joint_limits
    qs = rng.uniform(lim[:, 0], lim[:, 1], (n, robot.dof))
    qs[:, 7:] = 0.04
    return qs


def vertices(robot: cp.Robot) -> dict[str, np.ndarray]:
    """Each link's mesh vertices, homogeneous, link frame."""
    out = {}
    for n in robot.link_names:
        m = robot.link_mesh(n)
        if m is not None:
            v = np.asarray(m.vertices)
            out[n] = np.hstack([v, np.ones((len(v), 1))])
    return out


def travel(robot: cp.Robot, verts: dict[str, np.ndarray], qa: np.ndarray, qb: np.ndarray) -> float:
    """Largest displacement of a link vertex between ``qa`` and ``qb``."""
    pa, pb = robot.link_poses(qa), robot.link_poses(qb)
    return max(
        float(np.max(np.linalg.norm((v @ pa[n].T - v @ pb[n].T)[:, :3], axis=1)))
        for n, v in verts.items()
    )


def near_configurations(
    robot: cp.Robot, exact: FclChecker, n: int, sigma: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """``n`` configurations near the exact scene and their signed distances (see the module)."""
    verts = vertices(robot)
    lim = robot.joint_limits
    qs, sd = [], []
    while len(qs) < n:
        qa = random_configurations(robot, 1, rng)[0]
        if exact.collides(qa) or robot.link_poses(qa)["panda_hand"][2, 3] < 0.0:
            continue
        direction = np.zeros(robot.dof)
        direction[ARM] = rng.normal(size=7)
        direction /= np.linalg.norm(direction)

        def at(t: float, qa: np.ndarray = qa, direction: np.ndarray = direction) -> np.ndarray:
            return np.clip(qa + t * direction, lim[:, 0], lim[:, 1])

        ts = np.arange(0.02, 1.5, 0.02)
        hit = next((t for t in ts if exact.collides(at(t))), None)
        if hit is None:
            continue
        lo, hi = hit - 0.02, hit
        for _ in range(25):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if exact.collides(at(mid)) else (mid, hi)
        contact = at(hi)
        target = sigma * (rng.uniform(-6.0, 10.0) if rng.random() < 0.9 else rng.uniform(10, 30))
        if target >= 0.0:
            if exact.distance(qa) < target:
                continue
            a, b = 0.0, lo  # distance(at(a)) >= target > distance(at(b)) ~ 0
            for _ in range(20):
                mid = 0.5 * (a + b)
                a, b = (mid, b) if exact.distance(at(mid)) >= target else (a, mid)
            q = at(a)
            d = exact.distance(q)
            if exact.collides(q) or abs(d - target) > 0.25 * sigma:
                continue
        else:
            a, b = hi, hi + 0.3
            if travel(robot, verts, contact, at(b)) < -target:
                continue
            for _ in range(20):
                mid = 0.5 * (a + b)
                a, b = (mid, b) if travel(robot, verts, contact, at(mid)) < -target else (a, mid)
            q = at(b)
            if not exact.collides(q):
                continue
            d = -travel(robot, verts, contact, q)
        qs.append(q)
        sd.append(d)
    return np.array(qs), np.array(sd)


def motion_ends(
    robot: cp.Robot, centres: np.ndarray, sigma: float, rng: np.random.Generator
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per centre, the ends of a straight motion through it.

    Along a random direction of the arm's joints, its links travelling about 10 sigma
    either side.
    """
    verts = vertices(robot)
    ends = []
    for q in centres:
        direction = np.zeros(robot.dof)
        direction[ARM] = rng.normal(size=7)
        direction *= 0.01 / np.linalg.norm(direction)
        scale = 10.0 * sigma / max(travel(robot, verts, q, robot.clamp(q + direction)), 1e-12)
        ends.append((robot.clamp(q - scale * direction), robot.clamp(q + scale * direction)))
    return ends


def motion_rows(
    robot: cp.Robot,
    cloud: cp.PointCloud,
    ends: list[tuple[np.ndarray, np.ndarray]],
    sides: tuple[str, ...],
) -> None:
    """Print the motion table: ``check_motion`` with and without ``warm_start``."""
    print(
        f"\n`check_motion` through {len(ends)} near-contact configurations, every state "
        "checked, one thread:\n"
    )
    print(
        "| model | states | cold (s) | warm-started (s) | warm / cold "
        "| median motion cold / warm (ms) | largest worst-`P` difference |"
    )
    print("|---|---|---|---|---|---|---|")
    for model, side in variants(sides):
        seconds: dict[bool, list[float]] = {True: [], False: []}
        worst: dict[bool, list[float]] = {True: [], False: []}
        states = 0
        for i, (q0, q1) in enumerate(ends):
            order = (True, False) if i % 2 == 0 else (False, True)
            for warm in order:
                t = time.perf_counter()
                m = cp.check_motion(
                    robot,
                    q0,
                    q1,
                    cloud,
                    self_collision=False,
                    model=model,
                    mesh_side=side,
                    max_probability=1.0,
                    warm_start=warm,
                )
                seconds[warm].append(time.perf_counter() - t)
                worst[warm].append(m.probability)
            states += m.states_checked
        cold, warm_s = sum(seconds[False]), sum(seconds[True])
        diff = float(np.max(np.abs(np.subtract(worst[True], worst[False]))))
        print(
            f"| {label(model, side)} | {states} | {cold:.2f} | {warm_s:.2f} | "
            f"{warm_s / cold:.2f}x | "
            f"{np.median(seconds[False]) * 1e3:.0f} / {np.median(seconds[True]) * 1e3:.0f} | "
            f"{diff:.1e} |"
        )


def fcl_call_times(checker: FclChecker, qs: np.ndarray) -> np.ndarray:
    """Seconds of python-fcl's ``collide()`` per configuration, links posed beforehand."""
    out = np.empty(len(qs))
    for i, q in enumerate(qs):
        checker.pose(q)
        t0 = time.perf_counter()
        checker.collide_call()
        out[i] = time.perf_counter() - t0
    return out


def map_booleans(checker: FclChecker, qs: np.ndarray) -> np.ndarray:
    """Return the collision map's answer per configuration."""
    return np.array([checker.collides(q) for q in qs])


def many_seconds(threads: int, configurations: int, seed: int, side: str) -> float:
    """Wall time of ``collide_robot_many`` on random configurations, in a fresh process."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run(
        [
            sys.executable,
            __file__,
            "--many-only",
            str(configurations),
            "--seed",
            str(seed),
            "--mesh-side",
            side,
        ],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return float(json.loads(out.stdout.strip().splitlines()[-1])["seconds"])


def many_only(configurations: int, seed: int, side: str) -> None:
    """Time ``collide_robot_many`` (for :func:`many_seconds`); print JSON."""
    robot, _, cloud, _, _ = setup(seed)
    qs = random_configurations(robot, configurations, np.random.default_rng(seed + 1))
    cp.collide_robot_many(robot, qs[:10], cloud, mesh_side=side)  # link samples, scan hierarchy
    t0 = time.perf_counter()
    cp.collide_robot_many(robot, qs, cloud, self_collision=False, mesh_side=side)
    print(json.dumps({"seconds": time.perf_counter() - t0}))


def us(x: np.ndarray) -> str:
    """Median in microseconds (or milliseconds when large), as text."""
    m = float(np.median(x))
    return f"{m * 1e6:.1f} us" if m < 1e-3 else f"{m * 1e3:.2f} ms"


def occlusion_row(
    robot: cp.Robot,
    cloud: cp.PointCloud,
    queries: tuple[np.ndarray, np.ndarray, np.ndarray],
    model: str,
    side: str,
) -> None:
    """Print what reading the scan's shadow (``shadow=``) does to missed and free configurations.

    ``queries``: the near configurations, the missed deep collisions among them
    and the free ones beyond 3 sigma (indices). Each is queried again with
    ``shadow=filters.Occlusion(cloud, camera)`` at the default prior and a
    shadow depth of infinity, 5 cm and 2 cm: how many missed collisions no
    longer read free, and how many free configurations that read free without
    the shadow read contact with it (what the shadow costs).
    """
    near_q, missed, free = queries
    occ = cp.filters.Occlusion(cloud, CAMERA_AT)

    def free_with(i: int, **shadow: object) -> bool:
        r = cp.collide_robot(
            robot, near_q[i], cloud, self_collision=False, model=model, mesh_side=side, **shadow
        )
        return r.state == "free"

    was_free = [i for i in free if free_with(i)]
    for depth in (math.inf, 0.05, 0.02):
        caught = sum(1 for i in missed if not free_with(i, shadow=occ, shadow_depth=depth))
        flagged = sum(1 for i in was_free if not free_with(i, shadow=occ, shadow_depth=depth))
        within = "anywhere" if math.isinf(depth) else f"within {depth * 1e2:.0f} cm"
        print(
            f"  shadow= ({within} behind the observed surface, prior 0.5, cell "
            f"{occ.cell * 1e3:.1f} mrad): {caught} of the {len(missed)} missed no longer free; "
            f"{flagged} of the {len(was_free)} free configurations beyond 3 sigma read contact."
        )


def main() -> None:
    """Run the measurements and print the tables."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--configurations", type=int, default=2000)
    ap.add_argument("--near", type=int, default=1000)
    ap.add_argument("--many", type=int, default=10_000)
    ap.add_argument("--motions", type=int, default=60, help="short motions near the scene")
    ap.add_argument(
        "--repeat", type=int, default=1, help="calls per configuration; the fastest is kept"
    )
    ap.add_argument(
        "--mesh-side",
        choices=("both", *MESH_SIDES),
        default="both",
        help="how cloudprox's links stand: exact surfaces, samples, or both (default)",
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--many-only", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error(f"--repeat must be at least 1, got {args.repeat}")
    sides = MESH_SIDES if args.mesh_side == "both" else (args.mesh_side,)
    if args.many_only:
        many_only(args.many_only, args.seed, sides[0])
        return
    t_start = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    robot, meshes, cloud, resolution, sigma = setup(args.seed)
    total, largest, faces = distance_build_seconds(robot)
    log(
        f"links' signed distances ({faces} faces): built in {total * 1e3:.1f} ms, "
        f"the largest link {largest * 1e3:.1f} ms"
    )
    points = np.asarray(cloud.points)
    exact = FclChecker(robot, [fcl_object(m) for m in meshes.values()])
    maps = {
        f"map {s * 1e3:.0f} mm": FclChecker(robot, voxel_boxes(points, s))
        for s in (resolution, 0.02)
    }
    log(
        f"scan {len(cloud)} points, sensor resolution {resolution * 1e3:.1f} mm, "
        f"median sigma {sigma * 1e3:.2f} mm; maps: "
        + ", ".join(f"{k} {len(c.objects)} boxes" for k, c in maps.items())
    )
    qs = random_configurations(robot, args.configurations, rng)
    clearance = np.array([exact.distance(q) for q in qs])
    far = qs[clearance > 5 * sigma]
    log(f"{len(far)} of {len(qs)} random configurations farther than 5 sigma")
    near_q, near_d = near_configurations(robot, exact, args.near, sigma, rng)
    log(f"{len(near_q)} configurations near the scene")
    free_near = near_q[(near_d > 0) & (near_d <= 5 * sigma)]

    for model, side in variants(sides):  # link samples, scan hierarchy, elements: built once
        cp.collide_robot(robot, qs[0], cloud, model=model, mesh_side=side)
    rows = []
    penetrating = near_q[near_d < 0]
    cases = (
        ("uniform random", qs),
        ("far (> 5 sigma)", far),
        ("near contact (free, <= 5 sigma)", free_near),
        ("penetrating", penetrating),
    )
    for name, sel in cases:
        t_cp = {
            (model, side, decide): np.array(
                [
                    min(
                        cp.collide_robot(
                            robot,
                            q,
                            cloud,
                            self_collision=False,
                            model=model,
                            mesh_side=side,
                            decide_only=decide,
                        ).stats.time_seconds
                        for _ in range(args.repeat)
                    )
                    for q in sel
                ]
            )
            for model, side in variants(sides)
            for decide in (False, True)
        }
        t_ex = fcl_call_times(exact, sel)
        t_maps = {k: fcl_call_times(c, sel) for k, c in maps.items()}
        rows.append((name, len(sel), t_cp, t_ex, t_maps))
    print(
        f"\nPer configuration, one thread, {len(cloud)} scan points "
        f"(median sigma {sigma * 1e3:.2f} mm)"
        + (f"; cloudprox: the fastest of {args.repeat} calls" if args.repeat > 1 else "")
        + ":\n"
    )
    map_names = list(maps)
    modes = [(m, s, d) for m, s in variants(sides) for d in (False, True)]
    first = (*variants(sides)[0], False)
    print(
        "| configurations | n | "
        + " | ".join(
            f"cloudprox `collide_robot`, {label(m, s)}{', decide-only' if d else ''}"
            for m, s, d in modes
        )
        + " | python-fcl exact meshes | "
        + " | ".join(f"python-fcl {k} boxes" for k in map_names)
        + f" | cloudprox ({label(*first[:2])}) / fcl exact |"
    )
    print("|---|---|" + "---|" * (len(modes) + 1 + len(map_names)) + "---|")
    for name, n, t_cp, t_ex, t_maps in rows:
        print(
            f"| {name} | {n} | "
            + " | ".join(us(t_cp[md]) for md in modes)
            + f" | {us(t_ex)} | "
            + " | ".join(us(t_maps[k]) for k in map_names)
            + f" | {np.median(t_cp[first]) / np.median(t_ex):.1f}x |"
        )

    print("\ncloudprox's time per configuration, one thread: median / mean / max:\n")
    print(
        "| configurations | "
        + " | ".join(f"{label(m, s)}{', decide-only' if d else ''}" for m, s, d in modes)
        + " |"
    )
    print("|---|" + "---|" * len(modes))
    for name, _, t_cp, _, _ in rows:
        print(
            f"| {name} | "
            + " | ".join(
                f"{us(t_cp[md])} / {us(np.array([t_cp[md].mean()]))} / "
                f"{us(np.array([t_cp[md].max()]))}"
                for md in modes
            )
            + " |"
        )

    # What a planner calling `collide_robot` once per configuration waits for:
    # the call's wall time, the Python call and the lookup of the link samples
    # included (far configurations: where the query itself takes microseconds).
    walls = {}
    for model, side in variants(sides):
        w = []
        for q in far:
            t = time.perf_counter()
            cp.collide_robot(robot, q, cloud, self_collision=False, model=model, mesh_side=side)
            w.append(time.perf_counter() - t)
        walls[label(model, side)] = np.asarray(w)
    print(
        "\nOne `collide_robot` call's wall time, far configurations (median): "
        + ", ".join(f"{m} {us(w)}" for m, w in walls.items())
    )

    if args.motions:
        centres = near_q[: args.motions]
        motion_rows(robot, cloud, motion_ends(robot, centres, sigma, rng), sides)

    for side in sides:
        seconds = {k: many_seconds(k, args.many, args.seed, side) for k in (1, 2)}
        print(
            f"\n`collide_robot_many`, {side} links, {args.many} random configurations: "
            f"1 thread {seconds[1]:.2f} s, 2 threads {seconds[2]:.2f} s "
            f"(speed-up {seconds[1] / seconds[2]:.2f}x on 2 cores)"
        )

    answers = {
        f"cloudprox ({label(model, side)}{', decide-only' if decide else ''})": np.asarray(
            cp.collide_robot_many(
                robot,
                near_q,
                cloud,
                self_collision=False,
                model=model,
                mesh_side=side,
                decide_only=decide,
            ).states
        )
        for model, side in variants(sides)
        for decide in (False, True)
    }
    colliding = near_d <= 0.0
    for k, c in maps.items():
        answers[k] = np.where(map_booleans(c, near_q), "collision", "free")
    print(
        f"\nAgreement with the exact scene, {len(near_q)} configurations "
        f"({int(colliding.sum())} colliding), sigma {sigma * 1e3:.2f} mm:\n"
    )
    print(
        "| checker | decided accuracy | undecided | false collisions > 3 sigma "
        "| missed collisions < -3 sigma |\n|---|---|---|---|---|"
    )
    beyond, deep = near_d > 3 * sigma, near_d < -3 * sigma
    for name, st in answers.items():
        decided = st != "contact"  # cloudprox's undecided state
        acc = float(np.mean((st[decided] == "collision") == colliding[decided]))
        fp = int(np.sum(st[beyond] == "collision"))
        fn = int(np.sum(st[deep] == "free"))
        print(
            f"| {name} | {acc:.3f} | {1 - decided.mean():.1%} | "
            f"{fp}/{int(beyond.sum())} | {fn}/{int(deep.sum())} |"
        )
    # Missed deep collisions: is the surface they meet in the scan at all?
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    for model, side in variants(sides):
        states = answers[f"cloudprox ({label(model, side)})"]
        missed = np.flatnonzero(deep & (states == "free"))
        unseen = sum(
            1
            for i in missed
            if not np.any(
                np.isfinite(tree.query(exact.contacts(near_q[i]), distance_upper_bound=0.01)[0])
            )
        )
        also = ", ".join(f"{sum(answers[k][i] == 'free' for i in missed)} by the {k}" for k in maps)
        print(
            f"\ncloudprox ({label(model, side)})'s missed collisions deeper than 3 sigma: "
            f"{len(missed)}; of these, {unseen} meet the exact scene where no scan point lies "
            f"within 1 cm (a surface the camera does not see); missed too: {also}."
        )
        free = np.flatnonzero(beyond)
        occlusion_row(robot, cloud, (near_q, missed, free), model, side)
    log(f"({time.perf_counter() - t_start:.0f} s)")


if __name__ == "__main__":
    main()
