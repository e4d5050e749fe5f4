"""Input checking and conversion for the public API.

Every public function passes its arguments through here first: the caller's arrays are
never modified (everything is converted into fresh arrays when needed), and every problem
becomes a ``MeshError`` (a ``ValueError``) or ``TypeError`` that names it.
"""

from __future__ import annotations

import operator

import numpy as np

from .._rules import step_rules as R
from .._errors import MeshError
from .._typing import SCHEMES


def check_options(scheme, levels, loop_weights) -> int:
    """Validate scheme, levels and loop_weights; return levels as an int."""
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    if loop_weights not in R.LOOP_WEIGHTS:
        raise ValueError(f"loop_weights must be one of {R.LOOP_WEIGHTS}, got {loop_weights!r}")
    return count(levels, "levels")


NON_MANIFOLD = ("raise", "cut")
UV_MODES = ("linear", "smooth")


UV_INTERPOLATIONS = ("none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all")
_UV_MODE_AS = {"linear": "all", "smooth": "none"}


def check_uv_mode(uv_mode) -> str:
    if not isinstance(uv_mode, str) or uv_mode not in UV_MODES:
        raise ValueError(f"uv_mode must be one of {UV_MODES}, got {uv_mode!r}")
    return uv_mode


def check_uv_interpolation(uv_interpolation, uv_mode="linear") -> str:
    """The face-varying mode of a call, one of :data:`UV_INTERPOLATIONS` (OpenSubdiv's
    ``FVarLinearInterpolation``): ``uv_interpolation`` when given, else ``uv_mode``'s
    (``"linear"`` is ``"all"``, ``"smooth"`` is ``"none"``)."""
    check_uv_mode(uv_mode)
    if uv_interpolation is None:
        return _UV_MODE_AS[uv_mode]
    if not isinstance(uv_interpolation, str) or uv_interpolation not in UV_INTERPOLATIONS:
        raise ValueError(f"uv_interpolation must be one of {UV_INTERPOLATIONS}, got {uv_interpolation!r}")
    if uv_mode != "linear" and _UV_MODE_AS[uv_mode] != uv_interpolation:
        raise ValueError(f"uv_mode={uv_mode!r} and uv_interpolation={uv_interpolation!r} disagree; give one")
    return uv_interpolation


def count_of(k: int, word: str) -> str:
    """``"1 vertex"``, ``"1,234 vertices"``, ``"2 such faces"``: a count and its noun, for messages."""
    k = int(k)
    if k == 1:
        return f"1 {word}"
    return f"{k:,} {word[:-2] + 'ices' if word.endswith('vertex') else word + 's'}"


def tag_counts(sharp_edges, corners, sharp_faces=None) -> str:
    """The tags of a result in words, for the ``repr`` of results (masks counted as indices).

    >>> tag_counts(np.array([[0, 1]]), np.array([2]), np.array([True, False]))
    '1 crease, 1 corner, 1 sharp face'
    """
    def count(a) -> int:
        a = np.asarray(a)
        return int(a.sum()) if a.dtype == bool else len(a)

    parts = [count_of(count(sharp_edges), "crease"), count_of(count(corners), "corner")]
    if sharp_faces is not None and count(sharp_faces):
        parts.append(count_of(count(sharp_faces), "sharp face"))
    return ", ".join(parts)


def check_non_manifold(non_manifold) -> str:
    if not isinstance(non_manifold, str) or non_manifold not in NON_MANIFOLD:
        raise ValueError(f"non_manifold must be one of {NON_MANIFOLD}, got {non_manifold!r}")
    return non_manifold


def count(x, name: str) -> int:
    """A non-negative int option (n_vertices)."""
    if isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name} must be a non-negative integer, got {x!r}")
    try:
        x = operator.index(x)
    except TypeError:
        raise TypeError(f"{name} must be a non-negative integer, got {x!r}") from None
    if x < 0:
        raise ValueError(f"{name} must be a non-negative integer, got {x}")
    return x


def as_array(x, name: str, width: int, row: str, rows: str = "k") -> np.ndarray:
    """np.asarray, with numpy's errors on ragged or odd input turned into ones that say what is wrong."""
    try:
        return np.asarray(x)
    except (ValueError, TypeError) as exc:
        try:
            lengths = [len(r) for r in x]
        except TypeError:
            raise TypeError(f"{name} could not be read as an array ({exc})") from None
        if width <= 1:
            raise MeshError(f"{name} must be a regular array, got a ragged nested sequence") from None
        bad = next((i for i, k in enumerate(lengths) if k != width), 0)
        hint = _TRIANGULATE if name == "F" and lengths[bad] > 3 else ""
        raise MeshError(
            f"{name} must have shape ({rows}, {width}), but its rows have different lengths: {row} {bad} has "
            f"{lengths[bad]} entries{hint}"
        ) from None


