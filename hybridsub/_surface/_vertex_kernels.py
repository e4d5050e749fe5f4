"""Numba kernels of the vertex lane (:mod:`.vertex_lane`): every vertex's face corners grouped,
and the limit position and normal of every smooth vertex of a pure region in one pass over
its ring.

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


def _smooth_vertex_limits(start, A, B, face, X, blocked, face_sharp, w_table, cos_table, sin_table, want_normals):
    """Limit position and unit normal of every vertex whose ring is one closed fan of faces of
    one kind (all √3 or all Loop), with no tag (``blocked`` False).

    The corners of ``v`` are the slots of :func:`corner_slots`; the ring ``p_0 … p_{k−1}``
    follows faces ``(v, p_j, p_{j+1})`` from ``p_0 = A[start[v]]``. Position
    ``(1 − k w) v + w Σ p_j``, ``w = w_table[region, k]`` (region 1: Loop faces); normal
    ``t1 × t2``, ``t1 = Σ cos_table[k, j] p_j``, ``t2 = Σ sin_table[k, j] p_j``.
    Returns ``(P, N, done)``: ``done`` False where the vertex is left to the general path
    (tagged, mixed faces, a boundary or a second fan, valence ≥ the tables' size, a
    degenerate tangent pair); P and N are not written there. A vertex no face uses is done:
    its own position, a zero normal. Threaded over the vertices (``smooth_vertex_limits``;
    ``smooth_vertex_limits_serial`` the same on one thread: each vertex is its own sums).
    """
    n = start.shape[0] - 1
    kmax = cos_table.shape[0]
    P = np.empty((n, 3))
    N = np.zeros((n, 3))
    done = np.zeros(n, np.bool_)
    for v in prange(n):
        lo = start[v]
        k = start[v + 1] - lo
        if k == 0:
            P[v, 0], P[v, 1], P[v, 2] = X[v, 0], X[v, 1], X[v, 2]
            done[v] = True
            continue
        if blocked[v] or k >= kmax:
            continue
        n_sharp = 0
        for t in range(lo, lo + k):
            n_sharp += face_sharp[face[t]]
        if n_sharp != 0 and n_sharp != k:
            continue
        region = 1 if n_sharp == k else 0
        first = A[lo]
        cur = B[lo]
        x, y, z = X[first, 0], X[first, 1], X[first, 2]
        sx, sy, sz = x, y, z
        c = cos_table[k, 0]
        s = sin_table[k, 0]
        ax, ay, az = c * x, c * y, c * z
        bx, by, bz = s * x, s * y, s * z
        closed = True
        for j in range(1, k):
            if cur == first:  # back at the start early: a second fan
                closed = False
                break
            found = -1
            for t in range(lo + 1, lo + k):
                if A[t] == cur:
                    found = t
                    break
            if found < 0:  # the fan is open: a boundary
                closed = False
                break
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
        if not closed or cur != first:
            continue
        if want_normals:
            nx = ay * bz - az * by
            ny = az * bx - ax * bz
            nz = ax * by - ay * bx
            size = np.sqrt(nx * nx + ny * ny + nz * nz)
            scale = np.sqrt(ax * ax + ay * ay + az * az) * np.sqrt(bx * bx + by * by + bz * bz)
            if not size > 1e-12 * scale:
                continue
            N[v, 0], N[v, 1], N[v, 2] = nx / size, ny / size, nz / size
        w = w_table[region, k]
        c0 = 1.0 - k * w
        P[v, 0] = c0 * X[v, 0] + w * sx
        P[v, 1] = c0 * X[v, 1] + w * sy
        P[v, 2] = c0 * X[v, 2] + w * sz
        done[v] = True
    return P, N, done


smooth_vertex_limits, smooth_vertex_limits_serial = threaded_and_serial(_smooth_vertex_limits)


@kernel
def faces_around(start, face, vertices, n_faces):
    """(n_faces,) bool: the faces that use one of ``vertices`` (slots of :func:`corner_slots`)."""
    out = np.zeros(n_faces, np.bool_)
    for v in vertices:
        for t in range(start[v], start[v + 1]):
            out[face[t]] = True
    return out
