"""Odd arguments to the newer API (issue 31, section 4): each answered by the right result or
one clear error naming the argument — fit at extreme scales, degenerate and partial inputs,
multiresolution details that belong to another refinement, and the option keywords every entry
point takes through the one gate."""

import os
import warnings

import numpy as np
import pytest

import hybridsub
from hybridsub import MeshError
from hybridsub._io import read_off

DATA = os.path.join(os.path.dirname(__file__), "data")
V, F = read_off(os.path.join(DATA, "octahedron.off"))
R2 = hybridsub.refine(F, levels=2)
P = R2.apply(V * [1.0, 1.5, 2.0])  # a stretched octahedron's level 2: the level-2 fit is exact


# ----------------------------------------------------------------------------------------------
# fit


def test_fit_is_the_same_at_any_scale():
    """The fit runs on normalised coordinates: at 1e200 and 1e-200 it finds the unit fit,
    scaled (no overflow claiming convergence at rms=inf, no 'negative dimensions')."""
    unit = hybridsub.fit(F, P, V0=V, levels=2)
    assert unit.converged and unit.rms < 1e-9
    for s in (1e200, 1e-200):
        res = hybridsub.fit(F, P * s, V0=V * s, levels=2)
        assert res.converged and np.isfinite(res.rms) and res.rms < 1e-9 * s
        assert np.allclose(res.vertices / s, unit.vertices, atol=1e-9)
        assert np.all(np.isfinite(res.history["rms"])) and np.allclose(res.history["rms"] / s, unit.history["rms"],
                                                                       rtol=1e-6, atol=1e-12)


def test_fit_refuses_what_cannot_be_fitted():
    with pytest.raises(ValueError, match="smoothness 1e\\+300 is more than"):
        hybridsub.fit(F, P, V0=V, levels=2, smoothness=1e300)
    with pytest.raises(MeshError, match="V0 has no area"):
        hybridsub.fit(F, P, V0=np.zeros_like(V), levels=2)
    with pytest.raises(MeshError, match="F has no faces"):
        hybridsub.fit(np.empty((0, 3), np.int64), P, V0=V, levels=2)
    with pytest.raises(TypeError, match="max_iterations must be a number, got None"):
        hybridsub.fit(F, P, V0=V, levels=2, max_iterations=None)
    with pytest.raises(TypeError, match="smoothness must be a number"):
        hybridsub.fit(F, P, V0=V, levels=2, smoothness="1")
    with pytest.raises(MeshError, match="span more than a double"):
        hybridsub.fit(F, np.vstack([P, [[-1e308, 0, 0], [1e308, 0, 0]]]), V0=V, levels=2)


def test_fit_with_an_unused_vertex_keeps_it_where_it_is(tmp_path):
    spare = [[5.0, -7.0, 3.0]]
    V7 = np.vstack([V, spare])
    res = hybridsub.fit(F, P, V0=V7, levels=2)
    want = hybridsub.fit(F, P, V0=V, levels=2)
    assert res.converged and np.array_equal(res.vertices[6], spare[0])
    assert np.allclose(res.vertices[:6], want.vertices, atol=1e-12)
    with pytest.raises(MeshError, match="at least 6"):
        hybridsub.fit(F, P, V0=V[:5], levels=2)
    # the command line fits such a control file, too
    from hybridsub._app.cli import main

    hybridsub.write_mesh(tmp_path / "control.obj", V7, F)
    np.savetxt(tmp_path / "target.xyz", P)
    assert main(["fit", str(tmp_path / "control.obj"), str(tmp_path / "target.xyz"), "-o", str(tmp_path / "out.obj"),
                 "--levels", "2", "-q"]) == 0
    out = hybridsub.read_mesh(tmp_path / "out.obj")
    assert np.allclose(out.vertices, res.vertices, atol=1e-9)


