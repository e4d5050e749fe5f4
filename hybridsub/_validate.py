"""Input checking and conversion for the public API.

Every public function passes its arguments through here first: the caller's arrays are
never modified (everything is converted into fresh arrays when needed), and every problem
becomes a ``MeshError`` (a ``ValueError``) or ``TypeError`` that names it.
"""

from __future__ import annotations

import operator

import numpy as np

from . import _rules as R
from ._errors import MeshError

SCHEMES = ("hybrid", "sqrt3", "loop")


def check_options(scheme, levels, loop_weights) -> int:
    """Validate scheme, levels and loop_weights; return levels as an int."""
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    if loop_weights not in R.LOOP_WEIGHTS:
        raise ValueError(f"loop_weights must be one of {R.LOOP_WEIGHTS}, got {loop_weights!r}")
    if isinstance(levels, (bool, np.bool_)):
        raise TypeError(f"levels must be a non-negative integer, got {levels!r}")
    try:
        levels = operator.index(levels)
    except TypeError:
        raise TypeError(f"levels must be a non-negative integer, got {levels!r}") from None
    if levels < 0:
        raise ValueError(f"levels must be a non-negative integer, got {levels}")
    return levels


def as_vertices(V) -> np.ndarray:
    """(n, 3) float64 C-contiguous copy-or-view of V (never written to)."""
    A = np.asarray(V)
    if A.dtype == object or not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
        raise TypeError(f"V must be a numeric array of shape (n, 3), got dtype {A.dtype}")
    if A.ndim != 2 or A.shape[1] != 3:
        hint = " (2-D points: append a zero z column, e.g. np.c_[V, np.zeros(len(V))])" if (
            A.ndim == 2 and A.shape[1] == 2) else ""
        raise MeshError(f"V must have shape (n, 3), got {A.shape}{hint}")
    A = np.ascontiguousarray(A, dtype=np.float64)
    bad = ~np.isfinite(A).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshError(f"vertex {i} has a non-finite coordinate {A[i].tolist()} ({int(bad.sum())} such vertices)")
    return A


def as_faces(F, n_vertices: int | None) -> tuple[np.ndarray, int]:
    """(m, 3) int64 C-contiguous faces, checked; returns (faces, n_vertices)."""
    A = np.asarray(F)
    if A.ndim != 2 or A.shape[1] != 3:
        if A.ndim == 2 and A.shape[1] > 3:
            raise MeshError(
                f"F must have shape (m, 3), got {A.shape}: hybridsub subdivides triangle meshes; "
                "triangulate polygons first (e.g. a quad (a, b, c, d) becomes (a, b, c) and (a, c, d), "
                "or trimesh.Trimesh(vertices, faces) triangulates on load)"
            )
        raise MeshError(f"F must have shape (m, 3), got {A.shape}")
    if np.issubdtype(A.dtype, np.integer) or A.dtype == bool:
        if A.dtype == bool:
            raise TypeError("F must hold integer vertex indices, got a boolean array")
        if A.size and np.issubdtype(A.dtype, np.unsignedinteger) and A.max() > np.iinfo(np.int64).max:
            raise MeshError(f"F holds an index too large for int64: {A.max()}")
        Fi = np.ascontiguousarray(A, dtype=np.int64)
    elif np.issubdtype(A.dtype, np.floating):
        if not np.isfinite(A).all() or (A != np.round(A)).any():
            f = int(np.flatnonzero(~np.isfinite(A).all(axis=1) | (A != np.round(A)).any(axis=1))[0])
            raise MeshError(f"F must hold integer vertex indices; face {f} is {A[f].tolist()}")
        Fi = np.ascontiguousarray(A, dtype=np.int64)
    else:
        raise TypeError(f"F must be an integer array of shape (m, 3), got dtype {A.dtype}")
    if Fi.size:
        neg = (Fi < 0).any(axis=1)
        if neg.any():
            f = int(np.flatnonzero(neg)[0])
            raise MeshError(f"face {f} has a negative vertex index: {Fi[f].tolist()}")
        top = int(Fi.max())
        if n_vertices is None:
            n_vertices = top + 1
        elif top >= n_vertices:
            f = int(np.flatnonzero((Fi >= n_vertices).any(axis=1))[0])
            raise MeshError(
                f"face {f} = {Fi[f].tolist()} refers to vertex {int(Fi[f].max())}, but there are only "
                f"{n_vertices} vertices (valid indices 0..{n_vertices - 1})"
            )
        rep = (Fi[:, 0] == Fi[:, 1]) | (Fi[:, 1] == Fi[:, 2]) | (Fi[:, 2] == Fi[:, 0])
        if rep.any():
            f = int(np.flatnonzero(rep)[0])
            raise MeshError(
                f"face {f} = {Fi[f].tolist()} repeats a vertex (a degenerate face with {int(rep.sum())} "
                "like it); remove such faces first, e.g. trimesh's mesh.update_faces(mesh.nondegenerate_faces())"
            )
    elif n_vertices is None:
        n_vertices = 0
    n_vertices = operator.index(n_vertices)
    if n_vertices < 0:
        raise ValueError(f"n_vertices must be non-negative, got {n_vertices}")
    return Fi, n_vertices


