"""Numba kernels of the closest point on a triangle mesh: among candidate triangles, or
exactly through a uniform grid of cells.

Private. Contiguous float64 / int64 arrays in, outputs allocated by the caller. The closest
point on one triangle follows the Voronoi regions of its vertices, edges and face (Ericson,
*Real-Time Collision Detection*, 5.1.5), as barycentric coordinates.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .._jit import kernel


@kernel(inline="always")
def _closest_on_triangle(px, py, pz, P, a, b, c):
    """Barycentric (u, v, w) of the point of triangle (a, b, c) of ``P`` closest to p."""
    abx, aby, abz = P[b, 0] - P[a, 0], P[b, 1] - P[a, 1], P[b, 2] - P[a, 2]
    acx, acy, acz = P[c, 0] - P[a, 0], P[c, 1] - P[a, 1], P[c, 2] - P[a, 2]
    apx, apy, apz = px - P[a, 0], py - P[a, 1], pz - P[a, 2]
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return 1.0, 0.0, 0.0
    bpx, bpy, bpz = px - P[b, 0], py - P[b, 1], pz - P[b, 2]
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return 0.0, 1.0, 0.0
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        t = d1 / (d1 - d3)
        return 1.0 - t, t, 0.0
    cpx, cpy, cpz = px - P[c, 0], py - P[c, 1], pz - P[c, 2]
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return 0.0, 0.0, 1.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        t = d2 / (d2 - d6)
        return 1.0 - t, 0.0, t
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 0.0, 1.0 - t, t
    denom = va + vb + vc
    if not denom > 0.0:  # a degenerate triangle: its first vertex
        return 1.0, 0.0, 0.0
    v = vb / denom
    w = vc / denom
    return 1.0 - v - w, v, w


@kernel(parallel=True)
def closest_among(points, P, faces, candidates, face_out, bary_out, d2_out):
    """For each point, the closest point on its candidate triangles (``candidates[i]``, -1 ends).

    Fills ``face_out`` (m,), ``bary_out`` (m, 3) and the squared distance ``d2_out`` (m,);
    a point keeps the first of equally distant triangles. Points are independent rows.
    """
    m, k = candidates.shape
    for i in prange(m):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        best = face_out[i]
        bd = d2_out[i]
        for j in range(k):
            f = candidates[i, j]
            if f < 0:
                break
            best, bd = _try_face(px, py, pz, P, faces, f, best, bd, bary_out[i])
        face_out[i] = best
        d2_out[i] = bd


@kernel
def face_systems(face, bary, metric, residual, H, g):
    """Sum each point's data term into the blocks of its face: ``H[f, a, d, b, e] +=
    bary_a bary_b metric_de`` and ``g[f, a, d] += bary_a (metric · residual)_d``.

    ``face`` (m,), ``bary`` (m, 3), ``metric`` (m, 3, 3), ``residual`` (m, 3); ``H``
    (nf, 3, 3, 3, 3) and ``g`` (nf, 3, 3) zeroed by the caller. Serial: one summation order.
    """
    for i in range(face.shape[0]):
        f = face[i]
        for d in range(3):
            md = 0.0
            for e in range(3):
                md += metric[i, d, e] * residual[i, e]
            for a in range(3):
                g[f, a, d] += bary[i, a] * md
        for a in range(3):
            for b in range(3):
                w = bary[i, a] * bary[i, b]
                for d in range(3):
                    for e in range(3):
                        H[f, a, d, b, e] += w * metric[i, d, e]


@kernel
def bin_faces(P, faces, lo, h, dims, start):
    """Cell lists of a uniform grid: every face in each cell its bounding box touches.

    ``lo`` (3,) the grid's corner, ``h`` the cell size, ``dims`` (3,) cells per axis;
    ``start`` (nx·ny·nz + 1,) zeroed by the caller, filled with each cell's offset. Returns
    the faces of the cells, concatenated (cell ``c`` holds ``out[start[c]:start[c + 1]]``).
    """
    nf = faces.shape[0]
    box = np.empty((nf, 6), np.int64)
    for f in range(nf):
        for a in range(3):
            x0 = min(P[faces[f, 0], a], P[faces[f, 1], a], P[faces[f, 2], a])
            x1 = max(P[faces[f, 0], a], P[faces[f, 1], a], P[faces[f, 2], a])
            box[f, a] = min(max(int((x0 - lo[a]) / h), 0), dims[a] - 1)
            box[f, 3 + a] = min(max(int((x1 - lo[a]) / h), 0), dims[a] - 1)
    for f in range(nf):
        for i in range(box[f, 0], box[f, 3] + 1):
            for j in range(box[f, 1], box[f, 4] + 1):
                for k in range(box[f, 2], box[f, 5] + 1):
                    start[(i * dims[1] + j) * dims[2] + k + 1] += 1
    for c in range(1, start.shape[0]):
        start[c] += start[c - 1]
    fill = start[:-1].copy()
    out = np.empty(start[-1], np.int64)
    for f in range(nf):
        for i in range(box[f, 0], box[f, 3] + 1):
            for j in range(box[f, 1], box[f, 4] + 1):
                for k in range(box[f, 2], box[f, 5] + 1):
                    c = (i * dims[1] + j) * dims[2] + k
                    out[fill[c]] = f
                    fill[c] += 1
    return out


@kernel(inline="always")
def _try_face(px, py, pz, P, faces, f, best, bd, bary):
    """Face ``f`` tried for point p: ``(f, its squared distance)`` with ``bary`` (3,) set when
    it is nearer than ``bd`` (or no face was found yet), else ``(best, bd)`` unchanged."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    u, v, w = _closest_on_triangle(px, py, pz, P, a, b, c)
    qx = u * P[a, 0] + v * P[b, 0] + w * P[c, 0]
    qy = u * P[a, 1] + v * P[b, 1] + w * P[c, 1]
    qz = u * P[a, 2] + v * P[b, 2] + w * P[c, 2]
    d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
    if best < 0 or d < bd:
        bary[0], bary[1], bary[2] = u, v, w
        return f, d
    return best, bd


