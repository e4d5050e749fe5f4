"""Which mask applies where: every vertex and sector of one level classified, and the limit
and tangent masks of the classified ones gathered as sparse rows.

A vertex has a stationary limit mask when it is a corner, a crease vertex, a smooth vertex of
a pure region (all √3 or all Loop faces) or a Loop dart, and no incident crease is still
semi-sharp; a sector has stationary tangent masks by its kind (``SEC_*``). Everything else is
``SEC_TRANSIENT``: refined locally (``local``). ``docs/limit.md`` explains each decision.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from .._rules import limit as LR
from .._rules import step_rules as R
from .._topology import Level, Sectors, not_an_edge_error, vertex_sectors

# How a sector's normal is found.
SEC_SMOOTH = 0  # cos/sin tangent masks (Kobbelt and Loop smooth vertices)
SEC_DART = 1  # Loop dart: eigenvector masks
SEC_CREASE_LOOP = 2  # crease vertex, Loop sector: crease tangent × across tangent
SEC_CREASE_SQRT3 = 3  # crease vertex, √3 sector (hybrid): limit of the control fan normal
SEC_KOBBELT_BOUNDARY = 4  # "sqrt3" boundary vertex: Kobbelt's two-step boundary masks
SEC_CORNER = 5  # corner: the two crease tangents
SEC_FAN = 6  # the control fan's normal (fallback where nothing else applies and no refinement)
SEC_TRANSIENT = 7  # refine locally


@dataclass(frozen=True, eq=False)
class LimitPlan:
    """Which mask applies at every vertex and sector of one level."""

    sectors: Sectors
    pos_ok: np.ndarray  # (n,) a stationary limit mask exists
    settled: np.ndarray  # (n,) no incident semi-sharp crease (all are 0 or infinite)
    rows: tuple  # COO (row, col, weight) of the limit masks of the pos_ok vertices
    sec_kind: np.ndarray  # (s,) SEC_* code
    loop_weights: str

    @cached_property
    def tangents(self) -> tuple:
        """COO (sector, col, w1, w2) of the two tangent masks (SEC_* 0-5); only normals need them."""
        return _tangent_rows(self.sectors, self.sec_kind, self.loop_weights)

    def limit_csr(self, n: int, only: np.ndarray | None = None) -> sp.csr_matrix:
        """The limit masks as an (n, n) CSR matrix; with ``only``, just those vertices' rows."""
        rr, cc, ww = self.rows
        if only is not None:
            pick = np.isin(rr, only)
            rr, cc, ww = rr[pick], cc[pick], ww[pick]
        return sp.csr_matrix((ww, (rr, cc)), shape=(n, n))

    def tangent_csr(self, n: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """The two tangent masks of every sector as (s, n) CSR matrices."""
        s_, c_, w1, w2 = self.tangents
        ns = len(self.sectors.vertex)
        return (sp.csr_matrix((w1, (s_, c_)), shape=(ns, n)), sp.csr_matrix((w2, (s_, c_)), shape=(ns, n)))


def edge_sharpness(level: Level, pairs: np.ndarray, sharpness: np.ndarray, scheme: str):
    """Per-edge tagged sharpness and per-edge crease sharpness this level (boundary = inf)."""
    tagged = np.zeros(level.n_edges)
    if len(pairs):
        eid = level.find_edges(pairs)
        if (eid < 0).any():
            raise not_an_edge_error(pairs, np.flatnonzero(eid < 0))
        np.maximum.at(tagged, eid, sharpness)
    boundary = level.boundary_edge
    if scheme == "sqrt3":
        esharp = np.where(boundary, np.inf, 0.0)
    else:
        esharp = np.where(boundary, np.inf, tagged)
    return tagged, esharp


def plan_level(level: Level, esharp: np.ndarray, face_sharp: np.ndarray, corner: np.ndarray, scheme: str,
               loop_weights: str, only: np.ndarray | None = None) -> LimitPlan:
    """Classify every vertex and sector of ``level`` and gather their stationary masks.

    Parameters
    ----------
    level : Level
        The mesh.
    esharp : (E,) array of float
        Crease sharpness of every edge this level, boundary edges infinite (:func:`edge_sharpness`).
    face_sharp : (m,) array of bool
        Sharp (Loop) faces.
    corner : (n,) array of bool
        Tagged corners.
    scheme, loop_weights
        As for :func:`hybridsub.refine`.
    only : (n,) array of bool, optional
        Gather masks for these vertices only: the others are classified (``pos_ok``) but get
        no rows, and their sectors are ``SEC_FAN`` (no tangent masks).

    Returns
    -------
    LimitPlan

    Examples
    --------
    >>> import numpy as np
    >>> from hybridsub._topology import build_level
    >>> level = build_level(np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]), 4)
    >>> esharp = np.zeros(level.n_edges)
    >>> plan = plan_level(level, esharp, np.ones(4, bool), np.zeros(4, bool), "loop", "loop")
    >>> bool(plan.pos_ok.all()), plan.limit_csr(4).toarray()[0].round(4).tolist()
    (True, [0.4, 0.2, 0.2, 0.2])
    """
    sec = vertex_sectors(level, esharp > 0)
    vc = _classify(level, sec, esharp, face_sharp, corner, scheme, loop_weights)
    if only is not None:
        vc = dataclasses.replace(vc, corner=vc.corner & only, crease=vc.crease & only, smooth=vc.smooth & only,
                                 dart=vc.dart & only)
    rows = _limit_rows(level, sec, vc, esharp, scheme, loop_weights)
    kind = _sector_kinds(sec, vc, face_sharp, scheme)
    if only is not None:
        kind[~only[sec.vertex]] = SEC_FAN
    return LimitPlan(sec, vc.pos_ok, vc.settled, rows, kind, loop_weights)


@dataclass(frozen=True, eq=False)
class _Vertices:
    """What every vertex of a level is, for its limit mask."""

    unused: np.ndarray  # no face
    corner: np.ndarray
    crease: np.ndarray  # two crease edges
    smooth: np.ndarray  # no crease, a pure region
    smooth_w: np.ndarray  # the smooth mask's per-neighbour weight (0 elsewhere)
    dart: np.ndarray  # Loop dart
    pos_ok: np.ndarray  # any of the above: a stationary limit mask
    settled: np.ndarray  # no incident semi-sharp crease
    n_sectors: np.ndarray


def _classify(level, sec, esharp, face_sharp, corner, scheme, loop_weights) -> _Vertices:
    n = level.n_vertices
    ev = level.edge_vertices.ravel()
    s2 = np.repeat(esharp, 2)
    valence = level.valence
    c = np.bincount(ev, weights=s2 > 0, minlength=n).astype(np.int64)
    settled = np.bincount(ev, weights=(s2 > 0) & np.isfinite(s2), minlength=n) == 0
    n_faces_at = np.bincount(level.faces.ravel(), minlength=n)
    n_sharp_at = np.bincount(level.faces.ravel(), weights=np.repeat(face_sharp, 3), minlength=n)
    region = np.where(n_sharp_at == 0, R.REGION_SQRT3,
                      np.where(n_sharp_at == n_faces_at, R.REGION_LOOP, R.REGION_MIXED))
    n_sec_at = np.bincount(sec.vertex, minlength=n)
    unused = valence == 0
    if scheme == "sqrt3":
        nb = np.bincount(ev, weights=np.repeat(level.boundary_edge, 2), minlength=n).astype(np.int64)
        is_corner = unused | corner | (nb > 2)  # corner: boundary="edge_and_corner"'s lone boundary vertices
        is_crease = (nb == 2) & ~is_corner
        smooth = (nb == 0) & ~is_corner
        smooth_w = np.where(smooth, LR.smooth_limit_weight(valence, R.REGION_SQRT3), 0.0)
        pos_ok = np.ones(n, dtype=bool)
        dart_v = np.zeros(n, dtype=bool)
    else:
        is_corner = unused | corner | ((c >= 3) & settled)
        is_crease = (c == 2) & settled & ~is_corner
        smooth = (c == 0) & settled & ~is_corner & (region != R.REGION_MIXED)
        smooth_w = np.where(smooth, LR.smooth_limit_weight(valence, region, loop_weights), 0.0)
        dart_v = (c == 1) & settled & ~is_corner & (region == R.REGION_LOOP) & (n_sec_at == 1)
        pos_ok = is_corner | is_crease | smooth | dart_v
    return _Vertices(unused, is_corner, is_crease, smooth, smooth_w, dart_v, pos_ok, settled, n_sec_at)


class _Coo:
    """Sparse entries gathered in pieces: ``n_index`` int64 columns, then float64 weights."""

    def __init__(self, n_index: int, n_weights: int):
        self.dtypes = (np.int64,) * n_index + (np.float64,) * n_weights
        self.parts = [[] for _ in self.dtypes]

    def add(self, *cols):
        for part, col, dtype in zip(self.parts, cols, self.dtypes):
            part.append(np.asarray(col, dtype))

    def arrays(self) -> tuple:
        return tuple(np.concatenate(p).astype(d, copy=False) if p else np.zeros(0, d)
                     for p, d in zip(self.parts, self.dtypes))


def _ring_masks(coo: _Coo, sec: Sectors, ss_all: np.ndarray, row_of, ring_len, masks):
    """Masks over ``[v, ring_0 … ring_{len−1}]`` that depend on the sector size only.

    For every size ``k`` among the sectors ``ss_all``: ``masks(k)`` gives the weight vectors,
    ``ring_len(k)`` how many ring vertices they cover, ``row_of(sectors)`` the rows they go in.
    """
    k = sec.n_faces
    for kk in np.unique(k[ss_all]):
        ss = ss_all[k[ss_all] == kk]
        W = masks(int(kk))
        m = ring_len(kk)
        rid = row_of(ss)
        coo.add(rid, sec.vertex[ss], *(np.full(len(ss), w[0]) for w in W))
        idx = sec.ring_start[ss][:, None] + np.arange(m)[None, :]
        coo.add(np.repeat(rid, m), sec.ring[idx].ravel(), *(np.tile(w[1:], len(ss)) for w in W))


def _limit_rows(level: Level, sec: Sectors, vc: _Vertices, esharp, scheme, loop_weights) -> tuple:
    """COO (row, col, weight) of the limit masks of the vertices that have one."""
    coo = _Coo(2, 1)
    ends = level.edge_vertices
    ev = ends.ravel()
    other = ends[:, ::-1].ravel()  # the far end of each edge end
    # Corners: the vertex itself.
    v = np.flatnonzero(vc.corner)
    coo.add(v, v, np.ones(len(v)))
    # Crease vertices: 2/3 v + 1/6 (a + b), a and b the ends of the two crease edges.
    v = np.flatnonzero(vc.crease)
    if len(v):
        crease_end = np.repeat(level.boundary_edge if scheme == "sqrt3" else esharp > 0, 2)
        sel = crease_end & vc.crease[ev]
        coo.add(ev[sel], other[sel], np.full(int(sel.sum()), LR.CREASE_LIMIT_MASK[1]))
        coo.add(v, v, np.full(len(v), LR.CREASE_LIMIT_MASK[0]))
    # Smooth vertices of a pure region: (1 − n w) v + w Σ p_i.
    v = np.flatnonzero(vc.smooth)
    if len(v):
        coo.add(v, v, 1.0 - level.valence[v] * vc.smooth_w[v])
        sel = vc.smooth[ev]
        coo.add(ev[sel], other[sel], vc.smooth_w[ev[sel]])
    # Loop darts: the eigenvector mask over [v, p_0 … p_{n−1}], p_0 the crease neighbour.
    _ring_masks(coo, sec, np.flatnonzero(vc.dart[sec.vertex]), lambda ss: sec.vertex[ss], lambda kk: kk,
                lambda kk: LR.dart_masks(kk, loop_weights)[:1])
    return coo.arrays()


def _sector_kinds(sec: Sectors, vc: _Vertices, face_sharp: np.ndarray, scheme: str) -> np.ndarray:
    """The SEC_* code of every sector: how its normal is found."""
    k = sec.n_faces
    sv = sec.vertex
    kind = np.full(len(k), SEC_TRANSIENT, dtype=np.int8)
    if scheme == "sqrt3":
        kind[:] = np.where(sec.open, SEC_CORNER, np.where(vc.smooth[sv], SEC_SMOOTH, SEC_FAN))
        kind[sec.open & vc.crease[sv] & (vc.n_sectors[sv] == 1)] = SEC_KOBBELT_BOUNDARY
    else:
        sec_sharp = np.add.reduceat(face_sharp[sec.slots // 3].astype(np.int64), sec.slot_start[:-1]) \
            if len(k) else np.zeros(0, np.int64)
        kind[~sec.open & vc.smooth[sv]] = SEC_SMOOTH
        kind[vc.dart[sv]] = SEC_DART
        crease_sec = sec.open & vc.crease[sv]
        kind[crease_sec & (sec_sharp == k)] = SEC_CREASE_LOOP
        kind[crease_sec & (sec_sharp == 0)] = SEC_CREASE_SQRT3
        kind[sec.open & vc.corner[sv] & vc.settled[sv] & (sec.first_ring != sec.last_ring)] = SEC_CORNER
    kind[vc.unused[sv]] = SEC_FAN
    return kind


def _tangent_rows(sec: Sectors, kind: np.ndarray, loop_weights: str) -> tuple:
    """COO (sector, col, w1, w2) of the two tangent masks of every sector that has them."""
    coo = _Coo(2, 2)
    k = sec.n_faces
    sv = sec.vertex
    ring_sid, ring_j = sec.ring_index()
    rk = kind[ring_sid]
    # Smooth: Σ cos(2πj/n) p_j, Σ sin(2πj/n) p_j.
    sel = rk == SEC_SMOOTH
    w1, w2 = LR.smooth_tangent_weights(k[ring_sid[sel]], ring_j[sel])
    coo.add(ring_sid[sel], sec.ring[sel], w1, w2)
    # Crease sectors (Loop) and Kobbelt's boundary: along q_0 − q_k, across (closed form).
    for code, sch in ((SEC_CREASE_LOOP, "loop"), (SEC_KOBBELT_BOUNDARY, "sqrt3")):
        ss = np.flatnonzero(kind == code)
        if not len(ss):
            continue
        a, b = LR.sector_across_weights(k[ss], sch)
        coo.add(ss, sv[ss], np.zeros(len(ss)), a)
        b_full = np.zeros(len(k))
        b_full[ss] = b
        sel = rk == code
        kk = k[ring_sid[sel]]
        jj = ring_j[sel]
        end0 = jj == 0
        endk = jj == kk
        w_along = np.where(end0, 1.0, np.where(endk, -1.0, 0.0))
        w_across = np.where(end0 | endk, b_full[ring_sid[sel]], np.sin(np.pi * jj / np.maximum(kk, 1)))
        coo.add(ring_sid[sel], sec.ring[sel], w_along, w_across)
    # Crease sectors of √3 faces (hybrid): the asymptotic fan masks, per sector size.
    _ring_masks(coo, sec, np.flatnonzero(kind == SEC_CREASE_SQRT3), lambda ss: ss, lambda kk: kk + 1,
                LR.sqrt3_crease_sector_masks)
    # Loop darts: symmetric and antisymmetric eigenvector masks.
    _ring_masks(coo, sec, np.flatnonzero(kind == SEC_DART), lambda ss: ss, lambda kk: kk,
                lambda kk: LR.dart_masks(kk, loop_weights)[1:])
    # Corners: (q_0 − v) and (q_k − v).
    ss = np.flatnonzero(kind == SEC_CORNER)
    ones, zeros = np.ones(len(ss)), np.zeros(len(ss))
    coo.add(np.r_[ss, ss, ss], np.r_[sv[ss], sec.first_ring[ss], sec.last_ring[ss]],
            np.r_[-ones, ones, zeros], np.r_[-ones, zeros, ones])
    return coo.arrays()
