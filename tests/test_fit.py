"""hybridsub.fit: exactness, noise, smoothness, options; closest points against brute force."""

import numpy as np
import pytest

import hybridsub
from conftest import load_mesh
from hybridsub._surface._closest_kernels import closest_among
from hybridsub._surface.mesh_closest import ClosestPoints, closest_points


def _control():
    """A bumpy closed control mesh (18 vertices) with a crease path, and its mean edge length."""
    V, F = load_mesh("octahedron")
    r = hybridsub.refine(F, levels=1, scheme="loop")
    rng = np.random.default_rng(1)
    Vc = r.apply(V)
    Vc = Vc / np.linalg.norm(Vc, axis=1)[:, None] * (1 + 0.1 * rng.normal(size=(len(Vc), 1)))
    E = np.unique(np.sort(np.concatenate([r.faces[:, [0, 1]], r.faces[:, [1, 2]], r.faces[:, [2, 0]]]), axis=1),
                  axis=0)
    path = [0]
    for _ in range(3):                                     # a crease path of three edges
        ends = np.concatenate([E[E[:, 0] == path[-1], 1], E[E[:, 1] == path[-1], 0]])
        path.append(int(min(set(ends.tolist()) - set(path))))
    creases = np.array(list(zip(path[:-1], path[1:])))
    return Vc, r.faces, creases, np.linalg.norm(Vc[E[:, 0]] - Vc[E[:, 1]], axis=1).mean()


VC, FC, CREASES, EDGE = _control()


def _sample(r, V, n, rng):
    P = r.apply(V)
    f = rng.integers(0, len(r.faces), n)
    b = rng.dirichlet([1, 1, 1], n)
    return np.einsum("mi,mij->mj", b, P[r.faces[f]])


@pytest.mark.parametrize("scheme", ["hybrid", "sqrt3", "loop"])
def test_points_on_a_level_are_fitted_exactly_from_a_perturbed_start(scheme):
    rng = np.random.default_rng(2)
    sharp = None if scheme == "sqrt3" else CREASES
    kw = dict(scheme=scheme, sharp_faces=[0, 5] if scheme == "hybrid" else None)
    r = hybridsub.refine(FC, sharp, levels=2, **kw)
    pts = _sample(r, VC, 2500, rng)
    start = VC + 0.05 * EDGE * rng.normal(size=VC.shape) / np.sqrt(3)
    res = hybridsub.fit(FC, pts, sharp, V0=start, levels=2, **kw)
    diag = np.linalg.norm(pts.max(0) - pts.min(0))
    assert res.converged and res.iterations <= 10
    assert np.abs(res.vertices - VC).max() < 1e-8 * diag
    assert res.rms < 1e-10 * diag and res.max_error < 1e-9 * diag
    h = res.history
    assert len(h) == res.iterations + 1 and h["rms"][0] > 1e-4 * diag
    assert (np.diff(h["rms"][:4]) < 0).all()                  # fast decrease: Gauss-Newton on the distance
    assert (np.diff(h["seconds"]) >= 0).all() and h["step"][-1] == 0 and h["step"][0] > 0


def test_noise_of_sigma_leaves_an_rms_of_sigma():
    rng = np.random.default_rng(3)
    r = hybridsub.refine(FC, CREASES, levels=2)
    pts = _sample(r, VC, 4000, rng)
    sigma = 0.002 * np.linalg.norm(pts.max(0) - pts.min(0))
    res = hybridsub.fit(FC, pts + sigma * rng.normal(size=pts.shape), CREASES, V0=VC, levels=2, max_iterations=6)
    assert 0.9 * sigma < res.rms < 1.05 * sigma
    assert abs(res.history["rms"][-1] - res.history["rms"][-2]) < 1e-4 * sigma   # settled
    assert np.abs(res.vertices - VC).max() < 0.3 * EDGE


def test_smoothness_trades_distance_for_fairness_and_keeps_corners():
    rng = np.random.default_rng(4)
    r = hybridsub.refine(FC, CREASES, levels=1)
    pts = _sample(r, VC, 1500, rng)
    corner = [int(CREASES[0, 0])]
    plain = hybridsub.fit(FC, pts, CREASES, corners=corner, V0=VC, levels=1, max_iterations=3)
    fair = hybridsub.fit(FC, pts, CREASES, corners=corner, V0=VC, levels=1, smoothness=1.0, max_iterations=3)
    lap = hybridsub._fit.fitting.umbrella(FC, len(VC), CREASES, np.isin(np.arange(len(VC)), corner))
    assert np.abs(lap[corner[0]].toarray()).max() == 0              # corners are not smoothed
    assert np.count_nonzero(lap[int(CREASES[1, 0])].toarray()) == 3  # a crease vertex: its two crease neighbours
    assert fair.rms > plain.rms
    assert np.linalg.norm(lap @ fair.vertices) < np.linalg.norm(lap @ plain.vertices)


