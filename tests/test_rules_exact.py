"""Hand-computed exact cases for every rule of the scheme (docs/scheme.md, SCHEME.md).

Each test builds a tiny mesh by hand, writes the expected weights from the rule's formula
(exact fractions where the rule is rational) and compares them with rows of the step matrix
S (``V_{k+1} = S V_k``), so most checks do not depend on positions. Where the index layout is
not the point of a test, an output vertex is located by its row (``find_row``); the layout
itself is pinned in the ``test_layout_*`` tests.
"""

import math
from fractions import Fraction as Fr

import numpy as np
import pytest

import hybridsub

TOL = 1e-12


# --------------------------------------------------------------------------- formulas
def kobbelt_alpha(n):
    """R3: alpha_n = (4 - 2 cos(2 pi / n)) / 9."""
    return (4 - 2 * math.cos(2 * math.pi / n)) / 9


def loop_beta(n):
    """Loop region, loop_weights="loop": beta_n = (5/8 - (3/8 + 1/4 cos(2 pi / n))^2) / n."""
    return (5 / 8 - (3 / 8 + 1 / 4 * math.cos(2 * math.pi / n)) ** 2) / n


def warren_beta(n):
    """Loop region, loop_weights="warren": beta_3 = 3/16, beta_n = 3/(8n)."""
    return Fr(3, 16) if n == 3 else Fr(3, 8 * n)


def mixed_alpha(n):
    """Mixed table: 9/16 (n = 3), 3/8 (n = 4, 5), Kobbelt's alpha_n (n >= 6)."""
    if n == 3:
        return Fr(9, 16)
    if n in (4, 5):
        return Fr(3, 8)
    return kobbelt_alpha(n)


def smooth_row(v, nbrs, alpha):
    """(1 - alpha) v + alpha/n sum p_i."""
    n = len(nbrs)
    row = {v: 1 - alpha}
    for p in nbrs:
        row[p] = alpha / n
    return row


def loop_row(v, nbrs, beta):
    """(1 - n beta) v + beta sum p_i."""
    row = {v: 1 - len(nbrs) * beta}
    for p in nbrs:
        row[p] = beta
    return row


def crease_row(v, a, b):
    """B2: 3/4 v + 1/8 (a + b)."""
    return {v: Fr(3, 4), a: Fr(1, 8), b: Fr(1, 8)}


def blend(w, r1, r2):
    """w * r1 + (1 - w) * r2 (rows as dicts)."""
    out = {}
    for k, x in r1.items():
        out[k] = out.get(k, 0) + w * x
    for k, x in r2.items():
        out[k] = out.get(k, 0) + (1 - w) * x
    return out


# --------------------------------------------------------------------------- helpers
def dense(S):
    return S.toarray() if hasattr(S, "toarray") else np.asarray(S, dtype=float)


def as_vec(n_cols, weights):
    r = np.zeros(n_cols)
    for j, w in weights.items():
        r[j] += float(w)
    return r


def fmt(row):
    nz = np.flatnonzero(np.abs(row) > TOL)
    return "{" + ", ".join(f"{j}: {row[j]:.15g}" for j in nz) + "}"


def fmt_exp(weights):
    return "{" + ", ".join(f"{j}: {float(w):.15g}" for j, w in sorted(weights.items())) + "}"


def assert_row(S, i, weights, what=""):
    D = dense(S)
    exp = as_vec(D.shape[1], weights)
    assert np.allclose(D[i], exp, atol=TOL, rtol=0), (
        f"{what}: row {i} expected {fmt_exp(weights)}, got {fmt(D[i])}"
    )


def find_rows(S, weights):
    D = dense(S)
    exp = as_vec(D.shape[1], weights)
    return np.flatnonzero(np.all(np.abs(D - exp) <= TOL, axis=1))


def find_row(S, weights, what=""):
    hits = find_rows(S, weights)
    if len(hits) != 1:
        D = dense(S)
        cols = sorted(weights)
        # rows with the same support, to say what came instead
        supp = np.abs(D) > TOL
        want = np.zeros(D.shape[1], bool)
        want[cols] = True
        same = np.flatnonzero(np.all(supp[:, want], axis=1) & (supp.sum(1) == len(cols)))
        got = "; ".join(f"row {k}: {fmt(D[k])}" for k in same[:6]) or "none with that support"
        raise AssertionError(
            f"{what}: expected exactly one output vertex with row {fmt_exp(weights)}, "
            f"found {hits.tolist()} (rows with the same support: {got})"
        )
    return int(hits[0])


def canon(t):
    """A triangle up to rotation (orientation kept)."""
    t = tuple(int(x) for x in t)
    k = t.index(min(t))
    return t[k:] + t[:k]


def tri_set(F):
    return {canon(t) for t in np.asarray(F)}


def edge_set(F):
    return {
        frozenset((int(a), int(b)))
        for t in np.asarray(F)
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))
    }


def nbrs_of(F, v):
    return sorted({int(x) for t in np.asarray(F) if v in t for x in t if x != v})


def n_tagged(sharp_edges):
    return 0 if sharp_edges is None else len(np.asarray(sharp_edges).reshape(-1, 2))


def step1(F, n, **kw):
    return hybridsub.refine(np.asarray(F), levels=1, n_vertices=n, **kw)


# --------------------------------------------------------------------------- meshes
TET_V = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
TET_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])

