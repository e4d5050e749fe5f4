"""Property tests of hybridsub's public API on random valid meshes (see docs/scheme.md).

Meshes and tags come from ``tests/strategies.py``. Every property here follows from the
rules in ``docs/scheme.md`` / the shared ``SCHEME.md``; none compares against a reference
implementation (``tests/naive.py`` does that). Set ``HYBRIDSUB_PROPERTY_SCALE=10`` for ten
times as many examples.
"""

import os

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import strategies as ms

hybridsub = pytest.importorskip("hybridsub")

SCHEMES = ["hybrid", "sqrt3", "loop"]
TAGGED_SCHEMES = ["hybrid", "loop"]


# HYBRIDSUB_PROPERTY_SCALE=10 runs ten times as many examples (a longer hunt for bugs).
SCALE = int(os.environ.get("HYBRIDSUB_PROPERTY_SCALE", "1"))


def cfg(n):
    return settings(max_examples=n * SCALE, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])


# ---------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------


def levels_for(m, scheme, max_levels=3, budget=6000):
    """Largest number of levels <= max_levels whose output stays under ``budget`` faces."""
    grow = 4 if scheme != "sqrt3" else 3
    L = 1
    while L < max_levels and m * grow ** (L + 1) <= budget:
        L += 1
    return L


def positions(V, F, **kw):
    V2, F2 = hybridsub.subdivide(V, F, **kw)
    return np.asarray(V2), np.asarray(F2)


def norm_sharpness(s, k):
    """Sharpness tag to an array: None -> inf, >= 10 -> inf."""
    s = np.full(k, np.inf) if s is None else np.asarray(s, float).copy()
    s[s >= 10] = np.inf
    return s


def edge_faces(F):
    """dict sorted edge -> list of faces using it."""
    d = {}
    for f, (a, b, c) in enumerate(np.asarray(F).tolist()):
        for u, w in ((a, b), (b, c), (c, a)):
            d.setdefault((min(u, w), max(u, w)), []).append(f)
    return d


def crease_sharpness(F, sharp_edges, sharpness):
    """dict sorted edge -> sharpness of the crease edges (boundary edges: inf)."""
    ef = edge_faces(F)
    s_of = {e: np.inf for e, fs in ef.items() if len(fs) == 1}
    if sharp_edges is not None:
        se = np.asarray(sharp_edges).reshape(-1, 2)
        s = norm_sharpness(sharpness, len(se))
        for (u, w), x in zip(se.tolist(), s):
            e = (min(u, w), max(u, w))
            if x > 0:
                s_of[e] = max(s_of.get(e, 0.0), x)
    return s_of


def face_mask(scheme, sharp_faces, m):
    if scheme == "loop":
        return np.ones(m, bool)
    if scheme == "sqrt3":
        return np.zeros(m, bool)
    return ms.sharp_mask(sharp_faces, m)


def expected_step_counts(F, n, scheme, step_no, sharp_edges=None, sharpness=None,
                         sharp_faces=None):
    """(n_vertices', per-face child counts) for one step, from docs/scheme.md."""
    F = np.asarray(F)
    m = len(F)
    ef = edge_faces(F)
    if scheme == "sqrt3":
        nb = len([e for e, fs in ef.items() if len(fs) == 1])
        if step_no % 2 == 1:
            return n + m, np.full(m, 3)
        has_b = np.zeros(m, bool)
        for e, fs in ef.items():
            if len(fs) == 1:
                has_b[fs[0]] = True
        return n + 2 * nb + int((~has_b).sum()), np.full(m, 3)
    sharp = face_mask(scheme, sharp_faces, m)
    creases = crease_sharpness(F, sharp_edges, sharpness)
    split = {e for e, fs in ef.items() if e in creases or sharp[fs].any()}
    per_face = np.empty(m, np.int64)
    for f, (a, b, c) in enumerate(F.tolist()):
        s = sum((min(u, w), max(u, w)) in split for u, w in ((a, b), (b, c), (c, a)))
        per_face[f] = 4 if sharp[f] else 3 + s
    return n + len(split) + int((~sharp).sum()), per_face


