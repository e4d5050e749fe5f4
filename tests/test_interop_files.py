"""Interop (issue 16): PLY tags every reader skips, plyfile, meshio formats, write_mesh of mesh
objects, pyvista in and out of subdivide_mesh, textures kept in OBJ and GLB, progress bars."""

import os
import subprocess
import sys

import numpy as np
import pytest

import hybridsub
from hybridsub import MeshError, read_mesh, write_mesh

DATA = os.path.join(os.path.dirname(__file__), "data")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TET = (np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]),
       np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]))


@pytest.fixture(scope="module")
def tagged():
    """fandisk with creases (some semi-sharp), corners and a few sharp faces."""
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    s = np.where(np.arange(len(feat.sharp_edges)) % 3 == 0, 2.5, np.inf)
    return V, F, feat.sharp_edges, s, feat.corners, np.array([3, 5, 8])


# ---------------------------------------------------------------------------------------- PLY


@pytest.mark.parametrize("binary", [True, False])
def test_tagged_ply_reads_in_meshio_plyfile_and_trimesh(tmp_path, tagged, binary):
    import meshio
    import plyfile
    import trimesh

    V, F, E, s, C, S = tagged
    path = tmp_path / "f.ply"
    write_mesh(path, V, F, sharp_edges=E, sharpness=s, corners=C, sharp_faces=S, binary=binary)
    m = meshio.read(path)  # stopped at 'element crease' before
    assert np.array_equal(m.cells_dict["triangle"], F) and np.allclose(m.points, V)
    p = plyfile.PlyData.read(str(path))
    assert [e.name for e in p.elements] == ["vertex", "face"]
    t = trimesh.load(path, process=False)
    assert np.array_equal(t.faces, F)
    back = read_mesh(path)  # the tags come back exactly, from the header comments
    assert np.array_equal(back.sharp_edges, E) and np.array_equal(back.sharpness, s)
    assert np.array_equal(back.corners, np.sort(C)) and np.array_equal(back.sharp_faces, S)


def test_ply_tag_elements_of_older_files_read_through_plyfile(tmp_path, tagged):
    """Files with 'crease', 'corner' and 'sharp_face' elements (hybridsub before issue 16) read
    as before; plyfile reads the same elements."""
    import plyfile
    from hybridsub._io import ply as _ply

    V, F, E, s, C, S = tagged
    path = str(tmp_path / "old.ply")
    _ply.write_ply(path, [("vertex", [(k, "f8", V[:, i]) for i, k in enumerate("xyz")]),
                          ("face", [("vertex_indices", "i4", F.astype(np.int32))]),
                          ("crease", [("vertex1", "i4", E[:, 0]), ("vertex2", "i4", E[:, 1]),
                                      ("sharpness", "f8", np.where(np.isinf(s), 10.0, s))]),
                          ("corner", [("vertex", "i4", C), ("sharpness", "f8", np.full(len(C), 10.0))]),
                          ("sharp_face", [("face", "i4", S)])])
    m = read_mesh(path)
    assert np.array_equal(m.sharp_edges, E) and np.array_equal(m.sharpness, s)
    assert np.array_equal(m.corners, np.sort(C)) and np.array_equal(m.sharp_faces, S)
    p = plyfile.PlyData.read(path)
    assert np.array_equal(p["crease"]["vertex1"], E[:, 0]) and np.array_equal(p["sharp_face"]["face"], S)


def test_broken_ply_tags_and_files(tmp_path):
    with pytest.raises(MeshError, match="'comment crease' header lines hold 4 numbers, not a multiple of 3"):
        read_mesh(os.path.join(DATA, "bad_crease_comment.ply"))
    with pytest.raises(MeshError, match=r"corner 0 names vertices \[7.0\], but there are 3"):
        read_mesh(os.path.join(DATA, "corner_out_of_range.ply"))
    V, F = hybridsub.load_example()
    path = tmp_path / "t.ply"
    write_mesh(path, V, F)
    raw = path.read_bytes()
    path.write_bytes(raw[: len(raw) - 100])
    with pytest.raises(MeshError, match="the file ends inside element 'face'"):
        read_mesh(path)


# ---------------------------------------------------------------------------------- meshio


