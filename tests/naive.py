"""Slow, obvious reference implementation of one hybridsub refinement step.

This module is an independent re-reading of ``docs/scheme.md`` (and the shared
``SCHEME.md``), written for clarity, not speed: Python dicts keyed by sorted vertex
pairs, plain loops over faces, edges and vertices, one ``dict`` per row of the
refinement matrix.  The test-suite compares the fast (Numba) path against it on
random meshes, so it must follow the documented index layout, edge numbering,
face emission order and triangle rotation exactly.  It imports nothing from
``hybridsub``.

Meshes in the tests have at most a few thousand faces; that is all this is for.
"""

from math import cos, pi, inf

import numpy as np
import scipy.sparse as sp

__all__ = ["naive_step", "naive_refine"]

SCHEMES = ("hybrid", "loop", "sqrt3")


# ---------------------------------------------------------------------------
# Scalar rules (weights), straight from the docs
# ---------------------------------------------------------------------------

def kobbelt_alpha(n):
    """sqrt(3) region (R3): weight of the neighbour average."""
    return (4.0 - 2.0 * cos(2.0 * pi / n)) / 9.0


def loop_beta(n, loop_weights):
    """Loop region: per-neighbour weight."""
    if loop_weights == "loop":
        return (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * cos(2.0 * pi / n)) ** 2) / n
    if loop_weights == "warren":
        return 3.0 / 16.0 if n == 3 else 3.0 / (8.0 * n)
    raise ValueError(f"loop_weights must be 'loop' or 'warren', got {loop_weights!r}")


def mixed_alpha(n):
    """Mixed vertex (paper's R3 table): weight of the neighbour average."""
    if n <= 3:
        return 9.0 / 16.0
    if n <= 5:
        return 3.0 / 8.0
    return kobbelt_alpha(n)


def _add(row, weights, factor=1.0):
    """row += factor * weights (both dicts column -> weight)."""
    for j, x in weights.items():
        row[j] = row.get(j, 0.0) + factor * x


# ---------------------------------------------------------------------------
# Input normalisation
# ---------------------------------------------------------------------------

def _normalise_sharpness(value):
    """None -> inf; >= 10 -> inf; otherwise the float (may be <= 0: no crease)."""
    if value is None:
        return inf
    value = float(value)
    if value >= 10.0:
        return inf
    return value


def _face_mask(sharp_faces, m):
    if sharp_faces is None:
        return [False] * m
    arr = np.asarray(sharp_faces)
    if arr.dtype == bool:
        if arr.shape != (m,):
            raise ValueError(f"sharp_faces mask must have shape ({m},), got {arr.shape}")
        return [bool(x) for x in arr]
    mask = [False] * m
    for f in arr.reshape(-1):
        mask[int(f)] = True
    return mask


# ---------------------------------------------------------------------------
# One step
# ---------------------------------------------------------------------------