def step_inputs(F, n, tags, r):
    """(faces, n_vertices, tags) fed to each step of r: the input, then each step's output."""
    out = [(np.asarray(F), n, dict(tags))]
    for st_ in r.steps[:-1]:
        out.append((np.asarray(st_.faces), st_.n_vertices,
                    dict(sharp_edges=st_.sharp_edges, sharpness=st_.sharpness,
                         sharp_faces=st_.sharp_faces, corners=st_.corners)))
    return out


def dense(S):
    return S.toarray() if sp.issparse(S) else np.asarray(S)


def assert_same_matrix(A, B, atol=1e-14):
    A, B = sp.csr_matrix(A), sp.csr_matrix(B)
    assert A.shape == B.shape
    D = (A - B).tocsr()
    assert D.nnz == 0 or np.abs(D.data).max() <= atol


def scale(V):
    return max(1.0, float(np.abs(V).max()))


def crease_loops(E):
    """Closed loops of a set of undirected edges in which every vertex has degree 2."""
    adj = {}
    for u, w in np.asarray(E).tolist():
        adj.setdefault(u, []).append(w)
        adj.setdefault(w, []).append(u)
    assert all(len(x) == 2 for x in adj.values())
    seen, loops = set(), []
    for v0 in adj:
        if v0 in seen:
            continue
        loop, prev, v = [v0], None, v0
        seen.add(v0)
        while True:
            a, b = adj[v]
            nxt = b if a == prev else a
            if nxt == v0:
                break
            loop.append(nxt)
            seen.add(nxt)
            prev, v = v, nxt
        loops.append(loop)
    return loops


def walk_loop(adj, start, toward_old, n_old):
    """Walk the refined loop from ``start`` in the direction whose first old vertex
    (index < n_old) is ``toward_old``; returns the vertex sequence (start first)."""
    for first in adj[start]:
        seq, prev, v = [start], start, first
        while v != start:
            seq.append(v)
            nbrs = adj[v]
            assert len(nbrs) == 2, f"vertex {v} of the refined crease has degree {len(nbrs)}"
            nxt = nbrs[1] if nbrs[0] == prev else nbrs[0]
            prev, v = v, nxt
        olds = [x for x in seq[1:] if x < n_old]
        if (olds[0] if olds else start) == toward_old:
            return seq
    raise AssertionError("refined loop does not pass the old vertices in order")


def bspline_closed(P, levels):
    """Cubic B-spline refinement of a closed polyline: vertex (1/8, 3/4, 1/8), midpoints."""
    for _ in range(levels):
        Pm, Pp = np.roll(P, 1, axis=0), np.roll(P, -1, axis=0)
        even = 0.75 * P + 0.125 * (Pm + Pp)
        odd = 0.5 * (P + Pp)
        Q = np.empty((2 * len(P), P.shape[1]))
        Q[0::2], Q[1::2] = even, odd
        P = Q
    return P


# ---------------------------------------------------------------------------------------
# counts, topology
# ---------------------------------------------------------------------------------------


@cfg(40)
@given(st.data(), st.sampled_from(TAGGED_SCHEMES))
def test_counts_per_step(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes(sharpness=data.draw(st.sampled_from(["maybe", "mixed0"]))))
    if scheme == "loop":
        tags.pop("sharp_faces", None)
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    assert len(r.steps) == L
    for k, (Fk, nk, tk) in enumerate(step_inputs(F, len(V), tags, r)):
        nV, per_face = expected_step_counts(Fk, nk, scheme, k + 1, tk.get("sharp_edges"),
                                            tk.get("sharpness"), tk.get("sharp_faces"))
        step = r.steps[k]
        assert step.n_vertices == nV, f"step {k + 1}: |V'|"
        assert step.matrix.shape == (nV, nk)
        assert len(step.faces) == per_face.sum(), f"step {k + 1}: |F'|"
        assert np.array_equal(np.bincount(step.face_parent, minlength=len(Fk)), per_face)
    assert r.n_vertices == r.steps[-1].n_vertices == r.matrix.shape[0]
    assert np.array_equal(r.faces, r.steps[-1].faces)


