"""Regenerate the face-varying references of this folder with OpenSubdiv 3.5.

    benchmarks/peers/build.sh && python tests/data/fvar/generate.py

The input is a part of the textured bunny scan of ``../bunny10k_textured.fvar_linear.L1.npz``
(``V_in, F_in, UV_in, FUV_in``; no creases): the faces within ``RINGS`` rings of ``SEEDS``,
the scan's three vertices whose UV indices alternate p, q, p, q around them, where OpenSubdiv
gives a UV index a value of its own (``test_face_varying.alternating_uvs``; the only places
where a mode disagrees with hybridsub), so that the part holds every disagreement of the
whole scan, besides UV seams and the part's own boundary. ``benchmarks/peers/osd_fvar``
refines it uniformly with Far (Loop, ``VTX_BOUNDARY_EDGE_ONLY``) and each
``FVarLinearInterpolation`` mode, at levels 1 and 2. Written here (compressed):

- ``bunny_seams.input.npz``: ``V_in, F_in, UV_in, FUV_in``;
- ``bunny_seams.L{1,2}.npz``: OpenSubdiv's refined ``V, F`` and ``FUV`` (its UV index
  of each face corner; the same in every mode, which this script checks);
- ``bunny_seams.{mode}.L{1,2}.npz``: ``UV``, the refined UV values of ``mode``
  (``none``, ``corners_only``, ``corners_plus1``, ``corners_plus2``, ``boundaries``, ``all``),
  and ``note``.

tests/test_fvar_modes.py compares hybridsub with them per face corner.
"""

import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
BIN = os.path.join(ROOT, "benchmarks", "peers", "bin", "osd_fvar")
NAME = "bunny_seams"
SEEDS = (1409, 3160, 3403)  # vertices of the scan (see the module doc)
RINGS = 4
MODES = ("none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all")
OSD_NAMES = dict(none="FVAR_LINEAR_NONE", corners_only="FVAR_LINEAR_CORNERS_ONLY",
                 corners_plus1="FVAR_LINEAR_CORNERS_PLUS1", corners_plus2="FVAR_LINEAR_CORNERS_PLUS2",
                 boundaries="FVAR_LINEAR_BOUNDARIES", all="FVAR_LINEAR_ALL")


def write_input(tmp, V, F, UV, FUV):
    off, uvs = os.path.join(tmp, "in.off"), os.path.join(tmp, "in.uv")
    with open(off, "w") as f:
        f.write(f"OFF\n{len(V)} {len(F)} 0\n")
        f.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in F.tolist())
    with open(uvs, "w") as f:
        f.write(f"{len(UV)} {UV.shape[1]} {len(FUV)}\n")
        f.writelines(" ".join(repr(x) for x in row) + "\n" for row in UV.tolist())
        f.writelines(f"{a} {b} {c}\n" for a, b, c in FUV.tolist())
    return off, uvs


def read_output(prefix):
    with open(prefix + ".off") as f:
        f.readline()
        nv, nf, _ = map(int, f.readline().split())
        data = f.read().split()
    V = np.array(data[:3 * nv], dtype=np.float64).reshape(nv, 3)
    F = np.array(data[3 * nv:], dtype=np.int64).reshape(nf, 4)[:, 1:]
    with open(prefix + ".uv") as f:
        t, k, m = map(int, f.readline().split())
        data = f.read().split()
    UV = np.array(data[:t * k], dtype=np.float64).reshape(t, k)
    FUV = np.array(data[t * k:], dtype=np.int64).reshape(m, 3)
    return V, F, UV, FUV


def part(V, F, UV, FUV):
    """The faces within ``RINGS`` rings of ``SEEDS`` (the first ring: the faces at a seed; a face
    is in the next ring when it shares a vertex with the current part), their vertices and UV
    values renumbered in order."""
    keep = np.isin(F, SEEDS).any(axis=1)
    for _ in range(RINGS - 1):
        on = np.zeros(len(V), bool)
        on[F[keep].ravel()] = True
        keep = on[F].any(axis=1)
    used, Fp = np.unique(F[keep], return_inverse=True)
    uvs, FUVp = np.unique(FUV[keep], return_inverse=True)
    return V[used], Fp.reshape(-1, 3), UV[uvs], FUVp.reshape(-1, 3)


def main():
    if not os.path.exists(BIN):
        sys.exit(f"{BIN} not built: run benchmarks/peers/build.sh")
    d = np.load(os.path.join(HERE, "..", "bunny10k_textured.fvar_linear.L1.npz"))
    V, F, UV, FUV = part(*(d[k] for k in ("V_in", "F_in", "UV_in", "FUV_in")))
    np.savez_compressed(os.path.join(HERE, f"{NAME}.input.npz"), V_in=V, F_in=F, UV_in=UV, FUV_in=FUV)
    with tempfile.TemporaryDirectory() as tmp:
        off, uvs = write_input(tmp, V, F, UV, FUV)
        for levels in (1, 2):
            geometry = None
            for mode in MODES:
                prefix = os.path.join(tmp, f"{mode}.L{levels}")
                subprocess.run([BIN, off, uvs, str(levels), mode, "--out", prefix], check=True)
                V2, F2, UV2, FUV2 = read_output(prefix)
                if geometry is None:
                    geometry = (V2, F2, FUV2)
                    np.savez_compressed(os.path.join(HERE, f"{NAME}.L{levels}.npz"), V=V2,
                                        F=F2.astype(np.int32), FUV=FUV2.astype(np.int32))
                elif not (np.array_equal(geometry[0], V2) and np.array_equal(geometry[1], F2)
                          and np.array_equal(geometry[2], FUV2)):
                    sys.exit(f"{mode} L{levels}: OpenSubdiv's faces or UV indices differ between modes")
                note = (f"OpenSubdiv 3.5 Far, Loop, VTX_BOUNDARY_EDGE_ONLY, face-varying channel with "
                        f"{OSD_NAMES[mode]}, {levels} levels (tests/data/fvar/generate.py)")
                np.savez_compressed(os.path.join(HERE, f"{NAME}.{mode}.L{levels}.npz"), UV=UV2,
                                    note=note)
                print(f"{mode} L{levels}: {len(UV2)} UV values")


if __name__ == "__main__":
    main()
