"""Adaptive refinement, the public functions: :func:`refine_adaptive` (a region to a level,
or a tolerance) and :func:`subdivide_adaptive` (positions within a tolerance of the limit).

The engine is :mod:`hybridsub._refiner.adaptive`; this module adds the error criterion, which
needs the limit surface: every output face is compared with the limit surface over it, its
corners with their limit positions, the surface points at its edge midpoints and centroid
with the output triangles round it (``docs/adaptive.md``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .._input import RefineInput, as_vertices, open_gate
from .._refiner import FaceCharts, Refinement, refine, without_holes
from .._refiner.adaptive import AdaptiveMesh, RegionStep, adaptive_refinement
from .._topology import build_level
from .._typing import ArrayLike, Boundary, LoopWeights, MemoryLimit, NonManifold, Scheme, UVMode
from ._closest_kernels import closest_among
from .local import corner_mask, semi_sharp
from .mask_plan import plan_level
from .surface import LimitSurface
from .vertex_limit import limit_positions

#: How much one step divides a face's error by (its size squared): Loop halves edges, √3
#: divides them by √3. Used to predict how many more levels a face needs.
RATE = {True: 4.0, False: 3.0}


class AdaptiveWarning(UserWarning):
    """A tolerance that ``max_levels`` did not reach (the message gives the error reached)."""


def _where_mask(where, m: int) -> np.ndarray:
    """``where`` as an (m,) bool mask: a mask of the input faces or their indices."""
    if where is None:
        raise ValueError("refine_adaptive needs where= (faces to refine) with levels=, or V= with tolerance=")
    A = np.asarray(where)
    if A.dtype == bool:
        if A.shape != (m,):
            raise ValueError(f"where as a boolean mask must have one entry per face, shape ({m},), got {A.shape}")
        return A.copy()
    if A.ndim != 1 or (A.size and A.dtype.kind not in "iu"):
        raise ValueError(f"where must be a boolean mask of the {m} faces or a 1-D array of face indices, "
                         f"got an array of dtype {A.dtype} and shape {A.shape}")
    A = A.astype(np.int64)
    bad = np.flatnonzero((A < 0) | (A >= m))
    if len(bad):
        raise ValueError(f"where[{bad[0]}] = {A[bad[0]]} is not a face (the mesh has {m} faces)")
    mask = np.zeros(m, bool)
    mask[A] = True
    return mask


def tolerance_of(tolerance, V: np.ndarray) -> float:
    """A tolerance in mesh units: a positive finite number, or ``"0.1%"`` of the bounding-box diagonal."""
    if isinstance(tolerance, str):
        text = tolerance.strip()
        try:
            value = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
        except ValueError:
            raise ValueError(f"tolerance must be a positive number or a percentage such as '0.1%', got "
                             f"{tolerance!r}") from None
        if text.endswith("%") and math.isfinite(value) and value > 0:
            diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) if len(V) else 0.0
            if not diag > 0:
                raise ValueError(f"tolerance {tolerance!r} is relative to the bounding-box diagonal, which is 0")
            value *= diag
    elif isinstance(tolerance, (bool, np.bool_)) or not isinstance(tolerance, (int, float, np.integer, np.floating)):
        raise ValueError(f"tolerance must be a positive number (mesh units) or a percentage string, got {tolerance!r}")
    else:
        value = float(tolerance)
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"tolerance must be positive and finite, got {tolerance!r}")
    return value


def _max_levels(max_levels) -> int:
    if isinstance(max_levels, (bool, np.bool_)) or not isinstance(max_levels, (int, np.integer)) or max_levels < 0:
        raise ValueError(f"max_levels must be a non-negative integer, got {max_levels!r}")
    return int(max_levels)


def spread_one_ring(mesh: AdaptiveMesh, want: np.ndarray) -> np.ndarray:
    """Each face's wanted level raised to the largest wanted level of the faces that share a
    vertex with it."""
    at_v = np.zeros(mesh.n_vertices, np.int64)
    np.maximum.at(at_v, mesh.faces.ravel(), np.repeat(want, 3))
    return np.maximum(want, at_v[mesh.faces].max(axis=1))


#: The barycentric coordinates of the midpoint of each edge i → i + 1 of a face.
_EDGE_MIDPOINTS = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])


def distance_to_output(S: np.ndarray, P: np.ndarray, faces: np.ndarray, twin: np.ndarray, near: np.ndarray,
                       hidden: np.ndarray | None = None) -> np.ndarray:
    """How far each surface point ``S[i]`` (m, 3) is from the output mesh ``(P, faces)``, as
    far as face ``near[i]`` and its edge neighbours (``twin``, halfedge twins, -1 on the
    boundary) show: the distance to the nearest of those triangles, an upper bound of the
    distance to the whole output, and chart-free (a surface point the chart puts to the side
    of its face is measured against the face it lies over). Faces ``hidden`` are not output.

    Examples
    --------
    >>> P = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> G = np.array([[0, 1, 2], [1, 3, 2]]); twin = np.array([-1, 5, -1, -1, -1, 1])
    >>> distance_to_output(np.array([[0.9, 0.9, 0.1]]), P, G, twin, np.array([0])).round(6).tolist()
    [0.1]
    """
    cand = np.c_[near, np.where(twin[3 * near[:, None] + np.arange(3)] >= 0,
                                twin[3 * near[:, None] + np.arange(3)] // 3, -1)]
    if hidden is not None:
        cand = np.where((cand >= 0) & hidden[np.maximum(cand, 0)], -1, cand)
    cand = -np.sort(-cand, axis=1)  # (−1 ends a row)
    d2 = np.full(len(S), np.inf)
    closest_among(np.ascontiguousarray(S, dtype=np.float64), np.ascontiguousarray(P, dtype=np.float64),
                  np.ascontiguousarray(faces, dtype=np.int64), np.ascontiguousarray(cand),
                  np.full(len(S), -1, np.int64), np.zeros((len(S), 3)), d2)
    return np.sqrt(d2)


class Criterion:
    """The error criterion, called by the driver at every level (see ``OnLevel``).

    Follows the refinement's positions (level positions, ``S @ V``) and every face's chart;
    the error of a face (its corners at the limit positions with ``limit``, else at their
    level positions) is the largest of its corners' distances to their limit positions and
    the distances of the surface points at its edge midpoints and centroid to the output
    (:func:`distance_to_output`). Errors are taken once, when a face is made: a face's
    vertices never move afterwards.
    """

    def __init__(self, inp: RefineInput, X: np.ndarray, surface: LimitSurface, tolerance: float, limit: bool):
        self.inp, self.surface, self.tol, self.limit = inp, surface, tolerance, limit
        self.charts = FaceCharts(inp.faces, inp.n_vertices, lambda F, n: build_level(F, n).twin)
        self.P = X.copy()  # level positions
        self.Q = X.copy()  # output positions: limit positions where known
        self.known = np.zeros(len(X), bool)
        self.error = np.zeros(inp.n_faces)
        self.done = np.zeros(inp.n_faces, bool)

    def _limits(self, mesh: AdaptiveMesh, faces: np.ndarray, vertices: np.ndarray) -> None:
        """Limit positions of ``vertices``, placed through the charts of ``faces`` (each vertex
        through the first of them that uses it)."""
        f, b = self.charts.vertices(faces, mesh.n_vertices, vertices)
        self.Q[vertices] = self.surface.evaluate(f, b)
        self.known[vertices] = True

    def __call__(self, k: int, mesh: AdaptiveMesh, active: np.ndarray, step: RegionStep | None) -> np.ndarray:
        if step is not None:
            self.charts.step(step)
            self.P = step.matrix @ self.P
            # A vertex's limit position does not depend on its level: only new points need one.
            Q = np.empty_like(self.P)
            Q[:len(self.Q)] = self.Q
            self.Q = Q
            self.known = np.concatenate([self.known, np.zeros(len(self.P) - len(self.known), bool)])
            self.error = self.error[step.face_parent]
            self.done = self.done[step.face_parent] & (mesh.face_level < k)
        fresh = np.flatnonzero(~self.done)
        if self.inp.hole is not None:  # faces not rendered: not measured (error 0)
            hidden = self.inp.hole[mesh.face_parent[fresh]]
            self.error[fresh[hidden]] = 0.0
            self.done[fresh[hidden]] = True
            fresh = fresh[~hidden]
        self._mask_pass(mesh, active, k)
        self.error[fresh] = self._errors(mesh, fresh)
        self.done[fresh] = True
        want = np.zeros(len(mesh.faces), np.int64)
        over = self.error > self.tol
        rate = np.where(mesh.face_sharp, RATE[True], RATE[False])
        more = np.ceil(np.log(self.error[over] / self.tol) / np.log(rate[over])).astype(np.int64)
        want[over] = mesh.face_level[over] + np.maximum(more, 1)
        # The faces round a face over the tolerance are wanted at its level too, so that the
        # closure faces at the region's border are made in faces that are within the tolerance
        # already: a closure face is never refined again, and one over the tolerance would make
        # the driver start again with a wider margin (adaptive_refinement).
        return spread_one_ring(mesh, want)

    def _masked_limits(self, mesh: AdaptiveMesh, active: np.ndarray, P: np.ndarray, todo: np.ndarray):
        """Limit positions by the stationary limit masks (those of ``limit_positions``) of the
        vertices ``todo`` (n,) bool whose faces are all active: their one-ring is the uniform
        level's, at its positions ``P``. Returns the vertices placed and their positions."""
        F = mesh.faces
        af = np.flatnonzero(active)
        none = (np.empty(0, np.int64), np.empty((0, 3)))
        if not len(af):
            return none
        n = mesh.n_vertices
        all_count = np.bincount(F.ravel(), minlength=n)
        act_count = np.bincount(F[af].ravel(), minlength=n)
        todo = (act_count == all_count) & (act_count > 0) & todo
        todo &= ~semi_sharp(mesh.corner)  # no stationary mask: the surface places them
        corner = corner_mask(mesh.corner)
        if not todo.any():
            return none
        ids = np.unique(F[af].ravel())
        local = np.full(n, -1, np.int64)
        local[ids] = np.arange(len(ids))
        h = (3 * af[:, None] + np.arange(3)).ravel()
        level = build_level(local[F[af]], len(ids))
        # A star whose outer edges end the active region would be refined as if they were the
        # boundary (split, not flipped; the boundary rules): its vertex needs every face across
        # its star's edges active too, or the mesh's own boundary there.
        cut = (level.twin < 0) & (mesh.twin[h] >= 0)
        open_face = cut.reshape(-1, 3).any(axis=1)
        bad = np.zeros(n, bool)
        bad[F[af[open_face]].ravel()] = True
        todo &= ~bad
        if not todo.any():
            return none
        owner = level.edge_owner
        hs = mesh.hsharp[h] if mesh.hsharp is not None and self.inp.scheme != "sqrt3" else np.zeros(len(h))
        esharp = np.where(level.twin[owner] < 0, np.inf, hs[owner])
        plan = plan_level(level, esharp, mesh.face_sharp[af], corner[ids], self.inp.scheme,
                          self.inp.loop_weights)
        v = np.flatnonzero(todo)
        v = v[plan.pos_ok[local[v]]]
        if not len(v):
            return none
        L = plan.limit_csr(len(ids), only=local[v])
        return v, (L @ P[ids])[local[v]]

    def _mask_pass(self, mesh: AdaptiveMesh, active: np.ndarray, k: int) -> None:
        todo = ~self.known
        if self.inp.scheme == "sqrt3" and k % 2:
            # Kobbelt's next step trisects the boundary: an inner vertex of a face with a boundary
            # edge gets no face point there, and its one-ring's stationary mask (that of the
            # levels whose next step keeps the boundary) is not its limit; the surface places it.
            # (Boundary vertices are fine: an odd step leaves the boundary polygon as it was.)
            F = mesh.faces
            by_edge = (mesh.twin.reshape(-1, 3) < 0).any(axis=1)
            near = np.zeros(mesh.n_vertices, bool)
            near[F[by_edge].ravel()] = True
            on = np.zeros(mesh.n_vertices, bool)
            on[F.ravel()[mesh.twin < 0]] = True
            todo &= ~(near & ~on)
        v, q = self._masked_limits(mesh, active, self.P, todo)
        self.Q[v] = q
        self.known[v] = True

    def _errors(self, mesh: AdaptiveMesh, fresh: np.ndarray) -> np.ndarray:
        """The error of each face of ``fresh``: its corners against their limit positions,
        and the surface points at its edge midpoints (each edge once) and its centroid
        against the output faces there (:func:`distance_to_output`)."""
        F = mesh.faces
        need = np.unique(F[fresh].ravel())
        need = need[~self.known[need]]
        if len(need):
            self._limits(mesh, fresh, need)
        out = self.Q if self.limit else self.P
        err = np.linalg.norm(out[F[fresh]] - self.Q[F[fresh]], axis=2).max(axis=1)
        hidden = None if self.inp.hole is None else self.inp.hole[mesh.face_parent]
        # Edge midpoints: each edge once, from the face of its higher halfedge when both are fresh.
        h = (3 * fresh[:, None] + np.arange(3)).ravel()
        t = mesh.twin[h]
        is_fresh = np.zeros(len(F), bool)
        is_fresh[fresh] = True
        own = (t < 0) | (t < h) | ~is_fresh[np.maximum(t, 0) // 3]
        ho = h[own]
        f, b = self.charts.points(ho // 3, _EDGE_MIDPOINTS[ho % 3])
        e_half = np.zeros(3 * len(F))
        e_half[ho] = distance_to_output(self.surface.evaluate(f, b), out, F, mesh.twin, ho // 3, hidden)
        shared = ~own & (t >= 0)
        e_half[h[shared]] = e_half[t[shared]]
        err = np.maximum(err, e_half[h].reshape(-1, 3).max(axis=1))
        f, b = self.charts.points(fresh, np.full((len(fresh), 3), 1.0 / 3.0))
        e_c = distance_to_output(self.surface.evaluate(f, b), out, F, mesh.twin, fresh, hidden)
        return np.maximum(err, e_c)

    def positions(self, mesh: AdaptiveMesh) -> np.ndarray:
        """The output positions: limit positions with ``limit``, else level positions."""
        if not self.limit:
            return self.P
        missing = np.flatnonzero(~self.known)
        used = np.zeros(mesh.n_vertices, bool)
        used[mesh.faces.ravel()] = True
        missing = missing[used[missing]]
        if len(missing):
            self._limits(mesh, np.arange(len(mesh.faces)), missing)
        return self.Q


@dataclass(frozen=True, eq=False)
class AdaptiveResult:
    """What a tolerance-driven refinement made: the refinement, the positions, the error."""

    refinement: Refinement
    positions: np.ndarray
    error: float  # the largest face error, over the samples
    tolerance: float


def _by_tolerance(inp: RefineInput, X: np.ndarray, tolerance, max_levels: int, limit: bool) -> AdaptiveResult:
    tol = tolerance_of(tolerance, X)
    sharp_faces = inp.face_sharp if inp.scheme == "hybrid" else None
    if inp.cut is None:
        surface = LimitSurface(X, inp.faces, inp.sharp_edges, scheme=inp.scheme, sharpness=inp.sharpness,
                               sharp_faces=sharp_faces, loop_weights=inp.loop_weights, **_corner_tags(inp))
    else:  # the caller's mesh, cut as the gate cut it; the criterion follows the cut copy's vertices
        vs = inp.corner_sharpness
        if vs is not None and (np.isfinite(vs) & (vs > 0)).any():
            raise ValueError('a tolerance with non_manifold="cut" takes infinitely sharp corners only (finite '
                             "corner_sharpness): refine a region (where=, levels=) or give the corners infinite sharpness")
        u = inp.uncut
        surface = LimitSurface(X, u.faces, u.sharp_edges, scheme=inp.scheme, sharpness=u.sharpness,
                               sharp_faces=sharp_faces, corners=np.flatnonzero(u.corner),
                               loop_weights=inp.loop_weights, non_manifold="cut", boundary=_surface_boundary(inp))
        X = X[inp.cut.origin]
    holder = {}

    def on_level(k, mesh, active, step):
        if k == 0:
            holder["c"] = Criterion(inp, X, surface, tol, limit)
        return holder["c"](k, mesh, active, step)

    run = adaptive_refinement(inp, np.zeros(inp.n_faces, np.int64), max_levels, on_level)
    c = holder.get("c")
    refinement = without_holes(run.refinement, inp.hole)
    if c is None:  # no faces
        return AdaptiveResult(refinement, X.copy(), 0.0, tol)
    P = c.positions(run.mesh)
    err = float(c.error.max(initial=0.0))
    if err > tol:
        warnings.warn(f"tolerance {tol:.6g} not reached in max_levels={max_levels} levels: the largest error is "
                      f"{err:.6g} ({err / tol:.3g}× the tolerance); raise max_levels to go further",
                      AdaptiveWarning, stacklevel=4)
    return AdaptiveResult(refinement, P, err, tol)


def adaptive_result(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, tolerance,
                    max_levels: int = 8, limit: bool = True, scheme: Scheme = "hybrid",
                    sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
                    corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
                    corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                    holes: ArrayLike | None = None, non_manifold: NonManifold = "raise",
                    max_memory: MemoryLimit = None, uv_faces: ArrayLike | None = None, n_uvs: int | None = None,
                    uv_mode: UVMode = "linear") -> AdaptiveResult:
    """:func:`subdivide_adaptive`'s work, with the refinement and the error reached (for the
    command line; with ``uv_faces`` the refinement carries the UV index mesh)."""
    X = as_vertices(V)
    ml = _max_levels(max_levels)
    inp = _gate(F, sharp_edges, ml, len(X), scheme, sharpness, sharp_faces, corners, loop_weights,
                corner_sharpness, boundary, holes, non_manifold, max_memory,
                _uv_args(uv_faces, n_uvs, uv_mode, None))
    _no_hybrid_seams(inp)
    return _by_tolerance(inp, X, tolerance, ml, bool(limit))


def uniform_error(V: ArrayLike, F: ArrayLike, levels: int, *, only: ArrayLike | None = None,
                  scheme: Scheme = "hybrid", **tags) -> float:
    """The error of the uniform level ``levels`` measured as adaptive refinement measures its
    faces (corners at their limit positions, edge midpoints and centroids on the surface);
    ``only``: just the faces over these input faces. For the benchmark and the figure."""
    X = as_vertices(V)
    r = refine(F, levels=levels, scheme=scheme, n_vertices=len(X), **tags)
    P = limit_positions(X, F, levels=levels, scheme=scheme, **tags)
    G = r.faces
    pick = np.arange(len(G)) if only is None else np.flatnonzero(np.isin(r.face_parent, only))
    charts = FaceCharts(r.coarse_faces, len(X), lambda A, n: build_level(A, n).twin)
    for st in r.steps:
        charts.step(st)
    surface = LimitSurface(X, F, scheme=scheme, **tags)
    Q = np.vstack([_EDGE_MIDPOINTS, np.full(3, 1 / 3)])
    near = np.repeat(pick, len(Q))
    f, b = charts.points(near, np.tile(Q, (len(pick), 1)))
    d = distance_to_output(surface.evaluate(f, b), P, G, build_level(G, len(P)).twin, near)
    return float(d.max(initial=0.0))


def _gate(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
          corner_sharpness=None, boundary="edge_only", holes=None, non_manifold="raise",
          max_memory=None, uv=None) -> RefineInput:
    inp = open_gate(F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights,
                    corner_sharpness=corner_sharpness, boundary=boundary, holes=holes, non_manifold=non_manifold,
                    max_memory=max_memory, **(uv or {}))
    return inp


def _uv_args(uv_faces, n_uvs, uv_mode, uv_interpolation) -> dict | None:
    """The face-varying options as the gate takes them (None without ``uv_faces``; the gate
    refuses ``n_uvs`` without them, and checks the modes either way)."""
    if uv_faces is None and n_uvs is None and uv_mode == "linear" and uv_interpolation is None:
        return None
    return dict(uv_faces=uv_faces, n_uvs=n_uvs, uv_mode=uv_mode, uv_interpolation=uv_interpolation)


def _no_hybrid_seams(inp: RefineInput) -> None:
    """A tolerance with UVs takes ``"loop"``: the hybrid splits seams where it would flip them,
    a surface other than the one the error is measured against."""
    if inp.uv is not None and inp.scheme != "loop":
        raise ValueError('a tolerance with uv_faces= needs scheme="loop": the hybrid splits UV seams where it '
                         "flips other edges, a surface other than the limit surface the error is measured on; "
                         "refine a region (where=, levels=), or refine the UVs with scheme=\"loop\"")


def _surface_boundary(inp: RefineInput) -> str:
    """The boundary interpolation the criterion's surface is built with where it finds the
    corners ``boundary="edge_and_corner"`` adds itself (``"none"`` refines as ``"edge_only"``)."""
    return "edge_and_corner" if inp.boundary == "edge_and_corner" else "edge_only"


def _corner_tags(inp: RefineInput) -> dict:
    """The gate's corners as ``LimitSurface`` takes them: indices, and their sharpness beside
    them where some are semi-sharp (``"sqrt3"``: its boundary interpolation)."""
    if inp.scheme == "sqrt3":  # no corners of its own: those of boundary="edge_and_corner" come from it again
        return dict(boundary=_surface_boundary(inp))
    if inp.corner_sharpness is None:
        return dict(corners=np.flatnonzero(inp.corner))
    c = np.flatnonzero(inp.corner_sharpness > 0)
    return dict(corners=c, corner_sharpness=inp.corner_sharpness[c])


def refine_adaptive(F: ArrayLike, sharp_edges: ArrayLike | None = None, *, where: ArrayLike | None = None,
                    levels: int | None = None, V: ArrayLike | None = None, tolerance: float | str | None = None,
                    max_levels: int = 8, limit: bool = True, scheme: Scheme = "hybrid",
                    sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
                    corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
                    n_vertices: int | None = None, corner_sharpness: ArrayLike | None = None,
                    boundary: Boundary = "edge_only", holes: ArrayLike | None = None,
                    non_manifold: NonManifold = "raise", max_memory: MemoryLimit = None,
                    uv_faces: ArrayLike | None = None, n_uvs: int | None = None, uv_mode: UVMode = "linear",
                    uv_interpolation: str | None = None) -> Refinement:
    """Refine only where it matters: a region to a level, or everywhere to a tolerance.

    Two forms. ``where=`` and ``levels=``: the input faces in ``where`` are refined ``levels``
    times, the faces around them as much as the refinement needs (at most one level less
    every one or two vertex rings). ``V=`` and ``tolerance=``: every face is refined until it
    is within ``tolerance`` of the limit surface (see :func:`subdivide_adaptive`).

    Every output vertex is a vertex of the uniform refinement of its level
    (``vertex_level``), exactly where :func:`hybridsub.refine` puts it: ``apply`` gives those
    positions. The output is crack-free: a closed, consistently oriented manifold input gives
    one with the same Euler characteristic and no T-vertex. See ``docs/adaptive.md``.

    Parameters
    ----------
    F, sharp_edges, scheme, sharpness, sharp_faces, corners, loop_weights, n_vertices
        As for :func:`hybridsub.refine` (checked the same way); ``"sqrt3"`` with a boundary
        follows Kobbelt's boundary rule at each face's own level.
    corner_sharpness, boundary, holes, non_manifold
        As for :func:`hybridsub.refine`: semi-sharp corners (with a tolerance, not together
        with ``"cut"``), OpenSubdiv's boundary interpolation, faces left
        out of ``faces`` (those descending from a hole; a hole is not measured by ``tolerance``)
        and ``"cut"``: a non-manifold input refined as its manifold cut copy.
    where : (m,) bool mask or array_like of int
        The input faces to refine ``levels`` times.
    levels : int
        How many times the faces in ``where`` are refined.
    V : (n, 3) array_like of float
        Control positions, for ``tolerance``.
    tolerance : float or str
        In mesh units, or a string such as ``"0.1%"`` of the bounding-box diagonal.
    max_levels : int
        With ``tolerance``: the most levels any face gets (default 8); a tolerance not reached
        warns (``AdaptiveWarning``) with the error reached.
    limit : bool
        With ``tolerance``: measure the faces with their corners at their limit positions
        (the output of :func:`subdivide_adaptive` with ``limit=True``); else at their level
        positions (``apply(V)``).
    max_memory : int, float or str, optional
        As for :func:`hybridsub.refine`; the output is not known ahead, so each step is
        checked before it allocates, with what the steps so far keep and upper bounds on its
        own (``OutputTooLargeError`` names the level and the faces it would refine).
    uv_faces, n_uvs, uv_mode, uv_interpolation
        Face-varying data (UVs with seams), as for :func:`hybridsub.refine`: the UV index
        mesh is refined with the geometry's steps (seams split, never flipped), so
        ``uv_faces`` stays aligned with ``faces`` row by row and ``uv_refinement.apply(UV)``
        gives each UV value where the uniform refinement of its vertex's level puts it.
        With a tolerance only ``scheme="loop"`` (the hybrid's seams change its surface).

    Returns
    -------
    Refinement
        As from ``refine``, plus ``face_level`` and ``vertex_level``; ``steps`` are the
        adaptive steps (each step's ``face_parent`` is the face of the previous adaptive mesh
        that made the face); with ``uv_faces`` also ``uv_faces``, ``uv_matrix`` and
        ``uv_refinement``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V, F = hybridsub.load_example()
    >>> r = hybridsub.refine_adaptive(F, where=[0, 1], levels=2, scheme="loop")
    >>> int(r.face_level.max()), len(r.faces) < len(hybridsub.refine(F, levels=2, scheme="loop").faces)
    (2, True)
    """
    uv = _uv_args(uv_faces, n_uvs, uv_mode, uv_interpolation)
    if tolerance is not None or V is not None:
        if where is not None or levels is not None:
            raise ValueError("refine_adaptive takes where= with levels=, or V= with tolerance=, not both")
        if V is None or tolerance is None:
            raise ValueError("refine_adaptive with a tolerance needs both V= and tolerance=")
        X = as_vertices(V)
        ml = _max_levels(max_levels)
        inp = _gate(F, sharp_edges, ml, len(X) if n_vertices is None else n_vertices, scheme, sharpness,
                    sharp_faces, corners, loop_weights, corner_sharpness, boundary, holes, non_manifold, max_memory,
                    uv)
        _no_hybrid_seams(inp)
        return _by_tolerance(inp, X, tolerance, ml, bool(limit)).refinement
    if levels is None:
        raise ValueError("refine_adaptive needs levels= with where= (or V= with tolerance=)")
    inp = _gate(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
                corner_sharpness, boundary, holes, non_manifold, max_memory, uv)
    mask = _where_mask(where, inp.n_faces)
    run = adaptive_refinement(inp, mask.astype(np.int64) * inp.levels, inp.levels)
    return without_holes(run.refinement, inp.hole)


def subdivide_adaptive(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *,
                       tolerance: float | str, max_levels: int = 8, limit: bool = True, scheme: Scheme = "hybrid",
                       sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
                       corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
                       corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                       holes: ArrayLike | None = None, non_manifold: NonManifold = "raise",
                       max_memory: MemoryLimit = None) -> tuple[np.ndarray, np.ndarray]:
    """Subdivide until the mesh is within ``tolerance`` of the limit surface, only where needed.

    Each face is refined until the largest distance between it and the limit surface over it,
    measured at its corners, edge midpoints and centroid at the same surface parameter, is at
    most ``tolerance`` (such a parametric distance bounds the distance both ways: from each
    of those points of the output to the surface, and from the surface point to the output).
    Faces are refined with the scheme's exact rules (``docs/adaptive.md``): every vertex is a
    vertex of the uniform refinement of its level, and the output has no crack.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F, sharp_edges, scheme, sharpness, sharp_faces, corners, loop_weights, boundary, holes, non_manifold
        As for :func:`hybridsub.subdivide` (holes: left out of ``F2`` and not measured; with
        ``"cut"`` the output is the refined cut copy, its cut vertices apart).
    corner_sharpness
        As for :func:`hybridsub.subdivide` (finite values not together with ``"cut"``).
    tolerance : float or str
        In mesh units, or a string such as ``"0.1%"`` of the bounding-box diagonal.
    max_levels : int
        The most levels any face gets (default 8). A tolerance not reached: the result at
        ``max_levels`` and an ``AdaptiveWarning`` giving the error reached.
    limit : bool
        True (default): the output vertices at their limit positions; False: at the positions
        of their levels.
    max_memory : int, float or str, optional
        As for :func:`refine_adaptive`.

    Returns
    -------
    V2 : (n', 3) float64
    F2 : (m', 3) int64

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V, F = hybridsub.load_example()
    >>> V2, F2 = hybridsub.subdivide_adaptive(V, F, tolerance="1%", scheme="loop")
    >>> V2.shape[1], F2.shape[1]
    (3, 3)
    """
    res = adaptive_result(V, F, sharp_edges, tolerance=tolerance, max_levels=max_levels, limit=limit, scheme=scheme,
                          sharpness=sharpness, sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights,
                          corner_sharpness=corner_sharpness, boundary=boundary, holes=holes,
                          non_manifold=non_manifold, max_memory=max_memory)
    return res.positions.copy(), res.refinement.faces.copy()
