"""Both models of cloudprox on real meshes against exact ground truth.

Scanned and robot meshes that registry packages ship (fetched into the cache by
``tests/realfiles.py``, SHA-256 checked, never committed): the Stanford bunny
(the 99-face decimation in the ``stl_io`` crate), Spot (``meshx`` crate),
and the Franka Panda hand and link 1 collision meshes (``gym-ignition-models``
on PyPI). Each mesh is scaled to a 0.2 m bounding-box diagonal and sampled
area-weighted into 10 000 points; isotropic noise is ``level`` times the
diagonal. Poses of A: a random rotation and direction; the translation is
bisected to first contact (``cloudprox.exact_proximity`` on the meshes), then to
an exact distance uniform in [0, 10] sigma (or [10, 30] sigma for 10% of the
poses), or moved past first contact by [0, 6] sigma (the meshes are not convex,
so a penetration's depth is that travel, as in the real-scan experiment).
Labels are exact (``intersecting``). Two noise draws per pose.

``mesh-exact`` and ``mesh-sampled`` query A as its exact mesh against B's
noisy cloud (``cloudprox.collide_many(mesh, cloud, poses)``): the mesh's
surface as the separating surface (the default for a mesh side), or the
mesh sampled into a cloud (``mesh_side="sampled"``, the former default);
``mesh-exact-decide`` is ``mesh-exact`` with ``decide_only`` (no per-point
probabilities).

python-fcl (``pip install python-fcl``), when installed, answers the same
poses on the exact meshes in the same run: its ``distance()`` and ``collide()``
median times are the anchor of the speed column.

Usage: ``python3 benches/realmesh.py [--poses 100] [--levels 0.005,0.02] [--seed 0]
[--methods elements,points,nn-gap,collision-map,mesh-exact,mesh-exact-decide,mesh-sampled]
[--noise-scale 1] [--bounds]
[--save F.npz]`` (``--save``: every method's scores, states, seconds and the
exact signed distances per level, for a closer look at where the methods err
or flip; ``--noise-scale F``: the noise drawn, and its stated covariances
set, at ``F`` times the level's sigma, while the poses and the metrics stay
in the level's sigma, to see what the noise costs against what the sampling
does; ``--bounds``: per row, the near-contact AUC the same scores reach with
every pose beyond 1 and beyond 0.5 pair sigma of contact ranked perfectly).
``--residuals``: the elements' standardized residuals ``(g_true - gap) / std``
at facing pairs near contact against the exact meshes, by level, by the
probe's distance to its element's edge and by element size (mean 0 and
spread 1 when the gaps and their variances are right; bias and
over-confidence show as either off). ``--reliability``: per row, the
reliability table behind its ECE (ECE, Brier score, log-loss and the worst bin
holding 20 or more poses are columns of every row). ``--methods`` draws no
random numbers, so a subset reads the same as the full run for the methods it
keeps. Each pair's sampling spacing (in pair
sigma) is printed with its progress line.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benches.near_limits import ranked_beyond
from tests.realfiles import real_file

import cloudprox as cp
from cloudprox.reproduce import methods as m
from cloudprox.reproduce.metrics import auc_near, calibration, compute_metrics

PAIRS = (
    ("stl_panda_hand", "stl_binary_bunny"),
    ("stl_panda_link1", "stl_binary_bunny"),
    ("stl_panda_hand", "obj_spot"),
)
DIAGONAL = 0.2
POINTS = 10_000


def load(name: str) -> cp.Mesh:
    """Return the mesh ``name`` centred and scaled to the bounding-box diagonal."""
    mesh = cp.io.read_mesh(real_file(name))
    lo, hi = (np.asarray(x) for x in mesh.bounds())
    s = DIAGONAL / float(np.linalg.norm(hi - lo))
    return cp.Mesh((np.asarray(mesh.vertices) - 0.5 * (lo + hi)) * s, mesh.faces)


def fcl_times(a: cp.Mesh, b: cp.Mesh, poses: np.ndarray) -> tuple[float, float] | None:
    """Median seconds of python-fcl's ``distance()`` and ``collide()`` on the exact meshes."""
    try:
        import fcl  # type: ignore[import-not-found]
    except ImportError:
        return None

    def model(mesh: cp.Mesh) -> object:
        bvh = fcl.BVHModel()
        v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        bvh.beginModel(len(v), len(f))
        bvh.addSubModel(v, f)
        bvh.endModel()
        return bvh

    oa = fcl.CollisionObject(model(a), fcl.Transform())
    ob = fcl.CollisionObject(model(b), fcl.Transform())
    dist, coll = [], []
    for pose in poses:
        oa.setTransform(fcl.Transform(pose[:3, :3], pose[:3, 3]))
        t0 = time.perf_counter()
        fcl.distance(oa, ob, fcl.DistanceRequest(), fcl.DistanceResult())
        t1 = time.perf_counter()
        fcl.collide(oa, ob, fcl.CollisionRequest(), fcl.CollisionResult())
        t2 = time.perf_counter()
        dist.append(t1 - t0)
        coll.append(t2 - t1)
    return float(np.median(dist)), float(np.median(coll))


