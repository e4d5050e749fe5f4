"""Numba kernels of the vertex lane (:mod:`.vertex_lane`): every vertex's face corners grouped,
and the limit position and normal of every smooth vertex of a pure region, and of every
crease and boundary vertex among Loop faces, in one pass over its ring.

Private. Contiguous arrays in.
"""

from __future__ import annotations

import numpy as np

from numba import prange

from .._jit import kernel, threaded_and_serial


@kernel
def corner_slots(F, n, A, B, face):
    """Group the face corners by vertex (a counting sort, faces in increasing order): slot
    ``t`` of vertex ``v`` (``start[v] <= t < start[v + 1]``) is a corner of face ``face[t] =
    (v, A[t], B[t])``. ``A``, ``B``, ``face``: (3m,) arrays to fill. Returns ``start`` (n + 1,).

    Kept as vertex pairs rather than halfedge numbers, so that the pass over the rings reads
    them in order instead of gathering faces.
    """
    m = F.shape[0]
    start = np.zeros(n + 1, np.int64)
    for f in range(m):
        for i in range(3):
            start[F[f, i] + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    for f in range(m):
        u0, u1, u2 = F[f, 0], F[f, 1], F[f, 2]
        t = fill[u0]
        A[t], B[t], face[t] = u1, u2, f
        fill[u0] = t + 1
        t = fill[u1]
        A[t], B[t], face[t] = u2, u0, f
        fill[u1] = t + 1
        t = fill[u2]
        A[t], B[t], face[t] = u0, u1, f
        fill[u2] = t + 1
    return start


@kernel(inline="always")
def _walk(start, A, B, v, ring, off, t0, closed):
    """Follow ``v``'s faces ``(v, p_j, p_{j+1})`` from slot ``t0`` into ``ring[off:]``; returns
    the entries written (``k`` for a closed fan, ``k + 1`` for an open one), 0 where the walk
    is not one fan of all ``k`` faces, −1 where a closed walk met an opening."""
    lo = start[v]
    k = start[v + 1] - lo
    ring[off] = A[t0]
    cur = B[t0]
    for j in range(1, k):
        if cur == ring[off]:  # back at the start early: a second fan
            return 0
        found = -1
        for t in range(lo, lo + k):
            if A[t] == cur:
                found = t
                break
        if found < 0:
            return -1 if closed else 0
        ring[off + j] = cur
        cur = B[found]
    if closed:
        return k if cur == ring[off] else 0
    ring[off + k] = cur
    return k + 1


@kernel(inline="always")
def _fan(start, A, B, v, ring, off):
    """``v``'s ring into ``ring[off:]``: ``(entries, closed)``; entries 0 where its faces are
    not one fan (two fans, two openings). A closed ring starts at ``A[start[v]]`` (the first
    face's), an open one at the face after the opening."""
    lo = start[v]
    k = start[v + 1] - lo
    m = _walk(start, A, B, v, ring, off, lo, True)
    if m >= 0:
        return m, True
    t0 = -1
    for t in range(lo, lo + k):  # the opening: a face whose p_j ends no other face
        a = A[t]
        hit = False
        for u in range(lo, lo + k):
            if B[u] == a:
                hit = True
                break
        if not hit:
            if t0 >= 0:
                return 0, False
            t0 = t
    if t0 < 0:
        return 0, False
    return _walk(start, A, B, v, ring, off, t0, False), False


@kernel(inline="always")
def _sector_normal(X, v, ring, off, first, m, wrap, across, sin_half):
    """Unit normal of the crease sector ``q_j = ring[off + (first + j) % wrap]``, ``j = 0 … m``
    (``m`` faces): ``(q_0 − q_m) × (a v + b (q_0 + q_m) + Σ sin(πj/m) q_j)``; the fourth
    value False where the pair is degenerate (the general path's fan normal applies)."""
    q0 = ring[off + first % wrap]
    qm = ring[off + (first + m) % wrap]
    ux, uy, uz = X[q0, 0] - X[qm, 0], X[q0, 1] - X[qm, 1], X[q0, 2] - X[qm, 2]
    ca, cb = across[m, 0], across[m, 1]
    wx = ca * X[v, 0] + cb * (X[q0, 0] + X[qm, 0])
    wy = ca * X[v, 1] + cb * (X[q0, 1] + X[qm, 1])
    wz = ca * X[v, 2] + cb * (X[q0, 2] + X[qm, 2])
    for j in range(1, m):
        q = ring[off + (first + j) % wrap]
        c = sin_half[m, j]
        wx += c * X[q, 0]
        wy += c * X[q, 1]
        wz += c * X[q, 2]
    return _unit_cross(ux, uy, uz, wx, wy, wz)


@kernel(inline="always")
def _unit_cross(ax, ay, az, bx, by, bz):
    """``a × b`` normalised, and False where it is degenerate (under 1e-12 of ``|a| |b|``)."""
    nx = ay * bz - az * by
    ny = az * bx - ax * bz
    nz = ax * by - ay * bx
    size = np.sqrt(nx * nx + ny * ny + nz * nz)
    scale = np.sqrt(ax * ax + ay * ay + az * az) * np.sqrt(bx * bx + by * by + bz * bz)
    if not size > 1e-12 * scale:
        return 0.0, 0.0, 0.0, False
    return nx / size, ny / size, nz / size, True


@kernel(inline="always")
def _smooth(start, A, B, X, v, region, w_table, cos_table, sin_table, want_normals, P, N):
    """The smooth rule at ``v``, its ring's sums taken along the walk from ``A[start[v]]``:
    1 (``P[v]``, ``N[v]`` written), 0 (two fans, or a degenerate tangent pair: the general
    path's) or −1 (the fan is open: a boundary vertex)."""
    lo = start[v]
    k = start[v + 1] - lo
    first = A[lo]
    cur = B[lo]
    x, y, z = X[first, 0], X[first, 1], X[first, 2]
    sx, sy, sz = x, y, z
    c = cos_table[k, 0]
    s = sin_table[k, 0]
    ax, ay, az = c * x, c * y, c * z
    bx, by, bz = s * x, s * y, s * z
    for j in range(1, k):
        if cur == first:  # back at the start early: a second fan
            return 0
        found = -1
        for t in range(lo + 1, lo + k):
            if A[t] == cur:
                found = t
                break
        if found < 0:
            return -1
        x, y, z = X[cur, 0], X[cur, 1], X[cur, 2]
        sx += x
        sy += y
        sz += z
        c = cos_table[k, j]
        s = sin_table[k, j]
        ax += c * x
        ay += c * y
        az += c * z
        bx += s * x
        by += s * y
        bz += s * z
        cur = B[found]
    if cur != first:
        return 0
    if want_normals:
        nx, ny, nz, ok = _unit_cross(ax, ay, az, bx, by, bz)
        if not ok:
            return 0
        N[v, 0], N[v, 1], N[v, 2] = nx, ny, nz
    w = w_table[region, k]
    c0 = 1.0 - k * w
    P[v, 0] = c0 * X[v, 0] + w * sx
    P[v, 1] = c0 * X[v, 1] + w * sy
    P[v, 2] = c0 * X[v, 2] + w * sz
    return 1


@kernel(inline="always")
def _crease(start, A, B, X, v, cc, crease_nb, crease_mask, across, sin_half, want_normals, one_side, ring, P, N):
    """The crease rule at ``v`` among Loop faces (two creases through a closed fan, or the
    boundary of an open one with none): True with ``P[v]``, ``N[v]`` written, False where
    ``v`` is none of these or its normal is degenerate (the general path's). Its ring goes to
    ``ring[start[v] + v:]``."""
    lo = start[v]
    k = start[v + 1] - lo
    off = lo + v
    m, closed = _fan(start, A, B, v, ring, off)
    if m == 0 or not ((closed and cc == 2) or (not closed and cc == 0)):
        return False
    i1 = i2 = -1
    if closed:
        for j in range(k):
            p = ring[off + j]
            if p == crease_nb[v, 0] or p == crease_nb[v, 1]:
                if i1 < 0:
                    i1 = j
                else:
                    i2 = j
        if i2 < 0:
            return False
        a, b = ring[off + i1], ring[off + i2]
    else:
        a, b = ring[off], ring[off + k]
    if want_normals:
        if closed:
            x1, y1, z1, ok1 = _sector_normal(X, v, ring, off, i1, i2 - i1, k, across, sin_half)
            x2, y2, z2, ok2 = _sector_normal(X, v, ring, off, i2, k - (i2 - i1), k, across, sin_half)
            if not (ok1 and ok2):
                return False
            if not one_side:
                x1, y1, z1 = x1 + x2, y1 + y2, z1 + z2
                size = np.sqrt(x1 * x1 + y1 * y1 + z1 * z1)
                if size < 1e-6:  # sectors facing opposite ways (a fin)
                    return False
                x1, y1, z1 = x1 / size, y1 / size, z1 / size
        else:
            x1, y1, z1, ok1 = _sector_normal(X, v, ring, off, 0, k, k + 1, across, sin_half)
            if not ok1:
                return False
        N[v, 0], N[v, 1], N[v, 2] = x1, y1, z1
    c0, c1 = crease_mask[0], crease_mask[1]
    P[v, 0] = c0 * X[v, 0] + c1 * (X[a, 0] + X[b, 0])
    P[v, 1] = c0 * X[v, 1] + c1 * (X[a, 1] + X[b, 1])
    P[v, 2] = c0 * X[v, 2] + c1 * (X[a, 2] + X[b, 2])
    return True


def _vertex_limits(start, A, B, face, X, blocked, crease_count, crease_nb, face_sharp, w_table, cos_table, sin_table,
                   crease_mask, across, sin_half, want_normals, one_side):
    """Limit position and unit normal of every vertex whose faces are one fan of one kind and
    which is untagged (smooth), or, among Loop faces only, on one crease through it or on the
    boundary (crease vertices); ``blocked`` (corners, ends of semi-sharp creases) are not.

    The corners of ``v`` are the slots of :func:`corner_slots`; the ring ``p_0 … p_{k−1}``
    follows faces ``(v, p_j, p_{j+1})`` from ``p_0 = A[start[v]]`` (an open fan: from the face
    after its opening, ``p_0 … p_k``). Smooth: position ``(1 − k w) v + w Σ p_j``,
    ``w = w_table[region, k]`` (region 1: Loop faces), normal ``t1 × t2``, ``t1 = Σ
    cos_table[k, j] p_j``, ``t2 = Σ sin_table[k, j] p_j``. Crease (``crease_count[v]`` 2
    infinitely sharp creases to ``crease_nb[v]``, or an open fan and none): position
    ``crease_mask[0] v + crease_mask[1] (a + b)``, ``a``, ``b`` the crease's (boundary's)
    neighbours; each sector's normal by :func:`_sector_normal` (``across[m]``: the across
    mask's centre and end weights of a sector of ``m`` faces, ``sin_half[m, j] = sin(πj/m)``),
    the vertex's the normalized mean of its two sectors', or with ``one_side`` the one of the
    sector from the first crease neighbour counter-clockwise from ``p_0`` (OpenSubdiv's side).
    Returns ``(P, N, done)``: ``done`` False where the vertex is left to the general path
    (tagged otherwise, mixed faces, √3 faces at a crease, two fans, valence ≥ the tables'
    size, a degenerate tangent pair, sectors that cancel); P and N are not written there. A
    vertex no face uses is done: its own position, a zero normal. Threaded over the vertices
    (``vertex_limits``; ``vertex_limits_serial`` the same on one thread: each vertex is its
    own sums).
    """
    n = start.shape[0] - 1
    kmax = cos_table.shape[0]
    P = np.empty((n, 3))
    N = np.zeros((n, 3))
    done = np.zeros(n, np.bool_)
    ring = np.empty(A.shape[0] + n, A.dtype)  # crease vertex v's ring at start[v] + v, k + 1 entries at most
    for v in prange(n):
        lo = start[v]
        k = start[v + 1] - lo
        if k == 0:
            P[v, 0], P[v, 1], P[v, 2] = X[v, 0], X[v, 1], X[v, 2]
            done[v] = True
            continue
        if blocked[v] or k + 1 >= kmax:
            continue
        n_sharp = 0
        for t in range(lo, lo + k):
            n_sharp += face_sharp[face[t]]
        if n_sharp != 0 and n_sharp != k:
            continue
        region = 1 if n_sharp == k else 0
        cc = crease_count[v]
        if cc == 0:  # smooth, unless the fan turns out open
            state = _smooth(start, A, B, X, v, region, w_table, cos_table, sin_table, want_normals, P, N)
            if state == 1:
                done[v] = True
            if state >= 0:
                continue
        if region == 1 and _crease(start, A, B, X, v, cc, crease_nb, crease_mask, across, sin_half, want_normals,
                                   one_side, ring, P, N):
            done[v] = True
    return P, N, done


vertex_limits, vertex_limits_serial = threaded_and_serial(_vertex_limits)


@kernel
def crease_neighbours(pairs, sharpness, n):
    """Per vertex: how many infinitely sharp creases of ``pairs`` meet it (an edge listed twice
    counted once), and the far ends of the first two (−1: none)."""
    count = np.zeros(n, np.int64)
    nb = np.full((n, 2), -1, np.int64)
    for r in range(pairs.shape[0]):
        if not np.isinf(sharpness[r]):
            continue
        for e in range(2):
            u, w = pairs[r, e], pairs[r, 1 - e]
            if nb[u, 0] == w or nb[u, 1] == w:
                continue
            if count[u] < 2:
                nb[u, count[u]] = w
            count[u] += 1
    return count, nb


@kernel
def faces_around(start, face, vertices, n_faces):
    """(n_faces,) bool: the faces that use one of ``vertices`` (slots of :func:`corner_slots`)."""
    out = np.zeros(n_faces, np.bool_)
    for v in vertices:
        for t in range(start[v], start[v + 1]):
            out[face[t]] = True
    return out


@kernel
def compact_faces(F, faces, n):
    """The faces ``F[faces]`` (``faces`` a mask) over their own vertices, numbered in order of
    first use: returns ``(local faces (k, 3), used (u,), local (n,))``, ``used[j]`` the vertex
    numbered ``j``, ``local[v]`` the number of vertex ``v`` (−1: not used)."""
    local = np.full(n, -1, np.int64)
    k = 0
    for f in range(faces.shape[0]):
        k += faces[f]
    out = np.empty((k, 3), np.int64)
    used = np.empty(3 * k, np.int64)
    u = 0
    r = 0
    for f in range(faces.shape[0]):
        if not faces[f]:
            continue
        for i in range(3):
            v = F[f, i]
            if local[v] < 0:
                local[v] = u
                used[u] = v
                u += 1
            out[r, i] = local[v]
        r += 1
    return out, used[:u].copy(), local