# octahedron: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z
OCT_V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
OCT_F = np.array(
    [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
)
OCT_NBRS = {0: [2, 3, 4, 5], 1: [2, 3, 4, 5], 2: [0, 1, 4, 5], 3: [0, 1, 4, 5], 4: [0, 1, 2, 3], 5: [0, 1, 2, 3]}

_T = (1 + 5**0.5) / 2
ICO_V = np.array(
    [[-1, _T, 0], [1, _T, 0], [-1, -_T, 0], [1, -_T, 0], [0, -1, _T], [0, 1, _T],
     [0, -1, -_T], [0, 1, -_T], [_T, 0, -1], [_T, 0, 1], [-_T, 0, -1], [-_T, 0, 1]]
)
ICO_F = np.array(
    [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
     [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
     [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
)


def bipyramid(n):
    """Ring 0..n-1, apex T = n (valence n), apex B = n+1 (valence n); ring vertices valence 4.
    Faces 0..n-1: (i, i+1, T); faces n..2n-1: (i+1, i, B)."""
    T, B = n, n + 1
    F = [(i, (i + 1) % n, T) for i in range(n)] + [((i + 1) % n, i, B) for i in range(n)]
    ang = 2 * np.pi * np.arange(n) / n
    V = np.vstack([np.c_[np.cos(ang), np.sin(ang), np.zeros(n)], [[0, 0, 1], [0, 0, -1]]])
    return V, np.array(F)


def torus(k=4):
    """k x k regular torus grid: every vertex has valence 6. Vertex (i, j) = i*k + j."""
    idx = lambda i, j: (i % k) * k + (j % k)  # noqa: E731
    F = []
    for i in range(k):
        for j in range(k):
            F.append((idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)))
            F.append((idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)))
    return np.array(F), idx


def hex_fan():
    """Open hexagonal fan: centre 0, boundary ring 1..6; face f = (0, f+1, (f+1)%6+1)."""
    ang = np.pi / 3 * np.arange(6)
    V = np.vstack([[0, 0, 0], np.c_[np.cos(ang), np.sin(ang), np.zeros(6)]])
    F = np.array([(0, i, i % 6 + 1) for i in range(1, 7)])
    return V, F


def ring_next(i):
    return i % 6 + 1


def ring_prev(i):
    return (i - 2) % 6 + 1


def _check_manifold_closed(F):
    he = [(int(t[a]), int(t[(a + 1) % 3])) for t in F for a in range(3)]
    assert len(set(he)) == len(he)
    assert all((b, a) in set(he) for a, b in he)


def test_hand_meshes_are_what_they_claim():
    # sanity of the fixtures themselves (consistent orientation, closed, valences)
    for F in (TET_F, OCT_F, ICO_F, bipyramid(3)[1], bipyramid(12)[1], torus()[0]):
        _check_manifold_closed(F)
    assert all(len(nbrs_of(ICO_F, v)) == 5 for v in range(12))
    Ft, _ = torus()
    assert all(len(nbrs_of(Ft, v)) == 6 for v in range(16))
    for v, nb in OCT_NBRS.items():
        assert nbrs_of(OCT_F, v) == nb


# =========================================================================== R1
@pytest.mark.parametrize("scheme", ["hybrid", "sqrt3"])
def test_R1_face_point_tetrahedron(scheme):
    # R1: every smooth face (a,b,c) of a closed untagged mesh gets (a+b+c)/3, row 1/3,1/3,1/3.
    V2, F2, S = hybridsub.subdivide(TET_V, TET_F, scheme=scheme, return_matrix=True)
    assert S.shape == (8, 4)
    for f, (a, b, c) in enumerate(TET_F):
        i = find_row(S, {a: Fr(1, 3), b: Fr(1, 3), c: Fr(1, 3)}, f"R1 face point of face {f}")
        np.testing.assert_allclose(V2[i], TET_V[[a, b, c]].sum(0) / 3, atol=TOL)


# =========================================================================== R3
@pytest.mark.parametrize("scheme", ["hybrid", "sqrt3"])
@pytest.mark.parametrize(
    "name,F,nbrs",
    [
        ("tetrahedron n=3", TET_F, {v: [u for u in range(4) if u != v] for v in range(4)}),
        ("octahedron n=4", OCT_F, OCT_NBRS),
        ("icosahedron n=5", ICO_F, {v: nbrs_of(ICO_F, v) for v in range(12)}),
    ],
)
def test_R3_sqrt3_vertex_platonic(scheme, name, F, nbrs):
    # R3 in the sqrt3 region: v' = (1 - a_n) v + a_n/n sum p_i, a_n = (4 - 2cos(2pi/n))/9.
    # n=3: a=5/9; n=4: a=4/9; n=5: a=(4-2cos72)/9.
    assert abs(kobbelt_alpha(3) - 5 / 9) < 1e-15
    assert abs(kobbelt_alpha(4) - 4 / 9) < 1e-15
    r = step1(F, len(nbrs), scheme=scheme)
    for v, nb in nbrs.items():
        assert_row(r.matrix, v, smooth_row(v, nb, kobbelt_alpha(len(nb))), f"R3 {name} vertex {v}")


@pytest.mark.parametrize("scheme", ["hybrid", "sqrt3"])
def test_R3_sqrt3_vertex_valence6_torus(scheme):
    # R3 at valence 6 on a regular closed mesh: a_6 = (4 - 2*1/2)/9 = 1/3,
    # so v' = 2/3 v + 1/18 each of the six neighbours (i+-1,j), (i,j+-1), (i+1,j+1), (i-1,j-1).
    F, idx = torus(4)
    assert abs(kobbelt_alpha(6) - 1 / 3) < 1e-15
    r = step1(F, 16, scheme=scheme)
    for i in range(4):
        for j in range(4):
            v = idx(i, j)
            nb = [idx(i + 1, j), idx(i - 1, j), idx(i, j + 1), idx(i, j - 1),
                  idx(i + 1, j + 1), idx(i - 1, j - 1)]
            row = {v: Fr(2, 3)}
            row.update({p: Fr(1, 18) for p in nb})
            assert_row(r.matrix, v, row, f"R3 torus valence 6 vertex {v}")


@pytest.mark.parametrize("n", [3, 5, 6, 7, 12])
def test_R3_sqrt3_vertex_bipyramid(n):
    # R3 at the apexes of an n-bipyramid (valence n, e.g. n=12: a = (4 - sqrt3)/9) and at the
    # ring vertices (valence 4: a = 4/9), all faces smooth, no tags (hybrid).
    V, F = bipyramid(n)
    r = step1(F, n + 2)
    ring = list(range(n))
    for apex in (n, n + 1):
        assert_row(r.matrix, apex, smooth_row(apex, ring, kobbelt_alpha(n)), f"R3 apex n={n}")
    if n == 12:
        assert abs(kobbelt_alpha(12) - (4 - 3**0.5) / 9) < 1e-15
    for i in ring:
        nb = [(i - 1) % n, (i + 1) % n, n, n + 1]
        assert_row(r.matrix, i, smooth_row(i, nb, Fr(4, 9)), f"R3 ring vertex {i} (n=4)")


# =========================================================================== Loop region
@pytest.mark.parametrize("n", [3, 4, 5, 6, 7])
@pytest.mark.parametrize("loop_weights", ["loop", "warren"])
@pytest.mark.parametrize("how", ["hybrid all sharp", "loop"])
def test_loop_region_vertex(n, loop_weights, how):
    # Loop region (all faces sharp): v' = (1 - n b) v + b sum p_i,
    # "loop": b_n = (5/8 - (3/8 + 1/4 cos(2pi/n))^2)/n; "warren": b_3 = 3/16, b_n = 3/(8n).
    # Apexes have valence n, ring vertices valence 4.
    assert abs(loop_beta(3) - 3 / 16) < 1e-15  # (5/8 - 1/16)/3
    assert abs(loop_beta(4) - 31 / 256) < 1e-15  # (5/8 - 9/64)/4
    assert abs(loop_beta(6) - 1 / 16) < 1e-15  # (5/8 - 1/4)/6
    V, F = bipyramid(n)
    kw = dict(scheme="loop") if how == "loop" else dict(sharp_faces=np.ones(len(F), bool))
    r = step1(F, n + 2, loop_weights=loop_weights, **kw)
    beta = loop_beta if loop_weights == "loop" else warren_beta
    ring = list(range(n))
    for apex in (n, n + 1):
        assert_row(r.matrix, apex, loop_row(apex, ring, beta(n)),
                   f"Loop region ({loop_weights}, {how}) apex valence {n}")
    for i in ring:
        nb = [(i - 1) % n, (i + 1) % n, n, n + 1]
        assert_row(r.matrix, i, loop_row(i, nb, beta(4)),
                   f"Loop region ({loop_weights}, {how}) ring vertex valence 4")


def test_loop_region_and_sqrt3_region_in_one_hybrid_mesh():
    # Hybrid, bipyramid n=5 with the whole top fan sharp: top apex is in the Loop region
    # (b_5 "loop"), bottom apex in the sqrt3 region (a_5), ring vertices are mixed (n=4: a=3/8).
    n = 5
    V, F = bipyramid(n)
    mask = np.zeros(2 * n, bool)
    mask[:n] = True
    r = step1(F, n + 2, sharp_faces=mask)
    ring = list(range(n))
    assert_row(r.matrix, n, loop_row(n, ring, loop_beta(5)), "Loop-region apex")
    assert_row(r.matrix, n + 1, smooth_row(n + 1, ring, kobbelt_alpha(5)), "sqrt3-region apex")
    for i in ring:
        nb = [(i - 1) % n, (i + 1) % n, n, n + 1]
        assert_row(r.matrix, i, smooth_row(i, nb, Fr(3, 8)), f"mixed ring vertex {i}")


# =========================================================================== mixed table
@pytest.mark.parametrize("n", [3, 4, 5, 6, 7])
@pytest.mark.parametrize("loop_weights", ["loop", "warren"])
def test_mixed_vertex_table(n, loop_weights):
    # Mixed smooth vertex (some faces sharp, some smooth): (1 - a) v + a/n sum p_i with
    # a = 9/16 (n=3), 3/8 (n=4,5), Kobbelt a_n (n>=6); the table does not depend on loop_weights.
    # Bipyramid with only face 0 = (0, 1, T) sharp: apex T (valence n) is mixed, so are ring
    # vertices 0 and 1 (valence 4: a = 3/8); bottom apex B stays in the sqrt3 region.
    V, F = bipyramid(n)
    r = step1(F, n + 2, sharp_faces=[0], loop_weights=loop_weights)
    ring = list(range(n))
    T, B = n, n + 1
    assert_row(r.matrix, T, smooth_row(T, ring, mixed_alpha(n)), f"mixed apex valence {n}")
    for i in (0, 1):
        nb = [(i - 1) % n, (i + 1) % n, T, B]
        assert_row(r.matrix, i, smooth_row(i, nb, Fr(3, 8)), f"mixed ring vertex {i} valence 4")
    assert_row(r.matrix, B, smooth_row(B, ring, kobbelt_alpha(n)), "sqrt3 apex B")
    # positions agree with S
    V2, F2, S = hybridsub.subdivide(V, F, sharp_faces=[0], loop_weights=loop_weights,
                                    return_matrix=True)
    a = float(mixed_alpha(n))
    np.testing.assert_allclose(V2[T], (1 - a) * V[T] + a / n * V[ring].sum(0), atol=TOL)


# =========================================================================== R4
@pytest.mark.parametrize("sharp", [[0], [0, 1]], ids=["sharp|smooth", "sharp|sharp"])
def test_R4_split_smooth_edge_point(sharp):
    # R4: edge (1,T) of a bipyramid(5), between face 0 = (0,1,T) and face 1 = (1,2,T), is
    # split-smooth when one or both faces are sharp and it is no crease:
    # m = 3/8 (v1 + vT) + 1/8 (v0 + v2). Also edge (0,1) between sharp face 0 and smooth bottom
    # face (1,0,B): m = 3/8 (v0 + v1) + 1/8 (vT + vB).
    n, T, B = 5, 5, 6
    V, F = bipyramid(n)
    V2, F2, S = hybridsub.subdivide(V, F, sharp_faces=sharp, return_matrix=True)
    m = find_row(S, {1: Fr(3, 8), T: Fr(3, 8), 0: Fr(1, 8), 2: Fr(1, 8)}, "R4 edge (1,T)")
    np.testing.assert_allclose(V2[m], 3 / 8 * (V[1] + V[T]) + 1 / 8 * (V[0] + V[2]), atol=TOL)
    find_row(S, {0: Fr(3, 8), 1: Fr(3, 8), T: Fr(1, 8), B: Fr(1, 8)}, "R4 edge (0,1)")
    # a split-smooth edge is never flipped
    E = edge_set(F2)
    assert frozenset((1, m)) in E and frozenset((m, T)) in E and frozenset((1, T)) not in E


def test_R4_interior_edge_in_loop_scheme():
    # In "loop" every interior edge is split-smooth: edge (0,2) of the octahedron, faces
    # (0,2,4) and (2,0,5): m = 3/8 (v0 + v2) + 1/8 (v4 + v5).
    r = step1(OCT_F, 6, scheme="loop")
    find_row(r.matrix, {0: Fr(3, 8), 2: Fr(3, 8), 4: Fr(1, 8), 5: Fr(1, 8)}, "R4 loop interior edge")


# =========================================================================== B1
@pytest.mark.parametrize(
    "case,sharp,counts,valence_m",
    [
        # Fig. 2 case 1: crease between two smooth faces
        ("smooth|smooth", [], [4, 3, 3, 3, 4, 3, 3, 3], 4),
        # case 2: crease between sharp face 0 and smooth face 4; faces 1, 3 gain a split-smooth edge
        ("smooth|sharp", [0], [4, 4, 3, 4, 4, 3, 3, 3], 5),
        # case 3: both sharp; faces 1, 3, 5, 7 each gain one split-smooth edge
        ("sharp|sharp", [0, 4], [4, 4, 3, 4, 4, 4, 3, 4], 6),
    ],
)
def test_B1_crease_edge_point_and_topology(case, sharp, counts, valence_m):
    # B1: tagged crease (0,2) of the octahedron (faces 0=(0,2,4) and 4=(2,0,5)) gets the midpoint
    # m = (v0 + v2)/2 and is split, never flipped: (0,m) and (m,2) are output edges, (0,2) is not.
    # A smooth face with s split edges emits 3 + s faces, a sharp one 4.
    # New valence of m: 4 (smooth|smooth), 5 (smooth|sharp), 6 (sharp|sharp) (paper section 4).
    sharp = sharp or None
    V2, F2, S = hybridsub.subdivide(OCT_V, OCT_F, sharp_edges=[[0, 2]], sharp_faces=sharp,
                                    return_matrix=True)
    m = find_row(S, {0: Fr(1, 2), 2: Fr(1, 2)}, f"B1 ({case})")
    np.testing.assert_allclose(V2[m], (OCT_V[0] + OCT_V[2]) / 2, atol=TOL)
    E = edge_set(F2)
    assert frozenset((0, m)) in E and frozenset((m, 2)) in E, f"B1 ({case}): crease not split"
    assert frozenset((0, 2)) not in E, f"B1 ({case}): old crease edge survived"
    r = step1(OCT_F, 6, sharp_edges=[[0, 2]], sharp_faces=sharp)
    got = np.bincount(np.asarray(r.face_parent), minlength=8).tolist()
    assert got == counts, f"B1 ({case}): faces per input face expected {counts}, got {got}"
    n_split = {4: 1, 5: 3, 6: 5}[valence_m]
    assert r.n_vertices == 6 + n_split + (8 - len(sharp or []))
    assert len(nbrs_of(r.faces, m)) == valence_m, f"B1 ({case}): valence of the edge point"
    # no face-point edge across the crease
    if not sharp:
        c0 = find_row(r.matrix, {0: Fr(1, 3), 2: Fr(1, 3), 4: Fr(1, 3)})
        c4 = find_row(r.matrix, {2: Fr(1, 3), 0: Fr(1, 3), 5: Fr(1, 3)})
        assert frozenset((c0, c4)) not in edge_set(r.faces), "crease was flipped"


# =========================================================================== B2
@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_B2_crease_vertex_tagged(scheme):
    # B2: equator 0-2-1-3 of the octahedron tagged as a crease loop: each equator vertex has
    # two crease edges, v' = 3/4 v + 1/8 (a + b) with a, b its crease neighbours.
    creases = [[0, 2], [2, 1], [1, 3], [3, 0]]
    V2, F2, S = hybridsub.subdivide(OCT_V, OCT_F, sharp_edges=creases, scheme=scheme,
                                    return_matrix=True)
    for v, (a, b) in {0: (2, 3), 2: (0, 1), 1: (2, 3), 3: (1, 0)}.items():
        assert_row(S, v, crease_row(v, a, b), f"B2 tagged crease vertex {v} ({scheme})")
        np.testing.assert_allclose(V2[v], 3 / 4 * OCT_V[v] + 1 / 8 * (OCT_V[a] + OCT_V[b]),
                                   atol=TOL)


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_B2_boundary_vertex(scheme):
    # B2 on a boundary (boundary edges are creases in hybrid and loop): boundary vertex i of the
    # hexagonal fan: v' = 3/4 v_i + 1/8 (v_{i-1} + v_{i+1}); boundary edge points are midpoints.
    # The centre (valence 6, no crease): hybrid a_6 = 1/3 -> (2/3, 1/18 x6); loop b_6 = 1/16.
    V, F = hex_fan()
    r = step1(F, 7, scheme=scheme)
    for i in range(1, 7):
        assert_row(r.matrix, i, crease_row(i, ring_prev(i), ring_next(i)), f"B2 boundary {i}")
        find_row(r.matrix, {i: Fr(1, 2), ring_next(i): Fr(1, 2)}, f"B1 boundary edge {i}")
    ring = list(range(1, 7))
    exp = smooth_row(0, ring, Fr(1, 3)) if scheme == "hybrid" else loop_row(0, ring, Fr(1, 16))
    assert_row(r.matrix, 0, exp, f"centre ({scheme})")


# =========================================================================== corners
@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_corner_tagged_stays(scheme):
    # corner: a tagged corner never moves, its row is the unit row.
    V2, F2, S = hybridsub.subdivide(OCT_V, OCT_F, corners=[4], scheme=scheme, return_matrix=True)
    assert_row(S, 4, {4: 1}, f"tagged corner ({scheme})")
    np.testing.assert_array_equal(V2[4], OCT_V[4])


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
@pytest.mark.parametrize("creases", [[[4, 0], [4, 2], [4, 1]], [[4, 0], [2, 4], [4, 1], [3, 4]]],
                         ids=["3 creases", "4 creases"])
def test_corner_automatic_three_creases(scheme, creases):
    # A vertex with 3 or more incident crease edges is a corner automatically: unit row.
    r = step1(OCT_F, 6, sharp_edges=creases, scheme=scheme)
    assert_row(r.matrix, 4, {4: 1}, f"automatic corner ({scheme}, {len(creases)} creases)")


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_corner_automatic_boundary_plus_crease(scheme):
    # Boundary edges count: ring vertex 1 of the hex fan has boundary edges (6,1), (1,2) and the
    # tagged crease (0,1): c = 3, so it is a corner (unit row). The centre has one crease: a dart.
    V, F = hex_fan()
    r = step1(F, 7, sharp_edges=[[0, 1]], scheme=scheme)
    assert_row(r.matrix, 1, {1: 1}, f"boundary + crease corner ({scheme})")
    ring = list(range(1, 7))
    exp = smooth_row(0, ring, Fr(1, 3)) if scheme == "hybrid" else loop_row(0, ring, Fr(1, 16))
    assert_row(r.matrix, 0, exp, f"dart centre ({scheme})")


# =========================================================================== dart
@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_dart_uses_smooth_rule(scheme):
    # dart: vertex with exactly one crease edge (octahedron, crease (0,4)) is smooth.
    # hybrid (sqrt3 region, n=4): a_4 = 4/9 -> 5/9 v + 1/9 each; loop: b_4 = 31/256 ->
    # 33/64 v + 31/256 each. The crease edge still gets its midpoint.
    r = step1(OCT_F, 6, sharp_edges=[[0, 4]], scheme=scheme)
    for v in (0, 4):
        nb = OCT_NBRS[v]
        exp = smooth_row(v, nb, Fr(4, 9)) if scheme == "hybrid" else loop_row(v, nb, Fr(31, 256))
        assert_row(r.matrix, v, exp, f"dart vertex {v} ({scheme})")
    assert Fr(1) - 4 * Fr(31, 256) == Fr(33, 64)
    find_row(r.matrix, {0: Fr(1, 2), 4: Fr(1, 2)}, "crease edge point next to a dart")


def test_dart_in_loop_region_of_hybrid():
    # a dart whose faces are all sharp uses the Loop-region rule (octahedron, all sharp, crease (0,4)).
    r = step1(OCT_F, 6, sharp_edges=[[0, 4]], sharp_faces=np.ones(8, bool))
    assert_row(r.matrix, 4, loop_row(4, OCT_NBRS[4], Fr(31, 256)), "dart in Loop region")


# =========================================================================== flip
def test_flip_smooth_interior_edge():
    # Flip: edge (0,2) of the octahedron between smooth faces 0 = (0,2,4) and 4 = (2,0,5) is
    # replaced by the edge joining their face points c0, c4; the halfedge 0->2 of face 0 emits
    # (0, c4, c0) and the halfedge 2->0 of face 4 emits (2, c0, c4).
    r = step1(OCT_F, 6)
    c0 = find_row(r.matrix, {0: Fr(1, 3), 2: Fr(1, 3), 4: Fr(1, 3)}, "face point 0")
    c4 = find_row(r.matrix, {2: Fr(1, 3), 0: Fr(1, 3), 5: Fr(1, 3)}, "face point 4")
    E = edge_set(r.faces)
    assert frozenset((0, 2)) not in E, "flip: the old edge survived"
    assert frozenset((c0, c4)) in E, "flip: no edge between the two face points"
    T = tri_set(r.faces)
    assert canon((0, c4, c0)) in T and canon((2, c0, c4)) in T
    assert r.n_vertices == 6 + 8 and len(r.faces) == 24


# =========================================================================== Kobbelt boundary
def test_kobbelt_boundary_odd_step():
    # sqrt3 step 1 (odd): boundary vertices stay (unit rows); the interior centre gets R3 with
    # n = 6 (2/3, 1/18 x6); each face f = (0,i,j) gets its face point c_f and emits
    # (0, c_{f-1}, c_f), (c_f, i, j) [boundary halfedge i->j], (j, c_{f+1}, c_f).
    V, F = hex_fan()
    V2, F2, S = hybridsub.subdivide(V, F, scheme="sqrt3", return_matrix=True)
    for i in range(1, 7):
        assert_row(S, i, {i: 1}, f"Kobbelt odd step boundary vertex {i}")
        np.testing.assert_array_equal(V2[i], V[i])
    assert_row(S, 0, smooth_row(0, list(range(1, 7)), Fr(1, 3)), "interior centre")
    c = [find_row(S, {0: Fr(1, 3), i: Fr(1, 3), ring_next(i): Fr(1, 3)}, f"face point {i - 1}")
         for i in range(1, 7)]
    exp = set()
    for f in range(6):
        i, j = f + 1, ring_next(f + 1)
        exp |= {canon((0, c[f - 1], c[f])), canon((c[f], i, j)), canon((j, c[(f + 1) % 6], c[f]))}
    assert tri_set(F2) == exp
    assert len(F2) == 18 and len(V2) == 13


def test_kobbelt_boundary_even_step():
    # sqrt3 step 2 (even), on the step-1 mesh of the hex fan (boundary loop 1->2->...->6->1):
    # boundary vertex i -> (4 p_{i-1} + 19 p_i + 4 p_{i+1})/27; boundary edge i->j (k after j,
    # h before i) -> e1 = (p_h + 16 p_i + 10 p_j)/27, e2 = (10 p_i + 16 p_j + p_k)/27;
    # boundary faces (c_f, i, j) get no face point and emit (e1, e2, c_f); the interior centre
    # (valence 6, neighbours c_0..c_5) gets 2/3, 1/18 x6.
    V, F = hex_fan()
    r = hybridsub.refine(F, levels=2, n_vertices=7, scheme="sqrt3")
    s0, s1 = r.steps[0], r.steps[1]
    c = [find_row(s0.matrix, {0: Fr(1, 3), i: Fr(1, 3), ring_next(i): Fr(1, 3)})
         for i in range(1, 7)]
    F1 = np.asarray(s0.faces)
    S2 = s1.matrix
    assert S2.shape == (13 + 12 + 12, 13)
    assert len(s1.faces) == 54  # one triangle per halfedge of the step-1 mesh
    for i in range(1, 7):
        assert_row(S2, i, {ring_prev(i): Fr(4, 27), i: Fr(19, 27), ring_next(i): Fr(4, 27)},
                   f"Kobbelt even-step boundary vertex {i}")
    assert_row(S2, 0, smooth_row(0, c, Fr(1, 3)), "interior centre, even step")
    T2 = tri_set(s1.faces)
    e = {}
    for f in range(6):
        i = f + 1
        h, j = ring_prev(i), ring_next(i)
        k = ring_next(j)
        e1 = find_row(S2, {h: Fr(1, 27), i: Fr(16, 27), j: Fr(10, 27)}, f"e1 of edge {i}->{j}")
        e2 = find_row(S2, {i: Fr(10, 27), j: Fr(16, 27), k: Fr(1, 27)}, f"e2 of edge {i}->{j}")
        e[(i, j)] = (e1, e2)
        assert canon((e1, e2, c[f])) in T2, f"triangle (e1, e2, x) for boundary edge {i}->{j}"
        # the boundary face (c_f, i, j) of the step-1 mesh has no face point
        assert len(find_rows(S2, {c[f]: Fr(1, 3), i: Fr(1, 3), j: Fr(1, 3)})) == 0
    # every interior face of the step-1 mesh has its face point; build the whole face set by
    # the apex rule: halfedge u->w of f with twin in g emits (u, apex(g), apex(f)).
    he_face = {}
    for t, tri in enumerate(F1):
        for a in range(3):
            he_face[(int(tri[a]), int(tri[(a + 1) % 3]))] = t
    apex = {}  # (face, halfedge) -> apex vertex
    bnd = {}
    for t, tri in enumerate(F1):
        tri = [int(x) for x in tri]
        hes = [(tri[a], tri[(a + 1) % 3]) for a in range(3)]
        b = [hh for hh in hes if (hh[1], hh[0]) not in he_face]
        if b:
            u, w = b[0]
            x = ({*tri} - {u, w}).pop()
            e1, e2 = e[(u, w)]
            apex[(t, (w, x))], apex[(t, (x, u))] = e2, e1
            bnd[t] = (e1, e2, x)
        else:
            d = find_row(S2, {q: Fr(1, 3) for q in tri}, f"face point of step-1 face {t}")
            for hh in hes:
                apex[(t, hh)] = d
    exp = set()
    for t, tri in enumerate(F1):
        tri = [int(x) for x in tri]
        for a in range(3):
            u, w = tri[a], tri[(a + 1) % 3]
            if (w, u) in he_face:
                exp.add(canon((u, apex[(he_face[(w, u)], (w, u))], apex[(t, (u, w))])))
            else:
                exp.add(canon(bnd[t]))
    assert T2 == exp


# =========================================================================== semi-sharp
@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_semisharp_edge_half(scheme):
    # s = 0.5 on edge (0,2) of the octahedron (opposite 4, 5):
    # m = 0.5 (v0+v2)/2 + 0.5 [3/8 (v0+v2) + 1/8 (v4+v5)] = 7/16 (v0+v2) + 1/16 (v4+v5).
    # It is split at this level (not flipped, also in hybrid); its children (s = -0.5) are dropped.
    w = Fr(1, 2)
    exp = {0: w / 2 + (1 - w) * Fr(3, 8), 2: w / 2 + (1 - w) * Fr(3, 8),
           4: (1 - w) * Fr(1, 8), 5: (1 - w) * Fr(1, 8)}
    assert exp[0] == Fr(7, 16) and exp[4] == Fr(1, 16)
    r = step1(OCT_F, 6, sharp_edges=[[0, 2]], sharpness=[0.5], scheme=scheme)
    m = find_row(r.matrix, exp, f"semi-sharp s=0.5 edge point ({scheme})")
    E = edge_set(r.faces)
    assert frozenset((0, m)) in E and frozenset((m, 2)) in E and frozenset((0, 2)) not in E
    assert n_tagged(r.sharp_edges) == 0
    # vertices 0 and 2 have one edge with s > 0: smooth (dart-like) rule of their region
    exp0 = smooth_row(0, OCT_NBRS[0], Fr(4, 9)) if scheme == "hybrid" else \
        loop_row(0, OCT_NBRS[0], Fr(31, 256))
    assert_row(r.matrix, 0, exp0, f"vertex on a s=0.5 edge ({scheme})")


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_semisharp_edge_two(scheme):
    # s = 2 on edge (0,2) of the octahedron: step 1 midpoint m1 (children s = 1); step 2 the
    # children (0,m1), (m1,2) with s = 1 still give midpoints, m1 is a crease vertex with w = 1
    # (pure crease mask 3/4 m1 + 1/8 (v0 + v2)), grandchildren (s = 0) are dropped; step 3 the
    # edge (0,m2) is no crease: flipped in hybrid (sqrt3 region), Loop interior rule in loop.
    r = hybridsub.refine(OCT_F, [[0, 2]], levels=3, n_vertices=6, sharpness=[2.0], scheme=scheme)
    s0, s1, s2 = r.steps
    m1 = find_row(s0.matrix, {0: Fr(1, 2), 2: Fr(1, 2)}, "s=2, step 1 midpoint")
    se0 = {tuple(int(x) for x in e) for e in np.asarray(s0.sharp_edges)}
    assert {frozenset(e) for e in se0} == {frozenset((0, m1)), frozenset((m1, 2))}
    np.testing.assert_allclose(np.asarray(s0.sharpness, float), [1.0, 1.0])
    m2 = find_row(s1.matrix, {0: Fr(1, 2), m1: Fr(1, 2)}, "s=1 child, step 2 midpoint")
    find_row(s1.matrix, {m1: Fr(1, 2), 2: Fr(1, 2)}, "s=1 child, step 2 midpoint")
    assert_row(s1.matrix, m1, crease_row(m1, 0, 2), "crease vertex m1 at step 2 (w = 1)")
    assert n_tagged(s1.sharp_edges) == 0
    assert len(find_rows(s2.matrix, {0: Fr(1, 2), m2: Fr(1, 2)})) == 0, "s=0 edge still a crease"
    if scheme == "hybrid":
        assert frozenset((0, m2)) in edge_set(s1.faces)
        assert frozenset((0, m2)) not in edge_set(s2.faces), "s<=0 edge not flipped at step 3"
        # m2 is now a smooth sqrt3 vertex: valence 4 (crease point between smooth faces)
        nb = nbrs_of(s1.faces, m2)
        assert len(nb) == 4
        assert_row(s2.matrix, m2, smooth_row(m2, nb, Fr(4, 9)), "m2 at step 3")
    else:
        opp = [int(x) for t in np.asarray(s1.faces) if 0 in t and m2 in t for x in t
               if x not in (0, m2)]
        assert len(opp) == 2
        find_row(s2.matrix, {0: Fr(3, 8), m2: Fr(3, 8), opp[0]: Fr(1, 8), opp[1]: Fr(1, 8)},
                 "step 3 Loop interior edge point")


EQUATOR = [[0, 2], [2, 1], [1, 3], [3, 0]]


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
@pytest.mark.parametrize("s02,s03", [(0.5, 0.5), (0.5, 0.25), (2.0, 0.5)])
def test_semisharp_vertex_blend(scheme, s02, s03):
    # Vertex 0 of the octahedron on the equator crease loop with sharpness s02 on (0,2) and s03
    # on (3,0) (other equator edges: s = 0.5). Parent rule: 2 edges with s > 0 -> crease;
    # child rule: edges with s > 1 -> at most one -> smooth. Blend w * crease + (1 - w) * smooth
    # with w = mean of s over incident edges with 0 < s <= 1.
    # (0.5, 0.5): w = 1/2 -> loop: 81/128 v0, 63/512 (v2+v3), 31/512 (v4+v5).
    sh = [s02, 0.5, 0.5, s03]
    r = step1(OCT_F, 6, sharp_edges=EQUATOR, sharpness=sh, scheme=scheme)
    small = [s for s in (s02, s03) if 0 < s <= 1]
    w = Fr(sum(Fr(s) for s in small)) / len(small)
    smooth = loop_row(0, OCT_NBRS[0], Fr(31, 256)) if scheme == "loop" else \
        smooth_row(0, OCT_NBRS[0], Fr(4, 9))
    exp = blend(w, crease_row(0, 2, 3), smooth)
    if scheme == "loop" and (s02, s03) == (0.5, 0.5):
        assert exp == {0: Fr(81, 128), 2: Fr(63, 512), 3: Fr(63, 512), 4: Fr(31, 512),
                       5: Fr(31, 512)}
    assert_row(r.matrix, 0, exp, f"semi-sharp blend w={w} ({scheme}, s={s02},{s03})")


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_semisharp_corner_blends(scheme):
    # Vertex 4 of the octahedron with three creases:
    # (a) all s = 0.5: parent corner, child smooth, w = 1/2 -> 1/2 unit + 1/2 smooth mask;
    # (b) (4,0), (4,1) infinite, (4,2) s = 0.5: parent corner, child crease on (4,0),(4,1),
    #     w = 1/2 -> 1/2 unit + 1/2 (3/4 v4 + 1/8 (v0 + v1)) = 7/8 v4 + 1/16 (v0 + v1).
    smooth = loop_row(4, OCT_NBRS[4], Fr(31, 256)) if scheme == "loop" else \
        smooth_row(4, OCT_NBRS[4], Fr(4, 9))
    r = step1(OCT_F, 6, sharp_edges=[[4, 0], [4, 1], [4, 2]], sharpness=[0.5] * 3, scheme=scheme)
    assert_row(r.matrix, 4, blend(Fr(1, 2), {4: 1}, smooth), f"corner->smooth blend ({scheme})")
    r = step1(OCT_F, 6, sharp_edges=[[4, 0], [4, 1], [4, 2]], sharpness=[np.inf, np.inf, 0.5],
              scheme=scheme)
    exp = blend(Fr(1, 2), {4: 1}, crease_row(4, 0, 1))
    assert exp == {4: Fr(7, 8), 0: Fr(1, 16), 1: Fr(1, 16)}
    assert_row(r.matrix, 4, exp, f"corner->crease blend ({scheme})")


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_semisharp_sharp_parent_and_child_no_blend(scheme):
    # Equator creases with s = 2: parent and child rule are both crease -> pure B2 mask.
    r = step1(OCT_F, 6, sharp_edges=EQUATOR, sharpness=[2.0] * 4, scheme=scheme)
    assert_row(r.matrix, 0, crease_row(0, 2, 3), f"s=2 crease vertex ({scheme})")


def test_sharpness_ten_is_infinite():
    # sharpness >= 10 counts as infinite: children carry inf, the edge point is a midpoint.
    r = step1(OCT_F, 6, sharp_edges=[[0, 2]], sharpness=[10.0])
    find_row(r.matrix, {0: Fr(1, 2), 2: Fr(1, 2)}, "s=10 midpoint")
    assert np.all(np.isinf(np.asarray(r.sharpness, float))), r.sharpness


# =========================================================================== worked example
def test_worked_example_one_face_hybrid():
    # docs/scheme.md worked example: one smooth face (0,1,2), all edges boundary creases;
    # v_i' = 3/4 v_i + 1/8 (others); edge points 3, 4, 5 = midpoints of 0->1, 1->2, 2->0;
    # face point 6; faces exactly (6,0,3),(6,3,1),(6,1,4),(6,4,2),(6,2,5),(6,5,0).
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 2]])
    V2, F2, S = hybridsub.subdivide(V, F, return_matrix=True)
    exp_F = [[6, 0, 3], [6, 3, 1], [6, 1, 4], [6, 4, 2], [6, 2, 5], [6, 5, 0]]
    np.testing.assert_array_equal(np.asarray(F2), exp_F)
    h, q, e, t = Fr(1, 2), Fr(3, 4), Fr(1, 8), Fr(1, 3)
    exp_S = [[q, e, e], [e, q, e], [e, e, q], [h, h, 0], [0, h, h], [h, 0, h], [t, t, t]]
    np.testing.assert_allclose(dense(S), np.array(exp_S, float), atol=TOL)
    exp_V = [[e, e, 0], [q, e, 0], [e, q, 0], [h, 0, 0], [h, h, 0], [0, h, 0], [t, t, 0]]
    np.testing.assert_allclose(V2, np.array(exp_V, float), atol=TOL)
    r = step1(F, 3)
    assert list(np.asarray(r.face_parent)) == [0] * 6
    assert r.n_vertices == 7


