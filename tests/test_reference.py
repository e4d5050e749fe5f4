"""hybridsub against CGAL 5.5 and OpenSubdiv 3.5 outputs on real meshes (tests/data/*.npz).

Each file holds an input mesh, its tags and the reference result; see
../shared/reference/README.md for how they were made. Agreement is up to vertex and face
order: positions to 1e-12 of the bounding-box diagonal (1e-9 for semi-sharp creases, whose
OpenSubdiv weights are computed in single precision), triangles exactly.
"""

import glob
import os

import numpy as np
import pytest

import hybridsub
from meshcompare import mesh_difference

DATA = os.path.join(os.path.dirname(__file__), "data")
CASES = sorted(os.path.basename(p)[:-4] for p in glob.glob(os.path.join(DATA, "*.npz"))
               if ".fvar_" not in p)


def _call(d, scheme, levels, **kw):
    if scheme in ("sqrt3", "loop"):
        return hybridsub.subdivide(d["V_in"], d["F_in"], levels=levels, scheme=scheme, **kw)
    if scheme == "loop_creases":
        return hybridsub.subdivide(d["V_in"], d["F_in"], d["creases"], levels=levels, scheme="loop", **kw)
    if scheme == "loop_semisharp":
        return hybridsub.subdivide(d["V_in"], d["F_in"], d["creases"], levels=levels, scheme="loop",
                                   sharpness=d["sharpness"], **kw)
    raise AssertionError(scheme)


@pytest.mark.parametrize("case", CASES)
def test_matches_reference(case):
    d = np.load(os.path.join(DATA, case + ".npz"))
    scheme, levels = case.split(".")[-2], int(case.split(".")[-1][1:])
    V, F = _call(d, scheme, levels)
    tol = 1e-9 if scheme == "loop_semisharp" else 1e-12
    assert mesh_difference(V, F, d["V"], d["F"], tol) is None, mesh_difference(V, F, d["V"], d["F"], tol)


@pytest.mark.parametrize("case", [c for c in CASES if "loop_creases" in c or "loop_semisharp" in c])
def test_hybrid_all_sharp_matches_opensubdiv(case):
    """The hybrid scheme with every face sharp is Loop with creases: same OpenSubdiv result."""
    d = np.load(os.path.join(DATA, case + ".npz"))
    levels = int(case.split(".")[-1][1:])
    kw = {"sharpness": d["sharpness"]} if "semisharp" in case else {}
    V, F = hybridsub.subdivide(d["V_in"], d["F_in"], d["creases"], levels=levels, scheme="hybrid",
                               sharp_faces=np.ones(len(d["F_in"]), bool), **kw)
    tol = 1e-9 if "semisharp" in case else 1e-12
    assert mesh_difference(V, F, d["V"], d["F"], tol) is None


def test_reference_cases_cover_every_scheme():
    kinds = {c.split(".")[-2] for c in CASES}
    assert {"sqrt3", "loop", "loop_creases", "loop_semisharp"} <= kinds
    assert any("mesh_with_border.sqrt3.L3" == c for c in CASES)  # Kobbelt's boundary, odd and even


def test_comparison_detects_a_wrong_result():
    """The comparison itself must fail on a perturbed vertex, a flipped triangle, a missing face."""
    d = np.load(os.path.join(DATA, "octahedron.sqrt3.L2.npz"))
    V, F = hybridsub.subdivide(d["V_in"], d["F_in"], levels=2, scheme="sqrt3")
    assert mesh_difference(V, F, d["V"], d["F"]) is None
    W = V.copy()
    W[5] += 1e-9
    assert mesh_difference(W, F, d["V"], d["F"]) is not None
    G = F.copy()
    G[3] = G[3, ::-1]
    assert mesh_difference(V, G, d["V"], d["F"]) is not None
    assert mesh_difference(V, F[:-1], d["V"], d["F"]) is not None
