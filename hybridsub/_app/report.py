"""What a mesh is made of: ``mesh_report``, the counts and defects ``hybridsub info`` prints.

It describes a mesh without assuming it is valid, so it must survive non-manifold edges and
bad orientation. What subdividing will produce comes from the refiner
(:func:`hybridsub._refiner.predict_levels`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .._topology import undirected_edges


def mesh_report(V: np.ndarray, F: np.ndarray) -> dict:
    """Counts and checks of a triangle mesh that may be invalid (non-manifold, misoriented).

    Returns a dict: vertices, faces, edges, unreferenced_vertices, boundary_edges,
    boundary_loops, nonmanifold_edges (first few vertex pairs) and their count,
    misoriented_edges (count, first pair), nonmanifold_vertices (count, first few),
    degenerate_faces (repeated vertex), zero_area_faces, components, euler, genus (total, of an
    orientable manifold; else None), valence histogram {valence: count}, bbox (2, 3).
    """
    n, m = len(V), len(F)
    pairs, eid, cnt = undirected_edges(F, n)
    ne = len(pairs)
    used = np.zeros(n, bool)
    used[F.ravel()] = True
    u = F.ravel()
    w = F[:, [1, 2, 0]].ravel()
    # misoriented: an edge in two faces that run along it in the same direction
    order = np.argsort(eid, kind="stable")
    e_sorted = eid[order]
    two = cnt[e_sorted] == 2
    h1 = order[two][0::2]
    h2 = order[two][1::2]
    mis = u[h1] == u[h2]
    rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    T = V[F]
    area2 = np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1)
    # faces connected through edges
    rows = np.repeat(np.arange(m), 3)
    A = sp.csr_matrix((np.ones(3 * m), (rows, eid)), shape=(m, ne))
    ncomp = connected_components(A @ A.T, directed=False)[0] if m else 0
    # boundary loops: components of the graph of boundary edges
    bnd = pairs[cnt == 1]
    if len(bnd):
        G = sp.coo_matrix((np.ones(len(bnd)), (bnd[:, 0], bnd[:, 1])), shape=(n, n))
        labels = connected_components(G, directed=False)[1]
        loops = len(np.unique(labels[np.unique(bnd)]))
    else:
        loops = 0
    # vertex fans: face corners joined across two-face edges; a vertex with corners in more
    # than one group is non-manifold (a bow-tie)
    c1 = np.concatenate([h1, (h1 // 3) * 3 + (h1 + 1) % 3])
    same = u[h1] == u[h2]
    c2 = np.concatenate([np.where(same, h2, (h2 // 3) * 3 + (h2 + 1) % 3),
                         np.where(same, (h2 // 3) * 3 + (h2 + 1) % 3, h2)])
    C = sp.coo_matrix((np.ones(len(c1)), (c1, c2)), shape=(3 * m, 3 * m))
    lab = connected_components(C, directed=False)[1] if m else np.empty(0, np.int64)
    fan_keys = np.unique(u.astype(np.int64) * max(3 * m, 1) + lab)
    fans = np.bincount(fan_keys // max(3 * m, 1), minlength=n)
    nm_vertices = np.flatnonzero(fans > 1)
    valence = np.bincount(pairs.ravel(), minlength=n)[used]
    hist = dict(zip(*[a.tolist() for a in np.unique(valence, return_counts=True)]))
    n_used = int(used.sum())
    euler = n_used - ne + m
    manifold = not (cnt > 2).any() and len(nm_vertices) == 0
    # orientable manifold surface: χ = Σ (2 − 2g_i − b_i) over components
    g2 = 2 * ncomp - euler - loops
    genus = g2 // 2 if manifold and not mis.any() and g2 >= 0 and g2 % 2 == 0 else None
    return {
        "vertices": n, "faces": m, "edges": ne,
        "unreferenced_vertices": n - n_used,
        "boundary_edges": int((cnt == 1).sum()), "boundary_loops": loops,
        "nonmanifold_edges": int((cnt > 2).sum()), "nonmanifold_edge_examples": pairs[cnt > 2][:3].tolist(),
        "misoriented_edges": int(mis.sum()),
        "misoriented_edge_examples": np.stack([u[h1][mis], w[h1][mis]], axis=1)[:3].tolist(),
        "nonmanifold_vertices": len(nm_vertices), "nonmanifold_vertex_examples": nm_vertices[:5].tolist(),
        "degenerate_faces": int(rep.sum()), "zero_area_faces": int(((area2 == 0) & ~rep).sum()),
        "components": int(ncomp), "euler": int(euler), "genus": genus,
        "valence": hist,
        "bbox": np.array([V[used].min(axis=0), V[used].max(axis=0)]) if n_used else np.zeros((2, 3)),
    }
