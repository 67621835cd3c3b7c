"""P against the noise model on analytic shapes: parallel plates and spheres (issue 49).

The default model's ``P`` is meant to be a probability: among the poses that
get ``P`` near ``p``, a share ``p`` truly collides. On analytic shapes the truth
is known exactly and the noise is the stated one, so the only question is
whether ``P`` matches the frequency the noise model implies.

**Parallel plates.** Two slabs, 0.2 m squares: each a noisy ``21 x 21`` grid
(1 cm pitch) on the face that meets the other slab and another on its far face
20 sigma (2 cm) behind it (the far face says on which side the slab's body is; without it
two parallel patches have no inside and never cross). B's facing face is ``g``
above A's: ``g < 0`` is a collision.

*The standard error of the estimated gap* (the prior's unit). Isotropic noise
of standard deviation ``sigma`` moves a point of a flat face by ``sigma``
along the face's normal (the lateral components move it within the face and
change nothing). The face's height is the mean of its ``n`` points along the
normal, standard deviation ``sigma / sqrt(n)`` (on a centred grid the
least-squares plane at the centre is that mean: its slopes are uncorrelated
with it). The gap is the difference of two such independent means:

    sd(g_hat) = sigma * sqrt(1/n + 1/n) = sigma / sqrt(n_eff),  n_eff = n / 2.

With ``n = 441`` and ``sigma = 1 mm`` that is 0.067 mm;
:func:`test_the_gap_standard_error_is_that_of_two_face_means` checks it
numerically. A calibrated ``P`` reads about ``Phi(-g_hat / se)``: at a true gap
``g`` its mean is ``E Phi(-(g + se Z) / se) = Phi(-g / (sqrt(2) se))`` and at
``g = 0`` it is uniform on [0, 1] (mean 1/2, variance 1/12).

**Spheres.** Two spheres of radius 0.1 m, ``sigma = 1 mm``, points drawn
uniformly by area (fresh positions and noise in every draw). The contact is
seen flat to within the noise over the cap where the sphere stays within
``sigma`` of its tangent plane: area ``2 pi R sigma``, a share ``sigma / (2 R)``
of the ``N`` points, ``n_cap = N sigma / (2 R)`` (10 at 2000 points, 50 at
10 000), so the prior's unit is ``sigma * sqrt(2 / n_cap)`` (0.45 mm, 0.20 mm).
A quadric element that uses more of the sphere may read the gap more
precisely; calibration does not need the sharpest ``P``, only an honest one.

**Priors and tolerances.** True gaps are drawn uniformly within +-3 units. On
a bounded prior even the ideal ``Phi(-g_hat / se)`` is slightly off in the
outer bins (:data:`PRIOR_BIAS`, its ECE on an unlimited number of draws: about
0.0025). The ECE tolerance is that bias plus the ECE that ``P`` itself would
show by chance if it *were* calibrated: labels drawn as ``Bernoulli(P)`` for
the ``P`` values measured, 2000 times, the 99.9th percentile (the binomial
noise of the draws' number in each bin). Other tolerances are 3.29 standard
errors (two-sided 0.1 %) of the quantity tested, from the number of draws.
Nothing is tuned to what the library returns; tests that fail today are marked
``xfail(strict=True)`` with the number measured, so they flip when fixed.

**Standardized residuals.** At each facing pair of the elements model
(``cloudprox._native.facing_pairs``), ``(g_true - gap) / std`` should be
standard normal, ``g_true`` the exact gap at the pair: the pair's probe moved
to the closest point of its own exact surface and that point's signed
distance to the other exact solid. The pairs of one draw share elements and
are correlated, so the residuals are pooled over the draws and the
tolerances count draws, not pairs (as if each draw's pairs were one).

``benches/analytic.py`` runs the same scenes larger, at more noise levels and
with boxes, and prints the calibration table per scene.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pytest
from scipy.stats import chi2, norm

import cloudprox as cp
from cloudprox.reproduce.metrics import RELIABILITY_BINS, calibration

#: Two-sided 0.1 % normal quantile: every tolerance is this many standard errors.
Z_TOL = float(norm.ppf(1.0 - 0.0005))
#: One-sided level of the ECE tolerance (the null's upper quantile).
ECE_ALPHA = 1e-3
#: Half-width of the gap priors, in units of the scene's gap standard error.
PRIOR = 3.0

FloatArray = np.ndarray


# --------------------------------------------------------------------------
# Exact shapes


@dataclass(frozen=True)
class Rect:
    """A rectangle in 3D: centre, two in-plane unit axes and their half lengths."""

    centre: FloatArray
    e1: FloatArray
    e2: FloatArray
    h1: float
    h2: float

    def closest(self, p: FloatArray) -> FloatArray:
        """Closest points of the rectangle to ``p`` (n, 3)."""
        d = p - self.centre
        s1 = np.clip(d @ self.e1, -self.h1, self.h1)
        s2 = np.clip(d @ self.e2, -self.h2, self.h2)
        return self.centre + s1[:, None] * self.e1 + s2[:, None] * self.e2


def box_signed_distance(p: FloatArray, centre: FloatArray, half: FloatArray) -> FloatArray:
    """Exact signed distance of ``p`` to an axis-aligned box (negative inside)."""
    q = np.abs(p - centre) - half
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    return outside + np.minimum(q.max(axis=1), 0.0)


def box_faces(
    centre: FloatArray, half: FloatArray, axes: tuple[int, ...] = (0, 1, 2)
) -> list[Rect]:
    """The faces of an axis-aligned box normal to ``axes`` (both signs)."""
    eye = np.eye(3)
    out = []
    for k in axes:
        i, j = (a for a in range(3) if a != k)
        for s in (-1.0, 1.0):
            c = np.asarray(centre, dtype=float).copy()
            c[k] += s * half[k]
            out.append(Rect(c, eye[i], eye[j], float(half[i]), float(half[j])))
    return out


def _facing_gap(
    probe: FloatArray,
    from_a: FloatArray,
    g: float,
    faces_a: list[Rect],
    faces_b: list[Rect],
    facing: tuple[int, int],
) -> FloatArray:
    """Exact gaps at facing pairs of two boxes (or slabs) whose faces ``facing`` meet.

    A probe's closest point on its own sampled faces: on the face that meets the
    other box (``faces_a[facing[0]]``, ``faces_b[facing[1]]``), the gap is the
    two meeting faces' distance along their common normal, ``g``, also at and
    past their edges (which line up), and where they overlap (``g < 0``: the
    signed distance to the other box would be to its side there); elsewhere
    it is the signed distance of that point to the other box.
    """
    out = np.empty(len(probe))
    for mine, own, other, meeting in (
        (from_a, faces_a, faces_b, facing[0]),
        (~from_a, faces_b, faces_a, facing[1]),
    ):
        if not mine.any():
            continue
        p = probe[mine]
        cand = np.stack([r.closest(p) for r in own])
        best = np.argmin(np.linalg.norm(cand - p[None], axis=2), axis=0)
        on = cand[best, np.arange(len(p))]
        lo = np.min([r.centre - np.abs(r.h1 * r.e1) - np.abs(r.h2 * r.e2) for r in other], axis=0)
        hi = np.max([r.centre + np.abs(r.h1 * r.e1) + np.abs(r.h2 * r.e2) for r in other], axis=0)
        d = box_signed_distance(on, 0.5 * (lo + hi), 0.5 * (hi - lo))
        out[mine] = np.where(best == meeting, g, d)
    return out


# --------------------------------------------------------------------------
# Scenes


@dataclass(frozen=True)
class Scene:
    """An analytic scene: two noisy clouds, B posed at a true gap ``g``.

    ``sample(rng)`` returns A's and B's noisy points, each in its own frame.
    One pair of clouds serves ``contacts`` draws that meet at disjoint parts
    of their surfaces (independent readings: no point or element is near two
    of them): ``pose_b(g, k, rot)`` puts B at the true gap ``g`` in contact
    ``k`` (``rot``: a random rotation drawn per pair of clouds, for scenes
    whose contacts can be anywhere). ``exact_gap(probe, from_a, g, pose_b)``
    is the exact gap at facing pairs (world frame, see the module's docs);
    ``sigma_gap`` is the noise model's standard error of the estimated gap.
    """

    name: str
    sigma: float
    sigma_gap: float
    sample: Callable[[np.random.Generator], tuple[FloatArray, FloatArray]]
    pose_b: Callable[[float, int, FloatArray], FloatArray]
    exact_gap: Callable[[FloatArray, FloatArray, float, FloatArray], FloatArray]
    points: int
    contacts: int = 1


def _translation(axis: int, t: float) -> FloatArray:
    pose = np.eye(4)
    pose[axis, 3] = t
    return pose


def plates(sigma: float = 1e-3, k: int = 21, side: float = 0.2, back: float | None = None) -> Scene:
    """Two slabs whose facing ``k x k`` grids (``side`` square) are ``g`` apart along z.

    Each slab's far face is ``back`` behind its facing one (default ``20 sigma``,
    2 cm at 1 mm: far beyond the noise, so the two faces never mix).
    """
    back = 20.0 * sigma if back is None else back
    h = side / (k - 1)
    u = np.arange(k) * h - side / 2.0
    x, y = (c.ravel() for c in np.meshgrid(u, u))
    face = np.stack([x, y, np.zeros(k * k)], axis=1)
    # A's body below its face (z in [-back, 0]), B's above its own (in B's frame).
    lift = np.array([0.0, 0.0, back])
    base_a = np.concatenate([face, face - lift])
    base_b = np.concatenate([face, face + lift])
    half = np.array([side / 2.0, side / 2.0, back / 2.0])

    def sample(rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
        return (
            base_a + rng.normal(scale=sigma, size=base_a.shape),
            base_b + rng.normal(scale=sigma, size=base_b.shape),
        )

    def exact_gap(probe: FloatArray, from_a: FloatArray, g: float, _: FloatArray) -> FloatArray:
        return _facing_gap(
            probe,
            from_a,
            g,
            box_faces(np.array([0.0, 0.0, -back / 2.0]), half, (2,)),
            box_faces(np.array([0.0, 0.0, g + back / 2.0]), half, (2,)),
            (1, 0),
        )

    return Scene(
        f"plates {k}x{k}, sigma {sigma * 1e3:g} mm",
        sigma,
        sigma * np.sqrt(2.0 / (k * k)),
        sample,
        lambda g, _k, _r: _translation(2, g),
        exact_gap,
        2 * k * k,
    )


#: Directions of the four contacts one pair of spheres serves: a tetrahedron's
#: vertices, 109 degrees apart (a contact's cap spans about 8 degrees at 1 mm).
TETRAHEDRON = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]) / np.sqrt(3.0)


def spheres(n: int, sigma: float = 1e-3, radius: float = 0.1) -> Scene:
    """Two spheres of ``radius``, ``n`` area-uniform points each, ``g`` apart.

    One pair of clouds meets in four contacts (B's centre along the rotated
    :data:`TETRAHEDRON`'s directions), each seen by its own caps of both spheres.
    """
    n_cap = n * sigma / (2.0 * radius)

    def one(rng: np.random.Generator) -> FloatArray:
        v = rng.normal(size=(n, 3))
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        return radius * v + rng.normal(scale=sigma, size=(n, 3))

    def pose_b(g: float, k: int, rot: FloatArray) -> FloatArray:
        pose = np.eye(4)
        pose[:3, 3] = (2.0 * radius + g) * (rot @ TETRAHEDRON[k])
        return pose

    def exact_gap(probe: FloatArray, from_a: FloatArray, g: float, pose: FloatArray) -> FloatArray:
        cb = pose[:3, 3]
        own = np.where(from_a[:, None], 0.0, cb)
        other = np.where(from_a[:, None], cb, 0.0)
        d = probe - own
        on = own + radius * d / np.linalg.norm(d, axis=1, keepdims=True)
        return np.linalg.norm(on - other, axis=1) - radius

    return Scene(
        f"spheres {n} points, sigma {sigma * 1e3:g} mm",
        sigma,
        sigma * np.sqrt(2.0 / n_cap),
        lambda rng: (one(rng), one(rng)),
        pose_b,
        exact_gap,
        2 * n,
        contacts=len(TETRAHEDRON),
    )


def boxes(sigma: float = 1e-3, half: float = 0.1, spacing: float = 0.01) -> Scene:
    """Two cubes of side ``2 half`` sampled on a grid, face to face ``g`` apart along x."""
    base = np.asarray(cp.synthetic.sample_box_surface([half] * 3, spacing))
    n_face = int(np.sum(np.isclose(base[:, 0], half)))
    h3 = np.full(3, half)

    def sample(rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
        return (
            base + rng.normal(scale=sigma, size=base.shape),
            base + rng.normal(scale=sigma, size=base.shape),
        )

    def exact_gap(probe: FloatArray, from_a: FloatArray, g: float, _: FloatArray) -> FloatArray:
        ca, cb = np.zeros(3), np.array([2.0 * half + g, 0.0, 0.0])
        return _facing_gap(probe, from_a, g, box_faces(ca, h3), box_faces(cb, h3), (1, 0))

    return Scene(
        f"boxes {len(base)} points, sigma {sigma * 1e3:g} mm",
        sigma,
        sigma * np.sqrt(2.0 / n_face),
        sample,
        lambda g, _k, _r: _translation(0, 2.0 * half + g),
        exact_gap,
        2 * len(base),
    )


# --------------------------------------------------------------------------
# Running a scene


@dataclass
class Draws:
    """What the library answered over the noise draws of a scene (one row per draw)."""

    gap: FloatArray  # true gaps (m)
    p: FloatArray  # P per draw
    seconds: FloatArray  # collide's time per draw, the clouds prepared
    build_seconds: FloatArray  # per pair of clouds: building both clouds' elements
    residuals: list[FloatArray] = field(default_factory=list)  # (g_true - gap) / std per pair
    beside: list[FloatArray] = field(default_factory=list)  # probe beside the other element
    pair_std: list[FloatArray] = field(default_factory=list)  # each pair's std (m)


def run_draws(
    scene: Scene,
    gaps: FloatArray,
    seed: int,
    residuals: int = 0,
    request: cp.CollisionRequest | None = None,
) -> Draws:
    """Answer a noise draw of ``scene`` at each true gap; residuals for the first ``residuals``.

    Each pair of clouds serves ``scene.contacts`` consecutive draws.
    """
    rng = np.random.default_rng(seed)
    gaps = np.asarray(gaps, dtype=float)
    pairs = -(-len(gaps) // scene.contacts)
    out = Draws(gaps, np.empty(len(gaps)), np.empty(len(gaps)), np.empty(pairs))
    for i, g in enumerate(gaps):
        k = i % scene.contacts
        if k == 0:
            pa, pb = scene.sample(rng)
            a = cp.PointCloud(pa, sigma=scene.sigma)
            b = cp.PointCloud(pb, sigma=scene.sigma)
            rot = cp.pose.random_rotations(1, seed=int(rng.integers(2**63)))[0, :3, :3]
            t0 = time.perf_counter()
            a.prepare(request)
            b.prepare(request)
            out.build_seconds[i // scene.contacts] = time.perf_counter() - t0
        pose = scene.pose_b(float(g), k, rot)
        t0 = time.perf_counter()
        out.p[i] = cp.collide(a, b, pose_b=pose, request=request).probability
        out.seconds[i] = time.perf_counter() - t0
        if i < residuals:
            f = cp._native.facing_pairs(a, b, pose_b=pose, request=request)
            reach = np.asarray(f["within_reach"], dtype=bool)
            probe = np.asarray(f["probe"]).reshape(-1, 3)[reach]
            from_a = np.asarray(f["from_a"], dtype=bool)[reach]
            gap, std = np.asarray(f["gap"])[reach], np.asarray(f["std"])[reach]
            g_true = scene.exact_gap(probe, from_a, float(g), pose) if len(gap) else gap
            out.residuals.append((g_true - gap) / std)
            out.beside.append(np.asarray(f["beside"], dtype=bool)[reach])
            out.pair_std.append(std)
    return out


def prior_gaps(scene: Scene, count: int, seed: int) -> FloatArray:
    """``count`` true gaps uniform within +-:data:`PRIOR` units of ``scene.sigma_gap``."""
    return np.random.default_rng(seed).uniform(-PRIOR, PRIOR, count) * scene.sigma_gap


def prior_bias(draws: int = 400_000, seed: int = 1) -> float:
    """ECE of the ideal ``Phi(-g_hat / se)`` on the bounded prior, on many draws (about 0.0025)."""
    rng = np.random.default_rng(seed)
    g = rng.uniform(-PRIOR, PRIOR, draws)
    p = norm.cdf(-(g + rng.normal(size=draws)))
    return calibration(p, g < 0.0).ece


#: The bounded prior's own miscalibration of the ideal ``P`` (see the module's docs).
PRIOR_BIAS = prior_bias()


def ece_null(p: FloatArray, reps: int = 2000, seed: int = 2) -> FloatArray:
    """ECEs that a calibrated forecast with these ``P`` values shows by chance.

    Labels are drawn as ``Bernoulli(P)`` ``reps`` times; the bins are those of
    :func:`cloudprox.reproduce.metrics.calibration` (ten of equal width).
    """
    p = np.asarray(p, dtype=float)
    rng = np.random.default_rng(seed)
    y = rng.random((reps, p.size)) < p
    edges = np.linspace(0.0, 1.0, RELIABILITY_BINS + 1)
    which = np.clip(np.digitize(p, edges[1:-1]), 0, RELIABILITY_BINS - 1)
    ece = np.zeros(reps)
    for k in range(RELIABILITY_BINS):
        inside = which == k
        if inside.any():
            ece += inside.sum() / p.size * np.abs(p[inside].mean() - y[:, inside].mean(axis=1))
    return ece


def ece_tolerance(p: FloatArray) -> float:
    """The ECE a calibrated ``P`` stays below (:data:`ECE_ALPHA`), plus :data:`PRIOR_BIAS`."""
    return float(np.quantile(ece_null(p), 1.0 - ECE_ALPHA)) + PRIOR_BIAS


def near_half(p: FloatArray, label: FloatArray, lo: float = 0.3, hi: float = 0.7) -> tuple:
    """Draws with ``P`` in [lo, hi): count, mean P, observed frequency, tolerance."""
    inside = (p >= lo) & (p < hi)
    n = int(inside.sum())
    if n == 0:
        return 0, float("nan"), float("nan"), float("nan")
    mp, freq = float(p[inside].mean()), float(label[inside].mean())
    tol = Z_TOL * float(np.sqrt(np.mean(p[inside] * (1.0 - p[inside])) / n)) + PRIOR_BIAS
    return n, mp, freq, tol


def residual_summary(res: list[FloatArray]) -> tuple[int, int, float, float]:
    """Pooled residuals: draws with pairs, pairs, mean and standard deviation."""
    kept = [r for r in res if len(r)]
    z = np.concatenate(kept) if kept else np.zeros(0)
    return len(kept), len(z), float(np.mean(z)), float(np.std(z))


# --------------------------------------------------------------------------
# The standard error of the gap, numerically


def test_the_gap_standard_error_is_that_of_two_face_means() -> None:
    """The facing faces' fitted planes at the centre: sd sigma * sqrt(2 / n) (module docs)."""
    scene = plates()
    rng = np.random.default_rng(490)
    draws, k = 4000, 21
    face = slice(0, k * k)
    est = np.empty(draws)
    for i in range(draws):
        pa, pb = scene.sample(rng)
        # Least-squares planes z = c0 + c1 x + c2 y of the two facing faces, at the centre.
        design = np.c_[np.ones(k * k), pa[face, :2]]
        ca = np.linalg.lstsq(design, pa[face, 2], rcond=None)[0][0]
        cb = np.linalg.lstsq(np.c_[np.ones(k * k), pb[face, :2]], pb[face, 2], rcond=None)[0][0]
        est[i] = cb - ca
    # The plane's height at the centre is the face's mean, on a noisy grid too
    # up to the noise's lateral components (a second-order effect).
    s = float(np.std(est, ddof=1))
    lo, hi = (np.sqrt(chi2.ppf(q, draws - 1) / (draws - 1)) for q in (0.0005, 0.9995))
    assert lo * scene.sigma_gap <= s <= hi * scene.sigma_gap, (s, scene.sigma_gap)
    assert abs(np.mean(est)) <= Z_TOL * scene.sigma_gap / np.sqrt(draws)


def test_the_ece_tolerance_passes_the_ideal_forecast_and_fails_an_overconfident_one() -> None:
    """The harness itself: the ideal P of the noise model passes, a P with half its std fails."""
    rng = np.random.default_rng(491)
    g = rng.uniform(-PRIOR, PRIOR, 600)
    g_hat = g + rng.normal(size=g.size)
    ideal, over = norm.cdf(-g_hat), norm.cdf(-g_hat / 0.5)
    assert calibration(ideal, g < 0.0).ece <= ece_tolerance(ideal)
    assert calibration(over, g < 0.0).ece > ece_tolerance(over)
    assert 0.001 < PRIOR_BIAS < 0.005


# --------------------------------------------------------------------------
# Parallel plates


@pytest.fixture(scope="module")
def plate_draws() -> tuple[Scene, Draws]:
    scene = plates()
    return scene, run_draws(scene, prior_gaps(scene, 600, 4901), 4902, residuals=200)


@pytest.fixture(scope="module")
def plate_grid() -> tuple[Scene, dict[float, Draws]]:
    """P at fixed true gaps of -2 .. 2 standard errors (200 draws at 0, 60 elsewhere)."""
    scene = plates()
    out = {}
    for j, units in enumerate((-2.0, -1.0, 0.0, 1.0, 2.0)):
        count = 200 if units == 0.0 else 60
        out[units] = run_draws(scene, np.full(count, units * scene.sigma_gap), 4910 + j)
    return scene, out


def test_parallel_plates_p_is_calibrated(plate_draws: tuple[Scene, Draws]) -> None:
    _, d = plate_draws
    cal = calibration(d.p, d.gap < 0.0)
    assert cal.ece <= ece_tolerance(d.p), cal.table


def test_parallel_plates_p_near_one_half_matches_the_frequency(
    plate_draws: tuple[Scene, Draws],
) -> None:
    _, d = plate_draws
    n, mp, freq, tol = near_half(d.p, d.gap < 0.0)
    assert n >= 20, f"only {n} of {len(d.p)} draws read P in [0.3, 0.7)"
    assert abs(mp - freq) <= tol, (n, mp, freq, tol)


def test_parallel_plates_at_contact_read_one_half_on_average(
    plate_grid: tuple[Scene, dict[float, Draws]],
) -> None:
    _, grid = plate_grid
    p = grid[0.0].p
    # A calibrated P at g = 0 is Phi of a standard normal: uniform, variance 1/12.
    assert abs(np.mean(p) - 0.5) <= Z_TOL * np.sqrt(1.0 / 12.0 / len(p)), np.mean(p)


def test_parallel_plates_p_falls_with_the_gap_on_average(
    plate_grid: tuple[Scene, dict[float, Draws]],
) -> None:
    _, grid = plate_grid
    units = sorted(grid)
    means = np.array([np.mean(grid[u].p) for u in units])
    errs = np.array([np.std(grid[u].p, ddof=1) / np.sqrt(len(grid[u].p)) for u in units])
    # Every step of one standard error lowers the mean P (for the noise model's
    # P by 0.16 to 0.26, against a noise of about 0.05 on the difference of two
    # means of 60 draws), and from -2 to +2 by more than the two means' noise.
    assert np.all(np.diff(means) < 0.0), means
    assert means[0] - means[-1] > Z_TOL * np.hypot(errs[0], errs[-1]), (means, errs)


@pytest.mark.xfail(
    strict=True,
    reason="parallel plates: P is honest but less sharp than the noise model's (the plate "
    "is read by elements smaller than it, at a probe: about 1.9 times the standard error "
    "of two whole faces): mean P at -2 standard errors 0.78 where the noise model gives 0.92",
)
def test_parallel_plates_mean_p_follows_the_noise_model(
    plate_grid: tuple[Scene, dict[float, Draws]],
) -> None:
    _, grid = plate_grid
    for units, d in grid.items():
        expected = norm.cdf(-units / np.sqrt(2.0))
        tol = Z_TOL * np.std(d.p, ddof=1) / np.sqrt(len(d.p)) + PRIOR_BIAS
        assert abs(np.mean(d.p) - expected) <= tol, (units, np.mean(d.p), expected)


def test_parallel_plates_residuals_are_standard_normal(plate_draws: tuple[Scene, Draws]) -> None:
    _, d = plate_draws
    draws, pairs, mean, sd = residual_summary(d.residuals)
    assert draws >= 190 and pairs >= 10 * draws, (draws, pairs)
    # Tolerances count draws (each draw's pairs as one observation).
    assert abs(mean) <= Z_TOL / np.sqrt(draws), (mean, draws)
    lo, hi = (np.sqrt(chi2.ppf(q, draws) / draws) for q in (0.0005, 0.9995))
    assert lo <= sd <= hi, (sd, lo, hi)


# --------------------------------------------------------------------------
# Spheres


@pytest.mark.parametrize(("n", "count"), [(2000, 300), (10_000, 240)], ids=["2000", "10000"])
def test_spheres_p_is_calibrated(n: int, count: int) -> None:
    # Four contacts per pair of clouds (Scene.contacts): 75 and 60 pairs.
    scene = spheres(n)
    d = run_draws(scene, prior_gaps(scene, count, 4920 + n), 4930 + n)
    cal = calibration(d.p, d.gap < 0.0)
    assert cal.ece <= ece_tolerance(d.p), cal.table
