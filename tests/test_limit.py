"""Limit positions and normals.

Three kinds of checks: every mask is the left eigenvector of the local subdivision matrix
read off the project's own refinement; refining many levels converges to the limit at the
rate of the sub-dominant eigenvalue; the limit of a vertex does not depend on the level it is
evaluated at (``levels=``), which ties the stationary masks and the local refinement together.
"""

import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import load_mesh

import hybridsub
from hybridsub import MeshError, analysis
from hybridsub._rules import limit as LR
from hybridsub._rules import step_rules as R
from hybridsub.analysis import _canonical_order, model_neighbourhood


def _left_eig(M, lam):
    """Left eigenvectors of M for eigenvalue lam (columns), from the null space of M^T − lam."""
    u, s, vt = np.linalg.svd(M.T - lam * np.eye(len(M)))
    return vt[s < 1e-9].T


def _in_left_space(M, lam, x):
    return np.abs(x @ M - lam * x).max() < 1e-12 * max(1.0, np.abs(x).max())


# ------------------------------------------------------------------------------ stationary masks

@pytest.mark.parametrize("n", range(3, 21))
def test_kobbelt_masks_are_eigenvectors_of_the_sqrt3_matrix(n):
    M1 = analysis.subdivision_matrix(n, "sqrt3", steps=1)
    M2 = analysis.subdivision_matrix(n, "sqrt3", steps=2)
    b = LR.kobbelt_limit_beta(n)
    mask = np.r_[1 - b, np.full(n, b / n)]
    assert _in_left_space(M1, 1.0, mask) and _in_left_space(M2, 1.0, mask)
    j = np.arange(n)
    c, s = LR.smooth_tangent_weights(n, j)
    lam2 = (2 + 2 * np.cos(2 * np.pi / n)) / 9
    for t in (c, s):
        assert _in_left_space(M2, lam2, np.r_[0.0, t])
    # one step rotates the ring by π/n: cos + i sin is a left eigenvector, eigenvalue (1 + e^{∓2πi/n})/3
    z = np.r_[0.0, c + 1j * s]
    lam1 = (z @ M1)[1] / z[1]
    assert np.allclose(z @ M1, lam1 * z, atol=1e-12)
    assert np.isclose(abs(lam1), np.sqrt(lam2))


@pytest.mark.parametrize("weights", ["loop", "warren"])
@pytest.mark.parametrize("n", range(3, 21))
def test_loop_masks_are_eigenvectors_of_the_loop_matrix(n, weights):
    M = analysis.subdivision_matrix(n, "loop", loop_weights=weights)
    chi = LR.loop_limit_chi(n, weights)
    assert _in_left_space(M, 1.0, np.r_[1 - n * chi, np.full(n, chi)])
    c, s = LR.smooth_tangent_weights(n, np.arange(n))
    lam = (3 + 2 * np.cos(2 * np.pi / n)) / 8
    assert _in_left_space(M, lam, np.r_[0.0, c]) and _in_left_space(M, lam, np.r_[0.0, s])


@pytest.mark.parametrize("scheme", ["loop", "sqrt3"])
@pytest.mark.parametrize("k", range(1, 13))
def test_crease_and_kobbelt_boundary_masks(scheme, k):
    steps = 2 if scheme == "sqrt3" else 1
    M = analysis.subdivision_matrix(k, scheme, steps=steps, crease=True)
    np.testing.assert_allclose(M, LR.sector_matrix(k, scheme), atol=1e-15)
    # limit: the cubic B-spline (1/6, 2/3, 1/6) on the curve, in both schemes
    lim = np.zeros(k + 2)
    lim[0], lim[1], lim[k + 1] = 2 / 3, 1 / 6, 1 / 6
    assert _in_left_space(M, 1.0, lim)
    assert _left_eig(M, 1.0).shape[1] == 1
    # along the crease: q_0 − q_k; across: the closed form
    along = np.zeros(k + 2)
    along[1], along[k + 1] = 1.0, -1.0
    assert _in_left_space(M, 0.5 if scheme == "loop" else 1 / 3, along)
    a, b = LR.sector_across_weights(k, scheme)
    across = np.r_[a[0], b[0], np.sin(np.pi * np.arange(1, k) / k), b[0]]
    assert _in_left_space(M, float(LR.sector_across_eigenvalue(k, scheme)), across)
    assert abs(across.sum()) < 1e-12  # a direction: insensitive to translation


