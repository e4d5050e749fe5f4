"""Exact local refinement down to any point of the limit surface.

A point (face, bary) is followed through the refinement: at every level only the patch of
faces around the face that holds it (two vertex rings) is refined, with the project's own
step (``plan_step``, ``step_matrix``, ``child_level``: every scheme and tag), and the child
face holding the point is found in the parameter chart (:mod:`.._refiner.chart`). The
patches of all points are one mesh of disjoint pieces, refined together; points in the same
patch share it. Each level records the sparse map from one level's patch vertices to the
next's, so the result is a row over the control vertices: positions enter linearly.

At the last level the point's value is interpolated from the exact limit positions
(``_rules.limit`` masks, or local refinement where a vertex has none) of six vertices around
it: the corners of its face and the far corners of the three faces across its edges
(quadratic Lagrange interpolation in the chart; linear on the boundary). ``docs/limit.md``
gives the accuracy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._input import RefineInput
from .._topology import Level, child_level, face_parents, plan_step
from .._refiner import EQUILATERAL, barycentric, child_shapes, glue_maps, plan_supports, step_matrix
from .._refiner.loop import next_corners
from ._descent_kernels import cut_pieces, ring_pairs, ring_pairs_within
from .local import plan_vertices, refine_locally

#: Vertex rings of faces around a point's face kept at every level.
RINGS = 2
#: Interpolation stencils worse conditioned than this fall back to linear interpolation.
MAX_CONDITION = 1e6
#: Children of one face at most (√3: 3 + split edges; Loop: 4).
MAX_CHILDREN = 6


@dataclass(frozen=True, eq=False)
class Patches:
    """All live patches of one level as one mesh of disjoint pieces."""

    level: Level
    corner: np.ndarray  # (n,) bool, or each vertex's sharpness left (float64) with semi-sharp corners
    shape: np.ndarray  # (m, 3, 2) every face's corners in its own chart frame
    face: np.ndarray  # (k,) the face holding each node's points
    uv: np.ndarray  # (k, 3, 2) that face's corners in the input face's (u, v)


def ring_faces(F: np.ndarray, n: int, centre: np.ndarray, rings: int = RINGS):
    """(node, face) pairs: the faces within ``rings`` vertex rings of each node's centre face."""
    return ring_pairs(np.ascontiguousarray(F, dtype=np.int64), int(n), np.asarray(centre, dtype=np.int64), rings)


def cut_patches(level: Level, corner: np.ndarray, node: np.ndarray, f: np.ndarray):
    """The faces ``f`` of each node as a new mesh of disjoint pieces.

    Returns the new :class:`Level`, its corner mask, the old vertex of every new vertex, and
    the sorted (node, face) keys (to find a face's new index).
    """
    n, m = level.n_vertices, level.n_faces
    newF, vsel, twin = cut_pieces(np.ascontiguousarray(level.faces, dtype=np.int64),
                                  np.ascontiguousarray(level.twin, dtype=np.int64), int(n),
                                  np.asarray(node, dtype=np.int64), np.asarray(f, dtype=np.int64))
    fkeys = node * m + f
    hs = None if level.hsharp is None else level.hsharp.reshape(-1, 3)[f].ravel()
    new = Level(newF, len(vsel), twin, hs, level.face_sharp[f])
    return new, corner[vsel], vsel, fkeys


def start(inp: RefineInput, faces0: np.ndarray):
    """Level-0 patches around the input faces ``faces0`` (one node each), their selection
    (CSR, patch vertices × input vertices) and where each node's faces start (k + 1,)."""
    node, f = ring_faces(inp.level.faces, inp.n_vertices, faces0)
    vertex_corner = inp.corner if inp.corner_sharpness is None else inp.corner_sharpness
    level, corner, vsel, fkeys = cut_patches(inp.level, vertex_corner, node, f)
    sel = sp.csr_matrix((np.ones(len(vsel)), vsel, np.arange(len(vsel) + 1)), shape=(len(vsel), inp.n_vertices))
    cur = np.searchsorted(fkeys, np.arange(len(faces0)) * inp.n_faces + faces0)
    shape = np.repeat(EQUILATERAL[None], level.n_faces, axis=0)
    uv = np.repeat(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])[None], len(faces0), axis=0)
    return Patches(level, corner, shape, cur, uv), sel, np.searchsorted(node, np.arange(len(faces0) + 1))