_TRIANGULATE = (
    ": hybridsub subdivides triangle meshes; triangulate polygons first (e.g. a quad (a, b, c, d) "
    "becomes (a, b, c) and (a, c, d), or trimesh.Trimesh(vertices, faces) triangulates on load)"
)


def writable(A: np.ndarray) -> np.ndarray:
    """``A``, or a copy of it when it is read-only: Numba types a read-only array apart from a
    writable one, so a read-only input would compile every kernel it reaches a second time."""
    return A if A.flags.writeable else A.copy()


def mesh_object(x) -> str | None:
    """The class name of a trimesh or pyvista mesh object (``"trimesh.Trimesh"``), else None:
    what the array functions are given by mistake, and then point to ``subdivide_mesh``."""
    if isinstance(x, np.ndarray):  # trimesh's TrackedArray is an array
        return None
    top = type(x).__module__.split(".")[0]
    return f"{top}.{type(x).__name__}" if top in ("trimesh", "pyvista") else None


def as_vertices(V, return_dtype: bool = False):
    """(n, 3) float64 C-contiguous copy-or-view of V (never written to).

    With ``return_dtype``, also the dtype results should take: V's if floating, else float64.
    """
    kind = mesh_object(V)
    if kind is not None:
        raise TypeError(f"V must be an (n, 3) array of positions, got a {kind}: pass its vertices and faces, or "
                        "refine the mesh object with hybridsub.subdivide_mesh(mesh, ...), which keeps its UVs, "
                        "colours and tags")
    A = as_array(V, "V", 3, "vertex", "n")
    if A.ndim == 1 and A.size == 0:
        A = A.reshape(0, 3)
    if A.dtype == object or not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
        raise TypeError(f"V must be a real numeric array of shape (n, 3), got dtype {A.dtype}")
    if A.ndim != 2 or A.shape[1] != 3:
        hint = " (2-D points: append a zero z column, e.g. np.c_[V, np.zeros(len(V))])" if (
            A.ndim == 2 and A.shape[1] == 2) else ""
        raise MeshError(f"V must have shape (n, 3), got {A.shape}{hint}")
    dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.dtype(np.float64)
    A = writable(np.ascontiguousarray(A, dtype=np.float64))
    if not np.isfinite(A).all():  # (a row-wise reduction only to name the vertex: 30× slower)
        bad = ~np.isfinite(A).all(axis=1)
        i = int(np.flatnonzero(bad)[0])
        raise MeshError(f"vertex {i} has a non-finite coordinate {A[i].tolist()} ({int(bad.sum())} such vertices)")
    return (A, dtype) if return_dtype else A


def as_data(X, n: int):
    """Per-vertex data for ``Refinement.apply``: (array, dtype of the result, dtype to compute in)."""
    A = as_array(X, "data", 0, "row")
    if A.ndim == 0 or A.shape[0] != n:
        raise MeshError(f"data must have one row per coarse vertex ({n}), got shape {A.shape}")
    if np.issubdtype(A.dtype, np.complexfloating):
        return A, A.dtype, np.complex128
    if np.issubdtype(A.dtype, np.floating):
        return A, A.dtype, np.float64
    if A.dtype == bool or np.issubdtype(A.dtype, np.integer):
        return A, np.dtype(np.float64), np.float64
    raise TypeError(f"data must be numeric, got dtype {A.dtype}")


def not_integral(A: np.ndarray) -> np.ndarray:
    """Rows of a float array that do not hold integers (NaN and inf included)."""
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(A) | (A != np.round(A))
    return bad.any(axis=1) if bad.ndim == 2 else bad