def test_default_start_and_bad_arguments():
    rng = np.random.default_rng(5)
    r = hybridsub.refine(FC, levels=1)
    pts = np.vstack([VC + 0.01 * rng.normal(size=VC.shape), _sample(r, VC, 1000, rng)])
    res = hybridsub.fit(FC, pts, levels=1, max_iterations=3)
    assert res.vertices.shape == VC.shape and res.iterations == 3 and not res.converged
    seen = []
    hybridsub.fit(FC, pts, levels=1, max_iterations=2, callback=lambda *a: seen.append(a))
    assert [s[0] for s in seen] == [0, 1, 2]
    with pytest.raises(ValueError, match="pass V0"):
        hybridsub.fit(FC, pts[:5], levels=1)
    with pytest.raises(hybridsub.MeshError, match="V0 must have one row per control vertex"):
        hybridsub.fit(FC, pts, V0=VC[:4], levels=1)
    with pytest.raises(hybridsub.MeshError, match="points must have shape"):
        hybridsub.fit(FC, pts[:, :2], V0=VC, levels=1)
    with pytest.raises(hybridsub.MeshError, match="point 2 has a non-finite"):
        hybridsub.fit(FC, np.where(np.arange(len(pts))[:, None] == 2, np.nan, pts), V0=VC, levels=1)
    for bad in [dict(smoothness=-1), dict(tol=-1), dict(max_iterations=1.5)]:
        with pytest.raises(ValueError):
            hybridsub.fit(FC, pts, V0=VC, levels=1, **bad)
    with pytest.raises(hybridsub.MeshError, match="not an edge"):
        hybridsub.fit(FC, pts, [[0, 17]], V0=VC, levels=1)
    P0 = pts.copy()
    hybridsub.fit(FC, pts, V0=VC, levels=1, max_iterations=1)
    assert np.array_equal(pts, P0)


def test_closest_points_match_brute_force_as_the_mesh_moves():
    V, F = load_mesh("mesh_with_border")
    rng = np.random.default_rng(6)
    q = V[rng.integers(0, len(V), 400)] + 0.05 * rng.normal(size=(400, 3))
    search = ClosestPoints(F, q)
    every = np.tile(np.arange(len(F)), (len(q), 1))
    for step in range(3):
        P = V + 0.01 * step * rng.normal(size=V.shape)
        fp = search.search(P)
        f, b, d2 = np.full(len(q), -1), np.zeros((len(q), 3)), np.full(len(q), np.inf)
        closest_among(q, P, F, every, f, b, d2)
        assert np.abs(fp.distance - np.sqrt(d2)).max() < 1e-15
        assert np.allclose(np.linalg.norm(fp.points - q, axis=1), fp.distance)
    long = np.array([[0.0, 0, 0], [100, 0, 0], [0, 0.1, 0], [50, 1, 0]])   # one long sliver among small faces
    fp = closest_points(long, np.array([[0, 1, 2], [1, 3, 2]]), np.array([[90.0, 0.01, 1]]))
    assert fp.face.tolist() == [0] and abs(fp.distance[0] - 1) < 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("scheme", ["hybrid", "sqrt3", "loop"])
def test_points_on_the_limit_surface_are_fitted_exactly(scheme):
    rng = np.random.default_rng(7)
    sharp = None if scheme == "sqrt3" else CREASES
    kw = dict(scheme=scheme, sharp_faces=[0, 5] if scheme == "hybrid" else None)
    n = 300
    pts = hybridsub.LimitSurface(VC, FC, sharp, **kw).evaluate(rng.integers(0, len(FC), n),
                                                                 rng.dirichlet([1, 1, 1], n))
    start = VC + 0.05 * EDGE * rng.normal(size=VC.shape) / np.sqrt(3)
    res = hybridsub.fit(FC, pts, sharp, V0=start, max_iterations=8, **kw)
    diag = np.linalg.norm(pts.max(0) - pts.min(0))
    assert np.abs(res.vertices - VC).max() < 1e-8 * diag


@pytest.mark.slow
def test_the_limit_fit_takes_a_step_toward_the_points():
    rng = np.random.default_rng(8)
    pts = hybridsub.LimitSurface(VC, FC, CREASES).evaluate(rng.integers(0, len(FC), 40), rng.dirichlet([1, 1, 1], 40))
    res = hybridsub.fit(FC, pts, CREASES, V0=VC + 0.02 * EDGE, max_iterations=1)
    assert res.history["rms"][1] < 0.2 * res.history["rms"][0]


def test_closest_points_of_far_points_are_exact():
    V, F = load_mesh("mesh_with_border")
    rng = np.random.default_rng(10)
    q = V[rng.integers(0, len(V), 50)] + 0.5 * rng.normal(size=(50, 3))    # far: many shells of cells
    q = np.concatenate([q, V.mean(0) + 20.0 * rng.normal(size=(10, 3))])    # and outside the grid
    fp = closest_points(V, F, q)
    f, b, d2 = np.full(len(q), -1), np.zeros((len(q), 3)), np.full(len(q), np.inf)
    closest_among(q, V, F, np.tile(np.arange(len(F)), (len(q), 1)), f, b, d2)
    assert np.abs(fp.distance - np.sqrt(d2)).max() < 1e-15


def test_an_update_that_raises_the_error_is_halved_back(monkeypatch):
    import hybridsub._fit.fitting as fitting

    rng = np.random.default_rng(11)
    r = hybridsub.refine(FC, CREASES, levels=2)
    pts = _sample(r, VC, 3000, rng)
    start = VC + 0.05 * EDGE * rng.normal(size=VC.shape) / np.sqrt(3)
    true_update, calls = fitting._update, []

    def overshooting(*args):
        calls.append(1)
        return true_update(*args) * (16.0 if len(calls) == 1 else 1.0)   # the first update 16 times too long

    monkeypatch.setattr(fitting, "_update", overshooting)
    res = hybridsub.fit(FC, pts, CREASES, V0=start, levels=2, max_iterations=10)
    rms = res.history["rms"]
    assert np.all(np.diff(rms) <= 1e-9 * rms[:-1])       # each accepted update lowered the error
    assert rms[1] < 0.5 * rms[0]                         # the halved first update still helped
    diag = np.linalg.norm(pts.max(0) - pts.min(0))
    assert res.converged and np.abs(res.vertices - VC).max() < 1e-8 * diag
