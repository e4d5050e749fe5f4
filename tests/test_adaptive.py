"""Adaptive refinement (docs/adaptive.md): crack-free and exact, on random tagged meshes and the
shipped ones.

The oracles: the uniform refinement (``hybridsub.refine(...).apply(V)`` at every level, each
adaptive vertex matched by position to a vertex of the uniform level it claims), the mesh
checks of ``tests/strategies.py`` (manifold, oriented, Euler characteristic, boundary) and the
limit positions of ``hybridsub.limit_positions`` at the matched uniform vertices.
"""

import json
import os
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

import strategies as ms

hybridsub = pytest.importorskip("hybridsub")

DATA = os.path.join(os.path.dirname(__file__), "data")
SCALE = int(os.environ.get("HYBRIDSUB_PROPERTY_SCALE", "1"))


def cfg(n):
    # repeatable examples unless HYBRIDSUB_EXPLORE=1 (tests/conftest.py); what a fresh search
    # finds becomes a test of its own (tests/test_limit_oracle.py)
    return settings(max_examples=n * SCALE, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])


def diagonal(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) or 1.0


def _piece_of_vertices(F0, faces, face_parent, n):
    """The connected piece of the input (``F0``) each vertex of ``faces`` lies in, through the
    input face its faces descend from (−1: unused)."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    m = len(F0)
    A = sp.coo_matrix((np.ones(3 * m), (np.repeat(np.arange(m), 3), F0.ravel())))
    _, piece = connected_components(A @ A.T, directed=False)
    out = np.full(n, -1, np.int64)
    out[faces.ravel()] = np.repeat(piece[face_parent], 3)
    return out


def uniform_match(V, F, tags, scheme, r, X):
    """For each level j, the uniform level-j index of every adaptive vertex of level j (by
    position, within the same connected piece of the input: pieces may touch at coincident
    vertices); asserts each lies on one, to 1e-12 × the diagonal."""
    tol = 1e-12 * diagonal(V)
    F0, V0 = F, V
    top = int(r.vertex_level.max(initial=0))
    index = np.full(len(X), -1, np.int64)
    apart = 10.0 * (diagonal(V) + 1.0)
    if tags.get("non_manifold") == "cut":  # the cut copy's pieces and level 0 (its sheets meet at coincident vertices)
        from hybridsub._input import open_gate
        cut = open_gate(F, tags.get("sharp_edges"), 0, n_vertices=len(V), scheme=scheme, non_manifold="cut")
        F, V0 = cut.faces, V[cut.cut.origin]
    piece = _piece_of_vertices(F, r.faces, r.face_parent, len(X))
    # Holes hide faces and leave the refinement as it is: the uniform vertices' pieces are
    # those of the whole refinement, and a vertex only hidden faces use is not matched.
    tags = {k: v for k, v in tags.items() if k != "holes"}
    if tags.get("boundary") == "none":
        tags["boundary"] = "edge_only"
    for j in range(top + 1):
        sel = np.flatnonzero((r.vertex_level == j) & (piece >= 0))
        if not len(sel):
            continue
        if j:
            u = hybridsub.refine(F0, levels=j, scheme=scheme, n_vertices=len(V), **tags)
            U, upiece = u.apply(V), _piece_of_vertices(F, u.faces, u.face_parent, u.n_vertices)
        else:
            U, upiece = V0, _piece_of_vertices(F, F, np.arange(len(F)), len(V0))
        d, idx = cKDTree(np.column_stack([U, apart * upiece])).query(np.column_stack([X[sel], apart * piece[sel]]))
        assert d.max() <= tol, (j, float(d.max()))
        # Old vertices keep their indices (refine's layout): where the uniform vertex of the same
        # index is there too, it is the one (meshes such as elephant-with-holes repeat positions).
        same = sel < len(V0)
        at = np.linalg.norm(U[sel[same]] - X[sel[same]], axis=1) <= tol
        idx[np.flatnonzero(same)[at]] = sel[same][at]
        index[sel] = idx
    return index


def check_crack_free(V, F, r):
    """Manifold, consistently oriented, no degenerate or duplicate face, every vertex used,
    same Euler characteristic and as many boundary loops as the input (no T-vertex: one would
    open a hole)."""
    G = r.faces
    ms.check_mesh(None, G, nV=r.n_vertices)
    used = np.unique(F)
    assert len(np.unique(G)) == r.n_vertices - (len(V) - len(used))
    assert ms.euler(r.n_vertices, G) == ms.euler(len(V), F)
    assert _loops(ms.boundary_edges(G)) == _loops(ms.boundary_edges(F))
    assert len(r.face_level) == len(G) and len(r.vertex_level) == r.n_vertices
    assert len(r.face_parent) == len(G)


def _loops(E):
    """Number of boundary loops (connected components of the boundary edges)."""
    if not len(E):
        return 0
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    verts, inv = np.unique(E, return_inverse=True)
    inv = inv.reshape(-1, 2)
    A = sp.coo_matrix((np.ones(len(E)), (inv[:, 0], inv[:, 1])), shape=(len(verts), len(verts)))
    return connected_components(A, directed=False)[0]


@cfg(30)
@given(mesh=ms.tagged_meshes(bowties=False), data=st.data())
def test_region_refinement_is_crack_free_and_exact(mesh, data):
    V, F, tags = mesh
    scheme = data.draw(st.sampled_from(["hybrid", "loop", "sqrt3"]))
    if scheme == "sqrt3":  # Kobbelt's √3 takes no tags; open meshes follow his boundary rule
        tags = {}
    levels = data.draw(st.integers(0, 4 if len(F) <= 40 else 3))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    form = data.draw(st.sampled_from(["mask", "indices"]))
    where = rng.random(len(F)) < data.draw(st.sampled_from([0.05, 0.2, 0.5]))
    arg = where if form == "mask" else np.flatnonzero(where)
    r = hybridsub.refine_adaptive(F, where=arg, levels=levels, scheme=scheme, n_vertices=len(V), **tags)
    check_crack_free(V, F, r)
    X = r.apply(V)
    uniform_match(V, F, tags, scheme, r, X)
    # The faces asked for are refined `levels` times.
    assert (r.face_level[where[r.face_parent]] == levels).all()
    assert r.face_level.max(initial=0) <= levels


def _options(data, V, F, tags, scheme):
    """corner_sharpness (finite or infinite per corner), boundary and holes, drawn."""
    tags = dict(tags)
    if tags.get("corners") is not None and len(tags["corners"]) and scheme != "sqrt3":
        cs = data.draw(st.lists(st.sampled_from([0.5, 1.0, 1.5, 2.5, np.inf]), min_size=len(tags["corners"]),
                                max_size=len(tags["corners"])))
        tags["corner_sharpness"] = np.array(cs)
    tags["boundary"] = data.draw(st.sampled_from(["edge_only", "edge_and_corner", "none"]))
    if data.draw(st.booleans()):
        tags["holes"] = np.flatnonzero(np.random.default_rng(len(F)).random(len(F)) < 0.1)
    return tags


@cfg(30)
@given(mesh=ms.tagged_meshes(bowties=False), data=st.data())
def test_region_refinement_with_options_is_exact(mesh, data):
    # corner_sharpness, boundary and holes as refine takes them: every vertex is the uniform
    # refinement's (with the same options) at its level; the holes' descendants left out.
    V, F, tags = mesh
    scheme = data.draw(st.sampled_from(["hybrid", "loop", "sqrt3"]))
    if scheme == "sqrt3":
        tags = {}
    tags = _options(data, V, F, tags, scheme)
    levels = data.draw(st.integers(1, 3 if len(F) <= 40 else 2))
    where = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1))).random(len(F)) < 0.3
    r = hybridsub.refine_adaptive(F, where=where, levels=levels, scheme=scheme, n_vertices=len(V), **tags)
    uniform_match(V, F, tags, scheme, r, r.apply(V))
    # Holes (and boundary="none"'s) leave the refinement as it is and hide faces, as refine does.
    shown = {k: v for k, v in tags.items() if k != "holes"}
    if shown["boundary"] == "none":
        shown["boundary"] = "edge_only"
    full = hybridsub.refine_adaptive(F, where=where, levels=levels, scheme=scheme, n_vertices=len(V), **shown)
    assert np.array_equal(r.apply(V), full.apply(V))
    hidden = np.ones(len(F), bool)
    hidden[hybridsub.refine(F, levels=1, scheme=scheme, n_vertices=len(V), **tags).face_parent] = False
    assert np.array_equal(r.faces, full.faces[~hidden[full.face_parent]])
    assert (r.face_level[where[r.face_parent]] == levels).all()
    # The corners (with boundary="edge_and_corner" also its own) and the sharpness left to
    # each at its level, as refine gives them at that level.
    u0 = hybridsub.refine(F, levels=0, scheme=scheme, n_vertices=len(V), **tags)
    cs = np.zeros(len(V))
    cs[u0.corners] = np.inf if u0.corner_sharpness is None else u0.corner_sharpness
    left = np.where(np.isinf(cs), cs, np.maximum(cs - r.vertex_level[:len(V)], 0))
    assert np.array_equal(np.sort(r.corners), np.flatnonzero(left > 0))
    if r.corner_sharpness is not None:
        assert np.array_equal(r.corner_sharpness, left[r.corners])


@cfg(5)
@given(mesh=ms.tagged_meshes(bowties=False), data=st.data())
def test_tolerance_with_options_is_exact(mesh, data):
    V, F, tags = mesh
    scheme = data.draw(st.sampled_from(["hybrid", "loop", "sqrt3"]))
    if scheme == "sqrt3":
        tags = {}
    tags = _options(data, V, F, tags, scheme)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hybridsub.AdaptiveWarning)
        r = hybridsub.refine_adaptive(F, V=V, tolerance="3%", max_levels=2, scheme=scheme, **tags)
        V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="3%", max_levels=2, scheme=scheme, **tags)
    assert np.array_equal(F2, r.faces)
    index = uniform_match(V, F, tags, scheme, r, r.apply(V))
    used = np.isin(np.arange(r.n_vertices), F2)
    for j in range(int(r.vertex_level.max(initial=0)) + 1):
        sel = np.flatnonzero((r.vertex_level == j) & used)
        if len(sel):
            L = hybridsub.limit_positions(V, F, levels=j, scheme=scheme, **tags)
            d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
            assert d.max() <= 1e-9, (j, float(d.max()))


def test_tolerance_with_boundary_and_holes():
    I, J = np.meshgrid(np.arange(7), np.arange(7), indexing="ij")
    V, F = ms.grid(6, 6, (I[:6, :6] + J[:6, :6]) % 2 == 0, z=np.sin(I) * np.cos(0.7 * J))
    holes = [3, 17]
    for boundary in ("edge_only", "edge_and_corner", "none"):
        tags = dict(boundary=boundary, holes=holes)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            r = hybridsub.refine_adaptive(F, V=V, tolerance="0.5%", scheme="loop", **tags)
            V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="0.5%", scheme="loop", **tags)
        assert np.array_equal(F2, r.faces)
        index = uniform_match(V, F, tags, "loop", r, r.apply(V))
        used = np.isin(np.arange(r.n_vertices), F2)
        for j in range(int(r.vertex_level.max()) + 1):
            sel = np.flatnonzero((r.vertex_level == j) & used)
            L = hybridsub.limit_positions(V, F, levels=j, scheme="loop", **tags)
            d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
            assert d.max(initial=0) <= 1e-9, (boundary, j, d.max())
        u = hybridsub.refine(F, levels=1, scheme="loop", **tags)
        assert np.array_equal(np.unique(r.face_parent), np.unique(u.face_parent))  # holes left out


def _book(n=4):
    """Three bumpy sheets sharing a row of edges (each of them in three faces)."""
    I, J = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    G, Fg = ms.grid(n, n, (I[:n, :n] + J[:n, :n]) % 2 == 0)
    x, y = G[:, 0], G[:, 1]
    sheets = [np.column_stack([x, y, 0.2 * np.sin(x) * y]), np.column_stack([x, 0 * y, y + 0.1 * x * y]),
              np.column_stack([x, 0 * y, -y])]
    V = np.vstack(sheets)
    F = np.vstack([Fg, Fg + len(G), Fg[:, ::-1] + 2 * len(G)])
    _, first, inv = np.unique(np.round(V, 9), axis=0, return_index=True, return_inverse=True)
    return V[first], inv.ravel()[F]


def _cut_tolerance_run(V, F, scheme, tags):
    """The book cut apart and refined to 0.1 % of its diagonal, with no warning: the positions,
    the refinement (the same faces) and each vertex's uniform vertex."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="0.1%", scheme=scheme, **tags)
        r = hybridsub.refine_adaptive(F, V=V, tolerance="0.1%", scheme=scheme, **tags)
    assert np.array_equal(F2, r.faces) and r.vertex_level.max() >= 2
    return V2, r, uniform_match(V, F, tags, scheme, r, r.apply(V))


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_non_manifold_cut_is_exact(scheme):
    # non_manifold="cut" as refine takes it: the region's vertices are the uniform refinement's
    # of the cut copy; to a tolerance, at the cut copy's limit positions. (√3: the cut edges
    # are boundary edges of the copy, Kobbelt's boundary rule.)
    V, F = _book()
    tags = dict(non_manifold="cut", sharp_edges=None if scheme == "sqrt3" else F[:2, :2])
    with pytest.raises(hybridsub.MeshError):
        hybridsub.refine_adaptive(F, where=[0], levels=1, scheme=scheme)
    r = hybridsub.refine_adaptive(F, where=np.arange(12), levels=2, scheme=scheme, **tags)
    uniform_match(V, F, tags, scheme, r, r.apply(V))
    assert r.face_level.max() == 2 and r.face_level.min() == 0
    V2, r, index = _cut_tolerance_run(V, F, scheme, tags)
    from hybridsub._input import open_gate
    cut = open_gate(F, tags["sharp_edges"], 0, scheme=scheme, non_manifold="cut")  # the cut copy
    for j in range(int(r.vertex_level.max()) + 1):
        sel = np.flatnonzero(r.vertex_level == j)
        L = hybridsub.limit_positions(V[cut.cut.origin], cut.faces, cut.sharp_edges if len(cut.sharp_edges) else None,
                                      levels=j, scheme=scheme, corners=np.flatnonzero(cut.corner))
        d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
        assert d.max(initial=0) <= 1e-9, (j, d.max())


