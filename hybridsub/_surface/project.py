"""Closest points on the limit surface: seeds from the limit points of a refined level, then
Gauss–Newton on (face, u, v), walking across face boundaries in the rhombus chart."""

from __future__ import annotations

import dataclasses

import numpy as np

from .._input import RefineInput
from .._topology import build_level
from .._refiner import onto_input_faces, refinement_of
from .vertex_limit import LimitSetup, _evaluate
from .mask_plan import edge_sharpness

#: Levels of the refined mesh whose limit points seed the search.
SEED_LEVELS = 2
#: Seeds per point (the nearest limit points of the seed level): far points have several local minima.
SEEDS = 4
#: Depth of the descent while the foot point is still far (the last iterations use the full depth).
COARSE_DEPTH = 8
#: The coarse iterations stop at this step size in (u, v), the fine ones at FINE_STEP.
COARSE_STEP, FINE_STEP = 1e-7, 1e-11
#: The longest Gauss–Newton step in (u, v).
MAX_STEP = 0.5
#: At most this many iterations at the full depth (each costs a full descent).
FINE_ITER = 12


def seed_setup(inp: RefineInput):
    """(limit matrix of the seed level's vertices over the control vertices, their (face, bary))."""
    levels = SEED_LEVELS
    r = refinement_of(dataclasses.replace(inp, levels=levels))
    faces = r.faces
    n = r.n_vertices
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
    tagged, esharp = edge_sharpness(level, np.asarray(r.sharp_edges, np.int64).reshape(-1, 2),
                                    np.asarray(r.sharpness, np.float64), inp.scheme)
    s = LimitSetup(level, tagged, esharp, face_sharp, corner, r, n, True)
    L, _, _ = _evaluate(s, inp.scheme, inp.loop_weights, None, True, 1e-12, 60)
    M = (L @ r.matrix).tocsr()
    face, bary = r.vertex_origin
    used = face >= 0
    return M[used], face[used], bary[used]


def _newton_step(r, Du, Dv, Duu, Duv, Dvv):
    """Newton step in (u, v) on |x − P|²/2 (``r = x − P``); Gauss–Newton where the full
    Hessian is not positive definite."""
    a0 = np.einsum("ij,ij->i", Du, Du)
    b0 = np.einsum("ij,ij->i", Du, Dv)
    c0 = np.einsum("ij,ij->i", Dv, Dv)
    a = a0 - np.einsum("ij,ij->i", r, Duu)
    b = b0 - np.einsum("ij,ij->i", r, Duv)
    c = c0 - np.einsum("ij,ij->i", r, Dvv)
    spd = (a > 0) & (a * c - b * b > 0)
    a, b, c = np.where(spd, a, a0), np.where(spd, b, b0), np.where(spd, c, c0)
    gu = np.einsum("ij,ij->i", Du, r)
    gv = np.einsum("ij,ij->i", Dv, r)
    det = a * c - b * b
    det = np.where(np.abs(det) > 0, det, 1.0)
    return (c * gu - b * gv) / det, (a * gv - b * gu) / det


def _move(face, bary, du, dv, twin0, F0):
    """(u, v) moved by (du, dv), across at most one edge into the face there; clamped at the boundary."""
    nb = bary + np.stack([-du - dv, du, dv], axis=1)
    face, nb = onto_input_faces(face, nb, twin0, F0)
    return face, nb


def _iterate(surface, X, pts, face, bary, depth, max_iter, stop):
    """Damped Gauss–Newton at one descent depth: a step that does not bring a point closer is
    taken back and tried again four times shorter; a point stops when its step is below ``stop``."""
    inp = surface._inp
    twin0, F0 = inp.level.twin, inp.faces
    k = len(pts)
    best_f, best_b = face.copy(), bary.copy()
    best_d = np.full(k, np.inf)
    G = np.zeros((k, 5, 3))  # (Du, Dv, Duu, Duv, Dvv) at the best point
    R = np.zeros((k, 3))  # pts − P at the best point
    trust = np.ones(k)
    active = np.ones(k, dtype=bool)
    for _ in range(max_iter):
        idx = np.flatnonzero(active)
        if not len(idx):
            break
        P, *D = surface._applied(face[idx], bary[idx], 6, depth, X)
        d = np.linalg.norm(pts[idx] - P, axis=1)
        better = d <= best_d[idx] * (1 + 1e-14)
        ib = idx[better]
        best_f[ib], best_b[ib], best_d[ib] = face[ib], bary[ib], d[better]
        for j, Dj in enumerate(D):
            G[ib, j] = Dj[better]
        R[ib] = (pts[idx] - P)[better]
        trust[ib] = np.minimum(1.0, 2.0 * trust[ib])
        trust[idx[~better]] *= 0.25
        du, dv = _newton_step(R[idx], *(G[idx, j] for j in range(5)))
        size = np.hypot(du, dv)
        scale = trust[idx] * np.minimum(1.0, MAX_STEP / np.maximum(size, 1e-300))
        face[idx], bary[idx] = _move(best_f[idx], best_b[idx], du * scale, dv * scale, twin0, F0)
        active[idx[(size < stop) & better]] = False
        active[idx[trust[idx] < 1e-12]] = False
    return best_f, best_b


def closest_points(surface, X: np.ndarray, pts: np.ndarray, max_iter: int):
    """``(face, bary, Q, dist)`` of the points ``pts`` on the limit surface of ``surface`` with controls ``X``."""
    M, sf, sb = surface._seed_setup()
    S = M @ X
    k = min(SEEDS, len(S))
    from scipy.spatial import cKDTree  # (imported when used: it costs start-up time)

    _, near = cKDTree(S).query(pts, k=k)
    near = near.reshape(len(pts), k).ravel()
    many = np.repeat(pts, k, axis=0)
    face, bary = _iterate(surface, X, many, sf[near].copy(), sb[near].copy(), min(COARSE_DEPTH, surface.depth),
                          max_iter, COARSE_STEP)
    # The best of each point's seeds goes on at the full depth.
    d = np.linalg.norm(many - surface._applied(face, bary, 1, min(COARSE_DEPTH, surface.depth), X)[0], axis=1)
    pick = np.arange(len(pts)) * k + np.argmin(d.reshape(len(pts), k), axis=1)
    face, bary = _iterate(surface, X, pts, face[pick], bary[pick], surface.depth, min(max_iter, FINE_ITER),
                          FINE_STEP)
    Q, Du, Dv = surface.evaluate(face, bary, derivatives=True, vertices=X)
    N = np.cross(Du, Dv)
    d = pts - Q
    dist = np.linalg.norm(d, axis=1)
    sign = np.where(np.einsum("ij,ij->i", d, N) < 0, -1.0, 1.0)
    return face, bary, Q, sign * dist
