"""Adaptive refinement: the uniform step applied to a region of a mixed-level mesh.

The adaptive mesh of level k holds faces of levels 0..k. A face is *active* at level k when
it is a face of the uniform level k (not a closure face) and its three vertices are at level
k. One step refines a set R of active faces (the *region*) with the uniform step's own plan
and matrix, run on R alone as a mesh of its own (:func:`hybridsub._topology.plan_step`,
:func:`~hybridsub._topology.child_level`, :func:`.stencils.step_matrix`), and keeps of that
step only the rows whose stencils lie in R:

- a face point: always (its face is in R);
- an edge point: when both faces of its edge are in R, or the edge is on the input's boundary;
- an old vertex moves to level k + 1 (*promoted*) when every face of the adaptive mesh
  around it is in R; otherwise it stays at its level-k position.

Those are exactly the rows of the uniform step for these points, so every vertex of the
result is a vertex of the uniform refinement of its level, at its position. An edge of R's
border (R on one side only) is neither split nor flipped: its edge point is not made, and
the faces the step emitted with it are closed onto the edge's first end (a √3 face gives
``(c_f, u, w)``, a Loop face Loop's red–green closure). The faces on the other side are not
touched, so the result has no T-vertex. Closure faces are never refined again. Kobbelt's √3
on a mesh with a boundary runs its step on R and the faces round it, whose boundary rule
depends on the step's parity (:func:`_kobbelt_region`).

>>> import numpy as np
>>> from hybridsub._input import open_gate
>>> inp = open_gate([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]], levels=1, scheme="loop")
>>> mesh = start(inp)
>>> mesh, step = refine_region(mesh, np.array([True, True, False, False]), 0, "loop", "loop")
>>> len(mesh.faces), step.matrix.shape    # one edge inside the region: split, its faces closed
(6, (5, 4))
>>> mesh.genuine.tolist()                 # the four closure faces, and the two faces not refined
[False, False, False, False, True, True]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._input import RefineInput
from .._topology import Level, build_level, child_level, plan_step, seam_halfedges
from .._topology.uv import new_uv_corners
from .refinement import Refinement, RefinementStep, _compose_cut
from .._rules.step_rules import EDGE_SPLIT, EDGE_TRISECT
from .budget import RegionBudget
from .linear_uv import linear_uv_matrix
from .stencils import step_matrix


@dataclass(frozen=True, eq=False)
class AdaptiveUV:
    """The face-varying (UV) index mesh of an adaptive mesh: UV faces aligned row by row."""

    faces: np.ndarray  # (m, 3) int64 UV index of each face corner
    n_uvs: int
    corner: np.ndarray  # (t,) bool: UV indices kept as corners (``uv_start``'s, and new ones in "boundaries")
    mode: str  # the face-varying interpolation ("all": linear)


@dataclass(eq=False)
class AdaptiveMesh:
    """The adaptive mesh of one level: faces of several levels, tagged per halfedge."""

    faces: np.ndarray  # (m, 3) int64
    n_vertices: int
    twin: np.ndarray  # (3m,) int64, −1 on the boundary
    hsharp: np.ndarray | None  # (3m,) float64 sharpness per halfedge, None without tags
    face_sharp: np.ndarray  # (m,) bool
    face_level: np.ndarray  # (m,) int64
    genuine: np.ndarray  # (m,) bool: a face of the uniform refinement of its level
    face_parent: np.ndarray  # (m,) int64 input face
    vertex_level: np.ndarray  # (n,) int64
    # (n,) bool corners, or with semi-sharp corners (``corner_sharpness=``) float64: each input
    # vertex's sharpness at level 0 (inf a corner, 0 none), spent one a level (:func:`corners_at`)
    corner: np.ndarray
    uv: AdaptiveUV | None = None

    def active(self, k: int) -> np.ndarray:
        """(m,) faces that a step from level k may refine."""
        on = self.vertex_level[self.faces] == k
        return self.genuine & (self.face_level == k) & on.all(axis=1)


@dataclass(frozen=True, eq=False)
class RegionStep:
    """One adaptive step: the next mesh's faces, the step's matrix and each face's emitter."""

    faces: np.ndarray
    matrix: sp.csr_matrix
    face_parent: np.ndarray  # (m',) the face of the previous adaptive mesh that emitted each face
    source: np.ndarray  # (n' - n,) what made each new point: face f (f), or edge of halfedge h (m + h, h the lower)
    uv_matrix: sp.csr_matrix | None = None  # (t', t) with face-varying data

    @property
    def n_vertices(self) -> int:
        return self.matrix.shape[0]