def as_faces(F, n_vertices: int | None) -> tuple[np.ndarray, int]:
    """(m, 3) int64 C-contiguous faces, checked; returns (faces, n_vertices)."""
    if n_vertices is not None:
        n_vertices = count(n_vertices, "n_vertices")
    A = as_array(F, "F", 3, "face", "m")
    if A.ndim == 1 and A.size == 0:
        A = A.reshape(0, 3)
    if A.dtype == bool:
        raise TypeError("F must hold integer vertex indices, got a boolean array")
    if not (np.issubdtype(A.dtype, np.integer) or np.issubdtype(A.dtype, np.floating)):
        raise TypeError(f"F must be an integer array of shape (m, 3), got dtype {A.dtype}")
    if A.ndim != 2 or A.shape[1] != 3:
        hint = _TRIANGULATE if A.ndim == 2 and A.shape[1] > 3 else ""
        raise MeshError(f"F must have shape (m, 3), got {A.shape}{hint}")
    if np.issubdtype(A.dtype, np.floating) and A.size:
        frac = not_integral(A)
        if frac.any():
            f = int(np.flatnonzero(frac)[0])
            raise MeshError(f"F must hold integer vertex indices; face {f} is {A[f].tolist()}")
    if A.size:
        if A.min() < 0:
            f = int(np.flatnonzero((A < 0).any(axis=1))[0])
            raise MeshError(f"face {f} = {A[f].tolist()} has a negative vertex index")
        top = A.max()
        limit = n_vertices if n_vertices is not None else 2**62
        if top >= limit:
            f = int(np.flatnonzero((A >= limit).any(axis=1))[0])
            if n_vertices is None:
                raise MeshError(f"face {f} = {A[f].tolist()} refers to vertex {A[f].max()}, too large an index")
            raise MeshError(
                f"face {f} = {A[f].tolist()} refers to vertex {A[f].max()}, but there are only "
                f"{n_vertices} vertices (valid indices 0..{n_vertices - 1})"
            )
        if n_vertices is None:
            n_vertices = int(top) + 1
    elif n_vertices is None:
        n_vertices = 0
    Fi = writable(np.ascontiguousarray(A, dtype=np.int64))
    if Fi.size:
        rep = (Fi[:, 0] == Fi[:, 1]) | (Fi[:, 1] == Fi[:, 2]) | (Fi[:, 2] == Fi[:, 0])
        if rep.any():
            f = int(np.flatnonzero(rep)[0])
            raise MeshError(
                f"face {f} = {Fi[f].tolist()} repeats a vertex (a degenerate face with {int(rep.sum())} "
                "like it); remove such faces first, e.g. trimesh's mesh.update_faces(mesh.nondegenerate_faces())"
            )
    return Fi, n_vertices