@dataclass(frozen=True, eq=False)
class ChildShapes:
    """``shapes_of(faces)``: the corners of the next level's ``faces`` in their parents'
    frames (:func:`.._refiner.child_shapes`), from one step's parts: the next level's faces
    ``faces1``, their ``parent`` faces, the chart supports ``ids``, ``w`` of every next
    vertex over this level's ``faces``, ``twin`` and ``shape``."""

    faces: np.ndarray
    twin: np.ndarray
    shape: np.ndarray
    faces1: np.ndarray
    parent: np.ndarray
    ids: np.ndarray
    w: np.ndarray

    def __call__(self, faces: np.ndarray) -> np.ndarray:
        return child_shapes(self.faces, self.twin, self.shape, self.faces1[faces], self.parent[faces], self.ids,
                            self.w)


def _candidates(p: Patches, offsets: np.ndarray, shapes_of):
    """Children of each node's face and of its edge-neighbours: ids (k, 24) (−1: none) and
    corners (k, 24, 3, 2) in the node face's frame; ``shapes_of(faces)`` gives child shapes."""
    nbr, R, t = glue_maps(p.shape, p.level.twin, p.face)
    k = len(p.face)
    groups = np.concatenate([p.face[:, None], nbr], axis=1)  # (k, 4)
    Rg = np.concatenate([np.broadcast_to(np.eye(2), (k, 1, 2, 2)), R], axis=1)
    tg = np.concatenate([np.zeros((k, 1, 2)), t], axis=1)
    g = np.maximum(groups, 0)
    first, cnt = offsets[g], offsets[g + 1] - offsets[g]
    j = np.arange(MAX_CHILDREN)
    ids = np.where((groups[..., None] >= 0) & (j < cnt[..., None]), first[..., None] + j, -1)  # (k, 4, 6)
    some, back = np.unique(np.maximum(ids, 0), return_inverse=True)
    corners = shapes_of(some)[back.reshape(ids.shape)]  # (k, 4, 6, 3, 2)
    # Rg @ corner for every corner (einsum is several times slower on these shapes).
    corners = Rg[:, :, None, None, :, 0] * corners[..., :1] + Rg[:, :, None, None, :, 1] * corners[..., 1:]
    corners += tg[:, :, None, None, :]
    return ids.reshape(k, -1), corners.reshape(k, -1, 3, 2)


def refine_patches(p: Patches, scheme: str, step_no: int, loop_weights: str):
    """One step of the patches ``p``: ``(plan, S, faces1, child, shapes_of, cid, ccorn)`` —
    the step's plan and matrix, the next level's faces and :class:`Level`, ``shapes_of(faces)``
    the child faces' corners in their parents' frames (:class:`ChildShapes`), and each node's candidate children
    (:func:`_candidates`)."""
    lvl = p.level
    plan = plan_step(lvl, p.corner, scheme, step_no, loop_weights)
    S = step_matrix(lvl, plan)
    faces1, child, offsets = child_level(lvl, plan)
    ids, w = plan_supports(lvl.faces, plan, lvl.n_vertices)
    shapes_of = ChildShapes(lvl.faces, lvl.twin, p.shape, faces1, face_parents(offsets), ids, w)
    cid, ccorn = _candidates(p, offsets, shapes_of)
    return plan, S, faces1, child, shapes_of, cid, ccorn


def step(p: Patches, qnode: np.ndarray, bary: np.ndarray, scheme: str, loop_weights: str, step_no: int):
    """One level down: refine the patches, follow every point into its child face, cut the
    next patches. Returns (next Patches, map from this level's vertices, qnode, bary)."""
    plan, S, faces1, child, shapes_of, cid, ccorn = refine_patches(p, scheme, step_no, loop_weights)
    x = np.einsum("qc,qcd->qd", bary, p.shape[p.face[qnode]])
    b = barycentric(ccorn[qnode], x[:, None, :])  # (q, 24, 3)
    score = np.where(cid[qnode] >= 0, b.min(axis=2), -np.inf)
    pick = np.argmax(score, axis=1)
    q = np.arange(len(qnode))
    chosen = cid[qnode, pick]
    nb = b[q, pick]
    key, first, qn = np.unique(qnode * len(faces1) + chosen, return_index=True, return_inverse=True)
    centre = key % len(faces1)
    own = ccorn[qnode[first], pick[first]]  # (k', 3, 2) the chosen faces' corners, parent node frame
    lam = barycentric(p.shape[p.face[qnode[first]]][:, None], own)
    uv = lam @ p.uv[qnode[first]]
    nxt, corner_n, shape_n, cur, vsel, _, _ = cut_children(p, plan, faces1, child, shapes_of, centre)
    return Patches(nxt, corner_n, shape_n, cur, uv), sp.csr_matrix(S)[vsel], qn.ravel(), nb


