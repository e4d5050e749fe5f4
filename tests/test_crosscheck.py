"""Cross-checks with the Loop implementations Python users already have: libigl and trimesh."""

import numpy as np
import pytest

import hybridsub
from meshcompare import mesh_difference

igl = pytest.importorskip("igl")
trimesh = pytest.importorskip("trimesh")


@pytest.mark.parametrize("name", ["icosahedron", "cube-meshed", "mesh_with_border", "elephant-with-holes"])
@pytest.mark.parametrize("levels", [1, 2])
def test_warren_weights_match_igl_loop(mesh, name, levels):
    """igl.loop uses Warren's weights (3/16 at valence 3, 3/(8n) otherwise) and crease boundaries."""
    V, F = mesh(name)
    V_igl, F_igl = igl.loop(V, F, levels)
    V2, F2 = hybridsub.subdivide(V, F, levels=levels, scheme="loop", loop_weights="warren")
    assert mesh_difference(V2, F2, V_igl, F_igl) is None


@pytest.mark.parametrize("name", ["tetrahedron", "octahedron", "icosahedron", "cube-meshed"])
@pytest.mark.parametrize("levels", [1, 2])
def test_loop_weights_match_trimesh_on_closed_meshes(mesh, name, levels):
    V, F = mesh(name)
    V_tm, F_tm = trimesh.remesh.subdivide_loop(V, F, iterations=levels)
    V2, F2 = hybridsub.subdivide(V, F, levels=levels, scheme="loop")
    assert mesh_difference(V2, F2, V_tm, F_tm) is None


def test_loop_and_warren_weights_differ(mesh):
    """Guard against the option being ignored: at valence 4/5 the two weight sets disagree."""
    V, F = mesh("icosahedron")
    a, _ = hybridsub.subdivide(V, F, scheme="loop")
    b, _ = hybridsub.subdivide(V, F, scheme="loop", loop_weights="warren")
    assert np.abs(a - b).max() > 1e-3
