"""Vertex sectors: every vertex's faces in counter-clockwise order, cut at crease edges.

Around a vertex ``v`` the outgoing halfedges ``v → p_j`` follow each other counter-clockwise
(faces ``(v, p_j, p_{j+1})``). A *sector* is a run of those faces between two crease (or
boundary) edges: a vertex with no crease has one cyclic sector, with ring ``p_0 … p_{k−1}``;
an open sector of ``k`` faces has the ring ``q_0 … q_k``, ``q_0`` and ``q_k`` the far ends of
its two crease edges (a dart's single crease bounds both ends of its one sector). The walk
itself is the Numba kernel in ``_sector_kernels``; this module is its Python side.

>>> import numpy as np
>>> from hybridsub._topology import build_level
>>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1]])   # a closed fan around 0, open at the rim
>>> level = build_level(F, 4)
>>> crease = level.boundary_edge                        # only the rim is a crease
>>> sec = vertex_sectors(level, crease)
>>> sec.vertex.tolist(), sec.open.tolist(), sec.n_faces.tolist()
([0, 1, 2, 3], [False, True, True, True], [3, 2, 2, 2])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _sector_kernels as SK
from .level import Level


@dataclass(frozen=True, eq=False)
class Sectors:
    """The sectors of one level (see the module's docstring), as CSR arrays."""

    vertex: np.ndarray  # (s,) the sector's vertex
    open: np.ndarray  # (s,) bounded by crease edges (else cyclic)
    slot_start: np.ndarray  # (s + 1,) CSR into slots
    slots: np.ndarray  # outgoing halfedges, one per face, counter-clockwise
    ring_start: np.ndarray  # (s + 1,) CSR into ring
    ring: np.ndarray  # q_0 … q_k (open) or p_0 … p_{k−1} (cyclic)
    he_sector: np.ndarray  # (3m,) sector of each halfedge's origin corner

    @property
    def n_faces(self) -> np.ndarray:
        """(s,) faces of each sector."""
        return np.diff(self.slot_start)

    @property
    def slot_sector(self) -> np.ndarray:
        """Sector of every slot, in slot order."""
        return np.repeat(np.arange(len(self.vertex)), self.n_faces)

    @property
    def first_ring(self) -> np.ndarray:
        """(s,) first ring vertex of each sector (``q_0`` of an open sector)."""
        return self.ring[self.ring_start[:-1]]

    @property
    def last_ring(self) -> np.ndarray:
        """(s,) last ring vertex of each sector (``q_k`` of an open sector)."""
        return self.ring[self.ring_start[1:] - 1]

    def ring_index(self) -> tuple[np.ndarray, np.ndarray]:
        """For each ring entry: its sector and its position ``j`` in the sector's ring."""
        lens = np.diff(self.ring_start)
        sid = np.repeat(np.arange(len(lens)), lens)
        j = np.arange(len(self.ring)) - self.ring_start[sid]
        return sid, j


def vertex_sectors(level: Level, crease: np.ndarray) -> Sectors:
    """The sectors of every vertex of ``level``, cut at the edges where ``crease`` is True.

    Parameters
    ----------
    level : Level
        The faces and their twins.
    crease : (E,) array of bool
        Per edge of ``level``: a crease. Boundary edges must be marked too.

    Returns
    -------
    Sectors
        Vertex by vertex, each vertex's sectors in counter-clockwise order.

    Examples
    --------
    >>> import numpy as np
    >>> from hybridsub._topology import build_level
    >>> level = build_level(np.array([[0, 1, 2], [0, 2, 3]]), 4)
    >>> vertex_sectors(level, level.boundary_edge).ring_index()[1].tolist()[:3]
    [0, 1, 2]
    """
    crease_he = np.ascontiguousarray(crease[level.edge_of])
    return Sectors(*SK.vertex_sectors(level.faces, level.twin, level.by_origin, level.origin_start, crease_he))
