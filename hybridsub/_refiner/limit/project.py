"""Closest points on the limit surface: seeds from the limit points of a refined level, then
Gauss–Newton on (face, u, v), walking across face boundaries in the rhombus chart."""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.spatial import cKDTree

from ..._input import RefineInput
from ..chart import onto_input_faces
from ..refinement import refinement_of
from .api import LimitSetup, _evaluate
from .plan import edge_sharpness
from ..._topology import build_level

#: Levels of the refined mesh whose limit points seed the search.
SEED_LEVELS = 2
#: Depth of the descent while the foot point is still far (the last iterations use the full depth).
COARSE_DEPTH = 8
#: The coarse iterations stop at this step size in (u, v), the fine ones at FINE_STEP.
COARSE_STEP, FINE_STEP = 1e-7, 1e-11
#: The longest Gauss–Newton step in (u, v).
MAX_STEP = 0.5
#: At most this many iterations at the full depth (each costs a full descent).
FINE_ITER = 6


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


def _newton_step(P, Du, Dv, x):
    """Gauss–Newton step in (u, v) towards the foot point of ``x``."""
    r = x - P
    a = np.einsum("ij,ij->i", Du, Du)
    b = np.einsum("ij,ij->i", Du, Dv)
    c = np.einsum("ij,ij->i", Dv, Dv)
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
    """Gauss–Newton iterations at one descent depth, each point until its step is below ``stop``."""
    inp = surface._inp
    twin0, F0 = inp.level.twin, inp.faces
    active = np.ones(len(pts), dtype=bool)
    for _ in range(max_iter):
        idx = np.flatnonzero(active)
        if not len(idx):
            break
        M, Mu, Mv = surface._matrix(face[idx], bary[idx], True, depth)
        du, dv = _newton_step(M @ X, Mu @ X, Mv @ X, pts[idx])
        size = np.hypot(du, dv)
        scale = np.minimum(1.0, MAX_STEP / np.maximum(size, 1e-300))
        face[idx], bary[idx] = _move(face[idx], bary[idx], du * scale, dv * scale, twin0, F0)
        active[idx[size < stop]] = False
    return face, bary


def closest_points(surface, X: np.ndarray, pts: np.ndarray, max_iter: int):
    """``(face, bary, Q, dist)`` of the points ``pts`` on the limit surface of ``surface`` with controls ``X``."""
    M, sf, sb = surface._seed_setup()
    _, near = cKDTree(M @ X).query(pts)
    face, bary = sf[near].copy(), sb[near].copy()
    face, bary = _iterate(surface, X, pts, face, bary, min(COARSE_DEPTH, surface.depth), max_iter, COARSE_STEP)
    face, bary = _iterate(surface, X, pts, face, bary, surface.depth, min(max_iter, FINE_ITER), FINE_STEP)
    Q, Du, Dv = surface.evaluate(face, bary, derivatives=True, vertices=X)
    N = np.cross(Du, Dv)
    d = pts - Q
    dist = np.linalg.norm(d, axis=1)
    sign = np.where(np.einsum("ij,ij->i", d, N) < 0, -1.0, 1.0)
    return face, bary, Q, sign * dist