def test_worked_example_one_face_sqrt3():
    # Same face in "sqrt3", step 1: vertices stay (boundary), face point 3, faces
    # (3,0,1), (3,1,2), (3,2,0).
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 2]])
    V2, F2, S = hybridsub.subdivide(V, F, scheme="sqrt3", return_matrix=True)
    np.testing.assert_array_equal(np.asarray(F2), [[3, 0, 1], [3, 1, 2], [3, 2, 0]])
    t = 1 / 3
    np.testing.assert_allclose(dense(S), [[1, 0, 0], [0, 1, 0], [0, 0, 1], [t, t, t]], atol=TOL)
    np.testing.assert_allclose(V2, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [t, t, 0]], atol=TOL)


# =========================================================================== index layout
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])
# halfedges 0:0->1 1:1->2 2:2->0 3:0->2 4:2->3 5:3->0; edges in first-appearance order:
# e0=(0,1) e1=(1,2) e2=(2,0) [owner halfedge 2] e3=(2,3) e4=(3,0)


def test_layout_two_faces_hybrid_smooth():
    # Both faces smooth: boundary edges e0, e1, e3, e4 are split (creases) -> points 4, 5, 6, 7
    # in edge order; the diagonal e2 is flipped (no point); face points 8 (face 0), 9 (face 1).
    # Faces, parent by parent, halfedge by halfedge:
    # face 0: (8,0,4),(8,4,1) | (8,1,5),(8,5,2) | flip 2->0: (2,9,8)
    # face 1: flip 0->2: (0,8,9) | (9,2,6),(9,6,3) | (9,3,7),(9,7,0)
    r = step1(SQUARE_F, 4)
    h, t = Fr(1, 2), Fr(1, 3)
    assert r.n_vertices == 10 and r.matrix.shape == (10, 4)
    for i, (a, b) in zip((4, 5, 6, 7), [(0, 1), (1, 2), (2, 3), (3, 0)]):
        assert_row(r.matrix, i, {a: h, b: h}, f"layout: edge point of ({a},{b}) at index {i}")
    assert_row(r.matrix, 8, {0: t, 1: t, 2: t}, "layout: face point of face 0 at 8")
    assert_row(r.matrix, 9, {0: t, 2: t, 3: t}, "layout: face point of face 1 at 9")
    # old vertices keep their indices (each has 2 boundary creases: B2)
    assert_row(r.matrix, 0, crease_row(0, 1, 3), "old vertex 0")
    assert_row(r.matrix, 1, crease_row(1, 0, 2), "old vertex 1")
    assert_row(r.matrix, 2, crease_row(2, 1, 3), "old vertex 2")
    assert_row(r.matrix, 3, crease_row(3, 2, 0), "old vertex 3")
    exp_F = [[8, 0, 4], [8, 4, 1], [8, 1, 5], [8, 5, 2], [2, 9, 8],
             [0, 8, 9], [9, 2, 6], [9, 6, 3], [9, 3, 7], [9, 7, 0]]
    np.testing.assert_array_equal(np.asarray(r.faces), exp_F)
    assert list(np.asarray(r.face_parent)) == [0] * 5 + [1] * 5


