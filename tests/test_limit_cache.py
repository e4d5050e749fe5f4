"""The patch cache behind LimitSurface (issue 14's speed): the cached walk gives the direct
descent's rows, whatever the numbering, orientation or order of evaluation."""

import os

import numpy as np
import pytest
import scipy.sparse as sp
from test_limit_surface import CASES, FAN_F, FAN_V, OCTA_F, OCTA_V

import hybridsub
from hybridsub._surface import cache as C
from hybridsub._surface import descent as D
from hybridsub._surface import surface
from hybridsub._surface.regular import is_regular, regular_torus


def direct_rows(inp, f: np.ndarray, b: np.ndarray, n_rows: int, depth: int, tol: float,
                max_levels: int):
    """The rows of ``walk.walk_rows`` by the direct descent, every patch refined where it
    is met (no cache): the reference the cached walk is tested against."""
    faces0, qn = np.unique(f, return_inverse=True)
    p, sel0, _ = D.start(inp, faces0)
    maps = [sel0]
    qn, bb = qn.ravel(), b
    for k in range(depth):
        p, A, qn, bb = D.step(p, qn, bb, inp.scheme, inp.loop_weights, k + 1)
        maps.append(A)
    ids, *weights = D.stencil(p, qn, bb)
    L = D.limit_rows(p, np.unique(ids), inp.scheme, inp.loop_weights, tol, max_levels)
    q = len(f)
    W = np.concatenate([w.ravel() for w in weights[:n_rows]])
    R = sp.csr_matrix((W, np.tile(ids.ravel(), n_rows), np.arange(0, 6 * n_rows * q + 1, 6)),
                      shape=(n_rows * q, p.level.n_vertices)) @ L
    for A in reversed(maps):  # all rows (value, derivatives) through the levels at once
        R = R @ A
    R = sp.csr_matrix(R)
    return [R[i * q:(i + 1) * q] for i in range(n_rows)]


def _direct(s, f, b, n_rows):
    """The direct descent's rows, each point to the depth the surface takes it to."""
    depths = s._depths(f, b, s.depth)
    groups = [(d, np.flatnonzero(depths == d)) for d in np.unique(depths)]
    parts = [direct_rows(s._inp, f[i], b[i], n_rows, d, 1e-12, 60) for d, i in groups]
    where = np.empty(len(f), np.int64)
    where[np.concatenate([i for _, i in groups])] = np.arange(len(f))
    return [sp.csr_matrix(sp.vstack(ms))[where] for ms in zip(*parts)]


def _points(F, k, seed=0):
    rng = np.random.default_rng(seed)
    return rng.integers(0, len(F), k), rng.dirichlet([1, 1, 1], k)


@pytest.mark.parametrize("name", list(CASES))
def test_cached_walk_equals_the_direct_descent(name):
    """Many keys (creases, corners, semi-sharp, darts, boundaries, Kobbelt's parity): the
    cached rows are the direct descent's, to rounding (derivatives: to the last
    interpolation's conditioning). Points inside faces: on an edge of some level the walk
    keeps to the centre face's children where the direct descent takes whichever child
    rounding favours, and the two agree to the interpolation's error only."""
    V, F, kw = CASES[name]
    s = hybridsub.LimitSurface(V, F, depth=7, **kw)
    s._table.regular_stop = False  # every point all the way down, as the direct descent
    face, bary = _points(F, 60)
    cached = s.evaluation_matrix(face, bary, derivatives=True)
    f, b = s._points(face, bary)
    direct = _direct(s, f, b, 3)
    P = direct[0] @ V
    assert np.abs(cached[0] @ V - P).max() < 1e-13 * np.abs(P).max(), name
    for Mc, Md in zip(cached[1:], direct[1:]):
        D = Md @ V
        assert np.abs(Mc @ V - D).max() < 1e-8 * np.abs(D).max(), name
    assert s._table.n_keys > s.depth  # the walk met several patches per level