def residuals(
    ma: cp.Mesh, mb: cp.Mesh, draw: m.Draw, q: np.ndarray, dist: np.ndarray, reach: float
) -> dict[str, np.ndarray]:
    """Return the standardized residuals of the elements' facing pairs near contact.

    For every pose within ``reach`` of contact and every pair whose exact and
    estimated gaps are both within ``reach``, each facing pair's probe is
    moved onto its own exact mesh (its closest point there) and the exact gap
    is that point's signed distance to the other exact mesh; the residual is
    ``(g_true - gap) / std``, standard normal if the gaps and their variances
    are right. Also returned: whether the probe lies beside the other element,
    the probe's distance to its own element's edge and its element's size
    (both in the element's sampling spacings; 0 for a single point).
    """
    a = cp.PointCloud(draw.piano_points, cov=draw.piano_sensor_cov)
    b = cp.PointCloud(draw.room_points, cov=draw.room_sensor_cov)
    da, db = cp.MeshDistance(ma), cp.MeshDistance(mb)
    out: dict[str, list[np.ndarray]] = {"z": [], "beside": [], "from_a": [], "edge": [], "size": []}
    for pose in q[np.abs(dist) <= reach]:
        f = cp._native.facing_pairs(a, b, pose_a=pose)
        if len(f["gap"]) == 0:
            continue
        probe, from_a = np.asarray(f["probe"]), np.asarray(f["from_a"])
        rot, t = pose[:3, :3], pose[:3, 3]
        g_true = np.empty(len(probe))
        # A's probes: closest point on A (its own frame), back to the world, to B.
        if from_a.any():
            _, on_a, _ = da.closest((probe[from_a] - t) @ rot)
            g_true[from_a] = db.signed_distance(np.asarray(on_a) @ rot.T + t)
        if (~from_a).any():
            _, on_b, _ = db.closest(probe[~from_a])
            g_true[~from_a] = da.signed_distance((np.asarray(on_b) - t) @ rot)
        # Pairs at the contact: both the exact and the estimated gap within reach.
        at = (np.abs(g_true) <= reach) & (np.abs(np.asarray(f["gap"])) <= reach)
        out["z"].append(((g_true - np.asarray(f["gap"])) / np.asarray(f["std"]))[at])
        out["beside"].append(np.asarray(f["beside"])[at])
        out["from_a"].append(from_a[at])
        out["edge"].append(np.asarray(f["probe_edge"])[at])
        out["size"].append(np.asarray(f["size"])[at])
    return {k: np.concatenate(v) if v else np.zeros(0) for k, v in out.items()}


