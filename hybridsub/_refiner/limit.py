"""Limit positions and normals: where the refined meshes converge to.

Layers: ``_limit_rules`` holds the masks (pure weights), ``_limit_kernels`` walks the vertex
fans and cuts them into sectors (topology), this module decides which mask applies where,
assembles sparse matrices, and refines locally where no stationary mask exists. The public
functions are :func:`limit_matrix`, :func:`limit_positions` and :func:`limit_normals`; see
``docs/limit.md`` for every decision taken here.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._topology import _sector_kernels as LK
from .._rules import limit as LR
from .._rules import refinement as R
from .._input import arrays as val
from .._errors import MeshError
from .refinement import refine
from .._topology.level import Level, build_level
from .._typing import ArrayLike, LoopWeights, Scheme

# How a sector's normal is found.
SEC_SMOOTH = 0  # cos/sin tangent masks (Kobbelt and Loop smooth vertices)
SEC_DART = 1  # Loop dart: eigenvector masks
SEC_CREASE_LOOP = 2  # crease vertex, Loop sector: crease tangent × across tangent
SEC_CREASE_SQRT3 = 3  # crease vertex, √3 sector (hybrid): limit of the control fan normal
SEC_KOBBELT_BOUNDARY = 4  # "sqrt3" boundary vertex: Kobbelt's two-step boundary masks
SEC_CORNER = 5  # corner: the two crease tangents
SEC_FAN = 6  # the control fan's normal (fallback where nothing else applies and no refinement)
SEC_TRANSIENT = 7  # refine locally

#: Local levels after which the fan normal of a dart or mixed vertex of the hybrid scheme is
#: taken (it has no tangent plane; the fan's normal moves by O(1/levels) per level).
FAN_LEVELS = 16


@dataclass(frozen=True, eq=False)
class _Sectors:
    vertex: np.ndarray  # (s,) the sector's vertex
    open: np.ndarray  # (s,) bounded by crease edges (else cyclic)
    slot_start: np.ndarray  # (s + 1,) CSR into slots
    slots: np.ndarray  # outgoing halfedges, one per face, counter-clockwise
    ring_start: np.ndarray  # (s + 1,) CSR into ring
    ring: np.ndarray  # q_0 … q_k (open) or p_0 … p_{k−1} (cyclic)
    he_sector: np.ndarray  # (3m,) sector of each halfedge's origin corner

    @property
    def n_faces(self) -> np.ndarray:
        return np.diff(self.slot_start)


@dataclass(frozen=True, eq=False)
class _Plan:
    """Which mask applies at every vertex and sector of one level."""

    sectors: _Sectors
    pos_ok: np.ndarray  # (n,) a stationary limit mask exists
    settled: np.ndarray  # (n,) no incident semi-sharp crease (all are 0 or infinite)
    rows: tuple  # COO (row, col, weight) of the limit masks of the pos_ok vertices
    sec_kind: np.ndarray  # (s,) SEC_* code
    tangents: tuple  # COO (sector, col, w1, w2) of the two tangent masks (SEC_* 0-5)


def _edge_sharpness(level: Level, pairs: np.ndarray, sharpness: np.ndarray, scheme: str):
    """Per-edge tagged sharpness and per-edge crease sharpness this level (boundary = inf)."""
    tagged = np.zeros(level.n_edges)
    if len(pairs):
        eid = level.find_edges(pairs)
        if (eid < 0).any():
            j = int(np.flatnonzero(eid < 0)[0])
            raise MeshError(f"sharp edge {j} = {pairs[j].tolist()} is not an edge of the mesh")
        np.maximum.at(tagged, eid, sharpness)
    boundary = level.boundary_edge
    if scheme == "sqrt3":
        esharp = np.where(boundary, np.inf, 0.0)
    else:
        esharp = np.where(boundary, np.inf, tagged)
    return tagged, esharp


def _sectors(level: Level, esharp: np.ndarray) -> _Sectors:
    crease_he = np.ascontiguousarray(esharp[level.edge_of] > 0)
    out = LK.vertex_sectors(level.faces, level.twin, level.by_origin, level.origin_start, crease_he)
    return _Sectors(*out)


def _ring_index(sec: _Sectors):
    """For each ring entry: its sector and its position j in the sector's ring."""
    lens = np.diff(sec.ring_start)
    sid = np.repeat(np.arange(len(lens)), lens)
    j = np.arange(len(sec.ring)) - sec.ring_start[sid]
    return sid, j


