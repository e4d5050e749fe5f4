"""Halfedges and undirected edges of a face array, without a Level.

Halfedge ``h = 3 f + i`` of face ``f`` runs ``F[f, i] → F[f, (i+1) % 3]``. These helpers work
on any (m, 3) integer array, valid mesh or not (duplicate faces, edges in three or more
faces, inconsistent orientation), which is what input checks, the non-manifold cut and
reports need before a :class:`~hybridsub._topology.level.Level` can exist.

>>> import numpy as np
>>> F = np.array([[0, 1, 2], [0, 2, 3]])
>>> E = undirected_edges(F, 4)
>>> E.pairs.tolist(), E.count.tolist()
([[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]], [1, 2, 1, 1, 1])
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


def next_halfedge(h):
    """The next halfedge of the same face (``3f + i`` → ``3f + (i+1) % 3``); arrays or ints."""
    return h - h % 3 + (h % 3 + 1) % 3


def prev_halfedge(h):
    """The previous halfedge of the same face (``3f + i`` → ``3f + (i+2) % 3``); arrays or ints."""
    return h - h % 3 + (h % 3 + 2) % 3


def halfedge_ends(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(origin, destination) vertex of every halfedge, each (3m,)."""
    return F.ravel(), F[:, [1, 2, 0]].ravel()


def edge_keys(u: np.ndarray, w: np.ndarray, n: int) -> np.ndarray:
    """One int64 key per undirected vertex pair ``(u, w)`` of a mesh with ``n`` vertices."""
    u = np.asarray(u, dtype=np.int64)
    w = np.asarray(w, dtype=np.int64)
    return np.minimum(u, w) * np.int64(max(n, 1)) + np.maximum(u, w)


class EdgeGroups(NamedTuple):
    """Halfedges grouped by undirected edge (see :func:`group_halfedges`)."""

    order: np.ndarray  # (H,) halfedges sorted by edge, ties in halfedge order
    starts: np.ndarray  # (E,) where each group starts in ``order``
    sizes: np.ndarray  # (E,) halfedges in each group
    group: np.ndarray  # (H,) group of each halfedge

    @property
    def first(self) -> np.ndarray:
        """(E,) lowest-numbered halfedge of each group."""
        return self.order[self.starts]

    @property
    def second(self) -> np.ndarray:
        """(E,) second-lowest halfedge of each group (the first again where it is alone)."""
        return self.order[np.minimum(self.starts + 1, len(self.order) - 1)]


def group_halfedges(u: np.ndarray, w: np.ndarray) -> EdgeGroups:
    """Group halfedges ``u[h] → w[h]`` by undirected edge, groups in (min, max) vertex order."""
    lo, hi = np.minimum(u, w), np.maximum(u, w)
    order = np.lexsort((hi, lo))
    ls, hs = lo[order], hi[order]
    new = np.ones(len(order), dtype=bool)
    new[1:] = (ls[1:] != ls[:-1]) | (hs[1:] != hs[:-1])
    starts = np.flatnonzero(new)
    sizes = np.diff(np.append(starts, len(order)))
    group = np.empty(len(order), np.int64)
    group[order] = np.cumsum(new) - 1
    return EdgeGroups(order, starts, sizes, group)


class UndirectedEdges(NamedTuple):
    """The undirected edges of a face array (see :func:`undirected_edges`)."""

    pairs: np.ndarray  # (E, 2) int64, (min, max) vertex, sorted
    of_halfedge: np.ndarray  # (3m,) edge of each halfedge
    count: np.ndarray  # (E,) halfedges on each edge


def undirected_edges(F: np.ndarray, n: int) -> UndirectedEdges:
    """Undirected edges of the halfedges of ``F`` ((m, 3) int, ``n`` vertices), sorted."""
    u, w = halfedge_ends(F)
    g = group_halfedges(u, w)
    first = g.first
    pairs = np.stack([np.minimum(u[first], w[first]), np.maximum(u[first], w[first])], axis=1).astype(np.int64)
    return UndirectedEdges(pairs, g.group, g.sizes)
