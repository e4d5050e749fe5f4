"""Mesh files with features: OBJ tags in OpenSubdiv's convention, PLY tag elements, OFF, NPZ, trimesh formats."""

import os
import warnings

import numpy as np
import pytest

import hybridsub
from hybridsub import MeshError, read_mesh, write_mesh
from hybridsub import _io

DATA = os.path.join(os.path.dirname(__file__), "data")


@pytest.fixture(scope="module")
def fandisk():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    rng = np.random.default_rng(5)
    s = np.where(rng.random(len(feat.sharp_edges)) < 0.3, rng.uniform(0.1, 4.0, len(feat.sharp_edges)), np.inf)
    return V, F, feat.sharp_edges, s, feat.corners


def _write(path, text):
    with open(path, "w") as fh:
        fh.write(text)
    return str(path)


@pytest.mark.parametrize("ext,binary", [("obj", True), ("ply", True), ("ply", False), ("npz", True)])
def test_tags_round_trip_exactly(tmp_path, fandisk, ext, binary):
    V, F, E, s, C = fandisk
    sf = np.array([3, 17, 400, 12945])
    colors = np.random.default_rng(0).random((len(V), 3))
    path = tmp_path / f"m.{ext}"
    write_mesh(path, V, F, sharp_edges=E, sharpness=s, corners=C, sharp_faces=sf, vertex_colors=colors,
               binary=binary)
    m = read_mesh(path)
    assert np.array_equal(m.vertices, V) and np.array_equal(m.faces, F)
    assert np.array_equal(m.sharp_edges, E)
    assert np.array_equal(m.sharpness, s)  # inf stays inf (written as 10), finite values exactly
    assert np.array_equal(m.corners, C) and np.array_equal(m.sharp_faces, sf)
    tol = 0.5 / 255 if ext == "ply" else 0  # PLY stores 8-bit colours
    assert np.abs(m.vertex_colors[:, :3] - colors).max() <= tol
    assert m.notes == ()


def test_round_trip_gives_the_same_subdivision(tmp_path, fandisk):
    """What the file holds is what subdivide sees: read tags → the same surface as the arrays."""
    V, F, E, s, C = fandisk
    write_mesh(tmp_path / "m.obj", V, F, sharp_edges=E, sharpness=s, corners=C)
    m = read_mesh(tmp_path / "m.obj")
    a = hybridsub.subdivide(V, F, E, 2, sharpness=s, corners=C)
    b = hybridsub.subdivide(m.vertices, m.faces, m.sharp_edges, 2, sharpness=m.sharpness, corners=m.corners)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_obj_lines_follow_opensubdiv(tmp_path):
    V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    F = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    write_mesh(tmp_path / "t.obj", V, F, sharp_edges=[[0, 1], [1, 2]], sharpness=[np.inf, 2.5], corners=[3],
               sharp_faces=[1])
    lines = open(tmp_path / "t.obj").read().splitlines()
    assert "t crease 2/1/0 0 1 10.0" in lines  # 0-based, infinitely sharp written as 10
    assert "t crease 2/1/0 1 2 2.5" in lines
    assert "t corner 1/1/0 3 10.0" in lines
    assert "t sharpface 1/0/0 1" in lines
    assert "f 1 3 2" in lines  # faces stay 1-based as OBJ wants
    assert all(len(ln) < 256 for ln in lines)  # OpenSubdiv's shape reader stops at longer lines