def _dart_matrix_from_refine(n, weights):
    V, F, ring = model_neighbourhood(n, 4)
    r = hybridsub.refine(F, [[0, 1]], 1, n_vertices=len(V), scheme="loop", loop_weights=weights)
    V2 = r.apply(V)
    cols, _ = _canonical_order(V, F, len(V), 1, False)
    rows, _ = _canonical_order(V2, r.faces, len(V2), 1, False)
    return r.matrix.tocsr()[rows][:, cols].toarray()


@pytest.mark.parametrize("weights", ["loop", "warren"])
@pytest.mark.parametrize("n", [3, 4, 5, 6, 7, 9, 12, 20])
def test_loop_dart_masks(n, weights):
    M = _dart_matrix_from_refine(n, weights)
    np.testing.assert_allclose(M, LR.dart_matrix(n, weights), atol=1e-15)
    lim, ts, ta = LR.dart_masks(n, weights)
    assert _in_left_space(M, 1.0, lim) and np.isclose(lim.sum(), 1) and (lim > 0).all()
    ev = np.sort(np.abs(np.linalg.eigvals(M)))[::-1]
    lam_s = (ts @ M)[np.argmax(np.abs(ts))] / ts[np.argmax(np.abs(ts))]
    lam_a = (ta @ M)[np.argmax(np.abs(ta))] / ta[np.argmax(np.abs(ta))]
    assert _in_left_space(M, lam_s, ts) and _in_left_space(M, lam_a, ta)
    # the two tangents are the sub-dominant pair
    assert np.allclose(sorted([lam_s, lam_a], reverse=True), ev[1:3])


# --------------------------------------------------------------------- convergence to the limit

def _errors(V, F, levels, scheme, **kw):
    P = hybridsub.limit_positions(V, F, scheme=scheme, **kw)
    r = hybridsub.refine(F, kw.pop("sharp_edges", None), levels, n_vertices=len(V), scheme=scheme, **kw)
    X, out = V.copy(), [np.abs(V - P).max()]
    for st in r.steps:
        X = st.matrix @ X
        out.append(np.abs(X[: len(V)] - P).max())
    return np.array(out)


@pytest.mark.parametrize("name,n", [("tetrahedron", 3), ("octahedron", 4), ("icosahedron", 5)])
def test_refinement_converges_at_the_subdominant_rate(name, n):
    V, F = load_mesh(name)
    # √3: the centre's eigenvalue 2/3 − α_n per step; Loop: (3/8 + cos(2π/n)/4)² per step
    for scheme, rate, levels in (("sqrt3", 2 / 3 - R.kobbelt_alpha(n), 7), ("loop", (3 / 8 + np.cos(2 * np.pi / n) / 4) ** 2, 6),
                                 ("hybrid", 2 / 3 - R.kobbelt_alpha(n), 7)):
        e = _errors(V, F, levels, scheme)
        np.testing.assert_allclose(e[2:] / e[1:-1], rate, rtol=1e-6)


def test_open_and_creased_meshes_converge():
    V, F = load_mesh("mesh_with_border")
    for scheme, levels in (("loop", 4), ("hybrid", 4), ("sqrt3", 5)):
        e = _errors(V, F, levels, scheme)
        assert e[-1] < 0.15 * e[1], (scheme, e)
        if scheme == "sqrt3":  # Kobbelt's boundary: two steps at a time
            assert (e[3::2] < e[1:-2:2]).all()
        else:
            assert (np.diff(e[1:]) < 0).all()
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F)
    for scheme in ("loop", "hybrid"):
        e = _errors(V, F, 3, scheme, sharp_edges=feat.sharp_edges, corners=feat.corners)
        assert e[-1] < 0.05 * e[0] and (np.diff(e) < 0).all()