def as_sharp_edges(sharp_edges, sharpness, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) int64 pairs and (k,) normalized sharpness (inf, or finite in (0, 10))."""
    if sharp_edges is None:
        if sharpness is not None and np.size(sharpness):
            raise ValueError("sharpness was given without sharp_edges")
        return np.empty((0, 2), np.int64), np.empty(0)
    E = np.asarray(sharp_edges)
    if E.size == 0:
        E = E.reshape(0, 2)
    if E.ndim != 2 or E.shape[1] != 2:
        raise MeshError(f"sharp_edges must have shape (k, 2) (vertex pairs), got {E.shape}")
    if not (np.issubdtype(E.dtype, np.integer) or (np.issubdtype(E.dtype, np.floating)
                                                  and np.all(E == np.round(E)))):
        raise TypeError(f"sharp_edges must hold integer vertex indices, got dtype {E.dtype}")
    E = np.ascontiguousarray(E, dtype=np.int64)
    bad = ((E < 0) | (E >= n_vertices)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"sharp edge {j} = {E[j].tolist()} refers to a vertex outside 0..{n_vertices - 1}")
    if sharpness is None:
        s = np.full(len(E), np.inf)
    else:
        s = np.asarray(sharpness, dtype=np.float64).reshape(-1)
        if s.shape != (len(E),):
            raise MeshError(f"sharpness must have one value per sharp edge ({len(E)}), got {s.shape[0]}")
        if np.isnan(s).any():
            raise MeshError(f"sharpness {int(np.flatnonzero(np.isnan(s))[0])} is NaN")
        s = R.normalize_sharpness(s)
    return E, s


def as_face_mask(sharp_faces, n_faces: int) -> tuple[np.ndarray, bool]:
    """Boolean (m,) mask, and whether the caller gave indices (True) or a mask (False)."""
    if sharp_faces is None:
        return np.zeros(n_faces, dtype=bool), False
    A = np.asarray(sharp_faces)
    if A.dtype == bool:
        if A.shape != (n_faces,):
            raise MeshError(f"sharp_faces as a boolean mask must have shape ({n_faces},), got {A.shape}")
        return A.copy(), False
    idx = _indices(A, n_faces, "sharp_faces", "face")
    mask = np.zeros(n_faces, dtype=bool)
    mask[idx] = True
    return mask, True


def as_corner_mask(corners, n_vertices: int) -> np.ndarray:
    mask = np.zeros(n_vertices, dtype=bool)
    if corners is None:
        return mask
    A = np.asarray(corners)
    if A.dtype == bool:
        if A.shape != (n_vertices,):
            raise MeshError(f"corners as a boolean mask must have shape ({n_vertices},), got {A.shape}")
        return A.copy()
    mask[_indices(A, n_vertices, "corners", "vertex")] = True
    return mask


def _indices(A, n: int, name: str, what: str) -> np.ndarray:
    A = A.reshape(-1) if A.ndim <= 1 else A
    if A.ndim != 1:
        raise MeshError(f"{name} must be a 1-D array of {what} indices, got shape {A.shape}")
    if A.size == 0:
        return np.empty(0, np.int64)
    if not (np.issubdtype(A.dtype, np.integer) or (np.issubdtype(A.dtype, np.floating)
                                                  and np.all(A == np.round(A)))):
        raise TypeError(f"{name} must hold integer {what} indices (or be a boolean mask), got dtype {A.dtype}")
    idx = A.astype(np.int64)
    bad = (idx < 0) | (idx >= n)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{name}[{j}] = {idx[j]} is not a {what} index (valid 0..{n - 1})")
    return idx
