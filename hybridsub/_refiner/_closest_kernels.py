"""Numba kernel of the closest point on a triangle mesh among candidate triangles.

Private. Contiguous float64 / int64 arrays in, outputs allocated by the caller. The closest
point on one triangle follows the Voronoi regions of its vertices, edges and face (Ericson,
*Real-Time Collision Detection*, 5.1.5), as barycentric coordinates.
"""

from __future__ import annotations

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
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            u, v, w = _closest_on_triangle(px, py, pz, P, a, b, c)
            qx = u * P[a, 0] + v * P[b, 0] + w * P[c, 0]
            qy = u * P[a, 1] + v * P[b, 1] + w * P[c, 1]
            qz = u * P[a, 2] + v * P[b, 2] + w * P[c, 2]
            d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
            if best < 0 or d < bd:
                best = f
                bd = d
                bary_out[i, 0] = u
                bary_out[i, 1] = v
                bary_out[i, 2] = w
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