def poses(
    a: cp.ExactShape, b: cp.ExactShape, n: int, sigma: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Return ``n`` poses of ``a`` and their exact signed distances to ``b``."""
    out, dist = [], []
    while len(out) < n:
        target = sigma * (rng.uniform(-6.0, 10.0) if rng.random() < 0.9 else rng.uniform(10, 30))
        pose = cp.pose.random_rotations(1, seed=int(rng.integers(2**63)))[0]
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)

        def at(t: float, pose: np.ndarray = pose, d: np.ndarray = d) -> cp.Proximity:
            pose[:3, 3] = t * d
            return cp.exact_proximity(a, b, pose)

        # First contact along the direction (the objects overlap at t = 0).
        lo, hi = 0.0, 2.0 * DIAGONAL
        if at(hi).intersecting or not at(lo).intersecting:
            continue
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if at(mid).intersecting else (lo, mid)
        contact = hi
        if target >= 0.0:
            # Bisect the exact distance on the free side of first contact.
            lo, hi = contact, 2.0 * DIAGONAL
            if at(hi).distance < target:
                continue
            for _ in range(40):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if at(mid).distance < target else (lo, mid)
            r = at(hi)
            if r.intersecting:
                continue
            sd = float(r.distance)
        else:
            # Penetration: travel past first contact (the meshes are not convex,
            # so the depth is the travel, as in the real-scan experiment).
            if not at(contact + target).intersecting:
                continue
            sd = target
        if abs(sd - target) > sigma:
            continue
        out.append(pose.copy())
        dist.append(sd)
    return np.array(out), np.array(dist)


#: The methods compared (``--methods`` names) and their names in the table.
METHODS = {
    "elements": "elements (default)",
    "elements-x3": "elements, 3 segmentations",
    "points": "points (the paper's)",
    "nn-gap": "nn-gap",
    "collision-map": "collision map",
    "mesh-exact": "A as its exact mesh (exact side)",
    "mesh-exact-decide": "A as its exact mesh (exact side), decide_only",
    "mesh-sampled": "A as its exact mesh, sampled",
}


def method_name(method: str) -> str | None:
    """Return the table's name of ``method``, None if unknown.

    ``method`` is a key of :data:`METHODS` or ``elements[-xK][-cC]``: the elements
    averaged over ``K`` segmentations (1 to 16), with ``C`` spacings of context
    (``near_context``, at least 0.5; see :func:`cloudprox.reproduce.methods.model_options`).
    """
    if method in METHODS:
        return METHODS[method]
    try:
        options = m.model_options(method)
    except ValueError:
        return None
    k, context = options.segmentations, options.near_context
    if options.model != "elements":
        return None
    name = "elements" if k == 1 else f"elements, {k} segmentations"
    return name if context is None else f"{name}, context {context:g}"


def mesh_answer(mesh: cp.Mesh, draw: m.Draw, q: np.ndarray, side: str) -> m.MethodAnswer:
    """Return the answers with side A as its exact ``mesh`` against B's noisy cloud.

    ``side`` is ``"exact"`` (the mesh's surface as the separating surface),
    ``"exact-decide"`` (the same, ``decide_only``: ``P`` and the state without
    the per-point probabilities) or ``"sampled"`` (the mesh sampled into a
    cloud and the two clouds collided). Only B's noise is drawn: the labels
    are the exact meshes' as for every row.
    """
    _, room = draw.clouds()
    decide = side.endswith("-decide")
    side = side.removesuffix("-decide")
    results = cp.collide_many(mesh, room, q, mesh_side=side, decide_only=decide)
    return m.MethodAnswer(
        np.array([r.probability for r in results]),
        np.array([r.state for r in results]),
        np.array([r.stats.time_seconds for r in results]),
    )


def method_answer(
    method: str, draw: m.Draw, q: np.ndarray, mesh_a: cp.Mesh | None = None
) -> m.MethodAnswer:
    """Return ``method``'s answers (a key of :data:`METHODS`) for one draw at the poses ``q``.

    ``mesh_a`` is A's exact mesh, which the ``mesh-*`` methods query instead of
    A's cloud.
    """
    if method.startswith("mesh-"):
        if mesh_a is None:
            raise ValueError(f"{method} needs A's mesh")
        return mesh_answer(mesh_a, draw, q, method.removeprefix("mesh-"))
    if method.startswith("elements"):
        return m.cloudprox_answer(draw, q, "quadric", "max", method)
    if method == "points":
        return m.cloudprox_answer(draw, q, "quadric", "max")
    if method == "nn-gap":
        return m.nn_gap_answer(draw, q)
    if method == "collision-map":
        return m.collision_map_answer(draw, q, m.sampling_spacing(draw.room_points))
    raise ValueError(f"unknown method {method!r}; known: {', '.join(METHODS)}, elements[-xK][-cC]")


def main() -> None:
    """Run every pair at every level and print one table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--poses", type=int, default=100)
    ap.add_argument("--levels", default="0.005,0.02")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--save", type=Path, default=None, help="write the per-pose arrays (.npz)")
    ap.add_argument(
        "--methods",
        default=",".join(METHODS),
        help=f"comma-separated, among {', '.join(METHODS)} or elements[-xK][-cC] (the "
        "elements averaged over K segmentations, with C spacings of context) "
        "(default: all listed)",
    )
    ap.add_argument(
        "--bounds",
        action="store_true",
        help="also print each row's AUC near with every pose beyond 1 (0.5) pair sigma "
        "of contact ranked perfectly",
    )
    ap.add_argument(
        "--reliability",
        action="store_true",
        help="also print each row's reliability table (ten bins of P: poses, mean P, "
        "share that truly collides)",
    )
    ap.add_argument(
        "--residuals",
        action="store_true",
        help="also print the elements' standardized residuals (g_true - gap) / std at "
        "facing pairs, poses within 3 pair sigma of contact, first draw",
    )
    ap.add_argument(
        "--noise-scale",
        type=float,
        default=1.0,
        help="draw the noise at this multiple of the level's sigma (default 1)",
    )
    args = ap.parse_args()
    methods = list(dict.fromkeys(x.strip() for x in args.methods.split(",") if x.strip()))
    if not methods:
        ap.error("--methods is empty")
    for x in methods:
        if method_name(x) is None:
            try:
                m.model_options(x)  # says what is wrong with an elements name
            except ValueError as e:
                ap.error(str(e))
            ap.error(f"unknown method {x!r}; known: {', '.join(METHODS)}, elements[-xK][-cC]")
    names = [method_name(x) for x in methods]
    same = sorted({n for n in names if names.count(n) > 1 and n is not None})
    if same:
        ap.error(f"--methods names the same method twice: {same}")
    if not (np.isfinite(args.noise_scale) and args.noise_scale > 0.0):
        ap.error(f"--noise-scale must be finite and > 0, got {args.noise_scale}")
    if args.poses < 1:
        ap.error(f"--poses must be >= 1, got {args.poses}")
    rng = np.random.default_rng(args.seed)
    rows: dict[tuple[float, str], list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]] = {}
    fcl_rows: dict[float, list[tuple[float, float]]] = {}
    sigmas: dict[float, float] = {}
    resid: dict[float, dict[str, list[np.ndarray]]] = {}
    for level in (float(x) for x in args.levels.split(",")):
        sigma = level * DIAGONAL
        sigmas[level] = sigma
        pair_sigma = np.sqrt(2.0) * sigma
        for na, nb in PAIRS:
            ma, mb = load(na), load(nb)
            q, dist = poses(cp.ExactShape([ma]), cp.ExactShape([mb]), args.poses, pair_sigma, rng)
            pa, _, _ = ma.sample(POINTS, seed=1)
            pb, _, _ = mb.sample(POINTS, seed=2)
            drawn = args.noise_scale * sigma
            cov = np.broadcast_to(drawn**2 * np.eye(3), (POINTS, 3, 3)).copy()
            draws = [
                m.Draw(
                    np.asarray(pa) + rng.normal(scale=drawn, size=(POINTS, 3)),
                    cov,
                    np.asarray(pb) + rng.normal(scale=drawn, size=(POINTS, 3)),
                    cov,
                )
                for _ in range(2)
            ]
            answers = {method_name(k): [method_answer(k, d, q, ma) for d in draws] for k in methods}
            for name, ans in answers.items():
                rows.setdefault((level, name), []).append(
                    (
                        np.stack([x.score for x in ans]),
                        np.stack([x.state for x in ans]),
                        np.stack([x.seconds for x in ans]),
                        dist,
                    )
                )
            if args.residuals:
                res = residuals(ma, mb, draws[0], q, dist, 3.0 * pair_sigma)
                for k, v in res.items():
                    resid.setdefault(level, {}).setdefault(k, []).append(v)
            times = fcl_times(ma, mb, q)
            if times is not None:
                fcl_rows.setdefault(level, []).append(times)
            spacing = m.sampling_spacing(np.concatenate([np.asarray(pa), np.asarray(pb)]))
            print(
                f"{level:.1%} {na} vs {nb}: {len(q)} poses, sampling spacing "
                f"{spacing / pair_sigma:.2f} pair sigma",
                file=sys.stderr,
                flush=True,
            )
    if args.noise_scale != 1.0:
        print(
            f"noise drawn at {args.noise_scale:g} x the level's sigma; "
            "poses and metrics in the level's pair sigma\n"
        )
    print(
        "| level | method | ECE | Brier | log-loss | worst bin | AUC near | decided acc. "
        "| undecided | hard flips | FP > 3σ | FN < -3σ | ms |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )
    saved: dict[str, np.ndarray] = {}
    bounds: list[str] = []
    reliability: list[str] = []
    for (level, name), parts in rows.items():
        sc = np.concatenate([p[0] for p in parts], axis=1)
        st = np.concatenate([p[1] for p in parts], axis=1)
        se = np.concatenate([p[2] for p in parts], axis=1)
        d = np.concatenate([p[3] for p in parts])
        key = f"{level:g}/{name}"
        saved.update(
            {
                f"{key}/score": sc,
                f"{key}/state": st.astype(str),
                f"{key}/seconds": se,
                f"{key}/distance": d,
                f"{key}/sigma": np.array(np.sqrt(2.0) * sigmas[level]),
                f"{key}/noise_scale": np.array(args.noise_scale),
            }
        )
        mt = compute_metrics(sc, st, se, d, np.sqrt(2.0) * sigmas[level])
        cal = calibration(np.clip(sc, 0.0, 1.0), np.broadcast_to(d <= 0.0, sc.shape))
        if args.reliability:
            reliability.append(f"{level:.1%} {name}: P bin | poses | mean P | share colliding")
            reliability += [
                f"  [{lo:.1f}, {hi:.1f}) | {n} | {p:.3f} | {f:.3f}" for lo, hi, n, p, f in cal.table
            ]
        print(
            f"| {level:.1%} | {name} | {cal.ece:.3f} | {cal.brier:.3f} | {cal.log_loss:.3f} | "
            f"{cal.worst_bin():.3f} | {mt.auc_near:.3f} | {mt.decided_accuracy:.3f} | "
            f"{mt.undecided:.1%} | {mt.hard_flip:.1%} | {mt.false_positive_3s:.1%} | "
            f"{mt.false_negative_3s:.1%} | {mt.median_ms:.2f} |"
        )
        if args.bounds:
            ps = np.sqrt(2.0) * sigmas[level]
            b1, b05 = (auc_near(ranked_beyond(sc, d, ps, w), d, ps) for w in (1.0, 0.5))
            bounds.append(
                f"{level:.1%} {name}: AUC near {mt.auc_near:.3f}; poses beyond 1 pair sigma "
                f"ranked perfectly {b1:.3f}, beyond 0.5 {b05:.3f}"
            )
    for level, times in fcl_rows.items():
        d, c = np.median([t[0] for t in times]), np.median([t[1] for t in times])
        print(
            f"| {level:.1%} | python-fcl on the exact meshes: distance() {1e3 * d:.3f} ms, "
            f"collide() {1e3 * c:.3f} ms (medians of the pairs' medians) | | | | | | | |"
        )
    if resid:
        print(
            "\n| level | facing pairs | residual mean | residual sd | over: mean, sd "
            "| beside: mean, sd |\n|---|---|---|---|---|---|"
        )
    for level, parts in resid.items():
        z, bs = (np.concatenate(parts[k]) for k in ("z", "beside"))
        bs = bs.astype(bool)
        cell = lambda x: f"{np.mean(x):+.2f}, {np.std(x):.2f}" if len(x) else "-"  # noqa: E731
        print(
            f"| {level:.1%} | {len(z)} | {np.mean(z):+.2f} | {np.std(z):.2f} | "
            f"{cell(z[~bs])} | {cell(z[bs])} |"
        )
    if resid:
        print(
            "\n| level | residual mean, sd (pairs) by the probe's distance to its element's edge "
            "(spacings): single points | < 0.5 | 0.5-1 | 1-2 | >= 2 | by element size "
            "(spacings): < 3 | 3-10 | >= 10 |\n|---|---|---|---|---|---|---|---|---|"
        )
    for level, parts in resid.items():
        z, edge, size = (np.concatenate(parts[k]) for k in ("z", "edge", "size"))
        point = size <= 0.0

        def cell(mask: np.ndarray, z: np.ndarray = z) -> str:
            x = z[mask]
            return f"{np.mean(x):+.2f}, {np.std(x):.2f} ({len(x)})" if len(x) else "-"

        by_edge = [cell(point)] + [
            cell(~point & (edge >= lo) & (edge < hi))
            for lo, hi in ((0.0, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, np.inf))
        ]
        by_size = [
            cell(~point & (size >= lo) & (size < hi))
            for lo, hi in ((0.0, 3.0), (3.0, 10.0), (10.0, np.inf))
        ]
        print(f"| {level:.1%} | " + " | ".join(by_edge + by_size) + " |")
    if reliability:
        print()
        print("\n".join(reliability))
    if bounds:
        print()
        print("\n".join(bounds))
    if args.save is not None:
        np.savez_compressed(args.save, **saved)
        print(f"per-pose arrays: {args.save}", file=sys.stderr)


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"\n({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