def test_fit_with_fewer_points_than_unknowns_warns():
    with pytest.warns(UserWarning, match="4 points for 18 unknowns .* underdetermined"):
        hybridsub.fit(F, P[:4], V0=V, levels=2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hybridsub.fit(F, P[:4], V0=V, levels=2, smoothness=1.0, max_iterations=2)  # regularised: no warning
        hybridsub.fit(F, P, V0=V, levels=2, max_iterations=2)


def test_fit_takes_feature_angle():
    """fit(feature_angle=) keeps the detected creases sharp: the same fit as with the detected tags."""
    rng = np.random.default_rng(0)
    Vc = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    Fc = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                   [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    feat = hybridsub.detect_features(Vc, Fc, angle=30)
    r = hybridsub.refine(Fc, feat.sharp_edges, levels=2, corners=feat.corners)
    pts = r.apply(Vc) + 1e-3 * rng.normal(size=(r.n_vertices, 3))
    got = hybridsub.fit(Fc, pts, V0=Vc, levels=2, feature_angle=30, max_iterations=3)
    want = hybridsub.fit(Fc, pts, feat.sharp_edges, corners=feat.corners, V0=Vc, levels=2, max_iterations=3)
    assert np.allclose(got.vertices, want.vertices, atol=1e-12)
    plain = hybridsub.fit(Fc, pts, V0=Vc, levels=2, max_iterations=3)
    assert not np.allclose(plain.vertices, want.vertices, atol=1e-6)


# ----------------------------------------------------------------------------------------------
# multiresolution details


def test_reconstruct_refuses_details_of_another_refinement():
    rng = np.random.default_rng(1)
    X = R2.apply(V) + 0.01 * rng.normal(size=(R2.n_vertices, 3))
    coarse, details = R2.decompose(X)
    assert np.abs(R2.reconstruct(coarse, details) - X).max() < 1e-12
    assert details.fingerprint and hybridsub.refine(F, levels=2).decompose(X)[1].fingerprint == details.fingerprint
    warren = hybridsub.refine(F, levels=2, scheme="loop", loop_weights="warren")
    loop = hybridsub.refine(F, levels=2, scheme="loop")
    c, d = loop.decompose(loop.apply(V) + 0.01 * rng.normal(size=(loop.n_vertices, 3)))
    with pytest.raises(ValueError, match="another refinement"):
        warren.reconstruct(c, d)  # same sizes, other weights: error 0.019 before
    perm = np.array([3, 0, 5, 1, 4, 2])
    relabelled = hybridsub.refine(perm[F], levels=2)
    with pytest.raises(ValueError, match="another refinement"):
        relabelled.reconstruct(coarse, details)
    creased = hybridsub.refine(F, [[0, 1]], levels=2)
    with pytest.raises(ValueError, match="another refinement"):
        creased.reconstruct(coarse, details)


def test_reconstruct_refuses_nan_details():
    coarse, details = R2.decompose(R2.apply(V))
    levels = list(details.levels)
    levels[1] = levels[1].copy()
    levels[1][7, 2] = np.nan
    bad = hybridsub._fit.multires.MultiresDetails(tuple(levels), details.local_frames, details.shape,
                                                  details.fingerprint)
    with pytest.raises(ValueError, match=r"details\[1\] must be finite; row 7"):
        R2.reconstruct(coarse, bad)


@pytest.mark.parametrize("s", [1e200, 1e-200])
def test_multires_round_trip_at_any_scale(s):
    rng = np.random.default_rng(2)
    X = (R2.apply(V) + 0.01 * rng.normal(size=(R2.n_vertices, 3)))
    coarse, details = R2.decompose(X)
    coarse_s, details_s = R2.decompose(X * s)
    assert np.allclose(coarse_s / s, coarse, atol=1e-12)
    for a, b in zip(details_s, details):
        assert np.allclose(a / s, b, atol=1e-12)  # the same frames at any scale
    assert np.abs(R2.reconstruct(coarse_s, details_s) / s - X).max() < 1e-12


def test_project_takes_max_iterations_and_max_iter_is_deprecated():
    s = hybridsub.LimitSurface(V, F)
    pts = 1.1 * V[:2] + 0.05
    want = s.project(pts, max_iterations=30)
    with pytest.warns(DeprecationWarning, match="max_iterations"):
        old = s.project(pts, max_iter=30)
    for a, b in zip(want, old):
        assert np.array_equal(a, b)


# ----------------------------------------------------------------------------------------------
# the same option keywords through the one gate

CUBE_V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                   [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
FACES, BARY = [0, 5, 9], [[1 / 3, 1 / 3, 1 / 3], [0.2, 0.3, 0.5], [0.6, 0.4, 0.0]]


def test_limit_surface_and_limit_matrix_take_feature_angle():
    feat = hybridsub.detect_features(CUBE_V, CUBE_F, angle=30)
    want = hybridsub.LimitSurface(CUBE_V, CUBE_F, feat.sharp_edges, corners=feat.corners)
    got = hybridsub.LimitSurface(CUBE_V, CUBE_F, feature_angle=30)
    smooth = hybridsub.LimitSurface(CUBE_V, CUBE_F)
    assert np.array_equal(got.evaluate(FACES, BARY), want.evaluate(FACES, BARY))
    assert not np.allclose(smooth.evaluate(FACES, BARY), want.evaluate(FACES, BARY))
    L = hybridsub.limit_matrix(CUBE_F, feat.sharp_edges, corners=feat.corners, scheme="loop")
    L2 = hybridsub.limit_matrix(CUBE_F, feature_angle=30, vertices=CUBE_V, scheme="loop")
    assert abs(L - L2).max() == 0 and abs(L - hybridsub.limit_matrix(CUBE_F, scheme="loop")).max() > 0.01
    assert np.allclose(L2 @ CUBE_V, hybridsub.limit_positions(CUBE_V, CUBE_F, scheme="loop", feature_angle=30))
    with pytest.raises(TypeError, match="needs vertices="):
        hybridsub.limit_matrix(CUBE_F, feature_angle=30)


def test_limit_surface_takes_non_manifold_cut_and_max_memory():
    """Two tetrahedra on one edge (four faces there): refused as before by default; cut, the
    surface is the cut mesh's, with faces, rows and data over the caller's vertices."""
    Vn = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 0.3, 1], [0.5, -1, 0.1], [0.5, -0.3, -1.0]])
    Fn = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 4], [0, 5, 1], [0, 4, 5], [1, 5, 4]])
    with pytest.raises(MeshError, match="not edge-manifold"):
        hybridsub.LimitSurface(Vn, Fn)
    s = hybridsub.LimitSurface(Vn, Fn, non_manifold="cut")
    assert s.faces.shape == Fn.shape and np.array_equal(s.faces, Fn) and s.vertices.shape == Vn.shape
    faces, bary = [0, 4, 7], [[1 / 3, 1 / 3, 1 / 3], [0.2, 0.3, 0.5], [0.5, 0.5, 0.0]]
    M = s.evaluation_matrix(faces, bary)
    assert M.shape == (3, 6) and np.allclose(M.sum(axis=1), 1)
    assert np.allclose(M @ Vn, s.evaluate(faces, bary), atol=1e-14)
    # the oracle: the cut mesh written out by hand (tetrahedron B on its own copies of 0 and 1, which the
    # cut makes corners so that they move alike), evaluated as an ordinary manifold mesh
    Vc = np.vstack([Vn, Vn[[0, 1]]])
    Fc = Fn.copy()
    Fc[4:] = np.where(Fc[4:] == 0, 6, np.where(Fc[4:] == 1, 7, Fc[4:]))
    cut_by_hand = hybridsub.LimitSurface(Vc, Fc, corners=[0, 1, 6, 7])
    assert np.allclose(cut_by_hand.evaluate(faces, bary), s.evaluate(faces, bary), atol=1e-14)
    P = s.evaluate(faces, bary) + 0.01 * s.normals(faces, bary)
    f, b, Q, d = s.project(P[:2])
    assert np.allclose(np.abs(d), 0.01, atol=1e-9)
    # max_memory bounds what the surface refines for its closest-point seeds
    with pytest.raises(hybridsub.OutputTooLargeError):
        hybridsub.LimitSurface(CUBE_V, CUBE_F, max_memory=1000).project(CUBE_V[:1] * 1.1)