@pytest.mark.parametrize("name", list(CASES))
def test_a_shared_cache_gives_what_a_fresh_one_gives(name):
    """At the default depth, to the bit. A key's representative is the first patch met with
    it; patches of one key are the same tagged mesh with the same shapes (every face
    equilateral in the chart, taken exactly whichever corner it was entered at), so the
    history does not move a bit."""
    V, F, kw = CASES[name]
    face, bary = _points(F, 40, seed=1)
    warm = hybridsub.LimitSurface(V, F, **kw)
    warm.evaluate(*_points(F, 80, seed=2), derivatives=True)  # fills the cache with other points
    n_before = warm._table.n_keys
    got = warm.evaluate(face, bary, derivatives=True)
    surface._TABLES.clear()  # a table of its own
    new = hybridsub.LimitSurface(V, F, **kw)
    fresh = new.evaluate(face, bary, derivatives=True)
    assert warm._table.n_keys - n_before < new._table.n_keys  # some keys were found again
    for a, b in zip(got, fresh):
        assert np.array_equal(a, b)
    again = warm.evaluate(face, bary, derivatives=True)  # every key known: same bits
    for a, b in zip(got, again):
        assert np.array_equal(a, b)


def _shipped_kinds():
    """fandisk and the CAD cube with their 30° creases and corners, mesh_with_border (open)."""
    out = {}
    for name in ("fandisk", "cube-meshed", "mesh_with_border"):
        if name == "fandisk":
            V, F = hybridsub.load_example()
        else:
            m = hybridsub.read_mesh(os.path.join(os.path.dirname(__file__), "data", f"{name}.off"))
            V, F = m.vertices, m.faces
        feat = hybridsub.detect_features(V, F, 30)
        out[name] = (V, F, dict(sharp_edges=feat.sharp_edges, corners=feat.corners))
    return out


@pytest.mark.parametrize("scheme", ["loop", "sqrt3", "hybrid"])
def test_surfaces_of_one_kind_share_their_patches_to_the_bit(scheme):
    """A new surface takes the patch table its kind's surfaces filled before (other meshes,
    other points): it builds fewer patches, and its points are those of a fresh process, to
    the bit, in whatever order the meshes come."""
    meshes = _shipped_kinds()
    pts = {k: _points(F, 400, seed=21) for k, (_, F, _) in meshes.items()}

    def run(order):
        surface._TABLES.clear()
        out, keys = {}, {}
        for k in order:
            V, F, kw = meshes[k]
            s = hybridsub.LimitSurface(V, F, scheme=scheme, **({} if scheme == "sqrt3" else kw))
            before = s._table.n_keys
            out[k] = s.evaluate(*pts[k], derivatives=True)
            keys[k] = (before, s._table.n_keys - before)
        return out, keys

    alone = {}
    for k in meshes:
        got, keys = run([k])
        alone[k] = got[k]
        n_alone = keys[k][1]
    for order in (list(meshes), list(meshes)[::-1]):
        got, keys = run(order)
        for k in meshes:
            for a, b in zip(got[k], alone[k]):
                assert np.array_equal(a, b), (order, k)
        assert keys[order[-1]][0] > 0  # the last started from the others' patches
    assert keys[order[-1]][1] < n_alone  # and built fewer of its own


def test_surfaces_sharing_a_table_in_threads_give_the_serial_bits():
    """Surfaces of one kind evaluated at once from several Python threads (the shared table
    is filled under its lock) give what they give one after another."""
    import threading

    meshes = _shipped_kinds()
    pts = {k: _points(F, 1500, seed=22) for k, (_, F, _) in meshes.items()}
    serial = {k: hybridsub.LimitSurface(V, F, **kw).evaluate(*pts[k], derivatives=True)
              for k, (V, F, kw) in meshes.items()}
    surface._TABLES.clear()
    got, errors = {}, []

    def work(k):
        try:
            V, F, kw = meshes[k]
            got[k] = hybridsub.LimitSurface(V, F, **kw).evaluate(*pts[k], derivatives=True)
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in meshes]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for k in meshes:
        for a, b in zip(got[k], serial[k]):
            assert np.array_equal(a, b), k