@pytest.mark.parametrize("scheme", ["loop", "sqrt3"])
def test_cut_tolerance_with_edge_and_corner(scheme):
    # The cut copy's lone boundary vertices are corners (boundary="edge_and_corner"): the
    # criterion's surface pins them too, so the tolerance is reached, at the limit positions.
    V, F = _book()
    tags = dict(non_manifold="cut", boundary="edge_and_corner")
    V2, r, index = _cut_tolerance_run(V, F, scheme, tags)
    from hybridsub._input import open_gate
    cut = open_gate(F, None, 0, scheme=scheme, non_manifold="cut")
    corners = {} if scheme == "sqrt3" else dict(corners=np.flatnonzero(cut.corner))
    for j in range(int(r.vertex_level.max()) + 1):
        sel = np.flatnonzero(r.vertex_level == j)
        L = hybridsub.limit_positions(V[cut.cut.origin], cut.faces, levels=j, scheme=scheme,
                                      boundary="edge_and_corner", **corners)
        d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
        assert d.max(initial=0) <= 1e-9, (j, d.max())


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_tolerance_with_semi_sharp_corners(scheme):
    # A corner of sharpness 1.5 is pinned for two levels, then moves: its limit is not the
    # infinitely sharp corner's, and every output vertex is at its uniform vertex's limit.
    V, F = ms.icosahedron()
    tags = dict(corners=[0, 5], corner_sharpness=[1.5, np.inf])
    r = hybridsub.refine_adaptive(F, V=V, tolerance="1%", scheme=scheme, **tags)
    V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="1%", scheme=scheme, **tags)
    assert np.array_equal(F2, r.faces) and r.vertex_level.max() >= 2
    index = uniform_match(V, F, tags, scheme, r, r.apply(V))
    for j in range(int(r.vertex_level.max()) + 1):
        sel = np.flatnonzero(r.vertex_level == j)
        L = hybridsub.limit_positions(V, F, levels=j, scheme=scheme, **tags)
        d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
        assert d.max(initial=0) <= 1e-9, (j, d.max())
    assert np.allclose(V2[5], V[5]) and not np.allclose(V2[0], V[0])
    Vb, Fb = _book()  # cut copies of a semi-sharp corner: refused by name with a tolerance
    with pytest.raises(ValueError, match="infinitely sharp corners only"):
        hybridsub.subdivide_adaptive(Vb, Fb, tolerance="1%", scheme=scheme, non_manifold="cut", corners=[0],
                                     corner_sharpness=[1.5])


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_fandisk_region_exact_and_fewer_faces(scheme):
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    tags = {} if scheme == "sqrt3" else dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
    c = V[F].mean(axis=1)
    where = np.argsort(np.linalg.norm(c - c[0], axis=1))[:len(F) // 7]  # a patch of 15 % of the faces
    r = hybridsub.refine_adaptive(F, where=where, levels=2, scheme=scheme, **tags)
    check_crack_free(V, F, r)
    uniform_match(V, F, tags, scheme, r, r.apply(V))
    uniform = hybridsub.refine(F, levels=2, scheme=scheme, **tags)
    assert len(r.faces) < 0.5 * len(uniform.faces)
    assert r.face_level.max() == 2 and r.face_level.min() == 0


def test_fandisk_to_the_issues_tolerance_both_ways():
    # The default scheme on the shipped example with its 30° creases and corners, at 2e-4 × the
    # diagonal: within the tolerance both ways by the chart-free oracle, and in fewer than half
    # the faces of the coarsest uniform level as close (level 1 is not, by the same oracle).
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    tags = dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
    tol = 2e-4 * diagonal(V)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = hybridsub.refine_adaptive(F, V=V, tolerance=tol, **tags)
    V2 = hybridsub.subdivide_adaptive(V, F, tolerance=tol, **tags)[0]
    check_crack_free(V, F, r)
    surf = hybridsub.LimitSurface(V, F, **tags)
    assert _two_sided_error(V, F, V2, r.faces, surf) <= 1.5 * tol
    level1 = hybridsub.refine(F, levels=1, **tags).faces
    assert _two_sided_error(V, F, hybridsub.limit_positions(V, F, levels=1, **tags), level1, surf) > tol
    assert len(r.faces) < 0.5 * len(hybridsub.refine(F, levels=2, **tags).faces)


def test_everything_at_the_level_is_the_uniform_refinement():
    V, F = ms.icosahedron()
    for scheme in ("hybrid", "loop", "sqrt3"):
        r = hybridsub.refine_adaptive(F, where=np.ones(len(F), bool), levels=2, scheme=scheme)
        u = hybridsub.refine(F, levels=2, scheme=scheme)
        assert np.array_equal(r.faces, u.faces) or len(r.faces) == len(u.faces)
        assert np.allclose(r.apply(V)[:u.n_vertices].sum(0), u.apply(V).sum(0))
        assert (r.face_level == 2).all() and (r.vertex_level == 2).all()


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_tolerance_is_reached_and_limit_positions_are_exact(scheme):
    V, F = ms.torus(8, 6)
    feat_edges = np.array([[0, 1], [1, 2], [2, 3]])
    tags = dict(sharp_edges=feat_edges)
    tol = (2e-3 if scheme == "loop" else 6e-3) * diagonal(V)  # the surface evaluator is slower on √3 faces
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = hybridsub.refine_adaptive(F, V=V, tolerance=tol, scheme=scheme, **tags)
        V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance=tol, scheme=scheme, **tags)
    assert np.array_equal(F2, r.faces)
    check_crack_free(V, F, r)
    index = uniform_match(V, F, tags, scheme, r, r.apply(V))
    # Output vertices at the limit positions of the uniform vertices they are.
    surf = hybridsub.LimitSurface(V, F, scheme=scheme, **tags)
    for j in range(int(r.vertex_level.max()) + 1):
        sel = np.flatnonzero(r.vertex_level == j)
        if not len(sel):
            continue
        L = hybridsub.limit_positions(V, F, levels=j, scheme=scheme, **tags)
        d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
        assert d.max() <= 1e-12, (j, d.max())
    # The tolerance holds both ways, measured without the chart and more densely.
    err = _two_sided_error(V, F, V2, F2, surf)
    assert err <= 1.5 * tol, err / tol
    # Fewer faces than the uniform level that is as fine as the finest adaptive face.
    top = int(r.face_level.max())
    assert len(F2) < len(hybridsub.refine(F, levels=top, scheme=scheme, **tags).faces)


