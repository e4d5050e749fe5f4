"""Closest points on the limit surface, certified by a refined level.

Every rule of every scheme has non-negative weights (SCHEME.md), so the limit surface over a
triangle T of a refined level lies in the convex hull of the level's vertices that reach it,
and so within ``ε_T`` of T: the largest distance from T to a vertex of its ring (one ring
of faces round T for Loop, two for √3 and the hybrid). For a query q whose closest point on
the level is at distance d₀ on T₀, the limit surface has a point within ``d₀ + ε_T₀``; a
triangle with ``dist(q, T) − ε_T`` above that holds no closer limit point. Every input face
that a surviving triangle lies over gets a Newton run from the survivor's closest point
(damped Newton on (face, u, v), across smooth edges, along creases and the boundary, which
are walls), and the best foot wins. ``docs/limit.md`` derives the bound and says how it is
tested.
"""

from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .._input import RefineInput
from .._topology import build_level
from .._refiner import FaceCharts, onto_input_faces, refinement_of
from ._closest_kernels import (bin_faces, closest_among, closest_in_grid, face_rings, faces_within, ring_deviation,
                               survivor_components, survivor_minima)
from .mask_plan import edge_sharpness
from .mesh_closest import _grid
from .limit_setup import LimitSetup
from .level_eval import evaluate_level

#: The certificate's level: the first with at least this many faces (at least one level, at most MAX_LEVELS).
SEED_FACES = 30000
MAX_LEVELS = 6
#: Survivors gathered per point in the first pass (points with more are gathered again, with more room).
KEEP = 64
#: Depth of the descent while the foot point is still far (the last iterations use the full depth).
COARSE_DEPTH = 8
#: The coarse iterations stop at a step this long in space (in diagonals), the fine ones at
#: FINE_STEP (a little above the noise of a step at the full depth).
COARSE_STEP, FINE_STEP = 1e-8, 1e-11
#: Seeds whose coarse foot is within this (in diagonals) of the best go on at the full depth.
COARSE_GAP = 1e-5
#: A foot where the distance's curvature along some direction is below this fraction of a
#: plane's (1 − distance × the surface's curvature there) gets runs from either side along
#: it, at these multiples of the distance (``_weak_minima``).
WEAK = 0.5
WEAK_STARTS = np.array([-0.5, -0.25, 0.25, 0.5])
#: On a wall, a step along it that moves the point by more than this × the distance is taken
#: before any step off it (``_newton_step``).
WALL_FIRST = 1e-6
#: How far a seed at a vertex starts inside its face (towards the centroid, in barycentric units).
SEED_INSET = 0.01
#: Feet within NEAR_EDGE (barycentric) of an edge of their face whose residual has a part
#: above POLISH_TOL × (1 + distance) in the tangent plane get at most POLISH_ITER rounds of
#: ``_polish_near_edges`` (there the chart's derivatives hold only within part of a step).
NEAR_EDGE, POLISH_ITER, POLISH_TOL = 1e-3, 12, 1e-12
#: The longest Newton step in (u, v).
MAX_STEP = 0.5
#: At most this many iterations at the full depth (each costs a full descent).
FINE_ITER = 20
#: Queries farther than this (in diagonals) from the box's centre are moved in along the ray to
#: it, and keep the seeds of their FAR_SEEDS nearest input faces: the distance to their foot is
#: then the least to rounding (``docs/limit.md``), and squared distances stay finite.
FAR, FAR_SEEDS = 1e9, 4


@dataclasses.dataclass(frozen=True, eq=False)
class SeedMesh:
    """The certificate's refined level: its faces, the matrix of its vertices over the control
    vertices, its charts (points on its faces carried onto the input faces), the matrix of its
    vertices' limit points, the vertices that reach the limit surface over each face (CSR:
    ``face_rings``), the input's
    halfedge twins with creases and the boundary as walls (−1), the control vertices that
    faces use, the level's twins with its creases as walls, the
    input's corner vertices (tagged, or on three walls or more), and each input face's side:
    its component of faces joined across edges that are not walls."""

    faces: np.ndarray
    matrix: sp.csr_matrix
    charts: FaceCharts
    limits: sp.csr_matrix
    ring_start: np.ndarray
    ring: np.ndarray
    walls: np.ndarray
    used: np.ndarray
    level_walls: np.ndarray
    cone: np.ndarray
    side: np.ndarray


def seed_levels(n_faces: int, scheme: str) -> int:
    """The certificate's number of levels for an input of ``n_faces`` faces."""
    growth = 4 if scheme == "loop" else 3
    k = 1
    while n_faces * growth**k < SEED_FACES and k < MAX_LEVELS:
        k += 1
    return k