def test_cube_faces_stay_flat_and_edges_straight():
    # Why detect_features tags no sharp faces: √3 keeps planar regions bounded by creases flat.
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F)
    lo, hi = V.min(axis=0), V.max(axis=0)
    for scheme in ("hybrid", "loop"):
        P = hybridsub.limit_positions(V, F, feat.sharp_edges, corners=feat.corners, scheme=scheme)
        on = np.isclose(V, lo) | np.isclose(V, hi)
        assert np.allclose(P[on], V[on], atol=1e-12)  # coordinates fixed by a face plane stay
        N = hybridsub.limit_normals(V, F, feat.sharp_edges, corners=feat.corners, scheme=scheme, per_face_corner=True)
        fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        fn /= np.linalg.norm(fn, axis=1)[:, None]
        assert np.allclose(N, fn[:, None, :], atol=1e-12)  # each side of a crease: its plane
        Nv = hybridsub.limit_normals(V, F, feat.sharp_edges, corners=feat.corners, scheme=scheme)
        c = V - (lo + hi) / 2
        expect = np.where(on, np.sign(c), 0.0)
        expect /= np.linalg.norm(expect, axis=1)[:, None]
        assert np.allclose(Nv[on.any(axis=1)], expect[on.any(axis=1)], atol=1e-12)


def _tagged_octahedron():
    V, F = load_mesh("octahedron")
    return V, F, np.array([F[0, :2]])


def test_darts_mixed_and_semisharp_converge():
    V, F, e = _tagged_octahedron()
    # Loop: a dart's eigenvector mask; hybrid: the dart's valence grows, refined locally
    for scheme in ("loop", "hybrid"):
        err = _errors(V, F, 7, scheme, sharp_edges=e)
        assert err[-1] < 1e-2 * err[1] and (np.diff(err[1:]) < 0).all(), (scheme, err)
        if scheme == "loop":  # the error shrinks by the dart's sub-dominant eigenvalue
            lam = np.sort(np.abs(np.linalg.eigvals(LR.dart_matrix(4))))[-2]
            np.testing.assert_allclose(err[-1] / err[-2], lam, rtol=1e-2)
    # mixed vertices: a few sharp faces
    err = _errors(V, F, 7, "hybrid", sharp_faces=[0, 1])
    assert err[-1] < 1e-2 * err[1]
    # semi-sharp creases decay, then the masks apply
    V, F = load_mesh("icosahedron")
    e = np.array([[F[0, 0], F[0, 1]], [F[0, 1], F[0, 2]], [F[5, 0], F[5, 1]], [F[9, 1], F[9, 2]]])
    s = np.array([0.3, 1.6, 2.5, np.inf])
    for scheme in ("loop", "hybrid"):
        err = _errors(V, F, 6, scheme, sharp_edges=e, sharpness=s)
        assert err[-1] < 0.05 * err[1] and (np.diff(err[3:]) < 0).all(), (scheme, err)