def test_reads_an_opensubdiv_shape(tmp_path):
    """Lines as in OpenSubdiv's regression/shapes (loop_cube_creases1): v/vt/vn faces, 1-based,
    tags 0-based with three counts, per-tag sharpness, an interpolateboundary tag."""
    text = """# This file uses centimeters as units for non-parametric coordinates.

v 0.000000 1.414214 1.000000
v -1.414214 0.000000 1.000000
v 1.414214 -0.000000 1.000000
v -0.000000 -1.414214 1.000000
v 1.414214 -0.000000 -1.000000
v -0.000000 -1.414214 -1.000000
v 0.000000 1.414214 -1.000000
v -1.414214 0.000000 -1.000000
vt 0.375000 0.000000
vt 0.625000 0.000000
vt 0.375000 0.250000
vn 0.000000 0.000000 1.000000
f 1/1/1 2/2/1 3/3/1
f 3/3/1 2/2/1 4/1/1
f 3/3/1 4/1/1 5/2/1
f 5/2/1 4/1/1 6/3/1
f 5/2/1 6/3/1 7/1/1
f 7/1/1 6/3/1 8/2/1
f 7/1/1 8/2/1 1/3/1
f 1/3/1 8/2/1 2/1/1
f 2/2/1 8/1/1 4/3/1
f 4/3/1 8/1/1 6/2/1
f 7/1/1 1/2/1 5/3/1
f 5/3/1 1/2/1 3/1/1
t crease 2/1/0 1 3 5.0
t crease 2/1/0 3 2 5.0
t crease 2/1/0 2 4 0.2
t crease 2/1/0  0 6  10.0
t corner 1/1/0 7 10.0
t interpolateboundary 1/0/0 2
"""
    m = read_mesh(_write(tmp_path / "cube.obj", text))
    assert m.vertices.shape == (8, 3) and m.faces[0].tolist() == [0, 1, 2]
    assert m.sharp_edges.tolist() == [[1, 3], [3, 2], [2, 4], [0, 6]]
    assert m.sharpness.tolist() == [5.0, 5.0, 0.2, np.inf]
    assert m.corners.tolist() == [7]
    assert m.face_uv is not None and m.uv.shape == (3, 2)
    assert m.vertex_uv is None  # vertex 0 uses two different UVs: a seam
    # the mesh is closed: interpolateboundary makes no extra corner and gives no note
    assert m.notes == ()
    V2, F2 = hybridsub.subdivide(m.vertices, m.faces, m.sharp_edges, 1, scheme="loop", sharpness=m.sharpness,
                                 corners=m.corners)
    assert len(F2) == 48


def test_obj_vt_with_one_or_three_numbers(tmp_path):
    """'vt u' means v = 0; 'vt u v w' keeps u and v (both OBJ forms exist in the wild)."""
    head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    for vt, want in (("vt 0.5\nvt 0.25\nvt 1\n", [[0.5, 0], [0.25, 0], [1, 0]]),
                     ("vt 0.5 0.1 0.3\nvt 0.25 0.2 0\nvt 1 0.1 0.3\n", [[0.5, 0.1], [0.25, 0.2], [1, 0.1]]),
                     ("vt 0.5\nvt 0.25 0.2\nvt 1 0.1 0.3\n", [[0.5, 0], [0.25, 0.2], [1, 0.1]])):
        m = read_mesh(_write(tmp_path / "t.obj", head + vt + "f 1/1 2/2 3/3\n"))
        assert m.uv.tolist() == want and m.face_uv.tolist() == [[0, 1, 2]]


def test_tag_variants(tmp_path):
    text = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3
