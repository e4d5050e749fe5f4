"""Numba kernels: the hot loops of the topology pass, the stencil rows and face emission.

Private. Every kernel takes contiguous int64/float64/int8/bool arrays and plain ints, and
returns arrays; no Python objects. Callers in ``_topology`` and ``_stencils`` validate and
convert. Halfedge ``h = 3 f + i`` of face ``f = (a, b, c)`` runs ``F[f, i] → F[f, (i+1) % 3]``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._rules import (
    CORNER,
    CREASE,
    EDGE_FLIP,
    EDGE_KEEP,
    EDGE_SPLIT,
    EDGE_TRISECT,
    KOBBELT_TRISECTION,
    SMOOTH,
)

# Error codes of halfedge_twins.
OK = 0
ERR_SAME_DIRECTION = 1  # two halfedges u→w: non-manifold edge or inconsistent orientation
ERR_MULTIPLE_TWINS = 2  # several halfedges w→u for one u→w

_T0, _T1, _T2 = KOBBELT_TRISECTION


@njit(cache=True, inline="always")
def _dest(F, h):
    return F[h // 3, (h % 3 + 1) % 3]


@njit(cache=True, inline="always")
def _origin(F, h):
    return F[h // 3, h % 3]


@njit(cache=True, inline="always")
def _next(h):
    return h - h % 3 + (h % 3 + 1) % 3


@njit(cache=True, inline="always")
def _prev(h):
    return h - h % 3 + (h % 3 + 2) % 3


@njit(cache=True)
def halfedge_twins(F, n_vertices):
    """Twin of every halfedge (−1 on the boundary), and halfedges grouped by origin.

    Returns (twin, by_origin, origin_start, error, h_bad): ``by_origin[origin_start[v]:
    origin_start[v+1]]`` are the halfedges leaving v, in increasing order. ``error`` is OK or
    an ERR_* code with the offending halfedge ``h_bad``.
    """
    m = F.shape[0]
    nh = 3 * m
    start = np.zeros(n_vertices + 1, np.int64)
    for f in range(m):
        for i in range(3):
            start[F[f, i] + 1] += 1
    for v in range(n_vertices):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    by_origin = np.empty(nh, np.int64)
    for h in range(nh):
        u = F[h // 3, h % 3]
        by_origin[fill[u]] = h
        fill[u] += 1
    twin = np.full(nh, -1, np.int64)
    for h in range(nh):
        u = _origin(F, h)
        w = _dest(F, h)
        for k in range(start[u], start[u + 1]):
            g = by_origin[k]
            if g != h and _dest(F, g) == w:
                return twin, by_origin, start, ERR_SAME_DIRECTION, h
        for k in range(start[w], start[w + 1]):
            g = by_origin[k]
            if _dest(F, g) == u:
                if twin[h] >= 0:
                    return twin, by_origin, start, ERR_MULTIPLE_TWINS, h
                twin[h] = g
    return twin, by_origin, start, OK, -1


@njit(cache=True)
def number_edges(twin):
    """Edges in order of first appearance over the halfedges.

    Returns (edge_of_halfedge, owner): ``owner[e]`` is the lower-numbered halfedge of e.
    """
    nh = twin.shape[0]
    edge_of = np.empty(nh, np.int64)
    owner = np.empty(nh, np.int64)
    ne = 0
    for h in range(nh):
        t = twin[h]
        if t < 0 or h < t:
            edge_of[h] = ne
            owner[ne] = h
            ne += 1
        else:
            edge_of[h] = edge_of[t]
    return edge_of, owner[:ne].copy()


@njit(cache=True)
def vertex_edges(F, owner, n_vertices):
    """Incident edges of every vertex as CSR (start, edges), in increasing edge order."""
    ne = owner.shape[0]
    start = np.zeros(n_vertices + 1, np.int64)
    for e in range(ne):
        h = owner[e]
        start[_origin(F, h) + 1] += 1
        start[_dest(F, h) + 1] += 1
    for v in range(n_vertices):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    edges = np.empty(2 * ne, np.int64)
    for e in range(ne):
        h = owner[e]
        a = _origin(F, h)
        b = _dest(F, h)
        edges[fill[a]] = e
        fill[a] += 1
        edges[fill[b]] = e
        fill[b] += 1
    return start, edges


@njit(cache=True)
def find_edges(pairs, F, by_origin, origin_start, edge_of):
    """Edge index of each vertex pair (either orientation), −1 where there is no such edge."""
    k = pairs.shape[0]
    out = np.full(k, -1, np.int64)
    nv = origin_start.shape[0] - 1
    for j in range(k):
        a = pairs[j, 0]
        b = pairs[j, 1]
        if a < 0 or b < 0 or a >= nv or b >= nv:
            continue
        for q in range(origin_start[a], origin_start[a + 1]):
            h = by_origin[q]
            if _dest(F, h) == b:
                out[j] = edge_of[h]
                break
        if out[j] >= 0:
            continue
        for q in range(origin_start[b], origin_start[b + 1]):
            h = by_origin[q]
            if _dest(F, h) == a:
                out[j] = edge_of[h]
                break
    return out


@njit(cache=True)
def boundary_links(F, twin):
    """For each boundary halfedge, the next and previous boundary halfedges (−1 elsewhere).

    The next one leaves the halfedge's end and is found by turning around that vertex
    through its faces, so a vertex where several fans meet links within each fan.
    """
    nh = twin.shape[0]
    bnext = np.full(nh, -1, np.int64)
    bprev = np.full(nh, -1, np.int64)
    for h in range(nh):
        if twin[h] >= 0:
            continue
        g = _next(h)
        for _ in range(nh):
            t = twin[g]
            if t < 0:
                break
            g = _next(t)
        bnext[h] = g
        bprev[g] = h
    return bnext, bprev


# ---------------------------------------------------------------------------------------
# Stencil rows. Each row-writer takes scratch arrays ``cols``/``vals`` and returns how many
# entries it wrote, columns sorted ascending and unique; the CSR builder calls it twice
# (count, then fill) so rows are produced by one piece of code.


@njit(cache=True, inline="always")
def _sort_merge(cols, vals, k):
    for i in range(1, k):
        c = cols[i]
        x = vals[i]
        j = i - 1
        while j >= 0 and cols[j] > c:
            cols[j + 1] = cols[j]
            vals[j + 1] = vals[j]
            j -= 1
        cols[j + 1] = c
        vals[j + 1] = x
    out = 0
    for i in range(k):
        if out > 0 and cols[out - 1] == cols[i]:
            vals[out - 1] += vals[i]
        else:
            cols[out] = cols[i]
            vals[out] = vals[i]
            out += 1
    return out


@njit(cache=True)
def _add_mask(v, rule, crease_min, factor, F, owner, ve_start, ve_edges, esharp, wn, cs, cn, cols, vals):
    """Add factor × (the mask of ``rule``) to the row of v held in cols/vals (slot 0 = v).

    Slot 1 + j belongs to the j-th incident edge's other end. Crease neighbours are the
    ends of incident edges whose sharpness exceeds ``crease_min``.
    """
    if rule == CORNER:
        vals[0] += factor
        return
    lo = ve_start[v]
    hi = ve_start[v + 1]
    if rule == CREASE:
        vals[0] += factor * cs
        for j in range(hi - lo):
            if esharp[ve_edges[lo + j]] > crease_min:
                vals[1 + j] += factor * cn
        return
    n = hi - lo
    vals[0] += factor * (1.0 - n * wn[v])
    for j in range(n):
        vals[1 + j] += factor * wn[v]


@njit(cache=True)
def _vertex_row(v, F, owner, ve_start, ve_edges, esharp, rule_parent, rule_child, blend, wn, cs, cn, cols, vals):
    lo = ve_start[v]
    n = ve_start[v + 1] - lo
    cols[0] = v
    vals[0] = 0.0
    for j in range(n):
        h = owner[ve_edges[lo + j]]
        a = _origin(F, h)
        cols[1 + j] = _dest(F, h) if a == v else a
        vals[1 + j] = 0.0
    rp = rule_parent[v]
    rc = rule_child[v]
    if rp == SMOOTH or rc == rp or blend[v] >= 1.0:
        _add_mask(v, rp, 0.0, 1.0, F, owner, ve_start, ve_edges, esharp, wn, cs, cn, cols, vals)
        uses_all = rp == SMOOTH
        uses_creases = rp == CREASE
        child_creases = False
    else:
        w = blend[v]
        _add_mask(v, rp, 0.0, w, F, owner, ve_start, ve_edges, esharp, wn, cs, cn, cols, vals)
        _add_mask(v, rc, 1.0, 1.0 - w, F, owner, ve_start, ve_edges, esharp, wn, cs, cn, cols, vals)
        uses_all = rc == SMOOTH
        uses_creases = rp == CREASE
        child_creases = rc == CREASE
    k = 1
    for j in range(n):
        s = esharp[ve_edges[lo + j]]
        if uses_all or (uses_creases and s > 0.0) or (child_creases and s > 1.0):
            cols[k] = cols[1 + j]
            vals[k] = vals[1 + j]
            k += 1
    return _sort_merge(cols, vals, k)


@njit(cache=True)
def _edge_row(e, second, F, twin, owner, esharp, kind, bnext, bprev, cols, vals):
    h = owner[e]
    a = _origin(F, h)
    b = _dest(F, h)
    if kind[e] == EDGE_TRISECT:
        if second:  # e2 = (10 p_i + 16 p_{i+1} + p_{i+2}) / 27
            cols[0] = a
            vals[0] = _T2
            cols[1] = b
            vals[1] = _T1
            cols[2] = _dest(F, bnext[h])
            vals[2] = _T0
        else:  # e1 = (p_{i-1} + 16 p_i + 10 p_{i+1}) / 27
            cols[0] = _origin(F, bprev[h])
            vals[0] = _T0
            cols[1] = a
            vals[1] = _T1
            cols[2] = b
            vals[2] = _T2
        return _sort_merge(cols, vals, 3)
    s = esharp[e]
    t = twin[h]
    if s >= 1.0 or t < 0:
        cols[0] = a
        vals[0] = 0.5
        cols[1] = b
        vals[1] = 0.5
        return _sort_merge(cols, vals, 2)
    # R4 3/8 (a + b) + 1/8 (c + d), blended with the midpoint for 0 < s < 1.
    c = F[h // 3, (h % 3 + 2) % 3]
    d = F[t // 3, (t % 3 + 2) % 3]
    wab = s * 0.5 + (1.0 - s) * 0.375
    wcd = (1.0 - s) * 0.125
    cols[0] = a
    vals[0] = wab
    cols[1] = b
    vals[1] = wab
    cols[2] = c
    vals[2] = wcd
    cols[3] = d
    vals[3] = wcd
    return _sort_merge(cols, vals, 4)


@njit(cache=True)
def _face_row(f, F, cols, vals):
    for i in range(3):
        cols[i] = F[f, i]
        vals[i] = 1.0 / 3.0
    return _sort_merge(cols, vals, 3)


@njit(cache=True)
def build_matrix(
    n_vertices, n_new, F, twin, owner, ve_start, ve_edges, esharp, kind, edge_point, face_point,
    bnext, bprev, rule_parent, rule_child, blend, wn, cs, cn,
):
    """The step's refinement matrix S as CSR arrays (indptr, indices, data).

    Rows: old vertices, then edge points (``edge_point[e]``, two rows for trisected edges),
    then face points (``face_point[f]``); −1 marks an edge or face without a point.
    """
    ne = owner.shape[0]
    m = F.shape[0]
    maxval = 4
    for v in range(n_vertices):
        d = ve_start[v + 1] - ve_start[v]
        if d + 1 > maxval:
            maxval = d + 1
    cols = np.empty(maxval, np.int64)
    vals = np.empty(maxval, np.float64)
    counts = np.zeros(n_new + 1, np.int64)
    for v in range(n_vertices):
        counts[v + 1] = _vertex_row(v, F, owner, ve_start, ve_edges, esharp, rule_parent, rule_child, blend,
                                    wn, cs, cn, cols, vals)
    for e in range(ne):
        r = edge_point[e]
        if r < 0:
            continue
        counts[r + 1] = _edge_row(e, False, F, twin, owner, esharp, kind, bnext, bprev, cols, vals)
        if kind[e] == EDGE_TRISECT:
            counts[r + 2] = _edge_row(e, True, F, twin, owner, esharp, kind, bnext, bprev, cols, vals)
    for f in range(m):
        r = face_point[f]
        if r >= 0:
            counts[r + 1] = _face_row(f, F, cols, vals)
    for r in range(n_new):
        counts[r + 1] += counts[r]
    indptr = counts
    nnz = indptr[n_new]
    indices = np.empty(nnz, np.int64)
    data = np.empty(nnz, np.float64)
    for v in range(n_vertices):
        k = _vertex_row(v, F, owner, ve_start, ve_edges, esharp, rule_parent, rule_child, blend,
                        wn, cs, cn, cols, vals)
        p = indptr[v]
        indices[p:p + k] = cols[:k]
        data[p:p + k] = vals[:k]
    for e in range(ne):
        r = edge_point[e]
        if r < 0:
            continue
        k = _edge_row(e, False, F, twin, owner, esharp, kind, bnext, bprev, cols, vals)
        indices[indptr[r]:indptr[r] + k] = cols[:k]
        data[indptr[r]:indptr[r] + k] = vals[:k]
        if kind[e] == EDGE_TRISECT:
            k = _edge_row(e, True, F, twin, owner, esharp, kind, bnext, bprev, cols, vals)
            indices[indptr[r + 1]:indptr[r + 1] + k] = cols[:k]
            data[indptr[r + 1]:indptr[r + 1] + k] = vals[:k]
    for f in range(m):
        r = face_point[f]
        if r >= 0:
            k = _face_row(f, F, cols, vals)
            indices[indptr[r]:indptr[r] + k] = cols[:k]
            data[indptr[r]:indptr[r] + k] = vals[:k]
    return indptr, indices, data


# ---------------------------------------------------------------------------------------
# Connectivity of the next level.


@njit(cache=True)
def child_face_counts(F, edge_of, kind, face_sharp):
    """Number of children of each face: 4 if sharp, else 3 + its split edges."""
    m = F.shape[0]
    out = np.empty(m, np.int64)
    for f in range(m):
        if face_sharp[f]:
            out[f] = 4
        else:
            c = 3
            for i in range(3):
                if kind[edge_of[3 * f + i]] == EDGE_SPLIT:
                    c += 1
            out[f] = c
    return out


@njit(cache=True, inline="always")
def _apex(F, g, hg, edge_of, kind, edge_point, face_point):
    """The new vertex a face contributes to the flipped edge across its halfedge hg."""
    if face_point[g] >= 0:
        return face_point[g]
    base = 3 * g
    for j in range(3):  # g is trisected along its boundary halfedge base + j
        e = edge_of[base + j]
        if kind[e] == EDGE_TRISECT:
            k = hg - base
            if k == (j + 1) % 3:
                return edge_point[e] + 1
            return edge_point[e]
    return -1


@njit(cache=True)
def emit_faces(F, twin, edge_of, kind, edge_point, face_point, face_sharp, offsets):
    """Faces of the next level, in parent order; ``offsets`` = prefix sums of the counts."""
    m = F.shape[0]
    total = offsets[m]
    out = np.empty((total, 3), np.int64)
    parent = np.empty(total, np.int64)
    for f in range(m):
        o = offsets[f]
        for q in range(o, offsets[f + 1]):
            parent[q] = f
        a = F[f, 0]
        b = F[f, 1]
        c = F[f, 2]
        if face_sharp[f]:
            mab = edge_point[edge_of[3 * f]]
            mbc = edge_point[edge_of[3 * f + 1]]
            mca = edge_point[edge_of[3 * f + 2]]
            out[o, 0] = a
            out[o, 1] = mab
            out[o, 2] = mca
            out[o + 1, 0] = mab
            out[o + 1, 1] = b
            out[o + 1, 2] = mbc
            out[o + 2, 0] = mca
            out[o + 2, 1] = mbc
            out[o + 2, 2] = c
            out[o + 3, 0] = mab
            out[o + 3, 1] = mbc
            out[o + 3, 2] = mca
            continue
        cf = face_point[f]
        for i in range(3):
            h = 3 * f + i
            u = F[f, i]
            w = F[f, (i + 1) % 3]
            e = edge_of[h]
            k = kind[e]
            if k == EDGE_SPLIT:
                mid = edge_point[e]
                out[o, 0] = cf
                out[o, 1] = u
                out[o, 2] = mid
                out[o + 1, 0] = cf
                out[o + 1, 1] = mid
                out[o + 1, 2] = w
                o += 2
            elif k == EDGE_KEEP:
                out[o, 0] = cf
                out[o, 1] = u
                out[o, 2] = w
                o += 1
            elif k == EDGE_TRISECT:
                out[o, 0] = edge_point[e]
                out[o, 1] = edge_point[e] + 1
                out[o, 2] = F[f, (i + 2) % 3]
                o += 1
            else:  # EDGE_FLIP
                t = twin[h]
                out[o, 0] = u
                out[o, 1] = _apex(F, t // 3, t, edge_of, kind, edge_point, face_point)
                out[o, 2] = _apex(F, f, h, edge_of, kind, edge_point, face_point)
                o += 1
    return out, parent