@pytest.mark.parametrize("scheme", ["loop", "sqrt3", "hybrid"])
def test_renumbered_rotated_and_mirrored_copies_give_the_same_surface(scheme):
    """Two copies in one mesh: the second with its vertices renumbered, every face's corners
    rotated, mirrored (faces reversed, x negated). Its patches hit the first copy's keys (or
    their mirror images'), and the surface is the first copy's, mirrored."""
    V, F = FAN_V, FAN_F
    kw = {} if scheme == "sqrt3" else {"sharp_edges": [[0, 2]]}
    n = len(V)
    perm = np.random.default_rng(3).permutation(n)  # new id of each old vertex
    V2 = np.empty_like(V)
    V2[perm] = V * [-1, 1, 1] + [5, 0, 0]
    F2 = perm[F[:, [1, 0, 2]]]  # reversed: corner order (1, 0, 2)
    F2 = np.roll(F2, 1, axis=1)  # rotated: (2, 1, 0) of the original corners
    VV, FF = np.vstack([V, V2]), np.vstack([F, F2 + n])
    kw2 = {} if scheme == "sqrt3" else {"sharp_edges": [[0, 2], [perm[0] + n, perm[2] + n]]}
    s = hybridsub.LimitSurface(VV, FF, scheme=scheme, depth=8, **kw2)
    face, bary = _points(F, 50, seed=4)
    P = s.evaluate(face, bary)
    Q = s.evaluate(face + len(F), bary[:, [2, 1, 0]])
    assert np.abs(Q - (P * [-1, 1, 1] + [5, 0, 0])).max() < 1e-13
    alone = hybridsub.LimitSurface(V, F, scheme=scheme, depth=8, **kw).evaluate(face, bary)
    assert np.abs(alone - P).max() < 1e-13
    assert s._table.n_keys < 2 * s._depths(*s._points(face, bary), s.depth).sum()  # keys repeat (visits: 2 copies)


def test_keys_repeat_in_regular_regions():
    """Deep levels of a Loop surface meet few distinct patches: the cache is what makes the
    walk cheap (a broken canonical order would make every patch new)."""
    V, F = OCTA_V, OCTA_F
    s = hybridsub.LimitSurface(V, F, scheme="loop", depth=10)
    face, bary = _points(F, 200, seed=5)
    s.evaluate(face, bary)
    assert s._table.n_keys < 200 * 10 / 4


def _stored_transitions(t):
    """Each stored transition's contents (bytes) → the first entries holding them."""
    out = {}
    for a, b in {(int(a), int(b)) for a, b in zip(t.t_start.a, t.t_end.a) if b > a}:
        key = t.t_row.a[a:b].tobytes() + t.t_col.a[a:b].tobytes() + t.t_val.a[a:b].tobytes()
        out.setdefault(key, set()).add(a)
    return out


class _NothingShared(dict):
    """A transition index that never finds a content: every transition stored anew."""

    def get(self, key, default=None):
        return default


@pytest.mark.parametrize("name, shared", [("hybrid-crease", 0.9), ("loop-semisharp", 1.0)])
def test_transitions_are_stored_once_per_content(name, shared):
    """Keys of other connectivity often have the same step rows: the table holds each
    distinct transition once, and only what candidates point at; and the surface is the one
    of a table that shares nothing, to the bit (semi-sharp creases: rows of one pattern with
    other weights, which must not be shared)."""
    V, F, kw = CASES[name]
    face, bary = _points(F, 300, seed=11)
    plain = hybridsub.LimitSurface(V, F, depth=10, **kw)
    plain._table._t_index = _NothingShared()
    ref = plain.evaluate(face, bary, derivatives=True)
    surface._TABLES.clear()  # a table of its own
    s = hybridsub.LimitSurface(V, F, depth=10, **kw)
    got = s.evaluate(face, bary, derivatives=True)
    for a, b in zip(got, ref):
        assert np.array_equal(a, b)
    t = s._table
    stored = _stored_transitions(t)
    assert all(len(at) == 1 for at in stored.values())  # no content twice
    live = t.t_end.a > t.t_start.a
    first, at = np.unique(t.t_start.a[live], return_index=True)
    used = int((t.t_end.a[live][at] - first).sum())
    assert len(t.t_val.a) == used  # nothing stored that no candidate points at
    n_cands = int(live.sum())
    assert len(stored) < shared * n_cands  # candidates share their rows
    assert len(t.t_val.a) < shared * len(plain._table.t_val.a)


def _torus(n=6, seed=6):
    """A closed n × n torus grid, every vertex of valence 6 (regular Loop everywhere), jittered."""
    V, F = regular_torus(n)
    return V + 0.05 * np.random.default_rng(seed).standard_normal(V.shape), F


