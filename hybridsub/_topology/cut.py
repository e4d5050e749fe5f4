"""``non_manifold="cut"``: cut a mesh along the edges no subdivision rule is defined for.

An edge is *cut* when it is not a proper edge of a surface: three or more faces share it
(non-manifold), or its two faces run along it in the same direction (inconsistent
orientation, as along the seam of a Möbius strip). Around each vertex of a cut edge the faces
fall into *sectors*: faces joined through proper edges at that vertex. Every sector gets its own
copy of the vertex, so the cut edges become boundary edges of the pieces they separate and the
cut mesh is a valid input. Nothing else changes: faces keep their order, vertices their index
(the first sector of a vertex keeps it, further copies are appended).

Boundary edges are infinitely sharp creases in ``"hybrid"`` and ``"loop"``, so every copy of a
cut edge gets the same edge points. To make the copies of a vertex move alike, the vertices of
cut edges become corners (they stay where they are), as OpenSubdiv sharpens non-manifold
vertices — except a vertex on exactly two cut edges whose every copy has just those two as
creases: it keeps the crease rule, the same for every copy, and the cut curve stays smooth.
The copies then coincide at every level and the pieces stay joined along the cut.
``"sqrt3"`` takes no tags: each piece follows Kobbelt's boundary rule on its own and the pieces
separate slightly near the ends of a cut.

The input gate cuts (:func:`hybridsub._input.gate.open_gate`) and the refiner composes the
first step's matrix with the duplication (``S_1 @ D``, ``D[c, v] = 1`` when ``c`` is a copy
of ``v``), so ``Refinement.matrix`` and ``apply`` take the caller's vertices.

>>> import numpy as np
>>> F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])      # edge 0-1 in three faces
>>> cut = cut_non_manifold(F, 5)
>>> cut.n_vertices, cut.cut_edges.tolist()
(9, [[0, 1]])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .edges import edge_keys, group_halfedges, halfedge_ends, next_halfedge
from .errors import not_an_edge_error


@dataclass(frozen=True, eq=False)
class Cut:
    """A mesh cut along its improper edges."""

    faces: np.ndarray  # (m, 3) int64, faces of the cut mesh (same order as the input)
    origin: np.ndarray  # (n',) input vertex of each vertex of the cut mesh; origin[:n] == arange(n)
    cut_edges: np.ndarray  # (c, 2) input vertex pairs (sorted) of the edges that were cut
    corner: np.ndarray  # (n',) bool: copies made corners so that they move alike
    halfedge_cut: np.ndarray  # (3m,) bool: input halfedges on a cut edge

    @property
    def n_vertices(self) -> int:
        return self.origin.shape[0]


def cut_non_manifold(F: np.ndarray, n: int, crease_vertices: np.ndarray | None = None) -> Cut | None:
    """Cut ``F`` (checked (m, 3) int64, no repeated vertex, no duplicate face) along its
    non-manifold and inconsistently oriented edges; ``None`` if there are none.

    ``crease_vertices`` (n,) bool marks vertices on tagged creases: such a vertex on a cut
    becomes a corner (its copies could otherwise take different crease rules).
    """
    m = F.shape[0]
    if m == 0:
        return None
    u, w = halfedge_ends(F)
    groups = group_halfedges(u, w)
    sizes, group = groups.sizes, groups.group
    a, b = groups.first, groups.second
    proper = (sizes == 2) & (u[a] == w[b])  # two faces, opposite directions
    bad_group = (sizes >= 3) | ((sizes == 2) & ~proper)
    if not bad_group.any():
        return None
    he_cut = bad_group[group]

    # Sectors: corners (3f + i, the corner at vertex F[f, i]) joined through proper edges.
    # Halfedge h = u→w (face f) and its twin t = w→u (face g): u's corners are h and next(t),
    # w's corners are next(h) and t.
    import scipy.sparse as sp  # here: SciPy's graph module costs a third of a small run's start-up
    from scipy.sparse.csgraph import connected_components

    h, t = a[proper], b[proper]
    links_a = np.concatenate([h, next_halfedge(h)])
    links_b = np.concatenate([next_halfedge(t), t])
    nh = 3 * m
    graph = sp.coo_matrix((np.ones(len(links_a), np.int8), (links_a, links_b)), shape=(nh, nh))
    _, label = connected_components(graph, directed=False)
    sector_first = np.full(label.max() + 1, nh, np.int64)
    np.minimum.at(sector_first, label, np.arange(nh))

    # Vertices on a cut edge get one copy per sector; the others keep their index (bow-ties too).
    on_cut = np.zeros(n, dtype=bool)
    on_cut[u[he_cut]] = True
    on_cut[w[he_cut]] = True
    corners_cut = np.flatnonzero(on_cut[u])
    key_v = u[corners_cut]
    key_s = sector_first[label[corners_cut]]
    o = np.lexsort((key_s, key_v))
    kv, ks = key_v[o], key_s[o]
    first_of_pair = np.ones(len(o), dtype=bool)
    first_of_pair[1:] = (kv[1:] != kv[:-1]) | (ks[1:] != ks[:-1])
    first_of_vertex = np.ones(len(o), dtype=bool)
    first_of_vertex[1:] = kv[1:] != kv[:-1]
    extra = first_of_pair & ~first_of_vertex  # sectors after a vertex's first: new copies
    copy_index = np.where(first_of_vertex, kv, n + np.cumsum(extra) - 1)
    # every corner of a pair takes the index of the pair's first corner
    pair_id = np.cumsum(first_of_pair) - 1
    pair_index = copy_index[first_of_pair]
    new_v = u.copy()
    new_v[corners_cut[o]] = pair_index[pair_id]
    origin = np.concatenate([np.arange(n, dtype=np.int64), kv[extra]])
    Fc = new_v.reshape(m, 3)

    corner = _sharpen(Fc, u, w, a, group, he_cut, bad_group, on_cut, origin, n, crease_vertices)
    lo, hi = np.minimum(u[a[bad_group]], w[a[bad_group]]), np.maximum(u[a[bad_group]], w[a[bad_group]])
    return Cut(np.ascontiguousarray(Fc), origin, np.stack([lo, hi], axis=1), corner, he_cut)


def _sharpen(Fc, u, w, first_he, group, he_cut, bad_group, on_cut, origin, n, crease_vertices):
    """Corner mask of the cut mesh: copies of cut vertices that must not move (see module doc).

    ``first_he`` is the lowest halfedge of each edge group of the input.
    """
    n_cut = origin.shape[0]
    # number of distinct cut edges at each input vertex
    bad_he = first_he[bad_group]
    n_bad = np.bincount(np.concatenate([u[bad_he], w[bad_he]]), minlength=n)

    # boundary edges of the cut mesh, at each copy: how many, and how many are cut edges
    cu, cw = halfedge_ends(Fc)
    cut_groups = group_halfedges(cu, cw)
    sizes_c, group_c = cut_groups.sizes, cut_groups.group
    boundary_he = sizes_c[group_c] == 1
    ends = np.concatenate([cu[boundary_he], cw[boundary_he]])
    n_boundary = np.bincount(ends, minlength=n_cut)
    cut_b = boundary_he & he_cut
    # distinct input cut edges among a copy's boundary edges
    pairs = np.stack([np.concatenate([cu[cut_b], cw[cut_b]]),
                      np.concatenate([group[cut_b], group[cut_b]])], axis=1)
    pairs = np.unique(pairs, axis=0) if len(pairs) else pairs.reshape(0, 2)
    n_cut_edges = np.bincount(pairs[:, 0], minlength=n_cut) if len(pairs) else np.zeros(n_cut, np.int64)
    copy_ok = (n_boundary == 2) & (n_cut_edges == 2)

    keep_crease = on_cut & (n_bad == 2)
    if crease_vertices is not None:
        keep_crease &= ~crease_vertices
    all_ok = np.ones(n, dtype=bool)
    np.logical_and.at(all_ok, origin, copy_ok)
    sharpen = on_cut & ~(keep_crease & all_ok)
    return sharpen[origin]


def map_sharp_edges(cut: Cut, F: np.ndarray, pairs: np.ndarray, sharp: np.ndarray, n: int):
    """Tags given on the input's vertex pairs, as pairs of the cut mesh (every copy of an edge).

    Raises MeshError naming the first pair that is not an edge of the input.
    """
    if len(pairs) == 0:
        return pairs.copy(), sharp.copy()
    u, w = halfedge_ends(F)
    he_key = edge_keys(u, w, n)
    tag_key = edge_keys(pairs[:, 0], pairs[:, 1], n)
    missing = ~np.isin(tag_key, he_key) | (pairs[:, 0] == pairs[:, 1])
    if missing.any():
        raise not_an_edge_error(pairs, np.flatnonzero(missing))
    # the sharpness of each halfedge's edge: the largest given for it
    uk, inv = np.unique(tag_key, return_inverse=True)
    s_key = np.zeros(len(uk))
    np.maximum.at(s_key, inv, sharp)
    pos = np.searchsorted(uk, he_key)
    pos = np.minimum(pos, len(uk) - 1)
    hit = uk[pos] == he_key
    cu, cw = halfedge_ends(cut.faces)
    return (np.ascontiguousarray(np.stack([cu[hit], cw[hit]], axis=1), dtype=np.int64),
            s_key[pos[hit]])