def test_unreachable_tolerance_warns_with_the_error_reached():
    V, F = ms.icosahedron()
    with pytest.warns(hybridsub.AdaptiveWarning, match="not reached in max_levels=1"):
        V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance=1e-9, max_levels=1, scheme="loop")
    assert len(F2) == 4 * len(F)


def test_percent_tolerance_is_of_the_diagonal():
    V, F = ms.icosahedron()
    d = diagonal(V)
    a = hybridsub.subdivide_adaptive(V, F, tolerance="0.5%", scheme="loop")
    b = hybridsub.subdivide_adaptive(V, F, tolerance=0.005 * d, scheme="loop")
    assert np.array_equal(a[1], b[1]) and np.allclose(a[0], b[0])


def test_limit_false_gives_level_positions():
    V, F = ms.icosahedron()
    r = hybridsub.refine_adaptive(F, V=V, tolerance="1%", limit=False, scheme="loop")
    V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="1%", limit=False, scheme="loop")
    assert np.array_equal(F2, r.faces)
    assert np.allclose(V2, r.apply(V), atol=1e-14)


def test_vertex_origin_of_an_adaptive_refinement():
    V, F = ms.icosahedron()
    r = hybridsub.refine_adaptive(F, where=[0, 1, 2], levels=2, scheme="loop")
    face, bary = r.vertex_origin
    surf = hybridsub.LimitSurface(V, F, scheme="loop")
    P = surf.evaluate(face, bary)
    index = uniform_match(V, F, {}, "loop", r, r.apply(V))
    for j in range(3):
        sel = r.vertex_level == j
        L = hybridsub.limit_positions(V, F, levels=j, scheme="loop")
        assert np.allclose(P[sel], L[index[sel]], atol=1e-12)


