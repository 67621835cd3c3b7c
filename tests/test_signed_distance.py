"""Signed distance to meshes (``MeshDistance``) and its grid (``DistanceField``)
against a brute-force numpy reference: every triangle's closest point, and the
winding number summed over every face."""

from __future__ import annotations

import numpy as np
import pytest

import cloudprox as cp


def _closest_on_segments(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Squared distances from points ``p`` (n, 3) to segments ``a b`` (m, 3): (n, m)."""
    d = b - a
    dd = np.maximum((d * d).sum(-1), 1e-300)
    t = np.clip(((p[:, None, :] - a[None]) * d[None]).sum(-1) / dd[None], 0.0, 1.0)
    q = a[None] + t[..., None] * d[None]
    return ((p[:, None, :] - q) ** 2).sum(-1)


def brute_distance(mesh: cp.Mesh, p: np.ndarray) -> np.ndarray:
    """Distance from each point to the nearest triangle, over all triangles."""
    v, f = mesh.vertices, mesh.faces
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    h = ((p[:, None, :] - a[None]) * n[None]).sum(-1)  # height over each plane
    q = p[:, None, :] - h[..., None] * n[None]  # projection
    inside = np.ones(h.shape, dtype=bool)
    for u, w in ((a, b), (b, c), (c, a)):
        inside &= (np.cross(w - u, q - u[None]) * n[None]).sum(-1) >= 0.0
    d2 = np.where(inside, h * h, np.inf)
    for u, w in ((a, b), (b, c), (c, a)):
        d2 = np.minimum(d2, _closest_on_segments(p, u, w))
    return np.sqrt(d2.min(axis=1))


def brute_winding(mesh: cp.Mesh, p: np.ndarray) -> np.ndarray:
    """The generalized winding number (Van Oosterom & Strackee solid angles)."""
    v, f = mesh.vertices, mesh.faces
    a = v[f[:, 0]][None] - p[:, None, :]
    b = v[f[:, 1]][None] - p[:, None, :]
    c = v[f[:, 2]][None] - p[:, None, :]
    la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
    num = (a * np.cross(b, c)).sum(-1)
    dot = lambda x, y: (x * y).sum(-1)  # noqa: E731
    den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la
    return (2.0 * np.arctan2(num, den)).sum(axis=1) / (4.0 * np.pi)


def probe(mesh: cp.Mesh, n: int, near: float, far: float, seed: int) -> np.ndarray:
    """Points near the surface and in the box grown by ``far``."""
    rng = np.random.default_rng(seed)
    s = mesh.sample(n, seed=seed).points
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    lo, hi = mesh.bounds()
    box = rng.uniform(lo - far, hi + far, size=(n, 3))
    return np.vstack([s + d * rng.uniform(-near, near, size=(n, 1)), box])


def open_box() -> cp.Mesh:
    b = cp.Mesh.cuboid(0.1, 0.08, 0.06)
    return cp.Mesh(b.vertices, b.faces[:10])


@pytest.mark.parametrize(
    ("mesh", "method"),
    [
        (cp.Mesh.cuboid(0.1, 0.05, 0.03), "pseudo_normal"),
        (cp.Mesh.cylinder(0.05, 0.08, 24), "pseudo_normal"),
        (open_box(), "winding_number"),
        (
            cp.Mesh.merged([cp.Mesh.cuboid(0.05, 0.05, 0.05), cp.Mesh.cuboid(0.08, 0.02, 0.02)]),
            "winding_number",
        ),
    ],
)
def test_signed_distance_matches_brute_force(mesh: cp.Mesh, method: str) -> None:
    md = cp.MeshDistance(mesh)
    assert md.sign_method == method
    p = probe(mesh, 300, 0.03, 0.05, seed=1)
    d = brute_distance(mesh, p)
    w = brute_winding(mesh, p)
    sd = md.signed_distance(p)
    assert sd.shape == (len(p),) and sd.dtype == np.float64
    np.testing.assert_allclose(np.abs(sd), d, atol=1e-12, rtol=0)
    sure = (np.abs(w - 0.5) > 1e-6) & (d > 1e-9)
    assert sure.sum() > len(p) // 2
    np.testing.assert_array_equal((sd < 0)[sure], (w > 0.5)[sure])
    np.testing.assert_array_equal(md.contains(p)[sure], (w > 0.5)[sure])
    np.testing.assert_allclose(md.winding_number(p), w, atol=1e-9)
    np.testing.assert_allclose(md.distance(p), d, atol=1e-12, rtol=0)
    # closest: the point is on the surface that far away, the normal unit.
    dist, q, n = md.closest(p)
    np.testing.assert_array_equal(dist, sd)
    assert q.shape == (len(p), 3) and n.shape == (len(p), 3)
    np.testing.assert_allclose(np.linalg.norm(q - p, axis=1), d, atol=1e-12)
    np.testing.assert_allclose(brute_distance(mesh, q), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    # The normal points from the closest point to an outside query point.
    off = d > 1e-9
    g = (p - q)[off] / d[off, None] * np.where(sd[off] < 0, -1.0, 1.0)[:, None]
    np.testing.assert_allclose(n[off], g, atol=1e-9)


def test_closest_within_stops_at_its_bound() -> None:
    mesh = cp.Mesh.cylinder(0.05, 0.08, 24)
    md = cp.MeshDistance(mesh)
    p = probe(mesh, 200, 0.03, 0.1, seed=2)
    sd = md.signed_distance(p)
    dist, q, n = md.closest_within(p, 0.01)
    near = np.abs(sd) <= 0.01
    np.testing.assert_array_equal(dist[near], sd[near])
    assert np.isnan(dist[~near]).all() and np.isnan(q[~near]).all() and np.isnan(n[~near]).all()


@pytest.mark.parametrize(
    "mesh", [cp.Mesh.cuboid(0.1, 0.05, 0.03), cp.Mesh.cylinder(0.05, 0.08, 32), open_box()]
)
def test_the_field_bound_holds(mesh: cp.Mesh) -> None:
    md = cp.MeshDistance(mesh)
    field = md.field(0.004, 0.02)
    assert field.resolution == 0.004 and field.band == 0.02
    assert len(field.shape) == 3 and field.nbytes > 0 and field.origin.shape == (3,)
    assert field.stats["nodes_in_band"] > 0
    assert field.mesh_distance.sign_method == md.sign_method
    p = probe(mesh, 3000, 0.03, 0.05, seed=3)
    d, g, b = field.evaluate(p)
    assert d.shape == (len(p),) and g.shape == (len(p), 3) and b.shape == (len(p),)
    exact = md.signed_distance(p)
    assert (np.abs(exact - d) <= b).all()
    assert (b > 0).sum() > len(p) // 3  # most points interpolate
    assert b.max() <= 4 * np.sqrt(3) * 0.004
    # The constructor and the method build the same field.
    other = cp.DistanceField(md, 0.004, 0.02)
    np.testing.assert_array_equal(other.evaluate(p)[0], d)


def test_repairs_are_reported() -> None:
    cube = cp.Mesh.cuboid(0.1, 0.1, 0.1)
    faces = cube.faces.copy()
    faces[3] = faces[3][[0, 2, 1]]
    md = cp.MeshDistance(cp.Mesh(cube.vertices, faces))
    assert md.topology["reoriented_faces"] == 1
    assert md.topology["closed"] is True
    assert md.sign_method == "pseudo_normal"
    assert md.signed_distance([[0.0, 0.0, 0.0]])[0] == pytest.approx(-0.1)
    forced = cp.MeshDistance(cube, sign_method="winding_number")
    assert forced.sign_method == "winding_number"
    assert "12 faces" in repr(md) and "DistanceField" in repr(md.field(0.01, 0.02))


def test_bad_inputs_raise_invalid_input_error() -> None:
    md = cp.MeshDistance(cp.Mesh.cuboid(0.1, 0.1, 0.1))
    for bad in (np.zeros((3, 2)), np.zeros(3), "abc", [[0.0, 0.0, np.nan]], [[np.inf, 0, 0]]):
        with pytest.raises(cp.InvalidInputError):
            md.signed_distance(bad)
        with pytest.raises(cp.InvalidInputError):
            md.closest(bad)
    with pytest.raises(cp.InvalidInputError, match="non-finite"):
        md.contains([[0.0, 0.0, np.nan]])
    with pytest.raises(cp.InvalidInputError, match="max_distance"):
        md.closest_within([[0.0, 0.0, 0.0]], -1.0)
    with pytest.raises(cp.InvalidInputError, match="sign_method"):
        cp.MeshDistance(cp.Mesh.cuboid(0.1, 0.1, 0.1), sign_method="parity")  # type: ignore[arg-type]
    flat = cp.Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]])
    with pytest.raises(cp.InvalidInputError, match="degenerate"):
        cp.MeshDistance(flat)
    for resolution, band in ((0.0, 0.01), (-1.0, 0.01), (0.01, np.nan), (1e-5, 0.01)):
        with pytest.raises(cp.InvalidInputError):
            md.field(resolution, band)
    field = md.field(0.01, 0.02)
    with pytest.raises(cp.InvalidInputError):
        field.evaluate(np.zeros((2, 4)))
    # Empty batches are fine.
    assert md.signed_distance(np.zeros((0, 3))).shape == (0,)
    assert field.evaluate(np.zeros((0, 3)))[1].shape == (0, 3)
