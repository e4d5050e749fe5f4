"""holes=: faces that are not rendered but still shape their neighbours (OpenSubdiv's face holes).

Loop against OpenSubdiv 3.5 (tests/data/holes/, written by benchmarks/peers/osd_holes_references.py
with benchmarks/peers/osd_holes.cpp); every scheme against the rule of docs/scheme.md: the
matrix and positions are those without holes, the faces those without holes minus the
descendants (through ``face_parent``) of the holes.
"""

import glob
import os

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import hybridsub
from meshcompare import mesh_difference
from strategies import meshes, rngs, sharp_edge_tags, sharp_face_tags

DATA = os.path.join(os.path.dirname(__file__), "data", "holes")
CASES = sorted(os.path.basename(p)[:-4] for p in glob.glob(os.path.join(DATA, "*.npz")))


def test_reference_files_are_there():
    assert {"cube-meshed.loop.L1", "cube-meshed.loop.L2", "fandisk_creases.loop.L1"} <= set(CASES)


@pytest.mark.parametrize("case", CASES)
def test_loop_matches_opensubdiv(case):
    d = np.load(os.path.join(DATA, case + ".npz"))
    levels = int(case.split(".")[-1][1:])
    V, F = hybridsub.subdivide(d["V_in"], d["F_in"], d["creases"], levels=levels, scheme="loop", holes=d["holes"])
    assert len(F) < 4 ** levels * len(d["F_in"])  # the reference has holes to leave out
    assert mesh_difference(V, F, d["V"], d["F"]) is None, mesh_difference(V, F, d["V"], d["F"])
    # the hybrid scheme with every face sharp is Loop: the same faces left out
    V, F = hybridsub.subdivide(d["V_in"], d["F_in"], d["creases"], levels=levels, holes=d["holes"],
                               sharp_faces=np.ones(len(d["F_in"]), bool))
    assert mesh_difference(V, F, d["V"], d["F"]) is None


def test_a_vertex_only_holes_use_is_kept():
    d = np.load(os.path.join(DATA, "cube-meshed.loop.L1.npz"))
    V, F = hybridsub.subdivide(d["V_in"], d["F_in"], levels=1, scheme="loop", holes=d["holes"])
    assert 0 not in F and len(V) == 4 * len(d["F_in"]) // 2 + 2  # closed: n' = n + e, vertex 0 still there


def _check_rule(F, scheme, levels, holes, **tags):
    full = hybridsub.refine(F, levels=levels, scheme=scheme, **tags)
    r = hybridsub.refine(F, levels=levels, scheme=scheme, holes=holes, **tags)
    mask = np.zeros(len(F), bool)
    mask[holes] = True
    assert (r.matrix != full.matrix).nnz == 0 and r.n_vertices == full.n_vertices
    drop = mask[full.face_parent]
    np.testing.assert_array_equal(r.faces, full.faces[~drop])
    np.testing.assert_array_equal(r.face_parent, full.face_parent[~drop])
    assert not mask[r.face_parent].any()
    sf_full, sf = np.asarray(full.sharp_faces), np.asarray(r.sharp_faces)
    if sf_full.dtype == bool:
        np.testing.assert_array_equal(sf, sf_full[~drop])
    else:  # indices of the kept faces
        np.testing.assert_array_equal(r.faces[sf], full.faces[sf_full[~drop[sf_full]]])
    for k, (a, b) in enumerate(zip(r.steps, full.steps)):  # the steps keep their whole level
        np.testing.assert_array_equal(a.faces, b.faces)
        assert a.holes.shape == (len(b.faces),) and b.holes is None
    if levels:
        assert r.steps[-1].holes.sum() == drop.sum()
    return r, full