@cfg(30)
@given(ms.meshes("any"), st.data())
def test_counts_sqrt3(mesh, data):
    V, F = mesh
    L = data.draw(st.integers(1, levels_for(len(F), "sqrt3")))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme="sqrt3")
    assert len(r.steps) == L
    for k, (Fk, nk, _) in enumerate(step_inputs(F, len(V), {}, r)):
        nV, per_face = expected_step_counts(Fk, nk, "sqrt3", k + 1)
        assert r.steps[k].n_vertices == nV, f"step {k + 1}: |V'|"
        assert len(r.steps[k].faces) == 3 * len(Fk)
    assert len(r.faces) == 3 ** L * len(F)


@cfg(40)
@given(st.data(), st.sampled_from(SCHEMES))
def test_output_mesh_valid_and_euler(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    V, F = V, F
    if data.draw(st.booleans()):
        V = np.vstack([V, np.random.default_rng(0).normal(size=(2, 3))])   # unused vertices
    L = data.draw(st.integers(1, levels_for(len(F), scheme, max_levels=2)))
    V2, F2 = positions(V, F, levels=L, scheme=scheme, **tags)
    assert V2.shape == (len(V2), 3) and V2.dtype == np.float64
    assert np.issubdtype(F2.dtype, np.integer)
    ms.check_mesh(V2, F2)
    assert ms.euler(len(V2), F2) == ms.euler(len(V), F)
    # every new vertex is used; old vertices used before are used after
    used = np.zeros(len(V2), bool)
    used[F2.ravel()] = True
    assert used[len(V):].all()
    old_used = np.zeros(len(V), bool)
    old_used[F.ravel()] = True
    assert np.array_equal(used[:len(V)], old_used)


@cfg(30)
@given(st.data(), st.sampled_from(SCHEMES))
def test_face_parent(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    fp = np.asarray(r.face_parent)
    assert fp.shape == (len(r.faces),)
    assert fp.min() >= 0 and fp.max() < len(F)
    assert np.all(np.bincount(fp, minlength=len(F)) >= 1)
    # children of sharp faces are sharp, of smooth faces smooth
    mask_in = face_mask(scheme, tags.get("sharp_faces"), len(F))
    if scheme == "hybrid":
        assert np.array_equal(ms.sharp_mask(r.sharp_faces, len(r.faces)), mask_in[fp])
        if "sharp_faces" in tags:   # the caller's form comes back
            assert (np.asarray(r.sharp_faces).dtype == bool) == (tags["sharp_faces"].dtype == bool)
    # sharp faces make 4**L children
    counts = np.bincount(fp, minlength=len(F))
    assert np.all(counts[mask_in] == 4 ** L)
    # step face_parent indexes the step's input faces, and composes to r.face_parent
    comp = np.arange(len(F))
    for step in r.steps:
        sfp = np.asarray(step.face_parent)
        assert sfp.min() >= 0 and sfp.max() < len(comp)
        comp = comp[sfp]
    assert np.array_equal(comp, fp)
    # at level 1 every child of a smooth face uses one of its parent's corners (R1 children
    # (c_f, u, m), flips (u, c_g, c_f), Kobbelt (c_f, u, w)); of a sharp face, 3 of 4 do
    if L == 1:
        F2 = np.asarray(r.faces)
        share = (F2[:, :, None] == F[fp][:, None, :]).any(axis=(1, 2))
        assert share[~mask_in[fp]].all()
        assert share[mask_in[fp]].sum() == 3 * mask_in.sum()


# ---------------------------------------------------------------------------------------
# the matrix
# ---------------------------------------------------------------------------------------


@cfg(40)
@given(st.data(), st.sampled_from(SCHEMES))
def test_matrix_stochastic_nonnegative(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes(sharpness="mixed") if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    lw = data.draw(st.sampled_from(["loop", "warren"]))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, loop_weights=lw, **tags)
    for S in [r.matrix] + [s.matrix for s in r.steps]:
        assert sp.issparse(S) and S.format == "csr"
        assert S.dtype == np.float64
        assert np.all(np.isfinite(S.data))
        assert S.data.size == 0 or S.data.min() >= 0.0, f"negative weight {S.data.min()}"
        np.testing.assert_allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-12)
    assert r.matrix.shape == (r.n_vertices, len(V))


@pytest.mark.parametrize("levels", [1, 2, 3])
@pytest.mark.parametrize("scheme", SCHEMES)
@cfg(12)
@given(data=st.data())
def test_matrix_reproduces_positions(levels, scheme, data):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    if len(F) * 4 ** levels > 8000:
        F = F[: max(1, 8000 // 4 ** levels)]
        V, F = ms.compact(V, F)
        tags = {}
    V2, F2, S = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, return_matrix=True, **tags)
    assert S.shape == (len(V2), len(V))
    np.testing.assert_allclose(np.asarray(V2), S @ V, rtol=0, atol=1e-12 * scale(V))
    V2b, F2b = positions(V, F, levels=levels, scheme=scheme, **tags)
    assert np.array_equal(V2b, V2) and np.array_equal(F2b, F2)
    r = hybridsub.refine(F, levels=levels, n_vertices=len(V), scheme=scheme, **tags)
    assert np.array_equal(r.faces, F2)
    assert_same_matrix(r.matrix, S, atol=0)


@cfg(30)
@given(st.data(), st.sampled_from(SCHEMES))
def test_matrix_is_product_of_steps(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    P = sp.identity(len(V), format="csr")
    n = len(V)
    for step in r.steps:
        assert step.matrix.shape[1] == n
        n = step.matrix.shape[0]
        P = step.matrix @ P
    assert_same_matrix(r.matrix, P, atol=1e-14)


@cfg(30)
@given(st.data(), st.sampled_from(SCHEMES))
def test_apply_equals_matrix_product(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    L = data.draw(st.integers(1, levels_for(len(F), scheme, max_levels=2)))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    X = data.draw(ms.rngs()).normal(size=(len(V), 5))
    Y = np.asarray(r.apply(X))
    assert Y.shape == (r.n_vertices, 5)
    np.testing.assert_allclose(Y, r.matrix @ X, rtol=0, atol=1e-12 * scale(X))


@cfg(30)
@given(st.data(), st.sampled_from(SCHEMES))
def test_affine_invariance(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    rng = data.draw(ms.rngs())
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    A = Q @ np.diag(rng.uniform(0.5, 2.0, size=3)) @ Q.T @ np.linalg.qr(rng.normal(size=(3, 3)))[0]
    t = rng.uniform(-10, 10, size=3)
    L = data.draw(st.integers(1, levels_for(len(F), scheme, max_levels=2)))
    V2, F2 = positions(V, F, levels=L, scheme=scheme, **tags)
    W2, G2 = positions(V @ A + t, F, levels=L, scheme=scheme, **tags)
    assert np.array_equal(F2, G2)
    ref = V2 @ A + t
    np.testing.assert_allclose(W2, ref, rtol=0, atol=1e-12 * scale(ref))


# ---------------------------------------------------------------------------------------
# creases, corners, flat regions
# ---------------------------------------------------------------------------------------


@st.composite
def closed_crease_setups(draw):
    """(V, F, tags, loops): mesh with closed crease loops without corners, and the loops
    as ordered vertex lists. Loops are boundary loops of bow-tie-free open meshes or tagged
    loops on closed meshes; no other crease touches them."""
    kind = draw(st.sampled_from(["boundary", "bipyramid", "torus"]))
    if kind == "boundary":
        V, F = draw(st.one_of(ms.open_meshes(bowties=False, max_points=40), ms.grid_meshes(),
                              ms.fan_meshes(closed=True, max_valence=24),
                              ms.triangle_meshes()))
        return V, F, {}, crease_loops(ms.boundary_edges(F))
    if kind == "bipyramid":
        k = draw(st.integers(3, 24))
        V, F = ms.bipyramid(k, flat_base=draw(st.booleans()))
        loop = list(range(2, 2 + k))
        V = V + draw(ms.rngs()).uniform(-0.1, 0.1, size=V.shape)
    else:
        nu, nv = draw(st.integers(3, 7)), draw(st.integers(3, 7))
        V, F = ms.torus(nu, nv, draw(ms.rngs()).random((nu, nv)) < 0.5)
        i = draw(st.integers(0, nu - 1))
        loop = [i * nv + j for j in range(nv)]
    E = np.array([[loop[j], loop[(j + 1) % len(loop)]] for j in range(len(loop))])
    return V, F, {"sharp_edges": E}, [loop]


@cfg(40)
@given(closed_crease_setups(), st.sampled_from(TAGGED_SCHEMES), st.data())
def test_closed_crease_loop_is_cubic_bspline(setup, scheme, data):
    V, F, tags, loops = setup
    if scheme == "hybrid":
        tags["sharp_faces"] = data.draw(ms.sharp_face_tags(len(F)))
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    V2 = r.apply(V)
    E2 = np.vstack([ms.boundary_edges(r.faces), np.asarray(r.sharp_edges).reshape(-1, 2)])
    adj = {}
    for u, w in E2.tolist():
        adj.setdefault(u, set()).add(w)
        adj.setdefault(w, set()).add(u)
    adj = {v: sorted(x) for v, x in adj.items()}
    for loop in loops:
        seq = walk_loop(adj, loop[0], loop[1], len(V))
        assert len(seq) == len(loop) * 2 ** L
        assert seq[:: 2 ** L] == loop, "old vertices out of order along the crease"
        np.testing.assert_allclose(V2[seq], bspline_closed(V[loop], L), rtol=0,
                                   atol=1e-12 * scale(V))


@cfg(40)
@given(st.data(), st.sampled_from(TAGGED_SCHEMES))
def test_corners_never_move(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes(sharpness="maybe"))
    if scheme == "loop":
        tags.pop("sharp_faces", None)
    if "corners" not in tags:
        tags["corners"] = data.draw(ms.corner_tags(len(V), max_fraction=0.5))
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    V2, F2 = positions(V, F, levels=L, scheme=scheme, **tags)
    c = np.asarray(tags["corners"], np.int64)
    assert np.array_equal(V2[c], V[c]), "tagged corners moved"
    # automatic corners: >= 3 infinitely sharp creases (boundary edges count) stay so
    cs = crease_sharpness(F, tags.get("sharp_edges"), tags.get("sharpness"))
    count = np.zeros(len(V), int)
    for (u, w), s in cs.items():
        if np.isinf(s):
            count[u] += 1
            count[w] += 1
    auto = np.flatnonzero(count >= 3)
    assert np.array_equal(V2[auto], V[auto]), "automatic corners moved"
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    assert set(np.asarray(r.corners).tolist()) == set(c.tolist())


@st.composite
def folded_grids(draw):
    """A grid in z = 0 for x <= k, bent up for x > k, with the crease x = k tagged."""
    nx, ny = draw(st.integers(2, 8)), draw(st.integers(1, 8))
    k = draw(st.integers(1, nx - 1))
    rng = draw(ms.rngs())
    I = np.arange(nx + 1)[:, None] * np.ones((1, ny + 1))
    z = np.where(I > k, (I - k) * rng.uniform(0.3, 2.0) + rng.uniform(0, 0.3, I.shape) * (I > k), 0.0)
    V, F = ms.grid(nx, ny, rng.random((nx, ny)) < 0.5, z=z)
    idx = lambda i, j: i * (ny + 1) + j  # noqa: E731
    E = np.array([[idx(k, j), idx(k, j + 1)] for j in range(ny)])
    region = np.all(V[F][:, :, 0] <= k, axis=1)
    mode = draw(st.sampled_from(["smooth", "sharp", "random"]))
    sharp = rng.random(len(F)) < 0.5
    if mode != "random":
        sharp[region] = mode == "sharp"
    extra = draw(ms.sharp_edge_tags(F, sharpness="maybe", duplicates=False,
                                    edges=ms.edges_of(F[~region])))
    # extra tags only inside the bent part, away from the flat region's vertices
    flat_v = set(F[region].ravel().tolist())
    keep = [i for i, e in enumerate(extra[0].tolist()) if not (set(e) & flat_v)]
    se = np.vstack([E, extra[0][keep]])
    tags = {"sharp_edges": se, "sharp_faces": sharp}
    if extra[1] is not None:
        tags["sharpness"] = np.concatenate([np.full(len(E), np.inf), extra[1][keep]])
    return V, F, tags, region


@cfg(30)
@given(folded_grids(), st.sampled_from(TAGGED_SCHEMES), st.data())
def test_flat_region_bounded_by_creases_stays_flat(setup, scheme, data):
    V, F, tags, region = setup
    if scheme == "loop":
        tags.pop("sharp_faces")
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    X = V
    parent = np.arange(len(F))
    for step in r.steps:
        X = step.matrix @ X
        parent = parent[np.asarray(step.face_parent)]
        Fk = np.asarray(step.faces)
        flat = np.unique(Fk[region[parent]])
        assert np.abs(X[flat, 2]).max() <= 1e-13, "flat region left its plane"
    # and the bent part did not flatten: some vertex outside has z > 0
    assert X[:, 2].max() > 0


# ---------------------------------------------------------------------------------------
# reductions between the schemes
# ---------------------------------------------------------------------------------------


@cfg(40)
@given(ms.meshes("closed"), st.data())
def test_hybrid_untagged_closed_is_sqrt3(mesh, data):
    V, F = mesh
    L = data.draw(st.integers(1, levels_for(len(F), "sqrt3")))
    Vh, Fh = positions(V, F, levels=L)
    Vs, Fs = positions(V, F, levels=L, scheme="sqrt3")
    assert np.array_equal(Fh, Fs)
    np.testing.assert_allclose(Vh, Vs, rtol=0, atol=1e-14 * scale(V))


@cfg(40)
@given(st.data())
def test_hybrid_all_sharp_is_loop(data):
    V, F, tags = data.draw(ms.tagged_meshes(sharpness="maybe", sharp_faces=False))
    form = data.draw(st.sampled_from(["mask", "indices"]))
    all_sharp = np.ones(len(F), bool) if form == "mask" else np.arange(len(F))
    L = data.draw(st.integers(1, levels_for(len(F), "loop")))
    lw = data.draw(st.sampled_from(["loop", "warren"]))
    rh = hybridsub.refine(F, levels=L, n_vertices=len(V), sharp_faces=all_sharp,
                          loop_weights=lw, **tags)
    rl = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme="loop", loop_weights=lw, **tags)
    assert np.array_equal(rh.faces, rl.faces)
    assert np.array_equal(rh.face_parent, rl.face_parent)
    assert_same_matrix(rh.matrix, rl.matrix, atol=1e-14)
    assert np.array_equal(np.asarray(rh.sharp_edges).reshape(-1, 2),
                          np.asarray(rl.sharp_edges).reshape(-1, 2))
    k = len(np.asarray(rh.sharp_edges).reshape(-1, 2))
    assert np.array_equal(norm_sharpness(rh.sharpness, k), norm_sharpness(rl.sharpness, k))
    assert np.array_equal(np.sort(rh.corners), np.sort(rl.corners))
    Vh, _ = positions(V, F, levels=L, sharp_faces=all_sharp, loop_weights=lw, **tags)
    Vl, _ = positions(V, F, levels=L, scheme="loop", loop_weights=lw, **tags)
    np.testing.assert_allclose(Vh, Vl, rtol=0, atol=1e-14 * scale(V))


@cfg(30)
@given(st.data(), st.sampled_from(TAGGED_SCHEMES))
def test_two_calls_equal_one(data, scheme):
    """Refining the output of one level with its returned tags = refining two levels."""
    V, F, tags = data.draw(ms.tagged_meshes(sharpness=data.draw(st.sampled_from(["maybe", "mixed0"]))))
    if scheme == "loop":
        tags.pop("sharp_faces", None)
    if len(F) * 16 > 6000:
        return
    r2 = hybridsub.refine(F, levels=2, n_vertices=len(V), scheme=scheme, **tags)
    r1 = hybridsub.refine(F, levels=1, n_vertices=len(V), scheme=scheme, **tags)
    kw = dict(sharp_edges=r1.sharp_edges, sharpness=r1.sharpness, corners=r1.corners)
    if scheme == "hybrid":
        kw["sharp_faces"] = r1.sharp_faces
    rb = hybridsub.refine(r1.faces, levels=1, n_vertices=r1.n_vertices, scheme=scheme, **kw)
    assert np.array_equal(rb.faces, r2.faces)
    assert_same_matrix(rb.matrix @ r1.matrix, r2.matrix, atol=1e-14)
    assert np.array_equal(np.asarray(rb.sharp_edges).reshape(-1, 2),
                          np.asarray(r2.sharp_edges).reshape(-1, 2))


# ---------------------------------------------------------------------------------------
# API hygiene
# ---------------------------------------------------------------------------------------


@cfg(30)
@given(st.data(), st.sampled_from(SCHEMES))
def test_deterministic(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes() if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    L = data.draw(st.integers(1, levels_for(len(F), scheme, max_levels=2)))
    a = hybridsub.subdivide(V, F, levels=L, scheme=scheme, return_matrix=True, **tags)
    b = hybridsub.subdivide(V, F, levels=L, scheme=scheme, return_matrix=True, **tags)
    assert np.asarray(a[0]).tobytes() == np.asarray(b[0]).tobytes()
    assert np.asarray(a[1]).tobytes() == np.asarray(b[1]).tobytes()
    for x, y in zip((a[2].data, a[2].indices, a[2].indptr), (b[2].data, b[2].indices, b[2].indptr)):
        assert x.tobytes() == y.tobytes()


@cfg(15)  # calls every entry point per example: ~0.15 s each
@given(st.data(), st.sampled_from(SCHEMES), st.booleans())
def test_inputs_not_modified_and_read_only_ok(data, scheme, read_only):
    V, F, tags = data.draw(ms.tagged_meshes(sharpness="mixed0") if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    args = {"V": V, "F": F, **tags}
    copies = {k: np.array(v, copy=True) for k, v in args.items()}
    if read_only:
        for v in args.values():
            v.setflags(write=False)
    L = data.draw(st.integers(1, levels_for(len(F), scheme, max_levels=2)))
    V2, F2 = positions(V, F, levels=L, scheme=scheme, **tags)
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), scheme=scheme, **tags)
    r.apply(V)
    for k, v in args.items():
        assert v.dtype == copies[k].dtype and np.array_equal(v, copies[k]), f"{k} was modified"
    assert np.array_equal(r.faces, F2)
    # the outputs are not views of the inputs
    assert not np.shares_memory(np.asarray(V2), V)
    assert not np.shares_memory(np.asarray(F2), F)


@pytest.mark.parametrize("tag", ["sharp_edges", "sharpness", "sharp_faces", "corners"])
def test_sqrt3_rejects_tags(tag):
    V, F = ms.octahedron()
    tags = {"sharp_edges": np.array([[0, 2]]), "sharpness": np.array([np.inf]),
            "sharp_faces": np.array([0]), "corners": np.array([1])}
    kw = {tag: tags[tag]}
    if tag == "sharpness":
        kw["sharp_edges"] = tags["sharp_edges"]
    with pytest.raises(ValueError):
        hybridsub.subdivide(V, F, scheme="sqrt3", **kw)
    with pytest.raises(ValueError):
        hybridsub.refine(F, scheme="sqrt3", **kw)


@cfg(20)
@given(ms.with_unused_vertices(ms.meshes("any"), max_extra=4), st.sampled_from(SCHEMES))
def test_unused_vertices_kept_and_fixed(mesh, scheme):
    V, F = mesh
    V2, F2 = positions(V, F, scheme=scheme)
    unused = np.setdiff1d(np.arange(len(V)), F.ravel())
    assert np.array_equal(V2[unused], V[unused])
    assert not np.isin(unused, F2).any()


@cfg(20)
@given(st.data(), st.sampled_from(SCHEMES))
def test_zero_levels_is_identity(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes(sharpness="inf") if scheme != "sqrt3" else
                           ms.meshes("any").map(lambda m: (m[0], m[1], {})))
    r = hybridsub.refine(F, levels=0, n_vertices=len(V), scheme=scheme, **tags)
    assert len(r.steps) == 0 and r.n_vertices == len(V)
    assert np.array_equal(r.faces, F) and np.array_equal(r.face_parent, np.arange(len(F)))
    assert_same_matrix(r.matrix, sp.identity(len(V)), atol=0)
    assert np.array_equal(r.apply(V), V)
    V2, F2 = positions(V, F, levels=0, scheme=scheme, **tags)
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


@cfg(20)
@given(ms.meshes("any"), st.sampled_from(SCHEMES))
def test_default_n_vertices(mesh, scheme):
    V, F = mesh
    a = hybridsub.refine(F, scheme=scheme)
    b = hybridsub.refine(F, n_vertices=int(F.max()) + 1, scheme=scheme)
    assert a.matrix.shape[1] == int(F.max()) + 1
    assert np.array_equal(a.faces, b.faces)
    assert_same_matrix(a.matrix, b.matrix, atol=0)
