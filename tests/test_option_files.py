"""Holes and semi-sharp corners through every format that holds tags (OBJ, PLY, NPZ, meshio's
VTK/VTU/XDMF), a UserWarning naming them where a format cannot (OFF, STL, meshio's others),
and damaged tags answered with a MeshError naming the problem."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import hybridsub
from hybridsub._errors import MeshError

TAGGED = [".obj", ".ply", ".npz", ".vtk", ".vtu"]  # and .xdmf, the same code, where h5py is installed


def _mesh():
    m = hybridsub.read_mesh(Path(__file__).parent / "data" / "cube-meshed.off")
    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    tags = dict(sharp_edges=F[[3, 40], :2], sharpness=[1.5, np.inf], corners=[0, 7, 20],
                corner_sharpness=[0.5, 2.25, np.inf], sharp_faces=[1, 2], holes=[5, 17, 300])
    return V, F, tags


@pytest.mark.parametrize("ext", TAGGED)
def test_holes_and_corner_sharpness_round_trip(ext, tmp_path):
    V, F, tags = _mesh()
    path = tmp_path / f"m{ext}"
    hybridsub.write_mesh(path, V, F, **tags)
    m = hybridsub.read_mesh(path)
    assert np.array_equal(m.faces, F) and np.array_equal(m.vertices, V)
    assert m.holes.tolist() == [5, 17, 300]
    order = np.argsort(m.corners)
    assert m.corners[order].tolist() == [0, 7, 20]
    assert np.asarray(m.corner_sharpness)[order].tolist() == [0.5, 2.25, np.inf]
    assert sorted(m.sharp_faces.tolist()) == [1, 2]
    # read back, the file subdivides as the arrays do
    want = hybridsub.subdivide(V, F, levels=1, **tags)
    got = hybridsub.subdivide(m.vertices, m.faces, levels=1, **m.tag_arrays(), holes=m.holes)
    assert np.array_equal(got[1], want[1]) and np.array_equal(got[0], want[0])


@pytest.mark.parametrize("ext", [".off", ".stl", ".mesh"])
def test_formats_without_tags_say_the_holes_are_dropped(ext, tmp_path):
    V, F, tags = _mesh()
    with pytest.warns(UserWarning, match="3 holes"):
        hybridsub.write_mesh(tmp_path / f"m{ext}", V, F, holes=tags["holes"])


def test_write_mesh_holes_errors(tmp_path):
    V, F, _ = _mesh()
    with pytest.raises(MeshError, match="holes"):
        hybridsub.write_mesh(tmp_path / "m.obj", V, F, holes=[len(F)])


def _ply_text(tmp_path, extra):
    V, F, _ = _mesh()
    path = tmp_path / "m.ply"
    hybridsub.write_mesh(path, V, F, binary=False)
    text = path.read_text().replace("end_header", extra + "\nend_header", 1)
    path.write_text(text)
    return path, len(F)


def test_damaged_hole_tags(tmp_path):
    m = len(_mesh()[1])
    path, _ = _ply_text(tmp_path, f"comment hole 3 {m}")
    with pytest.raises(MeshError, match=f"hole 1 names face .*{m} .*valid 0..{m - 1}"):
        hybridsub.read_mesh(path)
    path, _ = _ply_text(tmp_path, "comment hole 2.5")
    with pytest.raises(MeshError, match="hole 0 names face"):
        hybridsub.read_mesh(path)
    path, _ = _ply_text(tmp_path, "comment hole x")
    with pytest.raises(MeshError, match="'comment hole' header line holds a value that is not a number"):
        hybridsub.read_mesh(path)
    # OBJ's t hole past the faces
    V, F, _ = _mesh()
    obj = tmp_path / "m.obj"
    hybridsub.write_mesh(obj, V, F)
    obj.write_text(obj.read_text() + f"t hole 1/0/0 {len(F) + 4}\n")
    with pytest.raises(MeshError, match=f"hole tag names face {len(F) + 4}"):
        hybridsub.read_mesh(obj)
    # NPZ holes past the faces
    npz = tmp_path / "m.npz"
    np.savez(npz, vertices=V, faces=F, holes=[len(F)])
    with pytest.raises(MeshError, match="holes"):
        hybridsub.read_mesh(npz)
    # meshio: hole cell data other than 0 or 1
    meshio = pytest.importorskip("meshio")
    vtu = tmp_path / "m.vtu"
    marks = np.zeros(len(F))
    marks[7] = 0.5
    meshio.Mesh(V, [("triangle", F)], cell_data={"hole": [marks]}).write(vtu)
    with pytest.raises(MeshError, match=r"'hole' cell data of triangle cell 7 \(face 7\) is 0.5"):
        hybridsub.read_mesh(vtu)



@pytest.mark.parametrize("mode,code", [("none", 0), ("edge_and_corner", 2)])
def test_obj_interpolateboundary_reads_as_tags(mode, code, tmp_path):
    """OpenSubdiv's ``t interpolateboundary``: 2 makes the lone boundary vertices corners, 0
    the faces at the boundary holes, so the file subdivides as boundary= would (and writes
    back as those tags: no format holds the option itself)."""
    m0 = hybridsub.read_mesh(Path(__file__).parent / "data" / "mesh_with_border.off")
    V, F = np.asarray(m0.vertices), np.asarray(m0.faces)
    path = tmp_path / "b.obj"
    hybridsub.write_mesh(path, V, F)
    path.write_text(path.read_text() + f"t interpolateboundary 1/0/0 {code}\n")
    m = hybridsub.read_mesh(path)
    assert any("interpolateboundary" in n for n in m.notes)
    got = hybridsub.subdivide(m.vertices, m.faces, levels=2, scheme="loop", **m.tag_arrays(), holes=m.holes)
    want = hybridsub.subdivide(V, F, levels=2, scheme="loop", boundary=mode)
    assert np.array_equal(got[1], want[1]) and np.array_equal(got[0], want[0])
    again = tmp_path / "again.obj"
    hybridsub.write_mesh(again, m)
    m2 = hybridsub.read_mesh(again)
    assert np.array_equal(m2.holes, m.holes) and np.array_equal(m2.corners, m.corners)
