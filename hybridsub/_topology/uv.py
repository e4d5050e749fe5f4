"""The face-varying (UV) index mesh of a level: seams, the UV level on the geometry's
halfedges, the UV indices kept as corners, and the UV edges and faces of linear new values.

Textures come as per-corner indices ``T (m, 3)``, aligned face by face with the faces. A
*seam* is an interior edge whose two faces disagree on the UV indices at its ends. The UV
index mesh is a :class:`~hybridsub._topology.level.Level` with the geometry's halfedges and
twins cut along seams, so its boundary is the mesh boundary plus both sides of every seam;
it is built from the geometry's adjacency, never from UV indices alone (a UV index pair that
recurs elsewhere does not glue faces). See ``docs/face_varying.md``.

>>> import numpy as np
>>> from hybridsub._topology.level import checked_level
>>> level = checked_level(np.array([[0, 1, 2], [0, 2, 3]]), 4)
>>> seam_halfedges(level, np.array([[0, 1, 2], [3, 4, 5]])).nonzero()[0].tolist()
[2, 3]
"""

from __future__ import annotations

import numpy as np

from .edges import next_halfedge
from .level import Level


def seam_halfedges(level: Level, T: np.ndarray) -> np.ndarray:
    """(3m,) bool: interior halfedges whose face and twin face disagree on a UV index."""
    twin = level.twin
    h = np.flatnonzero(twin >= 0)
    g = twin[h]
    o = T.ravel()
    nxt = next_halfedge(h)
    gnxt = next_halfedge(g)
    seam = np.zeros(len(twin), dtype=bool)
    seam[h] = (o[h] != o[gnxt]) | (o[nxt] != o[g])
    return seam


def uv_level(level: Level, T: np.ndarray, t: int) -> Level:
    """The UV index mesh as a Level on the geometry's halfedges, twins cut along seams, with
    the geometry's tags (a tag on a seam is moot: seams are UV boundary, creases anyway)."""
    twin = np.where(seam_halfedges(level, T), -1, level.twin)
    return Level(np.ascontiguousarray(T, dtype=np.int64), int(t), twin, level.hsharp, level.face_sharp)