# ------------------------------------------------------------------------------------------
# Bad input: refused like refine refuses it, and the adaptive arguments by name
# ------------------------------------------------------------------------------------------

TET = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
TETV = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


@pytest.mark.parametrize("kwargs", [
    dict(F=[[0, 1, 2], [0, 1, 2]]),                      # duplicate faces
    dict(F=[[0, 1, 2], [0, 1, 3], [0, 1, 4]]),            # non-manifold edge
    dict(F=[[0, 1, 2], [1, 0, 3], [0, 1, 4]]),
    dict(F=[[0, 1, 1]]),                                  # repeated vertex
    dict(F=[[0, 1, 2.5]]),
    dict(F=TET, sharp_edges=[[0, 5]]),                    # not an edge
    dict(F=TET, sharpness=[1.0]),
    dict(F=TET, scheme="catmull"),
    dict(F=TET, sharp_faces=[7]),
    dict(F=TET, corners=[9]),
])
def test_refused_like_refine(kwargs):
    kwargs = dict(kwargs)
    F = kwargs.pop("F")
    with pytest.raises((ValueError, TypeError)) as uniform:
        hybridsub.refine(F, levels=1, **kwargs)
    with pytest.raises(type(uniform.value)) as adaptive:
        hybridsub.refine_adaptive(F, where=[0], levels=1, **kwargs)
    assert str(adaptive.value) == str(uniform.value)


