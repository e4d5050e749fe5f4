"""PLY files: elements read through plyfile (ASCII and binary, vertex order kept, every
element read), written with NumPy, and PLY meshes with their tags.

trimesh's PLY loader unmerges vertices when faces carry texture coordinates and turns an
``edge`` element into a path, so hybridsub reads PLY through plyfile, which keeps every element
as the file has it: tags refer to vertex indices and must find the vertices where the file put
them. Only what hybridsub needs is interpreted (vertex x/y/z, colours, UVs; face
vertex_indices and texcoord; the tag comments, and the ``crease``/``edge``, ``corner`` and
``sharp_face`` elements of older files, see docs/formats.md); every other element is skipped.

Writing stays here: plyfile writes an element with a list property (every face) record by
record in Python, about 100 times slower than one NumPy record array.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from .._errors import MeshError
from .._input import count_of
from .._version import __version__
from .mesh import INFINITE, TaggedMesh, color_bytes, corner_tags, corner_values, sharpness_from_file, sharpness_to_file
from .tables import check_faces, triangulate_polygons

_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}

#: Fixed list lengths tried first when reading (plyfile then maps the element in one go); a
#: file whose lists differ (polygons) is read again record by record.
_KNOWN_LISTS = {"face": {"vertex_indices": 3, "vertex_index": 3, "texcoord": 6}}


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
    fmt, elements, comments = None, [], []
    for number, line in enumerate(lines[1:], start=2):
        w = line.split()
        if w and w[0] in ("comment", "obj_info"):
            comments.append(line.split(maxsplit=1)[1] if len(w) > 1 else "")
            continue
        if not w:
            continue
        try:
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                if not w[2].isdigit():
                    raise ValueError("an element count is a whole number >= 0")
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
    return fmt, elements, stop, comments


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
            if len(widths) != 1:
                raise _Ragged
            try:
                table = np.array(tokens, dtype=np.float64)
            except ValueError:
                raise _Ragged from None  # the row by row reader names the row
            col = 0
            for p in el.props:
                if col >= table.shape[1]:
                    raise _Ragged
                if len(p) == 2:
                    el.data[p[0]] = _typed(path, el, p[0], table[:, col], p[1])
                    col += 1
                else:
                    n = _typed(path, el, p[0] + " (its length)", table[:, col], "i8")
                    if (n != n[0]).any() or n[0] < 0 or col + 1 + n[0] > table.shape[1]:
                        raise _Ragged
                    el.data[p[0]] = _typed(path, el, p[0], table[:, col + 1:col + 1 + n[0]], p[2])
                    col += 1 + int(n[0])
        except _Ragged:
            _ascii_rows(path, tokens, el)


class _Ragged(Exception):
    pass


def _typed(path: str, el: _Element, prop: str, values: np.ndarray, dtype: str, row: int | None = None) -> np.ndarray:
    """``values`` (floats as read) as ``dtype``; an integer property must hold whole numbers in
    its type's range (a NaN or 1e30 would become some arbitrary index)."""
    if np.dtype(dtype).kind in "iu":
        info = np.iinfo(dtype)
        bad = ~np.isfinite(values) | (values != np.round(values)) | (values < info.min) | (values > info.max)
        if bad.any():
            i = np.unravel_index(int(np.flatnonzero(bad)[0]), values.shape)
            r = row if row is not None else int(i[0])
            raise MeshError(f"{path}: element '{el.name}' row {r}: {prop} is {float(values[i])!r}, not a whole number "
                            f"of type {dtype}")
    return values.astype(dtype)


def _ascii_rows(path: str, tokens: list[list[str]], el: _Element) -> None:
    cols: dict[str, list] = {p[0]: [] for p in el.props}
    for r, t in enumerate(tokens):
        i = 0
        try:
            for p in el.props:
                if len(p) == 2:
                    cols[p[0]].append(float(t[i]))
                    i += 1
                else:
                    n = int(_typed(path, el, p[0] + " (its length)", np.array([float(t[i])]), "i8", r)[0])
                    if n < 0 or i + 1 + n > len(t):
                        raise MeshError(f"{path}: element '{el.name}' row {r}: a list of {n} values, but the row "
                                        f"holds {len(t) - i - 1} more")
                    cols[p[0]].append(_typed(path, el, p[0], np.array(t[i + 1:i + 1 + n], dtype=np.float64), p[2], r))
                    i += 1 + n
        except IndexError:
            raise MeshError(f"{path}: element '{el.name}' row {r} holds {len(t)} values, fewer than its properties "
                            f"({', '.join(p[0] for p in el.props)}) need") from None
        except ValueError as e:
            if isinstance(e, MeshError):
                raise
            raise MeshError(f"{path}: element '{el.name}' row {r} holds a value that is not a number ({e})") from None
    for p in el.props:
        if len(p) == 2:
            el.data[p[0]] = _typed(path, el, p[0], np.array(cols[p[0]], dtype=np.float64), p[1])
        else:
            el.data[p[0]] = cols[p[0]]


