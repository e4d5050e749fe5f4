"""The example mesh shipped with the package."""

from __future__ import annotations

from importlib import resources

import numpy as np


def example_path(name: str = "fandisk") -> str:
    """Path of a shipped example mesh (``"fandisk"``: 6475 vertices, 12946 faces)."""
    return str(resources.files("hybridsub").joinpath("data", f"{name}.off"))


def read_off(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Read a triangle mesh from an OFF file, without merging or reordering anything."""
    with open(path) as fh:
        words = _strip_comments(fh)
    if not words or not words[0].endswith("OFF"):
        raise ValueError(f"{path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    pos = 4
    V = np.array(words[pos:pos + 3 * nv], dtype=np.float64).reshape(nv, 3)
    pos += 3 * nv
    F = np.empty((nf, 3), np.int64)
    for f in range(nf):
        k = int(words[pos])
        if k != 3:
            raise ValueError(f"{path}: face {f} has {k} vertices; only triangles are supported")
        F[f] = [int(x) for x in words[pos + 1:pos + 4]]
        pos += 1 + k
    return V, F


def _strip_comments(fh) -> list[str]:
    out = []
    for line in fh:
        out.extend(line.split("#", 1)[0].split())
    return out


def load_example(name: str = "fandisk") -> tuple[np.ndarray, np.ndarray]:
    """Load a shipped example mesh as ``(V, F)``.

    Examples
    --------
    >>> V, F = load_example()
    >>> V.shape, F.shape
    ((6475, 3), (12946, 3))
    """
    return read_off(example_path(name))
