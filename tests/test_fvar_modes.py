"""OpenSubdiv's face-varying modes (FVarLinearInterpolation) against its own results.

References: tests/data/fvar/ (``python tests/data/fvar/generate.py`` with
``benchmarks/peers/osd_fvar``), the textured bunny, Loop, levels 1 and 2. The corner rules of
``hybridsub._topology.uv.mode_corners`` are applied on top of the UV corners of
``uv_mode="smooth"`` (OpenSubdiv's FVAR_LINEAR_NONE); the public ``uv_interpolation=``
keyword is not wired yet, so the test sets the UV corners of a checked input directly.
"""

import dataclasses
import os

import numpy as np
import pytest

from hybridsub._input.gate import open_gate
from hybridsub._refiner.fastpath import walk_data
from hybridsub._topology.uv import mode_corners
from test_face_varying import corner_differences

DATA = os.path.join(os.path.dirname(__file__), "data", "fvar")
# none / corners_only differ where OpenSubdiv gives a UV index an extra value (the three
# alternating vertices of test_face_varying); corners_plus1/2 sharpen those, and agree everywhere
KNOWN = {("none", 1): 11, ("none", 2): 209, ("corners_only", 1): 7, ("corners_only", 2): 133}


@pytest.mark.parametrize("levels", [1, 2])
@pytest.mark.parametrize("mode", ["none", "corners_only", "corners_plus1", "corners_plus2"])
def test_corner_modes_match_opensubdiv(mode, levels):
    d = np.load(os.path.join(DATA, "bunny10k_textured.input.npz"))
    g = np.load(os.path.join(DATA, f"bunny10k_textured.L{levels}.npz"))
    ref = dict(V=g["V"], F=g["F"], FUV=g["FUV"],
               UV=np.load(os.path.join(DATA, f"bunny10k_textured.{mode}.L{levels}.npz"))["UV"])
    inp = open_gate(d["F_in"], None, levels, n_vertices=len(d["V_in"]), scheme="loop", uv_faces=d["FUV_in"],
                    n_uvs=len(d["UV_in"]), uv_mode="smooth", uv_name="FUV")
    uv = dataclasses.replace(inp.uv, corner=inp.uv.corner | mode_corners(inp.level, inp.uv.level, mode))
    last = None
    for last in walk_data(dataclasses.replace(inp, uv=uv), d["V_in"].astype(float), d["UV_in"].astype(float)):
        pass
    bad, _ = corner_differences(last.X, last.faces, last.UV, last.uv_faces, ref)
    assert int(bad.sum()) == KNOWN.get((mode, levels), 0)