def start(inp: RefineInput) -> AdaptiveMesh:
    """The adaptive mesh of level 0: the checked input, every face active."""
    level = inp.level
    m, n = inp.n_faces, inp.n_vertices
    corner = inp.corner if inp.corner_sharpness is None else inp.corner_sharpness
    uv = None
    if inp.uv is not None and inp.uv.corner is not None:
        uv = AdaptiveUV(inp.uv.faces, inp.uv.n_uvs, inp.uv.corner.copy(), inp.uv.mode)
    return AdaptiveMesh(inp.faces, n, level.twin, level.hsharp, inp.face_sharp.copy(), np.zeros(m, np.int64),
                        np.ones(m, bool), np.arange(m, dtype=np.int64), np.zeros(n, np.int64), corner.copy(), uv)


def corners_at(corner: np.ndarray, levels) -> np.ndarray:
    """The corner argument of a step from level ``levels`` (a scalar, or one per vertex): the
    mask as it is, or each vertex's sharpness less what ``levels`` steps spent (inf stays), as
    the uniform steps decay it (``next_corners``)."""
    if corner.dtype != np.float64:
        return corner
    return np.where(np.isinf(corner), corner, np.maximum(corner - levels, 0.0))


def corners_left(mesh: AdaptiveMesh) -> tuple[np.ndarray, np.ndarray | None]:
    """The vertices still corners at their own level and, with semi-sharp ones, the sharpness
    left to each (as ``Refinement.corners`` and ``corner_sharpness``)."""
    if mesh.corner.dtype != np.float64:
        return np.flatnonzero(mesh.corner), None
    left = corners_at(mesh.corner, mesh.vertex_level)
    c = np.flatnonzero(left > 0)
    return c, left[c]


