"""OFF files (and COFF, with vertex colours): geometry only, vertices in file order.

Two readers: :func:`read_off_mesh`, behind :func:`hybridsub.read_mesh` (colours, polygons,
errors that name the line's problem), and :func:`read_off`, the plain triangle loader of the
shipped examples and the test data (about twice as fast on fandisk).
"""

from __future__ import annotations

import numpy as np

from .._errors import MeshError
from .._input import count_of
from .mesh import TaggedMesh, unit_colors
from .tables import check_faces, text_rows, triangulate_polygons


def read_off_mesh(path: str, triangulate: bool) -> TaggedMesh:
    """Read an OFF or COFF file (see :func:`hybridsub.read_mesh`).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.off")
    >>> _ = open(path, "w").write("OFF\\n4 1 0\\n0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n4 0 1 2 3\\n")
    >>> m = read_off_mesh(path, True)
    >>> m.faces.tolist(), m.notes
    ([[0, 1, 2], [0, 2, 3]], ('triangulated 1 polygon into 2 triangles',))
    """
    with open(path, encoding="utf-8", errors="replace") as fh:
        lines = [ln.split("#", 1)[0].split() for ln in fh]
    lines = [w for w in lines if w]
    if not lines or not lines[0][0].endswith("OFF"):
        raise MeshError(f"{path}: not an OFF file (it must start with 'OFF')")
    head = lines[0]
    colored = "C" in head[0]
    rest = head[1:] if len(head) > 1 else lines[1] if len(lines) > 1 else []
    body = lines[1:] if len(head) > 1 else lines[2:]
    try:
        nv, nf = int(rest[0]), int(rest[1])
        if nv < 0 or nf < 0:
            raise ValueError
    except (IndexError, ValueError):
        raise MeshError(f"{path}: the OFF header needs vertex and face counts (whole numbers >= 0)") from None
    if len(body) < nv + nf:
        raise MeshError(f"{path}: the file ends early: the header promises {nv} vertices and {nf} faces")
    try:
        vrows = body[:nv]
        width = min(len(r) for r in vrows) if nv else 3
        A = np.array([r[:width] for r in vrows], dtype=np.float64).reshape(nv, -1)
        polys = [[int(x) for x in r[1:1 + int(r[0])]] for r in body[nv:nv + nf]]
    except ValueError:
        raise MeshError(f"{path}: a vertex or face line holds something that is not a number") from None
    V = np.ascontiguousarray(A[:, :3])
    colors = None
    if colored and A.shape[1] >= 6:
        colors = unit_colors(A[:, 3:7])
    F, origin = triangulate_polygons(path, polys, triangulate)
    check_faces(path, F, nv, origin)
    notes = (f"triangulated {count_of(nf, 'polygon')} into {count_of(len(F), 'triangle')}",) if origin is not None else ()
    return TaggedMesh(V, F, vertex_colors=colors, notes=notes)


def write_off(path: str, m: TaggedMesh) -> None:
    """Write ``m`` as OFF, or COFF (RGBA floats in [0, 1]) where it has vertex colours.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.off")
    >>> write_off(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]])))
    >>> open(path).read().splitlines()[:3]
    ['OFF', '3 1 0', '1.0 0.0 0.0']
    """
    parts = []
    if m.vertex_colors is not None:
        rgba = np.hstack([m.vertex_colors[:, :3], m.vertex_colors[:, 3:4] if m.vertex_colors.shape[1] == 4
                          else np.ones((len(m.vertices), 1))])
        parts.append(f"COFF\n{len(m.vertices)} {len(m.faces)} 0\n")
        parts += text_rows("", np.hstack([m.vertices, rgba]), "%r")
    else:
        parts.append(f"OFF\n{len(m.vertices)} {len(m.faces)} 0\n")
        parts += text_rows("", m.vertices, "%r")
    parts += text_rows("3 ", m.faces, "%d")
    with open(path, "w") as fh:
        fh.writelines(parts)


def read_off(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Read a triangle mesh from an OFF file as ``(V, F)``, without merging or reordering anything.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.off")
    >>> _ = open(path, "w").write("OFF\\n3 1 0\\n0 0 0\\n1 0 0\\n0 1 0\\n3 0 1 2\\n")
    >>> V, F = read_off(path)
    >>> V.shape, F.tolist()
    ((3, 3), [[0, 1, 2]])
    """
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
