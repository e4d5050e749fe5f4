"""The newer options (corner_sharpness=, boundary=, holes=) at every entry point that refines:
each against an independent computation of the same thing (the whole mesh refined until the
corners' sharpness is spent, subdivide for subdivide_mesh, limit_positions for LimitSurface)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import hybridsub

DATA = Path(__file__).parent / "data"


def _mesh(name):
    m = hybridsub.read_mesh(DATA / name)
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def _corner_case(scheme="loop"):
    """cube-meshed's eight corners (Loop); for the hybrid, whose mixed vertices are refined
    locally at every level of the whole-mesh oracle, the octahedron, every vertex a corner."""
    if scheme == "loop":
        V, F = _mesh("cube-meshed.off")
        c = np.flatnonzero((np.abs(V) > 0.999).sum(axis=1) == 3)
    else:
        V, F = _mesh("octahedron.off")
        c = np.arange(len(V))
    return V, F, c, np.resize([0.5, 1.0, 2.5, 3.2], len(c))


def _whole_mesh_limit(V, F, levels, scheme, sharp_faces, c, s):
    """The limit of the level-``levels`` vertices by refining the whole mesh until every
    sharpness is spent (⌈max s⌉ levels, at least ``levels``), then taking the limit masks of
    that level, where the corners left are infinitely sharp."""
    k = max(levels, int(np.ceil(s.max())))
    r = hybridsub.refine(F, levels=k, scheme=scheme, sharp_faces=sharp_faces, corners=c, corner_sharpness=s)
    n_keep = r.steps[levels - 1].n_vertices if levels else len(V)
    P = hybridsub.limit_positions(r.apply(V), r.faces, r.sharp_edges, sharpness=r.sharpness, scheme=scheme,
                                  sharp_faces=r.sharp_faces, corners=r.corners)
    return P[:n_keep]


@pytest.mark.parametrize("scheme,levels", [("loop", 0), ("loop", 1), ("hybrid", 0), ("hybrid", 2)])
def test_semi_sharp_corner_limit_is_local(scheme, levels):
    """limit_positions and limit_matrix refine only the semi-sharp corners' stars: the same
    limit as refining the whole mesh first, to 1e-12 × the diagonal."""
    V, F, c, s = _corner_case(scheme)
    sf = np.arange(0, len(F), 3) if scheme == "hybrid" else None
    kw = dict(levels=levels, scheme=scheme, sharp_faces=sf, corners=c, corner_sharpness=s)
    P = hybridsub.limit_positions(V, F, **kw)
    want = _whole_mesh_limit(V, F, levels, scheme, sf, c, s)
    diag = np.linalg.norm(np.ptp(V, axis=0))
    assert P.shape == want.shape
    assert np.abs(P - want).max() < 1e-12 * diag
    M = hybridsub.limit_matrix(F, **kw)
    assert np.abs(M @ V - want).max() < 1e-12 * diag


def _surface_case(scheme):
    """An open mesh (a boundary for boundary=), a semi-sharp crease, semi-sharp corners."""
    V, F = _mesh("mesh_with_border.off")
    c = np.array([0, 5, 17])
    s = np.array([0.5, 1.5, 2.7])
    kw = dict(scheme=scheme, corners=c, corner_sharpness=s, boundary="edge_and_corner",
              sharp_edges=F[[100, 300], :2], sharpness=[1.5, 0.6])
    if scheme == "hybrid":
        kw["sharp_faces"] = np.arange(60)  # a Loop region: its rim of mixed vertices
    return V, F, kw


@pytest.mark.parametrize("scheme", ["loop", "hybrid"])
def test_limit_surface_takes_the_options(scheme):
    """LimitSurface(...) at the vertices of a refined level (refine's vertex_origin) equals
    limit_positions(levels=L) with the same options, to 1e-12 × the diagonal."""
    V, F, kw = _surface_case(scheme)
    L = 2
    r = hybridsub.refine(F, levels=L, n_vertices=len(V), **kw)
    face, bary = r.vertex_origin
    P = hybridsub.limit_positions(V, F, levels=L, **kw)
    # the points on the faces at the semi-sharp corners and creases, and every 11th of the others
    near = np.isin(F, np.concatenate([kw["corners"], np.ravel(kw["sharp_edges"])])).any(axis=1)
    used = (face >= 0) & (near[np.maximum(face, 0)] | (np.arange(len(face)) % 11 == 0))
    surf = hybridsub.LimitSurface(V, F, **kw)
    Q = surf.evaluate(face[used], bary[used])
    diag = np.linalg.norm(np.ptp(V, axis=0))
    assert np.abs(Q - P[used]).max() < 1e-12 * diag
    # and the options make a difference there
    at = np.asarray(kw["corners"])  # old vertices keep their indices
    plain = hybridsub.LimitSurface(V, F, scheme=scheme, sharp_faces=kw.get("sharp_faces")).evaluate(face[at], bary[at])
    assert np.abs(plain - P[at]).max() > 1e-3 * diag


def test_subdivide_mesh_takes_the_options():
    """subdivide_mesh(trimesh, ...) equals subdivide(V, F, ...) with corner_sharpness,
    boundary and holes; its result, subdivided again from its metadata, equals two levels."""
    trimesh = pytest.importorskip("trimesh")
    V, F, kw = _surface_case("loop")
    kw.pop("scheme")
    holes = np.arange(0, len(F), 50)
    opts = dict(kw, holes=holes)
    mesh = trimesh.Trimesh(V, F, process=False)
    fine = hybridsub.subdivide_mesh(mesh, levels=1, scheme="loop", weld=False, **opts)
    V1, F1 = hybridsub.subdivide(V, F, levels=1, scheme="loop", **opts)
    assert np.array_equal(fine.faces, F1) and np.array_equal(fine.vertices, V1)
    meta = fine.metadata["hybridsub"]
    assert len(meta["corner_sharpness"]) == len(meta["corners"]) and np.isinf(meta["corner_sharpness"]).any()
    # again from the metadata (tags, the corners' sharpness left; the holes' faces are gone)
    again = hybridsub.subdivide_mesh(trimesh.Trimesh(V1, F1, process=False, metadata=fine.metadata), levels=1,
                                     scheme="loop", weld=False)
    r = hybridsub.refine(F, levels=1, n_vertices=len(V), scheme="loop", **opts)
    V2, F2 = hybridsub.subdivide(V1, F1, levels=1, scheme="loop", sharp_edges=r.sharp_edges,
                                 sharpness=r.sharpness, corners=r.corners, corner_sharpness=r.corner_sharpness)
    assert np.array_equal(again.faces, F2) and np.allclose(again.vertices, V2, rtol=0, atol=1e-13 * np.abs(V).max())


def test_face_varying_functions_take_the_options():
    """subdivide_face_varying and refine_face_varying with corner_sharpness, boundary and
    holes: the geometry is subdivide's (Loop), the UV faces stay aligned with the faces."""
    V, F, kw = _surface_case("loop")
    FUV = F.copy()  # no seams: the UVs are per vertex
    UV = V[:, :2].copy()
    holes = np.arange(0, len(F), 50)
    opts = dict(kw, holes=holes)
    V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, **opts)
    W2, G2 = hybridsub.subdivide(V, F, levels=2, **opts)
    assert np.array_equal(F2, G2) and np.allclose(V2, W2, rtol=0, atol=1e-13 * np.abs(V).max())
    assert FUV2.shape == F2.shape
    geo, uv = hybridsub.refine_face_varying(F, FUV, levels=2, uv_interpolation="none", **opts)
    assert np.array_equal(geo.faces, F2) and np.array_equal(uv.faces, FUV2)
    X, G, UVm, FUVm, S, Suv = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, return_matrix=True, **opts)
    assert np.allclose(S @ V, V2, rtol=0, atol=1e-13 * np.abs(V).max()) and np.array_equal(FUVm, FUV2)
    # without holes the fast path runs: the same numbers
    opts.pop("holes")
    V3, F3, _, _ = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, **opts)
    assert np.allclose(V3, hybridsub.subdivide(V, F, levels=2, **opts)[0], rtol=0, atol=1e-13 * np.abs(V).max())


