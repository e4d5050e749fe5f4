"""Tag lists for the command line (``--sharp-edges``, ``--corners``, ``--sharp-faces``): small
text files of numbers, ``#`` comments, commas or blanks between numbers, 0-based indices."""

from __future__ import annotations

import os
from collections.abc import Iterator

import numpy as np

from .._errors import MeshError
from .mesh import sharpness_from_file


def _lines(path: str) -> Iterator[tuple[int, str, list[str]]]:
    """(line number, line, its words) of a list file, comments left out."""
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    with open(path, encoding="utf-8", errors="replace") as fh:
        for number, line in enumerate(fh, start=1):
            yield number, line, line.split("#", 1)[0].replace(",", " ").split()


def read_index_file(path: str, columns: int, what: str) -> list[list[float]]:
    """Rows of ``columns`` or ``columns + 1`` numbers (any count if ``columns`` is 0), as floats;
    ``what`` names the expected row in errors.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "e.txt")
    >>> _ = open(path, "w").write("# creases\\n0 1\\n2, 3, 0.5\\n")
    >>> read_index_file(path, 2, "'i j'")
    [[0.0, 1.0], [2.0, 3.0, 0.5]]
    """
    rows = []
    for number, line, w in _lines(path):
        if not w:
            continue
        if columns and len(w) not in (columns, columns + 1):
            raise MeshError(f"{path}: line {number}: expected {what}, got {line.strip()!r}")
        try:
            rows.append([float(x) for x in w])
        except ValueError:
            raise MeshError(f"{path}: line {number}: expected {what}, got {line.strip()!r}") from None
    return rows


def read_edge_file(path: str) -> tuple[np.ndarray, np.ndarray]:
    """``i j`` or ``i j sharpness`` per line (0-based); returns pairs and sharpness (inf default).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "e.txt")
    >>> _ = open(path, "w").write("0 1\\n2 3 0.5\\n1 2 10\\n")
    >>> E, s = read_edge_file(path)
    >>> E.tolist(), s.tolist()
    ([[0, 1], [2, 3], [1, 2]], [inf, 0.5, inf])
    """
    rows = read_index_file(path, 2, "'i j' or 'i j sharpness'")
    E = np.array([r[:2] for r in rows], dtype=np.float64).reshape(-1, 2)
    s = np.array([r[2] if len(r) > 2 else np.inf for r in rows], dtype=np.float64)
    if (E != np.round(E)).any():
        raise MeshError(f"{path}: vertex indices must be integers")
    bad = np.isnan(s) | (s < 0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: edge {j} = ({int(E[j, 0])}, {int(E[j, 1])}) has sharpness {s[j]:g}; give 0 for "
                        "no crease, > 0 for a crease (>= 10 or inf: infinitely sharp)")
    return E.astype(np.int64), sharpness_from_file(s)


def read_list_file(path: str, what: str) -> np.ndarray:
    """Indices, any number per line (0-based); ``what`` names them in errors.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "c.txt")
    >>> _ = open(path, "w").write("3 5  # corners\\n8,13\\n")
    >>> read_list_file(path, "corner indices").tolist()
    [3, 5, 8, 13]
    """
    words = [w for _, _, ws in _lines(path) for w in ws]
    try:
        A = np.array([float(w) for w in words], dtype=np.float64)
    except ValueError:
        raise MeshError(f"{path}: expected {what} (integers), found {next(w for w in words if not _isnum(w))!r}") \
            from None
    if (A != np.round(A)).any():
        raise MeshError(f"{path}: {what} must be integers")
    return A.astype(np.int64)


def _isnum(w: str) -> bool:
    try:
        float(w)
        return True
    except ValueError:
        return False