def _empty(el: _Element) -> None:
    for p in el.props:
        el.data[p[0]] = np.empty(0, p[1]) if len(p) == 2 else np.empty((0, 0), p[2])


def _read_ply_ascii(path: str) -> tuple[dict[str, dict[str, Any]], list[str]]:
    """:func:`read_ply` for an ASCII file: whole tables parsed by NumPy, where plyfile parses
    value by value (25 s instead of 6.8 s for 350k faces)."""
    with open(path, "rb") as fh:
        raw = fh.read()
    fmt, elements, pos, comments = _parse_header(raw, path)
    _read_ascii(raw[pos:], elements, path)
    return {e.name: e.data for e in elements}, comments


def _check_binary_counts(path: str) -> None:
    """MeshError where a binary PLY header declares more elements than the file's size can hold
    (each record takes at least its scalars and its lists' counts): before plyfile allocates
    for them, or fails on a count that does not fit an index."""
    size = os.path.getsize(path)
    raw = b""
    with open(path, "rb") as fh:
        while b"end_header" not in raw and len(raw) < size:
            raw += fh.read(1 << 20)
    if b"end_header" not in raw:
        return  # plyfile says what is wrong with the header
    _fmt, elements, stop, _ = _parse_header(raw, path)
    left = size - stop
    for el in elements:
        least = sum(np.dtype(p[1]).itemsize for p in el.props)
        if el.count * least > left:
            raise MeshError(f"{path}: the header declares {el.count:,} '{el.name}' elements, at least "
                            f"{el.count * least:,} bytes, but only {left:,} bytes follow: the file is damaged or cut "
                            "short")
        left -= el.count * least


def read_ply(path: str) -> tuple[dict[str, dict[str, Any]], list[str]]:
    """Every element of a PLY file, through plyfile: ``({element: {property: values}}, comments)``.

    Scalar properties are (count,) arrays; list properties (count, L) arrays when every list
    has the same length L, else lists of arrays.
    """
    import plyfile

    with open(path, "rb") as fh:
        head = fh.read(64)
    if b"format ascii" in head:
        return _read_ply_ascii(path)
    _check_binary_counts(path)
    try:
        try:
            data = plyfile.PlyData.read(path, known_list_len=_KNOWN_LISTS)
        except plyfile.PlyElementParseError as e:
            if e.message != "unexpected list length":
                raise
            data = plyfile.PlyData.read(path, mmap=False)  # lists of different lengths: record by record
    except plyfile.PlyHeaderParseError as e:
        first = open(path, "rb").read(3)
        if first != b"ply":
            raise MeshError(f"{path}: not a PLY file (no 'ply' ... 'end_header' header)") from None
        raise MeshError(f"{path}: the PLY header is not valid ({e.message}, line {e.line})") from None
    except plyfile.PlyElementParseError as e:
        where = f" (element '{e.element.name}', row {e.row})" if e.element is not None else ""
        if "end-of-file" in e.message:
            raise MeshError(f"{path}: the file ends inside element '{e.element.name}' ({e.message}{where})") from None
        raise MeshError(f"{path}: PLY data not valid: {e.message}{where}") from None
    except (ValueError, EOFError, OverflowError, IndexError, KeyError, TypeError) as e:
        raise MeshError(f"{path}: not a valid PLY file ({type(e).__name__}: {e})") from None
    out: dict[str, dict[str, Any]] = {}
    for el in data.elements:
        cols: dict[str, Any] = {}
        for prop in el.properties:
            col = el.data[prop.name]
            if col.dtype == object:  # list property read record by record
                lengths = {len(x) for x in col}
                col = np.stack(list(col)) if len(lengths) == 1 else list(col)
            cols[prop.name] = np.array(col) if isinstance(col, np.ndarray) else col
        out[el.name] = cols
    return out, list(data.comments) + list(data.obj_info)


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
    """Read a PLY mesh with its tags: the ``crease`` / ``corner`` / ``sharp_face`` comment lines
    hybridsub writes, and the ``crease`` (or ``edge``), ``corner`` and ``sharp_face``
    elements of older files and other writers (see :func:`hybridsub.read_mesh`).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.ply")
    >>> write_ply_mesh(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([1])), binary=True)
    >>> m = read_ply_mesh(path, False)
    >>> m.faces.tolist(), m.corners.tolist()
    ([[0, 1, 2]], [1])
    """
    el, comments = read_ply(path)
    V, colors = _ply_vertices(path, el)
    n = len(V)
    fd = el.get("face", {})
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
    uv, face_uv = _ply_uv(el["vertex"], fd, F, origin)
    notes = [f"triangulated {count_of(len(polys), 'polygon')} into {count_of(len(F), 'triangle')}"] if origin is not None else []
    tags = _comment_tags(path, comments)
    E, s = _ply_creases(path, el, tags, n)
    C, Cs = _ply_corners(path, el, tags, n)
    S = _ply_sharp_faces(path, el, tags, len(polys), origin)
    H = _ply_holes(path, tags, len(polys), origin)
    return TaggedMesh(np.ascontiguousarray(V), np.ascontiguousarray(F), E, s, C, S, colors, uv, face_uv,
                      tuple(notes), corner_sharpness=Cs, holes=H)