@pytest.mark.parametrize("form", ["mask", "indices"])
def test_layout_two_faces_hybrid_one_sharp(form):
    # Face 1 sharp: every edge is split: points 4..8 for e0=(0,1), e1=(1,2), e2=(2,0)
    # [split-smooth, R4: 3/8 (v2+v0) + 1/8 (v1+v3)], e3=(2,3), e4=(3,0); face point 9 (face 0).
    # face 0: (9,0,4),(9,4,1),(9,1,5),(9,5,2),(9,2,6),(9,6,0)
    # face 1 (sharp, m_ab=6, m_bc=7, m_ca=8): (0,6,8),(6,2,7),(8,7,3),(6,7,8), all sharp.
    sharp = np.array([False, True]) if form == "mask" else np.array([1])
    r = step1(SQUARE_F, 4, sharp_faces=sharp)
    h = Fr(1, 2)
    assert r.n_vertices == 10
    for i, (a, b) in zip((4, 5, 7, 8), [(0, 1), (1, 2), (2, 3), (3, 0)]):
        assert_row(r.matrix, i, {a: h, b: h}, f"layout: crease point ({a},{b}) at {i}")
    assert_row(r.matrix, 6, {2: Fr(3, 8), 0: Fr(3, 8), 1: Fr(1, 8), 3: Fr(1, 8)},
               "layout: R4 point of the diagonal at 6")
    assert_row(r.matrix, 9, {0: Fr(1, 3), 1: Fr(1, 3), 2: Fr(1, 3)}, "layout: face point at 9")
    exp_F = [[9, 0, 4], [9, 4, 1], [9, 1, 5], [9, 5, 2], [9, 2, 6], [9, 6, 0],
             [0, 6, 8], [6, 2, 7], [8, 7, 3], [6, 7, 8]]
    np.testing.assert_array_equal(np.asarray(r.faces), exp_F)
    assert list(np.asarray(r.face_parent)) == [0] * 6 + [1] * 4
    sf = np.asarray(r.sharp_faces)
    if form == "mask":
        assert sf.dtype == bool and sf.tolist() == [False] * 6 + [True] * 4
    else:
        assert sorted(sf.tolist()) == [6, 7, 8, 9]


