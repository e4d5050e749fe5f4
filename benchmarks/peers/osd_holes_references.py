"""Write the OpenSubdiv references of ``holes=`` into tests/data/holes/ (osd_holes.cpp).

usage: python benchmarks/peers/osd_holes_references.py     (after benchmarks/peers/build.sh)

Each case is a mesh, a few hole faces (and creases), refined uniformly by OpenSubdiv 3.5's
Loop scheme (the options of osd_common.h, faces tagged through TopologyDescriptor::holeIndices).
A file holds the input (``V_in``, ``F_in``, ``creases``, ``holes``) and OpenSubdiv's last level:
every vertex (``V``) and the faces that are not holes (``F``). The holes are fixed here, chosen
to cover: scattered single faces, the whole ring of a vertex (a vertex only holes use) and
holes along a crease of fandisk.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "benchmarks", "peers", "bin", "osd_holes")
OUT = os.path.join(ROOT, "tests", "data", "holes")
sys.path.insert(0, ROOT)

from hybridsub._io import read_mesh  # noqa: E402


def _read_off(path: str) -> tuple[np.ndarray, np.ndarray]:
    words = [w for line in open(path) for w in line.split("#")[0].split()]
    nv, nf = int(words[1]), int(words[2])
    V = np.array(words[4:4 + 3 * nv], float).reshape(nv, 3)
    F = np.array(words[4 + 3 * nv:4 + 3 * nv + 4 * nf], np.int64).reshape(nf, 4)[:, 1:]
    return V, F


def _write_off(path: str, V: np.ndarray, F: np.ndarray) -> None:
    with open(path, "w") as f:
        f.write(f"OFF\n{len(V)} {len(F)} 0\n")
        np.savetxt(f, V, fmt="%.17g")
        np.savetxt(f, np.hstack([np.full((len(F), 1), 3), F]), fmt="%d")


def case(name: str, V, F, holes, creases, levels: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        mesh, hole_file = os.path.join(tmp, "in.off"), os.path.join(tmp, "holes.txt")
        crease_file, out = os.path.join(tmp, "creases.txt"), os.path.join(tmp, "out.off")
        _write_off(mesh, V, F)
        np.savetxt(hole_file, holes, fmt="%d")
        cmd = [BIN, mesh, str(levels), "--holes", hole_file, "--out", out]
        if len(creases):
            np.savetxt(crease_file, creases, fmt="%d")
            cmd += ["--creases", crease_file]
        info = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        V2, F2 = _read_off(out)
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, f"{name}.loop.L{levels}.npz")
    np.savez_compressed(path, V_in=V, F_in=F, creases=np.asarray(creases, np.int64).reshape(-1, 2),
                        holes=np.asarray(holes, np.int64), V=V2, F=F2, note=np.array(info["peer"]))
    print(f"{path}: {len(V2)} vertices, {len(F2)} faces; per level [vertices, faces, holes] {info['counts']}")


def main() -> None:
    cube = read_mesh(os.path.join(ROOT, "tests", "data", "cube-meshed.off"))
    V, F = cube.vertices, cube.faces
    ring = np.flatnonzero((F == 0).any(axis=1))  # every face around vertex 0
    holes = np.unique(np.concatenate([ring, [100, 101, 500, 1700]]))
    for levels in (1, 2):
        case("cube-meshed", V, F, holes, np.empty((0, 2), np.int64), levels)
    ref = np.load(os.path.join(ROOT, "tests", "data", "fandisk.loop_creases.L1.npz"))
    Vf, Ff, creases = ref["V_in"], ref["F_in"], ref["creases"]
    e = creases[len(creases) // 3]  # faces along a crease, on either side, and a few scattered
    along = np.flatnonzero(np.isin(Ff, e).sum(axis=1) >= 1)
    holes = np.unique(np.concatenate([along, np.arange(0, len(Ff), 997)]))
    case("fandisk_creases", Vf, Ff, holes, creases, 1)


if __name__ == "__main__":
    main()