CASES = {
    "sqrt3-border": ("mesh_with_border", "sqrt3", {}),
    "hybrid-border": ("mesh_with_border", "hybrid", {}),
    "loop-dart": ("octahedron", "loop", {"sharp_edges": [[0, 1]]}),
    "hybrid-dart": ("octahedron", "hybrid", {"sharp_edges": [[0, 1]]}),
    "hybrid-mixed": ("octahedron", "hybrid", {"sharp_faces": [0, 1, 5]}),
    "loop-semisharp": ("octahedron", "loop", {"sharp_edges": [[0, 1], [1, 2], [2, 0]], "sharpness": [0.4, 1.7, 2.5]}),
    "hybrid-semisharp": ("octahedron", "hybrid", {"sharp_edges": [[0, 1], [1, 2], [2, 0]],
                                                  "sharpness": [0.4, 1.7, 2.5], "sharp_faces": [3]}),
    "hybrid-corner": ("icosahedron", "hybrid", {"sharp_edges": [[0, 1]], "corners": [0, 5]}),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("levels", [1, 2])
def test_limit_does_not_depend_on_the_level_it_is_taken_at(case, levels):
    name, scheme, kw = CASES[case]
    V, F = load_mesh(name)
    if name == "octahedron" and "sharp_edges" in kw:
        kw = dict(kw, sharp_edges=np.array(kw["sharp_edges"]))
    P0 = hybridsub.limit_positions(V, F, scheme=scheme, **kw)
    PL = hybridsub.limit_positions(V, F, scheme=scheme, levels=levels, **kw)
    assert np.abs(PL[: len(V)] - P0).max() < 1e-10
    # and the matrix form composes with refine: L_levels == L(level-L mesh) @ r.matrix, its first rows == L_0
    L0 = hybridsub.limit_matrix(F, kw.get("sharp_edges"), scheme=scheme, **{k: v for k, v in kw.items() if k != "sharp_edges"})
    LL = hybridsub.limit_matrix(F, kw.get("sharp_edges"), levels=levels, scheme=scheme,
                                **{k: v for k, v in kw.items() if k != "sharp_edges"})
    assert abs(LL[: len(V)] - L0).max() < 1e-10
    np.testing.assert_allclose(LL @ V, PL, atol=1e-12)
    if scheme != "sqrt3":  # hybrid/loop: the refined mesh with its tags is a valid input
        r = hybridsub.refine(F, kw.get("sharp_edges"), levels, scheme=scheme,
                             **{k: v for k, v in kw.items() if k != "sharp_edges"})
        P2 = hybridsub.limit_positions(r.apply(V), r.faces, r.sharp_edges, scheme=scheme, sharpness=r.sharpness,
                                       sharp_faces=r.sharp_faces, corners=r.corners)
        np.testing.assert_allclose(P2, PL, atol=1e-12)


def test_matrix_properties_and_apply():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F)
    for scheme in ("hybrid", "loop", "sqrt3"):
        tags = {} if scheme == "sqrt3" else {"sharp_edges": feat.sharp_edges, "corners": feat.corners}
        L = hybridsub.limit_matrix(F, n_vertices=len(V), scheme=scheme, **tags)
        assert sp.isspmatrix_csr(L) and L.shape == (len(V), len(V)) and L.has_sorted_indices
        np.testing.assert_allclose(L.sum(axis=1).A1, 1.0, atol=1e-12)
        assert L.data.min() > -1e-12
        P = hybridsub.limit_positions(V, F, scheme=scheme, **tags)
        np.testing.assert_allclose(L @ V, P, atol=1e-12)
    P = hybridsub.limit_positions(V, F, feature_angle=30)
    np.testing.assert_allclose(P, hybridsub.limit_positions(V, F, feat.sharp_edges, corners=feat.corners), atol=0)


# ----------------------------------------------------------------------------------- normals

def _sphere(levels=2):
    V, F = load_mesh("icosahedron")
    V, F = hybridsub.subdivide(V, F, levels=levels, scheme="loop")
    V = V / np.linalg.norm(V, axis=1)[:, None]
    V = V * (1 + 0.15 * np.sin(3 * V[:, :1]) * np.cos(2 * V[:, 1:2]))  # not a sphere: a bumpy one
    return V, F


def _vertex_normals(V, F):
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N = np.zeros_like(V)
    for i in range(3):
        np.add.at(N, F[:, i], fn)
    return N / np.linalg.norm(N, axis=1)[:, None]


@pytest.mark.parametrize("scheme", ["loop", "sqrt3"])
def test_normals_converge_on_a_closed_smooth_mesh(scheme):
    V, F = _sphere()
    N = hybridsub.limit_normals(V, F, scheme=scheme)
    assert np.allclose(np.linalg.norm(N, axis=1), 1)
    assert (np.einsum("ij,ij->i", N, V) > 0).all()  # outward, as the faces face
    err = []
    for L in range(1, 6 if scheme == "loop" else 7):
        V2, F2 = hybridsub.subdivide(V, F, levels=L, scheme=scheme)
        err.append(np.abs(_vertex_normals(V2, F2)[: len(V)] - N).max())
    err = np.array(err)
    assert (np.diff(err) < 0).all() and err[-1] < 0.02 * err[0], err
    # the faces turned around: the normals too
    np.testing.assert_allclose(hybridsub.limit_normals(V, F[:, ::-1], scheme=scheme), -N, atol=1e-12)


def _sector_fan_normals(V, F, levels, scheme, **kw):
    """Per level-0 face corner: the normal of the refined control fan around its vertex, on its side."""
    n = len(V)
    r = hybridsub.refine(F, kw.pop("sharp_edges", None), levels, n_vertices=n, scheme=scheme, **kw)
    X = r.apply(V)
    FL = r.faces
    fn = np.cross(X[FL[:, 1]] - X[FL[:, 0]], X[FL[:, 2]] - X[FL[:, 0]])
    return X, FL, fn, r.face_parent