@pytest.mark.parametrize("kwargs, match", [
    (dict(where=np.ones(3, bool), levels=1), r"one entry per face, shape \(4,\)"),
    (dict(where=[0, 9], levels=1), r"where\[1\] = 9 is not a face"),
    (dict(where=[0.5], levels=1), "boolean mask of the 4 faces or a 1-D array of face indices"),
    (dict(where=[[0]], levels=1), "boolean mask of the 4 faces or a 1-D array of face indices"),
    (dict(where=[0], levels=-1), "levels must be a non-negative integer"),
    (dict(where=[0]), "needs levels="),
    (dict(levels=1), "needs where="),
    (dict(V=TETV, tolerance=0.0), "tolerance must be positive and finite"),
    (dict(V=TETV, tolerance=-1.0), "tolerance must be positive and finite"),
    (dict(V=TETV, tolerance=float("nan")), "tolerance must be positive and finite"),
    (dict(V=TETV, tolerance=float("inf")), "tolerance must be positive and finite"),
    (dict(V=TETV, tolerance="abc"), "percentage"),
    (dict(V=TETV, tolerance="-1%"), "tolerance must be positive and finite"),
    (dict(V=TETV, tolerance=None), "needs both V= and tolerance="),
    (dict(V=TETV, tolerance=0.1, max_levels=-1), "max_levels must be a non-negative integer"),
    (dict(V=TETV, tolerance=0.1, where=[0], levels=1), "not both"),
])
def test_adaptive_arguments_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        hybridsub.refine_adaptive(TET, **kwargs)


# ------------------------------------------------------------------------------------------
# Kobbelt's √3 with a boundary: boundary edges kept on odd steps, trisected on even ones
# ------------------------------------------------------------------------------------------

def _shipped(name):
    m = hybridsub.read_mesh(os.path.join(DATA, name + ".off"))
    return m.vertices, m.faces