@pytest.mark.parametrize("scheme", ["loop", "sqrt3", "hybrid"])
@pytest.mark.parametrize("levels", [0, 1, 2])
def test_matrix_unchanged_faces_of_holes_dropped(scheme, levels):
    V, F = hybridsub.load_example()
    holes = np.arange(3, len(F), 211)
    tags = {} if scheme == "sqrt3" else dict(sharp_faces=np.arange(0, len(F), 3))
    _check_rule(F, scheme, levels, holes, **tags)
    V0, F0 = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, **tags)
    V1, F1 = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, holes=holes, **tags)
    np.testing.assert_array_equal(V1, V0)  # every vertex kept, to the bit
    assert len(F1) < len(F0)


def test_sqrt3_each_face_keeps_the_flipped_triangle_at_the_start_of_its_edges():
    """Kobbelt's √3 replaces an edge v→w of f (g across it) by (v, c_g, c_f), emitted by f,
    and (w, c_f, c_g), emitted by g: a hole drops the three triangles its own edges start."""
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    r = hybridsub.refine(F, levels=1, scheme="sqrt3", holes=[0])
    assert r.faces.tolist() == hybridsub.refine(F, levels=1, scheme="sqrt3").faces[3:].tolist()
    c = {tuple(f) for f in [[0, 6, 4], [1, 7, 4], [2, 5, 4]]}  # c_0 = 4; across 0→1 face 2 (c = 6), ...
    assert not c & {tuple(f) for f in r.faces}


@settings(max_examples=30, deadline=None)
@given(mesh=meshes(max_points=40), scheme=st.sampled_from(["loop", "sqrt3", "hybrid"]), levels=st.integers(1, 2),
       data=st.data())
def test_rule_holds_on_any_mesh(mesh, scheme, levels, data):
    V, F = mesh
    if len(F) < 2:
        return
    rng = data.draw(rngs())
    holes = rng.permutation(len(F))[:rng.integers(1, len(F))]
    tags = {}
    if scheme != "sqrt3":
        pairs, s = data.draw(sharp_edge_tags(F))
        tags = dict(sharp_edges=pairs, sharpness=s, sharp_faces=data.draw(sharp_face_tags(len(F))))
    if data.draw(st.booleans()):
        mask = np.zeros(len(F), bool)
        mask[holes] = True
        holes = mask
    r, full = _check_rule(F, scheme, levels, np.flatnonzero(holes) if holes.dtype == bool else holes, **tags)
    r2 = hybridsub.refine(F, levels=levels, scheme=scheme, holes=holes, **tags)
    np.testing.assert_array_equal(r2.faces, r.faces)


def test_holes_go_through_the_gate():
    V, F = hybridsub.load_example()
    with pytest.raises(hybridsub.MeshError, match=r"holes\[1\] = 12946 is not a face index"):
        hybridsub.subdivide(V, F, holes=[0, len(F)])
    with pytest.raises(hybridsub.MeshError, match="holes marks every face"):
        hybridsub.refine(F, holes=np.ones(len(F), bool))
    with pytest.raises(hybridsub.MeshError, match=r"holes as a boolean mask must have one entry per face"):
        hybridsub.refine(F, holes=np.ones(3, bool))
    with pytest.raises(TypeError, match="holes must hold integer face indices"):
        hybridsub.refine(F, holes=["a"])
    h = np.array([4, 2])
    hybridsub.refine(F, holes=h)
    assert h.tolist() == [4, 2]  # the caller's array untouched
    r = hybridsub.refine(F, holes=np.zeros(len(F), bool))  # no hole: as without
    assert r.steps[0].holes is None and len(r.faces) == len(hybridsub.refine(F).faces)


def test_holes_with_cut_and_uv_faces():
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    FUV = np.arange(12).reshape(4, 3)
    r = hybridsub.refine(F, levels=2, uv_faces=FUV, holes=[1], scheme="loop")
    assert r.uv_faces.shape == r.faces.shape == (48, 3)
    full = hybridsub.refine(F, levels=2, uv_faces=FUV, scheme="loop")
    np.testing.assert_array_equal(r.uv_faces, full.uv_faces[full.face_parent != 1])
    # a non-manifold fin, cut: the cut keeps the faces in order, so holes index the input's
    G = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    r = hybridsub.refine(G, levels=1, scheme="loop", non_manifold="cut", holes=[2])
    assert len(r.faces) == 8 and not (r.face_parent == 2).any()


