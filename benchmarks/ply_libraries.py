"""PLY through plyfile or hybridsub's own code: the figures of docs/formats.md.

    python benchmarks/ply_libraries.py

fandisk at 3 levels (377k faces), each file written and read once: binary read through
plyfile (what hybridsub does), ASCII read through plyfile and through hybridsub's table
parser, and the face element written by plyfile and by hybridsub's NumPy record array.
"""

import os
import tempfile
import time

import numpy as np
import plyfile

import hybridsub
from hybridsub._io import ply


def timed(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def main():
    V, F = hybridsub.load_example()
    r = hybridsub.refine(F, levels=3)
    X, F3 = r.apply(V), r.faces
    d = tempfile.mkdtemp()
    b, a = os.path.join(d, "b.ply"), os.path.join(d, "a.ply")
    hybridsub.write_mesh(b, X, F3)
    hybridsub.write_mesh(a, X, F3, binary=False)
    print(f"{len(F3):,} faces")
    print(f"binary read, hybridsub (plyfile):      {timed(lambda: hybridsub.read_mesh(b)):.2f} s")
    print(f"ASCII read, plyfile:                   {timed(lambda: plyfile.PlyData.read(a)):.2f} s")
    print(f"ASCII read, hybridsub:                 {timed(lambda: hybridsub.read_mesh(a)):.2f} s")
    rec = np.empty(len(F3), dtype=[("vertex_indices", "i4", (3,))])
    rec["vertex_indices"] = F3
    el = plyfile.PlyElement.describe(rec, "face", len_types={"vertex_indices": "u1"})
    print(f"face element written, plyfile:         {timed(lambda: plyfile.PlyData([el]).write(b)):.2f} s")
    faces = [("face", [("vertex_indices", "i4", F3.astype(np.int32))])]
    print(f"face element written, hybridsub:       {timed(lambda: ply.write_ply(b, faces)):.2f} s")


if __name__ == "__main__":
    main()