def as_sharp_edges(sharp_edges, sharpness, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) int64 pairs and (k,) normalized sharpness (inf, or finite in (0, 10))."""
    if sharp_edges is None:
        if sharpness is not None and np.size(sharpness):
            raise ValueError("sharpness was given without sharp_edges")
        return np.empty((0, 2), np.int64), np.empty(0)
    if isinstance(sharp_edges, (int, np.integer)) and not isinstance(sharp_edges, bool):
        # subdivide(V, F, 2), as igl and trimesh are called: the number lands on sharp_edges
        raise TypeError(f"sharp_edges (the argument after the faces) got the number {sharp_edges}: it takes (k, 2) "
                        f"vertex pairs, and levels comes after it — pass levels={sharp_edges} by keyword")
    E = as_array(sharp_edges, "sharp_edges", 2, "row")
    if E.size == 0:
        E = E.reshape(0, 2)
    if E.dtype == bool or not (np.issubdtype(E.dtype, np.integer) or np.issubdtype(E.dtype, np.floating)):
        raise TypeError(f"sharp_edges must hold integer vertex indices, got dtype {E.dtype}")
    if E.ndim != 2 or E.shape[1] != 2:
        raise MeshError(f"sharp_edges must have shape (k, 2) (vertex pairs), got {E.shape}")
    if np.issubdtype(E.dtype, np.floating) and E.size:
        frac = not_integral(E)
        if frac.any():
            j = int(np.flatnonzero(frac)[0])
            raise MeshError(f"sharp_edges must hold integer vertex indices; sharp edge {j} is {E[j].tolist()}")
    bad = ((E < 0) | (E >= n_vertices)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(
            f"sharp edge {j} = {E[j].tolist()} refers to a vertex outside 0..{n_vertices - 1} "
            f"(there are {n_vertices} vertices)"
        )
    E = np.ascontiguousarray(E, dtype=np.int64)
    if sharpness is None:
        s = np.full(len(E), np.inf)
    else:
        S = as_array(sharpness, "sharpness", 1, "entry")
        if S.dtype == bool or not (np.issubdtype(S.dtype, np.integer) or np.issubdtype(S.dtype, np.floating)):
            raise TypeError(f"sharpness must be real numbers (inf: infinitely sharp), got dtype {S.dtype}")
        s = np.array(S, dtype=np.float64).reshape(-1)
        if s.shape != (len(E),):
            raise MeshError(f"sharpness must have one value per sharp edge ({len(E)}), got {s.shape[0]}")
        if np.isnan(s).any():
            j = int(np.flatnonzero(np.isnan(s))[0])
            raise MeshError(
                f"sharpness {j} (of sharp edge {E[j].tolist()}) is NaN; give a number: > 0 for a crease "
                "(>= 10 or inf: infinitely sharp), 0 for none"
            )
        if (s < 0).any():
            j = int(np.flatnonzero(s < 0)[0])
            raise MeshError(
                f"sharpness {j} (of sharp edge {E[j].tolist()}) is negative ({s[j]:g}); give 0 for no crease, "
                "> 0 for a crease (>= 10 or inf: infinitely sharp)"
            )
        s = R.normalize_sharpness(s)
    return E, s


def as_face_mask(sharp_faces, n_faces: int, name: str = "sharp_faces") -> tuple[np.ndarray, bool]:
    """Boolean (m,) mask, and whether the caller gave indices (True) or a mask (False)."""
    if sharp_faces is None:
        return np.zeros(n_faces, dtype=bool), False
    A = as_array(sharp_faces, name, 1, "entry")
    if A.dtype == bool:
        if A.shape != (n_faces,):
            raise MeshError(
                f"{name} as a boolean mask must have one entry per face, shape ({n_faces},), got {A.shape}"
            )
        return A.copy(), False
    idx = _indices(A, n_faces, name, "face")
    mask = np.zeros(n_faces, dtype=bool)
    mask[idx] = True
    return mask, True


def as_hole_mask(holes, n_faces: int) -> np.ndarray | None:
    """The (m,) bool mask of ``holes=`` (a mask or face indices), or None when no face is one.
    Holes on every face leave nothing to render: a ``MeshError``."""
    if holes is None:
        return None
    mask, _ = as_face_mask(holes, n_faces, "holes")
    if not mask.any():
        return None
    if mask.all():
        raise MeshError(f"holes marks every face ({count_of(n_faces, 'face')}): nothing would be left to render; "
                        "a hole is a face that shapes its neighbours but is not drawn")
    return mask


def as_corner_mask(corners, n_vertices: int) -> np.ndarray:
    mask = np.zeros(n_vertices, dtype=bool)
    if corners is None:
        return mask
    A = as_array(corners, "corners", 1, "entry")
    if A.dtype == bool:
        if A.shape != (n_vertices,):
            raise MeshError(
                f"corners as a boolean mask must have one entry per vertex, shape ({n_vertices},), got {A.shape}"
            )
        return A.copy()
    mask[_indices(A, n_vertices, "corners", "vertex")] = True
    return mask


def _indices(A, n: int, name: str, what: str) -> np.ndarray:
    A = A.reshape(-1) if A.ndim <= 1 else A
    if A.ndim != 1:
        raise MeshError(f"{name} must be a 1-D array of {what} indices (or a boolean mask), got shape {A.shape}")
    if A.size == 0:
        return np.empty(0, np.int64)
    if not (np.issubdtype(A.dtype, np.integer) or np.issubdtype(A.dtype, np.floating)):
        raise TypeError(f"{name} must hold integer {what} indices (or be a boolean mask), got dtype {A.dtype}")
    if np.issubdtype(A.dtype, np.floating):
        frac = not_integral(A)
        if frac.any():
            j = int(np.flatnonzero(frac)[0])
            raise MeshError(f"{name} must hold integer {what} indices; {name}[{j}] is {A[j]}")
    bad = (A < 0) | (A >= n)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        valid = f"valid 0..{n - 1}" if n else f"there is no {what}"
        raise MeshError(f"{name}[{j}] = {A[j]} is not a {what} index ({valid})")
    return A.astype(np.int64)


def as_uv_faces(FUV, m: int, n_uvs: int | None, name: str = "FUV") -> np.ndarray:
    """(m, 3) int64 UV faces, checked against the ``m`` faces and ``n_uvs`` UV values; errors
    name the argument (``name``) and the first bad face."""
    A = as_array(FUV, name, 3, "face", "m")
    if A.ndim == 1 and A.size == 0 and m == 0:
        A = A.reshape(0, 3)
    if A.dtype == bool or not (np.issubdtype(A.dtype, np.integer) or np.issubdtype(A.dtype, np.floating)):
        raise TypeError(f"{name} must hold integer UV indices, got dtype {A.dtype}")
    if A.ndim != 2 or A.shape[1] != 3 or A.shape[0] != m:
        raise MeshError(f"{name} must have shape ({m}, 3), one row of UV indices per face, got {A.shape}")
    if np.issubdtype(A.dtype, np.floating) and A.size:
        frac = not_integral(A)
        if frac.any():
            f = int(np.flatnonzero(frac)[0])
            raise MeshError(f"{name} must hold integer UV indices; face {f} has {A[f].tolist()}")
    T = np.ascontiguousarray(A, dtype=np.int64)
    if T.size:
        if T.min() < 0:
            f = int(np.flatnonzero((T < 0).any(axis=1))[0])
            raise MeshError(f"{name}: face {f} has a negative UV index: {T[f].tolist()}")
        if n_uvs is not None and T.max() >= n_uvs:
            f = int(np.flatnonzero((T >= n_uvs).any(axis=1))[0])
            raise MeshError(f"{name}: face {f} has UV indices {T[f].tolist()}, but there are only {n_uvs} UV values "
                            f"(valid indices 0..{n_uvs - 1})")
    return T


def as_uv_values(UV) -> np.ndarray:
    """(t, k) float64 face-varying values (UVs), checked finite; never a view the caller can see written."""
    A = np.asarray(UV)
    if A.dtype == object or not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
        raise TypeError(f"UV must be a numeric array of shape (t, k), got dtype {A.dtype}")
    if A.ndim not in (1, 2):
        raise MeshError(f"UV must have shape (t, k) (one row per UV value), got {A.shape}")
    A = np.ascontiguousarray(A, dtype=np.float64)
    if not np.isfinite(A).all():
        i = int(np.flatnonzero(~np.isfinite(A.reshape(len(A), -1)).all(axis=1))[0])
        raise MeshError(f"UV value {i} is not finite: {A[i].tolist()}")
    return A


#: OpenSubdiv's Sdc::Options::VtxBoundaryInterpolation, by name (``docs/scheme.md``).
BOUNDARY_MODES = ("edge_only", "edge_and_corner", "none")


def check_boundary(boundary) -> str:
    """The ``boundary=`` option, checked."""
    if not isinstance(boundary, str) or boundary not in BOUNDARY_MODES:
        raise ValueError(f"boundary must be one of {BOUNDARY_MODES}, got {boundary!r}")
    return boundary


def as_corner_sharpness(corners, corner_sharpness, n_vertices: int) -> tuple[np.ndarray, np.ndarray | None]:
    """``corners`` and their optional ``corner_sharpness``: the corner mask (n,) and, where
    some corner is semi-sharp, the sharpness of every vertex (n,) float64 (``inf`` infinitely
    sharp, ``0`` untagged; ≥ 10 is infinite), else None. A corner of sharpness 0 is no corner.

    >>> mask, s = as_corner_sharpness([1, 2], [0.5, 20], 4)
    >>> mask.tolist(), s.tolist()
    ([False, True, True, False], [0.0, 0.5, inf, 0.0])
    """
    mask = as_corner_mask(corners, n_vertices)
    if corner_sharpness is None:
        return mask, None
    if corners is None:
        raise ValueError("corner_sharpness was given without corners")
    S = np.asarray(corner_sharpness)
    if S.dtype == bool or not (np.issubdtype(S.dtype, np.floating) or np.issubdtype(S.dtype, np.integer)):
        raise TypeError(f"corner_sharpness must be real numbers (inf: infinitely sharp), got dtype {S.dtype}")
    s = np.array(S, dtype=np.float64).reshape(-1)
    A = np.asarray(corners)
    idx = np.flatnonzero(A) if A.dtype == bool else np.asarray(A).reshape(-1).astype(np.int64)
    if s.shape[0] != idx.shape[0]:
        raise MeshError(f"corner_sharpness must have one value per corner ({idx.shape[0]}), got {s.shape[0]}")
    bad = np.isnan(s) | (s < 0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"corner_sharpness {j} (of corner vertex {int(idx[j])}) is {s[j]}; give a number >= 0 "
                        "(0: no corner, >= 10 or inf: infinitely sharp)")
    vs = np.zeros(n_vertices, np.float64)
    np.maximum.at(vs, idx, R.normalize_sharpness(s))  # a vertex listed twice takes its sharpest value
    mask = vs > 0
    return mask, (vs if (np.isfinite(vs) & mask).any() else None)
