"""Numba kernels of the sector normals (:mod:`.normals`).

Private. Contiguous arrays in.
"""

from __future__ import annotations

import numpy as np

from .._jit import kernel


@kernel
def fan_area_vectors(F, slots, slot_sector, X, n_sectors):
    """Σ (p_j − v) × (p_{j+1} − v) over each sector's slots (halfedges ``3f + i`` leaving
    ``v = F[f, i]``; ``p_j``, ``p_{j+1}`` the face's next and previous corners)."""
    out = np.zeros((n_sectors, 3))
    for k in range(len(slots)):
        h = slots[k]
        f, i = h // 3, h % 3
        v, a, b = F[f, i], F[f, (i + 1) % 3], F[f, (i + 2) % 3]
        ax, ay, az = X[a, 0] - X[v, 0], X[a, 1] - X[v, 1], X[a, 2] - X[v, 2]
        bx, by, bz = X[b, 0] - X[v, 0], X[b, 1] - X[v, 1], X[b, 2] - X[v, 2]
        s = slot_sector[k]
        out[s, 0] += ay * bz - az * by
        out[s, 1] += az * bx - ax * bz
        out[s, 2] += ax * by - ay * bx
    return out