def test_layout_two_faces_loop():
    # "loop": all 5 edges split -> points 4..8 in edge order, no face points (9 vertices).
    r = step1(SQUARE_F, 4, scheme="loop")
    assert r.n_vertices == 9 and r.matrix.shape == (9, 4)
    h = Fr(1, 2)
    for i, (a, b) in zip((4, 5, 7, 8), [(0, 1), (1, 2), (2, 3), (3, 0)]):
        assert_row(r.matrix, i, {a: h, b: h}, f"loop layout: ({a},{b}) at {i}")
    assert_row(r.matrix, 6, {2: Fr(3, 8), 0: Fr(3, 8), 1: Fr(1, 8), 3: Fr(1, 8)}, "loop layout e2")
    exp_F = [[0, 4, 6], [4, 1, 5], [6, 5, 2], [4, 5, 6],
             [0, 6, 8], [6, 2, 7], [8, 7, 3], [6, 7, 8]]
    np.testing.assert_array_equal(np.asarray(r.faces), exp_F)


def test_layout_closed_mesh_face_points():
    # closed untagged mesh (hybrid): no split edges, so the face point of face f is n + f.
    r = step1(TET_F, 4)
    for f, (a, b, c) in enumerate(TET_F):
        assert_row(r.matrix, 4 + f, {a: Fr(1, 3), b: Fr(1, 3), c: Fr(1, 3)}, f"face point {f}")


