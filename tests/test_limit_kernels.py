"""The Numba kernels of the limit descent (chart placement, two-ring gathering, patch cutting,
chart supports) against plain NumPy/Python versions of the same definitions, on patches met
during real descents (every scheme, creases, boundaries)."""

import numpy as np
import pytest

import hybridsub
from hybridsub._input import open_gate
from hybridsub._refiner.chart import EQUILATERAL, child_shapes, glue, plan_supports
from hybridsub._surface import descent as D
from hybridsub._topology import child_level, face_parents, plan_step

FAN_V = np.array([[0.0, 0, 0.3]] + [[np.cos(a), np.sin(a), 0.1 * np.sin(3 * a)]
                                    for a in np.linspace(0, 2 * np.pi, 7)[:-1]])
FAN_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 6]])


def _fandisk_piece():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    return V, F, feat.sharp_edges


SETUPS = {
    "loop-creases": lambda: (*_fandisk_piece(), dict(scheme="loop")),
    "hybrid-creases": lambda: (*_fandisk_piece(), dict(scheme="hybrid")),
    "sqrt3-boundary": lambda: (FAN_V, FAN_F, None, dict(scheme="sqrt3")),
    "hybrid-boundary": lambda: (FAN_V, FAN_F, None, dict(scheme="hybrid", corners=[1])),
}


def _descent(name, levels=3, points=12):
    """(patches, plan, step number) at the first ``levels`` levels of a real descent."""
    V, F, sharp, kw = SETUPS[name]()
    inp = open_gate(F, sharp, 0, n_vertices=len(V), **kw)
    rng = np.random.default_rng(1)
    f = np.sort(rng.integers(0, len(F), points))
    faces0, qn = np.unique(f, return_inverse=True)
    p, _, _ = D.start(inp, faces0)
    qn, b = qn.ravel(), rng.dirichlet([1, 1, 1], points)
    out = []
    for k in range(levels):
        out.append((p, plan_step(p.level, p.corner, inp.scheme, k + 1, inp.loop_weights)))
        p, _, qn, b = D.step(p, qn, b, inp.scheme, inp.loop_weights, k + 1)
    return out


def _ring_faces_reference(F, centre, rings=2):
    faces_of = {}
    for f, tri in enumerate(F):
        for v in tri:
            faces_of.setdefault(int(v), set()).add(f)
    node, face = [], []
    for i, c in enumerate(centre):
        verts = set(F[c].tolist())
        for r in range(rings):
            fs = set().union(*(faces_of[v] for v in verts))
            if r < rings - 1:
                verts = set(F[sorted(fs)].ravel().tolist())
        node += [i] * len(fs)
        face += sorted(fs)
    return np.array(node), np.array(face)


def _supports_reference(F, plan, n):
    """Old vertices stay, edge points at midpoints (trisection points at thirds), face points at centroids."""
    ids, w = np.full((plan.n_new, 3), -1), np.zeros((plan.n_new, 3))
    ids[:n, 0], w[:n, 0] = np.arange(n), 1.0
    for h in np.flatnonzero(plan.edge_point >= 0):  # halfedges in order: the last of an edge's two wins
        f, i = divmod(int(h), 3)
        e, ends = plan.edge_point[h], [F[f, i], F[f, (i + 1) % 3]]
        if plan.trisected[f] == i:
            ids[e, :2], w[e, :2], ids[e + 1, :2], w[e + 1, :2] = ends, [2 / 3, 1 / 3], ends, [1 / 3, 2 / 3]
        else:
            ids[e, :2], w[e, :2] = ends, 0.5
    for f in np.flatnonzero(plan.face_point >= 0):
        ids[plan.face_point[f]], w[plan.face_point[f]] = F[f], 1 / 3
    return ids, w


def _child_shapes_reference(F, twin, shape, faces1, parent, sup_ids, sup_w):
    """Per corner: the first of the parent and its glued edge-neighbours holding every support."""
    nb = np.nan_to_num(glue(shape, twin, F, parent))  # (k, 3, 3, 2)
    out = np.zeros((len(faces1), 3, 2))
    for k, (tri, p) in enumerate(zip(faces1, parent)):
        tw = twin[3 * p:3 * p + 3]
        groups = [(F[p], shape[p])] + [(F[t // 3] if t >= 0 else np.full(3, -2), nb[k, i]) for i, t in enumerate(tw)]
        for c, v in enumerate(tri):
            ids, ws = sup_ids[v], sup_w[v]
            gid, gpos = next(g for g in groups if all(s < 0 or s in g[0] for s in ids))
            out[k, c] = sum(w * gpos[list(gid).index(s)] for s, w in zip(ids, ws) if s >= 0)
    return out


@pytest.mark.parametrize("name", list(SETUPS))
def test_descent_kernels_match_their_definitions(name):
    for p, plan in _descent(name):
        lvl = p.level
        # The two-ring gathering and the cut.
        centre = np.unique(p.face)
        node, f = D.ring_faces(lvl.faces, lvl.n_vertices, centre)
        rn, rf = _ring_faces_reference(lvl.faces, centre)
        assert np.array_equal(node, rn) and np.array_equal(f, rf)
        new, _, vsel, _ = D.cut_patches(lvl, p.corner, node, f)
        assert np.array_equal(vsel[new.faces], lvl.faces[f])  # the same triangles, renumbered
        node_of = np.empty(new.n_vertices, np.int64)
        node_of[new.faces] = node[:, None]
        assert np.all(np.diff(node_of * lvl.n_vertices + vsel) > 0)  # by node, then old id, each once
        where = {(n_, f_): r for r, (n_, f_) in enumerate(zip(node.tolist(), f.tolist()))}
        old = lvl.twin[3 * np.repeat(f, 3) + np.tile([0, 1, 2], len(f))]
        want = [-1 if t < 0 or (n_, t // 3) not in where else 3 * where[n_, t // 3] + t % 3
                for n_, t in zip(np.repeat(node, 3).tolist(), old.tolist())]
        assert np.array_equal(new.twin, want)  # twins kept inside a node's piece, cut elsewhere
        # The chart supports and the child corners.
        ids, w = plan_supports(lvl.faces, plan, lvl.n_vertices)
        faces1, _, offsets = child_level(lvl, plan)
        parent = face_parents(offsets)
        want_ids, want_w = _supports_reference(lvl.faces, plan, lvl.n_vertices)
        assert np.array_equal(ids, want_ids) and np.array_equal(w, want_w)
        pick = np.arange(0, len(faces1), max(1, len(faces1) // 200))
        got = child_shapes(lvl.faces, lvl.twin, p.shape, faces1[pick], parent[pick], ids, w)
        want = _child_shapes_reference(lvl.faces, lvl.twin, p.shape, faces1[pick], parent[pick], ids, w)
        assert np.allclose(got, want, rtol=0, atol=1e-13)


def test_chart_of_an_input_face_is_equilateral():
    p, _ = _descent("hybrid-boundary", levels=1)[0]
    assert np.allclose(p.shape, EQUILATERAL)
