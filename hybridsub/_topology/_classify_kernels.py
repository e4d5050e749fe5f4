"""Numba kernels of a step's classification: edge kinds, the numbering of the new points
(serially, or in chunks on threads with the same result), the per-vertex numbers the rules
need, and every vertex mask as four coefficients (from ``_rules``).

Private. Same conventions as ``_kernels`` (contiguous arrays and scalars in, outputs
allocated by the callers in ``plan``); an edge is owned by its lower-numbered halfedge.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .._atomic import atomic_add
from .._jit import NO_PARFORS, kernel, threaded_and_serial
from .._rules.step_rules import (
    CORNER,
    EDGE_FLIP,
    EDGE_KEEP,
    EDGE_SPLIT,
    EDGE_TRISECT,
    REGION_LOOP,
    REGION_MIXED,
    REGION_SQRT3,
    SCHEME_SQRT3,
    SMOOTH,
    vertex_mask,
    vertex_rule,
)
from ._halfedge_kernels import edge_sharpness, owned_ends_in


@kernel(inline="always")
def _boundary_halfedges(f, twin):
    """How many of face ``f``'s halfedges are on the boundary."""
    k = 0
    for i in range(3):
        if twin[3 * f + i] < 0:
            k += 1
    return k


@kernel(inline="always")
def _edge_kind(h, t, s, face_sharp, force_split, sqrt3, odd, twin):
    """The kind of edge ``h`` (twin ``t``, sharpness ``s``) this step. Kobbelt's even steps
    trisect the boundary edge of a face with one; a face with two or three (never met by a
    call, which starts with an odd step, but met where the limit surface cuts a patch out of
    a level) keeps them, as in an odd step (``docs/scheme.md``)."""
    if sqrt3:
        if t < 0:
            return EDGE_KEEP if odd or _boundary_halfedges(h // 3, twin) > 1 else EDGE_TRISECT
        return EDGE_FLIP
    if (s > 0.0 or face_sharp[h // 3] or (t >= 0 and face_sharp[t // 3])
            or (force_split.shape[0] > 0 and force_split[h])):
        return EDGE_SPLIT
    return EDGE_FLIP


@kernel(inline="always")
def _new_on_edge(k):
    """How many new points an edge of kind ``k`` gets."""
    if k == EDGE_SPLIT:
        return 1
    if k == EDGE_TRISECT:
        return 2
    return 0


@kernel(inline="always")
def _face_has_point(f, twin, face_sharp, sqrt3, odd):
    """(whether face ``f`` gets a face point, its trisected boundary halfedge or −1)."""
    if not sqrt3:
        return not face_sharp[f], -1
    tri = -1
    if not odd and _boundary_halfedges(f, twin) == 1:
        for i in range(3):
            if twin[3 * f + i] < 0:
                tri = i
    return tri < 0, tri


@kernel(inline="always")
def _count_end(v, s, counts, s_frac):
    """Vertex ``v``'s share of an edge of sharpness ``s`` in ``counts`` and ``s_frac``."""
    counts[0, v] += 1
    if s > 0.0:
        counts[1, v] += 1
        if s > 1.0:
            counts[2, v] += 1
        else:
            counts[3, v] += 1
            s_frac[v] += s


@kernel(parallel=NO_PARFORS)
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
    0 < s ≤ 1. Returns the number of vertices of the next level. New points are numbered
    edge points first (in owner halfedge order), then face points (in face order).
    :func:`classify_step_chunks` gives the same on threads.
    """
    m = F.shape[0]
    n = counts.shape[1]
    sqrt3 = scheme == SCHEME_SQRT3
    nxt = n
    for f in range(m):  # face by face: a face's corners without dividing halfedges by 3
        for i in range(3):
            h = 3 * f + i
            t = twin[h]
            if t >= 0 and t < h:
                hkind[h] = hkind[t]
                edge_point[h] = edge_point[t]
                continue
            s = edge_sharpness(h, twin, hsharp, has_tags)
            k = _edge_kind(h, t, s, face_sharp, force_split, sqrt3, odd, twin)
            hkind[h] = k
            new = _new_on_edge(k)
            edge_point[h] = nxt if new else -1
            nxt += new
            _count_end(F[f, i], s, counts, s_frac)
            _count_end(F[f, i + 1 if i < 2 else 0], s, counts, s_frac)
    for f in range(m):
        has, trisected[f] = _face_has_point(f, twin, face_sharp, sqrt3, odd)
        face_point[f] = nxt if has else -1
        nxt += 1 if has else 0
        if mixed:
            sh = 1 if face_sharp[f] else 0
            for i in range(3):
                v = F[f, i]
                counts[4, v] += 1
                counts[5, v] += sh
    return nxt


@kernel(parallel=True)
def classify_step_chunks(F, twin, hsharp, has_tags, face_sharp, mixed, force_split, scheme, odd, hkind, edge_point,
                         face_point, trisected, counts, s_frac, chunks):
    """:func:`classify_step` on ``chunks`` threads, with the same output to the bit.

    Each chunk of faces first counts its new points; the numbering then starts each chunk
    where the chunks before it end, so points are numbered as the serial pass numbers them.
    An edge's owner writes its kind and point to its twin as well. Each chunk adds its own
    edges' and faces' shares of the per-vertex counts atomically
    (integers: any order gives the same totals); the sums of fractional sharpness, floats,
    are gathered by vertex ranges in the serial order (:func:`_fraction_range`), when there
    are any.
    """
    m = F.shape[0]
    n = counts.shape[1]
    sqrt3 = scheme == SCHEME_SQRT3
    edge_start = np.zeros(chunks + 1, np.int64)
    face_start = np.zeros(chunks + 1, np.int64)
    fractional = np.zeros(chunks, np.bool_)
    for c in prange(chunks):
        new_e = 0
        new_f = 0
        for f in range(c * m // chunks, (c + 1) * m // chunks):
            for i in range(3):
                h = 3 * f + i
                t = twin[h]
                if t < 0 or t > h:
                    s = edge_sharpness(h, twin, hsharp, has_tags)
                    k = _edge_kind(h, t, s, face_sharp, force_split, sqrt3, odd, twin)
                    hkind[h] = k
                    if t >= 0:
                        hkind[t] = k
                    new_e += _new_on_edge(k)
                    _count_end_atomic(F[f, i], s, counts)
                    _count_end_atomic(F[f, i + 1 if i < 2 else 0], s, counts)
                    if 0.0 < s <= 1.0:
                        fractional[c] = True
            has, trisected[f] = _face_has_point(f, twin, face_sharp, sqrt3, odd)
            new_f += 1 if has else 0
            if mixed:
                for i in range(3):
                    atomic_add(counts[4], F[f, i], 1)
                    if face_sharp[f]:
                        atomic_add(counts[5], F[f, i], 1)
        edge_start[c + 1] = new_e
        face_start[c + 1] = new_f
    edge_start[0] = n
    for c in range(chunks):
        edge_start[c + 1] += edge_start[c]
    face_start[0] = edge_start[chunks]
    for c in range(chunks):
        face_start[c + 1] += face_start[c]
    for c in prange(chunks):
        nxt = edge_start[c]
        nfp = face_start[c]
        for f in range(c * m // chunks, (c + 1) * m // chunks):
            for h in range(3 * f, 3 * f + 3):
                t = twin[h]
                if t < 0 or t > h:
                    new = _new_on_edge(hkind[h])
                    edge_point[h] = nxt if new else -1
                    if t >= 0:
                        edge_point[t] = edge_point[h]
                    nxt += new
            has, _ = _face_has_point(f, twin, face_sharp, sqrt3, odd)
            face_point[f] = nfp if has else -1
            nfp += 1 if has else 0
    if fractional.any():
        for c in prange(chunks):
            _fraction_range(c * n // chunks, (c + 1) * n // chunks, F, twin, hsharp, s_frac)
    return face_start[chunks]


@kernel(inline="always")
def _count_end_atomic(v, s, counts):
    """:func:`_count_end`'s integer counts, added atomically (other threads may count ``v``)."""
    atomic_add(counts[0], v, 1)
    if s > 0.0:
        atomic_add(counts[1], v, 1)
        if s > 1.0:
            atomic_add(counts[2], v, 1)
        else:
            atomic_add(counts[3], v, 1)


@kernel(inline="always")
def _fraction_range(lo, hi, F, twin, hsharp, s_frac):
    """:func:`classify_step`'s sums of fractional sharpness (0 < s ≤ 1, tagged edges only)
    for the vertices ``lo:hi``: every edge is walked and only those vertices' terms kept, so
    each sum runs in the serial order."""
    for f in range(F.shape[0]):
        for i in range(3):
            u, w, mine_u, mine_w = owned_ends_in(F, twin, f, i, lo, hi)
            if not (mine_u or mine_w):
                continue
            h = 3 * f + i
            if twin[h] < 0:
                continue
            s = hsharp[h]
            if 0.0 < s <= 1.0:
                if mine_u:
                    s_frac[u] += s
                if mine_w:
                    s_frac[w] += s


def _vertex_coefficients(counts, s_frac, corner, region_of_all, weight_table, cs, cn, fix_boundary,
                         coefficients):
    """Fill ``coefficients`` (4, n) with each vertex mask as (self, every neighbour,
    parent-crease neighbours, child-crease neighbours); ``fix_boundary`` pins every
    non-smooth vertex (Kobbelt's odd steps). ``region_of_all`` is every vertex's region when
    the faces are all sharp or all smooth, −1 when the counts must decide. ``corner`` (n,)
    float64 is each vertex's sharpness (inf: a corner, 0: none): a vertex with s > 0 is a
    corner this step, one with s > 1 the next as well, and one with 0 < s ≤ 1 joins the
    semi-sharp blend like a decaying crease (OpenSubdiv's fractional weight at a vertex)."""
    n = counts.shape[1]
    for v in prange(n):
        sv = corner[v]
        rp = vertex_rule(counts[1, v], sv > 0.0)
        rc = vertex_rule(counts[2, v], sv > 1.0)
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
        decaying = counts[3, v]
        frac = s_frac[v]
        if 0.0 < sv <= 1.0:
            decaying += 1
            frac += sv
        blend = frac / decaying if decaying > 0 else 0.0
        val = counts[0, v]
        a, b, p, c = vertex_mask(val, rp, rc, blend, weight_table[region, val], cs, cn)
        coefficients[0, v] = a
        coefficients[1, v] = b
        coefficients[2, v] = p
        coefficients[3, v] = c


vertex_coefficients, vertex_coefficients_serial = threaded_and_serial(_vertex_coefficients)