def test_layout_kobbelt_steps():
    # sqrt3 on the hex fan. Step 1: face point of face f at 7 + f; faces per face f = (0,i,j):
    # (0, c_{f-1}, c_f), (c_f, i, j), (j, c_{f+1}, c_f).
    # Step 2: boundary edges in edge order of the step-1 mesh are (1,2), (2,3), ..., (6,1);
    # edge k gets e1 at 13 + 2k and e2 at 14 + 2k; then the face points of the interior step-1
    # faces (indices t with t % 3 != 1) in face order from 25.
    V, F = hex_fan()
    r = hybridsub.refine(F, levels=2, n_vertices=7, scheme="sqrt3")
    s0, s1 = r.steps
    c = [7 + f for f in range(6)]
    exp1 = []
    for f in range(6):
        i, j = f + 1, ring_next(f + 1)
        assert_row(s0.matrix, c[f], {0: Fr(1, 3), i: Fr(1, 3), j: Fr(1, 3)}, f"face point {f}")
        exp1 += [[0, c[f - 1], c[f]], [c[f], i, j], [j, c[(f + 1) % 6], c[f]]]
    np.testing.assert_array_equal(np.asarray(s0.faces), exp1)
    for k in range(6):
        i = k + 1
        h, j = ring_prev(i), ring_next(i)
        assert_row(s1.matrix, 13 + 2 * k, {h: Fr(1, 27), i: Fr(16, 27), j: Fr(10, 27)},
                   f"even-step layout: e1 of edge {k}")
        assert_row(s1.matrix, 14 + 2 * k, {i: Fr(10, 27), j: Fr(16, 27), ring_next(j): Fr(1, 27)},
                   f"even-step layout: e2 of edge {k}")
    nxt = 25
    for t, tri in enumerate(exp1):
        if t % 3 != 1:
            assert_row(s1.matrix, nxt, {q: Fr(1, 3) for q in tri}, f"even-step face point of {t}")
            nxt += 1
    assert nxt == 37 == s1.n_vertices


