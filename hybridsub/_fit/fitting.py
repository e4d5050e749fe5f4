"""Fitting a subdivision surface to points: :func:`fit`.

The surface is linear in the control positions: the point of parameter (face, bary) is one
sparse row ``e`` times ``V`` (``B S`` on a refined level, the evaluation matrix on the limit
surface). Each iteration projects the points on the current surface (foot points, normals)
and minimises the squared-distance model of Pottmann & Hofer / Cheng et al. at the foot
points,

    Σ_i w (e_i V − p_i)ᵀ (n_i n_iᵀ + λ (I − n_i n_iᵀ)) (e_i V − p_i)  +  μ ||L V||²,

point-to-plane along the normal (the tangent-distance term, Gauss–Newton on the distance,
fast near the surface) with a small tangential weight λ (a damping that keeps the system
regular where points only constrain the normal direction; it vanishes at a fixed point, since
``p_i − e_i V`` is normal there), and an optional smoothness term: ``L`` the umbrella operator
of the control mesh, along creases on crease neighbours only, zero at corners, so creases
and corners stay sharp. The sparse system (3n unknowns) is solved for the update of ``V``;
its LU factor is kept and reused across iterations as the preconditioner of conjugate
gradients, and refactored only when they stall.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .._errors import MeshError
from .._input import as_faces, as_vertices, count_of, open_gate
from .._typing import ArrayLike, LoopWeights, Scheme
from ._fit_kernels import face_systems
from .._surface import ClosestPoints, LimitSurface
from .._refiner import refine

TANGENT_WEIGHT = 1e-6       # λ near the target: the tangential damping
TANGENT_WEIGHT_MAX = 1e-2   # λ far from it (λ = RMS / diagonal in between)
_MAX_HALVINGS = 30
_RIDGE = 1e-12          # relative ridge on the update: vertices no point reaches stay put
_CG_RTOL = 1e-10
_CG_MAXITER = 40


@dataclass(frozen=True, eq=False)
class FitResult:
    """The result of :func:`hybridsub.fit`.

    Attributes
    ----------
    vertices : (n, 3) float64
        The fitted control positions (with the input's connectivity and tags).
    rms, max_error : float
        Root mean square and largest distance of the points to the fitted surface.
    iterations : int
        Least-squares updates made.
    converged : bool
        True when the update or the decrease of the squared error fell below ``tol``.
    history : (iterations + 1,) structured array
        Per iteration (0: the start): ``rms``, ``max_error``, ``step`` (largest vertex move
        of the update that followed, 0 for the last), ``seconds`` (since the call began).
    """

    vertices: np.ndarray
    rms: float
    max_error: float
    iterations: int
    converged: bool
    history: np.ndarray = field(repr=False)


HISTORY_DTYPE = np.dtype([("rms", "f8"), ("max_error", "f8"), ("step", "f8"), ("seconds", "f8")])


class Solver:
    """Solves ``H x = b`` for successive SPD ``H`` of one pattern, reusing one LU factor.

    The first system is factored; later ones are solved by conjugate gradients with that
    factor as preconditioner, and refactored when they do not converge in ``_CG_MAXITER``
    iterations. ``factorizations`` counts the LU factorisations made.
    """

    def __init__(self):
        self.factor = None
        self.factorizations = 0

    def solve(self, H: sp.csc_matrix, b: np.ndarray) -> np.ndarray:
        import scipy.sparse.linalg as spla  # (imported when used: it costs start-up time)

        if self.factor is not None:
            pre = spla.LinearOperator(H.shape, matvec=self.factor.solve, dtype=np.float64)
            x, info = spla.cg(H, b, rtol=_CG_RTOL, atol=0.0, maxiter=_CG_MAXITER, M=pre)
            if info == 0:
                return x
        self.factor = spla.splu(H, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                options={"SymmetricMode": True})
        self.factorizations += 1
        return self.factor.solve(b)


def normal_system(E: sp.csr_matrix, normals: np.ndarray, residual: np.ndarray, weight: float,
                  lam: float) -> tuple[sp.csr_matrix, np.ndarray]:
    """Blocks of ``H`` (3k × 3k, unknowns ordered x…, y…, z…) and gradient ``g`` (3k,) of the
    data term for evaluation rows ``E`` (m × k), unit normals and residuals ``e_i V − p_i``."""
    M = point_metric(normals, weight, lam)
    Et = sp.csr_matrix(E.T)
    blocks = [[None] * 3 for _ in range(3)]
    for d in range(3):
        for e in range(d, 3):
            blocks[d][e] = Et @ sp.diags(M[:, d, e]) @ E
            if e != d:
                blocks[e][d] = blocks[d][e].T
    Mr = np.einsum("mde,me->md", M, residual)
    g = np.concatenate([Et @ Mr[:, d] for d in range(3)])
    return sp.bmat(blocks, format="csr"), g


def point_metric(normals: np.ndarray, weight: float, lam: float) -> np.ndarray:
    """(m, 3, 3) ``weight (n nᵀ + λ (I − n nᵀ))``: the squared-distance model at each foot point."""
    nn = normals[:, :, None] * normals[:, None, :]
    return weight * (nn + lam * (np.eye(3) - nn))


def sandwich(H: sp.csr_matrix, S: sp.csr_matrix) -> sp.csr_matrix:
    """``diag(S, S, S)ᵀ H diag(S, S, S)``: the system of a refined level on the control points."""
    S3 = sp.block_diag([S, S, S], format="csr")
    return sp.csr_matrix(S3.T @ H @ S3)


def umbrella(F: np.ndarray, n: int, crease_pairs: np.ndarray, corner: np.ndarray) -> sp.csr_matrix:
    """The umbrella operator ``L`` (n × n): mean of the neighbours minus the vertex.

    A vertex on two or more creases averages its crease neighbours only (a curve's
    Laplacian); corners and unused vertices have zero rows.
    """
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    edges, count = np.unique(e, axis=0, return_counts=True)
    crease = np.zeros(len(edges), dtype=bool)
    crease[count == 1] = True
    if len(crease_pairs):
        key = edges[:, 0] * n + edges[:, 1]
        cp = np.sort(crease_pairs, axis=1)
        crease |= np.isin(key, cp[:, 0] * n + cp[:, 1])
    ends = np.concatenate([edges, edges[:, ::-1]])
    on_crease = np.concatenate([crease, crease])
    n_crease = np.bincount(ends[on_crease, 0], minlength=n)
    fixed = corner | (n_crease >= 3)
    keep = np.where(n_crease[ends[:, 0]] == 2, on_crease, True) & ~fixed[ends[:, 0]]
    rows, cols = ends[keep, 0], ends[keep, 1]
    deg = np.bincount(rows, minlength=n).astype(np.float64)
    A = sp.csr_matrix((1.0 / deg[rows], (rows, cols)), shape=(n, n))
    return sp.csr_matrix(A - sp.diags((deg > 0).astype(np.float64)))


def as_points(points) -> np.ndarray:
    """(m, 3) float64 target points, finite, at least one."""
    try:
        P = as_vertices(points)
    except (MeshError, TypeError) as e:
        raise type(e)(str(e).replace("V must", "points must").replace("vertex", "point")) from None
    if len(P) == 0:
        raise ValueError("points must hold at least one point, got none")
    return P


# ---------------------------------------------------------------------------------------------
# The surfaces fitted: a refined level, the limit surface
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Feet:
    """Foot points of the targets on the current surface: evaluation rows ``E`` (on the
    surface's own vertices), their ``face`` and ``bary`` coordinates, unit ``normals``,
    ``residual`` = foot − target, ``distance``."""

    E: sp.csr_matrix
    face: np.ndarray
    bary: np.ndarray
    normals: np.ndarray
    residual: np.ndarray
    distance: np.ndarray


class LevelSurface:
    """The level-L refined mesh ``(S V, faces)``: piecewise linear, exact closest points."""

    def __init__(self, r, points: np.ndarray):
        self.S = r.matrix
        self.faces = r.faces
        self.search = ClosestPoints(r.faces, points)

    def feet(self, V: np.ndarray, points: np.ndarray) -> Feet:
        P = self.S @ V
        fp = self.search.search(P)
        m = len(points)
        E = sp.csr_matrix((fp.bary.ravel(), self.faces[fp.face].ravel(), np.arange(0, 3 * m + 1, 3)),
                          shape=(m, len(P)))
        tri = P[self.faces[fp.face]]
        normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        residual = fp.points - points
        # Off the triangle's interior, the distance grows along the offset, not the face normal.
        rim = (fp.bary <= 0.0).any(axis=1) & (fp.distance > 0.0)
        normals[rim] = residual[rim]
        return Feet(E, fp.face, fp.bary, _unit(normals, residual), residual, fp.distance)

    def system(self, feet: Feet, weight: float, lam: float):
        """``H`` and ``g`` on the control points: the data term summed per face of the level
        (a kernel), assembled on the level's vertices, then ``diag(S,S,S)ᵀ H diag(S,S,S)``."""
        nf, nl = len(self.faces), self.S.shape[0]
        Hf = np.zeros((nf, 3, 3, 3, 3))
        gf = np.zeros((nf, 3, 3))
        face_systems(feet.face, feet.bary, point_metric(feet.normals, weight, lam), feet.residual, Hf, gf)
        used = np.flatnonzero(np.bincount(feet.face, minlength=nf))
        tri = self.faces[used]                                      # (u, 3) level vertices
        idx = tri[:, :, None] + nl * np.arange(3)[None, None, :]     # (u, a, d): unknown of (vertex, dim)
        rows = np.broadcast_to(idx[:, :, :, None, None], (len(used), 3, 3, 3, 3)).ravel()
        cols = np.broadcast_to(idx[:, None, None, :, :], (len(used), 3, 3, 3, 3)).ravel()
        H = sp.csr_matrix((Hf[used].ravel(), (rows, cols)), shape=(3 * nl, 3 * nl))
        g = np.bincount(idx.ravel(), weights=gf[used].ravel(), minlength=3 * nl)
        S3t = sp.block_diag([self.S.T] * 3, format="csr")
        return sandwich(H, self.S), S3t @ g


class LimitFitSurface:
    """The limit surface: closest points by :meth:`LimitSurface.project`, rows by its
    ``evaluation_matrix`` (which depends on connectivity and tags only)."""

    def __init__(self, surface: LimitSurface):
        self.surface = surface

    def feet(self, V: np.ndarray, points: np.ndarray) -> Feet:
        face, bary, Q, _ = self.surface.project(points, vertices=V)
        E, Eu, Ev = self.surface.evaluation_matrix(face, bary, derivatives=True)
        residual = E @ V - points
        normals = _unit(np.cross(Eu @ V, Ev @ V), residual)
        return Feet(sp.csr_matrix(E), face, bary, normals, residual, np.linalg.norm(residual, axis=1))

    def system(self, feet: Feet, weight: float, lam: float):
        return normal_system(feet.E, feet.normals, feet.residual, weight, lam)


def _unit(N: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """Unit rows of N; where N vanishes (a degenerate face), the residual's direction, else z."""
    out = np.zeros_like(N)
    for X in (N, residual):
        length = np.linalg.norm(X, axis=1)
        ok = (length > 0) & ~out.any(axis=1)
        out[ok] = X[ok] / length[ok, None]
    out[~out.any(axis=1), 2] = 1.0
    return out


# ---------------------------------------------------------------------------------------------
# fit
# ---------------------------------------------------------------------------------------------


def fit(F: ArrayLike, points: ArrayLike, sharp_edges: ArrayLike | None = None, *, scheme: Scheme = "hybrid",
        sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
        V0: ArrayLike | None = None, levels: int | None = None, smoothness: float = 0.0, max_iterations: int = 50,
        tol: float = 1e-12, loop_weights: LoopWeights = "loop", feature_angle: float | None = None,
        callback=None, corner_sharpness: ArrayLike | None = None) -> FitResult:
    """Control positions whose subdivision surface is closest to target points.

    Alternates the closest points of the targets on the current surface and a sparse
    least-squares update of the control positions that minimises the squared distances
    linearised at those points (point-to-plane along the surface normal: Pottmann & Hofer,
    Cheng et al. 2004/2007), so it converges in few iterations. Connectivity and tags stay
    those of the control mesh: creases and corners stay sharp, and the targets near a crease
    fit its curve. See ``docs/fitting.md``.

    Parameters
    ----------
    F : (m, 3) array_like of int
        The control mesh's triangles.
    points : (p, 3) array_like of float
        Target points (a scan, a dense mesh's vertices).
    sharp_edges, scheme, sharpness, sharp_faces, corners, corner_sharpness, loop_weights
        The control mesh's tags and rules, as in :func:`hybridsub.refine` (``holes=`` and
        ``boundary=`` are not taken: the targets are fitted to every face).
    V0 : (n, 3) array_like of float, optional
        Starting control positions, usually the control mesh's own (``fit(F, P, V0=V)``);
        vertices no face uses are allowed and stay where they are. Default: the first n target
        points (the control mesh is assumed to be made on the target's own samples, its vertex
        i at ``points[i]``, roughly over the target; no registration is made).
    levels : int, optional
        Fit the level-``levels`` refined mesh (piecewise linear, exact closest points, fast);
        default None fits the limit surface (:class:`hybridsub.LimitSurface`: its ``project``
        and ``evaluation_matrix``, exact but much slower per point).
    smoothness : float
        Weight μ of the fairness term ``μ / n ||L V||²`` beside the mean squared distance
        (``L``: umbrella operator of the control mesh, creases as curves, corners free).
    max_iterations : int
        Most least-squares updates.
    tol : float
        Stop when the largest vertex move of an update is below ``tol`` × the targets'
        bounding-box diagonal, or the squared error decreases by less than ``tol`` relatively.
    feature_angle : float, optional
        Also keep sharp the edges whose dihedral angle at the start positions exceeds this
        many degrees, with their corners (:func:`hybridsub.detect_features`), as for
        :func:`hybridsub.subdivide`.
    callback : callable, optional
        Called after each projection as ``callback(iteration, rms, max_error)``.

    Returns
    -------
    FitResult
        ``vertices``, ``rms``, ``max_error``, ``iterations``, ``converged``, ``history``.

    Raises
    ------
    MeshError
        No faces; a start ``V0`` whose triangles all have zero area; coordinates too far apart
        to be fitted in double precision.
    ValueError, TypeError
        An option out of range or of the wrong type (the message names it).

    Warns
    -----
    UserWarning
        Fewer points than unknowns (three per control vertex) without ``smoothness``: the fit
        is underdetermined, and many control meshes fit the points as well as the one returned.

    Notes
    -----
    The tangential damping λ is RMS / diagonal clamped to [1e-6, 1e-2] (firm far from the
    target, vanishing near it), and an update that raises the error is halved (up to 30
    times) before the next, so far starts converge too, more slowly. The fit runs on the
    points and start moved to the origin and scaled to a unit box (the energy is quadratic in
    lengths, so the answer is the same), which keeps coordinates of 1e200 or 1e-200 in range.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> r = hybridsub.refine(F, levels=2)
    >>> P = r.apply(V * [1.0, 1.5, 2.0])               # a stretched tetrahedron's level 2
    >>> target = np.vstack([P, P[r.faces].mean(axis=1)])  # its vertices and face centres
    >>> res = hybridsub.fit(F, target, V0=V, levels=2)
    >>> bool(res.converged), bool(res.rms < 1e-9)
    (True, True)
    """
    pts = as_points(points)
    max_iterations, tol, smoothness = _check_numbers(max_iterations, tol, smoothness)
    n_given = None
    if V0 is not None:
        n_given, n_used = len(as_vertices(V0)), as_faces(F, None)[1]
        if n_given < n_used:
            raise MeshError(f"V0 must have one row per control vertex (at least {n_used}, the faces use vertex "
                            f"{n_used - 1}), got shape {np.shape(as_vertices(V0))}")
    tags = dict(scheme=scheme, sharpness=sharpness, sharp_faces=sharp_faces, corners=corners,
                loop_weights=loop_weights, corner_sharpness=corner_sharpness)
    r = refine(F, sharp_edges, 0 if levels is None else levels, n_vertices=n_given, **tags)
    if len(r.faces) == 0:
        raise MeshError("F has no faces: there is no surface to fit")
    n = r.n_coarse
    V = _start(V0, pts, n)
    if feature_angle is not None:  # the features of the start, merged into the tags as subdivide does
        inp = open_gate(F, sharp_edges, 0, n_vertices=n, positions=V, feature_angle=feature_angle, **tags)
        sharp_edges, tags["sharpness"] = inp.sharp_edges, inp.sharpness
        tags["corners"] = np.flatnonzero(inp.corner)
        if inp.corner_sharpness is not None:  # the caller's semi-sharp ones keep their sharpness
            tags["corner_sharpness"] = inp.corner_sharpness[tags["corners"]]
        r = refine(F, sharp_edges, 0 if levels is None else levels, n_vertices=n, **tags)
    centre, scale = _normalisation(pts, V)
    pts, V = (pts - centre) / scale, (V - centre) / scale
    _check_start(r, V, len(pts), n, smoothness)
    if levels is None:
        surface = LimitFitSurface(LimitSurface(V, F, sharp_edges, **tags))
    else:
        surface = LevelSurface(r, pts)
    smooth = None
    if smoothness > 0:
        r0 = r if levels == 0 else refine(F, sharp_edges, 0, n_vertices=n, **tags)
        corner = np.zeros(n, dtype=bool)
        corner[r0.corners] = True
        Lu = umbrella(r0.faces, n, np.asarray(r0.sharp_edges).reshape(-1, 2), corner)
        smooth = (smoothness / n) * sp.csr_matrix(Lu.T @ Lu)
    user = None if callback is None else (lambda i, rms, mx: callback(i, rms * scale, mx * scale))
    res = _iterate(surface, V, pts, smooth, max_iterations, tol, user)
    hist = res.history.copy()
    for k in ("rms", "max_error", "step"):
        hist[k] *= scale
    return FitResult(res.vertices * scale + centre, res.rms * scale, res.max_error * scale, res.iterations,
                     res.converged, hist)


def _normalisation(pts: np.ndarray, V: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and scale that move the points' bounding box to the origin and a unit size:
    computed without squares or sums, so 1e300 stays finite; MeshError where the points (or
    the start) span more than a double can hold."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = lo / 2 + hi / 2
    with np.errstate(over="ignore"):
        extent = float(np.max(hi - lo))
    if not np.isfinite(extent):
        raise MeshError("the points span more than a double can hold (their bounding box overflows): "
                        "scale them down")
    scale = extent if extent > 0 else max(float(np.abs(centre).max()), 1.0)
    with np.errstate(over="ignore"):
        far = float(np.abs((V - centre) / scale).max())
    if not far < 1e150:
        raise MeshError(f"V0 lies {far:.3g} times the points' size away from them: too far to be fitted in "
                        "double precision; start from positions near the points")
    return centre, scale


def _check_start(r, V: np.ndarray, m: int, n: int, smoothness: float) -> None:
    """MeshError for a start with no area (every triangle degenerate: nothing to project on);
    a warning for fewer points than unknowns."""
    tri = (r.matrix @ V)[r.faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    if not (area > 0).any():
        raise MeshError("V0 has no area: every triangle of the start is degenerate (all vertices at one point, or "
                        "on one line), so the points have nothing to be projected on; start from the control mesh's "
                        "own positions")
    used = int((np.diff(sp.csc_matrix(r.matrix).indptr) > 0).sum())
    if smoothness == 0 and m < 3 * used:
        warnings.warn(f"fit: {count_of(m, 'point')} for {3 * used:,} unknowns ({count_of(used, 'control vertex')} "
                      "× 3): the fit is underdetermined, and many control meshes fit the points as well as this "
                      "one; give more points, or smoothness > 0", UserWarning, stacklevel=3)


def _iterate(surface, V, pts, smooth, max_iterations, tol, callback) -> FitResult:
    """The fit loop: project, update, and halve an update that raised the error."""
    t0 = time.perf_counter()
    diag = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))) or 1.0
    solver = Solver()
    rows, converged, it, energy, halvings = [], False, 0, np.inf, 0
    dx = V_prev = V  # (set by the first update; the first pass neither halves nor compares)
    while True:
        feet = surface.feet(V, pts)
        d = feet.distance
        rms, mx = float(np.sqrt(np.mean(d * d))), float(d.max())
        e = rms * rms + (0.0 if smooth is None else float((V * (smooth @ V)).sum()))
        if e > energy * (1 + 1e-9) and halvings < _MAX_HALVINGS:   # overshot: back half the way
            dx *= 0.5
            V = V - dx
            halvings += 1
            continue
        halvings = 0
        if rows:
            rows[-1][2] = float(np.abs(V - V_prev).max())
        rows.append([rms, mx, 0.0, time.perf_counter() - t0])
        if callback is not None:
            callback(it, rms, mx)
        if it and (0.0 <= energy - e <= tol * energy or rms <= tol * diag or rows[-2][2] <= tol * diag):
            converged = True
        if converged or it >= max_iterations:
            break
        energy, V_prev = e, V
        # The tangential damping shrinks with the distance: firm far from the target, ~0 at it.
        lam = min(TANGENT_WEIGHT_MAX, max(TANGENT_WEIGHT, rms / diag))
        dx = _update(surface, feet, smooth, V, lam, solver)
        V = V + dx
        it += 1
    hist = np.array([tuple(x) for x in rows], dtype=HISTORY_DTYPE)
    return FitResult(V, rms, mx, it, converged, hist)


def _update(surface, feet: Feet, smooth, V: np.ndarray, lam: float, solver: Solver) -> np.ndarray:
    """The least-squares update of the control positions, (n, 3)."""
    n, m = len(V), len(feet.distance)
    H, g = surface.system(feet, 1.0 / m, lam)
    if smooth is not None:
        H = H + sp.block_diag([smooth] * 3)
        g = g + (smooth @ V).T.ravel()
    H = sp.csc_matrix(H + (_RIDGE * H.diagonal().mean()) * sp.identity(3 * n))
    return solver.solve(H, -g).reshape(3, n).T


def _start(V0, pts: np.ndarray, n: int) -> np.ndarray:
    if V0 is None:
        if len(pts) < n:
            raise ValueError(f"without V0 the control mesh's {n} vertices start at the first {n} target points, "
                             f"but there are only {len(pts)}; pass V0")
        return pts[:n].copy()
    V = as_vertices(V0)
    if len(V) != n:
        raise MeshError(f"V0 must have one row per control vertex ({n}), got shape {V.shape}")
    return V.copy()


#: The largest smoothness: beyond, the points' term is below the rounding of the fairness term.
MAX_SMOOTHNESS = 1e12


def _check_numbers(max_iterations, tol, smoothness):
    for name, x in (("max_iterations", max_iterations), ("tol", tol), ("smoothness", smoothness)):
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise TypeError(f"{name} must be a number, got {x!r}")
    if not (np.isfinite(max_iterations) and int(max_iterations) == max_iterations and max_iterations >= 0):
        raise ValueError(f"max_iterations must be a non-negative integer, got {max_iterations!r}")
    max_iterations = int(max_iterations)
    tol, smoothness = float(tol), float(smoothness)
    if not tol >= 0:
        raise ValueError(f"tol must be >= 0, got {tol}")
    if not (smoothness >= 0 and np.isfinite(smoothness)):
        raise ValueError(f"smoothness must be a finite number >= 0, got {smoothness}")
    if smoothness > MAX_SMOOTHNESS:
        raise ValueError(f"smoothness {smoothness:g} is more than {MAX_SMOOTHNESS:g}: the points' distances would be "
                         "lost in the rounding of the fairness term, and the fit would ignore them")
    return max_iterations, tol, smoothness