def _point_triangle_distance(X, T):
    """The distance of each point ``X`` (k, 3) to its triangle ``T`` (k, 3, 3): to the foot on
    the plane where that foot is inside, else to the nearest of the three edges (an
    implementation of its own, not the Voronoi-region one the library uses)."""
    A, B, C = T[:, 0], T[:, 1], T[:, 2]
    e1, e2, w = B - A, C - A, X - A
    d00, d01, d11 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    d20, d21 = (w * e1).sum(1), (w * e2).sum(1)
    den = d00 * d11 - d01 * d01
    with np.errstate(divide="ignore", invalid="ignore"):
        v = (d11 * d20 - d01 * d21) / den
        u = (d00 * d21 - d01 * d20) / den
        inside = (den > 1e-30 * d00 * d11) & (v >= 0) & (u >= 0) & (u + v <= 1)
    foot = A + np.where(inside, v, 0)[:, None] * e1 + np.where(inside, u, 0)[:, None] * e2
    best = np.where(inside, np.linalg.norm(X - foot, axis=1), np.inf)
    for P, Q in ((A, B), (B, C), (C, A)):
        d = Q - P
        t = np.clip(((X - P) * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(X - P - t[:, None] * d, axis=1))
    return best


def _distance_to_mesh(S, V2, F2):
    """The distance of each point ``S`` to the triangle mesh ``(V2, F2)``, exact and without the
    library's closest-point code: an upper bound from the 8 faces of nearest centroid, then
    every face whose bounding sphere comes within it (:func:`_point_triangle_distance`)."""
    T = V2[F2]
    C = T.mean(axis=1)
    R = np.linalg.norm(T - C[:, None], axis=2).max(axis=1)
    tree = cKDTree(C)
    k = min(8, len(F2))
    near = tree.query(S, k=k)[1].reshape(len(S), k)
    i = np.repeat(np.arange(len(S)), k)
    best = np.full(len(S), np.inf)
    np.minimum.at(best, i, _point_triangle_distance(S[i], T[near.ravel()]))
    balls = tree.query_ball_point(S, best + R.max())
    i = np.repeat(np.arange(len(S)), [len(b) for b in balls])
    f = np.concatenate([np.asarray(b, np.int64) for b in balls])
    keep = np.linalg.norm(S[i] - C[f], axis=1) - R[f] <= best[i]
    np.minimum.at(best, i[keep], _point_triangle_distance(S[i[keep]], T[f[keep]]))
    return best


def test_the_oracles_point_triangle_distance_is_the_brute_force_one():
    # Its own check: random and degenerate triangles (a needle, a point) against the nearest
    # of 321,201 points of each triangle.
    rng = np.random.default_rng(4)
    T = rng.standard_normal((40, 3, 3))
    T[0, 2] = T[0, 1] + 1e-9 * (T[0, 1] - T[0, 0])  # a needle
    T[1, :] = T[1, 0]  # a point
    X = 2 * rng.standard_normal((40, 3))
    g = np.linspace(0, 1, 801)
    u, v = (a.ravel() for a in np.meshgrid(g, g))
    ok = u + v <= 1
    u, v = u[ok], v[ok]
    got = _point_triangle_distance(X, T)
    for x, t, d in zip(X, T, got):
        grid = (1 - u - v)[:, None] * t[0] + u[:, None] * t[1] + v[:, None] * t[2]
        brute = np.linalg.norm(grid - x, axis=1).min()
        assert d <= brute + 1e-12 and d >= brute - 3e-3 * np.linalg.norm(t[1:] - t[0], axis=1).max()


def _two_sided_error(V, F, V2, F2, surface, faces=200, points=3000, seed=0):
    """The largest distance, both ways, between the output ``(V2, F2)`` and the limit surface,
    measured without the parameter chart the criterion uses: 15 points of each of ``faces``
    random output faces projected onto the surface (``LimitSurface.project``, the closest
    point), and ``points`` surface points at random parameters of the input faces against
    the whole output (:func:`_distance_to_mesh`)."""
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(F2), min(faces, len(F2)), replace=False)
    g = np.linspace(0, 1, 5)
    B = np.array([(a, b, 1 - a - b) for a in g for b in g if a + b <= 1 + 1e-12])
    X = np.einsum("sj,fjc->fsc", B, V2[F2[pick]]).reshape(-1, 3)
    out_to_surface = np.linalg.norm(surface.project(X)[2] - X, axis=1).max()
    S = surface.evaluate(rng.integers(0, len(F), points), rng.dirichlet([1, 1, 1], points))
    return float(max(out_to_surface, _distance_to_mesh(S, V2, F2).max()))


def _at_limit_positions(V, F, r, V2, scheme, tags, bound=1e-9):
    """Every used output vertex at the limit position of the uniform vertex it is."""
    index = uniform_match(V, F, tags, scheme, r, r.apply(V))
    used = np.isin(np.arange(r.n_vertices), r.faces)
    for j in range(int(r.vertex_level.max(initial=0)) + 1):
        sel = np.flatnonzero((r.vertex_level == j) & used)
        if len(sel):
            L = hybridsub.limit_positions(V, F, levels=j, scheme=scheme, **tags)
            d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
            assert d.max() <= bound, (j, float(d.max()))


@pytest.mark.parametrize("name, levels", [("mesh_with_border", 4), ("elephant-with-holes", 3)])
def test_sqrt3_region_on_shipped_open_meshes(name, levels):
    # A patch that reaches the boundary, refined through trisecting (even) steps: every vertex
    # the uniform refinement's, the boundary loops kept, no T-vertex.
    V, F = _shipped(name)
    boundary_face = np.flatnonzero(np.isin(F, ms.boundary_edges(F)).sum(axis=1) >= 2)[0]
    c = V[F].mean(axis=1)
    where = np.argsort(np.linalg.norm(c - c[boundary_face], axis=1))[:len(F) // 6]
    r = hybridsub.refine_adaptive(F, where=where, levels=levels, scheme="sqrt3")
    check_crack_free(V, F, r)
    uniform_match(V, F, {}, "sqrt3", r, r.apply(V))
    assert (r.face_level[np.isin(r.face_parent, where)] == levels).all()
    assert r.face_level.min() == 0
    assert len(r.faces) < 0.5 * len(hybridsub.refine(F, levels=levels, scheme="sqrt3").faces)


@pytest.mark.parametrize("name, tol", [("mesh_with_border", "0.1%"), ("elephant-with-holes", "0.3%")])
def test_sqrt3_tolerance_on_shipped_open_meshes(name, tol):
    V, F = _shipped(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = hybridsub.refine_adaptive(F, V=V, tolerance=tol, scheme="sqrt3")
        V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance=tol, scheme="sqrt3")
    assert np.array_equal(F2, r.faces) and r.vertex_level.max() >= 2  # a trisecting step was made
    check_crack_free(V, F, r)
    _at_limit_positions(V, F, r, V2, "sqrt3", {})
    if name == "mesh_with_border":  # the tolerance on a denser sample than the criterion's
        t = hybridsub._surface.adaptive.tolerance_of(tol, V)
        assert _two_sided_error(V, F, V2, F2, hybridsub.LimitSurface(V, F, scheme="sqrt3")) <= 1.5 * t


@cfg(30)
@given(mesh=ms.open_meshes(bowties=False), data=st.data())
def test_sqrt3_region_on_open_meshes_is_crack_free_and_exact(mesh, data):
    V, F = mesh
    levels = data.draw(st.integers(1, 4 if len(F) <= 40 else 3))
    where = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1))).random(len(F)) < data.draw(
        st.sampled_from([0.1, 0.3, 0.6]))
    r = hybridsub.refine_adaptive(F, where=where, levels=levels, scheme="sqrt3", n_vertices=len(V))
    check_crack_free(V, F, r)
    uniform_match(V, F, {}, "sqrt3", r, r.apply(V))
    assert (r.face_level[where[r.face_parent]] == levels).all()