@kernel(inline="always")
def _cell_d2(px, py, pz, lo, h, i, j, k):
    """Squared distance from p to the box of cell (i, j, k)."""
    return _gap(px, lo[0] + i * h, h) + _gap(py, lo[1] + j * h, h) + _gap(pz, lo[2] + k * h, h)


@kernel(inline="always")
def _gap(x, c0, h):
    """Squared distance from x to the interval [c0, c0 + h]."""
    if x < c0:
        return (c0 - x) ** 2
    if x > c0 + h:
        return (x - c0 - h) ** 2
    return 0.0


@kernel(inline="always")
def _home(x, lo, h, dim):
    """The cell index along one axis of coordinate ``x`` clamped into the grid, and the
    clamped coordinate's distance to that cell's nearer wall."""
    c = min(max(x, lo), lo + dim * h)
    i = min(max(int((c - lo) / h), 0), dim - 1)
    return i, min(c - (lo + i * h), lo + (i + 1) * h - c)


@kernel(parallel=True)
def closest_in_grid(points, P, faces, lo, h, dims, start, cell_faces, face_out, bary_out, d2_out):
    """The closest point of each point on the mesh, exactly, through the grid of :func:`bin_faces`.

    Cells are visited in shells of growing Chebyshev radius r round the cell of the point
    clamped into the grid; every face point in shell r is at least (r − 1) h + δ away (δ:
    the clamped point's distance to its own cell's walls; clamping onto the grid's box never
    lengthens a distance to a point inside it), so the search stops once that reaches the
    best distance. ``face_out[i] >= 0`` on entry is tried first (a warm start).
    """
    m = points.shape[0]
    nmax = max(dims[0], max(dims[1], dims[2]))
    for i in prange(m):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        bary = bary_out[i]
        best, bd = -1, np.inf
        if face_out[i] >= 0:
            best, bd = _try_face(px, py, pz, P, faces, face_out[i], best, bd, bary)
        ci, wx = _home(px, lo[0], h, dims[0])
        cj, wy = _home(py, lo[1], h, dims[1])
        ck, wz = _home(pz, lo[2], h, dims[2])
        delta = max(min(wx, min(wy, wz)), 0.0)
        for r in range(nmax + 1):
            if r > 0:
                lb = (r - 1) * h + delta
                if lb * lb >= bd:
                    break
            for di in range(-r, r + 1):
                ii = ci + di
                if ii < 0 or ii >= dims[0]:
                    continue
                for dj in range(-r, r + 1):
                    jj = cj + dj
                    if jj < 0 or jj >= dims[1]:
                        continue
                    inner = abs(di) < r and abs(dj) < r
                    dk = -r
                    while dk <= r:
                        kk = ck + dk
                        if 0 <= kk < dims[2] and _cell_d2(px, py, pz, lo, h, ii, jj, kk) < bd:
                            cell = (ii * dims[1] + jj) * dims[2] + kk
                            for t in range(start[cell], start[cell + 1]):
                                best, bd = _try_face(px, py, pz, P, faces, cell_faces[t], best, bd, bary)
                        dk += 2 * r if inner and r > 0 else 1
        face_out[i] = best
        d2_out[i] = bd