def cut_children(p: Patches, plan, faces1: np.ndarray, child: Level, shapes_of, centre: np.ndarray,
                 within: tuple | None = None):
    """The patches (two rings) round the child faces ``centre`` of :func:`refine_patches`'
    step, as a new mesh of disjoint pieces: its :class:`Level`, corner mask, face shapes, each
    piece's centre face, the refined vertex of each new vertex, where each piece's faces start,
    and the refined face of each new face. ``within``: per centre the range of refined faces
    that holds its piece (``lo``, ``hi``), to look for the rings there only (a few centres
    on a large step)."""
    corner1 = next_corners(p.corner, plan.n_new)  # semi-sharp corners decay by one a level
    if within is None:
        node, f = ring_faces(faces1, plan.n_new, centre)
    else:
        node, f = ring_pairs_within(np.ascontiguousarray(faces1, dtype=np.int64), int(plan.n_new),
                                    np.asarray(centre, dtype=np.int64), np.asarray(within[0], dtype=np.int64),
                                    np.asarray(within[1], dtype=np.int64), RINGS)
    nxt, corner_n, vsel, fkeys = cut_patches(child, corner1, node, f)
    cur = np.searchsorted(fkeys, np.arange(len(centre)) * len(faces1) + centre)
    fstart = np.searchsorted(node, np.arange(len(centre) + 1))
    # Every face is equilateral in its own frame (the chart, ``_refiner/chart.py``).
    return nxt, corner_n, np.repeat(EQUILATERAL[None], len(f), axis=0), cur, vsel, fstart, f


def _edge_tags(level: Level, scheme: str):
    tagged = np.zeros(level.n_edges) if level.hsharp is None else level.hsharp[level.edge_owner].copy()
    if scheme == "sqrt3":
        return tagged, np.where(level.boundary_edge, np.inf, 0.0)
    return tagged, np.where(level.boundary_edge, np.inf, tagged)


def limit_rows(p: Patches, needed: np.ndarray, scheme: str, loop_weights: str, tol: float, max_levels: int):
    """Limit rows (n × n CSR; only ``needed`` rows filled) of the patches' vertices."""
    lvl = p.level
    n = lvl.n_vertices
    tagged, esharp = _edge_tags(lvl, scheme)
    plan = plan_vertices(lvl, esharp, lvl.face_sharp, p.corner, scheme, loop_weights)
    L = plan.limit_csr(n, only=needed)
    centers = needed[~plan.pos_ok[needed]]
    if len(centers):
        rows, _ = refine_locally(lvl, tagged, lvl.face_sharp, p.corner, scheme, loop_weights, centers, plan, None,
                                 True, tol, max_levels)
        moved = sp.csr_matrix((np.ones(len(centers)), (centers, np.arange(len(centers)))), shape=(n, len(centers)))
        L = L + moved @ rows
    return sp.csr_matrix(L)


def _basis(P):
    s, u = P[..., 0], P[..., 1]
    return np.stack([np.ones_like(s), s, u, s * s, s * u, u * u], -1)


def stencil_nodes(p: Patches):
    """The per-node part of :func:`stencil`: vertex ids (k, 6), the interpolation matrix
    (k, 6, 6), whether it is used (k,) (else linear), and the face's frame: centroid (k, 1, 2),
    size (k, 1, 1), corners (k, 3, 2)."""
    lvl = p.level
    nbr, R, t = glue_maps(p.shape, lvl.twin, p.face)
    tw = lvl.twin[3 * p.face[:, None] + np.arange(3)]
    far_local = np.where(tw >= 0, (tw % 3 + 2) % 3, 0)
    g = np.maximum(nbr, 0)
    far_ids = np.where(nbr >= 0, lvl.faces[g, far_local], -1)
    far = np.einsum("kiab,kib->kia", R, p.shape[g, far_local]) + t
    here = p.shape[p.face]  # (k, 3, 2)
    # A normalised frame: the face's centroid at 0, unit size.
    c0 = here.mean(axis=1, keepdims=True)
    scale = np.linalg.norm(here[:, 1] - here[:, 0], axis=1)[:, None, None]
    pts = (np.concatenate([here, far], axis=1) - c0) / scale  # (k, 6, 2)
    ids = np.concatenate([lvl.faces[p.face], far_ids], axis=1)
    full = (nbr >= 0).all(axis=1)
    A = _basis(np.where(full[:, None, None], pts, 0.0))  # (k, 6, 6)
    A[~full] = np.eye(6)
    full &= np.linalg.cond(A) < MAX_CONDITION  # slivers (√3 crease sectors grow a face per level)
    A[~full] = np.eye(6)
    return ids, A, full, c0, scale, here


