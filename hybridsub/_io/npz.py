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
              "face_uv")


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
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, OSError, EOFError, ValueError) as e:
        raise MeshError(f"{path}: not a readable NPZ file ({type(e).__name__}: {e})") from None
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
    except (MeshError, TypeError) as e:
        raise MeshError(f"{path}: {e}") from None
    ignored = sorted(set(arrays) - set(NPZ_ARRAYS))
    notes = (f"ignored arrays: {', '.join(ignored)}",) if ignored else ()
    return replace(mesh, notes=notes)


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
            if A is None:
                continue
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            with z.open(info, "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(A), allow_pickle=False)

