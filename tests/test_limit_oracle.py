"""The limit surface against two oracles that do not go through its descent (issue 30):

(a) uniform refinement and the limit masks at the refined vertices: ``evaluate`` at
    ``r.vertex_origin`` equals ``limit_positions(levels=L)`` at the default depth;
(b) convergence at random parameters: the piecewise-linear interpolation of the level-k
    limit positions, at the point's place in the level-k chart (followed down with
    ``face_parent`` and each child's corners in its parent's frame, not the descent), tends to
    ``evaluate`` geometrically.
"""

import os

import numpy as np
import pytest

import hybridsub
from conftest import load_mesh
from hybridsub._refiner.chart import FaceCharts
from hybridsub._topology import build_level


def _diag(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def _tags(V, F, kind, rng):
    if kind == "none":
        return {}
    if kind == "sharp-faces":
        return dict(sharp_faces=np.flatnonzero(rng.random(len(F)) < 0.3))
    feat = hybridsub.detect_features(V, F, 30.0)
    if not len(feat.sharp_edges):
        return {}
    if kind == "semisharp":
        return dict(sharp_edges=feat.sharp_edges, sharpness=rng.uniform(0.2, 3.0, len(feat.sharp_edges)))
    if kind == "integer-sharpness":  # corners for a level or two, then moving
        return dict(sharp_edges=feat.sharp_edges, sharpness=rng.choice([1.0, 2.0, 3.0], len(feat.sharp_edges)))
    return dict(sharp_edges=feat.sharp_edges, corners=feat.corners)


def _vertex_cases(slow):
    meshes = ["tetrahedron", "octahedron", "mesh_with_border"] + (["icosahedron", "cube-meshed",
                                                                     "elephant-with-holes", "fandisk"] if slow else [])
    out = []
    for name in meshes:
        for scheme, kinds in (("hybrid", ["none", "creases", "semisharp", "integer-sharpness", "sharp-faces"]),
                              ("loop", ["none", "creases", "semisharp", "integer-sharpness"]), ("sqrt3", ["none"])):
            for kind in kinds:
                if kind == "sharp-faces" and name in ("mesh_with_border", "cube-meshed", "elephant-with-holes",
                                                      "fandisk") and not (slow and name == "mesh_with_border"):
                    continue  # minutes: a third of the faces sharp makes mixed vertices everywhere
                out.append((name, scheme, kind))
    return out


def _check_vertices(name, scheme, kind, n_points):
    if name == "fandisk":
        V, F = hybridsub.load_example()
    else:
        V, F = load_mesh(name)
    rng = np.random.default_rng(len(name) + len(kind))
    kw = dict(scheme=scheme, **_tags(V, F, kind, rng))
    s = hybridsub.LimitSurface(V, F, **kw)
    for levels in (1, 2, 3):
        r = hybridsub.refine(F, levels=levels, **kw)
        ref = hybridsub.limit_positions(V, F, levels=levels, **kw)
        face, bary = r.vertex_origin
        idx = np.flatnonzero(face >= 0)
        idx = rng.choice(idx, min(n_points, len(idx)), replace=False)
        P = s.evaluate(face[idx], bary[idx])
        assert np.abs(P - ref[idx]).max() < 1e-12 * _diag(V), (name, scheme, kind, levels)


@pytest.mark.parametrize("case", _vertex_cases(False), ids="-".join)
def test_refined_vertices_are_their_limit_positions(case):
    """(a): every scheme, creases, corners, semi-sharp creases, sharp faces, boundaries."""
    _check_vertices(*case, n_points=120)


@pytest.mark.parametrize("scheme, levels", [("sqrt3", 5), ("sqrt3", 6), ("loop", 5)])
def test_deep_levels_round_valence_five_vertices(scheme, levels):
    """Past four √3 levels the refined vertices next to a vertex of valence 5 lie across a
    vertex of their faces' input face, where going round it (a cone, not a plane) is not
    unique: ``vertex_origin`` must report the face the refinement put each one in, as
    ``limit_positions`` says (it reported the next face round for 19 of 2,432 at level 5)."""
    V, F = hybridsub.load_example("icosahedron")
    r = hybridsub.refine(F, levels=levels, scheme=scheme)
    got = hybridsub.LimitSurface(V, F, scheme=scheme).evaluate(*r.vertex_origin)
    want = hybridsub.limit_positions(V, F, levels=levels, scheme=scheme)
    assert np.abs(got - want).max() <= 1e-12 * _diag(V)


def test_a_hybrid_mesh_with_semisharp_creases_and_sharp_faces():
    """Found by the adaptive refinement's property test (hypothesis): integer sharpness (1, 2)
    keeps some vertices corners for a level or two, then lets them move; their limit positions
    must not be read off the levels where they stood still. ``evaluate`` at ``vertex_origin``
    against ``limit_positions`` at level 1, and both against uniform refinement, whose
    refined positions of those vertices close in on the limit geometrically."""
    d = np.load(os.path.join(os.path.dirname(__file__), "data", "defects", "hybrid_semisharp_sharp_faces.npz"))
    V, F = d["V"], d["F"]
    tags = dict(sharp_edges=d["sharp_edges"], sharpness=d["sharpness"], sharp_faces=d["sharp_faces"])
    r = hybridsub.refine(F, levels=1, scheme="hybrid", n_vertices=len(V), **tags)
    got = hybridsub.LimitSurface(V, F, scheme="hybrid", **tags).evaluate(*r.vertex_origin)
    want = hybridsub.limit_positions(V, F, levels=1, scheme="hybrid", **tags)
    assert np.abs(got - want).max() <= 1e-12 * _diag(V)
    moved = np.flatnonzero(np.abs(want[:len(V)] - V).max(axis=1) > 1e-3)
    assert len(moved)
    gaps = []
    for levels in (3, 4, 5, 6):
        P = hybridsub.refine(F, levels=levels, scheme="hybrid", n_vertices=len(V), **tags).apply(V)
        gaps.append(np.abs(P[moved] - want[moved]).max())
    assert all(b < 0.7 * a for a, b in zip(gaps, gaps[1:])), gaps


@pytest.mark.parametrize("scheme", ["loop", "hybrid", "hybrid-mixed"])
@pytest.mark.parametrize("sharpness", [1.0, 2.0, 3.0])
def test_limit_positions_with_integer_sharpness_are_the_limit_of_refinement(scheme, sharpness):
    """Every edge of the octahedron semi-sharp with an integer sharpness: its vertices are
    corners for ``sharpness`` levels, then smooth (``hybrid-mixed``: sharp and smooth faces
    in a checkerboard, every vertex mixed, where no stationary mask exists). The refined
    positions of its vertices (uniform refinement, no limit code) close in on
    ``limit_positions`` geometrically, and their Aitken extrapolation agrees with it (an
    oracle independent of the local refinement the limit positions come from)."""
    V, F = load_mesh("octahedron")
    E = np.unique(np.sort(np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2), axis=1), axis=0)
    kw = dict(scheme=scheme.split("-")[0], sharp_edges=E, sharpness=np.full(len(E), sharpness))
    if scheme == "hybrid-mixed":
        kw["sharp_faces"] = np.flatnonzero(np.prod(V[F].mean(axis=1), axis=1) > 0)
        assert len(kw["sharp_faces"]) == 4
    want = hybridsub.limit_positions(V, F, **kw)
    P = [hybridsub.refine(F, levels=L, n_vertices=len(V), **kw).apply(V)[:len(V)] for L in (5, 6, 7)]
    gaps = [np.abs(p - want).max() for p in P]
    assert gaps[2] < 0.7 * gaps[1] < 0.49 * gaps[0], gaps
    d1, d2 = P[1] - P[0], P[2] - P[1]
    rho = np.linalg.norm(d2, axis=1) / np.linalg.norm(d1, axis=1)
    aitken = P[2] + (rho / (1 - rho))[:, None] * d2
    assert np.abs(aitken - want).max() < 0.25 * gaps[2], (gaps, np.abs(aitken - want).max())


