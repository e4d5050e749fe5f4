"""Face and vertex tables as mesh files hold them: polygon lists read as triangles, face
indices checked against the vertex count, and rows of numbers written as lines of text."""

from __future__ import annotations

from typing import Callable

import numpy as np

from .._errors import MeshError

#: Indices beyond this are refused on reading (they do not fit the int64 face arrays).
MAX_INDEX = np.iinfo(np.int64).max


def triangulate_polygons(path: str, polys: list, triangulate: bool, what: str = "face"):
    """Triangles of a list of index lists (fans, if ``triangulate``); returns (faces, polygon
    of each triangle), the second None where every polygon is a triangle.

    >>> F, origin = triangulate_polygons("q.obj", [[0, 1, 2, 3]], True)
    >>> F.tolist(), origin.tolist()
    ([[0, 1, 2], [0, 2, 3]], [0, 0])
    """
    sizes = np.fromiter((len(p) for p in polys), np.int64, len(polys))
    small = np.flatnonzero(sizes < 3)
    if len(small):  # no triangulation mends these: the file is damaged or not a surface
        f = int(small[0])
        raise MeshError(f"{path}: {what} {f} has only {int(sizes[f])} vertices ({len(small)} such): a face needs "
                        "at least three")
    huge = [f for f, p in enumerate(polys) if any(abs(i) > MAX_INDEX for i in p)]
    if huge:
        digits = len(str(max(abs(i) for i in polys[huge[0]])))
        raise MeshError(f"{path}: {what} {huge[0]} holds a vertex index too large for any mesh ({digits} digits)")
    if len(polys) and (sizes == 3).all():
        return np.array(polys, dtype=np.int64).reshape(-1, 3), None
    bad = np.flatnonzero(sizes != 3)
    if len(bad) and not triangulate:
        f = int(bad[0])
        raise MeshError(
            f"{path}: {what} {f} has {int(sizes[f])} vertices ({len(bad)} of {len(polys)} faces are not triangles): "
            "hybridsub subdivides triangle meshes; triangulate it first (--triangulate on the command line, "
            "read_mesh(..., triangulate=True) in Python)"
        )
    tris, origin = [], []
    for f, p in enumerate(polys):
        for i in range(1, len(p) - 1):
            tris.append((p[0], p[i], p[i + 1]))
            origin.append(f)
    return np.array(tris, dtype=np.int64).reshape(-1, 3), np.array(origin, dtype=np.int64)


def check_indices(path: str, F: np.ndarray, n: int, what: str, name: Callable[[int], str], base: int = 0) -> None:
    """Raise MeshError naming the first row of ``F`` with an index outside ``0..n-1`` (``name(f)``
    names row f); indices are shown counted from ``base``, as the file counts them (OBJ: 1).

    >>> check_indices("t.obj", np.array([[0, 1, 3]]), 3, "vertex", lambda f: f"face {f}", base=1)
    Traceback (most recent call last):
    ...
    hybridsub._errors.MeshError: t.obj: face 0 refers to vertex 4, but there are only 3 (valid 1..3)
    """
    if F.size == 0:
        return
    bad = ((F < 0) | (F >= n)).any(axis=1)
    if bad.any():
        f = int(np.flatnonzero(bad)[0])
        i = int(F[f][(F[f] < 0) | (F[f] >= n)][0])
        shown = f"{what} {i + base}" if base else f"{what} index {i}"
        raise MeshError(f"{path}: {name(f)} refers to {shown}, but there are only {n} (valid {base}..{n - 1 + base})")


def check_faces(path: str, F: np.ndarray, n: int, origin: np.ndarray | None, base: int = 0) -> None:
    """:func:`check_indices` for triangles of ``n`` vertices; errors name the file's face
    (``origin``: the polygon of each triangle, None where the file has triangles only)."""
    check_indices(path, F, n, "vertex", lambda f: f"face {int(origin[f]) if origin is not None else f}", base)


def text_rows(prefix: str, A: np.ndarray, fmt: str) -> list[str]:
    """Format rows of A as text lines, in chunks (one % per chunk is fast in CPython).

    >>> text_rows("f ", np.array([[1, 2, 3]]), "%d")
    ['f 1 2 3\\n']
    """
    if A.size == 0:
        return []
    row = prefix + " ".join([fmt] * (A.shape[1] // fmt.count("%"))) + "\n"
    out, chunk = [], 65536
    for s in range(0, len(A), chunk):
        block = A[s:s + chunk]
        out.append((row * len(block)) % tuple(block.ravel().tolist()))
    return out

