"""Face-varying UVs: what refining a textured mesh's UVs with their seams costs.

Run: ``pytest benchmarks/test_bench_face_varying.py --benchmark-only``. On the textured scan
of the tests (9,999 faces, 6,451 UV values, 1,289 seams), one group per level: positions
alone (``subdivide``), positions and UVs (``subdivide_face_varying``, linear and smooth), and
``subdivide_mesh`` on the mesh as trimesh loads it (welding included).
"""

import os

import numpy as np
import pytest
from _bench import ROOT, run_warm

import hybridsub

trimesh = pytest.importorskip("trimesh")


def _bunny():
    d = np.load(os.path.join(ROOT, "tests", "data", "bunny10k_textured.fvar_linear.L1.npz"))
    return d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"]


@pytest.mark.parametrize("levels", [1, 2, 3], ids=lambda n: f"L{n}")
@pytest.mark.parametrize("what", ["positions", "linear", "smooth", "trimesh"])
def test_face_varying(benchmark, what, levels):
    V, F, UV, FUV = _bunny()
    benchmark.group = f"bunny10k_textured L{levels}"
    if what == "positions":
        run_warm(benchmark, lambda: hybridsub.subdivide(V, F, levels=levels))
    elif what == "trimesh":
        vertex_of_uv = np.empty(len(UV), np.int64)
        vertex_of_uv[FUV.ravel()] = F.ravel()
        mesh = trimesh.Trimesh(V[vertex_of_uv], FUV, visual=trimesh.visual.TextureVisuals(uv=UV), process=False)
        run_warm(benchmark, lambda: hybridsub.subdivide_mesh(mesh, levels))
    else:
        run_warm(benchmark, lambda: hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=levels, uv_mode=what))