def test_subdivide_mesh_merges_detected_features_as_subdivide_does():
    """A caller's semi-sharp crease that the angle also detects keeps the caller's sharpness in
    both (before, subdivide_mesh let the detected infinite sharpness win)."""
    import trimesh

    e = np.array([[0, 1]])  # a cube edge: detected at 30 degrees too
    V2, F2 = hybridsub.subdivide(CUBE_V, CUBE_F, e, levels=1, sharpness=[0.5], feature_angle=30)
    out = hybridsub.subdivide_mesh(trimesh.Trimesh(CUBE_V, CUBE_F, process=False), levels=1, sharp_edges=e,
                                   sharpness=[0.5], feature_angle=30)
    assert np.allclose(np.asarray(out.vertices), V2, atol=1e-14) and np.array_equal(np.asarray(out.faces), F2)
    inf = hybridsub.subdivide(CUBE_V, CUBE_F, e, levels=1, sharpness=[np.inf], feature_angle=30)[0]
    assert not np.allclose(inf, V2)  # the sharpness given matters


def test_subdivide_given_a_mesh_object_points_to_subdivide_mesh():
    import trimesh

    m = trimesh.Trimesh(CUBE_V, CUBE_F, process=False)
    for call in (lambda: hybridsub.subdivide(m), lambda: hybridsub.subdivide(m, levels=2),
                 lambda: hybridsub.LimitSurface(m, CUBE_F)):
        with pytest.raises(TypeError, match=r"got a trimesh\.Trimesh.*subdivide_mesh\(mesh"):
            call()
    with pytest.raises(TypeError, match="needs the faces F"):
        hybridsub.subdivide(m.vertices)
    assert len(hybridsub.subdivide(m.vertices, m.faces)[1]) == 3 * len(CUBE_F)  # trimesh's arrays are arrays


