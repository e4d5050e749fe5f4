"""Numba kernels of the limit evaluation: ordered vertex fans and their sectors.

Private. Same conventions as ``_kernels``: contiguous int64/bool arrays in, arrays out;
halfedge ``h = 3 f + i`` runs ``F[f, i] → F[f, (i+1) % 3]``.

Around a vertex ``v`` the outgoing halfedges ``v → p_j`` are walked counter-clockwise (the
order in which the faces ``(v, p_j, p_{j+1})`` follow each other): from ``h`` the next one is
``twin(prev(h))``. A *fan* is one such walk: open (it starts at a boundary halfedge and stops
where the next twin is missing) or closed. A *sector* is a run of a fan's faces between two
crease edges: a fan with no crease is one cyclic sector; otherwise it is cut at every crease
edge (a closed fan with one crease, a dart, is one open sector whose two ends are that edge).
"""

from __future__ import annotations

import numpy as np

from .._jit import kernel
from ._halfedge_kernels import dest, origin, prev_in_face


@kernel
def vertex_sectors(F, twin, by_origin, origin_start, crease_he):
    """Sectors of every vertex, in counter-clockwise order.

    Parameters: faces ``F`` (m, 3); ``twin`` (3m,); halfedges grouped by origin
    (``by_origin``, ``origin_start``); ``crease_he`` (3m,) bool: the halfedge's edge is a crease
    (boundary edges must be marked too).

    Returns ``(sec_vertex, sec_open, sec_slot_start, sec_slots, sec_ring_start, sec_ring,
    he_sector)``: per sector its vertex and whether it is open (bounded by crease edges) or
    cyclic; its slots (outgoing halfedges, one per face, in order) as CSR; its ring as CSR
    (``k + 1`` vertices ``q_0 … q_k`` for an open sector of ``k`` faces, ``k`` vertices for a
    cyclic one); and the sector of every halfedge's origin corner.
    """
    n = origin_start.shape[0] - 1
    n_he = twin.shape[0]
    visited = np.zeros(n_he, dtype=np.bool_)
    fan = np.empty(n_he, dtype=np.int64)
    # Upper bounds: at most one sector per slot.
    sec_vertex = np.empty(n_he, dtype=np.int64)
    sec_open = np.empty(n_he, dtype=np.bool_)
    sec_slot_start = np.zeros(n_he + 1, dtype=np.int64)
    sec_slots = np.empty(n_he, dtype=np.int64)
    sec_ring_start = np.zeros(n_he + 1, dtype=np.int64)
    sec_ring = np.empty(2 * n_he, dtype=np.int64)
    he_sector = np.full(n_he, -1, dtype=np.int64)
    ns = 0
    n_slot = 0
    n_ring = 0
    for v in range(n):
        lo = origin_start[v]
        hi = origin_start[v + 1]
        for pass_open in (True, False):
            for t in range(lo, hi):
                h0 = by_origin[t]
                if visited[h0]:
                    continue
                if pass_open and twin[h0] >= 0:
                    continue
                # Walk the fan counter-clockwise.
                k = 0
                h = h0
                closed = False
                while True:
                    fan[k] = h
                    k += 1
                    visited[h] = True
                    nxt = twin[prev_in_face(h)]
                    if nxt < 0:
                        break
                    if nxt == h0:
                        closed = True
                        break
                    if visited[nxt]:  # corrupt tables; stop rather than loop
                        break
                    h = nxt
                # Rotate a closed fan to start at a crease, if it has one.
                start = 0
                n_crease = 0
                for i in range(k):
                    if crease_he[fan[i]]:
                        if n_crease == 0:
                            start = i
                        n_crease += 1
                if not closed or n_crease == 0:
                    start = 0
                # Cut into sectors.
                cyclic = closed and n_crease == 0
                i = 0
                while i < k:
                    sec_vertex[ns] = v
                    sec_open[ns] = not cyclic
                    while True:
                        hh = fan[(start + i) % k]
                        sec_slots[n_slot] = hh
                        he_sector[hh] = ns
                        n_slot += 1
                        sec_ring[n_ring] = dest(F, hh)
                        n_ring += 1
                        i += 1
                        if i >= k or (not cyclic and crease_he[fan[(start + i) % k]]):
                            break
                    if not cyclic:
                        last = fan[(start + i - 1) % k]
                        sec_ring[n_ring] = origin(F, prev_in_face(last))
                        n_ring += 1
                    ns += 1
                    sec_slot_start[ns] = n_slot
                    sec_ring_start[ns] = n_ring
    return (sec_vertex[:ns].copy(), sec_open[:ns].copy(), sec_slot_start[:ns + 1].copy(),
            sec_slots[:n_slot].copy(), sec_ring_start[:ns + 1].copy(), sec_ring[:n_ring].copy(),
            he_sector)