f -4 -2 -1
t crease 4/1/0 0 1 1 2 10
t crease 2/1 2 3 1.5
t crease 2/1/0 3 0 0
t corner 2/2/0 1 2 3.0 0.0
t hole 1/0/0 0
t interpolateboundary 1/0/0 2
"""
    m = read_mesh(_write(tmp_path / "v.obj", text))
    assert m.faces.tolist() == [[0, 1, 2], [0, 2, 3]]  # negative indices are relative
    assert m.sharp_edges.tolist() == [[0, 1], [1, 2], [2, 3]]  # a chain of pairs; sharpness 0 is no crease
    assert m.sharpness.tolist() == [np.inf, np.inf, 1.5]
    # corner 1 (sharpness 3: semi-sharp), corner 2 has sharpness 0; interpolateboundary 2 makes
    # vertices 1 and 3, each in a single face, infinitely sharp corners (OpenSubdiv's EDGE_AND_CORNER)
    assert m.corners.tolist() == [1, 3]
    assert m.corner_sharpness is None
    notes = " ".join(m.notes)
    assert m.holes.tolist() == [0]  # t hole: face indices (OpenSubdiv's face holes)
    assert "hole" not in notes and "sharpness <= 0" in notes
    assert "interpolateboundary 2" in notes


@pytest.mark.parametrize("line,needle", [
    ("t crease 2/1/0 0 1", "line 5"),
    ("t crease 3/1/0 0 1 2 10", "vertex pairs"),
    ("t crease 2/1/0 0 9 10", "names vertices [0, 9]"),
    ("t corner 1/1/0 -1 10", "vertex -1"),
    ("t sharpface 1/0/0 5", "face 5"),
])
def test_bad_tags_are_named(tmp_path, line, needle):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n" + line + "\n"
    with pytest.raises(MeshError, match=needle.replace("[", r"\[").replace("]", r"\]")):
        read_mesh(_write(tmp_path / "b.obj", text))


def test_polygons_are_refused_or_triangulated(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 2 5 3\nf 1 2 3 4\nt sharpface 1/0/0 1\n"
    path = _write(tmp_path / "q.obj", text)
    with pytest.raises(MeshError, match="face 1 has 4 vertices.*triangulate"):
        read_mesh(path)
    m = read_mesh(path, triangulate=True)
    assert m.faces.tolist() == [[1, 4, 2], [0, 1, 2], [0, 2, 3]]
    assert m.sharp_faces.tolist() == [1, 2]  # the quad's tag goes to both its triangles
    off = _write(tmp_path / "q.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    with pytest.raises(MeshError, match="face 0 has 4 vertices"):
        read_mesh(off)


def test_vertex_order_is_the_files(tmp_path):
    """Tags name vertices by index, so the readers must keep every vertex where the file has it,
    duplicates and unused ones included: trimesh's loaders merge or split them."""
    rng = np.random.default_rng(2)
    V = rng.random((12, 3))
    V[7] = V[3]  # a duplicate position
    F = np.array([[0, 1, 2], [2, 1, 3], [4, 5, 6], [7, 8, 9], [9, 8, 10]])  # vertex 11 unused
    uv = rng.random((15, 2))
    FT = np.arange(15).reshape(5, 3)  # face-varying UVs: each corner its own
    for ext in ("obj", "ply", "off"):
        path = tmp_path / f"o.{ext}"
        write_mesh(path, V, F, uv=uv if ext != "off" else None, face_uv=FT if ext != "off" else None)
        m = read_mesh(path)
        assert np.array_equal(m.vertices, V), ext
        assert np.array_equal(m.faces, F), ext
        if ext != "off":
            assert np.allclose(m.uv[m.face_uv], uv[FT], atol=1e-7), ext
    # trimesh, for the record, splits vertices on OBJ with UVs (which is why we read OBJ ourselves)
    import trimesh

    t = trimesh.load(tmp_path / "o.obj", process=False)
    assert len(t.vertices) != len(V)


def test_ply_edge_element_and_polygons(tmp_path):
    text = """ply
format ascii 1.0
comment an 'edge' element as other tools write it: vertex1 vertex2 and a crease value
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
element edge 2
property int vertex1
property int vertex2
property float crease
end_header
0 0 0
1 0 0
1 1 0
0 1 0
3 0 1 2
3 0 2 3
0 1 10
2 3 2
"""
    m = read_mesh(_write(tmp_path / "e.ply", text))
    assert m.faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert m.sharp_edges.tolist() == [[0, 1], [2, 3]] and m.sharpness.tolist() == [np.inf, 2.0]
    # binary PLY with a quad: the list lengths differ, the reader goes record by record
    from hybridsub._io import ply as _ply

    quad = tmp_path / "q.ply"
    _ply.write_ply(str(quad), [("vertex", [("x", "f4", np.arange(5.0)), ("y", "f4", np.zeros(5)),
                                           ("z", "f4", np.ones(5))]),
                               ("face", [("vertex_indices", "i4", np.array([[0, 1, 2]]))])])
    raw = open(quad, "rb").read().replace(b"element face 1", b"element face 2")
    body = raw + np.array([4], np.uint8).tobytes() + np.array([0, 2, 3, 4], "<i4").tobytes()
    open(quad, "wb").write(body)
    with pytest.raises(MeshError, match="face 1 has 4 vertices"):
        read_mesh(quad)
    assert read_mesh(quad, triangulate=True).faces.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4]]


