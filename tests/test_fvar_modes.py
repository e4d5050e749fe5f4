"""OpenSubdiv's six face-varying modes (``uv_interpolation=``, its FVarLinearInterpolation)
against OpenSubdiv's own results.

References: tests/data/fvar/ (``benchmarks/peers/build.sh && python tests/data/fvar/generate.py``),
the part of the textured bunny scan around its three alternating vertices (generate.py), Loop,
levels 1 and 2, compared per face corner as in test_face_varying.py.
"""

import os

import numpy as np
import pytest

import hybridsub
from meshcompare import mesh_difference
from test_face_varying import corner_differences

DATA = os.path.join(os.path.dirname(__file__), "data", "fvar")
MODES = ("none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all")
# none / corners_only differ where OpenSubdiv gives a UV index an extra value (the three
# alternating vertices of test_face_varying); the other modes sharpen those and agree everywhere
KNOWN = {("none", 1): 11, ("none", 2): 209, ("corners_only", 1): 7, ("corners_only", 2): 133}


@pytest.mark.parametrize("levels", [1, 2])
@pytest.mark.parametrize("mode", MODES)
def test_modes_match_opensubdiv(mode, levels):
    d = np.load(os.path.join(DATA, "bunny_seams.input.npz"))
    g = np.load(os.path.join(DATA, f"bunny_seams.L{levels}.npz"))
    ref = dict(V=g["V"], F=g["F"], FUV=g["FUV"],
               UV=np.load(os.path.join(DATA, f"bunny_seams.{mode}.L{levels}.npz"))["UV"])
    V, F, UV, FUV = hybridsub.subdivide_face_varying(d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"], levels=levels,
                                                     scheme="loop", uv_interpolation=mode)
    assert mesh_difference(V, F, ref["V"], ref["F"], 1e-12) is None
    bad, _ = corner_differences(V, F, UV, FUV, ref)
    assert int(bad.sum()) == KNOWN.get((mode, levels), 0)


def test_uv_mode_names_are_aliases():
    F = np.array([[0, 1, 2], [0, 2, 3]])
    FUV = np.array([[0, 1, 2], [3, 4, 5]])
    for old, new in (("linear", "all"), ("smooth", "none")):
        a = hybridsub.refine_face_varying(F, FUV, levels=2, uv_mode=old).uv.matrix
        b = hybridsub.refine_face_varying(F, FUV, levels=2, uv_interpolation=new).uv.matrix
        assert (a != b).nnz == 0
    with pytest.raises(ValueError, match="uv_interpolation must be one of"):
        hybridsub.refine_face_varying(F, FUV, uv_interpolation="smooth")
    with pytest.raises(ValueError, match="disagree"):
        hybridsub.refine_face_varying(F, FUV, uv_mode="smooth", uv_interpolation="all")


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_boundaries_keep_uv_boundary_linear_and_no_seam_modes_agree(scheme, mesh):
    V, F = mesh("mesh_with_border")
    rng = np.random.default_rng(3)
    UV = rng.random((len(V), 2))
    lin = hybridsub.refine_face_varying(F, F, levels=2, scheme=scheme, uv_interpolation="all").uv
    bnd = hybridsub.refine_face_varying(F, F, levels=2, scheme=scheme, uv_interpolation="boundaries").uv
    # boundary values of "boundaries" are those of linear interpolation
    Fb = bnd.faces
    he = np.stack([Fb.ravel(), np.roll(Fb, -1, axis=1).ravel()], axis=1)
    fwd = {tuple(x) for x in he.tolist()}
    on_boundary = np.unique([a for a, b in he.tolist() if (b, a) not in fwd])
    assert np.abs(bnd.apply(UV)[on_boundary] - lin.apply(UV)[on_boundary]).max() < 1e-14


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_closed_mesh_without_seams_refines_uvs_like_positions_in_every_mode_but_all(scheme, mesh):
    V, F = mesh("icosahedron")
    for mode in MODES[:-1]:
        geo, uv = hybridsub.refine_face_varying(F, F, levels=2, scheme=scheme, uv_interpolation=mode)
        assert abs(uv.matrix - geo.matrix).max() < 1e-15, mode


def _corner_table(V, F, UV, FUV):
    """Sorted rows (position, UV) of every face corner, rounded: order-free."""
    rows = np.hstack([V[F.ravel()], UV[FUV.ravel()]])
    rows = np.round(rows, 9) + 0.0
    return rows[np.lexsort(rows.T[::-1])]


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_mirrored_mesh_gives_mirrored_uvs(mode, scheme, mesh):
    from test_face_varying import uv_from_cuts
    V, F = mesh("mesh_with_border")
    cuts = [tuple(F[0, :2]), tuple(F[5, 1:])]
    UV, FUV = uv_from_cuts(F, cuts, np.random.default_rng(7))
    a = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, scheme=scheme, uv_interpolation=mode)
    M, Muv = np.array([-1.0, 1, 1]), np.array([-1.0, 1])
    b = hybridsub.subdivide_face_varying(V * M, F[:, ::-1], UV * Muv, FUV[:, ::-1], levels=2, scheme=scheme,
                                         uv_interpolation=mode)
    got = _corner_table(b[0] * M, b[1], b[2] * Muv, b[3])
    assert np.array_equal(_corner_table(*a), got)


@pytest.mark.parametrize("mode", MODES)
def test_refined_uvs_converge(mode, mesh):
    """The UV values of the coarse UV indices move less and less from level to level."""
    from test_face_varying import uv_from_cuts
    V, F = mesh("mesh_with_border")
    UV, FUV = uv_from_cuts(F, [tuple(F[0, :2]), tuple(F[5, 1:])], np.random.default_rng(7))
    moves = []
    prev = UV
    for levels in range(1, 5):
        _, _, UV2, _ = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=levels, scheme="hybrid",
                                                        uv_interpolation=mode)
        moves.append(np.abs(UV2[:len(UV)] - prev[:len(UV)]).max())
        prev = UV2
    assert all(b <= 0.5 * a + 1e-15 for a, b in zip(moves[1:], moves[2:])), moves
