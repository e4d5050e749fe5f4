"""NPZ mesh files: NumPy's ``savez`` format, one array per attribute of :class:`TaggedMesh`
(``inf`` for infinitely sharp), triangles only."""

from __future__ import annotations

import zipfile
from dataclasses import replace

import numpy as np

from .._errors import MeshError
from .mesh import TaggedMesh, as_tagged

#: The arrays of an NPZ mesh file, in the order written (docs/formats.md).
NPZ_ARRAYS = ("vertices", "faces", "sharp_edges", "sharpness", "corners", "sharp_faces", "vertex_colors", "uv",
              "face_uv", "corner_sharpness", "holes")


def read_npz(path: str) -> TaggedMesh:
    """Read an NPZ mesh (see :func:`hybridsub.read_mesh`); arrays not in ``NPZ_ARRAYS`` are noted and ignored.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.npz")
    >>> np.savez(path, vertices=np.eye(3), faces=[[0, 1, 2]], extra=[1])
    >>> read_npz(path).notes
    ('ignored arrays: extra',)
    """
    if not zipfile.is_zipfile(path):
        raise MeshError(f"{path}: not an NPZ file (NumPy's savez writes a zip archive; this is not one)")
    arrays = _read_arrays(path)
    missing = [k for k in ("vertices", "faces") if k not in arrays]
    if missing:
        raise MeshError(f"{path}: an NPZ mesh needs arrays 'vertices' and 'faces'; it has no {missing[0]!r} "
                        f"(it holds {', '.join(repr(k) for k in sorted(arrays)) or 'nothing'})")
    F = arrays["faces"]
    if F.ndim != 2 or F.shape[1] != 3:
        raise MeshError(f"{path}: 'faces' must have shape (m, 3) (triangles), got {F.shape}")
    if "face_uv" in arrays and "uv" not in arrays:
        raise MeshError(f"{path}: 'face_uv' needs a 'uv' array")
    try:
        mesh = as_tagged(*(arrays.get(k) for k in NPZ_ARRAYS))
    except (ValueError, TypeError) as e:
        raise MeshError(f"{path}: {e}") from None
    ignored = sorted(set(arrays) - set(NPZ_ARRAYS))
    notes = (f"ignored arrays: {', '.join(ignored)}",) if ignored else ()
    return replace(mesh, notes=notes)


def _read_arrays(path: str) -> dict[str, np.ndarray]:
    """The ``.npy`` members of the zip archive ``path`` by name. Each member's header is read
    first and its declared shape checked against the member's size, so a damaged header that
    declares terabytes is refused before anything is allocated; every failure (a damaged zip, a
    header NumPy cannot parse, an object array, data cut short) is one MeshError naming the member."""
    out = {}
    try:
        z = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError, EOFError, ValueError, NotImplementedError) as e:
        raise MeshError(f"{path}: not a readable NPZ file ({type(e).__name__}: {e})") from None
    with z:
        for info in z.infolist():
            name = info.filename
            key = name[:-4] if name.endswith(".npy") else name
            try:
                with z.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    shape, fortran, dtype = (np.lib.format.read_array_header_1_0(fh) if version == (1, 0)
                                             else np.lib.format.read_array_header_2_0(fh))
                    if dtype.hasobject:
                        raise ValueError("an array of Python objects (pickled), which is not read")
                    need = int(np.prod(shape, dtype=object)) * dtype.itemsize
                    if need > info.file_size:
                        raise ValueError(f"its header declares shape {shape} of {dtype} ({need:,} bytes), but the "
                                         f"member holds {info.file_size:,} bytes")
                with z.open(info) as fh:
                    out[key] = np.lib.format.read_array(fh, allow_pickle=False)
            except MemoryError:
                raise MeshError(f"{path}: array {key!r} does not fit in memory") from None
            except Exception as e:  # zipfile and numpy raise many kinds of errors on a damaged member
                raise MeshError(f"{path}: not a readable NPZ file: array {key!r} cannot be read ({type(e).__name__}: "
                                f"{e})") from None
    return out


def write_npz(path: str, m: TaggedMesh) -> None:
    """What np.savez writes (an uncompressed zip of .npy members), with fixed member dates so
    that the same mesh always gives the same bytes.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.npz")
    >>> write_npz(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]])))
    >>> sorted(np.load(path).files)
    ['corners', 'faces', 'sharp_edges', 'sharp_faces', 'sharpness', 'vertices']
    """
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
        for name in NPZ_ARRAYS:
            A = getattr(m, name)
            if A is None or (name == "holes" and not len(A)):  # written only when there are holes
                continue
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            with z.open(info, "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(A), allow_pickle=False)