def naive_step(F, n_vertices, *, scheme="hybrid", step=1, sharp_edges=None, sharpness=None,
               sharp_faces=None, corners=None, loop_weights="loop"):
    """One step. F (m,3) int; sharp_edges (k,2) any orientation (may contain duplicates);
    sharpness (k,) float or None (= inf; >= 10 means inf; <= 0 means not a crease);
    sharp_faces: bool mask (m,) or None; corners: int indices or None;
    step: 1-based step number within the call (matters only for scheme="sqrt3": odd/even Kobbelt boundary).
    Returns dict with keys:
      'S'          : scipy.sparse.csr_matrix (n_new, n_vertices), float64
      'faces'      : (m_new,3) int64, in the documented emission order and rotation
      'sharp_edges': (k',2) int64 tagged creases of the child level (boundary edges NOT listed),
                     children (u,m),(m,w) in the parent edge's owner orientation, parent edges in edge order
      'sharpness'  : (k',) float64 (inf for infinite)
      'sharp_faces': (m_new,) bool
      'corners'    : sorted unique int64 array (tagged corners only, same indices)
      'face_parent': (m_new,) int64 index of the emitting face in F
    """
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    F_list = [tuple(int(x) for x in row) for row in F]
    m = len(F_list)
    n = int(n_vertices)
    for face in F_list:
        for x in face:
            if not 0 <= x < n:
                raise ValueError(f"face index {x} out of range for {n} vertices")

    if scheme == "sqrt3":
        if sharp_edges is not None and len(np.asarray(sharp_edges).reshape(-1)) > 0:
            raise ValueError("scheme='sqrt3' takes no tags; use 'hybrid'")
        if corners is not None and len(np.asarray(corners).reshape(-1)) > 0:
            raise ValueError("scheme='sqrt3' takes no tags; use 'hybrid'")
        if sharp_faces is not None and any(_face_mask(sharp_faces, m)):
            raise ValueError("scheme='sqrt3' takes no tags; use 'hybrid'")
    kobbelt_even = scheme == "sqrt3" and step % 2 == 0

    # ---- halfedges: 3f+0 = a->b, 3f+1 = b->c, 3f+2 = c->a -------------------
    def origin(h):
        return F_list[h // 3][h % 3]

    def dest(h):
        return F_list[h // 3][(h % 3 + 1) % 3]

    def opposite(h):
        """The face's third vertex, opposite halfedge h."""
        return F_list[h // 3][(h % 3 + 2) % 3]

    def next_he(h):
        return 3 * (h // 3) + (h % 3 + 1) % 3

    def prev_he(h):
        return 3 * (h // 3) + (h % 3 + 2) % 3

    # ---- edges, numbered by first appearance; owner = lowest halfedge ---------
    edge_id = {}        # sorted pair -> edge index
    edge_uw = []        # owner orientation (u, w)
    edge_hes = []       # halfedges of the edge, ascending
    he_edge = [0] * (3 * m)
    for h in range(3 * m):
        u, w = origin(h), dest(h)
        key = (min(u, w), max(u, w))
        if key not in edge_id:
            edge_id[key] = len(edge_uw)
            edge_uw.append((u, w))
            edge_hes.append([h])
        else:
            edge_hes[edge_id[key]].append(h)
        he_edge[h] = edge_id[key]
    n_edges = len(edge_uw)
    for e in range(n_edges):
        if len(edge_hes[e]) > 2:
            raise ValueError(f"edge {edge_uw[e]} is in more than two faces")
    twin = [-1] * (3 * m)
    for hs in edge_hes:
        if len(hs) == 2:
            twin[hs[0]], twin[hs[1]] = hs[1], hs[0]
    is_boundary = [len(hs) == 1 for hs in edge_hes]

    # ---- tags ---------------------------------------------------------------
    tag_s = {}  # edge -> sharpness (> 0) of tagged edges
    if sharp_edges is not None:
        se = np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2)
        if sharpness is None:
            svals = [None] * len(se)
        else:
            svals = list(np.asarray(sharpness, dtype=np.float64).reshape(-1))
            if len(svals) != len(se):
                raise ValueError("sharpness must have one value per sharp edge")
        for (p, q), s in zip(se, svals):
            key = (min(int(p), int(q)), max(int(p), int(q)))
            if key not in edge_id:
                raise ValueError(f"sharp edge {key} is not an edge of the mesh")
            s = _normalise_sharpness(s)
            if s <= 0:
                continue
            e = edge_id[key]
            tag_s[e] = max(tag_s.get(e, 0.0), s)   # duplicates: the largest sharpness wins

    corner_set = set()
    if corners is not None:
        corner_set = {int(c) for c in np.asarray(corners).reshape(-1)}

    if scheme == "loop":
        face_sharp = [True] * m
    elif scheme == "sqrt3":
        face_sharp = [False] * m
    else:
        face_sharp = _face_mask(sharp_faces, m)

    # edge sharpness this level: boundary = inf (hybrid, loop), tags, else 0
    edge_s = [0.0] * n_edges
    for e in range(n_edges):
        if is_boundary[e] and scheme != "sqrt3":
            edge_s[e] = inf
        elif e in tag_s:
            edge_s[e] = tag_s[e]

    # ---- edge classes and new point indices ----------------------------------
    is_crease = [edge_s[e] > 0 for e in range(n_edges)]
    is_split = [is_crease[e] or any(face_sharp[h // 3] for h in edge_hes[e])
                for e in range(n_edges)]
    is_trisected = [kobbelt_even and is_boundary[e] for e in range(n_edges)]

    next_index = n
    edge_point = {}     # edge -> index of its edge point (split edges)
    edge_e1e2 = {}      # edge -> (e1, e2) (Kobbelt even steps, boundary edges)
    for e in range(n_edges):
        if is_split[e]:
            edge_point[e] = next_index
            next_index += 1
        elif is_trisected[e]:
            edge_e1e2[e] = (next_index, next_index + 1)
            next_index += 2

    face_has_boundary = [any(is_boundary[he_edge[3 * f + i]] for i in range(3)) for f in range(m)]
    face_point = {}
    for f in range(m):
        if face_sharp[f]:
            continue
        if kobbelt_even and face_has_boundary[f]:
            continue
        face_point[f] = next_index
        next_index += 1
    n_new = next_index

    if kobbelt_even:
        for f in range(m):
            nb = sum(is_boundary[he_edge[3 * f + i]] for i in range(3))
            if nb > 1:
                raise ValueError(
                    f"face {f} has {nb} boundary edges in an even Kobbelt step "
                    "(cannot happen after an odd step)")

    # ---- vertex neighbourhoods ------------------------------------------------
    nbrs = [set() for _ in range(n)]
    vert_edges = [[] for _ in range(n)]
    vert_faces = [[] for _ in range(n)]
    for e, (u, w) in enumerate(edge_uw):
        nbrs[u].add(w)
        nbrs[w].add(u)
        vert_edges[u].append(e)
        vert_edges[w].append(e)
    for f, face in enumerate(F_list):
        for v in set(face):
            vert_faces[v].append(f)

    def other_end(e, v):
        u, w = edge_uw[e]
        return w if u == v else u

    def smooth_mask(v):
        """Smooth mask of v in its region (sqrt3 / Loop / mixed)."""
        k = len(nbrs[v])
        sharp = [face_sharp[f] for f in vert_faces[v]]
        row = {}
        if not any(sharp):
            alpha = kobbelt_alpha(k)
            row[v] = 1.0 - alpha
            for p in nbrs[v]:
                row[p] = row.get(p, 0.0) + alpha / k
        elif all(sharp):
            beta = loop_beta(k, loop_weights)
            row[v] = 1.0 - k * beta
            for p in nbrs[v]:
                row[p] = row.get(p, 0.0) + beta
        else:
            alpha = mixed_alpha(k)
            row[v] = 1.0 - alpha
            for p in nbrs[v]:
                row[p] = row.get(p, 0.0) + alpha / k
        return row

    def crease_mask(v, es):
        row = {v: 0.75}
        for e in es:
            p = other_end(e, v)
            row[p] = row.get(p, 0.0) + 0.125
        return row

    # p_{i-1} / p_{i+2} of a boundary halfedge h = p_i -> p_{i+1}, turning through the fan
    def boundary_prev_vertex(h):
        """Origin of the boundary halfedge ending at origin(h), turning around origin(h)."""
        k = prev_he(h)
        for _ in range(3 * m + 1):
            if twin[k] == -1:
                return origin(k)
            k = prev_he(twin[k])
        raise RuntimeError("turning around a vertex did not reach the boundary")

    def boundary_next_vertex(h):
        """End of the boundary halfedge starting at dest(h), turning around dest(h)."""
        k = next_he(h)
        for _ in range(3 * m + 1):
            if twin[k] == -1:
                return dest(k)
            k = next_he(twin[k])
        raise RuntimeError("turning around a vertex did not reach the boundary")

    rows = [None] * n_new

    # ---- vertex points ------------------------------------------------------
    for v in range(n):
        if not vert_faces[v]:
            rows[v] = {v: 1.0}          # unreferenced vertex: never moves
            continue
        if scheme == "sqrt3":
            b_edges = [e for e in vert_edges[v] if is_boundary[e]]
            if not b_edges:
                rows[v] = smooth_mask(v)
            elif not kobbelt_even or len(b_edges) != 2:
                rows[v] = {v: 1.0}      # odd step, or non-manifold boundary vertex
            else:
                row = {v: 19.0 / 27.0}
                for e in b_edges:
                    p = other_end(e, v)
                    row[p] = row.get(p, 0.0) + 4.0 / 27.0
                rows[v] = row
            continue
        # hybrid / loop: parent rule (s > 0) and child rule (s > 1)
        parent_edges = [e for e in vert_edges[v] if edge_s[e] > 0]
        child_edges = [e for e in vert_edges[v] if edge_s[e] > 1]

        def rule(count):
            if v in corner_set or count >= 3:
                return "corner"
            if count == 2:
                return "crease"
            return "smooth"

        prule, crule = rule(len(parent_edges)), rule(len(child_edges))
        if prule == "smooth":
            rows[v] = smooth_mask(v)
            continue
        pmask = {v: 1.0} if prule == "corner" else crease_mask(v, parent_edges)
        if crule == prule:
            rows[v] = pmask
            continue
        if crule == "crease":
            cmask = crease_mask(v, child_edges)
        elif crule == "smooth":
            cmask = smooth_mask(v)
        else:  # child corner with a non-corner parent: impossible (child edges ⊆ parent edges)
            cmask = {v: 1.0}
        trans = [edge_s[e] for e in vert_edges[v] if 0 < edge_s[e] <= 1]
        wgt = min(1.0, sum(trans) / len(trans)) if trans else 0.0
        row = {}
        _add(row, pmask, wgt)
        _add(row, cmask, 1.0 - wgt)
        rows[v] = row

    # ---- edge points --------------------------------------------------------
    for e in range(n_edges):
        u, w = edge_uw[e]
        if e in edge_point:
            s = edge_s[e]
            mid = {}
            _add(mid, {u: 0.5})
            _add(mid, {w: 0.5})
            if s >= 1:
                row = mid
            else:
                hs = edge_hes[e]
                if len(hs) != 2:
                    raise RuntimeError("smooth edge point on a boundary edge")
                r4 = {}
                _add(r4, {u: 3.0 / 8.0})
                _add(r4, {w: 3.0 / 8.0})
                _add(r4, {opposite(hs[0]): 1.0 / 8.0})
                _add(r4, {opposite(hs[1]): 1.0 / 8.0})
                if s > 0:
                    row = {}
                    _add(row, mid, s)
                    _add(row, r4, 1.0 - s)
                else:
                    row = r4
            rows[edge_point[e]] = row
        elif e in edge_e1e2:
            h = edge_hes[e][0]                  # the only (owner) halfedge p_i -> p_{i+1}
            p_i, p_i1 = u, w
            p_im1 = boundary_prev_vertex(h)
            p_i2 = boundary_next_vertex(h)
            r1, r2 = {}, {}
            _add(r1, {p_im1: 1.0 / 27.0})
            _add(r1, {p_i: 16.0 / 27.0})
            _add(r1, {p_i1: 10.0 / 27.0})
            _add(r2, {p_i: 10.0 / 27.0})
            _add(r2, {p_i1: 16.0 / 27.0})
            _add(r2, {p_i2: 1.0 / 27.0})
            i1, i2 = edge_e1e2[e]
            rows[i1], rows[i2] = r1, r2

    # ---- face points --------------------------------------------------------
    for f, idx in face_point.items():
        row = {}
        for x in F_list[f]:
            row[x] = row.get(x, 0.0) + 1.0 / 3.0
        rows[idx] = row

    # ---- faces --------------------------------------------------------------
    # trisected face (Kobbelt even step): the boundary halfedge of each face
    face_bhe = {}
    if kobbelt_even:
        for f in range(m):
            for i in range(3):
                if is_boundary[he_edge[3 * f + i]]:
                    face_bhe[f] = 3 * f + i

    def apex(h):
        """Apex of face(h) for its halfedge h."""
        f = h // 3
        if f in face_point:
            return face_point[f]
        hb = face_bhe[f]
        e1, e2 = edge_e1e2[he_edge[hb]]
        if h == next_he(hb):
            return e2
        if h == prev_he(hb):
            return e1
        raise RuntimeError("apex asked for the boundary halfedge")

    out_faces, out_sharp, out_parent = [], [], []
    for f, (a, b, c) in enumerate(F_list):
        if face_sharp[f]:
            m_ab = edge_point[he_edge[3 * f + 0]]
            m_bc = edge_point[he_edge[3 * f + 1]]
            m_ca = edge_point[he_edge[3 * f + 2]]
            for tri in ((a, m_ab, m_ca), (m_ab, b, m_bc), (m_ca, m_bc, c), (m_ab, m_bc, m_ca)):
                out_faces.append(tri)
                out_sharp.append(True)
                out_parent.append(f)
            continue
        for i in range(3):
            h = 3 * f + i
            u, w = origin(h), dest(h)
            e = he_edge[h]
            if is_split[e]:
                cf, mp = face_point[f], edge_point[e]
                tris = [(cf, u, mp), (cf, mp, w)]
            elif is_boundary[e]:
                if is_trisected[e]:
                    e1, e2 = edge_e1e2[e]
                    tris = [(e1, e2, opposite(h))]
                else:
                    tris = [(face_point[f], u, w)]
            else:
                tris = [(u, apex(twin[h]), apex(h))]
            for tri in tris:
                out_faces.append(tri)
                out_sharp.append(False)
                out_parent.append(f)

    # ---- child tags ---------------------------------------------------------
    child_edges, child_s = [], []
    for e in range(n_edges):
        if e not in tag_s or is_boundary[e]:
            continue   # boundary edges are creases implicitly and are not listed
        s = edge_s[e]
        s1 = s if s == inf else s - 1.0
        if s1 <= 0:
            continue
        u, w = edge_uw[e]
        mp = edge_point[e]
        child_edges += [(u, mp), (mp, w)]
        child_s += [s1, s1]

    # ---- the matrix ---------------------------------------------------------
    ri, ci, vals = [], [], []
    for i, row in enumerate(rows):
        assert row is not None, f"row {i} never filled"
        for j, x in sorted(row.items()):
            if x != 0.0:
                ri.append(i)
                ci.append(j)
                vals.append(x)
    S = sp.csr_matrix((np.array(vals, dtype=np.float64), (np.array(ri, dtype=np.int64),
                                                          np.array(ci, dtype=np.int64))),
                      shape=(n_new, n))
    S.sum_duplicates()
    S.sort_indices()

    return {
        "S": S,
        "faces": np.array(out_faces, dtype=np.int64).reshape(-1, 3),
        "sharp_edges": np.array(child_edges, dtype=np.int64).reshape(-1, 2),
        "sharpness": np.array(child_s, dtype=np.float64),
        "sharp_faces": np.array(out_sharp, dtype=bool),
        "corners": np.array(sorted(corner_set), dtype=np.int64),
        "face_parent": np.array(out_parent, dtype=np.int64),
    }


def naive_refine(F, n_vertices, levels, **kw):
    """levels steps; returns the same dict for the whole thing, with 'S' the composite (S_L @ ... @ S_1)
    and face_parent mapped back to the input faces."""
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    m = len(F)
    scheme = kw.pop("scheme", "hybrid")
    loop_weights = kw.pop("loop_weights", "loop")
    sharp_edges = kw.pop("sharp_edges", None)
    sharpness = kw.pop("sharpness", None)
    sharp_faces = kw.pop("sharp_faces", None)
    corners = kw.pop("corners", None)
    if kw:
        raise TypeError(f"unexpected arguments {sorted(kw)}")

    # level-0 state (what a zero-level call returns)
    if scheme == "sqrt3":
        cur_mask = np.zeros(m, dtype=bool)
    elif scheme == "loop":
        cur_mask = np.ones(m, dtype=bool)
    else:
        cur_mask = np.array(_face_mask(sharp_faces, m), dtype=bool)
    out = {
        "S": sp.identity(int(n_vertices), dtype=np.float64, format="csr"),
        "faces": F.copy(),
        "sharp_edges": np.zeros((0, 2), dtype=np.int64) if sharp_edges is None
        else np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2),
        "sharpness": None if sharpness is None else np.asarray(sharpness, dtype=np.float64),
        "sharp_faces": cur_mask,
        "corners": np.array(sorted({int(c) for c in np.asarray(corners).reshape(-1)})
                            if corners is not None else [], dtype=np.int64),
        "face_parent": np.arange(m, dtype=np.int64),
    }
    if out["sharpness"] is None:
        out["sharpness"] = np.full(len(out["sharp_edges"]), inf)

    S_total = out["S"]
    faces, parent = F, np.arange(m, dtype=np.int64)
    n_cur = int(n_vertices)
    for k in range(levels):
        r = naive_step(faces, n_cur, scheme=scheme, step=k + 1,
                       sharp_edges=sharp_edges, sharpness=sharpness,
                       sharp_faces=sharp_faces if k == 0 else cur_mask,
                       corners=corners, loop_weights=loop_weights)
        S_total = (r["S"] @ S_total).tocsr()
        parent = parent[r["face_parent"]]
        faces, n_cur = r["faces"], r["S"].shape[0]
        sharp_edges, sharpness = r["sharp_edges"], r["sharpness"]
        cur_mask, corners = r["sharp_faces"], r["corners"]
        out = dict(r)
    S_total.sum_duplicates()
    S_total.sort_indices()
    out["S"] = S_total
    out["face_parent"] = parent
    return out