def test_command_line_boundary_in_subdivide_and_batch(tmp_path):
    """``hybridsub subdivide --boundary none`` leaves out the faces at the boundary, as
    subdivide(boundary="none"); a batch's task with ``boundary`` writes the same bytes (and a
    default batch's options, hence its manifest key, are unchanged)."""
    from hybridsub._app import batch as _batch
    from hybridsub._app.cli import main
    from hybridsub._app.pipeline import subdivide_file
    from hybridsub._app.task import file_options

    src = str(DATA / "mesh_with_border.off")
    out = tmp_path / "cli.obj"
    assert main(["subdivide", src, "-o", str(out), "--levels", "1", "--scheme", "loop", "--boundary", "none",
                 "-q"]) == 0
    V, F = _mesh("mesh_with_border.off")
    V1, F1 = hybridsub.subdivide(V, F, levels=1, scheme="loop", boundary="none")
    m = hybridsub.read_mesh(out)
    assert np.array_equal(m.faces, F1) and np.allclose(m.vertices, V1, rtol=0, atol=1e-9 * np.abs(V).max())
    args = (1, "loop", None, None, "loop", "obj", False, False, False, None)
    assert "boundary" not in _batch.batch_options(*args)
    options = _batch.batch_options(*args, boundary="none")
    assert options["boundary"] == "none"
    task_out = tmp_path / "task.obj"
    subdivide_file(file_options(options), src, str(task_out))
    assert task_out.read_bytes() == out.read_bytes()
    with pytest.raises(ValueError, match="boundary must be one of"):
        _batch.batch_options(*args, boundary="edges")


