"""Generate the OpenSubdiv references of ``boundary=`` and ``corner_sharpness=`` (Loop).

Runs ``benchmarks/peers/bin/osd_vtags`` (build it with ``benchmarks/peers/build.sh``; needs
OpenSubdiv 3.5) on each case below and writes ``<case>.npz`` beside this script: the input's
tags (``creases`` (k, 2), ``crease_sharpness`` (k,), ``corners`` (c,), ``corner_sharpness``
(c,)), the boundary mode and levels, and OpenSubdiv's refined ``V``, ``F``, the indices of
the faces it tags as holes (``holes``) and the limit position of each refined vertex
(``limit``, Far::PrimvarRefiner::Limit). Usage, from the repository root::

    python tests/data/vtags/make_references.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
BIN = ROOT / "benchmarks" / "peers" / "bin" / "osd_vtags"
BORDER = ROOT / "tests" / "data" / "mesh_with_border.off"
CUBE = ROOT / "tests" / "data" / "cube-meshed.off"


def _cases():
    """(name, mesh, levels, boundary, creases, crease sharpness, corners, corner sharpness)."""
    none2, none1 = np.empty((0, 2), np.int64), np.empty(0)
    for mode in ("edge_only", "edge_and_corner", "none"):
        yield f"border_{mode}", BORDER, 2, mode, none2, none1, np.empty(0, np.int64), none1
    # semi-sharp corners inside, on the boundary (a crease vertex blending into a corner) and
    # at a one-face boundary vertex, with a semi-sharp crease through one of them
    F = _read_off(BORDER)[1]
    yield ("border_corners", BORDER, 3, "edge_only", F[100, :2].reshape(1, 2), np.array([1.5]),
           np.array([F[100, 0], 200, 1, 0]), np.array([0.5, 2.5, 0.5, 1.0]))
    # the cube's eight corners, each its own sharpness, and a few inside the faces
    V = _read_off(CUBE)[0]
    ext = np.flatnonzero((np.abs(V) > 0.999).sum(axis=1) == 3)
    s = np.array([0.5, 1.0, 2.5, 0.5, 1.0, 2.5, 0.5, 1.0])[: len(ext)]
    inner = np.array([3, 40, 77])
    yield ("cube_corners", CUBE, 3, "edge_only", none2, none1, np.concatenate([ext, inner]),
           np.concatenate([s, [0.5, 2.5, 1.0]]))


def _read_off(path):
    words = [w for line in Path(path).read_text().splitlines() for w in line.split("#")[0].split()]
    nv, nf = int(words[1]), int(words[2])
    V = np.array(words[4:4 + 3 * nv], float).reshape(nv, 3)
    F = np.array(words[4 + 3 * nv:4 + 3 * nv + 4 * nf], np.int64).reshape(nf, 4)[:, 1:]
    return V, F


def main() -> int:
    if not BIN.exists():
        print(f"{BIN} is missing: run benchmarks/peers/build.sh", file=sys.stderr)
        return 1
    for name, mesh, levels, mode, creases, csharp, corners, vsharp in _cases():
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            np.savetxt(t / "creases.txt", np.column_stack([creases, csharp]) if len(creases) else np.empty((0, 3)),
                       fmt="%.17g")
            np.savetxt(t / "corners.txt", np.column_stack([corners, vsharp]) if len(corners) else np.empty((0, 2)),
                       fmt="%.17g")
            out = subprocess.run([str(BIN), str(mesh), str(levels), "--boundary", mode, "--creases",
                                  str(t / "creases.txt"), "--corners", str(t / "corners.txt"), "--out",
                                  str(t / "out.off"), "--limit", str(t / "limit.txt")],
                                 check=True, capture_output=True, text=True).stdout
            V, F = _read_off(t / "out.off")
            limit = np.loadtxt(t / "limit.txt").reshape(-1, 3)
        holes = np.array(out.split("holes:")[1].split(), np.int64)
        np.savez_compressed(HERE / f"{name}.npz", mesh=mesh.name, levels=levels, boundary=mode, creases=creases,
                            crease_sharpness=csharp, corners=corners, corner_sharpness=vsharp, V=V, F=F,
                            holes=holes, limit=limit)
        print(f"{name}: {len(V)} vertices, {len(F)} faces, {len(holes)} holes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