def _ply_vertices(path: str, el: dict[str, dict]) -> tuple[np.ndarray, np.ndarray | None]:
    """Positions and colours (or None) of the ``vertex`` element."""
    if "vertex" not in el:
        raise MeshError(f"{path}: the PLY file has no 'vertex' element")
    vd = el["vertex"]
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


#: Header comments that hold hybridsub's tags (every PLY reader skips comments), and the
#: numbers per tag: crease v1 v2 sharpness; corner v sharpness; sharp_face f; hole f.
_TAG_WIDTH = {"crease": 3, "corner": 2, "sharp_face": 1, "hole": 1}
_TAGS_PER_LINE = 16


def _comment_tags(path: str, comments: list[str]) -> dict[str, np.ndarray]:
    """The tag comment lines as (k, width) float arrays, by tag name."""
    rows: dict[str, list[str]] = {k: [] for k in _TAG_WIDTH}
    for line in comments:
        w = line.split(maxsplit=1)
        if w and w[0] in _TAG_WIDTH:
            rows[w[0]].append(w[1] if len(w) > 1 else "")
    out = {}
    for name, lines in rows.items():
        if not lines:
            continue
        try:
            A = np.array(" ".join(lines).split(), dtype=np.float64)
        except ValueError as e:
            raise MeshError(f"{path}: a 'comment {name}' header line holds a value that is not a number "
                            f"({e})") from None
        if A.size % _TAG_WIDTH[name]:
            raise MeshError(f"{path}: the 'comment {name}' header lines hold {A.size} numbers, not a multiple of "
                            f"{_TAG_WIDTH[name]} ({name}: " + ", ".join(_TAG_FIELDS[name]) + ")")
        if not np.isfinite(A).all():
            raise MeshError(f"{path}: a 'comment {name}' header line holds a value that is not finite")
        out[name] = A.reshape(-1, _TAG_WIDTH[name])
    return out


_TAG_FIELDS = {"crease": ("vertex1", "vertex2", "sharpness"), "corner": ("vertex", "sharpness"),
               "sharp_face": ("face",), "hole": ("face",)}


def _vertex_ids(path: str, what: str, A: np.ndarray, n: int, noun: str = "vertices") -> np.ndarray:
    """Float indices from a file as int64, each checked to be a whole number in 0..n-1."""
    bad = (A != np.round(A)) | (A < 0) | (A >= n)
    if bad.any():
        j = int(np.flatnonzero(bad.reshape(len(A), -1).any(axis=1))[0])
        raise MeshError(f"{path}: {what} {j} names {noun} {A[j].tolist()}, but there are {n} (valid 0..{n - 1})")
    return A.astype(np.int64)