def test_limit_surface_projects_with_semi_sharp_corners():
    """project() on a surface with semi-sharp corners: the limit points of its corners project
    onto themselves (the seeds' limit points take the sharpness left, as evaluate does)."""
    V, F, kw = _surface_case("loop")
    surf = hybridsub.LimitSurface(V, F, **kw)
    P = hybridsub.limit_positions(V, F, **kw)[kw["corners"]]
    face, bary, Q, dist = surf.project(P)
    diag = np.linalg.norm(np.ptp(V, axis=0))
    assert np.abs(Q - P).max() < 1e-10 * diag and np.abs(dist).max() < 1e-10 * diag
    assert np.abs(surf.evaluate(face, bary) - P).max() < 1e-10 * diag


@pytest.mark.parametrize("levels", [3, None])
def test_fit_takes_semi_sharp_corners(levels):
    """fit(corner_sharpness=) recovers the control positions of a surface (refined, or the
    limit) with semi-sharp corners from its own points; without the sharpness it cannot."""
    V, F, c, s = _corner_case("hybrid")  # the octahedron, every vertex a corner
    kw = dict(scheme="loop", corners=c, corner_sharpness=s)
    W = V * [1.0, 1.3, 0.8]
    if levels is None:
        target = hybridsub.limit_positions(W, F, levels=2, **kw)
    else:
        target = hybridsub.subdivide(W, F, levels=levels, **kw)[0]
    res = hybridsub.fit(F, target, V0=V, levels=levels, max_iterations=30, **kw)
    assert np.abs(res.vertices - W).max() < 1e-9
    wrong = hybridsub.fit(F, target, V0=V, levels=levels, max_iterations=30, scheme="loop", corners=c)
    assert np.abs(wrong.vertices - W).max() > 1e-3


def test_subdivide_mesh_pyvista_takes_the_options():
    pv = pytest.importorskip("pyvista")
    V, F, kw = _surface_case("loop")
    kw.pop("scheme")
    poly = pv.PolyData(V, np.hstack([np.full((len(F), 1), 3), F]).ravel())
    fine = hybridsub.subdivide_mesh(poly, levels=1, scheme="loop", weld=False, holes=[0, 9], **kw)
    V1, F1 = hybridsub.subdivide(V, F, levels=1, scheme="loop", holes=[0, 9], **kw)
    assert np.array_equal(np.asarray(fine.regular_faces), F1) and np.array_equal(np.asarray(fine.points), V1)
    assert len(fine.field_data["corner_sharpness"]) == len(fine.field_data["corners"])