def test_ply_written_by_hybridsub_loads_in_trimesh(tmp_path, fandisk):
    """The tag elements are named so that trimesh still reads the file as a mesh."""
    import trimesh

    V, F, E, s, C = fandisk
    write_mesh(tmp_path / "f.ply", V, F, sharp_edges=E, sharpness=s, corners=C)
    t = trimesh.load(tmp_path / "f.ply", process=False)
    assert isinstance(t, trimesh.Trimesh) and np.array_equal(t.faces, F) and np.allclose(t.vertices, V)


@pytest.mark.parametrize("ext", ["off", "stl", "glb"])
def test_formats_without_tags_warn(tmp_path, fandisk, ext):
    V, F, E, s, C = fandisk
    with pytest.warns(UserWarning, match="cannot hold .*722 creases"):
        write_mesh(tmp_path / f"f.{ext}", V, F, sharp_edges=E, corners=C)
    m = read_mesh(tmp_path / f"f.{ext}")
    assert len(m.faces) == len(F) and len(m.vertices) == len(V)  # STL is welded back together
    if ext == "off":
        assert np.array_equal(m.vertices, V) and np.array_equal(m.faces, F)
    assert not m.has_tags
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_mesh(tmp_path / f"g.{ext}", V, F)  # nothing to drop, nothing to say


def test_read_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="nosuch.obj: no such file"):
        read_mesh(tmp_path / "nosuch.obj")
    with pytest.raises(MeshError, match="unknown mesh format '.abc'"):
        read_mesh(_write(tmp_path / "a.abc", "1 2 3\n"))
    with pytest.raises(MeshError, match="not a triangle mesh"):  # trimesh reads it as a point cloud
        read_mesh(_write(tmp_path / "a.xyz", "1 2 3\n4 5 6\n7 8 9\n"))
    with pytest.raises(MeshError, match="no 'f' lines"):
        read_mesh(_write(tmp_path / "p.obj", "v 0 0 0\nv 1 0 0\n"))
    with pytest.raises(MeshError, match="not an OFF file"):
        read_mesh(_write(tmp_path / "x.off", "PLY\n"))
    with pytest.raises(MeshError, match=r"face 0 refers to vertex 8, but there are only 3 \(valid 1..3\)"):
        read_mesh(_write(tmp_path / "r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 8\n"))
    with pytest.raises(MeshError, match="not a PLY file"):
        read_mesh(_write(tmp_path / "x.ply", "hello\n"))


def test_npz_files(tmp_path, fandisk):
    """NPZ: plain np.load reads it, UVs with seams and semi-sharp creases come back exactly, the
    same mesh gives the same bytes, and what is not a mesh is named."""
    V, F, E, s, C = fandisk
    uv = np.random.default_rng(1).random((len(F) * 3, 2))
    fuv = np.arange(len(F) * 3).reshape(-1, 3)
    for name in ("a.npz", "b.npz"):
        write_mesh(tmp_path / name, V, F, sharp_edges=E, sharpness=s, corners=C, uv=uv, face_uv=fuv)
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "b.npz").read_bytes()
    with np.load(tmp_path / "a.npz") as z:
        assert sorted(z.files) == sorted(["vertices", "faces", "sharp_edges", "sharpness", "corners", "sharp_faces",
                                          "uv", "face_uv"])
        assert z["faces"].dtype == np.int64 and np.array_equal(z["sharpness"], s)
    m = read_mesh(tmp_path / "a.npz")
    assert np.array_equal(m.vertices, V) and np.array_equal(m.faces, F) and np.array_equal(m.sharpness, s)
    assert np.array_equal(m.uv, uv) and np.array_equal(m.face_uv, fuv) and m.vertex_uv is None
    np.savez(tmp_path / "extra.npz", vertices=V, faces=F, normals=V)
    assert read_mesh(tmp_path / "extra.npz").notes == ("ignored arrays: normals",)
    bad = {
        "text.npz": "not an NPZ file",
        "nofaces.npz": "an NPZ mesh needs arrays 'vertices' and 'faces'; it has no 'faces'",
        "quads.npz": "'faces' must have shape (m, 3) (triangles), got (1, 4)",
        "range.npz": "face 0 = [0, 1, 5] refers to vertex 5",
        "edges.npz": "sharp edge 0 = [0, 9] refers to a vertex outside 0..3",
        "objects.npz": "not a readable NPZ file",
        "uvonly.npz": "'face_uv' needs a 'uv' array",
    }
    T = np.eye(4, 3)
    (tmp_path / "text.npz").write_text("vertices faces")
    np.savez(tmp_path / "nofaces.npz", vertices=T)
    np.savez(tmp_path / "quads.npz", vertices=T, faces=[[0, 1, 2, 3]])
    np.savez(tmp_path / "range.npz", vertices=T, faces=[[0, 1, 5]])
    np.savez(tmp_path / "edges.npz", vertices=T, faces=[[0, 1, 2]], sharp_edges=[[0, 9]])
    np.savez(tmp_path / "objects.npz", vertices=T, faces=np.array([[0, 1, 2]], dtype=object))
    np.savez(tmp_path / "uvonly.npz", vertices=T, faces=[[0, 1, 2]], face_uv=[[0, 1, 2]])
    for name, msg in bad.items():
        with pytest.raises(MeshError) as e:
            read_mesh(tmp_path / name)
        assert str(e.value).startswith(str(tmp_path / name)) and msg in str(e.value), str(e.value)


