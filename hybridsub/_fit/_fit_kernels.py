"""Numba kernels of fitting: the per-face sums of the data term.

Private. Contiguous float64 / int64 arrays in, outputs allocated (and zeroed) by the caller.
"""

from __future__ import annotations

from .._jit import kernel


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