@pytest.mark.parametrize("ext", [".vtu", ".vtk"])  # XDMF: needs h5py too
def test_meshio_formats_keep_tags(tmp_path, tagged, ext):
    import meshio

    V, F, E, s, C, S = tagged
    path = tmp_path / ("f" + ext)
    write_mesh(path, V, F, sharp_edges=E, sharpness=s, corners=C, sharp_faces=S)
    m = meshio.read(path)
    assert np.array_equal(m.cells_dict["triangle"], F) and np.array_equal(m.cells_dict["line"], E)
    back = read_mesh(path)
    assert np.array_equal(back.faces, F) and np.allclose(back.vertices, V)
    assert np.array_equal(back.sharp_edges, E) and np.array_equal(back.sharpness, s)
    assert np.array_equal(back.corners, np.sort(C)) and np.array_equal(back.sharp_faces, S)


def test_meshio_volume_and_cli(tmp_path):
    import meshio

    meshio.Mesh(np.eye(4, 3), [("tetra", np.array([[0, 1, 2, 3]]))]).write(tmp_path / "tet.vtu")
    with pytest.raises(MeshError, match="tetra cells, a volume mesh"):
        read_mesh(tmp_path / "tet.vtu")
    src = tmp_path / "in.vtk"
    V, F = TET
    write_mesh(src, V, F, sharp_edges=[[0, 1]])
    from hybridsub._app.cli import main

    assert main(["subdivide", str(src), "-o", str(tmp_path / "out.vtu"), "--levels", "2", "-q"]) == 0
    r = hybridsub.refine(F, [[0, 1]], levels=2)
    out = read_mesh(tmp_path / "out.vtu")
    assert np.array_equal(out.faces, r.faces) and len(out.sharp_edges) == len(r.sharp_edges)


# ------------------------------------------------------------------- write_mesh of mesh objects


def test_write_mesh_of_a_trimesh_result_and_to_trimesh(tmp_path, tagged):
    import trimesh

    V, F, E, s, C, S = tagged
    fine = hybridsub.subdivide_mesh(trimesh.Trimesh(V, F, process=False), sharp_edges=E, sharpness=s, corners=C)
    write_mesh(tmp_path / "fine.ply", fine)  # one line, tags included
    back = read_mesh(tmp_path / "fine.ply")
    tags = fine.metadata["hybridsub"]
    assert np.array_equal(back.sharp_edges, tags["sharp_edges"]) and np.array_equal(back.sharpness, tags["sharpness"])
    assert len(back.corners) == len(C)
    t = back.to_trimesh()  # and back: subdivide_mesh finds the tags
    assert np.array_equal(t.metadata["hybridsub"]["sharp_edges"], back.sharp_edges)
    again = hybridsub.subdivide_mesh(t)
    assert len(again.metadata["hybridsub"]["sharp_edges"]) == 2 * len(back.sharp_edges)
    write_mesh(tmp_path / "c.obj", fine, corners=[])  # a tag argument replaces the stored one
    assert len(read_mesh(tmp_path / "c.obj").corners) == 0
    with pytest.raises(TypeError, match="takes no faces"):
        write_mesh(tmp_path / "x.obj", fine, F)
    with pytest.raises(TypeError, match="needs faces"):
        write_mesh(tmp_path / "x.obj", V)


def test_pyvista_in_and_out(tmp_path):
    pv = pytest.importorskip("pyvista")
    m = read_mesh(os.path.join(DATA, "cube-meshed.off"))
    V, F = m.vertices, m.faces
    poly = pv.PolyData.from_regular_faces(V, F)
    poly.point_data["height"] = V[:, 2]
    poly.point_data["label"] = np.arange(len(V), dtype=np.int32) % 7
    poly.cell_data["part"] = np.arange(len(F)) % 5
    snapshot = poly.copy(deep=True)
    fine = hybridsub.subdivide_mesh(poly, levels=2, feature_angle=30)
    assert isinstance(fine, pv.PolyData) and poly == snapshot  # the input is not modified
    r = hybridsub.refine(F, hybridsub.detect_features(V, F, 30).sharp_edges, levels=2,
                         corners=hybridsub.detect_features(V, F, 30).corners)
    assert np.array_equal(fine.regular_faces, r.faces) and np.allclose(fine.points, r.apply(V))
    assert np.allclose(fine.point_data["height"], fine.points[:, 2])  # refined like the positions
    assert fine.point_data["label"].dtype == np.int32
    assert np.array_equal(fine.cell_data["part"], (np.arange(len(F)) % 5)[r.face_parent])
    assert np.array_equal(fine.field_data["sharp_edges"], r.sharp_edges)
    again = hybridsub.subdivide_mesh(fine)  # the tags travel in field_data
    assert len(again.field_data["sharp_edges"]) == 2 * len(r.sharp_edges)
    write_mesh(tmp_path / "p.obj", fine)
    assert np.array_equal(read_mesh(tmp_path / "p.obj").sharp_edges, r.sharp_edges)
    back = read_mesh(tmp_path / "p.obj").to_pyvista()
    assert np.array_equal(back.field_data["corners"], r.corners) and back.n_cells == len(r.faces)
    with pytest.raises(MeshError, match="face 0 has 4 vertices.*triangulate"):
        hybridsub.subdivide_mesh(pv.Plane(i_resolution=2, j_resolution=2))
    with pytest.raises(TypeError, match="trimesh.Trimesh or a pyvista.PolyData, got ndarray"):
        hybridsub.subdivide_mesh(V)