def test_write_does_not_touch_the_callers_arrays(tmp_path, fandisk):
    V, F, E, s, C = fandisk
    args = [a.copy() for a in (V, F, E, s, C)]
    write_mesh(tmp_path / "f.obj", *args[:2], sharp_edges=args[2], sharpness=args[3], corners=args[4])
    for a, b in zip(args, (V, F, E, s, C)):
        assert np.array_equal(a, b)


def test_weld_remaps_tags():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 2], [3, 4, 5]])
    m = _io.TaggedMesh(V, F, np.array([[3, 5]]), np.array([np.inf]), np.array([4]), np.array([1]))
    w, merged, dropped = _io.weld(m)
    assert merged == 2 and dropped == 0
    assert w.faces.tolist() == [[0, 1, 2], [1, 3, 2]]
    assert w.sharp_edges.tolist() == [[1, 2]] and w.corners.tolist() == [3] and w.sharp_faces.tolist() == [1]


def test_opensubdiv_reference_through_a_file(tmp_path):
    """Interoperation: the OpenSubdiv semi-sharp reference, with its tags passed through an OBJ
    file written and read by hybridsub, gives OpenSubdiv's surface."""
    from meshcompare import mesh_difference

    d = np.load(os.path.join(DATA, "cube-meshed.loop_semisharp.L2.npz"))
    write_mesh(tmp_path / "c.obj", d["V_in"], d["F_in"], sharp_edges=d["creases"], sharpness=d["sharpness"])
    m = read_mesh(tmp_path / "c.obj")
    V, F = hybridsub.subdivide(m.vertices, m.faces, m.sharp_edges, 2, scheme="loop", sharpness=m.sharpness)
    assert mesh_difference(V, F, d["V"], d["F"], 1e-9) is None


def test_textured_glb_keeps_its_seams(tmp_path):
    """glTF holds UVs per vertex: writing duplicates vertices along seams, reading welds them
    back (a TaggedMesh holds face-varying UVs), so the surface is one piece again."""
    d = np.load(os.path.join(DATA, "bunny10k_textured.fvar_linear.L1.npz"))
    V, F, UV, FUV = d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"]
    write_mesh(tmp_path / "b.glb", V, F, uv=UV, face_uv=FUV)
    import trimesh

    t = trimesh.load(tmp_path / "b.glb", process=False, force="mesh")
    assert len(t.vertices) == len(UV) and t.visual.uv.shape == (len(UV), 2)  # one vertex per (v, vt) pair
    m = read_mesh(tmp_path / "b.glb")
    assert len(m.vertices) == len(V) and np.array_equal(m.faces.shape, F.shape)
    assert any("welded 1400 vertices that the file duplicates along UV seams" in n for n in m.notes)
    assert np.allclose(m.vertices[m.faces], V[F], atol=1e-5) and np.allclose(m.uv[m.face_uv], UV[FUV], atol=1e-6)
    assert len(hybridsub.seam_edges(m.faces, m.face_uv)) == len(hybridsub.seam_edges(F, FUV))