def irregular_uv(level: Level, uvl: Level) -> np.ndarray:
    """(t,) bool: UV indices that cannot be one smooth value, kept as UV corners.

    A UV index used by several separate face sectors around a vertex (more than one UV
    boundary halfedge leaves it), by several geometric vertices (which includes a face
    repeating a UV index), or at a vertex where several fans meet (a bow-tie, a corner of the
    geometry; OpenSubdiv sharpens every face-varying value there too).
    """
    t, n = uvl.n_vertices, max(level.n_vertices, 1)
    o = uvl.faces.ravel()
    fv = level.faces.ravel()
    uv_fans = np.bincount(o[uvl.twin < 0], minlength=t)
    pairs = np.unique(o * np.int64(n) + fv)
    users = np.bincount(pairs // n, minlength=t)
    bowtie = np.bincount(fv[level.twin < 0], minlength=level.n_vertices) > 1
    out = (uv_fans > 1) | (users > 1)
    out[o[bowtie[fv]]] = True
    return out


def carried_corners(level: Level, uvl: Level, corner: np.ndarray) -> np.ndarray:
    """(t,) bool: UV indices at tagged corner vertices."""
    out = np.zeros(uvl.n_vertices, dtype=bool)
    out[uvl.faces.ravel()[corner[level.faces.ravel()]]] = True
    return out


def linear_rows(uvl: Level, plan) -> tuple[np.ndarray, np.ndarray, bool]:
    """The UV edges (k, 2) and UV faces (l, 3) of ``uv_mode="linear"``'s new values, in
    ``plan``'s layout (old values, then edge points, then face points), each row sorted; and
    whether one repeats a UV index (a degenerate UV edge or face)."""
    t = uvl.n_vertices
    h = np.flatnonzero(plan.edge_point >= 0)
    h = h[(uvl.twin[h] < 0) | (h < uvl.twin[h])]  # one halfedge per split edge
    fv = uvl.faces.ravel()
    E = np.empty((len(h), 2), np.int64)
    E[plan.edge_point[h] - t] = np.sort(np.stack([fv[h], fv[next_halfedge(h)]], axis=1), axis=1)
    f = np.flatnonzero(plan.face_point >= 0)
    T = np.empty((len(f), 3), np.int64)
    T[plan.face_point[f] - t - len(h)] = np.sort(uvl.faces[f], axis=1)
    return E, T, bool((E[:, 0] == E[:, 1]).any() or (T[:, :2] == T[:, 1:]).any())


def uv_start(level: Level, T: np.ndarray, t: int, corner: np.ndarray, mode: str = "none") -> tuple[Level, np.ndarray]:
    """The UV index mesh of level 0 and its UV corner mask (t,): carried corner tags,
    irregular UV indices and those the face-varying ``mode`` sharpens (:func:`mode_corners`).
    They keep their status from level to level; new UV values are corners only in
    ``"boundaries"``, on UV boundary edges (:func:`new_uv_corners`)."""
    uvl = uv_level(level, T, t)
    return uvl, carried_corners(level, uvl, corner) | irregular_uv(level, uvl) | mode_corners(level, uvl, mode)


def new_uv_corners(uvl: Level, plan, n_old: int) -> np.ndarray:
    """(plan.n_new − n_old,) bool for ``"boundaries"``: the new values on UV boundary edges."""
    add = np.zeros(plan.n_new - n_old, dtype=bool)
    h = np.flatnonzero((plan.edge_point >= 0) & (uvl.twin < 0))
    add[plan.edge_point[h] - n_old] = True
    return add


def mode_corners(level: Level, uvl: Level, mode: str) -> np.ndarray:
    """(t,) bool: the UV indices a corner-sharpening mode adds to the UV corners of level 0.

    ``"corners_only"``: a UV index used by one face corner (its sector is one face).
    ``"corners_plus1"``: also every UV index at a vertex with more than two UV indices, and
    both at a vertex with two when either sector holds an interior infinitely sharp edge or
    is split in several pieces. ``"corners_plus2"``: also both at a vertex with two when one
    sector is a single face, and the one UV index at the end of a seam inside the mesh (a dart).
    ``"boundaries"``: every UV index at a vertex on a seam or on the mesh boundary.
    ``"none"`` and ``"all"`` add nothing. (OpenSubdiv's rules, ``Vtr::FVarLevel``; the
    semi-sharp dependency of ``corners_plus1/2`` is not included.)
    """
    t, n = uvl.n_vertices, level.n_vertices
    fv, o = level.faces.ravel(), uvl.faces.ravel()
    out = np.zeros(t, dtype=bool)
    if mode in ("none", "all"):
        return out
    if mode == "boundaries":  # every UV index at a vertex on a seam or on the mesh boundary
        at = np.zeros(n, dtype=bool)
        at[fv[uvl.twin < 0]] = True
        out[o[at[fv]]] = True
        return out
    span = np.bincount(o, minlength=t)
    out |= span == 1
    if mode in ("corners_plus1", "corners_plus2"):
        pairs = np.unique(fv * np.int64(t) + o)
        n_values = np.bincount(pairs // t, minlength=n)
        hs = level.hsharp if level.hsharp is not None else np.zeros(len(fv))
        inf_inside = np.bincount(o[(uvl.twin >= 0) & np.isinf(hs)], minlength=t) > 0
        split = np.bincount(o[uvl.twin < 0], minlength=t) > 1
        either = np.zeros(n, dtype=bool)
        either[fv[inf_inside[o] | split[o]]] = True
        sharpen = (n_values > 2) | ((n_values == 2) & either)
        if mode == "corners_plus2":
            seam_end = np.zeros(n, dtype=bool)
            seam_end[fv[(uvl.twin < 0) & (level.twin >= 0)]] = True
            boundary = np.zeros(n, dtype=bool)
            boundary[fv[level.twin < 0]] = True
            single = np.zeros(n, dtype=bool)
            single[fv[span[o] == 1]] = True
            sharpen |= ((n_values == 2) & single) | ((n_values == 1) & ~boundary & seam_end)
        out[o[sharpen[fv]]] = True
    return out