def seed_setup(inp: RefineInput) -> SeedMesh:
    """The :class:`SeedMesh` of ``inp`` (topology only: positions come with each call)."""
    levels = seed_levels(inp.n_faces, inp.scheme)
    r = refinement_of(dataclasses.replace(inp, levels=levels))
    F, n = inp.faces, inp.n_vertices
    charts = FaceCharts(F, n, lambda A, k: build_level(A, k).twin)
    for st in r.steps:
        charts.step(st)
    F, n = charts.F, charts.n
    faces = np.ascontiguousarray(F, dtype=np.int64)
    order = np.argsort(faces.ravel(), kind="stable")
    vf_start = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(faces.ravel(), minlength=n), out=vf_start[1:])
    ring_start, ring = face_rings(faces, vf_start, order // 3, 1 if inp.scheme == "loop" else 2, n)
    level = build_level(faces, n)
    fsh = np.asarray(r.sharp_faces)
    face_sharp = np.zeros(len(faces), dtype=bool)
    if fsh.dtype == bool:
        face_sharp[:] = fsh
    else:
        face_sharp[fsh] = True
    if inp.scheme == "loop":
        face_sharp[:] = True
    corner = np.zeros(n, dtype=bool)
    corner[np.asarray(r.corners, dtype=np.int64)] = True
    if r.corner_sharpness is not None:  # semi-sharp corners: their sharpness left (refined locally)
        corner = np.zeros(n)
        corner[np.asarray(r.corners, dtype=np.int64)] = r.corner_sharpness
    tagged, esharp = edge_sharpness(level, np.asarray(r.sharp_edges, np.int64).reshape(-1, 2),
                                    np.asarray(r.sharpness, np.float64), inp.scheme)
    s = LimitSetup(level, tagged, esharp, face_sharp, corner, r, n, True)
    L, _, _ = evaluate_level(s, inp.scheme, inp.loop_weights, None, True, 1e-12, 60)
    walls = inp.level.twin.copy()
    if inp.level.hsharp is not None:
        walls[np.isinf(inp.level.hsharp)] = -1
    h = np.flatnonzero((walls < 0) & ((inp.level.twin < 0) | (np.arange(len(walls)) < inp.level.twin)))
    ends = np.stack([inp.faces.ravel()[h], inp.faces[h // 3, (h % 3 + 1) % 3]])
    cone = inp.corner | (np.bincount(ends.ravel(), minlength=inp.n_vertices) >= 3)
    level_walls = charts.twin.copy()
    creases = np.asarray(r.sharp_edges, np.int64).reshape(-1, 2)[np.isinf(np.asarray(r.sharpness, np.float64))]
    if len(creases):
        key = np.sort(creases, axis=1) @ np.array([n, 1])
        ends = np.sort(np.stack([faces.ravel(), np.roll(faces, -1, axis=1).ravel()], axis=1), axis=1) @ np.array([n, 1])
        level_walls[np.isin(ends, key)] = -1
    across = np.flatnonzero(walls >= 0)
    n0 = inp.n_faces
    _, side = connected_components(sp.csr_matrix((np.ones(len(across)), (across // 3, walls[across] // 3)),
                                                 shape=(n0, n0)), directed=False)
    return SeedMesh(faces, r.matrix.tocsr(), charts, sp.csr_matrix(L @ r.matrix), ring_start, ring, walls,
                    np.unique(inp.faces), level_walls, cone, side)


def _hessian(r, Du, Dv, Duu, Duv, Dvv):
    """The Hessian (a, b, c) of |x − P|²/2 in (u, v) (``r = x − P``), Gauss–Newton's where the
    full one is not positive definite, and the descent direction's right side (gu, gv)."""
    a0 = np.einsum("ij,ij->i", Du, Du)
    b0 = np.einsum("ij,ij->i", Du, Dv)
    c0 = np.einsum("ij,ij->i", Dv, Dv)
    a = a0 - np.einsum("ij,ij->i", r, Duu)
    b = b0 - np.einsum("ij,ij->i", r, Duv)
    c = c0 - np.einsum("ij,ij->i", r, Dvv)
    spd = (a > 0) & (a * c - b * b > 0)
    full = (a, b, c)
    a, b, c = np.where(spd, a, a0), np.where(spd, b, b0), np.where(spd, c, c0)
    return a, b, c, np.einsum("ij,ij->i", Du, r), np.einsum("ij,ij->i", Dv, r), full, (a0, b0, c0)


def _descent_along_negative_curvature(full, metric):
    """The direction (du, dv) of the most negative curvature of the full Hessian ``full`` (a, b,
    c) relative to the metric ``metric`` (Gauss–Newton's), of unit length in space, and that
    curvature (≥ 0: none negative)."""
    af, bf, cf = full
    a0, b0, c0 = metric
    A = a0 * c0 - b0 * b0
    B = -(af * c0 + cf * a0 - 2 * bf * b0)
    C = af * cf - bf * bf
    A = np.where(A > 0, A, 1.0)
    lam = (-B - np.sqrt(np.maximum(B * B - 4 * A * C, 0.0))) / (2 * A)
    v1 = np.stack([-(bf - lam * b0), af - lam * a0])
    v2 = np.stack([cf - lam * c0, -(bf - lam * b0)])
    v = np.where((np.abs(v1).sum(axis=0) >= np.abs(v2).sum(axis=0))[None], v1, v2)
    size = np.sqrt(np.maximum(a0 * v[0] ** 2 + 2 * b0 * v[0] * v[1] + c0 * v[1] ** 2, 0.0))
    size = np.where(size > 0, size, np.inf)
    return v[0] / size, v[1] / size, lam


#: The direction (du, dv) along the edge opposite each corner (the corner's coordinate constant).
_ALONG = np.array([[1.0, -1.0], [0.0, 1.0], [1.0, 0.0]])


def _newton_step(face, bary, walls, cone_at, r, Du, Dv, Duu, Duv, Dvv):
    """Newton step in (u, v) on |x − P|²/2; on a wall (a crease or boundary edge of the face, the
    point on it) a step out of the face is replaced by Gauss–Newton's step along the wall, at a corner of
    two walls by none, and at a corner vertex (``cone_at`` (k, 3): the face's corners that are
    tagged corners or meet three walls or more) a step on past it by none."""
    a, b, c, gu, gv, full, (a0, b0, c0) = _hessian(r, Du, Dv, Duu, Duv, Dvv)
    det = a * c - b * b
    det = np.where(np.abs(det) > 0, det, 1.0)
    du, dv = (c * gu - b * gv) / det, (a * gv - b * gu) / det
    # Where the distance is stationary but not at a minimum (a saddle: between two feet on a
    # line of symmetry, a query near a centre of curvature) Gauss–Newton's step vanishes and
    # the run would stop there: go down the negative curvature, as far as the distance itself
    # (the damping shortens a step that does not bring the point closer).
    d = np.linalg.norm(r, axis=1)
    step = np.sqrt(np.maximum(a0 * du * du + 2 * b0 * du * dv + c0 * dv * dv, 0.0))
    nu, nv, lam = _descent_along_negative_curvature(full, (a0, b0, c0))
    escape = (lam < 0) & (step < 1e-3 * d) & np.isfinite(nu)
    if escape.any():
        sign = np.where(gu * nu + gv * nv < 0, -1.0, 1.0)  # downhill, or either way at a saddle
        du = np.where(escape, du + sign * d * nu, du)
        dv = np.where(escape, dv + sign * d * nv, dv)
    on_wall = (bary <= 1e-10) & (walls[3 * face[:, None] + (np.arange(3) + 1) % 3] < 0)
    for _ in range(2):
        for j in range(3):
            delta = (-du - dv, du, dv)[j]
            eu, ev = _ALONG[j]
            curv = a0 * eu * eu + 2 * b0 * eu * ev + c0 * ev * ev
            t = (gu * eu + gv * ev) / np.where(curv > 0, curv, 1.0)
            # On a wall the run first goes along it while that moves the point: across a split
            # edge the chart has no derivative, and a step into the face decided by the fitted
            # one would leave the wall before the point is right along it.
            along = np.abs(t) * np.sqrt(np.maximum(curv, 0.0)) > WALL_FIRST * d
            out = on_wall[:, j] & ((delta < 0) | along)
            if out.any():
                du, dv = np.where(out, t * eu, du), np.where(out, t * ev, dv)
    delta = np.stack([-du - dv, du, dv], axis=1)
    stuck = (on_wall & (delta < -1e-300)).any(axis=1)
    stuck |= ((bary >= 1 - 1e-10) & (delta > 0) & cone_at).any(axis=1)
    return np.where(stuck, 0.0, du), np.where(stuck, 0.0, dv)


def _iterate(surface, X, pts, face, bary, depth, max_iter, stop, seeds, point=None, low=None, gap=0.0):
    """Damped Newton at one descent depth: a step that does not bring a point closer is taken
    back and tried again four times shorter; a point stops when its Newton step moves it less
    than ``stop`` (in space, in units of the diagonal).
    Returns the best (face, bary) of each point, its distance, the surface point there and the
    derivatives (Du, Dv, Duu, Duv, Dvv) (k, 5, 3). With ``point`` (k,), the query each row
    belongs to, and ``low`` (k,), a lower bound on the distance each row can reach, a row stops
    (distance ∞) once another row of its query is nearer than ``low − gap``."""
    F0 = surface._inp.faces
    walls, cone = seeds.walls, seeds.cone
    k = len(pts)
    best_f, best_b = face.copy(), bary.copy()
    best_d = np.full(k, np.inf)
    G = np.zeros((k, 5, 3))  # (Du, Dv, Duu, Duv, Dvv) at the best point
    R = np.zeros((k, 3))  # pts − P at the best point
    Pb = np.zeros((k, 3))
    trust = np.ones(k)
    active = np.ones(k, dtype=bool)
    tried = np.ones(k)  # the fraction of its Newton step the row's last trial took
    slope = np.full(k, np.nan)  # (d − best) / tried of the row's last rejected trial
    for _ in range(max_iter):
        idx = np.flatnonzero(active)
        if not len(idx):
            break
        P, *D = surface._applied(face[idx], bary[idx], 6, depth, X, rule_depth=surface.depth)
        d = np.linalg.norm(pts[idx] - P, axis=1)
        # At a vertex or on a wall, a step that changes the distance by rounding only ends the
        # row: it circles the vertex through the faces round it, or the derivatives along a
        # crease (which mean little there) move it along a crease that is level to rounding.
        edge = best_b[idx].min(axis=1) <= 1e-10
        level = (np.isfinite(best_d[idx]) & (np.abs(d - best_d[idx]) <= 1e-15 * best_d[idx])
                 & ((best_b[idx].max(axis=1) >= 1 - 1e-10) | edge))
        better = d <= best_d[idx] * (1 + 1e-14) + 1e-15  # (the data are in units of the diagonal)
        ib = idx[better]
        best_f[ib], best_b[ib], best_d[ib] = face[ib], bary[ib], d[better]
        for j, Dj in enumerate(D):
            G[ib, j] = Dj[better]
        R[ib] = (pts[idx] - P)[better]
        Pb[ib] = P[better]
        trust[ib] = 1.0
        trust[idx[~better]] *= 0.25
        # Rejected trials lie on one ray from the best point. Two of them give the distance's
        # slope there (its quadratic through them): where it rises at first order at a vertex or
        # on a wall (a foot at a corner, or derivatives that mislead the step along a wall), no
        # shorter trial is nearer. (Inside a face a short enough step is: next to a corner of
        # the hybrid's creases the chart's derivatives change fast.)
        worse = idx[~better]
        s_new = (d[~better] - best_d[worse]) / tried[worse]
        s_old, t_old = slope[worse], 4.0 * tried[worse]
        g = s_new - (s_old - s_new) * tried[worse] / (t_old - tried[worse])
        rising = (s_new > 0) & (s_old > 0) & (g > 0.5 * s_new) & (d[~better] - best_d[worse] > 1e-12 * best_d[worse])
        at_rim = (best_b[worse].max(axis=1) >= 1 - 1e-10) | (best_b[worse].min(axis=1) <= 1e-10)
        active[worse[rising & at_rim]] = False
        slope[ib] = np.nan
        slope[worse] = s_new
        du, dv = _newton_step(best_f[idx], best_b[idx], walls, cone[F0[best_f[idx]]], R[idx],
                              *(G[idx, j] for j in range(5)))
        size = np.hypot(du, dv)
        scale = trust[idx] * np.minimum(1.0, MAX_STEP / np.maximum(size, 1e-300))
        reach = np.linalg.norm(du[:, None] * G[idx, 0] + dv[:, None] * G[idx, 1], axis=1)
        delta = np.stack([-du - dv, du, dv], axis=1) * scale[:, None]
        # A step out through a wall of the face stops on it (the next one goes along it).
        wall = walls[3 * best_f[idx][:, None] + (np.arange(3) + 1) % 3] < 0
        bb = best_b[idx]
        cut = np.where(wall & (delta < 0), bb / np.where(delta < 0, -delta, 1.0), 1.0).min(axis=1)
        nb = bb + delta * np.minimum(cut, 1.0)[:, None]
        tried[idx] = scale * np.minimum(cut, 1.0)
        face[idx], bary[idx] = onto_input_faces(best_f[idx], nb, walls, F0)
        active[idx[((reach < stop) & better) | level]] = False
        active[idx[trust[idx] < 1e-12]] = False
        if point is not None:
            U = np.full(point.max() + 1, np.inf)
            np.minimum.at(U, point, best_d)
            # (never on its own distance: a row nearer than its own bound is an evaluation off
            # by more than the gap, not a region ruled out)
            out = active & (low - gap > U[point]) & (best_d > U[point])
            active[out] = False
            best_d[out] = np.inf
    return best_f, best_b, best_d, Pb, G


def _tangential(r: np.ndarray, G: np.ndarray) -> np.ndarray:
    """The part of the residuals ``r`` (k, 3) in the tangent planes of the derivatives ``G``
    (k, ≥2, 3): zero at a foot where the distance is stationary."""
    N = np.cross(G[:, 0], G[:, 1])
    size = np.linalg.norm(N, axis=1)
    N = N / np.where(size > 0, size, 1.0)[:, None]
    return r - np.einsum("ij,ij->i", r, N)[:, None] * N


def _polish_near_edges(surface, X, q, face, bary, Qn, G):
    """Gauss–Newton steps from feet within ``NEAR_EDGE`` of an edge of their face (or on it)
    where the distance is not stationary (the residual has a part in the tangent plane), each on the
    chart's derivatives at one of a fan of points round the foot (``_FAN``), the nearest trial
    taken. Beside the hybrid's split edges the equilateral chart is piecewise smooth at the
    scale of the walk's last faces and sheared (a surface point 3e-7 away can be 5e-5 of a
    face away along the edge); a Newton run on the derivatives at the foot can end on a kink
    there, 1e-7 … 1e-6 diagonals from the true foot, while the derivatives of the piece that
    leads to it are those of a point next to it; a run that a step cut short ended on a crease
    wall 1e-5 of a face from its foot, where the wall's derivatives into the face are a fit.
    The trials stay inside the face; only nearer points are taken."""
    r = q - Qn
    d = np.linalg.norm(r, axis=1)
    loose = np.linalg.norm(_tangential(r, G), axis=1) > POLISH_TOL * (1 + d)
    rows = np.flatnonzero((bary.min(axis=1) < NEAR_EDGE) & loose)
    if not len(rows):
        return face, bary, Qn, G
    f, b, x, P, d = face[rows], bary[rows].copy(), q[rows], Qn[rows].copy(), d[rows]
    moved = np.zeros(len(rows), bool)
    live = np.arange(len(rows))
    n = len(_FAN)
    for _ in range(POLISH_ITER):
        if not len(live):
            break
        k, bl = len(live), b[live]
        at = (bl[None] + _FAN[:, None]).reshape(-1, 3)
        fl = np.tile(f[live], n)
        inside = at.min(axis=1) > 0
        Du, Dv = np.zeros((2, len(at), 3))
        if inside.any():
            Du[inside], Dv[inside] = surface._applied(fl[inside], at[inside], 3, surface.depth, X,
                                                      rule_depth=surface.depth)[1:3]
        r = np.tile(x[live] - P[live], (n, 1))
        a, c, e = (np.einsum("ij,ij->i", *pair) for pair in ((Du, Du), (Dv, Dv), (Du, Dv)))
        gu, gv = np.einsum("ij,ij->i", Du, r), np.einsum("ij,ij->i", Dv, r)
        det = a * c - e * e
        ok = inside & (det > 1e-30 * a * c)
        det = np.where(ok, det, 1.0)
        du, dv = np.where(ok, (c * gu - e * gv) / det, 0.0), np.where(ok, (a * gv - e * gu) / det, 0.0)
        delta = np.stack([-du - dv, du, dv], axis=1)
        bt = np.tile(bl, (n, 1))
        cut = np.where(delta < 0, 0.999 * bt / np.where(delta < 0, -delta, 1.0), 1.0).min(axis=1)
        delta *= np.minimum(cut, 1.0)[:, None]
        m = len(_POLISH_SHORTER)
        nb = (bt[None] + _POLISH_SHORTER[:, None, None] * delta[None]).reshape(-1, 3)  # (m × n × k, 3)
        ok = np.tile(ok, m)
        dn = np.full(len(nb), np.inf)
        Pn = np.zeros_like(nb)
        if ok.any():
            Pn[ok] = surface._applied(np.tile(fl, m)[ok], nb[ok], 1, surface.depth, X, rule_depth=surface.depth)[0]
            dn[ok] = np.linalg.norm(np.tile(x[live], (m * n, 1))[ok] - Pn[ok], axis=1)
        dn, Pn, nb = dn.reshape(m * n, k), Pn.reshape(m * n, k, 3), nb.reshape(m * n, k, 3)
        j = np.argmin(dn, axis=0)
        cols = np.arange(k)
        better = dn[j, cols] < d[live]
        i = live[better]
        b[i], P[i], d[i], moved[i] = nb[j, cols][better], Pn[j, cols][better], dn[j, cols][better], True
        live = live[better]
    i = rows[moved]
    if len(i):
        bary[i] = b[moved]
        out = surface._applied(face[i], bary[i], 6, surface.depth, X, rule_depth=surface.depth)
        Qn[i] = out[0]
        G[i] = np.stack(list(out[1:]), axis=1)
    return face, bary, Qn, G


def _fan(radii, n_angles: int) -> np.ndarray:
    """Barycentric offsets of points round a foot: ``n_angles`` directions in (u, v) at each of
    ``radii``, and the foot itself first."""
    t = np.linspace(0, 2 * np.pi, n_angles, endpoint=False)
    du, dv = (np.outer(radii, f(t)).ravel() for f in (np.cos, np.sin))
    return np.vstack([[0.0, 0.0, 0.0], np.c_[-du - dv, du, dv]])


#: Where ``_polish_near_edges`` takes the chart's derivatives round a foot.
_FAN = _fan(np.array([1e-8, 1e-6, 1e-4]), 16)
#: Each of its steps is tried whole and shortened by these factors.
_POLISH_SHORTER = np.array([1.0, 0.5, 0.25])


def _weak_minima(surface, X, q, face, bary, Qn, G, seeds: SeedMesh, max_iter: int):
    """Feet where the distance is nearly level along one direction (the distance's curvature
    there below ``WEAK`` of a plane's: a query near a centre of curvature) may have a nearer
    minimum along it, within the same component: runs from either side of the foot along that
    direction (at ``WEAK_STARTS`` × the distance), the nearest foot kept per query."""
    r = q - Qn
    _, _, _, _, _, full, metric = _hessian(r, *(G[:, j] for j in range(5)))
    nu, nv, lam = _descent_along_negative_curvature(full, metric)
    d = np.linalg.norm(r, axis=1)
    weak = np.flatnonzero((lam < WEAK) & np.isfinite(nu) & (d > 0))
    if not len(weak):
        return face, bary, Qn, G
    rows = np.repeat(weak, len(WEAK_STARTS))
    t = np.tile(WEAK_STARTS, len(weak)) * d[rows]
    du, dv = t * nu[rows], t * nv[rows]
    du, dv = (x * np.minimum(1.0, MAX_STEP / np.maximum(np.hypot(du, dv), 1e-300)) for x in (du, dv))
    b0 = bary[rows]
    delta = np.stack([-du - dv, du, dv], axis=1)
    F0 = surface._inp.faces
    wall = seeds.walls[3 * face[rows][:, None] + (np.arange(3) + 1) % 3] < 0
    cut = np.where(wall & (delta < 0), b0 / np.where(delta < 0, -delta, 1.0), 1.0).min(axis=1)
    f2, b2 = onto_input_faces(face[rows], b0 + delta * np.minimum(cut, 1.0)[:, None], seeds.walls, F0)
    f2, b2, _, _, _ = _iterate(surface, X, q[rows], f2, b2, min(COARSE_DEPTH, surface.depth), max_iter, COARSE_STEP,
                               seeds)
    f2, b2, d2, Q2, G2 = _iterate(surface, X, q[rows], f2, b2, surface.depth, min(max_iter, FINE_ITER), FINE_STEP,
                                  seeds)
    best = np.full(len(q), np.inf)
    np.minimum.at(best, rows, d2)
    for j in np.flatnonzero(d2 < d[rows]):  # (a few rows: queries near a centre of curvature)
        i = rows[j]
        if d2[j] == best[i] and d2[j] < d[i]:
            face[i], bary[i], Qn[i], G[i] = f2[j], b2[j], Q2[j], G2[j]
            d[i] = d2[j]
    return face, bary, Qn, G


#: Seeds this near a cone vertex (largest barycentric coordinate at least CONE_NEAR at a
#: corner vertex of the input) whose component may come within PROBE_WITHIN of the query
#: (its lower bound, in diagonals) also start from the nearest of a fan of probes round it.
CONE_NEAR, PROBE_WITHIN = 0.7, 0.05
_PROBE_R = np.geomspace(3e-2, 1e-5, 11)
_PROBE_T = np.array([0.01, 0.05, 0.15, 0.3, 0.5, 0.7, 0.85, 0.95, 0.99])


def _cone_probes(surface, Xn, q, point, sf, sb, low, seeds, depth):
    """Extra seeds next to corner vertices, for queries near the surface (``CONE_NEAR``): the
    nearest of a fan of points round the corner (distances ``_PROBE_R`` from it, ``_PROBE_T``
    of the way across), one per seed there."""
    F0 = surface._inp.faces
    k = np.argmax(sb, axis=1)
    near = np.flatnonzero((sb.max(axis=1) >= CONE_NEAR) & seeds.cone[F0[sf, k]] & (low < PROBE_WITHIN))
    if not len(near):
        return point, sf, sb, low
    R, T = (a.ravel() for a in np.meshgrid(_PROBE_R, _PROBE_T, indexing="ij"))
    m = len(R)
    kk = np.repeat(k[near], m)
    b = np.zeros((len(near) * m, 3))
    rr, tt = np.tile(R, len(near)), np.tile(T, len(near))
    rows = np.arange(len(b))
    b[rows, kk] = 1 - rr
    b[rows, (kk + 1) % 3] = rr * tt
    b[rows, (kk + 2) % 3] = rr * (1 - tt)
    ff = np.repeat(sf[near], m)
    P = surface._applied(ff, b, 1, depth, Xn, rule_depth=surface.depth)[0]
    d = np.linalg.norm(q[np.repeat(point[near], m)] - P, axis=1).reshape(len(near), m)
    j = np.argmin(d, axis=1)
    pb = b.reshape(len(near), m, 3)[np.arange(len(near)), j]
    return (np.r_[point, point[near]], np.r_[sf, sf[near]], np.r_[sb, pb], np.r_[low, low[near]])


def _frame(X: np.ndarray, seeds: SeedMesh):
    """Centre and scale of the data: the certificate works in units of the diagonal of the box
    of the used control vertices (no overflow or underflow at any scale)."""
    used = X[seeds.used]
    lo, hi = used.min(axis=0), used.max(axis=0)
    centre = 0.5 * lo + 0.5 * hi
    half = np.maximum(np.abs(hi - centre), np.abs(lo - centre))
    m = float(half.max())
    diag = 2 * m * float(np.linalg.norm(half / m)) if m > 0 else 0.0
    return centre, (diag if diag > 0 and np.isfinite(diag) else 1.0)


@dataclasses.dataclass(frozen=True, eq=False)
class LevelState:
    """The certificate's level at one set of control positions: its vertices ``P``, their
    limit points ``limits``, each face's ``eps`` (ε_T) and two grids of cells over the faces."""

    key: bytes
    P: np.ndarray
    limits: np.ndarray
    eps: np.ndarray
    grid: tuple  # the faces' cells: the nearest face of a point
    certificate: tuple  # the faces' cells, their boxes grown by ε_T (certificate_grid)


def level_state(seeds: SeedMesh, Xn: np.ndarray) -> LevelState:
    """The :class:`LevelState` of the control positions ``Xn`` (in units of the diagonal)."""
    P = np.ascontiguousarray(seeds.matrix @ Xn)
    faces = seeds.faces
    eps = np.empty(len(faces))
    ring_deviation(P, faces, seeds.ring_start, seeds.ring, eps)
    lo, h, dims = _grid(P, P[faces])  # (every vertex of a refined level is used)
    start = np.zeros(int(np.prod(dims)) + 1, dtype=np.int64)
    cell_faces = bin_faces(P, faces, np.zeros(len(faces)), lo, h, dims, start)
    return LevelState(_key(Xn), P, np.ascontiguousarray(seeds.limits @ Xn), eps, (lo, h, dims, start, cell_faces),
                      certificate_grid(P, faces, eps))


def certificate_grid(P: np.ndarray, faces: np.ndarray, eps: np.ndarray) -> tuple:
    """The grid of :func:`._closest_kernels.faces_within`: every face in each cell its box
    grown by its ε_T touches, over the grown boxes' extent: ``(lo, h, dims, start, cells)``."""
    tri = P[faces]
    grown = np.concatenate([tri.min(axis=1) - eps[:, None], tri.max(axis=1) + eps[:, None]])
    lo, h, dims = _grid(grown, tri)
    start = np.zeros(int(np.prod(dims)) + 1, dtype=np.int64)
    return lo, h, dims, start, bin_faces(P, faces, eps, lo, h, dims, start)


def _key(Xn: np.ndarray) -> bytes:
    return hashlib.blake2b(np.ascontiguousarray(Xn).tobytes(), digest_size=16).digest()


def candidates(seeds: SeedMesh, state: LevelState, pts: np.ndarray, limit: np.ndarray | None = None):
    """The certificate on the level at ``state``: for each point, the survivors' seeds.

    Returns ``(point, inface, bary, low)``: one seed per point and connected component of
    its surviving triangles (meeting across edges that are not creases; the survivor nearest
    the point), its barycentric coordinates over that input face (in its unfolded chart) and
    the component's lower bound on the distance to the limit surface over it.
    """
    faces, P, eps = seeds.faces, state.P, state.eps
    lo, h, dims, start, cell_faces = state.grid
    m = len(pts)
    f0 = np.full(m, -1, np.int64)
    b0 = np.zeros((m, 3))
    d2 = np.full(m, np.inf)
    closest_in_grid(pts, P, faces, lo, h, dims, start, cell_faces, f0, b0, d2)
    # An upper bound on the distance to the surface: the limit points of the nearest face's corners.
    bound = np.linalg.norm(pts[:, None, :] - state.limits[faces[f0]], axis=2).min(axis=1) * (1 + 1e-15) + 1e-12
    point, tri, lam, dist, lb = _survivors(pts, P, faces, eps, seeds.ring_start, seeds.ring, state.certificate, bound)
    order = np.lexsort((dist, point))
    point, tri, lam, dist, lb = point[order], tri[order], lam[order], dist[order], lb[order]
    start = np.searchsorted(point, np.arange(m + 1))
    label = np.empty(len(tri), np.int64)
    survivor_components(start, tri, seeds.level_walls, np.full(len(faces), -1, np.int64), label)
    low = lb.copy()
    np.minimum.at(low, label, lb)  # each component's lower bound, at its first survivor
    # A seed at every survivor nearer the query than its surviving neighbours (the nearest of
    # each component among them): a component can hold several minima of the distance.
    first = np.empty(len(tri), bool)
    survivor_minima(start, tri, seeds.level_walls, np.full(len(faces), -1, np.int64), first)
    point, tri, lam, low = point[first], tri[first], lam[first], low[label[first]]
    if limit is not None and len(point):  # the nearest ``limit[i]`` seeds of point i (still sorted)
        rank = np.arange(len(point)) - np.searchsorted(point, point)
        keep = rank < limit[point]
        point, tri, lam, low = point[keep], tri[keep], lam[keep], low[keep]
    # The seed: the closest point of the limit points' mesh (vertices at their limit points,
    # nearer the surface than the level) on the survivor and its neighbours this side of walls.
    near = np.c_[tri, seeds.level_walls[3 * tri[:, None] + np.arange(3)] // 3]
    near = -np.sort(-np.where(near >= 0, near, -1), axis=1)  # (−1 ends a row)
    tri2 = np.full(len(tri), -1, np.int64)
    lam2 = np.zeros((len(tri), 3))
    closest_among(np.ascontiguousarray(pts[point]), state.limits, faces, near, tri2, lam2,
                  np.full(len(tri), np.inf))
    g, bary = seeds.charts.points(tri2, lam2)
    return point, g, bary, low


def _survivors(pts, P, faces, eps, ring_start, ring, grid, bound):
    """Every (point, triangle, bary there, distance, lower bound) with the lower bound below ``bound``: the nearest
    ``KEEP`` of each point, then again with four times as many for the points that had more."""
    out = []
    rows = np.arange(len(pts))
    keep = KEEP
    while len(rows):
        m = len(rows)
        cf = np.full((m, keep), -1, np.int64)
        cb = np.zeros((m, keep, 3))
        cd = np.full((m, keep), np.inf)
        cl = np.zeros((m, keep))
        count = np.zeros(m, np.int64)
        faces_within(np.ascontiguousarray(pts[rows]), P, faces, eps, ring_start, ring, *grid,
                     np.ascontiguousarray(bound[rows]), cf, cb, cd, cl, count)
        done = count <= keep
        ok = (np.arange(keep)[None, :] < count[:, None]) & done[:, None]
        out.append((np.repeat(rows, keep)[ok.ravel()], cf[ok], cb[ok], cd[ok], cl[ok]))
        rows, keep = rows[~done], 4 * keep
    return tuple(np.concatenate(a) for a in zip(*out))


def _nearest_per_place(point: np.ndarray, d: np.ndarray, P: np.ndarray, best: np.ndarray,
                       side: np.ndarray | None = None) -> np.ndarray:
    """The coarse runs that go on: those within ``COARSE_GAP`` of their query's ``best``
    distance, of the runs of one query whose feet ``P`` share a cell of ``COARSE_GAP`` (and a
    ``side`` of the walls, if given) the nearest (indices into the runs). Runs on the two sides
    of a crease can end in one cell: at the coarse depth the one across the crease can be the
    nearer, and it cannot reach a foot on this side."""
    go = np.flatnonzero(d <= best[point] + COARSE_GAP)
    go = go[np.argsort(d[go], kind="stable")]
    side = np.zeros(len(point), np.int64) if side is None else side
    _, once = np.unique(np.c_[point[go], side[go], np.round(P[go] / COARSE_GAP)], axis=0, return_index=True)
    return go[once]


def closest_points(surface, X: np.ndarray, pts: np.ndarray, max_iter: int):
    """``(face, bary, Q, dist)`` of the points ``pts`` on the limit surface of ``surface`` with controls ``X``."""
    seeds = surface._seed_setup()
    centre, scale = _frame(X, seeds)
    Xn = (X - centre) / scale
    diff = pts - centre
    size = np.abs(diff).max(axis=1)
    unit = diff / np.where(size > 0, size, 1.0)[:, None]
    length = np.linalg.norm(unit, axis=1)
    with np.errstate(over="ignore"):
        far = size / scale * length > FAR
        q = np.where(far[:, None], unit / np.where(length > 0, length, 1.0)[:, None] * FAR, diff / scale)
    state = surface._level_state
    if state is None or state.key != _key(Xn):
        state = surface._level_state = level_state(seeds, Xn)
    F0 = surface._inp.faces
    point, sf, sb, low = candidates(seeds, state, np.ascontiguousarray(q), np.where(far, FAR_SEEDS, len(F0)))
    sf, sb = onto_input_faces(sf, sb, seeds.walls, F0)
    # A seed at a vertex starts a little inside its face: at an irregular vertex the chart's
    # derivatives are those of the characteristic map at its centre (zero or unbounded), and
    # a Newton step from there goes nowhere useful (a run that belongs at the vertex returns).
    at = sb.max(axis=1) >= 1 - 1e-9
    sb[at] = (1 - SEED_INSET) * sb[at] + SEED_INSET / 3
    coarse = min(COARSE_DEPTH, surface.depth)
    point, sf, sb, low = _cone_probes(surface, Xn, q, point, sf, sb, low, seeds, coarse)
    many = q[point]
    face, bary, d, Pc, _ = _iterate(surface, Xn, many, sf, sb, coarse, max_iter, COARSE_STEP, seeds, point, low,
                                    COARSE_GAP)
    # Every seed whose coarse foot is near the best goes on at the full depth, once per place.
    best = np.full(len(q), np.inf)
    np.minimum.at(best, point, d)
    go = _nearest_per_place(point, d, Pc, best, seeds.side[face])
    point, face, bary = point[go], face[go], bary[go]
    face, bary, d, Qn, G = _iterate(surface, Xn, q[point], face, bary, surface.depth, min(max_iter, FINE_ITER),
                                    FINE_STEP, seeds)
    face, bary, Qn, G = _polish_near_edges(surface, Xn, q[point], face, bary, Qn, G)
    d = np.linalg.norm(q[point] - Qn, axis=1)
    order = np.lexsort((d, point))
    pick = order[np.r_[True, point[order][1:] != point[order][:-1]]]
    face, bary, Qn, G = face[pick], bary[pick], Qn[pick], G[pick]
    face, bary, Qn, G = _weak_minima(surface, Xn, q, face, bary, Qn, G, seeds, max_iter)
    Q = centre + scale * Qn
    N = np.cross(G[:, 0], G[:, 1])
    e = pts - Q
    size = np.abs(e).max(axis=1)
    dist = size * np.linalg.norm(e / np.where(size > 0, size, 1.0)[:, None], axis=1)
    sign = np.where(np.einsum("ij,ij->i", q - Qn, N) < 0, -1.0, 1.0)
    return face, bary, Q, sign * dist
