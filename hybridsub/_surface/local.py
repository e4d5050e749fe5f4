"""Local refinement where no stationary mask exists: the stars of those vertices are refined
alone, with the project's own rules, until their limit rows (extrapolated) and sector normals
settle.

The 1-ring of a vertex after a step depends only on its 1-ring before it (every new
neighbour is a face point of one of its faces or an edge point of one of its edges, and the
rules that make them read only that ring and its tags), so each star is refined alone; all
stars go through ``refine`` together, as one mesh of disjoint pieces.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._rules.step_rules import child_sharpness
from .._topology import Level, build_level, halfedge_ends
from .._refiner import refine
from .normals import run_estimate, sector_normals
from .mask_plan import SEC_TRANSIENT, LimitPlan, edge_sharpness, plan_level

#: Local levels after which the fan normal of a dart or mixed vertex of the hybrid scheme is
#: taken (it has no tangent plane; the fan's normal moves by O(1/levels) per level).
FAN_LEVELS = 16


@dataclass(frozen=True, eq=False)
class _Stars:
    """The stars still refined, as one mesh of disjoint pieces with local vertex ids."""

    faces: np.ndarray  # (f, 3) local ids
    n: int  # local vertices
    centre: np.ndarray  # (nc,) local id of each centre (−1 once its star is dropped)
    star: np.ndarray  # (f,) centre index of each face
    sector0: np.ndarray  # (f,) the level-0 sector of the centre each face lies in
    face_sharp: np.ndarray  # (f,)
    pairs: np.ndarray  # crease edges (local ids) and their sharpness
    sharpness: np.ndarray
    P: sp.csr_matrix | None  # (n, n0) local vertices over the level-0 vertices (rows wanted)
    X: np.ndarray | None  # (n, 3) local positions, each centre at the origin (normals wanted)


def corner_mask(corner: np.ndarray) -> np.ndarray:
    """A corner mask from a mask or from vertex sharpness (float64: > 0 is a corner now)."""
    return corner > 0 if corner.dtype == np.float64 else corner


def semi_sharp(corner: np.ndarray) -> np.ndarray:
    """Vertices whose sharpness is finite and not spent (none for a corner mask)."""
    if corner.dtype != np.float64:
        return np.zeros(len(corner), dtype=bool)
    return (corner > 0) & np.isfinite(corner)


def plan_vertices(level: Level, esharp, face_sharp, corner: np.ndarray, scheme: str, loop_weights: str,
                  only: np.ndarray | None = None) -> LimitPlan:
    """:func:`plan_level` where ``corner`` may be vertex sharpness (float64): a semi-sharp
    vertex (finite sharpness left) has no stationary limit mask (it moves once its sharpness is
    spent), so it is left out of the plan's rows and marked unsettled, to be refined locally.
    ``only``: as for :func:`plan_level`."""
    plan = plan_level(level, esharp, face_sharp, corner_mask(corner), scheme, loop_weights, only)
    semi = semi_sharp(corner)
    if not semi.any():
        return plan
    rr, cc, ww = plan.rows
    keep = ~semi[rr]
    return dataclasses.replace(plan, pos_ok=plan.pos_ok & ~semi, settled=plan.settled & ~semi,
                               rows=(rr[keep], cc[keep], ww[keep]))


def _cut_stars(level: Level, tagged, face_sharp, centers, sectors0, X, want_rows) -> _Stars:
    """The stars (faces around each centre) of ``level``, copied apart."""
    n0 = level.n_vertices
    nc = len(centers)
    cidx = np.arange(nc)
    lens = level.origin_start[centers + 1] - level.origin_start[centers]
    star = np.repeat(cidx, lens)
    offs = np.arange(lens.sum()) - np.repeat(np.cumsum(lens) - lens, lens)
    h = level.by_origin[np.repeat(level.origin_start[centers], lens) + offs]
    f = h // 3
    key = star[:, None] * n0 + level.faces[f]
    uniq, inv = np.unique(key, return_inverse=True)
    Uf = inv.reshape(-1, 3).astype(np.int64)
    gid = uniq % n0
    cl = np.searchsorted(uniq, cidx * n0 + centers)  # local id of each centre
    he = (3 * f[:, None] + np.arange(3)[None, :]).ravel()
    s = tagged[level.edge_of[he]]
    pairs = np.stack(halfedge_ends(Uf), axis=1)[s > 0]
    nl = len(uniq)
    P = sp.csr_matrix((np.ones(nl), (np.arange(nl), gid)), shape=(nl, n0)) if want_rows else None
    Xl = X[gid] - X[centers][uniq // n0] if X is not None else None
    return _Stars(Uf, nl, cl, star, sectors0.he_sector[h], face_sharp[f].copy(), pairs, s[s > 0], P, Xl)


def _renumber(F: np.ndarray, n: int):
    """The vertices ``F`` uses, and the new id of every old one (−1: unused)."""
    used = np.unique(F)
    newid = np.full(n, -1, np.int64)
    newid[used] = np.arange(len(used))
    return used, newid


def _drop(st: _Stars, active: np.ndarray) -> _Stars:
    """The stars of the ``active`` centres only."""
    keepf = active[st.star]
    if keepf.all():
        return st
    Fk = st.faces[keepf]
    used, newid = _renumber(Fk, st.n)
    ok = (newid[st.pairs] >= 0).all(axis=1)
    return _Stars(newid[Fk], len(used), np.where(active, newid[st.centre], -1), st.star[keepf],
                  st.sector0[keepf], st.face_sharp[keepf], newid[st.pairs[ok]], st.sharpness[ok],
                  st.P[used] if st.P is not None else None, st.X[used] if st.X is not None else None)


def _step(st: _Stars, active, sharp_c, scheme, loop_weights) -> _Stars:
    """One step of every star; the new star is the children that touch the centre. ``sharp_c``:
    each centre's vertex sharpness this level (inf: a corner, 0: none)."""
    c = active & (sharp_c > 0)
    r = refine(st.faces, st.pairs, 1, n_vertices=st.n, scheme=scheme, sharpness=st.sharpness,
               sharp_faces=st.face_sharp, corners=st.centre[c], loop_weights=loop_weights,
               corner_sharpness=sharp_c[c] if semi_sharp(sharp_c).any() else None)
    s1 = r.steps[0]
    is_c = np.zeros(s1.n_vertices, dtype=bool)
    is_c[st.centre[active]] = True
    keep = is_c[s1.faces].any(axis=1)
    parent = s1.face_parent[keep]
    star = st.star[parent]
    used, newid = _renumber(s1.faces[keep], s1.n_vertices)
    Uf, nl = newid[s1.faces[keep]], len(used)
    cl = np.where(active, newid[np.maximum(st.centre, 0)], -1)
    P = (s1.matrix @ st.P)[used] if st.P is not None else None
    Xl = None
    if st.X is not None:
        star_v = np.empty(nl, np.int64)
        star_v[Uf.ravel()] = np.repeat(star, 3)
        Xl = (s1.matrix @ st.X)[used]
        Xl = Xl - Xl[cl[star_v]]  # keep each centre at the origin: no cancellation
    ep = s1.sharp_edges
    ok = (newid[ep] >= 0).all(axis=1)
    return _Stars(Uf, nl, cl, star, st.sector0[parent], np.asarray(s1.sharp_faces)[keep], newid[ep[ok]],
                  s1.sharpness[ok], P, Xl)


