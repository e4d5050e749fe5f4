"""The limit surface anywhere (issue 14): LimitSurface.evaluate / evaluation_matrix / normals /
project, and Refinement.vertex_origin."""

import copy
import pathlib

import numpy as np
import pytest

import hybridsub

# An octahedron, jittered: every vertex of valence 4 (extraordinary in every scheme).
OCTA_V = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
OCTA_V = OCTA_V + 0.1 * np.random.default_rng(0).standard_normal(OCTA_V.shape)
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
# An open fan of five triangles around vertex 0 (boundary, valence 6 at the centre).
FAN_V = np.array([[0.0, 0, 0.3]] + [[np.cos(a), np.sin(a), 0.1 * np.sin(3 * a)]
                                    for a in np.linspace(0, 2 * np.pi, 7)[:-1]])
FAN_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 6]])

CASES = {
    "loop-crease-corner": (OCTA_V, OCTA_F, dict(scheme="loop", sharp_edges=[[0, 2], [2, 1], [1, 3]], corners=[3])),
    "loop-semisharp": (OCTA_V, OCTA_F, dict(scheme="loop", sharp_edges=[[0, 2], [2, 1]], sharpness=[0.5, 1.5])),
    "sqrt3-closed": (OCTA_V, OCTA_F, dict(scheme="sqrt3")),
    "sqrt3-boundary": (FAN_V, FAN_F, dict(scheme="sqrt3")),
    "hybrid-crease": (OCTA_V, OCTA_F, dict(scheme="hybrid", sharp_edges=[[0, 2], [2, 1], [1, 3], [3, 0]])),
    "hybrid-mixed-dart": (OCTA_V, OCTA_F, dict(scheme="hybrid", sharp_edges=[[0, 4]], sharp_faces=[0, 1, 5])),
    "hybrid-boundary": (FAN_V, FAN_F, dict(scheme="hybrid", corners=[1])),
}


def _diag(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


@pytest.mark.parametrize("name", list(CASES))
def test_refined_vertices_evaluate_to_their_limit_positions(name):
    """evaluate(*r.vertex_origin) == limit_positions(levels=L) at the default depth: a point
    that is a vertex of a level takes that vertex's limit position, wherever the walk goes
    below it (the √3 chart folds round some vertices beside creases past ~16 levels, where
    a walk to the end went onto the wrong sheet: 3e-5 off, issue 30)."""
    V, F, kw = CASES[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    for levels in (1, 2, 3):
        r = hybridsub.refine(F, levels=levels, **kw)
        face, bary = r.vertex_origin
        ref = hybridsub.limit_positions(V, F, levels=levels, **kw)
        assert np.abs(s.evaluate(face, bary) - ref).max() < 1e-12 * _diag(V), (name, levels)


def test_vertex_origin_follows_the_chart():
    r = hybridsub.refine(OCTA_F, levels=2, scheme="sqrt3")
    face, bary = r.vertex_origin
    assert face.shape == (r.n_vertices,) and bary.shape == (r.n_vertices, 3)
    assert (bary >= 0).all() and np.allclose(bary.sum(axis=1), 1)
    # Old vertices sit at their own corner; two √3 steps trisect the old edges.
    own = OCTA_F[face[:6], np.argmax(bary[:6], axis=1)]
    assert np.array_equal(own, np.arange(6)) and np.allclose(bary[:6].max(axis=1), 1)
    pos = np.einsum("kc,kcd->kd", bary, OCTA_V[OCTA_F[face]])  # the chart mapped linearly onto the faces
    a, b = OCTA_V[0], OCTA_V[2]
    on_edge = [np.min(np.linalg.norm(pos - (a + t * (b - a)), axis=1)) for t in (1 / 3, 2 / 3)]
    assert max(on_edge) < 1e-12
    # Loop: the edge points are the midpoints, in every face that holds them.
    r = hybridsub.refine(OCTA_F, levels=1, scheme="loop")
    face, bary = r.vertex_origin
    assert np.allclose(np.sort(bary[6:], axis=1), [0, 0.5, 0.5])
    with pytest.raises(ValueError, match="cut"):
        hybridsub.refine(np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]), levels=1, non_manifold="cut").vertex_origin


