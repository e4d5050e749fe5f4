"""PLY files: reading and writing elements (ASCII and binary), keeping vertex order and extra
elements, and PLY meshes with their tag elements.

trimesh's PLY loader unmerges vertices when faces carry texture coordinates and turns an
``edge`` element into a path, so hybridsub reads PLY itself: tags refer to vertex indices and
must find the vertices where the file put them. Only what hybridsub needs is interpreted
(vertex x/y/z, colours, UVs; face vertex_indices and texcoord; the ``edge``, ``corner`` and
``sharp_face`` elements, see docs/formats.md); every other element is read and skipped.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._errors import MeshError
from .._input import count_of
from .._version import __version__
from .mesh import INFINITE, TaggedMesh, color_bytes, sharpness_from_file, sharpness_to_file
from .tables import check_faces, triangulate_polygons

_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


class _Element:
    def __init__(self, name: str, count: int):
        self.name = name
        self.count = count
        self.props: list[tuple] = []  # (name, dtype) or (name, count dtype, item dtype)
        self.data: dict[str, Any] = {}

    @property
    def has_lists(self) -> bool:
        return any(len(p) == 3 for p in self.props)


def _parse_header(raw: bytes, path: str):
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise MeshError(f"{path}: not a PLY file (no 'ply' ... 'end_header' header)")
    stop = raw.find(b"\n", end) + 1
    if stop == 0:
        stop = len(raw)
    lines = raw[:end].decode("ascii", errors="replace").splitlines()
    fmt, elements = None, []
    for number, line in enumerate(lines[1:], start=2):
        w = line.split()
        if not w or w[0] in ("comment", "obj_info"):
            continue
        try:
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                elements.append(_Element(w[1], int(w[2])))
            elif w[0] == "property":
                if not elements:
                    raise ValueError("property before any element")
                if w[1] == "list":
                    elements[-1].props.append((w[4], _TYPES[w[2]], _TYPES[w[3]]))
                else:
                    elements[-1].props.append((w[2], _TYPES[w[1]]))
            else:
                raise ValueError(f"unknown keyword {w[0]!r}")
        except (IndexError, KeyError, ValueError) as e:
            raise MeshError(f"{path}: PLY header line {number} {line.strip()!r} is not valid ({e})") from None
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise MeshError(f"{path}: unknown PLY format {fmt!r}")
    return fmt, elements, stop


def read_ply(path: str) -> dict[str, _Element]:
    """Read every element of a PLY file; returns {name: element} with ``element.data`` filled.

    Scalar properties become (count,) arrays, list properties (count, L) arrays when every
    list has the same length L, else Python lists of arrays.
    """
    with open(path, "rb") as fh:
        raw = fh.read()
    fmt, elements, pos = _parse_header(raw, path)
    if fmt == "ascii":
        _read_ascii(raw[pos:], elements, path)
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        _read_binary(raw, pos, elements, order, path)
    return {e.name: e for e in elements}


def _read_ascii(body: bytes, elements: list[_Element], path: str) -> None:
    lines = body.decode("ascii", errors="replace").splitlines()
    lines = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("comment")]
    start = 0
    for el in elements:
        rows = lines[start:start + el.count]
        if len(rows) < el.count:
            raise MeshError(f"{path}: the file ends inside element '{el.name}' "
                            f"({len(rows)} of {el.count} lines)")
        start += el.count
        if el.count == 0:
            _empty(el)
            continue
        tokens = [r.split() for r in rows]
        widths = {len(t) for t in tokens}
        try:
            if len(widths) == 1:
                table = np.array(tokens, dtype=np.float64)
                col = 0
                for p in el.props:
                    if len(p) == 2:
                        el.data[p[0]] = table[:, col].astype(p[1])
                        col += 1
                    else:
                        n = table[:, col].astype(np.int64)
                        if (n != n[0]).any():
                            raise _Ragged
                        el.data[p[0]] = table[:, col + 1:col + 1 + n[0]].astype(p[2])
                        col += 1 + int(n[0])
            else:
                raise _Ragged
        except _Ragged:
            _ascii_rows(tokens, el)
        except ValueError as e:
            raise MeshError(f"{path}: element '{el.name}' holds a value that is not a number ({e})") from None


class _Ragged(Exception):
    pass


def _ascii_rows(tokens: list[list[str]], el: _Element) -> None:
    cols: dict[str, list] = {p[0]: [] for p in el.props}
    for t in tokens:
        i = 0
        for p in el.props:
            if len(p) == 2:
                cols[p[0]].append(float(t[i]))
                i += 1
            else:
                n = int(float(t[i]))
                cols[p[0]].append(np.array(t[i + 1:i + 1 + n], dtype=np.float64).astype(p[2]))
                i += 1 + n
    for p in el.props:
        el.data[p[0]] = np.array(cols[p[0]], dtype=p[1]) if len(p) == 2 else cols[p[0]]


def _empty(el: _Element) -> None:
    for p in el.props:
        el.data[p[0]] = np.empty(0, p[1]) if len(p) == 2 else np.empty((0, 0), p[2])


def _read_binary(raw: bytes, pos: int, elements: list[_Element], order: str, path: str) -> None:
    for el in elements:
        if el.count == 0:
            _empty(el)
            continue
        fields: list[tuple] = []
        lengths: list[int] = []
        # Fast path: assume every list has the length of the first record's list.
        probe = pos
        for p in el.props:
            if len(p) == 2:
                fields.append((p[0], order + p[1]))
                probe += np.dtype(p[1]).itemsize
            else:
                if probe + np.dtype(p[1]).itemsize > len(raw):
                    raise MeshError(f"{path}: the file ends inside element '{el.name}'")
                n = int(np.frombuffer(raw, order + p[1], 1, probe)[0])
                lengths.append(n)
                fields.append((p[0] + "#n", order + p[1]))
                fields.append((p[0], order + p[2], (n,)))
                probe += np.dtype(p[1]).itemsize + n * np.dtype(p[2]).itemsize
        dt = np.dtype(fields)
        ok = pos + dt.itemsize * el.count <= len(raw)
        if ok:
            rec = np.frombuffer(raw, dt, el.count, pos)
            ok = all((rec[p[0] + "#n"] == n).all() for p, n in zip((q for q in el.props if len(q) == 3), lengths))
        if ok:
            for p in el.props:
                el.data[p[0]] = np.array(rec[p[0]])
            pos += dt.itemsize * el.count
            continue
        pos = _binary_rows(raw, pos, el, order, path)


def _binary_rows(raw: bytes, pos: int, el: _Element, order: str, path: str) -> int:
    """Record by record, for elements whose lists differ in length (polygons)."""
    cols: dict[str, list] = {p[0]: [] for p in el.props}
    try:
        for _ in range(el.count):
            for p in el.props:
                if len(p) == 2:
                    cols[p[0]].append(np.frombuffer(raw, order + p[1], 1, pos)[0])
                    pos += np.dtype(p[1]).itemsize
                else:
                    n = int(np.frombuffer(raw, order + p[1], 1, pos)[0])
                    pos += np.dtype(p[1]).itemsize
                    cols[p[0]].append(np.frombuffer(raw, order + p[2], n, pos).astype(p[2]))
                    pos += n * np.dtype(p[2]).itemsize
    except ValueError:
        raise MeshError(f"{path}: the file ends inside element '{el.name}'") from None
    for p in el.props:
        el.data[p[0]] = np.array(cols[p[0]], dtype=p[1]) if len(p) == 2 else cols[p[0]]
    return pos


def write_ply(path: str, elements: list[tuple[str, list[tuple]]], *, binary: bool = True,
              comments: tuple[str, ...] = ()) -> None:
    """Write elements ``[(name, [(prop, dtype, values), ...]), ...]``.

    A property whose values are 2-D ``(count, L)`` is written as a list property with a
    ``uchar`` count. dtypes are numpy codes ("f8", "i4", "u1", ...).
    """
    names = {v: k for k, v in reversed(list(_TYPES.items()))}
    head = ["ply", "format " + ("binary_little_endian 1.0" if binary else "ascii 1.0")]
    head += [f"comment {c}" for c in comments]
    for name, props in elements:
        count = len(props[0][2]) if props else 0
        head.append(f"element {name} {count}")
        for prop, dt, values in props:
            if np.ndim(values) == 2:
                head.append(f"property list uchar {names[dt]} {prop}")
            else:
                head.append(f"property {names[dt]} {prop}")
    head.append("end_header")
    with open(path, "wb") as fh:
        fh.write(("\n".join(head) + "\n").encode("ascii"))
        for _name, props in elements:
            if not props or len(props[0][2]) == 0:
                continue
            if binary:
                fields: list[tuple] = []
                cols: list[np.ndarray] = []
                for prop, dt, values in props:
                    values = np.asarray(values)
                    if values.ndim == 2:
                        fields.append((prop + "#n", "u1"))
                        cols.append(np.full(len(values), values.shape[1], np.uint8))
                        fields.append((prop, "<" + dt, (values.shape[1],)))
                    else:
                        fields.append((prop, "<" + dt))
                    cols.append(values)
                rec = np.empty(len(cols[0]), np.dtype(fields))
                for (fname, *_), col in zip(fields, cols):
                    rec[fname] = col
                fh.write(rec.tobytes())
            else:
                _write_ascii_rows(fh, props)


def _write_ascii_rows(fh, props) -> None:
    fmts, cols = [], []
    for _prop, dt, values in props:
        values = np.asarray(values)
        f = "%r" if dt[0] == "f" else "%d"
        if values.ndim == 2:
            fmts.append("%d")
            cols.append([values.shape[1]] * len(values))
            fmts.extend([f] * values.shape[1])
            cols.extend(values.astype(dt).T.tolist())
        else:
            fmts.append(f)
            cols.append(values.astype(dt).tolist())
    row = " ".join(fmts) + "\n"
    rows = list(zip(*cols))
    chunk = 65536
    for s in range(0, len(rows), chunk):
        block = rows[s:s + chunk]
        fh.write(((row * len(block)) % tuple(v for r in block for v in r)).encode("ascii"))


# ----------------------------------------------------------------------------------------------
# meshes

def read_ply_mesh(path: str, triangulate: bool) -> TaggedMesh:
    """Read a PLY mesh with its ``crease`` (or ``edge``), ``corner`` and ``sharp_face``
    elements (see :func:`hybridsub.read_mesh`).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.ply")
    >>> write_ply_mesh(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([1])), binary=True)
    >>> m = read_ply_mesh(path, False)
    >>> m.faces.tolist(), m.corners.tolist()
    ([[0, 1, 2]], [1])
    """
    el = read_ply(path)
    V, colors = _ply_vertices(path, el)
    n = len(V)
    fd = el["face"].data if "face" in el else {}
    key = next((k for k in ("vertex_indices", "vertex_index") if k in fd), None)
    if key is None:
        raise MeshError(f"{path}: not a triangle mesh (no 'face' element with vertex_indices)")
    idx = fd[key]
    polys = idx if isinstance(idx, list) else np.asarray(idx)
    if isinstance(polys, np.ndarray) and polys.ndim == 2 and polys.shape[1] == 3:
        F, origin = polys.astype(np.int64), None
    else:
        F, origin = triangulate_polygons(path, [list(map(int, p)) for p in polys], triangulate)
    check_faces(path, F, n, origin)
    uv, face_uv = _ply_uv(el["vertex"].data, fd, F, origin)
    notes = [f"triangulated {count_of(len(polys), 'polygon')} into {count_of(len(F), 'triangle')}"] if origin is not None else []
    E, s = _ply_creases(path, el, n)
    C = _ply_corners(path, el, n)
    S = _ply_sharp_faces(path, el, len(polys), origin)
    return TaggedMesh(np.ascontiguousarray(V), np.ascontiguousarray(F), E, s, C, S, colors, uv, face_uv,
                      tuple(notes))


def _ply_vertices(path: str, el: dict[str, _Element]) -> tuple[np.ndarray, np.ndarray | None]:
    """Positions and colours (or None) of the ``vertex`` element."""
    if "vertex" not in el:
        raise MeshError(f"{path}: the PLY file has no 'vertex' element")
    vd = el["vertex"].data
    if not all(k in vd for k in "xyz"):
        raise MeshError(f"{path}: the PLY 'vertex' element has no x, y, z properties")
    V = np.column_stack([np.asarray(vd[k], dtype=np.float64) for k in "xyz"]).reshape(-1, 3)
    colors = None
    if all(k in vd for k in ("red", "green", "blue")):
        cols = [vd[k] for k in ("red", "green", "blue", "alpha") if k in vd]
        scale = 255.0 if np.asarray(cols[0]).dtype.kind in "iu" else 1.0
        colors = np.column_stack(cols).astype(np.float64) / scale
    return V, colors


def _ply_uv(vd: dict, fd: dict, F: np.ndarray, origin: np.ndarray | None):
    """(uv, face_uv): per vertex (s/t, u/v or texture_u/texture_v), or per face corner
    (``texcoord`` lists of six), or (None, None)."""
    names = next(((a, b) for a, b in (("s", "t"), ("u", "v"), ("texture_u", "texture_v"))
                  if a in vd and b in vd), None)
    if names:
        return np.column_stack([np.asarray(vd[k], dtype=np.float64) for k in names]), F.copy()
    if "texcoord" in fd and origin is None and np.ndim(fd["texcoord"]) == 2 and np.shape(fd["texcoord"])[1] == 6:
        uv = np.asarray(fd["texcoord"], dtype=np.float64).reshape(-1, 2)
        return uv, np.arange(len(uv), dtype=np.int64).reshape(-1, 3)
    return None, None


def _ply_creases(path: str, el: dict[str, _Element], n: int) -> tuple[np.ndarray, np.ndarray]:
    """Crease pairs and sharpness of the ``crease`` (or ``edge``) element; sharpness <= 0 left out."""
    tag = "crease" if "crease" in el else "edge" if "edge" in el else None
    if not tag:
        return np.empty((0, 2), np.int64), np.empty(0)
    ed = el[tag].data
    if not ("vertex1" in ed and "vertex2" in ed):
        raise MeshError(f"{path}: the PLY '{tag}' element needs vertex1 and vertex2 properties")
    E = np.column_stack([np.asarray(ed["vertex1"]), np.asarray(ed["vertex2"])]).astype(np.int64).reshape(-1, 2)
    sk = next((k for k in ("crease", "sharpness") if k in ed), None)
    s = np.asarray(ed[sk], dtype=np.float64) if sk else np.full(len(E), np.inf)
    bad = ((E < 0) | (E >= n)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: {tag} {j} names vertices {E[j].tolist()}, but there are {n} vertices")
    keep = s > 0
    return E[keep], sharpness_from_file(s[keep])


def _ply_corners(path: str, el: dict[str, _Element], n: int) -> np.ndarray:
    """Sorted corner vertices of the ``corner`` element (those of sharpness <= 0 left out)."""
    if "corner" not in el:
        return np.empty(0, np.int64)
    cd = el["corner"].data
    ck = next((k for k in ("vertex", "vertex_index") if k in cd), None)
    if ck is None:
        raise MeshError(f"{path}: the PLY 'corner' element needs a 'vertex' property")
    C = np.asarray(cd[ck], dtype=np.int64)
    if "sharpness" in cd:
        C = C[np.asarray(cd["sharpness"]) > 0]
    if ((C < 0) | (C >= n)).any():
        raise MeshError(f"{path}: a corner names vertex {int(C[(C < 0) | (C >= n)][0])}, but there are {n}")
    return np.unique(C)


def _ply_sharp_faces(path: str, el: dict[str, _Element], nf: int, origin: np.ndarray | None) -> np.ndarray:
    """Sharp faces of the ``sharp_face`` element, as triangles (``origin``: polygon of each)."""
    if "sharp_face" not in el:
        return np.empty(0, np.int64)
    S = np.asarray(el["sharp_face"].data.get("face", np.empty(0)), dtype=np.int64)
    if ((S < 0) | (S >= nf)).any():
        raise MeshError(f"{path}: a sharp_face names face {int(S[(S < 0) | (S >= nf)][0])}, but there are {nf}")
    return np.flatnonzero(np.isin(origin, S)) if origin is not None else np.unique(S)


def write_ply_mesh(path: str, m: TaggedMesh, binary: bool) -> None:
    """Write ``m`` as PLY (binary little-endian or ASCII) with ``crease`` (vertex1, vertex2,
    sharpness; 10 = infinitely sharp), ``corner`` and ``sharp_face`` elements.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.ply")
    >>> write_ply_mesh(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]])), binary=False)
    >>> open(path).read().splitlines()[-2:]
    ['0.0 0.0 1.0', '3 0 1 2']
    """
    vertex = [("x", "f8", m.vertices[:, 0]), ("y", "f8", m.vertices[:, 1]), ("z", "f8", m.vertices[:, 2])]
    if m.vertex_colors is not None:
        c = color_bytes(m.vertex_colors)
        vertex += [(k, "u1", c[:, i]) for i, k in enumerate(("red", "green", "blue", "alpha")[:c.shape[1]])]
    face = [("vertex_indices", "i4", m.faces.astype(np.int32))]
    vuv = m.vertex_uv
    if vuv is not None:
        vertex += [("s", "f4", vuv[:, 0]), ("t", "f4", vuv[:, 1])]
    elif m.uv is not None:
        face.append(("texcoord", "f4", m.uv[m.face_uv].reshape(-1, 6)))
    elements = [("vertex", vertex), ("face", face)]
    if len(m.sharp_edges):
        # Not named "edge": trimesh turns an 'edge' element into a path and fails on extra properties.
        elements.append(("crease", [("vertex1", "i4", m.sharp_edges[:, 0]), ("vertex2", "i4", m.sharp_edges[:, 1]),
                                    ("sharpness", "f8", sharpness_to_file(m.sharpness))]))
    if len(m.corners):
        elements.append(("corner", [("vertex", "i4", m.corners), ("sharpness", "f8",
                                                                 np.full(len(m.corners), INFINITE))]))
    if len(m.sharp_faces):
        elements.append(("sharp_face", [("face", "i4", m.sharp_faces)]))
    write_ply(path, elements, binary=binary, comments=(
        f"hybridsub {__version__}",
        "crease: 0-based vertex1 vertex2 and sharpness (10 = infinitely sharp); corner: vertex, sharpness",
    ))