# ----------------------------------------------------------------------------------------------
# the command line

NM_V = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 0.3, 1], [0.5, -1, 0.1], [0.5, -0.3, -1.0]])
NM_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 4], [0, 5, 1], [0, 4, 5], [1, 5, 4]])


def test_cli_refuses_an_output_format_before_the_work(tmp_path, capsys):
    from hybridsub._app.cli import main

    src = os.path.join(DATA, "tetrahedron.off")
    for out in ("out.xyz", "out.svg", "out.nosuch"):
        assert main(["subdivide", src, "-o", str(tmp_path / out)]) == 1
        err = capsys.readouterr().err
        assert f"{tmp_path / out}: cannot write a mesh in this format" in err
        assert "faces" not in err.split("error:")[0]  # nothing was refined first
    assert main(["fit", src, src, "-o", str(tmp_path / "fit.xyz"), "--levels", "1"]) == 1
    assert "cannot write a mesh" in capsys.readouterr().err
    assert os.listdir(tmp_path) == []


def test_cli_non_manifold_cut(tmp_path, capsys):
    from hybridsub._app.cli import main

    hybridsub.write_mesh(tmp_path / "nm.obj", NM_V, NM_F)
    assert main(["subdivide", str(tmp_path / "nm.obj"), "-o", str(tmp_path / "a.obj"), "-q"]) == 1
    err = capsys.readouterr().err
    assert "--non-manifold cut" in err and 'non_manifold="cut"' not in err
    assert main(["subdivide", str(tmp_path / "nm.obj"), "-o", str(tmp_path / "a.obj"), "--levels", "2",
                 "--non-manifold", "cut", "-q"]) == 0
    got = hybridsub.read_mesh(tmp_path / "a.obj")
    V2, F2 = hybridsub.subdivide(NM_V, NM_F, levels=2, non_manifold="cut")
    assert np.array_equal(got.faces, F2) and np.abs(got.vertices - V2).max() < 1e-12
    # the cut's corners are written with the result, so one more level of it is two levels of the input
    assert main(["subdivide", str(tmp_path / "nm.obj"), "-o", str(tmp_path / "b.obj"), "--non-manifold", "cut",
                 "-q"]) == 0
    assert main(["subdivide", str(tmp_path / "b.obj"), "-o", str(tmp_path / "c.obj"), "-q"]) == 0
    again = hybridsub.read_mesh(tmp_path / "c.obj")
    assert np.array_equal(again.faces, F2) and np.abs(again.vertices - V2).max() < 1e-12