def _plan(level: Level, esharp: np.ndarray, face_sharp: np.ndarray, corner: np.ndarray, scheme: str,
          loop_weights: str) -> _Plan:
    n = level.n_vertices
    sec = _sectors(level, esharp)
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
    ring_sid, ring_j = _ring_index(sec)
    k = sec.n_faces
    sv = sec.vertex
    first_q = sec.ring[sec.ring_start[:-1]]
    last_q = sec.ring[sec.ring_start[1:] - 1]
    sec_sharp = np.add.reduceat(face_sharp[sec.slots // 3].astype(np.int64), sec.slot_start[:-1]) if len(k) else \
        np.zeros(0, np.int64)
    all_sharp = sec_sharp == k
    none_sharp = sec_sharp == 0

    rows_r, rows_c, rows_w = [], [], []

    def add_rows(r, cc, w):
        rows_r.append(np.asarray(r, np.int64))
        rows_c.append(np.asarray(cc, np.int64))
        rows_w.append(np.asarray(w, np.float64))

    unused = valence == 0
    if scheme == "sqrt3":
        nb = np.bincount(ev, weights=np.repeat(level.boundary_edge, 2), minlength=n).astype(np.int64)
        is_corner = unused | (nb > 2)
        is_crease = nb == 2
        smooth = (nb == 0) & ~unused
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

    # Corners: the vertex itself.
    v = np.flatnonzero(is_corner)
    add_rows(v, v, np.ones(len(v)))
    # Crease vertices: 2/3 v + 1/6 (a + b), a and b the ends of the two crease edges.
    v = np.flatnonzero(is_crease)
    if len(v):
        if scheme == "sqrt3":
            cmask = np.repeat(level.boundary_edge, 2)
        else:
            cmask = s2 > 0
        ends = level.edge_vertices
        other = np.stack([ends[:, 1], ends[:, 0]], axis=1).ravel()
        sel = cmask & is_crease[ev]
        add_rows(ev[sel], other[sel], np.full(int(sel.sum()), LR.CREASE_LIMIT_MASK[1]))
        add_rows(v, v, np.full(len(v), LR.CREASE_LIMIT_MASK[0]))
    # Smooth vertices of a pure region: (1 − n w) v + w Σ p_i.
    v = np.flatnonzero(smooth)
    if len(v):
        add_rows(v, v, 1.0 - valence[v] * smooth_w[v])
        ends = level.edge_vertices
        other = np.stack([ends[:, 1], ends[:, 0]], axis=1).ravel()
        sel = smooth[ev]
        add_rows(ev[sel], other[sel], smooth_w[ev[sel]])
    # Loop darts: the eigenvector mask over [v, p_0 … p_{n−1}], p_0 the crease neighbour.
    dart_sec = np.flatnonzero(dart_v[sv])
    for nn in np.unique(k[dart_sec]):
        ss = dart_sec[k[dart_sec] == nn]
        lim, _, _ = LR.dart_masks(int(nn), loop_weights)
        vv = sv[ss]
        add_rows(vv, vv, np.full(len(vv), lim[0]))
        idx = sec.ring_start[ss][:, None] + np.arange(nn)[None, :]
        add_rows(np.repeat(vv, nn), sec.ring[idx].ravel(), np.tile(lim[1:], len(vv)))

    # ---- sector kinds for normals -----------------------------------------------------------
    kind = np.full(len(k), SEC_TRANSIENT, dtype=np.int8)
    if scheme == "sqrt3":
        kind[:] = np.where(sec.open, SEC_CORNER, np.where(smooth[sv], SEC_SMOOTH, SEC_FAN))
        kind[sec.open & is_crease[sv] & (n_sec_at[sv] == 1)] = SEC_KOBBELT_BOUNDARY
    else:
        cyc = ~sec.open
        kind[cyc & smooth[sv]] = SEC_SMOOTH
        kind[dart_v[sv]] = SEC_DART
        crease_sec = sec.open & is_crease[sv]
        kind[crease_sec & all_sharp] = SEC_CREASE_LOOP
        kind[crease_sec & none_sharp] = SEC_CREASE_SQRT3
        kind[sec.open & is_corner[sv] & settled[sv] & (first_q != last_q)] = SEC_CORNER
    kind[unused[sv]] = SEC_FAN

    # ---- tangent masks ------------------------------------------------------------------------
    t_s, t_c, t_1, t_2 = [], [], [], []

    def add_t(s_, c_, w1, w2):
        t_s.append(np.asarray(s_, np.int64))
        t_c.append(np.asarray(c_, np.int64))
        t_1.append(np.asarray(w1, np.float64))
        t_2.append(np.asarray(w2, np.float64))

    rk = kind[ring_sid]
    # Smooth: Σ cos(2πj/n) p_j, Σ sin(2πj/n) p_j.
    sel = rk == SEC_SMOOTH
    w1, w2 = LR.smooth_tangent_weights(k[ring_sid[sel]], ring_j[sel])
    add_t(ring_sid[sel], sec.ring[sel], w1, w2)
    # Crease sectors (Loop) and Kobbelt's boundary: along q_0 − q_k, across (closed form).
    for code, sch in ((SEC_CREASE_LOOP, "loop"), (SEC_KOBBELT_BOUNDARY, "sqrt3")):
        ss = np.flatnonzero(kind == code)
        if not len(ss):
            continue
        a, b = LR.sector_across_weights(k[ss], sch)
        add_t(ss, sv[ss], np.zeros(len(ss)), a)
        b_full = np.zeros(len(k))
        b_full[ss] = b
        sel = rk == code
        kk = k[ring_sid[sel]]
        jj = ring_j[sel]
        end0 = jj == 0
        endk = jj == kk
        bsel = b_full[ring_sid[sel]]
        w_along = np.where(end0, 1.0, np.where(endk, -1.0, 0.0))
        w_across = np.where(end0 | endk, bsel, np.sin(np.pi * jj / np.maximum(kk, 1)))
        add_t(ring_sid[sel], sec.ring[sel], w_along, w_across)
    # Crease sectors of √3 faces (hybrid): the asymptotic fan masks, per sector size.
    ss_all = np.flatnonzero(kind == SEC_CREASE_SQRT3)
    for kk in np.unique(k[ss_all]):
        ss = ss_all[k[ss_all] == kk]
        T1, T2 = LR.sqrt3_crease_sector_masks(int(kk))
        add_t(ss, sv[ss], np.full(len(ss), T1[0]), np.full(len(ss), T2[0]))
        idx = sec.ring_start[ss][:, None] + np.arange(kk + 1)[None, :]
        add_t(np.repeat(ss, kk + 1), sec.ring[idx].ravel(), np.tile(T1[1:], len(ss)), np.tile(T2[1:], len(ss)))
    # Loop darts: symmetric and antisymmetric eigenvector masks.
    ss_all = np.flatnonzero(kind == SEC_DART)
    for kk in np.unique(k[ss_all]):
        ss = ss_all[k[ss_all] == kk]
        _, ts, ta = LR.dart_masks(int(kk), loop_weights)
        add_t(ss, sv[ss], np.full(len(ss), ts[0]), np.full(len(ss), ta[0]))
        idx = sec.ring_start[ss][:, None] + np.arange(kk)[None, :]
        add_t(np.repeat(ss, kk), sec.ring[idx].ravel(), np.tile(ts[1:], len(ss)), np.tile(ta[1:], len(ss)))
    # Corners: (q_0 − v) and (q_k − v).
    ss = np.flatnonzero(kind == SEC_CORNER)
    add_t(np.r_[ss, ss, ss], np.r_[sv[ss], first_q[ss], last_q[ss]],
          np.r_[-np.ones(len(ss)), np.ones(len(ss)), np.zeros(len(ss))],
          np.r_[-np.ones(len(ss)), np.zeros(len(ss)), np.ones(len(ss))])

    def cat(parts, dtype):
        return np.concatenate(parts).astype(dtype) if parts else np.zeros(0, dtype)

    rows = (cat(rows_r, np.int64), cat(rows_c, np.int64), cat(rows_w, np.float64))
    tangents = (cat(t_s, np.int64), cat(t_c, np.int64), cat(t_1, np.float64), cat(t_2, np.float64))
    return _Plan(sec, pos_ok, settled, rows, kind, tangents)


def _fan_normals(level: Level, sec: _Sectors, X: np.ndarray) -> np.ndarray:
    """Area vector of each sector's control fan, Σ (p_j − v) × (p_{j+1} − v)."""
    F = level.faces
    h = sec.slots
    f, i = h // 3, h % 3
    v = X[F[f, i]]
    a = X[F[f, (i + 1) % 3]] - v
    b = X[F[f, (i + 2) % 3]] - v
    cr = np.cross(a, b)
    out = np.zeros((len(sec.vertex), 3))
    if len(h):
        sid = np.repeat(np.arange(len(sec.vertex)), sec.n_faces)
        np.add.at(out, sid, cr)
    return out


def _unit(A: np.ndarray) -> np.ndarray:
    nrm = np.linalg.norm(A, axis=-1, keepdims=True)
    return np.divide(A, nrm, out=np.zeros_like(A), where=nrm > 0)


def _sector_normals(level: Level, plan: _Plan, X: np.ndarray) -> np.ndarray:
    """Unit normal of every sector whose kind is not SEC_TRANSIENT (rows of those: zero)."""
    sec = plan.sectors
    ns = len(sec.vertex)
    s_, c_, w1, w2 = plan.tangents
    T1 = sp.csr_matrix((w1, (s_, c_)), shape=(ns, level.n_vertices))
    T2 = sp.csr_matrix((w2, (s_, c_)), shape=(ns, level.n_vertices))
    t1, t2 = T1 @ X, T2 @ X
    nrm = np.cross(t1, t2)
    fan = _fan_normals(level, sec, X)
    kind = plan.sec_kind
    corner = kind == SEC_CORNER
    flip = corner & (np.einsum("ij,ij->i", nrm, fan) < 0)
    nrm[flip] *= -1.0
    size = np.linalg.norm(nrm, axis=1)
    scale = np.linalg.norm(t1, axis=1) * np.linalg.norm(t2, axis=1)
    weak = (size <= 1e-12 * scale) | (kind == SEC_FAN)
    nrm[weak] = fan[weak]
    nrm[kind == SEC_TRANSIENT] = 0.0
    return _unit(nrm)


# ---------------------------------------------------------------------------------------------
# Local refinement of the vertices without a stationary mask
# ---------------------------------------------------------------------------------------------


def _estimate(level: Level, sec: _Sectors, X: np.ndarray, sectors: np.ndarray, face_sharp: np.ndarray):
    """Normal estimate of sectors without stationary masks, and where it is the robust one.

    Between two crease edges the runs of √3 (smooth) faces grow by one face per step. For
    each run, with ring ``q_0 … q_r`` (``e_j = q_j − v``), ``(Σ e_j) × (Σ j e_j)`` has, up to
    one common factor, the limit of the run's control fan area vector, and gets there
    geometrically where the fan's own normal creeps (``docs/limit.md``); the runs' vectors
    are summed. Where a run goes (nearly) all the way round — darts, mixed vertices — ``Σ e_j``
    nearly cancels and the estimate is unstable: those sectors, and sectors without a √3 face,
    get the fan normal (``robust`` False). Oriented like the fan normal.
    """
    out = np.zeros((len(sectors), 3))
    if not len(sectors):
        return out, np.zeros(0, dtype=bool)
    fan = _fan_normals(level, sec, X)[sectors]
    nsec = len(sectors)
    k = sec.n_faces[sectors]
    op = sec.open[sectors]
    # Slots of the chosen sectors, cyclic ones rotated to start at a sharp -> smooth change.
    sid = np.repeat(np.arange(nsec), k)
    j = np.arange(k.sum()) - np.repeat(np.cumsum(k) - k, k)
    slot0 = sec.slot_start[sectors]
    smooth_raw = ~face_sharp[sec.slots[np.repeat(slot0, k) + j] // 3]
    prev = np.roll(smooth_raw, 1)
    firsts = np.cumsum(k) - k
    prev[firsts] = smooth_raw[firsts + k - 1]
    change = smooth_raw & ~prev & ~op[sid]
    big = np.iinfo(np.int64).max
    j0 = np.full(nsec, big)
    np.minimum.at(j0, sid[change], j[change])
    j0 = np.where(j0 == big, 0, j0)
    jr = (j + j0[sid]) % k[sid]  # slot index in the sector, after rotation
    ring0 = sec.ring_start[sectors]
    smooth = ~face_sharp[sec.slots[slot0[sid] + jr] // 3]
    # Runs: maximal sequences of smooth slots (no wrap after the rotation).
    prev = np.roll(smooth, 1)
    prev[firsts] = False
    start = smooth & ~prev
    nxt = np.roll(smooth, -1)
    nxt[firsts + k - 1] = False
    end = smooth & ~nxt
    run = np.cumsum(start) - 1
    run_start = j[start]
    n_run = int(start.sum())
    if n_run:
        # Each smooth slot j brings q_j; each run's last slot b brings q_{b+1} as well.
        ent_run = np.r_[run[smooth], run[end]]
        ent_sec = np.r_[sid[smooth], sid[end]]
        ent_j = np.r_[j[smooth], j[end] + 1]
        ring_len = np.where(op, k + 1, k)[ent_sec]
        ent_q = sec.ring[ring0[ent_sec] + (ent_j + j0[ent_sec]) % ring_len]
        ent_pos = ent_j - run_start[ent_run]
        e = X[ent_q] - X[sec.vertex[sectors[ent_sec]]]
        s1 = np.zeros((n_run, 3))
        s2 = np.zeros((n_run, 3))
        np.add.at(s1, ent_run, e)
        np.add.at(s2, ent_run, ent_pos[:, None] * e)
        est = np.cross(s1, s2)
        run_sec = sid[start]
        np.add.at(out, run_sec, est)
    has_run = np.bincount(sid[smooth], minlength=nsec) > 0
    ends_differ = sec.ring[sec.ring_start[sectors]] != sec.ring[sec.ring_start[sectors + 1] - 1]
    robust = has_run & op & ends_differ
    out[~robust] = fan[~robust]
    flip = np.einsum("ij,ij->i", out, fan) < 0
    out[flip] *= -1.0
    return _unit(out), robust


def _refine_locally(level, tagged, face_sharp, corner, scheme, loop_weights, centers, plan0, X, want_rows,
                    tol, max_levels):
    """Refine the stars of ``centers`` one level at a time with the project's own rules.

    The 1-ring of a vertex after a step depends only on its 1-ring before it (every new
    neighbour is a face point of one of its faces or an edge point of one of its edges, and
    the rules that make them read only that ring and its tags), so each star is refined alone;
    all stars go through ``refine`` together, as one mesh of disjoint pieces.

    Returns ``(rows, normals)``: the limit rows of the centres (CSR, one row per centre, over
    the input vertices; rows of centres that had a stationary mask are empty) and, for every
    level-0 sector, its normal estimate (zero where it was not asked for).
    """
    n0 = level.n_vertices
    sec0 = plan0.sectors
    nc = len(centers)
    cidx = np.arange(nc)
    lens = level.origin_start[centers + 1] - level.origin_start[centers]
    star = np.repeat(cidx, lens)
    offs = np.arange(lens.sum()) - np.repeat(np.cumsum(lens) - lens, lens)
    h = level.by_origin[np.repeat(level.origin_start[centers], lens) + offs]
    f = h // 3
    face_sec0 = sec0.he_sector[h]  # the level-0 sector of the centre each star face lies in
    key = star[:, None] * n0 + level.faces[f]
    uniq, inv = np.unique(key, return_inverse=True)
    Uf = inv.reshape(-1, 3).astype(np.int64)
    gid = uniq % n0
    cl = np.searchsorted(uniq, cidx * n0 + centers)  # local id of each centre
    he = (3 * f[:, None] + np.arange(3)[None, :]).ravel()
    s = tagged[level.edge_of[he]]
    pairs = np.stack([Uf.ravel(), Uf[:, [1, 2, 0]].ravel()], axis=1)[s > 0]
    sharp = s[s > 0]
    fs = face_sharp[f].copy()
    nl = len(uniq)
    star_f = star
    want_nrm = X is not None
    P = sp.csr_matrix((np.ones(nl), (np.arange(nl), gid)), shape=(nl, n0)) if want_rows else None
    Xl = X[gid] - X[centers][uniq // n0] if want_nrm else None
    is_corner_c = corner[centers]

    need_pos = ~plan0.pos_ok[centers] if want_rows else np.zeros(nc, dtype=bool)
    sec_need = np.zeros(len(sec0.vertex), dtype=bool)
    if want_nrm:
        sec_need = plan0.sec_kind == SEC_TRANSIENT
    need_nrm = np.bincount(np.searchsorted(centers, sec0.vertex[sec_need]), minlength=nc) > 0
    active = need_pos | need_nrm
    out_rows = sp.csr_matrix((nc, n0))
    hist = [None, None]
    ext_prev = None
    nrm_est = np.zeros((len(sec0.vertex), 3))
    nrm_prev = np.full((len(sec0.vertex), 3), np.inf)
    not_converged = 0

    for lev in range(1, max_levels + 1):
        # Drop the stars that are done.
        keepf = active[star_f]
        if not keepf.all():
            Fk = Uf[keepf]
            face_sec0, star_f, fs = face_sec0[keepf], star_f[keepf], fs[keepf]
            used = np.unique(Fk)
            newid = np.full(nl, -1, np.int64)
            newid[used] = np.arange(len(used))
            Uf, nl = newid[Fk], len(used)
            cl = np.where(active, newid[cl], -1)
            P = P[used] if want_rows else None
            Xl = Xl[used] if want_nrm else None
            ok = (newid[pairs] >= 0).all(axis=1)
            pairs, sharp = newid[pairs[ok]], sharp[ok]
        # One step of every star.
        r = refine(Uf, pairs, 1, n_vertices=nl, scheme=scheme, sharpness=sharp, sharp_faces=fs,
                   corners=cl[active & is_corner_c], loop_weights=loop_weights)
        st = r.steps[0]
        is_c = np.zeros(st.n_vertices, dtype=bool)
        is_c[cl[active]] = True
        keep = is_c[st.faces].any(axis=1)  # the new star: the children that touch the centre
        parent = st.face_parent[keep]
        face_sec0, star_f = face_sec0[parent], star_f[parent]
        used = np.unique(st.faces[keep])
        newid = np.full(st.n_vertices, -1, np.int64)
        newid[used] = np.arange(len(used))
        Uf, nl = newid[st.faces[keep]], len(used)
        cl = np.where(active, newid[np.maximum(cl, 0)], -1)
        if want_rows:
            P = (st.matrix @ P)[used]
        if want_nrm:
            star_v = np.empty(nl, np.int64)
            star_v[Uf.ravel()] = np.repeat(star_f, 3)
            Xl = (st.matrix @ Xl)[used]
            Xl = Xl - Xl[cl[star_v]]  # keep each centre at the origin: no cancellation
        ep = st.sharp_edges
        ok = (newid[ep] >= 0).all(axis=1)
        pairs, sharp = newid[ep[ok]], st.sharpness[ok]
        fs = np.asarray(st.sharp_faces)[keep]
        # What each centre is now.
        lvl = build_level(Uf, nl)
        _, esh = _edge_sharpness(lvl, pairs, sharp, scheme)
        cmask = np.zeros(nl, dtype=bool)
        cmask[cl[active & is_corner_c]] = True
        plan = _plan(lvl, esh, fs, cmask, scheme, loop_weights)
        last = lev == max_levels

        if want_rows and (active & need_pos).any():
            todo = np.flatnonzero(active & need_pos)
            stat = plan.pos_ok[cl[todo]]
            sel = sp.csr_matrix((np.ones(len(todo)), (todo, cl[todo])), shape=(nc, nl))
            cur = (sel @ P).tocsr()  # rows of the centres at this level
            fixed = todo[stat]
            if len(fixed):
                rr, cc, ww = plan.rows
                pick = np.isin(rr, cl[fixed])
                W = sp.csr_matrix((ww[pick], (rr[pick], cc[pick])), shape=(nl, nl))
                sel_f = sp.csr_matrix((np.ones(len(fixed)), (fixed, cl[fixed])), shape=(nc, nl))
                out_rows = out_rows + (sel_f @ W @ P)
                need_pos[fixed] = False
            moving = todo[~stat]
            if len(moving) and hist[0] is not None:
                # The rows converge geometrically: extrapolate the tail (Aitken, one ratio per
                # row) and stop when two extrapolations agree.
                d2 = cur - hist[0]
                e2 = np.asarray(abs(d2).sum(axis=1)).ravel()
                if hist[1] is not None:
                    e1 = np.asarray(abs(hist[0] - hist[1]).sum(axis=1)).ravel()
                    rho = np.clip(np.divide(e2, e1, out=np.full(nc, 0.5), where=e1 > 0), 0.0, 0.95)
                else:
                    rho = np.full(nc, 0.5)
                ext = (cur + sp.diags(rho / (1.0 - rho)) @ d2).tocsr()
                err = e2 * rho / (1.0 - rho)
                if ext_prev is not None:
                    err = np.minimum(err, np.asarray(abs(ext - ext_prev).sum(axis=1)).ravel())
                ext_prev = ext
                settled = np.zeros(nc, dtype=bool)
                settled[moving] = plan.settled[cl[moving]]
                finish = moving[((err[moving] < tol) & settled[moving]) | last]
                if len(finish):
                    if last:
                        not_converged += int((err[finish] >= tol).sum())
                    mask = np.zeros(nc)
                    mask[finish] = 1.0
                    out_rows = out_rows + sp.diags(mask) @ ext
                    need_pos[finish] = False
            hist = [cur, hist[0]]

        if want_nrm and (active & need_nrm).any():
            sec = plan.sectors
            ns = len(sec.vertex)
            owner = np.full(nl, -1, np.int64)
            owner[cl[active]] = cidx[active]
            sec_c = owner[sec.vertex]  # centre index of each sector (−1: a rim vertex)
            mine = (sec_c >= 0) & need_nrm[np.maximum(sec_c, 0)]
            est, robust = _estimate(lvl, sec, Xl, np.arange(ns), fs)
            value = np.where((plan.sec_kind != SEC_TRANSIENT)[:, None], _sector_normals(lvl, plan, Xl), est)
            slot_sid = np.repeat(np.arange(ns), sec.n_faces)
            sel = mine[slot_sid]
            tgt = face_sec0[sec.slots[sel] // 3]
            nrm_est[tgt] = value[slot_sid[sel]]
            # A centre is done when all its sectors are stationary or its estimates settle.
            moving_sec = mine & (plan.sec_kind == SEC_TRANSIENT)
            still_moving = np.bincount(sec_c[moving_sec], minlength=nc) > 0
            change = np.zeros(nc)
            tg = np.flatnonzero(sec_need)
            np.maximum.at(change, np.searchsorted(centers, sec0.vertex[tg]),
                          np.abs(nrm_est[tg] - nrm_prev[tg]).max(axis=1))
            settled = np.zeros(nc, dtype=bool)
            settled[active] = plan.settled[cl[active]]
            # Fan normals (darts, mixed vertices) creep towards their limit like 1/levels:
            # they stop after FAN_LEVELS levels (docs/limit.md).
            uses_fan = np.bincount(sec_c[moving_sec & ~robust], minlength=nc) > 0
            fan_done = uses_fan & (lev >= min(FAN_LEVELS, max_levels))
            done = need_nrm & active & (~still_moving | (settled & ((change < tol) & ~uses_fan | fan_done)) | last)
            need_nrm[done] = False
            nrm_prev = nrm_est.copy()
        active = active & (need_pos | need_nrm)
        if not active.any():
            break
    if not_converged:
        warnings.warn(f"the limit positions of {not_converged} vertices did not converge to tol={tol} "
                      f"within max_levels={max_levels} local refinements", RuntimeWarning, stacklevel=3)
    return out_rows.tocsr(), nrm_est


# ---------------------------------------------------------------------------------------------
# The evaluation of one mesh with its tags
# ---------------------------------------------------------------------------------------------


def _evaluate(level, tagged, esharp, face_sharp, corner, scheme, loop_weights, X, want_rows, tol, max_levels):
    """Limit matrix (n × n CSR, or None) and sector normals of one level."""
    n = level.n_vertices
    plan = _plan(level, esharp, face_sharp, corner, scheme, loop_weights)
    L = None
    nrm = _sector_normals(level, plan, X) if X is not None else None
    need = np.zeros(n, dtype=bool)
    if want_rows:
        need |= ~plan.pos_ok
    if X is not None:
        need[plan.sectors.vertex[plan.sec_kind == SEC_TRANSIENT]] = True
    centers = np.flatnonzero(need)
    rows = None
    if len(centers):
        rows, est = _refine_locally(level, tagged, face_sharp, corner, scheme, loop_weights, centers, plan, X,
                                    want_rows, tol, max_levels)
        if X is not None:
            t = plan.sec_kind == SEC_TRANSIENT
            nrm[t] = est[t]
    if want_rows:
        rr, cc, ww = plan.rows
        L = sp.csr_matrix((ww, (rr, cc)), shape=(n, n))
        if rows is not None:
            moved = sp.csr_matrix((np.ones(len(centers)), (centers, np.arange(len(centers)))),
                                  shape=(n, len(centers)))
            L = L + moved @ rows
        L = sp.csr_matrix(L)
        L.sum_duplicates()
        L.sort_indices()
    return L, plan, nrm



# ---------------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class _Setup:
    level: Level | None  # the level evaluated (None: no faces)
    tagged: np.ndarray
    esharp: np.ndarray
    face_sharp: np.ndarray
    corner: np.ndarray
    refinement: object  # the Refinement to the evaluated level
    n_keep: int  # vertices of the requested level
    same_level: bool  # evaluated at the requested level (else one finer: Kobbelt's parity)


def _setup(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights):
    levels = val.check_options(scheme, levels, loop_weights)
    Fi, n = val.as_faces(F, n_vertices)
    # Kobbelt's boundary rule alternates: evaluate where the next step is odd.
    l_eval = levels + (1 if scheme == "sqrt3" and levels % 2 else 0)
    r = refine(Fi, sharp_edges, l_eval, n_vertices=n, scheme=scheme, sharpness=sharpness,
               sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights)
    n_keep = r.steps[levels - 1].n_vertices if levels else n
    faces = r.faces
    n_eval = r.n_vertices
    m = len(faces)
    fsh = np.asarray(r.sharp_faces)
    face_sharp = np.zeros(m, dtype=bool)
    if fsh.dtype == bool:
        face_sharp[:] = fsh
    else:
        face_sharp[fsh] = True
    if scheme == "loop":
        face_sharp[:] = True
    corner = np.zeros(n_eval, dtype=bool)
    corner[np.asarray(r.corners, dtype=np.int64)] = True
    if m == 0:
        return _Setup(None, None, None, face_sharp, corner, r, n_keep, l_eval == levels)
    level = build_level(faces, n_eval)
    tagged, esharp = _edge_sharpness(level, np.asarray(r.sharp_edges, np.int64).reshape(-1, 2),
                                     np.asarray(r.sharpness, np.float64), scheme)
    return _Setup(level, tagged, esharp, face_sharp, corner, r, n_keep, l_eval == levels)


def _check_tol(tol, max_levels):
    tol = float(tol)
    if not tol > 0:
        raise ValueError(f"tol must be positive, got {tol}")
    if isinstance(max_levels, bool) or int(max_levels) != max_levels or max_levels < 1:
        raise ValueError(f"max_levels must be a positive integer, got {max_levels!r}")
    return tol, int(max_levels)


def _features(V, F, feature_angle, sharp_edges, sharpness, corners):
    if feature_angle is None:
        return sharp_edges, sharpness, corners
    from .._input.features import merge_detected

    return merge_detected(V, F, feature_angle, sharp_edges, sharpness, corners)


def limit_matrix(F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                 n_vertices: int | None = None, scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                 sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                 loop_weights: LoopWeights = "loop", tol: float = 1e-12, max_levels: int = 60) -> sp.csr_matrix:
    """The limit matrix: where every vertex of a level goes when refined forever.

    Parameters
    ----------
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges : (k, 2) array_like of int, optional
        Crease edges (vertex pairs, either orientation), as for :func:`hybridsub.refine`.
    levels : int
        Give the limit positions of the vertices of this level of refinement (0: the input).
    n_vertices : int, optional
        Number of vertices; default ``F.max() + 1``.
    scheme : {"hybrid", "sqrt3", "loop"}
        The subdivision scheme whose limit is meant.
    sharpness, sharp_faces, corners, loop_weights
        As for :func:`hybridsub.refine`.
    tol : float
        Vertices without a stationary limit mask (``docs/limit.md``) are refined locally until
        their weights change by less than this.
    max_levels : int
        At most this many local refinements (a ``RuntimeWarning`` says if ``tol`` was missed).

    Returns
    -------
    L : scipy.sparse.csr_matrix, (n_L, n)
        Limit positions of the level-``levels`` vertices are ``L @ V``. Rows are affine
        (sum to 1) and non-negative (up to rounding where a row was extrapolated).

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])   # tetrahedron
    >>> L = hybridsub.limit_matrix(F, scheme="loop")
    >>> L.shape, np.allclose(L.sum(axis=1), 1)
    ((4, 4), True)
    >>> L[0].toarray().round(4)                     # Loop's limit mask at valence 3
    array([[0.4, 0.2, 0.2, 0.2]])
    """
    tol, max_levels = _check_tol(tol, max_levels)
    s = _setup(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights)
    r = s.refinement
    if s.level is None:
        L = sp.identity(r.n_vertices, format="csr")
    else:
        L, _, _ = _evaluate(s.level, s.tagged, s.esharp, s.face_sharp, s.corner, scheme, loop_weights, None,
                            True, tol, max_levels)
    out = sp.csr_matrix((L @ r.matrix)[: s.n_keep])
    out.sort_indices()
    return out


def limit_positions(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                    scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                    sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                    loop_weights: LoopWeights = "loop", feature_angle: float | None = None, tol: float = 1e-12,
                    max_levels: int = 60) -> np.ndarray:
    """Limit positions of a mesh's vertices: the points of the limit surface they converge to.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights, tol, max_levels
        As for :func:`limit_matrix`.
    feature_angle : float, optional
        Also tag the features :func:`hybridsub.detect_features` finds at this angle (degrees),
        as :func:`hybridsub.subdivide` does.

    Returns
    -------
    (n_L, 3) ndarray
        Limit positions of the vertices of level ``levels`` (in the dtype of ``V`` if it is
        floating-point).

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> P = hybridsub.limit_positions(V, F, scheme="sqrt3")     # Kobbelt: β_3 = 5/8
    >>> P[0] * 6
    array([1., 1., 1.])
    """
    A = np.asarray(V)
    Vf = val.as_vertices(A)
    tol, max_levels = _check_tol(tol, max_levels)
    sharp_edges, sharpness, corners = _features(Vf, F, feature_angle, sharp_edges, sharpness, corners)
    s = _setup(F, sharp_edges, levels, len(Vf), scheme, sharpness, sharp_faces, corners, loop_weights)
    X = s.refinement.apply(Vf)
    if s.level is not None:
        L, _, _ = _evaluate(s.level, s.tagged, s.esharp, s.face_sharp, s.corner, scheme, loop_weights, None,
                            True, tol, max_levels)
        X = L @ X
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    return np.ascontiguousarray(X[: s.n_keep], dtype=out_dtype)


def limit_normals(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                  scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                  sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                  loop_weights: LoopWeights = "loop", feature_angle: float | None = None,
                  per_face_corner: bool = False, tol: float = 1e-10, max_levels: int = 60) -> np.ndarray:
    """Unit normals of the limit surface at the limit positions of a mesh's vertices.

    Smooth vertices get the normal of the limit surface's tangent plane (Kobbelt's and
    Loop's tangent masks). On a crease each side (sector) has its own normal; a vertex gets
    the normalized mean of its sectors' unit normals, ``per_face_corner=True`` gives each
    face corner the normal of its sector (split normals, for shading). ``docs/limit.md``
    says what each kind of vertex gets, and where the limit surface has no tangent plane.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights, feature_angle
        As for :func:`limit_positions`.
    per_face_corner : bool
        Return one normal per face corner, ``(m_L, 3, 3)``, instead of one per vertex.
    tol, max_levels
        For the vertices without stationary tangent masks, refined locally until the normal
        changes by less than ``tol`` (or ``max_levels`` levels).

    Returns
    -------
    (n_L, 3) ndarray, or (m_L, 3, 3) with ``per_face_corner``
        Unit normals on the side the faces face (right-hand rule on ``F``'s order); zero at
        vertices no face uses.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> N = hybridsub.limit_normals(V, F, scheme="loop")
    >>> np.allclose(N, V / np.sqrt(3))                 # outward, by symmetry
    True
    """
    A = np.asarray(V)
    Vf = val.as_vertices(A)
    tol, max_levels = _check_tol(tol, max_levels)
    sharp_edges, sharpness, corners = _features(Vf, F, feature_angle, sharp_edges, sharpness, corners)
    s = _setup(F, sharp_edges, levels, len(Vf), scheme, sharpness, sharp_faces, corners, loop_weights)
    r = s.refinement
    F_out = r.steps[levels - 1].faces if levels else r.faces
    if s.level is None:
        N = np.zeros((s.n_keep, 3))
        return np.zeros((len(F_out), 3, 3)) if per_face_corner else N
    X = r.apply(Vf)
    _, plan, nrm = _evaluate(s.level, s.tagged, s.esharp, s.face_sharp, s.corner, scheme, loop_weights, X,
                             False, tol, max_levels)
    N = np.zeros((s.level.n_vertices, 3))
    np.add.at(N, plan.sectors.vertex, nrm)
    # Sectors facing opposite ways (a fin: a crease that turns back on itself) cancel; there
    # the vertex gets its control fan's normal instead.
    cancel = np.linalg.norm(N, axis=1) < 1e-6
    if cancel.any():
        Fl = s.level.faces
        fn = np.cross(X[Fl[:, 1]] - X[Fl[:, 0]], X[Fl[:, 2]] - X[Fl[:, 0]])
        fan = np.zeros_like(N)
        for i in range(3):
            np.add.at(fan, Fl[:, i], fn)
        N[cancel] = fan[cancel]
    N = _unit(N)
    if per_face_corner:
        if s.same_level:
            return nrm[plan.sectors.he_sector].reshape(-1, 3, 3)
        return N[F_out]
    return N[: s.n_keep]
