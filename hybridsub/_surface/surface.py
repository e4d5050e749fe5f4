"""The limit surface anywhere: :class:`LimitSurface`, evaluated at any (face, bary), with
derivatives, normals and closest points; every value a sparse row over the control vertices."""

from __future__ import annotations

import dataclasses
import threading
import warnings

import numpy as np
import scipy.sparse as sp

from .._errors import MeshError
from .._input import as_vertices, open_gate, writable
from .._typing import ArrayLike, Boundary, LoopWeights, MemoryLimit, NonManifold, Scheme
from .cache import PatchTable
from .depth import PointDepths
from .edge_fit import combine, combine_rows, crease_polygons, curve_along, on_crease_curve, on_split_edge, samples
from .project import closest_points, seed_setup
from .walk import StartKeys, walk_points, walk_rows

#: Points followed down together at most (bounds the memory of one pass).
CHUNK = 20000
#: The first chunk of a new patch cache, before its growth per point is known.
FIRST_CHUNK = 4096
#: The patch cache is emptied between chunks once it holds about this many bytes.
CACHE_BYTES = 2**28

#: The patch cache of each kind of surface (scheme, Loop weights, tolerance, level bound,
#: corners as sharpness): its keys are patch types, not this mesh's patches, so a new surface
#: starts from what the surfaces of its kind made before (a repeated `subdivide_adaptive`, fit
#: or evaluation on the frames of an animation builds no patch twice). At most one per kind,
#: each under ``CACHE_BYTES``; a surface whose cache fills starts a new one for its kind.
_TABLES: dict[tuple, PatchTable] = {}
_TABLES_LOCK = threading.Lock()


def _default_depth(scheme: str) -> int:
    # Chart size after the descent: 3^(-depth/2) for √3 faces, 2^(-depth) for Loop faces.
    return 14 if scheme == "loop" else 18


def unit_normals(Du: np.ndarray, Dv: np.ndarray) -> np.ndarray:
    """Unit ``Du × Dv`` per row (zero where it vanishes), from tangents scaled to unit size
    first, so that neither huge nor tiny coordinates overflow or underflow the product."""
    su = np.abs(Du).max(axis=1, keepdims=True)
    sv = np.abs(Dv).max(axis=1, keepdims=True)
    U = np.divide(Du, su, out=np.zeros_like(Du), where=su > 0)
    W = np.divide(Dv, sv, out=np.zeros_like(Dv), where=sv > 0)
    N = np.cross(U, W)
    norm = np.linalg.norm(N, axis=1, keepdims=True)
    return np.divide(N, norm, out=np.zeros_like(N), where=norm > 0)


def _numbers(a, name: str) -> np.ndarray:
    """``a`` as a float64 array, or a TypeError naming the argument."""
    try:
        return np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be an array of numbers ({e})") from None