def _plan_stars(st: _Stars, active, sharp_c, scheme, loop_weights) -> tuple[Level, LimitPlan]:
    """What each centre is now (``sharp_c``: its vertex sharpness this level)."""
    lvl = build_level(st.faces, st.n)
    _, esh = edge_sharpness(lvl, st.pairs, st.sharpness, scheme)
    vs = np.zeros(st.n)
    vs[st.centre[active]] = sharp_c[active]
    return lvl, plan_vertices(lvl, esh, st.face_sharp, vs, scheme, loop_weights)


class _LimitRows:
    """The limit rows of the centres without a stationary limit mask, level by level: taken
    from the plan once a centre has a mask, else extrapolated until they settle."""

    def __init__(self, need: np.ndarray, n0: int, tol: float):
        self.need = need
        self.tol = tol
        self.out = sp.csr_matrix((len(need), n0))
        self.hist = [None, None]
        self.ext_prev = None
        self.not_converged = 0

    def update(self, plan: LimitPlan, st: _Stars, active: np.ndarray, last: bool, trusted: np.ndarray):
        """``trusted``: per centre, whether the last three steps were made from settled tags
        (only then is the history a geometric tail to extrapolate)."""
        todo = np.flatnonzero(active & self.need)
        if not len(todo):
            return
        nc, nl, cl = len(self.need), st.n, st.centre
        stat = plan.pos_ok[cl[todo]]
        sel = sp.csr_matrix((np.ones(len(todo)), (todo, cl[todo])), shape=(nc, nl))
        cur = (sel @ st.P).tocsr()  # rows of the centres at this level
        fixed = todo[stat]
        if len(fixed):
            W = plan.limit_csr(nl, only=cl[fixed])
            sel_f = sp.csr_matrix((np.ones(len(fixed)), (fixed, cl[fixed])), shape=(nc, nl))
            self.out = self.out + (sel_f @ W @ st.P)
            self.need[fixed] = False
        moving = todo[~stat]
        if len(moving) and self.hist[0] is not None:
            self._extrapolate(cur, moving, trusted[moving], last)
        self.hist = [cur, self.hist[0]]

    def _extrapolate(self, cur, moving, settled_moving, last):
        """The rows converge geometrically: extrapolate the tail (Aitken, one ratio per row)
        and finish a row when two extrapolations agree."""
        nc = len(self.need)
        h0, h1 = self.hist
        d2 = cur - h0
        e2 = np.asarray(abs(d2).sum(axis=1)).ravel()
        if h1 is not None:
            e1 = np.asarray(abs(h0 - h1).sum(axis=1)).ravel()
            rho = np.clip(np.divide(e2, e1, out=np.full(nc, 0.5), where=e1 > 0), 0.0, 0.95)
        else:
            rho = np.full(nc, 0.5)
        ext = (cur + sp.diags(rho / (1.0 - rho)) @ d2).tocsr()
        err = e2 * rho / (1.0 - rho)
        if self.ext_prev is not None:
            err = np.minimum(err, np.asarray(abs(ext - self.ext_prev).sum(axis=1)).ravel())
        self.ext_prev = ext
        settled = np.zeros(nc, dtype=bool)
        settled[moving] = settled_moving
        finish = moving[((err[moving] < self.tol) & settled[moving]) | last]
        if len(finish):
            if last:
                self.not_converged += int((err[finish] >= self.tol).sum())
            mask = np.zeros(nc)
            mask[finish] = 1.0
            self.out = self.out + sp.diags(mask) @ ext
            self.need[finish] = False