# =========================================================================== returned tags
def test_returned_crease_children_and_sharpness():
    # crease given as (2,0) with s = 3; its owner halfedge is 0->2 (face 0 = (0,2,4)), so the
    # edge point is 6 (first and only split edge) and the children are (0,6), (6,2), s = 2 each.
    # faces per input face: 4 for faces 0 and 4 (one split edge each), 3 for the others.
    r = step1(OCT_F, 6, sharp_edges=[[2, 0]], sharpness=[3.0])
    assert_row(r.matrix, 6, {0: Fr(1, 2), 2: Fr(1, 2)}, "crease point at index 6")
    np.testing.assert_array_equal(np.asarray(r.sharp_edges), [[0, 6], [6, 2]])
    np.testing.assert_allclose(np.asarray(r.sharpness, float), [2.0, 2.0])
    exp_parent = [0] * 4 + [1] * 3 + [2] * 3 + [3] * 3 + [4] * 4 + [5] * 3 + [6] * 3 + [7] * 3
    assert list(np.asarray(r.face_parent)) == exp_parent
    # infinite crease stays infinite
    r = step1(OCT_F, 6, sharp_edges=[[2, 0]], sharpness=[np.inf])
    assert np.all(np.isinf(np.asarray(r.sharpness, float)))


@pytest.mark.parametrize("form", ["mask", "indices"])
def test_returned_sharp_faces_corners_face_parent(form):
    # sharp face 0 of the octahedron: its 4 children are the only sharp output faces;
    # faces 1, 3, 4 gain a split-smooth edge (4 children each), others 3.
    # mask in -> mask out, indices in -> indices out; corners keep their indices;
    # over two levels face_parent composes and sharp faces are exactly the descendants of face 0.
    sharp = np.eye(8, dtype=bool)[0] if form == "mask" else np.array([0])
    r = step1(OCT_F, 6, sharp_faces=sharp, corners=[5])
    exp_parent = [0] * 4 + [1] * 4 + [2] * 3 + [3] * 4 + [4] * 4 + [5] * 3 + [6] * 3 + [7] * 3
    assert list(np.asarray(r.face_parent)) == exp_parent
    sf = np.asarray(r.sharp_faces)
    if form == "mask":
        assert sf.dtype == bool and sf.tolist() == [True] * 4 + [False] * 24
    else:
        assert sorted(sf.tolist()) == [0, 1, 2, 3]
    assert sorted(np.asarray(r.corners).tolist()) == [5]
    assert_row(r.matrix, 5, {5: 1}, "tagged corner")
    r2 = hybridsub.refine(OCT_F, levels=2, n_vertices=6, sharp_faces=sharp, corners=[5])
    fp0, fp1 = (np.asarray(s.face_parent) for s in r2.steps)
    np.testing.assert_array_equal(np.asarray(r2.face_parent), fp0[fp1])
    sf2 = np.asarray(r2.sharp_faces)
    desc = np.asarray(r2.face_parent) == 0
    if form == "mask":
        np.testing.assert_array_equal(sf2, desc)
    else:
        assert sorted(sf2.tolist()) == np.flatnonzero(desc).tolist()
    assert len(np.flatnonzero(desc)) == 16
    assert sorted(np.asarray(r2.corners).tolist()) == [5]


def test_matrix_consistency():
    # V2 == S @ V, r.apply(X) == S @ X, composite S == S_2 S_1 (levels = 2).
    V, F = bipyramid(5)
    V2, F2, S = hybridsub.subdivide(V, F, sharp_edges=[[0, 5]], sharp_faces=[0, 1], levels=2,
                                    return_matrix=True)
    np.testing.assert_allclose(V2, S @ V, atol=1e-12)
    r = hybridsub.refine(F, [[0, 5]], levels=2, n_vertices=7, sharp_faces=[0, 1])
    np.testing.assert_allclose(r.apply(V), V2, atol=1e-12)
    np.testing.assert_array_equal(np.asarray(r.faces), np.asarray(F2))
    comp = dense(r.steps[1].matrix) @ dense(r.steps[0].matrix)
    np.testing.assert_allclose(dense(r.matrix), comp, atol=1e-12)
    np.testing.assert_allclose(dense(r.matrix).sum(1), 1, atol=1e-12)
    assert r.n_vertices == r.steps[-1].n_vertices == len(V2)
