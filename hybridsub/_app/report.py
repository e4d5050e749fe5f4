"""What a mesh is made of, and what subdividing it will produce — from counts alone.

``mesh_report`` describes a mesh without assuming it is valid (it is what ``hybridsub info``
prints, so it must survive non-manifold edges and bad orientation). ``predict_levels`` gives
the exact face, vertex and edge counts of every level from the classes of SCHEME.md, without
refining anything, and a memory estimate from those counts.

Counting rules (exact for any valid input; ``tests/test_cli.py`` checks them against ``refine``):
- every edge lies in one or two faces, so ``E = (3F + B) / 2`` at every level (B: boundary
  edges), and the Euler characteristic ``V − E + F`` never changes; hence ``V`` follows from
  ``F`` and ``B``;
- ``"loop"``: ``F ← 4F``, ``B ← 2B``;
- ``"sqrt3"``: ``F ← 3F``; ``B`` is unchanged in odd steps and trisected (``B ← 3B``) in even ones;
- ``"hybrid"``: a sharp face makes 4 sharp faces, a smooth face ``3 + s`` smooth faces (``s``
  split edges). A split halfedge of a smooth face has two split children in two smooth faces
  while its edge stays split: for ever on a boundary or next to a sharp face, ``⌈σ⌉`` levels
  for a crease of sharpness ``σ`` between smooth faces. So with ``Fs, Fh`` smooth and sharp
  faces and ``σ_h`` the sharpness of each split halfedge of a smooth face at level 0,
  ``H_k = Σ_h 2^k [σ_h > k]``, ``Fs ← 3Fs + H_k``, ``Fh ← 4Fh``, ``B ← 2B``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .._rules import refinement as R

#: Bytes per face of one step's topology tables and classification (halfedge twins, edge
#: numbering, vertex→edge incidence, step plan). Measured as the peak RSS of
#: ``refine(F, levels=1)`` + ``apply`` minus everything else ``predict_levels`` counts:
#: 175–210 bytes per face on armadillo (L1, L2 inputs; hybrid, loop, sqrt3) and fandisk L3.
TOPOLOGY_BYTES_PER_FACE = 200


def _edges(F: np.ndarray, n: int):
    """Undirected edges of the halfedges of F: (pairs (E, 2), edge of each halfedge (3m,),
    halfedge count per edge (E,))."""
    u = F.ravel()
    w = F[:, [1, 2, 0]].ravel()
    lo, hi = np.minimum(u, w), np.maximum(u, w)
    key = lo.astype(np.int64) * max(n, 1) + hi
    uniq, first, inv, cnt = np.unique(key, return_index=True, return_inverse=True, return_counts=True)
    pairs = np.stack([lo[first], hi[first]], axis=1)
    return pairs, inv.ravel(), cnt


def mesh_report(V: np.ndarray, F: np.ndarray) -> dict:
    """Counts and checks of a triangle mesh that may be invalid (non-manifold, misoriented).

    Returns a dict: vertices, faces, edges, unreferenced_vertices, boundary_edges,
    boundary_loops, nonmanifold_edges (first few vertex pairs) and their count,
    misoriented_edges (count, first pair), nonmanifold_vertices (count, first few),
    degenerate_faces (repeated vertex), zero_area_faces, components, euler, genus (total, of an
    orientable manifold; else None), valence histogram {valence: count}, bbox (2, 3).
    """
    n, m = len(V), len(F)
    pairs, eid, cnt = _edges(F, n)
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


def predict_levels(F: np.ndarray, n_vertices: int, levels: int, *, scheme: str = "hybrid", sharp_edges=None,
                   sharpness=None, sharp_faces=None, attributes: int = 3) -> list[dict]:
    """Exact counts of every level of ``subdivide``, and a memory estimate, from level 0 alone.

    Parameters
    ----------
    F : (m, 3) int64
        A valid mesh's faces (every edge in one or two faces).
    n_vertices, levels, scheme, sharp_edges, sharpness, sharp_faces
        As for ``refine``; ``sharp_faces`` as a boolean mask or indices.
    attributes : int
        Floats per vertex being refined (3 for positions, more with colours or UVs).

    Returns
    -------
    list of dict, one per level 1..levels
        ``faces``, ``vertices``, ``edges``, ``boundary_edges``, ``nnz`` (an upper bound of the
        step matrix's non-zeros), ``output_bytes`` (positions and faces, float64/int64) and
        ``peak_bytes`` (estimated peak working memory of that step, as ``hybridsub subdivide``
        runs it: the previous level, the step's tables and matrix, and the new level).
    """
    F = np.asarray(F, dtype=np.int64)
    m0 = len(F)
    pairs, eid, cnt = _edges(F, n_vertices)
    E = len(pairs)
    B = int((cnt == 1).sum())
    Fh = Fs = 0
    H = np.empty(0)
    if scheme == "loop":
        Fh = m0
    elif scheme == "hybrid":
        sharp = np.zeros(m0, bool)
        if sharp_faces is not None:
            sf = np.asarray(sharp_faces)
            if sf.dtype == bool:
                sharp |= sf
            else:
                sharp[sf.astype(np.int64)] = True
        Fh, Fs = int(sharp.sum()), int((~sharp).sum())
        es = np.zeros(E)
        if sharp_edges is not None and len(sharp_edges):
            se = np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2)
            s = (np.full(len(se), np.inf) if sharpness is None
                 else R.normalize_sharpness(np.asarray(sharpness, dtype=np.float64)))
            key = se.min(axis=1) * max(n_vertices, 1) + se.max(axis=1)
            ekey = pairs[:, 0] * max(n_vertices, 1) + pairs[:, 1]
            pos = np.searchsorted(ekey, key)
            ok = (pos < E) & (ekey[np.minimum(pos, E - 1)] == key)
            np.maximum.at(es, pos[ok], s[ok])
        es[cnt == 1] = np.inf
        # for each halfedge, is the other face on its edge sharp?
        order = np.argsort(eid, kind="stable")
        other_sharp = np.zeros(3 * m0, bool)
        two = cnt[eid[order]] == 2
        h1, h2 = order[two][0::2], order[two][1::2]
        other_sharp[h1] = sharp[h2 // 3]
        other_sharp[h2] = sharp[h1 // 3]
        hs = np.where(other_sharp, np.inf, es[eid])
        H = hs[~np.repeat(sharp, 3) & (hs > 0)]
    out = []
    n, m = n_vertices, m0
    for k in range(levels):
        step = k + 1
        if scheme == "loop":
            m2, B2, face_points = 4 * m, 2 * B, 0
        elif scheme == "sqrt3":
            odd = step % 2 == 1
            m2, B2 = 3 * m, (B if odd else 3 * B)
            face_points = m if odd else m - B
        else:
            Hk = int(np.sum(np.where(H > k, 2.0 ** k, 0.0)))
            Fs2, Fh2 = 3 * Fs + Hk, 4 * Fh
            m2, B2, face_points = Fs2 + Fh2, 2 * B, Fs
            Fs, Fh = Fs2, Fh2
        E2 = (3 * m2 + B2) // 2
        n2 = n + (E2 - E) - (m2 - m)
        split_points = n2 - n - face_points
        nnz = n + 2 * E + 4 * split_points + 3 * face_points
        out_bytes = 8 * attributes * n2 + 24 * m2
        peak = (8 * attributes * n + 24 * m  # the level being refined
                + TOPOLOGY_BYTES_PER_FACE * m  # its tables and the step plan
                + 12 * nnz + 8 * (n2 + 1)  # the step matrix (CSR)
                + out_bytes + 8 * m2)  # the new level and its face parents
        out.append({"level": step, "faces": int(m2), "vertices": int(n2), "edges": int(E2),
                    "boundary_edges": int(B2), "nnz": int(nnz), "output_bytes": int(out_bytes),
                    "peak_bytes": int(peak)})
        n, m, E, B = n2, m2, E2, B2
    return out