def test_obj_hole_tags_round_trip(tmp_path):
    V, F = hybridsub.load_example()
    m = hybridsub.TaggedMesh(V, F, holes=np.arange(0, 40, 2))
    hybridsub.write_mesh(str(tmp_path / "h.obj"), m)
    back = hybridsub.read_mesh(str(tmp_path / "h.obj"))
    assert back.holes.tolist() == m.holes.tolist() and back.has_tags
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt hole 1/0/0 4\n")
    with pytest.raises(hybridsub.MeshError, match="hole tag names face 4, but the file has 1 faces"):
        hybridsub.read_mesh(str(tmp_path / "bad.obj"))


def test_command_line_leaves_out_the_faces_of_obj_holes(tmp_path):
    from hybridsub._app.cli import main
    V, F = hybridsub.load_example()
    src, dst = str(tmp_path / "a.obj"), str(tmp_path / "b.obj")
    hybridsub.write_mesh(src, hybridsub.TaggedMesh(V, F, holes=np.array([3, 7, 20])))
    assert main(["subdivide", src, "-o", dst, "--levels", "1", "--scheme", "loop", "--quiet"]) in (0, None)
    out = hybridsub.read_mesh(dst)
    V1, F1 = hybridsub.subdivide(V, F, levels=1, scheme="loop", holes=[3, 7, 20])
    assert mesh_difference(out.vertices, out.faces, V1, F1) is None


def test_limit_functions_take_holes():
    V, F = hybridsub.load_example()
    h = [0, 1, 2]
    np.testing.assert_array_equal(hybridsub.limit_positions(V, F, holes=h), hybridsub.limit_positions(V, F))
    N = hybridsub.limit_normals(V, F, per_face_corner=True, levels=1, scheme="loop")
    Nh = hybridsub.limit_normals(V, F, per_face_corner=True, levels=1, scheme="loop", holes=h)
    r = hybridsub.refine(F, levels=1, scheme="loop")
    np.testing.assert_array_equal(Nh, N[~np.isin(r.face_parent, h)])
    T1, _ = hybridsub.limit_tangents(V, F, per_face_corner=True, scheme="loop", holes=h)
    assert T1.shape == (len(F) - 3, 3, 3)
    S = hybridsub.LimitSurface(V, F, scheme="loop", holes=h)
    P = S.evaluate([5], [[1 / 3, 1 / 3, 1 / 3]])
    np.testing.assert_array_equal(P, hybridsub.LimitSurface(V, F, scheme="loop").evaluate([5], [[1 / 3] * 3]))
    with pytest.raises(hybridsub.MeshError, match=r"face\[1\] = 2 is a hole"):
        S.evaluate([5, 2], [[1 / 3] * 3] * 2)


def test_subdivide_mesh_takes_holes():
    trimesh = pytest.importorskip("trimesh")
    V, F = hybridsub.load_example()
    out = hybridsub.subdivide_mesh(trimesh.Trimesh(V, F, process=False), 1, scheme="loop", holes=[0, 1])
    V1, F1 = hybridsub.subdivide(V, F, levels=1, scheme="loop", holes=[0, 1])
    assert mesh_difference(out.vertices, out.faces, V1, F1) is None


def test_npz_holes_round_trip(tmp_path):
    V, F = hybridsub.load_example()
    m = hybridsub.TaggedMesh(V, F, holes=np.array([1, 5, 9]))
    hybridsub.write_mesh(str(tmp_path / "h.npz"), m)
    assert hybridsub.read_mesh(str(tmp_path / "h.npz")).holes.tolist() == [1, 5, 9]
    hybridsub.write_mesh(str(tmp_path / "n.npz"), hybridsub.TaggedMesh(V, F))
    assert "holes" not in np.load(str(tmp_path / "n.npz")).files  # files without holes as before