def test_loop_crease_sector_normals_converge():
    # Sectors of at most 3 faces: the crease tangent and the across tangent span the tangent plane.
    V, F = load_mesh("mesh_with_border")
    Nc = hybridsub.limit_normals(V, F, scheme="loop", per_face_corner=True)
    n = len(V)
    from hybridsub._surface.limit_setup import setup_limit
    from hybridsub._surface.mask_plan import plan_level
    s = setup_limit(F, None, 0, n, "loop", None, None, None, "loop")
    pl = plan_level(s.level, s.esharp, s.face_sharp, s.corner, "loop", "loop")
    k = pl.sectors.n_faces
    sec_n = np.zeros((len(k), 3))
    sec_n[pl.sectors.he_sector] = Nc.reshape(-1, 3)
    boundary_small = (pl.sec_kind == 2) & (k <= 3)
    assert boundary_small.sum() > 20
    he_sec = pl.sectors.he_sector.reshape(-1, 3)
    errs = []
    for L in (2, 3, 4):
        X, FL, fn, parent = _sector_fan_normals(V, F, L, "loop")
        acc = np.zeros_like(sec_n)
        for i in range(3):
            m = FL[:, i] < n
            pf = parent[m]
            pos = np.argmax(F[pf] == FL[m, i][:, None], axis=1)
            np.add.at(acc, he_sec[pf, pos], fn[m])
        acc /= np.linalg.norm(acc, axis=1)[:, None]
        errs.append(np.abs(acc - sec_n)[boundary_small].max())
    assert errs[1] < 0.6 * errs[0] and errs[2] < 0.6 * errs[1], errs  # halves per level


def _evolve_sector_estimate(V, F, center, crease, levels):
    """Independent of hybridsub._surface: refine the star of a crease vertex again and again with
    hybridsub.refine and return (Σ e_j) × (Σ j e_j) of the sector starting at crease[0]."""
    P, Fl, c, a = V.copy(), F.copy(), center, crease[0]
    se = np.array([[center, crease[0]], [center, crease[1]]])
    for _ in range(levels):
        P = P - P[c]
        r = hybridsub.refine(Fl, se, 1, n_vertices=len(P))
        Pn = r.apply(P)
        star = np.flatnonzero((r.faces == c).any(axis=1))
        Fk = r.faces[star]
        used, inv = np.unique(Fk, return_inverse=True)
        new = np.full(len(Pn), -1)
        new[used] = np.arange(len(used))
        cands = [int(x) for e in r.sharp_edges for x in e if c in e and x != c]
        a_new = max(cands, key=lambda x: np.dot(Pn[x] - Pn[c], P[a] - P[c]))
        keep = (new[r.sharp_edges] >= 0).all(axis=1)
        se = new[r.sharp_edges[keep]]
        Fl, P, c, a = inv.reshape(-1, 3), Pn[used], int(new[c]), int(new[a_new])
    nxt = {int(f[(list(f).index(c) + 1) % 3]): int(f[(list(f).index(c) + 2) % 3]) for f in Fl}
    crease_nb = {int(x) for e in se for x in e if c in e and x != c}
    ring = [a]
    while True:
        ring.append(nxt[ring[-1]])
        if ring[-1] in crease_nb:
            break
    e = P[ring] - P[c]
    return np.cross(e.sum(0), (np.arange(len(ring))[:, None] * e).sum(0))


@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_sqrt3_crease_sector_normal_is_the_limit_of_the_fan_normal(k):
    # A crease vertex with k smooth faces on one side, on a curved, irregular surface.
    rng = np.random.default_rng(k)
    th = np.r_[np.linspace(0, np.pi, k + 1), np.linspace(np.pi, 2 * np.pi, 5)[1:-1]]
    th[1:k] += 0.1 * rng.standard_normal(k - 1)
    p = 0.3 * np.c_[np.cos(th), np.sin(th)]
    V = np.vstack([[0, 0, 0], np.c_[p, p[:, 0] ** 2 + 0.5 * p[:, 1] ** 2 + 0.3 * p[:, 0] * p[:, 1]]])
    m = len(th)
    F = np.array([[0, 1 + i, 1 + (i + 1) % m] for i in range(m)])
    crease = [[0, 1], [0, 1 + k]]
    Nc = hybridsub.limit_normals(V, F, crease, per_face_corner=True)
    expect = Nc[0, 0]  # face 0 lies in the sector of k faces
    est = _evolve_sector_estimate(V, F, 0, [1, 1 + k], 70)
    np.testing.assert_allclose(est / np.linalg.norm(est), expect, atol=1e-9)
    # and the refined fan's own normal creeps towards it (like 1/levels: no tangent plane here)
    dev = []
    for L in (4, 8):
        X, FL, fn, parent = _sector_fan_normals(V, F, L, "hybrid", sharp_edges=np.array(crease))
        side = (FL == 0).any(axis=1) & (parent < k)
        f = fn[side].sum(0)
        dev.append(np.linalg.norm(f / np.linalg.norm(f) - expect))
    assert dev[1] < dev[0] or dev[0] < 1e-12