class LimitSurface:
    """The limit surface of a control mesh, evaluated at any point of its input faces.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Control vertices.
    F : (m, 3) array_like of int
        Triangles, as for :func:`hybridsub.refine`.
    sharp_edges, scheme, sharpness, sharp_faces, corners, loop_weights, non_manifold, max_memory
        As for :func:`hybridsub.refine`; every scheme and tag. With ``non_manifold="cut"`` the
        surface is that of the cut mesh (its faces are the input's, in the same order), and
        every row or value is still over the caller's vertices.
    feature_angle : float, optional
        Also keep sharp the edges whose dihedral angle exceeds this many degrees, with their
        corners, as for :func:`hybridsub.subdivide`.
    depth : int, optional
        Levels of exact local refinement before the last interpolation (default 18 for
        ``"hybrid"`` and ``"sqrt3"``, 14 for ``"loop"``). Points next to irregular
        vertices and next to split edges beside √3 faces are walked deeper, by a number of
        levels that grows with the log of their distance (at most 56; a smaller ``depth``
        shifts it down): 1e-12 × the diagonal or better everywhere (``docs/limit.md``).
    holes : (m,) bool mask or array_like of int, optional
        Faces not rendered (:func:`hybridsub.refine`): they shape the surface of their
        neighbours as any face does; :meth:`evaluate` (and :meth:`normals`) on a hole is a
        ``MeshError`` naming the point.
    corner_sharpness : (c,) array_like of float, optional
        Sharpness of each of ``corners`` (semi-sharp corners, decaying by one a level), as for
        :func:`hybridsub.refine`: every point is followed through the refinement with its
        patch's vertex sharpness, so the surface is that of :func:`hybridsub.subdivide` refined
        forever (its limit points are :func:`hybridsub.limit_positions`').
    boundary : {"edge_only", "edge_and_corner", "none"}
        OpenSubdiv's boundary interpolation, as for :func:`hybridsub.refine`; with ``"none"``
        the faces at the boundary are holes (evaluating them is a ``MeshError``).

    Notes
    -----
    Points are ``(face, bary)``: ``bary = (1 − u − v, u, v)`` over ``F[face]``; ``∂/∂u``,
    ``∂/∂v`` follow OpenSubdiv's triangle convention (corner 0 at (0, 0), 1 at (1, 0), 2 at
    (0, 1)). Each point is followed through the refinement by exact local refinement with the
    scheme's own rules, then interpolated from exact limit positions six vertices around it
    (or, at a regular Loop patch, given by its exact quartic). Each distinct patch is refined
    once and kept in the surface's patch cache: points near ones already evaluated cost table
    look-ups (``docs/limit.md``).

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> s = hybridsub.LimitSurface(V, F, scheme="loop")
    >>> P = s.evaluate([3, 3], [[1, 0, 0], [1/3, 1/3, 1/3]])
    >>> bool(np.allclose(P[0], hybridsub.limit_positions(V, F, scheme="loop")[1]))
    True
    """

    def __init__(self, V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *,
                 scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
                 corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
                 feature_angle: float | None = None, non_manifold: NonManifold = "raise",
                 max_memory: MemoryLimit = None, depth: int | None = None, holes: ArrayLike | None = None,
                 corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only"):
        X = as_vertices(V)
        inp = open_gate(F, sharp_edges, 0, n_vertices=len(X), scheme=scheme, sharpness=sharpness,
                        sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights,
                        non_manifold=non_manifold, max_memory=max_memory, positions=X, feature_angle=feature_angle,
                        holes=holes, corner_sharpness=corner_sharpness, boundary=boundary)
        self._hole = inp.hole  # (m,) bool or None: evaluate refuses these faces
        self._faces_in, self._copy = inp.faces, None
        if inp.cut is not None:  # the surface of the cut mesh (a manifold input), over the caller's vertices
            self._faces_in, self._copy = inp.uncut.faces, inp.cut.origin
            inp = dataclasses.replace(inp, cut=None, uncut=None)
        self._inp = inp
        self._V = X.copy()
        self._V.setflags(write=False)
        self._seeds = None
        self._level_state = None  # the certificate's level at the last control positions projected on
        if depth is None:
            depth = _default_depth(scheme)
        if isinstance(depth, bool) or int(depth) != depth or depth < 0:
            raise ValueError(f"depth must be a non-negative integer, got {depth!r}")
        self.depth = int(depth) + (int(depth) % 2 if scheme == "sqrt3" else 0)  # Kobbelt: even levels
        self._tol, self._max_levels = 1e-12, 60
        self._depths = PointDepths(self._inp, _default_depth(scheme))
        self._polygons = crease_polygons(self._inp)
        self._new_cache()

    @property
    def vertices(self) -> np.ndarray:
        """The control vertices (n, 3), read-only."""
        return self._V

    @property
    def faces(self) -> np.ndarray:
        """The input faces (m, 3), read-only view."""
        F = self._faces_in.view()
        F.setflags(write=False)
        return F

    @property
    def scheme(self) -> str:
        return self._inp.scheme

    def _points(self, face, bary):
        m = self._inp.n_faces
        f = np.asarray(face)
        if f.dtype.kind not in "iu" and not (f.dtype.kind == "f" and np.all(f == np.round(f))):
            raise TypeError(f"face must be integers, got dtype {f.dtype}")
        f = f.reshape(-1)
        big = np.flatnonzero(~(np.abs(f) < m)) if f.dtype.kind != "i" else np.zeros(0, np.int64)
        if len(big):  # before the cast to int64, which would wrap
            raise ValueError(f"face[{big[0]}] = {f[big[0]]} is not a face (the mesh has {m} faces)")
        f = f.astype(np.int64)
        b = _numbers(bary, "bary")
        if b.ndim == 1 and b.shape[0] == 3 and len(f) == 1:
            b = b[None]
        if b.ndim != 2 or b.shape != (len(f), 3):
            raise ValueError(f"bary must have shape ({len(f)}, 3) to match face, got {b.shape}")
        bad = np.flatnonzero((f < 0) | (f >= m))
        if len(bad):
            raise ValueError(f"face[{bad[0]}] = {f[bad[0]]} is not a face (the mesh has {m} faces)")
        b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
        total = b0 + b1 + b2  # not finite if a coordinate is not
        low = np.minimum(np.minimum(b0, b1), b2)
        bad = np.flatnonzero(~(np.abs(total - 1) <= 1e-9) | (low < -1e-9))
        if len(bad):
            raise ValueError(f"bary[{bad[0]}] = {b[bad[0]].tolist()} is not a point of its face: barycentric "
                             "coordinates must be >= 0 and sum to 1")
        if (low < 0).any():
            b = np.maximum(b, 0.0)
            total = b[:, 0] + b[:, 1] + b[:, 2]
        return f, b / total[:, None]

    def _new_cache(self):
        """The patch cache of this kind of surface (``_surface/cache.py``), a new one when it
        is full: filled as points are evaluated, shared with the surfaces of the same kind."""
        kind = (self._inp.scheme, self._inp.loop_weights, self._tol, self._max_levels,
                self._inp.corner_sharpness is not None)
        with _TABLES_LOCK:
            table = _TABLES.get(kind)
            if table is None or table.nbytes > CACHE_BYTES:
                table = _TABLES[kind] = PatchTable(*kind[:4], vertex_sharpness=kind[4])
        self._table = table
        self._starts = StartKeys(self._inp, self._table)
        self._chunk = getattr(self, "_chunk", CHUNK)

    def _rows(self, f: np.ndarray, b: np.ndarray, derivatives: bool, depth: int):
        return walk_rows(self._table, self._starts, f, b, 3 if derivatives else 1, self._depths(f, b, depth))

    def evaluation_matrix(self, face: ArrayLike, bary: ArrayLike, derivatives: bool = False):
        """The sparse rows that give the limit surface at the points: ``evaluate == M @ V``.

        Parameters
        ----------
        face : (k,) array_like of int
            Input faces.
        bary : (k, 3) array_like of float
            Barycentric coordinates over ``F[face]`` (non-negative, summing to 1).
        derivatives : bool
            Also the rows of ``∂P/∂u`` and ``∂P/∂v``.

        Returns
        -------
        M : scipy.sparse.csr_matrix, (k, n)
            Or ``(M, Mu, Mv)`` with ``derivatives=True``. Rows of ``M`` sum to 1, those of
            ``Mu``, ``Mv`` to 0; they depend on the connectivity and tags only. ``M @ V`` is
            ``evaluate``'s value to the bit; its derivatives agree with ``Mu @ V``, ``Mv @ V``
            to the rows' rounding, which grows like 3^(depth/2): past 24 levels (points next
            to irregular vertices and creases) ``evaluate`` applies them to the data instead,
            keeping their digits (``docs/limit.md``).

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> s = hybridsub.LimitSurface(V, F, sharp_edges=[[0, 1]])
        >>> M = s.evaluation_matrix([0, 3], [[0.2, 0.3, 0.5], [1, 0, 0]])
        >>> M.shape, bool(np.allclose(M.sum(axis=1), 1))
        ((2, 4), True)
        """
        mats = self._matrix(*self._points(face, bary), derivatives, self.depth)
        if self._copy is None:
            return mats
        n, c = len(self._V), self._copy  # the cut mesh's copies are their vertices
        C = sp.csr_matrix((np.ones(len(c)), (np.arange(len(c)), c)), shape=(len(c), n))
        out = [sp.csr_matrix(M @ C) for M in (mats if derivatives else (mats,))]
        for M in out:
            M.sort_indices()
        return tuple(out) if derivatives else out[0]

    def _chunks(self, f: np.ndarray, b: np.ndarray, work) -> list:
        """``work(f, b)`` on chunks of points; the patch cache emptied before a chunk once it
        holds more than ``CACHE_BYTES``. A chunk is sized so that the cache grows by at most
        half that during it, at the growth per point of the last chunk (``FIRST_CHUNK`` points
        on an empty cache, at most ``CHUNK``): points whose keys rarely repeat (the hybrid
        beside creases, some 30 kB a point) go in smaller chunks, the cap holding within a call."""
        out = []
        i = 0
        while i < len(f):
            if self._table.nbytes > CACHE_BYTES:
                self._new_cache()
            size = self._chunk if self._table.n_keys else min(self._chunk, FIRST_CHUNK)
            before = self._table.nbytes
            with self._table.lock:  # shared with other surfaces, perhaps in other threads
                out.append(work(f[i:i + size], b[i:i + size]))
            done = min(size, len(f) - i)
            i += size
            grown = max(self._table.nbytes - before, 0) / done
            self._chunk = CHUNK if grown * CHUNK <= CACHE_BYTES / 2 else max(int(CACHE_BYTES / 2 / grown), min(256, CHUNK))
        return out

    def _matrix(self, f: np.ndarray, b: np.ndarray, derivatives: bool, depth: int):
        chunks = self._chunks(f, b, lambda fc, bc: self._rows(fc, bc, derivatives, depth))
        parts = list(zip(*chunks)) or [()] * (3 if derivatives else 1)
        n = self._inp.n_vertices
        mats = [a[0] if len(a) == 1 else sp.csr_matrix(sp.vstack(a)) if a else sp.csr_matrix((0, n)) for a in parts]
        idx, k = on_split_edge(self._depths, f, b) if derivatives else (np.zeros(0, np.int64), None)
        if len(idx):  # no derivative across the edge in the chart: a fit of exact values (edge_fit.py)
            curve = on_crease_curve(self._polygons, f[idx], k)
            pts, W, A = samples(b[idx], k, curve)
            walked = self._walked_samples(curve, len(pts))
            q = len(idx)
            pick = sp.csr_matrix((np.ones(len(walked)), (walked, np.arange(len(walked)))), shape=(len(pts) * q, len(walked)))
            vals = pick @ self._matrix(np.tile(f[idx], len(pts))[walked], pts.reshape(-1, 3)[walked], False, depth)
            new = combine_rows(W, [mats[0][idx]] + [vals[j * q:(j + 1) * q] for j in range(len(pts))])
            if curve.any():
                cw, cc = curve_along(self._polygons, f[idx[curve]], b[idx[curve]], k[curve])
                R = sp.csr_matrix((cw.ravel(), (np.repeat(np.flatnonzero(curve), 4), cc.ravel())), shape=(q, n))
                new = [sp.csr_matrix(D + sp.diags(A[r]) @ R) for r, D in enumerate(new)]
            keep = np.ones(len(f))
            keep[idx] = 0.0
            put = sp.csr_matrix((np.ones(len(idx)), (idx, np.arange(len(idx)))), shape=(len(f), len(idx)))
            mats[1:] = [sp.csr_matrix(sp.diags(keep) @ M + put @ D) for M, D in zip(mats[1:], new)]
            for M in mats[1:]:
                M.eliminate_zeros()  # the replaced rows
        for M in mats:
            M.sum_duplicates()
            M.sort_indices()
        return tuple(mats) if derivatives else mats[0]

    def evaluate(self, face: ArrayLike, bary: ArrayLike, derivatives: bool = False, *,
                 vertices: ArrayLike | None = None):
        """Points of the limit surface (k, 3); with ``derivatives=True`` also ``∂P/∂u``, ``∂P/∂v``.

        ``vertices`` (n, d) evaluates the same surface with other control positions (or any
        per-vertex data): the rows depend on the connectivity and tags only.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> s = hybridsub.LimitSurface(V, F, scheme="loop")
        >>> P, Du, Dv = s.evaluate([3], [[0.25, 0.25, 0.5]], derivatives=True)
        >>> P.shape, Du.shape
        ((1, 3), (1, 3))
        >>> bool(np.allclose(s.evaluate([3], [[0.25, 0.25, 0.5]], vertices=2 * V), 2 * P))
        True
        """
        X = self._data(vertices)
        f, b = self._points(face, bary)
        if self._hole is not None and self._hole[f].any():
            j = int(np.flatnonzero(self._hole[f])[0])
            raise MeshError(f"face[{j}] = {int(f[j])} is a hole (holes=): the limit surface is not rendered there; "
                            "evaluate its neighbours, or build the LimitSurface without holes")
        n_rows = 3 if derivatives else 1
        res = self._applied(f, b, n_rows, self.depth, X.reshape(len(X), -1))
        res = res.reshape((n_rows, len(f)) + X.shape[1:])
        return tuple(res) if derivatives else res[0]

    def _applied(self, f: np.ndarray, b: np.ndarray, n_rows: int, depth: int, X: np.ndarray,
                 rule_depth: int | None = None) -> np.ndarray:
        """The first ``n_rows`` of value, ∂/∂u, ∂/∂v, ∂²/∂u², ∂²/∂u∂v, ∂²/∂v² applied to the
        data ``X`` (n, d): (n_rows, k, d). ``rule_depth``: see :class:`.depth.PointDepths`."""
        X2 = writable(np.ascontiguousarray(X, dtype=np.float64))
        parts = self._chunks(f, b, lambda fc, bc: walk_points(self._table, self._starts, fc, bc, n_rows,
                                                              self._depths(fc, bc, depth, rule_depth), X2))
        res = np.concatenate(parts, axis=1) if parts else np.zeros((n_rows, 0, X2.shape[1]))
        idx, k = on_split_edge(self._depths, f, b) if n_rows >= 3 else (np.zeros(0, np.int64), None)
        if len(idx):  # no derivative across the edge in the chart: a fit of exact values (edge_fit.py)
            curve = on_crease_curve(self._polygons, f[idx], k)
            pts, W, A = samples(b[idx], k, curve)
            walked = self._walked_samples(curve, len(pts))
            vals = np.zeros((len(pts) * len(idx), X2.shape[1]))
            if len(walked):
                vals[walked] = self._applied(np.tile(f[idx], len(pts))[walked], pts.reshape(-1, 3)[walked], 1, depth,
                                             X2, rule_depth)[0]
            D = combine(W, np.concatenate([res[:1, idx], vals.reshape(len(pts), len(idx), -1)]))
            if curve.any():
                cw, cc = curve_along(self._polygons, f[idx[curve]], b[idx[curve]], k[curve])
                D[:, curve] += A[:, curve, None] * np.einsum("cj,cjd->cd", cw, X2[cc])[None]
            res[1:3, idx] = D
        return res

    @staticmethod
    def _walked_samples(curve: np.ndarray, n_samples: int) -> np.ndarray:
        """Indices into the fit's (n_samples × q) samples that need a walk: not the two along
        a crease curve, whose derivative there is the curve's (``edge_fit.py``)."""
        need = np.ones((n_samples, len(curve)), bool)
        need[:2, curve] = False
        return np.flatnonzero(need.ravel())

    def normals(self, face: ArrayLike, bary: ArrayLike, *, vertices: ArrayLike | None = None) -> np.ndarray:
        """Unit normals ``∂P/∂u × ∂P/∂v`` (k, 3) (one-sided at creases: the given face's side).

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> N = hybridsub.LimitSurface(V, F).normals([3], [[1/3, 1/3, 1/3]])
        >>> N.round(6).tolist()                       # the face (1, 2, 3) faces away from 0
        [[0.57735, 0.57735, 0.57735]]
        """
        if vertices is not None:
            X = np.asarray(vertices)
            if X.ndim != 2 or X.shape[1] != 3:
                raise ValueError(f"normals need (n, 3) vertices, got shape {X.shape}")
        _, Du, Dv = self.evaluate(face, bary, derivatives=True, vertices=vertices)
        return unit_normals(Du, Dv)

    def project(self, points: ArrayLike, *, vertices: ArrayLike | None = None, max_iterations: int = 30,
                max_iter: int | None = None):
        """Closest points of the limit surface: ``(face, bary, Q, dist)``.

        ``dist`` is signed: positive on the side the normals point to. The foot is the
        closest point: a refined level whose faces bound the limit surface over them (its
        convex hull property) rules out every region that cannot hold a nearer point, and
        Newton on (face, u, v) runs in every region that survives, along creases and the
        boundary where the foot lies on them (``docs/limit.md``). ``max_iterations`` (an
        integer, at least 1; the name :func:`hybridsub.fit` uses, ``max_iter`` its deprecated
        alias) bounds the iterations of each run at the coarse descent depth.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> s = hybridsub.LimitSurface(V, F, depth=12)
        >>> P = s.evaluate([3], [[0.3, 0.3, 0.4]]); N = s.normals([3], [[0.3, 0.3, 0.4]])
        >>> face, bary, Q, dist = s.project(P + 0.01 * N)
        >>> bool(np.allclose(Q, P, atol=1e-12)), bool(np.isclose(dist[0], 0.01, atol=1e-12))
        (True, True)
        """
        if max_iter is not None:
            warnings.warn("LimitSurface.project(max_iter=) is deprecated: use max_iterations= (the name fit uses)",
                          DeprecationWarning, stacklevel=2)
            max_iterations = max_iter
        max_iter = max_iterations
        X = self._V if vertices is None else as_vertices(vertices)
        if len(X) != len(self._V):
            raise ValueError(f"vertices must have {len(self._V)} rows (the control mesh's), got {len(X)}")
        X = X if self._copy is None else X[self._copy]
        if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)):
            raise TypeError(f"max_iterations must be an integer, got {max_iter!r}")
        if max_iter < 1:
            raise ValueError(f"max_iterations must be at least 1, got {max_iter}")
        pts = _numbers(points, "points")
        if pts.ndim == 1 and pts.shape == (3,):
            pts = pts[None]
        if pts.ndim != 2 or pts.shape[1] != 3 or not np.isfinite(pts).all():
            raise ValueError(f"points must be a finite (k, 3) array, got shape {pts.shape}")
        return closest_points(self, X, pts, max_iter)

    def _data(self, vertices):
        """The control data of a call over the surface's own vertices (the cut mesh's copies
        under ``non_manifold="cut"``; data already over the copies is taken as it is)."""
        if vertices is None:
            return self._V if self._copy is None else self._V[self._copy]
        X = np.asarray(vertices)
        if X.dtype == object or not (np.issubdtype(X.dtype, np.floating) or np.issubdtype(X.dtype, np.integer)):
            raise TypeError(f"vertices must be a real numeric array, got dtype {X.dtype}")
        X = X.astype(np.float64, copy=False)
        over_copies = self._copy is not None and X.ndim in (1, 2) and X.shape[0] == len(self._copy)
        if not over_copies and (X.ndim not in (1, 2) or X.shape[0] != len(self._V)):
            raise ValueError(f"vertices must have {len(self._V)} rows (the control mesh's), got shape "
                             f"{X.shape}")
        if not np.isfinite(X).all():
            bad = ~np.isfinite(X.reshape(len(X), -1)).all(axis=1)
            i = int(np.flatnonzero(bad)[0])
            raise MeshError(f"vertex {i} has a non-finite value {X[i].tolist()} ({int(bad.sum())} such vertices)")
        return X if over_copies or self._copy is None else X[self._copy]

    def _seed_setup(self):
        """The limit points of two refined levels and where they lie (computed once)."""
        if self._seeds is None:
            self._seeds = seed_setup(self._inp)
        return self._seeds
