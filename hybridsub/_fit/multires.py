"""Multiresolution: least-squares reverse subdivision and details in local frames.

One step of a refinement maps level k to level k + 1 by ``X_{k+1} = S X_k``. Reverse
subdivision (Samavati & Bartels 1999) takes the level k + 1 data back by least squares,
``c = argmin ||S c − X_{k+1}||`` (the normal equations ``SᵀS c = Sᵀ X_{k+1}``, one sparse LU
of ``SᵀS`` per step, kept and reused), and keeps what the coarse level misses as the step's
*details* ``X_{k+1} − S c``. Creases need nothing of their own: each step's ``S`` already
holds their rules, so the coarse level of crease data is a crease of the same kind.

For positions (three columns), the details are written in a local frame of the smooth
level-(k+1) mesh ``S c`` at each of its vertices — tangent, bitangent, normal — so that a
coarse level moved, rotated or deformed carries the detail along (the frame follows the
mesh it is computed on). The frame's tangent points to a fixed neighbour (the next corner of
the vertex's first face), so it turns with the mesh.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._errors import MeshError
from .._input import as_data


@dataclass(frozen=True, eq=False)
class MultiresDetails:
    """The details of :meth:`hybridsub.Refinement.decompose`, one array per step.

    Attributes
    ----------
    levels : tuple of (n_{k+1}, c) float64 arrays
        ``levels[k]``: what level k + 1 holds beyond the refined level k, coarsest first.
        With ``local_frames`` the columns are (tangent, bitangent, normal) coordinates.
    local_frames : bool
        True when the details are in local frames (three-column data, ``frames=True``).
    shape : tuple of int
        Shape of one row of the data (``X.shape[1:]``), restored by ``reconstruct``.
    fingerprint : str
        A hash of the refinement that made them (every step's faces and matrix, so its
        connectivity, scheme, weights and tags): ``reconstruct`` refuses details whose
        fingerprint is not its own refinement's ('' skips the check, for details made by hand).

    A ``MultiresDetails`` is a sequence of its levels: ``len(d)``, ``d[k]``, iteration.
    """

    levels: tuple
    local_frames: bool
    shape: tuple
    fingerprint: str = ""

    def __len__(self) -> int:
        return len(self.levels)

    def __getitem__(self, k):
        return self.levels[k]

    def __iter__(self):
        return iter(self.levels)

    def norms(self) -> np.ndarray:
        """Largest detail length of each level, coarsest first (0 for data the coarse level makes)."""
        return np.array([float(np.sqrt((d * d).sum(axis=1)).max()) if d.size else 0.0 for d in self.levels])


def decompose(steps, n_coarse: int, cache: dict, X, frames: bool | None) -> tuple[np.ndarray, MultiresDetails]:
    """Coarse data and details of finest-level data ``X`` (see :meth:`Refinement.decompose`)."""
    Y, shape = _as_rows(X, steps[-1].n_vertices if steps else n_coarse, "X")
    local = _frames_wanted(frames, Y.shape[1])
    levels = []
    for k in range(len(steps) - 1, -1, -1):
        st = steps[k]
        c = _solve(cache, k, st.matrix, Y)
        refined = st.matrix @ c
        d = Y - refined
        if local:
            d = np.einsum("vij,vj->vi", local_frames(refined, st.faces), d)
        levels.append(d)
        Y = c
    return Y.reshape((n_coarse,) + shape), MultiresDetails(tuple(reversed(levels)), local, shape,
                                                            fingerprint(steps, n_coarse, cache))


def fingerprint(steps, n_coarse: int, cache: dict | None = None) -> str:
    """A hash of a refinement: its coarse vertex count and every step's faces and matrix
    (pattern and weights), which its scheme, weights and tags determine (kept in ``cache``)."""
    if cache is not None and "fingerprint" in cache:
        return cache["fingerprint"]
    h = hashlib.blake2b(digest_size=16)
    h.update(np.int64(n_coarse).tobytes())
    for st in steps:
        S = sp.csr_matrix(st.matrix)
        for a in (np.asarray(S.shape, np.int64), S.indptr.astype(np.int64), S.indices.astype(np.int64),
                  S.data.astype(np.float64), np.ascontiguousarray(st.faces, dtype=np.int64)):
            h.update(np.ascontiguousarray(a).tobytes())
    out = h.hexdigest()
    if cache is not None:
        cache["fingerprint"] = out
    return out


def reconstruct(steps, n_coarse: int, coarse, details: MultiresDetails, cache: dict | None = None) -> np.ndarray:
    """Finest-level data from coarse data and details (see :meth:`Refinement.reconstruct`)."""
    if not isinstance(details, MultiresDetails):
        raise TypeError(f"details must be the MultiresDetails that decompose returned, got {type(details).__name__}")
    if len(details) != len(steps):
        raise ValueError(f"details have {len(details)} levels, the refinement {len(steps)} steps")
    if details.fingerprint and details.fingerprint != fingerprint(steps, n_coarse, cache):
        raise ValueError("details were made by another refinement (other faces, vertex numbering, scheme, weights "
                         "or tags): reconstruct with the Refinement whose decompose made them")
    Y, shape = _as_rows(coarse, n_coarse, "coarse")
    if shape != details.shape:
        raise ValueError(f"coarse rows have shape {shape}, the details were made from rows of shape {details.shape}")
    for k, st in enumerate(steps):
        d = details[k]
        if d.shape != (st.n_vertices, Y.shape[1]):
            raise ValueError(f"details[{k}] must have shape {(st.n_vertices, Y.shape[1])}, got {d.shape}")
        bad = ~np.isfinite(d).all(axis=1)
        if bad.any():
            raise ValueError(f"details[{k}] must be finite; row {int(np.flatnonzero(bad)[0])} is not "
                             f"({int(bad.sum()):,} such rows)")
        refined = st.matrix @ Y
        if details.local_frames:
            d = np.einsum("vij,vi->vj", local_frames(refined, st.faces), d)
        Y = refined + d
    return Y.reshape((len(Y),) + shape)


def local_frames(P: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(n, 3, 3) orthonormal frames, rows (tangent, bitangent, normal), at the vertices of a mesh.

    The normal is the area-weighted vertex normal; the tangent is the edge to the vertex's
    fixed neighbour (the next corner of its first face) projected onto the tangent plane.
    Where the normal vanishes (an unused or degenerate vertex) the frame is the identity;
    where the neighbour lies along the normal, the tangent comes from the axis least aligned
    with it.

    >>> P = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> local_frames(P, np.array([[0, 1, 2]]))[0].round(3).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    n = len(P)
    R = np.zeros((n, 3, 3))
    R[:] = np.eye(3)
    if len(faces) == 0:
        return R
    P = _unit_box(P)  # frames do not change with scale or translation; products of 1e200 would overflow
    fn = np.cross(P[faces[:, 1]] - P[faces[:, 0]], P[faces[:, 2]] - P[faces[:, 0]])
    N = np.zeros((n, 3))
    for i in range(3):
        for d in range(3):
            N[:, d] += np.bincount(faces[:, i], weights=fn[:, d], minlength=n)
    flat = faces.ravel()
    used, first = np.unique(flat, return_index=True)
    neighbour = faces[:, [1, 2, 0]].ravel()[first]
    length = np.linalg.norm(N[used], axis=1)
    scale = np.abs(P[used] - P[neighbour]).max(axis=1)
    ok = length > 1e-300 + 1e-14 * scale * scale
    v, nb = used[ok], neighbour[ok]
    nrm = N[v] / length[ok, None]
    t = P[nb] - P[v]
    t -= (t * nrm).sum(axis=1)[:, None] * nrm
    tl = np.linalg.norm(t, axis=1)
    flat_t = tl <= 1e-12 * np.linalg.norm(P[nb] - P[v], axis=1)
    if flat_t.any():  # the neighbour lies along the normal: the axis least aligned with it
        axis = np.eye(3)[np.argmin(np.abs(nrm[flat_t]), axis=1)]
        t[flat_t] = axis - (axis * nrm[flat_t]).sum(axis=1)[:, None] * nrm[flat_t]
        tl[flat_t] = np.linalg.norm(t[flat_t], axis=1)
    t /= tl[:, None]
    R[v, 0] = t
    R[v, 1] = np.cross(nrm, t)
    R[v, 2] = nrm
    return R


def _unit_box(P: np.ndarray) -> np.ndarray:
    """``P`` moved and scaled into the unit box (its largest extent 1), without squares."""
    lo, hi = P.min(axis=0), P.max(axis=0)
    with np.errstate(over="ignore"):
        extent = float(np.max(hi - lo))
    if not np.isfinite(extent):
        raise ValueError("positions span more than a double can hold (their bounding box overflows)")
    return (P - (lo / 2 + hi / 2)) / extent if extent > 0 else P - lo


def _solve(cache: dict, k: int, S: sp.csr_matrix, Y: np.ndarray) -> np.ndarray:
    """``argmin ||S c − Y||`` by the normal equations, with the step's factor kept in ``cache``."""
    key = ("reverse", k)
    if key not in cache:
        StS = sp.csc_matrix(S.T @ S)
        try:
            import scipy.sparse.linalg as spla  # (imported when used: it costs start-up time)

            cache[key] = spla.splu(StS, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                   options={"SymmetricMode": True})
        except RuntimeError:
            raise MeshError(f"step {k + 1} cannot be reversed: its matrix does not have full column rank "
                            "(some coarse data does not reach the finer level)") from None
    return cache[key].solve(np.ascontiguousarray(S.T @ Y))


def _as_rows(X, n: int, name: str) -> tuple[np.ndarray, tuple]:
    """(n, c) float64 copy of per-vertex real data, and the shape of one row."""
    shape = np.shape(X)
    if len(shape) == 0 or shape[0] != n:
        raise MeshError(f"{name} must have one row per vertex of its level ({n}), got shape {shape}")
    A, _, work = as_data(X, n)
    if work == np.complex128:
        raise TypeError(f"{name} must be real, got dtype {A.dtype}")
    Y = np.array(A, dtype=np.float64).reshape(n, -1)
    if not np.isfinite(Y).all():
        raise ValueError(f"{name} must be finite; row {int(np.flatnonzero(~np.isfinite(Y).all(axis=1))[0])} is not")
    return Y, tuple(A.shape[1:])


def _frames_wanted(frames: bool | None, columns: int) -> bool:
    if frames is None:
        return columns == 3
    if frames and columns != 3:
        raise ValueError(f"frames=True needs positions (three columns), got {columns}")
    return bool(frames)
