"""Adaptive refinement with face-varying data (UVs with seams; docs/adaptive.md).

The oracles: the uniform refinement with the same UV faces (``hybridsub.refine(...,
uv_faces=FUV)``: each adaptive vertex matched by position to a vertex of the uniform level it
claims, and each adaptive face corner's UV value found among the uniform UV values at that
vertex), OpenSubdiv's face-varying refinement of the bunny with seams in every
``FVarLinearInterpolation`` mode (``tests/data/fvar``), and the crack-free mesh checks.
"""

import os

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import strategies as ms
from test_adaptive import cfg, check_crack_free, uniform_match
from test_face_varying import corner_differences
from test_fvar_modes import KNOWN, MODES

hybridsub = pytest.importorskip("hybridsub")

FVAR = os.path.join(os.path.dirname(__file__), "data", "fvar")


def _bunny():
    d = np.load(os.path.join(FVAR, "bunny_seams.input.npz"))
    return d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"]


def check_uvs(V, F, UV, FUV, tags, scheme, r, uv_interpolation):
    """Every face corner's UV value is one of the uniform refinement's UV values at the vertex
    the corner's vertex is (of its level), to 1e-12; the UV faces are aligned with the faces;
    an old vertex keeps the UV index its input face gives it."""
    utags = dict(tags, uv_faces=FUV, n_uvs=len(UV), uv_interpolation=uv_interpolation)
    X = r.apply(V)
    idx = uniform_match(V, F, utags, scheme, r, X)  # the geometry too: the hybrid splits seams
    U2 = r.uv_refinement.apply(UV)
    G, T = r.faces, r.uv_faces
    assert G.shape == T.shape and r.uv_matrix.shape == (len(U2), len(UV))
    assert np.allclose(U2, r.uv_matrix @ UV, atol=1e-13, rtol=0)
    checked = 0
    for j in range(int(r.vertex_level.max(initial=0)) + 1):
        if j:
            u = hybridsub.refine(F, levels=j, scheme=scheme, n_vertices=len(V), **utags)
            Gj, Tj, Uj = u.faces.ravel(), u.uv_faces.ravel(), u.uv_refinement.apply(UV)
        else:
            Gj, Tj, Uj = F.ravel(), FUV.ravel(), UV
        order = np.argsort(Gj, kind="stable")
        starts = np.searchsorted(Gj[order], np.arange(len(Uj) + len(X) + 1))
        for k in np.flatnonzero((r.vertex_level[G.ravel()] == j) & (idx[G.ravel()] >= 0)):
            w = idx[G.ravel()[k]]
            vals = Uj[Tj[order[starts[w]:starts[w + 1]]]]
            assert np.abs(vals - U2[T.ravel()[k]]).max(axis=1).min() <= 1e-12, (j, k)
            checked += 1
    old = G < len(V)
    hit = F[r.face_parent][:, None, :] == G[:, :, None]
    assert np.array_equal(np.einsum("fkj,fj->fk", hit, FUV[r.face_parent])[old], T[old])
    return checked


@cfg(40)
@given(mesh=ms.tagged_meshes(bowties=False), data=st.data())
def test_region_refinement_with_uvs_is_exact(mesh, data):
    V, F, tags = mesh
    UV, FUV = data.draw(ms.uv_charts(F))
    scheme = data.draw(st.sampled_from(["hybrid", "loop"]))
    mode = data.draw(st.sampled_from(MODES))
    levels = data.draw(st.integers(0, 3))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    where = rng.random(len(F)) < data.draw(st.sampled_from([0.05, 0.2, 0.5]))
    r = hybridsub.refine_adaptive(F, where=where, levels=levels, scheme=scheme, n_vertices=len(V),
                                  uv_faces=FUV, n_uvs=len(UV), uv_interpolation=mode, **tags)
    check_crack_free(V, F, r)
    check_uvs(V, F, UV, FUV, tags, scheme, r, mode)
    assert (r.face_level[where[r.face_parent]] == levels).all()


@pytest.mark.parametrize("levels", [1, 2])
@pytest.mark.parametrize("mode", MODES)
def test_everything_to_a_level_matches_opensubdiv(mode, levels):
    """Every face to the level is the uniform level: OpenSubdiv's UVs at every corner (but
    for the corners the uniform test knows to differ, by OpenSubdiv's own choice)."""
    V, F, UV, FUV = _bunny()
    g = np.load(os.path.join(FVAR, f"bunny_seams.L{levels}.npz"))
    ref = dict(V=g["V"], F=g["F"], FUV=g["FUV"], UV=np.load(os.path.join(FVAR, f"bunny_seams.{mode}.L{levels}.npz"))["UV"])
    r = hybridsub.refine_adaptive(F, where=np.ones(len(F), bool), levels=levels, scheme="loop", uv_faces=FUV,
                                  uv_interpolation=mode)
    bad, _ = corner_differences(r.apply(V), r.faces, r.uv_refinement.apply(UV), r.uv_faces, ref)
    assert int(bad.sum()) == KNOWN.get((mode, levels), 0)


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_bunny_region_with_seams(scheme):
    """A patch of the bunny crossing its seams, to three levels, both UV modes."""
    V, F, UV, FUV = _bunny()
    far = np.linalg.norm(V - V[F[0]].mean(axis=0), axis=1)
    where = (far[F] < np.quantile(far, 0.3)).all(axis=1)
    seams = hybridsub.seam_edges(F, FUV)
    assert np.isin(seams, F[where]).all(axis=1).any()  # the patch holds seams
    for mode in ("all", "none"):
        r = hybridsub.refine_adaptive(F, where=where, levels=3, scheme=scheme, uv_faces=FUV, uv_interpolation=mode)
        check_crack_free(V, F, r)
        assert check_uvs(V, F, UV, FUV, {}, scheme, r, mode) > 3 * len(F)


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_non_manifold_cut_with_uvs(scheme):
    """A third face on one of the bunny's edges, refined with ``non_manifold="cut"``: the cut
    copy's UVs are the uniform cut refinement's, corner by corner, in and round the region."""
    V, F, UV, FUV = _bunny()
    F = np.vstack([F, [[F[0, 0], F[0, 1], len(V)]]])
    V = np.vstack([V, V[F[0]].mean(axis=0) + 0.01])
    FUV = np.vstack([FUV, [[FUV[0, 0], FUV[0, 1], len(UV)]]])
    UV = np.vstack([UV, UV[:1] + 0.01])
    far = np.linalg.norm(V - V[F[0]].mean(axis=0), axis=1)
    where = (far[F] < np.quantile(far, 0.3)).all(axis=1)
    assert where[-1]  # the third face is refined
    r = hybridsub.refine_adaptive(F, where=where, levels=3, scheme=scheme, non_manifold="cut", uv_faces=FUV,
                                  uv_interpolation="all")
    assert check_uvs(V, F, UV, FUV, {"non_manifold": "cut"}, scheme, r, "all") > 3 * len(F)