def test_sqrt3_open_tolerance_with_options():
    # boundary="edge_and_corner" (its corners pinned) and holes: exact, at the limit positions
    # (non_manifold="cut": test_non_manifold_cut_is_exact).
    I, J = np.meshgrid(np.arange(7), np.arange(7), indexing="ij")
    V, F = ms.grid(6, 6, (I[:6, :6] + J[:6, :6]) % 2 == 0, z=np.sin(I) * np.cos(0.7 * J))
    for tags in (dict(boundary="edge_and_corner"), dict(holes=[3, 17])):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            r = hybridsub.refine_adaptive(F, V=V, tolerance="0.5%", scheme="sqrt3", **tags)
            V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="0.5%", scheme="sqrt3", **tags)
        assert np.array_equal(F2, r.faces) and r.vertex_level.max() >= 2
        _at_limit_positions(V, F, r, V2, "sqrt3", tags)


def test_inputs_are_not_written_to():
    V, F = ms.icosahedron()
    V0, F0 = V.copy(), F.copy()
    V.setflags(write=False)
    F.setflags(write=False)
    hybridsub.subdivide_adaptive(V, F, tolerance="2%", scheme="loop")
    hybridsub.refine_adaptive(F, where=np.zeros(len(F), bool), levels=1)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_memory_limit_refuses_the_step_that_would_not_fit(scheme):
    """``max_memory`` as ``refine`` takes it: a limit below what a step needs refuses that step
    by name (its level, the faces it would refine), before allocating it; ``"none"`` and a
    limit above what the run needs give the default's refinement. The estimate is checked
    against the memory the run really takes (tracemalloc's peak, an independent count):
    it must not be below it."""
    import tracemalloc

    V, F = hybridsub.load_example()
    where = np.arange(3000)
    want = hybridsub.refine_adaptive(F, where=where, levels=4, scheme=scheme)
    tracemalloc.start()
    hybridsub.refine_adaptive(F, where=where, levels=4, scheme=scheme, max_memory="none")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    with pytest.raises(hybridsub.OutputTooLargeError, match=r"refining [\d,]+ of the [\d,]+ faces at level \d"):
        hybridsub.refine_adaptive(F, where=where, levels=4, scheme=scheme, max_memory=peak)
    with pytest.raises(hybridsub.OutputTooLargeError, match="at level 0 .* set by max_memory"):
        hybridsub.refine_adaptive(F, where=where, levels=4, scheme=scheme, max_memory="1M")
    for mm in ("none", 2 * peak + 10**8):
        r = hybridsub.refine_adaptive(F, where=where, levels=4, scheme=scheme, max_memory=mm)
        assert np.array_equal(r.faces, want.faces) and np.array_equal(r.face_level, want.face_level)
    with pytest.raises(hybridsub.OutputTooLargeError, match="or a looser tolerance"):
        hybridsub.subdivide_adaptive(V, F, tolerance="0.005%", scheme=scheme, max_memory="20M")
    with pytest.raises(ValueError, match="max_memory"):
        hybridsub.refine_adaptive(F, where=where, levels=1, scheme=scheme, max_memory="lots")


def test_memory_limit_from_the_environment(monkeypatch, tmp_path, capsys):
    """The process-wide limits apply too (``HYBRIDSUB_MAX_MEMORY``), and the command line
    answers with the message and exit code 1 (``--force`` turns the check off, as it does for
    uniform levels)."""
    from hybridsub._app.cli import main
    V, F = hybridsub.load_example()
    monkeypatch.setenv("HYBRIDSUB_MAX_MEMORY", "5M")
    with pytest.raises(hybridsub.OutputTooLargeError, match="HYBRIDSUB_MAX_MEMORY"):
        hybridsub.refine_adaptive(F, where=np.arange(3000), levels=3)
    src = os.path.join(DATA, "cube-meshed.off")
    out = tmp_path / "a.obj"
    monkeypatch.setenv("HYBRIDSUB_MAX_MEMORY", "100k")
    assert main(["subdivide", src, "-o", str(out), "--tolerance", "0.1%"]) == 1
    assert "adaptive refinement" in capsys.readouterr().err and not out.exists()
    assert main(["subdivide", src, "-o", str(out), "--tolerance", "0.1%", "--force"]) == 0
    assert out.exists()


