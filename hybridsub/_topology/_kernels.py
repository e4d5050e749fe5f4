"""Numba kernels: the per-element loops of topology, classification, stencils and emission.

Private. Every kernel takes contiguous arrays (int64 indices, float64 data, int8 codes,
bool masks) and plain scalars; no Python objects. Large outputs are allocated by the
callers in ``_topology`` and ``_stencils`` (NumPy backs big arrays with huge pages, which
makes first touch several times cheaper than Numba's own allocations) and filled here.

Halfedge ``h = 3 f + i`` of face ``f`` runs ``F[f, i] → F[f, (i+1) % 3]``; ``twin[h]`` is the
halfedge across (−1 on the boundary). An edge is *owned* by its lower-numbered halfedge, and
edges are numbered in owner order: the order of first appearance over the halfedges.

One step runs ``classify_step`` (edge kinds, new-point layout, vertex statistics), then
``vertex_coefficients`` (each vertex mask as four numbers, from ``_rules``), then either
``apply_step`` (positions directly) or ``matrix_row_sizes`` and ``fill_matrix`` (the CSR
matrix S) — all walk the same rows in the same order, so ``apply_step(X) == S @ X`` bit for
bit — and ``emit_faces`` with ``emit_topology`` (the next level's faces, then its twins and
tags, derived from this level's instead of searched again).
"""

from __future__ import annotations

import numpy as np
import types

from numba import njit, prange

from .._rules.refinement import (
    CORNER,
    EDGE_FLIP,
    EDGE_KEEP,
    EDGE_SPLIT,
    EDGE_TRISECT,
    KOBBELT_TRISECTION,
    REGION_LOOP,
    REGION_MIXED,
    REGION_SQRT3,
    SCHEME_SQRT3,
    SMOOTH,
    edge_weights,
    vertex_mask,
    vertex_rule,
)

# Error codes of halfedge_twins.
OK = 0
ERR_SAME_DIRECTION = 1  # two halfedges u→w: non-manifold edge or inconsistent orientation
ERR_MULTIPLE_TWINS = 2  # several halfedges w→u for one u→w

_T0, _T1, _T2 = KOBBELT_TRISECTION
_THIRD = 1.0 / 3.0

#: Inputs smaller than this (faces or rows) run the serial twin of a threaded kernel:
#: starting threads costs more than the work.
PARALLEL_MIN = 20000


def _threaded_and_serial(fn):
    """Compile a kernel written with ``prange`` twice: threaded, and serial (``prange`` runs
    as ``range``). The serial twin is a copy of the function under its own name, so the
    two have separate on-disk caches."""
    serial = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + "_serial", fn.__defaults__,
                                fn.__closure__)
    serial.__qualname__ = fn.__qualname__ + "_serial"
    serial.__doc__ = fn.__doc__
    return njit(cache=True, parallel=True)(fn), njit(cache=True)(serial)