def stencil(p: Patches, qnode: np.ndarray, bary: np.ndarray):
    """Interpolation of the last level: vertex ids (q, 6), weights for the value, ∂/∂u, ∂/∂v,
    ∂²/∂u², ∂²/∂u∂v, ∂²/∂v² (q, 6 each) at every point, from six vertices around it (quadratic
    in the chart; second derivatives zero where it falls back to linear)."""
    ids, A, full, c0, scale, here = stencil_nodes(p)
    return (ids[qnode], *stencil_weights(A[qnode], full[qnode], c0[qnode, 0], scale[qnode, 0], here[qnode],
                                          p.uv[qnode], bary))


def stencil_weights(A, full, c0, scale, here, uv, bary):
    """:func:`stencil`'s weights from per-point copies of :func:`stencil_nodes`' data (``c0``
    (q, 2), ``scale`` (q, 1)) and the points' face corners in (u, v), ``uv`` (q, 3, 2)."""
    x = (np.einsum("qc,qcd->qd", bary, here) - c0) / scale
    s, u = x[:, 0], x[:, 1]
    z, o = np.zeros_like(s), np.ones_like(s)
    t2 = 2 * o
    rhs = np.stack([_basis(x), np.stack([z, o, z, 2 * s, u, z], -1), np.stack([z, z, o, z, s, 2 * u], -1),
                    np.stack([z, z, z, t2, z, z], -1), np.stack([z, z, z, z, o, z], -1),
                    np.stack([z, z, z, z, z, t2], -1)], -1)
    W = np.linalg.solve(np.swapaxes(A, 1, 2), rhs)  # (q, 6, 6): value, d/ds, d/dt, d²/ds², d²/dsdt, d²/dt²
    lin = ~full
    if lin.any():  # a boundary face or a sliver: linear interpolation
        W[lin] = 0.0
        W[lin, :3, 0] = bary[lin]
        E = here[lin] / scale[lin, :, None]
        Minv = np.linalg.inv(np.stack([E[:, 1] - E[:, 0], E[:, 2] - E[:, 0]], -1))  # rows: d bary1,2 / d(s,t)
        W[lin, 1:3, 1:3] = Minv
        W[lin, 0, 1:3] = -Minv.sum(axis=1)
    at = np.flatnonzero(bary.max(axis=1) >= 1.0 - 1e-14)  # at a vertex: its limit position exactly
    W[at, :, 0] = 0.0
    W[at, np.argmax(bary[at], axis=1), 0] = 1.0
    # d/d(u,v) = d/d(s,t) · d(s,t)/d(u,v), the chart frame being affine in (u, v) over the face.
    X = here / scale[:, :, None]
    U = uv
    Mx = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], -1)  # columns: ∂x/∂(bary1, bary2)
    Mu = np.stack([U[:, 1] - U[:, 0], U[:, 2] - U[:, 0]], -1)
    J = Mx @ np.linalg.inv(Mu)  # ∂(s,t)/∂(u,v)
    Wu = W[:, :, 1] * J[:, None, 0, 0] + W[:, :, 2] * J[:, None, 1, 0]
    Wv = W[:, :, 1] * J[:, None, 0, 1] + W[:, :, 2] * J[:, None, 1, 1]
    # Second derivatives (constant over the stencil; for Newton's method in project): Jᵀ H J.
    H = np.stack([np.stack([W[:, :, 3], W[:, :, 4]], -1), np.stack([W[:, :, 4], W[:, :, 5]], -1)], -1)
    Huv = np.einsum("qai,qkab,qbj->qkij", J, H, J)
    return W[:, :, 0], Wu, Wv, Huv[:, :, 0, 0], Huv[:, :, 0, 1], Huv[:, :, 1, 1]