def test_pyvista_textured_polydata_keeps_seams():
    pv = pytest.importorskip("pyvista")
    import trimesh

    box = trimesh.creation.box()
    soup_V, soup_F = box.vertices[box.faces].reshape(-1, 3), np.arange(36).reshape(-1, 3)
    poly = pv.PolyData.from_regular_faces(soup_V, soup_F)
    poly.active_texture_coordinates = np.arange(72).reshape(36, 2) / 72
    fine = hybridsub.subdivide_mesh(poly, levels=2)  # welded: one closed surface, UV seams kept
    assert len(np.unique(fine.points, axis=0)) == 146 and fine.active_texture_coordinates.shape == (228, 2)


def test_import_and_help_do_not_load_optional_libraries():
    code = ("import sys, hybridsub, hybridsub._app.cli as c\n"
            "try:\n    c.main(['--help'])\nexcept SystemExit:\n    pass\n"
            "print(sorted(m for m in ('pyvista', 'vtk', 'meshio', 'tqdm', 'plyfile') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


# ------------------------------------------------------------------------------ textures


def _textured_obj(folder):
    from PIL import Image

    os.makedirs(os.path.join(folder, "maps"), exist_ok=True)
    Image.fromarray(np.arange(192, dtype=np.uint8).reshape(8, 8, 3)).save(os.path.join(folder, "maps", "t.png"))
    with open(os.path.join(folder, "m.mtl"), "w") as fh:
        fh.write("newmtl mat\nKd 1 1 1\nmap_Kd maps/t.png\n")
    V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    lines = ["mtllib m.mtl"] + [f"v {a} {b} {c}" for a, b, c in V] + ["vt 0 0", "vt 1 0", "vt 0 1", "vt 1 1"]
    lines += ["usemtl mat"] + [f"f {a + 1}/{a + 1} {b + 1}/{b + 1} {c + 1}/{c + 1}" for a, b, c in F]
    path = os.path.join(folder, "tex.obj")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


def test_textured_obj_elsewhere_and_glb_keep_the_texture(tmp_path):
    import trimesh
    from hybridsub._app.cli import main

    src = _textured_obj(str(tmp_path / "src"))
    assert main(["subdivide", src, "-o", str(tmp_path / "out" / "fine.obj"), "--levels", "1", "-q"]) == 0
    assert (tmp_path / "out" / "m.mtl").exists() and (tmp_path / "out" / "maps" / "t.png").exists()
    t = trimesh.load(tmp_path / "out" / "fine.obj", process=False)
    assert t.visual.material.image.size == (8, 8)  # not trimesh's 2x2 stand-in
    assert main(["subdivide", src, "-o", str(tmp_path / "out" / "fine.glb"), "--levels", "1", "-q"]) == 0
    g = trimesh.load(tmp_path / "out" / "fine.glb", force="mesh")
    assert g.visual.material.baseColorTexture.size == (8, 8)
    # written under a temporary name elsewhere, then moved (as batch does): named for where it goes
    from hybridsub import _io

    tmp, final = tmp_path / "tmp" / "x.obj", tmp_path / "final" / "x.obj"
    _io.write(str(tmp), read_mesh(src), folder=str(final.parent))
    assert "mtllib m.mtl" in tmp.read_text() and not (tmp_path / "tmp" / "m.mtl").exists()
    assert (final.parent / "maps" / "t.png").exists()


# ------------------------------------------------------------------------------ progress


def test_progress_option_draws_a_tqdm_bar(capsys):
    V, F = TET
    V2, F2 = hybridsub.subdivide(V, F, levels=3, progress=True)
    err = capsys.readouterr().err
    assert "3/3" in err and f"{len(F2):,} faces" in err
    hybridsub.refine(F, levels=2, progress=False)
    assert capsys.readouterr().err == ""