def test_normals_edge_cases():
    V, F = load_mesh("tetrahedron")
    V = np.vstack([V, [[5.0, 5, 5]]])  # an unused vertex
    N = hybridsub.limit_normals(V, F)
    assert np.allclose(N[-1], 0) and np.allclose(np.linalg.norm(N[:-1], axis=1), 1)
    P = hybridsub.limit_positions(V, F)
    assert np.allclose(P[-1], V[-1])
    Nc = hybridsub.limit_normals(V, F, per_face_corner=True)
    assert Nc.shape == (4, 3, 3) and np.allclose(Nc, N[F])
    # levels: normals of the level-L vertices; the old vertices keep theirs
    N2 = hybridsub.limit_normals(V, F, levels=2)
    np.testing.assert_allclose(N2[: len(V)], N, atol=1e-10)
    N3 = hybridsub.limit_normals(V, F, levels=1, scheme="sqrt3", per_face_corner=True)
    assert N3.shape == (12, 3, 3)


def test_bad_input():
    V, F = load_mesh("octahedron")
    V.setflags(write=False)
    F.setflags(write=False)
    with pytest.raises(MeshError, match="not an edge of the mesh"):
        hybridsub.limit_positions(V, F, [[0, 5]])
    with pytest.raises(ValueError, match="without feature tags"):
        hybridsub.limit_matrix(F, [[0, 1]], scheme="sqrt3")
    with pytest.raises(ValueError, match="tol must be positive"):
        hybridsub.limit_normals(V, F, tol=0)
    with pytest.raises(ValueError, match="max_levels must be a positive integer"):
        hybridsub.limit_positions(V, F, max_levels=0)
    with pytest.raises(MeshError, match=r"V must have shape \(n, 3\)"):
        hybridsub.limit_normals(V[:, :2], F)
    with pytest.raises(ValueError, match="levels must be a non-negative integer"):
        hybridsub.limit_matrix(F, levels=-1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hybridsub.limit_positions(V, F, sharp_faces=[0])  # read-only arrays, no warning
    with pytest.warns(RuntimeWarning, match="did not converge"):
        hybridsub.limit_positions(V, F, sharp_faces=[0], max_levels=2)


def test_dart_mixed_and_fin_normals():
    # Darts and mixed vertices of the hybrid scheme: the control fan's normal after FAN_LEVELS
    # local levels (no tangent plane there); stable, unit, on the side the faces face.
    from hybridsub._surface.local import FAN_LEVELS
    V, F = _sphere(1)
    e = np.array([F[0, :2]])
    for kw in ({"sharp_edges": e}, {"sharp_faces": np.arange(0, len(F), 3)}):
        N = hybridsub.limit_normals(V, F, **kw)
        assert np.allclose(np.linalg.norm(N, axis=1), 1)
        assert (np.einsum("ij,ij->i", N, _vertex_normals(V, F)) > 0.9).all()
        np.testing.assert_allclose(hybridsub.limit_normals(V, F, max_levels=FAN_LEVELS + 20, **kw), N, atol=1e-12)
    # A crease that turns back on itself (a fin): its two sides face opposite ways; the vertex
    # gets its control fan's normal rather than a zero vector.
    V = np.array([[0, 0, 0], [1, 0.1, 0], [1, -0.1, 0], [0.5, 0, 1], [0.5, 0, -1]], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [0, 4, 1], [0, 2, 4], [1, 2, 3], [2, 1, 4]])
    N = hybridsub.limit_normals(V, F, [[0, 1], [0, 2]], corners=[0], scheme="loop")
    assert np.isclose(np.linalg.norm(N[0]), 1)