def test_loop_tolerance_with_uvs():
    """To a tolerance (Loop): the geometry of the run without UVs, the UVs exact; the hybrid
    (whose seams change its surface) and √3 are refused by name."""
    V, F, UV, FUV = _bunny()
    r = hybridsub.refine_adaptive(F, V=V, tolerance="0.1%", scheme="loop", uv_faces=FUV, uv_mode="smooth")
    r0 = hybridsub.refine_adaptive(F, V=V, tolerance="0.1%", scheme="loop")
    assert np.array_equal(r.faces, r0.faces) and np.array_equal(r.apply(V), r0.apply(V))
    assert len(np.unique(r.face_level)) >= 2  # levels mixed
    check_uvs(V, F, UV, FUV, {}, "loop", r, "none")
    with pytest.raises(ValueError, match='needs scheme="loop"'):
        hybridsub.refine_adaptive(F, V=V, tolerance="0.3%", uv_faces=FUV)
    with pytest.raises(ValueError, match="sqrt3"):
        hybridsub.refine_adaptive(F, where=[0], levels=1, scheme="sqrt3", uv_faces=FUV)
    with pytest.raises(ValueError, match="n_uvs was given without uv_faces"):
        hybridsub.refine_adaptive(F, where=[0], levels=1, n_uvs=5)
    with pytest.raises(ValueError, match="uv_mode"):
        hybridsub.refine_adaptive(F, where=[0], levels=1, uv_faces=FUV, uv_mode="cubic")
    bad = FUV.copy()
    bad[3, 1] = -2
    with pytest.raises(ValueError, match=r"FUV|uv_faces"):
        hybridsub.refine_adaptive(F, where=[0], levels=1, uv_faces=bad)
    FUV0 = FUV.copy()
    hybridsub.refine_adaptive(F, where=[0, 1], levels=2, uv_faces=FUV)
    assert np.array_equal(FUV, FUV0)


def test_holes_and_memory_with_uvs():
    """Holes leave their UV faces out with their faces; the memory check counts the UV step."""
    V, F, UV, FUV = _bunny()
    where = np.zeros(len(F), bool)
    where[:60] = True
    r = hybridsub.refine_adaptive(F, where=where, levels=2, uv_faces=FUV, holes=[5, 6])
    full = hybridsub.refine_adaptive(F, where=where, levels=2, uv_faces=FUV)
    assert len(r.uv_faces) == len(r.faces) < len(full.faces)
    keep = ~np.isin(full.face_parent, [5, 6])
    assert np.array_equal(r.uv_faces, full.uv_faces[keep])
    from hybridsub._refiner.budget import RegionBudget
    b = RegionBudget("hybrid")
    assert b.estimate(369, 233, 60, 0, 309).bytes > b.estimate(369, 233, 60).bytes


def test_cli_tolerance_keeps_uvs_with_loop(tmp_path, capsys):
    from hybridsub._app.cli import main
    V, F, UV, FUV = _bunny()
    src = tmp_path / "bunny.obj"
    hybridsub.write_mesh(src, V, F, uv=UV, face_uv=FUV)
    out = tmp_path / "a.obj"
    assert main(["subdivide", str(src), "-o", str(out), "--tolerance", "0.5%", "--scheme", "loop"]) == 0
    assert "dropped" not in capsys.readouterr().err
    m = hybridsub.read_mesh(str(out))
    r = hybridsub.refine_adaptive(F, V=V, tolerance="0.5%", scheme="loop", uv_faces=FUV)
    assert np.array_equal(m.faces, r.faces) and np.array_equal(m.face_uv, r.uv_faces)
    assert np.array_equal(m.uv, r.uv_refinement.apply(UV))
    assert main(["subdivide", str(src), "-o", str(out), "--tolerance", "0.5%"]) == 0
    assert "texture coordinates dropped: to a tolerance they are refined with --scheme loop" in capsys.readouterr().err
    assert hybridsub.read_mesh(str(out)).uv is None
    assert main(["subdivide", str(src), "-o", str(out), "--tolerance", "0.5%", "--uv-mode", "smooth"]) == 1
    assert "--uv-mode with --tolerance needs --scheme loop" in capsys.readouterr().err