# ------------------------------------------------------------------------------------------
# The command line
# ------------------------------------------------------------------------------------------


def test_cli_subdivide_to_a_tolerance(tmp_path, capsys):
    from hybridsub._app.cli import main
    src = os.path.join(DATA, "cube-meshed.off")
    out = tmp_path / "a.obj"
    assert main(["subdivide", src, "-o", str(out), "--tolerance", "0.5%", "--feature-angle", "30"]) == 0
    err = capsys.readouterr().err
    assert "adaptive to" in err and "error" in err
    m = hybridsub.read_mesh(str(out))
    given = hybridsub.read_mesh(src)
    V, F = given.vertices, given.faces
    feat = hybridsub.detect_features(V, F, 30)
    V2, F2 = hybridsub.subdivide_adaptive(V, F, feat.sharp_edges, tolerance="0.5%", corners=feat.corners)
    assert np.array_equal(m.faces, F2) and np.allclose(m.vertices, V2, atol=1e-9)
    assert len(m.sharp_edges) > 0  # the creases written back
    assert main(["subdivide", src, "-o", str(out), "--tolerance", "0.5%", "--levels", "2"]) == 1
    assert "exclude each other" in capsys.readouterr().err
    for bad in ("0", "-1%", "abc", "inf"):
        with pytest.raises(SystemExit) as e:
            main(["subdivide", src, "-o", str(out), "--tolerance", bad])
        assert e.value.code == 2


def test_cli_tolerance_takes_boundary(tmp_path, capsys):
    from hybridsub._app.cli import main
    I, J = np.meshgrid(np.arange(6), np.arange(6), indexing="ij")
    V, F = ms.grid(5, 5, (I[:5, :5] + J[:5, :5]) % 2 == 0, z=np.sin(I) * np.cos(0.7 * J))
    src, out = tmp_path / "g.obj", tmp_path / "a.obj"
    hybridsub.write_mesh(str(src), V, F)
    assert main(["subdivide", str(src), "-o", str(out), "--tolerance", "1%", "--boundary", "edge_and_corner",
                 "--scheme", "loop"]) == 0
    m = hybridsub.read_mesh(str(out))
    V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="1%", boundary="edge_and_corner", scheme="loop")
    assert np.array_equal(m.faces, F2) and np.allclose(m.vertices, V2, atol=1e-9)
    Va, Fa = hybridsub.subdivide_adaptive(V, F, tolerance="1%", scheme="loop")  # edge_only: corners move
    assert len(Fa) != len(F2) or not np.allclose(Va, V2)


def test_cli_sqrt3_tolerance_on_an_open_mesh(tmp_path, capsys):
    from hybridsub._app.cli import main
    src = os.path.join(DATA, "mesh_with_border.off")
    out = tmp_path / "a.obj"
    assert main(["subdivide", src, "-o", str(out), "--tolerance", "0.1%", "--scheme", "sqrt3"]) == 0
    assert "adaptive to" in capsys.readouterr().err
    m = hybridsub.read_mesh(str(out))
    given = hybridsub.read_mesh(src)
    V2, F2 = hybridsub.subdivide_adaptive(given.vertices, given.faces, tolerance="0.1%", scheme="sqrt3")
    assert np.array_equal(m.faces, F2) and np.allclose(m.vertices, V2, atol=1e-9)
    assert len(ms.boundary_edges(F2)) > len(ms.boundary_edges(given.faces))  # the boundary was trisected


def test_cli_info_reports_adaptive(capsys):
    from hybridsub._app.cli import main
    src = os.path.join(DATA, "icosahedron.off")
    assert main(["info", src]) == 0
    assert "add --tolerance" in capsys.readouterr().out
    assert main(["info", src, "--tolerance", "1%", "--scheme", "loop", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)["adaptive"]
    m = hybridsub.read_mesh(src)
    V2, F2 = hybridsub.subdivide_adaptive(m.vertices, m.faces, tolerance="1%", scheme="loop")
    assert rep["faces"] == len(F2) and rep["error"] <= rep["tolerance"]


@cfg(10)
@given(mesh=ms.tagged_meshes(bowties=False), data=st.data())
def test_tolerance_refinement_is_crack_free_and_exact(mesh, data):
    V, F, tags = mesh
    scheme = data.draw(st.sampled_from(["hybrid", "loop", "sqrt3"]))
    if scheme == "sqrt3":
        tags = {}
    tol = data.draw(st.sampled_from(["2%", "5%"]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hybridsub.AdaptiveWarning)
        r = hybridsub.refine_adaptive(F, V=V, tolerance=tol, max_levels=2, scheme=scheme, **tags)
        V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance=tol, max_levels=2, scheme=scheme, **tags)
    assert np.array_equal(F2, r.faces)
    check_crack_free(V, F, r)
    index = uniform_match(V, F, tags, scheme, r, r.apply(V))
    for j in range(int(r.vertex_level.max(initial=0)) + 1):
        sel = np.flatnonzero((r.vertex_level == j) & np.isin(np.arange(r.n_vertices), F2))
        if len(sel):
            L = hybridsub.limit_positions(V, F, levels=j, scheme=scheme, **tags)
            d = np.linalg.norm(V2[sel] - L[index[sel]], axis=1) / diagonal(V)
            assert d.max() <= 1e-9, (j, float(d.max()), int((d > 1e-9).sum()), len(d))