class _SectorNormals:
    """The normals of the level-0 sectors without stationary tangent masks, level by level:
    the stationary ones once a sector's refined pieces have them, else the runs estimate (or
    the fan normal) until it settles."""

    def __init__(self, plan0: LimitPlan, centers: np.ndarray, tol: float, max_levels: int):
        vertex0 = plan0.sectors.vertex
        self.targets = np.flatnonzero(plan0.sec_kind == SEC_TRANSIENT)
        self.target_centre = np.searchsorted(centers, vertex0[self.targets])
        self.need = np.bincount(self.target_centre, minlength=len(centers)) > 0
        self.est = np.zeros((len(vertex0), 3))
        self.prev = np.full((len(vertex0), 3), np.inf)
        self.tol = tol
        self.max_levels = max_levels

    def update(self, lvl: Level, plan: LimitPlan, st: _Stars, active: np.ndarray, lev: int, last: bool,
               trusted: np.ndarray):
        """``trusted``: per centre, whether the last two steps were made from settled tags."""
        nc = len(self.need)
        sec = plan.sectors
        owner = np.full(st.n, -1, np.int64)
        owner[st.centre[active]] = np.flatnonzero(active)
        sec_c = owner[sec.vertex]  # centre index of each sector (−1: a rim vertex)
        mine = (sec_c >= 0) & self.need[np.maximum(sec_c, 0)]
        est, robust = run_estimate(lvl, sec, st.X, st.face_sharp)
        value = np.where((plan.sec_kind != SEC_TRANSIENT)[:, None], sector_normals(lvl, plan, st.X), est)
        slot_sid = sec.slot_sector
        sel = mine[slot_sid]
        self.est[st.sector0[sec.slots[sel] // 3]] = value[slot_sid[sel]]
        # A centre is done when all its sectors are stationary or its estimates settle.
        moving_sec = mine & (plan.sec_kind == SEC_TRANSIENT)
        still_moving = np.bincount(sec_c[moving_sec], minlength=nc) > 0
        change = np.zeros(nc)
        tg = self.targets
        np.maximum.at(change, self.target_centre, np.abs(self.est[tg] - self.prev[tg]).max(axis=1))
        settled = trusted & active
        # Fan normals (darts, mixed vertices) creep towards their limit like 1/levels:
        # they stop after FAN_LEVELS levels (docs/limit.md).
        uses_fan = np.bincount(sec_c[moving_sec & ~robust], minlength=nc) > 0
        fan_done = uses_fan & (lev >= min(FAN_LEVELS, self.max_levels))
        done = self.need & active & (~still_moving | (settled & ((change < self.tol) & ~uses_fan | fan_done)) | last)
        self.need[done] = False
        self.prev = self.est.copy()


def refine_locally(level: Level, tagged, face_sharp, corner, scheme, loop_weights, centers, plan0: LimitPlan, X,
                   want_rows: bool, tol: float, max_levels: int):
    """Refine the stars of ``centers`` one level at a time with the project's own rules.

    ``corner`` is the corner mask, or each vertex's sharpness (float64: inf a corner, 0 none):
    a semi-sharp centre keeps its sharpness, decaying by one a level, and has its limit row
    once the sharpness is spent (only a vertex's own sharpness shapes its star; ``plan0``
    from :func:`plan_vertices`).

    Returns ``(rows, normals)``: the limit rows of the centres (CSR, one row per centre, over
    the input vertices; rows of centres that had a stationary mask are empty) and, for every
    level-0 sector, its normal estimate (zero where it was not asked for).
    """
    nc = len(centers)
    st = _cut_stars(level, tagged, face_sharp, centers, plan0.sectors, X, want_rows)
    sharp_c = corner[centers] if corner.dtype == np.float64 else np.where(corner[centers], np.inf, 0.0)
    rows = _LimitRows(~plan0.pos_ok[centers] if want_rows else np.zeros(nc, dtype=bool), level.n_vertices, tol)
    nrm = _SectorNormals(plan0, centers, tol, max_levels) if X is not None else None
    need_nrm = nrm.need if nrm is not None else np.zeros(nc, dtype=bool)
    active = rows.need | need_nrm
    # A star's positions converge geometrically only once its tags stop changing: count the
    # steps made from settled tags (with integer sharpness a vertex can stay put for a few
    # levels as a corner and then move, which must not read as converged).
    was_settled = plan0.settled[centers].copy()
    settled_steps = np.zeros(nc, np.int64)
    for lev in range(1, max_levels + 1):
        st = _step(_drop(st, active), active, sharp_c, scheme, loop_weights)
        sharp_c = child_sharpness(sharp_c)
        settled_steps = np.where(was_settled, settled_steps + 1, 0)
        lvl, plan = _plan_stars(st, active, sharp_c, scheme, loop_weights)
        was_settled = np.zeros(nc, dtype=bool)
        was_settled[active] = plan.settled[st.centre[active]]
        last = lev == max_levels
        if want_rows:
            rows.update(plan, st, active, last, settled_steps >= 3)
        if nrm is not None and (active & nrm.need).any():
            nrm.update(lvl, plan, st, active, lev, last, settled_steps >= 2)
        active = active & (rows.need | need_nrm)
        if not active.any():
            break
    if rows.not_converged:
        warnings.warn(f"the limit positions of {rows.not_converged} vertices did not converge to tol={tol} "
                      f"within max_levels={max_levels} local refinements", RuntimeWarning, stacklevel=3)
    return rows.out.tocsr(), (nrm.est if nrm is not None else np.zeros((len(plan0.sectors.vertex), 3)))
