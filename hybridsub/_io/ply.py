"""PLY reading and writing (ASCII and binary), keeping vertex order and extra elements.

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