@njit(cache=True, inline="always")
def _dest(F, h):
    return F[h // 3, (h % 3 + 1) % 3]


@njit(cache=True, inline="always")
def _origin(F, h):
    return F[h // 3, h % 3]


@njit(cache=True, inline="always")
def _opposite(F, h):
    return F[h // 3, (h % 3 + 2) % 3]


@njit(cache=True, inline="always")
def _next(h):
    return h - h % 3 + (h % 3 + 1) % 3


@njit(cache=True, inline="always")
def _prev(h):
    return h - h % 3 + (h % 3 + 2) % 3


# ---------------------------------------------------------------------------------------
# Topology of an input mesh (level 0). Later levels get their twins from emit_topology.


@njit(cache=True)
def group_by_origin(F, n_vertices):
    """Halfedges grouped by origin vertex (a counting sort): ``by_origin[start[v]:start[v+1]]``
    are the halfedges leaving v, in increasing order. Returns (by_origin, start)."""
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
    return by_origin, start


@njit(cache=True)
def halfedge_twins(F, n_vertices):
    """Twin of every halfedge (−1 on the boundary), and halfedges grouped by origin.

    Returns (twin, by_origin, origin_start, error, h_bad), the middle two as
    :func:`group_by_origin` gives them. ``error`` is OK or an ERR_* code with the offending
    halfedge ``h_bad``.
    """
    nh = 3 * F.shape[0]
    by_origin, start = group_by_origin(F, n_vertices)
    dest = np.empty(nh, np.int64)  # destination of by_origin[k], so every group scans contiguously
    for k in range(nh):
        dest[k] = _dest(F, by_origin[k])
    twin = np.full(nh, -1, np.int64)
    for u in range(n_vertices):
        for k in range(start[u], start[u + 1]):
            w = dest[k]
            h = by_origin[k]
            for q in range(k + 1, start[u + 1]):
                if dest[q] == w:
                    return twin, by_origin, start, ERR_SAME_DIRECTION, h
            if twin[h] >= 0:
                continue
            for q in range(start[w], start[w + 1]):
                if dest[q] == u:
                    g = by_origin[q]
                    if twin[h] >= 0:
                        return twin, by_origin, start, ERR_MULTIPLE_TWINS, h
                    twin[h] = g
                    twin[g] = h
    return twin, by_origin, start, OK, -1


@njit(cache=True)
def find_halfedges(pairs, F, by_origin, origin_start):
    """A halfedge of each vertex pair's edge (either orientation), −1 where there is none."""
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
                out[j] = h
                break
        if out[j] >= 0:
            continue
        for q in range(origin_start[b], origin_start[b + 1]):
            h = by_origin[q]
            if _dest(F, h) == a:
                out[j] = h
                break
    return out


@njit(cache=True)
def number_edges(twin):
    """Edge of each halfedge and owner halfedge of each edge, edges in owner order."""
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
# Classification of one step.


@njit(cache=True, inline="always")
def _sharpness(h, twin, hsharp, has_tags):
    """Sharpness of h's edge this step: inf on the boundary, the tag inside (0 untagged)."""
    if twin[h] < 0:
        return np.inf
    if has_tags:
        return hsharp[h]
    return 0.0


@njit(cache=True)
def classify_step(F, twin, hsharp, has_tags, face_sharp, mixed, force_split, scheme, odd, hkind, edge_point,
                  face_point, trisected, counts, s_frac):
    """Edge kinds and the layout of the new points, plus the per-vertex numbers the rules need.

    ``force_split`` (3m,) bool, or empty: edges to split even between smooth faces (UV
    seams). Fills ``hkind`` and ``edge_point`` (3m,): each halfedge's edge kind and the index of the
    (first) point on its edge or −1; ``face_point`` (m,) likewise; ``trisected`` (m,) the
    local index of a face's trisected boundary halfedge or −1. ``counts`` (6, n), zeroed
    by the caller, receives per vertex: valence, incident edges with s > 0, with s > 1, with
    0 < s ≤ 1, incident faces, incident sharp faces (the last two only if ``mixed``: some
    faces are sharp and some not); ``s_frac`` (n,), zeroed, the sum of s over edges with
    0 < s ≤ 1. Returns the number of vertices of the next level.
    """
    m = F.shape[0]
    n = counts.shape[1]
    sqrt3 = scheme == SCHEME_SQRT3
    nxt = n
    for h in range(3 * m):
        t = twin[h]
        if t >= 0 and t < h:
            hkind[h] = hkind[t]
            edge_point[h] = edge_point[t]
            continue
        s = _sharpness(h, twin, hsharp, has_tags)
        if sqrt3:
            if t < 0:
                k = EDGE_KEEP if odd else EDGE_TRISECT
            else:
                k = EDGE_FLIP
        elif (s > 0.0 or face_sharp[h // 3] or (t >= 0 and face_sharp[t // 3])
              or (force_split.shape[0] > 0 and force_split[h])):
            k = EDGE_SPLIT
        else:
            k = EDGE_FLIP
        hkind[h] = k
        if k == EDGE_SPLIT:
            edge_point[h] = nxt
            nxt += 1
        elif k == EDGE_TRISECT:
            edge_point[h] = nxt
            nxt += 2
        else:
            edge_point[h] = -1
        u = _origin(F, h)
        w = _dest(F, h)
        counts[0, u] += 1
        counts[0, w] += 1
        if s > 0.0:
            counts[1, u] += 1
            counts[1, w] += 1
            if s > 1.0:
                counts[2, u] += 1
                counts[2, w] += 1
            else:
                counts[3, u] += 1
                counts[3, w] += 1
                s_frac[u] += s
                s_frac[w] += s
    for f in range(m):
        trisected[f] = -1
        if sqrt3:
            has = True
            if not odd:
                for i in range(3):
                    if twin[3 * f + i] < 0:
                        has = False
                        trisected[f] = i
        else:
            has = not face_sharp[f]
        if has:
            face_point[f] = nxt
            nxt += 1
        else:
            face_point[f] = -1
        if mixed:
            sh = 1 if face_sharp[f] else 0
            for i in range(3):
                v = F[f, i]
                counts[4, v] += 1
                counts[5, v] += sh
    return nxt


@njit(cache=True)
def vertex_coefficients(counts, s_frac, corner, region_of_all, weight_table, cs, cn, fix_boundary,
                        coefficients):
    """Fill ``coefficients`` (4, n) with each vertex mask as (self, every neighbour,
    parent-crease neighbours, child-crease neighbours); ``fix_boundary`` pins every
    non-smooth vertex (Kobbelt's odd steps). ``region_of_all`` is every vertex's region when
    the faces are all sharp or all smooth, −1 when the counts must decide."""
    n = counts.shape[1]
    for v in range(n):
        rp = vertex_rule(counts[1, v], corner[v])
        rc = vertex_rule(counts[2, v], corner[v])
        if fix_boundary and rp != SMOOTH:
            rp = CORNER
            rc = CORNER
        if region_of_all >= 0:
            region = region_of_all
        elif counts[5, v] == 0:
            region = REGION_SQRT3
        elif counts[5, v] == counts[4, v]:
            region = REGION_LOOP
        else:
            region = REGION_MIXED
        blend = s_frac[v] / counts[3, v] if counts[3, v] > 0 else 0.0
        val = counts[0, v]
        a, b, p, c = vertex_mask(val, rp, rc, blend, weight_table[region, val], cs, cn)
        coefficients[0, v] = a
        coefficients[1, v] = b
        coefficients[2, v] = p
        coefficients[3, v] = c


# ---------------------------------------------------------------------------------------
# Stencils. Rows: each old vertex (itself, then its neighbours in edge order), then the
# edge points in edge order, then the face points. apply_step and build_matrix walk them
# identically.


@njit(cache=True, inline="always")
def _neighbour_coefficient(v, s, coef):
    c = coef[1, v]
    if s > 0.0:
        c += coef[2, v]
        if s > 1.0:
            c += coef[3, v]
    return c


def _apply_step(X, F, twin, hsharp, has_tags, hkind, edge_point, face_point, coef, bnext, bprev, out, chunks):
    """Fill ``out`` (n_new, k) with the next level's data ``S @ X``, without forming S.

    Old vertices gather from their neighbours in edge order. ``chunks`` threads each take
    one range of vertices and walk all edges, keeping their own vertices' terms, so every
    vertex is summed in the same order whatever the number of threads. Edge and face
    points, one row each, are computed in parallel.
    """
    n = coef.shape[1]
    k = X.shape[1]
    m = F.shape[0]
    for c in prange(chunks):
        lo = c * n // chunks
        hi = (c + 1) * n // chunks
        for v in range(lo, hi):
            for j in range(k):
                out[v, j] = coef[0, v] * X[v, j]
        for h in range(3 * m):
            t = twin[h]
            if t >= 0 and t < h:
                continue
            u = _origin(F, h)
            w = _dest(F, h)
            mine_u = lo <= u < hi
            mine_w = lo <= w < hi
            if not (mine_u or mine_w):
                continue
            s = _sharpness(h, twin, hsharp, has_tags)
            if mine_u:
                cu = _neighbour_coefficient(u, s, coef)
                if cu != 0.0:
                    for j in range(k):
                        out[u, j] += cu * X[w, j]
            if mine_w:
                cw = _neighbour_coefficient(w, s, coef)
                if cw != 0.0:
                    for j in range(k):
                        out[w, j] += cw * X[u, j]
    for h in prange(3 * m):
        r = edge_point[h]
        t = twin[h]
        if r < 0 or (t >= 0 and t < h):
            continue
        u = _origin(F, h)
        w = _dest(F, h)
        if hkind[h] == EDGE_TRISECT:
            p0 = _origin(F, bprev[h])
            p3 = _dest(F, bnext[h])
            for j in range(k):
                out[r, j] = _T0 * X[p0, j] + _T1 * X[u, j] + _T2 * X[w, j]
                out[r + 1, j] = _T2 * X[u, j] + _T1 * X[w, j] + _T0 * X[p3, j]
            continue
        wab, wcd = edge_weights(_sharpness(h, twin, hsharp, has_tags))
        if wcd == 0.0:
            for j in range(k):
                out[r, j] = wab * X[u, j] + wab * X[w, j]
        else:
            a = _opposite(F, h)
            b = _opposite(F, t)
            for j in range(k):
                out[r, j] = wab * X[u, j] + wab * X[w, j] + wcd * X[a, j] + wcd * X[b, j]
    for f in prange(m):
        r = face_point[f]
        if r >= 0:
            a = F[f, 0]
            b = F[f, 1]
            c3 = F[f, 2]
            for j in range(k):
                out[r, j] = _THIRD * X[a, j] + _THIRD * X[b, j] + _THIRD * X[c3, j]


apply_step, apply_step_serial = _threaded_and_serial(_apply_step)


@njit(cache=True)
def matrix_row_sizes(F, twin, hsharp, has_tags, hkind, edge_point, face_point, coef, bnext, bprev, indptr):
    """Fill ``indptr`` (n_new + 1, zeroed) with the CSR row offsets of the step's matrix."""
    n = coef.shape[1]
    m = F.shape[0]
    n_new = indptr.shape[0] - 1
    for v in range(n):
        indptr[v + 1] = 1
    for h in range(3 * m):
        t = twin[h]
        if t >= 0 and t < h:
            continue
        u = _origin(F, h)
        w = _dest(F, h)
        s = _sharpness(h, twin, hsharp, has_tags)
        if _neighbour_coefficient(u, s, coef) != 0.0:
            indptr[u + 1] += 1
        if _neighbour_coefficient(w, s, coef) != 0.0:
            indptr[w + 1] += 1
        r = edge_point[h]
        if r < 0:
            continue
        if hkind[h] == EDGE_TRISECT:
            indptr[r + 1] = 3
            indptr[r + 2] = 3
        else:
            indptr[r + 1] = 2 if edge_weights(s)[1] == 0.0 else 4
    for f in range(m):
        if face_point[f] >= 0:
            indptr[face_point[f] + 1] = 3
    for r in range(n_new):
        indptr[r + 1] += indptr[r]


@njit(cache=True)
def fill_matrix(F, twin, hsharp, has_tags, hkind, edge_point, face_point, coef, bnext, bprev, indptr,
                indices, data):
    """Fill the CSR ``indices`` and ``data`` of the step's matrix, rows in apply_step's order."""
    n = coef.shape[1]
    m = F.shape[0]
    fill = indptr[:n].copy()
    for v in range(n):
        indices[fill[v]] = v
        data[fill[v]] = coef[0, v]
        fill[v] += 1
    for h in range(3 * m):
        t = twin[h]
        if t >= 0 and t < h:
            continue
        u = _origin(F, h)
        w = _dest(F, h)
        s = _sharpness(h, twin, hsharp, has_tags)
        c = _neighbour_coefficient(u, s, coef)
        if c != 0.0:
            indices[fill[u]] = w
            data[fill[u]] = c
            fill[u] += 1
        c = _neighbour_coefficient(w, s, coef)
        if c != 0.0:
            indices[fill[w]] = u
            data[fill[w]] = c
            fill[w] += 1
        r = edge_point[h]
        if r < 0:
            continue
        q = indptr[r]
        if hkind[h] == EDGE_TRISECT:
            indices[q] = _origin(F, bprev[h])
            indices[q + 1] = u
            indices[q + 2] = w
            indices[q + 3] = u
            indices[q + 4] = w
            indices[q + 5] = _dest(F, bnext[h])
            data[q] = _T0
            data[q + 1] = _T1
            data[q + 2] = _T2
            data[q + 3] = _T2
            data[q + 4] = _T1
            data[q + 5] = _T0
            continue
        wab, wcd = edge_weights(s)
        indices[q] = u
        indices[q + 1] = w
        data[q] = wab
        data[q + 1] = wab
        if wcd != 0.0:
            indices[q + 2] = _opposite(F, h)
            indices[q + 3] = _opposite(F, t)
            data[q + 2] = wcd
            data[q + 3] = wcd
    for f in range(m):
        r = face_point[f]
        if r >= 0:
            q = indptr[r]
            for i in range(3):
                indices[q + i] = F[f, i]
                data[q + i] = _THIRD


def _csr_apply(indptr, indices, data, X, out):
    """``out = S @ X`` for CSR S, rows in parallel, each summed in stored order (as SciPy)."""
    k = X.shape[1]
    for r in prange(indptr.shape[0] - 1):
        for j in range(k):
            out[r, j] = 0.0
        for q in range(indptr[r], indptr[r + 1]):
            c = indices[q]
            w = data[q]
            for j in range(k):
                out[r, j] += w * X[c, j]


csr_apply, csr_apply_serial = _threaded_and_serial(_csr_apply)


# ---------------------------------------------------------------------------------------
# The next level: faces in parent order, and their twins and tags derived from this level.
#
# A smooth face emits, per halfedge u→w, a split pair A = (c, u, m), B = (c, m, w), a flip
# triangle T = (u, apex(g), apex(f)), a kept boundary triangle T = (c, u, w), or (Kobbelt's
# even steps) the trisection triangle (e1, e2, x); ``first[h]`` is the index of the first
# child face of h. A sharp face emits C0..C3 at ``first[3f]``. The child halfedges that the
# twins are stated in:
#   FH(h) = u→m, SH(h) = m→w (the two halves of a split edge);
#   OUT(h) = c_f→u and IN(h) = w→c_f (the spokes to f's face point).


@njit(cache=True, inline="always")
def _first_half(h, face_sharp, first):
    i = h % 3
    if face_sharp[h // 3]:
        return 3 * (first[h] + i) + i
    return 3 * first[h] + 1


@njit(cache=True, inline="always")
def _second_half(h, face_sharp, first):
    i = h % 3
    if face_sharp[h // 3]:
        return 3 * (first[h] + (i + 1) % 3) + i
    return 3 * (first[h] + 1) + 1


@njit(cache=True, inline="always")
def _spoke_out(h, hkind, first):
    if hkind[h] == EDGE_FLIP:
        return 3 * first[h] + 2
    return 3 * first[h]


@njit(cache=True, inline="always")
def _spoke_in(h, twin, hkind, first):
    k = hkind[h]
    if k == EDGE_FLIP:
        return 3 * first[twin[h]]
    if k == EDGE_SPLIT:
        return 3 * (first[h] + 1) + 2
    return 3 * first[h] + 2


@njit(cache=True, inline="always")
def _apex(g, hg, trisected, edge_point, face_point):
    """The new vertex face g gives the flipped edge across its halfedge hg: its face point,
    or for a face trisected along its halfedge j, e2 across the next halfedge, e1 across
    the one after."""
    fp = face_point[g]
    if fp >= 0:
        return fp
    j = trisected[g]
    if hg == 3 * g + (j + 1) % 3:
        return edge_point[3 * g + j] + 1
    return edge_point[3 * g + j]


@njit(cache=True, inline="always")
def _flip_start_twin(t, hkind, trisected, face_point, first):
    """Twin of the flip triangle's halfedge u→apex(g), g the face of t (t = w→u)."""
    g = t // 3
    if face_point[g] >= 0:
        return _spoke_out(_next(t), hkind, first)
    j = trisected[g]
    if t == 3 * g + (j + 1) % 3:
        return 3 * first[3 * g + j] + 1
    return -1


@njit(cache=True)
def child_offsets(hkind, face_sharp, offsets, first):
    """Fill the first child face of every face (``offsets``, m + 1) and of every halfedge
    (``first``, 3m)."""
    m = face_sharp.shape[0]
    o = 0
    for f in range(m):
        offsets[f] = o
        if face_sharp[f]:
            for i in range(3):
                first[3 * f + i] = o
            o += 4
        else:
            for i in range(3):
                first[3 * f + i] = o
                o += 2 if hkind[3 * f + i] == EDGE_SPLIT else 1
    offsets[m] = o


def _emit_faces(F, twin, hkind, edge_point, face_point, trisected, face_sharp, first, out):
    """Fill ``out`` with the faces of the next level, in parent order."""
    m = F.shape[0]
    for f in prange(m):
        o = first[3 * f]
        if face_sharp[f]:
            m0 = edge_point[3 * f]
            m1 = edge_point[3 * f + 1]
            m2 = edge_point[3 * f + 2]
            out[o, 0] = F[f, 0]
            out[o, 1] = m0
            out[o, 2] = m2
            out[o + 1, 0] = m0
            out[o + 1, 1] = F[f, 1]
            out[o + 1, 2] = m1
            out[o + 2, 0] = m2
            out[o + 2, 1] = m1
            out[o + 2, 2] = F[f, 2]
            out[o + 3, 0] = m0
            out[o + 3, 1] = m1
            out[o + 3, 2] = m2
            continue
        cf = face_point[f]
        for i in range(3):
            h = 3 * f + i
            k = hkind[h]
            if k == EDGE_FLIP:
                t = twin[h]
                out[o, 0] = F[f, i]
                out[o, 1] = _apex(t // 3, t, trisected, edge_point, face_point)
                out[o, 2] = cf if cf >= 0 else _apex(f, h, trisected, edge_point, face_point)
                o += 1
            elif k == EDGE_SPLIT:
                mid = edge_point[h]
                out[o, 0] = cf
                out[o, 1] = F[f, i]
                out[o, 2] = mid
                out[o + 1, 0] = cf
                out[o + 1, 1] = mid
                out[o + 1, 2] = F[f, (i + 1) % 3]
                o += 2
            elif k == EDGE_KEEP:
                out[o, 0] = cf
                out[o, 1] = F[f, i]
                out[o, 2] = F[f, (i + 1) % 3]
                o += 1
            else:  # EDGE_TRISECT
                out[o, 0] = edge_point[h]
                out[o, 1] = edge_point[h] + 1
                out[o, 2] = F[f, (i + 2) % 3]
                o += 1


emit_faces, emit_faces_serial = _threaded_and_serial(_emit_faces)


def _emit_topology(twin, hsharp, has_tags, hkind, face_point, trisected, face_sharp, first, tw, hs, fs):
    """Fill the next level's twins ``tw``, halfedge sharpness ``hs`` (zeroed; when
    ``has_tags``: children of creases with s > 1 carry s − 1) and sharp-face mask ``fs``
    (zeroed), derived from this level's (no search)."""
    m = face_sharp.shape[0]
    for f in prange(m):
        o = first[3 * f]
        if face_sharp[f]:
            for q in range(4):
                fs[o + q] = True
            c3 = 3 * (o + 3)
            tw[3 * o + 1] = c3 + 2
            tw[3 * (o + 1) + 2] = c3
            tw[3 * (o + 2)] = c3 + 1
            tw[c3] = 3 * (o + 1) + 2
            tw[c3 + 1] = 3 * (o + 2)
            tw[c3 + 2] = 3 * o + 1
            for i in range(3):
                h = 3 * f + i
                t = twin[h]
                a = _first_half(h, face_sharp, first)
                b = _second_half(h, face_sharp, first)
                tw[a] = _second_half(t, face_sharp, first) if t >= 0 else -1
                tw[b] = _first_half(t, face_sharp, first) if t >= 0 else -1
                if has_tags and t >= 0 and hsharp[h] > 1.0:
                    s = hsharp[h] - 1.0 if hsharp[h] < np.inf else hsharp[h]
                    hs[a] = s
                    hs[b] = s
            continue
        cf = face_point[f]
        for i in range(3):
            h = 3 * f + i
            k = hkind[h]
            q = first[h]
            t = twin[h]
            if k == EDGE_SPLIT:
                tw[3 * q] = _spoke_in(_prev(h), twin, hkind, first)
                tw[3 * q + 1] = _second_half(t, face_sharp, first) if t >= 0 else -1
                tw[3 * q + 2] = 3 * (q + 1)
                tw[3 * (q + 1)] = 3 * q + 2
                tw[3 * (q + 1) + 1] = _first_half(t, face_sharp, first) if t >= 0 else -1
                tw[3 * (q + 1) + 2] = _spoke_out(_next(h), hkind, first)
                if has_tags and t >= 0 and hsharp[h] > 1.0:
                    s = hsharp[h] - 1.0 if hsharp[h] < np.inf else hsharp[h]
                    hs[3 * q + 1] = s
                    hs[3 * (q + 1) + 1] = s
            elif k == EDGE_KEEP:
                tw[3 * q] = _spoke_in(_prev(h), twin, hkind, first)
                tw[3 * q + 1] = -1
                tw[3 * q + 2] = _spoke_out(_next(h), hkind, first)
            elif k == EDGE_TRISECT:
                tw[3 * q] = -1
                tw[3 * q + 1] = 3 * first[twin[_next(h)]]
                tw[3 * q + 2] = 3 * first[_prev(h)] + 2
            else:  # EDGE_FLIP
                tw[3 * q] = _flip_start_twin(t, hkind, trisected, face_point, first)
                tw[3 * q + 1] = 3 * first[t] + 1
                if cf >= 0:
                    tw[3 * q + 2] = _spoke_in(_prev(h), twin, hkind, first)
                else:  # f trisected along its halfedge j: h is its second or third halfedge
                    j = trisected[f]
                    if i == (j + 1) % 3:
                        tw[3 * q + 2] = -1
                    else:
                        tw[3 * q + 2] = 3 * first[3 * f + j] + 2


emit_topology, emit_topology_serial = _threaded_and_serial(_emit_topology)