def test_weld_merges_equal_uv_copies():
    """--weld: UV indices that land on one vertex with equal UVs become one (no seam there)."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 2], [3, 4, 5]])
    uv = V[:, :2].copy()
    m, merged, _ = _io.weld(_io.TaggedMesh(V, F, uv=uv, face_uv=F.copy()))
    assert merged == 2 and m.face_uv.tolist() == [[0, 1, 2], [1, 3, 2]] and len(m.uv) == 4
    uv[3] += 0.5  # a real seam at vertex 1 now: two UV indices there
    m, _, _ = _io.weld(_io.TaggedMesh(V, F, uv=uv, face_uv=F.copy()))
    assert m.face_uv.tolist() == [[0, 1, 2], [3, 4, 2]] and len(hybridsub.seam_edges(m.faces, m.face_uv)) == 1


# ----------------------------------------------------------------------------------------------
# OBJ materials: mtllib and usemtl travel with the faces

_MATERIAL_OBJ = """mtllib lib/mats.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0.5 0.5 1
f 1 2 5
usemtl red
f 2 3 5
f 3 4 5
usemtl blue paint
f 4 1 5
usemtl red
f 1 3 2
f 1 4 3
"""


@pytest.mark.parametrize("slow", [False, True])
def test_obj_materials_read_and_written_relative_to_the_new_file(tmp_path, slow):
    """Names in order of first use, a material per face (-1 before any usemtl), the library as
    an absolute path; written elsewhere, mtllib names the same library relative to the new file
    and usemtl lines follow the runs of faces. The careful reader (a tab) reads the same."""
    (tmp_path / "src" / "lib").mkdir(parents=True)
    text = _MATERIAL_OBJ.replace("f 1 2 5", "f\t1 2 5") if slow else _MATERIAL_OBJ
    _write(tmp_path / "src" / "m.obj", text)
    m = read_mesh(tmp_path / "src" / "m.obj")
    assert m.materials == ("red", "blue paint")
    assert m.face_material.tolist() == [-1, 0, 0, 1, 0, 0]
    assert m.material_libs == (str(tmp_path / "src" / "lib" / "mats.mtl"),)
    assert not any("material" in n for n in m.notes)
    out = tmp_path / "elsewhere" / "deeper" / "o.obj"
    _io.write(str(out), m)
    lines = out.read_text().splitlines()
    assert "mtllib ../../src/lib/mats.mtl" in lines
    assert [ln for ln in lines if ln.startswith("usemtl")] == ["usemtl red", "usemtl blue paint", "usemtl red"]
    back = read_mesh(out)
    assert back.materials == m.materials and back.material_libs == m.material_libs
    assert np.array_equal(back.face_material, m.face_material) and np.array_equal(back.faces, m.faces)


def test_obj_materials_follow_polygons_and_subdivision(tmp_path, capsys):
    """A quad split into two triangles keeps its material; 'hybridsub subdivide' gives each new
    face its parent's material, and says that only OBJ output keeps them."""
    from hybridsub._app.cli import main

    _write(tmp_path / "q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nusemtl a\nf 2 5 3\n"
                               "usemtl b\nf 1 2 3 4\n")
    m = read_mesh(tmp_path / "q.obj", triangulate=True)
    assert m.face_material.tolist() == [0, 1, 1] and m.materials == ("a", "b")
    assert main(["subdivide", str(tmp_path / "q.obj"), "-o", str(tmp_path / "q2.obj"), "--levels", "2",
                 "--triangulate", "-q"]) == 0
    r = hybridsub.refine(m.faces, None, 2, n_vertices=len(m.vertices))
    out = read_mesh(tmp_path / "q2.obj")
    assert out.materials == ("a", "b")
    assert np.array_equal(out.face_material, m.face_material[r.face_parent])
    assert main(["subdivide", str(tmp_path / "q.obj"), "-o", str(tmp_path / "q2.ply"), "--levels", "1",
                 "--triangulate"]) == 0
    assert "note: the materials of q.obj ('mtllib', 'usemtl') are kept in .obj output only" in \
        capsys.readouterr().err