@pytest.mark.parametrize("name", ["hybrid-crease", pytest.param("loop-crease-corner", marks=pytest.mark.slow),
                                  pytest.param("sqrt3-boundary", marks=pytest.mark.slow)])
def test_the_same_point_from_both_faces_of_an_edge(name):
    V, F, kw = CASES[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    # Every interior edge, at an irrational parameter.
    h = np.array([(f, i) for f in range(len(F)) for i in range(3)])
    a, b = F[h[:, 0], h[:, 1]], F[h[:, 0], (h[:, 1] + 1) % 3]
    t = 0.3137
    P, Q = [], []
    for (f, i), u, w in zip(h, a, b):
        for g in range(len(F)):
            if g != f and u in F[g] and w in F[g]:
                bf = np.zeros(3); bf[i], bf[(i + 1) % 3] = 1 - t, t
                bg = np.zeros(3); bg[list(F[g]).index(u)], bg[list(F[g]).index(w)] = 1 - t, t
                P.append((f, bf)); Q.append((g, bg))
    PP = s.evaluate([p[0] for p in P], [p[1] for p in P])
    QQ = s.evaluate([q[0] for q in Q], [q[1] for q in Q])
    assert np.abs(PP - QQ).max() < 1e-12 * _diag(V)


@pytest.mark.parametrize("name", ["hybrid-mixed-dart", pytest.param("loop-crease-corner", marks=pytest.mark.slow),
                                  pytest.param("sqrt3-closed", marks=pytest.mark.slow)])
def test_derivatives_agree_with_finite_differences(name):
    V, F, kw = CASES[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    face = np.array([0, 3, 6])
    uv = np.array([[0.3, 0.25], [0.41, 0.17], [0.2, 0.55]])
    e = 1e-4

    def at(duv):
        w = uv + duv
        return np.c_[1 - w.sum(axis=1), w]

    P, Du, Dv = s.evaluate(face, at(0), derivatives=True)
    fd_u = (s.evaluate(face, at([e, 0])) - s.evaluate(face, at([-e, 0]))) / (2 * e)
    fd_v = (s.evaluate(face, at([0, e])) - s.evaluate(face, at([0, -e]))) / (2 * e)
    scale = np.abs(Du).max()
    assert np.abs(Du - fd_u).max() < 1e-5 * scale and np.abs(Dv - fd_v).max() < 1e-5 * scale


def test_evaluation_matrix_is_what_evaluate_applies():
    V, F, kw = CASES["hybrid-crease"]
    s = hybridsub.LimitSurface(V, F, **kw)
    face, bary = np.array([0, 5, 7]), np.array([[0.2, 0.3, 0.5], [0.1, 0.1, 0.8], [1, 0, 0]])
    M, Mu, Mv = s.evaluation_matrix(face, bary, derivatives=True)
    assert M.shape == (3, 6) and np.allclose(M.sum(axis=1), 1)
    for D in (Mu[:2], Mv[:2]):  # rows sum to 0 (not asked at the crease vertex: no tangent plane there)
        assert (np.abs(D.sum(axis=1)).A1 < 1e-9 * abs(D).sum(axis=1).A1).all()
    P, Du, Dv = s.evaluate(face, bary, derivatives=True)
    assert np.array_equal(M @ V, P)  # derivatives: applied to the data forward, where the rows lose digits
    for D, G in ((Mu @ V, Du), (Mv @ V, Dv)):  # not at the crease vertex (no tangent plane: |Dv| ~ 4e3)
        assert np.abs(D[:2] - G[:2]).max() <= 1e-9 * np.abs(G[:2]).max()
    # Other control positions through the same rows; the surface is affine invariant.
    V2 = 2.0 * V + [1.0, -2.0, 0.5]
    assert np.allclose(s.evaluate(face, bary, vertices=V2), 2.0 * P + [1.0, -2.0, 0.5], atol=1e-14)
    assert np.array_equal(s.evaluation_matrix(face, bary).toarray(), M.toarray())
    assert s.vertices.shape == (6, 3) and np.array_equal(s.faces, F) and not s.vertices.flags.writeable


def test_normals_at_smooth_vertices_are_limit_normals():
    V, F, kw = CASES["loop-semisharp"]
    kw = dict(scheme="loop")
    s = hybridsub.LimitSurface(V, F, **kw)
    ref = hybridsub.limit_normals(V, F, **kw)
    N = s.normals(np.arange(8), np.tile([1.0, 0, 0], (8, 1)))  # corner 0 of every face
    assert np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", N, ref[F[:, 0]]), -1, 1))).max() < 1e-3
    assert np.allclose(np.linalg.norm(N, axis=1), 1)


def test_project_returns_points_pushed_off_along_the_normal():
    V, F, kw = CASES["hybrid-crease"]
    s = hybridsub.LimitSurface(V, F, depth=14, **kw)  # 1e-10 or better here; the default is finer
    face = np.array([0, 2, 5, 7])
    bary = np.array([[0.2, 0.3, 0.5], [0.5, 0.25, 0.25], [0.3, 0.3, 0.4], [0.6, 0.3, 0.1]])
    P = s.evaluate(face, bary)
    N = s.normals(face, bary)
    d = np.array([0.05, -0.03, 0.1, 0.02])
    f2, b2, Q, dist = s.project(P + d[:, None] * N)
    diag = _diag(V)
    assert np.abs(Q - P).max() < 1e-9 * diag
    assert np.abs(dist - d).max() < 1e-9 * diag
    assert np.abs(s.evaluate(f2, b2) - Q).max() < 1e-12 * diag


@pytest.mark.parametrize("case", ["sqrt3-closed", "hybrid-crease"])
def test_points_of_the_surface_near_its_vertices_project_onto_themselves(case):
    """The nearest seed of a point near an extraordinary vertex is that vertex, where Newton's
    method stalls: the best of the point's seeds must be the one that goes on."""
    V, F, kw = CASES[case]
    s = hybridsub.LimitSurface(V, F, depth=12, **kw)
    rng = np.random.default_rng(5)
    face = rng.integers(0, len(F), 24)
    bary = rng.dirichlet([1, 1, 1], 24) * 0.2
    bary[np.arange(24), rng.integers(0, 3, 24)] += 0.8          # within a fifth of a corner
    P = s.evaluate(face, bary)
    _, _, Q, dist = s.project(P)
    assert np.abs(dist).max() < 1e-9 * _diag(V) and np.abs(Q - P).max() < 1e-9 * _diag(V)


def test_bad_points_are_named():
    s = hybridsub.LimitSurface(OCTA_V, OCTA_F, depth=2)
    with pytest.raises(ValueError, match=r"face\[1\] = 8 is not a face"):
        s.evaluate([0, 8], [[1, 0, 0], [1, 0, 0]])
    with pytest.raises(ValueError, match=r"bary\[1\]"):
        s.evaluate([0, 1], [[1, 0, 0], [0.5, 0.7, -0.2]])
    with pytest.raises(ValueError, match="shape"):
        s.evaluate([0, 1], [[1, 0, 0]])
    with pytest.raises(ValueError, match="rows"):
        s.evaluate([0], [[1, 0, 0]], vertices=np.zeros((5, 3)))
    with pytest.raises(hybridsub.MeshError):
        hybridsub.LimitSurface(OCTA_V, OCTA_F, sharp_edges=[[0, 1]])  # not an edge


@pytest.mark.parametrize("scheme", ["sqrt3", pytest.param("loop", marks=pytest.mark.slow)])
def test_deeper_levels_are_exact_too(scheme):
    """Levels 3 and 4: refined faces reach round input vertices (the chart unfolds there)."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])  # valence 3: the chart is far from flat
    for levels in (3, 4) if scheme == "sqrt3" else (3,):
        r = hybridsub.refine(F, levels=levels, scheme=scheme)
        s = hybridsub.LimitSurface(V, F, scheme=scheme)
        ref = hybridsub.limit_positions(V, F, levels=levels, scheme=scheme)
        assert np.abs(s.evaluate(*r.vertex_origin) - ref).max() < 1e-12


@pytest.mark.parametrize("edges", [[[0, 1]], [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]])
def test_a_tetrahedron_with_creases_is_exact_at_every_depth(edges):
    """Issue 30's case: the hybrid with one or all six edges tagged was 3e-5 (5e-5) off at
    its refined vertices from depth 14 on, the default included."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    kw = dict(scheme="hybrid", sharp_edges=edges)
    for levels in (1, 2, 3):
        r = hybridsub.refine(F, levels=levels, **kw)
        ref = hybridsub.limit_positions(V, F, levels=levels, **kw)
        for depth in (4, 12, 16, 20, None):
            P = hybridsub.LimitSurface(V, F, depth=depth, **kw).evaluate(*r.vertex_origin)
            assert np.abs(P - ref).max() < 1e-12 * _diag(V), (levels, depth)


def test_loop_equals_opensubdiv_bfr_on_regular_patches():
    """tests/data/bfr/fandisk_loop.npz: OpenSubdiv 3.5 Bfr at random points of its regular patches
    (exact there), written by ``benchmarks/limit_surface.py --reference``."""
    ref = np.load(pathlib.Path(__file__).parent / "data" / "bfr" / "fandisk_loop.npz")
    V, F = hybridsub.load_example()
    s = hybridsub.LimitSurface(V, F, ref["sharp_edges"], scheme="loop")
    k = 16
    P, Du, Dv = s.evaluate(ref["face"][:k], ref["bary"][:k], derivatives=True)
    diag = _diag(V)
    assert np.abs(P - ref["P"][:k]).max() < 1e-12 * diag
    # Bfr's derivatives are exact too; ours carry the last interpolation's error.
    assert np.abs(Du - ref["Du"][:k]).max() < 1e-6 * np.abs(ref["Du"][:k]).max()
    assert np.abs(Dv - ref["Dv"][:k]).max() < 1e-6 * np.abs(ref["Dv"][:k]).max()


@pytest.mark.slow
def test_far_points_land_on_the_closest_point():
    """Points a few edge lengths away: no sample of the surface is closer, and the foot point is
    a critical point of the distance (x − Q ⟂ Du, Dv)."""
    s = hybridsub.LimitSurface(OCTA_V, OCTA_F, scheme="loop", depth=10)
    pts = np.random.default_rng(3).standard_normal((5, 3)) * 1.5
    face, bary, Q, dist = s.project(pts)
    g = np.linspace(0, 1, 21)
    U, W = np.meshgrid(g, g)
    keep = U + W <= 1
    grid = np.c_[1 - U[keep] - W[keep], U[keep], W[keep]]
    samples = s.evaluate(np.repeat(np.arange(8), len(grid)), np.tile(grid, (8, 1)))
    nearest = np.linalg.norm(pts[:, None] - samples[None], axis=2).min(axis=1)
    assert (np.abs(dist) <= nearest + 1e-12).all()
    _, Du, Dv = s.evaluate(face, bary, derivatives=True)
    r = pts - Q
    assert np.abs(np.einsum("ij,ij->i", r, Du)).max() < 1e-9 and np.abs(np.einsum("ij,ij->i", r, Dv)).max() < 1e-9


def _near_features(s, n, seed):
    """Points of the faces that get deeper walks: towards a corner, towards an edge (distances
    10⁻¹² … 1, log-uniform) or anywhere, a third each; some exactly on an edge."""
    rng = np.random.default_rng(seed)
    f = rng.choice(np.flatnonzero(s._depths.any), n)
    k, mode = rng.integers(0, 3, n), rng.integers(0, 3, n)
    r = 10.0 ** rng.uniform(-12, 0, n)
    r[rng.random(n) < 0.05] = 0.0
    b = rng.dirichlet([1, 1, 1], n)
    i, k1, k2 = np.arange(n), (k + 1) % 3, (k + 2) % 3
    to_corner = b.copy()
    to_corner[i, k1] *= r
    to_corner[i, k2] *= r
    to_edge = b.copy()
    to_edge[i, k2] *= r
    for B in (to_corner, to_edge):
        B /= B.sum(axis=1, keepdims=True)
    return f, np.where((mode == 0)[:, None], to_corner, np.where((mode == 1)[:, None], to_edge, b))


def _feature_cases():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    half = np.arange(len(F)) < len(F) // 2
    return {"hybrid-creases": (V, F, dict(sharp_edges=feat.sharp_edges, corners=feat.corners)),
            "hybrid-sharp-faces": (V, F, dict(sharp_faces=half)),
            "sqrt3": (V, F, dict(scheme="sqrt3")),
            "loop-creases": (V, F, dict(scheme="loop", sharp_edges=feat.sharp_edges))}


@pytest.mark.parametrize("name", ["hybrid-creases", "hybrid-sharp-faces", "sqrt3", "loop-creases",
                                  "sqrt3-boundary", "hybrid-boundary"])
def test_points_next_to_irregular_vertices_and_creases_are_exact(name, mesh):
    """Round irregular vertices and along split edges beside √3 faces the last interpolation
    is off by a fraction of the distance at any fixed depth (3e-7 × diagonal next to a
    valence-9 vertex at depth 14 or 18, 5e-9 next to a hybrid crease vertex at 24): such
    points are walked deeper (``_surface/depth.py``) and equal a walk to depth 56. (That is
    convergence in depth only: both walks share the chart; the oracles that do not are in
    ``test_limit_oracle.py``.)"""
    if name in ("sqrt3-boundary", "hybrid-boundary"):
        V, F = mesh("mesh_with_border")
        kw = dict(scheme=name.split("-")[0])
    else:
        V, F, kw = _feature_cases()[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    face, bary = _near_features(s, 150, seed=len(name))
    P = s.evaluate(face, bary)
    Q = hybridsub.LimitSurface(V, F, depth=56, **kw).evaluate(face, bary)
    assert np.linalg.norm(P - Q, axis=1).max() < 1e-12 * _diag(V), name


@pytest.mark.parametrize("name", ["hybrid-creases", "hybrid-sharp-faces", "sqrt3", "loop-creases"])
def test_the_depth_rule_skips_only_points_it_would_leave_at_the_default(name):
    """The cheap distance filter in front of the per-point depth rule changes no depth."""
    V, F, kw = _feature_cases()[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    face, bary = _near_features(s, 3000, seed=11)
    unfiltered = copy.copy(s._depths)
    unfiltered._reach = lambda base: (np.inf, np.inf)
    for depth in (s.depth - 6, s.depth, s.depth + 6):
        for rule_depth in (None, s.depth):
            d = s._depths(face, bary, depth, rule_depth)
            assert np.array_equal(d, unfiltered(face, bary, depth, rule_depth)) and (d >= depth).all()
            assert (d > depth).any()


@pytest.mark.parametrize("name", ["hybrid-creases", "sqrt3", "loop-creases"])
def test_a_shallow_evaluation_keeps_the_depth_rule_next_to_features(name):
    """``project``'s first iterations evaluate at depth 8, relying on an error below their
    margin (1e-5 diagonals): with ``rule_depth`` a point the rule takes deeper than the shallow
    depth keeps the rule's own depth, so points next to irregular vertices and split edges are
    as close to the surface as elsewhere (the whole rule shifted down leaves them 1e-7 off here,
    and a point 3e-3 of a face from an octahedron's corner 3e-4 diagonals off, where project
    then missed its foot)."""
    V, F, kw = _feature_cases()[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    face, bary = _near_features(s, 300, seed=5)
    exact = s.evaluate(face, bary)
    X = np.ascontiguousarray(s.vertices)
    err = np.linalg.norm(s._applied(face, bary, 1, 8, X, rule_depth=s.depth)[0] - exact, axis=1) / _diag(V)
    shifted = np.linalg.norm(s._applied(face, bary, 1, 8, X)[0] - exact, axis=1) / _diag(V)
    assert err.max() < 1e-10 and shifted.max() > 1e-8, (err.max(), shifted.max())


@pytest.mark.parametrize("name", ["sqrt3", "hybrid-creases"])
def test_derivatives_near_irregular_vertices_converge_with_depth(name):
    """Derivatives at the depths points next to irregular vertices are walked to (up to 56):
    applied to the data forward, they converge as the walk goes deeper; carried back as rows,
    their weights grow like 3^(depth/2) and cancel, and went wrong by whole radians."""
    V, F, kw = _feature_cases()[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    face, bary = _near_features(s, 300, seed=4)
    deeper = hybridsub.LimitSurface(V, F, depth=s.depth + 8, **kw)
    depth = s._depths(face, bary, s.depth)
    assert ((depth > 32) & (depth <= 48)).any()
    for D, E in zip(s.evaluate(face, bary, derivatives=True)[1:], deeper.evaluate(face, bary, derivatives=True)[1:]):
        # Not at vertices (an irregular one has no derivative in the chart: it depends on the
        # depth), nor next to the hybrid's crease vertices (no tangent plane).
        # Where the second walk is 8 levels deeper (not cut at 56).
        ok = (bary.max(axis=1) < 1 - 1e-14) & (np.linalg.norm(D, axis=1) > 1e-3 * _diag(V)) & (depth <= 48)
        assert np.all(np.linalg.norm(D - E, axis=1)[ok] < 1e-6 * np.linalg.norm(E, axis=1)[ok])


@pytest.mark.parametrize("name", ["sqrt3", "hybrid-creases"])
def test_points_pushed_off_next_to_extraordinary_vertices_come_back(name):
    """project near smooth vertices of valence ≠ 6 (10⁻⁶ … 10⁻¹ of a face away), where the
    walk goes deep: its Newton steps need derivatives that keep their digits there."""
    V, F, kw = _feature_cases()[name]
    s = hybridsub.LimitSurface(V, F, **kw)
    rng = np.random.default_rng(3)
    creased = np.zeros(len(V), bool)
    creased[np.asarray(kw.get("sharp_edges", np.zeros((0, 2), int))).ravel()] = True
    ev = np.flatnonzero((np.bincount(F.ravel(), minlength=len(V)) != 6) & ~creased)
    v = rng.choice(ev, 60)
    face = np.array([np.flatnonzero((F == x).any(axis=1))[0] for x in v])
    corner = np.argmax(F[face] == v[:, None], axis=1)
    r = 10.0 ** rng.uniform(-6, -1, 60)
    bary = rng.dirichlet([1, 1, 1], 60) * r[:, None]
    bary[np.arange(60), corner] += 1 - r
    P, N = s.evaluate(face, bary), s.normals(face, bary)
    d = 1e-3 * _diag(V)
    _, _, Q, dist = s.project(P + d * N)
    assert np.abs(Q - P).max() < 1e-9 * _diag(V) and np.abs(dist - d).max() < 1e-12 * _diag(V)


@pytest.mark.parametrize("scale", [1e200, 1e-155, 1.0])
def test_normals_at_extreme_scales(scale):
    """Du × Dv of coordinates ~1e200 overflows and of ~1e-155 underflows: the normals come
    from tangents scaled to unit size first (issue 30, point 5)."""
    V, F, kw = CASES["hybrid-crease"]
    face, bary = np.array([0, 3, 5]), np.array([[0.2, 0.3, 0.5], [0.6, 0.3, 0.1], [1 / 3, 1 / 3, 1 / 3]])
    ref = hybridsub.LimitSurface(V, F, **kw).normals(face, bary)
    s = hybridsub.LimitSurface(V * scale, F, **kw)
    for N in (s.normals(face, bary), hybridsub.LimitSurface(V, F, **kw).normals(face, bary, vertices=V * scale)):
        assert np.abs(N - ref).max() < 1e-9


def test_bad_vertices_for_evaluate_and_normals_are_named():
    s = hybridsub.LimitSurface(OCTA_V, OCTA_F)
    bad = OCTA_V.copy()
    bad[4, 1] = np.nan
    with pytest.raises(ValueError, match="vertex 4 has a non-finite"):
        s.evaluate([0], [[1, 0, 0]], vertices=bad)
    with pytest.raises(ValueError, match="vertex 4 has a non-finite"):
        s.normals([0], [[1, 0, 0]], vertices=bad)
    with pytest.raises(ValueError, match=r"normals need \(n, 3\) vertices"):
        s.normals([0], [[1, 0, 0]], vertices=OCTA_V[:, :2])
    with pytest.raises(TypeError, match="real numeric"):
        s.evaluate([0], [[1, 0, 0]], vertices=OCTA_V.astype(complex))
    assert s.evaluate([0], [[1, 0, 0]], vertices=OCTA_V[:, :2]).shape == (1, 2)  # any per-vertex data


def test_a_mesh_without_faces_has_an_empty_surface():
    s = hybridsub.LimitSurface(np.zeros((3, 3)), np.zeros((0, 3), int))
    P, Du, Dv = s.evaluate(np.zeros(0, int), np.zeros((0, 3)), derivatives=True)
    assert P.shape == Du.shape == (0, 3) and s.evaluation_matrix(np.zeros(0, int), np.zeros((0, 3))).shape == (0, 3)


def split_edge_vertices(tags, V, F, levels=2):
    """The level-``levels`` vertices inside input edges that are split edges beside a √3 face of
    the hybrid, as (face, bary) of their input face, and their sector normals on that face's side
    from the vertices' tangent masks (``limit_normals(per_face_corner=True)``)."""
    from hybridsub._surface.edge_fit import on_split_edge

    s = hybridsub.LimitSurface(V, F, **tags)
    r = hybridsub.refine(F, levels=levels, **tags)
    f0, b0 = r.vertex_origin
    idx, _ = on_split_edge(s._depths, f0, b0)
    NC = hybridsub.limit_normals(V, F, levels=levels, per_face_corner=True, **tags)
    fp = np.asarray(r.face_parent)
    ref = []
    for v in idx:
        rows, cols = np.nonzero(r.faces == v)
        side = np.flatnonzero(fp[rows] == f0[v])[0]
        ref.append(NC[rows[side], cols[side]])
    return s, f0[idx], b0[idx], np.array(ref)


@pytest.mark.parametrize("name", ["fandisk-creases", "border-hybrid"])
def test_normals_on_the_hybrids_creases_are_the_tangent_masks(name):
    """On a split edge beside a √3 face the chart has no derivative across the edge (the walk's
    grew with the depth and its normals were up to 93° off on fandisk's creases): evaluate fits
    exact values there (``edge_fit.py``). Oracle: the refined vertices on those edges, their
    sector normals from the tangent masks; at the default depth."""
    if name == "fandisk-creases":
        V, F = hybridsub.load_example()
        feat = hybridsub.detect_features(V, F, angle=30)
        tags = dict(scheme="hybrid", sharp_edges=feat.sharp_edges, corners=feat.corners)
    else:
        m = hybridsub.read_mesh(pathlib.Path(__file__).parent / "data" / "mesh_with_border.off")
        V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
        tags = dict(scheme="hybrid")
    s, face, bary, ref = split_edge_vertices(tags, V, F)
    pick = np.random.default_rng(0).permutation(len(face))[:400]
    face, bary, ref = face[pick], bary[pick], ref[pick]
    assert len(face) >= 200
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", s.normals(face, bary), ref), -1, 1)))
    assert angle.max() < 0.5 and np.median(angle) < 0.01, (angle.max(), np.median(angle))
    # Along the edge the derivative is the crease curve's: central differences of exact values.
    k = np.argmin(bary, axis=1)
    along = np.zeros_like(bary)
    along[np.arange(len(k)), (k + 1) % 3], along[np.arange(len(k)), (k + 2) % 3] = 1.0, -1.0
    _, Du, Dv = s.evaluate(face, bary, derivatives=True)
    De = along[:, 1:2] * Du + along[:, 2:3] * Dv
    h = 1e-4
    fd = (s.evaluate(face, bary + h * along) - s.evaluate(face, bary - h * along)) / (2 * h)
    assert np.abs(De - fd).max() < 1e-6 * np.abs(fd).max()
    # The rows say the same, to the fit's rounding (the values' over its step, 1e-5 of a face).
    M, Mu, Mv = s.evaluation_matrix(face[:50], bary[:50], derivatives=True)
    assert np.abs(Mu @ V - Du[:50]).max() < 1e-7 * np.abs(Du).max()
    assert np.abs(Mv @ V - Dv[:50]).max() < 1e-7 * np.abs(Dv).max()


def crease_curve_points(V, F, sharp_edges, corners, n, rng):
    """Random points on crease edges (tagged or boundary) whose two ends are crease vertices
    (two crease edges, no corner), and the crease curve there: the uniform cubic B-spline of the
    crease polygon (SCHEME.md's B1 midpoints and B2 (1/8, 3/4, 1/8) vertices, both schemes) at
    the edge parameter t, with its derivative d/dt. Returns face, bary, the halfedge's corner i
    (the point is (1 − t) at corner i, t at corner i + 1), value and derivative."""
    F = np.asarray(F, np.int64)
    he = np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2)
    key = np.sort(he, axis=1) @ np.array([len(V), 1])
    count = np.bincount(np.unique(key, return_inverse=True)[1])[np.unique(key, return_inverse=True)[1]]
    crease = np.isin(key, np.sort(np.asarray(sharp_edges).reshape(-1, 2), axis=1) @ np.array([len(V), 1])) | (count == 1)
    edges = np.unique(np.sort(he[crease], axis=1), axis=0)
    nb = {}
    for a, b in edges:
        nb.setdefault(int(a), []).append(int(b))
        nb.setdefault(int(b), []).append(int(a))
    regular = {v for v, w in nb.items() if len(w) == 2} - {int(c) for c in np.asarray(corners).ravel()}
    ok = np.flatnonzero(crease & np.isin(he[:, 0], list(regular)) & np.isin(he[:, 1], list(regular)))
    pick = rng.choice(ok, min(n, len(ok)), replace=False)
    face, i = pick // 3, pick % 3
    t = rng.uniform(0.01, 0.99, len(pick))
    bary = np.zeros((len(pick), 3))
    bary[np.arange(len(pick)), i], bary[np.arange(len(pick)), (i + 1) % 3] = 1 - t, t
    a, b = he[pick, 0], he[pick, 1]
    p0 = np.array([nb[int(x)][0] if nb[int(x)][0] != y else nb[int(x)][1] for x, y in zip(a, b)])
    p3 = np.array([nb[int(y)][0] if nb[int(y)][0] != x else nb[int(y)][1] for x, y in zip(a, b)])
    T = t[:, None]
    w = np.stack([(1 - T) ** 3, 3 * T**3 - 6 * T**2 + 4, -3 * T**3 + 3 * T**2 + 3 * T + 1, T**3]) / 6
    dw = np.stack([-3 * (1 - T) ** 2, 9 * T**2 - 12 * T, -9 * T**2 + 6 * T + 3, 3 * T**2]) / 6
    X = np.stack([V[p0], V[a], V[b], V[p3]])
    return face, bary, i, (w * X).sum(0), (dw * X).sum(0)


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
@pytest.mark.parametrize("mesh", ["fandisk", "cube-meshed", "mesh_with_border"])
def test_points_on_creases_are_the_crease_curve(scheme, mesh):
    """Oracle: on a crease edge between two crease vertices the limit is the cubic B-spline of the
    crease polygon (its rules see only crease vertices), a computation that shares nothing with
    the walk. At the default depth, random edge parameters: values to 1e-12 × diagonal, the
    derivative along the edge (Loop: the walk's; hybrid: the curve's, ``edge_fit.py``)."""
    if mesh == "fandisk":
        V, F = hybridsub.load_example()
    else:
        m = hybridsub.read_mesh(pathlib.Path(__file__).parent / "data" / f"{mesh}.off")
        V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    feat = hybridsub.detect_features(V, F, angle=30)
    if mesh == "mesh_with_border":  # its boundary, untagged
        feat = hybridsub.detect_features(V, F, angle=180)
    tags = dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
    face, bary, i, P, D = crease_curve_points(V, F, feat.sharp_edges, feat.corners, 300, np.random.default_rng(1))
    assert len(face) >= 60
    s = hybridsub.LimitSurface(V, F, scheme=scheme, **tags)
    Q, Du, Dv = s.evaluate(face, bary, derivatives=True)
    diag = _diag(V)
    assert np.abs(Q - P).max() < 1e-12 * diag
    # d/dt along corner i → i + 1, with (u, v) = (b1, b2): i = 0: Du; 1: Dv − Du; 2: −Dv
    Dt = np.where((i == 0)[:, None], Du, np.where((i == 1)[:, None], Dv - Du, -Dv))
    err = np.linalg.norm(Dt - D, axis=1).max() / np.linalg.norm(D, axis=1).max()
    # hybrid: the curve's own derivative, with the rounding of the fit across the edge mixed in
    # through (u, v) (up to 1.5e-9)
    assert err < (1e-10 if scheme == "loop" else 1e-8), err