def _ply_creases(path: str, el: dict[str, dict], tags: dict, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Crease pairs and sharpness of the ``crease`` comments and the ``crease`` (or ``edge``)
    element; sharpness <= 0 left out."""
    pairs, sharp = [], []
    if "crease" in tags:
        pairs.append(_vertex_ids(path, "crease", tags["crease"][:, :2], n))
        sharp.append(tags["crease"][:, 2])
    tag = "crease" if "crease" in el else "edge" if "edge" in el else None
    if tag:
        ed = el[tag]
        if not ("vertex1" in ed and "vertex2" in ed):
            raise MeshError(f"{path}: the PLY '{tag}' element needs vertex1 and vertex2 properties")
        E = np.column_stack([np.asarray(ed["vertex1"]), np.asarray(ed["vertex2"])]).astype(np.float64).reshape(-1, 2)
        sk = next((k for k in ("crease", "sharpness") if k in ed), None)
        pairs.append(_vertex_ids(path, tag, E, n))
        sharp.append(np.asarray(ed[sk], dtype=np.float64) if sk else np.full(len(E), np.inf))
    if not pairs:
        return np.empty((0, 2), np.int64), np.empty(0)
    E, s = np.concatenate(pairs), np.concatenate(sharp)
    keep = s > 0
    return E[keep], sharpness_from_file(s[keep])


def _ply_corners(path: str, el: dict[str, dict], tags: dict, n: int) -> tuple[np.ndarray, np.ndarray | None]:
    """Sorted corner vertices of the ``corner`` comments and element (sharpness <= 0 left out)
    and their sharpness (None: all infinite, :func:`corner_tags`)."""
    found, values = [], []
    if "corner" in tags:
        c = tags["corner"]
        found.append(_vertex_ids(path, "corner", c[:, :1], n)[:, 0])
        values.append(c[:, 1])
    if "corner" in el:
        cd = el["corner"]
        ck = next((k for k in ("vertex", "vertex_index") if k in cd), None)
        if ck is None:
            raise MeshError(f"{path}: the PLY 'corner' element needs a 'vertex' property")
        C = _vertex_ids(path, "corner", np.asarray(cd[ck], dtype=np.float64)[:, None], n)[:, 0]
        found.append(C)
        values.append(np.asarray(cd["sharpness"], np.float64) if "sharpness" in cd else np.full(len(C), np.inf))
    if not found:
        return np.empty(0, np.int64), None
    return corner_tags(np.concatenate(found), np.concatenate(values))


def _ply_sharp_faces(path: str, el: dict[str, dict], tags: dict, nf: int, origin: np.ndarray | None) -> np.ndarray:
    """Sharp faces of the ``sharp_face`` comments and element, as triangles (``origin``: polygon of each)."""
    found = []
    if "sharp_face" in tags:
        found.append(tags["sharp_face"])
    if "sharp_face" in el:
        found.append(np.asarray(el["sharp_face"].get("face", np.empty(0)), dtype=np.float64)[:, None])
    if not found:
        return np.empty(0, np.int64)
    S = _vertex_ids(path, "sharp_face", np.concatenate(found), nf, "face")[:, 0]
    return np.flatnonzero(np.isin(origin, S)) if origin is not None else np.unique(S)


def _ply_holes(path: str, tags: dict, nf: int, origin: np.ndarray | None) -> np.ndarray:
    """Holes of the ``hole`` comments, as triangles (every triangle of a polygon hole)."""
    if "hole" not in tags:
        return np.empty(0, np.int64)
    H = _vertex_ids(path, "hole", tags["hole"], nf, "face")[:, 0]
    return np.flatnonzero(np.isin(origin, H)) if origin is not None else np.unique(H)


def write_ply_mesh(path: str, m: TaggedMesh, binary: bool) -> None:
    """Write ``m`` as PLY (binary little-endian or ASCII): ``vertex`` and ``face`` elements
    only, so that every PLY reader reads it (meshio reads no other element); the tags as
    header comments, which every reader skips: ``comment crease v1 v2 s …`` (0-based, sharpness
    10 = infinitely sharp), ``comment corner v s …``, ``comment sharp_face f …``,
    ``comment hole f …`` (faces not rendered, ``holes=``), up to 16 tags a line.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.ply")
    >>> write_ply_mesh(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([2])),
    ...                binary=False)
    >>> text = open(path).read().splitlines()
    >>> text[4], text[-2:]
    ('comment corner 2 10.0', ['0.0 0.0 1.0', '3 0 1 2'])
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
    comments = [f"hybridsub {__version__}"]
    if m.has_tags:
        comments.append("tags: crease vertex1 vertex2 sharpness (0-based, 10 = infinitely sharp); "
                        "corner vertex sharpness; sharp_face face; hole face")
    comments += _tag_lines("crease", [m.sharp_edges[:, 0], m.sharp_edges[:, 1], sharpness_to_file(m.sharpness)])
    comments += _tag_lines("corner", [np.asarray(m.corners), corner_values(m)])
    comments += _tag_lines("sharp_face", [np.asarray(m.sharp_faces)])
    comments += _tag_lines("hole", [np.asarray(m.holes)])
    write_ply(path, [("vertex", vertex), ("face", face)], binary=binary, comments=tuple(comments))


def _tag_lines(name: str, cols: list[np.ndarray]) -> list[str]:
    """Comment lines ``name a b s a b s …``: integer columns as integers, the last float column
    (sharpness) as the shortest text that reads back to the same float."""
    if not len(cols[0]):
        return []
    ints = [np.asarray(c, dtype=np.int64).tolist() for c in (cols[:-1] if len(cols) > 1 else cols)]
    last = [repr(float(x)) for x in cols[-1]] if len(cols) > 1 else []
    per = list(zip(*ints, last)) if last else list(zip(*ints))
    out = []
    for s in range(0, len(per), _TAGS_PER_LINE):
        out.append(name + " " + " ".join(" ".join(map(str, t)) for t in per[s:s + _TAGS_PER_LINE]))
    return out