def _grid(n=6, seed=9):
    """An open n × n grid of triangles, jittered: boundary vertices with three faces (regular
    on the boundary) along the sides, two or one at the corners."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    V = np.stack([i.ravel() + 0.5 * j.ravel(), j.ravel() * 0.87, np.zeros(i.size)], 1)
    V += 0.05 * np.random.default_rng(seed).standard_normal(V.shape)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    F = [[idx[x, y], idx[x + 1, y], idx[x, y + 1]] for x in range(n) for y in range(n)]
    F += [[idx[x + 1, y], idx[x + 1, y + 1], idx[x, y + 1]] for x in range(n) for y in range(n)]
    return V, np.array(F)


def _regular_meshes(mesh):
    if mesh == "torus":
        return _torus(), {"scheme": "loop"}
    if mesh == "torus-crease":  # straight creases round the tube and along a diagonal (crossing
        V, F = _torus()  # at a corner), and a kinked one
        return (V, F), {"scheme": "loop", "sharp_edges": [[x * 6, ((x + 1) % 6) * 6] for x in range(6)]
                        + [[x * 7, (x + 1) % 6 * 7] for x in range(6)] + [[3, 9], [9, 10], [10, 16]]}
    if mesh == "grid-boundary":
        return _grid(), {"scheme": "loop"}
    if mesh == "torus-hybrid":  # Loop faces round a straight crease, √3 faces further off
        (V, F), kw = _regular_meshes("torus-crease")
        near = np.isin(F, np.arange(0, 36, 6)).any(axis=1) | np.isin(F, np.arange(1, 36, 6)).any(axis=1)
        return (V, F), {"scheme": "hybrid", "sharp_edges": kw["sharp_edges"][:6], "sharp_faces": near}
    return (OCTA_V, OCTA_F), {"scheme": "loop"}


@pytest.mark.parametrize("mesh", ["torus", "torus-crease", "grid-boundary", "torus-hybrid", "octahedron"])
def test_regular_loop_patches_stop_with_the_exact_quartic(mesh):
    """The walk stops at regular Loop patches (every point of the torus at once, those of the
    octahedron once away from its valence-4 vertices; beside straight creases and boundaries
    too) and takes the box spline there: the same surface as the walk to full depth,
    derivatives closer to the truth (exact)."""
    (V, F), kw = _regular_meshes(mesh)
    face, bary = _points(F, 80, seed=7)
    s = hybridsub.LimitSurface(V, F, **kw)
    P, Du, Dv = s.evaluate(face, bary, derivatives=True)
    surface._TABLES.clear()  # a table of its own
    deep = hybridsub.LimitSurface(V, F, depth=24, **kw)
    deep._table.regular_stop = False
    Pd, Dud, Dvd = deep.evaluate(face, bary, derivatives=True)
    assert np.abs(P - Pd).max() < 1e-13 * np.abs(Pd).max()
    scale = np.abs(Dud).max()
    assert np.abs(Du - Dud).max() < 1e-6 * scale and np.abs(Dv - Dvd).max() < 1e-6 * scale
    # Central differences of the quartic: its derivatives to the differences' own error (in
    # the hybrid's √3 faces the chart's (u, v) bends at the children's edges: not there).
    h = 1e-4
    inside = (bary[:, 1:] > 2 * h).all(axis=1) & (bary[:, 0] > 2 * h) & (kw["scheme"] == "loop")
    shift = np.array([-1.0, 1.0, 0.0]) * h
    fd = (s.evaluate(face[inside], bary[inside] + shift) - s.evaluate(face[inside], bary[inside] - shift)) / (2 * h)
    assert np.abs(fd - Du[inside]).max(initial=0.0) < 1e-6 * scale
    t = s._table
    flags = [is_regular(F_, tw, hs, fs, c) for F_, tw, hs, fs, c, _ in t.reps]  # the kernel's definition
    assert np.array_equal(t.regular.a[:t.n_keys], np.array(flags, np.int8))
    # Regular input faces take the box spline straight from their twelve control vertices:
    # those whose corners are interior, of valence 6, on no crease, with Loop faces only.
    faces_at = np.bincount(F.ravel(), minlength=len(V))
    E = np.sort(np.stack([F, np.roll(F, -1, axis=1)], 2).reshape(-1, 2), axis=1)
    e, count = np.unique(E, axis=0, return_counts=True)
    bad = faces_at != 6
    bad[e[count == 1].ravel()] = True
    bad[np.asarray(kw.get("sharp_edges", np.zeros((0, 2), int))).ravel()] = True
    loop_face = np.asarray(kw.get("sharp_faces", np.ones(len(F), bool)))
    bad[F[~loop_face].ravel()] = True
    fast = s._starts.rings[:, 0] >= 0
    assert np.array_equal(fast, ~bad[F].any(axis=1))
    if fast.any():
        assert np.array_equal(np.sort(s._starts.rings[fast], axis=1), _one_rings(F, np.flatnonzero(fast)))
    if mesh == "torus":
        assert fast.all() and t.n_keys == 0  # no patch was cut
    elif mesh != "octahedron":
        assert t.regular.a[:t.n_keys].max() == 1 and (t.poly.a[:t.n_keys] >= 0).any()
    if mesh in ("torus-crease", "grid-boundary", "torus-hybrid"):  # some regular keys: a crease at the centre
        on_crease = [(r[1][:3] < 0).any() or (r[2] is not None and r[2][:3].any()) for r in t.reps]
        assert (t.regular.a[:t.n_keys][np.array(on_crease)] == 1).any()


def _one_rings(F, faces):
    """The vertices of the faces sharing a vertex with each face, (k, 12) for regular faces."""
    out = []
    for f in faces:
        near = np.isin(F, F[f]).any(axis=1)
        out.append(np.unique(F[near]))
    return np.array(out)


def test_quartic_kernel_matches_its_definition():
    """quartic_points (the walk's kernel) == the Bernstein basis of regular.bernstein, chained
    to (u, v) by hand."""
    from hybridsub._surface.regular import bernstein, polynomial_weights

    rng = np.random.default_rng(8)
    bary = rng.dirichlet([1, 1, 1], 20)
    uv = rng.standard_normal((20, 3, 2))  # the face's corners in (u, v)
    G = np.linalg.inv(np.stack([uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]], -1))  # ∂(b1, b2)/∂(u, v)
    grad = np.concatenate([-G.sum(axis=1, keepdims=True), G], axis=1)  # ∂b/∂(u, v), (20, 3, 2)
    W = polynomial_weights(bary, grad, 6)
    B = bernstein(bary, 2)
    assert np.allclose(W[:, 0], B[0], rtol=0, atol=1e-14)
    assert np.allclose(W[:, 1], B[1] * G[:, None, 0, 0] + B[2] * G[:, None, 1, 0], rtol=1e-12, atol=1e-12)
    assert np.allclose(W[:, 2], B[1] * G[:, None, 0, 1] + B[2] * G[:, None, 1, 1], rtol=1e-12, atol=1e-12)
    H = np.array([[B[3], B[4]], [B[4], B[5]]])  # (2, 2, q, 15)
    Huv = np.einsum("qai,abqt,qbj->qtij", G, H, G)
    for o, (r1, r2) in enumerate(((0, 0), (0, 1), (1, 1))):
        assert np.allclose(W[:, 3 + o], Huv[:, :, r1, r2], rtol=1e-12, atol=1e-10)
    assert np.allclose(B[0].sum(axis=1), 1.0)  # a partition of unity


@pytest.mark.parametrize("scheme", ["loop", "hybrid", "sqrt3"])
def test_patches_joined_at_a_vertex_only(scheme):
    """A bowtie (two fans sharing one vertex): the canonical order reaches the second fan
    through no edge, and the cached walk still equals the direct descent."""
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.2], [0, 1, 0.1], [-1, 0, 0.3], [-1, -1, 0], [0, -1, 0.1]])
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 4, 5], [0, 5, 6]])
    s = hybridsub.LimitSurface(V, F, scheme=scheme, depth=6)
    s._table.regular_stop = False
    face, bary = _points(F, 40, seed=9)
    f, b = s._points(face, bary)
    direct = _direct(s, f, b, 1)[0]
    assert np.abs(s.evaluation_matrix(face, bary) @ V - direct @ V).max() < 1e-13


@pytest.mark.parametrize("mesh", ["torus-crease", "grid-boundary"])
def test_evaluate_in_chunks_equals_the_matrix_bit_for_bit(mesh, monkeypatch):
    """evaluate (rows applied as they are carried back, regular faces straight from their
    rings) == evaluation_matrix @ V to the bit, in chunks with the cache emptied between
    them, for 3-column, 1-D and empty data; the matrices hold no explicit zeros. Derivatives
    (applied to the data forward, where the rows cancel) agree to rounding."""
    import hybridsub._surface.surface as surface

    (V, F), kw = _regular_meshes(mesh)
    face, bary = _points(F, 50, seed=12)
    bary[:5] = np.eye(3)[[0, 1, 2, 0, 1]]  # some points on vertices
    monkeypatch.setattr(surface, "CHUNK", 7)
    monkeypatch.setattr(surface, "CACHE_BYTES", 0)  # a new cache for every chunk
    s = hybridsub.LimitSurface(V, F, **kw)
    assert (s._starts.rings[face, 0] >= 0).any() and (s._starts.rings[face, 0] < 0).any()  # both paths
    mats = s.evaluation_matrix(face, bary, derivatives=True)
    got = s.evaluate(face, bary, derivatives=True)
    assert np.array_equal(mats[0] @ V, got[0])
    for M, D in zip(mats[1:], got[1:]):
        assert np.abs(M @ V - D).max() <= 1e-9 * np.abs(D).max()  # the rows lose ~1e-16 × 3^(depth/2)
    assert all((M.data != 0).all() for M in mats)
    h = V[:, 2] - V[:, 0]  # per-vertex scalar data
    assert np.array_equal(s.evaluate(face, bary, vertices=h), mats[0] @ h)
    P0, Du0, Dv0 = s.evaluate(face[:0], bary[:0], derivatives=True)
    assert P0.shape == (0, 3) and Du0.shape == (0, 3) and s.evaluation_matrix(face[:0], bary[:0]).shape == (0, len(V))


@pytest.mark.slow  # compiles the threaded twins of the walk's kernels: ~13 s on an empty cache
@pytest.mark.parametrize("mesh", ["torus-crease", "hybrid-crease"])
def test_threaded_walk_gives_the_serial_bits(mesh, monkeypatch):
    """walk_known and back_points on threads (tasks of points) == their serial twins, bit for
    bit, values and derivatives, on a fresh surface each (the table filled the same way)."""
    import hybridsub._topology._kernels as topo

    if mesh == "hybrid-crease":
        V, F, kw = CASES[mesh]
    else:
        (V, F), kw = _regular_meshes(mesh)
    face, bary = _points(F, 300, seed=13)
    got = {}
    for threaded in (False, True):
        monkeypatch.setattr(topo, "PARALLEL_MIN", 0 if threaded else 10**12)
        surface._TABLES.clear()  # filled afresh
        got[threaded] = hybridsub.LimitSurface(V, F, **kw).evaluate(face, bary, derivatives=True)
    for a, b in zip(got[False], got[True]):
        assert np.array_equal(a, b)


def test_small_index_arrays_widen_when_a_piece_needs_more():
    """The representatives' corners and twins are kept as int16 until a piece has more than
    32767 of them: then the whole array is widened, its earlier entries unchanged."""
    from hybridsub._surface.cache import Grow

    g = Grow((3,), np.int16)
    g.append([[1, 2, 3], [-1, 4, 32767]])
    assert g.a.dtype == np.int16
    g.append([[5, 40000, -1]])
    assert g.a.dtype == np.int32
    assert g.a.tolist() == [[1, 2, 3], [-1, 4, 32767], [5, 40000, -1]]
    g.append(np.zeros((30, 3), np.int64))
    assert g.a.dtype == np.int32 and g.n == 33


def test_chunks_keep_the_cache_near_its_cap_within_a_call(monkeypatch):
    """Points that would take the cache past ``CACHE_BYTES`` go in chunks sized by the cache's
    growth per point, so one call holds the cache near the cap (it was one chunk of up to
    20000 points, 630 MB on a small CAD part); here a cap of 1 MB against the 1.4 MB that
    2000 points on the octahedron with a creased equator make."""
    import hybridsub._surface.surface as surface

    V, F = OCTA_V, OCTA_F
    kw = dict(sharp_edges=[[0, 2], [2, 1], [1, 3], [3, 0]])  # the equator
    face, bary = _points(F, 2000, seed=5)
    whole = hybridsub.LimitSurface(V, F, **kw).evaluate(face, bary, derivatives=True)
    cap = 2**20
    monkeypatch.setattr(surface, "CACHE_BYTES", cap)
    monkeypatch.setattr(surface, "FIRST_CHUNK", 200)
    s = hybridsub.LimitSurface(V, F, **kw)
    peaks = []
    emptied = s._new_cache

    def watched():
        peaks.append(s._table.nbytes)
        emptied()

    s._new_cache = watched
    got = s.evaluate(face, bary, derivatives=True)
    peaks.append(s._table.nbytes)
    assert len(peaks) > 2 and s._chunk < surface.CHUNK  # emptied on the way, in smaller chunks
    assert max(peaks) < 2 * cap, [p / cap for p in peaks]
    # A key's representative is the first patch met with it, so another history of the cache
    # may take another one (its shapes within the key's rounding): the same surface to rounding.
    # Values to rounding; derivatives to their last interpolation's error (1e-8 relative).
    for a, b, tol in zip(whole, got, (1e-13, 1e-8, 1e-8)):
        assert np.abs(a - b).max() <= tol * np.abs(a).max()