def _region_level(mesh: AdaptiveMesh, region: np.ndarray):
    """The faces ``region`` as a level of their own: (faces, vertices, the level, border halfedges)."""
    F, twin, n, m = mesh.faces, mesh.twin, mesh.n_vertices, len(mesh.faces)
    rf = np.flatnonzero(region)
    sub_ids = np.unique(F[rf].ravel())
    local = np.full(n, -1, np.int64)
    local[sub_ids] = np.arange(len(sub_ids))
    slot = np.full(m, -1, np.int64)
    slot[rf] = np.arange(len(rf))
    h = (3 * rf[:, None] + np.arange(3)).ravel()
    t = twin[h]
    tf = np.where(t >= 0, slot[np.maximum(t, 0) // 3], -1)
    ts = np.where(tf >= 0, 3 * tf + t % 3, -1)
    border = (t >= 0) & (tf < 0)  # R on one side only: not split, not flipped
    hs = None if mesh.hsharp is None else mesh.hsharp[h]
    level = Level(local[F[rf]], len(sub_ids), ts, hs, mesh.face_sharp[rf])
    return rf, sub_ids, local, level, border


def _region_matrix(S: sp.csr_matrix, sub_ids, local, promoted, kept_new, n: int, n1: int) -> sp.csr_matrix:
    """The step's (n1, n) matrix: the uniform rows of the promoted vertices and the kept new
    points (``S``'s, over the region's vertices), identity rows for every other vertex."""
    SA = sp.csr_matrix((S.data, sub_ids[S.indices], S.indptr), shape=(S.shape[0], n))
    prom = np.flatnonzero(promoted)
    src = np.concatenate([local[prom], kept_new])
    dst = np.concatenate([prom, np.arange(n, n1)])
    pick = sp.csr_matrix((np.ones(len(src)), (dst, src)), shape=(n1, S.shape[0]))
    stay = np.flatnonzero(~promoted)
    ident = sp.csr_matrix((np.ones(len(stay)), (stay, stay)), shape=(n1, n))
    M = (pick @ SA + ident).tocsr()
    M.sort_indices()
    return M


def _sources(mesh: AdaptiveMesh, rf: np.ndarray, plan, n_new: int) -> np.ndarray:
    """(n_new,) what made each point of a step planned on the faces ``rf`` (see
    ``RegionStep.source``; −1 for old vertices)."""
    m = len(mesh.faces)
    key = np.full(n_new, -1, np.int64)
    fp = plan.face_point.astype(np.int64)
    on = fp >= 0
    key[fp[on]] = rf[on]
    ep = plan.edge_point.astype(np.int64)
    hh = np.flatnonzero(ep >= 0)
    g = 3 * rf[hh // 3] + hh % 3
    t = mesh.twin[g]
    key[ep[hh]] = m + np.where(t >= 0, np.minimum(g, t), g)
    tri = hh[plan.hkind[hh] == EDGE_TRISECT]  # Kobbelt's trisection: the edge's second point too
    key[ep[tri] + 1] = key[ep[tri]]
    return key


def _kobbelt_region(mesh: AdaptiveMesh, region: np.ndarray, k: int, loop_weights: str):
    """Kobbelt's √3 with its boundary rule on the region ``region``: the step of level ``k``
    (step k + 1, whose parity decides whether boundary edges are kept or trisected) run on R
    and every face that shares a vertex with it (the *ghosts*), so that each vertex of R has
    its whole star: R's border edges are interior edges there (a face of R beside one gets its
    face point, the edge is not trisected), and a boundary edge of R is trisected with its
    true boundary neighbours. Only R's children are kept; a border halfedge's flip triangle
    ``(u, apex(g), apex(f))`` is closed onto the edge, ``(u, w, apex(f))``, as a √3 face beside
    a face not refined (no ghost point is kept). Returns what :func:`refine_region` needs."""
    F = mesh.faces
    ring = grow(mesh, region, 1) & ~region
    rf, gf = np.flatnonzero(region), np.flatnonzero(ring)
    sub_faces = np.concatenate([rf, gf])
    sub_ids = np.unique(F[sub_faces].ravel())
    local = np.full(mesh.n_vertices, -1, np.int64)
    local[sub_ids] = np.arange(len(sub_ids))
    slot = np.full(len(F), -1, np.int64)
    slot[sub_faces] = np.arange(len(sub_faces))
    h = (3 * sub_faces[:, None] + np.arange(3)).ravel()
    t = mesh.twin[h]
    tf = np.where(t >= 0, slot[np.maximum(t, 0) // 3], -1)
    ts = np.where(tf >= 0, 3 * tf + t % 3, -1)
    level = Level(local[F[sub_faces]], len(sub_ids), ts, None, np.zeros(len(sub_faces), bool))
    plan = plan_step(level, corners_at(mesh.corner[sub_ids], k), "sqrt3", k + 1, loop_weights)
    faces_c = child_level(level, plan, want_topology=False)[0]
    S = step_matrix(level, plan).tocsr()
    nr = len(rf)
    # One child per halfedge (√3 splits no edge): halfedge h of R's faces made child h.
    faces_c = faces_c[:3 * nr].copy()
    hr = np.arange(3 * nr)
    hb = hr[(t[hr] >= 0) & (tf[hr] >= nr)]  # R's border halfedges
    faces_c[hb, 1] = level.faces[hb // 3, (hb % 3 + 1) % 3]
    closure = np.zeros(len(faces_c), bool)
    closure[hb] = True
    # The new points kept: those R's children use (its face points and trisection points).
    ns = len(sub_ids)
    used = np.zeros(plan.n_new, bool)
    used[faces_c.ravel()] = True
    kept_new = np.flatnonzero(used[ns:]) + ns
    return rf, sub_faces, sub_ids, local, plan, faces_c, 3 * np.arange(nr + 1), S, kept_new, closure


@dataclass(frozen=True, eq=False)
class _UVRegion:
    """The UV index mesh of a region: its level (twins cut along seams and R's border), the
    UV indices it uses, their local numbers, and the step planned on it."""

    ids: np.ndarray
    local: np.ndarray
    level: Level
    seams: np.ndarray  # (3r,) bool: the region's seam halfedges, split by the geometry's step


def _uv_region(uv: AdaptiveUV, rf: np.ndarray, level: Level) -> _UVRegion:
    T = uv.faces[rf]
    ids = np.unique(T.ravel())
    local = np.full(uv.n_uvs, -1, np.int64)
    local[ids] = np.arange(len(ids))
    Ts = local[T]
    seams = seam_halfedges(level, Ts)
    uvl = Level(Ts, len(ids), np.where(seams, -1, level.twin), level.hsharp, level.face_sharp)
    return _UVRegion(ids, local, uvl, seams)


def _uv_step(mesh: AdaptiveMesh, ur: _UVRegion, plan, k: int, scheme: str, loop_weights: str, hb: np.ndarray,
             promoted: np.ndarray, ok: np.ndarray, keep_f: np.ndarray, order: np.ndarray):
    """The UV step of a region, with the geometry's kept rows: a UV edge point where the
    geometry keeps the edge point (else closed onto the UV index of its halfedge's origin, as
    the geometry closes it), a UV index promoted where its vertex is (every UV index there is
    then refined with its whole UV star). Returns the next :class:`AdaptiveUV` and the (t', t)
    matrix."""
    uv, uvl = mesh.uv, ur.level
    t, ns = uv.n_uvs, len(ur.ids)
    uv_plan = plan_step(uvl, uv.corner[ur.ids], scheme, k + 1, loop_weights, force_split=plan.hkind == EDGE_SPLIT)
    if not np.array_equal(uv_plan.hkind, plan.hkind):
        raise AssertionError("UV index mesh and geometry disagree on split edges")  # pragma: no cover
    faces_c = child_level(uvl, uv_plan, want_topology=False)[0]
    S = linear_uv_matrix(uvl, uv_plan) if uv.mode == "all" else step_matrix(uvl, uv_plan).tocsr()
    ep = uv_plan.edge_point.astype(np.int64)
    dropped = np.zeros(uv_plan.n_new, bool)
    target = np.arange(uv_plan.n_new, dtype=np.int64)
    dropped[ep[hb]] = True
    target[ep[hb]] = uvl.faces.ravel()[hb]
    kept_new = np.flatnonzero(~dropped[ns:]) + ns
    to_mesh = np.empty(uv_plan.n_new, np.int64)
    to_mesh[:ns] = ur.ids
    to_mesh[dropped] = ur.ids[target[dropped]]
    to_mesh[kept_new] = t + np.arange(len(kept_new))
    t1 = t + len(kept_new)
    # A UV index moves with its vertex (all its corners' vertices promoted): its level is its vertex's.
    used = np.bincount(uv.faces.ravel(), minlength=t)
    with_promoted = np.bincount(uv.faces.ravel()[promoted[mesh.faces.ravel()]], minlength=t)
    M = _region_matrix(S, ur.ids, ur.local, (used == with_promoted) & (used > 0), kept_new, t, t1)
    faces1 = np.concatenate([uv.faces[keep_f], to_mesh[faces_c][ok]])[order]
    added = np.zeros(len(kept_new), bool)
    if uv.mode == "boundaries":  # new values on UV boundary edges are corners too
        added = new_uv_corners(uvl, uv_plan, ns)[kept_new - ns]
    corner = np.concatenate([uv.corner, added])
    return AdaptiveUV(np.ascontiguousarray(faces1, dtype=np.int64), t1, corner, uv.mode), M


def refine_region(mesh: AdaptiveMesh, region: np.ndarray, k: int, scheme: str,
                  loop_weights: str) -> tuple[AdaptiveMesh, RegionStep]:
    """Refine the active faces ``region`` (m,) bool of level ``k`` once (see the module).
    ``scheme="sqrt3"`` is Kobbelt's with his boundary rule (:func:`_kobbelt_region`); on a
    closed mesh ``"hybrid"`` without tags is the same step, made on R alone."""
    F, n = mesh.faces, mesh.n_vertices
    if scheme == "sqrt3":
        rf, sub_faces, sub_ids, local, plan, faces_c, offsets, S, kept_new, closure = _kobbelt_region(
            mesh, region, k, loop_weights)
        to_mesh = np.full(plan.n_new, -1, np.int64)
        to_mesh[:len(sub_ids)] = sub_ids
        child_sharp = np.zeros(len(faces_c), bool)
        child_hsharp = None
    else:
        rf, sub_ids, local, level, border = _region_level(mesh, region)
        sub_faces = rf
        ns, Fs = len(sub_ids), level.faces
        ur = None if mesh.uv is None else _uv_region(mesh.uv, rf, level)
        plan = plan_step(level, corners_at(mesh.corner[sub_ids], k), scheme, k + 1, loop_weights,
                         force_split=None if ur is None else ur.seams)  # seams are split, never flipped
        faces_c, child, offsets = child_level(level, plan)
        S = step_matrix(level, plan).tocsr()
        n_sub_new = plan.n_new

        # The new points: kept (face points, edge points inside R or on the input's boundary) or
        # dropped (edge points of border edges), each dropped one closed onto its edge's first end.
        ep = plan.edge_point.astype(np.int64)
        has = ep >= 0
        dropped = np.zeros(n_sub_new, bool)
        target = np.arange(n_sub_new, dtype=np.int64)
        hb = np.flatnonzero(has & border)
        dropped[ep[hb]] = True
        target[ep[hb]] = Fs.ravel()[hb]  # the halfedge's origin (sub numbering)
        kept_new = np.flatnonzero(~dropped[ns:]) + ns
        to_mesh = np.empty(n_sub_new, np.int64)
        to_mesh[:ns] = sub_ids
        to_mesh[dropped] = sub_ids[target[dropped]]
        closure = dropped[faces_c].any(axis=1)
        child_sharp, child_hsharp = child.face_sharp, child.hsharp
    source = _sources(mesh, sub_faces, plan, plan.n_new)[kept_new]
    to_mesh[kept_new] = n + np.arange(len(kept_new))
    n1 = n + len(kept_new)

    # Promoted vertices: every face around them in R.
    all_count = np.bincount(F.ravel(), minlength=n)
    r_count = np.bincount(F[rf].ravel(), minlength=n)
    promoted = (r_count == all_count) & (r_count > 0)
    prom = np.flatnonzero(promoted)
    M = _region_matrix(S, sub_ids, local, promoted, kept_new, n, n1)

    # Faces: each face of R replaced by its children (degenerate closure ones left out), the
    # rest kept, in the order of the faces they come from.
    kids = to_mesh[faces_c]
    ok = (kids[:, 0] != kids[:, 1]) & (kids[:, 1] != kids[:, 2]) & (kids[:, 2] != kids[:, 0])
    kid_parent = rf[np.repeat(np.arange(len(rf)), np.diff(offsets))]
    keep_f = np.flatnonzero(~region)
    emitter = np.concatenate([keep_f, kid_parent[ok]])
    order = np.argsort(emitter, kind="stable")
    emitter = emitter[order]
    faces1 = np.concatenate([F[keep_f], kids[ok]])[order]

    def merged(old, new):
        return np.concatenate([old[keep_f], new[ok]])[order]

    face_sharp = merged(mesh.face_sharp, child_sharp)
    face_level = merged(mesh.face_level, np.full(len(kids), k + 1, np.int64))
    genuine = merged(mesh.genuine, ~closure)
    face_parent = mesh.face_parent[emitter]
    hsharp = None
    if mesh.hsharp is not None:
        old_h = mesh.hsharp.reshape(-1, 3)
        new_h = child_hsharp.reshape(-1, 3) if child_hsharp is not None else np.zeros((len(kids), 3))
        hsharp = merged(old_h, new_h).ravel()
    vertex_level = np.concatenate([mesh.vertex_level, np.full(n1 - n, k + 1, np.int64)])
    vertex_level[prom] = k + 1
    corner = np.concatenate([mesh.corner, np.zeros(n1 - n, mesh.corner.dtype)])
    uv = uv_matrix = None
    if mesh.uv is not None:
        uv, uv_matrix = _uv_step(mesh, ur, plan, k, scheme, loop_weights, hb, promoted, ok, keep_f, order)
    faces1 = np.ascontiguousarray(faces1, dtype=np.int64)
    twin1 = build_level(faces1, n1).twin
    out = AdaptiveMesh(faces1, n1, twin1, hsharp, face_sharp, face_level, genuine, face_parent, vertex_level, corner,
                       uv)
    return out, RegionStep(faces1, M, emitter, source, uv_matrix)


def grow(mesh: AdaptiveMesh, mask: np.ndarray, rings: int) -> np.ndarray:
    """``mask`` (m,) bool and every face within ``rings`` vertex rings of it."""
    F = mesh.faces
    for _ in range(rings):
        on = np.zeros(mesh.n_vertices, bool)
        on[F[mask].ravel()] = True
        mask = on[F].any(axis=1)
    return mask


def graded(mesh: AdaptiveMesh, want: np.ndarray, rings: int, k: int = 0) -> np.ndarray:
    """The wanted final level of each face (m,) raised so that levels fall by at most one
    every ``rings`` vertex rings: the ring a face needs around it to be refined once more.
    Only wanted levels above ``k + 1`` are spread (what the steps from level k need)."""
    want = want.copy()
    top = int(want.max(initial=0))
    for d in range(top, k + 1, -1):
        near = grow(mesh, want >= d, rings)
        want[near] = np.maximum(want[near], d - 1)
    return want


def edge_tags(mesh: AdaptiveMesh) -> tuple[np.ndarray, np.ndarray]:
    """Tagged interior creases as vertex pairs and their sharpness (the larger of the two
    sides': an edge on a region's border is still its coarser level's edge)."""
    if mesh.hsharp is None:
        return np.empty((0, 2), np.int64), np.empty(0)
    h = np.arange(len(mesh.twin))
    t = mesh.twin
    own = (t > h)
    s = np.maximum(mesh.hsharp[h[own]], mesh.hsharp[t[own]])
    keep = s > 0
    hh = h[own][keep]
    F = mesh.faces
    pairs = np.stack([F[hh // 3, hh % 3], F[hh // 3, (hh % 3 + 1) % 3]], axis=1)
    return pairs.astype(np.int64), s[keep]


def uv_edge_tags(mesh: AdaptiveMesh) -> tuple[np.ndarray, np.ndarray]:
    """The tagged creases carried onto the UV index mesh: its interior edges (not seams) as
    UV index pairs, with their sharpness (as :func:`edge_tags`)."""
    if mesh.hsharp is None:
        return np.empty((0, 2), np.int64), np.empty(0)
    T = mesh.uv.faces
    h = np.arange(len(mesh.twin))
    t = mesh.twin
    tv = T.ravel()
    nxt = 3 * (h // 3) + (h % 3 + 1) % 3
    tn = 3 * (np.maximum(t, 0) // 3) + (np.maximum(t, 0) % 3 + 1) % 3
    own = (t > h) & (tv[h] == tv[tn]) & (tv[nxt] == tv[np.maximum(t, 0)])  # inside the UV mesh: no seam
    s = np.maximum(mesh.hsharp[h[own]], mesh.hsharp[t[own]])
    keep = s > 0
    hh = h[own][keep]
    return np.stack([tv[hh], tv[nxt[hh]]], axis=1).astype(np.int64), s[keep]


#: Vertex rings per level of difference: what one more step needs around a face (a √3 flip
#: reaches into the neighbour face, whose far vertex's ring must be refined too).
RINGS = {"loop": 1, "hybrid": 2, "sqrt3": 2}


#: What the driver calls at each level k before choosing the region: ``on_level(k, mesh,
#: active, step)`` with the step that made this level (None at level 0); it returns the
#: wanted final level of each face (m,) int64 (raised where the faces are not yet good enough).
OnLevel = "Callable[[int, AdaptiveMesh, np.ndarray, RegionStep | None], np.ndarray]"


@dataclass(frozen=True, eq=False)
class AdaptiveRun:
    """One pass of the driver: the refinement and what it could not refine."""

    refinement: Refinement
    missed: np.ndarray  # (j,) input faces a wanted level could not reach
    missed_level: np.ndarray  # (j,) the level wanted there
    mesh: AdaptiveMesh


def adaptive_pass(inp: RefineInput, want0: np.ndarray, max_levels: int, on_level=None) -> AdaptiveRun:
    """Refine each input face to (at least) its wanted level ``want0`` (m,), at most
    ``max_levels``; the wanted levels are graded (:data:`RINGS`) and inherited by the
    children, and ``on_level`` may raise them level by level."""
    mesh = start(inp)
    scheme = inp.scheme
    if scheme == "sqrt3" and not (inp.level.twin < 0).any():  # closed: the hybrid's step without tags, on R alone
        scheme = "hybrid"
    rings = RINGS[inp.scheme]
    want = np.minimum(np.asarray(want0, np.int64), max_levels)
    steps, uv_steps, st = [], [], None
    missed, missed_level = [], []
    budget = RegionBudget(inp.scheme, inp.max_memory)
    for k in range(max_levels + 1):
        act = mesh.active(k)
        if on_level is not None:
            want = np.maximum(want, np.minimum(on_level(k, mesh, act, st), max_levels))
        if k == 0 or on_level is not None:  # else the children keep their parents' graded levels
            want = graded(mesh, want, rings, k)
        need = want > k
        miss = need & ~act & (mesh.face_level <= k)
        if miss.any():
            missed.append(mesh.face_parent[miss])
            missed_level.append(want[miss])
        region = need & act
        if k == max_levels or not region.any():
            break
        trisect = int((mesh.twin.reshape(-1, 3)[region] < 0).sum()) if scheme == "sqrt3" and k % 2 else 0
        budget.check(k, len(mesh.faces), mesh.n_vertices, int(region.sum()), trisect,
                     None if mesh.uv is None else mesh.uv.n_uvs)
        mesh, st = refine_region(mesh, region, k, scheme, inp.loop_weights)
        budget.add(st.faces, st.matrix, st.uv_matrix)
        want = want[st.face_parent]
        pairs, sharp = edge_tags(mesh)
        sf = inp.faces_out(mesh.face_sharp)
        uv_faces = None if mesh.uv is None else mesh.uv.faces
        steps.append(RefinementStep(st.faces, st.matrix, pairs, sharp, sf, corners_left(mesh)[0], st.face_parent,
                                    uv_faces, st.uv_matrix))
        if mesh.uv is not None:
            uv_steps.append(RefinementStep(uv_faces, st.uv_matrix, *uv_edge_tags(mesh), sf,
                                           np.flatnonzero(mesh.uv.corner), st.face_parent))
    pairs, sharp = edge_tags(mesh)
    face_parent = mesh.face_parent.copy()
    corners_out, corner_sharpness = corners_left(mesh)
    uv = None
    if mesh.uv is not None:
        uv = Refinement(mesh.uv.faces, *uv_edge_tags(mesh), inp.faces_out(mesh.face_sharp),
                        np.flatnonzero(mesh.uv.corner), face_parent.copy(), uv_steps, inp.uv.n_uvs, inp.max_memory)
    r = Refinement(mesh.faces, pairs, sharp, inp.faces_out(mesh.face_sharp), corners_out, face_parent, steps,
                   inp.n_vertices, inp.max_memory, uv, coarse_faces=inp.faces if inp.cut is None else None,
                   face_level=mesh.face_level.copy(), vertex_level=mesh.vertex_level.copy(),
                   corner_sharpness=corner_sharpness)
    r = _compose_cut(inp, r)  # non_manifold="cut": the first step takes the caller's vertices
    cat = (lambda a: np.concatenate(a) if a else np.empty(0, np.int64))
    return AdaptiveRun(r, cat(missed), cat(missed_level), mesh)


def adaptive_refinement(inp: RefineInput, want0: np.ndarray, max_levels: int, on_level=None,
                        passes: int = 6) -> AdaptiveRun:
    """:func:`adaptive_pass`, run again with the wanted levels of the input faces it missed
    raised, until nothing is missed (at most ``passes`` times)."""
    want0 = np.asarray(want0, np.int64).copy()
    for _ in range(passes):
        run = adaptive_pass(inp, want0, max_levels, on_level)
        if not len(run.missed):
            return run
        before = want0.copy()
        np.maximum.at(want0, run.missed, run.missed_level)
        if np.array_equal(before, want0):  # raised already: more rings are needed than grading gives
            np.maximum.at(want0, run.missed, np.minimum(run.missed_level + 1, max_levels))
            if np.array_equal(before, want0):
                return run
    return run
