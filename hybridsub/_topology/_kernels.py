"""Numba kernels of the topology layer: twins, edge numbering and the emission of the next
level (a step's classification is in ``_classify_kernels``).

Private. Every kernel takes contiguous arrays (int64 indices, float64 data, int8 codes,
bool masks) and plain scalars; no Python objects. Large outputs are allocated by the
callers in ``level`` (NumPy backs big arrays with huge pages, which makes first touch
several times cheaper than Numba's own allocations) and filled here. Halfedges are implicit
(see ``_halfedge_kernels``). An edge is *owned* by its lower-numbered halfedge, and edges are
numbered in owner order: the order of first appearance over the halfedges.

One step runs ``_classify_kernels.classify_step`` (edge kinds, new-point layout, vertex
statistics), then ``vertex_coefficients`` (each vertex mask as four numbers); the refiner's
stencil kernels turn these into rows of S; ``emit_faces`` with ``emit_topology`` make the next
level's faces, then its twins and tags, derived from this level's instead of searched again.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import prange

from .._atomic import atomic_add
from .._jit import NO_PARFORS, kernel, threaded_and_serial
from .._prefetch import prefetch
from .._rules.step_rules import (
    EDGE_FLIP,
    EDGE_KEEP,
    EDGE_SPLIT,
    EDGE_TRISECT,
)
from ._halfedge_kernels import dest, far_twins, next_in_face, prev_in_face

# Error codes of halfedge_twins.
OK = 0
ERR_SAME_DIRECTION = 1  # two halfedges u→w: non-manifold edge or inconsistent orientation
ERR_MULTIPLE_TWINS = 2  # more than two halfedges on one edge

#: Inputs smaller than this (faces or rows) run the serial twin of a threaded kernel: below
#: it threads save a few milliseconds at most, and a first call would pay for compiling the
#: threaded twins as well (docs/performance.md, first call).
PARALLEL_MIN = 65536


def use_threads(rows: int) -> bool:
    """Whether a kernel over ``rows`` faces or rows runs its threaded twin: from
    ``PARALLEL_MIN`` rows (read at call time) and with more than one thread (on one, the
    serial twins are faster: no threaded loops' machinery).

    >>> use_threads(10)
    False
    """
    return rows >= PARALLEL_MIN and numba.get_num_threads() > 1


# ---------------------------------------------------------------------------------------
# Topology of an input mesh (level 0). Later levels get their twins from emit_topology.


@kernel(inline="always")
def _group_starts(start):
    """A counting sort's group starts from its counts: ``start`` (holding each group's size
    at ``start[g + 1]``) summed in place; returns a copy of the starts to fill from."""
    for g in range(start.shape[0] - 1):
        start[g + 1] += start[g]
    return start[:-1].copy()


@kernel(parallel=NO_PARFORS)
def fill_by_origin(F, n_vertices, by_origin):
    """Group the halfedges by origin vertex (a counting sort) into ``by_origin`` (3m,):
    ``by_origin[start[v]:start[v+1]]`` are the halfedges leaving v, in increasing order.
    Returns ``start`` (n + 1,)."""
    m = F.shape[0]
    start = np.zeros(n_vertices + 1, np.int64)
    for f in range(m):
        for i in range(3):
            start[F[f, i] + 1] += 1
    fill = _group_starts(start)
    for f in range(m):
        for i in range(3):
            u = F[f, i]
            by_origin[fill[u]] = 3 * f + i
            fill[u] += 1
    return start


@kernel(parallel=NO_PARFORS)
def group_by_origin(F, n_vertices):
    """:func:`fill_by_origin` into a new array, for kernels; returns (by_origin, start)."""
    by_origin = np.empty(3 * F.shape[0], np.int64)
    return by_origin, fill_by_origin(F, n_vertices, by_origin)


#: Groups of halfedges (by lower end) longer than this are matched by sorting their keys
#: instead of comparing every pair: a fan of many faces around one vertex stays n log n.
_SORT_GROUP_FROM = 64


@kernel(parallel=NO_PARFORS)
def halfedge_twins(F, n_vertices, twin, key, half):
    """Fill ``twin`` (3m,) with the twin of every halfedge (−1 on the boundary).

    ``key`` and ``half`` (3m,) are scratch (int32 where the indices fit). Returns (error,
    h_bad): OK or an ERR_* code with the offending halfedge (the messages are made from the
    faces, by ``errors``). The halfedges are grouped by the lower-numbered end of their edge
    (a counting sort), so both halves of an edge fall in one group, and each group is matched
    on its own, in memory order: a halfedge's key is its edge's other end and whether it
    leaves the lower end.
    """
    m = F.shape[0]
    start = np.zeros(n_vertices + 1, np.int64)
    for f in range(m):
        for i in range(3):
            start[min(F[f, i], F[f, i + 1 if i < 2 else 0]) + 1] += 1
    fill = _group_starts(start)
    for f in range(m):
        for i in range(3):
            u = F[f, i]
            w = F[f, i + 1 if i < 2 else 0]
            lo = min(u, w)
            k = fill[lo]
            fill[lo] = k + 1
            key[k] = 2 * max(u, w) + (1 if u < w else 0)
            half[k] = 3 * f + i
    twin[:] = -1
    for v in range(n_vertices):
        err, bad = _match_group(start[v], start[v + 1], key, half, twin)
        if err != OK:
            return err, bad
    return OK, -1


@kernel
def _sort_pairs(key, half, a, b):
    """Sort ``key[a:b]``, ``half[a:b]`` in place by (key, half): a heapsort (n log n, no
    allocation; NumPy's sorts cost the first call seconds of compiling)."""
    n = b - a
    for root in range(n // 2 - 1, -1, -1):
        _sift_down(key, half, a, root, n)
    for end in range(n - 1, 0, -1):
        key[a], key[a + end] = key[a + end], key[a]
        half[a], half[a + end] = half[a + end], half[a]
        _sift_down(key, half, a, 0, end)


@kernel(inline="always")
def _sift_down(key, half, a, root, n):
    while True:
        child = 2 * root + 1
        if child >= n:
            return
        c, r = a + child, a + root
        if child + 1 < n and (key[c + 1] > key[c] or (key[c + 1] == key[c] and half[c + 1] > half[c])):
            child += 1
            c += 1
        if key[r] > key[c] or (key[r] == key[c] and half[r] >= half[c]):
            return
        key[r], key[c] = key[c], key[r]
        half[r], half[c] = half[c], half[r]
        root = child


@kernel(inline="always")
def _match_group(a, b, key, half, twin):
    """Pair the halfedges ``key[a:b]``, ``half[a:b]`` of one group into twins; returns
    (OK, −1) or an error and its halfedge. A group longer than ``_SORT_GROUP_FROM`` is
    sorted by key first, then only neighbours are compared."""
    if b - a > _SORT_GROUP_FROM:
        _sort_pairs(key, half, a, b)
        for k in range(a, b - 1):
            if key[k] >> 1 == key[k + 1] >> 1:
                err = _pair(twin, key[k], half[k], key[k + 1], half[k + 1])
                if err != OK:
                    return err, np.int64(half[k])
        return OK, np.int64(-1)
    for k in range(a, b):
        for q in range(k + 1, b):
            if key[q] >> 1 == key[k] >> 1:
                err = _pair(twin, key[k], half[k], key[q], half[q])
                if err != OK:
                    return err, np.int64(half[k])
    return OK, np.int64(-1)


@kernel(parallel=True)
def halfedge_twins_chunks(F, n_vertices, twin, key, half, chunks):
    """:func:`halfedge_twins` on ``chunks`` threads: chunks of faces count and place their
    halfedges with atomic adds (so a group's order varies from run to run), then chunks of
    vertices match their groups. The twins of a valid mesh are the same whatever that order
    (each edge has one halfedge each way); on an invalid one some error is found, which
    ``errors`` then names from the faces."""
    m = F.shape[0]
    start = np.zeros(n_vertices + 1, np.int64)
    for c in prange(chunks):
        for f in range(c * m // chunks, (c + 1) * m // chunks):
            for i in range(3):
                atomic_add(start, min(F[f, i], F[f, i + 1 if i < 2 else 0]) + 1, 1)
    fill = _group_starts(start)
    for c in prange(chunks):
        for f in range(c * m // chunks, (c + 1) * m // chunks):
            for i in range(3):
                u = F[f, i]
                w = F[f, i + 1 if i < 2 else 0]
                k = atomic_add(fill, min(u, w), 1)
                key[k] = 2 * max(u, w) + (1 if u < w else 0)
                half[k] = 3 * f + i
    errors = np.zeros(chunks, np.int64)
    where = np.full(chunks, -1, np.int64)
    for c in prange(chunks):
        for t in range(3 * c * m // chunks, 3 * (c + 1) * m // chunks):
            twin[t] = -1
    for c in prange(chunks):
        for v in range(c * n_vertices // chunks, (c + 1) * n_vertices // chunks):
            err, bad = _match_group(start[v], start[v + 1], key, half, twin)
            if err != OK:
                errors[c] = err
                where[c] = bad
                break
    for c in range(chunks):
        if errors[c] != OK:
            return errors[c], where[c]
    return OK, -1


def twin_search(F: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """:func:`halfedge_twins` with its arrays allocated by NumPy (huge pages for big ones);
    returns (twin, error)."""
    nh = 3 * F.shape[0]
    small = 2 * n_vertices + 1 < 2**31 and nh < 2**31
    key = np.empty(nh, np.int32 if small else np.int64)
    half = np.empty(nh, np.int32 if small else np.int64)
    twin = np.empty(nh, np.int64)
    if use_threads(F.shape[0]):
        err, _ = halfedge_twins_chunks(F, n_vertices, twin, key, half, numba.get_num_threads())
    else:
        err, _ = halfedge_twins(F, n_vertices, twin, key, half)
    return twin, err


@kernel(inline="always")
def _pair(twin, key_h, h, key_g, g):
    """Make halfedges h and g of one edge twins, or say why they cannot be."""
    if key_h == key_g:
        return ERR_SAME_DIRECTION
    if twin[h] >= 0 or twin[g] >= 0:
        return ERR_MULTIPLE_TWINS
    twin[h] = g
    twin[g] = h
    return OK


@kernel(parallel=NO_PARFORS)
def first_pillow(twin):
    """The first face whose three edges all lie in one other face (with it, a closed
    two-triangle "pillow": a duplicate face of opposite orientation), or −1."""
    for f in range(twin.shape[0] // 3):
        a = twin[3 * f]
        b = twin[3 * f + 1]
        c = twin[3 * f + 2]
        if a >= 0 and b >= 0 and c >= 0 and a // 3 == b // 3 and b // 3 == c // 3:
            return f
    return -1


@kernel
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
            if dest(F, h) == b:
                out[j] = h
                break
        if out[j] >= 0:
            continue
        for q in range(origin_start[b], origin_start[b + 1]):
            h = by_origin[q]
            if dest(F, h) == a:
                out[j] = h
                break
    return out


@kernel(parallel=NO_PARFORS)
def number_edges(twin, edge_of, owner):
    """Fill the edge of each halfedge (``edge_of``, 3m) and the owner halfedge of each edge
    (``owner[:ne]``), edges in owner order; returns the number of edges ``ne``."""
    ne = 0
    for h in range(twin.shape[0]):
        t = twin[h]
        if t < 0 or h < t:
            edge_of[h] = ne
            owner[ne] = h
            ne += 1
        else:
            edge_of[h] = edge_of[t]
    return ne


@kernel(parallel=NO_PARFORS)
def step_counts(twin, hkind, face_sharp, face_point, out):
    """What a step makes, in one pass: ``out`` (6,) int64 receives the boundary halfedges,
    the split edges, the trisected edges (an interior edge counted once), the split halfedges
    of smooth faces, the sharp faces and the face points."""
    out[:] = 0
    for h in range(twin.shape[0]):
        k = hkind[h]
        inner = twin[h] >= 0
        if not inner:
            out[0] += 1
        if k == EDGE_SPLIT:
            if not inner or twin[h] > h:
                out[1] += 1
            if not face_sharp[h // 3]:
                out[3] += 1
        elif k == EDGE_TRISECT and (not inner or twin[h] > h):
            out[2] += 1
    for f in range(face_sharp.shape[0]):
        if face_sharp[f]:
            out[4] += 1
        if face_point[f] >= 0:
            out[5] += 1


@kernel
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
        g = next_in_face(h)
        for _ in range(nh):
            t = twin[g]
            if t < 0:
                break
            g = next_in_face(t)
        bnext[h] = g
        bprev[g] = h
    return bnext, bprev


# Prefetching the faces across edges pays where they lie far apart (Level.far_apart; the
# measured effect is in docs/performance.md, "Kernel design").
_FACES_AHEAD = 16


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


@kernel(inline="always")
def _first_half(h, face_sharp, first):
    i = h % 3
    if face_sharp[h // 3]:
        return 3 * (first[h] + i) + i
    return 3 * first[h] + 1


@kernel(inline="always")
def _second_half(h, face_sharp, first):
    i = h % 3
    if face_sharp[h // 3]:
        return 3 * (first[h] + (i + 1) % 3) + i
    return 3 * (first[h] + 1) + 1


@kernel(inline="always")
def _spoke_out(h, hkind, first):
    if hkind[h] == EDGE_FLIP:
        return 3 * first[h] + 2
    return 3 * first[h]


@kernel(inline="always")
def _spoke_in(h, twin, hkind, first):
    k = hkind[h]
    if k == EDGE_FLIP:
        return 3 * first[twin[h]]
    if k == EDGE_SPLIT:
        return 3 * (first[h] + 1) + 2
    return 3 * first[h] + 2


@kernel(inline="always")
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


@kernel(inline="always")
def _flip_start_twin(t, hkind, trisected, face_point, first):
    """Twin of the flip triangle's halfedge u→apex(g), g the face of t (t = w→u)."""
    g = t // 3
    if face_point[g] >= 0:
        return _spoke_out(next_in_face(t), hkind, first)
    j = trisected[g]
    if t == 3 * g + (j + 1) % 3:
        return 3 * first[3 * g + j] + 1
    return -1


@kernel(parallel=NO_PARFORS)
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


emit_faces, emit_faces_serial = threaded_and_serial(_emit_faces)


@kernel(inline="always")
def _prefetch_faces_across(h0, twin, hkind, face_point, face_sharp, first):
    """Prefetch what :func:`_emit_topology` reads of the faces across face ``h0 // 3``'s
    edges (they lie anywhere in this level; each read waits on memory otherwise)."""
    for h in range(h0, h0 + 3):
        t = twin[h]
        if t >= 0:
            prefetch(first, t)
            prefetch(hkind, t)
            prefetch(face_point, t // 3)
            prefetch(face_sharp, t // 3)


def _emit_topology(twin, hsharp, has_tags, hkind, face_point, trisected, face_sharp, first, tw, hs, fs, fetch):
    """Fill the next level's twins ``tw``, halfedge sharpness ``hs`` (zeroed; when
    ``has_tags``: children of creases with s > 1 carry s − 1) and sharp-face mask ``fs``
    (zeroed), derived from this level's (no search)."""
    m = face_sharp.shape[0]
    for f in prange(m):
        if fetch and f + _FACES_AHEAD < m:
            _prefetch_faces_across(3 * (f + _FACES_AHEAD), twin, hkind, face_point, face_sharp, first)
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
                tw[3 * q] = _spoke_in(prev_in_face(h), twin, hkind, first)
                tw[3 * q + 1] = _second_half(t, face_sharp, first) if t >= 0 else -1
                tw[3 * q + 2] = 3 * (q + 1)
                tw[3 * (q + 1)] = 3 * q + 2
                tw[3 * (q + 1) + 1] = _first_half(t, face_sharp, first) if t >= 0 else -1
                tw[3 * (q + 1) + 2] = _spoke_out(next_in_face(h), hkind, first)
                if has_tags and t >= 0 and hsharp[h] > 1.0:
                    s = hsharp[h] - 1.0 if hsharp[h] < np.inf else hsharp[h]
                    hs[3 * q + 1] = s
                    hs[3 * (q + 1) + 1] = s
            elif k == EDGE_KEEP:
                tw[3 * q] = _spoke_in(prev_in_face(h), twin, hkind, first)
                tw[3 * q + 1] = -1
                tw[3 * q + 2] = _spoke_out(next_in_face(h), hkind, first)
            elif k == EDGE_TRISECT:
                tw[3 * q] = -1
                tw[3 * q + 1] = 3 * first[twin[next_in_face(h)]]
                tw[3 * q + 2] = 3 * first[prev_in_face(h)] + 2
            else:  # EDGE_FLIP
                tw[3 * q] = _flip_start_twin(t, hkind, trisected, face_point, first)
                tw[3 * q + 1] = 3 * first[t] + 1
                if cf >= 0:
                    tw[3 * q + 2] = _spoke_in(prev_in_face(h), twin, hkind, first)
                else:  # f trisected along its halfedge j: h is its second or third halfedge
                    j = trisected[f]
                    if i == (j + 1) % 3:
                        tw[3 * q + 2] = -1
                    else:
                        tw[3 * q + 2] = 3 * first[3 * f + j] + 2


emit_topology, emit_topology_serial = threaded_and_serial(_emit_topology)