@pytest.mark.slow
@pytest.mark.parametrize("case", _vertex_cases(True), ids="-".join)
def test_refined_vertices_are_their_limit_positions_everywhere(case):
    _check_vertices(*case, n_points=3000)


def _into_frame(x: np.ndarray, f: int, i: int, t: int) -> np.ndarray:
    """Barycentric coordinates ``x`` (..., 3) over the face across halfedge ``3f + i`` (its
    twin ``t``), in ``f``'s frame: there corner ``t % 3`` is our corner i + 1, the next our
    corner i, the third our corner i + 2 mirrored across the edge."""
    a = t % 3
    out = np.zeros(x.shape)
    out[..., (i + 1) % 3] += x[..., a] + x[..., (a + 2) % 3]
    out[..., i] += x[..., (a + 1) % 3] + x[..., (a + 2) % 3]
    out[..., (i + 2) % 3] -= x[..., (a + 2) % 3]
    return out


def _charts(F0: np.ndarray, n0: int, r) -> FaceCharts:
    charts = FaceCharts(F0, n0, lambda F, n: build_level(F, n).twin)
    for st in r.steps:
        charts.step(st)
    return charts


def _locate(charts: FaceCharts, face: int, bary: np.ndarray) -> tuple[int, np.ndarray]:
    """The face of the last level of ``charts`` that holds the point (``face``, ``bary``) of the
    input, and the point's barycentric coordinates there, followed down level by level with
    ``face_parent`` and the chart's rule (every face equilateral in its own frame, its
    edge-neighbours mirrored onto it; each child's corners in its parent's frame from
    :class:`FaceCharts`), among the children of the point's face and of its neighbours."""
    f, b = face, np.asarray(bary, dtype=np.float64)
    for lam, parent, twin in charts.levels:
        best, best_lo, best_b = -1, -np.inf, None
        for g, i in [(f, -1)] + [(int(twin[3 * f + i]) // 3, i) for i in range(3) if twin[3 * f + i] >= 0]:
            for c in np.flatnonzero(parent == g):
                corners = lam[c] if i < 0 else _into_frame(lam[c], f, i, int(twin[3 * f + i]))
                x = np.linalg.solve(corners.T, b)  # the point over the child's corners
                if x.min() > best_lo:
                    best, best_lo, best_b = int(c), float(x.min()), x
        f, b = best, best_b
    return f, b


@pytest.mark.parametrize("scheme, tags, levels", [
    ("sqrt3", {}, (2, 4, 6)),
    ("loop", dict(sharp_edges=[[0, 2], [2, 1], [1, 3]], corners=[3]), (2, 3, 4, 5)),
    ("hybrid", dict(sharp_edges=[[0, 2], [2, 1], [1, 3], [3, 0]]), (2, 4, 6)),
    ("hybrid", dict(sharp_edges=[[0, 4]], sharp_faces=[0, 1, 5]), (2, 4, 6)),
])
def test_refinement_converges_to_the_surface_at_random_parameters(scheme, tags, levels):
    """(b): at random points away from the input edges (so that the level-k face holding one
    descends from its input face), the gap between ``evaluate`` and the piecewise-linear
    interpolation of the level-k limit positions shrinks geometrically with k."""
    from test_limit_surface import OCTA_F as F, OCTA_V as V

    kw = dict(scheme=scheme, **tags)
    rng = np.random.default_rng(7)
    q = 40
    face = rng.integers(0, len(F), q)
    bary = 0.15 + 0.55 * rng.dirichlet([1, 1, 1], q)
    P = hybridsub.LimitSurface(V, F, **kw).evaluate(face, bary)
    gaps = []
    for k in levels:
        r = hybridsub.refine(F, levels=k, **kw)
        L = hybridsub.limit_positions(V, F, levels=k, **kw)
        gap = 0.0
        charts = _charts(F, len(V), r)
        for f, b, p in zip(face, bary, P):
            c, lam = _locate(charts, int(f), b)
            assert lam.min() > -1e-9  # a face of the level holds the point
            gap = max(gap, float(np.linalg.norm(lam @ L[r.faces[c]] - p)))
        gaps.append(gap)
    gaps = np.array(gaps) / _diag(V)
    rate = (gaps[-1] / gaps[0]) ** (1 / (levels[-1] - levels[0]))
    assert rate < 0.75 and np.all(np.diff(np.log(gaps)) < 0), gaps


@pytest.mark.parametrize("name, scheme, levels", [("icosahedron", "sqrt3", 6), ("tetrahedron", "hybrid", 5)])
def test_both_faces_of_an_edge_put_its_midpoint_on_one_surface_point(name, scheme, levels):
    """The charts that carry each face of a refinement onto the input (``FaceCharts``, which
    adaptive refinement measures its error through): an edge's midpoint, taken through either
    of its two faces, is one point of the limit surface, also where √3's flips have moved
    faces round a vertex of valence 5 (an earlier chart, which carried each face in the chart
    of the input face it started in, named points 6 % of the diagonal apart there)."""
    from hybridsub._refiner.chart import FaceCharts

    V, F = load_mesh(name)
    kw = dict(scheme=scheme, sharp_edges=[[0, 1]]) if scheme == "hybrid" else dict(scheme=scheme)
    r = hybridsub.refine(F, levels=levels, n_vertices=len(V), **kw)
    charts = FaceCharts(F, len(V), lambda A, n: build_level(A, n).twin)
    for st in r.steps:
        charts.step(st)
    twin = build_level(r.faces, r.n_vertices).twin
    h = np.flatnonzero(twin > np.arange(len(twin)))
    t = twin[h]

    def midpoints(hh):
        b = np.zeros((len(hh), 3))
        b[np.arange(len(hh)), hh % 3] = 0.5
        b[np.arange(len(hh)), (hh + 1) % 3] = 0.5
        return charts.points(hh // 3, b)

    s = hybridsub.LimitSurface(V, F, **kw)
    gap = np.linalg.norm(s.evaluate(*midpoints(h)) - s.evaluate(*midpoints(t)), axis=1)
    assert gap.max() <= 1e-9 * _diag(V), (int((gap > 1e-9 * _diag(V)).sum()), float(gap.max() / _diag(V)))
