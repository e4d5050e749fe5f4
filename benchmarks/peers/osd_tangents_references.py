"""Write the OpenSubdiv references of ``limit_tangents`` into tests/data/tangents/ (osd_tangents.cpp).

usage: python benchmarks/peers/osd_tangents_references.py     (after benchmarks/peers/build.sh)

Fandisk with its creases (tests/data/fandisk.loop_creases.L1.npz's input) and cube-meshed, Loop,
at levels 0 and 1: OpenSubdiv 3.5's PrimvarRefiner::Limit positions (``P``) and tangents
(``T1``, ``T2``) of every vertex, beside the input (``V_in``, ``F_in``, ``creases``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "benchmarks", "peers", "bin", "osd_tangents")
OUT = os.path.join(ROOT, "tests", "data", "tangents")
sys.path.insert(0, ROOT)

from hybridsub._io import read_mesh  # noqa: E402


def case(name, V, F, creases, levels):
    with tempfile.TemporaryDirectory() as tmp:
        mesh, cf, out = (os.path.join(tmp, f) for f in ("in.off", "creases.txt", "out.txt"))
        with open(mesh, "w") as f:
            f.write(f"OFF\n{len(V)} {len(F)} 0\n")
            np.savetxt(f, V, fmt="%.17g")
            np.savetxt(f, np.hstack([np.full((len(F), 1), 3), F]), fmt="%d")
        cmd = [BIN, mesh, str(levels), "--out", out]
        if len(creases):
            np.savetxt(cf, creases, fmt="%d")
            cmd += ["--creases", cf]
        subprocess.run(cmd, check=True, capture_output=True)
        R = np.loadtxt(out)
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, f"{name}.loop.L{levels}.npz")
    np.savez_compressed(path, V_in=V, F_in=F, creases=np.asarray(creases, np.int64).reshape(-1, 2),
                        P=R[:, :3], T1=R[:, 3:6], T2=R[:, 6:])
    print(path, len(R))


def main():
    ref = np.load(os.path.join(ROOT, "tests", "data", "fandisk.loop_creases.L1.npz"))
    for levels in (0, 1):
        case("fandisk_creases", ref["V_in"], ref["F_in"], ref["creases"], levels)
    cube = read_mesh(os.path.join(ROOT, "tests", "data", "cube-meshed.off"))
    case("cube-meshed", cube.vertices, cube.faces, np.empty((0, 2), np.int64), 0)


if __name__ == "__main__":
    main()
